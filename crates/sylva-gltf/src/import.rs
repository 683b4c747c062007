//! Reading GLB files back, so `sylva render` can show any GLB: the ones Sylva writes, and
//! simple ones from elsewhere.
//!
//! What is read: the default scene's node tree (translation, rotation, scale or matrix,
//! composed down the hierarchy), with `EXT_mesh_gpu_instancing` (a copy of the node's mesh
//! per instance, at the instance's `TRANSLATION`, `ROTATION` and `SCALE` under the node's
//! transform), triangle primitives with `VEC3` positions and optional normals (flat normals
//! are computed when missing), optional `TEXCOORD_0` (`(0, 0)` when missing), `UNSIGNED_BYTE`,
//! `SHORT` or `INT` indices (or none), each material's base colour, and `COLOR_0` (RGB or
//! RGBA). Attributes may be `FLOAT` or any integer type, normalised or not, as
//! `KHR_mesh_quantization` allows. `COLOR_0` splits a primitive into one
//! material per shade (base colour × vertex colour to a byte, each triangle taking its first
//! vertex's colour; at most 1024 shades a primitive, further ones in the base colour), as
//! Sylva's lean materials are written. A base colour texture whose image is one of Sylva's
//! pictures (named as [`sylva_mesh::picture::Picture::name`] gives, `sylva-texture-<id>`
//! for a texture id) gives the material its texture id back, and a material's
//! `extras.sylva_surface` its surface (leaf cards cut out by alpha, petals, bark); other
//! textures, skins, morph targets, sparse accessors and non-triangle modes are ignored. Every node's transform is baked into
//! a world-space copy of its mesh. Every offset and count is checked, so a truncated or
//! hostile file is an error, never a panic; the work is counted before it is done (at most
//! 100 million triangles and a million instances a file, within the memory budget).

use std::collections::{HashMap, HashSet};

use serde_json::Value;
use sylva_core::glam::{Mat3, Mat4, Quat, Vec3};
use sylva_core::species::Surface;
use sylva_core::{Material, MaterialKind};
use sylva_mesh::mesh::{Mesh, Primitive};
use sylva_mesh::picture::Picture;
use sylva_mesh::scene::{Scene, SceneNode};

/// Most shades one primitive's `COLOR_0` is split into; triangles of further shades keep
/// the material's base colour (Sylva's own files have a few dozen).
const MAX_SHADES: usize = 1024;

/// Why a GLB could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// Not a GLB (bad magic or version).
    #[error("not a GLB file (glTF 2.0 binary): {0}")]
    NotGlb(&'static str),
    /// A length or offset points past the data.
    #[error("truncated or inconsistent GLB: {0}")]
    Truncated(String),
    /// The JSON chunk is not valid JSON.
    #[error("the GLB's JSON chunk is invalid: {0}")]
    Json(#[from] serde_json::Error),
    /// A value has the wrong type or is out of range.
    #[error("invalid glTF: {0}")]
    Invalid(String),
    /// More geometry than the limit.
    #[error("the GLB holds more than {limit} triangles")]
    TooLarge {
        /// The limit.
        limit: usize,
    },
    /// Reading it would not fit in the memory budget.
    #[error("the file's meshes do not fit in memory")]
    OverBudget(#[from] sylva_core::budget::OverBudget),
}

/// Meshes read from a GLB, each already placed in world space.
#[derive(Clone, Debug, Default)]
pub struct ImportedScene {
    /// One mesh per node that has one, with its transform baked in.
    pub meshes: Vec<(String, Mesh)>,
}

impl ImportedScene {
    /// A scene borrowing the meshes (each at the origin, as transforms are baked in).
    pub fn scene(&self) -> Scene<'_> {
        Scene {
            nodes: self
                .meshes
                .iter()
                .map(|(name, mesh)| SceneNode::new(name.clone(), mesh))
                .collect(),
        }
    }
}

/// Most triangles read from one file.
const MAX_TRIANGLES: usize = 100_000_000;
/// Most instances (`EXT_mesh_gpu_instancing`) read from one file: each becomes a world-space
/// copy of its mesh, so a small file of tiny meshes must not ask for millions of copies.
const MAX_PLACED: usize = 1_000_000;

fn too_many_placed() -> ImportError {
    invalid(format!(
        "more than {MAX_PLACED} instances of meshes (EXT_mesh_gpu_instancing); each is drawn as a copy"
    ))
}

fn invalid(what: impl Into<String>) -> ImportError {
    ImportError::Invalid(what.into())
}

fn u32_at(bytes: &[u8], at: usize) -> Result<u32, ImportError> {
    bytes
        .get(at..at + 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .ok_or_else(|| ImportError::Truncated(format!("no 4 bytes at offset {at}")))
}

/// Reads a GLB.
pub fn read_glb(bytes: &[u8]) -> Result<ImportedScene, ImportError> {
    let (json, bin) = chunks(bytes)?;
    let root: Value = serde_json::from_slice(json)?;
    Reader { root: &root, bin }.scene()
}

/// The Sylva textures a GLB's materials name (ids, sorted, each once), read from its JSON
/// alone: what a server may serve beside the GLB's OBJ.
pub fn texture_ids(bytes: &[u8]) -> Result<Vec<u16>, ImportError> {
    let (json, bin) = chunks(bytes)?;
    let root: Value = serde_json::from_slice(json)?;
    let reader = Reader { root: &root, bin };
    let mut ids: Vec<u16> = reader
        .list("materials")
        .iter()
        .filter_map(|m| {
            match reader.sylva_picture(&m["pbrMetallicRoughness"]["baseColorTexture"]) {
                Some(Picture::Design(id)) => Some(id),
                _ => None,
            }
        })
        .collect();
    ids.sort_unstable();
    ids.dedup();
    Ok(ids)
}

/// The extras of a GLB's first node (in its default scene's order) whose extras hold a
/// `genome` (what Sylva's plants carry), else of its first node, else `null`; read from the
/// JSON alone.
pub fn first_extras(bytes: &[u8]) -> Result<Value, ImportError> {
    let (json, _) = chunks(bytes)?;
    let root: Value = serde_json::from_slice(json)?;
    let scene = root["scene"].as_u64().unwrap_or(0) as usize;
    let nodes = root["scenes"][scene]["nodes"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    let extras: Vec<&Value> = nodes
        .iter()
        .filter_map(|n| root["nodes"].get(n.as_u64()? as usize))
        .map(|n| &n["extras"])
        .collect();
    Ok(extras
        .iter()
        .find(|e| e.get("genome").is_some())
        .or(extras.first())
        .map_or(Value::Null, |e| (*e).clone()))
}

/// The bytes of the textures a GLB carries: each image's buffer view, or the data its
/// `data:` URI holds (an image in a file beside the GLB counts as nothing), read from its
/// JSON alone.
pub fn texture_bytes(bytes: &[u8]) -> Result<u64, ImportError> {
    let (json, bin) = chunks(bytes)?;
    let root: Value = serde_json::from_slice(json)?;
    let reader = Reader { root: &root, bin };
    let mut total = 0u64;
    for image in reader.list("images") {
        if let Some(view) = image.get("bufferView") {
            let view = reader.item("bufferViews", view)?;
            total = total.saturating_add(view["byteLength"].as_u64().unwrap_or(0));
        } else if let Some(data) = image["uri"]
            .as_str()
            .and_then(|u| u.strip_prefix("data:"))
            .and_then(|u| u.split_once(";base64,"))
        {
            total = total.saturating_add(data.1.len() as u64 / 4 * 3);
        }
    }
    Ok(total)
}

/// A GLB's JSON and binary chunks.
fn chunks(bytes: &[u8]) -> Result<(&[u8], &[u8]), ImportError> {
    if bytes.len() < 12 || u32_at(bytes, 0)? != 0x4654_6C67 {
        return Err(ImportError::NotGlb("it does not start with \"glTF\""));
    }
    if u32_at(bytes, 4)? != 2 {
        return Err(ImportError::NotGlb("only version 2 is read"));
    }
    let total = (u32_at(bytes, 8)? as usize).min(bytes.len());
    let (mut json, mut bin): (Option<&[u8]>, &[u8]) = (None, &[]);
    let mut at = 12;
    while at + 8 <= total {
        let len = u32_at(bytes, at)? as usize;
        let kind = u32_at(bytes, at + 4)?;
        let data = bytes
            .get(at + 8..at + 8 + len)
            .ok_or_else(|| ImportError::Truncated(format!("chunk at {at} runs past the end")))?;
        match kind {
            0x4E4F_534A if json.is_none() => json = Some(data),
            0x004E_4942 if bin.is_empty() => bin = data,
            _ => {}
        }
        at += 8 + len.next_multiple_of(4);
    }
    Ok((json.ok_or(ImportError::NotGlb("no JSON chunk"))?, bin))
}

struct Reader<'a> {
    root: &'a Value,
    bin: &'a [u8],
}

impl Reader<'_> {
    fn list(&self, name: &str) -> &[Value] {
        self.root[name].as_array().map_or(&[], Vec::as_slice)
    }

    fn item(&self, list: &str, index: &Value) -> Result<&Value, ImportError> {
        let i = index
            .as_u64()
            .ok_or_else(|| invalid(format!("{list} index is not a whole number")))?;
        self.list(list)
            .get(i as usize)
            .ok_or_else(|| invalid(format!("{list}[{i}] does not exist")))
    }

    /// The default scene's nodes (every node nobody names as a child, without a scene),
    /// after checking the hierarchy is what glTF allows: each node at most one parent, no
    /// cycles, roots without parents, each listed once. A walk from the roots then visits
    /// every node at most once, whatever the file.
    fn roots(&self) -> Result<Vec<usize>, ImportError> {
        let nodes = self.list("nodes");
        let index = |v: &Value, what: &str| -> Result<usize, ImportError> {
            v.as_u64()
                .filter(|&i| (i as usize) < nodes.len())
                .map(|i| i as usize)
                .ok_or_else(|| invalid(format!("{what} names node {v}, which does not exist")))
        };
        let mut parent: Vec<Option<usize>> = vec![None; nodes.len()];
        for (i, node) in nodes.iter().enumerate() {
            for child in node["children"].as_array().map_or(&[][..], Vec::as_slice) {
                let c = index(child, &format!("node {i}"))?;
                if parent[c].replace(i).is_some() || c == i {
                    return Err(invalid(format!(
                        "node {c} has more than one parent (glTF allows one, and no cycles)"
                    )));
                }
            }
        }
        let roots: Vec<usize> = match self
            .list("scenes")
            .get(self.root["scene"].as_u64().unwrap_or(0) as usize)
        {
            Some(scene) => scene["nodes"]
                .as_array()
                .map_or(&[][..], Vec::as_slice)
                .iter()
                .map(|n| index(n, "the scene"))
                .collect::<Result<_, _>>()?,
            None => (0..nodes.len()).filter(|&i| parent[i].is_none()).collect(),
        };
        let mut listed = vec![false; nodes.len()];
        for &r in &roots {
            if parent[r].is_some() || std::mem::replace(&mut listed[r], true) {
                return Err(invalid(format!(
                    "the scene lists node {r}, which is a child or listed twice"
                )));
            }
        }
        Ok(roots)
    }

    /// Every node the scene shows with its world transform, parents first.
    fn placed_nodes(&self, roots: &[usize]) -> Result<Vec<(usize, Mat4)>, ImportError> {
        let nodes = self.list("nodes");
        let mut placed = Vec::new();
        let mut stack: Vec<(usize, Mat4)> =
            roots.iter().rev().map(|&r| (r, Mat4::IDENTITY)).collect();
        while let Some((i, parent)) = stack.pop() {
            let world = parent * local_transform(&nodes[i])?;
            placed.push((i, world));
            let children = nodes[i]["children"]
                .as_array()
                .map_or(&[][..], Vec::as_slice);
            // Indices were checked by `roots`.
            for child in children.iter().rev() {
                stack.push((child.as_u64().unwrap_or(0) as usize, world));
            }
        }
        Ok(placed)
    }

    fn scene(&self) -> Result<ImportedScene, ImportError> {
        let roots = self.roots()?;
        let placed = self.placed_nodes(&roots)?;
        let nodes = self.list("nodes");
        // Each instance of an instanced node, with its world transform.
        let mut instances: HashMap<usize, Vec<Mat4>> = HashMap::new();
        let mut copies = 0usize;
        for &(i, world) in &placed {
            if nodes[i].get("mesh").is_some()
                && let Some(ext) = nodes[i]["extensions"].get("EXT_mesh_gpu_instancing")
            {
                let local = self.instances(ext)?;
                copies = copies.saturating_add(local.len());
                if copies > MAX_PLACED {
                    return Err(too_many_placed());
                }
                instances.insert(i, local.into_iter().map(|m| world * m).collect());
            }
        }
        // Count the work before doing it: every node (or instance) gets its own world-space
        // copy of its mesh, whose primitives share their vertices when they share an accessor.
        let (mut vertices, mut indices) = (0u64, 0u64);
        let mut sizes: HashMap<u64, (u64, u64)> = HashMap::new();
        for &(i, _) in &placed {
            let copies = instances.get(&i).map_or(1, |m| m.len() as u64);
            if let Some(mesh) = nodes[i].get("mesh") {
                let key = mesh.as_u64().unwrap_or(u64::MAX);
                let (v, n) = match sizes.get(&key) {
                    Some(&size) => size,
                    None => {
                        let size = self.mesh_size(self.item("meshes", mesh)?)?;
                        sizes.insert(key, size);
                        size
                    }
                };
                vertices = vertices.saturating_add(v.saturating_mul(copies));
                indices = indices.saturating_add(n.saturating_mul(copies));
            }
        }
        if indices / 3 > MAX_TRIANGLES as u64 {
            return Err(ImportError::TooLarge {
                limit: MAX_TRIANGLES,
            });
        }
        sylva_core::budget::check(
            sylva_mesh::mesher::mesh_bytes(vertices, indices / 3),
            format_args!(
                "reading a GLB of {vertices} vertices and {} triangles",
                indices / 3
            ),
            "read a smaller file",
        )?;
        let mut out = ImportedScene::default();
        for (i, world) in placed {
            let node = &nodes[i];
            if let Some(mesh) = node.get("mesh") {
                let name = node["name"].as_str().unwrap_or("node");
                let mesh = self.item("meshes", mesh)?;
                match instances.get(&i) {
                    None => out.meshes.push((name.to_owned(), self.mesh(mesh, world)?)),
                    Some(worlds) => {
                        for (k, &world) in worlds.iter().enumerate() {
                            out.meshes
                                .push((format!("{name}-{k}"), self.mesh(mesh, world)?));
                        }
                    }
                }
            }
        }
        Ok(out)
    }

    /// The local transforms of an `EXT_mesh_gpu_instancing` extension's instances.
    fn instances(&self, ext: &Value) -> Result<Vec<Mat4>, ImportError> {
        let attribute = |name: &str, n: usize| -> Result<Option<Vec<f32>>, ImportError> {
            let Some(index) = ext["attributes"].get(name) else {
                return Ok(None);
            };
            let accessor = self.item("accessors", index)?;
            // Refused before reading: each instance becomes a copy of the node's mesh.
            if accessor["count"]
                .as_u64()
                .is_some_and(|c| c > MAX_PLACED as u64)
            {
                return Err(too_many_placed());
            }
            let want = if n == 4 { "VEC4" } else { "VEC3" };
            if accessor["type"] != want {
                return Err(invalid(format!("instance {name} must be {want}")));
            }
            let values = self.floats(accessor, n, name)?;
            if !values.iter().all(|v| v.is_finite()) {
                return Err(invalid(format!("instance {name} is not finite")));
            }
            Ok(Some(values))
        };
        let t = attribute("TRANSLATION", 3)?;
        let r = attribute("ROTATION", 4)?;
        let s = attribute("SCALE", 3)?;
        let counts: Vec<usize> = [(&t, 3), (&r, 4), (&s, 3)]
            .iter()
            .filter_map(|(a, n)| a.as_ref().map(|a| a.len() / n))
            .collect();
        let count = counts.first().copied().unwrap_or(0);
        if counts.iter().any(|&c| c != count) {
            return Err(invalid("instance attributes have different counts"));
        }
        Ok((0..count)
            .map(|i| {
                let t = t
                    .as_ref()
                    .map_or(Vec3::ZERO, |t| Vec3::from_slice(&t[3 * i..]));
                let r = r.as_ref().map_or(Quat::IDENTITY, |r| {
                    Quat::from_slice(&r[4 * i..]).normalize()
                });
                let s = s
                    .as_ref()
                    .map_or(Vec3::ONE, |s| Vec3::from_slice(&s[3 * i..]));
                Mat4::from_scale_rotation_translation(s, r, t)
            })
            .collect())
    }

    /// Vertices (one copy per distinct vertex-attribute accessors) and indices a mesh holds
    /// once read.
    fn mesh_size(&self, mesh: &Value) -> Result<(u64, u64), ImportError> {
        let mut seen = HashSet::new();
        let (mut vertices, mut indices) = (0u64, 0u64);
        for prim in triangle_primitives(mesh) {
            let a = &prim["attributes"];
            let count = |v: &Value| -> Result<u64, ImportError> {
                self.item("accessors", v)?["count"]
                    .as_u64()
                    .ok_or_else(|| invalid("accessor without count"))
            };
            let positions = count(&a["POSITION"])?;
            if seen.insert(vertex_key(prim)) {
                vertices = vertices.saturating_add(positions);
            }
            let n = match prim.get("indices") {
                Some(i) => count(i)?,
                None => positions,
            };
            indices = indices.saturating_add(n);
        }
        Ok((vertices, indices))
    }

    fn mesh(&self, mesh: &Value, world: Mat4) -> Result<Mesh, ImportError> {
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        let mut out = Mesh::default();
        // Vertices already copied, by the accessors they came from.
        let mut shared: HashMap<VertexKey, u32> = HashMap::new();
        for prim in triangle_primitives(mesh) {
            let positions = self.vec3s(self.item("accessors", &prim["attributes"]["POSITION"])?)?;
            let indices: Vec<u32> = match prim.get("indices") {
                Some(i) => self.indices(self.item("accessors", i)?)?,
                None => (0..positions.len() as u32).collect(),
            };
            let usable = indices.len() / 3 * 3;
            if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(invalid(format!(
                    "index {bad} is past the {} vertices of its primitive",
                    positions.len()
                )));
            }
            let base = match shared.get(&vertex_key(prim)) {
                Some(&base) => base,
                None => {
                    let base = u32::try_from(out.positions.len())
                        .map_err(|_| invalid("too many vertices"))?;
                    self.vertices(
                        prim,
                        &positions,
                        &indices[..usable],
                        world,
                        normal_matrix,
                        &mut out,
                    )?;
                    shared.insert(vertex_key(prim), base);
                    base
                }
            };
            let material = self.material(prim.get("material"))?;
            if material.surface == Some(Surface::Impostor) && out.impostor.is_none() {
                out.impostor = self.impostor_picture(prim.get("material"))?;
            }
            let Some(colors) = prim["attributes"].get("COLOR_0") else {
                out.primitives.push(Primitive {
                    material: out.materials.len(),
                    indices: indices[..usable].iter().map(|i| i + base).collect(),
                });
                out.materials.push(material);
                continue;
            };
            // Vertex colours (lean materials): one material per shade, each triangle taking
            // the colour of its first vertex.
            let colors = self.colors(self.item("accessors", colors)?)?;
            if colors.len() != positions.len() {
                return Err(invalid("COLOR_0 and POSITION counts differ"));
            }
            // Shades by their colour to a byte (a file may give every triangle its own):
            // at most MAX_SHADES per primitive, the rest drawn in the base colour.
            let mut shades: HashMap<[u8; 3], usize> = HashMap::new();
            let mut unshaded = None;
            for t in indices[..usable].chunks_exact(3) {
                let shade = colors[t[0] as usize];
                let color: [f32; 3] = std::array::from_fn(|c| material.color[c] * shade[c]);
                let key = color.map(|c| (c * 255.0).round() as u8);
                let known = shades.get(&key).copied();
                let slot = match known {
                    Some(s) => s,
                    None if shades.len() >= MAX_SHADES => *unshaded.get_or_insert_with(|| {
                        out.materials.push(material.clone());
                        out.primitives.push(Primitive {
                            material: out.materials.len() - 1,
                            indices: Vec::new(),
                        });
                        out.materials.len() - 1
                    }),
                    None => {
                        let [r, g, b] = key;
                        out.materials.push(Material {
                            name: format!("{}-{r:02x}{g:02x}{b:02x}", material.name),
                            color,
                            ..material.clone()
                        });
                        out.primitives.push(Primitive {
                            material: out.materials.len() - 1,
                            indices: Vec::new(),
                        });
                        shades.insert(key, out.materials.len() - 1);
                        out.materials.len() - 1
                    }
                };
                out.primitives[slot]
                    .indices
                    .extend(t.iter().map(|i| i + base));
            }
        }
        Ok(out)
    }

    /// Appends a primitive's vertices, placed in world space.
    fn vertices(
        &self,
        prim: &Value,
        positions: &[Vec3],
        indices: &[u32],
        world: Mat4,
        normal_matrix: Mat3,
        out: &mut Mesh,
    ) -> Result<(), ImportError> {
        let normals = match prim["attributes"].get("NORMAL") {
            Some(n) => self.vec3s(self.item("accessors", n)?)?,
            None => flat_normals(positions, indices),
        };
        if normals.len() != positions.len() {
            return Err(invalid("NORMAL and POSITION counts differ"));
        }
        match prim["attributes"].get("TEXCOORD_0") {
            Some(t) => {
                let uvs = self.vec2s(self.item("accessors", t)?)?;
                if uvs.len() != positions.len() {
                    return Err(invalid("TEXCOORD_0 and POSITION counts differ"));
                }
                out.uvs.extend(uvs);
            }
            None => out.uvs.resize(out.uvs.len() + positions.len(), [0.0; 2]),
        }
        for (p, n) in positions.iter().zip(&normals) {
            out.positions.push(world.transform_point3(*p).to_array());
            out.normals
                .push((normal_matrix * *n).normalize_or(Vec3::Y).to_array());
        }
        Ok(())
    }

    fn material(&self, index: Option<&Value>) -> Result<Material, ImportError> {
        let Some(index) = index else {
            return Ok(Material::of_kind(MaterialKind::Bark));
        };
        let m = self.item("materials", index)?;
        let name = m["name"].as_str().unwrap_or("material").to_owned();
        let kind = [MaterialKind::Leaf, MaterialKind::Flower, MaterialKind::Root]
            .into_iter()
            .find(|k| name.contains(k.name()))
            .unwrap_or(MaterialKind::Bark);
        let factor = &m["pbrMetallicRoughness"]["baseColorFactor"];
        let channel = |i: usize| factor[i].as_f64().map_or(0.8, |v| v.clamp(0.0, 1.0) as f32);
        // A surface Sylva wrote is read back from the extras; a picture from its name.
        let surface =
            serde_json::from_value::<Surface>(m["extras"][crate::export::SURFACE_EXTRA].clone())
                .ok();
        let picture = self.sylva_picture(&m["pbrMetallicRoughness"]["baseColorTexture"]);
        let texture = match picture {
            Some(Picture::Design(id)) | Some(Picture::Petal(Some(id))) => Some(id),
            _ => None,
        };
        Ok(Material {
            name,
            kind,
            color: [channel(0), channel(1), channel(2)],
            texture,
            surface,
        })
    }

    /// The PNG an impostor's material shows (its base colour texture's image), if it has one.
    fn impostor_picture(
        &self,
        index: Option<&Value>,
    ) -> Result<Option<std::sync::Arc<Vec<u8>>>, ImportError> {
        let Some(index) = index else {
            return Ok(None);
        };
        let info = &self.item("materials", index)?["pbrMetallicRoughness"]["baseColorTexture"];
        if info["index"].is_null() {
            return Ok(None);
        }
        let texture = self.item("textures", &info["index"])?;
        let image = self.item("images", &texture["source"])?;
        let view = self.item("bufferViews", &image["bufferView"])?;
        let field = |key: &str| view[key].as_u64().and_then(|v| usize::try_from(v).ok());
        let (start, length) = (field("byteOffset").unwrap_or(0), field("byteLength"));
        let bytes = length
            .and_then(|l| start.checked_add(l))
            .and_then(|end| self.bin.get(start..end))
            .ok_or_else(|| {
                ImportError::Truncated("an impostor's image runs past the binary chunk".into())
            })?;
        Ok(Some(std::sync::Arc::new(bytes.to_vec())))
    }

    /// The Sylva picture behind a texture reference, if its image is one of Sylva's.
    fn sylva_picture(&self, info: &Value) -> Option<Picture> {
        let texture = self
            .list("textures")
            .get(info["index"].as_u64()? as usize)?;
        let image = self
            .list("images")
            .get(texture["source"].as_u64()? as usize)?;
        Picture::from_name(image["name"].as_str()?)
    }

    /// The bytes of an accessor's elements: (data from the first element, stride, count).
    fn view(&self, accessor: &Value, element: usize) -> Result<(&[u8], usize, usize), ImportError> {
        let count = accessor["count"]
            .as_u64()
            .ok_or_else(|| invalid("accessor without count"))? as usize;
        let view = self.item("bufferViews", &accessor["bufferView"])?;
        if view["buffer"].as_u64() != Some(0) {
            return Err(invalid("only the GLB's own buffer 0 is read"));
        }
        let stride = view["byteStride"].as_u64().map_or(element, |s| s as usize);
        // Offsets come from the file: add them checked, so that huge ones are refused.
        let field = |item: &Value, key: &str| item[key].as_u64().unwrap_or(0);
        let overflow = || ImportError::Truncated("buffer view or accessor offset overflows".into());
        let view_start = field(view, "byteOffset");
        let start = view_start
            .checked_add(field(accessor, "byteOffset"))
            .and_then(|s| usize::try_from(s).ok())
            .ok_or_else(overflow)?;
        let view_end = view_start
            .checked_add(field(view, "byteLength"))
            .and_then(|e| usize::try_from(e).ok())
            .ok_or_else(overflow)?;
        let needed = if count == 0 {
            0
        } else {
            stride
                .checked_mul(count - 1)
                .and_then(|n| n.checked_add(element))
                .ok_or_else(|| ImportError::Truncated("accessor size overflows".into()))?
        };
        let end = start
            .checked_add(needed)
            .ok_or_else(|| ImportError::Truncated("accessor offset overflows".into()))?;
        if stride < element || end > view_end || end > self.bin.len() {
            return Err(ImportError::Truncated(format!(
                "accessor of {count} elements runs past its buffer view"
            )));
        }
        Ok((&self.bin[start..end], stride, count))
    }

    fn vec3s(&self, accessor: &Value) -> Result<Vec<Vec3>, ImportError> {
        if accessor["type"] != "VEC3" {
            return Err(invalid("positions and normals must be VEC3"));
        }
        let flat = self.floats(accessor, 3, "POSITION or NORMAL")?;
        Ok(flat.chunks_exact(3).map(Vec3::from_slice).collect())
    }

    fn vec2s(&self, accessor: &Value) -> Result<Vec<[f32; 2]>, ImportError> {
        if accessor["type"] != "VEC2" {
            return Err(invalid("TEXCOORD_0 must be VEC2"));
        }
        let flat = self.floats(accessor, 2, "TEXCOORD_0")?;
        Ok(flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }

    /// `COLOR_0` as RGB (alpha is dropped: Sylva's materials are opaque).
    fn colors(&self, accessor: &Value) -> Result<Vec<[f32; 3]>, ImportError> {
        let n = match accessor["type"].as_str() {
            Some("VEC3") => 3,
            Some("VEC4") => 4,
            _ => return Err(invalid("COLOR_0 must be VEC3 or VEC4")),
        };
        let flat = self.floats(accessor, n, "COLOR_0")?;
        Ok(flat
            .chunks_exact(n)
            .map(|c| [c[0], c[1], c[2]].map(|x| x.clamp(0.0, 1.0)))
            .collect())
    }

    /// An accessor of `n` components per element as floats: `FLOAT`, or any integer type,
    /// normalised (signed ones as `max(c / max, -1)`, as glTF says) or as it is.
    fn floats(&self, accessor: &Value, n: usize, what: &str) -> Result<Vec<f32>, ImportError> {
        let normalized = accessor["normalized"].as_bool().unwrap_or(false);
        let Some(kind @ (5120..=5123 | 5126)) = accessor["componentType"].as_u64() else {
            return Err(invalid(format!(
                "{what} must be FLOAT, BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT"
            )));
        };
        let size = match kind {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let (data, stride, count) = self.view(accessor, n * size)?;
        let decode = |b: &[u8]| -> f32 {
            let (value, max) = match kind {
                5120 => (f32::from(b[0] as i8), 127.0),
                5121 => (f32::from(b[0]), 255.0),
                5122 => (f32::from(i16::from_le_bytes([b[0], b[1]])), 32_767.0),
                5123 => (f32::from(u16::from_le_bytes([b[0], b[1]])), 65_535.0),
                _ => return f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            };
            if normalized {
                (value / max).max(-1.0)
            } else {
                value
            }
        };
        Ok((0..count)
            .flat_map(|i| {
                (0..n)
                    .map(move |k| decode(&data[i * stride + size * k..i * stride + size * (k + 1)]))
            })
            .collect())
    }

    fn indices(&self, accessor: &Value) -> Result<Vec<u32>, ImportError> {
        let size = match accessor["componentType"].as_u64() {
            Some(5121) => 1,
            Some(5123) => 2,
            Some(5125) => 4,
            _ => return Err(invalid("indices must be UNSIGNED_BYTE, SHORT or INT")),
        };
        let (data, stride, count) = self.view(accessor, size)?;
        Ok((0..count)
            .map(|i| {
                let b = &data[i * stride..i * stride + size];
                match size {
                    1 => u32::from(b[0]),
                    2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                }
            })
            .collect())
    }
}

fn local_transform(node: &Value) -> Result<Mat4, ImportError> {
    let floats = |name: &str, n: usize| -> Result<Option<Vec<f32>>, ImportError> {
        match node.get(name) {
            None => Ok(None),
            Some(v) => {
                let list: Option<Vec<f32>> = v.as_array().filter(|a| a.len() == n).map(|a| {
                    a.iter()
                        .filter_map(|x| x.as_f64().map(|x| x as f32))
                        .collect()
                });
                match list {
                    Some(l) if l.len() == n && l.iter().all(|x| x.is_finite()) => Ok(Some(l)),
                    _ => Err(invalid(format!("node {name} must be {n} finite numbers"))),
                }
            }
        }
    };
    if let Some(m) = floats("matrix", 16)? {
        return Ok(Mat4::from_cols_slice(&m));
    }
    let t = floats("translation", 3)?.map_or(Vec3::ZERO, |v| Vec3::new(v[0], v[1], v[2]));
    let r = floats("rotation", 4)?.map_or(Quat::IDENTITY, |v| {
        Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize()
    });
    let s = floats("scale", 3)?.map_or(Vec3::ONE, |v| Vec3::new(v[0], v[1], v[2]));
    Ok(Mat4::from_scale_rotation_translation(s, r, t))
}

/// The accessors a primitive's vertices come from: primitives with the same share them.
type VertexKey = (Option<u64>, Option<u64>, Option<u64>);

fn vertex_key(prim: &Value) -> VertexKey {
    let a = &prim["attributes"];
    (
        a["POSITION"].as_u64(),
        a.get("NORMAL").and_then(Value::as_u64),
        a.get("TEXCOORD_0").and_then(Value::as_u64),
    )
}

/// A mesh's triangle primitives (other modes are left out).
fn triangle_primitives(mesh: &Value) -> impl Iterator<Item = &Value> {
    mesh["primitives"]
        .as_array()
        .map_or(&[][..], Vec::as_slice)
        .iter()
        .filter(|p| p["mode"].as_u64().unwrap_or(4) == 4)
}

fn flat_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    normals
        .into_iter()
        .map(|n| n.normalize_or(Vec3::Y))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::to_glb;

    fn triangle_mesh() -> Mesh {
        Mesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            uvs: vec![[0.0, 0.0], [1.0, 0.25], [0.5, 3.5]],
            primitives: vec![Primitive {
                material: 0,
                indices: vec![0, 1, 2],
            }],
            materials: vec![Material::of_kind(MaterialKind::Leaf)],
            impostor: None,
        }
    }

    /// The fuzzer's finds: offsets near `u64::MAX` once overflowed an addition (a panic in
    /// builds with overflow checks, as this test's); now they are refused as truncated.
    #[test]
    fn huge_offsets_found_by_the_fuzzer_are_refused() {
        let folder = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/regressions/glb");
        for name in ["view-end-add-overflow", "accessor-start-add-overflow"] {
            let bytes = std::fs::read(format!("{folder}/{name}")).unwrap();
            let error = read_glb(&bytes).unwrap_err();
            assert!(
                matches!(error, ImportError::Truncated(_)),
                "{name}: {error}"
            );
        }
    }

    #[test]
    fn texture_ids_are_those_the_materials_name() {
        let mut mesh = triangle_mesh();
        mesh.materials[0].texture = Some(7);
        let glb = to_glb(&Scene::single(SceneNode::new("a", &mesh))).unwrap();
        assert_eq!(texture_ids(&glb).unwrap(), [7]);
        let plain = to_glb(&Scene::single(SceneNode::new("a", &triangle_mesh()))).unwrap();
        assert!(texture_ids(&plain).unwrap().is_empty());
        assert!(texture_ids(b"not a glb at all").is_err());
    }

    #[test]
    fn reads_back_what_it_writes_with_transforms_baked() {
        let mesh = triangle_mesh();
        let mut a = SceneNode::new("a", &mesh);
        a.translation = Vec3::new(5.0, 0.0, 0.0);
        let mut b = SceneNode::new("b", &mesh);
        b.rotation = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let glb = to_glb(&Scene { nodes: vec![a, b] }).unwrap();
        let back = read_glb(&glb).unwrap();
        assert_eq!(back.meshes.len(), 2);
        assert_eq!(back.meshes[0].1.positions[1], [6.0, 0.0, 0.0]);
        let p = Vec3::from_array(back.meshes[1].1.positions[1]);
        assert!((p - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        assert_eq!(back.meshes[0].1.materials[0].kind, MaterialKind::Leaf);
        assert_eq!(back.meshes[0].1.triangle_count(), 1);
        // Untextured materials need no texture coordinates, so none are written.
        assert_eq!(back.meshes[0].1.uvs, [[0.0; 2]; 3]);
        assert_eq!(back.meshes[0].1.materials[0].texture, None);
    }

    #[test]
    fn lean_materials_come_back_as_one_material_per_shade() {
        // Two shades of leaf on separate triangles: written as one leaf material with
        // COLOR_0, read back as two materials whose colours are the shades, to a byte.
        let mut mesh = triangle_mesh();
        mesh.positions.extend_from_within(..);
        mesh.normals.extend_from_within(..);
        mesh.uvs.extend_from_within(..);
        let mut dark = mesh.materials[0].clone();
        dark.color = [0.05, 0.2, 0.02];
        mesh.materials.push(dark);
        mesh.primitives.push(Primitive {
            material: 1,
            indices: vec![3, 4, 5],
        });
        let glb = to_glb(&Scene::single(SceneNode::new("p", &mesh))).unwrap();
        let back = read_glb(&glb).unwrap();
        let m = &back.meshes[0].1;
        assert_eq!(m.materials.len(), 2);
        assert_eq!(m.triangle_count(), 2);
        for (got, want) in m.materials.iter().zip(&mesh.materials) {
            assert_eq!(got.kind, MaterialKind::Leaf);
            for c in 0..3 {
                assert!(
                    (got.color[c] - want.color[c]).abs() < 1.0 / 255.0,
                    "{got:?}"
                );
            }
        }
    }

    #[test]
    fn a_shade_for_every_triangle_is_bounded() {
        // 2000 triangles, each its own colour: at most MAX_SHADES materials, plus one for
        // the rest in the base colour, and every triangle still drawn.
        let mut mesh = Mesh::default();
        for k in 0..2000u32 {
            mesh.positions.extend_from_slice(&[
                [k as f32, 0.0, 0.0],
                [k as f32, 1.0, 0.0],
                [k as f32, 0.0, 1.0],
            ]);
            mesh.normals.extend_from_slice(&[[1.0, 0.0, 0.0]; 3]);
            let mut m = Material::of_kind(MaterialKind::Leaf);
            m.color = [k as f32 / 2000.0, 0.5, (k % 7) as f32 / 7.0];
            mesh.materials.push(m);
            mesh.primitives.push(Primitive {
                material: k as usize,
                indices: vec![3 * k, 3 * k + 1, 3 * k + 2],
            });
        }
        let glb = to_glb(&Scene::single(SceneNode::new("p", &mesh))).unwrap();
        let back = read_glb(&glb).unwrap();
        let m = &back.meshes[0].1;
        assert_eq!(m.triangle_count(), 2000);
        assert!(m.materials.len() <= MAX_SHADES + 1, "{}", m.materials.len());
        assert_eq!(m.materials.len(), m.primitives.len());
    }

    #[test]
    fn uvs_and_texture_ids_round_trip() {
        let mut mesh = crate::export::tests::small_mesh();
        mesh.materials[0].texture = Some(2);
        mesh.materials[2].texture = Some(14);
        let glb = to_glb(&Scene::single(SceneNode::new("p", &mesh))).unwrap();
        let back = read_glb(&glb).unwrap();
        let m = &back.meshes[0].1;
        // Primitives come back one vertex block each, in order: vertices of a primitive are
        // copied, so compare through the indices. Only textured ones carry coordinates.
        for (p, q) in mesh.primitives.iter().zip(&m.primitives) {
            let textured = mesh.materials[p.material].texture.is_some();
            for (&i, &j) in p.indices.iter().zip(&q.indices) {
                let expected = if textured {
                    mesh.uvs[i as usize]
                } else {
                    [0.0; 2]
                };
                assert_eq!(m.uvs[j as usize], expected);
            }
        }
        // A textured mesh without texture coordinates reads back as zeros.
        let textures: Vec<Option<u16>> = m.materials.iter().map(|m| m.texture).collect();
        assert_eq!(textures, [Some(2), None, Some(14)]);
        let mut bare = triangle_mesh();
        bare.uvs.clear();
        bare.materials[0].texture = Some(4);
        let glb = to_glb(&Scene::single(SceneNode::new("b", &bare))).unwrap();
        assert_eq!(read_glb(&glb).unwrap().meshes[0].1.uvs, [[0.0; 2]; 3]);
    }

    #[test]
    fn surfaces_are_written_as_cut_outs_and_bark_and_read_back() {
        use sylva_core::species::{BarkKind, LeafKind, Surface};
        let mut mesh = crate::export::tests::small_mesh();
        let surfaces = [
            Surface::Bark(BarkKind::Plated),
            Surface::Branchlets(LeafKind::Maple),
            Surface::Petals,
        ];
        for (m, s) in mesh.materials.iter_mut().zip(surfaces) {
            m.surface = Some(s);
        }
        mesh.materials[2].texture = Some(7);
        let glb = to_glb(&Scene::single(SceneNode::new("p", &mesh))).unwrap();
        let (json, _) = crate::export::glb::tests::chunks(&glb);
        let materials = json["materials"].as_array().unwrap();
        // Bark: its tiling picture and a normal map, opaque and one-sided.
        assert!(materials[0]["normalTexture"]["index"].is_u64());
        assert!(materials[0].get("alphaMode").is_none());
        assert!(materials[0].get("doubleSided").is_none());
        for cut in &materials[1..] {
            assert_eq!(cut["alphaMode"], "MASK");
            assert_eq!(cut["alphaCutoff"], 0.5);
            assert_eq!(cut["doubleSided"], true);
        }
        let images: Vec<&str> = json["images"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| i["name"].as_str().unwrap())
            .collect();
        assert_eq!(
            images,
            [
                "sylva-bark-plated",
                "sylva-bark-plated-normal",
                "sylva-leaves-maple",
                "sylva-petal-7"
            ]
        );
        let back = read_glb(&glb).unwrap();
        let read: Vec<_> = back.meshes[0]
            .1
            .materials
            .iter()
            .map(|m| m.surface)
            .collect();
        assert_eq!(read, surfaces.map(Some));
        assert_eq!(back.meshes[0].1.materials[2].texture, Some(7));
    }

    /// Two impostors' pictures are embedded once each, marked unlit, and read back into
    /// their meshes; an impostor's material on a mesh without a picture is an error.
    #[test]
    fn impostor_pictures_are_written_unlit_and_read_back() {
        use sylva_core::species::{LeafKind, Surface};
        let picture = |kind| Picture::Leaves(kind).png().unwrap();
        let card = |png: Option<std::sync::Arc<Vec<u8>>>| {
            let mut mesh = triangle_mesh();
            mesh.materials[0].surface = Some(Surface::Impostor);
            mesh.impostor = png;
            mesh
        };
        let (oak, pine) = (
            card(Some(picture(LeafKind::Oak))),
            card(Some(picture(LeafKind::Pine))),
        );
        let scene = Scene {
            nodes: vec![
                SceneNode::new("oak", &oak),
                SceneNode::new("pine", &pine),
                SceneNode::new("oak-again", &oak),
            ],
        };
        let glb = to_glb(&scene).unwrap();
        let (json, _) = crate::export::glb::tests::chunks(&glb);
        assert_eq!(
            json["extensionsUsed"],
            serde_json::json!(["KHR_materials_unlit"])
        );
        assert_eq!(json["images"].as_array().unwrap().len(), 2);
        assert_eq!(json["materials"].as_array().unwrap().len(), 2);
        let m = &json["materials"][0];
        assert_eq!(
            m["extensions"]["KHR_materials_unlit"],
            serde_json::json!({})
        );
        assert_eq!(m["alphaMode"], "MASK");
        let back = read_glb(&glb).unwrap();
        let pictures: Vec<_> = back
            .meshes
            .iter()
            .map(|(_, m)| m.impostor.clone())
            .collect();
        assert_eq!(pictures, [&oak, &pine, &oak].map(|m| m.impostor.clone()));
        assert_eq!(
            back.meshes[1].1.materials[0].surface,
            Some(Surface::Impostor)
        );

        let bare = card(None);
        let error = to_glb(&Scene::single(SceneNode::new("bare", &bare))).unwrap_err();
        assert!(error.to_string().contains("impostor"), "{error}");
    }

    #[test]
    fn truncated_and_garbage_files_are_errors() {
        let mesh = triangle_mesh();
        let glb = to_glb(&Scene::single(SceneNode::new("a", &mesh))).unwrap();
        for cut in [0, 11, 12, 20, glb.len() / 2, glb.len() - 4] {
            assert!(read_glb(&glb[..cut]).is_err(), "cut at {cut}");
        }
        assert!(read_glb(b"not a glb at all").is_err());
        let mut flipped = glb.clone();
        for (i, b) in flipped.iter_mut().enumerate().skip(20) {
            if i % 7 == 0 {
                *b ^= 0x5a;
            }
        }
        let _ = read_glb(&flipped); // must not panic
    }

    /// A GLB of `json` and a binary chunk.
    fn glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
        let mut j = serde_json::to_vec(json).unwrap();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let mut b = bin.to_vec();
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        let total = 12 + 8 + j.len() + 8 + b.len();
        let mut out = Vec::new();
        for v in [0x4654_6C67u32, 2, total as u32, j.len() as u32, 0x4E4F_534A] {
            out.extend(v.to_le_bytes());
        }
        out.extend(&j);
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(0x004E_4942u32.to_le_bytes());
        out.extend(&b);
        out
    }

    /// One triangle's positions and a mesh whose `primitives` primitives all use them.
    fn shared_mesh(primitives: usize, nodes: serde_json::Value) -> Vec<u8> {
        let bin: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
            .iter()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        let prim = serde_json::json!({ "attributes": { "POSITION": 0 } });
        let json = serde_json::json!({
            "asset": { "version": "2.0" },
            "buffers": [{ "byteLength": bin.len() }],
            "bufferViews": [{ "buffer": 0, "byteLength": bin.len() }],
            "accessors": [{ "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3" }],
            "meshes": [{ "primitives": vec![prim; primitives] }],
            "nodes": nodes,
        });
        glb(&json, &bin)
    }

    #[test]
    fn what_gltf_forbids_is_refused_before_any_work() {
        // Nodes that share children (a DAG): sixty levels would be 2^60 paths.
        let dag: Vec<serde_json::Value> = (0..60)
            .map(|i| serde_json::json!({ "mesh": 0, "children": [i + 1] }))
            .chain((0..60).map(|i| serde_json::json!({ "children": [i + 1] })))
            .chain([serde_json::json!({ "mesh": 0 })])
            .collect();
        let e = read_glb(&shared_mesh(1, serde_json::json!(dag))).unwrap_err();
        assert!(e.to_string().contains("more than one parent"), "{e}");
        // A cycle, and a node that is its own child.
        let cycle = serde_json::json!([{ "children": [1] }, { "children": [0], "mesh": 0 }]);
        let e = read_glb(&shared_mesh(1, cycle)).unwrap();
        assert!(e.meshes.is_empty(), "a cycle has no root: nothing to show");
        let selfish = serde_json::json!([{ "children": [0], "mesh": 0 }]);
        assert!(read_glb(&shared_mesh(1, selfish)).is_err());
        // A hierarchy deeper than any recursion could follow is read, once per node.
        let deep: Vec<serde_json::Value> = (0..10_000)
            .map(|i| serde_json::json!({ "children": [i + 1] }))
            .chain([serde_json::json!({ "mesh": 0 })])
            .collect();
        assert_eq!(
            read_glb(&shared_mesh(1, serde_json::json!(deep)))
                .unwrap()
                .meshes
                .len(),
            1
        );
    }

    #[test]
    fn instanced_nodes_give_a_mesh_per_instance_and_bad_instances_are_refused() {
        let instanced = |attributes: serde_json::Value| {
            let node = serde_json::json!({
                "name": "i", "mesh": 0, "translation": [0.0, 0.0, 5.0],
                "extensions": { "EXT_mesh_gpu_instancing": { "attributes": attributes } },
            });
            read_glb(&shared_mesh(1, serde_json::json!([node])))
        };
        // The triangle's own corners as three instances' translations.
        let scene = instanced(serde_json::json!({ "TRANSLATION": 0 })).unwrap();
        let names: Vec<&str> = scene.meshes.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["i-0", "i-1", "i-2"]);
        assert_eq!(scene.meshes[1].1.positions[2], [1.0, 1.0, 5.0]);
        for (attributes, why) in [
            (serde_json::json!({ "ROTATION": 0 }), "must be VEC4"),
            (serde_json::json!({ "TRANSLATION": 9 }), "does not exist"),
            (
                serde_json::json!({ "TRANSLATION": "x" }),
                "not a whole number",
            ),
        ] {
            let e = instanced(attributes).unwrap_err();
            assert!(e.to_string().contains(why), "{e}");
        }
        // A tiny file asking for millions of copies is refused before any is read or made:
        // two nodes of 600,000 instances each (the second's count alone is under the cap).
        let bin: Vec<u8> = vec![0; 36];
        let node = |name: &str| {
            serde_json::json!({ "name": name, "mesh": 0, "extensions": {
                "EXT_mesh_gpu_instancing": { "attributes": { "TRANSLATION": 1 } } } })
        };
        let mut json = serde_json::json!({
            "asset": { "version": "2.0" },
            "buffers": [{ "byteLength": 36 }],
            "bufferViews": [{ "buffer": 0, "byteLength": 36 }],
            "accessors": [
                { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3" },
                { "bufferView": 0, "componentType": 5126, "count": 2_000_000, "type": "VEC3" },
            ],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 } }] }],
            "nodes": [node("a")],
        });
        let e = read_glb(&glb(&json, &bin)).unwrap_err();
        assert!(e.to_string().contains("instances"), "{e}");
        let bin: Vec<u8> = vec![0; 36 + 12 * 600_000];
        json["buffers"][0]["byteLength"] = serde_json::json!(bin.len());
        json["bufferViews"] = serde_json::json!([
            { "buffer": 0, "byteLength": 36 },
            { "buffer": 0, "byteOffset": 36, "byteLength": 12 * 600_000 },
        ]);
        json["accessors"][1] = serde_json::json!(
            { "bufferView": 1, "componentType": 5126, "count": 600_000, "type": "VEC3" });
        json["nodes"] = serde_json::json!([node("a"), node("b")]);
        let e = read_glb(&glb(&json, &bin)).unwrap_err();
        assert!(e.to_string().contains("instances"), "{e}");
    }

    #[test]
    fn primitives_that_share_an_accessor_share_their_vertices() {
        let file = shared_mesh(5000, serde_json::json!([{ "mesh": 0 }]));
        let scene = read_glb(&file).unwrap();
        let mesh = &scene.meshes[0].1;
        assert_eq!(mesh.positions.len(), 3, "one copy of the shared vertices");
        assert_eq!(mesh.triangle_count(), 5000);
    }
}
