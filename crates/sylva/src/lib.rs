//! Sylva's library layer: the one API the command line, the studio and Python call to grow,
//! mesh, export, picture, evolve and breed plants of any model.
//!
//! - [`archive`]: the studio's archive, the SQLite file of `sylva studio --db`: its schema
//!   and migrations, how it is opened beside a running studio, its plants and their parents
//!   ([`archive::Archive`]), for every front end alike.
//! - [`registry`]: the one list of models ([`Registry::standard`]); genome files and
//!   configs name their model and the registry hands them to it, and each model's line says
//!   which workflows of its own it offers.
//! - [`genome`]: [`Genome`], a genome of any model: read from files, grown, and varied by
//!   hand with the model's own operators ([`Genome::mutate`], [`Genome::cross`]).
//! - [`assets`]: grown plants as meshes carrying their origin, scenes of many plants,
//!   and pictures.
//! - [`export`]: the one verb scenes are written with: GLB, OBJ, VRML97 or STL, as bytes
//!   or files.
//! - [`lod`]: a grown plant's levels of detail as assets ([`LodAssets`]): one mesh per
//!   level at about half the triangles of the one before, as files or one scene.
//! - [`skeleton`]: a grown plant as data ([`Skeleton`]): segments, organs, materials and
//!   origin, written as `PLANT.skeleton.json` and read back.
//! - [`preset`]: species presets ([`preset::Preset`]): a genome and how to grow it into a
//!   tree of a species (height, foliage, bark), in one small file.
//! - [`inspect`]: a plausibility report ([`inspect::Report`]): a plant's figures against
//!   the ranges real trees give.
//! - [`biomorph`]: the biomorph loop (Bornhofen and Lattaud's design loop), a mother and
//!   her children grown together in one world ([`biomorph::Biomorphs`]), for any model
//!   whose registry line offers it.
//! - [`experiment`]: experiments run from a config into a report, records and assets
//!   ([`Experiment`]), for any model whose registry line offers them.
//! - [`garden`]: gardens and forests, planned, estimated, grown and meshed or streamed as a
//!   GLB, for any model whose registry line offers them.
//! - [`evolution`]: configs ([`Config`]) and runs ([`Evolution`]) of any model that evolves:
//!   step, browse, checkpoint, resume; maps of varieties ([`Varieties`]) and genomes as
//!   vectors for optimisers outside Sylva ([`GenomeSpace`]).
//! - [`report`]: `stats.csv`, `fitness.svg` and experiment reports.
//! - [`files`]: reading input with limits, writing output atomically.
//! - [`error`]: typed errors; [`InputError`] names the file, line, column and what was
//!   expected.
//! - [`models`]: the models' settings types, item by item, for settings built in code.
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
pub mod export;
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
pub use skeleton::Skeleton;
pub use sylva_core::dress::{Dress, Dressed};
pub use sylva_core::species::{BarkKind, LeafKind};
pub use sylva_evolve::{GenerationStats, IndividualId, MapStats};
pub use sylva_model::Work;
pub use sylva_model::{CrossLevel, Depth, Knobs};

/// Model settings a front end builds in code (the studio's design and family forms), item
/// by item: the models' handles, their settings types and the parts those are made of.
/// Each reads and writes as its section of an evolution config does, with the same checks.
pub mod models {
    pub use sylva_automata::{AutomataModel, AutomataSettings, Growth};
    pub use sylva_bintree::BinTreeModel;
    pub use sylva_evolve::GenerationalSettings;
    pub use sylva_fitness::poncin::{
        DensityGrid, EndpointRule, GridCell, GridConfig, NumTarget, PAPER_TARGET, PoncinFitness,
        PoncinWeights, TargetShape,
    };
}

// What front ends need of the layers below, item by item (a front end depends on `sylva`
// alone; `scripts/check-layers` refuses a whole crate re-exported here).

/// Plants, the thread pool, budgets, seeds and measures (`sylva-core`).
pub mod core {
    pub use sylva_core::{MaterialKind, Plant, PlantMeta};

    /// Memory and time budgets of a process.
    pub mod budget {
        pub use sylva_core::budget::{
            Seconds, default_budget, max_memory, max_time, parse_bytes, parse_duration,
            set_max_memory, set_max_time,
        };
    }
    /// Leaves and bark on any plant.
    pub mod dress {
        pub use sylva_core::dress::dress;
    }
    /// Placement in a scene.
    pub mod glam {
        pub use sylva_core::glam::{DVec3, Quat, Vec3};
    }
    /// Hashes that do not change between runs or machines.
    pub mod hash {
        pub use sylva_core::hash::stable_hash;
    }
    /// Susinno's tree measures.
    pub mod measures {
        pub use sylva_core::measures::TreeMeasures;
    }
    /// The one parallel seam: a pool of threads and the stop that cuts work short.
    pub mod par {
        pub use sylva_core::par::{Pool, Stop};
    }
    /// Seeded random streams.
    pub mod rng {
        pub use sylva_core::rng::seeded;
    }
    /// Foliage and bark kinds.
    pub mod species {
        pub use sylva_core::species::UnknownKind;
    }
    /// The pipe model's taper.
    pub mod taper {
        pub use sylva_core::taper::PipeTaper;
    }
}

/// Every model's genome field by field ([`ModelEntry::schema`](registry::ModelEntry::schema)):
/// what a panel, Python or the docs show, and what a value is checked against.
pub mod schema {
    pub use sylva_model::schema::{Editor, FieldSpec, Kind, ListSpec, Schema, StructureSpec};
}

/// GLBs read back (`sylva-gltf`): a file's scene, its first node's extras, its textures.
/// Scenes are written through [`export`].
pub mod import {
    pub use sylva_gltf::import::{ImportedScene, first_extras, read_glb, texture_ids};
}

/// Meshes, scenes, textures and wind rigs (`sylva-mesh`).
pub mod mesh {
    pub use sylva_mesh::{Mesh, Scene, SceneNode};

    /// The pictures a material shows.
    pub mod picture {
        pub use sylva_mesh::picture::Picture;
    }
    /// Procedural textures.
    pub mod texture {
        pub use sylva_mesh::texture::texture_png;
    }
    /// Wind rigs.
    pub mod wind {
        pub use sylva_mesh::wind::{MAX_JOINTS, WindError, WindOptions};
    }
}

/// Pictures: the renderer's views, contact sheets, overlays, impostors and variety maps
/// (`sylva-render`).
pub mod render {
    pub use sylva_render::{
        CAPTION_HEIGHT, MAX_SIZE, MIN_SIZE, SheetCell, SheetOptions, View, contact_sheet,
        encode_png,
    };

    /// Impostors' pictures.
    pub mod impostor {
        pub use sylva_render::impostor::impostor;
    }
    /// Variety maps' pictures.
    pub mod map {
        pub use sylva_render::map::{MapAxis, MapPicture, map_picture};
    }
    /// Outline overlays.
    pub mod overlay {
        pub use sylva_render::overlay::overlay;
    }
}
