//! The shared test tree (also the benchmark's) meshes into a valid mesh of over a million
//! triangles, the same every time.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use sylva_core::glam::Vec3;
use sylva_mesh::mesher::{MeshOptions, Mesher};

#[test]
fn bench_tree_is_big_valid_and_deterministic() {
    let plant = sylva_testkit::bench_tree();
    let mut mesher = Mesher::new(MeshOptions::default()).expect("default options");
    let mesh = mesher.mesh(&plant).expect("the tree meshes");
    assert!(
        mesh.triangle_count() >= 1_000_000,
        "{}",
        mesh.triangle_count()
    );
    assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()));
    assert_eq!(mesh.uvs.len(), mesh.vertex_count());
    assert!(
        mesh.uvs
            .iter()
            .all(|uv| (0.0..=1.0).contains(&uv[0]) && uv[1].is_finite() && uv[1] >= 0.0)
    );
    for n in &mesh.normals {
        let len = Vec3::from_array(*n).length();
        assert!((len - 1.0).abs() < 1e-4, "normal of length {len}");
    }
    let vertices = mesh.vertex_count() as u32;
    for p in &mesh.primitives {
        assert!(p.indices.iter().all(|&i| i < vertices));
    }
    // Bark, leaves and flowers.
    assert_eq!(mesh.primitives.len(), 3);
    assert_eq!(mesher.mesh(&plant).expect("again"), mesh);
}
