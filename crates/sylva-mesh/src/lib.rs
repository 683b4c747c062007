//! From a [`Plant`](sylva_core::Plant) to triangles, files and pictures.
//!
//! - [`mesh`]: the [`Mesh`] type (shared vertices, one primitive per material).
//! - [`mesher`]: [`Mesher`](mesher::Mesher) turns a plant into a mesh (generalised cylinders
//!   along each axis, parallel-transport frames, shared rings, caps, leaves and flowers, all
//!   with texture coordinates).
//! - [`scene`]: [`Scene`], meshes placed in the world with their origin data.
//! - [`export`]: GLB (glTF 2.0 binary), OBJ with MTL, VRML97.
//! - [`import`]: GLB files read back, for pictures of any GLB.
//! - [`lod`]: levels of detail, a chain of simplified plants at about half the triangles each.
//! - [`render`]: a software z-buffer renderer writing PNG, and contact sheets.
//! - [`texture`]: bark, leaf and petal textures generated from a material's texture id.
//!
//! A mesh never knows which model made the plant.

pub mod export;
pub mod import;
pub mod lod;
pub mod mesh;
pub mod mesher;
pub mod render;
pub mod scene;
pub mod texture;
pub mod wind;

pub use mesh::{Mesh, Primitive};
pub use scene::{Scene, SceneNode};
