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
//! - `config.rs`: [`Config`], a config of any model.
//! - `run.rs`: [`Evolution`], a run of any model.
//! - `typed.rs`: a run of one model, typed: started from its config or resumed, and its
//!   population as [`Member`]s.
//! - `face.rs`: the object-safe faces by which [`Config`], [`Evolution`] and
//!   [`Varieties`] hold a config, a run and a map of one model as any model's, each
//!   implemented once for the typed value it stands for.
//! - `checkpoint.rs`: the checkpoint file a run resumes from.
//! - `hooks.rs`: what a front end adds to a run ([`RunHooks`]): a [`Stop`] that cuts a long
//!   generation short, and a fitness term of its own scored a batch of plants at a time.
//! - `silhouette.rs`: the `[match]` term, a plant's silhouette against target pictures.
//! - `outline.rs`: matches, runs towards target pictures; `trials.rs`: `auto`, the trials
//!   across the models and their log, from which trials killed part way resume.
//! - `typed_map.rs` and `varieties.rs`: a MAP-Elites run of one model, typed, and
//!   [`Varieties`], a MAP-Elites run of any model (`[run] strategy =
//!   "map-elites"` and `[map]`): a map of the fittest plant of every kind.
//! - `typed_space.rs` and `space.rs`: [`GenomeSpace`], any model's genomes as vectors of
//!   numbers, decoded and scored as a map run scores them, for optimisers outside Sylva.

mod checkpoint;
mod config;
mod face;
mod hooks;
pub mod outline;
mod run;
mod schema;
mod silhouette;
mod space;
mod trials;
mod typed;
mod typed_map;
mod typed_space;
mod varieties;

pub use checkpoint::checkpoint_model;
pub use config::{Config, evaluations_done};
pub use hooks::{OwnTerm, PlantScorer, RunHooks, ScorerError, Stop, Stopped};
pub use run::Evolution;
pub use schema::{
    AxisConfig, EmitterKind, EvolveConfig, MapConfig, MatchConfig, OutputConfig, RunConfig,
    SearchStrategy, WindConfig,
};
pub use space::{Coding, Codons, GenomeSpace, MAX_DIM, Scores, SpaceOptions};
pub use sylva_fitness::descriptors::Descriptor;
pub use typed::{GenerationTime, Member};
pub use varieties::{Varieties, Variety};
