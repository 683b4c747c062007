//! The helix of the paper's Figures 1 and 2, rebuilt from the prose in
//! `examples/automata/helix.json`: it grows a straight trunk with a branch every 70 steps,
//! branches spiralling round the trunk and bending down.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use sylva_automata::{AutomataGenome, Detail, Program, Simulator, Stop};
use sylva_core::glam::Vec3;
use sylva_core::{Plant, PlantMeta};

const HELIX: &str = include_str!("../../../examples/automata/helix.json");

fn helix() -> (AutomataGenome, Plant) {
    let genome = AutomataGenome::from_json(HELIX).unwrap();
    let (plant, report) = genome.develop_with_report(0).unwrap();
    assert!(!report.bounds.any(), "{report:?}");
    assert_eq!(report.iterations, 1000);
    assert_eq!(report.stop, Stop::Iterations);
    (genome, plant)
}

#[test]
fn the_helix_has_a_trunk_and_fourteen_branches() {
    let (_, plant) = helix();
    // 1000 / 70: branches start at steps 70, 140, ..., 980.
    let branches: Vec<usize> = (0..plant.segments().len())
        .filter(|&i| plant.segments()[i].lateral)
        .collect();
    assert_eq!(branches.len(), 14);
    assert!(plant.segments().iter().all(|s| s.order <= 1));
    // The trunk: 1000 steps of 1 unit (0.01 m), straight up.
    let trunk: Vec<_> = plant.segments().iter().filter(|s| s.order == 0).collect();
    assert_eq!(trunk.len(), 1000);
    let top = trunk.last().unwrap().end;
    assert!((top - Vec3::new(0.0, 10.0, 0.0)).length() < 1e-3, "{top}");
    // Branch points at heights 0.69, 1.39, ... m.
    for (k, &b) in branches.iter().enumerate() {
        let start = plant.segments()[b].start;
        // Created during the 70th step, before that step's move.
        let want = 0.7 * (k + 1) as f32 - 0.01;
        assert!(
            (start.y - want).abs() < 1e-3,
            "branch {k} starts at {start}"
        );
    }
    assert_eq!(plant.tips().count(), 15);
    assert!(plant.organs().is_empty());
}

#[test]
fn branches_leave_at_seventy_degrees_and_bend_down() {
    let (_, plant) = helix();
    let mut azimuths = Vec::new();
    for (i, s) in plant.segments().iter().enumerate() {
        if !s.lateral {
            continue;
        }
        let first = s.vector().normalize();
        let angle = first.y.clamp(-1.0, 1.0).acos().to_degrees();
        assert!((angle - 70.2).abs() < 0.5, "branch {i} leaves at {angle}°");
        azimuths.push(first.z.atan2(first.x).to_degrees());
        // Follow the axis to its tip.
        let mut last = i;
        while let Some(next) = plant
            .segments()
            .iter()
            .position(|c| c.parent.map(|p| p.index()) == Some(last) && !c.lateral)
        {
            last = next;
        }
        let tip = plant.segments()[last];
        // Full-length branches (the first six are not cut by the iteration limit) end
        // pointing down.
        if azimuths.len() <= 6 {
            assert!(
                tip.vector().y < 0.0,
                "branch {i} ends heading {}",
                tip.vector()
            );
            assert!(tip.end.y < s.start.y + 2.0);
        }
        assert!(tip.end_radius < s.start_radius);
    }
    // Successive branches turn about the trunk by 70 × 0.7° = 49°: a helix.
    for w in azimuths.windows(2) {
        let turn = (w[1] - w[0]).rem_euclid(360.0);
        assert!(
            (turn - 49.0).abs() < 0.5 || (turn - 311.0).abs() < 0.5,
            "{turn}"
        );
    }
}

#[test]
fn chords_keep_the_tips_with_few_segments() {
    let (genome, full) = helix();
    let program = Program::compile(&genome.program, &genome.growth.semantics());
    let mut plant = Plant::new(PlantMeta::default());
    let report = Simulator::new().run(
        &program,
        &genome.growth.grow_options(),
        Detail::Chords,
        &mut plant,
    );
    assert_eq!(report.segments as usize, plant.segments().len());
    // Trunk: 15 runs between 14 branch points; one per branch.
    assert_eq!(plant.segments().len(), 15 + 14);
    let mut a: Vec<[f32; 3]> = full.tips().map(|p| p.to_array()).collect();
    let mut b: Vec<[f32; 3]> = plant.tips().map(|p| p.to_array()).collect();
    a.sort_by(|x, y| x.partial_cmp(y).unwrap());
    b.sort_by(|x, y| x.partial_cmp(y).unwrap());
    assert_eq!(a, b);
}

/// Renders the helix to `/tmp/helix-{iso,front,top}.png` for a person to look at:
/// `cargo test -p sylva-automata --test automata_helix -- --ignored`.
#[test]
#[ignore = "writes pictures to /tmp"]
fn render_the_helix() {
    use sylva_mesh::mesher::{MeshOptions, mesh_plant};
    use sylva_mesh::{Scene, SceneNode};
    use sylva_render::{RenderOptions, View, render, write_png};

    let (_, plant) = helix();
    let mesh = mesh_plant(&plant, &MeshOptions::default()).unwrap();
    let scene = Scene::single(SceneNode::new("helix", &mesh));
    for view in [View::Iso, View::Front, View::Top] {
        let options = RenderOptions {
            view,
            ..RenderOptions::default()
        };
        let image = render(&scene, &options).unwrap();
        let path = std::env::temp_dir().join(format!("helix-{view}.png"));
        write_png(&path, &image).unwrap();
        eprintln!("wrote {}", path.display());
    }
}
