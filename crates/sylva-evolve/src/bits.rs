//! Fixed-length bit strings, the genome of a classic genetic algorithm.
//!
//! [`BitString<W>`] holds up to `64 * W` bits inline (it is `Copy`, so breeding does not
//! allocate). [`Quantized`] maps a run of bits to a number in a range, which is how models
//! document their encodings. Operators: [`BitFlip`] mutation and [`OnePoint`] and [`Uniform`]
//! crossover.

use std::fmt;

use rand::{Rng, RngExt};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::variation::{Crossover, Mutate};

/// A string of `len` bits stored in `W` 64-bit words; bits past `len` are always zero.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct BitString<const W: usize> {
    words: [u64; W],
    len: u16,
}

impl<const W: usize> BitString<W> {
    /// Bits this type can hold.
    pub const CAPACITY: usize = 64 * W;

    /// `len` zero bits; `None` if `len` exceeds [`Self::CAPACITY`].
    pub fn zeros(len: usize) -> Option<Self> {
        (len <= Self::CAPACITY).then_some(BitString {
            words: [0; W],
            len: len as u16,
        })
    }

    /// `len` random bits.
    pub fn random<R: Rng + ?Sized>(len: usize, rng: &mut R) -> Option<Self> {
        let mut s = Self::zeros(len)?;
        for w in &mut s.words {
            *w = rng.next_u64();
        }
        s.clear_tail();
        Some(s)
    }

    /// Number of bits.
    #[inline]
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// True for the empty string.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Bit `i` (false past the end).
    #[inline]
    pub fn get(&self, i: usize) -> bool {
        i < self.len() && (self.words[i / 64] >> (i % 64)) & 1 == 1
    }

    /// Sets bit `i`; ignored past the end.
    #[inline]
    pub fn set(&mut self, i: usize, value: bool) {
        if i < self.len() {
            let mask = 1u64 << (i % 64);
            if value {
                self.words[i / 64] |= mask;
            } else {
                self.words[i / 64] &= !mask;
            }
        }
    }

    /// Flips bit `i`; ignored past the end.
    #[inline]
    pub fn flip(&mut self, i: usize) {
        if i < self.len() {
            self.words[i / 64] ^= 1u64 << (i % 64);
        }
    }

    /// Reads `width` (at most 64) bits starting at `offset`, first bit least significant.
    pub fn read(&self, offset: usize, width: usize) -> u64 {
        (0..width.min(64)).fold(0, |acc, k| acc | (u64::from(self.get(offset + k)) << k))
    }

    /// Writes the low `width` (at most 64) bits of `value` starting at `offset`.
    pub fn write(&mut self, offset: usize, width: usize, value: u64) {
        for k in 0..width.min(64) {
            self.set(offset + k, (value >> k) & 1 == 1);
        }
    }

    /// Number of positions where `self` and `other` differ.
    pub fn hamming(&self, other: &Self) -> u32 {
        self.words
            .iter()
            .zip(&other.words)
            .map(|(a, b)| (a ^ b).count_ones())
            .sum()
    }

    fn clear_tail(&mut self) {
        let len = self.len();
        for (w, word) in self.words.iter_mut().enumerate() {
            let keep = len.saturating_sub(w * 64).min(64);
            *word &= if keep == 64 {
                u64::MAX
            } else {
                (1u64 << keep) - 1
            };
        }
    }
}

impl<const W: usize> fmt::Display for BitString<W> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for i in 0..self.len() {
            f.write_str(if self.get(i) { "1" } else { "0" })?;
        }
        Ok(())
    }
}

impl<const W: usize> fmt::Debug for BitString<W> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "BitString({self})")
    }
}

/// Why a text is not a bit string.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ParseBitsError {
    /// A character other than `0` or `1`.
    #[error("character {index} is {found:?}; a bit string holds only '0' and '1'")]
    BadCharacter {
        /// Position of the character.
        index: usize,
        /// The character.
        found: char,
    },
    /// Longer than the type holds.
    #[error("{len} bits is more than the {capacity} this genome holds")]
    TooLong {
        /// Bits given.
        len: usize,
        /// Bits allowed.
        capacity: usize,
    },
}

impl<const W: usize> std::str::FromStr for BitString<W> {
    type Err = ParseBitsError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let len = s.chars().count();
        let mut bits = Self::zeros(len).ok_or(ParseBitsError::TooLong {
            len,
            capacity: Self::CAPACITY,
        })?;
        for (index, c) in s.chars().enumerate() {
            match c {
                '0' => {}
                '1' => bits.set(index, true),
                found => return Err(ParseBitsError::BadCharacter { index, found }),
            }
        }
        Ok(bits)
    }
}

impl<const W: usize> Serialize for BitString<W> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de, const W: usize> Deserialize<'de> for BitString<W> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// A number encoded in `bits` bits, spread evenly over `min..=max`: code 0 is `min`, the
/// largest code is `max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantized {
    /// Width in bits (1 to 32).
    pub bits: u8,
    /// Value of code 0.
    pub min: f64,
    /// Value of the largest code.
    pub max: f64,
}

impl Quantized {
    /// Largest code.
    #[inline]
    pub fn max_code(&self) -> u64 {
        (1u64 << self.bits) - 1
    }

    /// The value of a code (codes past the largest are clamped).
    #[inline]
    pub fn decode(&self, code: u64) -> f64 {
        let t = code.min(self.max_code()) as f64 / self.max_code() as f64;
        self.min + (self.max - self.min) * t
    }

    /// The nearest code to a value (values outside the range are clamped).
    pub fn encode(&self, value: f64) -> u64 {
        let span = self.max - self.min;
        if !value.is_finite() || span == 0.0 {
            return 0;
        }
        let t = ((value - self.min) / span).clamp(0.0, 1.0);
        (t * self.max_code() as f64).round() as u64
    }

    /// The distance between neighbouring values.
    pub fn step(&self) -> f64 {
        (self.max - self.min) / self.max_code() as f64
    }
}

/// Flips each bit independently with probability `rate`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BitFlip {
    /// Probability per bit, 0 to 1.
    pub rate: f64,
}

impl<const W: usize> Mutate<BitString<W>> for BitFlip {
    fn mutate<R: Rng + ?Sized>(&self, genome: &mut BitString<W>, rng: &mut R) {
        let rate = crate::rng::probability(self.rate);
        for i in 0..genome.len() {
            if rng.random_bool(rate) {
                genome.flip(i);
            }
        }
    }
}

/// One-point crossover: bits before a random cut from the first parent, the rest from the
/// second.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OnePoint;

impl<const W: usize> Crossover<BitString<W>> for OnePoint {
    fn crossover<R: Rng + ?Sized>(
        &self,
        a: &BitString<W>,
        b: &BitString<W>,
        rng: &mut R,
    ) -> BitString<W> {
        let len = a.len().min(b.len());
        let cut = if len == 0 {
            0
        } else {
            rng.random_range(0..=len)
        };
        let mut child = *a;
        for i in cut..len {
            child.set(i, b.get(i));
        }
        child
    }
}

/// Uniform crossover: each bit from either parent with equal probability.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Uniform;

impl<const W: usize> Crossover<BitString<W>> for Uniform {
    fn crossover<R: Rng + ?Sized>(
        &self,
        a: &BitString<W>,
        b: &BitString<W>,
        rng: &mut R,
    ) -> BitString<W> {
        let mut child = *a;
        for (w, word) in child.words.iter_mut().enumerate() {
            let mask = rng.next_u64();
            *word = (a.words[w] & mask) | (b.words[w] & !mask);
        }
        child.clear_tail();
        child
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;
    use proptest::prelude::*;

    type Bits = BitString<2>;

    #[test]
    fn quantized_ends_and_steps() {
        let q = Quantized {
            bits: 8,
            min: 0.0,
            max: 180.0,
        };
        assert_eq!(q.decode(0), 0.0);
        assert_eq!(q.decode(255), 180.0);
        assert_eq!(q.encode(180.0), 255);
        assert_eq!(q.encode(-5.0), 0);
        assert_eq!(q.encode(f64::NAN), 0);
        assert!((q.step() - 180.0 / 255.0).abs() < 1e-12);
    }

    #[test]
    fn parse_errors() {
        assert!(matches!(
            "01x".parse::<Bits>(),
            Err(ParseBitsError::BadCharacter {
                index: 2,
                found: 'x'
            })
        ));
        assert!(matches!(
            "0".repeat(129).parse::<Bits>(),
            Err(ParseBitsError::TooLong { len: 129, .. })
        ));
    }

    proptest! {
        #[test]
        fn text_round_trip(seed in any::<u64>(), len in 0usize..=128) {
            let s = Bits::random(len, &mut rng::seeded(seed)).unwrap();
            let text = s.to_string();
            prop_assert_eq!(text.len(), len);
            prop_assert_eq!(text.parse::<Bits>().unwrap(), s);
        }

        #[test]
        fn read_write_round_trip(seed in any::<u64>(), offset in 0usize..100, width in 1usize..28, value in any::<u32>()) {
            let mut s = Bits::random(128, &mut rng::seeded(seed)).unwrap();
            let v = u64::from(value) & ((1 << width) - 1);
            s.write(offset, width, v);
            prop_assert_eq!(s.read(offset, width), v);
        }

        #[test]
        fn quantized_round_trip(bits in 1u8..=16, code in any::<u16>()) {
            let q = Quantized { bits, min: -3.0, max: 7.5 };
            let code = u64::from(code) & q.max_code();
            prop_assert_eq!(q.encode(q.decode(code)), code);
        }

        #[test]
        fn crossover_children_take_each_bit_from_a_parent(seed in any::<u64>(), len in 1usize..=128) {
            let mut r = rng::seeded(seed);
            let a = Bits::random(len, &mut r).unwrap();
            let b = Bits::random(len, &mut r).unwrap();
            for child in [OnePoint.crossover(&a, &b, &mut r), Uniform.crossover(&a, &b, &mut r)] {
                prop_assert_eq!(child.len(), len);
                for i in 0..len {
                    prop_assert!(child.get(i) == a.get(i) || child.get(i) == b.get(i));
                }
                prop_assert_eq!(child.read(len, 64), 0, "no bits past the end");
            }
        }

        #[test]
        fn bit_flip_rate_extremes(seed in any::<u64>(), len in 0usize..=128) {
            let mut r = rng::seeded(seed);
            let a = Bits::random(len, &mut r).unwrap();
            let mut none = a;
            BitFlip { rate: 0.0 }.mutate(&mut none, &mut r);
            prop_assert_eq!(none, a);
            let mut all = a;
            BitFlip { rate: 1.0 }.mutate(&mut all, &mut r);
            prop_assert_eq!(all.hamming(&a) as usize, len);
        }
    }
}
