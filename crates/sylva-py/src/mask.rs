//! Target pictures given as numpy arrays (`sylva.match(mask)`), as the PNG files a match's
//! config names.
//!
//! A match's config names its pictures by path, so that its checkpoint resumes and the run
//! pickles; an array is written as a PNG into a folder of the system's temporary files, named
//! by its content, and read back as any picture is: the same run as from that PNG file.

use std::path::PathBuf;

use numpy::{PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray};
use numpy::{PyUntypedArrayMethods, dtype};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

use crate::errors::{IntoPy, bad_value};

/// The path of the picture `value` gives (the argument `name`): a path as it is, a numpy
/// array written as a PNG file ([`png_of`]).
pub fn picture_path(py: Python<'_>, value: &Bound<'_, PyAny>, name: &str) -> PyResult<PathBuf> {
    let Ok(array) = value.cast::<PyUntypedArray>() else {
        return value.extract::<PathBuf>().map_err(|_| {
            PyTypeError::new_err(format!(
                "`{name}` must be the path of a PNG or JPEG picture or a numpy array (a 2-D \
                 mask, or a uint8 image), got {}",
                value
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".into(), |n| n.to_string())
            ))
        });
    };
    let png = png_of(py, array, name)?;
    let hash = sylva::core::hash::stable_hash(&png);
    let path = std::env::temp_dir()
        .join("sylva-targets")
        .join(format!("{hash:016x}.png"));
    if !path.exists() {
        py.detach(|| {
            sylva::files::create_dir(path.parent().unwrap_or(&path))?;
            sylva::files::write(&path, &png)
        })
        .py()?;
    }
    Ok(path)
}

/// PNG bytes of a numpy picture (the argument `name`):
/// - a bool array (h, w): a mask, ink where True;
/// - a uint8 array: an image, grey (h, w), RGB (h, w, 3) or RGBA (h, w, 4), read as a
///   picture file is (dark ink on a light background, or the opaque pixels);
/// - any other array of numbers (h, w): a mask, ink where nonzero.
///
/// A mask is drawn black on white, which any threshold above 0 reads back exactly.
fn png_of(py: Python<'_>, array: &Bound<'_, PyUntypedArray>, name: &str) -> PyResult<Vec<u8>> {
    let shape = array.shape().to_vec();
    let kind = array.dtype().kind();
    let expected = "a 2-D mask (h, w) of bools or numbers, or a uint8 image: grey (h, w), \
                    RGB (h, w, 3) or RGBA (h, w, 4)";
    let side = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    if array.dtype().is_equiv_to(&dtype::<u8>(py)) {
        let channels = match shape.as_slice() {
            [_, _] => 1,
            [_, _, c @ (3 | 4)] => *c as u8,
            _ => {
                return Err(bad_value(
                    name,
                    format!("an array of shape {shape:?}; expected {expected}"),
                ));
            }
        };
        let pixels: Vec<u8> = array
            .cast::<PyArrayDyn<u8>>()?
            .readonly()
            .as_array()
            .iter()
            .copied()
            .collect();
        // 0 and 1 alone read as a picture would be all ink: surely a mask.
        if pixels.iter().all(|&p| p <= 1) {
            return Err(bad_value(
                name,
                "a uint8 array is read as a picture (dark ink on a light background), and this \
                 one holds only 0 and 1: for a mask, pass `mask.astype(bool)`",
            ));
        }
        return sylva::picture::encode_png(name, side(shape[1]), side(shape[0]), channels, pixels)
            .py();
    }
    let [height, width] = shape[..] else {
        return Err(bad_value(
            name,
            format!("an array of shape {shape:?}; expected {expected}"),
        ));
    };
    let ink: Vec<bool> = match kind {
        b'b' => array
            .cast::<PyArrayDyn<bool>>()?
            .readonly()
            .as_array()
            .iter()
            .copied()
            .collect(),
        b'i' | b'u' | b'f' => {
            let numbers = py
                .import("numpy")?
                .call_method1("asarray", (array, dtype::<f64>(py)))?;
            let numbers = numbers.cast_into::<PyArrayDyn<f64>>()?;
            let numbers = numbers.readonly();
            if numbers.as_array().iter().any(|v| v.is_nan()) {
                return Err(bad_value(
                    name,
                    "the mask holds NaN; expected numbers (nonzero: ink)",
                ));
            }
            numbers.as_array().iter().map(|&v| v != 0.0).collect()
        }
        _ => {
            return Err(PyTypeError::new_err(format!(
                "`{name}`: an array of dtype {}; expected {expected}",
                array.dtype()
            )));
        }
    };
    let pixels = ink.into_iter().map(|i| if i { 0 } else { 255 }).collect();
    sylva::picture::encode_png(name, side(width), side(height), 1, pixels).py()
}
