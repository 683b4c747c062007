#![allow(clippy::unwrap_used)]
//! Assets as engines take them: lean materials (one per organ kind, shades in `COLOR_0`),
//! checked with the Khronos validator and three.js's GLTFLoader.

#[path = "../../sylva/tests/common/mod.rs"]
mod common;
mod support;
use support::{example, s, sylva, temp_dir, three_scene};

#[test]
fn shades_become_vertex_colours_of_one_material_per_kind() {
    let dir = temp_dir("lean");
    let bush = dir.join("bush.glb");
    let helix = dir.join("helix.glb");
    for (genome, out) in [
        ("plantmaker/flowering-bush.json", &bush),
        ("automata/helix.json", &helix),
    ] {
        let run = sylva(&["grow", &example(genome), "-o", s(out)]);
        assert!(run.status.success(), "{run:?}");
    }
    common::validate(&[bush.clone(), helix.clone()]);
    let seen = three_scene(&[bush, helix]);
    // The bush's 29 shades: bark, leaf and flower, each with vertex colours on.
    let names: Vec<&str> = seen[0]["materials"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["bark", "leaf-t3", "flower-t7"]);
    assert!(
        seen[0]["materials"]
            .as_array()
            .unwrap()
            .iter()
            .all(|m| m["vertexColors"] == true)
    );
    assert_eq!(seen[0]["colored"], seen[0]["geometries"]);
    // One colour per kind already: no vertex colours.
    assert_eq!(seen[1]["colored"], 0);
    std::fs::remove_dir_all(dir).unwrap();
}
