//! Sylva's meshes as files, and files back as meshes.
//!
//! - [`export`]: writing a [`Scene`](sylva_mesh::Scene) as GLB (glTF 2.0 binary, with
//!   instancing, quantisation, lean materials, embedded textures and wind rigs), OBJ with
//!   MTL, VRML97 and STL: [`export::to_glb`], [`export::write_scene`] and the rest.
//! - [`import`]: GLB files read back as a scene ([`import::read_glb`]), for pictures of any
//!   GLB.
//! - [`lod`]: levels of detail, a chain of simplified plants at about half the triangles
//!   each, written as one GLB per level.
//!
//! How it fits: it reads what `sylva-mesh` makes (meshes, scenes, the textures it embeds and
//! the wind rigs it writes) and knows nothing of pictures: the renderer, `sylva-render`,
//! draws scenes without it. Front ends write scenes through the `sylva` library's `export` verbs and read GLBs
//! through `sylva::import`.
//!
//! Every writer is deterministic: the same scene gives the same bytes.

pub mod export;
pub mod import;
pub mod lod;
