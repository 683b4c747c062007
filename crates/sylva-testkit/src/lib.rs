//! Test helpers shared by Sylva's crates, as a dev-dependency only (never published).
//!
//! - [`binary_tree`] and [`bench_tree`]: deterministic test plants grown with the turtle, for
//!   the mesher's, the writers' and the renderer's tests and benchmarks.
//! - [`validate`]: runs the Khronos glTF validator on written GLB files, for every crate
//!   whose tests write them (the GLB writer's, the library's and the command line's).
//!
//! - [`toy`] (feature `toy`): a fifth model, a cylinder that evolves towards a height, for
//!   tests that show a model of one's own flowing through the library and the studio.
//!
//! It depends on `sylva-core` alone (and, with `toy`, on the model traits and the engine),
//! so any crate above it may use it in its tests.

#[cfg(feature = "toy")]
pub mod toy;

use std::path::{Path, PathBuf};
use std::process::Command;

use sylva_core::glam::{Quat, Vec2};
use sylva_core::{Organ, OrganKind, Plant, PlantMeta, SegmentId, Turtle};

/// Runs the Khronos glTF validator (`tools/gltf-validator`, installed by
/// `npm ci --prefix tools/gltf-validator`) on `glbs`; every GLB must have zero errors and zero
/// warnings.
///
/// # Panics
///
/// When the validator is not installed, Node.js does not run, or any file has an error or a
/// warning (the validator's report is in the message).
pub fn validate(glbs: &[PathBuf]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let script = root.join("tools/gltf-validator/validate.mjs");
    assert!(
        root.join("tools/gltf-validator/node_modules/gltf-validator")
            .exists(),
        "the validator is not installed: run `npm ci --prefix tools/gltf-validator`"
    );
    let out = Command::new("node")
        .arg(&script)
        .args(glbs)
        .output()
        .expect("node runs (install Node.js)");
    assert!(
        out.status.success(),
        "validator: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A deterministic recursive binary tree grown with the turtle: `2^(depth+1) - 1` axes of
/// `segments_per_axis` gently spiralling, tapering segments each; every tip carries a leaf and
/// every third tip also a flower.
pub fn binary_tree(depth: u32, segments_per_axis: u32) -> Plant {
    let mut plant = Plant::new(PlantMeta {
        model: "test-binary-tree".into(),
        genome_hash: 0,
        seed: u64::from(depth),
    });
    let mut turtle = Turtle::default();
    let mut tips = 0;
    grow_axis(
        &mut plant,
        &mut turtle,
        None,
        Axis {
            level: 0,
            depth,
            segments: segments_per_axis.max(1),
            length: 4.0,
            radius: 0.25,
        },
        &mut tips,
    );
    plant
}

/// The benchmark tree: depth 10, 24 segments per axis, 1.25 million triangles with the
/// default mesh options.
pub fn bench_tree() -> Plant {
    binary_tree(10, 24)
}

/// One axis of the tree and the depth it grows to.
struct Axis {
    level: u32,
    depth: u32,
    segments: u32,
    length: f32,
    radius: f32,
}

/// Grows `axis` from the turtle, then its two children (or, at the last level, a leaf and
/// every third time a flower); `tips` counts the tips grown so far.
fn grow_axis(
    plant: &mut Plant,
    turtle: &mut Turtle,
    parent: Option<SegmentId>,
    axis: Axis,
    tips: &mut u32,
) {
    let n = axis.segments;
    let step = axis.length / n as f32;
    let (mut parent, mut lateral) = (parent, parent.is_some());
    for i in 0..n {
        // Roll a little and pitch a little: a gentle spiral, so frames must not twist.
        turtle.frame.rotate_h(0.15);
        turtle.frame.rotate_l(0.03);
        let r0 = axis.radius * (1.0 - 0.5 * i as f32 / n as f32);
        let r1 = axis.radius * (1.0 - 0.5 * (i + 1) as f32 / n as f32);
        let start = turtle.position;
        let end = turtle.forward(step);
        let id = plant
            .add_segment(start, end, (r0, r1), parent, lateral, Plant::BARK)
            .expect("the test tree is well formed");
        (parent, lateral) = (Some(id), false);
    }
    if axis.level == axis.depth {
        let leaf = Organ {
            kind: OrganKind::Leaf,
            position: turtle.position,
            orientation: turtle.frame.rotation() * Quat::from_rotation_x(-0.4),
            size: Vec2::new(0.3, 0.1),
            material: Plant::LEAF,
            parent,
        };
        plant.add_organ(leaf).expect("the leaf is well formed");
        if tips.is_multiple_of(3) {
            let flower = Organ {
                kind: OrganKind::Flower,
                size: Vec2::new(0.12, 0.04),
                material: Plant::FLOWER,
                orientation: turtle.frame.rotation(),
                ..leaf
            };
            plant.add_organ(flower).expect("the flower is well formed");
        }
        *tips += 1;
        return;
    }
    for side in [1.0f32, -1.0] {
        turtle.push();
        turtle.frame.rotate_h(0.9 * side);
        turtle.frame.rotate_u(0.55 * side);
        grow_axis(
            plant,
            turtle,
            parent,
            Axis {
                level: axis.level + 1,
                length: axis.length * 0.78,
                radius: axis.radius * 0.5 * 0.8,
                ..axis
            },
            tips,
        );
        turtle.pop();
    }
}
