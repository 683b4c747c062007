//! A MAP-Elites run of one model, typed ([`TypedMap`]): a map of the fittest plant of every
//! kind ([`sylva_evolve::map`]), placed by descriptors measured on the grown plant
//! ([`sylva_fitness::descriptors`]) and scored by the model's own terms, with the
//! `[match]` outline if the config has one. [`Varieties`](super::Varieties) is its erased
//! face.

use std::cell::RefCell;
use std::path::Path;
use std::sync::Arc;

use serde::Serialize;
use sylva_core::par::Pool;
use sylva_evolve::map::{Axis, Describe, Emitter, MapCheckpoint, MapRun, MapSettings};
use sylva_evolve::{Problem, WithTerm};
use sylva_fitness::descriptors::{self, Descriptor, Scratch};
use sylva_model::{Evolve, VectorCoding};

use crate::error::{Error, InputError};
use crate::genome::Genome;

use super::checkpoint;
use super::schema::{EmitterKind, EvolveConfig, MapConfig, SearchStrategy};
use super::typed::{Member, Where, member_of, setup, typed_start, with_term};

thread_local! {
    /// Per-thread measuring buffers; they carry nothing between plants.
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Places model `M`'s genomes by descriptors of the plant each grows (with its own seed).
pub(super) struct PlantDescriber<M> {
    pub(super) model: M,
    pub(super) descriptors: Vec<Descriptor>,
}

impl<M: Evolve> Describe<WithTerm<M::Problem>> for PlantDescriber<M> {
    /// A genome that fails to grow is not described.
    fn describe(
        &self,
        problem: &WithTerm<M::Problem>,
        evolved: &<M::Problem as Problem>::Genome,
        out: &mut [f64],
    ) -> bool {
        let genome = self.model.genome_file(&problem.problem, evolved);
        let seed = self.model.default_seed(&genome);
        let Ok(plant) = self.model.develop(&genome, seed) else {
            return false;
        };
        SCRATCH.with(|scratch| {
            descriptors::measure(&plant, &self.descriptors, &mut scratch.borrow_mut(), out);
        });
        true
    }
}

/// A model's direct coding ([`Evolve::vector_coding`]) as CMA-ME emitters search it.
struct DirectCoding<M: Evolve> {
    model: M,
    coding: Box<dyn VectorCoding<M>>,
}

impl<M: Evolve> sylva_evolve::Coding<WithTerm<M::Problem>> for DirectCoding<M> {
    fn bounds(&self) -> &[[f64; 2]] {
        self.coding.bounds()
    }

    fn decode(&self, x: &[f64]) -> <M::Problem as Problem>::Genome {
        self.coding.decode(x)
    }

    fn encode(
        &self,
        problem: &WithTerm<M::Problem>,
        genome: &<M::Problem as Problem>::Genome,
    ) -> Option<Vec<f64>> {
        let file = self.model.genome_file(&problem.problem, genome);
        self.coding.encode(&file).ok()
    }
}

/// What CMA-ME emitters search, for model `M`.
type EngineCoding<M> = Arc<dyn sylva_evolve::Coding<WithTerm<<M as Evolve>::Problem>>>;

/// The coding CMA-ME emitters search, if `config` asks for them; refused, naming the
/// config (`source`), for a model whose genomes have none.
fn emitter_coding<M: Evolve>(
    config: &EvolveConfig<M>,
    problem: &WithTerm<M::Problem>,
    source: &str,
) -> Result<Option<EngineCoding<M>>, Error> {
    let map = config.map.as_ref();
    if map.is_none_or(|m| m.emitter == EmitterKind::Operators) {
        return Ok(None);
    }
    let Some(coding) = config
        .model
        .vector_coding(&problem.problem, config.run.seed)
    else {
        return Err(InputError::new(
            source,
            format!(
                "`[map] emitter = \"cma-me\"` searches genomes as vectors of numbers, and \
                 `{}` genomes have none (their structure varies): CMA-ME searches PlantMaker \
                 and binary trees; use `emitter = \"operators\"`",
                M::NAME
            ),
        )
        .into());
    };
    Ok(Some(Arc::new(DirectCoding {
        model: config.model.clone(),
        coding,
    })))
}

/// One filled cell of a map: where it is, and its elite.
#[derive(Clone, Debug, PartialEq)]
pub struct Variety {
    /// The cell, row-major over the axes (the first slowest).
    pub cell: usize,
    /// The cell's place along each axis.
    pub coordinates: Vec<u32>,
    /// The elite's descriptors, one per axis.
    pub descriptors: Vec<f64>,
    /// The elite.
    pub member: Member,
}

/// A map run of model `M`, with the config it follows (its `[map]` filled in).
pub(crate) struct TypedMap<M: Evolve> {
    pub(super) config: EvolveConfig<M>,
    pub(super) descriptors: Vec<Descriptor>,
    pub(super) run: MapRun<WithTerm<M::Problem>, M::Strategy>,
}

/// The checkpoint file of a map run: the effective config and the engine's checkpoint.
#[derive(Serialize)]
#[serde(bound = "")]
struct SavedMapRef<'a, M: Evolve> {
    config: &'a EvolveConfig<M>,
    checkpoint: MapCheckpoint<<M::Problem as Problem>::Genome>,
}

impl<M: Evolve + Default> TypedMap<M> {
    pub(super) fn varieties(&self) -> Vec<Variety> {
        self.run
            .filled()
            .iter()
            .filter_map(|&cell| self.variety_of(cell))
            .collect()
    }

    pub(super) fn checkpoint(&self) -> Result<String, Error> {
        let saved = SavedMapRef::<M> {
            config: &self.config,
            checkpoint: self.run.checkpoint(),
        };
        serde_json::to_string(&saved)
            .map_err(|e| InputError::new("checkpoint", e))
            .map_err(Error::from)
    }

    pub(super) fn variety_of(&self, cell: usize) -> Option<Variety> {
        let elite = self.run.elite(cell)?;
        Some(Variety {
            cell,
            coordinates: self.run.settings().coordinates(cell),
            descriptors: elite.descriptors.clone(),
            member: member_of(
                &self.config.model,
                &self.run.problem().problem,
                &elite.individual,
            ),
        })
    }
}

/// `config` as a map run's: the strategy set and `[map]` filled in with its defaults.
pub(super) fn as_map<M: Evolve>(config: &EvolveConfig<M>) -> EvolveConfig<M> {
    let mut config = config.clone();
    config.run.strategy = SearchStrategy::MapElites;
    config.map.get_or_insert_with(MapConfig::default);
    config
}

/// The engine's settings of a map run of `config` (a map run's, see [`as_map`]).
pub(super) fn map_settings<M: Evolve>(config: &EvolveConfig<M>) -> (MapSettings, Vec<Descriptor>) {
    let map = config.map.clone().unwrap_or_default();
    let axes = map
        .descriptors
        .iter()
        .map(|a| {
            let (min, max) = a.bounds();
            Axis {
                min,
                max,
                cells: a.cells,
            }
        })
        .collect();
    let settings = MapSettings {
        seed: config.run.seed,
        axes,
        initial: map.initial as usize,
        batch: map.batch as usize,
        crossover: map.crossover,
        qd_offset: map.qd_offset,
        emitter: match map.emitter {
            EmitterKind::Operators => Emitter::Operators,
            EmitterKind::CmaMe => Emitter::CmaMe {
                emitters: map.emitters.unwrap_or(MapConfig::EMITTERS),
                sigma: map.sigma.unwrap_or(MapConfig::SIGMA),
            },
        },
    };
    (settings, map.descriptors.iter().map(|a| a.name).collect())
}

/// Starts a map run of `config`: generation 0 made, evaluated and placed. A refusal names
/// the config (`source`).
pub(crate) fn start_map<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    at: &Where,
    start: Vec<Genome>,
    pool: Pool,
) -> Result<TypedMap<M>, Error> {
    let (source, target) = (at.source.as_str(), at.target.as_ref());
    let config = as_map(config);
    let (settings, descriptors) = map_settings(&config);
    let typed = typed_start::<M>(&start)?;
    // Every cell's elite and a generation of offspring, each at the settings' bounds.
    let held = (settings.cells() + settings.batch.max(settings.initial)) as u64;
    let genome = config.model.genome_bytes(&config.settings);
    sylva_core::budget::check(
        held.saturating_mul(genome).saturating_mul(2),
        format_args!(
            "a map of {} cells and generations of {} (`[map]`)",
            settings.cells(),
            settings.batch.max(settings.initial)
        ),
        "draw a map of fewer cells, or breed smaller batches or smaller genomes",
    )
    .map_err(|e| InputError::new(source, e).over_limit())?;
    // A generation grows up to `initial` or `batch` genomes.
    let mut timed = config.clone();
    timed.run.population = settings.batch.max(settings.initial) as u32;
    if let Some(t) = timed.generation_time(&start, pool.threads()) {
        sylva_core::budget::check_time(t.seconds, t.what, t.advice)
            .map_err(|e| InputError::new(source, e).over_limit())?;
    }
    let setup = setup(
        &config,
        target,
        typed,
        config.run.seed,
        settings.initial,
        source,
    )?;
    let problem = with_term(&config, setup.problem, target)?;
    let coding = emitter_coding(&config, &problem, source)?;
    let describer = Arc::new(PlantDescriber {
        model: config.model.clone(),
        descriptors: descriptors.clone(),
    });
    let run = MapRun::new(
        problem,
        setup.strategy,
        describer,
        coding,
        pool,
        settings,
        setup.first,
    )
    .map_err(|e| InputError::new("[map]", e))?;
    Ok(TypedMap {
        config,
        descriptors,
        run,
    })
}

/// Resumes the map run of `config` saved in a checkpoint's `text` (read from `path`).
pub(crate) fn resume_map<M: Evolve + Default>(
    config: &EvolveConfig<M>,
    at: &Where,
    path: &Path,
    text: &str,
    pool: Pool,
) -> Result<TypedMap<M>, Error> {
    let (source, target) = (at.source.as_str(), at.target.as_ref());
    let config = as_map(config);
    let (saved, engine): (EvolveConfig<M>, MapCheckpoint<_>) = checkpoint::parse(path, text)?;
    if saved.resumable() != config.resumable() {
        return Err(InputError::file(
            path,
            "the checkpoint was written by a different config (only `generations`, \
             `threads` and `checkpoint_seconds` may change when resuming)",
        )
        .into());
    }
    let (settings, descriptors) = map_settings(&config);
    if engine.settings != settings {
        return Err(InputError::file(path, "the checkpoint's map differs from its config").into());
    }
    let setup = setup(&config, target, Vec::new(), 0, 0, source)?;
    let problem = with_term(&config, setup.problem, target)?;
    let coding = emitter_coding(&config, &problem, source)?;
    let describer = Arc::new(PlantDescriber {
        model: config.model.clone(),
        descriptors: descriptors.clone(),
    });
    let run = MapRun::resume(problem, setup.strategy, describer, coding, pool, engine)
        .map_err(|e| InputError::file(path, e))?;
    Ok(TypedMap {
        config,
        descriptors,
        run,
    })
}
