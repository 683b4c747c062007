//! Sylva from Python: the native half (`sylva._sylva`) of the `sylva` package.
//!
//! Everything here stands on Sylva's library layer (`sylva::Genome`, `sylva::Grown`,
//! `sylva::Config`, `sylva::Evolution`), as the command line does; this crate only turns
//! Python values into the library's and back:
//!
//! - [`genome`]: `Genome` (load, fields, grow, mutate), `cross`, `models`;
//! - [`plant`]: `Plant` (measures, export, render), `Mesh` (numpy arrays), `Scene`, `garden`;
//! - [`evolution`]: `Config`, `Evolution` (step, browse, checkpoint, migrants), `Member`;
//! - [`errors`]: Sylva's errors as the exceptions of `sylva/errors.py`.
//!
//! Calls that grow, mesh, render, write or breed release the GIL. The pure-Python half
//! (`python/sylva`) adds island evolution on Ray or a local process pool.

mod errors;
mod evolution;
mod genome;
mod json;
mod pair;
mod plant;

use pyo3::prelude::*;

/// Sylva's native module.
#[pymodule]
fn _sylva(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<genome::Genome>()?;
    m.add_class::<plant::Plant>()?;
    m.add_class::<plant::Mesh>()?;
    m.add_class::<plant::Scene>()?;
    m.add_class::<evolution::Config>()?;
    m.add_class::<evolution::Evolution>()?;
    m.add_class::<evolution::Member>()?;
    m.add_function(wrap_pyfunction!(genome::cross, m)?)?;
    m.add_function(wrap_pyfunction!(genome::models, m)?)?;
    m.add_function(wrap_pyfunction!(genome::_rust_grow_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(plant::garden, m)?)?;
    m.add_function(wrap_pyfunction!(plant::scene, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
