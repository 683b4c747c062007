//! Biomorph breeding (section 4.1).
//!
//! [`breed_garden`] builds the paper's design-loop garden: at most nine specimens on a 3 × 3
//! grid, the mother's seed in one corner and her mutated children at even distances, grown
//! together for a fixed time in one world (so they compete, as in the paper's Figure 7).
//! The caller — a person, or [`largest_biomass`] — picks the next mother from the returned
//! [`Specimen`]s. Evolution may start from [`LSystemGenome::empty`], which does not
//! germinate; mutations add rules until plants with leaves and roots appear
//! ([`evolve_biomorphs`] runs that loop with a chooser).

use rand::Rng;
use serde::{Deserialize, Serialize};
use sylva_core::Plant;
use sylva_core::glam::Vec2;
use sylva_core::par::Pool;
use sylva_evolve::Mutate;

use crate::garden::{Garden, GardenError, GrowSettings, Sowing, StepRecord};
use crate::genome::{LSystemGenome, LSystemMutation};
use crate::grammar::Module;
use crate::growth::{BoundsHit, GrowingPlant};
use crate::mutate::MutationRates;
use crate::work::{self, Rules, Work};

/// Most specimens in a breeding garden, as in the paper.
pub const MAX_SPECIMENS: usize = 9;

/// How a breeding garden is laid out and grown.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BreedSettings {
    /// World and growing time. Default [`GrowSettings::default`] (64³ voxels of 0.125 m,
    /// 150 steps).
    pub grow: GrowSettings,
    /// Distance between neighbouring seeds, 0.01 to 1000 metres. Default 2.5.
    #[serde(deserialize_with = "spacing")]
    pub spacing: f32,
    /// Children sown with the mother, 0 to 8. Default 8.
    #[serde(deserialize_with = "children")]
    pub children: usize,
    /// Mutation probabilities. Default [`MutationRates::default`].
    pub rates: MutationRates,
    /// When the mother's shoot draws nothing (empty rules), mutate each child again, up to
    /// [`MAX_REDRAWS`] times, until its shoot draws a module ([`LSystem::draws_within`]), so
    /// that a person breeding by eye has something to choose from. Default false: the paper's
    /// loop, where most first steps from empty rules change nothing visible.
    ///
    /// [`LSystem::draws_within`]: crate::genome::LSystem::draws_within
    pub visible_children: bool,
}

/// Most extra mutations a child of a mother that draws nothing gets with
/// [`BreedSettings::visible_children`].
pub const MAX_REDRAWS: usize = 1000;

/// Derivations of a shoot looked at for a module (the mutations add a rule and a symbol at a
/// time, so a drawn module shows within a few).
const DRAW_STEPS: usize = 8;
/// The longest string looked at.
const DRAW_LIMIT: usize = 4096;

sylva_core::ranged!(spacing: f32, "spacing", 0.01, 1000.0, " m");
sylva_core::ranged!(children: usize, "children", 0, MAX_SPECIMENS - 1);

impl Default for BreedSettings {
    fn default() -> Self {
        BreedSettings {
            grow: GrowSettings::default(),
            spacing: 2.5,
            children: 8,
            rates: MutationRates::default(),
            visible_children: false,
        }
    }
}

/// One grown specimen of a garden.
#[derive(Clone, Debug, PartialEq)]
pub struct Specimen {
    /// Its genome.
    pub genome: LSystemGenome,
    /// True for the mother's own seed.
    pub is_mother: bool,
    /// Where it grew, `(x, z)` metres.
    pub position: Vec2,
    /// Its geometry, foot at the origin.
    pub plant: Plant,
    /// The figures it ended with.
    pub stats: SpecimenStats,
}

/// What a specimen achieved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SpecimenStats {
    /// Biomass (dry mass: structure and pools) at the end, grams.
    pub biomass: f64,
    /// Light absorbed over its life.
    pub light: f64,
    /// Minerals taken up over its life, grams.
    pub uptake: f64,
    /// Modules of each kind: leaves, branches, fine roots, root branches.
    pub modules: [u32; 4],
    /// Rewrites refused by the bounds.
    pub bounds: BoundsHit,
}

impl SpecimenStats {
    /// Stats of a growing plant.
    pub fn of(p: &GrowingPlant) -> SpecimenStats {
        SpecimenStats {
            biomass: p.biomass(),
            light: p.totals().light,
            uptake: p.totals().uptake,
            modules: p.counts(),
            bounds: *p.bounds(),
        }
    }

    /// Leaves it has.
    pub fn leaves(&self) -> u32 {
        self.modules[Module::Leaf.index()]
    }

    /// Fine roots it has.
    pub fn fine_roots(&self) -> u32 {
        self.modules[Module::FineRoot.index()]
    }

    /// True when it grew at least one module.
    pub fn germinated(&self) -> bool {
        self.modules.iter().any(|&m| m > 0)
    }

    /// True when it has both leaves and fine roots: it can feed itself.
    pub fn has_leaves_and_roots(&self) -> bool {
        self.leaves() > 0 && self.fine_roots() > 0
    }
}

/// A grown breeding garden.
#[derive(Clone, Debug, PartialEq)]
pub struct BredGarden {
    /// The specimens; the mother first.
    pub specimens: Vec<Specimen>,
    /// Per plant and step records.
    pub records: Vec<StepRecord>,
}

/// Position of grid cell `i` (0 to 8, row by row) with the grid centred on the origin;
/// cell 0 is a corner.
pub fn grid_position(i: usize, spacing: f32) -> Vec2 {
    let (row, col) = ((i / 3) as f32, (i % 3) as f32);
    Vec2::new((col - 1.0) * spacing, (row - 1.0) * spacing)
}

/// Grows the given genomes together on the breeding grid (the first in the corner); each
/// plant's share of a step runs on `pool`. Refused before the first step when it would take
/// longer than the time budget ([`breeding_work`]).
pub fn grow_together(
    genomes: Vec<LSystemGenome>,
    settings: &BreedSettings,
    pool: &Pool,
) -> Result<BredGarden, GardenError> {
    grow_together_with(genomes, settings, pool, &mut |_| {})
}

/// As [`grow_together`], calling `on_step` with the steps done after each (a progress bar).
pub fn grow_together_with(
    genomes: Vec<LSystemGenome>,
    settings: &BreedSettings,
    pool: &Pool,
    on_step: &mut dyn FnMut(u32),
) -> Result<BredGarden, GardenError> {
    if genomes.len() > MAX_SPECIMENS {
        return Err(GardenError::TooManyPlants(genomes.len()));
    }
    let sowings: Vec<Sowing> = genomes
        .into_iter()
        .enumerate()
        .map(|(i, g)| Sowing::new(g, grid_position(i, settings.spacing)))
        .collect();
    if let Some(first) = sowings.first() {
        work::garden(
            &settings.grow.world,
            &sowings,
            settings.grow.steps,
            Rules::Known,
        )
        .check(
            pool.threads(),
            format_args!(
                "a breeding round of {}",
                breeding_what(sowings.len(), settings, &first.genome)
            ),
            BREEDING_ADVICE,
        )?;
    }
    let mut garden = Garden::new(settings.grow.world, sowings)?;
    garden.run_with(settings.grow.steps, pool, on_step)?;
    let records = garden.records().to_vec();
    let specimens = garden
        .plants()
        .iter()
        .enumerate()
        .map(|(i, p)| Specimen {
            genome: p.genome().clone(),
            is_mother: i == 0,
            position: Vec2::new(p.position().x, p.position().z),
            plant: p.plant().clone(),
            stats: SpecimenStats::of(p),
        })
        .collect();
    Ok(BredGarden { specimens, records })
}

/// What to change when breeding would take too long.
const BREEDING_ADVICE: &str = "lower `max_symbols` and `max_modules` in the mother's \
     `physiology` (her children keep it), or her module lengths";

/// "9 plants growing 150 steps, each up to ...".
fn breeding_what(plants: usize, settings: &BreedSettings, mother: &LSystemGenome) -> String {
    format!(
        "{plants} plants growing {} steps, each up to {}",
        settings.grow.steps,
        work::bounds(&mother.physiology)
    )
}

/// The work of growing `genomes` on the breeding grid ([`grow_together`]), at their bounds
/// ([`crate::work`]).
pub fn breeding_work(genomes: &[LSystemGenome], settings: &BreedSettings) -> Work {
    let sowings: Vec<Sowing> = genomes
        .iter()
        .enumerate()
        .map(|(i, g)| Sowing::new(g.clone(), grid_position(i, settings.spacing)))
        .collect();
    work::garden(
        &settings.grow.world,
        &sowings,
        settings.grow.steps,
        Rules::Known,
    )
}

/// The mother and `settings.children` mutated children, as [`breed_garden`] sows them.
pub fn breeding_genomes<R: Rng + ?Sized>(
    mother: &LSystemGenome,
    settings: &BreedSettings,
    rng: &mut R,
) -> Vec<LSystemGenome> {
    let mutation = LSystemMutation {
        rates: settings.rates,
        parameter_scale: 0.0,
    };
    let children = settings.children.min(MAX_SPECIMENS - 1);
    let draws = |g: &LSystemGenome| g.shoot.draws_within(DRAW_STEPS, DRAW_LIMIT);
    let redraw = settings.visible_children && !draws(mother);
    let mut genomes = Vec::with_capacity(children + 1);
    genomes.push(mother.clone());
    for _ in 0..children {
        let mut child = mother.clone();
        mutation.mutate(&mut child, rng);
        for _ in 0..MAX_REDRAWS {
            if !redraw || draws(&child) {
                break;
            }
            mutation.mutate(&mut child, rng);
        }
        genomes.push(child);
    }
    genomes
}

/// The paper's design-loop garden: the mother in a corner and `settings.children` mutated
/// children ([`breeding_genomes`]), grown together.
pub fn breed_garden<R: Rng + ?Sized>(
    mother: &LSystemGenome,
    settings: &BreedSettings,
    rng: &mut R,
    pool: &Pool,
) -> Result<BredGarden, GardenError> {
    grow_together(breeding_genomes(mother, settings, rng), settings, pool)
}

/// The chooser of runs without a person: the specimen with the largest biomass. On a tie
/// the child is preferred to the mother (the last of the tied children), so evolution can
/// drift through neutral changes — from empty rules, most first steps change nothing.
pub fn largest_biomass(garden: &BredGarden) -> usize {
    let mut best = 0;
    for (i, s) in garden.specimens.iter().enumerate() {
        if s.stats.biomass >= garden.specimens[best].stats.biomass {
            best = i;
        }
    }
    best
}

/// One generation of a biomorph run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BiomorphGeneration {
    /// Generation, from 1.
    pub generation: u32,
    /// Index of the chosen specimen.
    pub chosen: usize,
    /// The chosen specimen's figures.
    pub stats: SpecimenStats,
    /// Specimens that grew at least one module.
    pub germinated: usize,
}

/// A biomorph run: each generation's choice, and the last garden.
#[derive(Clone, Debug, PartialEq)]
pub struct BiomorphRun {
    /// One entry per generation.
    pub generations: Vec<BiomorphGeneration>,
    /// The mother chosen last.
    pub mother: LSystemGenome,
    /// The last garden grown.
    pub last: BredGarden,
}

impl BiomorphRun {
    /// The first generation whose chosen plant had leaves and fine roots, if any.
    pub fn first_with_leaves_and_roots(&self) -> Option<u32> {
        self.generations
            .iter()
            .find(|g| g.stats.has_leaves_and_roots())
            .map(|g| g.generation)
    }
}

/// Runs `generations` rounds of the design loop from `start`, letting `choose` pick each
/// next mother. Generation `g`'s mutations read stream `(seed, g, 0)`, so a run is
/// repeatable.
pub fn evolve_biomorphs(
    start: &LSystemGenome,
    settings: &BreedSettings,
    generations: u32,
    seed: u64,
    choose: impl FnMut(&BredGarden) -> usize,
    pool: &Pool,
) -> Result<BiomorphRun, GardenError> {
    evolve_biomorphs_with(
        start,
        settings,
        generations,
        seed,
        choose,
        pool,
        &mut |_| {},
    )
}

/// The work of [`evolve_biomorphs`] for `generations` rounds from `start`: each round
/// `settings.children + 1` plants at their bounds, with any rules and sizes mutation may
/// give them ([`Rules::Any`]).
pub fn biomorphs_work(start: &LSystemGenome, settings: &BreedSettings, generations: u32) -> Work {
    let plants = settings.children.min(MAX_SPECIMENS - 1) + 1;
    let sowings: Vec<Sowing> = (0..plants)
        .map(|i| Sowing::new(start.clone(), grid_position(i, settings.spacing)))
        .collect();
    work::garden(
        &settings.grow.world,
        &sowings,
        settings.grow.steps,
        Rules::Any,
    )
    .times(u64::from(generations.max(1)))
}

/// As [`evolve_biomorphs`], calling `on_step` with the garden steps done so far, over all
/// generations (a progress bar). Refused before the first round when the rounds would take
/// longer than the time budget ([`biomorphs_work`]).
pub fn evolve_biomorphs_with(
    start: &LSystemGenome,
    settings: &BreedSettings,
    generations: u32,
    seed: u64,
    mut choose: impl FnMut(&BredGarden) -> usize,
    pool: &Pool,
    on_step: &mut dyn FnMut(u64),
) -> Result<BiomorphRun, GardenError> {
    biomorphs_work(start, settings, generations).check(
        pool.threads(),
        format_args!(
            "{generations} breeding rounds (`generations`) of {}",
            breeding_what(
                settings.children.min(MAX_SPECIMENS - 1) + 1,
                settings,
                start
            )
        ),
        format_args!("breed fewer generations or for fewer steps, or {BREEDING_ADVICE}"),
    )?;
    let steps = u64::from(settings.grow.steps);
    let mut mother = start.clone();
    let mut record = Vec::new();
    let mut last = None;
    for generation in 1..=generations {
        let mut rng = sylva_core::rng::stream(seed, generation, 0);
        let before = u64::from(generation - 1) * steps;
        let garden = grow_together_with(
            breeding_genomes(&mother, settings, &mut rng),
            settings,
            pool,
            &mut |done| on_step(before + u64::from(done)),
        )?;
        let chosen = choose(&garden).min(garden.specimens.len().saturating_sub(1));
        let specimen = &garden.specimens[chosen];
        record.push(BiomorphGeneration {
            generation,
            chosen,
            stats: specimen.stats,
            germinated: garden
                .specimens
                .iter()
                .filter(|s| s.stats.germinated())
                .count(),
        });
        mother = specimen.genome.clone();
        last = Some(garden);
    }
    let last = match last {
        Some(g) => g,
        None => grow_together(vec![mother.clone()], settings, pool)?,
    };
    Ok(BiomorphRun {
        generations: record,
        mother,
        last,
    })
}
