//! Gardens: several plants growing together in one voxel world, competing for light and
//! minerals, for a fixed time.
//!
//! One [`Garden::step`]:
//!
//! 1. seeds whose time has come are sown;
//! 2. every growing plant adds its shade, and the light field is recomputed;
//! 3. every plant reads the light its leaves absorb and states its roots' demands — all
//!    from the same state;
//! 4. the demands are served together ([`Uptake`]): where a voxel is short, every root in it
//!    gets the same fraction;
//! 5. every plant runs its physiology and development, reading the (now fixed) environment;
//! 6. litter and the holdings of plants that died go back to the environment;
//! 7. minerals diffuse; one [`StepRecord`] per plant is kept.
//!
//! No plant sees another's changes of the same step, so the order of plants does not bias
//! the outcome. Steps 3 and 5 run on the caller's [`Pool`] (in parallel if it has threads); every
//! sum over plants is taken in plant order, so the result is the same bytes for any number
//! of threads.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};
use sylva_core::environment::{Environment, EnvironmentError, EnvironmentSettings, Uptake};
use sylva_core::glam::{Vec2, Vec3};
use sylva_core::par::Pool;
use sylva_core::{Plant, PlantError};

use crate::genome::LSystemGenome;
use crate::growth::{BoundsHit, GrowingPlant};
use crate::physiology::PhysiologyError;

/// Most steps one run may ask for.
pub const MAX_STEPS: u32 = 100_000;

/// Most plants a garden may hold.
pub const MAX_PLANTS: usize = 4096;

/// A world and a time to grow in.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GrowSettings {
    /// The world. Default [`EnvironmentSettings::default`] (64³ voxels of 0.125 m).
    pub world: EnvironmentSettings,
    /// Steps to grow, 0 to [`MAX_STEPS`]. Default 150: long enough for the example tree
    /// (`examples/lsystem/tree.json`) to form its crown.
    #[serde(deserialize_with = "steps")]
    pub steps: u32,
}

sylva_core::ranged!(steps: u32, "steps", 0, MAX_STEPS);

impl Default for GrowSettings {
    fn default() -> Self {
        GrowSettings {
            world: EnvironmentSettings::default(),
            steps: 150,
        }
    }
}

/// Why a garden could not grow.
#[derive(Debug, thiserror::Error)]
pub enum GardenError {
    /// The world's settings are out of range.
    #[error("world")]
    Environment(#[from] EnvironmentError),
    /// A genome's physiology is out of range.
    #[error("plant {plant}: {error}")]
    Physiology {
        /// Which plant.
        plant: usize,
        /// What is wrong.
        error: PhysiologyError,
    },
    /// Interpretation produced an invalid part (a NaN slipped through).
    #[error("invalid plant part")]
    Plant(#[from] PlantError),
    /// More steps than [`MAX_STEPS`].
    #[error("{0} steps asked for; at most {MAX_STEPS}")]
    TooManySteps(u64),
    /// More plants than [`MAX_PLANTS`].
    #[error("{0} plants sown; at most {MAX_PLANTS}")]
    TooManyPlants(usize),
    /// A position is not finite.
    #[error("plant {0} is sown at a position that is not finite")]
    BadPosition(usize),
    /// The plants at their bounds and the world would not fit in the memory budget.
    #[error("the garden does not fit in memory")]
    OverBudget(#[from] sylva_core::budget::OverBudget),
    /// Growing would take longer than the time budget ([`crate::work`]).
    #[error("growing would take too long")]
    OverTime(#[from] sylva_core::budget::OverTime),
}

impl From<GardenError> for sylva_model::DevelopError {
    fn from(e: GardenError) -> Self {
        match e {
            GardenError::Plant(e) => sylva_model::DevelopError::Plant(e),
            GardenError::OverBudget(e) => sylva_model::DevelopError::OverBudget(e),
            other => sylva_model::DevelopError::Model(Box::new(other)),
        }
    }
}

/// A seed to sow.
#[derive(Clone, Debug, PartialEq)]
pub struct Sowing {
    /// What grows.
    pub genome: LSystemGenome,
    /// Where on the ground, `(x, z)` metres.
    pub position: Vec2,
    /// The step it is sown at (0: from the start).
    pub sown_at: u32,
}

impl Sowing {
    /// A seed sown at the start.
    pub fn new(genome: LSystemGenome, position: Vec2) -> Sowing {
        Sowing {
            genome,
            position,
            sown_at: 0,
        }
    }
}

/// One plant's figures after one step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StepRecord {
    /// Step, 1-based.
    pub step: u32,
    /// Plant index, in sowing order.
    pub plant: u32,
    /// Biomass (dry mass: structure and pools), grams.
    pub biomass: f64,
    /// Light its leaves absorbed this step.
    pub light: f64,
    /// Minerals its roots took up this step, grams.
    pub uptake: f64,
    /// Modules.
    pub modules: u32,
    /// Leaves.
    pub leaves: u32,
    /// Fine roots.
    pub fine_roots: u32,
    /// True while growing (sown and not dead).
    pub growing: bool,
}

/// Where the carbon and minerals of a garden are, grams: what came in against what is there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Balance {
    /// Seeds' carbon plus all carbon fixed.
    pub carbon_in: f64,
    /// Carbon in plants (pools and biomass) and litter.
    pub carbon_now: f64,
    /// The soil's starting minerals plus the seeds'.
    pub minerals_in: f64,
    /// Minerals in plants and soil.
    pub minerals_now: f64,
}

impl Balance {
    /// Largest relative error of the two balances.
    pub fn error(&self) -> f64 {
        let rel = |a: f64, b: f64| (a - b).abs() / a.abs().max(b.abs()).max(1e-12);
        rel(self.carbon_in, self.carbon_now).max(rel(self.minerals_in, self.minerals_now))
    }
}

/// Plants growing together. See the [module documentation](self).
#[derive(Clone, Debug)]
pub struct Garden {
    env: Environment,
    plants: Vec<GrowingPlant>,
    step: u32,
    records: Vec<StepRecord>,
    uptake: Uptake,
    soil_minerals: f64,
}

impl Garden {
    /// A world with seeds in it. Positions outside the world are allowed (the plant's
    /// modules are then read from the nearest voxels).
    pub fn new(world: EnvironmentSettings, sowings: Vec<Sowing>) -> Result<Garden, GardenError> {
        if sowings.len() > MAX_PLANTS {
            return Err(GardenError::TooManyPlants(sowings.len()));
        }
        // What the plants may grow to (their `max_symbols` and `max_modules`), before the
        // world is made.
        let plants: u64 = sowings
            .iter()
            .map(|s| GrowingPlant::memory_bound(&s.genome.physiology))
            .sum();
        sylva_core::budget::check(
            plants.saturating_add(world.memory_bytes()),
            format_args!(
                "{} plants at their bounds (`max_symbols`, `max_modules`) in a world of {:?} \
                 voxels",
                sowings.len(),
                world.size
            ),
            "lower the bounds, sow fewer plants or use a smaller world",
        )?;
        let env = Environment::new(world)?;
        let mut plants = Vec::with_capacity(sowings.len());
        for (i, s) in sowings.into_iter().enumerate() {
            s.genome
                .physiology
                .validate()
                .map_err(|error| GardenError::Physiology { plant: i, error })?;
            if !s.position.is_finite() {
                return Err(GardenError::BadPosition(i));
            }
            let foot = Vec3::new(s.position.x, 0.0, s.position.y);
            plants.push(GrowingPlant::new(s.genome, foot, s.sown_at)?);
        }
        let soil_minerals = env.total_minerals();
        Ok(Garden {
            env,
            plants,
            step: 0,
            records: Vec::new(),
            uptake: Uptake::default(),
            soil_minerals,
        })
    }

    /// The world.
    pub fn env(&self) -> &Environment {
        &self.env
    }

    /// The plants, in sowing order.
    pub fn plants(&self) -> &[GrowingPlant] {
        &self.plants
    }

    /// Every plant's geometry (foot at the origin), in sowing order.
    pub fn into_plants(self) -> Vec<Plant> {
        self.plants
            .into_iter()
            .map(GrowingPlant::into_plant)
            .collect()
    }

    /// Steps run so far.
    pub fn steps(&self) -> u32 {
        self.step
    }

    /// One record per plant per step, in step then plant order.
    pub fn records(&self) -> &[StepRecord] {
        &self.records
    }

    /// Plants whose growth hit a bound, with what was refused.
    pub fn bounded(&self) -> impl Iterator<Item = (usize, &BoundsHit)> {
        self.plants
            .iter()
            .enumerate()
            .map(|(i, p)| (i, p.bounds()))
            .filter(|(_, b)| b.any())
    }

    /// Runs `steps` steps; each plant's share of a step runs on `pool`.
    pub fn run(&mut self, steps: u32, pool: &Pool) -> Result<(), GardenError> {
        self.run_with(steps, pool, &mut |_| {})
    }

    /// As [`Garden::run`], calling `on_step` with the steps done after each (a progress
    /// bar).
    pub fn run_with(
        &mut self,
        steps: u32,
        pool: &Pool,
        on_step: &mut dyn FnMut(u32),
    ) -> Result<(), GardenError> {
        if u64::from(self.step) + u64::from(steps) > u64::from(MAX_STEPS) {
            return Err(GardenError::TooManySteps(
                u64::from(self.step) + u64::from(steps),
            ));
        }
        for done in 1..=steps {
            self.step(pool)?;
            on_step(done);
        }
        Ok(())
    }

    /// One step (see the [module documentation](self)); each plant's share runs on `pool`.
    pub fn step(&mut self, pool: &Pool) -> Result<(), GardenError> {
        if self.step >= MAX_STEPS {
            return Err(GardenError::TooManySteps(u64::from(self.step) + 1));
        }
        let now = self.step;
        for p in &mut self.plants {
            p.sow_if_due(now);
        }
        self.env.clear_shade();
        for p in &self.plants {
            p.cast_shade(&mut self.env);
        }
        self.env.update_light();

        let env = &self.env;
        pool.map_mut(&mut self.plants, |p| p.gather(env));
        self.uptake.clear();
        for p in &self.plants {
            p.demand(&mut self.uptake);
        }
        self.uptake.apply(&mut self.env);
        for p in &mut self.plants {
            p.collect(&self.uptake);
        }

        let env = &self.env;
        let step = now + 1;
        let results = pool.map_mut(&mut self.plants, |p| p.grow(env, step));
        results
            .into_iter()
            .collect::<Result<Vec<()>, PlantError>>()?;
        for p in &mut self.plants {
            p.settle(&mut self.env);
        }
        self.env.diffuse();
        self.step = step;
        for (i, p) in self.plants.iter().enumerate() {
            let c = p.counts();
            self.records.push(StepRecord {
                step,
                plant: i as u32,
                biomass: p.biomass(),
                light: p.last().light,
                uptake: p.last().uptake,
                modules: p.modules(),
                leaves: c[crate::grammar::Module::Leaf.index()],
                fine_roots: c[crate::grammar::Module::FineRoot.index()],
                growing: p.is_growing(),
            });
        }
        Ok(())
    }

    /// Carbon and minerals: what came in against what is there now.
    pub fn balance(&self) -> Balance {
        let mut b = Balance {
            carbon_in: 0.0,
            carbon_now: self.env.total_litter(),
            minerals_in: self.soil_minerals,
            minerals_now: self.env.total_minerals(),
        };
        for p in &self.plants {
            let t = p.totals();
            let (carbon, minerals) = p.holdings();
            b.carbon_in += t.seed_carbon + t.fixed;
            b.carbon_now += carbon;
            b.minerals_in += t.seed_minerals;
            b.minerals_now += minerals;
        }
        b
    }

    /// The records as CSV: a header, then one line per plant per step, numbers with six
    /// decimals (the same garden gives the same bytes).
    pub fn csv(&self) -> String {
        records_csv(&self.records)
    }
}

/// Formats step records as CSV (see [`Garden::csv`]).
pub fn records_csv(records: &[StepRecord]) -> String {
    let mut out =
        String::from("step,plant,biomass,light,uptake,modules,leaves,fine_roots,growing\n");
    for r in records {
        let _ = writeln!(
            out,
            "{},{},{:.6},{:.6},{:.6},{},{},{},{}",
            r.step,
            r.plant,
            r.biomass,
            r.light,
            r.uptake,
            r.modules,
            r.leaves,
            r.fine_roots,
            u8::from(r.growing)
        );
    }
    out
}
