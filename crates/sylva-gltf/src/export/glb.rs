//! glTF 2.0 binary (GLB) writer.
//!
//! Layout: one glTF node per scene node, all at the root of one scene; one glTF mesh per
//! distinct [`Mesh`] (nodes that borrow the same mesh, compared by address, share it); one
//! primitive per [`Primitive`](sylva_mesh::Primitive), all sharing the mesh's POSITION and NORMAL
//! accessors. Primitives whose material has a texture also share a TEXCOORD_0 accessor
//! (`(0, 0)` throughout for a mesh without `uvs`); the others have none, since the validator
//! reports texture coordinates no material reads as unused, and a mesh without textured
//! materials gets no TEXCOORD_0 at all. Indices are `u16` when the mesh has at most 65 535 vertices (65 535 itself is
//! the primitive-restart value glTF forbids), `u32` otherwise. Materials are metallic-roughness
//! with the plant colour as base colour, not metallic and rough (0.9); identical materials
//! are written once. They are not `doubleSided`: leaves and petals already carry a back face,
//! and a double-sided material would draw both coincident faces from either side.
//!
//! Lean materials ([`super::lean`]): when a mesh has several colours of one organ kind and
//! texture, they become one primitive and one material per kind and texture, with the
//! colours in a `COLOR_0` attribute (normalised `u8` RGBA, after TEXCOORD_0 and the skin's
//! attributes); other meshes are written with one primitive per material as above.
//!
//! A material with a texture id also gets `baseColorTexture`: each distinct id used is one
//! PNG ([`sylva_mesh::texture`]) embedded in its own buffer view (no `target`), an `image` named
//! `sylva-texture-<id>` (which [`crate::import`] reads back as the id), and a `texture`
//! with a sampler that repeats in u, and in v for bark or clamps to the edge for leaves and
//! petals, with trilinear filtering. The colour stays in `baseColorFactor`, which glTF
//! multiplies with the texture.
//!
//! Each buffer view holds one tightly packed accessor (no `byteStride`), but for quantised
//! attributes and a skin's (below); each starts on a 4-byte boundary and has its `target` set.
//! A skinned mesh's `JOINTS_0` (4 bytes), `WEIGHTS_0` (4 normalised bytes) and `_WIND` (a
//! float) share one view of stride 12, so each vertex's influence is worked out once, as it
//! is written ([`sylva_mesh::wind::Rig::for_each_influence`]). The JSON chunk is
//! padded with spaces and the BIN chunk with zeros to 4 bytes. A mesh with no triangles gives
//! a node without a mesh. The JSON is built with `serde_json`, whose maps keep a fixed key
//! order, so output is deterministic.
//!
//! [`GlbOptions`] add two extensions, each declared in `extensionsUsed` only when used:
//!
//! - **Instancing** (`EXT_mesh_gpu_instancing`, not required): the nodes that share a mesh
//!   and equal extras, and have no rig, become one node (named after the first of them, with
//!   their extras) whose extension lists each one's place as `TRANSLATION` and `ROTATION`
//!   accessors (floats, in untargeted buffer views after the meshes' data). No `SCALE`: nodes
//!   have none, and glTF's default is 1. Nodes with a rig stay plain (a skinned mesh ignores
//!   its node's transform, and three.js does not instance skinned meshes).
//! - **Quantisation** (`KHR_mesh_quantization`, required): positions are normalised `SHORT`s
//!   (8 bytes per vertex with padding, `byteStride` 8) over the mesh's bounding box, and
//!   normals normalised `BYTE`s (4 bytes with padding); texture coordinates, colours and
//!   indices are as without. The dequantisation, a uniform scale `s` (the largest half
//!   extent) about an offset `o` (the box's centre), goes into each node that shows the mesh:
//!   a plain node's translation becomes `t + R o` with scale `s`; an instanced node carries
//!   `o` and `s` itself, and each instance `D⁻¹ I D`: translation `(t − o + R o) / s`, the
//!   same rotation. A position comes back within `s / 65534` (half a step) of its value.
//!   Meshes with a rig are not quantised (the dequantisation would have to move into the
//!   inverse bind matrices).
//!
//! An impostor's material (a card showing a picture of its plant, the last level of detail)
//! is marked `KHR_materials_unlit` (not required): its picture was lit when it was made. Its
//! picture is the mesh's own ([`Mesh::impostor`]), embedded once per distinct picture.
//!
//! [`to_glb`] and [`to_glb_with`] build the file in memory in one pass. [`Glb`] streams it:
//! a first pass over the meshes computes the JSON (offsets, bounds) and the binary chunk's
//! length without keeping any data, then [`Glb::write_to`] writes the header, the JSON and the
//! binary chunk mesh by mesh through a buffer. Its meshes come from a [`MeshSource`], which
//! may make each mesh when it is asked for (and drop it after), so memory holds one mesh at a
//! time. Both give the same bytes.

use std::collections::HashMap;
use std::io::{self, BufWriter, Write};

use serde_json::{Map, Value, json};
use sylva_core::glam::{Quat, Vec3};
use sylva_core::species::Surface;
use sylva_mesh::mesh::Mesh;
use sylva_mesh::picture::Picture;
use sylva_mesh::scene::Scene;
use sylva_mesh::wind::Rig;

use super::{ExportError, MaterialKey, check_mesh, check_node, check_scene, material_key};

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const GLB_VERSION: u32 = 2;
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const BYTE: u32 = 5120;
const UNSIGNED_BYTE: u32 = 5121;
const SHORT: u32 = 5122;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const LINEAR: u32 = 9729;
const LINEAR_MIPMAP_LINEAR: u32 = 9987;
const REPEAT: u32 = 10497;
const CLAMP_TO_EDGE: u32 = 33071;
/// The instancing extension's name.
pub const EXT_MESH_GPU_INSTANCING: &str = "EXT_mesh_gpu_instancing";
/// The quantisation extension's name.
pub const KHR_MESH_QUANTIZATION: &str = "KHR_mesh_quantization";
/// The extension marking a material unlit: an impostor's, whose picture was lit already.
pub const KHR_MATERIALS_UNLIT: &str = "KHR_materials_unlit";
/// Where a material's extras carry its [`Surface`], for [`crate::import`] to read back.
pub(crate) const SURFACE_EXTRA: &str = "sylva_surface";
/// The alpha below which a cut-out card (leaf or petal) shows nothing.
pub const ALPHA_CUTOFF: f64 = 0.5;
/// Most vertices that `u16` indices can address (65 535 is reserved for primitive restart).
const U16_VERTICES: usize = 65_535;
/// Roughness of every material: plants are matte.
const ROUGHNESS: f64 = 0.9;
/// Largest normalised `SHORT`: quantised positions span -32 767 to 32 767.
const SHORT_MAX: f32 = 32_767.0;

/// How a GLB is laid out. The default is core glTF with float attributes, as [`to_glb`]
/// writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct GlbOptions {
    /// Nodes that share a mesh and equal extras (and have no rig) become one node with
    /// `EXT_mesh_gpu_instancing`. Default `false`.
    pub instancing: bool,
    /// Positions and normals of meshes without a rig are quantised (`KHR_mesh_quantization`,
    /// which a viewer must support to open the file). Default `false`.
    pub quantize: bool,
}

/// What a GLB holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GlbStats {
    /// Bytes of the file.
    pub bytes: u64,
    /// glTF meshes written (meshes with triangles).
    pub meshes: usize,
    /// Nodes carrying `EXT_mesh_gpu_instancing`.
    pub instanced: usize,
    /// Triangles shown, over every node and instance.
    pub triangles: u64,
}

/// A node as the GLB writer takes it: a mesh by its index in a [`MeshSource`], placed.
#[derive(Clone, Debug)]
pub struct GlbNode<'a> {
    /// The node's name.
    pub name: &'a str,
    /// Its mesh, by index in the [`MeshSource`]. Nodes with the same index share one glTF
    /// mesh, so they must have the same rig.
    pub mesh: usize,
    /// A skin and wind clip for the mesh.
    pub rig: Option<&'a Rig>,
    /// Where the mesh's origin goes, metres.
    pub translation: Vec3,
    /// Rotation applied before the translation.
    pub rotation: Quat,
    /// The node's glTF `extras`.
    pub extras: Option<&'a Value>,
}

/// Where a streamed GLB's meshes come from. [`Glb`] asks for each mesh twice, once per pass,
/// and is done with one before it asks for the next, so a source may make each mesh when
/// asked and reuse one buffer for all of them. It must give the same mesh both times.
pub trait MeshSource {
    /// Mesh `index`.
    fn mesh(&mut self, index: usize) -> Result<&Mesh, ExportError>;
}

impl MeshSource for Vec<&Mesh> {
    fn mesh(&mut self, index: usize) -> Result<&Mesh, ExportError> {
        self.get(index)
            .copied()
            .ok_or(ExportError::NoSuchMesh { index })
    }
}

/// Encodes `scene` as a GLB file. Fails only on a scene [`check_scene`] refuses or one too
/// large for a GLB's 32-bit lengths.
pub fn to_glb(scene: &Scene) -> Result<Vec<u8>, ExportError> {
    to_glb_with(scene, &GlbOptions::default())
}

/// As [`to_glb`], laid out as `options` say.
pub fn to_glb_with(scene: &Scene, options: &GlbOptions) -> Result<Vec<u8>, ExportError> {
    check_scene(scene)?;
    // The binary chunk is built, then copied into the file: about twice its size at once.
    let mut seen = std::collections::HashSet::new();
    let binary: u64 = scene
        .nodes
        .iter()
        .filter(|n| seen.insert(n.mesh as *const Mesh))
        .map(|n| {
            let m = n.mesh;
            let rigged = if n.rig.is_some() { 12 } else { 0 };
            (m.positions.len() as u64 * (32 + rigged)).saturating_add(
                m.primitives
                    .iter()
                    .map(|p| p.indices.len() as u64 * 4)
                    .sum(),
            )
        })
        .sum();
    sylva_core::budget::check(
        binary.saturating_mul(2),
        format_args!(
            "writing a GLB of about {}",
            sylva_core::budget::Bytes(binary)
        ),
        "export fewer or smaller plants",
    )?;
    let (nodes, mut meshes) = scene_nodes(scene);
    let (json, bin, _) = encode(&nodes, &mut meshes, options, false, Vec::new())?;
    let total = glb_len(json.len(), bin.len());
    let header = header(total, json.len(), bin.len())?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(&header);
    out.extend_from_slice(&json);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(&bin);
    }
    Ok(out)
}

/// The fewest bytes a mesh of `vertices` and `triangles` adds to a GLB's binary chunk:
/// positions and normals (quantised when `quantize`) and indices, without texture
/// coordinates, colours or a skin. What is over 4 GiB by this count can be refused before
/// any mesh is made.
pub fn mesh_binary_floor(vertices: u64, triangles: u64, quantize: bool) -> u64 {
    let vertex = if quantize { 8 + 4 } else { 12 + 12 };
    let index = if vertices > U16_VERTICES as u64 { 4 } else { 2 };
    vertices
        .saturating_mul(vertex)
        .saturating_add(triangles.saturating_mul(3 * index))
}

/// Bytes `mesh` adds to the binary chunk of a GLB laid out with `options` (the mesh
/// without a rig): `(each, once)`, what each copy of the mesh adds and what the first adds
/// besides (its embedded textures). Estimates of large scenes multiply them before the
/// other meshes are made.
pub fn mesh_binary_bytes(mesh: &Mesh, options: &GlbOptions) -> Result<(u64, u64), ExportError> {
    let mut w = Writer::new(Counter(0), options.quantize);
    w.mesh(mesh, "", None)?;
    let first = w.bin.len() as u64;
    w.mesh(mesh, "", None)?;
    let each = w.bin.len() as u64 - first;
    Ok((each, first.saturating_sub(each)))
}

/// A GLB laid out and ready to stream: its JSON is built and its length known; its binary
/// data is made only while [`Glb::write_to`] writes it. Every check is done when it is made,
/// so writing fails only on I/O.
///
/// ```
/// use sylva_gltf::export::{Glb, GlbOptions, to_glb};
/// use sylva_mesh::Scene;
///
/// let scene = Scene::default();
/// let mut glb = Glb::of_scene(&scene, GlbOptions::default())?;
/// let mut bytes = Vec::new();
/// glb.write_to(&mut bytes)?;
/// assert_eq!(bytes, to_glb(&scene)?);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Glb<'a> {
    nodes: Vec<GlbNode<'a>>,
    meshes: Box<dyn MeshSource + 'a>,
    options: GlbOptions,
    json: Vec<u8>,
    bin_len: usize,
    stats: GlbStats,
}

impl<'a> Glb<'a> {
    /// Lays out the GLB of `nodes`, whose meshes come from `meshes` (each asked for once),
    /// checking every node and mesh as [`check_scene`] does.
    pub fn new(
        nodes: Vec<GlbNode<'a>>,
        mut meshes: Box<dyn MeshSource + 'a>,
        options: GlbOptions,
    ) -> Result<Glb<'a>, ExportError> {
        let (json, Counter(bin_len), mut stats) =
            encode(&nodes, &mut *meshes, &options, true, Counter(0))?;
        stats.bytes = glb_len(json.len(), bin_len);
        header(stats.bytes, json.len(), bin_len)?;
        Ok(Glb {
            nodes,
            meshes,
            options,
            json,
            bin_len,
            stats,
        })
    }

    /// Lays out the GLB of a scene: the bytes [`to_glb_with`] gives.
    pub fn of_scene(scene: &'a Scene<'a>, options: GlbOptions) -> Result<Glb<'a>, ExportError> {
        let (nodes, meshes) = scene_nodes(scene);
        Glb::new(nodes, Box::new(meshes), options)
    }

    /// What the file holds, and its size.
    pub fn stats(&self) -> GlbStats {
        self.stats
    }

    /// Writes the file to `out` through a buffer of its own (so `out` needs none), making
    /// the binary data mesh by mesh.
    pub fn write_to(&mut self, out: &mut dyn Write) -> io::Result<()> {
        let mut out = BufWriter::with_capacity(1 << 20, out);
        out.write_all(
            &header(self.stats.bytes, self.json.len(), self.bin_len).map_err(io::Error::other)?,
        )?;
        out.write_all(&self.json)?;
        if self.bin_len > 0 {
            out.write_all(&(self.bin_len as u32).to_le_bytes())?;
            out.write_all(&CHUNK_BIN.to_le_bytes())?;
        }
        let stream = Stream {
            out,
            len: 0,
            error: None,
        };
        let (_, stream, _) = encode(&self.nodes, &mut *self.meshes, &self.options, false, stream)
            .map_err(io::Error::other)?;
        let Stream {
            mut out,
            len,
            error,
        } = stream;
        if let Some(e) = error {
            return Err(e);
        }
        if len != self.bin_len {
            return Err(io::Error::other(
                "the meshes changed between the GLB writer's two passes",
            ));
        }
        out.flush()
    }
}

/// The nodes of a scene for the writer, and their distinct meshes: one per (mesh, rig)
/// pair, compared by address, in order of first appearance.
fn scene_nodes<'a>(scene: &'a Scene<'a>) -> (Vec<GlbNode<'a>>, Vec<&'a Mesh>) {
    let mut index_of: HashMap<(*const Mesh, *const Rig), usize> = HashMap::new();
    let mut meshes = Vec::new();
    let nodes = scene
        .nodes
        .iter()
        .map(|node| {
            let rig: *const Rig = node.rig.map_or(std::ptr::null(), |r| r as *const Rig);
            let mesh = *index_of
                .entry((node.mesh as *const Mesh, rig))
                .or_insert_with(|| {
                    meshes.push(node.mesh);
                    meshes.len() - 1
                });
            GlbNode {
                name: &node.name,
                mesh,
                rig: node.rig,
                translation: node.translation,
                rotation: node.rotation,
                extras: node.extras.as_ref(),
            }
        })
        .collect();
    (nodes, meshes)
}

/// Bytes of a GLB with a JSON chunk of `json` bytes and a binary chunk of `bin` bytes.
fn glb_len(json: usize, bin: usize) -> u64 {
    12 + 8 + json as u64 + if bin > 0 { 8 + bin as u64 } else { 0 }
}

/// The file header and the JSON chunk's header.
fn header(total: u64, json: usize, bin: usize) -> Result<[u8; 20], ExportError> {
    let total32 = u32::try_from(total).map_err(|_| ExportError::TooLarge { bytes: total })?;
    debug_assert_eq!(total, glb_len(json, bin));
    let mut out = [0u8; 20];
    for (i, word) in [GLB_MAGIC, GLB_VERSION, total32, json as u32, CHUNK_JSON]
        .into_iter()
        .enumerate()
    {
        out[4 * i..4 * i + 4].copy_from_slice(&word.to_le_bytes());
    }
    Ok(out)
}

/// Where the binary chunk's bytes go: memory, a stream, or nowhere (counted only).
trait Sink {
    /// Bytes put so far.
    fn len(&self) -> usize;
    /// Appends bytes.
    fn put(&mut self, bytes: &[u8]);
    /// Room for `additional` more bytes is wanted soon.
    fn reserve(&mut self, _additional: usize) {}
    /// Whether bytes are only counted (the layout pass): work that only makes bytes can skip.
    fn counts_only(&self) -> bool {
        false
    }
    /// Appends `n` zeros.
    fn put_zeros(&mut self, mut n: usize) {
        while n > 0 {
            let k = n.min(64);
            self.put(&[0; 64][..k]);
            n -= k;
        }
    }
    /// Zeros up to the next multiple of 4.
    fn pad4(&mut self) {
        let n = self.len().next_multiple_of(4) - self.len();
        self.put(&[0; 3][..n]);
    }
}

impl Sink for Vec<u8> {
    fn len(&self) -> usize {
        Vec::len(self)
    }
    fn put(&mut self, bytes: &[u8]) {
        self.extend_from_slice(bytes);
    }
    fn reserve(&mut self, additional: usize) {
        Vec::reserve(self, additional);
    }
}

/// Counts bytes without keeping them: the layout pass.
struct Counter(usize);

impl Sink for Counter {
    fn len(&self) -> usize {
        self.0
    }
    fn put(&mut self, bytes: &[u8]) {
        self.0 += bytes.len();
    }
    fn counts_only(&self) -> bool {
        true
    }
    fn put_zeros(&mut self, n: usize) {
        self.0 += n;
    }
}

/// Writes bytes through a buffer, keeping the first error (and writing nothing after it).
struct Stream<W: Write> {
    out: W,
    len: usize,
    error: Option<io::Error>,
}

impl<W: Write> Sink for Stream<W> {
    fn len(&self) -> usize {
        self.len
    }
    fn put(&mut self, bytes: &[u8]) {
        self.len += bytes.len();
        if self.error.is_none()
            && let Err(e) = self.out.write_all(bytes)
        {
            self.error = Some(e);
        }
    }
}

/// A mesh once written: its glTF index (`None` without triangles), its dequantisation, and
/// its triangles.
#[derive(Clone, Copy, Debug)]
struct Written {
    index: Option<usize>,
    dequant: Option<Dequant>,
    triangles: u64,
}

/// Nodes drawn by one instanced node.
struct Group {
    /// Its place in the nodes array.
    slot: usize,
    /// The mesh as written.
    mesh: Written,
    /// The nodes it draws, by index; the first names it and gives its extras.
    members: Vec<usize>,
}

/// Walks the nodes in order, putting the binary chunk's data into `sink`; returns the JSON
/// chunk (padded), the sink and what the file holds (less its size). With `check`, each
/// node, and each mesh when it is first used, is checked as [`check_scene`] does.
fn encode<S: Sink>(
    nodes: &[GlbNode<'_>],
    meshes: &mut dyn MeshSource,
    options: &GlbOptions,
    check: bool,
    sink: S,
) -> Result<(Vec<u8>, S, GlbStats), ExportError> {
    let mut w = Writer::new(sink, options.quantize);
    let mut written: Vec<Option<Written>> = Vec::new();
    let mut json_nodes = Vec::with_capacity(nodes.len());
    let mut triangles = 0u64;
    // Rigs go after the plants' nodes: (node index, rig, the node's transform).
    let mut rigs: Vec<(usize, &Rig, Vec3, Quat)> = Vec::new();
    let mut groups: Vec<Group> = Vec::new();
    // Per source mesh, the groups drawing it.
    let mut groups_of: HashMap<usize, Vec<usize>> = HashMap::new();
    for (i, node) in nodes.iter().enumerate() {
        if check {
            check_node(i, node.translation, node.rotation)?;
        }
        if written.len() <= node.mesh {
            written.resize(node.mesh + 1, None);
        }
        // Indices follow first appearance.
        let mesh = match written[node.mesh] {
            Some(m) => m,
            None => {
                let data = meshes.mesh(node.mesh)?;
                if check {
                    check_mesh(i, data)?;
                }
                let m = w.mesh(data, node.name, node.rig)?;
                written[node.mesh] = Some(m);
                m
            }
        };
        triangles += mesh.triangles;
        if options.instancing && node.rig.is_none() && mesh.index.is_some() {
            let candidates = groups_of.entry(node.mesh).or_default();
            match candidates
                .iter()
                .find(|&&g| nodes[groups[g].members[0]].extras == node.extras)
            {
                Some(&g) => groups[g].members.push(i),
                None => {
                    candidates.push(groups.len());
                    groups.push(Group {
                        slot: json_nodes.len(),
                        mesh,
                        members: vec![i],
                    });
                    // Filled in once every member is known.
                    json_nodes.push(Value::Null);
                }
            }
            continue;
        }
        let mut n = Map::new();
        n.insert("name".into(), json!(node.name));
        if let Some(m) = mesh.index {
            n.insert("mesh".into(), json!(m));
        }
        if let (Some(rig), Some(_)) = (node.rig, mesh.index) {
            // A skinned mesh ignores its node's transform: the rig's root node carries it.
            rigs.push((
                json_nodes.len(),
                rig,
                node.translation,
                node.rotation.normalize(),
            ));
        } else {
            place(&mut n, node.translation, node.rotation, mesh.dequant);
        }
        if let Some(extras) = node.extras {
            n.insert("extras".into(), extras.clone());
        }
        json_nodes.push(Value::Object(n));
    }
    let mut nodes_json = json_nodes;
    let instanced = groups.len();
    for group in groups {
        let first = &nodes[group.members[0]];
        let mut n = Map::new();
        n.insert("name".into(), json!(first.name));
        n.insert("mesh".into(), json!(group.mesh.index));
        place(&mut n, Vec3::ZERO, Quat::IDENTITY, group.mesh.dequant);
        let (translation, rotation) = w.instances(
            group.members.iter().map(|&k| &nodes[k]),
            group.members.len(),
            group.mesh.dequant,
        );
        n.insert(
            "extensions".into(),
            json!({ EXT_MESH_GPU_INSTANCING: { "attributes": {
                "TRANSLATION": translation, "ROTATION": rotation,
            } } }),
        );
        if let Some(extras) = first.extras {
            n.insert("extras".into(), extras.clone());
        }
        nodes_json[group.slot] = Value::Object(n);
    }

    let plant_nodes = nodes_json.len();
    let mut scene_nodes: Vec<usize> = (0..plant_nodes).collect();
    let mut skins = Vec::new();
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    for (node, rig, translation, rotation) in rigs {
        let name = nodes_json[node]["name"]
            .as_str()
            .unwrap_or("plant")
            .to_owned();
        // The rig's root: a plain node with the plant's place, parent of its root joints.
        let root_node = nodes_json.len();
        let mut root_json = json!({ "name": format!("{name}-rig") });
        if translation != Vec3::ZERO {
            root_json["translation"] = json!(translation.to_array().map(short));
        }
        if rotation != Quat::IDENTITY {
            root_json["rotation"] = json!(rotation.to_array().map(short));
        }
        nodes_json.push(root_json);
        scene_nodes.push(root_node);
        let first = nodes_json.len();
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); rig.joints.len()];
        let mut roots = Vec::new();
        for (j, joint) in rig.joints.iter().enumerate() {
            let local = match joint.parent {
                Some(p) => {
                    children[p].push(first + j);
                    joint.position - rig.joints[p].position
                }
                None => {
                    roots.push(first + j);
                    joint.position
                }
            };
            let mut n = json!({ "name": format!("{name}-joint-{j}") });
            if local != Vec3::ZERO {
                n["translation"] = json!(local.to_array());
            }
            nodes_json.push(n);
        }
        for (j, c) in children.into_iter().enumerate() {
            if !c.is_empty() {
                nodes_json[first + j]["children"] = json!(c);
            }
        }
        nodes_json[root_node]["children"] = json!(roots);
        let ibm = w.inverse_binds(rig);
        skins.push(json!({
            "name": format!("{name}-skin"),
            "inverseBindMatrices": ibm,
            "joints": (first..first + rig.joints.len()).collect::<Vec<_>>(),
            "skeleton": root_node,
        }));
        nodes_json[node]["skin"] = json!(skins.len() - 1);
        let input = w.times(&rig.times);
        for (j, keys) in rig.rotations.iter().enumerate() {
            let output = w.rotations(keys);
            samplers.push(json!({ "input": input, "output": output, "interpolation": "LINEAR" }));
            channels.push(json!({
                "sampler": samplers.len() - 1,
                "target": { "node": first + j, "path": "rotation" },
            }));
        }
    }
    let animations = if channels.is_empty() {
        Vec::new()
    } else {
        vec![json!({ "name": "wind", "channels": channels, "samplers": samplers })]
    };

    let mut root = Map::new();
    root.insert(
        "asset".into(),
        json!({ "version": "2.0", "generator": concat!("Sylva ", env!("CARGO_PKG_VERSION")) }),
    );
    let mut used = Vec::new();
    if instanced > 0 {
        used.push(EXT_MESH_GPU_INSTANCING);
    }
    if w.unlit {
        used.push(KHR_MATERIALS_UNLIT);
    }
    if w.quantized {
        used.push(KHR_MESH_QUANTIZATION);
        root.insert("extensionsRequired".into(), json!([KHR_MESH_QUANTIZATION]));
    }
    if !used.is_empty() {
        root.insert("extensionsUsed".into(), json!(used));
    }
    root.insert("scene".into(), json!(0));
    root.insert(
        "scenes".into(),
        if scene_nodes.is_empty() {
            json!([{}])
        } else {
            json!([{ "nodes": scene_nodes }])
        },
    );
    w.bin.pad4();
    let bin_len = w.bin.len();
    let stats = GlbStats {
        bytes: 0,
        meshes: w.meshes.len(),
        instanced,
        triangles,
    };
    let arrays = [
        ("nodes", nodes_json),
        ("meshes", w.meshes),
        ("skins", skins),
        ("animations", animations),
        ("materials", w.materials),
        ("textures", w.textures),
        ("images", w.images),
        ("samplers", w.samplers),
        ("accessors", w.accessors),
        ("bufferViews", w.views),
        (
            "buffers",
            if bin_len > 0 {
                vec![json!({ "byteLength": bin_len })]
            } else {
                Vec::new()
            },
        ),
    ];
    // glTF forbids empty arrays at the root: leave them out.
    for (name, items) in arrays {
        if !items.is_empty() {
            root.insert(name.into(), Value::Array(items));
        }
    }
    let mut json = serde_json::to_vec(&Value::Object(root))?;
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    Ok((json, w.bin, stats))
}

/// Sets a node's transform: `translation` and `rotation`, after the mesh's dequantisation
/// when it has one (translation `t + R o`, scale `s`). Identity parts are left out.
fn place(n: &mut Map<String, Value>, translation: Vec3, rotation: Quat, dequant: Option<Dequant>) {
    let rotation = rotation.normalize();
    let translation = match dequant {
        Some(d) => translation + rotation * d.offset,
        None => translation,
    };
    if translation != Vec3::ZERO {
        n.insert(
            "translation".into(),
            json!(translation.to_array().map(short)),
        );
    }
    if rotation != Quat::IDENTITY {
        n.insert("rotation".into(), json!(rotation.to_array().map(short)));
    }
    if let Some(d) = dequant {
        n.insert("scale".into(), json!([d.scale, d.scale, d.scale]));
    }
}

/// How a quantised mesh's positions come back: `offset + scale * q / 32767`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Dequant {
    offset: Vec3,
    scale: f32,
}

impl Dequant {
    /// The dequantisation of positions in the box `min`..`max`: about its centre, by its
    /// largest half extent (1 for a box of no extent).
    fn of(min: Vec3, max: Vec3) -> Dequant {
        let offset = 0.5 * (min + max);
        let scale = (0.5 * (max - min)).max_element();
        Dequant {
            offset,
            scale: if scale > 0.0 && scale.is_finite() {
                scale
            } else {
                1.0
            },
        }
    }

    /// A position as normalised shorts.
    fn quantize(&self, p: Vec3) -> [i16; 3] {
        let q = (p - self.offset) / self.scale * SHORT_MAX;
        q.to_array()
            .map(|c| round(c.clamp(-SHORT_MAX, SHORT_MAX)) as i16)
    }
}

/// A unit normal as normalised bytes: rounded, or, when that is too far from unit length
/// (the validator allows 0.00674), the one of the eight roundings of its components up or
/// down whose length is nearest 1, then nearest the normal.
fn quantize_normal(n: Vec3) -> [i8; 3] {
    let v = n * 127.0;
    let rounded = Vec3::from_array(v.to_array().map(|c| round(c) as f32));
    // |length - 1| is about half |length² - 1|: within 0.0045.
    if (rounded.length_squared() / (127.0 * 127.0) - 1.0).abs() < 0.009 {
        return rounded.to_array().map(|x| x as i8);
    }
    let (lo, hi) = (v.floor(), v.ceil());
    let mut best = ([0i8; 3], f32::INFINITY);
    for k in 0..8 {
        let pick = |axis: usize, l: f32, h: f32| if (k >> axis) & 1 == 0 { l } else { h };
        let c = Vec3::new(
            pick(0, lo.x, hi.x),
            pick(1, lo.y, hi.y),
            pick(2, lo.z, hi.z),
        )
        .clamp(Vec3::splat(-127.0), Vec3::splat(127.0));
        let back = c / 127.0;
        let score = (back.length() - 1.0).abs() + 0.5 * back.distance(n);
        if score < best.1 {
            best = (c.to_array().map(|x| x as i8), score);
        }
    }
    best.0
}

/// `x` rounded half away from zero, as `f32::round` does, without the call to the C
/// library that it costs on x86-64's baseline (a third of a quantised write's time).
/// `x` is at most 32 767 in size.
fn round(x: f32) -> i32 {
    let whole = x as i32;
    // Exact: the fraction of a float is a float.
    let fraction = x - whole as f32;
    whole + i32::from(fraction >= 0.5) - i32::from(fraction <= -0.5)
}

/// The parts of the glTF document built while walking the scene.
struct Writer<S> {
    bin: S,
    /// Quantise meshes without a rig.
    quantize: bool,
    /// A mesh was quantised, so the file uses (and requires) the extension.
    quantized: bool,
    /// Some material is unlit (`KHR_materials_unlit`: an impostor's, whose picture was lit).
    unlit: bool,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    textures: Vec<Value>,
    images: Vec<Value>,
    samplers: Vec<Value>,
    /// (name, colour bits, texture, surface) to material index, to write identical
    /// materials once.
    material_of: HashMap<(MaterialKey, u64), usize>,
    /// Picture to glTF texture index, to embed each picture once.
    texture_of: HashMap<(Picture, u64), usize>,
    /// The picture of the mesh being written, when it is an impostor's, and its hash (which
    /// tells its materials and texture from another impostor's).
    impostor: Option<(std::sync::Arc<Vec<u8>>, u64)>,
    /// The sampler of each wrapping, once written: index `2·(clamps u) + (clamps v)`.
    sampler_of: [Option<usize>; 4],
}

impl<S: Sink> Writer<S> {
    fn new(bin: S, quantize: bool) -> Self {
        Writer {
            bin,
            quantize,
            quantized: false,
            unlit: false,
            views: Vec::new(),
            accessors: Vec::new(),
            meshes: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
            images: Vec::new(),
            samplers: Vec::new(),
            material_of: HashMap::new(),
            texture_of: HashMap::new(),
            impostor: None,
            sampler_of: [None; 4],
        }
    }

    /// Writes a mesh's data: its glTF mesh index (`None` when it has no triangles), and its
    /// dequantisation when it was quantised.
    fn mesh(&mut self, mesh: &Mesh, name: &str, rig: Option<&Rig>) -> Result<Written, ExportError> {
        let triangles = mesh.triangle_count() as u64;
        self.impostor = mesh
            .impostor
            .as_ref()
            .map(|png| (png.clone(), sylva_core::hash::stable_hash(png)));
        if mesh.primitives.iter().all(|p| p.indices.is_empty()) {
            return Ok(Written {
                index: None,
                dequant: None,
                triangles,
            });
        }
        let count = mesh.positions.len();
        let index_count: usize = mesh.primitives.iter().map(|p| p.indices.len() + 2).sum();
        // Positions, normals and coordinates (32 bytes a vertex at most), vertex colours (4)
        // and a skin's joints, weights and flutter (12): one growth of a mesh-sized buffer
        // would copy it and fault in twice its pages.
        let skin = if rig.is_some() { 12 } else { 0 };
        self.bin.reserve((36 + skin) * count + 4 * index_count);
        let dequant = (self.quantize && rig.is_none()).then(|| {
            let (min, max) = bounds(&mesh.positions);
            Dequant::of(min, max)
        });
        let (position, normal) = match dequant {
            None => self.float_positions_normals(mesh),
            Some(d) => {
                self.quantized = true;
                self.quantized_positions_normals(mesh, d)
            }
        };
        let textured = |p: &sylva_mesh::Primitive| {
            !p.indices.is_empty() && Picture::base_of(&mesh.materials[p.material]).is_some()
        };
        let texcoord = if mesh.primitives.iter().any(textured) {
            let start = self.bin.len();
            if mesh.uvs.len() == count {
                for uv in &mesh.uvs {
                    let mut b = [0u8; 8];
                    b[..4].copy_from_slice(&uv[0].to_le_bytes());
                    b[4..].copy_from_slice(&uv[1].to_le_bytes());
                    self.bin.put(&b);
                }
            } else {
                // check_scene allows only one per position or none.
                for _ in 0..count {
                    self.bin.put(&[0; 8]);
                }
            }
            let view = self.view(start, ARRAY_BUFFER);
            Some(self.accessor(json!({
                "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC2",
            })))
        } else {
            None
        };

        // A normal map needs a tangent space, written rather than left to each viewer.
        let normal_mapped = |p: &sylva_mesh::Primitive| {
            !p.indices.is_empty() && Picture::normal_of(&mesh.materials[p.material]).is_some()
        };
        let tangent = if mesh.primitives.iter().any(normal_mapped) {
            let start = self.bin.len();
            for t in tangents(mesh) {
                for c in t {
                    self.bin.put(&c.to_le_bytes());
                }
            }
            let view = self.view(start, ARRAY_BUFFER);
            Some(self.accessor(json!({
                "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC4",
            })))
        } else {
            None
        };

        let skin = match rig {
            Some(rig) if rig.vertices() == count => Some(self.skin_attributes(rig, mesh)),
            _ => None,
        };

        // What is drawn: each primitive with its material, or lean materials' merged ones.
        let lean = super::lean::LeanPlan::of(mesh);
        let color = lean.as_ref().map(|plan| {
            let start = self.bin.len();
            for rgba in &plan.colors {
                self.bin.put(rgba);
            }
            let view = self.view(start, ARRAY_BUFFER);
            self.accessor(json!({
                "bufferView": view, "componentType": UNSIGNED_BYTE, "normalized": true,
                "count": count, "type": "VEC4",
            }))
        });
        let draws: Vec<(&sylva_core::Material, Vec<&sylva_mesh::Primitive>)> = match &lean {
            Some(plan) => plan
                .materials
                .iter()
                .zip(&plan.members)
                .map(|(m, group)| (m, group.iter().map(|&p| &mesh.primitives[p]).collect()))
                .collect(),
            None => mesh
                .primitives
                .iter()
                .filter(|p| !p.indices.is_empty())
                .map(|p| (&mesh.materials[p.material], vec![p]))
                .collect(),
        };

        let wide = count > U16_VERTICES;
        let mut primitives = Vec::new();
        for (material, group) in draws {
            let start = self.bin.len();
            let indices = group.iter().flat_map(|p| p.indices.iter().copied());
            if wide {
                for i in indices {
                    self.bin.put(&i.to_le_bytes());
                }
            } else {
                // check_scene put every index below count <= 65 535.
                for i in indices {
                    self.bin.put(&(i as u16).to_le_bytes());
                }
            }
            self.bin.pad4();
            let view = self.view(start, ELEMENT_ARRAY_BUFFER);
            let indices = self.accessor(json!({
                "bufferView": view,
                "componentType": if wide { UNSIGNED_INT } else { UNSIGNED_SHORT },
                "count": group.iter().map(|p| p.indices.len()).sum::<usize>(),
                "type": "SCALAR",
            }));
            let textured = Picture::base_of(material).is_some();
            let normal_map = Picture::normal_of(material).is_some();
            let material = self.material(material)?;
            let mut attributes = json!({ "POSITION": position, "NORMAL": normal });
            if let (Some(t), true) = (texcoord, textured) {
                attributes["TEXCOORD_0"] = json!(t);
            }
            if let (Some(t), true) = (tangent, normal_map) {
                attributes["TANGENT"] = json!(t);
            }
            if let Some(c) = color {
                attributes["COLOR_0"] = json!(c);
            }
            if let Some((joints, weights, flutter)) = skin {
                attributes["JOINTS_0"] = json!(joints);
                attributes["WEIGHTS_0"] = json!(weights);
                attributes["_WIND"] = json!(flutter);
            }
            primitives.push(json!({
                "attributes": attributes,
                "indices": indices,
                "material": material,
            }));
        }
        self.meshes
            .push(json!({ "name": name, "primitives": primitives }));
        Ok(Written {
            index: Some(self.meshes.len() - 1),
            dequant,
            triangles,
        })
    }

    /// A mesh's POSITION and NORMAL accessors as floats.
    fn float_positions_normals(&mut self, mesh: &Mesh) -> (usize, usize) {
        let count = mesh.positions.len();
        let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let start = self.bin.len();
        for p in &mesh.positions {
            let p = Vec3::from_array(*p);
            (min, max) = (min.min(p), max.max(p));
            push_vec3(&mut self.bin, p);
        }
        let view = self.view(start, ARRAY_BUFFER);
        let position = self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC3",
            // Exact f32 values written as f64: the validator compares them exactly.
            "min": min.to_array(), "max": max.to_array(),
        }));
        let start = self.bin.len();
        for n in &mesh.normals {
            // Renormalise: glTF requires unit normals, and a zero normal gets +Y.
            push_vec3(&mut self.bin, Vec3::from_array(*n).normalize_or(Vec3::Y));
        }
        let view = self.view(start, ARRAY_BUFFER);
        let normal = self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC3",
        }));
        (position, normal)
    }

    /// A mesh's POSITION (normalised shorts) and NORMAL (normalised bytes) accessors, each
    /// element padded to 4 bytes as glTF requires of vertex attributes.
    fn quantized_positions_normals(&mut self, mesh: &Mesh, d: Dequant) -> (usize, usize) {
        let count = mesh.positions.len();
        let (mut min, mut max) = ([i16::MAX; 3], [i16::MIN; 3]);
        let start = self.bin.len();
        for p in &mesh.positions {
            let q = d.quantize(Vec3::from_array(*p));
            let mut b = [0u8; 8];
            for (k, c) in q.iter().enumerate() {
                min[k] = min[k].min(*c);
                max[k] = max[k].max(*c);
                b[2 * k..2 * k + 2].copy_from_slice(&c.to_le_bytes());
            }
            self.bin.put(&b);
        }
        let view = self.view(start, ARRAY_BUFFER);
        self.views[view]["byteStride"] = json!(8);
        // A normalised accessor's bounds are its stored integers.
        let position = self.accessor(json!({
            "bufferView": view, "componentType": SHORT, "normalized": true, "count": count,
            "type": "VEC3", "min": min, "max": max,
        }));
        let start = self.bin.len();
        for n in &mesh.normals {
            let [x, y, z] = quantize_normal(Vec3::from_array(*n).normalize_or(Vec3::Y));
            self.bin.put(&[x as u8, y as u8, z as u8, 0]);
        }
        let view = self.view(start, ARRAY_BUFFER);
        self.views[view]["byteStride"] = json!(4);
        let normal = self.accessor(json!({
            "bufferView": view, "componentType": BYTE, "normalized": true, "count": count,
            "type": "VEC3",
        }));
        (position, normal)
    }

    /// An instanced node's TRANSLATION and ROTATION accessors: each node's place, through
    /// the mesh's dequantisation `D` when it has one (`D⁻¹ I D`, as the node carries `D`).
    fn instances<'n>(
        &mut self,
        nodes: impl Iterator<Item = &'n GlbNode<'n>> + Clone,
        count: usize,
        dequant: Option<Dequant>,
    ) -> (usize, usize) {
        let start = self.bin.len();
        for node in nodes.clone() {
            let rotation = node.rotation.normalize();
            let t = match dequant {
                Some(d) => (node.translation - d.offset + rotation * d.offset) / d.scale,
                None => node.translation,
            };
            push_vec3(&mut self.bin, t);
        }
        let view = self.untargeted_view(start);
        let translation = self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC3",
        }));
        let start = self.bin.len();
        for node in nodes {
            push_quat(&mut self.bin, node.rotation.normalize());
        }
        let view = self.untargeted_view(start);
        let rotation = self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC4",
        }));
        (translation, rotation)
    }

    /// A rigged mesh's JOINTS_0, WEIGHTS_0 and `_WIND` accessors.
    fn skin_attributes(&mut self, rig: &Rig, mesh: &Mesh) -> (usize, usize, usize) {
        // One buffer view, a vertex's joints, weights and flutter side by side (12 bytes), so
        // that each vertex's influence is worked out once, as it is written.
        let count = rig.vertices();
        let start = self.bin.len();
        if self.bin.counts_only() {
            self.bin.put_zeros(12 * count);
        } else {
            let mut chunk = [0u8; 12 * 256];
            let mut used = 0;
            rig.for_each_influence(mesh, |i| {
                chunk[used..used + 4].copy_from_slice(&i.joints);
                chunk[used + 4..used + 8].copy_from_slice(&i.weights);
                chunk[used + 8..used + 12].copy_from_slice(&i.flutter.to_le_bytes());
                used += 12;
                if used == chunk.len() {
                    self.bin.put(&chunk);
                    used = 0;
                }
            });
            self.bin.put(&chunk[..used]);
        }
        let view = self.view(start, ARRAY_BUFFER);
        self.views[view]["byteStride"] = json!(12);
        let joints = self.accessor(json!({
            "bufferView": view, "componentType": UNSIGNED_BYTE, "count": count, "type": "VEC4",
        }));
        let weights = self.accessor(json!({
            "bufferView": view, "byteOffset": 4, "componentType": UNSIGNED_BYTE,
            "normalized": true, "count": count, "type": "VEC4",
        }));
        let flutter = self.accessor(json!({
            "bufferView": view, "byteOffset": 8, "componentType": FLOAT, "count": count,
            "type": "SCALAR",
        }));
        (joints, weights, flutter)
    }

    /// A rig's inverse bind matrices: each joint's rest place undone (rest rotations are
    /// the identity), column-major.
    fn inverse_binds(&mut self, rig: &Rig) -> usize {
        let start = self.bin.len();
        for joint in &rig.joints {
            let m = sylva_core::glam::Mat4::from_translation(-joint.position);
            for c in m.to_cols_array() {
                self.bin.put(&c.to_le_bytes());
            }
        }
        let view = self.untargeted_view(start);
        self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": rig.joints.len(), "type": "MAT4",
        }))
    }

    /// An animation's key times.
    fn times(&mut self, times: &[f32]) -> usize {
        let start = self.bin.len();
        for t in times {
            self.bin.put(&t.to_le_bytes());
        }
        let view = self.untargeted_view(start);
        let (min, max) = times
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &t| {
                (a.min(t), b.max(t))
            });
        self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": times.len(), "type": "SCALAR",
            "min": [min], "max": [max],
        }))
    }

    /// An animation's rotations, one unit quaternion (x, y, z, w) per key.
    fn rotations(&mut self, keys: &[Quat]) -> usize {
        let start = self.bin.len();
        for q in keys {
            push_quat(&mut self.bin, q.normalize());
        }
        let view = self.untargeted_view(start);
        self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": keys.len(), "type": "VEC4",
        }))
    }

    /// A buffer view over the bytes put since `start`, which is on a 4-byte boundary.
    fn view(&mut self, start: usize, target: u32) -> usize {
        let view = self.untargeted_view(start);
        self.views[view]["target"] = json!(target);
        view
    }

    /// A buffer view without a target (for image, skin, animation and instance data), over
    /// the bytes put since `start`.
    fn untargeted_view(&mut self, start: usize) -> usize {
        debug_assert_eq!(start % 4, 0);
        let length = self.bin.len() - start;
        self.views.push(json!({
            "buffer": 0, "byteOffset": start, "byteLength": length,
        }));
        self.views.len() - 1
    }

    /// The glTF texture showing `picture`, embedding its PNG the first time.
    fn texture(&mut self, picture: Picture) -> Result<usize, ExportError> {
        let key = (picture, self.impostor_hash(picture));
        if let Some(&t) = self.texture_of.get(&key) {
            return Ok(t);
        }
        let png = match (picture, &self.impostor) {
            (Picture::Impostor, Some((png, _))) => png.clone(),
            // (`check_mesh` refuses an impostor without a picture: it would be clear.)
            _ => picture.png().map_err(|source| ExportError::Png {
                picture: picture.name(),
                source,
            })?,
        };
        let start = self.bin.len();
        self.bin.put(&png);
        let view = self.untargeted_view(start);
        self.bin.pad4();
        self.images.push(json!({
            "bufferView": view,
            "mimeType": "image/png",
            "name": picture.name(),
        }));
        let (repeat_u, repeat_v) = (picture.repeats_u(), picture.repeats_v());
        let slot = 2 * usize::from(!repeat_u) + usize::from(!repeat_v);
        let wrap = |repeats| if repeats { REPEAT } else { CLAMP_TO_EDGE };
        let sampler = match self.sampler_of[slot] {
            Some(s) => s,
            None => {
                self.samplers.push(json!({
                    "magFilter": LINEAR,
                    "minFilter": LINEAR_MIPMAP_LINEAR,
                    "wrapS": wrap(repeat_u),
                    "wrapT": wrap(repeat_v),
                }));
                self.sampler_of[slot] = Some(self.samplers.len() - 1);
                self.samplers.len() - 1
            }
        };
        let name = match picture {
            Picture::Design(id) => sylva_mesh::texture::texture_info(id).name.to_owned(),
            other => other.name(),
        };
        self.textures.push(json!({
            "name": name,
            "sampler": sampler,
            "source": self.images.len() - 1,
        }));
        self.texture_of.insert(key, self.textures.len() - 1);
        Ok(self.textures.len() - 1)
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// The hash of the impostor picture `picture` stands for, 0 for any other picture.
    fn impostor_hash(&self, picture: Picture) -> u64 {
        match (picture, &self.impostor) {
            (Picture::Impostor, Some((_, hash))) => *hash,
            _ => 0,
        }
    }

    fn material(&mut self, m: &sylva_core::Material) -> Result<usize, ExportError> {
        let shown = Picture::base_of(m).map_or(0, |p| self.impostor_hash(p));
        let key = (material_key(m), shown);
        if let Some(&i) = self.material_of.get(&key) {
            return Ok(i);
        }
        let [r, g, b] = m.color.map(|c| short(c.clamp(0.0, 1.0)));
        let mut pbr = json!({
            "baseColorFactor": [r, g, b, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": ROUGHNESS,
        });
        if let Some(picture) = Picture::base_of(m) {
            pbr["baseColorTexture"] = json!({ "index": self.texture(picture)? });
        }
        let mut material = json!({
            "name": m.name,
            "pbrMetallicRoughness": pbr,
        });
        if let Some(normal) = Picture::normal_of(m) {
            material["normalTexture"] = json!({ "index": self.texture(normal)? });
        }
        if let Some(surface) = m.surface {
            if surface.is_cut_out() {
                material["alphaMode"] = json!("MASK");
                material["alphaCutoff"] = json!(ALPHA_CUTOFF);
                material["doubleSided"] = json!(true);
            }
            if surface == Surface::Impostor {
                material["extensions"] = json!({ KHR_MATERIALS_UNLIT: {} });
                self.unlit = true;
            }
            material["extras"] = json!({ SURFACE_EXTRA: surface });
        }
        self.materials.push(material);
        self.material_of.insert(key, self.materials.len() - 1);
        Ok(self.materials.len() - 1)
    }
}

/// Each vertex's tangent (unit, square to its normal, along increasing `u`) and the sign `w`
/// that turns `normal × tangent` into the direction of decreasing `v` (up the picture, where
/// normal maps point green, as glTF reads them): accumulated from the triangles' texture
/// coordinates as MikkTSpace does, without its splitting of vertices.
fn tangents(mesh: &Mesh) -> Vec<[f32; 4]> {
    let n = mesh.positions.len();
    let mut along_u = vec![Vec3::ZERO; n];
    let mut along_v = vec![Vec3::ZERO; n];
    let uv = |i: usize| mesh.uvs.get(i).copied().unwrap_or([0.0; 2]);
    for prim in &mesh.primitives {
        for t in prim.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
            if a.max(b).max(c) >= n {
                continue;
            }
            let p = |i: usize| Vec3::from_array(mesh.positions[i]);
            let (e1, e2) = (p(b) - p(a), p(c) - p(a));
            let ([u0, v0], [u1, v1], [u2, v2]) = (uv(a), uv(b), uv(c));
            let (du1, dv1, du2, dv2) = (u1 - u0, v1 - v0, u2 - u0, v2 - v0);
            let det = du1 * dv2 - du2 * dv1;
            if det.is_nan() || det.abs() <= 1e-12 {
                continue;
            }
            let su = (e1 * dv2 - e2 * dv1) / det;
            let sv = (e2 * du1 - e1 * du2) / det;
            if !(su.is_finite() && sv.is_finite()) {
                continue;
            }
            for i in [a, b, c] {
                along_u[i] += su;
                along_v[i] += sv;
            }
        }
    }
    (0..n)
        .map(|i| {
            let normal = mesh
                .normals
                .get(i)
                .map_or(Vec3::Y, |&v| Vec3::from_array(v))
                .normalize_or(Vec3::Y);
            let t = (along_u[i] - normal * normal.dot(along_u[i]))
                .try_normalize()
                .unwrap_or_else(|| normal.any_orthonormal_vector());
            let w = if normal.cross(t).dot(-along_v[i]) < 0.0 {
                -1.0
            } else {
                1.0
            };
            [t.x, t.y, t.z, w]
        })
        .collect()
}

/// The smallest box holding `positions`.
fn bounds(positions: &[[f32; 3]]) -> (Vec3, Vec3) {
    positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(min, max), p| {
            let p = Vec3::from_array(*p);
            (min.min(p), max.max(p))
        })
}

fn push_vec3(bin: &mut impl Sink, v: Vec3) {
    let mut b = [0u8; 12];
    for (k, c) in v.to_array().iter().enumerate() {
        b[4 * k..4 * k + 4].copy_from_slice(&c.to_le_bytes());
    }
    bin.put(&b);
}

fn push_quat(bin: &mut impl Sink, q: Quat) {
    let mut b = [0u8; 16];
    for (k, c) in q.to_array().iter().enumerate() {
        b[4 * k..4 * k + 4].copy_from_slice(&c.to_le_bytes());
    }
    bin.put(&b);
}

/// The `f64` nearest the shortest decimal that reads back as `x`: `0.85f32` is written as
/// `0.85`, not `0.8500000238418579`. For values that are not compared bit for bit.
fn short(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::export::tests::small_mesh;
    use sylva_mesh::scene::SceneNode;

    fn u32_at(b: &[u8], at: usize) -> u32 {
        u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
    }

    /// Splits a GLB into its JSON and BIN chunks, checking header and alignment.
    pub(crate) fn chunks(glb: &[u8]) -> (Value, Option<&[u8]>) {
        assert_eq!(u32_at(glb, 0), GLB_MAGIC);
        assert_eq!(u32_at(glb, 4), 2);
        assert_eq!(u32_at(glb, 8) as usize, glb.len());
        assert_eq!(glb.len() % 4, 0);
        let json_len = u32_at(glb, 12) as usize;
        assert_eq!(json_len % 4, 0, "JSON chunk is padded to 4 bytes");
        assert_eq!(u32_at(glb, 16), CHUNK_JSON);
        let json_bytes = &glb[20..20 + json_len];
        let json: Value = serde_json::from_slice(json_bytes).unwrap();
        let rest = &glb[20 + json_len..];
        if rest.is_empty() {
            return (json, None);
        }
        let bin_len = u32_at(rest, 0) as usize;
        assert_eq!(bin_len % 4, 0, "BIN chunk is padded to 4 bytes");
        assert_eq!(u32_at(rest, 4), CHUNK_BIN);
        assert_eq!(rest.len(), 8 + bin_len);
        (json, Some(&rest[8..]))
    }

    /// Meshes and rigs for the sample scenes: plain, lean, textured, rigged, wide, empty.
    pub(crate) struct Samples {
        plain: Mesh,
        other: Mesh,
        lean: Mesh,
        textured: Mesh,
        rigged: Mesh,
        rig: Rig,
        wide: Mesh,
        empty: Mesh,
    }

    #[test]
    fn a_mesh_is_weighed_as_the_writer_writes_it() {
        let s = samples();
        for mesh in [&s.plain, &s.lean, &s.textured, &s.wide] {
            for quantize in [false, true] {
                let options = GlbOptions {
                    quantize,
                    ..GlbOptions::default()
                };
                let (each, once) = mesh_binary_bytes(mesh, &options).unwrap();
                // Beside another mesh in one file, the mesh adds `each` (and `once`).
                let two = to_glb_with(
                    &Scene {
                        nodes: vec![SceneNode::new("a", mesh), SceneNode::new("b", &s.other)],
                    },
                    &options,
                )
                .unwrap();
                let (_, bin) = chunks(&two);
                let alone =
                    to_glb_with(&Scene::single(SceneNode::new("b", &s.other)), &options).unwrap();
                let (_, plain) = chunks(&alone);
                let added = bin.unwrap().len() as u64 - plain.unwrap().len() as u64;
                // The textured mesh embeds its pictures once, the others nothing (padding
                // aside).
                assert!(
                    added >= each && added <= each + once + 4,
                    "{added} {each} {once}"
                );
                let floor = mesh_binary_floor(
                    mesh.positions.len() as u64,
                    mesh.triangle_count() as u64,
                    quantize,
                );
                assert!(floor <= each, "{floor} > {each}");
                assert!(floor > 0);
            }
        }
    }

    /// The small mesh with half of its first primitive's triangles in a darker shade of
    /// the same material: what lean materials merge.
    pub(crate) fn two_shades() -> Mesh {
        let mut mesh = small_mesh();
        let shade = mesh.primitives[0].material;
        let mut darker = mesh.materials[shade].clone();
        darker.color = darker.color.map(|c| c * 0.5);
        darker.name.push_str("-dark");
        mesh.materials.push(darker);
        let half = mesh.primitives[0].indices.len() / 6 * 3;
        let moved = mesh.primitives[0].indices.split_off(half);
        mesh.primitives.push(sylva_mesh::Primitive {
            material: mesh.materials.len() - 1,
            indices: moved,
        });
        mesh
    }

    pub(crate) fn samples() -> Samples {
        let plant = crate::export::tests::small_plant();
        let mut other = small_mesh();
        for p in &mut other.positions {
            p[1] *= 1.5;
        }
        let lean = two_shades();
        let mut textured = small_mesh();
        textured.materials[0].texture = Some(0);
        textured.materials[1].texture = Some(3);
        let (rigged, sources) =
            sylva_mesh::mesher::Mesher::new(sylva_mesh::mesher::MeshOptions::default())
                .unwrap()
                .mesh_with_sources(&plant)
                .unwrap();
        let rig = sylva_mesh::wind::rig(
            &plant,
            &rigged,
            sources,
            &sylva_mesh::wind::WindOptions::default(),
        );
        let mut wide = Mesh {
            materials: vec![sylva_core::Material::of_kind(
                sylva_core::MaterialKind::Bark,
            )],
            ..Mesh::default()
        };
        for i in 0..70_000u32 {
            wide.positions.push([i as f32 * 1e-3, (i % 3) as f32, 0.0]);
            wide.normals.push([0.0, 0.0, 1.0]);
        }
        wide.primitives.push(sylva_mesh::Primitive {
            material: 0,
            indices: vec![0, 1, 2, 69_997, 69_998, 69_999],
        });
        Samples {
            plain: small_mesh(),
            other,
            lean,
            textured,
            rigged,
            rig,
            wide,
            empty: Mesh::default(),
        }
    }

    /// Named scenes over the samples, covering every part of the writer.
    pub(crate) fn sample_scenes(s: &Samples) -> Vec<(&'static str, Scene<'_>)> {
        let at = |name: &str, mesh, x: f32, yaw: f32| {
            let mut node = SceneNode::new(name, mesh);
            node.translation = Vec3::new(x, 0.0, -0.5 * x);
            node.rotation = Quat::from_rotation_y(yaw);
            node.extras = Some(json!({ "seed": x as u64, "genome": { "model": "m" } }));
            node
        };
        let mut rigged = at("r1", &s.rigged, 2.0, 0.5);
        rigged.rig = Some(&s.rig);
        let mut rigged2 = at("r2", &s.rigged, -3.0, 1.5);
        rigged2.rig = Some(&s.rig);
        vec![
            ("single", Scene::single(at("p", &s.plain, 1.0, 0.3))),
            (
                "shared",
                Scene {
                    nodes: vec![
                        at("a1", &s.plain, 1.0, 0.1),
                        at("b", &s.other, 2.0, 0.2),
                        at("a2", &s.plain, 3.0, 0.3),
                        at("b2", &s.other, 4.0, 0.0),
                        SceneNode::new("a3", &s.plain),
                    ],
                },
            ),
            ("lean", Scene::single(at("l", &s.lean, 0.0, 0.0))),
            ("textured", Scene::single(at("t", &s.textured, 5.0, 2.0))),
            (
                "wind",
                Scene {
                    nodes: vec![rigged, at("p", &s.plain, 7.0, 0.0), rigged2],
                },
            ),
            ("wide", Scene::single(at("w", &s.wide, 0.0, 0.0))),
            ("empty", Scene::default()),
            ("empty-mesh", Scene::single(SceneNode::new("e", &s.empty))),
            (
                "mixed",
                Scene {
                    nodes: vec![
                        at("t", &s.textured, 1.0, 0.0),
                        at("l1", &s.lean, 2.0, 1.0),
                        at("e", &s.empty, 3.0, 0.0),
                        at("l2", &s.lean, 4.0, 2.0),
                        at("t2", &s.textured, 5.0, 3.0),
                    ],
                },
            ),
        ]
    }

    /// The bytes `to_glb` wrote for the sample scenes before the streaming writer (the hash
    /// of each file), so that no rewrite of the writer changes them. The wind scene's changed
    /// once, on purpose: its skin's joints, weights and flutter went into one interleaved
    /// buffer view (the same values, checked vertex by vertex), so each vertex's influence is
    /// worked out once as it is written.
    #[test]
    fn sample_scenes_keep_their_bytes() {
        let s = samples();
        let found: Vec<(&str, u64)> = sample_scenes(&s)
            .iter()
            .map(|(name, scene)| {
                (
                    *name,
                    sylva_core::hash::stable_hash(&to_glb(scene).unwrap()),
                )
            })
            .collect();
        assert_eq!(found, GOLDEN);
    }

    const ALL_OPTIONS: [GlbOptions; 4] = [
        GlbOptions {
            instancing: false,
            quantize: false,
        },
        GlbOptions {
            instancing: true,
            quantize: false,
        },
        GlbOptions {
            instancing: false,
            quantize: true,
        },
        GlbOptions {
            instancing: true,
            quantize: true,
        },
    ];

    fn streamed(glb: &mut Glb<'_>) -> Vec<u8> {
        let mut bytes = Vec::new();
        glb.write_to(&mut bytes).unwrap();
        assert_eq!(bytes.len() as u64, glb.stats().bytes);
        bytes
    }

    #[test]
    fn streaming_gives_the_bytes_of_the_in_memory_writer() {
        let s = samples();
        let dir = tempfile::tempdir().unwrap();
        for (name, scene) in sample_scenes(&s) {
            for options in ALL_OPTIONS {
                let in_memory = to_glb_with(&scene, &options).unwrap();
                let mut glb = Glb::of_scene(&scene, options).unwrap();
                assert_eq!(streamed(&mut glb), in_memory, "{name} {options:?}");
                // Twice from one layout: the second write is the same.
                assert_eq!(streamed(&mut glb), in_memory, "{name} {options:?}");
                assert_eq!(glb.stats().triangles, scene.triangle_count() as u64);
            }
            // And to a file, through the atomic write.
            let path = dir.path().join(format!("{name}.glb"));
            crate::export::write_scene(&path, &scene).unwrap();
            assert_eq!(
                std::fs::read(&path).unwrap(),
                to_glb(&scene).unwrap(),
                "{name}"
            );
        }
    }

    /// Makes each mesh when asked, into one buffer, noting the requests.
    struct Making<'m> {
        meshes: Vec<&'m Mesh>,
        buffer: Mesh,
        asked: std::rc::Rc<std::cell::RefCell<Vec<usize>>>,
    }

    impl MeshSource for Making<'_> {
        fn mesh(&mut self, index: usize) -> Result<&Mesh, ExportError> {
            self.asked.borrow_mut().push(index);
            self.buffer = self
                .meshes
                .get(index)
                .copied()
                .cloned()
                .ok_or(ExportError::NoSuchMesh { index })?;
            Ok(&self.buffer)
        }
    }

    #[test]
    fn meshes_made_on_demand_give_the_same_bytes_asked_once_per_pass() {
        let s = samples();
        let scenes = sample_scenes(&s);
        let scene = &scenes.iter().find(|(n, _)| *n == "mixed").unwrap().1;
        let (nodes, meshes) = scene_nodes(scene);
        let n = meshes.len();
        for options in ALL_OPTIONS {
            let asked = std::rc::Rc::default();
            let source = Making {
                meshes: meshes.clone(),
                buffer: Mesh::default(),
                asked: std::rc::Rc::clone(&asked),
            };
            let mut glb = Glb::new(nodes.clone(), Box::new(source), options).unwrap();
            assert_eq!(*asked.borrow(), (0..n).collect::<Vec<_>>());
            assert_eq!(streamed(&mut glb), to_glb_with(scene, &options).unwrap());
            assert_eq!(asked.borrow().len(), 2 * n, "each mesh once per pass");
        }
        // A source without the mesh asked for is an error, not a panic.
        let mut nodes = nodes;
        nodes[0].mesh = 99;
        let e = Glb::new(nodes, Box::new(meshes), GlbOptions::default())
            .err()
            .unwrap();
        assert!(matches!(e, ExportError::NoSuchMesh { index: 99 }), "{e}");
    }

    #[test]
    fn instancing_draws_nodes_that_share_a_mesh_and_extras_with_one_node() {
        let (a, b) = (small_mesh(), samples().other);
        let same = json!({ "seed": 1 });
        let other = json!({ "seed": 2 });
        let node = |name: &str, mesh, x: f32, extras: &Value| {
            let mut n = SceneNode::new(name, mesh);
            n.translation = Vec3::new(x, 0.0, 1.0);
            n.rotation = Quat::from_rotation_y(x);
            n.extras = Some(extras.clone());
            n
        };
        let scene = Scene {
            nodes: vec![
                node("a0", &a, 0.0, &same),
                node("b0", &b, 1.0, &same),
                node("a1", &a, 2.0, &same),
                node("a2", &a, 3.0, &other),
                node("a3", &a, 4.0, &same),
            ],
        };
        let options = GlbOptions {
            instancing: true,
            quantize: false,
        };
        let bytes = to_glb_with(&scene, &options).unwrap();
        let (json, bin) = chunks(&bytes);
        let bin = bin.unwrap();
        assert_eq!(json["extensionsUsed"], json!([EXT_MESH_GPU_INSTANCING]));
        assert!(json.get("extensionsRequired").is_none());
        let nodes = json["nodes"].as_array().unwrap();
        // a0 (with a1 and a3), b0, a2: three nodes in order of first appearance, two meshes.
        assert_eq!(nodes.len(), 3);
        assert_eq!(json["meshes"].as_array().unwrap().len(), 2);
        let names: Vec<&str> = nodes.iter().map(|n| n["name"].as_str().unwrap()).collect();
        assert_eq!(names, ["a0", "b0", "a2"]);
        assert_eq!(nodes[0]["extras"], same);
        assert_eq!(nodes[2]["extras"], other);
        assert_eq!(nodes[0]["mesh"], nodes[2]["mesh"]);
        let attributes = &nodes[0]["extensions"][EXT_MESH_GPU_INSTANCING]["attributes"];
        assert!(attributes.get("SCALE").is_none());
        let floats = |accessor: &Value| -> Vec<f32> {
            let a = &json["accessors"][accessor.as_u64().unwrap() as usize];
            let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
            assert!(view.get("target").is_none());
            let start = view["byteOffset"].as_u64().unwrap() as usize;
            let len = view["byteLength"].as_u64().unwrap() as usize;
            bin[start..start + len]
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                .collect()
        };
        let t = floats(&attributes["TRANSLATION"]);
        assert_eq!(t, [0.0, 0.0, 1.0, 2.0, 0.0, 1.0, 4.0, 0.0, 1.0]);
        let r = floats(&attributes["ROTATION"]);
        assert_eq!(r[4..8], Quat::from_rotation_y(2.0).normalize().to_array());
        // A lone node is an instanced node too; rigged ones never are.
        let count = |attribute: &Value| {
            json["accessors"][attribute.as_u64().unwrap() as usize]["count"].clone()
        };
        assert_eq!(count(&attributes["ROTATION"]), 3);
        let s = samples();
        let scenes = sample_scenes(&s);
        let wind = &scenes.iter().find(|(n, _)| *n == "wind").unwrap().1;
        let (json, _) = chunks(&to_glb_with(wind, &options).unwrap());
        let nodes = json["nodes"].as_array().unwrap();
        assert!(nodes[0]["skin"].is_u64() && nodes[2]["skin"].is_u64());
        assert!(nodes[1]["extensions"][EXT_MESH_GPU_INSTANCING].is_object());
    }

    /// Every vertex of every node as Sylva's reader places it in the world.
    fn world_vertices(glb: &[u8]) -> Vec<(Vec3, Vec3)> {
        let scene = crate::import::read_glb(glb).unwrap();
        scene
            .meshes
            .iter()
            .flat_map(|(_, m)| {
                m.positions
                    .iter()
                    .zip(&m.normals)
                    .map(|(p, n)| (Vec3::from_array(*p), Vec3::from_array(*n)))
            })
            .collect()
    }

    #[test]
    fn quantised_positions_come_back_within_half_a_step() {
        let s = samples();
        for (name, scene) in sample_scenes(&s) {
            let exact = world_vertices(&to_glb(&scene).unwrap());
            for options in &ALL_OPTIONS[1..] {
                let bytes = to_glb_with(&scene, options).unwrap();
                let (json, _) = chunks(&bytes);
                let back = world_vertices(&bytes);
                assert_eq!(back.len(), exact.len(), "{name} {options:?}");
                // The largest extent of any mesh bounds the error of every position.
                let extent = scene
                    .nodes
                    .iter()
                    .map(|n| {
                        let (min, max) = bounds(&n.mesh.positions);
                        (max - min).max_element()
                    })
                    .fold(0.0f32, f32::max);
                let mut worst = (0.0f32, 0.0f32);
                for ((p, n), (q, m)) in exact.iter().zip(&back) {
                    worst.0 = worst.0.max((*p - *q).abs().max_element());
                    worst.1 = worst.1.max(n.angle_between(*m));
                }
                // Rigged meshes stay floats; the wind scene's plain node is quantised.
                let quantized = options.quantize && !name.starts_with("empty");
                let bound = if quantized {
                    // Per axis of the mesh, half a step is half of this (a step is the half
                    // extent over 32767), and a turn about Y mixes two axes (√2 at most);
                    // 2e-6 m allows for the floats' rounding in the transforms.
                    extent / 65534.0 + 2e-6
                } else {
                    2e-6
                };
                assert!(
                    worst.0 <= bound,
                    "{name} {options:?}: {} > {bound}",
                    worst.0
                );
                // Normals as bytes turn by at most about a degree.
                assert!(
                    worst.1 <= 0.02,
                    "{name} {options:?}: normal off by {}",
                    worst.1
                );
                if quantized {
                    assert_eq!(json["extensionsRequired"], json!([KHR_MESH_QUANTIZATION]));
                } else {
                    assert!(json.get("extensionsRequired").is_none(), "{name}");
                }
            }
        }
    }

    #[test]
    fn quantised_normals_are_unit_length_to_the_validators_tolerance() {
        let mut worst = 0.0f32;
        for i in 0..2000 {
            // Spread over the sphere (a Fibonacci lattice) and along the axes.
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
            let a = i as f32 * 2.399_963;
            let n = Vec3::new(
                (1.0 - z * z).sqrt() * a.cos(),
                z,
                (1.0 - z * z).sqrt() * a.sin(),
            );
            for n in [n, Vec3::X, -Vec3::Y, Vec3::new(1.0, 1.0, 1.0).normalize()] {
                let q = Vec3::from_array(quantize_normal(n).map(f32::from)) / 127.0;
                worst = worst.max((q.length() - 1.0).abs());
                assert!(q.angle_between(n) < 0.02, "{n}: {q}");
            }
        }
        assert!(worst < 0.005, "{worst}");
    }

    #[test]
    fn rounding_matches_the_standard_library() {
        for x in [
            0.0f32, 0.5, -0.5, 1.5, -2.5, 0.49999997, 126.5, -32_766.5, 1e-9, 3.7,
        ] {
            assert_eq!(round(x), x.round() as i32, "{x}");
        }
    }

    #[test]
    fn positions_quantise_to_the_full_range_of_shorts() {
        let d = Dequant::of(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 8.0, 2.0));
        assert_eq!(d.offset, Vec3::new(1.0, 4.0, 2.0));
        assert_eq!(d.scale, 4.0);
        assert_eq!(d.quantize(Vec3::new(-1.0, 0.0, 2.0)), [-16384, -32767, 0]);
        assert_eq!(d.quantize(Vec3::new(3.0, 8.0, 2.0)), [16384, 32767, 0]);
        // A box of no extent (one point) scales by 1.
        assert_eq!(Dequant::of(Vec3::ONE, Vec3::ONE).scale, 1.0);
    }

    const GOLDEN: &[(&str, u64)] = &[
        ("single", 0xf0cb2741ca6e59cf),
        ("shared", 0x9073e6f609768fe5),
        ("lean", 0x2084a482472e881a),
        ("textured", 0xba278ea2d742ac86),
        ("wind", 0xec84_32fd_b9d8_0901),
        ("wide", 0xdd325f1cd0150298),
        ("empty", 0xf2c6ab7472da058),
        ("empty-mesh", 0x53fbbd7fb468edd6),
        ("mixed", 0xbc46033f21986b14),
    ];

    #[test]
    fn header_chunks_and_alignment() {
        let mesh = small_mesh();
        let mut node = SceneNode::new("plant", &mesh);
        node.translation = Vec3::new(1.0, 0.0, 2.0);
        node.extras = Some(json!({ "seed": 7, "genome": { "model": "bintree", "bits": [1, 0] } }));
        let glb = to_glb(&Scene::single(node)).unwrap();
        let (json, bin) = chunks(&glb);
        let bin = bin.unwrap();
        assert_eq!(
            json["buffers"][0]["byteLength"].as_u64().unwrap() as usize,
            bin.len()
        );
        for view in json["bufferViews"].as_array().unwrap() {
            assert_eq!(view["byteOffset"].as_u64().unwrap() % 4, 0);
            assert!(view.get("byteStride").is_none());
            assert!(view["target"].is_u64());
        }
        assert_eq!(
            json["asset"]["generator"],
            concat!("Sylva ", env!("CARGO_PKG_VERSION"))
        );
        assert_eq!(json["nodes"][0]["extras"]["genome"]["model"], "bintree");
        assert_eq!(json["nodes"][0]["translation"], json!([1.0, 0.0, 2.0]));
        assert_eq!(
            json["meshes"][0]["primitives"].as_array().unwrap().len(),
            mesh.primitives.len()
        );
        assert_eq!(json["accessors"][2]["componentType"], UNSIGNED_SHORT);
        // Untextured: no texture coordinates, images or samplers.
        for p in json["meshes"][0]["primitives"].as_array().unwrap() {
            assert!(p["attributes"].get("TEXCOORD_0").is_none());
        }
        assert!(json.get("images").is_none() && json.get("samplers").is_none());
        let pos = &json["accessors"][0];
        let b = mesh.bounds();
        assert_eq!(pos["min"], json!(b.min.to_array()));
        assert_eq!(pos["max"], json!(b.max.to_array()));
    }

    #[test]
    fn shared_meshes_are_written_once() {
        let a = small_mesh();
        let b = small_mesh();
        let scene = Scene {
            nodes: vec![
                SceneNode::new("a1", &a),
                SceneNode::new("b", &b),
                SceneNode::new("a2", &a),
            ],
        };
        let (json, _) = chunks(&to_glb(&scene).unwrap());
        assert_eq!(json["meshes"].as_array().unwrap().len(), 2);
        assert_eq!(json["nodes"][0]["mesh"], 0);
        assert_eq!(json["nodes"][1]["mesh"], 1);
        assert_eq!(json["nodes"][2]["mesh"], 0);
        // Identical materials are shared too.
        assert_eq!(json["materials"].as_array().unwrap().len(), 3);
    }

    #[test]
    fn shades_of_one_kind_share_a_material_and_carry_vertex_colours() {
        let plain = to_glb(&Scene::single(SceneNode::new("p", &small_mesh()))).unwrap();
        let (json, _) = chunks(&plain);
        assert!(json.to_string().find("COLOR_0").is_none());
        let mesh = two_shades();
        let shade = mesh.primitives[0].material;
        let (json, _) = chunks(&to_glb(&Scene::single(SceneNode::new("p", &mesh))).unwrap());
        let prims = json["meshes"][0]["primitives"].as_array().unwrap();
        assert_eq!(
            prims.len(),
            mesh.primitives.len() - 1,
            "the two shades merged"
        );
        let color = prims[0]["attributes"]["COLOR_0"].as_u64().unwrap() as usize;
        assert_eq!(json["accessors"][color]["componentType"], UNSIGNED_BYTE);
        assert_eq!(json["accessors"][color]["normalized"], true);
        assert!(prims.iter().all(|p| p["attributes"]["COLOR_0"] == color));
        let kind = mesh.materials[shade].kind.name();
        assert_eq!(json["materials"][0]["name"], kind);
    }

    #[test]
    fn empty_scene_and_empty_mesh_are_valid() {
        let glb = to_glb(&Scene::default()).unwrap();
        let (json, bin) = chunks(&glb);
        assert!(bin.is_none());
        assert!(json.get("nodes").is_none() && json.get("buffers").is_none());
        let empty = Mesh::default();
        let glb = to_glb(&Scene::single(SceneNode::new("e", &empty))).unwrap();
        let (json, bin) = chunks(&glb);
        assert!(bin.is_none());
        assert!(json["nodes"][0].get("mesh").is_none());
        assert_eq!(json["scenes"][0]["nodes"], json!([0]));
    }

    #[test]
    fn same_scene_same_bytes() {
        let mesh = small_mesh();
        let mut node = SceneNode::new("plant", &mesh);
        node.rotation = Quat::from_rotation_y(0.3);
        node.extras = Some(json!({ "z": 1, "a": [1.5, 2.5], "m": { "y": null, "b": true } }));
        let scene = Scene::single(node);
        assert_eq!(to_glb(&scene).unwrap(), to_glb(&scene).unwrap());
        let again = small_mesh();
        let mut node = SceneNode::new("plant", &again);
        node.rotation = Quat::from_rotation_y(0.3);
        node.extras = Some(json!({ "a": [1.5, 2.5], "m": { "b": true, "y": null }, "z": 1 }));
        assert_eq!(
            to_glb(&scene).unwrap(),
            to_glb(&Scene::single(node)).unwrap()
        );
    }

    #[test]
    fn wide_indices_past_65535_vertices() {
        let mut mesh = Mesh {
            materials: vec![sylva_core::Material::of_kind(
                sylva_core::MaterialKind::Bark,
            )],
            ..Mesh::default()
        };
        for i in 0..70_000u32 {
            mesh.positions.push([i as f32, (i % 3) as f32, 0.0]);
            mesh.normals.push([0.0, 0.0, 1.0]);
        }
        mesh.primitives.push(sylva_mesh::Primitive {
            material: 0,
            indices: vec![0, 1, 2, 69_997, 69_998, 69_999],
        });
        let (json, _) = chunks(&to_glb(&Scene::single(SceneNode::new("w", &mesh))).unwrap());
        assert_eq!(json["accessors"][2]["componentType"], UNSIGNED_INT);
    }

    #[test]
    fn textures_are_embedded_once_per_id() {
        let mut mesh = small_mesh();
        // bark: texture 0; leaf: 3; flower: 3 too (shared); plus an untextured material.
        mesh.materials[0].texture = Some(0);
        mesh.materials[1].texture = Some(3);
        mesh.materials[2].texture = Some(3);
        let glb = to_glb(&Scene::single(SceneNode::new("t", &mesh))).unwrap();
        let (json, bin) = chunks(&glb);
        let bin = bin.unwrap();
        // Every primitive is textured: all read the one TEXCOORD_0 accessor.
        assert_eq!(json["accessors"][2]["type"], "VEC2");
        for p in json["meshes"][0]["primitives"].as_array().unwrap() {
            assert_eq!(p["attributes"]["TEXCOORD_0"], 2);
        }
        let images = json["images"].as_array().unwrap();
        assert_eq!(images.len(), 2);
        assert_eq!(images[0]["name"], "sylva-texture-0");
        assert_eq!(images[1]["name"], "sylva-texture-3");
        for image in images {
            assert_eq!(image["mimeType"], "image/png");
            let view = &json["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
            assert!(view.get("target").is_none(), "image views have no target");
            let start = view["byteOffset"].as_u64().unwrap() as usize;
            let len = view["byteLength"].as_u64().unwrap() as usize;
            assert_eq!(start % 4, 0);
            let png = &bin[start..start + len];
            assert!(png.starts_with(b"\x89PNG"));
            let id: u16 = image["name"].as_str().unwrap()["sylva-texture-".len()..]
                .parse()
                .unwrap();
            assert_eq!(png, sylva_mesh::texture::texture(id).png().unwrap());
        }
        // Bark repeats both ways; the leaf texture is clamped along v.
        let samplers = json["samplers"].as_array().unwrap();
        assert_eq!(samplers.len(), 2);
        assert_eq!(samplers[0]["wrapT"], REPEAT);
        assert_eq!(samplers[1]["wrapT"], CLAMP_TO_EDGE);
        let textures = json["textures"].as_array().unwrap();
        assert_eq!(textures.len(), 2);
        assert_eq!(textures[1]["sampler"], 1);
        let materials = json["materials"].as_array().unwrap();
        let texture_of =
            |m: &Value| m["pbrMetallicRoughness"]["baseColorTexture"]["index"].as_u64();
        assert_eq!(texture_of(&materials[0]), Some(0));
        assert_eq!(texture_of(&materials[1]), Some(1));
        assert_eq!(texture_of(&materials[2]), Some(1));
        // The colour is still the factor.
        let c = mesh.materials[1].color;
        assert_eq!(
            materials[1]["pbrMetallicRoughness"]["baseColorFactor"][1],
            json!(short(c[1]))
        );

        // Same material name and colour but no texture: a separate, untextured material.
        let mut plain = mesh.clone();
        plain.materials[1].texture = None;
        let scene = Scene {
            nodes: vec![SceneNode::new("t", &mesh), SceneNode::new("p", &plain)],
        };
        let (json, _) = chunks(&to_glb(&scene).unwrap());
        let materials = json["materials"].as_array().unwrap();
        assert_eq!(materials.len(), 4);
        assert!(texture_of(&materials[3]).is_none());
        let leaf = &json["meshes"][1]["primitives"][1];
        assert!(leaf["attributes"].get("TEXCOORD_0").is_none());
        assert!(json["meshes"][1]["primitives"][0]["attributes"]["TEXCOORD_0"].is_u64());
        assert_eq!(json["images"].as_array().unwrap().len(), 2);
    }

    #[test]
    fn refuses_broken_meshes() {
        let mut mesh = small_mesh();
        mesh.normals.pop();
        let e = to_glb(&Scene::single(SceneNode::new("x", &mesh))).unwrap_err();
        assert!(matches!(e, ExportError::NormalCount { .. }), "{e}");
        let mut mesh = small_mesh();
        mesh.primitives[0].indices.pop();
        let e = to_glb(&Scene::single(SceneNode::new("x", &mesh))).unwrap_err();
        assert!(matches!(e, ExportError::PartialTriangle { .. }), "{e}");
        let mesh = small_mesh();
        let mut node = SceneNode::new("x", &mesh);
        node.rotation = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        let e = to_glb(&Scene::single(node)).unwrap_err();
        assert!(matches!(e, ExportError::ZeroRotation { .. }), "{e}");
    }
}
