//! Whole numbers given from Python (counts, sizes, ids, seeds): read as any int, numpy's
//! too, and checked where the argument's name is known, so that `run.run(-3)` raises
//! `InputError` (a `ValueError`) naming `generations` and the range it takes, not pyo3's
//! bare `OverflowError` naming nothing. (pyo3 names the argument only for a `TypeError`.)

use pyo3::prelude::*;

use crate::errors::bad_value;

/// An int as Python gave it, before its range is checked ([`Whole::get`]). One beyond
/// ±2¹²⁷ is kept as the nearest of those, which every range refuses all the same.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Whole(pub i128);

impl<'a, 'py> FromPyObject<'a, 'py> for Whole {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        match obj.extract::<i128>() {
            Ok(n) => Ok(Whole(n)),
            // An int too large either way: out of every range, on its side of 0.
            Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) => {
                let negative = obj.lt(0)?;
                Ok(Whole(if negative { i128::MIN } else { i128::MAX }))
            }
            Err(e) => Err(e),
        }
    }
}

/// The unsigned types arguments are read into, with their largest value for messages.
pub trait Unsigned: TryFrom<i128> {
    /// The largest value.
    const MOST: u128;
}

impl Unsigned for u16 {
    const MOST: u128 = u16::MAX as u128;
}
impl Unsigned for u32 {
    const MOST: u128 = u32::MAX as u128;
}
impl Unsigned for u64 {
    const MOST: u128 = u64::MAX as u128;
}
impl Unsigned for usize {
    const MOST: u128 = usize::MAX as u128;
}

impl Whole {
    /// The number as `T`, or an `InputError` naming argument `name` and `T`'s range.
    pub fn get<T: Unsigned>(self, name: &str) -> PyResult<T> {
        T::try_from(self.0).map_err(|_| {
            let got = match self.0 {
                i128::MIN => "a larger negative int".to_owned(),
                i128::MAX => "a larger int".to_owned(),
                n => n.to_string(),
            };
            bad_value(
                name,
                format!("expected an int from 0 to {}, got {got}", T::MOST),
            )
        })
    }
}

/// An optional [`Whole`] as `T`, named `name`.
pub fn get<T: Unsigned>(value: Option<Whole>, name: &str) -> PyResult<Option<T>> {
    value.map(|v| v.get(name)).transpose()
}
