//! Genomes as vectors for optimisers outside Sylva ([`GenomeSpace`]): every model decodes
//! any vector into a plant, scores do not depend on threads, and bad vectors and options are
//! refused by name.

#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::Path;

use rand::RngExt;
use sylva::core::par::Pool;
use sylva::core::rng;
use sylva::evolution::{Coding, Codons, SpaceOptions};
use sylva::{Config, GenomeSpace, Varieties};

#[test]
fn codons_are_the_draws_then_the_stream() {
    let entries = [0.0, 0.5, 1.0, 0.25];
    let mut codons = Codons::new(&entries, rng::seeded(3));
    let mut r = || rand::Rng::next_u64(&mut codons);
    assert_eq!([r(), r(), r(), r()], [0, 1 << 63, u64::MAX, 1 << 62]);
    let mut stream = rng::seeded(3);
    assert_eq!(r(), rand::Rng::next_u64(&mut stream));
    // A 32-bit draw is the upper half; a range draw lands where the entry says. (An
    // entry at a cell's very edge, as 0.3 · 10 is in binary, reads the next one too:
    // rand's unbiased ranges.)
    let mut codons = Codons::new(&[0.75, 0.35, 0.99, 0.1, 0.6], rng::seeded(3));
    assert_eq!(rand::Rng::next_u32(&mut codons), 3 << 30);
    assert_eq!(codons.random_range(0..10u32), 3);
    assert_eq!(codons.random_range(0..10u32), 9);
    assert!(codons.random_bool(0.2));
    assert!(!codons.random_bool(0.5));
    assert_eq!(codons.drawn(), 5);
}

fn config(toml: &str) -> Config {
    sylva::Registry::standard()
        .parse_config(Path::new("space.toml"), toml)
        .expect("a valid config")
}

#[test]
fn every_model_decodes_any_vector_into_a_plant() {
    for model in ["bintree", "automata", "plantmaker", "lsystem"] {
        let config = config(&format!("model = \"{model}\"\n"));
        let space = GenomeSpace::new(&config, Vec::new(), &SpaceOptions::default()).unwrap();
        let direct = matches!(model, "bintree" | "plantmaker");
        assert_eq!(space.coding() == Coding::Direct, direct, "{model}");
        let low: Vec<f64> = space.bounds().iter().map(|b| b[0]).collect();
        let high: Vec<f64> = space.bounds().iter().map(|b| b[1]).collect();
        let mut rng = rng::seeded(5);
        let middle: Vec<f64> = space
            .bounds()
            .iter()
            .map(|[lo, hi]| rng.random_range(*lo..=*hi))
            .collect();
        for x in [&low, &high, &middle] {
            let genome = space.decode(x).unwrap();
            assert_eq!(genome.model(), model);
            // Same vector, same genome.
            assert_eq!(genome, space.decode(x).unwrap());
            genome.develop(genome.default_seed()).unwrap();
        }
    }
}

#[test]
fn scores_are_the_maps_and_do_not_depend_on_threads() {
    let config = config(
        "model = \"bintree\"\n[run]\nstrategy = \"map-elites\"\nseed = 4\n[map]\n\
         initial = 12\nbatch = 4\n",
    );
    let space = GenomeSpace::new(&config, Vec::new(), &SpaceOptions::default()).unwrap();
    let map = Varieties::start(&config, Vec::new(), Pool::Serial).unwrap();
    let elites = map.varieties();
    assert!(!elites.is_empty());
    let mut xs = Vec::new();
    for v in &elites {
        xs.extend(space.encode(&v.member.genome).unwrap());
    }
    let serial = space.evaluate(&xs, &Pool::Serial).unwrap();
    let parallel = space
        .evaluate(&xs, &Pool::with_threads(3).unwrap())
        .unwrap();
    assert_eq!(serial, parallel);
    for (i, v) in elites.iter().enumerate() {
        assert_eq!(serial.fitness[i], v.member.total());
        assert_eq!(serial.descriptors[2 * i..2 * i + 2], v.descriptors[..]);
    }
}

#[test]
fn bad_vectors_and_options_are_refused_by_name() {
    let config = config("model = \"automata\"\n");
    let space = GenomeSpace::new(
        &config,
        Vec::new(),
        &SpaceOptions {
            dim: Some(40),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((space.coding(), space.dim()), (Coding::Codons, 40));
    let e = space.decode(&[0.5; 39]).unwrap_err();
    assert!(e.location == "x" && e.message.contains("40 entries"), "{e}");
    let mut xs = vec![0.5; 80];
    xs[43] = f64::NAN;
    let e = space.evaluate(&xs, &Pool::Serial).unwrap_err().to_string();
    assert!(
        e.contains("X") && e.contains("row 1, entry 3 is NaN"),
        "{e}"
    );
    let e = space.decode_many(&xs[..79], &Pool::Serial).unwrap_err();
    assert!(
        e.location == "X" && e.message.contains("whole vectors"),
        "{e}"
    );
    let g = space.decode(&[0.5; 40]).unwrap();
    assert_eq!(space.encode(&g).unwrap_err().location, "genome");
    let direct = SpaceOptions {
        coding: Some(Coding::Direct),
        ..Default::default()
    };
    let e = GenomeSpace::new(&config, Vec::new(), &direct)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("coding") && e.contains("no direct coding"),
        "{e}"
    );
    let bintree = crate::config("model = \"bintree\"\n");
    let e = GenomeSpace::new(
        &bintree,
        Vec::new(),
        &SpaceOptions {
            dim: Some(65),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("dim") && e.contains("11 entries"), "{e}");
    // Entries outside the bounds are clamped to them.
    let space = GenomeSpace::new(&bintree, Vec::new(), &SpaceOptions::default()).unwrap();
    let low: Vec<f64> = space.bounds().iter().map(|b| b[0]).collect();
    let below: Vec<f64> = low.iter().map(|v| v - 100.0).collect();
    assert_eq!(space.decode(&below).unwrap(), space.decode(&low).unwrap());
}

/// The shipped PlantMaker map starts from the five examples, whose segment counts differ
/// (5, 6 or 18 inflorescences; 5 or 7 fans) and mix in their crossovers: every elite of it
/// still has a vector, and decodes back to itself (its own growth seed aside, which is no
/// entry).
#[test]
fn every_elite_of_the_plantmaker_example_map_has_a_vector() {
    use sylva_plantmaker::{PlantMaker, PlantMakerModel};
    let registry = sylva::Registry::standard();
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/plantmaker/varieties.toml");
    // A smaller first generation and batches, for a test's time.
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("initial = 100\nbatch = 50", "initial = 30\nbatch = 20");
    let config = registry.parse_config(&path, &text).unwrap();
    let start = config
        .load_start(&registry, path.parent().unwrap())
        .unwrap();
    let pool = Pool::with_threads(2).unwrap();
    let mut map = Varieties::start(&config, start.clone(), pool).unwrap();
    for _ in 0..3 {
        map.step();
    }
    let space = GenomeSpace::new(&config, start, &SpaceOptions::default()).unwrap();
    let elites = map.varieties();
    let typed = |g: &sylva::Genome| -> PlantMaker { g.get::<PlantMakerModel>().unwrap().clone() };
    let shapes: std::collections::HashSet<_> = (elites.iter())
        .map(|v| {
            let g = typed(&v.member.genome);
            (g.branches.len(), g.fans.len(), g.inflorescences.len())
        })
        .collect();
    assert!(
        shapes.len() > 1,
        "the elites all have the counts {shapes:?}"
    );
    for v in &elites {
        let x = space.encode(&v.member.genome).unwrap();
        let back = typed(&space.decode(&x).unwrap());
        let elite = typed(&v.member.genome);
        assert_eq!(
            back,
            PlantMaker {
                seed: space.seed(),
                ..elite
            }
        );
    }
}
