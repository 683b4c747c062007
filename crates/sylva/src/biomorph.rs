//! Bornhofen and Lattaud's design loop (section 4.1) as one workflow: the mother and her
//! mutated children are sown on a 3×3 grid of one voxel world and grow together, shading
//! each other; a person picks the next mother from what grew. The command line's
//! `sylva breed` and the studio's garden mode both run it.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use sylva::biomorph::{BiomorphOptions, Biomorphs};
//! let path = std::path::Path::new("examples/lsystem/herb.json");
//! let mother = sylva::Registry::standard().load_genome(path)?;
//! let sown = Biomorphs::sow(&mother, path, &BiomorphOptions::default(), 1)?;
//! let pool = sylva::core::par::Pool::with_threads(0)?;
//! let garden = sown.grow(&pool, &mut |_step| {})?;
//! let scene = garden.assets(|i, _| format!("specimen-{i}"), |_, s| s.origin(1).extras())?;
//! # Ok(())
//! # }
//! ```

use std::path::{Path, PathBuf};

use sylva_core::glam::Vec3;
use sylva_core::par::Pool;
use sylva_core::{MaterialKind, Plant};
use sylva_lsystem::breed::{BreedSettings, breeding_genomes, breeding_work, grow_together_with};
use sylva_lsystem::{LSystemGenome, LSystemModel};
use sylva_model::Model;

pub use sylva_lsystem::breed::SpecimenStats;

use crate::Work;
use crate::assets::{Origin, Placed, SceneAssets, check_scene_glb};
use crate::error::{Error, InputError};
use crate::genome::Genome;

/// The model whose plants grow in biomorph gardens.
pub const MODEL: &str = LSystemModel::NAME;

/// A genome of another model than [`MODEL`], given to a biomorph garden.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{MODEL}` genomes; this is a `{model}` genome")]
pub struct WrongModel {
    /// The genome's model.
    pub model: &'static str,
}

/// How a biomorph garden is laid out and grown. The defaults are the paper's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiomorphOptions {
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
    /// Keep the roots in the plants handed back (and so in their meshes). Default true.
    pub roots: bool,
}

impl Default for BiomorphOptions {
    fn default() -> Self {
        let paper = BreedSettings::default();
        BiomorphOptions {
            children: paper.children as u32,
            steps: paper.grow.steps,
            spacing: paper.spacing,
            elevation: paper.grow.world.light.elevation,
            azimuth: paper.grow.world.light.azimuth,
            visible_children: paper.visible_children,
            roots: true,
        }
    }
}

impl BiomorphOptions {
    fn settings(&self) -> BreedSettings {
        let mut b = BreedSettings {
            children: self.children as usize,
            spacing: self.spacing,
            visible_children: self.visible_children,
            ..BreedSettings::default()
        };
        b.grow.steps = self.steps;
        b.grow.world.light.elevation = self.elevation;
        b.grow.world.light.azimuth = self.azimuth;
        b
    }
}

/// Checks that `genome` can grow in a biomorph garden.
pub fn grows(genome: &Genome) -> Result<(), WrongModel> {
    mother_of(genome).map(|_| ())
}

fn mother_of(genome: &Genome) -> Result<&LSystemGenome, WrongModel> {
    genome.get::<LSystemModel>().ok_or(WrongModel {
        model: genome.model(),
    })
}

/// Empty rules: the paper's start, from which breeding builds a plant.
pub fn empty_rules() -> Genome {
    Genome::new(LSystemModel, LSystemGenome::empty())
}

/// A mother and her children, sown and not yet grown.
pub struct Biomorphs {
    genomes: Vec<LSystemGenome>,
    settings: BreedSettings,
    roots: bool,
    source: PathBuf,
}

impl Biomorphs {
    /// Sows `mother` and her children, mutated with `seed`; `source` (the mother's file, or
    /// what the front end calls her) is named in errors.
    pub fn sow(
        mother: &Genome,
        source: &Path,
        options: &BiomorphOptions,
        seed: u64,
    ) -> Result<Biomorphs, WrongModel> {
        let settings = options.settings();
        let mut rng = sylva_core::rng::seeded(seed);
        let genomes = breeding_genomes(mother_of(mother)?, &settings, &mut rng);
        Ok(Biomorphs {
            genomes,
            settings,
            roots: options.roots,
            source: source.to_owned(),
        })
    }

    /// Plants sown, the mother's first.
    pub fn len(&self) -> usize {
        self.genomes.len()
    }

    /// True when nothing is sown (never: the mother is).
    pub fn is_empty(&self) -> bool {
        self.genomes.is_empty()
    }

    /// Steps they will grow.
    pub fn steps(&self) -> u32 {
        self.settings.grow.steps
    }

    /// Their work at the genomes' bounds.
    pub fn work(&self) -> Work {
        breeding_work(&self.genomes, &self.settings)
    }

    /// Grows them together on `pool`, calling `on_step` with the steps done. Refused before
    /// the first step when it would take longer than the time budget.
    pub fn grow(
        self,
        pool: &Pool,
        on_step: &mut dyn FnMut(u32),
    ) -> Result<BiomorphGarden, InputError> {
        let garden = grow_together_with(self.genomes, &self.settings, pool, on_step)
            .map_err(|e| InputError::file_error(&self.source, &e))?;
        let specimens = garden
            .specimens
            .into_iter()
            .map(|s| Specimen {
                plant: match self.roots {
                    true => s.plant,
                    false => s.plant.without(MaterialKind::Root),
                },
                genome: Genome::new(LSystemModel, s.genome),
                is_mother: s.is_mother,
                position: Vec3::new(s.position.x, 0.0, s.position.y),
                stats: s.stats,
            })
            .collect();
        Ok(BiomorphGarden {
            specimens,
            source: self.source,
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
}

impl BiomorphGarden {
    /// The specimens meshed where they grew, node `i` named `name(i, specimen)` and carrying
    /// `extras(i, specimen)`.
    pub fn assets(
        &self,
        name: impl Fn(usize, &Specimen) -> String,
        extras: impl Fn(usize, &Specimen) -> serde_json::Value,
    ) -> Result<SceneAssets, Error> {
        let hint = LSystemModel.mesh_hint();
        let placed: Vec<Placed> = self
            .specimens
            .iter()
            .enumerate()
            .map(|(i, s)| Placed {
                translation: s.position,
                extras: Some(extras(i, s)),
                ..Placed::new(name(i, s), &s.plant, hint)
            })
            .collect();
        check_scene_glb(
            &placed,
            false,
            &self.source,
            "grow smaller plants (lower `max_modules` in the mother's `physiology`)",
        )?;
        SceneAssets::mesh(&placed, None).map_err(|e| e.in_file(&self.source))
    }
}
