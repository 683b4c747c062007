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
//! - [`archive`]: `StudioArchive`, the studio's archive (`sylva studio --db`) on the
//!   library's: plants listed and read, bred plants written back with their parents;
//! - [`space`]: `GenomeSpace`, genomes as numpy vectors for optimisers outside Sylva;
//! - [`errors`]: Sylva's errors as the exceptions of `sylva/errors.py`;
//! - [`work`]: long calls off the calling thread, so Ctrl-C is heard and a Python fitness
//!   function is served; [`mask`]: numpy masks as match targets.
//!
//! The module reads and makes genomes and configs with the models it was made with
//! ([`init`]): Sylva's four, or a registry of a crate's own, kept by the module and its
//! classes ([`models`]); there is no registry of the process's.
//!
//! Calls that grow, mesh, render, write or breed release the GIL; runs stop on Ctrl-C within
//! one member's evaluation. The pure-Python half
//! (`python/sylva`) adds island evolution on Ray or a local process pool.

mod archive;
mod errors;
mod evolution;
mod genome;
mod handle;
mod json;
mod mask;
mod models;
mod pair;
mod plant;
mod space;
mod varieties;
mod whole;
mod work;

use pyo3::prelude::*;
use sylva::Registry;

/// Sylva's native module, with Sylva's four models.
#[cfg(feature = "module")]
#[pymodule]
fn _sylva(m: &Bound<'_, PyModule>) -> PyResult<()> {
    init(m, Registry::standard())
}

/// Fills `m` with Sylva's classes and functions, reading and making genomes and configs
/// with `registry`. A crate that adds its own models builds its module with this (and this
/// crate without its default `module` feature):
///
/// ```ignore
/// #[pymodule]
/// fn _mytrees(m: &Bound<'_, PyModule>) -> PyResult<()> {
///     let models = sylva::Registry::standard().with(ModelEntry::of::<MyModel>());
///     _sylva::init(m, models)
/// }
/// ```
///
/// The module keeps `registry` (as `_models`), and so do the classes it adds: its functions
/// and the classes' constructors read and make genomes and configs with it, and with nothing
/// else. A class is one per process, so a second module with other models raises
/// `ImportError`.
pub fn init(m: &Bound<'_, PyModule>, registry: Registry) -> PyResult<()> {
    let py = m.py();
    let classes = [
        py.get_type::<handle::Genome>(),
        py.get_type::<plant::Plant>(),
        py.get_type::<plant::Mesh>(),
        py.get_type::<plant::Scene>(),
        py.get_type::<evolution::Config>(),
        py.get_type::<evolution::Evolution>(),
        py.get_type::<evolution::Member>(),
        py.get_type::<varieties::Varieties>(),
        py.get_type::<varieties::Variety>(),
        py.get_type::<varieties::Archive>(),
        py.get_type::<space::GenomeSpace>(),
        py.get_type::<archive::StudioArchive>(),
        py.get_type::<archive::ArchivedPlant>(),
    ];
    models::Models::install(m, &classes, registry)?;
    for class in classes {
        m.add(class.name()?, class)?;
    }
    m.add_function(wrap_pyfunction!(varieties::varieties, m)?)?;
    m.add_function(wrap_pyfunction!(genome::cross, m)?)?;
    m.add_function(wrap_pyfunction!(genome::models, m)?)?;
    m.add_function(wrap_pyfunction!(genome::schema, m)?)?;
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
fn set_max_memory(bytes: whole::Whole) -> PyResult<()> {
    sylva::core::budget::set_max_memory(bytes.get("bytes")?);
    Ok(())
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
