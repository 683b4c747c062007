//! A fitness: one total to select on, and the named terms it was made of.
//!
//! Higher totals are better. A NaN total is stored as negative infinity, the worst possible
//! value, so a broken evaluation can never win a comparison. Terms are kept inline (up to
//! [`MAX_TERMS`]) so evaluating does not allocate.

use std::cmp::Ordering;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// Most terms a fitness can keep. [`crate::Run::new`] refuses problems that declare more.
pub const MAX_TERMS: usize = 12;

/// A total and its terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fitness {
    total: f64,
    terms: [f64; MAX_TERMS],
    len: u8,
}

impl Fitness {
    /// A fitness with `total` and the given terms (at most [`MAX_TERMS`]; more are dropped).
    pub fn new(total: f64, terms: &[f64]) -> Self {
        let len = terms.len().min(MAX_TERMS);
        let mut inline = [0.0; MAX_TERMS];
        inline[..len].copy_from_slice(&terms[..len]);
        Fitness {
            total: if total.is_nan() {
                f64::NEG_INFINITY
            } else {
                total
            },
            terms: inline,
            len: len as u8,
        }
    }

    /// The total; higher is better; never NaN.
    #[inline]
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The terms, in the order of [`crate::Problem::term_names`].
    #[inline]
    pub fn terms(&self) -> &[f64] {
        &self.terms[..usize::from(self.len)]
    }

    /// Orders by total (a total order, as totals are never NaN).
    #[inline]
    pub fn cmp_total(&self, other: &Fitness) -> Ordering {
        self.total.total_cmp(&other.total)
    }
}

#[derive(Serialize, Deserialize)]
struct FitnessRepr {
    total: f64,
    terms: Vec<f64>,
}

impl Serialize for Fitness {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        FitnessRepr {
            total: self.total,
            terms: self.terms().to_vec(),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for Fitness {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let repr = FitnessRepr::deserialize(d)?;
        if repr.terms.len() > MAX_TERMS {
            return Err(serde::de::Error::custom(format!(
                "a fitness holds at most {MAX_TERMS} terms, got {}",
                repr.terms.len()
            )));
        }
        Ok(Fitness::new(repr.total, &repr.terms))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_is_worst() {
        let nan = Fitness::new(f64::NAN, &[]);
        let low = Fitness::new(-1e300, &[]);
        assert_eq!(nan.total(), f64::NEG_INFINITY);
        assert_eq!(nan.cmp_total(&low), Ordering::Less);
    }

    #[test]
    fn terms_round_trip() {
        let f = Fitness::new(3.5, &[1.0, 2.5]);
        let json = serde_json::to_string(&f).unwrap();
        assert_eq!(json, r#"{"total":3.5,"terms":[1.0,2.5]}"#);
        let back: Fitness = serde_json::from_str(&json).unwrap();
        assert_eq!(back, f);
    }
}
