//! Bornhofen and Lattaud's virtual plants: L-system shoots and roots.
//!
//! This module holds the morphology so far: the alphabet and rules in the paper's notation
//! ([`grammar`]), the mutation operators of section 3.3 ([`mutate`]), and interpretation into
//! a [`Plant`](sylva_core::Plant) ([`interpret`]). Derivation is kept apart from
//! interpretation. The voxel world of light and minerals and the transport-resistance
//! physiology that drive growth in the paper are not written yet.

pub mod grammar;
pub mod interpret;
pub mod mutate;
