//! Export, the one verb front ends write scenes with: a [`Scene`] (one grown plant's
//! [`crate::Grown::scene`], a level-of-detail group, a garden, a GLB read back) as the
//! bytes of a format, or as every file the format makes.
//!
//! - [`glb`]: glTF 2.0 binary, one file's bytes.
//! - [`obj`]: Wavefront OBJ and its MTL, as texts.
//! - [`stl`]: binary STL in millimetres, for 3D printing.
//! - [`files`]: every file of the format a path's extension names (an OBJ's MTL and
//!   textures too), each with its path, to zip or stage.
//! - [`write`]: those files written atomically (a GLB streamed, never all in memory).
//!
//! Every verb refuses a scene with a non-finite position or transform (naming the node)
//! before writing anything, so no file holds numbers a reader chokes on.

use std::path::{Path, PathBuf};

use sylva_gltf::export::check_scene;
use sylva_mesh::Scene;

pub use sylva_gltf::export::Format;

use crate::error::{Error, InputError};

/// The GLB of `scene`.
pub fn glb(scene: &Scene<'_>) -> Result<Vec<u8>, Error> {
    Ok(sylva_gltf::export::to_glb(scene)?)
}

/// The OBJ text of `scene` and the text of its MTL, which the OBJ names as `mtl_name`.
pub fn obj(scene: &Scene<'_>, mtl_name: &str) -> Result<(String, String), Error> {
    check_scene(scene)?;
    Ok(sylva_gltf::export::to_obj(scene, mtl_name))
}

/// The binary STL of `scene`, in millimetres.
pub fn stl(scene: &Scene<'_>) -> Result<Vec<u8>, Error> {
    check_scene(scene)?;
    Ok(sylva_gltf::export::to_stl(scene))
}

/// Every file of `scene` exported to `path`, in the format its extension names: the file
/// itself, and for an OBJ its MTL and textures beside it (named after `path`).
pub fn files(scene: &Scene<'_>, path: &Path) -> Result<Vec<(PathBuf, Vec<u8>)>, Error> {
    Ok(sylva_gltf::export::scene_files(path, scene)?)
}

/// Writes `scene` to `path` in the format its extension names (GLB, OBJ with its MTL and
/// textures, VRML97, STL), each file atomically.
pub fn write(scene: &Scene<'_>, path: &Path) -> Result<(), Error> {
    Ok(sylva_gltf::export::write_scene(path, scene)?)
}

/// The format `path`'s extension names, checked before any work is done.
pub fn format(path: &Path) -> Result<Format, InputError> {
    Format::from_path(path).map_err(|e| InputError::file_error(path, &e))
}
