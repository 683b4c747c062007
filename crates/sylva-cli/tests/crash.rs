//! Crash safety: `sylva evolve` killed with SIGKILL at twenty moments of a run of each model
//! resumes from its checkpoint and ends with the same `best.json` and `stats.csv` (less
//! timing) as the run that was never interrupted; no checkpoint is ever unreadable.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sylva-crash-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn evolve(config: &Path, out: &Path, resume: bool) {
    let mut args = vec!["evolve", s(config), "--out", s(out)];
    if resume {
        args.push("--resume");
    }
    let output = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(&args)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// `stats.csv` without its wall-clock column, and `best.json`.
fn results(out: &Path) -> (String, String) {
    let stats = fs::read_to_string(out.join("stats.csv"))
        .unwrap()
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_owned() + "\n")
        .collect();
    (stats, fs::read_to_string(out.join("best.json")).unwrap())
}

/// The generation the checkpoint in `out` has saved, if there is one yet.
fn saved_generation(out: &Path) -> Option<u64> {
    let text = fs::read_to_string(out.join("checkpoint.json")).ok()?;
    let saved: serde_json::Value = serde_json::from_str(&text).ok()?;
    saved["checkpoint"]["generation"].as_u64()
}

/// Runs `config` straight, then kills it at twenty moments spread over that run's
/// generations and resumes each. The moments are chosen by progress (the generation the
/// checkpoint has reached), not by the clock, so a busy machine gives the same verdict.
fn killed_runs_resume_exactly(name: &str, config_text: &str) {
    let dir = temp_dir(name);
    let config = dir.join("c.toml");
    fs::write(&config, config_text).unwrap();
    let straight = dir.join("straight");
    evolve(&config, &straight, false);
    let expected = results(&straight);
    let generations = expected.0.lines().count().saturating_sub(1) as u64;
    // Moments spread over the run, jittered by a fixed sequence (repeatable): wait for the
    // checkpoint of generation `target`, then kill after a few more microseconds, which
    // lands anywhere in the next generation's work or its checkpoint write.
    let mut jitter = 0x9e37_79b9_u32;
    let (mut resumed, mut waited) = (0, 0);
    for i in 0..20u32 {
        jitter = jitter.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let target = u64::from(i) * generations / 20;
        let out = dir.join(format!("killed-{i}"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_sylva"))
            .args(["evolve", s(&config), "--out", s(&out)])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        if target > 0 {
            waited += 1;
            while child.try_wait().unwrap().is_none()
                && saved_generation(&out).is_none_or(|g| g < target)
            {
                std::thread::sleep(Duration::from_millis(1));
            }
        }
        std::thread::sleep(Duration::from_micros(u64::from(jitter >> 20) * 10));
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
        let checkpoint = out.join("checkpoint.json");
        let resume = checkpoint.exists();
        if resume {
            resumed += 1;
            let text = fs::read_to_string(&checkpoint).unwrap();
            let saved: serde_json::Value = serde_json::from_str(&text)
                .unwrap_or_else(|e| panic!("{name}: kill {i} left an unreadable checkpoint: {e}"));
            assert!(
                saved["checkpoint"]["generation"].is_u64(),
                "{name}: kill {i}"
            );
        }
        evolve(&config, &out, resume);
        let leftovers: Vec<_> = fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty(), "{name}: kill {i} left {leftovers:?}");
        assert!(
            results(&out) == expected,
            "{name}: the run killed after generation {target} of {generations} ended differently"
        );
    }
    // Every kill that waited for a checkpoint really resumes.
    eprintln!("{name}: {resumed} of 20 killed runs resumed from a checkpoint");
    assert!(
        resumed >= waited,
        "{name}: only {resumed} of 20 kills came after a checkpoint"
    );
    fs::remove_dir_all(&dir).unwrap();
}

/// Checkpoints every generation and draws small pictures.
const RUN: &str = "checkpoint_seconds = 0\nseed = 3\n";
const OUTPUT: &str = "[output]\nimage_size = 64\nsheet_size = 2\n";

#[test]
fn binary_tree_runs_survive_kills() {
    killed_runs_resume_exactly(
        "bintree",
        &format!("[run]\n{RUN}generations = 150\npopulation = 60\n{OUTPUT}"),
    );
}

#[test]
fn automata_runs_survive_kills() {
    killed_runs_resume_exactly(
        "automata",
        &format!(
            "model = \"automata\"\n[run]\n{RUN}generations = 20\npopulation = 60\n{OUTPUT}\
             [automata.growth]\niterations = 40\n"
        ),
    );
}

#[test]
fn plantmaker_runs_survive_kills() {
    killed_runs_resume_exactly(
        "plantmaker",
        &format!("model = \"plantmaker\"\n[run]\n{RUN}generations = 15\npopulation = 12\n{OUTPUT}"),
    );
}

#[test]
fn lsystem_runs_survive_kills() {
    killed_runs_resume_exactly(
        "lsystem",
        &format!(
            "model = \"lsystem\"\n[run]\n{RUN}generations = 8\npopulation = 6\n{OUTPUT}\
             [lsystem.grow]\nsteps = 30\n[lsystem.grow.world]\nsize = [24, 24, 24]\n\
             soil_layers = 8\n"
        ),
    );
}
