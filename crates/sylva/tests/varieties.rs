//! Variety maps: a MAP-Elites run of any model (`[run] strategy = "map-elites"` and
//! `[map]`) fills a map of the fittest plant of every kind, deterministically on any
//! number of threads, resumes exactly, and refuses bad maps naming the field.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::Path;

use sylva::core::par::Pool;
use sylva::{Config, Evolution, Registry, Varieties};

fn examples() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples"))
}

fn config(model: &str, map: &str) -> Config {
    let text = format!(
        "model = \"{model}\"\n[run]\nstrategy = \"map-elites\"\nseed = 4\n[map]\ninitial = 12\nbatch = 8\n{map}"
    );
    Registry::standard()
        .parse_config(&examples().join(model).join("test.toml"), &text)
        .unwrap()
}

fn parse(text: &str) -> Result<Config, sylva::InputError> {
    Registry::standard().parse_config(Path::new("map.toml"), text)
}

/// Everything of a map but wall time: its checkpoint with the seconds zeroed.
fn bytes(map: &Varieties) -> String {
    let mut value: serde_json::Value = serde_json::from_str(&map.checkpoint().unwrap()).unwrap();
    for row in value["checkpoint"]["stats"].as_array_mut().unwrap() {
        row["seconds"] = 0.into();
    }
    value.to_string()
}

#[test]
fn every_model_fills_a_map_whose_elites_sit_in_their_cells() {
    for model in ["bintree", "automata", "plantmaker", "lsystem"] {
        let map = "descriptors = [{ name = \"height_to_width\", cells = 4 }, { name = \"tips\", range = [0, 40], cells = 4 }]\n";
        let mut map_config = config(model, map);
        if model == "lsystem" {
            // A small world, grown briefly: the test is about the map, not the plants.
            map_config = config(
                model,
                &format!("{map}\n[lsystem]\nstart = \"herb.json\"\n[lsystem.grow]\nsteps = 20\n"),
            );
        }
        let mut run = Varieties::start(&map_config, Vec::new(), Pool::Serial).unwrap();
        run.step();
        let stats = run.stats();
        assert_eq!(stats.len(), 2, "{model}");
        assert_eq!(stats[1].evaluations, 8, "{model}");
        assert!(
            stats[1].filled >= stats[0].filled && stats[0].filled > 0,
            "{model}"
        );
        let varieties = run.varieties();
        assert_eq!(varieties.len(), stats[1].filled, "{model}");
        for v in &varieties {
            let axes = run.axes();
            for (i, axis) in axes.iter().enumerate() {
                assert_eq!(axis.cell(v.descriptors[i]), v.coordinates[i], "{model}");
            }
            assert_eq!(v.cell, (v.coordinates[0] * 4 + v.coordinates[1]) as usize);
            assert_eq!(v.member.genome.model(), model);
            assert!(v.member.total().is_finite(), "{model}");
        }
        let best = run.best().unwrap();
        assert_eq!(best.member.total(), stats[1].best, "{model}");
        // The effective config names the map.
        let toml = run.config().to_toml();
        assert!(toml.contains("strategy = \"map-elites\"") && toml.contains("[map]"));
    }
}

#[test]
fn a_map_does_not_depend_on_threads_and_resumes_exactly() {
    let map =
        "descriptors = [{ name = \"porosity\", cells = 5 }, { name = \"lean\", cells = 5 }]\n";
    let config = config("bintree", map);
    let mut serial = Varieties::start(&config, Vec::new(), Pool::Serial).unwrap();
    for _ in 0..6 {
        serial.step();
    }
    let mut parallel =
        Varieties::start(&config, Vec::new(), Pool::with_threads(3).unwrap()).unwrap();
    for _ in 0..2 {
        parallel.step();
    }
    let saved = parallel.checkpoint().unwrap();
    let mut resumed =
        Varieties::resume(&config, Path::new("checkpoint.json"), &saved, Pool::Serial).unwrap();
    for _ in 0..4 {
        resumed.step();
    }
    assert_eq!(bytes(&serial), bytes(&resumed));
    // A checkpoint of another map is refused, naming the file.
    let other = self::config(
        "bintree",
        "descriptors = [{ name = \"porosity\", cells = 6 }]\n",
    );
    let e = Varieties::resume(&other, Path::new("checkpoint.json"), &saved, Pool::Serial)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("checkpoint.json") && e.contains("different config"),
        "{e}"
    );
}

#[test]
fn a_map_with_an_outline_places_plants_that_fit_it() {
    let text = "model = \"bintree\"\n[run]\nstrategy = \"map-elites\"\n[map]\ninitial = 10\nbatch = 5\n[match]\nfront = \"cone.png\"\nbeside = false\n";
    let config = Registry::standard()
        .parse_config(&examples().join("match/test.toml"), text)
        .unwrap();
    let mut run = Varieties::start(&config, Vec::new(), Pool::Serial).unwrap();
    run.step();
    assert_eq!(run.term_names(), ["iou"]);
    let best = run.best().unwrap().member.fitness.unwrap();
    assert!(best.total() > 0.0 && best.total() <= 1.0);
}

#[test]
fn bad_maps_are_refused_naming_the_field() {
    let run = "model = \"bintree\"\n[run]\nstrategy = \"map-elites\"\n";
    let cases = [
        (
            format!("{run}[map]\ndescriptors = [{{ name = \"leafiness\" }}]\n"),
            "height_to_width",
            5,
        ),
        (
            format!("{run}[map]\ndescriptors = []\n"),
            "1 to 3 descriptors",
            5,
        ),
        (
            format!("{run}[map]\ndescriptors = [{{ name = \"lean\", range = [0.5, 0.1] }}]\n"),
            "low then high",
            5,
        ),
        (
            format!("{run}[map]\ndescriptors = [{{ name = \"lean\", range = [0, nan] }}]\n"),
            "finite",
            5,
        ),
        (
            format!(
                "{run}[map]\ndescriptors = [{{ name = \"lean\", cells = 1000 }}, {{ name = \"tips\", cells = 1000 }}]\n"
            ),
            "at most 100000",
            5,
        ),
        (
            format!("{run}[map]\ndescriptors = [{{ name = \"lean\", cells = 0 }}]\n"),
            "`cells` must be",
            5,
        ),
        (format!("{run}[map]\nbatch = -3\n"), "`batch` must be", 5),
        (format!("{run}[map]\ncrossover = 1.5\n"), "`crossover`", 5),
        (
            format!("{run}[map]\nemitter = \"cma\"\n"),
            "expected `operators` or `cma-me`",
            5,
        ),
        (
            format!("{run}[map]\nemitter = \"cma-me\"\nsigma = 0\n"),
            "`sigma` must be",
            6,
        ),
        (
            format!("{run}[map]\nemitter = \"cma-me\"\nemitters = 0\n"),
            "`emitters` must be",
            6,
        ),
        (
            format!("{run}[map]\nsigma = 0.2\n"),
            "emitter = \"cma-me\"",
            0,
        ),
        (
            format!("{run}[map]\ncolour = 1\n"),
            "unknown field `colour`",
            5,
        ),
        (
            "model = \"bintree\"\n[run]\nstrategy = \"islands\"\n".to_owned(),
            "map-elites",
            3,
        ),
        (
            "model = \"bintree\"\n[map]\ninitial = 10\n".to_owned(),
            "strategy = \"map-elites\"",
            0,
        ),
    ];
    for (text, expected, line) in cases {
        let e = parse(&text).unwrap_err();
        assert!(e.message.contains(expected), "{text}: {e}");
        if line > 0 {
            assert_eq!(e.line, line, "{text}: {e}");
        }
        assert!(e.to_string().contains("map.toml"), "{e}");
    }
}

#[test]
fn a_map_is_not_run_as_one_population() {
    let config = config("bintree", "");
    let e = Evolution::start(&config, Vec::new(), Pool::Serial).unwrap_err();
    assert!(e.to_string().contains("varieties"), "{e}");
    // A map run of a config without `[map]` draws the default map.
    let plain = parse("model = \"bintree\"\n[run]\nseed = 2\n").unwrap();
    let run = Varieties::start(&plain, Vec::new(), Pool::Serial).unwrap();
    let names: Vec<&str> = run.descriptors().iter().map(|d| d.name()).collect();
    assert_eq!(names, ["height_to_width", "porosity"]);
    assert_eq!(run.cells(), 100);
}

#[test]
fn cma_me_emitters_fill_a_plantmaker_map_and_resume_exactly() {
    let map = "emitter = \"cma-me\"\nemitters = 2\nsigma = 0.2\n\
               descriptors = [{ name = \"leaf_count\", range = [0, 600], cells = 4 }, \
               { name = \"porosity\", range = [0.2, 1], cells = 4 }]\n";
    let config = config("plantmaker", map);
    let mut serial = Varieties::start(&config, Vec::new(), Pool::Serial).unwrap();
    for _ in 0..5 {
        serial.step();
    }
    let stats = serial.stats();
    assert!(stats[5].filled > stats[0].filled, "{stats:?}");
    assert!(
        (serial.varieties().iter()).any(|v| v.member.origin.operator == "cma-me"),
        "an emitter's sample made an elite"
    );
    let toml = serial.config().to_toml();
    assert!(toml.contains("emitter = \"cma-me\""), "{toml}");
    let mut parallel =
        Varieties::start(&config, Vec::new(), Pool::with_threads(3).unwrap()).unwrap();
    parallel.step();
    parallel.step();
    let saved = parallel.checkpoint().unwrap();
    assert!(saved.contains("\"emitters\""), "the strategies are saved");
    let mut resumed =
        Varieties::resume(&config, Path::new("checkpoint.json"), &saved, Pool::Serial).unwrap();
    for _ in 0..3 {
        resumed.step();
    }
    assert_eq!(bytes(&serial), bytes(&resumed));
}

#[test]
fn cma_me_is_refused_for_genomes_of_varying_structure() {
    for model in ["automata", "lsystem"] {
        let config = config(model, "emitter = \"cma-me\"\n");
        let e = Varieties::start(&config, Vec::new(), Pool::Serial)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("test.toml") && e.contains(model) && e.contains("emitter = \"operators\""),
            "{e}"
        );
    }
}

#[test]
fn a_stopped_step_leaves_the_map_as_it_was() {
    let map = "descriptors = [{ name = \"porosity\", cells = 5 }]\n";
    let config = config("bintree", map);
    let mut stopped =
        Varieties::start(&config, Vec::new(), Pool::with_threads(2).unwrap()).unwrap();
    let before = bytes(&stopped);
    let stop = sylva::evolution::Stop::new();
    stop.stop();
    assert!(stopped.step_until(&stop).is_err());
    assert_eq!(bytes(&stopped), before);
    // It goes on exactly as a map that was never stopped.
    stop.reset();
    stopped.step_until(&stop).unwrap();
    let mut straight = Varieties::start(&config, Vec::new(), Pool::Serial).unwrap();
    straight.step();
    assert_eq!(bytes(&stopped), bytes(&straight));
}
