//! Field validation during deserialisation, so a bad value's error carries the line and
//! column where it stands (serde_json and toml attach positions to errors raised while
//! reading a field). Genomes and configs use these through `#[serde(deserialize_with)]`;
//! [`ranged!`](macro@crate::ranged) declares such a reader in one line, for any [`Ranged`] type:
//! floats and whole numbers, and arrays and vectors of them.
//!
//! ```
//! use serde::Deserialize;
//!
//! sylva_core::ranged!(depth: u32, "depth", 1, 14);
//! sylva_core::ranged!(radius: f64, "radius", 0.001, 5.0, " m");
//! sylva_core::ranged!(size: [u32; 3], "size", 2, 1024);
//!
//! #[derive(Deserialize)]
//! struct Tree {
//!     #[serde(deserialize_with = "depth")]
//!     depth: u32,
//!     #[serde(deserialize_with = "radius")]
//!     radius: f64,
//!     #[serde(deserialize_with = "size")]
//!     size: [u32; 3],
//! }
//!
//! let tree: Tree = serde_json::from_str(r#"{"depth": 3, "radius": 0.5, "size": [4, 4, 4]}"#)?;
//! assert_eq!((tree.depth, tree.size), (3, [4, 4, 4]));
//! let e = serde_json::from_str::<Tree>(r#"{"depth": 3, "radius": -1, "size": [4, 4, 4]}"#);
//! let message = e.err().map(|e| e.to_string()).unwrap_or_default();
//! assert!(message.starts_with("`radius` must be a number from 0.001 to 5 m, got -1"));
//! # Ok::<(), serde_json::Error>(())
//! ```

use std::fmt::{Debug, Display};

use glam::DVec3;
use serde::{Deserialize, Deserializer, de::Error};

/// A value read with a range check; the error names the field, the range and the unit.
pub trait Ranged: Sized {
    /// The type of the bounds (the element type, for arrays and vectors).
    type Bound: Copy + Display;

    /// Reads the value and checks every number in it against `min..=max`.
    fn read<'de, D: Deserializer<'de>>(
        d: D,
        field: &str,
        min: Self::Bound,
        max: Self::Bound,
        unit: &str,
    ) -> Result<Self, D::Error>;
}

/// A number a field may hold: read through `f64` or `i64`, so that an out-of-range value
/// (a negative count, say) gets the range message rather than a type error.
pub trait Number: Copy + Display + Debug {
    /// How the number is read.
    type Wire: for<'de> Deserialize<'de> + Copy + Debug;
    /// How a value is described: "number" or "whole number".
    const NOUN: &'static str;
    /// The wire value, if it lies in `min..=max` (and is finite).
    fn accept(wire: Self::Wire, min: Self, max: Self) -> Option<Self>;
}

impl Number for f64 {
    type Wire = f64;
    const NOUN: &'static str = "number";
    fn accept(v: f64, min: f64, max: f64) -> Option<f64> {
        (v.is_finite() && (min..=max).contains(&v)).then_some(v)
    }
}

impl Number for f32 {
    type Wire = f64;
    const NOUN: &'static str = "number";
    fn accept(v: f64, min: f32, max: f32) -> Option<f32> {
        (v.is_finite() && (f64::from(min)..=f64::from(max)).contains(&v)).then_some(v as f32)
    }
}

macro_rules! whole_numbers {
    ($($t:ty),*) => {$(
        impl Number for $t {
            type Wire = i64;
            const NOUN: &'static str = "whole number";
            fn accept(v: i64, min: $t, max: $t) -> Option<$t> {
                (i128::from(v) >= min as i128 && i128::from(v) <= max as i128).then_some(v as $t)
            }
        }
    )*};
}
whole_numbers!(u8, u16, u32, u64, usize, i32, i64);

impl<T: Number> Ranged for T {
    type Bound = T;
    fn read<'de, D: Deserializer<'de>>(
        d: D,
        field: &str,
        min: T,
        max: T,
        unit: &str,
    ) -> Result<T, D::Error> {
        let v = T::Wire::deserialize(d)?;
        T::accept(v, min, max).ok_or_else(|| {
            D::Error::custom(format!(
                "`{field}` must be a {} from {min} to {max}{unit}, got {v:?}",
                T::NOUN
            ))
        })
    }
}

/// "two", "three", ...: how many numbers an array holds, in words.
fn count_in_words(n: usize) -> String {
    match n {
        2 => "two".into(),
        3 => "three".into(),
        4 => "four".into(),
        n => n.to_string(),
    }
}

impl<T: Number, const N: usize> Ranged for [T; N]
where
    [T::Wire; N]: for<'de> Deserialize<'de>,
{
    type Bound = T;
    fn read<'de, D: Deserializer<'de>>(
        d: D,
        field: &str,
        min: T,
        max: T,
        unit: &str,
    ) -> Result<[T; N], D::Error> {
        let v = <[T::Wire; N]>::deserialize(d)?;
        let mut out = [min; N];
        for (o, &w) in out.iter_mut().zip(&v) {
            *o = T::accept(w, min, max).ok_or_else(|| {
                D::Error::custom(format!(
                    "`{field}` must be {} {}s from {min} to {max}{unit}, got {v:?}",
                    count_in_words(N),
                    T::NOUN
                ))
            })?;
        }
        Ok(out)
    }
}

impl Ranged for DVec3 {
    type Bound = f64;
    fn read<'de, D: Deserializer<'de>>(
        d: D,
        field: &str,
        min: f64,
        max: f64,
        unit: &str,
    ) -> Result<DVec3, D::Error> {
        <[f64; 3]>::read(d, field, min, max, unit).map(DVec3::from_array)
    }
}

/// Reads a list of 1 to `max_len` numbers, each in `min..=max`. It stops reading at the
/// first entry past `max_len`, so a huge list costs nothing.
pub fn list<'de, D: Deserializer<'de>, T: Number>(
    d: D,
    field: &str,
    min: T,
    max: T,
    max_len: usize,
) -> Result<Vec<T>, D::Error> {
    struct List<'a, T> {
        field: &'a str,
        min: T,
        max: T,
        max_len: usize,
    }
    impl<'de, T: Number> serde::de::Visitor<'de> for List<'_, T> {
        type Value = Vec<T>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(f, "a list of 1 to {} {}s", self.max_len, T::NOUN)
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
            let (field, min, max, max_len) = (self.field, self.min, self.max, self.max_len);
            let mut out = Vec::new();
            while let Some(w) = seq.next_element::<T::Wire>()? {
                if out.len() == max_len {
                    return Err(A::Error::custom(format!(
                        "`{field}` must hold 1 to {max_len} {}s, got more",
                        T::NOUN
                    )));
                }
                out.push(T::accept(w, min, max).ok_or_else(|| {
                    A::Error::custom(format!(
                        "`{field}` entries must be {}s from {min} to {max}, got {w:?}",
                        T::NOUN
                    ))
                })?);
            }
            if out.is_empty() {
                return Err(A::Error::custom(format!(
                    "`{field}` must hold 1 to {max_len} {}s, got none",
                    T::NOUN
                )));
            }
            Ok(out)
        }
    }
    d.deserialize_seq(List {
        field,
        min,
        max,
        max_len,
    })
}

/// Declares `fn $name(d) -> Result<$type, _>` reading a [`Ranged`] value, for
/// `#[serde(deserialize_with = "...")]`: `ranged!(depth: u32, "depth", 1, 14)` or, with a
/// unit, `ranged!(radius: f64, "radius", 0.0, 5.0, " m")`; a visibility may lead
/// (`ranged!(pub(crate) depth: ...)`).
#[macro_export]
macro_rules! ranged {
    ($vis:vis $name:ident: $ty:ty, $field:literal, $min:expr, $max:expr) => {
        $crate::ranged!($vis $name: $ty, $field, $min, $max, "");
    };
    ($vis:vis $name:ident: $ty:ty, $field:literal, $min:expr, $max:expr, $unit:literal) => {
        $vis fn $name<'de, D: serde::Deserializer<'de>>(d: D) -> Result<$ty, D::Error> {
            <$ty as $crate::ranged::Ranged>::read(d, $field, $min, $max, $unit)
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read<T: Ranged>(json: &str, min: T::Bound, max: T::Bound) -> Result<T, String> {
        let mut d = serde_json::Deserializer::from_str(json);
        T::read(&mut d, "x", min, max, " m").map_err(|e| e.to_string())
    }

    #[test]
    fn numbers_and_whole_numbers() {
        assert_eq!(read::<f64>("0.5", 0.0, 1.0), Ok(0.5));
        assert!(
            read::<f64>("1.5", 0.0, 1.0)
                .unwrap_err()
                .contains("from 0 to 1 m, got 1.5")
        );
        assert_eq!(read::<u32>("7", 1, 8), Ok(7));
        let e = read::<u32>("-3", 1, 8).unwrap_err();
        assert!(
            e.contains("`x` must be a whole number from 1 to 8 m, got -3"),
            "{e}"
        );
        assert!(read::<u64>("10000000001", 1, 10_000_000_000).is_err());
        assert_eq!(
            read::<u64>("10000000000", 1, 10_000_000_000),
            Ok(10_000_000_000)
        );
        assert!(read::<usize>("1000000000000000", 1, 1000).is_err());
        assert!(read::<u8>("2.5", 0, 9).is_err());
    }

    #[test]
    fn arrays_and_vectors() {
        assert_eq!(read::<[u32; 3]>("[2, 3, 4]", 2, 9), Ok([2, 3, 4]));
        let e = read::<[u32; 3]>("[2, 1, 4]", 2, 9).unwrap_err();
        assert!(
            e.contains("`x` must be three whole numbers from 2 to 9 m, got [2, 1, 4]"),
            "{e}"
        );
        assert!(read::<[f64; 2]>("[0.5, NaN]", 0.0, 1.0).is_err());
        assert_eq!(
            read::<DVec3>("[1, 2, 3]", 0.0, 3.0),
            Ok(DVec3::new(1.0, 2.0, 3.0))
        );
        assert!(
            read::<DVec3>("[1, 2, 4]", 0.0, 3.0)
                .unwrap_err()
                .contains("three numbers")
        );
    }

    #[test]
    fn lists_are_bounded() {
        let list = |json: &str| {
            let mut d = serde_json::Deserializer::from_str(json);
            list::<_, f64>(&mut d, "refs", 0.0, 1.0, 3).map_err(|e| e.to_string())
        };
        assert_eq!(list("[0.5, 1]"), Ok(vec![0.5, 1.0]));
        assert!(list("[]").unwrap_err().contains("got none"));
        assert!(
            list("[0.1, 0.2, 0.3, 0.4]")
                .unwrap_err()
                .contains("1 to 3 numbers")
        );
        assert!(list("[0.1, 2]").unwrap_err().contains("from 0 to 1, got 2"));
    }
}
