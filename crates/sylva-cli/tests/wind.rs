#![allow(clippy::unwrap_used)]
//! `--wind` on `sylva grow` and `sylva garden`, and `[output] wind` in evolution configs:
//! validator-clean GLBs that three.js plays; bad wind flags refused before any work.

use std::path::{Path, PathBuf};
use std::process::Command;

mod support;
use support::{example, sylva, temp_dir as temp};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn three_plays(files: &[PathBuf]) {
    let out = Command::new("node")
        .arg(root().join("tools/three-check/wind.mjs"))
        .args(files)
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn grow_garden_and_evolve_write_wind_that_plays() {
    let dir = temp("ok");
    let tree = dir.join("tree.glb");
    let out = sylva(&[
        "grow",
        &example("lsystem/tree.json"),
        "-o",
        tree.to_str().unwrap(),
        "--wind",
        "--wind-strength",
        "2",
        "--wind-period",
        "3",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("clip `wind` of 3 s"));
    let garden = dir.join("garden.glb");
    let out = sylva(&[
        "garden",
        &example("plantmaker/tulip.json"),
        "--count",
        "4",
        "-o",
        garden.to_str().unwrap(),
        "--wind",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let config = dir.join("c.toml");
    let text = std::fs::read_to_string(root().join("examples/bintree/default.toml")).unwrap();
    std::fs::write(&config, format!("{text}wind = {{ strength = 1.5 }}\n")).unwrap();
    let run = dir.join("run");
    let out = sylva(&[
        "evolve",
        config.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--generations",
        "2",
        "--population",
        "40",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let effective = std::fs::read_to_string(run.join("config.toml")).unwrap();
    assert!(effective.contains("[output.wind]") && effective.contains("strength = 1.5"));
    let files = [tree, garden, run.join("best.glb")];
    sylva_testkit::validate(&files);
    three_plays(&files);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_draws_a_strip_of_the_wind_clip() {
    let dir = temp("strip");
    let png = dir.join("strip.png");
    let palm = example("plantmaker/palm.json");
    let args = [
        "render",
        &palm,
        "-o",
        png.to_str().unwrap(),
        "--wind",
        "--wind-frames",
        "4",
        "--size",
        "400x100",
    ];
    let out = sylva(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let first = std::fs::read(&png).unwrap();
    assert_eq!(&first[1..4], b"PNG");
    // The frames differ from a strip of the plant at rest (strength 0), and repeat exactly.
    let still = dir.join("still.png");
    let mut calm = args.to_vec();
    calm[3] = still.to_str().unwrap();
    calm.extend(["--wind-strength", "0"]);
    assert!(sylva(&calm).status.success());
    assert_ne!(std::fs::read(&still).unwrap(), first);
    assert!(sylva(&args).status.success());
    assert_eq!(std::fs::read(&png).unwrap(), first);
    for bad in [
        &["--wind-frames", "1"][..],
        &["--wind-frames", "33"],
        &["--wind-frames", "4", "--wind-period", "0.1"],
    ] {
        let mut a = vec![
            "render",
            palm.as_str(),
            "-o",
            png.to_str().unwrap(),
            "--wind",
        ];
        a.extend_from_slice(bad);
        assert_eq!(sylva(&a).status.code(), Some(2), "{bad:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_wind_is_refused_before_any_work() {
    let dir = temp("bad");
    let glb = dir.join("x.glb");
    let obj = dir.join("x.obj");
    let cases: [(&[&str], &str); 5] = [
        (
            &["-o", obj.to_str().unwrap(), "--wind"],
            "wind needs a .glb",
        ),
        (
            &[
                "-o",
                glb.to_str().unwrap(),
                "--wind",
                "--wind-strength",
                "11",
            ],
            "--wind-strength",
        ),
        (
            &[
                "-o",
                glb.to_str().unwrap(),
                "--wind",
                "--wind-strength",
                "NaN",
            ],
            "--wind-strength",
        ),
        (
            &["-o", glb.to_str().unwrap(), "--wind", "--wind-period", "0"],
            "--wind-period",
        ),
        (
            &["-o", glb.to_str().unwrap(), "--wind-period", "3"],
            "--wind",
        ),
    ];
    for (args, says) in cases {
        let oak = example("bintree/oak.json");
        let mut all = vec!["grow", oak.as_str()];
        all.extend_from_slice(args);
        let out = sylva(&all);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains(says),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(!glb.exists() && !obj.exists(), "{args:?} wrote a file");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
