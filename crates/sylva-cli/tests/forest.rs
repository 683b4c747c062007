#![allow(clippy::unwrap_used)]
//! `sylva garden --variants K`: every plant one of K grown seeds per genome, one mesh each in
//! the GLB, the garden file regrowing the same bytes; without it, nothing changes.

#[path = "../../sylva/tests/common/mod.rs"]
mod common;
mod support;
use support::{example, s, sylva, temp_dir};

/// The JSON chunk of a GLB.
fn gltf(glb: &[u8]) -> serde_json::Value {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&glb[20..20 + len]).unwrap()
}

#[test]
fn variants_place_a_few_meshes_many_times() {
    let dir = temp_dir("variants");
    let glb = dir.join("forest.glb");
    let (tulip, fern) = (
        example("plantmaker/tulip.json"),
        example("plantmaker/fern.json"),
    );
    let out = sylva(&[
        "garden",
        &tulip,
        &fern,
        "--count",
        "30",
        "--area",
        "40x40",
        "--variants",
        "3",
        "-o",
        s(&glb),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("60 plants (6 meshes)"));
    let bytes = std::fs::read(&glb).unwrap();
    let json = gltf(&bytes);
    assert_eq!(json["meshes"].as_array().unwrap().len(), 6);
    let nodes = json["nodes"].as_array().unwrap();
    assert_eq!(nodes.len(), 60);
    // Plant i of a genome is variant i mod 3: its seed in the extras says so.
    let garden: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("forest.garden.json")).unwrap())
            .unwrap();
    assert_eq!(garden["variants"], 3);
    let seeds = garden["plants"][0]["seeds"].as_array().unwrap();
    for (i, node) in nodes[..30].iter().enumerate() {
        assert_eq!(node["extras"]["seed"], seeds[i % 3]);
    }
    common::validate(std::slice::from_ref(&glb));
    // The garden file grows the same bytes again, and refuses a second --variants.
    let again = dir.join("again.glb");
    let garden_file = dir.join("forest.garden.json");
    let out = sylva(&["garden", s(&garden_file), "-o", s(&again)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read(&again).unwrap(), bytes);
    let out = sylva(&[
        "garden",
        s(&garden_file),
        "--variants",
        "2",
        "-o",
        s(&again),
    ]);
    assert_eq!(out.status.code(), Some(2));
    for bad in ["0", "1001", "-1", "x"] {
        let out = sylva(&["garden", &tulip, "--variants", bad, "-o", s(&glb)]);
        assert_eq!(out.status.code(), Some(2), "--variants {bad}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
