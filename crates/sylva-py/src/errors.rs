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
                kwargs.set_item("detail", in_python_words(&e.message))?;
            }
            Ok(PyErr::from_value(
                class.call((in_python_words(&message),), Some(&kwargs))?,
            ))
        })();
        // Without the package's Python half (an import of the bare module), the error still
        // comes through, as the exception the import raised.
        made.unwrap_or_else(|e| e)
    })
}

/// How serde and the library name types and values, and how Python does (`expected u32` is
/// `expected a non-negative int`); longer names first.
const PYTHON_WORDS: &[(&str, &str)] = &[
    ("expected usize", "expected a non-negative int"),
    ("expected isize", "expected an int"),
    ("expected u64", "expected a non-negative int"),
    ("expected u32", "expected a non-negative int"),
    ("expected u16", "expected a non-negative int"),
    ("expected u8", "expected a non-negative int"),
    ("expected i64", "expected an int"),
    ("expected i32", "expected an int"),
    ("expected i16", "expected an int"),
    ("expected i8", "expected an int"),
    ("expected f64", "expected a float"),
    ("expected f32", "expected a float"),
    ("expected a string", "expected a str"),
    ("expected a boolean", "expected a bool"),
    ("expected a sequence", "expected a list"),
    ("expected a map", "expected a dict"),
    ("boolean `true`", "bool True"),
    ("boolean `false`", "bool False"),
    ("floating point `", "float `"),
    ("integer `", "int `"),
    ("type: string", "type: str"),
    ("type: sequence", "type: list"),
    ("type: map", "type: dict"),
    ("unit value", "None"),
    // The command line's flags, as Python sets the same budgets.
    ("`--max-memory`", "`sylva.set_max_memory(bytes)`"),
    ("`--max-time`", "`sylva.set_max_time(seconds)`"),
];

/// `message` in Python's words for types and values ([`PYTHON_WORDS`]); a word is replaced
/// only where it ends (`u8` is not the start of `u80`).
fn in_python_words(message: &str) -> String {
    let mut out = message.to_owned();
    for (rust, python) in PYTHON_WORDS {
        let mut from = 0;
        while let Some(at) = out[from..].find(rust).map(|i| i + from) {
            let end = at + rust.len();
            let whole = rust.ends_with(['`', ' '])
                || !out[end..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_');
            if whole {
                out.replace_range(at..end, python);
                from = at + python.len();
            } else {
                from = end;
            }
        }
    }
    out
}

/// An [`sylva::InputError`] as a Python `InputError` with its place; a file that is not
/// there, or may not be read, as Python's own `FileNotFoundError` or `PermissionError` (an
/// `OSError` with its errno, message and file name).
pub fn input_error(e: &sylva::InputError) -> PyErr {
    if let (Some(kind), Some(path)) = (e.io, &e.path)
        && let Some(error) = os_error(kind, &e.to_string(), path)
    {
        return error;
    }
    let class = if e.limit { "LimitError" } else { "InputError" };
    raise(class, e.to_string(), Some(e))
}

/// A file that is not there, or may not be read or written, as Python's own
/// `FileNotFoundError` or `PermissionError` (an `OSError` with its errno, message and file
/// name); None for other kinds.
fn os_error(kind: std::io::ErrorKind, message: &str, path: &std::path::Path) -> Option<PyErr> {
    let (class, errno) = match kind {
        std::io::ErrorKind::NotFound => ("FileNotFoundError", "ENOENT"),
        std::io::ErrorKind::PermissionDenied => ("PermissionError", "EACCES"),
        _ => return None,
    };
    Python::attach(|py| -> PyResult<PyErr> {
        let errno = py.import("errno")?.getattr(errno)?;
        let class = py.import("builtins")?.getattr(class)?;
        let error = class.call1((errno, message, path.display().to_string()))?;
        Ok(PyErr::from_value(error))
    })
    .ok()
}

/// Any Sylva error as the Python exception of its kind, its causes in the message: bad input
/// is an `InputError`, a file that is not there or may not be written (a missing folder to
/// export into) `FileNotFoundError` or `PermissionError`, a refusal of work that does not fit a `LimitError`, an exception of the
/// run's own fitness function that exception, a stop `KeyboardInterrupt`, anything else a
/// `SylvaError`.
pub fn error(e: sylva::Error) -> PyErr {
    match e {
        sylva::Error::Input(input) => input_error(&input),
        // The run's own fitness function's exception, raised again as it was.
        sylva::Error::Scorer(inner) => match inner.downcast::<PyErr>() {
            Ok(e) => *e,
            Err(other) => raise("SylvaError", sylva::error::chain(&*other), None),
        },
        sylva::Error::Io {
            ref path,
            ref source,
            ..
        } => {
            let message = sylva::error::chain(&e);
            os_error(source.kind(), &message, path)
                .unwrap_or_else(|| raise("SylvaError", message, None))
        }
        sylva::Error::Stopped(_) => {
            pyo3::exceptions::PyKeyboardInterrupt::new_err("stopped before it finished")
        }
        e if e.is_limit() => raise("LimitError", sylva::error::chain(&e), None),
        e => raise("SylvaError", sylva::error::chain(&e), None),
    }
}

/// An archive's error as its Python exception: a genome that does not read as the
/// `InputError` it is (its file the archive and the plant), a plant `StudioArchive.add` cannot
/// write as an `InputError` naming it, the rest as `sylva.ArchiveError` with its file.
pub fn archive_error(e: sylva::archive::ArchiveError) -> PyErr {
    use sylva::archive::ArchiveError;
    match e {
        ArchiveError::Genome { error, .. } => input_error(&error),
        ArchiveError::Addition { index, problem, .. } => {
            bad_value(format!("plants[{index}]"), problem)
        }
        e => raise_archive(e.to_string(), e.path()),
    }
}

/// `sylva.ArchiveError` for an archive already closed.
pub fn archive_closed(path: &std::path::Path) -> PyErr {
    raise_archive(format!("{} is closed", path.display()), path)
}

fn raise_archive(message: String, path: &std::path::Path) -> PyErr {
    Python::attach(|py| {
        let made = (|| -> PyResult<PyErr> {
            let class = py.import("sylva.errors")?.getattr("ArchiveError")?;
            let kwargs = PyDict::new(py);
            kwargs.set_item("path", path.display().to_string())?;
            Ok(PyErr::from_value(class.call((message,), Some(&kwargs))?))
        })();
        made.unwrap_or_else(|e| e)
    })
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

#[cfg(test)]
mod tests {
    use super::in_python_words;

    #[test]
    fn messages_speak_python() {
        assert_eq!(
            in_python_words("invalid type: string \"abc\", expected i64"),
            "invalid type: str \"abc\", expected an int"
        );
        assert_eq!(
            in_python_words("invalid value: integer `-1`, expected u64"),
            "invalid value: int `-1`, expected a non-negative int"
        );
        assert_eq!(
            in_python_words("invalid type: boolean `true`, expected f64"),
            "invalid type: bool True, expected a float"
        );
        // Only whole words: a name that merely starts like one is left alone.
        assert_eq!(in_python_words("expected u80"), "expected u80");
        assert_eq!(in_python_words("expected a stringy"), "expected a stringy");
    }
}
