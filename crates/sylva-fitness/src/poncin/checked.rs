//! Range-checked readers for the config's vectors and lists, in the style of
//! [`sylva_core::ranged`]: a bad value is refused while its field is read, so the error names
//! the field and the allowed range (and TOML adds the line).

use glam::DVec3;
use serde::{Deserialize, Deserializer, de::Error};

/// Reads three finite numbers, each in `min..=max`, as a vector.
pub(crate) fn vec3<'de, D: Deserializer<'de>>(
    d: D,
    field: &str,
    min: f64,
    max: f64,
    unit: &str,
) -> Result<DVec3, D::Error> {
    let v = <[f64; 3]>::deserialize(d)?;
    if v.iter().all(|x| x.is_finite() && (min..=max).contains(x)) {
        Ok(DVec3::from_array(v))
    } else {
        Err(D::Error::custom(format!(
            "`{field}` must be three numbers from {min} to {max}{unit}, got {v:?}"
        )))
    }
}

/// Reads three whole numbers, each in `min..=max`.
pub(crate) fn uint3<'de, D: Deserializer<'de>>(
    d: D,
    field: &str,
    min: u32,
    max: u32,
) -> Result<[u32; 3], D::Error> {
    let v = <[i64; 3]>::deserialize(d)?;
    if v.iter()
        .all(|x| (i64::from(min)..=i64::from(max)).contains(x))
    {
        Ok(v.map(|x| x as u32))
    } else {
        Err(D::Error::custom(format!(
            "`{field}` must be three whole numbers from {min} to {max}, got {v:?}"
        )))
    }
}

/// Reads a list of `1..=max_len` finite numbers, each in `min..=max`.
pub(crate) fn list<'de, D: Deserializer<'de>>(
    d: D,
    field: &str,
    min: f64,
    max: f64,
    max_len: usize,
) -> Result<Vec<f64>, D::Error> {
    let v = Vec::<f64>::deserialize(d)?;
    if v.is_empty() || v.len() > max_len {
        return Err(D::Error::custom(format!(
            "`{field}` must hold 1 to {max_len} numbers, got {}",
            v.len()
        )));
    }
    match v
        .iter()
        .find(|x| !(x.is_finite() && (min..=max).contains(*x)))
    {
        Some(bad) => Err(D::Error::custom(format!(
            "`{field}` entries must be numbers from {min} to {max}, got {bad}"
        ))),
        None => Ok(v),
    }
}

/// Declares `fn $name(d) -> Result<DVec3, _>` for `#[serde(deserialize_with = "...")]`.
macro_rules! ranged_vec3 {
    ($name:ident, $field:literal, $min:expr, $max:expr, $unit:literal) => {
        fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<glam::DVec3, D::Error> {
            $crate::poncin::checked::vec3(d, $field, $min, $max, $unit)
        }
    };
}

/// Declares `fn $name(d) -> Result<u32, _>` for `#[serde(deserialize_with = "...")]`.
macro_rules! ranged_u32 {
    ($name:ident, $field:literal, $min:expr, $max:expr) => {
        fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
            sylva_core::ranged::integer(d, $field, $min, $max)
        }
    };
}

pub(crate) use {ranged_u32, ranged_vec3};
