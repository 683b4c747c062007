#![allow(clippy::unwrap_used)]
//! Wind GLBs of every model: validator-clean, a skin per plant, one looping clip.

use std::path::{Path, PathBuf};

use sylva::assets::{Placed, SceneAssets};
use sylva::{GrowOptions, Grown};
use sylva_core::glam::Vec3;
use sylva_mesh::wind::WindOptions;

/// Growing with `seed`, roots kept or not, and `wind`.
fn windy(seed: u64, roots: bool, wind: Option<WindOptions>) -> GrowOptions {
    GrowOptions {
        seed: Some(seed),
        roots,
        wind,
        ..GrowOptions::default()
    }
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
}

/// The JSON chunk of a GLB.
fn gltf(glb: &[u8]) -> serde_json::Value {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&glb[20..20 + len]).unwrap()
}

#[test]
fn wind_glbs_of_every_model_are_validator_clean() {
    let dir = std::env::temp_dir().join(format!("sylva-wind-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut files = Vec::new();
    for name in [
        "bintree/oak.json",
        "automata/helix.json",
        "plantmaker/fern.json",
        "plantmaker/flowering-bush.json",
        "lsystem/tree.json",
    ] {
        let genome = sylva::Registry::standard()
            .load_genome(&example(name))
            .unwrap();
        let seed = genome.default_seed();
        let grown = Grown::grow(genome, &windy(seed, false, Some(WindOptions::default()))).unwrap();
        let rig = grown.rig.as_ref().unwrap();
        assert!(rig.joints.len() >= 2, "{name}: {} joints", rig.joints.len());
        let glb = sylva_gltf::export::to_glb(&grown.scene()).unwrap();
        let json = gltf(&glb);
        assert_eq!(json["animations"][0]["name"], "wind", "{name}");
        assert_eq!(json["skins"].as_array().unwrap().len(), 1);
        assert_eq!(
            json["skins"][0]["joints"].as_array().unwrap().len(),
            rig.joints.len()
        );
        assert_eq!(
            json["nodes"][0]["extras"]["wind"]["joints"],
            rig.joints.len()
        );
        // Sylva's own reader takes it back (the rest pose), as `sylva render` does.
        let back = sylva_gltf::import::read_glb(&glb).unwrap();
        assert_eq!(
            back.scene().triangle_count(),
            grown.mesh.triangle_count(),
            "{name}"
        );
        let file = dir.join(name.replace('/', "-").replace(".json", ".glb"));
        std::fs::write(&file, &glb).unwrap();
        files.push(file);
    }
    // A garden: each plant its own skin, one clip moving them all, places kept by the rigs.
    let genome = sylva::Registry::standard()
        .load_genome(&example("bintree/oak.json"))
        .unwrap();
    let plant = genome.develop(0).unwrap();
    let placed: Vec<Placed> = (0..3)
        .map(|i| Placed {
            translation: Vec3::new(4.0 * i as f32, 0.0, 0.0),
            ..Placed::new(format!("oak-{i}"), &plant, genome.mesh_hint())
        })
        .collect();
    let assets = SceneAssets::mesh(&placed, Some(WindOptions::default())).unwrap();
    let glb = sylva_gltf::export::to_glb(&assets.scene()).unwrap();
    let json = gltf(&glb);
    assert_eq!(json["skins"].as_array().unwrap().len(), 3);
    assert_eq!(json["animations"].as_array().unwrap().len(), 1);
    let rig_root = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["name"] == "oak-2-rig")
        .unwrap();
    assert_eq!(rig_root["translation"], serde_json::json!([8.0, 0.0, 0.0]));
    let file = dir.join("garden.glb");
    std::fs::write(&file, &glb).unwrap();
    files.push(file);
    sylva_testkit::validate(&files);
    // three.js's GLTFLoader and AnimationMixer, under Node: the joints move and the loop closes.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = std::process::Command::new("node")
        .arg(root.join("tools/three-check/wind.mjs"))
        .args(&files)
        .output()
        .expect("node runs (install Node.js)");
    assert!(
        out.status.success(),
        "three.js: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn without_wind_the_bytes_are_unchanged() {
    let genome = sylva::Registry::standard()
        .load_genome(&example("bintree/oak.json"))
        .unwrap();
    let plain = Grown::grow(genome.clone(), &windy(0, true, None)).unwrap();
    let none = Grown::grow(genome, &windy(0, true, None)).unwrap();
    assert_eq!(
        sylva_gltf::export::to_glb(&plain.scene()).unwrap(),
        sylva_gltf::export::to_glb(&none.scene()).unwrap()
    );
}

/// Writes `target/wind-<name>.png`: the plant posed at eight moments of its wind clip, side by
/// side, drawn by Sylva's renderer (`cargo test -p sylva --test wind -- --ignored`).
#[test]
#[ignore = "writes pictures to look at"]
fn wind_strips() {
    for (name, strength) in [
        ("lsystem/tree.json", 2.0),
        ("bintree/oak.json", 8.0),
        ("plantmaker/palm.json", 2.0),
    ] {
        let genome = sylva::Registry::standard()
            .load_genome(&example(name))
            .unwrap();
        let seed = genome.default_seed();
        let wind = WindOptions::new(strength, 4.0).unwrap();
        let grown = Grown::grow(genome, &windy(seed, false, Some(wind))).unwrap();
        let rig = grown.rig.as_ref().unwrap();
        let b = sylva_mesh::Scene::single(sylva_mesh::SceneNode::new("p", &grown.mesh)).bounds();
        let step = 1.1 * (b.max.x - b.min.x);
        let frames: Vec<_> = (0..4)
            .map(|k| rig.pose(&grown.mesh, k as f32 * 1.0))
            .collect();
        let nodes = frames
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let mut n = sylva_mesh::SceneNode::new(format!("t{k}"), m);
                n.translation = Vec3::new(k as f32 * step, 0.0, 0.0);
                n
            })
            .collect();
        let scene = sylva_mesh::Scene { nodes };
        let png = sylva::assets::picture(&scene, sylva_render::View::Front, (1600, 420)).unwrap();
        let out = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../target")
            .join(format!(
                "wind-{}.png",
                name.split('/')
                    .next_back()
                    .unwrap()
                    .trim_end_matches(".json")
            ));
        std::fs::write(&out, png).unwrap();
    }
}
