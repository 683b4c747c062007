//! The plausibility report: figures measured as defined, real trees' ranges applied, and
//! skeleton files read back into the plants they were written from.
#![allow(clippy::unwrap_used)]

use sylva::core::glam::Vec3;
use sylva::core::{Plant, PlantMeta};
use sylva::inspect::{AssetFacts, Report, Verdict};
use sylva::skeleton::Skeleton;
use sylva::{Dress, GrowOptions, Grown, LeafKind, Registry};

fn figure(report: &Report, name: &str) -> Option<f64> {
    report
        .figures
        .iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("no figure {name}"))
        .value
}

fn oak(options: GrowOptions) -> Grown {
    let text = std::fs::read_to_string("../../examples/bintree/oak.json").unwrap();
    Grown::grow(Registry::standard().parse_genome(&text).unwrap(), &options).unwrap()
}

#[test]
fn a_pipe_model_tree_measures_its_own_exponent() {
    let mut p = Plant::new(PlantMeta::default());
    // Forks splitting each mother into two children of 2^(-1/2.5) its radius: e = 2.5.
    let r = 0.5f32.powf(1.0 / 2.5);
    let mut parents = vec![None];
    for level in 0..5 {
        let mut next = Vec::new();
        for &parent in &parents {
            for k in 0..if level == 0 { 1 } else { 2 } {
                let start = Vec3::new(0.0, level as f32, 0.0);
                let end = start + Vec3::new((k as f32 - 0.5) * 0.3, 1.0, 0.0);
                let radius = 0.1 * r.powi(level);
                let id = p
                    .add_segment(
                        start,
                        end,
                        (radius, radius),
                        parent,
                        parent.is_some(),
                        Plant::BARK,
                    )
                    .unwrap();
                next.push(Some(id));
            }
        }
        parents = next;
    }
    let report = Report::of(&p, None);
    let e = figure(&report, "pipe_exponent").unwrap();
    assert!((e - 2.5).abs() < 1e-6, "{e}");
    assert_eq!(figure(&report, "thicker_below"), Some(1.0));
    assert_eq!(figure(&report, "height"), Some(5.0));
    // Leafless: no leaf figures, never guessed.
    assert_eq!(figure(&report, "leaf_length"), None);
    assert_eq!(figure(&report, "triangles"), None);
}

#[test]
fn a_dressed_tree_passes_and_an_undressed_one_is_told_apart() {
    let dressed = oak(GrowOptions {
        dress: Dress::foliage(LeafKind::Oak),
        height: Some(14.0),
        ..Default::default()
    });
    let asset = AssetFacts {
        triangles: dressed.mesh.triangle_count() as u64,
        texture_bytes: 800_000,
    };
    let report = Report::of(&dressed.plant, Some(asset));
    assert!(report.failures().is_empty(), "{}", report.table());
    let leaf = figure(&report, "leaf_length").unwrap();
    assert!(
        (0.08..=0.12).contains(&leaf),
        "an oak leaf is 8 to 12 cm: {leaf}"
    );
    let slenderness = figure(&report, "slenderness").unwrap();
    assert!((slenderness - 32.0).abs() < 2.0, "{slenderness}");
    assert!(figure(&report, "leaf_area_index").unwrap() > 0.5);
    assert!(figure(&report, "leaves_on_twigs").unwrap() > 0.8);

    // The binary tree as Susinno grew it, scaled to 14 m: bare, so no leaf figures.
    let plain = oak(GrowOptions {
        height: Some(14.0),
        ..Default::default()
    });
    let report = Report::of(&plain.plant, None);
    for name in ["leaf_length", "leaf_area_index", "leaves_on_twigs"] {
        let f = report.figures.iter().find(|f| f.name == name).unwrap();
        assert_eq!(f.verdict(), Verdict::None, "{name}");
    }
}

#[test]
fn huge_leaves_and_heavy_assets_are_implausible() {
    // A PlantMaker palm scaled to 20 m: its fronds' leaves grow with it.
    let text = std::fs::read_to_string("../../examples/plantmaker/palm.json").unwrap();
    let genome = Registry::standard().parse_genome(&text).unwrap();
    let grown = Grown::grow(
        genome,
        &GrowOptions {
            height: Some(20.0),
            ..Default::default()
        },
    )
    .unwrap();
    let heavy = AssetFacts {
        triangles: 1_000_000,
        texture_bytes: 5_000_000,
    };
    let report = Report::of(&grown.plant, Some(heavy));
    let failed: Vec<&str> = report.failures().iter().map(|f| f.name).collect();
    assert!(failed.contains(&"triangles"), "{failed:?}");
    assert!(failed.contains(&"texture_bytes"), "{failed:?}");
    assert!(failed.contains(&"leaf_length"), "{}", report.table());
}

#[test]
fn skeleton_files_read_back_into_their_plants() {
    let grown = oak(GrowOptions {
        dress: Dress::foliage(LeafKind::Birch),
        height: Some(9.0),
        ..Default::default()
    });
    let skeleton = Skeleton::of_grown(&grown);
    let dir = std::env::temp_dir().join(format!("sylva-inspect-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("oak.skeleton.json");
    std::fs::write(&path, skeleton.to_json()).unwrap();
    let back = Skeleton::read(&path).unwrap().to_plant(&path).unwrap();
    assert_eq!(back.segments(), grown.plant.segments());
    assert_eq!(back.materials(), grown.plant.materials());
    assert_eq!(back.organs().len(), grown.plant.organs().len());
    // The report of the file is the report of the plant (orientations written to the
    // float and read back renormalised: the leaf area to a part in a million).
    let (a, b) = (Report::of(&back, None), Report::of(&grown.plant, None));
    for (x, y) in a.figures.iter().zip(&b.figures) {
        match (x.value, y.value) {
            (Some(u), Some(v)) => assert!((u - v).abs() <= 1e-6 * v.abs().max(1.0), "{}", x.name),
            (u, v) => assert_eq!(u, v, "{}", x.name),
        }
    }
    // A child before its parent is refused, naming it.
    let mut broken = skeleton.clone();
    broken.segments[1].parent = Some(5);
    let e = broken.to_plant(&path).unwrap_err().to_string();
    assert!(
        e.contains("segments[1]") && e.contains("parents first"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
