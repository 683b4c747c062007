//! Growing self-organising trees: the default genome, and the same grown to about 20,000
//! leaves (the figure issue 52 names), each grown alone on one thread.
//!
//! Run with `cargo bench -p sylva-grown --bench grow`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use criterion::{Criterion, criterion_group, criterion_main};
use sylva_grown::{Growth, Param, grow};

fn trees(c: &mut Criterion) {
    let mut group = c.benchmark_group("grown");
    group.sample_size(20);
    let default = Growth::default();
    let mut dense = Growth::default();
    dense.parameters.set(Param::Points, 6000.0);
    for (name, genome) in [("default", default), ("dense", dense)] {
        let (_, report) = grow(&genome, genome.seed).unwrap();
        eprintln!("{name}: {report:?}");
        group.bench_function(name, |b| b.iter(|| grow(&genome, genome.seed).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, trees);
criterion_main!(benches);
