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

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_core::{Plant, PlantMeta, hash::stable_hash, ranged_number};

use super::compile::{AtEnd, ElseEnd, Program, Semantics};
use super::sim::{ChildVariables, Detail, GrowOptions, GrowthReport, Limits, Simulator};
use super::tree::GpTree;
use crate::tag::{FormatV1, model_tag};
use crate::{DevelopError, GenomeError};

/// Model name in genome files.
pub const MODEL: &str = "automata";

model_tag!(
    /// The `"model": "automata"` header field.
    AutomataTag,
    MODEL
);

/// An `automata` genome. Lengths are paper units (see `unit`), angles degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AutomataGenome {
    /// Always `"automata"`.
    pub model: AutomataTag,
    /// Always 1.
    pub format: FormatV1,
    /// The GP tree, as an S-expression (see [`super::sexpr`]).
    #[serde(serialize_with = "write_program", deserialize_with = "read_program")]
    pub program: GpTree,
    /// Iteration limit, 1 to 100 000. Default 100.
    #[serde(default = "d_iterations", deserialize_with = "iterations")]
    pub iterations: u32,
    /// The root automaton's starting Length, paper units per step, 0 to 1000. Default 1.
    #[serde(default = "d_root_length", deserialize_with = "root_length")]
    pub root_length: f64,
    /// Metres per paper unit, 0.000001 to 1000. Default 0.1.
    #[serde(default = "d_unit", deserialize_with = "unit")]
    pub unit: f64,
    /// Gravity bending, degrees per step at a horizontal heading, 0 to 90. Default 0.
    #[serde(default, deserialize_with = "gravity")]
    pub gravity: f64,
    /// Degrees per unit of a rotation value, 0 to 36. Default 10.
    #[serde(default = "d_degrees", deserialize_with = "degrees_per_unit")]
    pub degrees_per_unit: f64,
    /// Radius at thickness 1, paper units, 0 to 1000. Default 3.
    #[serde(default = "d_radius", deserialize_with = "radius")]
    pub radius: f64,
    /// Leaf length, paper units, 0 to 1000. Default 4.
    #[serde(default = "d_organ", deserialize_with = "leaf_length")]
    pub leaf_length: f64,
    /// Flower diameter, paper units, 0 to 1000. Default 4.
    #[serde(default = "d_organ", deserialize_with = "flower_size")]
    pub flower_size: f64,
    /// Leaves near horizontal. Default true.
    #[serde(default = "d_true")]
    pub horizontal_leaves: bool,
    /// `"rejoin"` (default) or `"end"`: see [`ElseEnd`].
    #[serde(default)]
    pub else_end: ElseEnd,
    /// `"die"` (default) or `"restart"`: see [`AtEnd`].
    #[serde(default)]
    pub at_end: AtEnd,
    /// `IfEqual` tolerance, 0 to 10. Default 0.5.
    #[serde(default = "d_tolerance", deserialize_with = "equal_tolerance")]
    pub equal_tolerance: f64,
    /// `"length_thickness"` (default), `"all"` or `"fresh"`: see [`ChildVariables`].
    #[serde(default)]
    pub child_variables: ChildVariables,
    /// Runaway bounds; each field defaults as in [`Limits`].
    #[serde(default)]
    pub limits: Limits,
}

fn d_iterations() -> u32 {
    100
}
fn d_root_length() -> f64 {
    1.0
}
fn d_unit() -> f64 {
    0.1
}
fn d_degrees() -> f64 {
    10.0
}
fn d_radius() -> f64 {
    3.0
}
fn d_organ() -> f64 {
    4.0
}
fn d_true() -> bool {
    true
}
fn d_tolerance() -> f64 {
    0.5
}

fn iterations<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    sylva_core::ranged::integer(d, "iterations", 1, 100_000)
}
ranged_number!(root_length, "root_length", 0.0, 1000.0, " units");
ranged_number!(unit, "unit", 1e-6, 1000.0, " m");
ranged_number!(gravity, "gravity", 0.0, 90.0, " degrees per step");
ranged_number!(degrees_per_unit, "degrees_per_unit", 0.0, 36.0, " degrees");
ranged_number!(radius, "radius", 0.0, 1000.0, " units");
ranged_number!(leaf_length, "leaf_length", 0.0, 1000.0, " units");
ranged_number!(flower_size, "flower_size", 0.0, 1000.0, " units");
ranged_number!(equal_tolerance, "equal_tolerance", 0.0, 10.0, "");

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

impl AutomataGenome {
    /// A genome with every setting at its default.
    pub fn new(program: GpTree) -> AutomataGenome {
        let g = GrowOptions::default();
        let s = Semantics::default();
        AutomataGenome {
            model: AutomataTag,
            format: FormatV1,
            program,
            iterations: d_iterations(),
            root_length: d_root_length(),
            unit: d_unit(),
            gravity: 0.0,
            degrees_per_unit: d_degrees(),
            radius: d_radius(),
            leaf_length: d_organ(),
            flower_size: d_organ(),
            horizontal_leaves: d_true(),
            else_end: s.else_end,
            at_end: s.at_end,
            equal_tolerance: d_tolerance(),
            child_variables: g.child_variables,
            limits: g.limits,
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

    /// Grows the plant at full detail. The model is deterministic: `seed` is only recorded
    /// in the plant's metadata.
    pub fn develop(&self, seed: u64) -> Result<Plant, DevelopError> {
        self.develop_with_report(seed).map(|(plant, _)| plant)
    }

    /// Grows the plant and says what the simulator did.
    pub fn develop_with_report(&self, seed: u64) -> Result<(Plant, GrowthReport), DevelopError> {
        let json = serde_json::to_vec(self)?;
        let mut plant = Plant::new(PlantMeta {
            model: MODEL.to_owned(),
            genome_hash: stable_hash(&json),
            seed,
        });
        let program = Program::compile(&self.program, &self.semantics());
        let report = Simulator::new().run(&program, &self.grow_options(), Detail::Full, &mut plant);
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
        assert_eq!(plant.segments.len(), 1);
        assert_eq!(plant.meta.model, "automata");
        assert_eq!(plant.meta.seed, 7);
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
}
