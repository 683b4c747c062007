//! Sylva's errors as Python exceptions.
//!
//! The exception classes are plain Python (`sylva/errors.py`), so that `InputError` can be a
//! `ValueError` as well as a `SylvaError`; this module raises them with the same message the
//! command line prints and the place it points at.

use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A Python exception of class `name` in `sylva.errors`, made with `message` and `place`.
fn raise(name: &str, message: String, place: Option<&sylva::InputError>) -> PyErr {
    Python::attach(|py| {
        let made = (|| -> PyResult<PyErr> {
            let class = py.import("sylva.errors")?.getattr(name)?;
            let kwargs = PyDict::new(py);
            if let Some(e) = place {
                kwargs.set_item("location", &e.location)?;
                kwargs.set_item("path", e.path.as_ref().map(|p| p.display().to_string()))?;
                kwargs.set_item("line", e.line)?;
                kwargs.set_item("column", e.column)?;
                kwargs.set_item("detail", &e.message)?;
            }
            Ok(PyErr::from_value(class.call((message,), Some(&kwargs))?))
        })();
        // Without the package's Python half (an import of the bare module), the error still
        // comes through, as the exception the import raised.
        made.unwrap_or_else(|e| e)
    })
}

/// An [`sylva::InputError`] as a Python `InputError` with its place; a file that is not
/// there, or may not be read, as Python's own `FileNotFoundError` or `PermissionError` (an
/// `OSError` with its errno, message and file name).
pub fn input_error(e: &sylva::InputError) -> PyErr {
    let os_error = match e.io {
        Some(std::io::ErrorKind::NotFound) => Some(("FileNotFoundError", "ENOENT")),
        Some(std::io::ErrorKind::PermissionDenied) => Some(("PermissionError", "EACCES")),
        _ => None,
    };
    if let (Some((class, errno)), Some(path)) = (os_error, &e.path) {
        let made = Python::attach(|py| -> PyResult<PyErr> {
            let errno = py.import("errno")?.getattr(errno)?;
            let class = py.import("builtins")?.getattr(class)?;
            let error = class.call1((errno, e.to_string(), path.display().to_string()))?;
            Ok(PyErr::from_value(error))
        });
        if let Ok(error) = made {
            return error;
        }
    }
    raise("InputError", e.to_string(), Some(e))
}

/// Any Sylva error as the Python exception of its kind, its causes in the message: bad input
/// is an `InputError`, a refusal of work that does not fit a `LimitError`, anything else a
/// `SylvaError`.
pub fn error(e: sylva::Error) -> PyErr {
    match e {
        sylva::Error::Input(input) => input_error(&input),
        e if e.is_limit() => raise("LimitError", sylva::error::chain(&e), None),
        e => raise("SylvaError", sylva::error::chain(&e), None),
    }
}

/// Bad input of a value given from Python: `location` names the argument or field.
pub fn bad_value(location: impl Into<String>, message: impl ToString) -> PyErr {
    input_error(&sylva::InputError::new(location, message))
}

/// Results of Sylva's library, as Python results.
pub trait IntoPy<T> {
    /// The result with its error as a Python exception.
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, sylva::Error> {
    fn py(self) -> PyResult<T> {
        self.map_err(error)
    }
}

impl<T> IntoPy<T> for Result<T, sylva::InputError> {
    fn py(self) -> PyResult<T> {
        self.map_err(|e| input_error(&e))
    }
}
