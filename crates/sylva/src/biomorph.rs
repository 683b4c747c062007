//! The biomorph loop (Bornhofen and Lattaud's design loop, section 4.1) for any model that
//! offers it ([`sylva_model::biomorphs::Biomorphs`], said in its registry line): the mother
//! and her mutated children are sown on a 3×3 grid of one world and grow together, shading
//! each other; a person picks the next mother from what grew. The model sows and grows
//! them; this module finds the model in the registry, keeps the genomes typed between
//! sowing and growing, and meshes what grew. The command line's `sylva breed` and the
//! studio's garden mode both run it.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use sylva::biomorph::{BiomorphOptions, Biomorphs};
//! let models = sylva::Registry::standard();
//! let path = std::path::Path::new("examples/lsystem/herb.json");
//! let mother = models.load_genome(path)?;
//! let sown = Biomorphs::sow(&models, &mother, path, &BiomorphOptions::default(), 1)?;
//! let pool = sylva::core::par::Pool::with_threads(0)?;
//! let garden = sown.grow(&pool, &mut |_step| {})?;
//! let scene = garden.assets(|i, _| format!("specimen-{i}"), |_, s| s.origin(1).extras())?;
//! # Ok(())
//! # }
//! ```

use std::error::Error as StdError;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use sylva_core::glam::Vec3;
use sylva_core::par::Pool;
use sylva_core::{MaterialKind, Plant};
use sylva_model::biomorphs;
use sylva_model::{Evolve, Model, Work};

pub use sylva_model::biomorphs::{BiomorphSettings, BoundsHit, SpecimenStats};

use crate::assets::{Origin, Placed, SceneAssets, check_scene_glb};
use crate::error::{Error, InputError};
use crate::genome::Genome;
use crate::registry::{EntryOf, Registry};

/// The models of `registry` whose plants grow in biomorph gardens, in order (the first is
/// the one [`first_mother`] starts with).
pub fn models(registry: &Registry) -> Vec<&'static str> {
    offering(registry).map(|(name, _)| name).collect()
}

/// The models of `registry` that grow biomorphs, with their faces, in order.
fn offering(registry: &Registry) -> impl Iterator<Item = (&'static str, &dyn BiomorphFace)> {
    registry
        .models()
        .iter()
        .filter_map(|m| Some((m.name(), m.offer::<Arc<dyn BiomorphFace>>()?.as_ref())))
}

/// A genome of a model that does not grow biomorphs, given to a biomorph garden.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{expected} genomes; this is a `{model}` genome")]
pub struct WrongModel {
    /// The genome's model.
    pub model: &'static str,
    /// The models that do, as a person reads them (`` `lsystem` ``).
    pub expected: String,
}

impl WrongModel {
    fn of(registry: &Registry, genome: &Genome) -> WrongModel {
        let names: Vec<String> = offering(registry).map(|(n, _)| format!("`{n}`")).collect();
        WrongModel {
            model: genome.model(),
            expected: match names.is_empty() {
                true => "no model's (none here grows biomorphs)".to_owned(),
                false => names.join(" or "),
            },
        }
    }
}

/// How a biomorph garden is laid out and grown (the paper's defaults), and whether the
/// plants handed back keep their roots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiomorphOptions {
    /// The garden: children, steps, spacing, light, visible children.
    pub settings: BiomorphSettings,
    /// Keep the roots in the plants handed back (and so in their meshes). Default true.
    pub roots: bool,
}

impl Default for BiomorphOptions {
    fn default() -> Self {
        BiomorphOptions {
            settings: BiomorphSettings::default(),
            roots: true,
        }
    }
}

/// Checks that `genome` can grow in a biomorph garden: its model offers them in `registry`.
pub fn grows(registry: &Registry, genome: &Genome) -> Result<(), WrongModel> {
    match face_of(registry, genome) {
        Some(_) => Ok(()),
        None => Err(WrongModel::of(registry, genome)),
    }
}

fn face_of<'r>(registry: &'r Registry, genome: &Genome) -> Option<&'r dyn BiomorphFace> {
    let face = registry
        .get(genome.model())?
        .offer::<Arc<dyn BiomorphFace>>()?;
    Some(face.as_ref())
}

/// The mother a garden of `registry`'s first biomorph model starts from when a person
/// brings none (the L-system's empty rules, from which breeding builds a plant).
pub fn first_mother(registry: &Registry) -> Option<Genome> {
    offering(registry)
        .next()
        .map(|(_, face)| face.first_mother())
}

impl<M: biomorphs::Biomorphs + Evolve + Default> EntryOf<M> {
    /// Its plants grow in biomorph gardens (this module).
    pub fn with_biomorphs(self) -> Self {
        self.offering::<Arc<dyn BiomorphFace>>(Arc::new(M::default()))
    }
}

/// What the registry holds of a model that grows biomorphs: its typed trait, erased.
pub(crate) trait BiomorphFace: Send + Sync {
    fn first_mother(&self) -> Genome;
    /// The mother and her children, typed until they grow; `None` when `mother` is not
    /// this model's.
    fn sow(&self, mother: &Genome, settings: BiomorphSettings, seed: u64) -> Option<Box<dyn Sown>>;
}

impl<M: biomorphs::Biomorphs> BiomorphFace for M {
    fn first_mother(&self) -> Genome {
        Genome::new(self.clone(), biomorphs::Biomorphs::first_mother(self))
    }

    fn sow(&self, mother: &Genome, settings: BiomorphSettings, seed: u64) -> Option<Box<dyn Sown>> {
        let genomes = biomorphs::Biomorphs::sow(self, mother.get::<M>()?, &settings, seed);
        Some(Box::new(SownOf {
            model: self.clone(),
            genomes,
            settings,
        }))
    }
}

/// Genomes sown, of one model.
pub(crate) trait Sown: Send {
    fn len(&self) -> usize;
    /// What to change for smaller plants ([`biomorphs::Biomorphs::SMALLER`]).
    fn smaller(&self) -> &'static str;
    fn steps(&self) -> u32;
    fn work(&self) -> Work;
    fn grow(
        self: Box<Self>,
        pool: &Pool,
        on_step: &mut dyn FnMut(u32),
    ) -> Result<Vec<Specimen>, Box<dyn StdError + Send + Sync>>;
}

struct SownOf<M: Model> {
    model: M,
    genomes: Vec<M::Genome>,
    settings: BiomorphSettings,
}

impl<M: biomorphs::Biomorphs> Sown for SownOf<M> {
    fn len(&self) -> usize {
        self.genomes.len()
    }

    fn smaller(&self) -> &'static str {
        M::SMALLER
    }

    fn steps(&self) -> u32 {
        self.settings.steps
    }

    fn work(&self) -> Work {
        self.model.biomorph_work(&self.genomes, &self.settings)
    }

    fn grow(
        self: Box<Self>,
        pool: &Pool,
        on_step: &mut dyn FnMut(u32),
    ) -> Result<Vec<Specimen>, Box<dyn StdError + Send + Sync>> {
        let SownOf {
            model,
            genomes,
            settings,
        } = *self;
        let grown = model.grow_together(genomes, &settings, pool, on_step)?;
        Ok(grown
            .into_iter()
            .map(|s| Specimen {
                genome: Genome::new(model.clone(), s.genome),
                is_mother: s.is_mother,
                position: s.position,
                plant: s.plant,
                stats: s.stats,
            })
            .collect())
    }
}

/// A mother and her children, sown and not yet grown.
pub struct Biomorphs {
    sown: Box<dyn Sown>,
    roots: bool,
    source: PathBuf,
}

impl Biomorphs {
    /// Sows `mother` and her children, mutated with `seed`, by her model in `registry`;
    /// `source` (the mother's file, or what the front end calls her) is named in errors.
    /// A mother of a model that does not grow biomorphs is refused.
    pub fn sow(
        registry: &Registry,
        mother: &Genome,
        source: &Path,
        options: &BiomorphOptions,
        seed: u64,
    ) -> Result<Biomorphs, WrongModel> {
        let sown = face_of(registry, mother)
            .and_then(|face| face.sow(mother, options.settings, seed))
            .ok_or_else(|| WrongModel::of(registry, mother))?;
        Ok(Biomorphs {
            sown,
            roots: options.roots,
            source: source.to_owned(),
        })
    }

    /// Plants sown, the mother's first.
    pub fn len(&self) -> usize {
        self.sown.len()
    }

    /// True when nothing is sown (never: the mother is).
    pub fn is_empty(&self) -> bool {
        self.sown.len() == 0
    }

    /// Steps they will grow.
    pub fn steps(&self) -> u32 {
        self.sown.steps()
    }

    /// Their work at the genomes' bounds.
    pub fn work(&self) -> Work {
        self.sown.work()
    }

    /// Grows them together on `pool`, calling `on_step` with the steps done. Refused before
    /// the first step when it would take longer than the time budget.
    pub fn grow(
        self,
        pool: &Pool,
        on_step: &mut dyn FnMut(u32),
    ) -> Result<BiomorphGarden, InputError> {
        let smaller = self.sown.smaller();
        let mut specimens = self
            .sown
            .grow(pool, on_step)
            .map_err(|e| InputError::file_error(&self.source, &*e))?;
        if !self.roots {
            for s in &mut specimens {
                s.plant = s.plant.without(MaterialKind::Root);
            }
        }
        Ok(BiomorphGarden {
            specimens,
            source: self.source,
            smaller,
        })
    }
}

/// A specimen of a grown biomorph garden.
pub struct Specimen {
    /// Its genome.
    pub genome: Genome,
    /// True for the mother's own seed.
    pub is_mother: bool,
    /// Where its foot stands, metres (y = 0).
    pub position: Vec3,
    /// Its geometry, foot at the origin (roots left out when asked).
    pub plant: Plant,
    /// The figures it ended with.
    pub stats: SpecimenStats,
}

impl Specimen {
    /// Its genome and `seed`, as a node's origin.
    pub fn origin(&self, seed: u64) -> Origin {
        Origin::of(&self.genome, seed)
    }
}

/// A grown biomorph garden: each specimen shaped by its neighbours, so it cannot be grown
/// alone again.
pub struct BiomorphGarden {
    /// The specimens, the mother first.
    pub specimens: Vec<Specimen>,
    source: PathBuf,
    smaller: &'static str,
}

impl BiomorphGarden {
    /// The specimens meshed where they grew, node `i` named `name(i, specimen)` and carrying
    /// `extras(i, specimen)`.
    pub fn assets(
        &self,
        name: impl Fn(usize, &Specimen) -> String,
        extras: impl Fn(usize, &Specimen) -> serde_json::Value,
    ) -> Result<SceneAssets, Error> {
        let placed: Vec<Placed> = self
            .specimens
            .iter()
            .enumerate()
            .map(|(i, s)| Placed {
                translation: s.position,
                extras: Some(extras(i, s)),
                ..Placed::new(name(i, s), &s.plant, s.genome.mesh_hint())
            })
            .collect();
        check_scene_glb(
            &placed,
            false,
            &self.source,
            &format!("grow smaller plants ({})", self.smaller),
        )?;
        SceneAssets::mesh(&placed, None).map_err(|e| e.in_file(&self.source))
    }
}
