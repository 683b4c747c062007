//! The command line as a user drives it: runs write every file, results are deterministic
//! whatever the thread count, runs resume after a kill, and bad input gets exit code 2 with
//! an error that names the file, line, column and field, leaving no output behind.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sylva::core::hash::stable_hash;

use sylva_testkit::validate;

fn sylva(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(args)
        .output()
        .expect("the sylva binary runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sylva-cli-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn ok(output: &Output) {
    assert!(
        output.status.success(),
        "exit {:?}\nstdout: {}\nstderr: {}",
        output.status.code(),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A small, quick config.
const SMALL: &str = "[run]\ngenerations = 12\npopulation = 40\nseed = 7\n\n[output]\nimage_size = 96\nsheet_size = 6\n";

/// `stats.csv` without its wall-clock column.
fn stats_without_timing(dir: &Path) -> String {
    fs::read_to_string(dir.join("stats.csv"))
        .unwrap()
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_owned() + "\n")
        .collect()
}

#[test]
fn evolve_writes_every_file_and_grow_reproduces_the_glb() {
    let dir = temp_dir("files");
    let config = dir.join("small.toml");
    fs::write(&config, SMALL).unwrap();
    let out = dir.join("run");
    ok(&sylva(&["evolve", s(&config), "--out", s(&out)]));
    for file in [
        "stats.csv",
        "best.json",
        "best.glb",
        "best.png",
        "fitness.svg",
        "population.png",
        "config.toml",
        "checkpoint.json",
    ] {
        let len = fs::metadata(out.join(file)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{file} written");
    }
    let stats = fs::read_to_string(out.join("stats.csv")).unwrap();
    let mut lines = stats.lines();
    assert_eq!(
        lines.next().unwrap(),
        "generation,best,mean,surface_to_volume,symmetry,radius_to_length,volume,height,\
         straightness,pipe_model,roundness,evals_per_s"
    );
    assert_eq!(lines.count(), 13, "generations 0 to 12");
    // No temporary files are left behind.
    for entry in fs::read_dir(&out).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        assert!(!name.ends_with(".tmp"), "{name}");
    }

    let regrown = dir.join("regrown.glb");
    ok(&sylva(&[
        "grow",
        s(&out.join("best.json")),
        "-o",
        s(&regrown),
    ]));
    assert_eq!(
        fs::read(&regrown).unwrap(),
        fs::read(out.join("best.glb")).unwrap(),
        "sylva grow best.json gives the bytes the run wrote"
    );
    validate(&[out.join("best.glb"), regrown.clone()]);

    // A GLB renders as it is, and like the genome it came from.
    let from_glb = dir.join("from-glb.png");
    let from_json = dir.join("from-json.png");
    ok(&sylva(&[
        "render",
        s(&regrown),
        "-o",
        s(&from_glb),
        "--size",
        "96x96",
    ]));
    ok(&sylva(&[
        "render",
        s(&out.join("best.json")),
        "-o",
        s(&from_json),
        "--size",
        "96x96",
    ]));
    assert_eq!(fs::read(&from_glb).unwrap(), fs::read(&from_json).unwrap());
    let broken = dir.join("broken.glb");
    fs::write(&broken, &fs::read(&regrown).unwrap()[..100]).unwrap();
    let refused = sylva(&["render", s(&broken), "-o", s(&dir.join("b.png"))]);
    assert_eq!(refused.status.code(), Some(2));
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn same_results_on_one_or_two_threads_and_golden() {
    let dir = temp_dir("threads");
    let config = dir.join("small.toml");
    fs::write(&config, SMALL).unwrap();
    let runs: Vec<PathBuf> = ["1", "2"]
        .iter()
        .map(|threads| {
            let out = dir.join(format!("t{threads}"));
            ok(&sylva(&[
                "evolve",
                s(&config),
                "--out",
                s(&out),
                "--threads",
                threads,
            ]));
            out
        })
        .collect();
    assert_eq!(
        stats_without_timing(&runs[0]),
        stats_without_timing(&runs[1])
    );
    for file in ["best.json", "best.glb", "best.png"] {
        assert_eq!(
            fs::read(runs[0].join(file)).unwrap(),
            fs::read(runs[1].join(file)).unwrap(),
            "{file}"
        );
    }
    // Golden values: any change to the model, the engine, the mesher or the exporter that
    // changes results shows here. Update them only for an intended change.
    let hash = |name: &str| stable_hash(&fs::read(runs[0].join(name)).unwrap());
    let stats_hash = stable_hash(stats_without_timing(&runs[0]).as_bytes());
    validate(&[runs[0].join("best.glb")]);
    let golden = (stats_hash, hash("best.json"), hash("best.glb"));
    assert_eq!(golden, GOLDEN, "{golden:#x?}");
    fs::remove_dir_all(&dir).unwrap();
}

const GOLDEN: (u64, u64, u64) = (
    0x629d_55af_3752_0bb2,
    0x2810_836f_7727_2b53,
    0x1d25_3038_9dae_fe45,
);

#[test]
fn a_killed_run_resumes_exactly() {
    let dir = temp_dir("resume");
    let config = dir.join("c.toml");
    fs::write(
        &config,
        "[run]\ngenerations = 100000\npopulation = 30\nseed = 3\ncheckpoint_seconds = 0\n\
         [output]\nimage_size = 64\nsheet_size = 2\n",
    )
    .unwrap();
    // Start a long run and kill it once it has checkpointed a few generations.
    let out = dir.join("killed");
    let mut child = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(["evolve", s(&config), "--out", s(&out)])
        .spawn()
        .unwrap();
    let checkpoint = out.join("checkpoint.json");
    let generation_saved = |path: &Path| -> Option<u64> {
        let text = fs::read_to_string(path).ok()?;
        let v: serde_json::Value = serde_json::from_str(&text).ok()?;
        v["checkpoint"]["generation"].as_u64()
    };
    while generation_saved(&checkpoint).unwrap_or(0) < 5 {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before it checkpointed generation 5"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let saved = generation_saved(&checkpoint).unwrap();
    let target = (saved + 10).to_string();

    // Resume to a target, and compare with a run that was never interrupted.
    ok(&sylva(&[
        "evolve",
        s(&config),
        "--out",
        s(&out),
        "--resume",
        "--generations",
        &target,
    ]));
    let straight = dir.join("straight");
    ok(&sylva(&[
        "evolve",
        s(&config),
        "--out",
        s(&straight),
        "--generations",
        &target,
    ]));
    assert_eq!(stats_without_timing(&out), stats_without_timing(&straight));
    assert_eq!(
        fs::read(out.join("best.json")).unwrap(),
        fs::read(straight.join("best.json")).unwrap()
    );
    validate(&[out.join("best.glb"), straight.join("best.glb")]);

    // A different config refuses to resume.
    let other = dir.join("other.toml");
    fs::write(&other, "[run]\npopulation = 31\nseed = 3\n").unwrap();
    let refused = sylva(&["evolve", s(&other), "--out", s(&out), "--resume"]);
    assert_eq!(refused.status.code(), Some(2));
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn grow_writes_obj_mtl_vrml_and_png() {
    let dir = temp_dir("formats");
    let genome = dir.join("tree.json");
    fs::write(&genome, include_str!("../../../examples/bintree/oak.json")).unwrap();
    ok(&sylva(&[
        "grow",
        s(&genome),
        "-o",
        s(&dir.join("t.obj")),
        "--png",
        s(&dir.join("t.png")),
    ]));
    let obj = fs::read_to_string(dir.join("t.obj")).unwrap();
    assert!(obj.contains("mtllib t.mtl"));
    assert!(
        fs::read_to_string(dir.join("t.mtl"))
            .unwrap()
            .contains("newmtl")
    );
    assert!(fs::metadata(dir.join("t.png")).unwrap().len() > 1000);
    ok(&sylva(&["grow", s(&genome), "-o", s(&dir.join("t.wrl"))]));
    assert!(
        fs::read_to_string(dir.join("t.wrl"))
            .unwrap()
            .starts_with("#VRML V2.0 utf8")
    );
    for view in ["front", "side", "top", "iso"] {
        let png = dir.join(format!("{view}.png"));
        ok(&sylva(&[
            "render",
            s(&genome),
            "-o",
            s(&png),
            "--view",
            view,
            "--size",
            "120x90",
        ]));
        let bytes = fs::read(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        // Width and height sit in the IHDR chunk.
        assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 120);
        assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), 90);
    }
    fs::remove_dir_all(&dir).unwrap();
}

/// Runs `sylva grow` on a genome text; expects exit code 2, an error naming `location` and
/// mentioning `what`, and no output file.
fn bad_genome(text: &str, location: &str, what: &str) {
    let dir = temp_dir("bad-genome");
    let genome = dir.join("g.json");
    fs::write(&genome, text).unwrap();
    let glb = dir.join("out.glb");
    let out = sylva(&["grow", s(&genome), "-o", s(&glb)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{text}\n{stderr}");
    let expected = format!("{}:{location}", genome.display());
    assert!(
        stderr.contains(&expected),
        "{text}\nexpected {expected} in\n{stderr}"
    );
    assert!(names_line_and_column(&stderr, &genome), "{stderr}");
    assert!(
        stderr.contains(what),
        "{text}\nexpected {what:?} in\n{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!glb.exists(), "no output is written");
    fs::remove_dir_all(&dir).unwrap();
}

/// True when the error names `path:LINE:COLUMN:`.
fn names_line_and_column(stderr: &str, path: &Path) -> bool {
    let prefix = format!("{}:", path.display());
    stderr.split(&prefix).skip(1).any(|rest| {
        let mut parts = rest.splitn(3, ':');
        let line = parts.next().unwrap_or("");
        let column = parts.next().unwrap_or("");
        !line.is_empty()
            && !column.is_empty()
            && line.chars().all(|c| c.is_ascii_digit())
            && column.chars().all(|c| c.is_ascii_digit())
    })
}

const GOOD: &str = include_str!("../../../examples/bintree/oak.json");

#[test]
fn bad_genomes_are_refused_with_position_and_field() {
    let field = |name: &str, value: &str| {
        let mut done = false;
        GOOD.lines()
            .map(|l| {
                if !done && l.trim_start().starts_with(&format!("\"{name}\"")) {
                    done = true;
                    let indent = &l[..l.len() - l.trim_start().len()];
                    let comma = if l.trim_end().ends_with(',') { "," } else { "" };
                    format!("{indent}\"{name}\": {value}{comma}\n")
                } else {
                    format!("{l}\n")
                }
            })
            .collect::<String>()
    };
    let line_of = |name: &str| {
        GOOD.lines()
            .position(|l| l.trim_start().starts_with(&format!("\"{name}\"")))
            .unwrap()
            + 1
    };
    let depth = line_of("depth");
    let radius = line_of("lower_radius");
    bad_genome(
        &field("lower_radius", "-0.3"),
        &format!("{radius}:"),
        "lower_radius",
    );
    bad_genome(&field("lower_radius", "1e999"), &format!("{radius}:"), "");
    bad_genome(&field("depth", "100"), &format!("{depth}:"), "depth");
    bad_genome(&field("depth", "2.5"), &format!("{depth}:"), "");
    bad_genome(&field("depth", "\"deep\""), &format!("{depth}:"), "");
    bad_genome(
        &field("length", "0"),
        &format!("{}:", line_of("length")),
        "length",
    );
    bad_genome(
        &GOOD.replacen("\"depth\"", "\"dept\"", 1),
        &format!("{depth}:"),
        "unknown field `dept`",
    );
    bad_genome(
        &GOOD.replacen("\"bintree\"", "\"oak\"", 1),
        "2:",
        "unknown model `oak`",
    );
    bad_genome(
        &GOOD.replacen("\"format\": 1", "\"format\": 2", 1),
        "3:",
        "format",
    );
    bad_genome(&GOOD[..GOOD.len() / 2], "", "EOF");
    bad_genome("", "1:", "EOF");
    bad_genome("[1, 2]", "1:", "");
    let zero_axis = GOOD.replacen(
        &GOOD[GOOD.find("\"axis\"").unwrap()..GOOD.find(']').unwrap() + 1],
        "\"axis\": [0, 0, 0]",
        1,
    );
    bad_genome(&zero_axis, "", "zero vector");
}

#[test]
fn bad_configs_and_flags_are_refused() {
    let dir = temp_dir("bad-config");
    let config = dir.join("c.toml");
    let out = dir.join("run");
    for (text, location, what) in [
        ("[run]\npopulation = -3\n", "2:14", "population"),
        ("[bintree.weights]\nvolume = nan\n", "2:10", "weight"),
        (
            "[run]\npopulaton = 10\n",
            "2:1",
            "unknown field `populaton`",
        ),
        ("[output]\nview = \"back\"\n", "2:8", "iso"),
        ("[run\n", "1:", ""),
        (
            "model = \"automata\"\n[automata.growth]\nroot_length = -1\n",
            "3:15",
            "root_length",
        ),
        (
            "model = \"automata\"\n[automata.fitness]\nendpoints = \"leaves\"\n",
            "3:13",
            "axes",
        ),
    ] {
        fs::write(&config, text).unwrap();
        let o = sylva(&["evolve", s(&config), "--out", s(&out)]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{text}\n{stderr}");
        let expected = format!("{}:{location}", config.display());
        assert!(
            stderr.contains(&expected),
            "{text}\nexpected {expected} in\n{stderr}"
        );
        assert!(names_line_and_column(&stderr, &config), "{stderr}");
        assert!(stderr.contains(what), "{text}\n{stderr}");
        assert!(!out.join("stats.csv").exists());
    }
    let missing = sylva(&["evolve", s(&dir.join("none.toml"))]);
    assert_eq!(missing.status.code(), Some(2));
    for args in [
        vec!["evolve", "--population", "0"],
        vec!["evolve", "--generations", "-1"],
        vec!["evolve", "--threads", "lots"],
        vec!["render", "x.json", "-o", "x.png", "--size", "0x10"],
        vec!["render", "x.json", "-o", "x.png", "--view", "back"],
        vec!["frobnicate"],
    ] {
        assert_eq!(sylva(&args).status.code(), Some(2), "{args:?}");
    }
    let genome = dir.join("g.json");
    fs::write(&genome, GOOD).unwrap();
    let wrong_ext = sylva(&["grow", s(&genome), "-o", s(&dir.join("tree.fbx"))]);
    assert_eq!(wrong_ext.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&wrong_ext.stderr).contains("fbx"));
    fs::remove_dir_all(&dir).unwrap();
}

fn example(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(path)
}

#[test]
fn every_example_genome_grows_into_a_valid_glb() {
    let dir = temp_dir("examples");
    let mut glbs = Vec::new();
    for name in [
        "bintree/oak.json",
        "automata/helix.json",
        "plantmaker/fern.json",
        "plantmaker/palm.json",
        "plantmaker/flowering-bush.json",
        "plantmaker/tulip.json",
        "plantmaker/conifer.json",
        "lsystem/bush.json",
        "lsystem/herb.json",
    ] {
        let glb = dir.join(name.replace('/', "-").replace(".json", ".glb"));
        let out = sylva(&["grow", s(&example(name)), "-o", s(&glb)]);
        ok(&out);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(!stdout.contains(" 0 triangles"), "{name}: {stdout}");
        glbs.push(glb);
    }
    validate(&glbs);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_garden_file_regrows_the_same_scene() {
    let dir = temp_dir("garden");
    let forest = dir.join("forest.glb");
    ok(&sylva(&[
        "garden",
        s(&example("plantmaker/conifer.json")),
        s(&example("plantmaker/fern.json")),
        "--count",
        "4",
        "--area",
        "20x20",
        "--seed",
        "3",
        "-o",
        s(&forest),
    ]));
    let garden = dir.join("forest.garden.json");
    let again = dir.join("again.glb");
    ok(&sylva(&["garden", s(&garden), "-o", s(&again)]));
    assert_eq!(fs::read(&forest).unwrap(), fs::read(&again).unwrap());
    validate(&[forest]);
    // Too many plants for the plot is bad input, not a crash.
    let crowded = sylva(&[
        "garden",
        s(&example("plantmaker/conifer.json")),
        "--count",
        "500",
        "--area",
        "3x3",
        "-o",
        s(&dir.join("crowded.glb")),
    ]);
    assert_eq!(crowded.status.code(), Some(2));
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_herbs_under_a_tree_grow_less() {
    let dir = temp_dir("simulate");
    let out = sylva(&[
        "simulate",
        s(&example("lsystem/herbs-under-tree.toml")),
        "--out",
        s(&dir),
    ]);
    ok(&out);
    let report = fs::read_to_string(dir.join("report.txt")).unwrap();
    let ratio: f64 = report
        .lines()
        .find_map(|l| l.strip_prefix("biomass ratio shaded/open: "))
        .unwrap()
        .parse()
        .unwrap();
    assert!(ratio < 0.6, "{report}");
    assert!(
        fs::read_to_string(dir.join("records.csv"))
            .unwrap()
            .lines()
            .count()
            > 10
    );
    validate(&[dir.join("scene.glb")]);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn automata_runs_write_their_table_2_columns() {
    let dir = temp_dir("automata");
    let config = dir.join("a.toml");
    let text = fs::read_to_string(example("automata/box-above.toml"))
        .unwrap()
        .replace("generations = 100", "generations = 3")
        .replace("population = 1000", "population = 200")
        .replace("sheet_size = 24", "sheet_size = 2\nimage_size = 64");
    fs::write(&config, text).unwrap();
    let out = dir.join("run");
    ok(&sylva(&["evolve", s(&config), "--out", s(&out)]));
    let stats = fs::read_to_string(out.join("stats.csv")).unwrap();
    assert!(
        stats.starts_with(
            "generation,best,mean,branches,leaves,forbidden_leaves,f_pos,f_num,f_dist,f_angle,\
             f_thick,f_grid,f_total,evals_per_s"
        ),
        "{stats}"
    );
    assert_eq!(stats.lines().count(), 5);
    validate(&[out.join("best.glb")]);
    // The same run on one thread: same stats and bytes (the per-thread buffers of the
    // simulator, fitness and breeding carry nothing between individuals).
    let serial = dir.join("serial");
    ok(&sylva(&[
        "evolve",
        s(&config),
        "--out",
        s(&serial),
        "--threads",
        "1",
    ]));
    assert_eq!(stats_without_timing(&out), stats_without_timing(&serial));
    assert_eq!(
        fs::read(out.join("best.glb")).unwrap(),
        fs::read(serial.join("best.glb")).unwrap()
    );
    ok(&sylva(&[
        "grow",
        s(&out.join("best.json")),
        "-o",
        s(&dir.join("regrown.glb")),
    ]));
    assert_eq!(
        fs::read(out.join("best.glb")).unwrap(),
        fs::read(dir.join("regrown.glb")).unwrap()
    );
    fs::remove_dir_all(&dir).unwrap();
}

/// Runs an automata example as shipped (small pictures only); returns its stats rows.
fn automata_example_stats(name: &str, dir: &Path) -> Vec<Vec<f64>> {
    automata_example_run(name, dir, None)
}

/// Runs an automata example as shipped, with its own seed or another, into
/// `dir/NAME` (`dir/NAME-seedS` for another seed); returns its stats rows.
fn automata_example_run(name: &str, dir: &Path, seed: Option<u64>) -> Vec<Vec<f64>> {
    let config = dir.join(name);
    let text = fs::read_to_string(example(&format!("automata/{name}")))
        .unwrap()
        .replace("sheet_size = 24", "sheet_size = 2\nimage_size = 64");
    fs::write(&config, text).unwrap();
    let stem = name.replace(".toml", "");
    let out = match seed {
        Some(seed) => dir.join(format!("{stem}-seed{seed}")),
        None => dir.join(stem),
    };
    let seed = seed.map(|s| s.to_string());
    let mut args = vec!["evolve", s(&config), "--out", s(&out)];
    if let Some(seed) = &seed {
        args.extend(["--seed", seed.as_str()]);
    }
    ok(&sylva(&args));
    fs::read_to_string(out.join("stats.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// The bar for Poncin's runs, met by the examples as shipped (docs/automata.md):
/// the sphere run gets past the two-endpoint trap, and the box-above run keeps its leaves out
/// of the forbidden cells.
#[test]
fn the_automata_examples_beat_the_trap_and_avoid_the_box() {
    let dir = temp_dir("automata-examples");
    // Columns: generation, best, mean, branches, leaves, forbidden_leaves, f_pos, f_num, …
    let (branches, leaves, forbidden, f_pos, f_num) = (3, 4, 5, 6, 7);
    let sphere = automata_example_stats("sphere.toml", &dir);
    assert_eq!(sphere.len(), 51, "1000 individuals for 50 generations");
    assert!(
        sphere[10][branches] >= 10.0,
        "generation 10: {:?}",
        sphere[10]
    );
    assert!(sphere[50][f_num] <= 2.0, "generation 50: {:?}", sphere[50]);
    assert!(sphere[50][f_pos] <= 20.0, "generation 50: {:?}", sphere[50]);
    let box_above = automata_example_stats("box-above.toml", &dir);
    let last = &box_above[box_above.len() - 1];
    assert_eq!(box_above.len(), 101);
    assert!(last[leaves] > 0.0 && last[forbidden] == 0.0, "{last:?}");
    // Two levels: 8 branches with 4 sub-branches on each by generation 50, with the
    // shipped seed (20) and another.
    for seed in [None, Some(7)] {
        let two_levels = automata_example_run("two-levels.toml", &dir, seed);
        assert_eq!(
            two_levels[50][f_num], 0.0,
            "seed {seed:?}: {:?}",
            two_levels[50]
        );
    }
    fs::remove_dir_all(&dir).unwrap();
}

/// Issue 14's taper bars on a grown skeleton, checked from outside as a user would: along
/// every path from the foot through woody segments the radius never grows and no step is
/// to less than half; returns the thickest tip as a share of the foot.
fn taper_bars(skeleton: &sylva::skeleton::Skeleton) -> Result<f32, String> {
    let segments = &skeleton.segments;
    let foot = segments
        .iter()
        .filter(|s| s.woody && s.parent.is_none())
        .map(|s| s.start_radius)
        .fold(0.0, f32::max);
    let mut continued = vec![false; segments.len()];
    // Radii are 32-bit floats: equal thicknesses may differ in the last bit.
    let eps = 1e-6;
    for (i, s) in segments.iter().enumerate().filter(|(_, s)| s.woody) {
        let mut chain = vec![s.start_radius, s.end_radius];
        if let Some(p) = s.parent.map(|p| p as usize).filter(|&p| segments[p].woody) {
            continued[p] = true;
            chain.insert(0, segments[p].end_radius);
        }
        for w in chain.windows(2) {
            if w[1] > w[0] * (1.0 + eps) {
                return Err(format!("segment {i} thickens: {chain:?}"));
            }
            if w[1] < 0.5 * w[0] * (1.0 - eps) {
                return Err(format!("segment {i} steps to less than half: {chain:?}"));
            }
        }
    }
    let tips = segments
        .iter()
        .zip(&continued)
        .filter(|(s, c)| s.woody && !**c);
    Ok(tips.map(|(s, _)| s.end_radius / foot).fold(0.0, f32::max))
}

/// Figure 17's pine as shipped: the shape bar for its cone (F_num at most 2, F_pos at most
/// 20) at its last generation, leaves, and the taper bars on the grown tree (issue 14).
#[test]
fn the_pine_example_tapers_and_fits_its_cone() {
    let dir = temp_dir("automata-pine");
    let (leaves, f_pos, f_num) = (4, 6, 7);
    // The shipped seed (3). Other seeds are measured in docs/automata.md (17 of 24 meet
    // both bars); a second seed here cost CI 47 s.
    let pine = automata_example_run("pine.toml", &dir, None);
    let last = &pine[pine.len() - 1];
    assert_eq!(pine.len(), 101);
    assert!(last[f_num] <= 2.0 && last[f_pos] <= 20.0, "{last:?}");
    assert!(last[leaves] > 0.0, "a pine with leaves: {last:?}");
    let skeleton = dir.join("pine.skeleton.json");
    ok(&sylva(&[
        "grow",
        s(&dir.join("pine").join("best.json")),
        "-o",
        s(&skeleton),
    ]));
    let skeleton = sylva::skeleton::Skeleton::read(&skeleton).unwrap();
    let tip = taper_bars(&skeleton).unwrap_or_else(|e| panic!("{e}"));
    assert!(tip <= 0.25 + 1e-5, "the thickest tip is {tip} of the foot");
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plantmaker_evolves_without_a_person() {
    let dir = temp_dir("plantmaker-evolve");
    let config = dir.join("p.toml");
    let text = fs::read_to_string(example("plantmaker/evolve.toml"))
        .unwrap()
        .replace("generations = 30", "generations = 3")
        .replace("population = 120", "population = 16")
        .replace(
            "start = [\"flowering-bush.json\"]",
            &format!(
                "start = [{:?}]",
                example("plantmaker/tulip.json").display().to_string()
            ),
        )
        .replace("sheet_size = 16", "sheet_size = 2\nimage_size = 64");
    fs::write(&config, text).unwrap();
    let out = dir.join("run");
    ok(&sylva(&["evolve", s(&config), "--out", s(&out)]));
    let stats = fs::read_to_string(out.join("stats.csv")).unwrap();
    assert_eq!(stats.lines().count(), 5);
    let best: f64 = stats
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let first: f64 = stats
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert!(best >= first, "elitism keeps the best: {first} then {best}");
    validate(&[out.join("best.glb")]);
    // The best genome grows again into the same asset with its own seed.
    ok(&sylva(&[
        "grow",
        s(&out.join("best.json")),
        "-o",
        s(&dir.join("again.glb")),
    ]));
    assert_eq!(
        fs::read(out.join("best.glb")).unwrap(),
        fs::read(dir.join("again.glb")).unwrap()
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn lsystem_plants_breed_and_evolve() {
    let dir = temp_dir("lsystem");
    // One round of the design loop: nine specimens, each with its genome file.
    let round = dir.join("round1");
    ok(&sylva(&[
        "breed",
        s(&example("lsystem/herb.json")),
        "--out",
        s(&round),
        "--hide-roots",
    ]));
    let table = fs::read_to_string(round.join("specimens.csv")).unwrap();
    assert_eq!(table.lines().count(), 10, "{table}");
    validate(&[round.join("garden.glb")]);
    // The next round breeds a chosen child.
    ok(&sylva(&[
        "breed",
        s(&round.join("child-3.json")),
        "--out",
        s(&dir.join("round2")),
        "--children",
        "2",
    ]));
    // Hiding roots removes segments.
    let count = |args: &[&str]| -> usize {
        let out = sylva(args);
        ok(&out);
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        text.split(": ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let herb = example("lsystem/herb.json");
    let glb = dir.join("h.glb");
    let all = count(&["grow", s(&herb), "-o", s(&glb)]);
    let shoot = count(&["grow", s(&herb), "-o", s(&glb), "--hide-roots"]);
    assert!(shoot < all, "{shoot} < {all}");
    // Evolution without a person, from empty rules, selecting biomass.
    let config = dir.join("e.toml");
    let text = fs::read_to_string(example("lsystem/evolve.toml"))
        .unwrap()
        .replace("generations = 15", "generations = 2")
        .replace("population = 24", "population = 6")
        .replace(
            "start = \"herb.json\"",
            &format!(
                "start = {:?}",
                example("lsystem/herb.json").display().to_string()
            ),
        )
        .replace("sheet_size = 12", "sheet_size = 2")
        .replace("image_size = 600", "image_size = 64");
    fs::write(&config, text).unwrap();
    let out = dir.join("run");
    ok(&sylva(&["evolve", s(&config), "--out", s(&out)]));
    let stats = fs::read_to_string(out.join("stats.csv")).unwrap();
    assert!(
        stats.starts_with("generation,best,mean,biomass,light,uptake"),
        "{stats}"
    );
    validate(&[out.join("best.glb")]);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn docs_genomes_is_the_output_of_sylva_schema() {
    let out = sylva(&["schema"]);
    ok(&out);
    let doc = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/genomes.md");
    let written = fs::read_to_string(&doc).unwrap_or_default();
    assert!(
        written == String::from_utf8(out.stdout).unwrap(),
        "docs/genomes.md is not what `sylva schema` prints: run \
         `cargo run -- schema > docs/genomes.md`"
    );
}

#[test]
fn schema_as_json_and_for_an_unknown_model() {
    let out = sylva(&["schema", "grown", "--json"]);
    ok(&out);
    let schema: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let height = schema["fields"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["path"] == "parameters.height")
        .unwrap();
    assert_eq!(
        (height["min"].as_f64(), height["max"].as_f64()),
        (Some(1.0), Some(40.0))
    );
    let out = sylva(&["schema", "oak"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("MODEL") && err.contains("no model is named \"oak\""),
        "{err}"
    );
}
