//! The models a module reads and makes genomes and configs with: the registry its maker gave
//! [`crate::init`], kept by the module and by the classes it adds (as `_models`). Functions
//! reach it through their module (`#[pyo3(pass_module)]`), constructors through their class
//! (`#[classmethod]`); nothing else holds a registry, and no call falls back to one.
//!
//! A class object is one per process (PyO3 makes each once), so the classes keep the first
//! module's models: a second module of the same classes with other models is refused.

use pyo3::exceptions::{PyImportError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::PyType;
use sylva::Registry;

/// Where a module and its classes keep their models.
const ATTRIBUTE: &str = "_models";

/// The models of a Sylva module: one registry, made by whoever made the module.
#[pyclass(module = "sylva", name = "Models", frozen)]
pub struct Models {
    registry: Registry,
}

impl Models {
    /// The registry.
    pub fn registry(&self) -> &Registry {
        &self.registry
    }

    /// The models' names, in the registry's order.
    fn names(&self) -> Vec<&'static str> {
        self.registry.models().iter().map(|e| e.name()).collect()
    }

    /// The models of `holder`: a module `init` filled, or one of the classes it added.
    pub fn of<'py>(holder: &Bound<'py, PyAny>) -> PyResult<Bound<'py, Models>> {
        let py = holder.py();
        let held = holder.getattr(pyo3::intern!(py, ATTRIBUTE)).ok();
        held.and_then(|h| h.cast_into::<Models>().ok())
            .ok_or_else(|| {
                PyRuntimeError::new_err(format!(
                    "{holder} has no models: Sylva's classes and functions are used through a \
                 module made by `_sylva::init`"
                ))
            })
    }

    /// Gives `module` and `classes` the models of `registry`, once: classes that another
    /// module already gave models keep them, and the module shares them if they are the
    /// same models, and is refused if not.
    pub fn install(
        module: &Bound<'_, PyModule>,
        classes: &[Bound<'_, PyType>],
        registry: Registry,
    ) -> PyResult<()> {
        let py = module.py();
        let held = classes
            .iter()
            .find_map(|class| Models::of(class.as_any()).ok());
        let models = match held {
            Some(held) => {
                let (have, want) = (held.get().names(), Models { registry }.names());
                if have != want {
                    return Err(PyImportError::new_err(format!(
                        "Sylva's native module is already loaded in this process with the \
                         models {}; it cannot also be loaded with {}",
                        have.join(", "),
                        want.join(", ")
                    )));
                }
                held
            }
            None => Bound::new(py, Models { registry })?,
        };
        for class in classes {
            if Models::of(class.as_any()).is_err() {
                class.setattr(ATTRIBUTE, &models)?;
            }
        }
        module.add(ATTRIBUTE, models)
    }
}
