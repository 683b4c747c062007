//! VRML97 writer.
//!
//! One `Transform` per node (translation, and rotation as axis and angle), named with `DEF`
//! after the node; inside it one `Shape` per primitive: an `Appearance` whose `Material` has
//! the plant colour as `diffuseColor`, and an `IndexedFaceSet` with per-vertex normals and
//! texture coordinates, `solid FALSE` and `ccw TRUE`. A mesh's `Coordinate`, `Normal` and
//! `TextureCoordinate` nodes are written once, with `DEF`, the first time it appears, and
//! re-used with `USE` by its other primitives and by every other node that borrows the same
//! mesh. Texture coordinates hold `u` and `1 - v` (VRML's `t` points up the picture); faces
//! index them like their vertices (no `texCoordIndex`). Numbers are written in the shortest
//! form that reads back as the same `f32`.
//!
//! A textured material's `Appearance` also has `texture ImageTexture { url
//! "<stem>_tex<id>.png" }` ([`super::texture_files`] gives the files), with `repeatT FALSE`
//! for leaf and petal textures. The textures are grey, one component, which VRML97
//! multiplies with `diffuseColor` (an RGB texture would replace it). A material with a
//! surface names its picture ([`Picture::file_name`]): cut-out leaves and petals are grey
//! and alpha, two components, which VRML97 reads as intensity and transparency, so their
//! outline is cut; bark's normal map has no place in VRML97 and is left out.

use std::collections::HashMap;
use std::fmt::Write as _;

use sylva_core::glam::Vec3;
use sylva_mesh::mesh::Mesh;
use sylva_mesh::picture::Picture;
use sylva_mesh::scene::Scene;

use super::{push_float, push_vec3, token, valid_triangles};

/// The stem [`to_vrml`] names texture files after: `scene_tex<id>.png`.
pub const DEFAULT_TEXTURE_STEM: &str = "scene";

/// Encodes `scene` as a VRML97 (`.wrl`) file whose textures are `scene_tex<id>.png`
/// ([`DEFAULT_TEXTURE_STEM`]); see [`to_vrml_with_textures`].
pub fn to_vrml(scene: &Scene) -> String {
    to_vrml_with_textures(scene, DEFAULT_TEXTURE_STEM)
}

/// Encodes `scene` as a VRML97 (`.wrl`) file whose materials' textures are the files
/// `<stem>_tex<id>.png` next to it, as [`super::texture_files`]`(scene, stem)` names them.
/// Never fails: indices out of range are dropped and non-finite numbers written as 0 (use
/// [`super::check_scene`] to refuse such scenes).
pub fn to_vrml_with_textures(scene: &Scene, stem: &str) -> String {
    let stem = token(stem);
    let vertices: usize = scene.nodes.iter().map(|n| n.mesh.positions.len()).sum();
    let mut out = String::with_capacity(64 * vertices + 256);
    let _ = writeln!(
        out,
        "#VRML V2.0 utf8\n# Sylva {}; Y up, metres\n",
        env!("CARGO_PKG_VERSION")
    );
    let mut mesh_ids: HashMap<*const Mesh, usize> = HashMap::new();
    for (index, node) in scene.nodes.iter().enumerate() {
        let key: *const Mesh = node.mesh;
        let fresh = !mesh_ids.contains_key(&key);
        let next_id = mesh_ids.len();
        let id = *mesh_ids.entry(key).or_insert(next_id);

        let _ = writeln!(out, "DEF N{index}_{} Transform {{", token(&node.name));
        out.push_str("  translation ");
        push_vec3(&mut out, node.translation.to_array());
        let (axis, angle) = node.rotation.normalize().to_axis_angle();
        let (axis, angle) = if axis.is_finite() && angle.is_finite() {
            (axis, angle)
        } else {
            (Vec3::X, 0.0)
        };
        out.push_str("\n  rotation ");
        push_vec3(&mut out, axis.to_array());
        out.push(' ');
        push_float(&mut out, angle);
        out.push_str("\n  children [\n");
        shapes(&mut out, node.mesh, id, fresh, &stem);
        out.push_str("  ]\n}\n");
    }
    out
}

/// Writes one `Shape` per primitive of `mesh`; the first defines the mesh's coordinates and
/// normals when `fresh`, every other one uses them.
fn shapes(out: &mut String, mesh: &Mesh, id: usize, mut fresh: bool, stem: &str) {
    let count = mesh.positions.len();
    for p in &mesh.primitives {
        let mut triangles = valid_triangles(&p.indices, count).peekable();
        if triangles.peek().is_none() {
            continue;
        }
        let material = mesh.materials.get(p.material);
        let color = material
            .map_or([0.8; 3], |m| m.color)
            .map(|c| c.clamp(0.0, 1.0));
        out.push_str(
            "    Shape {\n      appearance Appearance {\n        material Material { diffuseColor ",
        );
        push_vec3(out, color);
        out.push_str(" }\n");
        // An impostor's picture is its mesh's; only GLB carries it.
        if let Some(picture) = material
            .and_then(Picture::base_of)
            .filter(|p| *p != Picture::Impostor)
        {
            let repeat = match (picture.repeats_u(), picture.repeats_v()) {
                (true, true) => "",
                (true, false) => " repeatT FALSE",
                _ => " repeatS FALSE repeatT FALSE",
            };
            let _ = writeln!(
                out,
                "        texture ImageTexture {{ url \"{}\"{repeat} }}",
                picture.file_name(stem)
            );
        }
        out.push_str("      }\n      geometry IndexedFaceSet {\n");
        if fresh {
            let _ = writeln!(out, "        coord DEF M{id}_P Coordinate {{ point [");
            for v in &mesh.positions {
                out.push_str("          ");
                push_vec3(out, *v);
                out.push_str(",\n");
            }
            let _ = writeln!(
                out,
                "        ] }}\n        normal DEF M{id}_N Normal {{ vector ["
            );
            for i in 0..count {
                let n = mesh.normals.get(i).copied().unwrap_or([0.0, 1.0, 0.0]);
                out.push_str("          ");
                push_vec3(out, Vec3::from_array(n).normalize_or(Vec3::Y).to_array());
                out.push_str(",\n");
            }
            out.push_str("        ] }\n");
            let _ = writeln!(
                out,
                "        texCoord DEF M{id}_T TextureCoordinate {{ point ["
            );
            for i in 0..count {
                let [u, v] = mesh.uvs.get(i).copied().unwrap_or([0.0, 0.0]);
                out.push_str("          ");
                push_float(out, u);
                out.push(' ');
                push_float(out, 1.0 - v);
                out.push_str(",\n");
            }
            out.push_str("        ] }\n");
            fresh = false;
        } else {
            let _ = writeln!(
                out,
                "        coord USE M{id}_P\n        normal USE M{id}_N\n        texCoord USE M{id}_T"
            );
        }
        out.push_str("        coordIndex [\n");
        for [a, b, c] in triangles {
            let _ = writeln!(out, "          {a}, {b}, {c}, -1,");
        }
        out.push_str(
            "        ]\n        normalPerVertex TRUE\n        solid FALSE\n        ccw TRUE\n      }\n    }\n",
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::tests::small_mesh;
    use sylva_core::glam::Quat;
    use sylva_mesh::scene::SceneNode;

    fn balanced(text: &str) -> bool {
        let mut stack = Vec::new();
        for c in text
            .lines()
            .filter(|l| !l.trim_start().starts_with('#'))
            .flat_map(str::chars)
        {
            let open = match c {
                '[' | '{' => {
                    stack.push(c);
                    continue;
                }
                ']' => '[',
                '}' => '{',
                _ => continue,
            };
            if stack.pop() != Some(open) {
                return false;
            }
        }
        stack.is_empty()
    }

    #[test]
    fn structure() {
        let mesh = small_mesh();
        let other = small_mesh();
        let mut turned = SceneNode::new("turned one", &mesh);
        turned.rotation = Quat::from_rotation_x(0.5);
        turned.translation = Vec3::new(0.0, 0.0, -2.0);
        let scene = Scene {
            nodes: vec![
                SceneNode::new("a", &mesh),
                SceneNode::new("b", &other),
                turned,
            ],
        };
        let text = to_vrml(&scene);
        assert!(text.starts_with("#VRML V2.0 utf8\n"));
        assert!(balanced(&text));
        assert_eq!(text.matches("Transform {").count(), 3);
        assert_eq!(text.matches("Shape {").count(), 3 * mesh.primitives.len());
        // Two distinct meshes: two DEFs each of coordinates and normals, USEd elsewhere.
        assert_eq!(text.matches(" Coordinate {").count(), 2);
        assert_eq!(text.matches("TextureCoordinate {").count(), 2);
        assert_eq!(
            text.matches("texCoord USE M0_T").count(),
            2 * mesh.primitives.len() - 1
        );
        assert!(
            !text.contains("ImageTexture"),
            "no textures, no ImageTexture"
        );
        assert_eq!(
            text.matches("coord USE M0_P").count(),
            2 * mesh.primitives.len() - 1
        );
        assert_eq!(text.matches(", -1,").count(), 3 * mesh.triangle_count());
        assert!(text.contains("DEF N2_turned_one Transform {"));
        assert!(text.contains("rotation 1 0 0 0.5"));
        assert!(text.contains("translation 0 0 -2"));
        assert_eq!(
            text.matches("solid FALSE").count(),
            3 * mesh.primitives.len()
        );
    }

    #[test]
    fn textured_materials_get_an_image_texture() {
        let mut mesh = small_mesh();
        mesh.materials[0].texture = Some(2);
        mesh.materials[1].texture = Some(4);
        let text = to_vrml_with_textures(&Scene::single(SceneNode::new("p", &mesh)), "oak 1");
        assert!(balanced(&text));
        assert!(text.contains("texture ImageTexture { url \"oak_1_tex2.png\" }\n"));
        assert!(text.contains("texture ImageTexture { url \"oak_1_tex4.png\" repeatT FALSE }"));
        assert_eq!(text.matches("ImageTexture").count(), 2);
        // Texture coordinates flip v.
        let uv = mesh.uvs[1];
        let first = text.split("TextureCoordinate { point [\n").nth(1).unwrap();
        let second_line = first.lines().nth(1).unwrap().trim().trim_end_matches(',');
        let xy: Vec<f32> = second_line.split(' ').map(|x| x.parse().unwrap()).collect();
        assert_eq!(xy[0], uv[0]);
        assert!((xy[1] - (1.0 - uv[1])).abs() < 1e-6);
        assert!(to_vrml(&Scene::single(SceneNode::new("p", &mesh))).contains("scene_tex2.png"));
    }

    #[test]
    fn empty_and_broken_meshes() {
        let empty = Mesh::default();
        let text = to_vrml(&Scene::single(SceneNode::new("e", &empty)));
        assert!(balanced(&text));
        assert!(!text.contains("Shape"));
        let mut broken = small_mesh();
        broken.positions[0][0] = f32::NAN;
        broken.primitives[0].indices[0] = 1 << 30;
        let mut node = SceneNode::new("b", &broken);
        node.rotation = Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0);
        let text = to_vrml(&Scene::single(node));
        assert!(balanced(&text));
        assert!(!text.contains("NaN"));
    }

    #[test]
    fn same_scene_same_text() {
        let mesh = small_mesh();
        let scene = Scene::single(SceneNode::new("p", &mesh));
        assert_eq!(to_vrml(&scene), to_vrml(&scene));
    }
}
