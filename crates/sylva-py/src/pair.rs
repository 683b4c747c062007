//! Two values given from Python as any sequence of two: a tuple, a list or a numpy array
//! (`render(size=[64, 64])`), as Python code expects of a pair.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

/// Two values, from any sequence of two.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pair<T>(pub T, pub T);

impl<T> From<Pair<T>> for (T, T) {
    fn from(pair: Pair<T>) -> (T, T) {
        (pair.0, pair.1)
    }
}

impl<'a, 'py, T: pyo3::conversion::FromPyObjectOwned<'py>> FromPyObject<'a, 'py> for Pair<T> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let not_a_pair = || {
            PyTypeError::new_err(format!(
                "expected two values (a tuple, a list or an array of two), got {}",
                obj.repr()
                    .map_or_else(|_| "?".to_owned(), |r| r.to_string())
            ))
        };
        if obj.is_instance_of::<pyo3::types::PyString>() {
            return Err(not_a_pair());
        }
        let items: Vec<Bound<'py, PyAny>> = obj
            .try_iter()
            .map_err(|_| not_a_pair())?
            .collect::<PyResult<_>>()?;
        match items.as_slice() {
            [a, b] => Ok(Pair(
                a.extract().map_err(Into::into)?,
                b.extract().map_err(Into::into)?,
            )),
            _ => Err(not_a_pair()),
        }
    }
}
