//! What a front end adds to a run ([`RunHooks`]): a stop that cuts generations short and
//! leaves the run whole, and a fitness term of its own scored a batch of plants at a time.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::Path;
use std::sync::{Arc, Mutex};

use sylva::evolution::{ScorerError, Stop};
use sylva::{Config, Error, Evolution, Grown, OwnTerm, PlantScorer, RunHooks};
use sylva_core::par::Pool;

fn small(model: &str, extra: &str) -> Config {
    sylva::Registry::standard()
        .parse_config(
            Path::new("c.toml"),
            &format!(
                "model = \"{model}\"\n[run]\ngenerations = 4\npopulation = 8\nseed = 5\n{extra}"
            ),
        )
        .unwrap()
}

/// Every figure of a run's statistics but the wall-clock seconds.
fn rows(e: &Evolution) -> Vec<(u32, f64, f64, Vec<f64>)> {
    e.stats()
        .iter()
        .map(|s| (s.generation, s.best, s.mean, s.best_terms.clone()))
        .collect()
}

#[test]
fn a_stopped_generation_leaves_the_run_whole_and_it_goes_on_exactly() {
    for (model, extra) in [
        ("bintree", ""),
        ("automata", "[automata.growth]\niterations = 30\n"),
        ("plantmaker", ""),
    ] {
        let c = small(model, extra);
        let mut straight = Evolution::start(&c, Vec::new(), Pool::Serial).unwrap();
        straight.step_batch(4, |_| {}).unwrap();

        let stop = Stop::new();
        let hooks = RunHooks {
            stop: Some(stop.clone()),
            term: None,
        };
        let pool = Pool::with_threads(2).unwrap();
        let mut stopped = Evolution::start_with(&c, Vec::new(), pool, hooks).unwrap();
        stopped.step_batch(2, |_| {}).unwrap();
        let before = (stopped.checkpoint().unwrap(), stopped.population());
        // Set before the step, the stop ends its first job: the step is cut short.
        stop.stop();
        assert!(matches!(stopped.step(), Err(Error::Stopped(_))), "{model}");
        assert!(matches!(stopped.step(), Err(Error::Stopped(_))), "{model}");
        // The run reads as it was before the step, and checkpoints the same bytes.
        assert_eq!(stopped.generation(), 2, "{model}");
        assert_eq!(stopped.stats().len(), 3, "{model}");
        assert_eq!(stopped.checkpoint().unwrap(), before.0, "{model}");
        assert_eq!(stopped.population(), before.1, "{model}");
        assert_eq!(stopped.best(), straight_best_at(&c, 2), "{model}");
        // Let go, it steps on as if it had never been stopped.
        stop.reset();
        stopped.step_batch(2, |_| {}).unwrap();
        assert_eq!(rows(&stopped), rows(&straight), "{model}");
        assert_eq!(stopped.best(), straight.best(), "{model}");
    }
}

/// The best member of a run of `c` after `generations` generations.
fn straight_best_at(c: &Config, generations: u32) -> sylva::Member {
    let mut run = Evolution::start(c, Vec::new(), Pool::Serial).unwrap();
    run.step_batch(generations, |_| {}).unwrap();
    run.best()
}

#[test]
fn a_stopped_start_or_resume_makes_nothing() {
    let c = small("bintree", "");
    let stop = Stop::new();
    stop.stop();
    let hooks = RunHooks {
        stop: Some(stop.clone()),
        term: None,
    };
    let e = Evolution::start_with(&c, Vec::new(), Pool::Serial, hooks.clone()).unwrap_err();
    assert!(matches!(e, Error::Stopped(_)), "{e}");
    let run = Evolution::start(&c, Vec::new(), Pool::Serial).unwrap();
    let text = run.checkpoint().unwrap();
    let e =
        Evolution::resume_with(&c, Path::new("c.json"), &text, Pool::Serial, hooks).unwrap_err();
    assert!(matches!(e, Error::Stopped(_)), "{e}");
}

/// A plant's height, a batch at a time, each batch's size noted.
#[derive(Default)]
struct Height {
    batches: Mutex<Vec<usize>>,
}

impl PlantScorer for Height {
    fn score(&self, plants: Vec<Grown>) -> Result<Vec<f64>, ScorerError> {
        self.batches.lock().unwrap().push(plants.len());
        Ok(plants.iter().map(|p| f64::from(p.plant.height())).collect())
    }
}

fn own(scorer: Arc<dyn PlantScorer>, beside: bool, batch: usize) -> RunHooks {
    RunHooks {
        stop: None,
        term: Some(OwnTerm {
            name: "mine".into(),
            scorer,
            weight: 2.0,
            beside,
            batch,
        }),
    }
}

#[test]
fn an_own_term_joins_the_model_s_terms_or_replaces_them_in_batches() {
    let c = small("plantmaker", "").clone();
    let plain = Evolution::start(&c, Vec::new(), Pool::Serial).unwrap();
    let height = Arc::new(Height::default());
    let mut beside =
        Evolution::start_with(&c, Vec::new(), Pool::Serial, own(height.clone(), true, 3)).unwrap();
    let mut names = plain.term_names().to_vec();
    names.push("mine".into());
    assert_eq!(beside.term_names(), names);
    // Generation 0 scored in batches of at most 3 (the eight, less any repeats).
    let batches = height.batches.lock().unwrap().clone();
    assert!(
        batches.iter().all(|&b| b <= 3) && batches.iter().sum::<usize>() <= 8,
        "{batches:?}"
    );
    for m in beside.population() {
        let f = m.fitness.unwrap();
        let h = f64::from(
            sylva::Grown::grow(m.genome.clone(), &Default::default())
                .unwrap()
                .plant
                .height(),
        );
        assert_eq!(*f.terms().last().unwrap(), h);
        let own_total = plain
            .population()
            .iter()
            .find(|p| p.genome == m.genome)
            .map(|p| p.total());
        if let Some(t) = own_total {
            assert_eq!(f.total(), t + 2.0 * h);
        }
    }
    // A bred generation's offspring are foreseen and scored in batches too: none is scored
    // alone (a batch of one would only come from the last of a generation's batches).
    height.batches.lock().unwrap().clear();
    beside.step_batch(2, |_| {}).unwrap();
    let batches = height.batches.lock().unwrap().clone();
    assert!(
        batches.iter().filter(|&&b| b < 3).count() <= 2,
        "{batches:?}"
    );
    // With room for all, each generation is one call.
    let whole = Arc::new(Height::default());
    let mut run =
        Evolution::start_with(&c, Vec::new(), Pool::Serial, own(whole.clone(), true, 1000))
            .unwrap();
    run.step_batch(3, |_| {}).unwrap();
    assert_eq!(whole.batches.lock().unwrap().len(), 4);

    // The same on two threads, and alone in place of the model's terms.
    let mut threads = Evolution::start_with(
        &c,
        Vec::new(),
        Pool::with_threads(2).unwrap(),
        own(Arc::new(Height::default()), true, 3),
    )
    .unwrap();
    threads.step_batch(2, |_| {}).unwrap();
    assert_eq!(rows(&threads), rows(&beside));
    let mut alone = Evolution::start_with(
        &c,
        Vec::new(),
        Pool::Serial,
        own(Arc::new(Height::default()), false, 64),
    )
    .unwrap();
    assert_eq!(alone.term_names(), ["mine"]);
    alone.step_batch(3, |_| {}).unwrap();
    let best = alone.best();
    let h = f64::from(
        sylva::Grown::grow(best.genome.clone(), &Default::default())
            .unwrap()
            .plant
            .height(),
    );
    assert_eq!(best.fitness.unwrap().total(), 2.0 * h);
    assert!(
        rows(&alone)[3].1 >= rows(&alone)[0].1,
        "selected for height"
    );

    // Checkpointed, it resumes with the same term only.
    let text = beside.checkpoint().unwrap();
    assert!(text.contains("\"own_term\""));
    let path = Path::new("c.json");
    let e = Evolution::resume(&c, path, &text, Pool::Serial).unwrap_err();
    assert!(
        e.to_string().contains("resume it with that function again"),
        "{e}"
    );
    let e = Evolution::resume_with(
        &c,
        path,
        &text,
        Pool::Serial,
        own(Arc::new(Height::default()), false, 3),
    )
    .unwrap_err();
    assert!(e.is_input(), "{e}");
    let mut resumed = Evolution::resume_with(
        &c,
        path,
        &text,
        Pool::Serial,
        own(Arc::new(Height::default()), true, 3),
    )
    .unwrap();
    resumed.step().unwrap();
    beside.step().unwrap();
    assert_eq!(rows(&resumed), rows(&beside));
    let e = Evolution::resume_with(
        &c,
        path,
        &plain.checkpoint().unwrap(),
        Pool::Serial,
        own(Arc::new(Height::default()), true, 3),
    )
    .unwrap_err();
    assert!(e.to_string().contains("without one"), "{e}");
}

/// A scorer that fails, or answers wrongly.
struct Broken(&'static str);

impl PlantScorer for Broken {
    fn score(&self, plants: Vec<Grown>) -> Result<Vec<f64>, ScorerError> {
        match self.0 {
            "fails" => Err("the user's bug".into()),
            "short" => Ok(vec![1.0; plants.len() - 1]),
            _ => Ok(vec![f64::NAN; plants.len()]),
        }
    }
}

#[test]
fn an_own_term_s_failures_are_errors_and_leave_the_run_whole() {
    let c = small("bintree", "");
    for (how, expected) in [
        ("fails", "the user's bug"),
        ("short", "scores for a batch"),
        ("nan", "NaN"),
    ] {
        let e = Evolution::start_with(
            &c,
            Vec::new(),
            Pool::Serial,
            own(Arc::new(Broken(how)), true, 4),
        )
        .unwrap_err();
        assert!(sylva::error::chain(&e).contains(expected), "{how}: {e}");
    }
    let e = Evolution::start_with(
        &c,
        Vec::new(),
        Pool::Serial,
        own(Arc::new(Broken("fails")), true, 4),
    )
    .unwrap_err();
    let Error::Scorer(inner) = e else {
        panic!("not the scorer's error")
    };
    assert_eq!(inner.to_string(), "the user's bug");

    // A scorer that fails once the run is under way leaves it as it was.
    struct Later(Mutex<u32>);
    impl PlantScorer for Later {
        fn score(&self, plants: Vec<Grown>) -> Result<Vec<f64>, ScorerError> {
            let mut calls = self.0.lock().unwrap();
            *calls += 1;
            if *calls > 1 {
                return Err("later".into());
            }
            Ok(vec![0.0; plants.len()])
        }
    }
    let mut run = Evolution::start_with(
        &c,
        Vec::new(),
        Pool::Serial,
        own(Arc::new(Later(Mutex::new(0))), true, 64),
    )
    .unwrap();
    let before = run.checkpoint().unwrap();
    assert!(matches!(run.step(), Err(Error::Scorer(_))));
    assert_eq!((run.generation(), run.checkpoint().unwrap()), (0, before));

    // A weight out of range, or a `[match]` beside, is refused naming what.
    let mut bad = own(Arc::new(Height::default()), true, 4);
    if let Some(t) = &mut bad.term {
        t.weight = f64::NAN;
    }
    let e = Evolution::start_with(&c, Vec::new(), Pool::Serial, bad).unwrap_err();
    assert!(e.to_string().contains("fitness_weight"), "{e}");
    let matched = small(
        "bintree",
        &format!(
            "[match]\nfront = \"{}\"\n",
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../examples/match/cone.png")
                .display()
        ),
    );
    let e = Evolution::start_with(
        &matched,
        Vec::new(),
        Pool::Serial,
        own(Arc::new(Height::default()), true, 4),
    )
    .unwrap_err();
    assert!(e.to_string().contains("[match]"), "{e}");
}
