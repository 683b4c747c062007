//! The paper's simulations (section 4) as library entry points with TOML configs.
//!
//! - [`HerbsUnderTree`] (Figure 8): herbs sown in two rings around a tree under vertical
//!   light; the inner ring lies under the crown. Outcome: the herbs' biomass and light, and
//!   the ratio of shaded to unshaded biomass (the paper: shaded herbs "grow poorly").
//! - [`LateralLight`] (Figure 9): two trees of one genome under lateral light, against the
//!   same pair under vertical light. Outcome: crown asymmetry (the horizontal offset of the
//!   leaves' centroid towards the light over the crown radius), height and width, and
//!   bushiness (shoot tips per cubic metre of the crown's convex hull; the paper: the crown
//!   is "replaced by rather bushy forms").
//! - [`EmptyRules`] (section 4.1): biomorph breeding from empty rules, choosing the largest
//!   biomass each generation, until plants have leaves and fine roots.
//!
//! A config file holds one of them as its only table, `[herbs-under-tree]`,
//! `[lateral-light]` or `[empty-rules]` ([`Simulation`]); it names genome files relative to
//! itself ([`Simulation::genome_files`]). The model reads no files: the caller loads those
//! genomes and passes them to [`Simulation::run`]. Each outcome holds its measured figures,
//! the grown plants placed in the world with their genomes ([`SimulationOutcome::plants`])
//! and the per-step records ([`SimulationOutcome::records`]). [`Simulation::work`] estimates
//! an experiment before it starts, and it is refused when that is over the time budget
//! ([`crate::work`]).

use std::fmt::Write as _;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use sylva_core::environment::{EnvironmentSettings, LightSettings};
use sylva_core::glam::{Vec2, Vec3};
use sylva_core::hull::convex_hull_volume;
use sylva_core::par::Pool;
use sylva_core::{MaterialKind, Plant, Segment};

use crate::breed::{
    BiomorphRun, BreedSettings, biomorphs_work, evolve_biomorphs_with, largest_biomass,
};
use crate::garden::{Garden, GardenError, MAX_STEPS, Sowing, StepRecord};
use crate::genome::LSystemGenome;
use crate::work::{self, Rules, Work};

/// Why a simulation could not run.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// The genomes given do not match the files the experiment names.
    #[error("the experiment needs {expected} genomes (its genome files), got {given}")]
    Genomes {
        /// Genome files the experiment names.
        expected: usize,
        /// Genomes given.
        given: usize,
    },
    /// A setting is out of range.
    #[error("{0}")]
    Config(String),
    /// The garden refused to grow.
    #[error(transparent)]
    Garden(#[from] GardenError),
}

/// What to change when an experiment would take too long.
const EXPERIMENT_ADVICE: &str = "lower `max_symbols` and `max_modules` in the genomes' \
     `physiology`, the steps, or the world's voxels";

/// A world with its light set to `light`, everything else from `world`.
fn with_light(world: &EnvironmentSettings, light: LightSettings) -> EnvironmentSettings {
    EnvironmentSettings { light, ..*world }
}

/// A grown plant placed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedPlant {
    /// A name for pictures and exports (`tree`, `herb 3`, ...).
    pub label: String,
    /// The genome it grew from.
    pub genome: LSystemGenome,
    /// Its foot, world coordinates.
    pub position: Vec3,
    /// Its geometry, foot at the origin.
    pub plant: Plant,
    /// Biomass (dry mass: structure and pools) at the end, grams.
    pub biomass: f64,
}

fn placed(garden: &Garden, labels: &[String]) -> Vec<PlacedPlant> {
    garden
        .plants()
        .iter()
        .zip(labels)
        .map(|(p, label)| PlacedPlant {
            label: label.clone(),
            genome: p.genome().clone(),
            position: p.position(),
            plant: p.plant().clone(),
            biomass: p.biomass(),
        })
        .collect()
}

/// Shape of a plant's crown, measured from its foot: height, the spread and lean of its
/// leaves, and how bushy it is (shoot tips per cubic metre of its convex hull).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CrownShape {
    /// Highest point of the shoot, metres.
    pub height: f32,
    /// Largest horizontal distance of a leaf from the foot, metres.
    pub radius: f32,
    /// Horizontal offset of the leaves' centroid along `towards`, metres.
    pub offset: f32,
    /// `offset / radius`: 0 for a symmetric crown, up to 1 for a one-sided one.
    pub asymmetry: f32,
    /// Leaves.
    pub leaves: usize,
    /// Shoot tips: ends of the woody skeleton, bark segments from which no bark segment
    /// grows (leaves may).
    pub tips: usize,
    /// Woody axes of the shoot: the trunk and every bark segment that starts a branch.
    pub branches: usize,
    /// Crown volume: the convex hull of the shoot's skeleton (both ends of every bark and
    /// leaf segment, the foot included), cubic metres.
    pub volume: f32,
    /// Bushiness: `tips / volume`, shoot tips per cubic metre of crown; 0 without volume.
    pub bushiness: f32,
}

impl CrownShape {
    /// Measures `plant`'s leaves; `towards` is a horizontal direction (the light's).
    pub fn of(plant: &Plant, towards: Vec2) -> CrownShape {
        let towards = towards.normalize_or_zero();
        let mut shape = CrownShape::default();
        let mut sum = Vec2::ZERO;
        let kind = |s: &Segment| plant.materials().get(s.material.index()).map(|m| m.kind);
        let bark = |s: &Segment| kind(s) == Some(MaterialKind::Bark);
        let mut bears_wood = vec![false; plant.segments().len()];
        let mut shoot = Vec::new();
        for s in plant.segments() {
            if bark(s) {
                if let Some(p) = s.parent {
                    bears_wood[p.index()] = true;
                }
                if s.lateral || s.parent.is_none() {
                    shape.branches += 1;
                }
            }
            if kind(s) != Some(MaterialKind::Root) {
                shoot.extend([s.start.as_dvec3(), s.end.as_dvec3()]);
            }
        }
        shape.tips = plant
            .segments()
            .iter()
            .zip(&bears_wood)
            .filter(|(s, wood)| bark(s) && !**wood)
            .count();
        shape.volume = convex_hull_volume(&shoot) as f32;
        if shape.volume > 0.0 {
            shape.bushiness = shape.tips as f32 / shape.volume;
        }
        for s in plant.segments() {
            shape.height = shape.height.max(s.end.y).max(s.start.y);
            if kind(s) != Some(MaterialKind::Leaf) {
                continue;
            }
            let mid = (s.start + s.end) * 0.5;
            let h = Vec2::new(mid.x, mid.z);
            shape.radius = shape.radius.max(h.length());
            sum += h;
            shape.leaves += 1;
        }
        if shape.leaves > 0 {
            shape.offset = (sum / shape.leaves as f32).dot(towards);
            if shape.radius > 0.0 {
                shape.asymmetry = shape.offset / shape.radius;
            }
        }
        shape
    }
}

fn vertical() -> LightSettings {
    LightSettings {
        elevation: 90.0,
        ..LightSettings::default()
    }
}

// ----- herbs under a tree -----

/// Herbs sown around a tree under vertical light (Figure 8).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HerbsUnderTree {
    /// The tree's genome file, relative to the config.
    pub tree: PathBuf,
    /// The herbs' genome file, relative to the config.
    pub herb: PathBuf,
    /// The world; its light is made vertical. Default [`EnvironmentSettings::default`].
    #[serde(default)]
    pub world: EnvironmentSettings,
    /// Steps the tree grows alone before the herbs are sown, 0 to half of
    /// [`MAX_STEPS`]. Default 120.
    #[serde(default = "default_head_start", deserialize_with = "head_start")]
    pub head_start: u32,
    /// Steps everything then grows together, 0 to half of [`MAX_STEPS`]. Default 60.
    #[serde(default = "default_herb_steps", deserialize_with = "half_steps")]
    pub steps: u32,
    /// Radius of the ring of herbs under the crown, 0 to 1000 metres. Default 0.8.
    #[serde(default = "default_inner", deserialize_with = "inner_radius")]
    pub inner_radius: f32,
    /// Radius of the ring of herbs in the open, 0 to 1000 metres. Default 3.2.
    #[serde(default = "default_outer", deserialize_with = "outer_radius")]
    pub outer_radius: f32,
    /// Herbs in each ring, 1 to 64. Default 6.
    #[serde(default = "default_per_ring", deserialize_with = "herbs_per_ring")]
    pub herbs_per_ring: u32,
}

sylva_core::ranged!(head_start: u32, "head_start", 0, MAX_STEPS / 2);
sylva_core::ranged!(half_steps: u32, "steps", 0, MAX_STEPS / 2);
sylva_core::ranged!(inner_radius: f32, "inner_radius", 0.0, 1000.0, " m");
sylva_core::ranged!(outer_radius: f32, "outer_radius", 0.0, 1000.0, " m");
sylva_core::ranged!(herbs_per_ring: u32, "herbs_per_ring", 1, 64);
sylva_core::ranged!(steps: u32, "steps", 0, MAX_STEPS);
sylva_core::ranged!(spacing: f32, "spacing", 0.0, 1000.0, " m");
sylva_core::ranged!(generations: u32, "generations", 1, 10_000);

fn default_head_start() -> u32 {
    120
}
fn default_herb_steps() -> u32 {
    60
}
fn default_inner() -> f32 {
    0.8
}
fn default_outer() -> f32 {
    3.2
}
fn default_per_ring() -> u32 {
    6
}

/// One herb's outcome.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HerbOutcome {
    /// Where it grew, `(x, z)`.
    pub position: Vec2,
    /// True for the inner ring (under the crown).
    pub shaded: bool,
    /// Biomass (dry mass: structure and pools) at the end, grams.
    pub biomass: f64,
    /// Light absorbed over its life.
    pub light: f64,
}

/// What [`HerbsUnderTree`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct HerbsUnderTreeOutcome {
    /// Every herb.
    pub herbs: Vec<HerbOutcome>,
    /// The tree's crown at the end.
    pub crown: CrownShape,
    /// Mean biomass of the shaded herbs, grams.
    pub shaded_biomass: f64,
    /// Mean biomass of the herbs in the open, grams.
    pub open_biomass: f64,
    /// `shaded_biomass / open_biomass`: below 1 when shade slows growth.
    pub biomass_ratio: f64,
    /// Mean light absorbed by a shaded herb over the light of one in the open.
    pub light_ratio: f64,
    /// The tree first, then the herbs.
    pub plants: Vec<PlacedPlant>,
    /// Per plant and step records (plant 0 is the tree).
    pub records: Vec<StepRecord>,
}

impl Default for HerbsUnderTree {
    fn default() -> Self {
        HerbsUnderTree {
            tree: "tree.json".into(),
            herb: "herb.json".into(),
            world: EnvironmentSettings::default(),
            head_start: default_head_start(),
            steps: default_herb_steps(),
            inner_radius: default_inner(),
            outer_radius: default_outer(),
            herbs_per_ring: default_per_ring(),
        }
    }
}

impl HerbsUnderTree {
    /// Runs with the tree's and the herbs' genomes; each plant's share of a step runs on
    /// `pool`.
    pub fn run(
        &self,
        tree: &LSystemGenome,
        herb: &LSystemGenome,
        pool: &Pool,
    ) -> Result<HerbsUnderTreeOutcome, ExperimentError> {
        self.run_with(tree, herb, pool, &mut |_| {})
    }

    /// The tree and the herbs, as sown, with their labels.
    fn sowings(
        &self,
        tree: &LSystemGenome,
        herb: &LSystemGenome,
    ) -> Result<(Vec<Sowing>, Vec<String>), ExperimentError> {
        if !(1..=64).contains(&self.herbs_per_ring) {
            return Err(ExperimentError::Config(format!(
                "`herbs_per_ring` must be 1 to 64, got {}",
                self.herbs_per_ring
            )));
        }
        let mut sowings = vec![Sowing::new(tree.clone(), Vec2::ZERO)];
        let mut labels = vec!["tree".to_owned()];
        let n = self.herbs_per_ring;
        for (ring, radius) in [(0, self.inner_radius), (1, self.outer_radius)] {
            for i in 0..n {
                // Offset the rings by half a step so no herb stands behind another.
                let a = std::f32::consts::TAU * (i as f32 + 0.5 * ring as f32) / n as f32;
                sowings.push(Sowing {
                    genome: herb.clone(),
                    position: Vec2::new(a.cos(), a.sin()) * radius,
                    sown_at: self.head_start,
                });
                labels.push(format!("herb {}", labels.len()));
            }
        }
        Ok((sowings, labels))
    }

    /// The work of [`HerbsUnderTree::run`], at the plants' bounds.
    pub fn work(
        &self,
        tree: &LSystemGenome,
        herb: &LSystemGenome,
    ) -> Result<Work, ExperimentError> {
        let (sowings, _) = self.sowings(tree, herb)?;
        let steps = self.head_start.saturating_add(self.steps);
        Ok(work::garden(&self.world, &sowings, steps, Rules::Known))
    }

    /// As [`HerbsUnderTree::run`], calling `on_step` with the steps done after each.
    pub fn run_with(
        &self,
        tree: &LSystemGenome,
        herb: &LSystemGenome,
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<HerbsUnderTreeOutcome, ExperimentError> {
        let (sowings, labels) = self.sowings(tree, herb)?;
        let n = self.herbs_per_ring;
        self.work(tree, herb)?
            .check(
                pool.threads(),
                format_args!(
                    "a tree and {} herbs growing {} steps (`head_start` and `steps`), the tree up \
                 to {} and each herb up to {}",
                    2 * n,
                    self.head_start.saturating_add(self.steps),
                    work::bounds(&tree.physiology),
                    work::bounds(&herb.physiology)
                ),
                EXPERIMENT_ADVICE,
            )
            .map_err(GardenError::from)?;
        let world = with_light(&self.world, vertical());
        let mut garden = Garden::new(world, sowings)?;
        garden.run_with(self.head_start + self.steps, pool, &mut |done| {
            on_step(u64::from(done))
        })?;
        let herbs: Vec<HerbOutcome> = garden.plants()[1..]
            .iter()
            .enumerate()
            .map(|(i, p)| HerbOutcome {
                position: Vec2::new(p.position().x, p.position().z),
                shaded: (i as u32) < n,
                biomass: p.biomass(),
                light: p.totals().light,
            })
            .collect();
        let mean = |shaded: bool, f: fn(&HerbOutcome) -> f64| {
            let v: Vec<f64> = herbs.iter().filter(|h| h.shaded == shaded).map(f).collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        let shaded_biomass = mean(true, |h| h.biomass);
        let open_biomass = mean(false, |h| h.biomass);
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
        Ok(HerbsUnderTreeOutcome {
            crown: CrownShape::of(garden.plants()[0].plant(), Vec2::X),
            biomass_ratio: ratio(shaded_biomass, open_biomass),
            light_ratio: ratio(mean(true, |h| h.light), mean(false, |h| h.light)),
            shaded_biomass,
            open_biomass,
            herbs,
            plants: placed(&garden, &labels),
            records: garden.records().to_vec(),
        })
    }
}

// ----- lateral light -----

/// Two trees of one genome under lateral light, against the same pair under vertical light
/// (Figure 9).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LateralLight {
    /// The trees' genome file, relative to the config.
    pub tree: PathBuf,
    /// The world, with its lateral light (`world.light`). Default: the default world with
    /// light from +X at 30 degrees above the horizon.
    #[serde(default = "default_lateral_world")]
    pub world: EnvironmentSettings,
    /// Steps to grow, 0 to [`MAX_STEPS`]. Default 150.
    #[serde(default = "default_lateral_steps", deserialize_with = "steps")]
    pub steps: u32,
    /// Distance between the two trees, 0 to 1000 metres; they stand side by side across the
    /// light. Default 3.
    #[serde(default = "default_lateral_spacing", deserialize_with = "spacing")]
    pub spacing: f32,
}

fn default_lateral_world() -> EnvironmentSettings {
    EnvironmentSettings {
        light: LightSettings {
            elevation: 30.0,
            azimuth: 0.0,
            ..LightSettings::default()
        },
        ..EnvironmentSettings::default()
    }
}
fn default_lateral_steps() -> u32 {
    150
}
fn default_lateral_spacing() -> f32 {
    3.0
}

impl Default for LateralLight {
    fn default() -> Self {
        LateralLight {
            tree: "tree.json".into(),
            world: default_lateral_world(),
            steps: default_lateral_steps(),
            spacing: default_lateral_spacing(),
        }
    }
}

/// What [`LateralLight`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct LateralLightOutcome {
    /// Horizontal direction towards the lateral light.
    pub towards_light: Vec2,
    /// The two trees under lateral light.
    pub lateral: [CrownShape; 2],
    /// The same two under vertical light (measured along the same direction).
    pub vertical: [CrownShape; 2],
    /// The lateral-light trees.
    pub plants: Vec<PlacedPlant>,
    /// The vertical-light trees.
    pub control: Vec<PlacedPlant>,
    /// Per plant and step records of the lateral run.
    pub records: Vec<StepRecord>,
}

impl LateralLightOutcome {
    /// Mean asymmetry of the two lateral-light trees.
    pub fn lateral_asymmetry(&self) -> f32 {
        0.5 * (self.lateral[0].asymmetry + self.lateral[1].asymmetry)
    }

    /// Mean asymmetry of the two vertical-light trees.
    pub fn vertical_asymmetry(&self) -> f32 {
        0.5 * (self.vertical[0].asymmetry + self.vertical[1].asymmetry)
    }

    /// Mean bushiness of the two lateral-light trees.
    pub fn lateral_bushiness(&self) -> f32 {
        0.5 * (self.lateral[0].bushiness + self.lateral[1].bushiness)
    }

    /// Mean bushiness of the two vertical-light trees.
    pub fn vertical_bushiness(&self) -> f32 {
        0.5 * (self.vertical[0].bushiness + self.vertical[1].bushiness)
    }
}

impl LateralLight {
    /// Runs with the trees' genome; each plant's share of a step runs on `pool`.
    pub fn run(
        &self,
        tree: &LSystemGenome,
        pool: &Pool,
    ) -> Result<LateralLightOutcome, ExperimentError> {
        self.run_with(tree, pool, &mut |_| {})
    }

    /// The work of [`LateralLight::run`] (two gardens of two trees), at the trees' bounds.
    pub fn work(&self, tree: &LSystemGenome) -> Work {
        let pair = [
            Sowing::new(tree.clone(), Vec2::ZERO),
            Sowing::new(tree.clone(), Vec2::ZERO),
        ];
        work::garden(&self.world, &pair, self.steps, Rules::Known).times(2)
    }

    /// As [`LateralLight::run`], calling `on_step` with the steps done after each, over both
    /// gardens.
    pub fn run_with(
        &self,
        tree: &LSystemGenome,
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<LateralLightOutcome, ExperimentError> {
        let source = self.world.light.towards_source();
        let towards = Vec2::new(source.x, source.z);
        if towards.length() < 1e-3 {
            return Err(ExperimentError::Config(
                "lateral-light needs a light below 90 degrees of elevation".into(),
            ));
        }
        self.work(tree)
            .check(
                pool.threads(),
                format_args!(
                    "two pairs of trees growing {} steps (`steps`), each up to {}",
                    self.steps,
                    work::bounds(&tree.physiology)
                ),
                EXPERIMENT_ADVICE,
            )
            .map_err(GardenError::from)?;
        // Side by side across the light.
        let across = Vec2::new(-towards.y, towards.x).normalize() * (0.5 * self.spacing);
        let mut grow = |world: EnvironmentSettings, before: u64| {
            let sowings = vec![
                Sowing::new(tree.clone(), -across),
                Sowing::new(tree.clone(), across),
            ];
            let mut garden = Garden::new(world, sowings)?;
            garden.run_with(self.steps, pool, &mut |done| {
                on_step(before + u64::from(done))
            })?;
            Ok::<Garden, ExperimentError>(garden)
        };
        let lateral = grow(self.world, 0)?;
        let control = grow(with_light(&self.world, vertical()), u64::from(self.steps))?;
        let shapes = |g: &Garden| [0, 1].map(|i| CrownShape::of(g.plants()[i].plant(), towards));
        let labels = ["tree 1".to_owned(), "tree 2".to_owned()];
        Ok(LateralLightOutcome {
            towards_light: towards.normalize(),
            lateral: shapes(&lateral),
            vertical: shapes(&control),
            plants: placed(&lateral, &labels),
            control: placed(&control, &labels),
            records: lateral.records().to_vec(),
        })
    }
}

// ----- evolution from empty rules -----

/// Biomorph breeding from empty rules, choosing the largest biomass (section 4.1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EmptyRules {
    /// The breeding garden: world, steps, spacing, children, mutation rates.
    #[serde(default)]
    pub breed: BreedSettings,
    /// Generations, 1 to 10000. Default 30.
    #[serde(default = "default_generations", deserialize_with = "generations")]
    pub generations: u32,
    /// Seed of the mutations. Default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// A starting genome file, relative to the config; the empty genome when absent.
    #[serde(default)]
    pub start: Option<PathBuf>,
}

fn default_generations() -> u32 {
    30
}
fn default_seed() -> u64 {
    1
}

impl Default for EmptyRules {
    fn default() -> Self {
        EmptyRules {
            breed: BreedSettings::default(),
            generations: default_generations(),
            seed: default_seed(),
            start: None,
        }
    }
}

/// What [`EmptyRules`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct EmptyRulesOutcome {
    /// The run.
    pub run: BiomorphRun,
    /// The first generation whose chosen plant had leaves and fine roots.
    pub leaves_and_roots_at: Option<u32>,
    /// The last garden's plants.
    pub plants: Vec<PlacedPlant>,
}

impl EmptyRules {
    /// Runs from `start` (the genome of `self.start`, or [`LSystemGenome::empty`]); each
    /// plant's share of a step runs on `pool`.
    pub fn run(
        &self,
        start: &LSystemGenome,
        pool: &Pool,
    ) -> Result<EmptyRulesOutcome, ExperimentError> {
        self.run_with(start, pool, &mut |_| {})
    }

    /// As [`EmptyRules::run`], calling `on_step` with the garden steps done after each, over
    /// all generations.
    pub fn run_with(
        &self,
        start: &LSystemGenome,
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<EmptyRulesOutcome, ExperimentError> {
        if !(1..=10_000).contains(&self.generations) {
            return Err(ExperimentError::Config(format!(
                "`generations` must be 1 to 10000, got {}",
                self.generations
            )));
        }
        let run = evolve_biomorphs_with(
            start,
            &self.breed,
            self.generations,
            self.seed,
            largest_biomass,
            pool,
            on_step,
        )?;
        let plants = run
            .last
            .specimens
            .iter()
            .enumerate()
            .map(|(i, s)| PlacedPlant {
                label: if s.is_mother {
                    "mother".to_owned()
                } else {
                    format!("child {i}")
                },
                genome: s.genome.clone(),
                position: Vec3::new(s.position.x, 0.0, s.position.y),
                plant: s.plant.clone(),
                biomass: s.stats.biomass,
            })
            .collect();
        Ok(EmptyRulesOutcome {
            leaves_and_roots_at: run.first_with_leaves_and_roots(),
            run,
            plants,
        })
    }
}

// ----- configs and outcomes -----

/// A simulation config: one experiment, named by its table.
// Read once per run; boxing the larger variants would only complicate the config type.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum Simulation {
    /// `[herbs-under-tree]`.
    HerbsUnderTree(HerbsUnderTree),
    /// `[lateral-light]`.
    LateralLight(LateralLight),
    /// `[empty-rules]`.
    EmptyRules(EmptyRules),
}

/// What a simulation measured.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum SimulationOutcome {
    /// Herbs under a tree.
    HerbsUnderTree(HerbsUnderTreeOutcome),
    /// Trees under lateral light.
    LateralLight(LateralLightOutcome),
    /// Breeding from empty rules.
    EmptyRules(EmptyRulesOutcome),
}

impl Simulation {
    /// The genome files the experiment names, relative to its config file, in the order
    /// [`Simulation::run`] takes their genomes.
    pub fn genome_files(&self) -> Vec<&std::path::Path> {
        match self {
            Simulation::HerbsUnderTree(c) => vec![c.tree.as_path(), c.herb.as_path()],
            Simulation::LateralLight(c) => vec![c.tree.as_path()],
            Simulation::EmptyRules(c) => c.start.as_deref().into_iter().collect(),
        }
    }

    /// Runs the experiment with the genomes of [`Simulation::genome_files`], in order; each
    /// plant's share of a step runs on `pool`.
    pub fn run(
        &self,
        genomes: &[LSystemGenome],
        pool: &Pool,
    ) -> Result<SimulationOutcome, ExperimentError> {
        self.run_with(genomes, pool, &mut |_| {})
    }

    /// The genomes, checked against the files the experiment names.
    fn check_genomes(&self, genomes: &[LSystemGenome]) -> Result<(), ExperimentError> {
        let expected = self.genome_files().len();
        if genomes.len() != expected {
            return Err(ExperimentError::Genomes {
                expected,
                given: genomes.len(),
            });
        }
        Ok(())
    }

    /// The work of the experiment with these genomes, at the plants' bounds
    /// ([`crate::work`]); its `steps` are the garden steps that
    /// [`run_with`](Simulation::run_with) counts.
    pub fn work(&self, genomes: &[LSystemGenome]) -> Result<Work, ExperimentError> {
        self.check_genomes(genomes)?;
        Ok(match self {
            Simulation::HerbsUnderTree(c) => c.work(&genomes[0], &genomes[1])?,
            Simulation::LateralLight(c) => c.work(&genomes[0]),
            Simulation::EmptyRules(c) => {
                let empty = LSystemGenome::empty();
                biomorphs_work(genomes.first().unwrap_or(&empty), &c.breed, c.generations)
            }
        })
    }

    /// As [`Simulation::run`], calling `on_step` with the garden steps done after each (a
    /// progress bar; [`Simulation::work`] says how many there are). Refused before the
    /// first step when the experiment would take longer than the time budget.
    pub fn run_with(
        &self,
        genomes: &[LSystemGenome],
        pool: &Pool,
        on_step: &mut dyn FnMut(u64),
    ) -> Result<SimulationOutcome, ExperimentError> {
        self.check_genomes(genomes)?;
        Ok(match self {
            Simulation::HerbsUnderTree(c) => SimulationOutcome::HerbsUnderTree(c.run_with(
                &genomes[0],
                &genomes[1],
                pool,
                on_step,
            )?),
            Simulation::LateralLight(c) => {
                SimulationOutcome::LateralLight(c.run_with(&genomes[0], pool, on_step)?)
            }
            Simulation::EmptyRules(c) => {
                let empty = LSystemGenome::empty();
                SimulationOutcome::EmptyRules(c.run_with(
                    genomes.first().unwrap_or(&empty),
                    pool,
                    on_step,
                )?)
            }
        })
    }
}

impl SimulationOutcome {
    /// The grown plants, placed in the world.
    pub fn plants(&self) -> &[PlacedPlant] {
        match self {
            SimulationOutcome::HerbsUnderTree(o) => &o.plants,
            SimulationOutcome::LateralLight(o) => &o.plants,
            SimulationOutcome::EmptyRules(o) => &o.plants,
        }
    }

    /// Per plant and step records (of the lateral-light run, of the last breeding garden).
    pub fn records(&self) -> &[StepRecord] {
        match self {
            SimulationOutcome::HerbsUnderTree(o) => &o.records,
            SimulationOutcome::LateralLight(o) => &o.records,
            SimulationOutcome::EmptyRules(o) => &o.run.last.records,
        }
    }
}

impl SimulationOutcome {
    /// `report.txt`: the measured outcome, one figure a line.
    pub fn report(&self) -> String {
        let mut out = String::new();
        match self {
            SimulationOutcome::HerbsUnderTree(o) => {
                let _ = writeln!(out, "tree crown radius: {:.2} m", o.crown.radius);
                let _ = writeln!(out, "shaded herbs, mean biomass: {:.3} g", o.shaded_biomass);
                let _ = writeln!(out, "open herbs, mean biomass: {:.3} g", o.open_biomass);
                let _ = writeln!(out, "biomass ratio shaded/open: {:.3}", o.biomass_ratio);
                let _ = writeln!(out, "light ratio shaded/open: {:.3}", o.light_ratio);
            }
            SimulationOutcome::LateralLight(o) => {
                for (name, shapes) in [("lateral", &o.lateral), ("vertical", &o.vertical)] {
                    for (i, s) in shapes.iter().enumerate() {
                        let _ = writeln!(
                            out,
                            "{name} light, tree {}: height {:.2} m, crown radius {:.2} m, \
                             leaves offset towards the light {:.2} m, asymmetry {:.3}",
                            i + 1,
                            s.height,
                            s.radius,
                            s.offset,
                            s.asymmetry
                        );
                    }
                }
                let _ = writeln!(
                    out,
                    "mean asymmetry: lateral {:.3}, vertical {:.3}",
                    o.lateral_asymmetry(),
                    o.vertical_asymmetry()
                );
                for (name, shapes) in [("lateral", &o.lateral), ("vertical", &o.vertical)] {
                    for (i, s) in shapes.iter().enumerate() {
                        let _ = writeln!(
                            out,
                            "{name} light, tree {}: {} shoot tips, {} branches, {} leaves, \
                             crown hull {:.2} m³, bushiness {:.1} tips/m³",
                            i + 1,
                            s.tips,
                            s.branches,
                            s.leaves,
                            s.volume,
                            s.bushiness
                        );
                    }
                }
                let _ = writeln!(
                    out,
                    "mean bushiness (shoot tips per m³ of crown hull): lateral {:.1}, vertical {:.1}",
                    o.lateral_bushiness(),
                    o.vertical_bushiness()
                );
            }
            SimulationOutcome::EmptyRules(o) => {
                for g in &o.run.generations {
                    let _ = writeln!(
                        out,
                        "generation {}: chose {} (biomass {:.3} g, {} leaves, {} fine roots), \
                         {} of the garden germinated",
                        g.generation,
                        g.chosen,
                        g.stats.biomass,
                        g.stats.leaves(),
                        g.stats.fine_roots(),
                        g.germinated
                    );
                }
                let _ = match o.leaves_and_roots_at {
                    Some(g) => writeln!(out, "leaves and fine roots from generation {g}"),
                    None => writeln!(out, "no plant with leaves and fine roots yet"),
                };
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_core::{Material, PlantMeta};

    /// A trunk forking into two branches, one with a leaf, over a long root: the shoot's hull
    /// is the tetrahedron of the foot, the fork and the two branch ends.
    #[test]
    fn crown_counts_tips_and_branches_over_the_shoots_hull() {
        let mut p = Plant::new(PlantMeta::default());
        let root = p
            .add_material(Material::of_kind(MaterialKind::Root))
            .unwrap();
        let fork = Vec3::Y;
        let trunk = p
            .add_segment(Vec3::ZERO, fork, (0.1, 0.1), None, false, Plant::BARK)
            .unwrap();
        let a = p
            .add_segment(
                fork,
                fork + Vec3::X,
                (0.05, 0.05),
                Some(trunk),
                true,
                Plant::BARK,
            )
            .unwrap();
        p.add_segment(
            fork,
            fork + Vec3::Z,
            (0.05, 0.05),
            Some(trunk),
            true,
            Plant::BARK,
        )
        .unwrap();
        // On the hull's face: it adds no volume, and branch `a` stays a tip.
        let leaf_end = fork + Vec3::new(0.5, 0.0, 0.5);
        p.add_segment(
            fork + Vec3::X,
            leaf_end,
            (0.02, 0.02),
            Some(a),
            true,
            Plant::LEAF,
        )
        .unwrap();
        p.add_segment(Vec3::ZERO, Vec3::NEG_Y * 3.0, (0.1, 0.1), None, false, root)
            .unwrap();
        let crown = CrownShape::of(&p, Vec2::X);
        assert_eq!((crown.tips, crown.branches, crown.leaves), (2, 3, 1));
        assert!((crown.volume - 1.0 / 6.0).abs() < 1e-6, "{crown:?}");
        assert!((crown.bushiness - 12.0).abs() < 1e-4, "{crown:?}");

        // A branch growing from `a` makes it bear wood: still two tips, one more branch.
        p.add_segment(
            fork + Vec3::X,
            fork + Vec3::X * 2.0,
            (0.02, 0.02),
            Some(a),
            true,
            Plant::BARK,
        )
        .unwrap();
        let crown = CrownShape::of(&p, Vec2::X);
        assert_eq!((crown.tips, crown.branches), (2, 4));
        assert!((crown.volume - 2.0 / 6.0).abs() < 1e-6, "{crown:?}");
    }

    #[test]
    fn a_plant_without_a_shoot_is_not_bushy() {
        let crown = CrownShape::of(&Plant::new(PlantMeta::default()), Vec2::X);
        assert_eq!((crown.tips, crown.branches, crown.volume), (0, 0, 0.0));
        assert_eq!(crown.bushiness, 0.0);
    }
}
