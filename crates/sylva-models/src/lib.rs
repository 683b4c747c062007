//! Sylva's plant models: each turns a genome into a [`Plant`](sylva_core::Plant).
//!
//! - [`bintree`]: Susinno's recursive binary tree, with its analytic tree measures and the
//!   bit encoding of its genetic algorithm.
//! - [`genome`]: genome files of any model ([`Genome`]), with errors that point at the line
//!   and column.
//!
//! ```
//! use sylva_models::{Genome, bintree::BinTree};
//!
//! let genome = Genome::BinTree(BinTree::default());
//! let text = genome.to_json();
//! assert_eq!(Genome::from_json(&text)?, genome);
//! let plant = genome.develop(0)?;
//! assert_eq!(plant.segments().len(), 255);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod automata;
pub mod bintree;
pub mod genome;
pub mod lsystem;
pub mod plantmaker;
pub mod tag;

pub use genome::{Genome, GenomeError};

/// Why a genome could not be grown.
#[derive(Debug, thiserror::Error)]
pub enum DevelopError {
    /// The plant refused a part (a NaN or negative value slipped through).
    #[error("invalid plant part: {0}")]
    Plant(#[from] sylva_core::PlantError),
    /// The genome could not be serialised for its fingerprint.
    #[error("genome could not be serialised: {0}")]
    Serialize(#[from] serde_json::Error),
    /// The genome asks for a larger plant than the model allows.
    #[error("the plant would have more than {limit} parts (segments and organs)")]
    TooLarge {
        /// The limit, in segments plus organs.
        limit: usize,
    },
    /// An L-system plant could not grow in its world (bad world or physiology settings).
    #[error("{0}")]
    LSystem(#[from] lsystem::garden::GardenError),
}
