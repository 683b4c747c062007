//! From a [`Plant`](sylva_core::Plant) to triangles: the mesher and what every writer and the
//! renderer read.
//!
//! - [`mesh`]: the [`Mesh`] type (shared vertices, one primitive per material).
//! - [`mesher`]: [`Mesher`](mesher::Mesher) turns a plant into a mesh (generalised cylinders
//!   along each axis, parallel-transport frames, shared rings, caps, leaves and flowers, all
//!   with texture coordinates).
//! - [`scene`]: [`Scene`], meshes placed in the world with their origin data.
//! - [`texture`]: bark, leaf and petal textures generated from a material's texture id.
//! - [`atlas`]: leaf and needle atlases and petal cut-outs (grey and alpha) for cards.
//! - [`bark`]: tiling bark colour textures and normal maps, one pair per bark kind.
//! - [`picture`]: which picture a material shows ([`picture::Picture`]), made and encoded
//!   once per process, for every writer and the renderer alike.
//! - [`wind`]: a skin and a looping sway clip for a meshed plant, carried by a
//!   [`SceneNode`] to the GLB writer.
//!
//! How it fits: this crate is the bottom of the geometry layers, on `sylva-core` alone. Files
//! (GLB, OBJ, VRML97, STL, the GLB reader and levels of detail) are `sylva-gltf`; pictures
//! (the software renderer and contact sheets) are `sylva-render`. Both read the meshes,
//! scenes and textures made here, and neither depends on the other; the `sylva` library
//! hands front ends what they need of all three (`sylva::mesh`, `sylva::export`,
//! `sylva::import`, `sylva::render`).
//!
//! A mesh never knows which model made the plant.

pub mod atlas;
pub mod bark;
pub mod mesh;
pub mod mesher;
pub mod picture;
pub mod scene;
pub mod texture;
pub mod wind;

pub use mesh::{Mesh, Primitive};
pub use scene::{Scene, SceneNode};
