//! A model's genome described field by field: what each value means, its kind, range, step
//! and unit, its group, and whether it is among those that move the plant's shape most. One
//! description serves every front end (the studio's panel, Python's `sylva.schema`, the
//! docs' tables) and checks a value before it is sent to the model.
//!
//! Paths are the genome file's JSON paths (`growth.gravity`); a field of every item of a
//! list is written with empty brackets (`branches[].waves`) and matches any index
//! (`branches[2].waves`). What fields cannot say (an L-system's rules, an automata
//! program) is a [`StructureSpec`], edited as a whole.

use std::borrow::Cow;

use serde::Serialize;
use serde_json::Value;

/// Every part of a model's genome a person can set by hand, in the order a panel shows it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Schema {
    /// The fields holding one value each.
    pub fields: Vec<FieldSpec>,
    /// The lists whose items' fields are written `list[].field`.
    pub lists: Vec<ListSpec>,
    /// The parts edited as a whole structure rather than field by field.
    pub structures: Vec<StructureSpec>,
}

/// One field holding one value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FieldSpec {
    /// Its JSON path in a genome file.
    pub path: String,
    /// The panel group it belongs to.
    pub group: &'static str,
    /// What it does, in a sentence.
    pub meaning: Cow<'static, str>,
    /// What values it takes.
    #[serde(flatten)]
    pub kind: Kind,
    /// Its unit as written after a number (`" m"`, `"°"`), or `""`.
    pub unit: &'static str,
    /// Among the fields that move the plant's shape most (shown first, and open).
    pub shapes: bool,
    /// May be left out of a file: the model's default (said in `meaning`) holds then.
    pub optional: bool,
}

/// What values a field takes.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Kind {
    /// A number from `min` to `max`; a slider spans `soft_min` to `soft_max` (where plants
    /// worth growing lie; a typed value may go to the ends), moves by `step`, and along a
    /// logarithmic scale where `log` (ranges over many orders of magnitude).
    Number {
        /// The least value.
        min: f64,
        /// The greatest value.
        max: f64,
        /// The least value a slider offers.
        soft_min: f64,
        /// The greatest value a slider offers.
        soft_max: f64,
        /// A slider's step.
        step: f64,
        /// Whether a slider moves along a logarithmic scale.
        log: bool,
    },
    /// A whole number from `min` to `max`; a slider spans `soft_min` to `soft_max`.
    Integer {
        /// The least value.
        min: i64,
        /// The greatest value.
        max: i64,
        /// The least value a slider offers.
        soft_min: i64,
        /// The greatest value a slider offers.
        soft_max: i64,
    },
    /// One of a few names.
    Choice {
        /// The names, as files write them.
        options: Vec<String>,
    },
    /// `true` or `false`.
    Flag,
    /// A colour, `"#rrggbb"`.
    Colour,
    /// An item of another list of the genome, by number: 1 to that list's length (at most
    /// `max`).
    Item {
        /// The list's path.
        list: &'static str,
        /// The longest the list may be.
        max: i64,
    },
    /// Items of another list of the genome, by number: a sorted list of distinct numbers
    /// from 1 to that list's length (at most `max`).
    Items {
        /// The list's path.
        list: &'static str,
        /// The longest the list may be.
        max: i64,
    },
    /// A direction: three numbers from -1 to 1, not all zero.
    Axis,
    /// A random seed: a whole number from 0 to 2^64 − 1.
    Seed,
}

/// A list of items, each with the fields written `path[].field`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ListSpec {
    /// Its JSON path.
    pub path: &'static str,
    /// What an item is.
    pub meaning: &'static str,
    /// Fewest items.
    pub min: usize,
    /// Most items.
    pub max: usize,
}

/// A part of the genome edited as a whole.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StructureSpec {
    /// Its JSON path.
    pub path: &'static str,
    /// What it is.
    pub meaning: &'static str,
    /// How a person edits it.
    pub editor: Editor,
}

/// How a structure is edited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Editor {
    /// Lines of text, each checked as the model parses it (L-system rules).
    Rules,
    /// A tree of nodes (a genetic program).
    Program,
}

impl FieldSpec {
    /// A required field that is not among the shape's movers, without a unit; the builders
    /// below say otherwise.
    pub fn new(
        path: impl Into<String>,
        group: &'static str,
        kind: Kind,
        meaning: impl Into<Cow<'static, str>>,
    ) -> Self {
        FieldSpec {
            path: path.into(),
            group,
            meaning: meaning.into(),
            kind,
            unit: "",
            shapes: false,
            optional: false,
        }
    }

    /// With this unit.
    pub fn unit(self, unit: &'static str) -> Self {
        FieldSpec { unit, ..self }
    }

    /// Among the fields that move the shape most.
    pub fn shaping(self) -> Self {
        FieldSpec {
            shapes: true,
            ..self
        }
    }

    /// May be left out of a file.
    pub fn optional(self) -> Self {
        FieldSpec {
            optional: true,
            ..self
        }
    }
}

impl Kind {
    /// A number from `min` to `max`, its step the power of ten that cuts the range into 100
    /// to 1,000 steps.
    pub fn number(min: f64, max: f64) -> Kind {
        Kind::Number {
            min,
            max,
            soft_min: min,
            soft_max: max,
            step: step_of(min, max),
            log: false,
        }
    }

    /// A number from `min` (above 0) to `max` over several orders of magnitude: a
    /// logarithmic slider, its step the least value.
    pub fn scale(min: f64, max: f64) -> Kind {
        Kind::Number {
            min,
            max,
            soft_min: min,
            soft_max: max,
            step: min,
            log: true,
        }
    }

    /// A whole number from `min` to `max`, a slider spanning all of it.
    pub fn integer(min: i64, max: i64) -> Kind {
        Kind::Integer {
            min,
            max,
            soft_min: min,
            soft_max: max,
        }
    }

    /// The same, with a slider spanning `soft_min` to `soft_max` only (and, for a number, a
    /// step to suit that span).
    pub fn slider(self, soft_min: f64, soft_max: f64) -> Kind {
        match self {
            Kind::Number {
                min,
                max,
                log,
                step,
                ..
            } => Kind::Number {
                min,
                max,
                soft_min,
                soft_max,
                step: if log {
                    step
                } else {
                    step_of(soft_min, soft_max)
                },
                log,
            },
            Kind::Integer { min, max, .. } => Kind::Integer {
                min,
                max,
                soft_min: soft_min as i64,
                soft_max: soft_max as i64,
            },
            other => other,
        }
    }

    /// Whether `value` is one this kind takes; otherwise what it takes, in words.
    fn check(&self, value: &Value) -> Result<(), String> {
        let ok = match self {
            Kind::Number { min, max, .. } => value
                .as_f64()
                .is_some_and(|v| v.is_finite() && (*min..=*max).contains(&v)),
            Kind::Integer { min, max, .. } => {
                value.as_i64().is_some_and(|v| (*min..=*max).contains(&v))
            }
            Kind::Choice { options } => value
                .as_str()
                .is_some_and(|v| options.iter().any(|o| o == v)),
            Kind::Flag => value.is_boolean(),
            Kind::Colour => value.as_str().is_some_and(|c| {
                c.len() == 7 && c.starts_with('#') && c[1..].chars().all(|h| h.is_ascii_hexdigit())
            }),
            Kind::Item { max, .. } => value.as_i64().is_some_and(|n| (1..=*max).contains(&n)),
            Kind::Items { max, .. } => value.as_array().is_some_and(|items| {
                let numbers: Vec<_> = items.iter().filter_map(Value::as_i64).collect();
                numbers.len() == items.len()
                    && numbers.iter().all(|n| (1..=*max).contains(n))
                    && numbers.windows(2).all(|w| w[0] < w[1])
            }),
            Kind::Axis => {
                triple(value, -1.0, 1.0)
                    && value
                        .as_array()
                        .is_some_and(|a| a.iter().any(|c| c.as_f64() != Some(0.0)))
            }
            Kind::Seed => value.as_u64().is_some(),
        };
        if ok { Ok(()) } else { Err(self.expected()) }
    }

    /// What values it takes, in words.
    pub fn expected(&self) -> String {
        match self {
            Kind::Number { min, max, .. } => format!("a number from {min} to {max}"),
            Kind::Integer { min, max, .. } => format!("a whole number from {min} to {max}"),
            Kind::Choice { options } => format!("one of {}", options.join(", ")),
            Kind::Flag => "true or false".into(),
            Kind::Colour => "a colour, #rrggbb".into(),
            Kind::Item { list, .. } => format!("the number of one of `{list}`, from 1"),
            Kind::Items { list, .. } => {
                format!("a sorted list of distinct numbers of `{list}`, from 1")
            }
            Kind::Axis => "a direction: three numbers from -1 to 1, not all zero".into(),
            Kind::Seed => "a whole number from 0 to 18446744073709551615".into(),
        }
    }

    /// A choice among the names a type's values serialise to (`CrownShape::ALL`).
    pub fn choice_of<T: Serialize>(all: &[T]) -> Kind {
        let options = all
            .iter()
            .filter_map(|v| serde_json::to_value(v).ok()?.as_str().map(str::to_owned))
            .collect();
        Kind::Choice { options }
    }
}

/// The power of ten that cuts `min..max` into 100 to 1,000 steps.
fn step_of(min: f64, max: f64) -> f64 {
    10f64.powf(((max - min) / 100.0).log10().floor())
}

/// Three numbers from `min` to `max`.
fn triple(value: &Value, min: f64, max: f64) -> bool {
    value.as_array().is_some_and(|a| {
        a.len() == 3
            && a.iter()
                .all(|c| c.as_f64().is_some_and(|c| (min..=max).contains(&c)))
    })
}

impl Schema {
    /// Fields only: no lists, no structures.
    pub fn of(fields: Vec<FieldSpec>) -> Schema {
        Schema {
            fields,
            lists: Vec::new(),
            structures: Vec::new(),
        }
    }

    /// The field at `path`: its own, or a list item's (`branches[2].waves` is
    /// `branches[].waves`).
    pub fn field(&self, path: &str) -> Option<&FieldSpec> {
        let general = without_indices(path);
        self.fields.iter().find(|f| f.path == general)
    }

    /// Whether `value` may be set at `path`; otherwise an error naming the field, what it
    /// takes and the value.
    pub fn check(&self, path: &str, value: &Value) -> Result<(), String> {
        let field = self
            .field(path)
            .ok_or_else(|| format!("`{path}` is not a field of this model's genomes"))?;
        field
            .kind
            .check(value)
            .map_err(|expected| format!("`{path}` takes {expected}{}, not {value}", field.unit))
    }

    /// The schema as Markdown: a table of its fields (the shape's movers in bold), then its
    /// lists and structures. The docs' tables (docs/genomes.md) are this.
    pub fn markdown(&self) -> String {
        let mut out = String::from(
            "| field | group | takes | slider | meaning |\n| --- | --- | --- | --- | --- |\n",
        );
        for f in &self.fields {
            let path = if f.shapes {
                format!("**`{}`**", f.path)
            } else {
                format!("`{}`", f.path)
            };
            let unit = match f.unit.trim() {
                "" => String::new(),
                unit => format!(" ({unit})"),
            };
            let slider = match f.kind {
                Kind::Number {
                    soft_min,
                    soft_max,
                    log: true,
                    ..
                } => {
                    format!("{soft_min} to {soft_max}, logarithmic")
                }
                Kind::Number {
                    soft_min,
                    soft_max,
                    step,
                    ..
                } => {
                    format!("{soft_min} to {soft_max} by {step}")
                }
                Kind::Integer {
                    soft_min, soft_max, ..
                } => format!("{soft_min} to {soft_max}"),
                _ => String::new(),
            };
            let optional = if f.optional { " Optional." } else { "" };
            out += &format!(
                "| {path} | {} | {}{unit} | {slider} | {}{optional} |\n",
                f.group,
                f.kind.expected(),
                f.meaning.replace('|', "\\|")
            );
        }
        for list in &self.lists {
            out += &format!(
                "\n`{}`: {} From {} to {} items; each holds the `{}[]` fields.\n",
                list.path, list.meaning, list.min, list.max, list.path
            );
        }
        for structure in &self.structures {
            let editor = match structure.editor {
                Editor::Rules => "edited as text, each rule checked as the model reads it",
                Editor::Program => "edited as a tree of nodes",
            };
            out += &format!(
                "\n`{}`: {} A structure, {editor}.\n",
                structure.path, structure.meaning
            );
        }
        out
    }

    /// Each field of the schema and its value in `genome` (a genome file as JSON), every
    /// list item's in turn: what a panel shows.
    pub fn values<'a>(&'a self, genome: &'a Value) -> Vec<(String, &'a FieldSpec, &'a Value)> {
        let mut out = Vec::new();
        for field in &self.fields {
            collect(genome, &field.path, String::new(), field, &mut out);
        }
        out
    }
}

/// `path` with every `[index]` emptied to `[]`.
fn without_indices(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    let mut in_index = false;
    for c in path.chars() {
        match c {
            '[' => {
                in_index = true;
                out.push('[');
            }
            ']' => {
                in_index = false;
                out.push(']');
            }
            _ if in_index => {}
            _ => out.push(c),
        }
    }
    out
}

fn collect<'a>(
    value: &'a Value,
    rest: &str,
    at: String,
    field: &'a FieldSpec,
    out: &mut Vec<(String, &'a FieldSpec, &'a Value)>,
) {
    let (head, tail) = match rest.split_once('.') {
        Some((head, tail)) => (head, Some(tail)),
        None => (rest, None),
    };
    let join = |name: &str| {
        if at.is_empty() {
            name.to_owned()
        } else {
            format!("{at}.{name}")
        }
    };
    if let Some(list) = head.strip_suffix("[]") {
        for (i, item) in value[list].as_array().into_iter().flatten().enumerate() {
            let here = join(&format!("{list}[{i}]"));
            match tail {
                Some(tail) => collect(item, tail, here, field, out),
                None => out.push((here, field, item)),
            }
        }
        return;
    }
    let Some(child) = value.get(head) else { return };
    match tail {
        Some(tail) => collect(child, tail, join(head), field, out),
        None => out.push((join(head), field, child)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn schema() -> Schema {
        let field = |path: &str, kind| FieldSpec::new(path, "shape", kind, "").unit("°");
        Schema::of(vec![
            field("angle", Kind::number(0.0, 360.0)),
            field("branches[].waves", Kind::integer(1, 16)),
        ])
    }

    #[test]
    fn steps_cut_a_range_into_a_hundred_to_a_thousand() {
        for (min, max, step) in [(0.0, 360.0, 1.0), (0.001, 0.02, 0.0001), (1.0, 40.0, 0.1)] {
            let Kind::Number { step: s, .. } = Kind::number(min, max) else {
                unreachable!()
            };
            assert!((s - step).abs() < 1e-12, "{min}..{max}: {s}");
        }
    }

    #[test]
    fn list_items_match_their_general_field_and_values_are_checked() {
        let s = schema();
        assert_eq!(
            s.field("branches[3].waves").unwrap().path,
            "branches[].waves"
        );
        assert!(s.check("branches[0].waves", &json!(16)).is_ok());
        let e = s.check("branches[0].waves", &json!(17)).unwrap_err();
        assert_eq!(
            e,
            "`branches[0].waves` takes a whole number from 1 to 16°, not 17"
        );
        assert!(s.check("angle", &json!(f64::NAN)).is_err());
        assert!(s.check("angle", &json!("12")).is_err());
        assert!(
            s.check("nothing", &json!(1))
                .unwrap_err()
                .contains("not a field")
        );
    }

    #[test]
    fn values_walk_lists_item_by_item() {
        let s = schema();
        let genome = json!({"angle": 30.0, "branches": [{"waves": 2}, {"waves": 5}]});
        let paths: Vec<_> = s
            .values(&genome)
            .into_iter()
            .map(|(p, _, v)| (p, v.clone()))
            .collect();
        assert_eq!(
            paths,
            [
                ("angle".to_owned(), json!(30.0)),
                ("branches[0].waves".to_owned(), json!(2)),
                ("branches[1].waves".to_owned(), json!(5)),
            ]
        );
    }
}
