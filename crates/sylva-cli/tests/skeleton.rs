//! `sylva grow GENOME -o PLANT.skeleton.json`, the grown plant as data, through the real
//! binary: every example of the four models, the same bytes twice, the pipe model's taper
//! seen from outside, roots, and paths that cannot be written.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::Path;

mod support;
use support::{example, s, sylva, temp_dir};

use serde_json::Value;
use sylva::skeleton::Skeleton;

/// Runs `sylva grow` and returns the segments and organs it reports
/// ("wrote X: N segments, M organs, ...").
fn grow(args: &[&str]) -> (usize, usize) {
    let mut all = vec!["grow"];
    all.extend_from_slice(args);
    let out = sylva(&all);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{all:?}\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let count = |what: &str| {
        let words: Vec<&str> = stdout
            .split(|c: char| c.is_whitespace() || c == ',')
            .collect();
        let at = words.iter().position(|w| *w == what).unwrap();
        words[at - 1].parse::<usize>().unwrap()
    };
    (count("segments"), count("organs"))
}

/// Files in `dir`, sorted.
fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Every rule a skeleton file keeps, checked on the file as written.
fn check(name: &str, path: &Path) -> Skeleton {
    let text = fs::read_to_string(path).unwrap();
    let value: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(value["format"], 1, "{name}");
    assert_eq!(value["kind"], "sylva-skeleton", "{name}");
    // The stable field order, and one segment per line.
    let keys: Vec<&str> = value
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    let mut sorted = keys.clone();
    sorted.sort_by_key(|k| text.find(&format!("\n  \"{k}\": ")).unwrap());
    assert_eq!(
        sorted,
        [
            "format",
            "kind",
            "sylva_version",
            "origin",
            "taper",
            "roots",
            "materials",
            "segments",
            "organs"
        ],
        "{name}"
    );
    let skeleton = Skeleton::read(path).unwrap();
    assert_eq!(
        text.lines()
            .filter(|l| l.starts_with("    {\"start\":"))
            .count(),
        skeleton.segments.len(),
        "{name}: one segment a line"
    );
    // Read back and written again, the same bytes: floats are in their shortest round-trip
    // form and nothing is lost.
    assert_eq!(skeleton.to_json(), text, "{name}");

    let genome: Value = serde_json::from_str(&fs::read_to_string(example(name)).unwrap()).unwrap();
    assert_eq!(skeleton.origin.model, genome["model"].as_str().unwrap());
    assert_eq!(skeleton.origin.genome["model"], genome["model"]);
    assert_eq!(skeleton.origin.genome_hash.len(), 16, "{name}");
    assert!(
        skeleton
            .origin
            .genome_hash
            .chars()
            .all(|c| c.is_ascii_hexdigit())
    );
    let materials = &skeleton.materials;
    for (i, seg) in skeleton.segments.iter().enumerate() {
        let at = format!("{name}: segment {i}");
        assert!(finite(&seg.start) && finite(&seg.end), "{at}");
        for r in [seg.start_radius, seg.end_radius] {
            assert!(r.is_finite() && r > 0.0, "{at}: radius {r}");
        }
        match seg.parent {
            None => assert!(!seg.lateral && seg.order == 0, "{at}"),
            Some(p) => {
                assert!((p as usize) < i, "{at}: parent {p} is not earlier");
                let parent = &skeleton.segments[p as usize];
                assert_eq!(seg.order, parent.order + u16::from(seg.lateral), "{at}");
            }
        }
        let material = &materials[seg.material as usize];
        assert_eq!(seg.kind, material.kind, "{at}");
        let woody = matches!(seg.kind, sylva::core::MaterialKind::Bark)
            || matches!(seg.kind, sylva::core::MaterialKind::Root);
        assert_eq!(seg.woody, woody, "{at}");
    }
    for (i, organ) in skeleton.organs.iter().enumerate() {
        let at = format!("{name}: organ {i}");
        assert!(
            finite(&organ.position) && finite(&organ.orientation),
            "{at}"
        );
        assert!(organ.length >= 0.0 && organ.width >= 0.0, "{at}");
        let norm = |v: &[f32]| v.iter().map(|x| x * x).sum::<f32>().sqrt();
        assert!((norm(&organ.orientation) - 1.0).abs() < 1e-4, "{at}");
        assert!((norm(&organ.axis) - 1.0).abs() < 1e-4, "{at}");
        assert!((norm(&organ.normal) - 1.0).abs() < 1e-4, "{at}");
        if let Some(p) = organ.parent {
            assert!((p as usize) < skeleton.segments.len(), "{at}");
        }
        assert!((organ.material as usize) < materials.len(), "{at}");
    }
    skeleton
}

const EXAMPLES: [&str; 10] = [
    "bintree/oak.json",
    "automata/helix.json",
    "plantmaker/fern.json",
    "plantmaker/palm.json",
    "plantmaker/flowering-bush.json",
    "plantmaker/tulip.json",
    "plantmaker/conifer.json",
    "lsystem/bush.json",
    "lsystem/herb.json",
    "lsystem/tree.json",
];

#[test]
fn every_example_genome_exports_its_skeleton_the_same_twice() {
    let dir = temp_dir("examples");
    for name in EXAMPLES {
        let stem = name.replace('/', "-").replace(".json", "");
        let glb = dir.join(format!("{stem}.glb"));
        let path = dir.join(format!("{stem}.skeleton.json"));
        let meshed = grow(&[&example(name), "-o", s(&glb)]);
        let written = grow(&[&example(name), "-o", s(&path)]);
        assert_eq!(written, meshed, "{name}: what grow reports for the mesh");
        let skeleton = check(name, &path);
        assert_eq!(
            (skeleton.segments.len(), skeleton.organs.len()),
            meshed,
            "{name}"
        );
        assert!(!skeleton.segments.is_empty(), "{name}");
        assert_eq!(skeleton.taper, None);
        assert!(skeleton.roots);
        let first = fs::read(&path).unwrap();
        grow(&[&example(name), "-o", s(&path)]);
        assert_eq!(fs::read(&path).unwrap(), first, "{name}: same bytes twice");
    }
    // Nothing but the files asked for.
    assert_eq!(files_in(&dir).len(), 2 * EXAMPLES.len());
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn with_a_picture_the_skeleton_keeps_its_bytes() {
    // `--png` grows and meshes the plant; without it only the skeleton is grown. Both give
    // the same file, with the seed, the taper and the roots as asked.
    let dir = temp_dir("png");
    let name = "plantmaker/fern.json";
    let args = ["--seed", "7", "--taper", "2.2", "--hide-roots"];
    let plain = dir.join("plain.skeleton.json");
    let pictured = dir.join("pictured.skeleton.json");
    let mut with_png = vec![example(name), "-o".into(), s(&pictured).into()];
    with_png.extend(["--png".into(), s(&dir.join("fern.png")).into()]);
    with_png.extend(args.iter().map(|a| a.to_string()));
    let mut without = vec![example(name), "-o".into(), s(&plain).into()];
    without.extend(args.iter().map(|a| a.to_string()));
    grow(&with_png.iter().map(String::as_str).collect::<Vec<_>>());
    grow(&without.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(fs::read(&plain).unwrap(), fs::read(&pictured).unwrap());
    assert!(fs::metadata(dir.join("fern.png")).unwrap().len() > 0);
    let skeleton = check(name, &plain);
    assert_eq!(skeleton.origin.seed, 7);
    assert!(!skeleton.roots);
    assert_eq!(skeleton.taper.unwrap().pipe_exponent, 2.2);
    fs::remove_dir_all(&dir).unwrap();
}

/// What the pipe model promises, read from the file alone: no woody segment ends thicker
/// than it starts, no woody child starts thicker than its woody parent starts, and an axis
/// thins without steps (a continuation starts as its parent ends). So along any path from a
/// foot to a tip the wood never thickens. Returns how many parent-child links were checked.
fn never_thickens(name: &str, skeleton: &Skeleton) -> usize {
    let segments = &skeleton.segments;
    let mut links = 0;
    for (i, seg) in segments.iter().enumerate().filter(|(_, s)| s.woody) {
        assert!(seg.end_radius <= seg.start_radius, "{name}: segment {i}");
        let Some(p) = seg.parent else { continue };
        let parent = &segments[p as usize];
        if !parent.woody {
            continue;
        }
        assert!(
            seg.start_radius <= parent.start_radius,
            "{name}: segment {i}"
        );
        if !seg.lateral {
            assert_eq!(seg.start_radius, parent.end_radius, "{name}: segment {i}");
        }
        links += 1;
    }
    links
}

#[test]
fn the_pipe_taper_never_thickens_from_a_segment_to_its_child() {
    let dir = temp_dir("taper");
    let name = "automata/helix.json";
    let plain = dir.join("plain.skeleton.json");
    let tapered = dir.join("tapered.skeleton.json");
    grow(&[&example(name), "-o", s(&plain)]);
    grow(&[&example(name), "-o", s(&tapered), "--taper", "2.5"]);
    let plain = check(name, &plain);
    let skeleton = check(name, &tapered);
    assert_eq!(skeleton.taper.unwrap().pipe_exponent, 2.5);
    assert_eq!(skeleton.segments.len(), plain.segments.len());
    assert_ne!(
        skeleton.segments, plain.segments,
        "the taper changed the radii"
    );
    let segments = &skeleton.segments;
    assert!(segments.iter().all(|s| s.woody), "the helix is all wood");
    assert_eq!(never_thickens(name, &skeleton), segments.len() - 1);
    // On the helix each branch also starts no thicker than where its parent ends (its
    // laterals carry fewer tips than the axis they leave).
    for (i, seg) in segments.iter().enumerate() {
        if let Some(p) = seg.parent {
            let parent = &segments[p as usize];
            assert!(seg.start_radius <= parent.end_radius, "segment {i}");
        }
    }
    // The trunk carries every tip: the foot is the thickest.
    let foot = segments[0].start_radius;
    assert!(segments.iter().all(|s| s.start_radius <= foot));
    // A plant of wood, leaves and roots: only the wood is re-thickened and checked.
    let name = "lsystem/tree.json";
    let tree = dir.join("tree.skeleton.json");
    grow(&[&example(name), "-o", s(&tree), "--taper", "2"]);
    let skeleton = check(name, &tree);
    assert!(skeleton.segments.iter().any(|s| !s.woody));
    assert!(never_thickens(name, &skeleton) > 100);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn roots_are_in_the_skeleton_unless_hidden() {
    let dir = temp_dir("roots");
    let name = "lsystem/herb.json";
    let with = dir.join("with.skeleton.json");
    let without = dir.join("without.skeleton.json");
    grow(&[&example(name), "-o", s(&with)]);
    let hidden = grow(&[&example(name), "-o", s(&without), "--hide-roots"]);
    let meshed = grow(&[&example(name), "-o", s(&dir.join("h.glb")), "--hide-roots"]);
    assert_eq!(hidden, meshed);
    let is_root = |k| k == sylva::core::MaterialKind::Root;
    let with = check(name, &with);
    let without = check(name, &without);
    assert!(with.roots && !without.roots);
    let roots = with.segments.iter().filter(|s| is_root(s.kind)).count();
    assert!(roots > 0);
    assert!(!without.segments.iter().any(|s| is_root(s.kind)));
    assert_eq!(without.segments.len() + roots, with.segments.len());
    fs::remove_dir_all(&dir).unwrap();
}

/// Runs `sylva grow` on the oak to `output` (and more flags); expects `code` and `mention`
/// in what it says.
fn refused(output: &Path, more: &[&str], code: i32, mention: &str) {
    let oak = example("bintree/oak.json");
    let mut args = vec!["grow", &oak, "-o", s(output)];
    args.extend_from_slice(more);
    let out = sylva(&args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stderr.contains(mention),
        "{args:?}: {mention:?} not in\n{stderr}"
    );
}

#[test]
fn paths_that_cannot_be_written_are_refused_and_leave_nothing() {
    let dir = temp_dir("paths");
    // A folder where the file should go: refused before any work, as bad input.
    let folder = dir.join("taken.skeleton.json");
    fs::create_dir(&folder).unwrap();
    refused(&folder, &[], 2, "is a folder");
    // The same for meshes.
    let glb_folder = dir.join("taken.glb");
    fs::create_dir(&glb_folder).unwrap();
    refused(&glb_folder, &[], 2, "is a folder");
    // A file where a folder should be, and a folder that does not exist: the path is named.
    let file = dir.join("plain-file");
    fs::write(&file, "x").unwrap();
    let under_file = file.join("oak.skeleton.json");
    refused(&under_file, &[], 1, s(&under_file));
    let nowhere = dir.join("missing/oak.skeleton.json");
    refused(&nowhere, &[], 1, s(&nowhere));
    // A picture that cannot be written: the skeleton does not appear either.
    let beside = dir.join("oak.skeleton.json");
    let png = dir.join("missing/oak.png");
    refused(&beside, &["--png", s(&png)], 1, s(&png));
    // A plain `.json` is not taken for a skeleton; the error says how to ask for one.
    refused(&dir.join("oak.json"), &[], 2, ".skeleton.json");
    // A skeleton over the memory budget is refused with its estimate.
    refused(&beside, &["--max-memory", "100K"], 2, "--max-memory");
    assert_eq!(
        files_in(&dir),
        ["plain-file", "taken.glb", "taken.skeleton.json"]
    );
    assert!(files_in(&folder).is_empty() && files_in(&glb_folder).is_empty());
    // And a genome is not read as a skeleton.
    let e = Skeleton::read(Path::new(&example("bintree/oak.json"))).unwrap_err();
    assert!(e.to_string().contains("not a skeleton file"), "{e}");
    fs::remove_dir_all(&dir).unwrap();
}
