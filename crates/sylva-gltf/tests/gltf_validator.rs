//! Every kind of GLB Sylva writes passes the Khronos glTF validator with no errors and no
//! warnings.
//!
//! Needs Node.js and the validator installed from the lock file:
//! `npm ci --prefix tools/gltf-validator` (from the repository root). The test fails, never
//! skips, when either is missing.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::json;
use sylva_core::dress::{Dress, dress};
use sylva_core::glam::{Quat, Vec2, Vec3};
use sylva_core::species::LeafKind;
use sylva_core::{Material, MaterialId, MaterialKind, Organ, OrganKind, Plant, PlantMeta};
use sylva_gltf::export::write_scene;
use sylva_mesh::mesher::{MeshOptions, mesh_plant};
use sylva_mesh::{Mesh, Scene, SceneNode};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("the crate lives in crates/<name>")
        .to_owned()
}

/// The validator script, after checking that Node.js and the npm package are installed.
fn validator() -> PathBuf {
    let tool = repo_root().join("tools/gltf-validator");
    let install = "run `npm ci --prefix tools/gltf-validator` from the repository root";
    match Command::new("node").arg("--version").output() {
        Ok(out) if out.status.success() => {}
        _ => panic!(
            "Node.js (`node`) is needed to run the glTF validator; install it, then {install}"
        ),
    }
    assert!(
        tool.join("node_modules/gltf-validator/package.json")
            .is_file(),
        "the glTF validator is not installed in {}: {install}",
        tool.display()
    );
    tool.join("validate.mjs")
}

fn mesh(plant: &Plant) -> Mesh {
    mesh_plant(plant, &MeshOptions::default()).expect("test plants mesh")
}

/// A small tree with leaves, flowers and, below ground, roots ending in root tips.
fn tree_with_organs() -> Plant {
    let mut plant = sylva_testkit::binary_tree(4, 6);
    let root = plant
        .add_material(Material::of_kind(MaterialKind::Root))
        .expect("a fourth material fits");
    let mut parent = None;
    for i in 0..4 {
        let start = Vec3::new(0.05 * i as f32, -0.3 * i as f32, 0.0);
        let end = Vec3::new(0.05 * (i + 1) as f32, -0.3 * (i + 1) as f32, 0.0);
        let r = 0.1 - 0.02 * i as f32;
        parent = Some(
            plant
                .add_segment(start, end, (r, r - 0.02), parent, false, root)
                .expect("valid root"),
        );
    }
    plant
        .add_organ(Organ {
            kind: OrganKind::RootTip,
            position: Vec3::new(0.2, -1.2, 0.0),
            orientation: Quat::from_rotation_z(std::f32::consts::PI),
            size: Vec2::new(0.05, 0.02),
            material: root,
            parent,
        })
        .expect("valid root tip");
    plant
}

#[test]
fn written_glbs_pass_the_khronos_validator() {
    let script = validator();
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut files = Vec::new();
    let mut write = |name: &str, scene: &Scene| {
        let path = dir.path().join(name);
        write_scene(&path, scene).expect("the scene exports");
        files.push(path);
    };

    // A tree with leaves, flowers, roots and origin data.
    let tree = mesh(&tree_with_organs());
    let mut node = SceneNode::new("tree", &tree);
    node.extras = Some(json!({
        "genome": {
            "model": "bintree",
            "format": 1,
            "values": { "angle": 35.5, "bits": [1, 0, 1, 1], "nested": { "deep": [null, true, "x"] } }
        },
        "seed": 42,
        "sylva": env!("CARGO_PKG_VERSION"),
    }));
    write("tree.glb", &Scene::single(node));

    // Two nodes sharing one mesh and a third with another, placed and turned.
    let small = mesh(&sylva_testkit::binary_tree(2, 3));
    let mut a = SceneNode::new("a", &tree);
    a.translation = Vec3::new(-3.0, 0.0, 0.0);
    let mut b = SceneNode::new("b", &tree);
    b.translation = Vec3::new(3.0, 0.0, 1.0);
    b.rotation = Quat::from_rotation_y(1.1);
    let mut c = SceneNode::new("c", &small);
    c.rotation = Quat::from_rotation_y(-0.4) * Quat::from_rotation_x(0.1);
    c.extras = Some(json!({ "seed": 7 }));
    write(
        "garden.glb",
        &Scene {
            nodes: vec![a, b, c],
        },
    );

    // An empty plant, alone and next to a real one; and a scene with no nodes at all.
    let empty = mesh(&Plant::new(PlantMeta::default()));
    assert_eq!(empty.triangle_count(), 0);
    write(
        "empty-plant.glb",
        &Scene::single(SceneNode::new("empty", &empty)),
    );
    write(
        "empty-and-small.glb",
        &Scene {
            nodes: vec![
                SceneNode::new("empty", &empty),
                SceneNode::new("small", &small),
            ],
        },
    );
    write("no-nodes.glb", &Scene::default());

    // Textured materials: bark and root each with their own texture, leaf and flower sharing
    // one, and a second plant with an untextured bark, a petal texture and an id past the
    // designs; the two plants share the leaf texture.
    let mut textured = tree_with_organs();
    let textures = [Some(0), Some(3), Some(3), Some(1)];
    for (m, t) in textures.into_iter().enumerate() {
        textured.set_texture(MaterialId(m as u16), t).unwrap();
    }
    let textured = mesh(&textured);
    let mut other = sylva_testkit::binary_tree(2, 3);
    other.set_texture(Plant::LEAF, Some(3)).unwrap();
    other.set_texture(Plant::FLOWER, Some(16)).unwrap();
    let other = mesh(&other);
    assert!(other.materials[0].texture.is_none());
    let mut second = SceneNode::new("other", &other);
    second.translation = Vec3::new(2.0, 0.0, 0.0);
    write(
        "textured.glb",
        &Scene {
            nodes: vec![SceneNode::new("textured", &textured), second],
        },
    );

    // Realism surfaces: leaf cards cut out by alpha (MASK, double-sided) in shades merged
    // into vertex colours, petals cut to shape, tiling bark with its normal map; a broadleaf
    // of flat cards and a conifer of crossed ones.
    let dressed: Vec<(&str, Mesh)> = [("oak", LeafKind::Oak), ("pine", LeafKind::Pine)]
        .into_iter()
        .map(|(name, kind)| {
            let (plant, report) = dress(&tree_with_organs(), &Dress::foliage(kind), 1).unwrap();
            assert!(report.cards > 0);
            (name, mesh(&plant))
        })
        .collect();
    for (name, mesh) in &dressed {
        write(
            &format!("dressed-{name}.glb"),
            &Scene::single(SceneNode::new(*name, mesh)),
        );
    }

    // Past 65 535 vertices: 32-bit indices.
    let big = mesh(&sylva_testkit::binary_tree(8, 12));
    assert!(big.vertex_count() > 65_535, "{}", big.vertex_count());
    write("big.glb", &Scene::single(SceneNode::new("big", &big)));

    let out = Command::new("node")
        .arg(&script)
        .args(&files)
        .output()
        .expect("node runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}{stderr}");
    assert!(
        out.status.success(),
        "the glTF validator reported problems (exit {:?}):\n{stdout}{stderr}",
        out.status.code()
    );
    for f in &files {
        let line = format!("{}: 0 errors, 0 warnings", f.display());
        assert!(stdout.contains(&line), "missing `{line}` in\n{stdout}");
    }
}

#[test]
fn the_validator_script_reports_bad_files() {
    let script = validator();
    let dir = tempfile::tempdir().expect("a temporary directory");
    let bad = dir.path().join("bad.glb");
    std::fs::write(&bad, b"glTF\x02\0\0\0\x0c\0\0\0").expect("write");
    let out = Command::new("node")
        .arg(&script)
        .arg(&bad)
        .output()
        .expect("node runs");
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let missing = Command::new("node")
        .arg(&script)
        .arg(dir.path().join("missing.glb"))
        .output()
        .expect("node runs");
    assert_eq!(missing.status.code(), Some(2), "{missing:?}");
    let usage = Command::new("node")
        .arg(&script)
        .output()
        .expect("node runs");
    assert_eq!(usage.status.code(), Some(2), "{usage:?}");
}
