//! The behaviour descriptors' cost per plant beside the plant's growth: a binary tree 10
//! levels deep (1023 segments) grown, and its descriptors measured: all eight together
//! (the silhouette drawn once, the plant walked once), and each alone.
//!
//! Run with `cargo bench -p sylva-fitness --bench descriptors`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sylva_bintree::BinTree;
use sylva_fitness::descriptors::{self, Descriptor, Scratch};

fn descriptors(c: &mut Criterion) {
    let genome = BinTree {
        depth: 10,
        ..BinTree::default()
    };
    let plant = genome.develop(0).unwrap();
    assert_eq!(plant.segments().len(), 1023);
    let mut group = c.benchmark_group("descriptors");
    group.bench_function("grow the binary tree", |b| {
        b.iter(|| black_box(genome.develop(0).unwrap()))
    });
    let mut scratch = Scratch::default();
    let mut out = [0.0; 8];
    group.bench_function("all eight", |b| {
        b.iter(|| {
            descriptors::measure(black_box(&plant), &Descriptor::ALL, &mut scratch, &mut out);
            black_box(out)
        })
    });
    for d in Descriptor::ALL {
        group.bench_function(d.name(), |b| {
            b.iter(|| black_box(d.measure(black_box(&plant), &mut scratch)))
        });
    }
    group.finish();
}

criterion_group!(benches, descriptors);
criterion_main!(benches);
