//! Python values to and from JSON, through Python's own `json` module (so that dicts,
//! lists, numbers and strings cross exactly as `json.dumps` writes them).

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::bad_value;

/// A Python value as JSON; NaN and infinities are refused, naming `what`. numpy scalars and
/// arrays count as the numbers and lists they hold (`np.float32(0.3)` is 0.3).
pub fn from_py(value: &Bound<'_, PyAny>, what: &str) -> PyResult<serde_json::Value> {
    let py = value.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("allow_nan", false)?;
    kwargs.set_item("default", numpy_values(py)?)?;
    let text: String = py
        .import("json")?
        .call_method("dumps", (value,), Some(&kwargs))
        .map_err(|e| bad_value(what, format!("not JSON data: {e}")))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| bad_value(what, e))
}

/// JSON as a Python value (dicts, lists, floats, ints, strings, `None`).
pub fn to_py<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?
        .call_method1("loads", (value.to_string(),))
}

/// A JSON value at a field path: dot-separated keys, list positions as numbers
/// (`rotation1.axis.0`) or in brackets (`branches[2].waves`).
pub fn pointer(field: &str) -> String {
    // `branches[2].waves` (the schema's way) is `branches.2.waves`.
    field
        .replace('[', ".")
        .replace(']', "")
        .split('.')
        .map(|k| format!("/{}", k.replace('~', "~0").replace('/', "~1")))
        .collect()
}

/// `json.dumps`'s `default`: a numpy value as the Python value it holds (`tolist()`), and
/// anything else refused as `json` refuses it.
fn numpy_values(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyCFunction>> {
    pyo3::types::PyCFunction::new_closure(py, None, None, |args, _| -> PyResult<Py<PyAny>> {
        let value = args.get_item(0)?;
        let kind = value.get_type();
        let module: String = kind.getattr("__module__")?.extract().unwrap_or_default();
        if module == "numpy" || module.starts_with("numpy.") {
            return Ok(value.call_method0("tolist")?.unbind());
        }
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "Object of type {} is not JSON serializable",
            kind.name()?
        )))
    })
}
