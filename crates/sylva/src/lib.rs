//! Sylva's library layer: the one API the command line, the studio and Python call to grow,
//! mesh, export, picture, evolve and breed plants of any model.
//!
//! - [`archive`]: the studio's archive, the SQLite file of `sylva studio --db`: its schema
//!   and migrations, how it is opened beside a running studio, its plants and their parents
//!   ([`archive::Archive`]), for every front end alike.
//! - [`registry`]: the one list of models ([`Registry::standard`]); genome files and
//!   configs name their model and the registry hands them to it.
//! - [`genome`]: [`Genome`], a genome of any model: read from files, grown, and varied by
//!   hand with the model's own operators ([`Genome::mutate`], [`Genome::cross`]).
//! - [`assets`]: grown plants as meshes carrying their origin, scenes of many plants,
//!   exports (GLB, OBJ, VRML97) and pictures.
//! - [`lod`]: a grown plant's levels of detail as assets ([`LodAssets`]): one mesh per
//!   level at about half the triangles of the one before, as files or one scene.
//! - [`skeleton`]: a grown plant as data ([`Skeleton`]): segments, organs, materials and
//!   origin, written as `PLANT.skeleton.json` and read back.
//! - [`preset`]: species presets ([`preset::Preset`]): a genome and how to grow it into a
//!   tree of a species (height, foliage, bark), in one small file.
//! - [`inspect`]: a plausibility report ([`inspect::Report`]): a plant's figures against
//!   the ranges real trees give.
//! - [`biomorph`]: Bornhofen and Lattaud's design loop, a mother and her children grown
//!   together in one voxel world ([`biomorph::Biomorphs`]).
//! - [`experiment`]: their experiments, run from a config into a report, records and
//!   assets ([`Experiment`]).
//! - [`garden`]: PlantMaker gardens and forests, planned, estimated, grown and meshed or
//!   streamed as a GLB.
//! - [`evolution`]: configs ([`Config`]) and runs ([`Evolution`]) of any model that evolves:
//!   step, browse, checkpoint, resume; maps of varieties ([`Varieties`]) and genomes as
//!   vectors for optimisers outside Sylva ([`GenomeSpace`]).
//! - [`report`]: `stats.csv`, `fitness.svg` and experiment reports.
//! - [`files`]: reading input with limits, writing output atomically.
//! - [`error`]: typed errors; [`InputError`] names the file, line, column and what was
//!   expected.
//!
//! ```
//! use sylva::{Genome, GrowOptions, Grown, Registry, Settings};
//!
//! // A genome file of any model, grown into a meshed plant.
//! let text = r#"{"model": "bintree", "format": 1, "depth": 5, "lower_radius": 0.2,
//!   "upper_radius": 0.15, "length": 1.5, "length_ratio": 0.8,
//!   "rotation1": {"angle": 30, "axis": [1, 0, 0]},
//!   "rotation2": {"angle": -30, "axis": [0, 0, 1]}, "min_radius": 0.02}"#;
//! let genome: Genome = Registry::standard().parse_genome(text)?;
//! let grown = Grown::grow(genome.clone(), &GrowOptions::default())?;
//! assert_eq!(grown.plant.segments().len(), 31);
//! // Bred by hand with the model's own operators.
//! let child = genome.mutate(Settings::Default, 7)?;
//! assert_eq!(child.model(), "bintree");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod archive;
pub mod assets;
pub mod biomorph;
pub mod error;
pub mod evolution;
pub mod experiment;
pub mod files;
pub mod garden;
pub mod genome;
pub mod inspect;
pub mod lod;
pub mod picture;
pub mod preset;
pub mod registry;
pub mod report;
pub mod skeleton;

pub use assets::{GrowOptions, Grown, Origin, Placed, SceneAssets};
pub use error::{Error, FieldError, InputError};
pub use evolution::{
    Config, Evolution, EvolveConfig, GenomeSpace, Member, OutputConfig, OwnTerm, PlantScorer,
    RunConfig, RunHooks, Varieties, Variety,
};
pub use experiment::Experiment;
pub use genome::{Genome, Settings};
pub use lod::{LodAssets, Preview};
pub use registry::{ModelEntry, Registry};
pub use registry::{load_genome, parse_genome};
pub use skeleton::Skeleton;
pub use sylva_core::dress::{Dress, Dressed};
pub use sylva_core::species::{BarkKind, LeafKind};
pub use sylva_evolve::{GenerationStats, IndividualId, MapStats};
pub use sylva_lsystem::work::Work;
pub use sylva_model::{CrossLevel, Depth, Knobs};

// The layers below, for front ends that need their types (plants, meshes, scenes, files,
// pictures, the thread pool, budgets): a front end depends on `sylva` alone.
pub use sylva_core as core;
pub use sylva_gltf as gltf;
pub use sylva_mesh as mesh;
pub use sylva_model as model;
pub use sylva_render as render;
