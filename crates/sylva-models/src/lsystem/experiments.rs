//! The paper's simulations (section 4) as library entry points with TOML configs.
//!
//! - [`HerbsUnderTree`] (Figure 8): herbs sown in two rings around a tree under vertical
//!   light; the inner ring lies under the crown. Outcome: the herbs' biomass and light, and
//!   the ratio of shaded to unshaded biomass (the paper: shaded herbs "grow poorly").
//! - [`LateralLight`] (Figure 9): two trees of one genome under lateral light, against the
//!   same pair under vertical light. Outcome: crown asymmetry (the horizontal offset of the
//!   leaves' centroid towards the light over the crown radius) and height and width.
//! - [`EmptyRules`] (section 4.1): biomorph breeding from empty rules, choosing the largest
//!   biomass each generation, until plants have leaves and fine roots.
//!
//! A config file holds one of them as its only table, `[herbs-under-tree]`,
//! `[lateral-light]` or `[empty-rules]` ([`Simulation`]); genome paths are relative to the
//! config file. [`Simulation::run`] loads the genomes and runs; each outcome gives a
//! one-line-per-figure [`report`](SimulationOutcome::report), the grown plants placed in
//! the world ([`SimulationOutcome::plants`]) and the per-step CSV.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sylva_core::environment::{EnvironmentSettings, LightSettings};
use sylva_core::glam::{Vec2, Vec3};
use sylva_core::{MaterialKind, Plant};

use super::breed::{BiomorphRun, BreedSettings, evolve_biomorphs, largest_biomass};
use super::garden::{Garden, GardenError, Sowing, StepRecord, records_csv};
use super::genome::LSystemGenome;

/// Why a simulation could not run.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// A genome file could not be read.
    #[error("cannot read {path}: {error}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// A genome file is not a valid L-system genome.
    #[error("{path}:{line}:{column}: {message}")]
    Genome {
        /// The file.
        path: PathBuf,
        /// Line of the error.
        line: usize,
        /// Column of the error.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A setting is out of range.
    #[error("{0}")]
    Config(String),
    /// The garden refused to grow.
    #[error(transparent)]
    Garden(#[from] GardenError),
}

/// Reads an L-system genome file.
pub fn load_genome(path: &Path) -> Result<LSystemGenome, ExperimentError> {
    let text = std::fs::read_to_string(path).map_err(|error| ExperimentError::Read {
        path: path.to_owned(),
        error,
    })?;
    LSystemGenome::from_json(&text).map_err(|e| ExperimentError::Genome {
        path: path.to_owned(),
        line: e.line,
        column: e.column,
        message: e.message,
    })
}

/// A world with its light set to `light`, everything else from `world`.
fn with_light(world: &EnvironmentSettings, light: LightSettings) -> EnvironmentSettings {
    EnvironmentSettings { light, ..*world }
}

/// A grown plant placed in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedPlant {
    /// A name for pictures and exports (`tree`, `herb 3`, ...).
    pub label: String,
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
            position: p.position(),
            plant: p.plant().clone(),
            biomass: p.biomass(),
        })
        .collect()
}

/// Horizontal shape of a plant's leaves, measured from its foot.
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
}

impl CrownShape {
    /// Measures `plant`'s leaves; `towards` is a horizontal direction (the light's).
    pub fn of(plant: &Plant, towards: Vec2) -> CrownShape {
        let towards = towards.normalize_or_zero();
        let mut shape = CrownShape::default();
        let mut sum = Vec2::ZERO;
        for s in &plant.segments {
            shape.height = shape.height.max(s.end.y).max(s.start.y);
            let leaf = plant
                .materials
                .get(s.material.index())
                .is_some_and(|m| m.kind == MaterialKind::Leaf);
            if !leaf {
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
    /// Steps the tree grows alone before the herbs are sown. Default 120.
    #[serde(default = "default_head_start")]
    pub head_start: u32,
    /// Steps everything then grows together. Default 60.
    #[serde(default = "default_herb_steps")]
    pub steps: u32,
    /// Radius of the ring of herbs under the crown, metres. Default 0.8.
    #[serde(default = "default_inner")]
    pub inner_radius: f32,
    /// Radius of the ring of herbs in the open, metres. Default 3.2.
    #[serde(default = "default_outer")]
    pub outer_radius: f32,
    /// Herbs in each ring, 1 to 64. Default 6.
    #[serde(default = "default_per_ring")]
    pub herbs_per_ring: u32,
}

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
    /// Loads the genomes (relative to `base`) and runs.
    pub fn run(&self, base: &Path) -> Result<HerbsUnderTreeOutcome, ExperimentError> {
        let tree = load_genome(&base.join(&self.tree))?;
        let herb = load_genome(&base.join(&self.herb))?;
        self.run_with(&tree, &herb)
    }

    /// Runs with genomes already loaded.
    pub fn run_with(
        &self,
        tree: &LSystemGenome,
        herb: &LSystemGenome,
    ) -> Result<HerbsUnderTreeOutcome, ExperimentError> {
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
        let world = with_light(&self.world, vertical());
        let mut garden = Garden::new(world, sowings)?;
        garden.run(self.head_start + self.steps)?;
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
    /// Steps to grow. Default 150.
    #[serde(default = "default_lateral_steps")]
    pub steps: u32,
    /// Distance between the two trees, metres; they stand side by side across the light.
    /// Default 3.
    #[serde(default = "default_lateral_spacing")]
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
}

impl LateralLight {
    /// Loads the genome (relative to `base`) and runs.
    pub fn run(&self, base: &Path) -> Result<LateralLightOutcome, ExperimentError> {
        let tree = load_genome(&base.join(&self.tree))?;
        self.run_with(&tree)
    }

    /// Runs with the genome already loaded.
    pub fn run_with(&self, tree: &LSystemGenome) -> Result<LateralLightOutcome, ExperimentError> {
        let source = self.world.light.towards_source();
        let towards = Vec2::new(source.x, source.z);
        if towards.length() < 1e-3 {
            return Err(ExperimentError::Config(
                "lateral-light needs a light below 90 degrees of elevation".into(),
            ));
        }
        // Side by side across the light.
        let across = Vec2::new(-towards.y, towards.x).normalize() * (0.5 * self.spacing);
        let grow = |world: EnvironmentSettings| -> Result<Garden, ExperimentError> {
            let sowings = vec![
                Sowing::new(tree.clone(), -across),
                Sowing::new(tree.clone(), across),
            ];
            let mut garden = Garden::new(world, sowings)?;
            garden.run(self.steps)?;
            Ok(garden)
        };
        let lateral = grow(self.world)?;
        let control = grow(with_light(&self.world, vertical()))?;
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
    #[serde(default = "default_generations")]
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
    /// Loads the start genome if any (relative to `base`) and runs.
    pub fn run(&self, base: &Path) -> Result<EmptyRulesOutcome, ExperimentError> {
        let start = match &self.start {
            Some(p) => load_genome(&base.join(p))?,
            None => LSystemGenome::empty(),
        };
        self.run_with(&start)
    }

    /// Runs from a genome already loaded.
    pub fn run_with(&self, start: &LSystemGenome) -> Result<EmptyRulesOutcome, ExperimentError> {
        if !(1..=10_000).contains(&self.generations) {
            return Err(ExperimentError::Config(format!(
                "`generations` must be 1 to 10000, got {}",
                self.generations
            )));
        }
        let run = evolve_biomorphs(
            start,
            &self.breed,
            self.generations,
            self.seed,
            largest_biomass,
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
    /// Runs the experiment; genome paths are relative to `base` (the config's folder).
    pub fn run(&self, base: &Path) -> Result<SimulationOutcome, ExperimentError> {
        Ok(match self {
            Simulation::HerbsUnderTree(c) => SimulationOutcome::HerbsUnderTree(c.run(base)?),
            Simulation::LateralLight(c) => SimulationOutcome::LateralLight(c.run(base)?),
            Simulation::EmptyRules(c) => SimulationOutcome::EmptyRules(c.run(base)?),
        })
    }
}

impl SimulationOutcome {
    /// The measured outcome, one figure a line.
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
                        g.stats.modules[0],
                        g.stats.modules[2],
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

    /// The grown plants, placed in the world.
    pub fn plants(&self) -> &[PlacedPlant] {
        match self {
            SimulationOutcome::HerbsUnderTree(o) => &o.plants,
            SimulationOutcome::LateralLight(o) => &o.plants,
            SimulationOutcome::EmptyRules(o) => &o.plants,
        }
    }

    /// Per plant and step records as CSV.
    pub fn csv(&self) -> String {
        match self {
            SimulationOutcome::HerbsUnderTree(o) => records_csv(&o.records),
            SimulationOutcome::LateralLight(o) => records_csv(&o.records),
            SimulationOutcome::EmptyRules(o) => records_csv(&o.run.last.records),
        }
    }
}
