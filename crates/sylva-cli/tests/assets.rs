#![allow(clippy::unwrap_used)]
//! Assets as engines take them: lean materials (one per organ kind, shades in `COLOR_0`),
//! checked with the Khronos validator and three.js's GLTFLoader.

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
    sylva_testkit::validate(&[bush.clone(), helix.clone()]);
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

#[test]
fn levels_of_detail_halve_end_in_an_impostor_and_load_as_named_siblings() {
    let dir = temp_dir("lod");
    let tree = dir.join("tree.glb");
    let run = sylva(&[
        "grow",
        &example("lsystem/tree.json"),
        "-o",
        s(&tree),
        "--lod",
        "4",
    ]);
    assert!(run.status.success(), "{run:?}");
    // Four meshed levels, then the impostor.
    let levels: Vec<_> = (0..5)
        .map(|k| dir.join(format!("tree_LOD{k}.glb")))
        .collect();
    let mut all = levels.clone();
    all.push(tree.clone());
    sylva_testkit::validate(&all);
    let seen = three_scene(&all);
    let group = &seen[5];
    let names: Vec<&str> = group["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "tree_LOD0",
            "tree_LOD1",
            "tree_LOD2",
            "tree_LOD3",
            "tree_LOD4"
        ]
    );
    let full = seen[0]["triangles"].as_f64().unwrap();
    let mut coverage = f64::INFINITY;
    for k in 0..5 {
        // Each file holds its level alone, and the group's node says the same of it.
        let triangles = seen[k]["triangles"].as_f64().unwrap();
        let lod = &group["extras"][k]["lod"];
        if k < 4 {
            let aim = full / f64::from(1u32 << k);
            assert!(
                triangles <= aim && triangles >= 0.7 * aim,
                "LOD{k}: {triangles} for {aim}"
            );
            assert!(lod["impostor"].is_null());
        } else {
            assert_eq!(triangles, 4.0, "two crossed cards");
            assert_eq!(lod["impostor"], true);
        }
        assert_eq!(lod["level"], k);
        assert_eq!(lod["levels"], 5);
        assert_eq!(lod["triangles"].as_f64().unwrap(), triangles);
        assert_eq!(seen[k]["nodes"][0], format!("tree_LOD{k}"));
        let c = lod["screen_coverage"].as_f64().unwrap();
        assert!(c < coverage && c > 0.0, "coverage falls level by level");
        coverage = c;
        assert!(
            group["extras"][k]["genome"].is_null(),
            "scene.mjs leaves the genome out"
        );
        assert_eq!(group["extras"][k]["seed"], 0);
    }
    assert!(
        (coverage - 0.01).abs() < 1e-6,
        "the impostor is culled at 1%"
    );
    let handover = group["extras"][3]["lod"]["screen_coverage"]
        .as_f64()
        .unwrap();
    assert!(
        handover <= 0.1 + 1e-6,
        "the impostor takes over at 10% or less"
    );
    // three.js reads the impostor's material as unlit and cut out.
    let material = &seen[4]["materials"][0];
    assert_eq!(material["type"], "MeshBasicMaterial", "{material}");
    assert_eq!(material["alphaTest"], 0.5);
    let bytes = std::fs::metadata(&levels[4]).unwrap().len();
    assert!(bytes < 400_000, "the impostor's file is {bytes} bytes");

    // The same bytes again; with wind, every level rigged and still valid.
    let first = std::fs::read(&tree).unwrap();
    assert!(
        sylva(&[
            "grow",
            &example("lsystem/tree.json"),
            "-o",
            s(&tree),
            "--lod",
            "4"
        ])
        .status
        .success()
    );
    assert_eq!(std::fs::read(&tree).unwrap(), first);
    let windy = dir.join("windy.glb");
    let run = sylva(&[
        "grow",
        &example("plantmaker/flowering-bush.json"),
        "-o",
        s(&windy),
        "--lod",
        "3",
        "--wind",
    ]);
    assert!(run.status.success(), "{run:?}");
    sylva_testkit::validate(&[
        windy.clone(),
        dir.join("windy_LOD2.glb"),
        dir.join("windy_LOD3.glb"),
    ]);

    // Refused before any work: a format without levels, and counts out of range.
    for (output, lod) in [("tree.obj", "3"), ("tree.glb", "1"), ("tree.glb", "9")] {
        let out = dir.join("refused").join(output);
        let run = sylva(&[
            "grow",
            &example("lsystem/tree.json"),
            "-o",
            s(&out),
            "--lod",
            lod,
        ]);
        assert_eq!(run.status.code(), Some(2), "{output} --lod {lod}");
        assert!(String::from_utf8_lossy(&run.stderr).contains("--lod"));
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_strip_of_the_levels_is_drawn_side_by_side() {
    let dir = temp_dir("lod-strip");
    let strip = dir.join("strip.png");
    let run = sylva(&[
        "render",
        &example("bintree/oak.json"),
        "--lod",
        "3",
        "--size",
        "120x100",
        "-o",
        s(&strip),
    ]);
    assert!(run.status.success(), "{run:?}");
    let png = std::fs::read(&strip).unwrap();
    // PNG header: width and height, big-endian, at bytes 16 and 20.
    let width = u32::from_be_bytes(png[16..20].try_into().unwrap());
    assert_eq!(width, 4 * 120, "three levels and the impostor");
    let glb = dir.join("oak.glb");
    assert!(
        sylva(&["grow", &example("bintree/oak.json"), "-o", s(&glb)])
            .status
            .success()
    );
    let run = sylva(&["render", s(&glb), "--lod", "3", "-o", s(&strip)]);
    assert_eq!(run.status.code(), Some(2));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn grow_quantizes_single_plants_and_their_levels() {
    let dir = temp_dir("grow-quantize");
    let plain = dir.join("plain.glb");
    let small = dir.join("small.glb");
    let g = example("lsystem/tree.json");
    assert!(sylva(&["grow", &g, "-o", s(&plain)]).status.success());
    let run = sylva(&["grow", &g, "-o", s(&small), "--quantize", "--lod", "2"]);
    assert!(run.status.success(), "{run:?}");
    let files = [
        plain.clone(),
        small.clone(),
        dir.join("small_LOD0.glb"),
        dir.join("small_LOD1.glb"),
        dir.join("small_LOD2.glb"),
    ];
    sylva_testkit::validate(&files);
    assert!(std::fs::metadata(&files[2]).unwrap().len() < std::fs::metadata(&plain).unwrap().len());
    let seen = three_scene(&files[..3]);
    // Quantised or not, three.js puts the plant in the same place, to a millimetre.
    let (a, b) = (&seen[0]["box"], &seen[2]["box"]);
    for corner in 0..2 {
        for axis in 0..3 {
            let (x, y) = (
                a[corner][axis].as_f64().unwrap(),
                b[corner][axis].as_f64().unwrap(),
            );
            assert!(
                (x - y).abs() < 1e-3,
                "corner {corner}, axis {axis}: {x} and {y}"
            );
        }
    }
    for (output, extra) in [("tree.obj", None), ("tree.glb", Some("--wind"))] {
        let out = dir.join(output);
        let mut args = vec!["grow", &g, "-o", s(&out), "--quantize"];
        args.extend(extra);
        let run = sylva(&args);
        assert_eq!(run.status.code(), Some(2), "{output} {extra:?}");
        assert!(String::from_utf8_lossy(&run.stderr).contains("--quantize"));
    }
    std::fs::remove_dir_all(dir).unwrap();
}
