//! Binary STL, for 3D printing: every triangle of every node in world space, in millimetres
//! (the unit slicers assume; Sylva's scenes are in metres), each with its face normal. STL
//! has no colours, textures or nodes. Leaves and petals are single surfaces, as in every
//! format: a slicer prints them only if they are made thicker first.
//!
//! The file: an 80-byte header (`Sylva <version> binary STL, millimetres`, padded with
//! spaces), the triangle count (u32), then per triangle its normal and three corners (12
//! little-endian f32) and a zero attribute count (u16).

use sylva_core::glam::Vec3;
use sylva_mesh::scene::Scene;

/// Millimetres per metre.
const MM: f32 = 1000.0;

/// Bytes a triangle takes.
const TRIANGLE_BYTES: usize = 50;

/// Encodes `scene` as binary STL. Never fails: indices out of range are skipped, and a
/// degenerate triangle gets a zero normal (use [`super::check_scene`] to refuse scenes with
/// non-finite numbers).
pub fn to_stl(scene: &Scene) -> Vec<u8> {
    let triangles: usize = scene
        .nodes
        .iter()
        .flat_map(|n| &n.mesh.primitives)
        .map(|p| p.indices.len() / 3)
        .sum();
    let mut out = Vec::with_capacity(84 + TRIANGLE_BYTES * triangles);
    let mut header = format!(
        "Sylva {} binary STL, millimetres",
        env!("CARGO_PKG_VERSION")
    )
    .into_bytes();
    // An ASCII STL starts with "solid": a binary one must not, or readers mistake it.
    header.resize(80, b' ');
    out.extend_from_slice(&header[..80]);
    let count_at = out.len();
    out.extend_from_slice(&[0; 4]);
    let mut written = 0u32;
    for node in &scene.nodes {
        let world: Vec<Vec3> = node
            .mesh
            .positions
            .iter()
            .map(|p| node.transform_point(Vec3::from_array(*p)) * MM)
            .collect();
        for primitive in &node.mesh.primitives {
            for t in primitive.indices.chunks_exact(3) {
                let corner = |i: u32| world.get(i as usize).copied();
                let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) else {
                    continue;
                };
                let normal = (b - a).cross(c - a).normalize_or_zero();
                for v in [normal, a, b, c] {
                    for x in v.to_array() {
                        out.extend_from_slice(&x.to_le_bytes());
                    }
                }
                out.extend_from_slice(&[0, 0]);
                written += 1;
            }
        }
    }
    out[count_at..count_at + 4].copy_from_slice(&written.to_le_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva_core::{Material, MaterialKind};
    use sylva_mesh::scene::SceneNode;
    use sylva_mesh::{Mesh, Primitive};

    fn f32_at(bytes: &[u8], at: usize) -> f32 {
        f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
    }

    #[test]
    fn triangles_in_world_millimetres_with_normals() {
        let mesh = Mesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [9.0, 9.0, 9.0],
            ],
            normals: vec![[0.0, 0.0, 1.0]; 4],
            uvs: Vec::new(),
            primitives: vec![Primitive {
                material: 0,
                indices: vec![0, 1, 2, 0, 1, 7],
            }],
            materials: vec![Material::of_kind(MaterialKind::Bark)],
            impostor: None,
        };
        let mut node = SceneNode::new("a", &mesh);
        node.translation = Vec3::new(0.0, 2.0, 0.0);
        let stl = to_stl(&Scene::single(node));
        assert!(!stl.starts_with(b"solid"));
        assert!(stl.starts_with(b"Sylva "));
        // The triangle naming a missing vertex is skipped.
        assert_eq!(u32::from_le_bytes([stl[80], stl[81], stl[82], stl[83]]), 1);
        assert_eq!(stl.len(), 84 + TRIANGLE_BYTES);
        let t = 84;
        assert_eq!(
            [f32_at(&stl, t), f32_at(&stl, t + 4), f32_at(&stl, t + 8)],
            [0.0, 0.0, 1.0]
        );
        // the second corner: (1, 0, 0) m moved up 2 m, in millimetres
        assert_eq!(
            [
                f32_at(&stl, t + 24),
                f32_at(&stl, t + 28),
                f32_at(&stl, t + 32)
            ],
            [1000.0, 2000.0, 0.0]
        );
        assert_eq!(&stl[t + 48..t + 50], &[0, 0]);
    }
}
