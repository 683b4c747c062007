//! Plants that look real, through the command line: leaves, needles and bark put on any
//! model's plant (`--foliage`, `--bark`, `--density`), the plausibility report (`sylva
//! inspect`), and every bad input refused naming the flag or field and what it accepts.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;

mod support;
use support::{example, s, sylva, temp_dir};

/// Runs sylva, expecting success; returns stdout.
fn ok(args: &[&str]) -> String {
    let out = sylva(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?}\n{stderr}");
    String::from_utf8(out.stdout).unwrap()
}

/// Runs sylva expecting exit `code` and `mention` in stderr; returns stderr.
fn refused(args: &[&str], code: i32, mention: &str) -> String {
    let out = sylva(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "{args:?}\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stderr.contains(mention),
        "{args:?}: expected {mention:?} in\n{stderr}"
    );
    stderr
}

#[test]
fn dressed_assets_carry_cut_out_leaves_bark_and_their_dress() {
    let dir = temp_dir("realism-dressed");
    let glb = dir.join("oak.glb");
    let out = ok(&[
        "grow",
        &example("bintree/oak.json"),
        "-o",
        s(&glb),
        "--foliage",
        "oak",
        "--height",
        "14",
    ]);
    assert!(out.contains("oak cards on its last twigs"), "{out}");
    let bytes = fs::read(&glb).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    for needle in [
        "\"alphaMode\":\"MASK\"",
        "\"doubleSided\":true",
        "\"normalTexture\"",
        "\"TANGENT\"",
        "sylva-leaves-oak",
        "sylva-bark-furrowed",
        "\"foliage\":\"oak\"",
    ] {
        assert!(text.contains(needle), "no {needle} in the GLB's JSON");
    }
    // Within the game budget for a broadleaf in leaf, and plausible; the GLB inspects as
    // the genome grown with the same flags does.
    let report = ok(&["inspect", s(&glb), "--check", "--json"]);
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    let figure = |name: &str| {
        report["figures"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == name)
            .unwrap()
            .clone()
    };
    assert!(figure("triangles")["value"].as_f64().unwrap() <= 40_000.0);
    assert!(figure("texture_bytes")["value"].as_f64().unwrap() <= 2_000_000.0);
    assert_eq!(figure("leaf_length")["verdict"], "real");
    let genome_report = ok(&[
        "inspect",
        &example("bintree/oak.json"),
        "--foliage",
        "oak",
        "--height",
        "14",
        "--json",
    ]);
    let genome_report: serde_json::Value = serde_json::from_str(&genome_report).unwrap();
    assert_eq!(
        genome_report["figures"][0], report["figures"][0],
        "the same height"
    );
    // OBJ: its MTL cuts the leaves with a mask and names the bark's normal map; every
    // file it names is written beside it.
    let obj = dir.join("pine.obj");
    ok(&[
        "grow",
        &example("plantmaker/conifer.json"),
        "-o",
        s(&obj),
        "--foliage",
        "pine",
    ]);
    let mtl = fs::read_to_string(dir.join("pine.mtl")).unwrap();
    assert!(
        mtl.contains("map_d -clamp on pine_leaves-pine-mask.png"),
        "{mtl}"
    );
    assert!(mtl.contains("norm pine_bark-plated-normal.png"), "{mtl}");
    for line in mtl.lines().filter(|l| l.contains(".png")) {
        let file = line.split_whitespace().last().unwrap();
        assert!(dir.join(file).is_file(), "{file} named but not written");
    }
    // Same flags, same bytes.
    let again = dir.join("again.glb");
    ok(&[
        "grow",
        &example("bintree/oak.json"),
        "-o",
        s(&again),
        "--foliage",
        "oak",
        "--height",
        "14",
    ]);
    assert_eq!(fs::read(&again).unwrap(), bytes);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_dress_and_inspect_input_is_refused_naming_what_is_allowed() {
    let dir = temp_dir("realism-hostile");
    let oak = example("bintree/oak.json");
    let oak = oak.as_str();
    let out = dir.join("x.glb");
    let stderr = refused(
        &["grow", oak, "-o", s(&out), "--foliage", "palm"],
        2,
        "unknown foliage kind `palm`",
    );
    assert!(stderr.contains("oak, birch, aspen"), "{stderr}");
    refused(
        &["grow", oak, "-o", s(&out), "--bark", "cork"],
        2,
        "unknown bark kind `cork`: choose one of smooth, birch, furrowed, plated",
    );
    for density in ["0", "-1", "NaN", "1e40", "5"] {
        let flag = format!("--density={density}");
        refused(
            &["grow", oak, "-o", s(&out), "--foliage", "oak", &flag],
            2,
            "0.25 to 4",
        );
    }
    assert!(!out.exists(), "nothing written");
    // In a config's [output]: the field named, with the kinds allowed.
    let config = dir.join("bad.toml");
    fs::write(&config, "[output]\nfoliage = \"palm\"\n").unwrap();
    refused(&["evolve", s(&config)], 2, "choose one of oak");
    fs::write(&config, "[output]\ndensity = 9\n").unwrap();
    refused(
        &["evolve", s(&config)],
        2,
        "`density` must be a number from 0.25 to 4",
    );
    // A GLB is drawn or inspected as it is: growing flags are refused, naming them.
    let glb = dir.join("oak.glb");
    ok(&["grow", oak, "-o", s(&glb)]);
    refused(
        &[
            "render",
            s(&glb),
            "-o",
            s(&dir.join("x.png")),
            "--foliage",
            "oak",
        ],
        2,
        "--foliage",
    );
    refused(&["inspect", s(&glb), "--height", "3"], 2, "--height");
    // A truncated GLB, a GLB of another generator's (no genome), a malformed genome and a
    // skeleton whose parent comes after its child: exit 2, the file named.
    let bytes = fs::read(&glb).unwrap();
    let cut = dir.join("cut.glb");
    fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    refused(&["inspect", s(&cut)], 2, "cut.glb");
    let bad = dir.join("bad.json");
    fs::write(
        &bad,
        "{\"model\": \"bintree\", \"format\": 1, \"depth\": \"deep\"}",
    )
    .unwrap();
    refused(&["inspect", s(&bad)], 2, "bad.json:1:");
    let skeleton = dir.join("oak.skeleton.json");
    ok(&["grow", oak, "-o", s(&skeleton)]);
    let text = fs::read_to_string(&skeleton).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["segments"][1]["parent"] = serde_json::json!(40);
    fs::write(&skeleton, value.to_string()).unwrap();
    refused(&["inspect", s(&skeleton)], 2, "segments[1]");
    refused(&["inspect", s(&dir.join("missing.glb"))], 2, "missing.glb");
    refused(
        &["inspect", s(&dir.join("plant.png"))],
        2,
        "expected a genome",
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn check_fails_an_implausible_plant_naming_each_figure() {
    // PlantMaker's palm scaled to 30 m: its fronds' leaves grew with it.
    let out = sylva(&[
        "inspect",
        &example("plantmaker/palm.json"),
        "--height",
        "30",
        "--check",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("implausible: leaf_length"), "{stderr}");
    // Dressed with ash leaves, its leaves are a real size: no longer named.
    let out = sylva(&[
        "inspect",
        &example("plantmaker/palm.json"),
        "--height",
        "30",
        "--foliage",
        "ash",
        "--check",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("leaf_length"), "{stderr}");
}

#[test]
fn every_species_preset_is_plausible_and_within_its_budget() {
    // Conifers at most 30,000 triangles, broadleaves 40,000; textures at most 2 MB.
    let species = [
        ("oak", 40_000.0),
        ("birch", 40_000.0),
        ("maple", 40_000.0),
        ("willow", 40_000.0),
        ("pine", 30_000.0),
        ("spruce", 30_000.0),
        ("shrub", 40_000.0),
        ("aspen", 40_000.0),
        ("ash", 40_000.0),
    ];
    for (name, budget) in species {
        let preset = example(&format!("species/{name}.toml"));
        let report = ok(&["inspect", &preset, "--check", "--json"]);
        let report: serde_json::Value = serde_json::from_str(&report).unwrap();
        let value = |figure: &str| {
            report["figures"]
                .as_array()
                .unwrap()
                .iter()
                .find(|f| f["name"] == figure)
                .unwrap()["value"]
                .as_f64()
                .unwrap()
        };
        assert!(
            value("triangles") <= budget,
            "{name}: {}",
            value("triangles")
        );
        assert!(value("texture_bytes") <= 2_000_000.0, "{name}");
    }
}

/// The Sylva-mode tree example, `sylva evolve` without a config (written out in
/// `examples/bintree/default.toml`): its best tree comes out in oak leaves and bark, passes
/// the plausibility report and fits a broadleaf's budget.
#[test]
fn the_default_run_writes_a_dressed_plausible_tree() {
    let dir = temp_dir("realism-default-run");
    let run = dir.join("run");
    ok(&["evolve", "--out", s(&run)]);
    let glb = run.join("best.glb");
    let report = ok(&["inspect", s(&glb), "--check", "--json"]);
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    let figure = |name: &str| {
        report["figures"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == name)
            .unwrap()["value"]
            .as_f64()
    };
    assert!(figure("triangles").unwrap() <= 40_000.0);
    assert!(figure("leaf_length").unwrap() < 0.15, "oak leaves");
    let bytes = fs::read(&glb).unwrap();
    assert!(bytes.windows(16).any(|w| w == b"sylva-leaves-oak"));
    fs::remove_dir_all(&dir).unwrap();
}
