//! Biomorph gardens, a capability a model may offer ([`Biomorphs`]): a mother and her
//! mutated children sown on one plot of a shared world and grown together, shading each
//! other, for a person to pick the next mother from what grew (Bornhofen and Lattaud's
//! design loop, section 4.1). The library's `biomorph` module runs the loop for whichever
//! model says, in its registry line, that it offers this.

use std::error::Error;

use sylva_core::Plant;
use sylva_core::glam::Vec3;
use sylva_core::par::Pool;

use crate::{Model, Work};

/// How a biomorph garden is laid out and grown. The defaults are the paper's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiomorphSettings {
    /// Children sown with the mother, 0 to 8. Default 8.
    pub children: u32,
    /// Steps to grow. Default 150.
    pub steps: u32,
    /// Metres between neighbouring seeds. Default 2.5.
    pub spacing: f32,
    /// The light's height above the horizon, degrees. Default 90 (straight down).
    pub elevation: f64,
    /// The compass direction the light comes from, degrees. Default 0.
    pub azimuth: f64,
    /// Mutate children of a mother whose shoot draws nothing until theirs draws something,
    /// so a person breeding by eye has something to see. Default false (the paper's loop).
    pub visible_children: bool,
}

impl Default for BiomorphSettings {
    fn default() -> Self {
        BiomorphSettings {
            children: 8,
            steps: 150,
            spacing: 2.5,
            elevation: 90.0,
            azimuth: 0.0,
            visible_children: false,
        }
    }
}

/// What a specimen achieved in its garden: the figures a person breeding by eye reads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpecimenStats {
    /// Biomass (dry mass) at the end, grams.
    pub biomass: f64,
    /// Light absorbed over its life.
    pub light: f64,
    /// Minerals taken up over its life, grams.
    pub uptake: f64,
    /// Leaves it has.
    pub leaves: u32,
    /// Fine roots it has.
    pub fine_roots: u32,
    /// True when it grew at least one part.
    pub germinated: bool,
    /// Growth its model's bounds refused.
    pub bounds: BoundsHit,
}

/// Growth a model's bounds refused while a specimen grew (an L-system's rewrites refused by
/// its symbol and module limits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct BoundsHit {
    /// Refused by the limit on the genome's size (an L-system's symbols).
    pub symbols: u32,
    /// Refused by the limit on the plant's parts (an L-system's modules).
    pub modules: u32,
    /// The first step (1-based) a bound was hit, if ever.
    pub first_step: Option<u32>,
}

impl BoundsHit {
    /// True when some growth was refused.
    pub fn any(&self) -> bool {
        self.symbols > 0 || self.modules > 0
    }
}

/// One grown specimen of a biomorph garden.
#[derive(Clone, Debug)]
pub struct Specimen<G> {
    /// Its genome.
    pub genome: G,
    /// True for the mother's own seed.
    pub is_mother: bool,
    /// Where its foot stands, metres (y = 0).
    pub position: Vec3,
    /// Its geometry, foot at the origin.
    pub plant: Plant,
    /// The figures it ended with.
    pub stats: SpecimenStats,
}

/// A model whose plants grow in biomorph gardens. It says so in its registry line
/// (`ModelEntry::of::<M>().with_biomorphs()`), and the library's biomorph loop finds it
/// there.
pub trait Biomorphs: Model {
    /// What a person changes to grow smaller plants, when a garden's scene is too large
    /// to write (said in the error, after "grow smaller plants").
    const SMALLER: &'static str;

    /// The genome a garden starts from when a person brings none (the L-system's paper
    /// starts from empty rules, from which breeding builds a plant).
    fn first_mother(&self) -> Self::Genome;

    /// The mother (first) and `settings.children` children mutated from her with the
    /// stream of `seed`.
    fn sow(
        &self,
        mother: &Self::Genome,
        settings: &BiomorphSettings,
        seed: u64,
    ) -> Vec<Self::Genome>;

    /// The work of growing `genomes` together, at their bounds, before the first step.
    fn biomorph_work(&self, genomes: &[Self::Genome], settings: &BiomorphSettings) -> Work;

    /// Grows `genomes` together on `pool` (the first in a corner, as [`Biomorphs::sow`]
    /// hands them), calling `on_step` with the steps done; refused before the first step
    /// when it would take longer than the time budget.
    fn grow_together(
        &self,
        genomes: Vec<Self::Genome>,
        settings: &BiomorphSettings,
        pool: &Pool,
        on_step: &mut dyn FnMut(u32),
    ) -> Result<Vec<Specimen<Self::Genome>>, Box<dyn Error + Send + Sync>>;
}
