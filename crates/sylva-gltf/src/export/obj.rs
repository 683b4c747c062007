//! Wavefront OBJ and MTL writer.
//!
//! OBJ has no instancing and no transforms, so every node's vertices are written already in
//! world space, under an `o` and a `g` named after the node; indices are 1-based and offset
//! by the vertices of the nodes before. Texture coordinates (`vt`) and normals (`vn`) come in
//! the same order as vertices, so faces are `f a/a/a b/b/b c/c/c`. OBJ's `v` points up the
//! picture where the mesh's (glTF's) points down, so `vt` holds `u` and `1 - v`. Each
//! primitive starts with `usemtl`.
//!
//! Materials are written once per distinct (name, colour, texture). When two nodes use one
//! name with different colours or textures, the later one is renamed `n<node>_<name>` (with
//! a number appended if that is taken too). Names are made single words (spaces become `_`).
//! A textured material gets `map_Kd <stem>_tex<id>.png`, `stem` being the MTL file's (see
//! [`super::texture_files`]); MTL multiplies the map by `Kd`, like glTF. Leaf and petal
//! textures, which do not repeat along `v`, are clamped (`-clamp on`). A material with a
//! surface ([`sylva_core::species::Surface`]) names its picture the same way
//! ([`Picture::file_name`]); cut-out leaves and petals add `map_d` with their mask (the
//! outline as grey and as alpha, so readers of either channel cut it), and bark adds its
//! normal map as `norm` and `map_Bump`.

use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;
use std::path::Path;

use sylva_core::glam::Vec3;
use sylva_mesh::picture::Picture;
use sylva_mesh::scene::Scene;

use super::{MaterialKey, material_key, push_float, push_vec3, token, valid_triangles};

/// Encodes `scene` as OBJ text and the text of its MTL file, which the OBJ names as
/// `mtl_file_name` in its `mtllib` line. Never fails: indices out of range are dropped and
/// non-finite numbers written as 0 (use [`super::check_scene`] to refuse such scenes).
pub fn to_obj(scene: &Scene, mtl_file_name: &str) -> (String, String) {
    let vertices: usize = scene.nodes.iter().map(|n| n.mesh.positions.len()).sum();
    let mut obj = String::with_capacity(64 * vertices + 256);
    let mut mtl = String::new();
    let _ = writeln!(obj, "# Sylva {}", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(mtl, "# Sylva {}", env!("CARGO_PKG_VERSION"));
    // MTL file names may not hold spaces in most readers.
    let _ = writeln!(
        obj,
        "mtllib {}",
        mtl_file_name.replace(char::is_whitespace, "_")
    );

    let texture_stem = token(
        &Path::new(mtl_file_name)
            .file_stem()
            .map_or_else(|| "scene".into(), |s| s.to_string_lossy()),
    );
    // Names written, and (name, colour bits, texture, surface) -> name written.
    let mut taken: HashSet<String> = HashSet::new();
    let mut written: HashMap<MaterialKey, String> = HashMap::new();
    let mut offset = 1usize;
    for (index, node) in scene.nodes.iter().enumerate() {
        let mesh = node.mesh;
        let name = token(&node.name);
        let _ = writeln!(obj, "o {name}\ng {name}");
        for p in &mesh.positions {
            obj.push_str("v ");
            let world = node.transform_point(Vec3::from_array(*p));
            push_vec3(&mut obj, world.to_array());
            obj.push('\n');
        }
        for i in 0..mesh.positions.len() {
            let [u, v] = mesh.uvs.get(i).copied().unwrap_or([0.0, 0.0]);
            obj.push_str("vt ");
            push_float(&mut obj, u);
            obj.push(' ');
            push_float(&mut obj, 1.0 - v);
            obj.push('\n');
        }
        let rotation = node.rotation.normalize();
        for i in 0..mesh.positions.len() {
            let n = mesh.normals.get(i).copied().unwrap_or([0.0, 1.0, 0.0]);
            let n = (rotation * Vec3::from_array(n)).normalize_or(Vec3::Y);
            obj.push_str("vn ");
            push_vec3(&mut obj, n.to_array());
            obj.push('\n');
        }
        for p in &mesh.primitives {
            let Some(material) = mesh.materials.get(p.material) else {
                continue;
            };
            let key = material_key(material);
            let mtl_name = match written.get(&key) {
                Some(n) => n.clone(),
                None => {
                    let base = token(&material.name);
                    let mut n = base.clone();
                    let mut k = 1;
                    while taken.contains(&n) {
                        n = if k == 1 {
                            format!("n{index}_{base}")
                        } else {
                            format!("n{index}_{base}_{k}")
                        };
                        k += 1;
                    }
                    taken.insert(n.clone());
                    written.insert(key, n.clone());
                    write_material(&mut mtl, &n, material.color);
                    // An impostor's picture is its mesh's; only GLB carries it.
                    let shown = Picture::base_of(material).filter(|p| *p != Picture::Impostor);
                    if let Some(picture) = shown {
                        let clamp = if picture.repeats_v() {
                            ""
                        } else {
                            "-clamp on "
                        };
                        let file = picture.file_name(&texture_stem);
                        let _ = writeln!(mtl, "map_Kd {clamp}{file}");
                    }
                    if let Some(mask) = Picture::mask_of(material).filter(|_| shown.is_some()) {
                        let file = mask.file_name(&texture_stem);
                        let _ = writeln!(mtl, "map_d -clamp on {file}");
                    }
                    if let Some(normal) = Picture::normal_of(material) {
                        let file = normal.file_name(&texture_stem);
                        let _ = writeln!(mtl, "norm {file}\nmap_Bump {file}");
                    }
                    n
                }
            };
            let _ = writeln!(obj, "usemtl {mtl_name}");
            for t in valid_triangles(&p.indices, mesh.positions.len()) {
                let [a, b, c] = t.map(|i| i as usize + offset);
                let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
            }
        }
        offset += mesh.positions.len();
    }
    (obj, mtl)
}

fn write_material(mtl: &mut String, name: &str, color: [f32; 3]) {
    let color = color.map(|c| {
        if c.is_finite() {
            c.clamp(0.0, 1.0)
        } else {
            0.0
        }
    });
    let _ = writeln!(mtl, "\nnewmtl {name}");
    // Ambient and diffuse alike: the plant's colour under any light.
    for key in ["Ka ", "\nKd "] {
        mtl.push_str(key);
        push_vec3(mtl, color);
    }
    mtl.push_str("\nKs 0.04 0.04 0.04\nNs 10\nd 1\nillum 2\n");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::tests::small_mesh;
    use sylva_core::glam::Quat;
    use sylva_mesh::scene::SceneNode;

    fn lines<'a>(text: &'a str, prefix: &str) -> Vec<&'a str> {
        text.lines().filter(|l| l.starts_with(prefix)).collect()
    }

    #[test]
    fn counts_and_names() {
        let mesh = small_mesh();
        let mut moved = SceneNode::new("second plant", &mesh);
        moved.translation = Vec3::new(3.0, 0.0, 0.0);
        moved.rotation = Quat::from_rotation_y(1.0);
        let scene = Scene {
            nodes: vec![SceneNode::new("first", &mesh), moved],
        };
        let (obj, mtl) = to_obj(&scene, "garden.mtl");
        let v = mesh.vertex_count();
        assert_eq!(lines(&obj, "v ").len(), 2 * v);
        assert_eq!(lines(&obj, "vn ").len(), 2 * v);
        assert_eq!(lines(&obj, "vt ").len(), 2 * v);
        assert_eq!(lines(&obj, "f ").len(), 2 * mesh.triangle_count());
        assert_eq!(lines(&obj, "mtllib "), ["mtllib garden.mtl"]);
        assert_eq!(lines(&obj, "o "), ["o first", "o second_plant"]);
        assert_eq!(lines(&obj, "usemtl ").len(), 2 * mesh.primitives.len());
        for m in &mesh.materials {
            assert!(obj.contains(&format!("usemtl {}", m.name)));
            assert!(mtl.contains(&format!("newmtl {}\n", m.name)));
        }
        // Identical materials of both nodes are written once.
        assert_eq!(lines(&mtl, "newmtl ").len(), mesh.primitives.len());
        assert_eq!(lines(&mtl, "Kd ").len(), mesh.primitives.len());
        assert_eq!(lines(&mtl, "d 1").len(), mesh.primitives.len());
        // Every face index is within the vertices written.
        for f in lines(&obj, "f ") {
            for corner in f[2..].split(' ') {
                let parts: Vec<&str> = corner.split('/').collect();
                assert_eq!(parts.len(), 3);
                assert!(parts[0] == parts[1] && parts[1] == parts[2], "{corner}");
                let i: usize = parts[0].parse().unwrap();
                assert!((1..=2 * v).contains(&i));
            }
        }
        // The second node's faces start after the first node's vertices.
        let second = obj.split("o second_plant").nth(1).unwrap();
        let first_face = lines(second, "f ")[0];
        let i: usize = first_face[2..].split('/').next().unwrap().parse().unwrap();
        assert!(i > v);
    }

    #[test]
    fn colliding_material_names_are_renamed() {
        let a = small_mesh();
        let mut b = small_mesh();
        b.materials[0].color = [0.9, 0.9, 0.9];
        let scene = Scene {
            nodes: vec![SceneNode::new("a", &a), SceneNode::new("b", &b)],
        };
        let (obj, mtl) = to_obj(&scene, "x.mtl");
        assert!(mtl.contains("newmtl bark\n") && mtl.contains("newmtl n1_bark\n"));
        assert!(obj.contains("usemtl n1_bark"));
        assert_eq!(lines(&mtl, "newmtl ").len(), 4);
    }

    #[test]
    fn textures_become_map_kd_and_uvs_flip_v() {
        let mut mesh = small_mesh();
        mesh.materials[0].texture = Some(1);
        mesh.materials[2].texture = Some(7);
        let (obj, mtl) = to_obj(&Scene::single(SceneNode::new("p", &mesh)), "my_tree.mtl");
        assert_eq!(
            lines(&mtl, "map_Kd "),
            [
                "map_Kd my_tree_tex1.png",
                "map_Kd -clamp on my_tree_tex7.png"
            ]
        );
        // The map follows its material.
        let bark = mtl
            .split("newmtl ")
            .find(|m| m.starts_with("bark"))
            .unwrap();
        assert!(bark.contains("map_Kd my_tree_tex1.png"));
        let leaf = mtl
            .split("newmtl ")
            .find(|m| m.starts_with("leaf"))
            .unwrap();
        assert!(!leaf.contains("map_Kd"));
        let vts = lines(&obj, "vt ");
        assert_eq!(vts.len(), mesh.vertex_count());
        for (line, uv) in vts.iter().zip(&mesh.uvs) {
            let xy: Vec<f32> = line[3..].split(' ').map(|x| x.parse().unwrap()).collect();
            assert_eq!(xy[0], uv[0]);
            assert!((xy[1] - (1.0 - uv[1])).abs() < 1e-6);
        }
    }

    #[test]
    fn broken_meshes_do_not_panic() {
        let mut mesh = small_mesh();
        mesh.positions[0] = [f32::NAN, f32::INFINITY, 1.0];
        mesh.normals.truncate(2);
        mesh.primitives[0].indices.push(99_999);
        mesh.primitives[0].material = 42;
        let (obj, _) = to_obj(&Scene::single(SceneNode::new("x", &mesh)), "x.mtl");
        assert!(!obj.contains("NaN") && !obj.contains("inf"));
        assert_eq!(lines(&obj, "vn ").len(), mesh.vertex_count());
    }

    #[test]
    fn same_scene_same_text() {
        let mesh = small_mesh();
        let scene = Scene::single(SceneNode::new("p", &mesh));
        assert_eq!(to_obj(&scene, "p.mtl"), to_obj(&scene, "p.mtl"));
    }
}
