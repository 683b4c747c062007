//! Field validation during deserialisation, so a bad value's error carries the line and
//! column where it stands (serde_json and toml attach positions to errors raised while
//! reading a field). Genomes and configs use these through `#[serde(deserialize_with)]`;
//! [`ranged_number!`](crate::ranged_number) declares such a reader in one line.

use serde::{Deserialize, Deserializer, de::Error};

/// Reads a finite number in `min..=max`; the error names the field, the range and the unit.
pub fn number<'de, D: Deserializer<'de>>(
    d: D,
    field: &str,
    min: f64,
    max: f64,
    unit: &str,
) -> Result<f64, D::Error> {
    let v = f64::deserialize(d)?;
    if v.is_finite() && (min..=max).contains(&v) {
        Ok(v)
    } else {
        Err(D::Error::custom(format!(
            "`{field}` must be a number from {min} to {max}{unit}, got {v}"
        )))
    }
}

/// Reads an integer in `min..=max`.
pub fn integer<'de, D: Deserializer<'de>>(
    d: D,
    field: &str,
    min: u32,
    max: u32,
) -> Result<u32, D::Error> {
    let v = i64::deserialize(d)?;
    if (i64::from(min)..=i64::from(max)).contains(&v) {
        Ok(v as u32)
    } else {
        Err(D::Error::custom(format!(
            "`{field}` must be a whole number from {min} to {max}, got {v}"
        )))
    }
}

/// Declares `fn $name(d) -> Result<f64, _>` reading a number in a range, for
/// `#[serde(deserialize_with = "...")]`.
#[macro_export]
macro_rules! ranged_number {
    ($name:ident, $field:literal, $min:expr, $max:expr, $unit:literal) => {
        fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
            $crate::ranged::number(d, $field, $min, $max, $unit)
        }
    };
}
