//! PlantMaker genomes as vectors ([`CodeCoding`]), for optimisers outside Sylva: the codes
//! of the paper's tables, the numbers of the packed face, one entry each, segment by
//! segment (the n branches' 23 codes, the m fans' 15, the k inflorescences' 4), except
//! that a colour is three entries (red, green, blue, 0 to 255) and an inflorescence's fan
//! set one entry per fan (1: the fan is placed), so that nearby vectors are similar
//! plants. An option is its table code (an inflorescence's `expressed` is 0 for yes, as in
//! Table 3).
//!
//! Each entry rounds to the nearest code, and its bounds reach half a code past the
//! variable's range, so every code owns an equal stretch and a uniform vector draws every
//! code alike. The genome's own seed, which only reseeds its growth, is not an entry:
//! decoded genomes take the coding's seed.
//!
//! Segment counts: where every genome of a run has the same (its start genomes', else the
//! settings' `branches`, `fans` and `inflorescences`), the vector holds that many segments
//! ([`CodeCoding::new`]). Where they differ (a map started from the five examples, whose
//! crossovers mix their counts), the vector starts with the three counts, each from 1 to the
//! most any start genome has, and holds that most of each segment; a genome fills the first
//! slots and the rest are written as their lowest codes and never read
//! ([`CodeCoding::up_to`]), so every genome of the run has a vector and decodes back to
//! itself.

use sylva_model::VectorCoding;

use crate::genes::{
    BRANCH_VARIABLES, Branch, FAN_VARIABLES, Fan, FanSet, GeneKind, INFLORESCENCE_VARIABLES,
    Inflorescence, Variable, mask_of,
};
use crate::{FormatV1, PlantMaker, PlantMakerModel, PlantMakerTag};

/// PlantMaker's codes as a vector.
#[derive(Clone, Debug, PartialEq)]
pub struct CodeCoding {
    /// Slots for branches, fans and inflorescences: a genome's counts, or the most.
    branches: usize,
    fans: usize,
    inflorescences: usize,
    /// Whether the counts vary: the vector then starts with them.
    counted: bool,
    seed: u64,
    bounds: Vec<[f64; 2]>,
}

/// The bounds of the codes `lo..=hi`: half a code beyond each end.
fn bounds(lo: u32, hi: u32) -> [f64; 2] {
    [f64::from(lo) - 0.5, f64::from(hi) + 0.5]
}

/// The code an entry stands for: the nearest whole number in `lo..=hi`.
fn code(x: f64, lo: u32, hi: u32) -> u32 {
    // Casting saturates: far below the range (and NaN, which callers refuse) gives 0.
    ((x + 0.5).floor().max(0.0) as u32).clamp(lo, hi)
}

impl CodeCoding {
    /// The coding of genomes of `branches`, `fans` and `inflorescences` segments (each
    /// clamped to 1..=32, as [`PlantMaker::random`] does), decoded with growth seed `seed`.
    pub fn new(branches: usize, fans: usize, inflorescences: usize, seed: u64) -> CodeCoding {
        CodeCoding::with(branches, fans, inflorescences, false, seed)
    }

    /// The coding of genomes of 1 to `branches`, `fans` and `inflorescences` segments (each
    /// clamped to 1..=32): three entries for the counts, then that many slots of each.
    pub fn up_to(branches: usize, fans: usize, inflorescences: usize, seed: u64) -> CodeCoding {
        CodeCoding::with(branches, fans, inflorescences, true, seed)
    }

    fn with(
        branches: usize,
        fans: usize,
        inflorescences: usize,
        counted: bool,
        seed: u64,
    ) -> CodeCoding {
        let (n, m, k) = (
            branches.clamp(1, crate::MAX_BRANCHES),
            fans.clamp(1, crate::MAX_FANS),
            inflorescences.clamp(1, crate::MAX_INFLORESCENCES),
        );
        let mut all = Vec::new();
        if counted {
            all.extend([n, m, k].map(|most| bounds(1, most as u32)));
        }
        // A slot's ranges are those of the most segments: a genome with fewer has codes
        // within them.
        for _ in 0..n {
            all.extend(BRANCH_VARIABLES.iter().map(|v| {
                let (lo, hi) = v.range(n, m);
                bounds(lo, hi)
            }));
        }
        for _ in 0..m {
            for v in &FAN_VARIABLES {
                match v.kind {
                    GeneKind::Color => all.extend([bounds(0, 255); 3]),
                    _ => {
                        let (lo, hi) = v.range(n, m);
                        all.push(bounds(lo, hi));
                    }
                }
            }
        }
        for _ in 0..k {
            for v in &INFLORESCENCE_VARIABLES {
                match v.kind {
                    GeneKind::FanSet => all.extend(std::iter::repeat_n(bounds(0, 1), m)),
                    _ => {
                        let (lo, hi) = v.range(n, m);
                        all.push(bounds(lo, hi));
                    }
                }
            }
        }
        CodeCoding {
            branches: n,
            fans: m,
            inflorescences: k,
            counted,
            seed,
            bounds: all,
        }
    }

    /// Reads `N` codes of `table` from a slot of `x` (advancing it), for a genome of `n`
    /// branches and `m` fans: a branch number past `n` is read as `n`, and a fan set keeps
    /// the first `m` fans.
    fn codes<const N: usize>(
        &self,
        table: &[Variable; N],
        x: &mut &[f64],
        (n, m): (usize, usize),
    ) -> [u32; N] {
        std::array::from_fn(|i| {
            let v = &table[i];
            let (lo, hi) = v.range(n, m);
            match v.kind {
                GeneKind::Color => {
                    let rgb = take(x, 3);
                    rgb.iter().fold(0, |c, e| (c << 8) | code(*e, 0, 255))
                }
                GeneKind::FanSet => {
                    let bits = take(x, self.fans);
                    let set = (bits.iter().enumerate())
                        .fold(0, |set, (f, e)| set | (code(*e, 0, 1) << f));
                    set & mask_of(m)
                }
                _ => code(take(x, 1)[0], lo, hi),
            }
        })
    }

    /// The entries of a slot no segment fills: each variable's lowest code.
    fn unused(&self, table: &[Variable], out: &mut Vec<f64>) {
        for v in table {
            match v.kind {
                GeneKind::Color => out.extend([0.0; 3]),
                GeneKind::FanSet => out.extend(std::iter::repeat_n(0.0, self.fans)),
                _ => out.push(f64::from(v.range(self.branches, self.fans).0)),
            }
        }
    }
}

/// The first `count` entries of `x`, which moves past them.
fn take<'a>(x: &mut &'a [f64], count: usize) -> &'a [f64] {
    let (head, rest) = x.split_at(count);
    *x = rest;
    head
}

/// Writes `codes` of `table` as entries (colours as channels, fan sets as one entry per
/// fan of `fans`).
fn entries(codes: &[u32], table: &[Variable], fans: usize, out: &mut Vec<f64>) {
    for (c, v) in codes.iter().zip(table) {
        match v.kind {
            GeneKind::Color => out.extend([c >> 16, (c >> 8) & 255, c & 255].map(f64::from)),
            GeneKind::FanSet => {
                out.extend((1..=fans).map(|f| f64::from(u8::from(FanSet(*c).contains(f)))));
            }
            _ => out.push(f64::from(*c)),
        }
    }
}

impl VectorCoding<PlantMakerModel> for CodeCoding {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.bounds
    }

    fn decode(&self, x: &[f64]) -> PlantMaker {
        let mut rest = x;
        let (n, m, k) = if self.counted {
            let c = take(&mut rest, 3);
            let count = |e: f64, most: usize| code(e, 1, most as u32) as usize;
            (
                count(c[0], self.branches),
                count(c[1], self.fans),
                count(c[2], self.inflorescences),
            )
        } else {
            (self.branches, self.fans, self.inflorescences)
        };
        let legal = "codes are rounded into their ranges";
        // Every slot is read, to move past it; those beyond the genome's counts are dropped.
        let mut branches: Vec<Branch> = (0..self.branches)
            .map(|_| {
                Branch::from_codes(&self.codes(&BRANCH_VARIABLES, &mut rest, (n, m))).expect(legal)
            })
            .collect();
        let mut fans: Vec<Fan> = (0..self.fans)
            .map(|_| {
                let codes = self.codes(&FAN_VARIABLES, &mut rest, (n, m));
                Fan::from_codes(&codes, n).expect(legal)
            })
            .collect();
        let mut inflorescences: Vec<Inflorescence> = (0..self.inflorescences)
            .map(|_| {
                let codes = self.codes(&INFLORESCENCE_VARIABLES, &mut rest, (n, m));
                Inflorescence::from_codes(&codes, m).expect(legal)
            })
            .collect();
        branches.truncate(n);
        fans.truncate(m);
        inflorescences.truncate(k);
        PlantMaker {
            model: PlantMakerTag,
            format: FormatV1,
            seed: self.seed,
            branches,
            fans,
            inflorescences,
        }
    }

    fn encode(&self, genome: &PlantMaker) -> Result<Vec<f64>, String> {
        let counts = (
            genome.branches.len(),
            genome.fans.len(),
            genome.inflorescences.len(),
        );
        let most = (self.branches, self.fans, self.inflorescences);
        let fits = if self.counted {
            (1..=most.0).contains(&counts.0)
                && (1..=most.1).contains(&counts.1)
                && (1..=most.2).contains(&counts.2)
        } else {
            counts == most
        };
        if !fits {
            return Err(format!(
                "the genome has {} branches, {} fans and {} inflorescences; this space's \
                 genomes have {}{}, {} and {} (the start genomes', else the settings' \
                 `branches`, `fans` and `inflorescences`)",
                counts.0,
                counts.1,
                counts.2,
                if self.counted { "1 to " } else { "" },
                most.0,
                most.1,
                most.2
            ));
        }
        let mut out = Vec::with_capacity(self.bounds.len());
        if self.counted {
            out.extend([counts.0, counts.1, counts.2].map(|c| c as f64));
        }
        for slot in 0..self.branches {
            match genome.branches.get(slot) {
                Some(b) => entries(&b.codes(), &BRANCH_VARIABLES, self.fans, &mut out),
                None => self.unused(&BRANCH_VARIABLES, &mut out),
            }
        }
        for slot in 0..self.fans {
            match genome.fans.get(slot) {
                Some(f) => entries(&f.codes(), &FAN_VARIABLES, self.fans, &mut out),
                None => self.unused(&FAN_VARIABLES, &mut out),
            }
        }
        for slot in 0..self.inflorescences {
            match genome.inflorescences.get(slot) {
                Some(i) => entries(&i.codes(), &INFLORESCENCE_VARIABLES, self.fans, &mut out),
                None => self.unused(&INFLORESCENCE_VARIABLES, &mut out),
            }
        }
        debug_assert_eq!(out.len(), self.bounds.len());
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Entries of a fan: its 15 codes with each of its two colours as three channels.
    const FAN_ENTRIES: usize = FAN_VARIABLES.len() + 4;

    fn lower(c: &CodeCoding) -> Vec<f64> {
        c.bounds().iter().map(|b| b[0]).collect()
    }

    #[test]
    fn the_vector_holds_every_code_and_decodes_back() {
        let coding = CodeCoding::new(5, 5, 5, 1);
        assert_eq!(
            coding.bounds().len(),
            5 * 23 + 5 * FAN_ENTRIES + 5 * (3 + 5)
        );
        let tulip = PlantMaker::default();
        let x = coding.encode(&tulip).unwrap();
        assert_eq!(x.len(), coding.bounds().len());
        assert_eq!(coding.decode(&x), tulip);
        let mut rng = sylva_core::rng::seeded(9);
        for _ in 0..100 {
            let g = PlantMaker::random(5, 5, 5, &mut rng);
            let x = coding.encode(&g).unwrap();
            assert!(
                x.iter()
                    .zip(coding.bounds())
                    .all(|(v, [lo, hi])| lo < v && v < hi)
            );
            assert_eq!(coding.decode(&x), PlantMaker { seed: 1, ..g });
        }
    }

    #[test]
    fn the_ends_of_the_bounds_decode_to_legal_genomes() {
        let coding = CodeCoding::new(3, 4, 2, 7);
        let low = coding.decode(&lower(&coding));
        low.check().unwrap();
        assert_eq!(low.fans[0].branch, 1);
        assert!(
            low.inflorescences
                .iter()
                .all(|i| i.fans == FanSet(0) && i.expressed)
        );
        let x: Vec<f64> = coding.bounds().iter().map(|b| b[1]).collect();
        let high = coding.decode(&x);
        high.check().unwrap();
        assert_eq!(high.fans[0].branch, 3);
        assert_eq!(high.fans[0].min_color.code(), 0xff_ffff);
        assert!(high.inflorescences.iter().all(|i| i.fans == FanSet(0b1111)));
        assert_eq!(high.seed, 7);
    }

    #[test]
    fn other_segment_counts_are_refused_by_name() {
        let coding = CodeCoding::new(4, 5, 5, 1);
        let e = coding.encode(&PlantMaker::default()).unwrap_err();
        assert!(e.contains("5 branches") && e.contains("`branches`"), "{e}");
    }

    #[test]
    fn genomes_of_varying_counts_have_vectors_that_decode_back() {
        // The five examples: 5 branches each, 5 or 7 fans, 5, 6 or 18 inflorescences.
        let coding = CodeCoding::up_to(5, 7, 18, 3);
        assert_eq!(
            coding.bounds().len(),
            3 + 5 * 23 + 7 * FAN_ENTRIES + 18 * (3 + 7)
        );
        let mut rng = sylva_core::rng::seeded(4);
        for (n, m, k) in [(5, 5, 6), (5, 7, 18), (1, 1, 1), (3, 7, 2), (5, 2, 18)] {
            for _ in 0..20 {
                let g = PlantMaker::random(n, m, k, &mut rng);
                let x = coding.encode(&g).unwrap();
                assert_eq!(x.len(), coding.bounds().len());
                assert!(
                    x.iter()
                        .zip(coding.bounds())
                        .all(|(v, [lo, hi])| lo < v && v < hi)
                );
                assert_eq!(coding.decode(&x), PlantMaker { seed: 3, ..g });
            }
        }
        // Any vector decodes to a legal genome, whatever its counts say.
        for _ in 0..50 {
            let x: Vec<f64> = coding
                .bounds()
                .iter()
                .map(|[lo, hi]| rand::RngExt::random_range(&mut rng, *lo..*hi))
                .collect();
            let g = coding.decode(&x);
            g.check().unwrap();
            assert_eq!(coding.decode(&coding.encode(&g).unwrap()), g);
        }
        let e = coding
            .encode(&PlantMaker::random(6, 5, 5, &mut rng))
            .unwrap_err();
        assert!(e.contains("6 branches") && e.contains("1 to 5"), "{e}");
    }
}
