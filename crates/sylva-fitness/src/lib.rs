//! Fitness terms over a [`Plant`](sylva_core::Plant), shared by every model.
//!
//! - [`tree`]: Susinno's six tree measures ([`TreeMeasures`], with two of Sylva's) read
//!   from any plant, and his weighted fitness ([`SusinnoWeights`]), reported term by term.
//! - [`poncin`]: Poncin's terms for GP-grown trees (target surface, branch count, spread,
//!   thickness, density grid) and their weighted total ([`PoncinFitness`]).
//! - [`silhouette`]: the outline term: a plant's silhouette against a target outline
//!   ([`silhouette::Outline`]), as intersection over union.
//! - [`descriptors`]: behaviour descriptors for quality-diversity search (height to width,
//!   porosity, lean, asymmetry, branching depth, bare trunk, leaf count, tips), each a
//!   [`descriptors::Descriptor`] measured on a plant.
//!
//! ```
//! use sylva_fitness::{SusinnoWeights, TreeMeasures};
//! use sylva_bintree::BinTree;
//!
//! let plant = BinTree::default().develop(0)?;
//! let measures = TreeMeasures::of_plant(&plant);
//! let score = SusinnoWeights::default().score(&measures);
//! assert_eq!(score.terms.len(), 8);
//! assert!((score.terms.iter().sum::<f64>() - score.total).abs() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod descriptors;
pub mod poncin;
pub mod silhouette;
pub mod tree;

pub use poncin::{PoncinFitness, PoncinScore, PoncinScratch, PoncinWeights};
pub use tree::{SusinnoScore, SusinnoWeights, TreeMeasures};
