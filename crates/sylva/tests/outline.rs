//! The `[match]` section: a target outline joins any model's own terms as one more term
//! (`iou`), or decides alone; its pictures are read relative to the config, and a bad one
//! or a bad field is an error naming it.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::Path;

use sylva::core::par::Pool;
use sylva::{Config, Evolution, Registry};

fn examples() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples"))
}

fn config(text: &str) -> Result<Config, sylva::InputError> {
    // As if the config lived in examples/match, beside its pictures.
    Registry::standard().parse_config(&examples().join("match/test.toml"), text)
}

#[test]
fn an_outline_joins_every_models_own_terms() {
    for model in ["bintree", "automata", "plantmaker"] {
        let text = format!(
            "model = \"{model}\"\n[run]\npopulation = 6\nseed = 2\n[match]\nfront = \"cone.png\"\nweight = 5\n"
        );
        let config = config(&text).unwrap();
        let mut run = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap();
        run.step().unwrap();
        let names = run.term_names().to_vec();
        assert_eq!(names.last().map(String::as_str), Some("iou"), "{model}");
        assert!(names.len() > 1, "{model}: the model's own terms count too");
        let best = run.best().fitness.unwrap();
        let iou = *best.terms().last().unwrap();
        assert!((0.0..=1.0).contains(&iou) && iou > 0.0, "{model}: {iou}");
        // The config keeps its section.
        assert!(config.to_toml().contains("[match]"), "{model}");
    }
}

#[test]
fn an_outline_alone_decides() {
    let text = "model = \"bintree\"\n[run]\npopulation = 8\n[match]\nfront = \"round.png\"\nside = \"round.png\"\nbeside = false\n";
    let config = config(text).unwrap();
    let run = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap();
    assert_eq!(run.term_names(), ["iou"]);
    let best = run.best().fitness.unwrap();
    assert_eq!(best.total(), best.terms()[0]);
    assert!(
        run.guides().is_none(),
        "the model's own guides mean nothing here"
    );
}

#[test]
fn bad_match_sections_name_the_field_or_file() {
    let e = config("model = \"bintree\"\n[match]\nfront = \"round.png\"\nthreshold = \"bright\"\n")
        .err()
        .unwrap();
    assert!(e.message.contains("otsu") && e.line == 4, "{e}");
    let e = config("model = \"bintree\"\n[match]\nfront = \"round.png\"\ncolour = 1\n")
        .err()
        .unwrap();
    assert!(
        e.message.contains("unknown field `colour`") && e.line == 4,
        "{e}"
    );
    let e = config("model = \"bintree\"\n[match]\nside = \"round.png\"\n")
        .err()
        .unwrap();
    assert!(e.message.contains("missing field `front`"), "{e}");
    let e = config("model = \"bintree\"\n[match]\nfront = \"round.png\"\nrows = 4\n")
        .err()
        .unwrap();
    assert!(e.message.contains("rows"), "{e}");
    let e = config("model = \"bintree\"\n[match]\nfront = \"round.png\"\ncloseness = 11\n")
        .err()
        .unwrap();
    assert!(
        e.message.contains("`closeness` must be") && e.line == 4,
        "{e}"
    );
    // Closeness is left out of a config that does not set it, and kept where it is set.
    let plain = config("model = \"bintree\"\n[match]\nfront = \"round.png\"\n").unwrap();
    assert!(!plain.to_toml().contains("closeness"));
    let close =
        config("model = \"bintree\"\n[match]\nfront = \"round.png\"\ncloseness = 0.5\n").unwrap();
    assert!(
        close.to_toml().contains("closeness = 0.5"),
        "{}",
        close.to_toml()
    );
    // A picture that is not there is named when the run starts.
    let config = config("model = \"bintree\"\n[match]\nfront = \"nowhere.png\"\n").unwrap();
    let e = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap_err();
    assert!(e.to_string().contains("nowhere.png"), "{e}");
}

/// `match_config` breeds each model for fitting: mostly mutants for the generational
/// models, more bits flipped for binary trees; L-systems keep their defaults.
/// What `sylva match examples/match/round.png` asks for, from the front alone.
fn round_target() -> sylva::evolution::MatchConfig {
    sylva::evolution::MatchConfig {
        front: examples().join("match/round.png"),
        side: None,
        threshold: sylva::picture::Threshold::default(),
        weight: 1.0,
        beside: false,
        rows: sylva::evolution::MatchConfig::DEFAULT_ROWS,
        closeness: 0.0,
        topiary: None,
    }
}

#[test]
fn a_match_breeds_for_fitting() {
    use sylva::evolution::RunConfig;
    use sylva::evolution::outline::match_config;
    let target = round_target();
    let registry = Registry::standard();
    let toml = |model: &str| {
        match_config(&registry, model, &RunConfig::default(), &target)
            .unwrap()
            .to_toml()
    };
    for model in ["plantmaker", "automata"] {
        let text = toml(model);
        assert!(
            text.contains("mutation = 0.7\nelitism = 5\nreevaluate = false"),
            "{model}: {text}"
        );
    }
    assert!(toml("plantmaker").contains("mutation_spread = 0.05"));
    assert!(toml("bintree").contains("mutation_rate = 0.05"));
    let defaults = registry.get("lsystem").unwrap().default_config().to_toml();
    let lsystem = toml("lsystem");
    let section = |t: &str| t[t.find("[lsystem]").unwrap()..t.find("[output]").unwrap()].to_owned();
    assert_eq!(section(&lsystem), section(&defaults));
}

/// A match's PlantMaker leaves are leaf green (`palette = "foliage"`): the outline cannot
/// see colour, but the plausibility report can: a green blade is a leaf, judged for its
/// size against the plant's height, where a fan of any colour may be a flower, which it
/// does not judge. So the colours do change the scores, through the report alone.
#[test]
fn a_match_grows_green_leaves_judged_as_leaves() {
    use sylva::core::MaterialKind;
    use sylva::evolution::RunConfig;
    use sylva::evolution::outline::match_config;
    let run = RunConfig {
        population: 12,
        ..RunConfig::default()
    };
    let foliage = match_config(&Registry::standard(), "plantmaker", &run, &round_target())
        .unwrap()
        .to_toml();
    assert!(foliage.contains("palette = \"foliage\""), "{foliage}");
    let any = foliage.replace("palette = \"foliage\"", "palette = \"any\"");
    let bred = |text: &str| {
        let config = Registry::standard()
            .parse_config(Path::new("match.toml"), text)
            .unwrap();
        let mut evolution = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap();
        evolution.step().unwrap();
        evolution.step().unwrap();
        let ious: Vec<f64> = evolution
            .population()
            .iter()
            .map(|m| m.fitness.unwrap().total())
            .collect();
        let best = evolution.best().genome.clone();
        (ious, best.develop(best.default_seed()).unwrap())
    };
    let ((green_scores, green), (any_scores, plant)) = (bred(&foliage), bred(&any));
    assert_ne!(green_scores, any_scores);
    // The green plant's blades are measured as leaves.
    let report = sylva::inspect::Report::of(&green, None);
    let leaf = report.figures.iter().find(|f| f.name == "leaf_length");
    assert!(leaf.and_then(|f| f.value).is_some(), "{}", report.table());
    assert!(!green.organs().is_empty());
    for o in green.organs() {
        let kind = green.materials()[o.material.index()].kind;
        assert_eq!(
            kind,
            MaterialKind::Leaf,
            "a green blade is a leaf, not a flower"
        );
    }
    let flowers = |p: &sylva::core::Plant| {
        p.materials()
            .iter()
            .filter(|m| m.kind == MaterialKind::Flower)
            .count()
    };
    assert!(
        flowers(&plant) > 0,
        "left to drift, colours make flowers of leaves"
    );
}

/// A match stopped by hand (a front end's Ctrl-C) ends with `Stopped`, not as if its time
/// were up, and leaves the run at its last whole generation; counted in generations, it
/// breeds exactly that many.
#[test]
fn breeding_until_a_limit_tells_a_stop_from_the_time() {
    use std::time::Instant;
    use sylva::core::par::Stop;
    use sylva::evolution::outline::{Limit, breed_until};
    let text = "model = \"bintree\"\n[run]\npopulation = 8\n[match]\nfront = \"round.png\"\nbeside = false\n";
    let config = config(text).unwrap();
    let mut run = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap();
    let stop = Stop::new();
    let mut steps = 0;
    breed_until(
        &mut run,
        Limit::Generations(3),
        Instant::now(),
        &stop,
        |_| {
            steps += 1;
            Ok::<_, sylva::Error>(())
        },
    )
    .unwrap();
    assert_eq!((run.generation(), steps), (3, 3));
    stop.stop();
    let e = breed_until(
        &mut run,
        Limit::Seconds(3600.0),
        Instant::now(),
        &stop,
        |_| Ok::<_, sylva::Error>(()),
    );
    assert!(matches!(e, Err(sylva::Error::Stopped(_))), "{e:?}");
    assert_eq!(run.generation(), 3);
    assert!(!stop.timed_out(), "the deadline is cleared after breeding");
}

/// `auto` tries each model for a share of the match, runs off the best two for a further
/// share, and goes on with the better, the same each time.
#[test]
fn auto_tries_every_model_then_runs_off_the_best_two() {
    use sylva::core::par::Stop;
    use sylva::evolution::RunConfig;
    use sylva::evolution::outline::{Limit, RUNOFF_SHARE, TRIAL_SHARE, Trial};
    use sylva::evolution::outline::{best_iou, start_auto};
    let target = round_target();
    let run = RunConfig {
        population: 6,
        seed: 4,
        ..RunConfig::default()
    };
    let generations = 25;
    let (first, more) = (
        (f64::from(generations) * TRIAL_SHARE) as u32,
        (f64::from(generations) * RUNOFF_SHARE) as u32,
    );
    let auto = || {
        let mut trials = Vec::new();
        let limit = Limit::Generations(generations);
        let (evolution, _) = start_auto(
            &Registry::standard(),
            &target,
            &run,
            limit,
            &Pool::Serial,
            &Stop::new(),
            |t| trials.push(t.clone()),
        )
        .unwrap();
        (evolution, trials)
    };
    let (chosen, trials) = auto();
    let reached = |runoff: bool| -> Vec<(&str, f64, u32)> {
        (trials.iter())
            .filter_map(|t| match t {
                Trial::Reached {
                    model,
                    iou,
                    generations,
                    runoff: r,
                } if *r == runoff => Some((*model, *iou, *generations)),
                _ => None,
            })
            .collect()
    };
    let (tried, runoff) = (reached(false), reached(true));
    let models: Vec<&str> = tried.iter().map(|t| t.0).collect();
    assert_eq!(
        models,
        ["bintree", "automata", "plantmaker", "grown"],
        "{trials:?}"
    );
    assert!(trials.iter().any(|t| matches!(
        t,
        Trial::LeftOut {
            model: "lsystem",
            ..
        }
    )));
    assert!(tried.iter().all(|t| t.2 == first), "{tried:?}");
    // The best two of the trials, in their order, each bred further.
    let mut ranked = tried.clone();
    ranked.sort_by(|a, b| b.1.total_cmp(&a.1));
    assert_eq!(runoff.len(), 2, "{trials:?}");
    for (r, t) in runoff.iter().zip(&ranked) {
        assert_eq!((r.0, r.2), (t.0, first + more));
    }
    // The better of the run-off goes on, as it was.
    let better = if runoff[1].1 > runoff[0].1 {
        runoff[1]
    } else {
        runoff[0]
    };
    assert_eq!(chosen.config().model(), better.0);
    assert_eq!(
        (best_iou(&chosen), chosen.generation()),
        (better.1, first + more)
    );
    // The same target, seed and generations: the same choice and the same best plant.
    let (again, _) = auto();
    assert_eq!(again.best().genome, chosen.best().genome);
}

/// Trees pass for trees: every tree example of every model passes the stem factors the
/// outline term weighs its IoU by (the small L-system herb and bush do not).
#[test]
fn the_tree_examples_pass_the_stem_factors() {
    use sylva_fitness::silhouette::{Scratch, plausibility};
    let mut scratch = Scratch::default();
    let trees = [
        "automata/helix.json",
        "bintree/oak.json",
        "lsystem/tree.json",
        "plantmaker/conifer.json",
        "plantmaker/fern.json",
        "plantmaker/flowering-bush.json",
        "plantmaker/palm.json",
        "plantmaker/tulip.json",
    ];
    let plausibility = |example: &str, scratch: &mut Scratch| {
        let genome = sylva::Registry::standard()
            .load_genome(&examples().join(example))
            .unwrap();
        let plant = genome.develop(genome.default_seed()).unwrap();
        plausibility(&plant, scratch)
    };
    for example in trees {
        let p = plausibility(example, &mut scratch);
        assert!(p > 0.99, "{example}: {p}");
    }
    for herb in ["lsystem/herb.json", "lsystem/bush.json"] {
        let p = plausibility(herb, &mut scratch);
        assert!(p < 0.5, "{herb}: {p}");
    }
}

/// A topiary match grows its plants inside the outline: the term scores the pruned plant,
/// the run's files grow it so, and the overlay shows it, each at the IoU the others see;
/// without (the default) the plant grows whole.
#[test]
fn a_pruning_match_scores_writes_and_shows_the_pruned_plant() {
    use sylva::Grown;
    use sylva::evolution::outline::{best_iou, match_config, overlay, prune, space};
    use sylva::evolution::{MatchConfig, RunConfig};
    let run = RunConfig {
        generations: 2,
        population: 12,
        ..RunConfig::default()
    };
    let grown = |target: &MatchConfig| {
        let config = match_config(&Registry::standard(), "plantmaker", &run, target).unwrap();
        let mut evolution = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap();
        while evolution.generation() < 2 {
            evolution.step().unwrap();
        }
        let best = evolution.best().clone();
        let options = config.grow_options().unwrap();
        let plant = Grown::grow(best.genome.clone(), &options).unwrap().plant;
        let (_, iou) = overlay(target, Path::new(""), &best.genome).unwrap();
        (best, options, plant, (iou, best_iou(&evolution)))
    };
    let pruning = MatchConfig {
        topiary: Some(true),
        ..round_target()
    };
    let (best, options, plant, (iou, term)) = grown(&pruning);
    let outlines = options
        .pruned_to
        .expect("a pruning match prunes its files' plant");
    assert_eq!(outlines.len(), 1, "the front view alone");
    let whole = best.genome.develop(best.genome.default_seed()).unwrap();
    assert_eq!(plant, prune(&outlines, &whole));
    assert_ne!(plant, whole, "something was cut");
    assert_eq!(
        space(&pruning, Path::new("")).unwrap().unwrap()[0],
        outlines[0]
    );
    // The overlay is of the pruned plant (its IoU alone; the term is times plausibility).
    let front = MatchConfig {
        side: None,
        rows: 256,
        ..pruning.clone()
    };
    let target = &sylva::evolution::outline::outlines(&front, Path::new("")).unwrap()[0];
    let mut scratch = sylva_fitness::silhouette::Scratch::default();
    assert_eq!(iou, target.iou(&plant, &mut scratch));
    assert!(iou > 0.4 && term > 0.4, "{iou} {term}");
    // The term scores the leaves clipped as they are drawn; the pieces the files carry
    // show the same outline, but for slivers at its edges.
    let shown = iou * sylva_fitness::silhouette::plausibility(&plant, &mut scratch);
    assert!((term - shown).abs() < 0.03, "{term} {shown}");
    let free = round_target();
    let (best, options, plant, _) = grown(&free);
    assert!(options.pruned_to.is_none());
    assert_eq!(
        plant,
        best.genome.develop(best.genome.default_seed()).unwrap()
    );
}

#[test]
fn a_matchs_pictures_are_read_once_and_carried_to_its_files() {
    use sylva::evolution::outline::{Target, match_config, overlay};
    use sylva::evolution::{MatchConfig, RunConfig};
    // The pictures live in a folder of their own, which goes once they are read: whatever
    // needs them later (the run's term, its checkpoint's resume, the best plant's pruning,
    // the overlay) uses the pictures carried; read again, they are missing, named.
    let dir = std::env::temp_dir().join(format!("sylva-target-once-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(examples().join("match/round.png"), dir.join("round.png")).unwrap();
    let target = MatchConfig {
        front: dir.join("round.png"),
        topiary: Some(true),
        ..round_target()
    };
    let pictures = Target::read(&target, Path::new("")).unwrap();
    let run = RunConfig {
        generations: 2,
        population: 8,
        ..RunConfig::default()
    };
    let registry = Registry::standard();
    let fresh = match_config(&registry, "bintree", &run, &target).unwrap();
    let config = fresh.clone().with_target(Some(pictures.clone()));
    std::fs::remove_dir_all(&dir).unwrap();
    let gone = fresh.grow_options().unwrap_err();
    assert!(gone.to_string().contains("round.png"), "{gone}");
    let mut evolution = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap();
    evolution.step().unwrap();
    let checkpoint = evolution.checkpoint().unwrap();
    let resumed = Evolution::resume(&config, Path::new("c.json"), &checkpoint, Pool::Serial);
    assert_eq!(resumed.unwrap().generation(), 1);
    // The run's config carries them on to the files' plant and the overlay.
    let options = evolution.config().grow_options().unwrap();
    assert!(options.pruned_to.is_some());
    let best = evolution.best().genome.clone();
    let (png, iou) = pictures.overlay(&target, &best).unwrap();
    assert!(png.starts_with(b"\x89PNG") && (0.0..=1.0).contains(&iou));
    assert!(
        overlay(&target, Path::new(""), &best).is_err(),
        "read again: gone"
    );
    // Carried pictures are used only for the files they were read from.
    let other = MatchConfig {
        front: examples().join("match/cone.png"),
        ..target.clone()
    };
    assert!(!pictures.is_of(&other) && pictures.is_of(&target));
}

/// A run's checkpoint without its wall-clock seconds: equal runs give equal text.
fn without_seconds(checkpoint: &str) -> serde_json::Value {
    let mut value: serde_json::Value = serde_json::from_str(checkpoint).unwrap();
    for row in value["checkpoint"]["stats"].as_array_mut().unwrap() {
        row["seconds"] = serde_json::Value::Null;
    }
    value
}

/// An auto match killed during its trials resumes from the trials its log kept: those are
/// not bred again (a model goes on to its run-off from its kept run), and a match counting
/// generations ends with the same bytes as one never killed, its trials' generations too.
#[test]
fn auto_killed_during_its_trials_resumes_from_its_log_to_the_same_bytes() {
    use std::time::Instant;
    use sylva::core::par::Stop;
    use sylva::evolution::RunConfig;
    use sylva::evolution::outline::{AutoEvent, AutoMatch, Limit, TrialLog, breed_until};
    use sylva::report::trials_csv;
    let (target, registry, stop) = (round_target(), Registry::standard(), Stop::new());
    let run = RunConfig {
        population: 6,
        seed: 4,
        ..RunConfig::default()
    };
    let limit = Limit::Generations(25);
    let auto = AutoMatch {
        registry: &registry,
        target: &target,
        base: Path::new(""),
        run: &run,
        limit,
        pool: &Pool::Serial,
        stop: &stop,
    };
    let finish = |mut evolution: Evolution| {
        breed_until(&mut evolution, limit, Instant::now(), &stop, |_| {
            Ok::<_, sylva::Error>(())
        })
        .unwrap();
        (
            without_seconds(&evolution.checkpoint().unwrap()),
            evolution.best().genome.to_json(),
        )
    };
    // Never killed: every generation of the trials, in order.
    let mut whole_log = TrialLog::new();
    let mut bred = Vec::new();
    let (whole, _) = auto
        .start(&mut whole_log, |event| {
            if let AutoEvent::Bred {
                model,
                runoff,
                evolution,
            } = event
            {
                bred.push((model, runoff, evolution.generation()));
            }
            Ok::<_, sylva::Error>(())
        })
        .unwrap();
    assert_eq!(whole_log.chosen().unwrap().0, whole.config().model());
    let whole = finish(whole);
    let whole_csv = trials_csv(&whole_log);
    assert_eq!(whole_csv.lines().count(), 1 + bred.len(), "{whole_csv}");
    // Killed at a generation of the first trials, of the first run-off and of the second:
    // the log as the last trial to end left it, written and read as a front end keeps it.
    for kill in [4, 13, bred.len() - 2] {
        let (mut seen, mut kept) = (0, None);
        let killed = auto.start(&mut TrialLog::new(), |event| {
            match event {
                AutoEvent::Begun { .. } => {}
                AutoEvent::Bred { .. } => seen += 1,
                AutoEvent::Ended { log, .. } => kept = Some(log.to_json()?),
            }
            if seen == kill {
                return Err(sylva::Error::Stopped(sylva::evolution::Stopped));
            }
            Ok(())
        });
        assert!(killed.is_err());
        let text = kept.unwrap();
        let mut log = TrialLog::parse(Path::new("trials.json"), &text).unwrap();
        let ended: Vec<(String, bool)> = (log.trials().iter())
            .map(|t| (t.model.clone(), t.runoff))
            .collect();
        assert!(!ended.is_empty(), "kill {kill}: no trial had ended");
        let mut again = Vec::new();
        let (resumed, _) = auto
            .start(&mut log, |event| {
                if let AutoEvent::Bred {
                    model,
                    runoff,
                    evolution,
                } = event
                {
                    again.push((model, runoff, evolution.generation()));
                }
                Ok::<_, sylva::Error>(())
            })
            .unwrap();
        // Only what had not ended is bred, and just as the match never killed bred it.
        for (model, runoff, _) in &again {
            assert!(
                !ended.contains(&(model.to_string(), *runoff)),
                "kill {kill}: {model} (run-off {runoff}) was bred again"
            );
        }
        assert_eq!(again, bred[bred.len() - again.len()..], "kill {kill}");
        assert_eq!(trials_csv(&log), whole_csv, "kill {kill}");
        assert!(
            finish(resumed) == whole,
            "kill {kill}: the match ended otherwise"
        );
    }
    // A log is resumed by its own match only.
    let other = RunConfig {
        population: 7,
        ..run.clone()
    };
    let e = AutoMatch {
        run: &other,
        ..auto
    }
    .start(&mut whole_log.clone(), |_| Ok::<_, sylva::Error>(()))
    .unwrap_err();
    assert!(e.to_string().contains("population of 6, not 7"), "{e}");
    let e = TrialLog::parse(Path::new("trials.json"), "{\"format\": 1, \"trials\": [").unwrap_err();
    assert!(e.to_string().contains("trials.json"), "{e}");
}

/// A plant the plausibility report fails scores half its outline per figure failed: a
/// binary tree whose trunk is a log (4 m wide, the tree about 13 m tall) against the same
/// tree slender.
#[test]
fn a_log_scores_half_per_figure_it_fails() {
    use sylva::evolution::outline::{IMPLAUSIBLE, realism};
    let tree = |radius: f64| {
        let text = format!(
            r#"{{"model": "bintree", "format": 1, "depth": 5, "lower_radius": {radius},
              "upper_radius": {radius}, "length": 4.0, "length_ratio": 0.8,
              "rotation1": {{"angle": 30, "axis": [1, 0, 0]}},
              "rotation2": {{"angle": -30, "axis": [0, 0, 1]}}, "min_radius": 0.02}}"#
        );
        let genome = Registry::standard().parse_genome(&text).unwrap();
        genome.develop(0).unwrap()
    };
    let (log, pole) = (tree(2.0), tree(0.1));
    let failed = sylva::inspect::Report::of(&log, None).failures().len();
    assert!(
        failed >= 1,
        "{}",
        sylva::inspect::Report::of(&log, None).table()
    );
    assert_eq!(realism(&log), IMPLAUSIBLE.powi(failed as i32));
    assert_eq!(
        realism(&pole),
        1.0,
        "{}",
        sylva::inspect::Report::of(&pole, None).table()
    );
}
