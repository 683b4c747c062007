//! Writing a [`Scene`] to files: GLB (glTF 2.0 binary), OBJ with MTL, VRML97 and STL.
//!
//! - [`to_glb`]: one glTF node per [`SceneNode`](sylva_mesh::SceneNode), one glTF mesh per distinct
//!   [`Mesh`] (nodes borrowing the same mesh share it), the node's extras kept as glTF
//!   `extras`. Checked by the Khronos validator in the tests. [`to_glb_with`] and
//!   [`GlbOptions`] add instancing (`EXT_mesh_gpu_instancing`) and quantisation
//!   (`KHR_mesh_quantization`); [`Glb`] streams the same bytes to a file without holding
//!   them, its meshes made one at a time if need be ([`MeshSource`]).
//! - [`to_obj`]: world-space vertices, one object per node, one `usemtl` per primitive.
//! - [`to_vrml`] / [`to_vrml_with_textures`]: one `Transform` per node, one `Shape` per
//!   primitive.
//! - [`to_stl`]: binary STL in millimetres, for 3D printing: triangles only.
//! - [`write_scene`]: picks the format from the file extension ([`Format::from_path`]) and
//!   writes atomically, so a reader never sees half a file.
//!
//! Textures ([`sylva_mesh::texture`]): a GLB embeds the PNG of each texture id its materials use.
//! OBJ and VRML97 refer to PNG files next to the model, named `<stem>_tex<id>.png` after the
//! model's file stem (made a single word, see [`texture_files`]); [`write_scene`] writes them
//! before the files that name them.
//!
//! Every exporter is deterministic: the same scene gives the same bytes.
//!
//! ```no_run
//! use sylva_core::{Plant, PlantMeta, glam::Vec3};
//! use sylva_gltf::export;
//! use sylva_mesh::{Scene, SceneNode, mesher::{MeshOptions, mesh_plant}};
//!
//! let mut plant = Plant::new(PlantMeta::default());
//! plant.add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.05), None, false, Plant::BARK)?;
//! let mesh = mesh_plant(&plant, &MeshOptions::default())?;
//! let scene = Scene::single(SceneNode::new("plant", &mesh));
//! export::write_scene("plant.glb".as_ref(), &scene)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub(crate) mod glb;
mod lean;
mod obj;
mod stl;
mod vrml;

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

use sylva_mesh::mesh::Mesh;
use sylva_mesh::picture::Picture;
use sylva_mesh::scene::Scene;
use thiserror::Error;

pub use glb::ALPHA_CUTOFF;
pub(crate) use glb::SURFACE_EXTRA;
pub use glb::{
    EXT_MESH_GPU_INSTANCING, Glb, GlbNode, GlbOptions, GlbStats, KHR_MESH_QUANTIZATION, MeshSource,
    mesh_binary_bytes, mesh_binary_floor, to_glb, to_glb_with,
};
pub use obj::to_obj;
pub use stl::to_stl;
pub use vrml::{DEFAULT_TEXTURE_STEM, to_vrml, to_vrml_with_textures};

/// What makes two materials the same in a file: name, colour (bit for bit), texture id and
/// surface. Writers write each distinct one once.
pub(crate) type MaterialKey = (
    String,
    [u32; 3],
    Option<u16>,
    Option<sylva_core::species::Surface>,
);

/// The [`MaterialKey`] of a material.
pub(crate) fn material_key(m: &sylva_core::Material) -> MaterialKey {
    (
        m.name.clone(),
        m.color.map(f32::to_bits),
        m.texture,
        m.surface,
    )
}

/// Why a scene could not be exported.
#[derive(Debug, Error)]
pub enum ExportError {
    /// The file extension names no format this crate writes.
    #[error("unknown export format \".{extension}\" (expected .glb, .obj, .wrl or .stl)")]
    UnknownExtension {
        /// The extension found.
        extension: String,
    },
    /// The path has no extension to pick a format by.
    #[error("{path:?} has no file extension (expected .glb, .obj, .wrl or .stl)")]
    NoExtension {
        /// The path given.
        path: PathBuf,
    },
    /// Writing a file failed.
    #[error("cannot write {path:?}")]
    Io {
        /// The file being written.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: io::Error,
    },
    /// A position, normal, colour or transform is NaN or infinite.
    #[error("node {node}: {what} is not finite")]
    NotFinite {
        /// The scene node.
        node: usize,
        /// Which value.
        what: &'static str,
    },
    /// A node's rotation is a zero quaternion.
    #[error("node {node}: rotation is a zero quaternion")]
    ZeroRotation {
        /// The scene node.
        node: usize,
    },
    /// A mesh has an impostor's material but no picture for it.
    #[error("node {node}: an impostor's material on a mesh without an impostor picture")]
    NoImpostorPicture {
        /// The scene node.
        node: usize,
    },
    /// A mesh has a different number of normals than positions.
    #[error("node {node}: {positions} positions but {normals} normals")]
    NormalCount {
        /// The scene node.
        node: usize,
        /// Positions in its mesh.
        positions: usize,
        /// Normals in its mesh.
        normals: usize,
    },
    /// A mesh has texture coordinates, but not one per position.
    #[error("node {node}: {positions} positions but {uvs} texture coordinates")]
    UvCount {
        /// The scene node.
        node: usize,
        /// Positions in its mesh.
        positions: usize,
        /// Texture coordinates in its mesh.
        uvs: usize,
    },
    /// A texture could not be encoded as PNG.
    #[error("cannot encode texture {picture} as PNG")]
    Png {
        /// The picture's name ([`Picture::name`]).
        picture: String,
        /// What went wrong.
        #[source]
        source: image::ImageError,
    },
    /// A primitive's index count is not a multiple of three.
    #[error("node {node}, primitive {primitive}: {len} indices is not whole triangles")]
    PartialTriangle {
        /// The scene node.
        node: usize,
        /// The primitive.
        primitive: usize,
        /// Its index count.
        len: usize,
    },
    /// A primitive refers to a vertex the mesh does not have.
    #[error("node {node}, primitive {primitive}: index {index} but only {vertices} vertices")]
    IndexOutOfRange {
        /// The scene node.
        node: usize,
        /// The primitive.
        primitive: usize,
        /// The bad index.
        index: u32,
        /// Vertices in the mesh.
        vertices: usize,
    },
    /// A primitive refers to a material the mesh does not have.
    #[error("node {node}, primitive {primitive}: material {material} but only {len} materials")]
    NoSuchMaterial {
        /// The scene node.
        node: usize,
        /// The primitive.
        primitive: usize,
        /// The material asked for.
        material: usize,
        /// Materials in the mesh.
        len: usize,
    },
    /// The GLB would exceed the 4 GiB a GLB header can describe.
    #[error("the GLB would be {bytes} bytes, more than a GLB can hold")]
    TooLarge {
        /// The size it would have.
        bytes: u64,
    },
    /// The file would not fit in the memory budget while it is made.
    #[error("the file does not fit in memory while it is made")]
    OverBudget(#[from] sylva_core::budget::OverBudget),
    /// The glTF JSON could not be written.
    #[error("cannot write the glTF JSON")]
    Json(#[from] serde_json::Error),
    /// A [`MeshSource`] was asked for a mesh it does not have.
    #[error("no mesh {index} in the scene's meshes")]
    NoSuchMesh {
        /// The index asked for.
        index: usize,
    },
    /// A [`MeshSource`] could not make a mesh.
    #[error("meshing")]
    Mesh(#[from] sylva_mesh::mesher::MeshError),
    /// A [`MeshSource`] could not make the plant to mesh.
    #[error("growing the plant of mesh {index}")]
    Source {
        /// The mesh asked for.
        index: usize,
        /// Why.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// A file format [`write_scene`] can write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// glTF 2.0 binary, `.glb`.
    Glb,
    /// Wavefront OBJ with an MTL file, `.obj`.
    Obj,
    /// VRML97, `.wrl`.
    Vrml,
    /// Binary STL in millimetres, `.stl`.
    Stl,
}

impl Format {
    /// The format named by a path's extension (`glb`, `obj`, `wrl` or `stl`, in any case).
    pub fn from_path(path: &Path) -> Result<Format, ExportError> {
        let Some(extension) = path.extension() else {
            return Err(ExportError::NoExtension {
                path: path.to_owned(),
            });
        };
        let extension = extension.to_string_lossy();
        match extension.to_ascii_lowercase().as_str() {
            "glb" => Ok(Format::Glb),
            "obj" => Ok(Format::Obj),
            "wrl" => Ok(Format::Vrml),
            "stl" => Ok(Format::Stl),
            _ => Err(ExportError::UnknownExtension {
                extension: extension.into_owned(),
            }),
        }
    }

    /// The usual file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Glb => "glb",
            Format::Obj => "obj",
            Format::Vrml => "wrl",
            Format::Stl => "stl",
        }
    }
}

/// Writes `scene` to `path` in the format its extension names, each file atomically (see
/// [`scene_files`] for the files an OBJ or VRML97 export adds). The scene is checked first
/// ([`check_scene`]), so no malformed file is written.
pub fn write_scene(path: &Path, scene: &Scene) -> Result<(), ExportError> {
    if Format::from_path(path)? == Format::Glb {
        // Streamed: the file's bytes are never all in memory.
        let mut glb = Glb::of_scene(scene, GlbOptions::default())?;
        return sylva_core::io::write_atomic_with(path, |file| glb.write_to(file)).map_err(
            |source| ExportError::Io {
                path: path.to_owned(),
                source,
            },
        );
    }
    for (file, bytes) in scene_files(path, scene)? {
        sylva_core::io::write_atomic(&file, &bytes).map_err(|source| ExportError::Io {
            path: file.clone(),
            source,
        })?;
    }
    Ok(())
}

/// The files an export of `scene` to `path` consists of, in the order to write them: the
/// textures and the MTL file first (so the model never refers to a missing file), the file
/// at `path` last. An OBJ gets its MTL file next to it, named after the OBJ's stem made a
/// single word (spaces become `_`, as in the OBJ's `mtllib` line); OBJ and VRML97 files also
/// get the PNGs of the textures their materials use ([`texture_files`]). The scene is
/// checked first ([`check_scene`]).
pub fn scene_files(path: &Path, scene: &Scene) -> Result<Vec<(PathBuf, Vec<u8>)>, ExportError> {
    let format = Format::from_path(path)?;
    check_scene(scene)?;
    let stem = path
        .file_stem()
        .map_or_else(|| "scene".to_owned(), |s| s.to_string_lossy().into_owned());
    let sibling = |name: &str| path.with_file_name(name);
    let textures = || -> Result<Vec<(PathBuf, Vec<u8>)>, ExportError> {
        Ok(texture_files(scene, &stem)?
            .into_iter()
            .map(|(name, png)| (sibling(&name), png))
            .collect())
    };
    Ok(match format {
        Format::Glb => vec![(path.to_owned(), to_glb(scene)?)],
        Format::Stl => vec![(path.to_owned(), to_stl(scene))],
        Format::Vrml => {
            let mut files = textures()?;
            files.push((
                path.to_owned(),
                to_vrml_with_textures(scene, &stem).into_bytes(),
            ));
            files
        }
        Format::Obj => {
            let mtl_name = format!("{}.mtl", stem.replace(char::is_whitespace, "_"));
            let (obj, mtl) = to_obj(scene, &mtl_name);
            let mut files = textures()?;
            files.push((sibling(&mtl_name), mtl.into_bytes()));
            files.push((path.to_owned(), obj.into_bytes()));
            files
        }
    })
}

/// The PNG files OBJ and VRML97 exports of `scene` refer to: one `(file name, PNG bytes)`
/// per picture ([`Picture`]) that a material of a primitive with triangles shows (its base
/// picture, normal map and cut-out mask), designs first in id order. Files are named
/// [`Picture::file_name`] with `stem` made a single word as OBJ and VRML names are (letters,
/// digits, `_` and `-` kept, anything else `_`): `<stem>_tex<id>.png` for a texture id,
/// which is how [`to_obj`] (from its MTL file's stem) and [`to_vrml_with_textures`] name them.
pub fn texture_files(scene: &Scene, stem: &str) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    let stem = token(stem);
    used_pictures(scene)
        .into_iter()
        .map(|picture| {
            let png = picture.png().map_err(|source| ExportError::Png {
                picture: picture.name(),
                source,
            })?;
            Ok((picture.file_name(&stem), png.to_vec()))
        })
        .collect()
}

/// Pictures shown by materials of primitives that have triangles, in order.
fn used_pictures(scene: &Scene) -> std::collections::BTreeSet<Picture> {
    scene
        .nodes
        .iter()
        .flat_map(|n| {
            n.mesh
                .primitives
                .iter()
                .filter(|p| !p.indices.is_empty())
                .filter_map(|p| n.mesh.materials.get(p.material))
                .flat_map(|m| {
                    [
                        Picture::base_of(m),
                        Picture::normal_of(m),
                        Picture::mask_of(m),
                    ]
                })
                .flatten()
        })
        // An impostor's picture is its mesh's; only GLB carries it.
        .filter(|p| !matches!(p, Picture::Impostor))
        .collect()
}

/// Checks that every node can be exported faithfully: finite transforms, positions, normals,
/// texture coordinates and colours; as many normals as positions, and as many texture
/// coordinates or none; whole triangles; indices and materials in range.
/// [`to_glb`] and [`write_scene`] call it; [`to_obj`] and [`to_vrml`] instead skip or replace
/// what is broken, so they never fail.
pub fn check_scene(scene: &Scene) -> Result<(), ExportError> {
    for (node, n) in scene.nodes.iter().enumerate() {
        check_node(node, n.translation, n.rotation)?;
        check_mesh(node, n.mesh)?;
    }
    Ok(())
}

/// Checks a node's transform: finite, with a rotation that is not a zero quaternion.
fn check_node(
    node: usize,
    translation: sylva_core::glam::Vec3,
    rotation: sylva_core::glam::Quat,
) -> Result<(), ExportError> {
    if !translation.is_finite() {
        return Err(ExportError::NotFinite {
            node,
            what: "translation",
        });
    }
    if !rotation.is_finite() {
        return Err(ExportError::NotFinite {
            node,
            what: "rotation",
        });
    }
    if rotation.length_squared() < 1e-12 {
        return Err(ExportError::ZeroRotation { node });
    }
    Ok(())
}

fn check_mesh(node: usize, mesh: &Mesh) -> Result<(), ExportError> {
    let finite = |v: &[[f32; 3]]| v.iter().flatten().all(|c| c.is_finite());
    if mesh.normals.len() != mesh.positions.len() {
        return Err(ExportError::NormalCount {
            node,
            positions: mesh.positions.len(),
            normals: mesh.normals.len(),
        });
    }
    if !finite(&mesh.positions) {
        return Err(ExportError::NotFinite {
            node,
            what: "a vertex position",
        });
    }
    if !finite(&mesh.normals) {
        return Err(ExportError::NotFinite {
            node,
            what: "a vertex normal",
        });
    }
    if !mesh.uvs.is_empty() && mesh.uvs.len() != mesh.positions.len() {
        return Err(ExportError::UvCount {
            node,
            positions: mesh.positions.len(),
            uvs: mesh.uvs.len(),
        });
    }
    if !mesh.uvs.iter().flatten().all(|c| c.is_finite()) {
        return Err(ExportError::NotFinite {
            node,
            what: "a texture coordinate",
        });
    }
    if mesh
        .materials
        .iter()
        .flat_map(|m| m.color)
        .any(|c| !c.is_finite())
    {
        return Err(ExportError::NotFinite {
            node,
            what: "a material colour",
        });
    }
    if mesh.impostor.is_none()
        && mesh
            .materials
            .iter()
            .any(|m| m.surface == Some(sylva_core::species::Surface::Impostor))
    {
        return Err(ExportError::NoImpostorPicture { node });
    }
    let vertices = mesh.positions.len();
    for (primitive, p) in mesh.primitives.iter().enumerate() {
        if !p.indices.len().is_multiple_of(3) {
            return Err(ExportError::PartialTriangle {
                node,
                primitive,
                len: p.indices.len(),
            });
        }
        if p.material >= mesh.materials.len() {
            return Err(ExportError::NoSuchMaterial {
                node,
                primitive,
                material: p.material,
                len: mesh.materials.len(),
            });
        }
        if let Some(&index) = p.indices.iter().find(|&&i| i as usize >= vertices) {
            return Err(ExportError::IndexOutOfRange {
                node,
                primitive,
                index,
                vertices,
            });
        }
    }
    Ok(())
}

/// Triangles of a primitive whose three indices address existing vertices; what the text
/// exporters write (a checked scene loses nothing).
fn valid_triangles(indices: &[u32], vertices: usize) -> impl Iterator<Item = [u32; 3]> + '_ {
    indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .filter(move |t| t.iter().all(|&i| (i as usize) < vertices))
}

/// Appends `x` in the shortest form that reads back as the same `f32`; NaN and infinities,
/// which text formats cannot hold, are written as 0.
fn push_float(out: &mut String, x: f32) {
    let x = if x.is_finite() { x } else { 0.0 };
    // -0 reads as 0 everywhere; writing it plainly keeps outputs tidy.
    let x = if x == 0.0 { 0.0 } else { x };
    let _ = write!(out, "{x}");
}

/// Appends three floats separated by spaces.
fn push_vec3(out: &mut String, v: [f32; 3]) {
    push_float(out, v[0]);
    out.push(' ');
    push_float(out, v[1]);
    out.push(' ');
    push_float(out, v[2]);
}

/// A name safe as one token (OBJ names, VRML identifiers): letters, digits, `_` and `-` kept,
/// everything else turned into `_`; never empty.
fn token(name: &str) -> String {
    let mut t: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if t.is_empty() {
        t.push('_');
    }
    t
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use sylva_core::glam::{Quat, Vec2, Vec3};
    use sylva_core::{Organ, OrganKind, Plant, PlantMeta};
    use sylva_mesh::mesher::{MeshOptions, mesh_plant};
    use sylva_mesh::scene::SceneNode;

    /// A small plant with a trunk, a branch, a leaf and a flower.
    pub(crate) fn small_plant() -> Plant {
        let mut p = Plant::new(PlantMeta::default());
        let a = p
            .add_segment(Vec3::ZERO, Vec3::Y, (0.1, 0.08), None, false, Plant::BARK)
            .unwrap();
        let b = p
            .add_segment(
                Vec3::Y,
                Vec3::new(0.5, 1.6, 0.0),
                (0.05, 0.03),
                Some(a),
                true,
                Plant::BARK,
            )
            .unwrap();
        p.add_organ(Organ {
            kind: OrganKind::Leaf,
            position: Vec3::new(0.5, 1.6, 0.0),
            orientation: Quat::from_rotation_z(-0.5),
            size: Vec2::new(0.3, 0.1),
            material: Plant::LEAF,
            parent: Some(b),
        })
        .unwrap();
        p.add_organ(Organ {
            kind: OrganKind::Flower,
            position: Vec3::Y,
            orientation: Quat::IDENTITY,
            size: Vec2::new(0.2, 0.05),
            material: Plant::FLOWER,
            parent: Some(a),
        })
        .unwrap();
        p
    }

    pub(crate) fn small_mesh() -> Mesh {
        mesh_plant(&small_plant(), &MeshOptions::default()).unwrap()
    }

    #[test]
    fn format_from_extension() {
        assert_eq!(
            Format::from_path(Path::new("a/b.GLB")).unwrap(),
            Format::Glb
        );
        assert_eq!(Format::from_path(Path::new("b.obj")).unwrap(), Format::Obj);
        assert_eq!(Format::from_path(Path::new("b.Wrl")).unwrap(), Format::Vrml);
        assert_eq!(Format::from_path(Path::new("b.STL")).unwrap(), Format::Stl);
        let e = Format::from_path(Path::new("b.fbx")).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains(".fbx") && msg.contains(".glb") && msg.contains(".stl"),
            "{msg}"
        );
        assert!(matches!(
            Format::from_path(Path::new("noext")),
            Err(ExportError::NoExtension { .. })
        ));
    }

    #[test]
    fn write_scene_writes_each_format_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = small_mesh();
        let scene = Scene::single(SceneNode::new("plant", &mesh));
        for name in ["p.glb", "p.obj", "p.wrl"] {
            write_scene(&dir.path().join(name), &scene).unwrap();
        }
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["p.glb", "p.mtl", "p.obj", "p.wrl"],
            "no temporary files left"
        );
        let obj = std::fs::read_to_string(dir.path().join("p.obj")).unwrap();
        assert!(obj.contains("mtllib p.mtl"));
        assert_eq!(
            std::fs::read(dir.path().join("p.glb")).unwrap(),
            to_glb(&scene).unwrap()
        );
    }

    #[test]
    fn write_scene_writes_the_textures_obj_and_vrml_name() {
        let dir = tempfile::tempdir().unwrap();
        let mut mesh = small_mesh();
        mesh.materials[0].texture = Some(2);
        mesh.materials[1].texture = Some(5);
        mesh.materials[2].texture = Some(5);
        let scene = Scene::single(SceneNode::new("plant", &mesh));
        for name in ["my tree.obj", "p.wrl", "p.glb"] {
            write_scene(&dir.path().join(name), &scene).unwrap();
        }
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                "my tree.obj",
                "my_tree.mtl",
                "my_tree_tex2.png",
                "my_tree_tex5.png",
                "p.glb",
                "p.wrl",
                "p_tex2.png",
                "p_tex5.png",
            ],
            "one PNG per texture id, named as the files refer to them; no temporary files"
        );
        let png = std::fs::read(dir.path().join("p_tex5.png")).unwrap();
        assert_eq!(png, sylva_mesh::texture::texture(5).png().unwrap());
        let obj = std::fs::read_to_string(dir.path().join("my tree.obj")).unwrap();
        assert!(obj.contains("mtllib my_tree.mtl\n"));
        let mtl = std::fs::read_to_string(dir.path().join("my_tree.mtl")).unwrap();
        assert!(mtl.contains("map_Kd my_tree_tex2.png\n"));
        assert!(mtl.contains("map_Kd -clamp on my_tree_tex5.png\n"));
        let wrl = std::fs::read_to_string(dir.path().join("p.wrl")).unwrap();
        assert!(wrl.contains("url \"p_tex2.png\""));
        assert!(wrl.contains("url \"p_tex5.png\""));

        let files = texture_files(&scene, "a b").unwrap();
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["a_b_tex2.png", "a_b_tex5.png"]);
        // Untextured scenes need no files.
        let plain = small_mesh();
        assert!(
            texture_files(&Scene::single(SceneNode::new("p", &plain)), "p")
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn texture_coordinates_are_checked() {
        let mut mesh = small_mesh();
        mesh.uvs.pop();
        let e = check_scene(&Scene::single(SceneNode::new("x", &mesh))).unwrap_err();
        assert!(matches!(e, ExportError::UvCount { .. }), "{e}");
        let mut mesh = small_mesh();
        mesh.uvs[2][1] = f32::INFINITY;
        let e = check_scene(&Scene::single(SceneNode::new("x", &mesh))).unwrap_err();
        assert!(matches!(e, ExportError::NotFinite { .. }), "{e}");
        // None at all is fine: exporters write (0, 0).
        let mut mesh = small_mesh();
        mesh.uvs.clear();
        check_scene(&Scene::single(SceneNode::new("x", &mesh))).unwrap();
    }

    #[test]
    fn write_scene_refuses_bad_extensions_and_bad_meshes_without_writing() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = small_mesh();
        let scene = Scene::single(SceneNode::new("plant", &mesh));
        let e = write_scene(&dir.path().join("p.fbx"), &scene).unwrap_err();
        assert!(matches!(e, ExportError::UnknownExtension { ref extension } if extension == "fbx"));

        let mut broken = small_mesh();
        broken.primitives[0].indices[0] = 1_000_000;
        let scene = Scene::single(SceneNode::new("plant", &broken));
        let e = write_scene(&dir.path().join("p.glb"), &scene).unwrap_err();
        assert!(matches!(e, ExportError::IndexOutOfRange { .. }), "{e}");
        let mut nan = small_mesh();
        nan.positions[3][1] = f32::NAN;
        let scene = Scene::single(SceneNode::new("plant", &nan));
        let e = write_scene(&dir.path().join("p.obj"), &scene).unwrap_err();
        assert!(matches!(e, ExportError::NotFinite { .. }), "{e}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

        // A directory that does not exist is an I/O error naming the path.
        let e = write_scene(&dir.path().join("no/such/p.glb"), &Scene::default()).unwrap_err();
        assert!(matches!(e, ExportError::Io { .. }), "{e}");
    }

    #[test]
    fn a_failed_write_leaves_no_partial_file() {
        // The target is a directory, so the final rename fails after the data was written.
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("p.glb");
        std::fs::create_dir(&target).unwrap();
        let mesh = small_mesh();
        let e = write_scene(&target, &Scene::single(SceneNode::new("plant", &mesh))).unwrap_err();
        assert!(
            matches!(e, ExportError::Io { ref path, .. } if path == &target),
            "{e}"
        );
        assert!(target.is_dir());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary file left"
        );
    }

    #[test]
    fn write_scene_replaces_an_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.wrl");
        std::fs::write(&path, "old").unwrap();
        let mesh = small_mesh();
        write_scene(&path, &Scene::single(SceneNode::new("plant", &mesh))).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("#VRML V2.0 utf8"));
    }

    #[test]
    fn floats_are_short_and_round_trip() {
        let mut s = String::new();
        for x in [0.1f32, -0.0, 1e-7, 3.0, f32::NAN, 123456.79, -2.5e-3] {
            s.clear();
            push_float(&mut s, x);
            let back: f32 = s.parse().unwrap();
            if x.is_finite() {
                assert_eq!(back, x, "{s}");
            } else {
                assert_eq!(back, 0.0);
            }
            assert!(!s.contains('e'), "{s}");
        }
    }

    #[test]
    fn tokens_are_single_words() {
        assert_eq!(token("a b\tc"), "a_b_c");
        assert_eq!(token(""), "_");
        assert_eq!(token("bark-2"), "bark-2");
    }
}
