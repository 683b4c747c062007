//! The outline term's cost per plant beside the plant's growth: a binary tree of Susinno's
//! default genome (1023 segments) grown, and its silhouette drawn and compared with a
//! target at 64, 128 and 256 rows, front and side.
//!
//! Run with `cargo bench -p sylva-fitness --bench silhouette`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sylva_bintree::BinTree;
use sylva_fitness::silhouette::{Bitmap, Outline, Scratch, Side};

/// A round crown on a trunk, 200 x 240 pixels.
fn target() -> Bitmap {
    let mut b = Bitmap::new(200, 240);
    for y in 0..240u32 {
        let dy = y as f32 - 90.0;
        let half = (70.0f32 * 70.0 - dy * dy).max(0.0).sqrt();
        if half > 0.0 {
            b.fill_span(y, (100.0 - half) as u32, (100.0 + half) as u32);
        }
        if y > 150 {
            b.fill_span(y, 93, 107);
        }
    }
    b
}

fn silhouette(c: &mut Criterion) {
    let genome = BinTree::default();
    let plant = genome.develop(0).unwrap();
    let picture = target();
    let mut group = c.benchmark_group("silhouette");
    group.bench_function("grow the binary tree", |b| {
        b.iter(|| black_box(genome.develop(0).unwrap()))
    });
    for rows in [64, 128, 256] {
        for side in [Side::Front, Side::Side] {
            let outline = Outline::new(&picture, side, rows).unwrap();
            let mut scratch = Scratch::default();
            group.bench_function(format!("iou {side:?} at {rows} rows"), |b| {
                b.iter(|| black_box(outline.iou(black_box(&plant), &mut scratch)))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, silhouette);
criterion_main!(benches);
