//! What growing a genome does: the growth's report (cycles, internodes, shed, points left,
//! leaves, why it stopped), the tree's height and the time it took.
//!
//! `cargo run --release -p sylva-grown --example report -- examples/grown/oak.json
//! [name=value ...]`, where each `name=value` sets a parameter (or `crown=cone`) first;
//! `default` for the file grows the default genome; `params` prints the parameter table.
#![allow(clippy::unwrap_used)] // A tool for people tuning genomes: a bad argument panics.

fn main() {
    let mut args = std::env::args().skip(1);
    let mut genome = match args.next().as_deref() {
        Some("params") => return print!("{}", sylva_grown::genome::params_table()),
        Some("default") | None => sylva_grown::Growth::default(),
        Some(path) => sylva_model::file::parse(&std::fs::read_to_string(path).unwrap()).unwrap(),
    };
    for arg in args {
        let (name, value) = arg.split_once('=').unwrap();
        if name == "crown" {
            genome.crown = serde_json::from_value(serde_json::json!(value)).unwrap();
            continue;
        }
        let i = sylva_grown::PARAMS
            .iter()
            .position(|p| p.name == name)
            .unwrap();
        genome.parameters.set_at(i, value.parse().unwrap());
    }
    let start = std::time::Instant::now();
    let (plant, report) = sylva_grown::grow(&genome, genome.seed).unwrap();
    let took = start.elapsed();
    let top = plant
        .segments()
        .iter()
        .map(|s| s.end.y)
        .fold(0.0f32, f32::max);
    println!("{report:?}");
    println!("height {top:.2} m, grown in {took:?}");
}
