//! Gardens and forests: many plants of one or more genomes on a rectangular plot.
//!
//! The paper: "in order to recreate the garden one need only store the (single) genome
//! prototype along with all the seeds". A [`Garden`] file holds exactly that: each genome
//! with its list of seeds, the plot's size, and a placement seed. [`Garden::grow`] grows
//! every plant and places it with [`place`], so the same file always gives the same plants
//! at the same spots, turned the same way.
//!
//! **Placement** is dart throwing (a Poisson-disc-like scatter): each plant's footprint is
//! the circle about its base that holds it seen from above ([`footprint`]; it may turn
//! freely);
//! plants are placed largest first, each at the first of up to `max_tries` uniform random
//! spots on the plot where its circle lies inside the plot and overlaps no circle placed
//! before; then it is turned about Y by a random angle. Darts come from one ChaCha8 stream of
//! the placement seed. If a plant finds no spot, placement fails and says how many fitted.
//!
//! ```
//! use sylva_plantmaker::{Garden, PlantMaker};
//!
//! let garden = Garden::new(PlantMaker::default(), 6, [8.0, 8.0], 7);
//! let grown = garden.grow()?;
//! assert_eq!(grown.plants.len(), 6);
//! let again = Garden::from_json(&garden.to_json())?.grow()?;
//! assert_eq!(grown.placements, again.placements);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::f32::consts::TAU;

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sylva_core::Plant;
use sylva_core::glam::{Vec2, Vec3};

use crate::{PlantMaker, PlantMakerModel};
use sylva_model::GenomeError;
use sylva_model::gardens::{GardenPlan, Gardens};
use sylva_model::{FormatV1, model_tag};

/// Model name of garden files.
pub const GARDEN_MODEL: &str = "plantmaker-garden";

model_tag!(
    /// The `"model": "plantmaker-garden"` header field.
    GardenTag,
    GARDEN_MODEL
);

/// Darts per plant when a file does not say.
pub const DEFAULT_TRIES: u32 = 1000;

fn default_tries() -> u32 {
    DEFAULT_TRIES
}

sylva_core::ranged!(max_tries: u32, "max_tries", 1, 1_000_000);

sylva_core::ranged!(area: [f64; 2], "area", 0.1, 100_000.0, " m (width and depth)");

/// A garden file: genomes with their seeds, the plot, and the placement seed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Garden {
    /// Always `"plantmaker-garden"`.
    pub model: GardenTag,
    /// Always 1.
    pub format: FormatV1,
    /// Width (along x) and depth (along z) of the plot, metres, centred on the origin.
    #[serde(deserialize_with = "area")]
    pub area: [f64; 2],
    /// Seeds the positions and turns of the plants.
    pub placement_seed: u64,
    /// Darts thrown per plant before giving up, 1 to 1 000 000. Default 1000.
    #[serde(default = "default_tries", deserialize_with = "max_tries")]
    pub max_tries: u32,
    /// The genomes, each with one seed per plant.
    pub plants: Vec<GardenPlants>,
    /// Grow only the first `variants` seeds of each genome, 1 to 1000, and make every
    /// plant of it one of those (plant `i` is variant `i mod variants`), so a scene holds a
    /// few meshes placed many times. Absent (the default): every plant its own seed.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "some_variants"
    )]
    pub variants: Option<u32>,
    /// How the garden's GLB draws a forest of variants: one node per variant with
    /// `EXT_mesh_gpu_instancing` (absent or `true`, the default), or each plant as a plain
    /// node sharing its variant's mesh (`false`). Growing ignores it; Sylva's GLB export
    /// reads it, so that the file gives the same bytes again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instancing: Option<bool>,
    /// Whether the garden's GLB quantises positions and normals (`KHR_mesh_quantization`).
    /// Absent: no. Growing ignores it, as it does `instancing`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub quantize: bool,
}

sylva_core::ranged!(variants: u32, "variants", 1, 1000);

fn some_variants<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
    variants(d).map(Some)
}

/// Plants of one genome: one per seed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GardenPlants {
    /// The genome.
    pub genome: PlantMaker,
    /// One seed per plant.
    pub seeds: Vec<u64>,
}

// Where plants stand, grown gardens, their errors and limit are any model's
// (`sylva_model::gardens`); PlantMaker's gardens plan, place and grow them.
pub use sylva_model::gardens::{GardenError, GrownGarden, MAX_PLANTS, Placement};

/// Bytes a grown plant holds.
fn plant_bytes(plant: &Plant) -> u64 {
    (std::mem::size_of_val(plant.segments()) + std::mem::size_of_val(plant.organs())) as u64
}

/// A plant that found no spot, by index in the radii given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoRoom {
    /// Index of the plant that found no spot.
    pub plant: usize,
    /// How many had been placed.
    pub placed: usize,
}

/// Scatters circles of the given radii on a `width` x `depth` plot centred on the origin
/// without overlaps (see the [module docs](self)). Returns each circle's centre (x, z) and
/// turn, in the order given.
pub fn place(
    radii: &[f32],
    [width, depth]: [f32; 2],
    seed: u64,
    max_tries: u32,
) -> Result<Vec<(Vec2, f32)>, NoRoom> {
    let mut order: Vec<usize> = (0..radii.len()).collect();
    order.sort_by(|&a, &b| radii[b].total_cmp(&radii[a]));
    let largest = radii.iter().copied().fold(0.0f32, f32::max);
    // A grid of cells at least two largest radii wide: a circle can only touch circles whose
    // centres lie in its own cell or the eight around it. Cells are widened so there are
    // about four per plant at most: a huge plot of few plants needs no grid of millions of
    // empty cells (which cells hold a plant changes only how many are looked at, not where
    // the plants go).
    let spread =
        ((f64::from(width) * f64::from(depth)) / (4.0 * radii.len().max(1) as f64)).sqrt() as f32;
    let cell = (2.0 * largest).max(spread).max(1e-3);
    let (cols, rows) = (
        ((width / cell).ceil() as usize).clamp(1, 4096),
        ((depth / cell).ceil() as usize).clamp(1, 4096),
    );
    let cell_of = |p: Vec2| {
        let c = (((p.x + 0.5 * width) / cell) as usize).min(cols - 1);
        let r = (((p.y + 0.5 * depth) / cell) as usize).min(rows - 1);
        (c, r)
    };
    let mut grid: Vec<Vec<usize>> = vec![Vec::new(); cols * rows];
    let mut out = vec![(Vec2::ZERO, 0.0f32); radii.len()];
    let mut rng = sylva_core::rng::seeded(seed);
    for (placed, &i) in order.iter().enumerate() {
        let r = radii[i].max(0.0);
        let (hx, hz) = (0.5 * width - r, 0.5 * depth - r);
        let mut spot = None;
        if hx >= 0.0 && hz >= 0.0 {
            for _ in 0..max_tries {
                let p = Vec2::new(
                    hx * (2.0 * rng.random::<f32>() - 1.0),
                    hz * (2.0 * rng.random::<f32>() - 1.0),
                );
                let (c, row) = cell_of(p);
                let free = (row.saturating_sub(1)..=(row + 1).min(rows - 1)).all(|rr| {
                    (c.saturating_sub(1)..=(c + 1).min(cols - 1)).all(|cc| {
                        grid[rr * cols + cc].iter().all(|&j| {
                            let gap = r + radii[j].max(0.0);
                            out[j].0.distance_squared(p) >= gap * gap
                        })
                    })
                });
                if free {
                    spot = Some(p);
                    break;
                }
            }
        }
        let Some(p) = spot else {
            return Err(NoRoom { plant: i, placed });
        };
        let (c, row) = cell_of(p);
        grid[row * cols + c].push(i);
        out[i] = (p, rng.random::<f32>() * TAU);
    }
    Ok(out)
}

/// Radius about the base (the y axis) of the circle that holds the whole plant seen from
/// above: the farthest reach of any segment (with its radius) or organ (with its length).
/// It does not change as the plant turns about Y, and is tighter than the corners of its
/// bounding box.
pub fn footprint(plant: &Plant) -> f32 {
    let reach = |p: Vec3, extra: f32| p.x.hypot(p.z) + extra;
    let segments = plant
        .segments()
        .iter()
        .map(|s| reach(s.start, s.start_radius).max(reach(s.end, s.end_radius)));
    let organs = plant
        .organs()
        .iter()
        .map(|o| reach(o.position, o.size.x.max(o.size.y)));
    segments.chain(organs).fold(0.0, f32::max)
}

impl Garden {
    /// `count` plants of one genome on a `width` x `depth` plot; their seeds and the
    /// placement seed all derive from `seed`.
    pub fn new(genome: PlantMaker, count: usize, area: [f64; 2], seed: u64) -> Garden {
        let mut garden = Garden {
            model: GardenTag,
            format: FormatV1,
            area,
            placement_seed: seed,
            max_tries: DEFAULT_TRIES,
            plants: Vec::new(),
            variants: None,
            instancing: None,
            quantize: false,
        };
        garden.add(genome, count);
        garden
    }

    /// Adds `count` plants of another genome, with seeds drawn from the placement seed and
    /// the genome's index.
    pub fn add(&mut self, genome: PlantMaker, count: usize) {
        let group = self.plants.len() as u32;
        let mut rng = sylva_core::rng::stream(self.placement_seed, 1, group);
        let seeds = (0..count).map(|_| rng.random()).collect();
        self.plants.push(GardenPlants { genome, seeds });
    }

    /// Number of plants.
    pub fn count(&self) -> usize {
        self.plants.iter().map(|p| p.seeds.len()).sum()
    }

    /// Parses a garden file; errors carry the line and column.
    pub fn from_json(text: &str) -> Result<Garden, GenomeError> {
        Ok(serde_json::from_str(text)?)
    }

    /// The garden file, pretty-printed with a final newline.
    pub fn to_json(&self) -> String {
        let mut s =
            serde_json::to_string_pretty(self).expect("gardens hold only numbers and strings");
        s.push('\n');
        s
    }

    /// Grows every plant and places them. A garden file is held to the same limits as
    /// gardens planted from genomes: at most [`MAX_PLANTS`] plants, and plants that fit the
    /// memory budget (estimated from the first plant of each genome, before the others grow).
    pub fn grow(&self) -> Result<GrownGarden, GardenError> {
        self.plan(true)
    }

    /// Where every plant stands, as [`Garden::grow`] places them, without keeping the
    /// plants: each is grown to measure its footprint and dropped, so memory holds one plant
    /// at a time. [`Garden::develop`] grows a placement's plant again.
    pub fn placements(&self) -> Result<Vec<Placement>, GardenError> {
        Ok(self.plan(false)?.placements)
    }

    /// The plant of `placement` (one of this garden's), grown again.
    pub fn develop(&self, placement: &Placement) -> Result<Plant, GardenError> {
        let group = self.plants.get(placement.group).ok_or(GardenError::Empty)?;
        group
            .genome
            .develop(placement.seed)
            .map_err(|source| GardenError::Develop {
                group: placement.group,
                index: placement.index,
                source,
            })
    }

    /// Grows and places the plants, keeping them when `keep` (else `plants` stays empty).
    fn plan(&self, keep: bool) -> Result<GrownGarden, GardenError> {
        let count = self.count();
        if count > MAX_PLANTS {
            return Err(GardenError::TooManyPlants(count));
        }
        let mut plants = Vec::new();
        // Per distinct plant, the radius of its footprint.
        let mut footprints: Vec<f32> = Vec::new();
        // Per placement: (group, index, seed, plant).
        let mut ids = Vec::with_capacity(count);
        let mut estimate = 0u64;
        for (group, g) in self.plants.iter().enumerate() {
            let grown = g
                .seeds
                .len()
                .min(self.variants.map_or(usize::MAX, |v| v as usize));
            let first = footprints.len();
            for (index, &seed) in g.seeds.iter().enumerate() {
                if index < grown {
                    let plant = g
                        .genome
                        .develop(seed)
                        .map_err(|source| GardenError::Develop {
                            group,
                            index,
                            source,
                        })?;
                    if index == 0 && keep {
                        estimate = estimate
                            .saturating_add(plant_bytes(&plant).saturating_mul(grown as u64));
                        sylva_core::budget::check(
                            estimate,
                            format_args!("a garden of {count} plants (its genomes' counts)"),
                            "plant fewer",
                        )?;
                    }
                    footprints.push(footprint(&plant));
                    if keep {
                        plants.push(plant);
                    }
                }
                let variant = index % grown;
                ids.push((group, index, g.seeds[variant], first + variant));
            }
        }
        if footprints.is_empty() {
            return Err(GardenError::Empty);
        }
        let radii: Vec<f32> = ids
            .iter()
            .map(|&(_, _, _, plant)| footprints[plant])
            .collect();
        let [width, depth] = self.area;
        for (&r, &(group, index, _, _)) in radii.iter().zip(&ids) {
            if f64::from(2.0 * r) > width.min(depth) {
                return Err(GardenError::TooWide {
                    group,
                    index,
                    diameter: 2.0 * r,
                    width,
                    depth,
                });
            }
        }
        let spots = place(
            &radii,
            [width as f32, depth as f32],
            self.placement_seed,
            self.max_tries,
        )
        .map_err(|e| GardenError::DoesNotFit {
            placed: e.placed,
            count: ids.len(),
            tries: self.max_tries,
        })?;
        let placements = spots
            .iter()
            .zip(&radii)
            .zip(&ids)
            .map(
                |((&(p, yaw), &radius), &(group, index, seed, plant))| Placement {
                    group,
                    index,
                    seed,
                    plant,
                    translation: Vec3::new(p.x, 0.0, p.y),
                    yaw,
                    radius,
                },
            )
            .collect();
        Ok(GrownGarden { placements, plants })
    }
}

/// PlantMaker's gardens, as the library's garden module reaches them.
impl GardenPlan for Garden {
    type Genome = PlantMaker;

    fn add(&mut self, genome: PlantMaker, count: usize) {
        Garden::add(self, genome, count);
    }

    fn count(&self) -> usize {
        Garden::count(self)
    }

    fn groups(&self) -> Vec<(&PlantMaker, &[u64])> {
        self.plants
            .iter()
            .map(|g| (&g.genome, g.seeds.as_slice()))
            .collect()
    }

    fn variants(&self) -> Option<u32> {
        self.variants
    }

    fn set_variants(&mut self, variants: Option<u32>) {
        self.variants = variants;
    }

    fn instancing(&self) -> Option<bool> {
        self.instancing
    }

    fn set_instancing(&mut self, instancing: Option<bool>) {
        self.instancing = instancing;
    }

    fn quantize(&self) -> bool {
        self.quantize
    }

    fn set_quantize(&mut self, quantize: bool) {
        self.quantize = quantize;
    }

    fn to_json(&self) -> String {
        Garden::to_json(self)
    }

    fn grow(&self) -> Result<GrownGarden, GardenError> {
        Garden::grow(self)
    }

    fn placements(&self) -> Result<Vec<Placement>, GardenError> {
        Garden::placements(self)
    }

    fn develop(&self, placement: &Placement) -> Result<Plant, GardenError> {
        Garden::develop(self, placement)
    }
}

/// PlantMaker offers gardens and forests (its registry line says so).
impl Gardens for PlantMakerModel {
    type Garden = Garden;
    const GARDEN_FILE: &'static str = GARDEN_MODEL;

    fn read_garden(text: &str) -> Result<Garden, GenomeError> {
        Garden::from_json(text)
    }

    fn new_garden(genome: PlantMaker, count: usize, area: [f64; 2], seed: u64) -> Garden {
        Garden::new(genome, count, area, seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn places_without_overlap() {
        let radii: Vec<f32> = (0..60).map(|i| 0.2 + 0.05 * (i % 7) as f32).collect();
        let spots = place(&radii, [12.0, 9.0], 3, 2000).unwrap();
        for i in 0..radii.len() {
            let (p, _) = spots[i];
            assert!(p.x.abs() + radii[i] <= 6.0 + 1e-4 && p.y.abs() + radii[i] <= 4.5 + 1e-4);
            for j in 0..i {
                let d = p.distance(spots[j].0);
                assert!(d >= radii[i] + radii[j] - 1e-4, "{i} and {j} overlap");
            }
        }
        assert_eq!(spots, place(&radii, [12.0, 9.0], 3, 2000).unwrap());
    }

    #[test]
    fn crowding_is_reported() {
        let radii = vec![1.0; 50];
        let e = place(&radii, [5.0, 5.0], 1, 200).unwrap_err();
        assert!(e.placed < 50 && e.placed >= 1);
    }
}
