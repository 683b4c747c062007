//! Sylva's plant models: each turns a genome into a [`Plant`](sylva_core::Plant).
//!
//! - [`automata`]: Poncin's GP trees compiled by cellular encoding into turtle automata,
//!   their simulator and GP operators.
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
//! assert_eq!(plant.segments.len(), 255);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod automata;
pub mod bintree;
pub mod genome;
pub mod lsystem;
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
}
