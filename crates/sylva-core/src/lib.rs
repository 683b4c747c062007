//! Sylva's shared vocabulary.
//!
//! Every model grows a [`Plant`]; fitness terms, meshing and pictures read only a `Plant`,
//! and a `Plant` keeps its own rules, so they can trust it.
//!
//! - [`turtle`]: the HLU [`Frame`] and [`Turtle`] of *The Algorithmic Beauty of Plants*.
//! - [`environment`]: the voxel world of light and minerals that plants can grow in.
//! - [`plant`]: [`Plant`], its [`Segment`]s, [`Organ`]s and [`Material`]s, with typed ids.
//! - [`measures`]: tips, height, bounds, surface area, volume, and Susinno's
//!   [`TreeMeasures`].
//! - [`hull`]: the volume of a cloud of points' convex hull (a crown's envelope).
//! - [`taper`]: the pipe model's radii for any grown plant.
//! - [`species`]: kinds of foliage and bark with real sizes, and the [`species::Surface`]
//!   a material may carry.
//! - [`dress`]: puts leaves or needles of a kind, and a bark, on any grown plant.
//! - [`budget`]: the memory a job may use (from the limits the process runs under) and the
//!   time it may take, checked before the work starts.
//! - [`hash`]: a stable hash for genome fingerprints.
//! - [`io`]: atomic file writes.
//! - [`par`]: the one seam where work goes parallel ([`par::Pool`]).
//! - [`ranged`](mod@ranged): range-checked fields for genome and config files.
//! - [`rng`]: ChaCha8 streams from a seed, the only source of randomness.
//!
//! Conventions: Y is up, right-handed, metres; angles are radians in code.
//!
//! ```
//! use sylva_core::{Plant, PlantMeta, Turtle, glam::Vec3};
//!
//! let mut plant = Plant::new(PlantMeta::default());
//! let mut turtle = Turtle::default();
//! let base = turtle.position;
//! let top = turtle.forward(2.0);
//! let trunk = plant.add_segment(base, top, (0.2, 0.1), None, false, Plant::BARK)?;
//! turtle.frame.rotate_l(0.6);
//! let tip = turtle.forward(1.0);
//! plant.add_segment(top, tip, (0.1, 0.05), Some(trunk), true, Plant::BARK)?;
//! assert_eq!(plant.tips().count(), 1);
//! assert!(plant.height() > 2.0);
//! # Ok::<(), sylva_core::PlantError>(())
//! ```

pub mod budget;
pub mod dress;
pub mod environment;
pub mod hash;
pub mod hull;
pub mod io;
pub mod measures;
pub mod par;
pub mod plant;
pub mod ranged;
pub mod rng;
pub mod species;
pub mod taper;
pub mod turtle;

pub use glam;
pub use measures::{Aabb, TreeMeasures};
pub use plant::{
    Material, MaterialId, MaterialKind, Organ, OrganKind, Plant, PlantError, PlantMeta, Segment,
    SegmentId,
};
pub use turtle::{Frame, Turtle};
