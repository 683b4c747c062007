//! The library's plumbing: errors that name the place and every cause, outputs written
//! together or not at all, the statistics table and plot, and skeleton files' layout and
//! paths.

#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::{Path, PathBuf};

use sylva::error::chain;
use sylva::files::Outputs;
use sylva::report::{fitness_svg, stats_csv};
use sylva::skeleton::{GrowOutput, SUFFIX, is_skeleton_path};
use sylva::{Error, GenerationStats, IndividualId, InputError, Registry, Skeleton};

#[test]
fn positions_count_characters_and_move_to_the_token_start() {
    // Columns count characters, not bytes: "é" is two bytes.
    let text = "a = 1\nbé = 22\nc = 3\n";
    let e = InputError::at(Path::new("g.toml"), text, 2, 6, "bad".into());
    assert_eq!(
        (e.line, e.column, e.location.as_str()),
        (2, 6, "g.toml:2:6")
    );
    // serde_json reports the place just past a bad token: the error points at its start.
    let text = "{\n  \"a\": -0.5,\n}";
    let e = InputError::at(Path::new("g.json"), text, 2, 12, "bad".into());
    assert_eq!(e.location, "g.json:2:8");
    assert_eq!((e.line, e.column), (2, 8));
    // A place past the end is the end; line 0 is a place unknown, the whole file.
    let e = InputError::at(Path::new("g.json"), "x", 9, 9, "bad".into());
    assert_eq!(e.location, "g.json:1:1");
    let e = InputError::at(Path::new("g.json"), text, 0, 0, "bad".into());
    assert_eq!(e.location, "g.json");
}

#[test]
fn a_bad_last_value_is_shown_where_it_stands() {
    let text = "{\n  \"a\": 1,\n  \"b\": -3\n}\n";
    let e = InputError::at(Path::new("g.json"), text, 4, 1, "bad b".into());
    assert_eq!(e.location, "g.json:3:8");
    // A missing field belongs to the whole object: it stays at the bracket.
    let e = InputError::at(Path::new("g.json"), text, 4, 1, "missing field `c`".into());
    assert_eq!(e.location, "g.json:4:1");
}

#[test]
fn location_names_file_line_column() {
    let e = InputError::spanned(Path::new("x.toml"), "a\nbb\n", 3..4, "bad".into());
    assert_eq!(e.to_string(), "x.toml:2:2: bad");
}

#[test]
fn chains_name_every_cause() {
    let e = Error::Io {
        action: "writing",
        path: "x.glb".into(),
        source: std::io::Error::other("disk full"),
    };
    assert_eq!(chain(&e), "writing x.glb: disk full");
}

/// A folder of its own for a test, empty.
fn temp_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("files")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn outputs_appear_together_on_commit() {
    let dir = temp_dir("commit");
    let mut out = Outputs::new();
    out.create_dir(&dir.join("run")).unwrap();
    out.add(&dir.join("run/a.txt"), b"a").unwrap();
    out.add(&dir.join("run/b.txt"), b"b").unwrap();
    assert!(!dir.join("run/a.txt").exists(), "nothing before the commit");
    out.commit().unwrap();
    assert_eq!(std::fs::read(dir.join("run/a.txt")).unwrap(), b"a");
    assert_eq!(std::fs::read_dir(dir.join("run")).unwrap().count(), 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_rename_leaves_no_temporary_file() {
    let dir = temp_dir("rename");
    std::fs::create_dir_all(dir.join("taken.json")).unwrap();
    let mut out = Outputs::new();
    out.add(&dir.join("a.txt"), b"a").unwrap();
    out.add(&dir.join("taken.json"), b"b").unwrap();
    out.add(&dir.join("c.txt"), b"c").unwrap();
    let e = out.commit().unwrap_err();
    assert!(e.to_string().contains("taken.json"), "{e}");
    let mut left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["a.txt", "taken.json"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn dropped_outputs_leave_nothing() {
    let dir = temp_dir("drop");
    {
        let mut out = Outputs::new();
        out.create_dir(&dir.join("run/deep")).unwrap();
        out.add(&dir.join("run/deep/a.txt"), b"a").unwrap();
        // A second file that cannot be written: the command fails.
        assert!(out.add(&dir.join("missing/b.txt"), b"b").is_err());
    }
    assert!(!dir.exists(), "folders made for the outputs go too");
}

fn row(generation: u32, best: f64, mean: f64) -> GenerationStats {
    GenerationStats {
        generation,
        best,
        mean,
        best_id: IndividualId(0),
        best_terms: vec![best / 2.0, best / 2.0],
        evaluations: 10,
        seconds: 0.5,
    }
}

#[test]
fn csv_has_header_and_rows() {
    let csv = stats_csv(
        &["a".into(), "b".into()],
        &[row(0, 1.5, 1.0), row(1, 2.0, 1.25)],
    );
    assert_eq!(
        csv,
        "generation,best,mean,a,b,evals_per_s\n0,1.5,1,0.75,0.75,20\n1,2,1.25,1,1,20\n"
    );
    // A best without terms still fills every column.
    let mut short = row(0, 0.0, 0.0);
    short.best_terms.clear();
    let csv = stats_csv(&["a".into(), "b".into()], &[short]);
    assert_eq!(csv.lines().nth(1), Some("0,0,0,,,20"));
}

#[test]
fn svg_plots_both_lines() {
    let svg = fitness_svg(&[row(0, 1.0, 0.5), row(1, 2.0, 1.0), row(2, 2.5, 2.0)], "t").unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(svg.contains("best") && svg.contains("mean"));
    assert!(svg.matches("<polyline").count() >= 2, "two lines");
    // Degenerate inputs still give a picture.
    assert!(fitness_svg(&[], "empty").is_ok());
    assert!(fitness_svg(&[row(0, f64::NEG_INFINITY, f64::NEG_INFINITY)], "x").is_ok());
}

#[test]
fn skeleton_files_spread_two_levels_and_pack_the_rest() {
    // A trunk and two branches, no organs.
    let text = r#"{"model": "bintree", "format": 1, "depth": 2, "lower_radius": 0.2,
      "upper_radius": 0.15, "length": 1.5, "length_ratio": 0.8,
      "rotation1": {"angle": 30, "axis": [1, 0, 0]},
      "rotation2": {"angle": -30, "axis": [0, 0, 1]}, "min_radius": 0.02}"#;
    let genome = Registry::standard().parse_genome(text).unwrap();
    let plant = genome.develop(genome.default_seed()).unwrap();
    let json = Skeleton::of(&plant, &genome, None, false).to_json();
    let lines: Vec<&str> = json.lines().collect();
    // The file's fields one a line, indented two spaces; each segment and material on a
    // line of its own, indented four, compact; an empty list stays on its field's line.
    assert_eq!((lines[0], *lines.last().unwrap()), ("{", "}"));
    assert!(lines.contains(&"  \"organs\": []"), "{json}");
    let segments: Vec<&&str> = lines
        .iter()
        .filter(|l| l.starts_with("    {\"start\":"))
        .collect();
    assert_eq!(segments.len(), plant.segments().len(), "{json}");
    assert!(
        segments
            .iter()
            .all(|l| !l.contains(": ") && !l.contains(", ")),
        "{json}"
    );
    for l in &lines[1..lines.len() - 1] {
        assert!(l.starts_with("  "), "{l}");
    }
    let back: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(
        back["segments"].as_array().unwrap().len(),
        plant.segments().len()
    );
    assert!(json.ends_with("}\n"));
}

#[test]
fn skeleton_paths_by_their_ending() {
    assert!(is_skeleton_path(Path::new("out/oak.skeleton.json")));
    assert!(is_skeleton_path(Path::new("OAK.Skeleton.JSON")));
    assert!(!is_skeleton_path(Path::new("oak.json")));
    assert!(!is_skeleton_path(Path::new("skeleton.json.glb")));
    assert_eq!(
        GrowOutput::of(Path::new("a.glb")).unwrap(),
        GrowOutput::Asset(sylva::export::Format::Glb)
    );
    assert_eq!(
        GrowOutput::of(Path::new("a.skeleton.json")).unwrap(),
        GrowOutput::Skeleton
    );
    let e = GrowOutput::of(Path::new("a.json")).unwrap_err();
    assert!(
        e.message.contains("\".json\"") && e.message.contains(SUFFIX),
        "{e}"
    );
    let e = GrowOutput::of(Path::new("a")).unwrap_err();
    assert!(e.message.contains("no extension"), "{e}");
}
