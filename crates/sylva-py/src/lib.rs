//! Sylva from Python: the native half (`sylva._sylva`) of the `sylva` package.
//!
//! Everything here stands on Sylva's library layer (`sylva::Genome`, `sylva::Grown`,
//! `sylva::Config`, `sylva::Evolution`), as the command line does; this crate only turns
//! Python values into the library's and back:
//!
//! - [`genome`]: `Genome`'s methods (load, fields, grow, mutate), `cross`, `models`; the
//!   class's data is [`handle`]'s, which every module holding genomes shares;
//! - [`plant`]: `Plant` (measures, export, render), `Mesh` (numpy arrays), `Scene`, `garden`;
//! - [`evolution`]: `Config`, `Evolution` (step, browse, checkpoint, migrants), `Member`;
//! - [`varieties`]: `Varieties` (maps of varieties: step, archive, checkpoint), `Variety`,
//!   `Archive`;
//! - [`space`]: `GenomeSpace`, genomes as numpy vectors for optimisers outside Sylva;
//! - [`errors`]: Sylva's errors as the exceptions of `sylva/errors.py`;
//! - [`work`]: long calls off the calling thread, so Ctrl-C is heard and a Python fitness
//!   function is served; [`mask`]: numpy masks as match targets.
//!
//! The module reads and makes genomes and configs with the models it was made with
//! ([`init`]): Sylva's four, or a registry of a crate's own.
//!
//! Calls that grow, mesh, render, write or breed release the GIL; runs stop on Ctrl-C within
//! one member's evaluation. The pure-Python half
//! (`python/sylva`) adds island evolution on Ray or a local process pool.

mod errors;
mod evolution;
mod genome;
mod handle;
mod json;
mod mask;
mod pair;
mod plant;
mod space;
mod varieties;
mod work;

use std::sync::OnceLock;

use pyo3::prelude::*;
use sylva::Registry;

/// The models this module knows, given when the module is made ([`init`]).
static MODELS: OnceLock<Registry> = OnceLock::new();

/// The models genome files, configs and random genomes are read and made with: the
/// registry the module was made with, or Sylva's four.
pub(crate) fn registry() -> &'static Registry {
    MODELS.get().unwrap_or(Registry::standard())
}

/// Sylva's native module, with Sylva's four models.
#[cfg(feature = "module")]
#[pymodule]
fn _sylva(m: &Bound<'_, PyModule>) -> PyResult<()> {
    init(m, Registry::standard().clone())
}

/// Fills `m` with Sylva's classes and functions, reading and making genomes and configs
/// with `registry`. A crate that adds its own models builds its module with this (and this
/// crate without its default `module` feature):
///
/// ```ignore
/// #[pymodule]
/// fn _mytrees(m: &Bound<'_, PyModule>) -> PyResult<()> {
///     let models = sylva::Registry::standard().clone().with(ModelEntry::of::<MyModel>());
///     _sylva::init(m, models)
/// }
/// ```
///
/// A process holds one registry: making a second module with other models raises
/// `ImportError`.
pub fn init(m: &Bound<'_, PyModule>, registry: Registry) -> PyResult<()> {
    let names = |r: &Registry| r.models().iter().map(|e| e.name()).collect::<Vec<_>>();
    let wanted = names(&registry);
    let held = names(MODELS.get_or_init(|| registry));
    if held != wanted {
        return Err(pyo3::exceptions::PyImportError::new_err(format!(
            "Sylva's native module is already loaded in this process with the models {}; \
             it cannot also be loaded with {}",
            held.join(", "),
            wanted.join(", ")
        )));
    }
    m.add_class::<handle::Genome>()?;
    m.add_class::<plant::Plant>()?;
    m.add_class::<plant::Mesh>()?;
    m.add_class::<plant::Scene>()?;
    m.add_class::<evolution::Config>()?;
    m.add_class::<evolution::Evolution>()?;
    m.add_class::<evolution::Member>()?;
    m.add_class::<varieties::Varieties>()?;
    m.add_class::<varieties::Variety>()?;
    m.add_class::<varieties::Archive>()?;
    m.add_class::<space::GenomeSpace>()?;
    m.add_function(wrap_pyfunction!(varieties::varieties, m)?)?;
    m.add_function(wrap_pyfunction!(genome::cross, m)?)?;
    m.add_function(wrap_pyfunction!(genome::models, m)?)?;
    m.add_function(wrap_pyfunction!(evolution::match_outline, m)?)?;
    m.add_function(wrap_pyfunction!(genome::_rust_grow_seconds, m)?)?;
    m.add_function(wrap_pyfunction!(plant::garden, m)?)?;
    m.add_function(wrap_pyfunction!(plant::scene, m)?)?;
    m.add_function(wrap_pyfunction!(plant::texture_png, m)?)?;
    m.add_function(wrap_pyfunction!(plant::picture_png, m)?)?;
    m.add_function(wrap_pyfunction!(set_max_memory, m)?)?;
    m.add_function(wrap_pyfunction!(max_memory, m)?)?;
    m.add_function(wrap_pyfunction!(set_max_time, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

/// Sets the memory budget of this process in bytes (0 goes back to the default: the least of
/// the machine's memory and the process's limits). Work whose estimate is over it raises
/// `LimitError` before it starts, as the command line's `--max-memory` does.
#[pyfunction]
fn set_max_memory(bytes: u64) {
    sylva::core::budget::set_max_memory(bytes);
}

/// The memory budget in force, in bytes.
#[pyfunction]
fn max_memory() -> u64 {
    sylva::core::budget::max_memory()
}

/// Sets the time budget of this process in seconds (0 goes back to the default hour). Work
/// estimated to take longer raises `LimitError` before it starts, as `--max-time` does.
#[pyfunction]
fn set_max_time(seconds: f64) -> PyResult<()> {
    if !(seconds.is_finite() && seconds >= 0.0) {
        return Err(errors::bad_value(
            "seconds",
            format!("{seconds}; expected a number of seconds, 0 or more"),
        ));
    }
    sylva::core::budget::set_max_time(std::time::Duration::from_secs_f64(seconds.min(1e12)));
    Ok(())
}
