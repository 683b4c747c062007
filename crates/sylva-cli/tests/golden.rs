//! Golden bytes for every model, driven through the command line so that they outlive any
//! refactor of the library behind it: one plant of each model grown and exported, a
//! PlantMaker garden, a small evolution of each model, one breeding round and one experiment.
//!
//! Any change to a model, the engine, the mesher, the exporters or the renderer that changes
//! results shows here. Update a hash only for an intended change, and say why in the commit.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

use sylva::core::hash::stable_hash;

fn sylva(args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(args)
        .output()
        .expect("the sylva binary runs");
    assert!(
        out.status.success(),
        "sylva {args:?}: exit {:?}\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn example(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(path)
        .display()
        .to_string()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sylva-golden-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// Hash of a file's bytes; `stats.csv` loses its wall-clock column first.
fn hash(path: &Path) -> u64 {
    let bytes = fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if path.file_name().is_some_and(|n| n == "stats.csv") {
        let text: String = String::from_utf8(bytes)
            .unwrap()
            .lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_owned() + "\n")
            .collect();
        stable_hash(text.as_bytes())
    } else {
        stable_hash(&bytes)
    }
}

/// Compares every hash at once, so one run shows every change (and the new values).
fn check(dir: &Path, golden: &[(&str, u64)]) {
    let found: Vec<(&str, u64)> = golden
        .iter()
        .map(|&(file, _)| (file, hash(&dir.join(file))))
        .collect();
    let changed: Vec<String> = golden
        .iter()
        .zip(&found)
        .filter(|(g, f)| g.1 != f.1)
        .map(|(_, (file, h))| format!("    (\"{file}\", {h:#018x}),"))
        .collect();
    assert!(changed.is_empty(), "changed bytes:\n{}", changed.join("\n"));
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn one_plant_of_each_model() {
    let dir = temp_dir("plants");
    for (genome, name) in [
        ("bintree/oak.json", "bintree"),
        ("automata/helix.json", "automata"),
        ("plantmaker/flowering-bush.json", "plantmaker"),
        ("lsystem/herb.json", "lsystem"),
        ("grown/birch.json", "grown"),
    ] {
        let glb = dir.join(format!("{name}.glb"));
        let obj = dir.join(format!("{name}.obj"));
        let wrl = dir.join(format!("{name}.wrl"));
        let png = dir.join(format!("{name}.png"));
        let g = example(genome);
        sylva(&["grow", &g, "-o", glb.to_str().unwrap()]);
        sylva(&["grow", &g, "-o", obj.to_str().unwrap()]);
        sylva(&["grow", &g, "-o", wrl.to_str().unwrap()]);
        sylva(&[
            "render",
            &g,
            "-o",
            png.to_str().unwrap(),
            "--size",
            "128x96",
        ]);
    }
    check(
        &dir,
        &[
            ("bintree.glb", 0x1a92_6c05_dfb1_1804),
            ("bintree.obj", 0xe32d_4a92_71ab_6f66),
            ("bintree.wrl", 0xdbc4_7fce_36e4_5baf),
            ("bintree.png", 0xb9a7_2f03_eb27_e8ee),
            ("automata.glb", 0x1264_c933_a541_7ee2),
            ("automata.obj", 0x4cda_bedd_4962_f381),
            ("automata.wrl", 0x5940_a067_7cd5_0df9),
            ("automata.png", 0x68b6_e8e4_8498_f113),
            ("plantmaker.glb", 0x275a_ec47_574a_872e),
            ("plantmaker.obj", 0x745c_00a4_4fa6_e209),
            ("plantmaker.wrl", 0x0c1b_ecb8_58ed_505c),
            ("plantmaker.png", 0x2516_d62a_ccf2_381e),
            ("lsystem.glb", 0xf21f_751a_518d_5e1f),
            ("lsystem.obj", 0xb7b2_1d21_c371_d211),
            ("lsystem.wrl", 0x6c1a_fb10_cf41_5531),
            ("lsystem.png", 0x6c6d_cd66_74b2_365d),
            ("grown.glb", 0x3396_8a1e_0056_0769),
            ("grown.obj", 0x67d3_c47c_2c87_4897),
            ("grown.wrl", 0x602d_4100_dd9f_2a83),
            ("grown.png", 0xebdc_0363_1cdd_8df4),
        ],
    );
}

#[test]
fn a_plantmaker_garden() {
    let dir = temp_dir("garden");
    let glb = dir.join("garden.glb");
    sylva(&[
        "garden",
        &example("plantmaker/conifer.json"),
        &example("plantmaker/tulip.json"),
        "--count",
        "3",
        "--area",
        "12x8",
        "--seed",
        "5",
        "-o",
        glb.to_str().unwrap(),
        "--png",
        dir.join("garden.png").to_str().unwrap(),
    ]);
    check(
        &dir,
        &[
            ("garden.glb", 0xe413_2dc4_87ee_8404),
            ("garden.garden.json", 0x8e6c_21a1_29f0_ba42),
            ("garden.png", 0xd5f5_7a1f_3656_2915),
        ],
    );
}

/// A small evolution of `model` from an example config, shrunk by `edits`.
fn evolve(name: &str, config: &str, edits: &[(&str, &str)], golden: &[(&str, u64)]) {
    let dir = temp_dir(name);
    let mut text = fs::read_to_string(example(config)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{config} has {from:?}");
        text = text.replace(from, to);
    }
    let path = dir.join("config.in.toml");
    fs::write(&path, text).unwrap();
    let out = dir.join("run");
    sylva(&[
        "evolve",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    check(&out, golden);
    fs::remove_dir_all(&dir).unwrap();
}

const SMALL_OUTPUT: &str = "[output]\nimage_size = 64\nsheet_size = 4\n";

#[test]
fn a_small_automata_run() {
    evolve(
        "automata",
        "automata/sphere.toml",
        &[
            ("generations = 50", "generations = 3"),
            ("population = 1000", "population = 60"),
            ("[output]\nsheet_size = 24", SMALL_OUTPUT),
        ],
        &[
            ("stats.csv", 0x3636_0574_0b0c_39de),
            ("best.json", 0xf40d_76df_8758_6260),
            ("best.glb", 0xf18d_776c_3e05_aa37),
            ("best.png", 0x25a2_b823_e666_b519),
            ("population.png", 0xcac9_870b_4f5c_0aa3),
        ],
    );
}

#[test]
fn a_small_grown_run() {
    evolve(
        "grown",
        "grown/evolve.toml",
        &[
            ("generations = 20", "generations = 2"),
            ("population = 40", "population = 12"),
            (
                "start = [\"oak.json\"]",
                &format!("start = [{:?}]", example("grown/birch.json")),
            ),
            ("[output]\nsheet_size = 16", SMALL_OUTPUT),
        ],
        &[
            ("stats.csv", 0xf46c_887c_c7a9_7658),
            ("best.json", 0x22a5_4f48_dbe4_56b1),
            ("best.glb", 0x59ba_345b_e90e_1c47),
            ("best.png", 0x8539_7d73_9556_becb),
            ("population.png", 0x08a1_eee5_1da0_472c),
        ],
    );
}

#[test]
fn a_small_plantmaker_run() {
    evolve(
        "plantmaker",
        "plantmaker/evolve.toml",
        &[
            ("generations = 30", "generations = 3"),
            ("population = 120", "population = 12"),
            (
                "start = [\"flowering-bush.json\"]",
                &format!("start = [{:?}]", example("plantmaker/tulip.json")),
            ),
            ("[output]\nsheet_size = 16", SMALL_OUTPUT),
        ],
        &[
            ("stats.csv", 0x7bfa_8165_d4fb_7972),
            ("best.json", 0x5657_b9ef_f216_00c3),
            ("best.glb", 0xbfa6_97ec_f0f6_6095),
            ("best.png", 0xd757_4006_b50a_44ca),
            ("population.png", 0x26e7_33ba_ec34_664d),
        ],
    );
}

#[test]
fn a_small_lsystem_run() {
    evolve(
        "lsystem",
        "lsystem/evolve.toml",
        &[
            ("generations = 15", "generations = 1"),
            ("population = 24", "population = 4"),
            (
                "start = \"herb.json\"",
                &format!("start = {:?}", example("lsystem/herb.json")),
            ),
            ("[output]\nimage_size = 600\nsheet_size = 12", SMALL_OUTPUT),
        ],
        &[
            ("stats.csv", 0x4de2_2088_6a3a_00fe),
            ("best.json", 0x1158_469e_881d_63fa),
            ("best.glb", 0x4536_ff61_75fb_b631),
            ("best.png", 0x2bd5_2aed_3cec_3a0f),
            ("population.png", 0x3013_2255_14ea_d27f),
        ],
    );
}

#[test]
fn a_breeding_round() {
    let dir = temp_dir("breed");
    sylva(&[
        "breed",
        &example("lsystem/herb.json"),
        "--out",
        dir.to_str().unwrap(),
        "--children",
        "3",
        "--seed",
        "4",
    ]);
    check(
        &dir,
        &[
            ("specimens.csv", 0xf6a7_dc1d_2c4d_8b96),
            ("mother.json", 0x152e_74df_131e_7342),
            ("child-1.json", 0x1751_ad35_554d_58ee),
            ("child-2.json", 0x1d45_3002_f258_2aca),
            ("child-3.json", 0xcd9e_a176_a496_5e5d),
            ("garden.glb", 0xc70e_7536_d058_dfdf),
            ("garden.png", 0xff9e_8023_59f2_f95a),
            ("specimens.png", 0x8988_b684_b160_06b5),
        ],
    );
}

/// `scene.glb` changed once on purpose: its nodes carry each plant's genome and seed (with
/// its biomass), so a plant of an experiment can be grown again.
/// `report.txt` changed once on purpose: lines for each crown's bushiness (shoot tips per m³
/// of its convex hull) were added after the unchanged asymmetry lines; `side.png` is new.
#[test]
fn an_experiment() {
    let dir = temp_dir("simulate");
    sylva(&[
        "simulate",
        &example("lsystem/lateral-light.toml"),
        "--out",
        dir.to_str().unwrap(),
    ]);
    check(
        &dir,
        &[
            ("report.txt", 0x8755_3c32_5e90_8b96),
            ("records.csv", 0xb99e_2a2d_f61e_5f2e),
            ("scene.glb", 0x8493_205e_7532_486c),
            ("scene.png", 0x91c1_ec3a_02cf_40e7),
            ("side.png", 0x3353_95bf_0e3d_bc8d),
        ],
    );
}
