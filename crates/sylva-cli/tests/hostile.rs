//! Hostile and huge input through the command line: every refusal is clean (exit code 2, the
//! file and what was expected, no panic), bounded, and leaves no output behind.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::Path;
use std::process::{Command, Output};

mod support;
use support::{example, s, sylva, temp_dir};

/// Runs sylva and expects a clean refusal: `code`, no panic, and `mention` in what it says.
fn refused(args: &[&str], code: i32, mention: &str) -> String {
    let out = sylva(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "{args:?}\n{stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}\n{stderr}");
    assert!(
        stderr.contains(mention),
        "{args:?}: expected {mention:?} in\n{stderr}"
    );
    stderr
}

/// Files left in `dir`.
fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn errors_far_along_a_long_line_print_a_short_snippet() {
    let dir = temp_dir("long-lines");
    let oak = fs::read_to_string(example("bintree/oak.json")).unwrap();
    let genome: serde_json::Value = serde_json::from_str(&oak).unwrap();
    let one_line = serde_json::to_string(&genome).unwrap();
    let padded = one_line
        .replacen(",", &format!(",{}", " ".repeat(200_000)), 1)
        .replace("\"min_radius\":0.02", "\"min_radius\":-5");
    let path = dir.join("long.json");
    fs::write(&path, padded).unwrap();
    let stderr = refused(
        &["grow", s(&path), "-o", s(&dir.join("x.glb"))],
        2,
        "min_radius",
    );
    assert!(stderr.len() < 3000, "{} bytes of error", stderr.len());
    assert!(stderr.contains("long.json:1:2"), "{stderr}");
    // The same in a config, with a huge number.
    let config = dir.join("long.toml");
    let text = format!("[bintree]\nmutation_rate = {}\n", "9".repeat(100_000));
    fs::write(&config, text).unwrap();
    let stderr = refused(&["evolve", s(&config)], 2, "long.toml:2:17");
    assert!(stderr.len() < 3000, "{} bytes of error", stderr.len());
    assert_eq!(files_in(&dir), ["long.json", "long.toml"]);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn devices_folders_and_byte_order_marks() {
    let dir = temp_dir("files");
    let glb = dir.join("x.glb");
    if Path::new("/dev/zero").exists() {
        refused(&["grow", "/dev/zero", "-o", s(&glb)], 2, "at most");
    }
    refused(&["grow", s(&dir), "-o", s(&glb)], 2, "folder");
    // A byte-order mark, as some editors write, is read past.
    let bom = dir.join("bom.json");
    let text = format!(
        "\u{feff}{}",
        fs::read_to_string(example("bintree/oak.json")).unwrap()
    );
    fs::write(&bom, text).unwrap();
    assert!(sylva(&["grow", s(&bom), "-o", s(&glb)]).status.success());
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bad_last_value_is_pointed_at_not_the_closing_bracket() {
    let dir = temp_dir("last-value");
    let oak = fs::read_to_string(example("bintree/oak.json")).unwrap();
    let line = oak
        .lines()
        .position(|l| l.contains("\"min_radius\""))
        .unwrap()
        + 1;
    let path = dir.join("g.json");
    fs::write(
        &path,
        oak.replace("\"min_radius\": 0.02", "\"min_radius\": -3"),
    )
    .unwrap();
    refused(
        &["grow", s(&path), "-o", s(&dir.join("x.glb"))],
        2,
        &format!("g.json:{line}:17"),
    );
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failing_command_leaves_no_output_behind() {
    let dir = temp_dir("outputs");
    // The picture cannot be written: the asset is not left either.
    let out = sylva(&[
        "grow",
        &example("bintree/oak.json"),
        "-o",
        s(&dir.join("tree.glb")),
        "--png",
        s(&dir.join("missing/tree.png")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing/tree.png"));
    assert!(files_in(&dir).is_empty(), "{:?}", files_in(&dir));
    // An OBJ's MTL and textures go with it.
    let out = sylva(&[
        "grow",
        &example("plantmaker/fern.json"),
        "-o",
        s(&dir.join("fern.obj")),
        "--png",
        s(&dir.join("missing/fern.png")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(files_in(&dir).is_empty(), "{:?}", files_in(&dir));
    // Bad input makes no run or experiment folder.
    let config = dir.join("c.toml");
    fs::write(&config, "[run]\npopulation = 0\n").unwrap();
    refused(
        &["evolve", s(&config), "--out", s(&dir.join("run"))],
        2,
        "population",
    );
    let experiment = dir.join("e.toml");
    fs::write(&experiment, "[lateral-light]\ntree = \"nowhere.json\"\n").unwrap();
    refused(
        &["simulate", s(&experiment), "--out", s(&dir.join("sim"))],
        2,
        "nowhere.json",
    );
    refused(
        &[
            "breed",
            &example("bintree/oak.json"),
            "--out",
            s(&dir.join("b")),
        ],
        2,
        "`lsystem` genomes",
    );
    assert_eq!(files_in(&dir), ["c.toml", "e.toml"]);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_config_number_is_range_checked_where_it_stands() {
    let dir = temp_dir("ranges");
    let config = dir.join("c.toml");
    for (text, location, mention) in [
        (
            "model = \"lsystem\"\n[lsystem.rates]\ndelete_char = 2\n",
            "3:15",
            "`delete_char` must be a number from 0 to 1",
        ),
        (
            "model = \"lsystem\"\n[lsystem.rates]\nmutate_char = nan\n",
            "3:15",
            "mutate_char",
        ),
        (
            "model = \"automata\"\n[automata.breeding]\ntournament = 1000000000000000\n",
            "3:14",
            "`tournament` must be a whole number from 1 to 1000",
        ),
        (
            "model = \"plantmaker\"\n[plantmaker.breeding]\nelitism = -1\n",
            "3:11",
            "elitism",
        ),
        (
            "model = \"lsystem\"\n[lsystem.grow]\nsteps = 4000000000\n",
            "3:9",
            "`steps` must be a whole number from 0 to 100000",
        ),
    ] {
        fs::write(&config, text).unwrap();
        let out = dir.join("run");
        refused(
            &["evolve", s(&config), "--out", s(&out)],
            2,
            &format!("c.toml:{location}"),
        );
        refused(&["evolve", s(&config), "--out", s(&out)], 2, mention);
        assert!(!out.exists());
    }
    // A world that cannot be built is refused before any genome grows in it.
    for (world, mention) in [
        ("size = [1024, 1024, 1024]", "voxels"),
        ("size = [16, 16, 16]\nsoil_layers = 16", "soil_layers"),
    ] {
        let text = format!("model = \"lsystem\"\n[lsystem.grow.world]\n{world}\n");
        fs::write(&config, text).unwrap();
        refused(&["evolve", s(&config)], 2, mention);
        refused(&["evolve", s(&config)], 2, "[lsystem.grow.world]");
    }
    // Experiments: every number has its range too.
    let tree = example("lsystem/tree.json");
    let herb = example("lsystem/herb.json");
    for (text, mention) in [
        (
            format!(
                "[herbs-under-tree]\ntree = {tree:?}\nherb = {herb:?}\nhead_start = 4000000000\n"
            ),
            "head_start",
        ),
        (
            format!("[herbs-under-tree]\ntree = {tree:?}\nherb = {herb:?}\nouter_radius = -1e30\n"),
            "outer_radius",
        ),
        (
            format!("[lateral-light]\ntree = {tree:?}\nspacing = inf\n"),
            "spacing",
        ),
        (
            "[empty-rules.breed]\nchildren = 1000000\n".to_owned(),
            "`children` must be",
        ),
        (
            "[empty-rules.breed.rates]\ninsert_rule = 1.5\n".to_owned(),
            "insert_rule",
        ),
        ("[empty-rules]\ngenerations = 0\n".to_owned(), "generations"),
    ] {
        fs::write(&config, &text).unwrap();
        let out = dir.join("sim");
        refused(&["simulate", s(&config), "--out", s(&out)], 2, mention);
        assert!(!out.exists());
    }
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn work_that_does_not_fit_is_refused_with_its_estimate() {
    let dir = temp_dir("budget");
    let glb = dir.join("x.glb");
    // A small budget refuses even a small tree, naming the file, the estimate and the flag.
    let stderr = refused(
        &[
            "grow",
            &example("bintree/oak.json"),
            "-o",
            s(&glb),
            "--max-memory",
            "1M",
        ],
        2,
        "oak.json",
    );
    assert!(
        stderr.contains("would need about") && stderr.contains("--max-memory"),
        "{stderr}"
    );
    // Automata limits at their documented maxima.
    let automata = dir.join("a.json");
    fs::write(
        &automata,
        r#"{"model": "automata", "format": 1, "program": "(Top (Wait))",
            "limits": {"points": 100000000, "organs": 10000000, "automata": 1000000,
                       "states": 1000000000, "states_per_step": 1000000}}"#,
    )
    .unwrap();
    refused(
        &["grow", s(&automata), "-o", s(&glb), "--max-memory", "1G"],
        2,
        "limits.points",
    );
    // A population of the largest automata trees.
    let config = dir.join("c.toml");
    fs::write(
        &config,
        "model = \"automata\"\n[run]\npopulation = 1000000\n[automata]\nmax_size = 5000\n",
    )
    .unwrap();
    refused(
        &["evolve", s(&config), "--out", s(&dir.join("run"))],
        2,
        "`population`",
    );
    // L-system plants at their bounds in an experiment.
    let mut tree: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(example("lsystem/tree.json")).unwrap()).unwrap();
    tree["physiology"]["max_symbols"] = 1_000_000.into();
    tree["physiology"]["max_modules"] = 1_000_000.into();
    let big = dir.join("big.json");
    fs::write(&big, serde_json::to_string(&tree).unwrap()).unwrap();
    fs::write(&config, format!("[lateral-light]\ntree = {:?}\n", s(&big))).unwrap();
    refused(
        &[
            "simulate",
            s(&config),
            "--out",
            s(&dir.join("sim")),
            "--max-memory",
            "256M",
        ],
        2,
        "max_symbols",
    );
    // A garden file is held to the same limits as `--count`.
    let mut garden: serde_json::Value = serde_json::json!({
        "model": "plantmaker-garden", "format": 1, "area": [100000.0, 100000.0],
        "placement_seed": 1, "plants": []
    });
    let fern: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(example("plantmaker/fern.json")).unwrap())
            .unwrap();
    let seeds: Vec<u64> = (0..200_000).collect();
    garden["plants"] = serde_json::json!([{ "genome": fern, "seeds": seeds }]);
    let file = dir.join("forest.garden.json");
    fs::write(&file, serde_json::to_string(&garden).unwrap()).unwrap();
    refused(&["garden", s(&file), "-o", s(&glb)], 2, "at most 100000");
    assert!(!glb.exists());
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_glb_whose_nodes_share_children_is_refused_at_once() {
    let dir = temp_dir("dag");
    // Sixty levels of nodes that each name the next level twice over: 2^60 paths.
    let nodes: Vec<serde_json::Value> = (0..60)
        .map(|i| serde_json::json!({ "children": [2 * i + 1, 2 * i + 2] }))
        .chain((0..61).map(|_| serde_json::json!({})))
        .collect();
    let mut nodes = nodes;
    for i in 0..60 {
        nodes[2 * i + 1] = serde_json::json!({ "children": [2 * i + 3] });
        nodes[2 * i + 2] = serde_json::json!({ "children": [2 * i + 3] });
    }
    let json = serde_json::json!({ "asset": { "version": "2.0" }, "nodes": nodes });
    let mut j = serde_json::to_vec(&json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut file = Vec::new();
    for v in [
        0x4654_6C67u32,
        2,
        (20 + j.len()) as u32,
        j.len() as u32,
        0x4E4F_534A,
    ] {
        file.extend(v.to_le_bytes());
    }
    file.extend(&j);
    let path = dir.join("dag.glb");
    fs::write(&path, file).unwrap();
    refused(
        &["render", s(&path), "-o", s(&dir.join("x.png"))],
        2,
        "more than one parent",
    );
    fs::remove_dir_all(&dir).unwrap();
}

/// Runs sylva under an rlimit (`"as"`: the address space, `"data"`: the data segment) of
/// `bytes`, set by util-linux's `prlimit`, or by the shell's `ulimit` where it is missing.
fn sylva_limited(resource: &str, bytes: u64, args: &[&str]) -> Output {
    let sylva = env!("CARGO_BIN_EXE_sylva");
    let has_prlimit = Command::new("prlimit")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    let mut command = if has_prlimit {
        let mut c = Command::new("prlimit");
        c.arg(format!("--{resource}={bytes}")).arg("--").arg(sylva);
        c
    } else {
        let flag = if resource == "as" { "-v" } else { "-d" };
        let mut c = Command::new("sh");
        c.arg("-c")
            .arg(format!(
                "ulimit {flag} {} && exec \"$0\" \"$@\"",
                bytes / 1024
            ))
            .arg(sylva);
        c
    };
    command
        .args(args)
        .output()
        .expect("sylva runs under a limit")
}

#[test]
fn the_memory_budget_knows_the_process_limits() {
    if !cfg!(target_os = "linux") {
        return;
    }
    let dir = temp_dir("rlimits");
    let glb = dir.join("g.glb");
    let conifer = example("plantmaker/conifer.json");
    // 5000 conifers of 8 variants hold about 300 MiB of nodes (each carries its genome).
    let garden = [
        "garden",
        &conifer,
        "--count",
        "5000",
        "--variants",
        "8",
        "--area",
        "100000x100000",
        "-o",
        s(&glb),
    ];
    for (resource, limit) in [
        ("as", "RLIMIT_AS 256.0 MiB"),
        ("data", "RLIMIT_DATA 256.0 MiB"),
    ] {
        let out = sylva_limited(resource, 256 << 20, &garden);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{resource}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        for part in [
            "conifer.json",
            "a garden of 5000 plants",
            "would need about",
            limit,
        ] {
            assert!(
                stderr.contains(part),
                "{resource}: expected {part:?} in {stderr}"
            );
        }
        assert!(!glb.exists());
        // A budget that ignores the limit (as the default did, half the machine's memory)
        // lets the same garden start, and the allocator kills it.
        let mut ignoring = garden.to_vec();
        ignoring.extend(["--max-memory", "64G"]);
        let out = sylva_limited(resource, 256 << 20, &ignoring);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.code().is_none() && stderr.contains("memory allocation of"),
            "{resource}: {:?} {stderr}",
            out.status
        );
        assert!(!glb.exists());
    }
    // The documented maximum under a 4 GiB address space: refused before a plant grows
    // but the first, for the GLB it would write and, as a forest of variants, for memory.
    let max = [
        "garden",
        &conifer,
        "--count",
        "100000",
        "--area",
        "100000x100000",
        "-o",
        s(&glb),
    ];
    let out = sylva_limited("as", 4 << 30, &max);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("more than the 4 GiB a GLB can hold"),
        "{stderr}"
    );
    assert!(stderr.contains("`--variants K`"), "{stderr}");
    let mut variants = max.to_vec();
    variants.extend(["--variants", "8"]);
    let out = sylva_limited("as", 4 << 30, &variants);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("a garden of 100000 plants"), "{stderr}");
    assert!(stderr.contains("RLIMIT_AS 4.0 GiB"), "{stderr}");
    assert!(!glb.exists());
    fs::remove_dir_all(&dir).unwrap();
}

/// An L-system genome whose rules grow exponentially in both compartments, with every
/// physiology setting at its documented maximum (and those that speed growth at their
/// least, where less is faster: `min_cost`, `module_density`, `maintenance`, `growth_loss`),
/// so its strings reach a million symbols within a step.
fn maximal_lsystem(fast: bool) -> serde_json::Value {
    let mut physiology = serde_json::json!({
        "seed_biomass": 10, "seed_carbon": 100, "seed_minerals": 100,
        "carbon_content": 1, "mineral_content": 1, "photosynthesis": 100, "uptake": 100,
        "carbon_inhibition": 1e4, "mineral_inhibition": 1e4, "growth_rate": 1e4,
        "carbon_resistance": 1000, "mineral_resistance": 1000, "growth_loss": 0.9,
        "maintenance": 1, "module_density": 1e6, "min_cost": 100, "apex_capacity": 1e3,
        "allocation_exponent": 8, "allocation_floor": 1, "life_span": 1000000,
        "max_symbols": 1000000, "max_modules": 1000000
    });
    if fast {
        for (field, value) in [
            ("min_cost", 1e-5),
            ("module_density", 1.0),
            ("maintenance", 0.0),
            ("growth_loss", 0.0),
        ] {
            physiology[field] = value.into();
        }
    }
    serde_json::json!({
        "model": "lsystem", "format": 1,
        "shoot": { "axiom": "[A]", "rules": ["A -> bA[+lA][-lA]"] },
        "root": { "axiom": "[A]", "rules": ["A -> cA[<rA][>rA]"] },
        "angles": { "turn": 30, "pitch": 30, "roll": 30 },
        "modules": {
            "leaf": { "length": 0.1, "radius": 0.025 },
            "branch": { "length": 0.15, "radius": 0.015 },
            "fine_root": { "length": 0.06, "radius": 0.005 },
            "root_branch": { "length": 0.1, "radius": 0.008 }
        },
        "physiology": physiology
    })
}

/// The estimate a refusal or a note gives, in seconds ("up to about 2.7 min").
fn estimate_in(stderr: &str) -> f64 {
    let rest = stderr
        .split("up to about ")
        .nth(1)
        .unwrap_or_else(|| panic!("an estimate in {stderr}"));
    let mut words = rest.split_whitespace();
    let number: f64 = words.next().unwrap().parse().unwrap();
    let unit = words.next().unwrap().trim_end_matches([',', ')', ';']);
    number
        * match unit {
            "s" => 1.0,
            "min" => 60.0,
            "h" => 3600.0,
            "days" => 86_400.0,
            other => panic!("unit {other:?} in {stderr}"),
        }
}

#[test]
fn maximal_lsystem_work_is_estimated_before_it_starts() {
    let dir = temp_dir("lsystem-work");
    let genome = dir.join("maximal.json");
    fs::write(&genome, maximal_lsystem(true).to_string()).unwrap();
    let out = dir.join("round");
    // Breeding nine specimens of it on one thread: refused under a 1-minute budget with the
    // estimate at the bounds and what to change, before any plant grows.
    let breed = [
        "breed",
        s(&genome),
        "--out",
        s(&out),
        "--threads",
        "1",
        "--max-time",
        "1m",
    ];
    let stderr = refused(&breed, 2, "maximal.json");
    for part in [
        "a breeding round of 9 plants growing 150 steps",
        "1000000 symbols a compartment and 1000000 modules",
        "more than the time budget of 60 s (set with `--max-time`)",
        "lower `max_symbols` and `max_modules`",
    ] {
        assert!(stderr.contains(part), "expected {part:?} in {stderr}");
    }
    // 1350 plant-steps at 2 million symbols and their leaves, branches and roots.
    let estimate = estimate_in(&stderr);
    assert!((300.0..600.0).contains(&estimate), "{estimate}: {stderr}");
    assert!(!out.exists());
    // Two threads share the plants' work.
    let mut two = breed.to_vec();
    two[5] = "2";
    let halved = estimate_in(&refused(&two, 2, "maximal.json"));
    assert!(halved < 0.6 * estimate, "{halved} against {estimate}");

    // Evolving from it, four genomes a generation: each generation is estimated with any
    // rules mutation may write, and refused over the budget.
    let config = dir.join("evolve.toml");
    fs::write(
        &config,
        format!(
            "model = \"lsystem\"\n[run]\npopulation = 4\ngenerations = 3\nthreads = 1\n\
             [lsystem]\nstart = {:?}\n",
            s(&genome)
        ),
    )
    .unwrap();
    let run = dir.join("run");
    let stderr = refused(
        &["evolve", s(&config), "--out", s(&run), "--max-time", "1m"],
        2,
        "a generation of 4 genomes (`population`) on 1 thread,",
    );
    assert!(stderr.contains("`[lsystem.grow] steps`"), "{stderr}");
    assert!(stderr.contains("smaller `population`"), "{stderr}");
    assert!(estimate_in(&stderr) > 120.0, "{stderr}");
    assert!(!run.exists());

    // The same genome as literally maximal (its costs at their maximum too): it hardly
    // grows, but its bounds are those of the fast one, so the estimate is the same and,
    // under the default hour, it is announced before the round starts.
    let slow = dir.join("slow.json");
    fs::write(&slow, maximal_lsystem(false).to_string()).unwrap();
    let args = ["breed", s(&slow), "--out", s(&out), "--threads", "1"];
    let done = sylva(&args);
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert!(done.status.success(), "{stderr}");
    assert!(
        stderr.contains("note: growing 9 plants for 150 steps may take up to about"),
        "{stderr}"
    );
    assert_eq!(estimate_in(&stderr), estimate);
    assert!(out.join("specimens.csv").exists());
    // Grown alone, with leaves and fine roots of 2 m (32 voxel samples each): announced
    // likewise, and refused under a budget below its estimate.
    let mut long = maximal_lsystem(false);
    for module in ["leaf", "fine_root"] {
        long["modules"][module]["length"] = 2.0.into();
    }
    let long_file = dir.join("long.json");
    fs::write(&long_file, long.to_string()).unwrap();
    let glb = dir.join("one.glb");
    let done = sylva(&["grow", s(&long_file), "-o", s(&glb)]);
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert!(done.status.success(), "{stderr}");
    assert!(
        stderr.contains("note: growing the plant may take up to about"),
        "{stderr}"
    );
    assert!(estimate_in(&stderr) > 60.0, "{stderr}");
    let stderr = refused(
        &["grow", s(&genome), "-o", s(&glb), "--max-time", "20s"],
        2,
        "growing a plant 150 steps, up to 1000000 symbols a compartment",
    );
    assert!(stderr.contains("time budget of 20 s"), "{stderr}");
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_absurd_world_is_refused_under_the_default_time_budget() {
    // Documented maxima of a world: 16.7 million voxels of 1 cm with diffusion 100 m² a
    // step, six million sub-steps each step.
    let dir = temp_dir("absurd-world");
    let config = dir.join("world.toml");
    fs::write(
        &config,
        format!(
            "[lateral-light]\ntree = {:?}\nsteps = 50000\n\
             [lateral-light.world]\nvoxel_size = 0.01\nsize = [1024, 16, 1024]\nsoil_layers = 8\n\
             [lateral-light.world.light]\nelevation = 30.0\n\
             [lateral-light.world.minerals]\ndiffusion = 100\n",
            example("lsystem/tree.json")
        ),
    )
    .unwrap();
    let out = dir.join("sim");
    let stderr = refused(
        &["simulate", s(&config), "--out", s(&out)],
        2,
        "two pairs of trees growing 50000 steps (`steps`)",
    );
    assert!(stderr.contains("years"), "{stderr}");
    assert!(
        stderr.contains("time budget of 1.0 h (the default; set another with `--max-time`)"),
        "{stderr}"
    );
    assert!(!out.exists());
    fs::remove_dir_all(&dir).unwrap();
}
