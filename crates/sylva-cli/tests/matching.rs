//! `sylva match` as a designer drives it: a picture in, a plant whose outline matches it
//! out, with every file `sylva evolve` writes and `overlay.png`; the same target, seed and
//! generations give the same bytes; a run resumes after it stops as if it never had, and
//! an auto match killed during its trials resumes from the trials it kept; and a bad
//! picture gets exit code 2 naming the file, with nothing written.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;

mod support;
use support::{example, ok, s, sylva, temp_dir};

fn target() -> PathBuf {
    PathBuf::from(example("match/round.png"))
}

/// A quick match of the round target by binary trees, `generations` long, into `out`.
fn quick(out: &Path, generations: &str, resume: bool) -> Output {
    let mut args = vec![
        "match",
        s(&target()).to_owned().leak(),
        "--model",
        "bintree",
        "--generations",
        generations,
        "--population",
        "16",
        "--seed",
        "3",
        "--out",
        s(out),
    ];
    if resume {
        args.push("--resume");
    }
    sylva(&args)
}

/// Every file of a run as bytes, but for wall-clock seconds (`stats.csv`'s last column,
/// the checkpoint).
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
        .into_iter()
        .map(|name| {
            let bytes = fs::read(dir.join(&name)).unwrap();
            let bytes = match name.as_str() {
                // The checkpoint and the trials' log hold wall-clock seconds.
                "checkpoint.json" | "trials.json" => Vec::new(),
                "stats.csv" => String::from_utf8(bytes)
                    .unwrap()
                    .lines()
                    .map(|l| l.rsplit_once(',').map_or(l, |(a, _)| a).to_owned() + "\n")
                    .collect::<String>()
                    .into_bytes(),
                _ => bytes,
            };
            (name, bytes)
        })
        .collect()
}

#[test]
fn a_match_writes_every_file_the_same_each_time_and_resumes() {
    let dir = temp_dir("files");
    let (first, second, resumed) = (dir.join("a"), dir.join("b"), dir.join("c"));
    let said = ok(&quick(&first, "12", false));
    assert!(said.contains("outline IoU"), "{said}");
    let names: Vec<String> = files(&first).into_iter().map(|(n, _)| n).collect();
    for name in [
        "best.glb",
        "best.json",
        "best.png",
        "checkpoint.json",
        "config.toml",
        "fitness.svg",
        "overlay.png",
        "population.png",
        "stats.csv",
    ] {
        assert!(
            names.contains(&name.to_owned()),
            "{name} missing: {names:?}"
        );
    }
    let stats = fs::read_to_string(first.join("stats.csv")).unwrap();
    assert!(stats.starts_with("generation,best,mean,iou,"), "{stats}");
    assert_eq!(
        stats.lines().count(),
        14,
        "a header and generations 0 to 12"
    );
    let config = fs::read_to_string(first.join("config.toml")).unwrap();
    assert!(
        config.contains("[match]") && config.contains("beside = false"),
        "{config}"
    );
    assert!(config.contains("generations = 12"), "{config}");
    // The same target, seed and generations: the same bytes.
    ok(&quick(&second, "12", false));
    // Stopped at 5 and resumed to 12: as if it never stopped.
    ok(&quick(&resumed, "5", false));
    ok(&quick(&resumed, "12", true));
    let (a, b, c) = (files(&first), files(&second), files(&resumed));
    for ((name, x), ((_, y), (_, z))) in a.iter().zip(b.iter().zip(&c)) {
        assert!(x == y, "{name} differs between two equal runs");
        assert!(x == z, "{name} differs after a resume");
    }
}

#[test]
fn bad_pictures_are_refused_naming_the_file_and_nothing_is_written() {
    let dir = temp_dir("bad");
    let text = dir.join("notes.png");
    fs::write(&text, "this is not a picture\n").unwrap();
    let blank = dir.join("blank.png");
    // A white picture: two empty outlines without a caption.
    let white = sylva::render::overlay::overlay(40, 40, 1, |_, _| false, |_, _| false, "");
    fs::write(&blank, sylva::render::encode_png(&white).unwrap()).unwrap();
    let missing = dir.join("missing.png");
    for (file, expected) in [
        (&text, "not a PNG or JPEG picture"),
        (&blank, "no ink"),
        (&missing, "missing.png"),
    ] {
        let out = dir.join("out");
        let output = sylva(&["match", s(file), "--generations", "1", "--out", s(&out)]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(s(file)), "{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
        assert!(!out.exists(), "nothing is written for {}", file.display());
    }
    // A threshold out of range is refused by name.
    let output = sylva(&["match", s(&target()), "--threshold", "1.5"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("luminance"));
    // So are rows the outlines cannot be compared at.
    for rows in ["8", "513", "-1", "many"] {
        let output = sylva(&["match", s(&target()), &format!("--rows={rows}")]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("--rows"), "{stderr}");
    }
    // Rows it can are the run's `[match] rows`.
    let out = dir.join("rows");
    let args = [
        "--model",
        "bintree",
        "--generations",
        "1",
        "--population",
        "8",
    ];
    let output = sylva(
        &[
            &["match", s(&target()), "--rows", "32", "--out", s(&out)],
            &args[..],
        ]
        .concat(),
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let config = fs::read_to_string(out.join("config.toml")).unwrap();
    assert!(config.contains("rows = 32"), "{config}");
}

#[test]
fn height_scales_the_best_plants_assets_and_is_recorded() {
    let dir = temp_dir("height");
    let out = dir.join("run");
    let target = target();
    let args = [
        "match",
        s(&target),
        "--model",
        "bintree",
        "--generations",
        "2",
        "--population",
        "8",
        "--height",
        "7",
        "--topiary",
        "--out",
        s(&out),
    ];
    ok(&sylva(&args));
    let config = fs::read_to_string(out.join("config.toml")).unwrap();
    assert!(config.contains("height = 7.0"), "{config}");
    assert!(config.contains("topiary = true"), "{config}");
    let glb = fs::read(out.join("best.glb")).unwrap();
    assert!(String::from_utf8_lossy(&glb).contains("\"height\":7.0"));
    // The genome is the plant as evolved; its assets are scaled, and (a topiary match's)
    // pruned to the outline as `grow --pruned-to` prunes it.
    let grown = dir.join("grown.glb");
    let best = out.join("best.json");
    let config = out.join("config.toml");
    let grow = |more: &[&str]| {
        let mut args = vec!["grow", s(&best), "-o", s(&grown), "--height", "7"];
        args.extend(more);
        ok(&sylva(&args));
        fs::read(&grown).unwrap()
    };
    assert_eq!(grow(&["--pruned-to", s(&config)]), glb);
    assert_ne!(grow(&[]), glb, "the match pruned its plant");
    let evolve = dir.join("evolve.toml");
    fs::write(&evolve, "model = \"bintree\"\n").unwrap();
    let refused = sylva(&["grow", s(&best), "-o", s(&grown), "--pruned-to", s(&evolve)]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("evolve.toml"));
    for bad in ["0", "-1", "nan", "1e9"] {
        let flag = format!("--height={bad}");
        let refused = sylva(&["grow", s(&best), "-o", s(&grown), &flag]);
        assert_eq!(refused.status.code(), Some(2), "{bad}");
        let stderr = String::from_utf8_lossy(&refused.stderr);
        assert!(
            stderr.contains("--height") && stderr.contains("0.01 to 1000"),
            "{stderr}"
        );
    }
}

#[test]
fn a_population_too_large_for_the_seconds_is_refused_on_time() {
    // Generation 0 of 200,000 plants takes minutes on any machine; the match's one second
    // bounds it (and each model's trial), so it ends with a clear error, not hours later.
    let dir = temp_dir("huge-population");
    for model in ["plantmaker", "auto"] {
        let out = dir.join(model);
        let output = sylva(&[
            "match",
            s(&target()),
            "--model",
            model,
            "--population",
            "200000",
            "--seconds",
            "1",
            "--out",
            s(&out),
        ]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{model}: {stderr}");
        assert!(stderr.contains("population"), "{model}: {stderr}");
        assert!(!out.exists(), "{model}: nothing is written");
    }
}

#[test]
fn an_out_folder_that_is_a_file_is_refused_before_the_run() {
    // Checked first: a minute of breeding is not lost to it at the end.
    let dir = temp_dir("out-is-a-file");
    let file = dir.join("taken");
    fs::write(&file, "a file\n").unwrap();
    for out in [file.clone(), file.join("run")] {
        for args in [
            vec!["match", s(&target()), "--generations", "1"],
            vec!["evolve", "--generations", "1"],
        ] {
            let output = sylva(&[&args[..], &["--out", s(&out)]].concat());
            let stderr = String::from_utf8_lossy(&output.stderr);
            assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(stderr.contains("is a file, not a folder"), "{stderr}");
            assert!(stderr.contains(s(&file)), "{stderr}");
            assert!(
                !stderr.contains("generation"),
                "refused before breeding: {stderr}"
            );
        }
    }
    assert_eq!(fs::read_to_string(&file).unwrap(), "a file\n");
}

/// An auto match of the round target, counting generations, into `out`.
fn auto_args(out: &Path) -> Vec<String> {
    [
        "match",
        s(&target()),
        "--generations",
        "25",
        "--population",
        "6",
        "--seed",
        "4",
        "--out",
        s(out),
    ]
    .map(str::to_owned)
    .to_vec()
}

#[test]
fn an_auto_match_killed_during_its_trials_resumes_from_them_to_the_same_bytes() {
    use std::process::{Command, Stdio};
    use std::time::Duration;
    let dir = temp_dir("auto-killed");
    let (whole, killed) = (dir.join("whole"), dir.join("killed"));
    let args = auto_args(&whole);
    let said = sylva(&args.iter().map(String::as_str).collect::<Vec<_>>());
    ok(&said);
    // The trials' generations are recorded, every model's that bred.
    let csv = fs::read_to_string(whole.join("trials.csv")).unwrap();
    assert!(
        csv.starts_with("model,phase,generation,best,mean,iou\n"),
        "{csv}"
    );
    for model in ["bintree", "automata", "plantmaker", "grown"] {
        let first = csv
            .lines()
            .filter(|l| l.starts_with(&format!("{model},trial,")))
            .count();
        assert_eq!(first, 3, "{model}: generations 0 to 2 of its trial\n{csv}");
    }
    assert_eq!(
        csv.lines().filter(|l| l.contains(",runoff,")).count(),
        6,
        "{csv}"
    );
    // Killed (SIGKILL) as soon as the first trial is kept, while the others are bred.
    let mut child = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(auto_args(&killed))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let log = killed.join("trials.json");
    while child.try_wait().unwrap().is_none() && !log.exists() {
        std::thread::sleep(Duration::from_millis(1));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let kept: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&log).expect("the trials kept a log")).unwrap();
    assert!(
        kept.get("chosen").is_none(),
        "killed after the trials: {kept}"
    );
    assert!(!killed.join("checkpoint.json").exists());
    // The same command with --resume goes on from the trials kept, to the same bytes.
    let mut again = auto_args(&killed);
    again.push("--resume".to_owned());
    let resumed = sylva(&again.iter().map(String::as_str).collect::<Vec<_>>());
    ok(&resumed);
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(
        stderr.contains("auto: bintree reached") && stderr.contains("(kept in trials.json)"),
        "{stderr}"
    );
    let (a, b) = (files(&whole), files(&killed));
    assert_eq!(
        a.iter().map(|f| &f.0).collect::<Vec<_>>(),
        b.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{name} differs after a kill during the trials");
    }
    // A log is resumed by its own match only.
    let mut other = auto_args(&killed);
    other[5] = "7".to_owned();
    fs::write(&log, serde_json::to_string(&kept).unwrap()).unwrap();
    other.push("--resume".to_owned());
    let refused = sylva(&other.iter().map(String::as_str).collect::<Vec<_>>());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("trials.json") && stderr.contains("population of 6, not 7"),
        "{stderr}"
    );
    fs::remove_dir_all(&dir).unwrap();
}
