//! glTF 2.0 binary (GLB) writer.
//!
//! Layout: one glTF node per scene node, all at the root of one scene; one glTF mesh per
//! distinct [`Mesh`] (nodes that borrow the same mesh, compared by address, share it); one
//! primitive per [`Primitive`](crate::Primitive), all sharing the mesh's POSITION and NORMAL
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
//! PNG ([`crate::texture`]) embedded in its own buffer view (no `target`), an `image` named
//! `sylva-texture-<id>` (which [`crate::import`] reads back as the id), and a `texture`
//! with a sampler that repeats in u, and in v for bark or clamps to the edge for leaves and
//! petals, with trilinear filtering. The colour stays in `baseColorFactor`, which glTF
//! multiplies with the texture.
//!
//! Each buffer view holds one tightly packed accessor (no `byteStride`), starts on a 4-byte
//! boundary and has its `target` set. The JSON chunk is padded with spaces and the BIN chunk
//! with zeros to 4 bytes. A mesh with no triangles gives a node without a mesh. The JSON is
//! built with `serde_json`, whose maps keep a fixed key order, so output is deterministic.

use std::collections::HashMap;

use serde_json::{Map, Value, json};
use sylva_core::glam::{Quat, Vec3};

use super::{ExportError, check_scene};
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::wind::Rig;

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const GLB_VERSION: u32 = 2;
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_BYTE: u32 = 5121;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const LINEAR: u32 = 9729;
const LINEAR_MIPMAP_LINEAR: u32 = 9987;
const REPEAT: u32 = 10497;
const CLAMP_TO_EDGE: u32 = 33071;
/// The prefix of the glTF image names that carry a Sylva texture id.
pub(crate) const IMAGE_NAME_PREFIX: &str = "sylva-texture-";
/// Most vertices that `u16` indices can address (65 535 is reserved for primitive restart).
const U16_VERTICES: usize = 65_535;
/// Roughness of every material: plants are matte.
const ROUGHNESS: f64 = 0.9;

/// Encodes `scene` as a GLB file. Fails only on a scene [`check_scene`] refuses or one too
/// large for a GLB's 32-bit lengths.
pub fn to_glb(scene: &Scene) -> Result<Vec<u8>, ExportError> {
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
    let mut w = Writer::default();
    let mut mesh_of: HashMap<(*const Mesh, *const Rig), Option<usize>> = HashMap::new();
    let mut nodes = Vec::with_capacity(scene.nodes.len());
    // Rigs go after the plants' nodes: (node index, rig, the node's transform).
    let mut rigs: Vec<(usize, &Rig, Vec3, Quat)> = Vec::new();
    for node in &scene.nodes {
        // Addresses only find a mesh already written; indices follow first appearance.
        let rig_key: *const Rig = node.rig.map_or(std::ptr::null(), |r| r as *const Rig);
        let key = (node.mesh as *const Mesh, rig_key);
        let mesh = match mesh_of.get(&key) {
            Some(&m) => m,
            None => {
                let m = w.mesh(node.mesh, &node.name, node.rig)?;
                mesh_of.insert(key, m);
                m
            }
        };
        let mut n = Map::new();
        n.insert("name".into(), json!(node.name));
        if let Some(m) = mesh {
            n.insert("mesh".into(), json!(m));
        }
        if let (Some(rig), Some(_)) = (node.rig, mesh) {
            // A skinned mesh ignores its node's transform: the rig's root node carries it.
            rigs.push((
                nodes.len(),
                rig,
                node.translation,
                node.rotation.normalize(),
            ));
            if let Some(extras) = &node.extras {
                n.insert("extras".into(), extras.clone());
            }
            nodes.push(Value::Object(n));
            continue;
        }
        if node.translation != Vec3::ZERO {
            n.insert(
                "translation".into(),
                json!(node.translation.to_array().map(short)),
            );
        }
        let rotation = node.rotation.normalize();
        if rotation != Quat::IDENTITY {
            n.insert("rotation".into(), json!(rotation.to_array().map(short)));
        }
        if let Some(extras) = &node.extras {
            n.insert("extras".into(), extras.clone());
        }
        nodes.push(Value::Object(n));
    }

    let plant_nodes = nodes.len();
    let mut scene_nodes: Vec<usize> = (0..plant_nodes).collect();
    let mut skins = Vec::new();
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    for (node, rig, translation, rotation) in rigs {
        let name = nodes[node]["name"].as_str().unwrap_or("plant").to_owned();
        // The rig's root: a plain node with the plant's place, parent of its root joints.
        let root_node = nodes.len();
        let mut root_json = json!({ "name": format!("{name}-rig") });
        if translation != Vec3::ZERO {
            root_json["translation"] = json!(translation.to_array().map(short));
        }
        if rotation != Quat::IDENTITY {
            root_json["rotation"] = json!(rotation.to_array().map(short));
        }
        nodes.push(root_json);
        scene_nodes.push(root_node);
        let first = nodes.len();
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
            nodes.push(n);
        }
        for (j, c) in children.into_iter().enumerate() {
            if !c.is_empty() {
                nodes[first + j]["children"] = json!(c);
            }
        }
        nodes[root_node]["children"] = json!(roots);
        let ibm = w.inverse_binds(rig);
        skins.push(json!({
            "name": format!("{name}-skin"),
            "inverseBindMatrices": ibm,
            "joints": (first..first + rig.joints.len()).collect::<Vec<_>>(),
            "skeleton": root_node,
        }));
        nodes[node]["skin"] = json!(skins.len() - 1);
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
    root.insert("scene".into(), json!(0));
    root.insert(
        "scenes".into(),
        if scene_nodes.is_empty() {
            json!([{}])
        } else {
            json!([{ "nodes": scene_nodes }])
        },
    );
    pad4(&mut w.bin, 0);
    let bin_len = w.bin.len();
    let arrays = [
        ("nodes", nodes),
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
    pad4(&mut json, b' ');

    let total = 12 + 8 + json.len() as u64 + if bin_len > 0 { 8 + bin_len as u64 } else { 0 };
    let too_large = || ExportError::TooLarge { bytes: total };
    let total32 = u32::try_from(total).map_err(|_| too_large())?;
    let mut out = Vec::with_capacity(total as usize);
    for word in [
        GLB_MAGIC,
        GLB_VERSION,
        total32,
        json.len() as u32,
        CHUNK_JSON,
    ] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json);
    if bin_len > 0 {
        out.extend_from_slice(&(bin_len as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(&w.bin);
    }
    Ok(out)
}

/// The parts of the glTF document built while walking the scene.
#[derive(Default)]
struct Writer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    textures: Vec<Value>,
    images: Vec<Value>,
    samplers: Vec<Value>,
    /// (name, colour bits, texture) to material index, to write identical materials once.
    material_of: HashMap<(String, [u32; 3], Option<u16>), usize>,
    /// Texture id to glTF texture index, to embed each picture once.
    texture_of: HashMap<u16, usize>,
    /// The sampler for textures that repeat along v ([0]) and that clamp ([1]), once written.
    sampler_of: [Option<usize>; 2],
}

impl Writer {
    /// Writes a mesh's data and returns its glTF mesh index; `None` when it has no triangles.
    fn mesh(
        &mut self,
        mesh: &Mesh,
        name: &str,
        rig: Option<&Rig>,
    ) -> Result<Option<usize>, ExportError> {
        if mesh.primitives.iter().all(|p| p.indices.is_empty()) {
            return Ok(None);
        }
        let count = mesh.positions.len();
        let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let start = self.bin.len();
        let index_count: usize = mesh.primitives.iter().map(|p| p.indices.len() + 2).sum();
        self.bin.reserve(32 * count + 4 * index_count);
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
        let textured = |p: &crate::Primitive| {
            !p.indices.is_empty() && mesh.materials[p.material].texture.is_some()
        };
        let texcoord = if mesh.primitives.iter().any(textured) {
            let start = self.bin.len();
            if mesh.uvs.len() == count {
                for uv in &mesh.uvs {
                    for c in uv {
                        self.bin.extend_from_slice(&c.to_le_bytes());
                    }
                }
            } else {
                // check_scene allows only one per position or none.
                self.bin.resize(start + 8 * count, 0);
            }
            let view = self.view(start, ARRAY_BUFFER);
            Some(self.accessor(json!({
                "bufferView": view, "componentType": FLOAT, "count": count, "type": "VEC2",
            })))
        } else {
            None
        };

        let skin = match rig {
            Some(rig) if rig.vertex_joints.len() == count => Some(self.skin_attributes(rig)),
            _ => None,
        };

        // What is drawn: each primitive with its material, or lean materials' merged ones.
        let lean = super::lean::LeanPlan::of(mesh);
        let color = lean.as_ref().map(|plan| {
            let start = self.bin.len();
            for rgba in &plan.colors {
                self.bin.extend_from_slice(rgba);
            }
            let view = self.view(start, ARRAY_BUFFER);
            self.accessor(json!({
                "bufferView": view, "componentType": UNSIGNED_BYTE, "normalized": true,
                "count": count, "type": "VEC4",
            }))
        });
        let draws: Vec<(&sylva_core::Material, Vec<&crate::Primitive>)> = match &lean {
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
                    self.bin.extend_from_slice(&i.to_le_bytes());
                }
            } else {
                // check_scene put every index below count <= 65 535.
                for i in indices {
                    self.bin.extend_from_slice(&(i as u16).to_le_bytes());
                }
            }
            pad4(&mut self.bin, 0);
            let view = self.view(start, ELEMENT_ARRAY_BUFFER);
            let indices = self.accessor(json!({
                "bufferView": view,
                "componentType": if wide { UNSIGNED_INT } else { UNSIGNED_SHORT },
                "count": group.iter().map(|p| p.indices.len()).sum::<usize>(),
                "type": "SCALAR",
            }));
            let textured = material.texture.is_some();
            let material = self.material(material)?;
            let mut attributes = json!({ "POSITION": position, "NORMAL": normal });
            if let (Some(t), true) = (texcoord, textured) {
                attributes["TEXCOORD_0"] = json!(t);
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
        Ok(Some(self.meshes.len() - 1))
    }

    /// A rigged mesh's JOINTS_0, WEIGHTS_0 and `_WIND` accessors.
    fn skin_attributes(&mut self, rig: &Rig) -> (usize, usize, usize) {
        let count = rig.vertex_joints.len();
        let start = self.bin.len();
        for j in &rig.vertex_joints {
            self.bin.extend_from_slice(j);
        }
        let view = self.view(start, ARRAY_BUFFER);
        let joints = self.accessor(json!({
            "bufferView": view, "componentType": UNSIGNED_BYTE, "count": count, "type": "VEC4",
        }));
        let start = self.bin.len();
        for w in &rig.vertex_weights {
            self.bin.extend_from_slice(w);
        }
        let view = self.view(start, ARRAY_BUFFER);
        let weights = self.accessor(json!({
            "bufferView": view, "componentType": UNSIGNED_BYTE, "normalized": true,
            "count": count, "type": "VEC4",
        }));
        let start = self.bin.len();
        for f in &rig.flutter {
            self.bin.extend_from_slice(&f.to_le_bytes());
        }
        let view = self.view(start, ARRAY_BUFFER);
        let flutter = self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": count, "type": "SCALAR",
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
                self.bin.extend_from_slice(&c.to_le_bytes());
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
            self.bin.extend_from_slice(&t.to_le_bytes());
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
            for c in q.normalize().to_array() {
                self.bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        let view = self.untargeted_view(start);
        self.accessor(json!({
            "bufferView": view, "componentType": FLOAT, "count": keys.len(), "type": "VEC4",
        }))
    }

    /// A buffer view over `bin[start..]`, which starts on a 4-byte boundary.
    fn view(&mut self, start: usize, target: u32) -> usize {
        let view = self.untargeted_view(start);
        self.views[view]["target"] = json!(target);
        view
    }

    /// A buffer view without a target (for image data), over `bin[start..]`.
    fn untargeted_view(&mut self, start: usize) -> usize {
        debug_assert_eq!(start % 4, 0);
        let length = self.bin.len() - start;
        self.views.push(json!({
            "buffer": 0, "byteOffset": start, "byteLength": length,
        }));
        self.views.len() - 1
    }

    /// The glTF texture showing Sylva texture `id`, embedding its PNG the first time.
    fn texture(&mut self, id: u16) -> Result<usize, ExportError> {
        if let Some(&t) = self.texture_of.get(&id) {
            return Ok(t);
        }
        let png =
            crate::texture::texture_png(id).map_err(|source| ExportError::Png { id, source })?;
        let start = self.bin.len();
        self.bin.extend_from_slice(&png);
        let view = self.untargeted_view(start);
        pad4(&mut self.bin, 0);
        self.images.push(json!({
            "bufferView": view,
            "mimeType": "image/png",
            "name": format!("{IMAGE_NAME_PREFIX}{id}"),
        }));
        let repeats = crate::texture::texture_info(id).family.repeats_v();
        let slot = usize::from(!repeats);
        let sampler = match self.sampler_of[slot] {
            Some(s) => s,
            None => {
                self.samplers.push(json!({
                    "magFilter": LINEAR,
                    "minFilter": LINEAR_MIPMAP_LINEAR,
                    "wrapS": REPEAT,
                    "wrapT": if repeats { REPEAT } else { CLAMP_TO_EDGE },
                }));
                self.sampler_of[slot] = Some(self.samplers.len() - 1);
                self.samplers.len() - 1
            }
        };
        self.textures.push(json!({
            "name": crate::texture::texture_info(id).name,
            "sampler": sampler,
            "source": self.images.len() - 1,
        }));
        self.texture_of.insert(id, self.textures.len() - 1);
        Ok(self.textures.len() - 1)
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn material(&mut self, m: &sylva_core::Material) -> Result<usize, ExportError> {
        let key = (m.name.clone(), m.color.map(f32::to_bits), m.texture);
        if let Some(&i) = self.material_of.get(&key) {
            return Ok(i);
        }
        let [r, g, b] = m.color.map(|c| short(c.clamp(0.0, 1.0)));
        let mut pbr = json!({
            "baseColorFactor": [r, g, b, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": ROUGHNESS,
        });
        if let Some(id) = m.texture {
            pbr["baseColorTexture"] = json!({ "index": self.texture(id)? });
        }
        self.materials.push(json!({
            "name": m.name,
            "pbrMetallicRoughness": pbr,
        }));
        self.material_of.insert(key, self.materials.len() - 1);
        Ok(self.materials.len() - 1)
    }
}

fn push_vec3(bin: &mut Vec<u8>, v: Vec3) {
    for c in v.to_array() {
        bin.extend_from_slice(&c.to_le_bytes());
    }
}

fn pad4(bytes: &mut Vec<u8>, fill: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(fill);
    }
}

/// The `f64` nearest the shortest decimal that reads back as `x`: `0.85f32` is written as
/// `0.85`, not `0.8500000238418579`. For values that are not compared bit for bit.
fn short(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::tests::small_mesh;
    use crate::scene::SceneNode;

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
        let mut mesh = small_mesh();
        let plain = to_glb(&Scene::single(SceneNode::new("p", &mesh))).unwrap();
        let (json, _) = chunks(&plain);
        assert!(json.to_string().find("COLOR_0").is_none());
        let shade = mesh.primitives[0].material;
        let mut darker = mesh.materials[shade].clone();
        darker.color = darker.color.map(|c| c * 0.5);
        darker.name.push_str("-dark");
        mesh.materials.push(darker);
        let half = mesh.primitives[0].indices.len() / 6 * 3;
        let moved = mesh.primitives[0].indices.split_off(half);
        mesh.primitives.push(crate::Primitive {
            material: mesh.materials.len() - 1,
            indices: moved,
        });
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
        mesh.primitives.push(crate::Primitive {
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
            let id: u16 = image["name"].as_str().unwrap()[IMAGE_NAME_PREFIX.len()..]
                .parse()
                .unwrap();
            assert_eq!(png, crate::texture::texture(id).png().unwrap());
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
