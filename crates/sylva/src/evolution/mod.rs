//! Evolution without a person, for any model that can evolve: configs, runs, checkpoints.
//!
//! A config ([`EvolveConfig`]) is TOML: the model's name, the run's size and seed
//! (`[run]`), the model's settings (its own section, `[bintree]`, `[automata]`, ...) and
//! what a run writes (`[output]`). Every section and field is optional; unknown fields are
//! refused; every number is checked against its range while it is read, so an error points
//! at the line and column of the offending value.
//!
//! ```toml
//! model = "bintree"          # the model to evolve; its section follows
//!
//! [run]
//! generations = 150          # generations to breed after the random first one
//! population = 400           # individuals per generation
//! seed = 1                   # seed of every random choice
//! threads = 0                # 0: one per core; results do not depend on it
//! checkpoint_seconds = 2     # 0: checkpoint every generation
//!
//! [bintree]                  # the model's settings (see its crate)
//! mutation_rate = 0.02
//!
//! [output]
//! image_size = 800           # pixels, square, for best.png
//! view = "iso"               # front, side, top or iso
//! sheet_size = 48            # individuals on the contact sheet
//! taper = 2.5                # optional: the pipe model's radii for best.* and the sheet (2 to 3)
//! ```
//!
//! [`Config`] is a config of any model (it knows which from the `model` field, through the
//! [`Registry`](crate::Registry)); [`Evolution`] is a run of any model: step it one generation or a batch,
//! read its statistics, browse its population and each member's family, and write a
//! checkpoint that resumes it exactly.
//!
//! - `schema.rs`: what a config file holds ([`EvolveConfig`] of one model, its `[run]` and
//!   `[output]`), read with every number checked.
//! - `config.rs`: [`Config`], a config of any model, and what it takes to start or resume
//!   a run of it.
//! - `run.rs`: [`Evolution`], a run of any model, and its [`Member`]s.
//!
//! Each holds its model's handle (`erased.rs`) beside the typed value.
//! - `checkpoint.rs`: the checkpoint file a run resumes from.
//! - `hooks.rs`: what a front end adds to a run ([`RunHooks`]): a [`Stop`] that cuts a long
//!   generation short, and a fitness term of its own scored a batch of plants at a time.
//! - `outline.rs`: the `[match]` term, a plant's silhouette against target pictures.
//! - `varieties.rs`: [`Varieties`], a MAP-Elites run of any model (`[run] strategy =
//!   "map-elites"` and `[map]`): a map of the fittest plant of every kind.
//! - `space.rs`: [`GenomeSpace`], any model's genomes as vectors of numbers, decoded and
//!   scored as a map run scores them, for optimisers outside Sylva.

mod checkpoint;
mod config;
mod hooks;
pub mod outline;
mod run;
mod schema;
mod space;
mod varieties;

pub use checkpoint::checkpoint_model;
pub use config::{Config, GenerationTime, evaluations_done};
pub(crate) use config::{resume, start};
pub use hooks::{OwnTerm, PlantScorer, RunHooks, ScorerError, Stop, Stopped};
pub(crate) use run::TypedRun;
pub use run::{Evolution, Member};
pub use schema::{
    AxisConfig, EmitterKind, EvolveConfig, MapConfig, MatchConfig, OutputConfig, RunConfig,
    SearchStrategy, WindConfig,
};
pub use space::{Coding, Codons, GenomeSpace, MAX_DIM, Scores, SpaceOptions};
pub(crate) use space::{SpaceValue, new_space};
pub use sylva_fitness::descriptors::Descriptor;
pub(crate) use varieties::{MapValue, resume_map, start_map};
pub use varieties::{Varieties, Variety};
