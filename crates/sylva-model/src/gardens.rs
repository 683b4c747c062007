//! Gardens and forests, a capability a model may offer ([`Gardens`]): many plants of a few
//! genomes on one plot, planned in a garden file that grows the same scene again
//! (PlantMaker's, after Gal, Mahal and Sipper). The model plans, places and grows the
//! plants ([`GardenPlan`]); the library's `garden` module estimates the scene, meshes it or
//! streams it as a GLB, for whichever model says, in its registry line, that it offers this.

use sylva_core::Plant;
use sylva_core::glam::{Quat, Vec3};

use crate::{DevelopError, GenomeError, Model};

/// Most plants in a garden.
pub const MAX_PLANTS: usize = 100_000;

/// Where one plant of a garden stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Index of its genome in the garden.
    pub group: usize,
    /// Index of its seed in that genome's seeds.
    pub index: usize,
    /// The seed it grows from.
    pub seed: u64,
    /// Its plant in [`GrownGarden::plants`] (shared by the plants of one variant).
    pub plant: usize,
    /// Where its base stands (y = 0), metres.
    pub translation: Vec3,
    /// Its turn about +Y, radians.
    pub yaw: f32,
    /// Radius of its footprint about its base, metres.
    pub radius: f32,
}

impl Placement {
    /// The turn as a quaternion, for a scene node.
    pub fn rotation(&self) -> Quat {
        Quat::from_rotation_y(self.yaw)
    }
}

/// A grown garden: plants and their placements, in file order (genome by genome, seed by
/// seed). Without variants there is one plant per placement, in the same order; with
/// variants, one per variant, which the placements share.
#[derive(Clone, Debug, PartialEq)]
pub struct GrownGarden {
    /// Where each plant stands.
    pub placements: Vec<Placement>,
    /// The plants, in their own coordinates (base at the origin), like `placements`.
    pub plants: Vec<Plant>,
}

/// Why a garden could not be grown.
#[derive(Debug, thiserror::Error)]
pub enum GardenError {
    /// The garden has no plants.
    #[error("the garden has no plants")]
    Empty,
    /// More plants than [`MAX_PLANTS`].
    #[error("the garden has {0} plants; at most {MAX_PLANTS}")]
    TooManyPlants(usize),
    /// The plants would not fit in the memory budget.
    #[error("the garden does not fit in memory")]
    OverBudget(#[from] sylva_core::budget::OverBudget),
    /// A plant could not be grown.
    #[error("plant {index} of genome {group} could not be grown")]
    Develop {
        /// Its genome.
        group: usize,
        /// Its seed's index.
        index: usize,
        /// Why.
        source: DevelopError,
    },
    /// A plant's footprint is wider than the plot.
    #[error(
        "plant {index} of genome {group} needs a circle {diameter:.2} m across, wider than the {width} x {depth} m plot"
    )]
    TooWide {
        /// Its genome.
        group: usize,
        /// Its seed's index.
        index: usize,
        /// Its footprint's diameter, metres.
        diameter: f32,
        /// Plot width, metres.
        width: f64,
        /// Plot depth, metres.
        depth: f64,
    },
    /// The plot is too crowded: a plant found no free spot.
    #[error(
        "only {placed} of {count} plants fit on the plot ({tries} tries each); enlarge the area or plant fewer"
    )]
    DoesNotFit {
        /// Plants placed before one found no spot (largest first).
        placed: usize,
        /// Plants in the garden.
        count: usize,
        /// Darts per plant.
        tries: u32,
    },
}

/// A garden as its file holds it: genomes, each with one seed per plant, the plot, and how
/// its scene is laid out.
pub trait GardenPlan: Clone + Send + Sync + 'static {
    /// The genomes it plants.
    type Genome;

    /// Adds `count` plants of another genome.
    fn add(&mut self, genome: Self::Genome, count: usize);
    /// Number of plants.
    fn count(&self) -> usize;
    /// The genomes planted, each with its plants' seeds, in file order.
    fn groups(&self) -> Vec<(&Self::Genome, &[u64])>;
    /// Grow only this many seeds of each genome and make every plant one of them (a forest
    /// of variants), or every plant its own seed (`None`).
    fn variants(&self) -> Option<u32>;
    /// Sets [`GardenPlan::variants`].
    fn set_variants(&mut self, variants: Option<u32>);
    /// Whether a forest of variants is written as GPU instances (`None`: the default, yes).
    fn instancing(&self) -> Option<bool>;
    /// Sets [`GardenPlan::instancing`].
    fn set_instancing(&mut self, instancing: Option<bool>);
    /// Whether its GLB quantises positions and normals.
    fn quantize(&self) -> bool;
    /// Sets [`GardenPlan::quantize`].
    fn set_quantize(&mut self, quantize: bool);
    /// The garden file, pretty-printed with a final newline.
    fn to_json(&self) -> String;
    /// Grows every plant and places them.
    fn grow(&self) -> Result<GrownGarden, GardenError>;
    /// Where every plant stands, as [`GardenPlan::grow`] places them, without keeping the
    /// plants.
    fn placements(&self) -> Result<Vec<Placement>, GardenError>;
    /// The plant of `placement` (one of this garden's), grown again.
    fn develop(&self, placement: &Placement) -> Result<Plant, GardenError>;
}

/// A model whose plants grow in gardens and forests. It says so in its registry line
/// (`ModelEntry::of::<M>().with_gardens()`), and the library's garden module finds it there.
pub trait Gardens: Model {
    /// Its garden files.
    type Garden: GardenPlan<Genome = Self::Genome>;

    /// The `model` its garden files name (`"plantmaker-garden"`), which tells them from
    /// genome files.
    const GARDEN_FILE: &'static str;

    /// Reads a garden file; errors carry the line and column.
    fn read_garden(text: &str) -> Result<Self::Garden, GenomeError>;

    /// A new garden of `count` plants of `genome` on a plot `area` = (width, depth) metres
    /// centred on the origin, their seeds, places and turns drawn from `seed`.
    fn new_garden(genome: Self::Genome, count: usize, area: [f64; 2], seed: u64) -> Self::Garden;
}
