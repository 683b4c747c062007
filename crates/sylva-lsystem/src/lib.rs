//! Bornhofen and Lattaud's virtual plants: L-system shoots and roots grown in a voxel world
//! of light and minerals by a transport-resistance physiology, bred like biomorphs.
//!
//! - [`grammar`]: the alphabet of Table 1 and rules in the paper's notation.
//! - [`mutate`]: the character and rule operators of section 3.3.
//! - [`interpret`]: strings to sphylls (derivation is kept apart from interpretation).
//! - [`physiology`]: Thornley's two-substrate transport-resistance model.
//! - [`growth`]: one plant growing: apexes paying for their rules, rewriting, re-interpreting.
//! - [`garden`]: plants growing together in a [`sylva_core::environment::Environment`].
//! - [`genome`]: [`LSystemGenome`], its file format, `develop` and the mutation operator.
//! - [`breed`]: the biomorph design loop and an [`sylva_evolve::Problem`] for runs without
//!   a person.
//! - [`experiments`]: the paper's two simulations and the run from empty rules.
//!
//! ```
//! use sylva_lsystem::{LSystemGenome, garden::GrowSettings};
//! use sylva_core::environment::EnvironmentSettings;
//!
//! let bush = LSystemGenome::bush();
//! let small = GrowSettings {
//!     world: EnvironmentSettings { size: [24, 24, 24], soil_layers: 8, ..Default::default() },
//!     steps: 30,
//! };
//! let plant = bush.develop_with(&small, 0)?;
//! assert!(plant.segments().len() > 10);
//! assert!(LSystemGenome::empty().develop_with(&small, 0)?.segments().is_empty());
//! # Ok::<(), sylva_model::DevelopError>(())
//! ```

pub mod breed;
pub mod experiments;
pub mod garden;
pub mod genome;
pub mod grammar;
pub mod growth;
pub mod interpret;
pub mod mutate;
pub mod physiology;

pub use genome::{CompartmentCrossover, LSystemGenome, LSystemMutation};
