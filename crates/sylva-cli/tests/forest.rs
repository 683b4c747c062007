#![allow(clippy::unwrap_used)]
//! `sylva garden --variants K`: every plant one of K grown seeds per genome, drawn by one
//! `EXT_mesh_gpu_instancing` node per variant (or, with `--no-instancing`, one plain node per
//! plant sharing its variant's mesh), `--quantize` for `KHR_mesh_quantization`, the garden
//! file regrowing the same bytes; the streamed writer giving the bytes of the in-memory one;
//! without the flags, nothing changes.

use std::path::{Path, PathBuf};

mod support;
use support::{example, s, sylva, temp_dir, three_scene};

/// The JSON chunk of a GLB.
fn gltf(glb: &[u8]) -> serde_json::Value {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&glb[20..20 + len]).unwrap()
}

/// Runs `sylva garden` on the tulip and the fern, 30 each on a 40 m plot, with `extra`
/// flags, into `dir/name.glb`; returns the GLB's bytes and what the command printed.
fn garden(dir: &Path, name: &str, extra: &[&str]) -> (Vec<u8>, String) {
    let glb = dir.join(format!("{name}.glb"));
    let (tulip, fern) = (
        example("plantmaker/tulip.json"),
        example("plantmaker/fern.json"),
    );
    let mut args = vec![
        "garden", &tulip, &fern, "--count", "30", "--area", "40x40", "-o",
    ];
    args.push(s(&glb));
    args.extend_from_slice(extra);
    let out = sylva(&args);
    assert!(
        out.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    (
        std::fs::read(&glb).unwrap(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// Grows `dir/name.garden.json` again into `dir/name-again.glb` and checks the bytes.
fn regrows_the_same(dir: &Path, name: &str, bytes: &[u8]) {
    let again = dir.join(format!("{name}-again.glb"));
    let file = dir.join(format!("{name}.garden.json"));
    let out = sylva(&["garden", s(&file), "-o", s(&again)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read(&again).unwrap(), bytes, "{name}");
}

fn garden_file(dir: &Path, name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join(format!("{name}.garden.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn variants_are_instanced_one_node_per_variant() {
    let dir = temp_dir("instanced");
    let (bytes, printed) = garden(&dir, "forest", &["--variants", "3"]);
    assert!(printed.contains("60 plants (6 meshes)"), "{printed}");
    let json = gltf(&bytes);
    assert_eq!(
        json["extensionsUsed"],
        serde_json::json!(["EXT_mesh_gpu_instancing"])
    );
    assert!(json.get("extensionsRequired").is_none());
    assert_eq!(json["meshes"].as_array().unwrap().len(), 6);
    let nodes = json["nodes"].as_array().unwrap();
    assert_eq!(nodes.len(), 6, "one node per variant");
    // Plant i of a genome is variant i mod 3: each variant's node carries its seed and
    // draws its ten plants.
    let file = garden_file(&dir, "forest");
    assert_eq!(file["variants"], 3);
    assert!(file.get("instancing").is_none() && file.get("quantize").is_none());
    for (g, group) in file["plants"].as_array().unwrap().iter().enumerate() {
        for v in 0..3 {
            let node = &nodes[3 * g + v];
            assert_eq!(node["name"], format!("plant-{}", 30 * g + v));
            assert_eq!(node["extras"]["seed"], group["seeds"][v]);
            assert_eq!(node["extras"]["genome"], group["genome"]);
            let attributes = &node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"];
            for attribute in ["TRANSLATION", "ROTATION"] {
                let accessor = &json["accessors"][attributes[attribute].as_u64().unwrap() as usize];
                assert_eq!(accessor["count"], 10, "{attribute}");
            }
        }
    }
    let glb = dir.join("forest.glb");
    sylva_testkit::validate(std::slice::from_ref(&glb));
    // three.js draws an InstancedMesh per primitive, 60 plants in all.
    let seen = &three_scene(std::slice::from_ref(&glb))[0];
    assert_eq!(seen["nodes"].as_array().unwrap().len(), 6);
    let meshes = seen["meshes"].as_u64().unwrap();
    assert_eq!(seen["instanced"].as_u64().unwrap(), meshes);
    let primitives: usize = json["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["primitives"].as_array().unwrap().len())
        .sum();
    assert_eq!(meshes as usize, primitives);
    // Each primitive of a variant's mesh is drawn ten times.
    assert_eq!(seen["instances"].as_u64().unwrap(), 10 * meshes);
    regrows_the_same(&dir, "forest", &bytes);

    // --no-instancing: a plain node per plant, sharing its variant's mesh; recorded.
    let (plain, printed) = garden(&dir, "plain", &["--variants", "3", "--no-instancing"]);
    assert!(printed.contains("60 plants (6 meshes)"), "{printed}");
    let json = gltf(&plain);
    assert!(json.get("extensionsUsed").is_none());
    assert_eq!(json["meshes"].as_array().unwrap().len(), 6);
    let nodes = json["nodes"].as_array().unwrap();
    assert_eq!(nodes.len(), 60);
    let file = garden_file(&dir, "plain");
    assert_eq!(file["instancing"], false);
    let seeds = file["plants"][0]["seeds"].as_array().unwrap();
    for (i, node) in nodes[..30].iter().enumerate() {
        assert_eq!(node["extras"]["seed"], seeds[i % 3]);
        assert_eq!(node["mesh"], i % 3);
    }
    let seen = &three_scene(&[dir.join("plain.glb")])[0];
    assert_eq!(seen["instanced"], 0);
    assert_eq!(seen["triangles"], three_scene(&[glb])[0]["triangles"]);
    sylva_testkit::validate(&[dir.join("plain.glb")]);
    regrows_the_same(&dir, "plain", &plain);
    // The flag adds to what a garden file says.
    let again = dir.join("forest-plain.glb");
    let file = dir.join("forest.garden.json");
    let out = sylva(&["garden", s(&file), "--no-instancing", "-o", s(&again)]);
    assert!(out.status.success());
    assert_eq!(std::fs::read(&again).unwrap(), plain);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every vertex of a GLB as Sylva's reader places it in the world.
fn world_vertices(glb: &[u8]) -> Vec<[f32; 3]> {
    let scene = sylva::import::read_glb(glb).unwrap();
    scene
        .meshes
        .iter()
        .flat_map(|(_, m)| m.positions.iter().copied())
        .collect()
}

#[test]
fn quantised_forests_keep_every_position_within_half_a_step() {
    let dir = temp_dir("quantized");
    let (instanced, _) = garden(&dir, "exact", &["--variants", "3"]);
    let (plain, _) = garden(&dir, "exactplain", &["--variants", "3", "--no-instancing"]);
    let (all, _) = garden(&dir, "exactall", &[]);
    let mut files = Vec::new();
    for (name, flags, exact) in [
        ("q", &["--variants", "3", "--quantize"][..], &instanced),
        (
            "qplain",
            &["--variants", "3", "--quantize", "--no-instancing"][..],
            &plain,
        ),
        ("qall", &["--quantize"][..], &all),
    ] {
        let (bytes, _) = garden(&dir, name, flags);
        let json = gltf(&bytes);
        assert_eq!(
            json["extensionsRequired"],
            serde_json::json!(["KHR_mesh_quantization"])
        );
        assert_eq!(garden_file(&dir, name)["quantize"], true);
        regrows_the_same(&dir, name, &bytes);
        files.push(dir.join(format!("{name}.glb")));
        assert!(bytes.len() < exact.len(), "{name}: {} bytes", bytes.len());
        // The tallest plant bounds the error: half a step of 1/32767 of its half extent.
        let (a, b) = (world_vertices(exact), world_vertices(&bytes));
        assert_eq!(a.len(), b.len());
        let tallest = a.iter().map(|p| p[1]).fold(0.0f32, f32::max);
        let worst = a
            .iter()
            .zip(&b)
            .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0f32, f32::max))
            .fold(0.0f32, f32::max);
        // Plants are at most about as wide as tall; 1e-5 m covers the floats' own rounding
        // at 20 m from the origin.
        assert!(
            worst <= 2.0 * tallest / 65534.0 + 1e-5,
            "{name}: {worst} m off, tallest {tallest} m"
        );
    }
    sylva_testkit::validate(&files);
    // three.js draws as many triangles as from the float files, in the same place: each
    // file's world box is the float file's (three.js bounds an InstancedMesh by its
    // geometry's box, so instanced files are compared with instanced ones).
    let exact = three_scene(&[
        dir.join("exact.glb"),
        dir.join("exactplain.glb"),
        dir.join("exactall.glb"),
    ]);
    for (seen, exact) in three_scene(&files).iter().zip(&exact) {
        assert_eq!(seen["triangles"], exact["triangles"]);
        let corners = |v: &serde_json::Value| -> Vec<f64> {
            let b = v["box"].as_array().unwrap();
            b.iter()
                .flat_map(|c| c.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()))
                .collect()
        };
        for (a, b) in corners(seen).iter().zip(corners(exact)) {
            assert!((a - b).abs() < 1e-3, "{}: {a} against {b}", seen["file"]);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn streaming_meshes_plant_by_plant_gives_the_bytes_of_the_held_scene() {
    // With --png the scene is meshed whole (the picture needs it); without, each plant is
    // meshed as its bytes are written. Both give the same GLB.
    let dir = temp_dir("streamed");
    for flags in [
        &[][..],
        &["--variants", "3"][..],
        &["--variants", "3", "--quantize"][..],
        &["--variants", "2", "--no-instancing"][..],
    ] {
        let (streamed, _) = garden(&dir, "streamed", flags);
        let png = dir.join("held.png");
        let mut held_flags = flags.to_vec();
        held_flags.extend_from_slice(&["--png", s(&png)]);
        let (held, _) = garden(&dir, "held", &held_flags);
        assert_eq!(streamed, held, "{flags:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn wind_forests_stay_plain_and_refuse_quantisation() {
    let dir = temp_dir("wind");
    // Skinned meshes are not instanced (a skin ignores its node's transform, and three.js
    // instances no skinned mesh): the plants of a variant stay plain nodes with their rigs.
    let (bytes, _) = garden(&dir, "wind", &["--variants", "2", "--wind"]);
    let json = gltf(&bytes);
    assert!(json.get("extensionsUsed").is_none());
    assert_eq!(json["skins"].as_array().unwrap().len(), 60);
    sylva_testkit::validate(&[dir.join("wind.glb")]);
    let glb = dir.join("w.glb");
    let tulip = example("plantmaker/tulip.json");
    let refused = |args: &[&str], flag: &str| {
        let out = sylva(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(flag), "{args:?}: {err}");
        assert!(!glb.exists());
    };
    refused(
        &["garden", &tulip, "--quantize", "--wind", "-o", s(&glb)],
        "--quantize",
    );
    refused(
        &["garden", &tulip, "--quantize", "-o", s(&dir.join("w.obj"))],
        "--quantize",
    );
    refused(
        &["garden", &tulip, "--no-instancing", "-o", s(&glb)],
        "--no-instancing",
    );
    // A garden file that asks for quantisation, grown with wind.
    garden(&dir, "q", &["--quantize"]);
    refused(
        &[
            "garden",
            s(&dir.join("q.garden.json")),
            "--wind",
            "-o",
            s(&glb),
        ],
        "--wind",
    );
    // A garden file's fields are checked like the rest of it.
    let mut file = garden_file(&dir, "q");
    file["quantize"] = serde_json::json!("yes");
    let bad: PathBuf = dir.join("bad.garden.json");
    std::fs::write(&bad, file.to_string()).unwrap();
    refused(&["garden", s(&bad), "-o", s(&glb)], "quantize");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn variants_are_checked() {
    let dir = temp_dir("checked");
    let (_, _) = garden(&dir, "forest", &["--variants", "3"]);
    let glb = dir.join("again.glb");
    let garden_file = dir.join("forest.garden.json");
    // A garden file refuses a second --variants.
    let out = sylva(&["garden", s(&garden_file), "--variants", "2", "-o", s(&glb)]);
    assert_eq!(out.status.code(), Some(2));
    let tulip = example("plantmaker/tulip.json");
    for bad in ["0", "1001", "-1", "x"] {
        let out = sylva(&["garden", &tulip, "--variants", bad, "-o", s(&glb)]);
        assert_eq!(out.status.code(), Some(2), "--variants {bad}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
