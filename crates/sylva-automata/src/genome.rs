//! The `automata` genome file: a GP tree in its text form plus the growth settings.
//!
//! Only `model`, `format` and `program` are required; every other field has the default of
//! [`GrowOptions`] and [`Semantics`]. Unknown fields are refused, numbers are range-checked
//! while reading (so errors carry the JSON line and column), and the program is parsed on
//! load: a bad program is reported with the field name and the line and column inside the
//! program text.
//!
//! ```json
//! {
//!   "model": "automata",
//!   "format": 1,
//!   "program": "(Top (Repeat 10 (Seq (RotateH 1) (Wait))) (Killme))",
//!   "iterations": 100
//! }
//! ```

use serde::de::value::MapAccessDeserializer;
use serde::de::{self, DeserializeSeed, Error as _, IntoDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_core::{Plant, ranged};

use crate::compile::{AtEnd, ElseEnd, Program, Semantics};
use crate::sim::{ChildVariables, Detail, GrowOptions, GrowthReport, Limits, Simulator};
use crate::tree::GpTree;
use sylva_model::schema::{Editor, FieldSpec, Kind, Schema, StructureSpec};
use sylva_model::{DevelopError, GenomeError};
use sylva_model::{FormatV1, model_tag};

/// Model name in genome files.
pub const MODEL: &str = "automata";

model_tag!(
    /// The `"model": "automata"` header field.
    AutomataTag,
    MODEL
);

/// An `automata` genome: a program and how it grows. Lengths are paper units (see
/// [`Growth::unit`]), angles degrees. In the file, the growth settings stand beside
/// `program` (one flat object).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AutomataGenome {
    /// Always `"automata"`.
    pub model: AutomataTag,
    /// Always 1.
    pub format: FormatV1,
    /// The GP tree, as an S-expression (see [`crate::sexpr`]).
    #[serde(serialize_with = "write_program")]
    pub program: GpTree,
    /// How the program grows.
    #[serde(flatten)]
    pub growth: Growth,
}

/// How a program grows: every field of an `automata` genome file but the program. Evolution
/// configs hold one too (`[automata.growth]`), and it goes into every evolved genome.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Growth {
    /// Iteration limit, 1 to 100 000. Default 100.
    #[serde(deserialize_with = "iterations")]
    pub iterations: u32,
    /// The root automaton's starting Length, paper units per step, 0 to 1000. Default 1.
    #[serde(deserialize_with = "root_length")]
    pub root_length: f64,
    /// Metres per paper unit, 0.000001 to 1000. Default 0.1.
    #[serde(deserialize_with = "unit")]
    pub unit: f64,
    /// Gravity bending, degrees per step at a horizontal heading, 0 to 90. Default 0.
    #[serde(deserialize_with = "gravity")]
    pub gravity: f64,
    /// Degrees per unit of a rotation value, 0 to 36. Default 10.
    #[serde(deserialize_with = "degrees_per_unit")]
    pub degrees_per_unit: f64,
    /// Radius at thickness 1, paper units, 0 to 1000. Default 3.
    #[serde(deserialize_with = "radius")]
    pub radius: f64,
    /// Leaf length, paper units, 0 to 1000. Default 4.
    #[serde(deserialize_with = "leaf_length")]
    pub leaf_length: f64,
    /// Flower diameter, paper units, 0 to 1000. Default 4.
    #[serde(deserialize_with = "flower_size")]
    pub flower_size: f64,
    /// Leaves near horizontal. Default true.
    pub horizontal_leaves: bool,
    /// `"rejoin"` (default) or `"end"`: see [`ElseEnd`].
    pub else_end: ElseEnd,
    /// `"die"` (default) or `"restart"`: see [`AtEnd`].
    pub at_end: AtEnd,
    /// `IfEqual` tolerance, 0 to 10. Default 0.5.
    #[serde(deserialize_with = "equal_tolerance")]
    pub equal_tolerance: f64,
    /// `"length_thickness"` (default), `"all"` or `"fresh"`: see [`ChildVariables`].
    pub child_variables: ChildVariables,
    /// Runaway bounds; each field defaults as in [`Limits`].
    pub limits: Limits,
}

/// The genome field by field: how the program grows (the program itself is a structure,
/// edited as a tree).
pub fn schema() -> Schema {
    let units = |name: &str, meaning: &'static str| {
        FieldSpec::new(
            name.to_owned(),
            "growth",
            Kind::number(0.0, 1000.0).slider(0.0, 20.0),
            meaning,
        )
        .unit(" units")
    };
    let limit = |name: &str, max: i64, meaning: &'static str| {
        FieldSpec::new(
            format!("limits.{name}"),
            "limits",
            Kind::integer(1, max),
            meaning,
        )
    };
    let fields = vec![
        FieldSpec::new(
            "iterations",
            "growth",
            Kind::integer(1, 100_000).slider(1.0, 2000.0),
            "Steps the automata run: the plant's age.",
        )
        .shaping(),
        units(
            "root_length",
            "The root automaton's starting length per step.",
        )
        .shaping(),
        FieldSpec::new(
            "unit",
            "growth",
            Kind::scale(1e-6, 1000.0),
            "Metres per unit of the paper's space: the plant's scale.",
        )
        .unit(" m"),
        FieldSpec::new(
            "gravity",
            "growth",
            Kind::number(0.0, 90.0),
            "How far a horizontal shoot bends down each step.",
        )
        .unit("° per step")
        .shaping(),
        FieldSpec::new(
            "degrees_per_unit",
            "growth",
            Kind::number(0.0, 36.0),
            "Degrees turned per unit of a rotation's value: how sharply branches turn.",
        )
        .unit("°")
        .shaping(),
        units("radius", "A stem's radius at thickness 1."),
        units("leaf_length", "A leaf's length."),
        units("flower_size", "A flower's diameter."),
        FieldSpec::new(
            "horizontal_leaves",
            "growth",
            Kind::Flag,
            "Leaves held near horizontal.",
        ),
        FieldSpec::new(
            "else_end",
            "program",
            Kind::choice_of(&[ElseEnd::Rejoin, ElseEnd::End]),
            "Where an If's else branch goes when it ends: on with what follows the If, or to the automaton's end.",
        ),
        FieldSpec::new(
            "at_end",
            "program",
            Kind::choice_of(&[AtEnd::Die, AtEnd::Restart]),
            "What reaching its end does to an automaton: it dies, or starts again.",
        ),
        FieldSpec::new(
            "equal_tolerance",
            "program",
            Kind::number(0.0, 10.0),
            "How near two values are equal for IfEqual.",
        ),
        FieldSpec::new(
            "child_variables",
            "program",
            Kind::choice_of(&[
                ChildVariables::LengthThickness,
                ChildVariables::All,
                ChildVariables::Fresh,
            ]),
            "The variables a new automaton starts with: its creator's length and thickness, all its creator's, or fresh ones.",
        ),
        limit(
            "states_per_step",
            1_000_000,
            "States one automaton may run in one step before it is killed.",
        ),
        limit(
            "states",
            1_000_000_000,
            "States in the whole run; growth stops there.",
        ),
        limit(
            "automata",
            1_000_000,
            "Automata in the whole run, the root included.",
        ),
        limit(
            "points",
            100_000_000,
            "Recorded positions; growth stops there.",
        ),
        FieldSpec::new(
            "limits.organs",
            "limits",
            Kind::integer(0, 10_000_000),
            "Leaves and flowers.",
        ),
    ];
    let program = StructureSpec {
        path: "program",
        meaning: "The genetic program compiled into the turtle automata: a tree of nodes.",
        editor: Editor::Program,
    };
    Schema {
        fields,
        lists: Vec::new(),
        structures: vec![program],
    }
}

impl Default for Growth {
    fn default() -> Self {
        let g = GrowOptions::default();
        let s = Semantics::default();
        Growth {
            iterations: 100,
            root_length: 1.0,
            unit: 0.1,
            gravity: 0.0,
            degrees_per_unit: 10.0,
            radius: 3.0,
            leaf_length: 4.0,
            flower_size: 4.0,
            horizontal_leaves: true,
            else_end: s.else_end,
            at_end: s.at_end,
            equal_tolerance: 0.5,
            child_variables: g.child_variables,
            limits: g.limits,
        }
    }
}

impl Growth {
    /// The compile-time choices.
    pub fn semantics(&self) -> Semantics {
        Semantics {
            degrees_per_unit: self.degrees_per_unit as f32,
            else_end: self.else_end,
            at_end: self.at_end,
            equal_tolerance: self.equal_tolerance as f32,
        }
    }

    /// The growth settings.
    pub fn grow_options(&self) -> GrowOptions {
        GrowOptions {
            iterations: self.iterations,
            root_length: self.root_length as f32,
            unit: self.unit as f32,
            gravity: self.gravity as f32,
            radius: self.radius as f32,
            leaf_length: self.leaf_length as f32,
            flower_size: self.flower_size as f32,
            horizontal_leaves: self.horizontal_leaves,
            child_variables: self.child_variables,
            limits: self.limits,
        }
    }
}

ranged!(iterations: u32, "iterations", 1, 100_000);
ranged!(root_length: f64, "root_length", 0.0, 1000.0, " units");
ranged!(unit: f64, "unit", 1e-6, 1000.0, " m");
ranged!(gravity: f64, "gravity", 0.0, 90.0, " degrees per step");
ranged!(degrees_per_unit: f64, "degrees_per_unit", 0.0, 36.0, " degrees");
ranged!(radius: f64, "radius", 0.0, 1000.0, " units");
ranged!(leaf_length: f64, "leaf_length", 0.0, 1000.0, " units");
ranged!(flower_size: f64, "flower_size", 0.0, 1000.0, " units");
ranged!(equal_tolerance: f64, "equal_tolerance", 0.0, 10.0, "");

fn write_program<S: Serializer>(tree: &GpTree, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(tree)
}

fn read_program<'de, D: Deserializer<'de>>(d: D) -> Result<GpTree, D::Error> {
    let text = String::deserialize(d)?;
    GpTree::parse(&text).map_err(|e| {
        serde::de::Error::custom(format!(
            "`program`: at line {}, column {} of the program (byte {}): expected {}, found {}",
            e.line, e.column, e.offset, e.expected, e.found
        ))
    })
}

/// Reads the flat genome object: `model`, `format` and `program` here, every other field
/// through [`Growth`]'s own reader, so its range checks, defaults and unknown-field errors
/// (with their positions) are the ones of the config's `[automata.growth]`.
impl<'de> Deserialize<'de> for AutomataGenome {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_map(GenomeVisitor)
    }
}

struct GenomeVisitor;

impl<'de> Visitor<'de> for GenomeVisitor {
    type Value = AutomataGenome;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an automata genome object")
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<AutomataGenome, A::Error> {
        let mut header = Header::default();
        let growth = Growth::deserialize(MapAccessDeserializer::new(HeaderFields {
            map,
            header: &mut header,
        }))?;
        Ok(AutomataGenome {
            model: header
                .model
                .ok_or_else(|| A::Error::missing_field("model"))?,
            format: header
                .format
                .ok_or_else(|| A::Error::missing_field("format"))?,
            program: header
                .program
                .ok_or_else(|| A::Error::missing_field("program"))?,
            growth,
        })
    }
}

/// The genome's own fields, taken out of the map as it is read.
#[derive(Default)]
struct Header {
    model: Option<AutomataTag>,
    format: Option<FormatV1>,
    program: Option<GpTree>,
}

/// A map that reads the header fields itself and shows only the others.
struct HeaderFields<'h, A> {
    map: A,
    header: &'h mut Header,
}

impl<'de, A: MapAccess<'de>> MapAccess<'de> for HeaderFields<'_, A> {
    type Error = A::Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, A::Error> {
        fn once<T, E: de::Error>(
            slot: &mut Option<T>,
            value: T,
            name: &'static str,
        ) -> Result<(), E> {
            match slot.replace(value) {
                Some(_) => Err(E::duplicate_field(name)),
                None => Ok(()),
            }
        }
        while let Some(key) = self.map.next_key::<String>()? {
            let h = &mut *self.header;
            match key.as_str() {
                "model" => once(&mut h.model, self.map.next_value()?, "model")?,
                "format" => once(&mut h.format, self.map.next_value()?, "format")?,
                "program" => once(
                    &mut h.program,
                    self.map.next_value_seed(ProgramSeed)?,
                    "program",
                )?,
                _ => return seed.deserialize(key.into_deserializer()).map(Some),
            }
        }
        Ok(None)
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, A::Error> {
        self.map.next_value_seed(seed)
    }
}

struct ProgramSeed;

impl<'de> DeserializeSeed<'de> for ProgramSeed {
    type Value = GpTree;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<GpTree, D::Error> {
        read_program(d)
    }
}

impl AutomataGenome {
    /// A genome with every setting at its default.
    pub fn new(program: GpTree) -> AutomataGenome {
        AutomataGenome::with_growth(program, Growth::default())
    }

    /// A genome of `program` grown with `growth`.
    pub fn with_growth(program: GpTree, growth: Growth) -> AutomataGenome {
        AutomataGenome {
            model: AutomataTag,
            format: FormatV1,
            program,
            growth,
        }
    }

    /// Parses a genome file (an `automata` one).
    pub fn from_json(text: &str) -> Result<AutomataGenome, GenomeError> {
        Ok(serde_json::from_str(text)?)
    }

    /// The genome as pretty JSON, ending with a newline.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self)
            .expect("genomes hold only finite numbers and strings");
        s.push('\n');
        s
    }

    /// Grows the plant at full detail. The model is deterministic: `seed` is only recorded
    /// in the plant's metadata.
    pub fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        self.develop_with_report(seed).map(|(plant, _)| plant)
    }

    /// Grows the plant and says what the simulator did.
    pub fn develop_with_report(&self, seed: u64) -> Result<(Plant, GrowthReport), DevelopError> {
        self.growth.limits.check_budget()?;
        let mut plant = Plant::new(sylva_model::plant_meta::<crate::AutomataModel>(self, seed));
        let program = Program::compile(&self.program, &self.growth.semantics());
        let report = Simulator::new().run(
            &program,
            &self.growth.grow_options(),
            Detail::Full,
            &mut plant,
        );
        Ok((plant, report))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_file_takes_defaults_and_round_trips() {
        let g = AutomataGenome::from_json(
            r#"{"model": "automata", "format": 1, "program": "(Top (Wait))"}"#,
        )
        .unwrap();
        assert_eq!(
            g,
            AutomataGenome::new(GpTree::parse("(Top (Wait))").unwrap())
        );
        assert_eq!(AutomataGenome::from_json(&g.to_json()).unwrap(), g);
        let plant = g.develop(7).unwrap();
        assert_eq!(plant.segments().len(), 1);
        assert_eq!(plant.meta().model, "automata");
        assert_eq!(plant.meta().seed, 7);
    }

    #[test]
    fn errors_name_the_field_and_position() {
        let e = AutomataGenome::from_json(
            "{\"model\": \"automata\", \"format\": 1,\n \"program\": \"(Top (RotateH 11))\"}",
        )
        .unwrap_err();
        assert!(e.message.contains("`program`"), "{}", e.message);
        assert!(e.message.contains("line 1, column 15"), "{}", e.message);
        assert_eq!(e.line, 2);
        let e = AutomataGenome::from_json(
            r#"{"model": "automata", "format": 1, "program": "(Top (Wait))", "unit": -1}"#,
        )
        .unwrap_err();
        assert!(e.message.contains("`unit` must be"), "{}", e.message);
        let e = AutomataGenome::from_json(
            r#"{"model": "automata", "format": 1, "program": "(Top (Wait))", "colour": 1}"#,
        )
        .unwrap_err();
        assert!(e.message.contains("unknown field"), "{}", e.message);
        let e = AutomataGenome::from_json(
            r#"{"model": "automata", "format": 1, "program": "(Top (Wait))",
                "limits": {"automata": 0}}"#,
        )
        .unwrap_err();
        assert!(e.message.contains("`limits.automata`"), "{}", e.message);
    }

    #[test]
    fn growth_fields_and_header_fields_keep_their_positions() {
        let text = "{\n \"model\": \"automata\",\n \"format\": 1,\n \"gravity\": 100,\n \"program\": \"(Top (Wait))\"\n}";
        let e = AutomataGenome::from_json(text).unwrap_err();
        assert!(e.message.contains("`gravity` must be"), "{}", e.message);
        assert_eq!(e.line, 4);
        let e = AutomataGenome::from_json("{\"model\": \"automata\", \"format\": 1}").unwrap_err();
        assert!(
            e.message.contains("missing field `program`"),
            "{}",
            e.message
        );
        let e = AutomataGenome::from_json(
            r#"{"model": "automata", "format": 1, "program": "(Top (Wait))", "program": "(Top (Wait))"}"#,
        )
        .unwrap_err();
        assert!(
            e.message.contains("duplicate field `program`"),
            "{}",
            e.message
        );
        let e = AutomataGenome::from_json(r#"{"model": "bintree", "format": 1}"#).unwrap_err();
        assert!(e.message.contains("`model` must be"), "{}", e.message);
        // A genome whose growth fields sit before the program reads the same.
        let g = AutomataGenome::from_json(
            r#"{"iterations": 7, "model": "automata", "format": 1, "program": "(Top (Wait))"}"#,
        )
        .unwrap();
        assert_eq!(g.growth.iterations, 7);
        assert_eq!(AutomataGenome::from_json(&g.to_json()).unwrap(), g);
    }
}
