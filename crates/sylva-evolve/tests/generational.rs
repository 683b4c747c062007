//! The generational tournament strategy keeps the engine's promises: it improves, it is
//! identical for any thread count, it resumes exactly, it validates its rates and elitism
//! never loses the best.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::collections::HashMap;

use rand::Rng;
use sylva_evolve::bits::{BitFlip, BitString, OnePoint};
use sylva_evolve::{
    Checkpoint, Fitness, Generational, GenerationalError, GenerationalSettings, Pool, Problem, Run,
    RunSettings,
};

type Bits = BitString<2>;

/// Ones count with a bonus for alternating neighbours: rugged enough to need selection.
struct Rugged;

impl Problem for Rugged {
    type Genome = Bits;
    fn term_names(&self) -> Vec<String> {
        vec!["ones".into(), "alternations".into()]
    }
    fn evaluate(&self, g: &Bits) -> Fitness {
        let ones = (0..g.len()).filter(|&i| g.get(i)).count() as f64;
        let alt = (1..g.len()).filter(|&i| g.get(i) != g.get(i - 1)).count() as f64;
        Fitness::new(ones + 0.5 * alt, &[ones, alt])
    }
    fn random_genome<R: Rng + ?Sized>(&self, rng: &mut R) -> Bits {
        Bits::random(100, rng).unwrap()
    }
}

type Strat = Generational<OnePoint, BitFlip>;

fn strategy(settings: GenerationalSettings) -> Strat {
    Generational::new(OnePoint, BitFlip { rate: 0.02 }, settings).unwrap()
}

fn settings(population: usize) -> RunSettings {
    RunSettings {
        seed: 7,
        population,
        keep_history: 0,
    }
}

/// Population and statistics without wall time.
fn fingerprint(run: &Run<Rugged, Strat>) -> String {
    let mut stats = run.stats().to_vec();
    for s in &mut stats {
        s.seconds = 0.0;
    }
    serde_json::to_string(&(run.population(), stats)).unwrap()
}

#[test]
fn improves() {
    let mut run = Run::new(
        Rugged,
        strategy(GenerationalSettings::default()),
        Pool::Serial,
        settings(80),
    )
    .unwrap();
    let (first_best, first_mean) = (run.stats()[0].best, run.stats()[0].mean);
    run.run_batch(30, |_| {});
    let last = run.stats().last().unwrap();
    // Random genomes score about 75 and the best possible about 100.
    assert!(last.best > first_best, "{first_best} -> {}", last.best);
    assert!(last.best >= 98.0, "{}", last.best);
    assert!(
        last.mean > first_mean + 15.0,
        "{first_mean} -> {}",
        last.mean
    );
}

#[test]
fn same_result_for_one_and_two_threads() {
    let prints: Vec<String> = [1, 2]
        .into_iter()
        .map(|threads| {
            let ev = Pool::with_threads(threads).unwrap();
            let mut run = Run::new(
                Rugged,
                strategy(GenerationalSettings::default()),
                ev,
                settings(64),
            )
            .unwrap();
            run.run_batch(20, |_| {});
            fingerprint(&run)
        })
        .collect();
    assert_eq!(prints[0], prints[1]);
}

#[test]
fn resume_from_checkpoint_equals_uninterrupted() {
    let make = || strategy(GenerationalSettings::default());
    let mut straight = Run::new(Rugged, make(), Pool::Serial, settings(40)).unwrap();
    straight.run_batch(15, |_| {});

    let mut first = Run::new(Rugged, make(), Pool::Serial, settings(40)).unwrap();
    first.run_batch(6, |_| {});
    let json = serde_json::to_string(&first.checkpoint()).unwrap();
    drop(first);
    let checkpoint: Checkpoint<Bits> = serde_json::from_str(&json).unwrap();
    let mut resumed = Run::resume(Rugged, make(), Pool::Serial, checkpoint).unwrap();
    resumed.run_batch(9, |_| {});
    assert_eq!(fingerprint(&resumed), fingerprint(&straight));
}

#[test]
fn rates_and_tournament_are_validated() {
    let bad = |s: GenerationalSettings| Generational::new(OnePoint, BitFlip { rate: 0.1 }, s);
    let base = GenerationalSettings::default();
    assert!(matches!(
        bad(GenerationalSettings {
            tournament: 0,
            ..base.clone()
        }),
        Err(GenerationalError::Tournament(0))
    ));
    assert!(matches!(
        bad(GenerationalSettings {
            tournament: 1_000_000_000_000_000,
            ..base.clone()
        }),
        Err(GenerationalError::Tournament(_))
    ));
    for value in [-0.1, 1.5, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            bad(GenerationalSettings {
                mutation: value,
                ..base.clone()
            }),
            Err(GenerationalError::BadRate {
                name: "mutation",
                ..
            })
        ));
    }
    let err = bad(GenerationalSettings {
        crossover: 0.5,
        ..base.clone()
    })
    .unwrap_err();
    assert!(matches!(err, GenerationalError::RateSum { .. }));
    assert!(err.to_string().contains("add up to 1"), "{err}");
    // Sums that are 1 up to rounding pass.
    assert!(
        bad(GenerationalSettings {
            crossover: 0.7,
            reproduction: 0.2,
            mutation: 0.1,
            ..base
        })
        .is_ok()
    );
}

#[test]
fn settings_read_from_config_with_defaults() {
    let s: GenerationalSettings =
        serde_json::from_str(r#"{"tournament": 4, "reevaluate": false}"#).unwrap();
    assert_eq!(s.tournament, 4);
    assert!(!s.reevaluate);
    assert_eq!(s.crossover, 0.88);
    let err = serde_json::from_str::<GenerationalSettings>(r#"{"tournamnet": 4}"#).unwrap_err();
    assert!(err.to_string().contains("unknown field"), "{err}");
}

#[test]
fn elitism_keeps_the_best() {
    // Heavy mutation and no crossover: without elitism the best is easily lost.
    let harsh = GenerationalSettings {
        crossover: 0.0,
        reproduction: 0.0,
        mutation: 1.0,
        tournament: 2,
        ..GenerationalSettings::default()
    };
    let make = |elitism| {
        Generational::new(
            OnePoint,
            BitFlip { rate: 0.2 },
            GenerationalSettings {
                elitism,
                ..harsh.clone()
            },
        )
        .unwrap()
    };
    let mut run = Run::new(Rugged, make(2), Pool::Serial, settings(20)).unwrap();
    for _ in 0..30 {
        let before = run.best().clone();
        run.step();
        assert!(run.best().total() >= before.total());
        let elite = &run.population()[0];
        assert_eq!(elite.genome, before.genome);
        assert_eq!(elite.origin.operator, "elite");
        assert_eq!(elite.origin.parents, vec![before.id]);
    }
    let mut lossy = Run::new(Rugged, make(0), Pool::Serial, settings(20)).unwrap();
    let mut lost = false;
    for _ in 0..30 {
        let before = lossy.best().total();
        lossy.step();
        lost |= lossy.best().total() < before;
    }
    assert!(
        lost,
        "without elitism this setting loses the best at least once"
    );
}

#[test]
fn operators_follow_the_rates_and_record_parents() {
    let mut run = Run::new(
        Rugged,
        strategy(GenerationalSettings::default()),
        Pool::Serial,
        settings(2000),
    )
    .unwrap();
    let parents: Vec<_> = run.population().iter().map(|i| i.id).collect();
    run.step();
    let mut counts: HashMap<String, usize> = HashMap::new();
    for ind in run.population() {
        *counts.entry(ind.origin.operator.to_string()).or_default() += 1;
        let expected = if ind.origin.operator == "crossover" {
            2
        } else {
            1
        };
        assert_eq!(ind.origin.parents.len(), expected);
        assert!(ind.origin.parents.iter().all(|p| parents.contains(p)));
        assert_eq!(ind.origin.generation, 1);
        assert!(ind.fitness.is_some());
    }
    assert_eq!(counts["elite"], 1);
    let share = |op: &str| counts.get(op).copied().unwrap_or(0) as f64 / 1999.0;
    assert!((share("crossover") - 0.88).abs() < 0.03, "{counts:?}");
    assert!((share("reproduction") - 0.10).abs() < 0.03, "{counts:?}");
    assert!((share("mutation") - 0.02).abs() < 0.015, "{counts:?}");
}

#[test]
fn copies_reuse_fitness_only_when_asked() {
    let evaluations = |reevaluate| {
        let s = GenerationalSettings {
            reevaluate,
            ..GenerationalSettings::default()
        };
        let mut run = Run::new(Rugged, strategy(s), Pool::Serial, settings(500)).unwrap();
        run.step();
        let copies = run
            .population()
            .iter()
            .filter(|i| matches!(&*i.origin.operator, "elite" | "reproduction"))
            .count() as u64;
        (run.stats()[1].evaluations, copies)
    };
    let (all, _) = evaluations(true);
    assert_eq!(all, 500);
    let (fewer, copies) = evaluations(false);
    assert_eq!(fewer, 500 - copies);
    assert!(copies > 20);
}

#[test]
fn demes_breed_apart_and_migrate_in_a_ring() {
    let demes = GenerationalSettings {
        demes: 4,
        migrate_every: 3,
        migrants: 2,
        ..GenerationalSettings::default()
    };
    let mut run = Run::new(Rugged, strategy(demes), Pool::Serial, settings(40)).unwrap();
    // Slots 10d..10d+10 are deme d.
    let deme = |slot: usize| slot / 10;
    for generation in 1..=9u32 {
        let before: HashMap<_, _> = run
            .population()
            .iter()
            .enumerate()
            .map(|(slot, i)| (i.id, (slot, i.total())))
            .collect();
        run.step();
        let migration = generation % 3 == 0;
        for (slot, ind) in run.population().iter().enumerate() {
            let op = &*ind.origin.operator;
            let from: Vec<usize> = ind.origin.parents.iter().map(|p| before[p].0).collect();
            match slot % 10 {
                0 => assert_eq!(op, "elite"),
                1 | 2 if migration => {
                    assert_eq!(op, "migrant");
                    assert_eq!(deme(from[0]), (deme(slot) + 3) % 4, "ring");
                }
                _ => {
                    assert!(op != "elite" && op != "migrant", "{op} in slot {slot}");
                    assert!(
                        from.iter().all(|&p| deme(p) == deme(slot)),
                        "{from:?} {slot}"
                    );
                }
            }
            if op == "elite" {
                // Each deme keeps its own best.
                let best = before
                    .values()
                    .filter(|(s, _)| deme(*s) == deme(slot))
                    .map(|(_, t)| *t)
                    .fold(f64::NEG_INFINITY, f64::max);
                assert_eq!(ind.total(), best);
            }
        }
    }
}

#[test]
fn demes_are_the_same_for_one_and_two_threads_and_one_deme_is_the_plain_step() {
    let demes = GenerationalSettings {
        demes: 3,
        migrate_every: 2,
        ..GenerationalSettings::default()
    };
    let prints: Vec<String> = [1, 2]
        .into_iter()
        .map(|threads| {
            let ev = Pool::with_threads(threads).unwrap();
            let mut run = Run::new(Rugged, strategy(demes.clone()), ev, settings(64)).unwrap();
            run.run_batch(12, |_| {});
            fingerprint(&run)
        })
        .collect();
    assert_eq!(prints[0], prints[1]);
    let plain = |s: GenerationalSettings| {
        let mut run = Run::new(Rugged, strategy(s), Pool::Serial, settings(64)).unwrap();
        run.run_batch(12, |_| {});
        fingerprint(&run)
    };
    let one = GenerationalSettings {
        demes: 1,
        migrate_every: 1,
        migrants: 5,
        ..GenerationalSettings::default()
    };
    assert_eq!(plain(one), plain(GenerationalSettings::default()));
    assert_ne!(prints[0], plain(GenerationalSettings::default()));
}

#[test]
fn deme_settings_are_checked_and_stay_out_of_default_configs() {
    for (text, field) in [
        (r#"{"demes": 0}"#, "demes"),
        (r#"{"demes": 5000}"#, "demes"),
        (r#"{"migrate_every": 0}"#, "migrate_every"),
        (r#"{"migrants": -1}"#, "migrants"),
    ] {
        let err = serde_json::from_str::<GenerationalSettings>(text).unwrap_err();
        assert!(err.to_string().contains(field), "{text}: {err}");
    }
    let written = serde_json::to_string(&GenerationalSettings::default()).unwrap();
    assert!(
        !written.contains("demes") && !written.contains("migra"),
        "{written}"
    );
    let bad = Generational::new(
        OnePoint,
        BitFlip { rate: 0.1 },
        GenerationalSettings {
            migrate_every: 0,
            ..GenerationalSettings::default()
        },
    );
    assert!(matches!(bad, Err(GenerationalError::MigrateEvery)));
}
