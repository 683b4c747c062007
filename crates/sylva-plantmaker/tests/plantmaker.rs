//! PlantMaker: both genome faces round-trip, every operator keeps genes legal and mixes its
//! parents, development is deterministic and bounded, gardens re-create their scenes, and the
//! examples grow into what their names say (counted here, looked at in the pictures test).
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use proptest::prelude::*;
use sylva_core::{MaterialKind, hash::stable_hash};
use sylva_evolve::{Crossover, IndividualId, Mutate, rng};
use sylva_model::DevelopError;
use sylva_plantmaker::garden::{footprint, place};
use sylva_plantmaker::variation::{Process, breed, crossover};
use sylva_plantmaker::{
    Garden, GardenError, Level, Mutation, Operator, Parent, PlantMaker, PlantMakerCrossover,
};

const EXAMPLES: [(&str, &str); 5] = [
    (
        "fern",
        include_str!("../../../examples/plantmaker/fern.json"),
    ),
    (
        "palm",
        include_str!("../../../examples/plantmaker/palm.json"),
    ),
    (
        "flowering-bush",
        include_str!("../../../examples/plantmaker/flowering-bush.json"),
    ),
    (
        "tulip",
        include_str!("../../../examples/plantmaker/tulip.json"),
    ),
    (
        "conifer",
        include_str!("../../../examples/plantmaker/conifer.json"),
    ),
];

fn example(name: &str) -> PlantMaker {
    let text = EXAMPLES.iter().find(|(n, _)| *n == name).unwrap().1;
    PlantMaker::from_json(text).unwrap()
}

/// A random genome of 1 to 6 segments of each kind.
fn random_genome(seed: u64) -> PlantMaker {
    let mut r = rng::seeded(seed);
    let n = 1 + (seed % 6) as usize;
    let m = 1 + (seed / 6 % 6) as usize;
    let k = 1 + (seed / 36 % 6) as usize;
    PlantMaker::random(n, m, k, &mut r)
}

/// Every code of `child` comes from some parent at the same place, or the child is one of
/// them; used to check that high-level crossover only copies.
fn codes(g: &PlantMaker) -> Vec<Vec<u32>> {
    g.branches
        .iter()
        .map(|b| b.codes().to_vec())
        .chain(g.fans.iter().map(|f| f.codes().to_vec()))
        .chain(g.inflorescences.iter().map(|i| i.codes().to_vec()))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn json_round_trips(seed in any::<u64>()) {
        let g = random_genome(seed);
        g.check().unwrap();
        let text = g.to_json();
        let back = PlantMaker::from_json(&text).unwrap();
        prop_assert_eq!(&back, &g);
        prop_assert_eq!(back.to_json(), text);
    }

    #[test]
    fn packed_round_trips(seed in any::<u64>()) {
        let g = random_genome(seed);
        let text = g.to_packed();
        let back = PlantMaker::from_packed(&text).unwrap();
        prop_assert_eq!(&back, &g);
        prop_assert_eq!(back.to_packed(), text);
    }

    #[test]
    fn crossover_keeps_genes_legal_and_copies(
        seeds in prop::collection::vec(any::<u64>(), 2..5),
        weights in prop::collection::vec(0.0f64..10.0, 4),
        level in 0usize..3,
        seed in any::<u64>(),
    ) {
        let genomes: Vec<PlantMaker> = seeds.iter().map(|&s| random_genome(s)).collect();
        let parents: Vec<Parent> = genomes
            .iter()
            .zip(&weights)
            .map(|(genome, &dominance)| Parent { genome, dominance })
            .collect();
        let level = [Level::Low, Level::Medium, Level::High][level];
        let bred = crossover(&parents, level, &mut rng::seeded(seed)).unwrap();
        bred.genome.check().unwrap();
        prop_assert!(!bred.parents.is_empty());
        prop_assert!(bred.parents.iter().all(|&p| p < parents.len()));
        // Low and medium level copy whole segments: each is some parent's (up to references
        // made legal), so its options and numbers other than references match a parent's.
        if level != Level::High {
            let child = &bred.genome;
            for (i, b) in child.branches.iter().enumerate() {
                prop_assert!(genomes.iter().any(|g| g.branches.get(i) == Some(b)));
            }
        }
        // The child's codes are each some parent's code in the same place.
        let child = codes(&bred.genome);
        let all: Vec<Vec<Vec<u32>>> = genomes.iter().map(codes).collect();
        let (n, m) = (bred.genome.branches.len(), bred.genome.fans.len());
        for (s, seg) in child.iter().enumerate() {
            let is_fan = s >= n && s < n + m;
            let is_infl = s >= n + m;
            for (v, &code) in seg.iter().enumerate() {
                let reference = (is_fan && v == 0) || (is_infl && v == 3);
                if !reference {
                    prop_assert!(
                        all.iter().any(|p| p.iter().any(|ps| ps.len() == seg.len() && ps[v] == code)),
                        "segment {} variable {} code {} from no parent", s, v, code
                    );
                }
            }
        }
    }

    #[test]
    fn mutation_keeps_genes_legal(seed in any::<u64>(), rate in 0.0f64..=1.0, spread in 0.0f64..1.0) {
        let mut g = random_genome(seed);
        Mutation { rate, spread }.mutate(&mut g, &mut rng::seeded(seed ^ 1));
        g.check().unwrap();
        let packed = g.to_packed();
        prop_assert_eq!(PlantMaker::from_packed(&packed).unwrap(), g);
    }

    #[test]
    fn random_genomes_grow_or_report_their_size(seed in any::<u64>()) {
        let g = random_genome(seed);
        match g.develop(seed) {
            Ok(plant) => {
                prop_assert!(!plant.segments().is_empty());
                prop_assert!(plant.segments().len() + plant.organs().len() <= sylva_plantmaker::MAX_PARTS);
                prop_assert!(plant.segments().iter().all(|s| s.start.is_finite() && s.end.is_finite()));
            }
            Err(DevelopError::TooLarge { .. }) => {}
            Err(e) => prop_assert!(false, "{e}"),
        }
    }

    #[test]
    fn edited_packed_text_never_panics(seed in any::<u64>(), edits in prop::collection::vec((any::<usize>(), any::<u8>()), 1..6)) {
        let mut bytes = random_genome(seed).to_packed().into_bytes();
        for (at, byte) in edits {
            let at = at % bytes.len();
            bytes[at] = byte;
        }
        if let Ok(text) = String::from_utf8(bytes)
            && let Ok(g) = PlantMaker::from_packed(&text)
        {
            g.check().unwrap();
        }
    }
}

#[test]
fn children_mix_their_parents() {
    let (a, b) = (example("palm"), example("tulip"));
    let parents = [
        Parent {
            genome: &a,
            dominance: 1.0,
        },
        Parent {
            genome: &b,
            dominance: 1.0,
        },
    ];
    let mut r = rng::seeded(5);
    for _ in 0..20 {
        let low = crossover(&parents, Level::Low, &mut r).unwrap();
        assert_eq!(low.parents, vec![0, 1]);
        let g = &low.genome;
        let from_a = g.branches == a.branches && g.inflorescences == b.inflorescences;
        let from_b = g.branches == b.branches && g.inflorescences == a.inflorescences;
        assert!(
            from_a || from_b,
            "low level: branches from one, inflorescences from the other"
        );

        let high = crossover(&parents, Level::High, &mut r).unwrap();
        assert_eq!(high.parents, vec![0, 1]);
        let mixed = codes(&high.genome);
        let (ca, cb) = (codes(&a), codes(&b));
        let same_a = mixed
            .iter()
            .flatten()
            .zip(ca.iter().flatten())
            .filter(|(x, y)| x == y)
            .count();
        let same_b = mixed
            .iter()
            .flatten()
            .zip(cb.iter().flatten())
            .filter(|(x, y)| x == y)
            .count();
        assert!(same_a > 20 && same_b > 20, "{same_a} {same_b}");
    }
}

#[test]
fn dominance_gives_more_genes() {
    let (a, b) = (example("palm"), example("tulip"));
    let parents = [
        Parent {
            genome: &a,
            dominance: 9.0,
        },
        Parent {
            genome: &b,
            dominance: 1.0,
        },
    ];
    let mut r = rng::seeded(8);
    let (mut from_a, mut from_b) = (0, 0);
    for _ in 0..20 {
        let child = codes(&crossover(&parents, Level::High, &mut r).unwrap().genome);
        for ((x, y), z) in child
            .iter()
            .flatten()
            .zip(codes(&a).iter().flatten())
            .zip(codes(&b).iter().flatten())
        {
            if x == y && x != z {
                from_a += 1;
            } else if x == z && x != y {
                from_b += 1;
            }
        }
    }
    assert!(from_a > 5 * from_b, "{from_a} vs {from_b}");
    // Zero dominance gives nothing while others have some.
    let parents = [
        Parent {
            genome: &a,
            dominance: 1.0,
        },
        Parent {
            genome: &b,
            dominance: 0.0,
        },
    ];
    let child = crossover(&parents, Level::Medium, &mut r).unwrap();
    assert_eq!(child.genome, a);
    assert_eq!(child.parents, vec![0]);
}

#[test]
fn lineage_and_engine_traits() {
    let (a, b) = (example("fern"), example("conifer"));
    let parents = [
        Parent {
            genome: &a,
            dominance: 1.0,
        },
        Parent {
            genome: &b,
            dominance: 2.0,
        },
    ];
    let mut r = rng::seeded(1);
    let bred = breed(
        &parents,
        Operator::from_depth(Process::Crossover, 0.5),
        &mut r,
    )
    .unwrap();
    let origin = bred.origin(4, &[IndividualId(10), IndividualId(11)]);
    assert_eq!(origin.operator, "crossover-medium");
    assert_eq!(origin.generation, 4);
    assert!(!origin.parents.is_empty());
    let mutated = breed(
        &parents[..1],
        Operator::from_depth(Process::Mutation, 0.2),
        &mut r,
    )
    .unwrap();
    assert_eq!(
        mutated.origin(1, &[IndividualId(3)]).parents,
        vec![IndividualId(3)]
    );
    assert!(breed(&parents, Operator::Mutation(Mutation::default()), &mut r).is_err());

    // The generic engine's traits.
    let child = PlantMakerCrossover { level: Level::High }.crossover(&a, &b, &mut r);
    child.check().unwrap();
    let mut m = a.clone();
    Mutation::default().mutate(&mut m, &mut r);
    m.check().unwrap();
    assert_ne!(m, a);
}

#[test]
fn seeds_give_similar_but_different_plants() {
    let g = example("flowering-bush");
    let plants: Vec<_> = (0..10).map(|s| g.develop(s).unwrap()).collect();
    for (i, p) in plants.iter().enumerate() {
        assert_eq!(p, &g.develop(i as u64).unwrap(), "same seed, same plant");
        for q in &plants[..i] {
            assert_ne!(p.segments(), q.segments());
        }
        // Similar: same materials kinds, heights within a factor of 1.5 of the first.
        let ratio = p.height() / plants[0].height();
        assert!((0.66..1.5).contains(&ratio), "{ratio}");
    }
}

#[test]
fn golden_plant() {
    // Locks development: a change here changes every stored plant.
    let plant = PlantMaker::default().develop(1).unwrap();
    let bytes = serde_json::to_vec(&plant).unwrap();
    assert_eq!(plant.segments().len(), 91);
    assert_eq!(plant.organs().len(), 15);
    assert_eq!(stable_hash(&bytes), GOLDEN, "{:#x}", stable_hash(&bytes));
}
const GOLDEN: u64 = 0x55f6_6c41_cc6a_2137;

#[test]
fn examples_are_canonical_and_grow_as_named() {
    for (name, text) in EXAMPLES {
        let g = PlantMaker::from_json(text).unwrap();
        assert_eq!(g.to_json(), text, "{name} is written as Sylva writes it");
        assert_eq!(PlantMaker::from_packed(&g.to_packed()).unwrap(), g);
        let p = g.develop(g.seed).unwrap();
        let kinds: Vec<MaterialKind> = p.materials().iter().map(|m| m.kind).collect();
        let height = p.height();
        match name {
            "tulip" => {
                assert!(
                    kinds.contains(&MaterialKind::Flower) && kinds.contains(&MaterialKind::Leaf)
                );
                assert!((0.2..0.8).contains(&height), "{height}");
            }
            "palm" => {
                assert!(kinds.contains(&MaterialKind::Leaf));
                assert!((3.0..10.0).contains(&height), "{height}");
            }
            "conifer" => {
                assert!((3.0..10.0).contains(&height), "{height}");
                let b = p.bounds();
                assert!(b.max.x - b.min.x < height, "narrower than tall");
            }
            "fern" => {
                assert!(kinds.contains(&MaterialKind::Leaf));
                assert!(height < 1.0, "{height}");
            }
            "flowering-bush" => {
                assert!(
                    kinds.contains(&MaterialKind::Flower) && kinds.contains(&MaterialKind::Leaf)
                );
                assert!(height < 1.5, "{height}");
            }
            _ => unreachable!(),
        }
    }
}

#[test]
fn gardens_recreate_their_scene() {
    let mut garden = Garden::new(example("tulip"), 12, [5.0, 4.0], 42);
    garden.add(example("fern"), 3);
    let text = garden.to_json();
    let a = garden.grow().unwrap();
    let b = Garden::from_json(&text).unwrap().grow().unwrap();
    assert_eq!(a.placements, b.placements);
    assert_eq!(a.plants, b.plants);
    assert_eq!(a.placements.len(), 15);
    assert_eq!(a.placements[14].group, 1);
    for (i, p) in a.placements.iter().enumerate() {
        assert!((p.radius - footprint(&a.plants[i])).abs() < 1e-6);
        for q in &a.placements[..i] {
            let d = p.translation.distance(q.translation);
            assert!(d >= p.radius + q.radius - 1e-4, "overlap");
        }
    }
    // Seeds differ, so plants differ.
    assert_ne!(a.plants[0].segments(), a.plants[1].segments());

    let crowded = Garden::new(example("palm"), 40, [10.0, 10.0], 1);
    assert!(matches!(
        crowded.grow(),
        Err(GardenError::DoesNotFit { .. })
    ));
    let tiny = Garden::new(example("palm"), 1, [1.0, 1.0], 1);
    assert!(matches!(tiny.grow(), Err(GardenError::TooWide { .. })));
    let e = Garden::from_json(&text.replacen("5.0", "-5.0", 1)).unwrap_err();
    assert!(e.message.contains("area"), "{e}");
}

#[test]
fn placement_is_deterministic_and_spaced() {
    let radii: Vec<f32> = (0..200).map(|i| 0.1 + 0.02 * (i % 5) as f32).collect();
    let a = place(&radii, [20.0, 20.0], 9, 1000).unwrap();
    assert_eq!(a, place(&radii, [20.0, 20.0], 9, 1000).unwrap());
    assert_ne!(a, place(&radii, [20.0, 20.0], 10, 1000).unwrap());
}

#[test]
fn the_packed_example_is_the_tulip() {
    let text = include_str!("../../../examples/plantmaker/tulip.packed");
    let g = PlantMaker::from_packed(text).unwrap();
    assert_eq!(g, example("tulip"));
    assert_eq!(g.to_packed(), text);
}
