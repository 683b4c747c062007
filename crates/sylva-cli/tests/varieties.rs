//! `sylva evolve` of a MAP-Elites config: a map of varieties with its table, genomes and
//! picture; the same config and seed give the same bytes; a run stopped and resumed
//! gives what a straight run gives; a bad `[map]` gets exit code 2 at its line, with
//! nothing written.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::Path;
use std::process::Output;

mod support;
use support::{ok, s, sylva, temp_dir};

const CONFIG: &str = "model = \"bintree\"\n\n[run]\nstrategy = \"map-elites\"\nseed = 5\n\n[map]\ninitial = 20\nbatch = 10\ndescriptors = [{ name = \"height_to_width\", cells = 4 }, { name = \"porosity\", cells = 3 }]\n\n[output]\nimage_size = 128\n";

/// A map run of [`CONFIG`] in `dir`, `generations` long.
fn quick(dir: &Path, generations: &str, resume: bool) -> Output {
    let config = dir.join("map.toml");
    fs::write(&config, CONFIG).unwrap();
    let out = dir.join("run");
    let mut args = vec![
        "evolve",
        s(&config),
        "--generations",
        generations,
        "--out",
        s(&out),
    ];
    if resume {
        args.push("--resume");
    }
    sylva(&args)
}

/// Every file of a run (and of its `archive/`) as bytes, but the checkpoint (it keeps
/// wall-clock seconds).
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut found = Vec::new();
    for sub in ["", "archive"] {
        for entry in fs::read_dir(dir.join(sub)).unwrap() {
            let entry = entry.unwrap();
            let name = Path::new(sub).join(entry.file_name());
            if entry.path().is_file() && !name.ends_with("checkpoint.json") {
                found.push((name.display().to_string(), fs::read(entry.path()).unwrap()));
            }
        }
    }
    found.sort();
    found
}

#[test]
fn a_map_run_writes_its_table_genomes_and_picture() {
    let dir = temp_dir("writes");
    let stdout = ok(&quick(&dir, "6", false));
    assert!(stdout.contains("of 12 cells filled"), "{stdout}");
    let run = dir.join("run");
    let csv = fs::read_to_string(run.join("archive.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with(
            "cell,height_to_width_cell,porosity_cell,height_to_width,porosity,fitness,"
        ) && header.ends_with(",id,genome"),
        "{header}"
    );
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert!(!rows.is_empty());
    // Each row's genome file is there, and there are no others.
    for row in &rows {
        let file = row.rsplit(',').next().unwrap();
        assert!(run.join(file).is_file(), "{file}");
    }
    assert_eq!(
        fs::read_dir(run.join("archive")).unwrap().count(),
        rows.len()
    );
    let stats = fs::read_to_string(run.join("stats.csv")).unwrap();
    assert!(stats.starts_with("generation,filled,coverage,qd_score,"));
    assert_eq!(stats.lines().count(), 1 + 7);
    let last: Vec<&str> = stats.lines().last().unwrap().split(',').collect();
    assert_eq!(last[1], rows.len().to_string());
    for file in ["archive.png", "best.png"] {
        assert!(fs::read(run.join(file)).unwrap().starts_with(b"\x89PNG"));
    }
    assert!(fs::read(run.join("best.glb")).unwrap().starts_with(b"glTF"));
    let config = fs::read_to_string(run.join("config.toml")).unwrap();
    assert!(config.contains("strategy = \"map-elites\"") && config.contains("[map]"));
}

#[test]
fn the_same_map_twice_gives_the_same_bytes_and_a_resumed_map_the_straight_ones() {
    let (a, b, c) = (temp_dir("a"), temp_dir("b"), temp_dir("c"));
    ok(&quick(&a, "8", false));
    ok(&quick(&b, "8", false));
    assert_eq!(files(&a.join("run")), files(&b.join("run")));
    ok(&quick(&c, "3", false));
    ok(&quick(&c, "8", true));
    assert_eq!(files(&a.join("run")), files(&c.join("run")));
}

#[test]
fn a_bad_map_exits_2_at_its_line_with_nothing_written() {
    let dir = temp_dir("bad");
    let config = dir.join("map.toml");
    let text = CONFIG.replace("\"porosity\"", "\"leafiness\"");
    fs::write(&config, text).unwrap();
    let out = dir.join("run");
    let output = sylva(&["evolve", s(&config), "--out", s(&out)]);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("map.toml:10") && stderr.contains("leafiness"),
        "{stderr}"
    );
    assert!(!out.exists());
}
