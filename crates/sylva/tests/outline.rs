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
