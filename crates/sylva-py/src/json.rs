//! Python values to and from JSON, through Python's own `json` module (so that dicts,
//! lists, numbers and strings cross exactly as `json.dumps` writes them).

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::bad_value;

/// A Python value as JSON; NaN and infinities are refused, naming `what`.
pub fn from_py(value: &Bound<'_, PyAny>, what: &str) -> PyResult<serde_json::Value> {
    let py = value.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("allow_nan", false)?;
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
/// (`rotation1.axis.0`).
pub fn pointer(field: &str) -> String {
    field
        .split('.')
        .map(|k| format!("/{}", k.replace('~', "~0").replace('/', "~1")))
        .collect()
}
