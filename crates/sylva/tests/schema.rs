//! Every model's schema against its own genome files: each example's values are ones its
//! schema takes, every required field is in them, and a number set to either end of its
//! range is a genome the model still reads (so the schema never offers a value the model
//! refuses), while one past the end is refused by the schema.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::Path;

use serde_json::{Value, json};
use sylva::registry::Registry;
use sylva::schema::{Kind, Schema};

/// The example genomes of a model, as JSON.
fn examples(model: &str) -> Vec<(String, Value)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let registry = Registry::standard();
    let mut found = Vec::new();
    for folder in std::fs::read_dir(&root).unwrap() {
        for file in std::fs::read_dir(folder.unwrap().path()).unwrap() {
            let path = file.unwrap().path();
            if path.extension().is_some_and(|e| e == "json") {
                let text = std::fs::read_to_string(&path).unwrap();
                if let Ok(genome) = registry.parse_genome(&text)
                    && genome.model() == model
                {
                    found.push((path.display().to_string(), genome.to_value()));
                }
            }
        }
    }
    found.sort_by(|a, b| a.0.cmp(&b.0));
    found
}

/// `genome` with the value at `path` (`branches[0].waves`) replaced.
fn set(genome: &Value, path: &str, value: Value) -> Value {
    let mut out = genome.clone();
    let mut at = &mut out;
    for part in path.split('.') {
        at = match part.split_once('[') {
            Some((list, index)) => {
                &mut at[list][index.trim_end_matches(']').parse::<usize>().unwrap()]
            }
            None => &mut at[part],
        };
    }
    *at = value;
    out
}

fn ends(kind: &Kind) -> Option<[(Value, Value); 2]> {
    match *kind {
        Kind::Number { min, max, .. } => {
            let past = (max - min).max(1.0);
            Some([
                (json!(min), json!(min - past)),
                (json!(max), json!(max + past)),
            ])
        }
        Kind::Integer { min, max, .. } => {
            Some([(json!(min), json!(min - 1)), (json!(max), json!(max + 1))])
        }
        _ => None,
    }
}

#[test]
fn every_model_has_a_schema_its_examples_fill() {
    let registry = Registry::standard();
    for entry in registry.models() {
        let schema: Schema = entry.schema();
        assert!(!schema.fields.is_empty(), "{} has no fields", entry.name());
        for field in &schema.fields {
            let within = match field.kind {
                Kind::Number {
                    min,
                    max,
                    soft_min,
                    soft_max,
                    step,
                    ..
                } => min <= soft_min && soft_min < soft_max && soft_max <= max && step > 0.0,
                Kind::Integer {
                    min,
                    max,
                    soft_min,
                    soft_max,
                } => min <= soft_min && soft_min < soft_max && soft_max <= max,
                _ => true,
            };
            assert!(
                within,
                "{}: `{}`'s slider is outside its range",
                entry.name(),
                field.path
            );
        }
        let genomes = examples(entry.name());
        assert!(
            !genomes.is_empty(),
            "{} has no example genome",
            entry.name()
        );
        for (file, genome) in &genomes {
            let values = schema.values(genome);
            for field in schema.fields.iter().filter(|f| !f.optional) {
                let in_list = field.path.contains("[]");
                assert!(
                    in_list || values.iter().any(|(_, f, _)| f.path == field.path),
                    "{file}: the schema's required `{}` is not in the genome",
                    field.path
                );
            }
            for (path, _, value) in &values {
                schema
                    .check(path, value)
                    .unwrap_or_else(|e| panic!("{file}: {e}"));
            }
        }
    }
}

#[test]
fn the_ends_of_every_range_are_genomes_the_model_reads() {
    let registry = Registry::standard();
    for entry in registry.models() {
        let schema = entry.schema();
        let (file, genome) = examples(entry.name()).remove(0);
        // The first place each field is found in the example (its first list item).
        let mut seen = Vec::new();
        for (path, field, _) in schema.values(&genome) {
            if seen.contains(&field.path) {
                continue;
            }
            seen.push(field.path.clone());
            let Some(ends) = ends(&field.kind) else {
                continue;
            };
            for (inside, outside) in ends {
                let text = set(&genome, &path, inside.clone()).to_string();
                registry.parse_genome(&text).unwrap_or_else(|e| {
                    panic!("{file}: `{path}` = {inside} is in the schema's range, but: {e}")
                });
                assert!(
                    schema.check(&path, &outside).is_err(),
                    "{file}: `{path}` = {outside}"
                );
            }
        }
        assert!(!seen.is_empty(), "{file}: no field of the schema found");
    }
}

#[test]
fn a_value_outside_the_schema_is_refused_naming_field_range_and_value() {
    let schema = Registry::standard().get("grown").unwrap().schema();
    let e = schema.check("parameters.height", &json!(80.0)).unwrap_err();
    assert_eq!(
        e,
        "`parameters.height` takes a number from 1 to 40 m, not 80.0"
    );
    let e = schema.check("crown", &json!("square")).unwrap_err();
    assert!(e.contains("one of ellipsoid, cone, flame"), "{e}");
}
