//! The outline term's cost beside growth on a plant a match evolves: PlantMaker's best plant
//! for the umbrella outline (`examples/match/umbrella.png`, `sylva match` with its
//! defaults), grown, and scored (IoU times plausibility) from the front and the side at
//! 32, 64, 128 and 256 (the default) rows. And the same plant grown inside the outline, as
//! a match does by default: its term (`score_pruned`: stems cut, leaves clipped as they
//! are drawn, front and side at 256 rows), and the pieces its outputs carry (`prune`).
//!
//! Run with `cargo bench -p sylva --bench outline`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use sylva::evolution::MatchConfig;
use sylva::picture::{Threshold, load_target};
use sylva_fitness::silhouette::{Outline, SPACE_ROWS, Scratch, Side, prune, score_pruned};

fn outline(c: &mut Criterion) {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let genome = sylva::Registry::standard()
        .load_genome(&here.join("benches/umbrella-plantmaker.json"))
        .unwrap();
    let seed = genome.default_seed();
    let plant = genome.develop(seed).unwrap();
    let picture = here.join("../../examples/match/umbrella.png");
    let picture = load_target(&picture, Threshold::default()).unwrap();
    let mut group = c.benchmark_group("outline");
    group.bench_function(
        format!(
            "grow the umbrella's PlantMaker plant ({} segments, {} organs)",
            plant.segments().len(),
            plant.organs().len()
        ),
        |b| b.iter(|| black_box(genome.develop(seed).unwrap())),
    );
    for rows in [32, 64, 128, 256] {
        let views =
            [Side::Front, Side::Side].map(|side| Outline::new(&picture, side, rows).unwrap());
        let mut scratch = Scratch::default();
        group.bench_function(format!("score front and side at {rows} rows"), |b| {
            b.iter(|| {
                let sum: f64 = views
                    .iter()
                    .map(|v| v.score(black_box(&plant), &mut scratch))
                    .sum();
                black_box(sum)
            })
        });
    }
    let space =
        [Side::Front, Side::Side].map(|side| Outline::new(&picture, side, SPACE_ROWS).unwrap());
    let views = [Side::Front, Side::Side]
        .map(|side| Outline::new(&picture, side, MatchConfig::DEFAULT_ROWS).unwrap());
    let pruned = prune(&space, &plant);
    let mut scratch = Scratch::default();
    group.bench_function(
        format!(
            "prune to front and side ({} segments, {} organs kept)",
            pruned.segments().len(),
            pruned.organs().len()
        ),
        |b| b.iter(|| black_box(prune(&space, black_box(&plant)))),
    );
    group.bench_function("the term pruned: front and side at 256 rows", |b| {
        b.iter(|| {
            black_box(score_pruned(
                &space,
                &views,
                black_box(&plant),
                0.0,
                &mut scratch,
            ))
        })
    });
    group.finish();
}

criterion_group!(benches, outline);
criterion_main!(benches);
