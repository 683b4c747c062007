//! PlantMaker: Gal, Mahal and Sipper's *Evolutionary Plantographics* (Artificial Life, 2004).
//!
//! Where each element of the paper is in Sylva, and where Sylva chose otherwise and why:
//! `docs/fidelity.md`.
//!
//! A [`PlantMaker`] genome holds n branch prototypes ([`Branch`], the paper's Table 1), m fans
//! ([`Fan`], Table 2) and k inflorescences ([`Inflorescence`], Table 3), plus a seed. The first
//! branch is the stem; a fan places copies of one branch prototype around a point; an
//! inflorescence places some fans at one height on the stem. Fans name a branch and
//! inflorescences name fans, so segments nobody names ("orphans") can exist: they are kept,
//! crossed and mutated, and do not change the plant. Defaults: n = 5 and m = 5 as in the
//! paper, and k = 5 inflorescences so that every fan can get a height of its own.
//!
//! - [`genes`]: the three segment kinds, their variables and ranges.
//! - [`packed`]: the paper's "string of numbers" face of a genome, one line per segment.
//! - [`palette`]: the colours a run's fans may take (any, or leaf greens and bark browns).
//! - [`develop`](mod@develop): genotype to phenotype, [`PlantMaker::develop`].
//! - [`variation`]: the three crossovers with dominance, mutation, the depth control, lineage.
//! - [`garden`]: many plants of one or more genomes placed on a plot without overlapping.
//! - [`problem`]: evolution without a person: the model's settings (the `[plantmaker]`
//!   config), Poncin's shared terms over the grown plant, generational breeding.
//! - [`vector`]: genomes as vectors of their codes, for optimisers outside Sylva.
//! - [`PlantMakerModel`]: the model as Sylva's [`Model`](sylva_model::Model) and
//!   [`Evolve`](sylva_model::Evolve).
//!
//! ```
//! use sylva_plantmaker::PlantMaker;
//!
//! let genome = PlantMaker::default();
//! let text = genome.to_json();
//! assert_eq!(PlantMaker::from_json(&text)?, genome);
//! assert_eq!(PlantMaker::from_packed(&genome.to_packed())?, genome);
//! let plant = genome.develop(genome.seed)?;
//! assert!(plant.height() > 0.5);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod develop;
pub mod garden;
pub mod genes;
pub mod packed;
pub mod palette;
pub mod problem;
pub mod variation;
pub mod vector;

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

pub use develop::{LEAF_RATIO, LENGTH_UNIT, MAX_PARTS, THICKNESS_UNIT};
pub use garden::{Garden, GardenError, GardenPlants, GrownGarden, Placement};
pub use genes::{
    Amount, Branch, BranchShape, Fan, FanSet, Inflorescence, Progression, Rgb, SegmentPattern,
    Tenths, Thickness,
};
pub use packed::PackedError;
pub use palette::{Painted, Palette};
pub use problem::{PlantMakerProblem, PlantMakerSettings, PlantMakerStrategy};
use sylva_model::GenomeError;
use sylva_model::{FormatV1, model_tag};
pub use variation::{Bred, Level, Mutation, Operator, Parent, PlantMakerCrossover, VariationError};

use genes::{
    BRANCH_VARIABLES, FAN_VARIABLES, INFLORESCENCE_VARIABLES, MAX_BRANCHES, MAX_FANS,
    MAX_INFLORESCENCES,
};

/// Model name in genome files.
pub const MODEL: &str = "plantmaker";

model_tag!(
    /// The `"model": "plantmaker"` header field.
    PlantMakerTag,
    MODEL
);

/// A PlantMaker genome: branch prototypes, fans, inflorescences and the seed.
///
/// Fields are public for building genomes in code; [`PlantMaker::check`] says whether such a
/// genome is legal (files and the packed face are checked when read).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "Unchecked")]
pub struct PlantMaker {
    /// Always `"plantmaker"`.
    pub model: PlantMakerTag,
    /// Always 1.
    pub format: FormatV1,
    /// Seeds the random choices of development (the paper's seed variable).
    pub seed: u64,
    /// Branch prototypes, 1 to 32; the first is the stem.
    pub branches: Vec<Branch>,
    /// Fans, 1 to 32.
    pub fans: Vec<Fan>,
    /// Inflorescences, 1 to 32.
    pub inflorescences: Vec<Inflorescence>,
}

/// The genome as read, before its cross-references are checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Unchecked {
    model: PlantMakerTag,
    format: FormatV1,
    seed: u64,
    branches: Vec<Branch>,
    fans: Vec<Fan>,
    inflorescences: Vec<Inflorescence>,
}

impl TryFrom<Unchecked> for PlantMaker {
    type Error = String;
    fn try_from(u: Unchecked) -> Result<Self, String> {
        let g = PlantMaker {
            model: u.model,
            format: u.format,
            seed: u.seed,
            branches: u.branches,
            fans: u.fans,
            inflorescences: u.inflorescences,
        };
        g.check()?;
        Ok(g)
    }
}

/// A plain branch for the defaults: straight, constant, no noise.
const fn plain_branch(segments: u8, length: u8, base: u8, apex: u8) -> Branch {
    Branch {
        segment_pattern: SegmentPattern::Straight,
        branch_shape: BranchShape::Straight,
        min_x_angle: 0,
        max_x_angle: 0,
        min_y_angle: 0,
        max_y_angle: 0,
        waves: 1,
        segment_count: Amount::Constant,
        min_segments: segments,
        max_segments: segments,
        thickness: Thickness::Thinner,
        min_base_thickness: apex,
        max_base_thickness: base,
        min_apex_thickness: apex,
        max_apex_thickness: base,
        length: Amount::Constant,
        min_length: length,
        max_length: length,
        noise: false,
        min_noise_x_angle: 0,
        max_noise_x_angle: 0,
        min_noise_y_angle: 0,
        max_noise_y_angle: 0,
    }
}

/// A plain fan for the defaults: constant everything.
const fn plain_fan(branch: u8, count: u8, angle: u16, color: [u8; 3]) -> Fan {
    Fan {
        branch,
        count,
        length_mode: Progression::Constant,
        min_length_factor: Tenths(10),
        max_length_factor: Tenths(10),
        angle_mode: Progression::Constant,
        min_angle: angle,
        max_angle: angle,
        thickness_mode: Progression::Constant,
        min_thickness_factor: Tenths(10),
        max_thickness_factor: Tenths(10),
        color_mode: Progression::Constant,
        min_color: Rgb(color),
        max_color: Rgb(color),
        texture: 0,
    }
}

impl Default for PlantMaker {
    /// A small sapling: a stem with two whorls of drooping, noisy branches and a crown of
    /// leaves; the fifth branch, fan and inflorescence are orphans.
    fn default() -> Self {
        let stem = Branch {
            noise: true,
            min_noise_x_angle: 356,
            max_noise_x_angle: 4,
            min_noise_y_angle: 356,
            max_noise_y_angle: 4,
            ..plain_branch(10, 12, 30, 8)
        };
        let twig = Branch {
            branch_shape: BranchShape::Curved,
            min_x_angle: 352,
            max_x_angle: 0,
            segment_count: Amount::Random,
            min_segments: 5,
            max_segments: 8,
            noise: true,
            min_noise_x_angle: 355,
            max_noise_x_angle: 5,
            min_noise_y_angle: 350,
            max_noise_y_angle: 10,
            ..plain_branch(6, 8, 10, 3)
        };
        let leaf = Branch {
            segment_pattern: SegmentPattern::Diamond,
            thickness: Thickness::Constant,
            min_base_thickness: 45,
            max_base_thickness: 45,
            min_apex_thickness: 2,
            max_apex_thickness: 2,
            ..plain_branch(1, 8, 45, 2)
        };
        let whorl = Fan {
            length_mode: Progression::Random,
            min_length_factor: Tenths(7),
            max_length_factor: Tenths(12),
            angle_mode: Progression::Random,
            min_angle: 20,
            max_angle: 40,
            ..plain_fan(2, 5, 30, [0x6b, 0x4a, 0x2f])
        };
        let crown = Fan {
            angle_mode: Progression::Alternating,
            min_angle: 10,
            max_angle: 70,
            color_mode: Progression::Random,
            min_color: Rgb([0x3d, 0x7a, 0x25]),
            max_color: Rgb([0x6f, 0x9e, 0x2c]),
            ..plain_fan(3, 9, 30, [0x3d, 0x7a, 0x25])
        };
        let inflorescence = |start_angle, position, fans: &[usize]| Inflorescence {
            start_angle,
            expressed: true,
            position,
            fans: FanSet::of(fans),
        };
        PlantMaker {
            model: PlantMakerTag,
            format: FormatV1,
            seed: 1,
            branches: vec![
                stem,
                twig,
                leaf,
                plain_branch(4, 10, 6, 2),
                plain_branch(3, 5, 20, 20),
            ],
            fans: vec![
                whorl,
                crown,
                plain_fan(2, 3, 60, [0x6b, 0x4a, 0x2f]),
                plain_fan(3, 6, 45, [0x3d, 0x7a, 0x25]),
                plain_fan(5, 4, 0, [0xc0, 0x30, 0x40]),
            ],
            inflorescences: vec![
                inflorescence(0, 45, &[1]),
                inflorescence(36, 70, &[1]),
                inflorescence(0, 100, &[2]),
                inflorescence(90, 85, &[4]),
                Inflorescence {
                    expressed: false,
                    ..inflorescence(0, 30, &[5])
                },
            ],
        }
    }
}

impl PlantMaker {
    /// Parses the JSON face; errors carry the line and column (cross-reference errors, such
    /// as a fan naming a missing branch, are found after the whole genome is read and point
    /// at its end, but name the segment and field).
    pub fn from_json(text: &str) -> Result<PlantMaker, GenomeError> {
        Ok(serde_json::from_str(text)?)
    }

    /// The JSON face, pretty-printed with a final newline; parsing it gives the same genome.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self)
            .expect("genomes hold only integers, strings and finite decimals");
        s.push('\n');
        s
    }

    /// Whether the genome is legal: segment counts, every code in its table's range, and
    /// every fan and branch reference pointing at an existing segment.
    pub fn check(&self) -> Result<(), String> {
        let (n, m, k) = (
            self.branches.len(),
            self.fans.len(),
            self.inflorescences.len(),
        );
        for (what, len, max) in [
            ("branches", n, MAX_BRANCHES),
            ("fans", m, MAX_FANS),
            ("inflorescences", k, MAX_INFLORESCENCES),
        ] {
            if !(1..=max).contains(&len) {
                return Err(format!(
                    "a genome has 1 to {max} {what}, this one has {len}"
                ));
            }
        }
        let fail = |kind: &str, i: usize, table: &[genes::Variable], e: genes::CodeError| {
            format!(
                "{kind} {}, variable {} (`{}`): {e}",
                i + 1,
                table[e.index].number,
                table[e.index].name
            )
        };
        for (i, b) in self.branches.iter().enumerate() {
            Branch::from_codes(&b.codes()).map_err(|e| fail("branch", i, &BRANCH_VARIABLES, e))?;
        }
        for (i, f) in self.fans.iter().enumerate() {
            Fan::from_codes(&f.codes(), n).map_err(|e| fail("fan", i, &FAN_VARIABLES, e))?;
        }
        for (i, f) in self.inflorescences.iter().enumerate() {
            Inflorescence::from_codes(&f.codes(), m)
                .map_err(|e| fail("inflorescence", i, &INFLORESCENCE_VARIABLES, e))?;
        }
        Ok(())
    }

    /// Size of the genome in bits as the tables count it, plus 64 for the seed.
    pub fn bit_length(&self) -> u32 {
        let (n, m) = (self.branches.len(), self.fans.len());
        let sum = |table: &[genes::Variable]| -> u32 { table.iter().map(|v| v.bits(n, m)).sum() };
        sum(&BRANCH_VARIABLES) * n as u32
            + sum(&FAN_VARIABLES) * m as u32
            + sum(&INFLORESCENCE_VARIABLES) * self.inflorescences.len() as u32
            + 64
    }

    /// A genome of `branches`, `fans` and `inflorescences` segments (each clamped to
    /// 1..=32) with every code drawn uniformly in its range, and a random seed.
    pub fn random<R: Rng + ?Sized>(
        branches: usize,
        fans: usize,
        inflorescences: usize,
        rng: &mut R,
    ) -> PlantMaker {
        let (n, m, k) = (
            branches.clamp(1, MAX_BRANCHES),
            fans.clamp(1, MAX_FANS),
            inflorescences.clamp(1, MAX_INFLORESCENCES),
        );
        fn draw<R: Rng + ?Sized, const N: usize>(
            table: &[genes::Variable; N],
            n: usize,
            m: usize,
            rng: &mut R,
        ) -> [u32; N] {
            std::array::from_fn(|i| {
                let (lo, hi) = table[i].range(n, m);
                rng.random_range(lo..=hi)
            })
        }
        PlantMaker {
            model: PlantMakerTag,
            format: FormatV1,
            seed: rng.random(),
            branches: (0..n)
                .map(|_| Branch::from_codes(&draw(&BRANCH_VARIABLES, n, m, rng)))
                .collect::<Result<_, _>>()
                .expect("codes drawn within their ranges"),
            fans: (0..m)
                .map(|_| Fan::from_codes(&draw(&FAN_VARIABLES, n, m, rng), n))
                .collect::<Result<_, _>>()
                .expect("codes drawn within their ranges"),
            inflorescences: (0..k)
                .map(|_| Inflorescence::from_codes(&draw(&INFLORESCENCE_VARIABLES, n, m, rng), m))
                .collect::<Result<_, _>>()
                .expect("codes drawn within their ranges"),
        }
    }

    /// Fans drawn by at least one expressed inflorescence (0-based), ascending.
    pub fn expressed_fans(&self) -> Vec<usize> {
        (0..self.fans.len())
            .filter(|&f| {
                self.inflorescences
                    .iter()
                    .any(|i| i.expressed && i.fans.contains(f + 1))
            })
            .collect()
    }

    /// Segments that do not affect the plant ("orphans"): branches no expressed fan uses
    /// (never the stem), fans no expressed inflorescence places, and unexpressed
    /// inflorescences. All 0-based.
    pub fn orphans(&self) -> Orphans {
        let fans = self.expressed_fans();
        let used: Vec<usize> = fans
            .iter()
            .map(|&f| usize::from(self.fans[f].branch) - 1)
            .collect();
        Orphans {
            branches: (1..self.branches.len())
                .filter(|b| !used.contains(b))
                .collect(),
            fans: (0..self.fans.len()).filter(|f| !fans.contains(f)).collect(),
            inflorescences: (0..self.inflorescences.len())
                .filter(|&i| !self.inflorescences[i].expressed)
                .collect(),
        }
    }
}

/// Segments of a genome that do not show in its plant (0-based indices).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Orphans {
    /// Branch prototypes no expressed fan uses.
    pub branches: Vec<usize>,
    /// Fans no expressed inflorescence places.
    pub fans: Vec<usize>,
    /// Inflorescences that are not expressed.
    pub inflorescences: Vec<usize>,
}

/// PlantMaker as a Sylva model. Genomes carry their own seed, which is the seed they grow
/// with unless another is given.
#[derive(Clone, Copy, Debug, Default)]
pub struct PlantMakerModel;

impl sylva_model::Model for PlantMakerModel {
    type Genome = PlantMaker;
    type Settings = PlantMakerSettings;
    const NAME: &'static str = MODEL;
    const TITLE: &'static str = "PlantMaker";

    fn develop(
        &self,
        genome: &PlantMaker,
        seed: u64,
    ) -> Result<sylva_core::Plant, sylva_model::DevelopError> {
        genome.develop(seed)
    }

    /// A random genome of the settings' sizes.
    fn random<R: Rng + ?Sized>(&self, s: &PlantMakerSettings, rng: &mut R) -> PlantMaker {
        s.random(rng)
    }

    /// The paper's mutation at the settings' rate and spread.
    fn mutate<R: Rng + ?Sized>(
        &self,
        g: &PlantMaker,
        s: &PlantMakerSettings,
        rng: &mut R,
    ) -> PlantMaker {
        let mut child = g.clone();
        sylva_evolve::Mutate::mutate(&s.mutation(), &mut child, rng);
        s.palette.apply(&mut child);
        child
    }

    /// The paper's own controls: the level is the crossover's (Figure 9), and Depth d
    /// mutates each variable with probability 0.05·d by noise of 0.05 + 0.02·d of its range
    /// (Depth 2: 0.1 and 0.09).
    fn packed(&self, genome: &PlantMaker) -> Option<String> {
        Some(genome.to_packed())
    }

    fn schema(&self) -> sylva_model::schema::Schema {
        genes::schema()
    }

    fn hand_settings(
        &self,
        knobs: sylva_model::Knobs,
        base: PlantMakerSettings,
    ) -> PlantMakerSettings {
        let d = f64::from(knobs.depth.get());
        PlantMakerSettings {
            crossover: match knobs.level {
                sylva_model::CrossLevel::Low => Level::Low,
                sylva_model::CrossLevel::Medium => Level::Medium,
                sylva_model::CrossLevel::High => Level::High,
            },
            mutation_rate: 0.05 * d,
            mutation_spread: 0.05 + 0.02 * d,
            ..base
        }
    }

    /// The paper's crossover of every parent, by dominance, at the settings' level.
    fn cross<R: Rng + ?Sized>(
        &self,
        parents: &[Parent<'_>],
        s: &PlantMakerSettings,
        rng: &mut R,
    ) -> Result<sylva_model::Bred<PlantMaker>, VariationError> {
        let mut bred = variation::crossover(parents, s.crossover, rng)?;
        s.palette.apply(&mut bred.genome);
        Ok(sylva_model::Bred {
            genome: bred.genome,
            parents: bred.parents,
        })
    }

    fn default_seed(&self, genome: &PlantMaker) -> u64 {
        genome.seed
    }

    fn with_seed(&self, genome: &PlantMaker, seed: u64) -> PlantMaker {
        PlantMaker {
            seed,
            ..genome.clone()
        }
    }
}

impl sylva_model::Evolve for PlantMakerModel {
    type Problem = PlantMakerProblem;
    type Strategy = PlantMakerStrategy;

    /// Most offspring are mutants that move less than the paper's, the five best are kept,
    /// and colours keep to leaf greens and bark browns ([`Palette::Foliage`]): the outline
    /// cannot see colour, and left to drift a match's leaves came out blue, purple and red.
    /// Measured on the tuning outlines (`examples/match`, docs/match.md), the outline term's
    /// mean rose from 0.731 to 0.828 (40 s a target).
    fn fitting(&self, settings: &mut PlantMakerSettings) {
        settings.mutation_spread = 0.05;
        settings.palette = Palette::Foliage;
        settings.breeding = sylva_evolve::GenerationalSettings::mostly_mutants();
    }

    fn start_files(&self, settings: &PlantMakerSettings) -> Vec<std::path::PathBuf> {
        settings.start.clone()
    }

    fn setup(
        &self,
        settings: &PlantMakerSettings,
        start: Vec<PlantMaker>,
        seed: u64,
        population: usize,
    ) -> Result<sylva_model::Setup<Self>, sylva_model::ConfigError> {
        let strategy = problem::strategy(settings)
            .map_err(|e| sylva_model::ConfigError::new("breeding", e))?;
        let mut start_counts: Vec<[usize; 3]> = Vec::new();
        for g in &start {
            let counts = [g.branches.len(), g.fans.len(), g.inflorescences.len()];
            if !start_counts.contains(&counts) {
                start_counts.push(counts);
            }
        }
        Ok(sylva_model::Setup {
            problem: PlantMakerProblem {
                settings: settings.clone(),
                start_counts,
            },
            strategy,
            first: problem::first_generation(settings, start, seed, population),
        })
    }

    fn genome_file(&self, _problem: &PlantMakerProblem, genome: &PlantMaker) -> PlantMaker {
        genome.clone()
    }

    /// The tables' codes ([`vector::CodeCoding`]) at the segment counts every genome of
    /// the run has (the start genomes', else the settings'), or, where the start genomes'
    /// differ, with the counts as entries up to the most of each; decoded genomes grow
    /// with `seed`.
    fn vector_coding(
        &self,
        problem: &PlantMakerProblem,
        seed: u64,
    ) -> Option<Box<dyn sylva_model::VectorCoding<Self>>> {
        let s = &problem.settings;
        let own = [s.branches, s.fans, s.inflorescences].map(|c| c as usize);
        let coding = match problem.start_counts.as_slice() {
            [] => vector::CodeCoding::new(own[0], own[1], own[2], seed),
            [one] => vector::CodeCoding::new(one[0], one[1], one[2], seed),
            many => {
                let most = |i: usize| many.iter().map(|c| c[i]).max().unwrap_or(own[i]);
                vector::CodeCoding::up_to(most(0), most(1), most(2), seed)
            }
        };
        Some(Box::new(coding))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_legal_and_has_orphans() {
        let g = PlantMaker::default();
        g.check().unwrap();
        let o = g.orphans();
        assert_eq!(o.branches, vec![3, 4]);
        assert_eq!(o.fans, vec![2, 4]);
        assert_eq!(o.inflorescences, vec![4]);
    }

    #[test]
    fn json_errors_name_the_field_and_range() {
        let text = PlantMaker::default().to_json().replacen(
            "\"min_segments\": 10",
            "\"min_segments\": 300",
            1,
        );
        let e = PlantMaker::from_json(&text).unwrap_err();
        assert!(
            e.message
                .contains("`min_segments` must be a whole number from 1 to 128"),
            "{e}"
        );
        assert!(e.line > 1 && e.column > 0);
        let text = PlantMaker::default().to_json().replacen(
            "\"segment_pattern\": \"straight\"",
            "\"segment_pattern\": \"wavy\"",
            1,
        );
        let e = PlantMaker::from_json(&text).unwrap_err();
        assert!(e.message.contains("diamond"), "{e}");
        let text = PlantMaker::default()
            .to_json()
            .replacen("\"branch\": 2", "\"branch\": 9", 1);
        let e = PlantMaker::from_json(&text).unwrap_err();
        assert!(e.message.contains("fan 1, variable 1 (`branch`)"), "{e}");
        assert!(e.message.contains("expected 1 to 5"), "{e}");
    }
}
