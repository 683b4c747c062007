//! The L-system genome (section 3.3): shoot and root L-systems, module shapes, rotation
//! angles and the fixed physiology, with the paper's mutation operators.
//!
//! A genome file reads like the paper:
//!
//! ```json
//! {
//!   "model": "lsystem",
//!   "format": 1,
//!   "shoot": { "axiom": "[A]", "rules": ["A -> [>b[B]A]$$$$[>b[B]A]$$$$[>b[B]A]", "B -> >>l"] },
//!   "root": { "axiom": "[A]", "rules": ["A -> [<c[B]$$A][[B]$$A]", "B -> >r"] },
//!   "angles": { "turn": 30, "pitch": 30, "roll": 30 },
//!   "modules": {
//!     "leaf": { "length": 0.1, "radius": 0.025 },
//!     "branch": { "length": 0.15, "radius": 0.015 },
//!     "fine_root": { "length": 0.06, "radius": 0.005 },
//!     "root_branch": { "length": 0.1, "radius": 0.008 }
//!   }
//! }
//! ```
//!
//! Rules are parsed while the file is read, so a bad rule's error names the compartment,
//! the rule, the column and the rule's text, and serde_json adds the line and column of the
//! string in the file. `physiology` may be left out (the defaults of [`Physiology`]) and is
//! not written when it has its defaults; `description` is free text.
//!
//! Evolution changes only the rules, the shapes and the angles ([`LSystemMutation`]); the
//! axioms and the physiology stay fixed, as in the paper.

use std::fmt;

use rand::{Rng, RngExt};
use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sylva_evolve::Mutate;

use crate::grammar::{
    Axis, Compartment, MAX_RULES, Module, Rule, RuleSet, Symbol, Word, parse_rule, parse_word,
};
use crate::interpret::{Angles, ModuleShape};
use crate::mutate::{MutationRates, mutate_rules};
use crate::physiology::Physiology;
use sylva_model::schema::{Editor, FieldSpec, Kind, Schema, StructureSpec};
use sylva_model::{FormatV1, model_tag};

/// Model name in genome files.
pub const MODEL: &str = "lsystem";

model_tag!(
    /// The `"model": "lsystem"` header field.
    LSystemTag,
    MODEL
);

/// One compartment's L-system: an axiom and rules (rule `i` rewrites the `i`-th letter).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct LSystem {
    /// The starting string, `[A]` in the paper.
    pub axiom: Vec<Symbol>,
    /// The production rules.
    pub rules: RuleSet,
}

impl LSystem {
    /// Axiom `[A]` and no rules: a compartment that never grows.
    pub fn empty() -> LSystem {
        LSystem {
            axiom: vec![Symbol::Push, Symbol::Apex(0), Symbol::Pop],
            rules: RuleSet::default(),
        }
    }

    /// Whether the system writes a module within `steps` derivations of its axiom (or before
    /// its string passes `limit` symbols), the environment aside: one that does not draws
    /// nothing, however long it grows (growth also needs light, minerals and reserves).
    pub fn draws_within(&self, steps: usize, limit: usize) -> bool {
        let drawn = |word: &[Symbol]| word.iter().any(|s| matches!(s, Symbol::Module(_)));
        let mut word = self.axiom.clone();
        for _ in 0..steps {
            if drawn(&word) {
                return true;
            }
            match crate::grammar::derive(&word, &self.rules, limit) {
                Ok(next) if next != word => word = next,
                _ => break,
            }
        }
        drawn(&word)
    }

    /// Parses an axiom and rules written in the paper's notation.
    pub fn parse(axiom: &str, rules: &[&str], compartment: Compartment) -> Result<LSystem, String> {
        let axiom = parse_word(axiom, compartment).map_err(|e| {
            format!(
                "{} axiom, column {}: {}",
                name(compartment),
                e.column,
                e.message
            )
        })?;
        let lines: Vec<String> = rules.iter().map(|r| (*r).to_owned()).collect();
        let rules = RuleSet::parse(&lines, compartment).map_err(|e| {
            let text = lines.get(e.rule).map_or("", String::as_str);
            format!("{} {e} in `{text}`", name(compartment))
        })?;
        Ok(LSystem { axiom, rules })
    }
}

fn name(c: Compartment) -> &'static str {
    match c {
        Compartment::Shoot => "shoot",
        Compartment::Root => "root",
    }
}

impl Serialize for LSystem {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("LSystem", 2)?;
        st.serialize_field("axiom", &Word(&self.axiom).to_string())?;
        st.serialize_field("rules", &self.rules.to_lines())?;
        st.end()
    }
}

/// Reads an [`LSystem`] of a known compartment, parsing each string as it is read so the
/// error stands at that string.
struct LSystemSeed(Compartment);

impl<'de> DeserializeSeed<'de> for LSystemSeed {
    type Value = LSystem;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<LSystem, D::Error> {
        d.deserialize_struct("LSystem", &["axiom", "rules"], self)
    }
}

impl<'de> Visitor<'de> for LSystemSeed {
    type Value = LSystem;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an L-system: { \"axiom\": \"[A]\", \"rules\": [\"A -> ...\"] }")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<LSystem, A::Error> {
        let compartment = self.0;
        let mut axiom = None;
        let mut rules = None;
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "axiom" => {
                    if axiom.is_some() {
                        return Err(de::Error::duplicate_field("axiom"));
                    }
                    let text: String = map.next_value()?;
                    axiom = Some(parse_word(&text, compartment).map_err(|e| {
                        de::Error::custom(format!(
                            "{} axiom `{text}`, column {}: {}",
                            name(compartment),
                            e.column,
                            e.message
                        ))
                    })?);
                }
                "rules" => {
                    if rules.is_some() {
                        return Err(de::Error::duplicate_field("rules"));
                    }
                    rules = Some(map.next_value_seed(RulesSeed(compartment))?);
                }
                other => return Err(de::Error::unknown_field(other, &["axiom", "rules"])),
            }
        }
        Ok(LSystem {
            axiom: axiom.unwrap_or_else(|| LSystem::empty().axiom),
            rules: rules.ok_or_else(|| de::Error::missing_field("rules"))?,
        })
    }
}

struct RulesSeed(Compartment);

impl<'de> DeserializeSeed<'de> for RulesSeed {
    type Value = RuleSet;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<RuleSet, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for RulesSeed {
    type Value = RuleSet;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "a list of at most {MAX_RULES} rules such as \"A -> [>bA]\""
        )
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RuleSet, A::Error> {
        let mut set = RuleSet::default();
        loop {
            let index = set.rules.len();
            if index >= MAX_RULES {
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(de::Error::custom(format!(
                        "{} has more than {MAX_RULES} rules (one per letter A to Z)",
                        name(self.0)
                    )));
                }
                break;
            }
            match seq.next_element_seed(RuleSeed {
                index,
                compartment: self.0,
            })? {
                Some(rule) => set.rules.push(rule),
                None => break,
            }
        }
        Ok(set)
    }
}

/// Reads one rule, parsing it inside the string's own visitor so that serde_json places an
/// error at that string.
struct RuleSeed {
    index: usize,
    compartment: Compartment,
}

impl<'de> DeserializeSeed<'de> for RuleSeed {
    type Value = crate::grammar::Rule;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_str(self)
    }
}

impl<'de> Visitor<'de> for RuleSeed {
    type Value = crate::grammar::Rule;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a rule such as \"A -> [>bA]\"")
    }

    fn visit_str<E: de::Error>(self, line: &str) -> Result<Self::Value, E> {
        parse_rule(self.index, line, self.compartment)
            .map_err(|e| E::custom(format!("{} {e} in `{line}`", name(self.compartment))))
    }
}

fn shoot_system<'de, D: Deserializer<'de>>(d: D) -> Result<LSystem, D::Error> {
    LSystemSeed(Compartment::Shoot).deserialize(d)
}

fn root_system<'de, D: Deserializer<'de>>(d: D) -> Result<LSystem, D::Error> {
    LSystemSeed(Compartment::Root).deserialize(d)
}

/// The sphyll of each module, named as in Table 1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Modules {
    /// `l`.
    pub leaf: ModuleShape,
    /// `b`.
    pub branch: ModuleShape,
    /// `r`.
    pub fine_root: ModuleShape,
    /// `c`.
    pub root_branch: ModuleShape,
}

impl Modules {
    /// The shapes in [`Module::index`] order, as interpretation takes them.
    pub fn as_array(&self) -> [ModuleShape; 4] {
        [self.leaf, self.branch, self.fine_root, self.root_branch]
    }

    /// The shape of one module.
    pub fn get(&self, m: Module) -> ModuleShape {
        self.as_array()[m.index()]
    }

    fn get_mut(&mut self, m: Module) -> &mut ModuleShape {
        match m {
            Module::Leaf => &mut self.leaf,
            Module::Branch => &mut self.branch,
            Module::FineRoot => &mut self.fine_root,
            Module::RootBranch => &mut self.root_branch,
        }
    }
}

impl Default for Modules {
    /// Small leaves and twigs and fine roots, a little under a voxel of the default world
    /// (the sizes of [`LSystemGenome::bush`]).
    fn default() -> Self {
        let shape = |length, radius| ModuleShape { length, radius };
        Modules {
            leaf: shape(0.1, 0.025),
            branch: shape(0.15, 0.015),
            fine_root: shape(0.06, 0.005),
            root_branch: shape(0.1, 0.008),
        }
    }
}

/// The genome field by field: angles, module shapes and the physiology's constants (the two
/// L-systems are structures, edited as rules).
pub fn schema() -> Schema {
    let angle = |name: &str, meaning: &'static str| {
        FieldSpec::new(
            format!("angles.{name}"),
            "angles",
            Kind::number(-180.0, 180.0),
            meaning,
        )
        .unit("°")
        .shaping()
    };
    let mut fields = vec![
        angle("turn", "The turn of `+` and `-`."),
        angle("pitch", "The pitch of `>` and `<`."),
        angle("roll", "The roll of `$` and `&`."),
    ];
    for (module, what) in [
        ("leaf", "a leaf (`l`)"),
        ("branch", "a branch (`b`)"),
        ("fine_root", "a fine root (`r`)"),
        ("root_branch", "a root branch (`c`)"),
    ] {
        let shaping = matches!(module, "leaf" | "branch");
        let length = FieldSpec::new(
            format!("modules.{module}.length"),
            "modules",
            Kind::number(0.005, 2.0),
            format!("The length of {what}."),
        )
        .unit(" m");
        fields.push(if shaping { length.shaping() } else { length });
        fields.push(
            FieldSpec::new(
                format!("modules.{module}.radius"),
                "modules",
                Kind::number(0.001, 0.5),
                format!("The radius of {what}."),
            )
            .unit(" m"),
        );
    }
    let physiology: [(&str, Kind, &'static str, &'static str); 20] = [
        (
            "seed_biomass",
            Kind::scale(1e-4, 10.0),
            " g",
            "Structural mass of the seed's embryo, half shoot, half root.",
        ),
        (
            "seed_carbon",
            Kind::number(0.0, 100.0).slider(0.0, 5.0),
            " g",
            "Carbon reserve of the seed.",
        ),
        (
            "seed_minerals",
            Kind::number(0.0, 100.0).slider(0.0, 1.0),
            " g",
            "Mineral reserve of the seed.",
        ),
        (
            "carbon_content",
            Kind::number(0.01, 1.0),
            "",
            "Carbon in a gram of biomass.",
        ),
        (
            "mineral_content",
            Kind::number(0.001, 1.0),
            "",
            "Minerals in a gram of biomass.",
        ),
        (
            "photosynthesis",
            Kind::number(0.0, 100.0).slider(0.0, 10.0),
            " g",
            "Carbon fixed per unit of absorbed light (a square metre of open sky for one step).",
        ),
        (
            "uptake",
            Kind::number(0.0, 100.0).slider(0.0, 1.0),
            " m",
            "Soil volume a square metre of fine root draws on per step.",
        ),
        (
            "carbon_inhibition",
            Kind::scale(1e-4, 1e4),
            " g/g",
            "Shoot carbon concentration at which photosynthesis is halved.",
        ),
        (
            "mineral_inhibition",
            Kind::scale(1e-4, 1e4),
            " g/g",
            "Root mineral concentration at which uptake is halved.",
        ),
        (
            "growth_rate",
            Kind::number(0.0, 1e4).slider(0.0, 200.0),
            " per step",
            "k of growth = k·C·N/W.",
        ),
        (
            "carbon_resistance",
            Kind::scale(1.0, 1000.0),
            "",
            "Resistance to carbon transport.",
        ),
        (
            "mineral_resistance",
            Kind::scale(1.0, 1000.0),
            "",
            "Resistance to mineral transport.",
        ),
        (
            "growth_loss",
            Kind::number(0.0, 0.9),
            "",
            "Share of the carbon spent on growth lost to litter.",
        ),
        (
            "maintenance",
            Kind::number(0.0, 1.0),
            " g/g",
            "Carbon a gram of biomass costs to keep each step.",
        ),
        (
            "module_density",
            Kind::scale(1.0, 1e6),
            " g/m³",
            "Biomass per cubic metre of module.",
        ),
        (
            "min_cost",
            Kind::scale(1e-5, 100.0),
            " g",
            "Least biomass any rewrite costs.",
        ),
        (
            "apex_capacity",
            Kind::scale(1e-4, 1e3),
            " g",
            "Most biomass an apex of weight 1 takes in one step.",
        ),
        (
            "allocation_exponent",
            Kind::number(0.0, 8.0),
            "",
            "How sharply allocation favours well-placed apexes.",
        ),
        (
            "allocation_floor",
            Kind::number(0.0, 1.0),
            "",
            "Added to every apex's quality, so apexes in the dark still get a little.",
        ),
        (
            "life_span",
            Kind::integer(1, 1_000_000).slider(1.0, 5000.0),
            " steps",
            "Steps a plant lives.",
        ),
    ];
    for (name, kind, unit, meaning) in physiology {
        fields.push(
            FieldSpec::new(format!("physiology.{name}"), "physiology", kind, meaning)
                .unit(unit)
                .optional(),
        );
    }
    for (name, min, meaning) in [
        (
            "max_symbols",
            8,
            "Longest string of a compartment, in symbols.",
        ),
        ("max_modules", 1, "Most modules of a compartment."),
    ] {
        fields.push(
            FieldSpec::new(
                format!("physiology.{name}"),
                "limits",
                Kind::integer(min, 1_000_000),
                meaning,
            )
            .optional(),
        );
    }
    let rules = |path, meaning| StructureSpec {
        path,
        meaning,
        editor: Editor::Rules,
    };
    Schema {
        fields,
        lists: Vec::new(),
        structures: vec![
            rules(
                "shoot",
                "The above-ground L-system (`l`, `b`): its axiom and rules such as `A -> [>bA]`.",
            ),
            rules(
                "root",
                "The below-ground L-system (`r`, `c`): its axiom and rules.",
            ),
        ],
    }
}

/// A virtual plant's genome: both L-systems, module shapes, angles and physiology.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LSystemGenome {
    /// Always `"lsystem"`.
    pub model: LSystemTag,
    /// Always 1.
    pub format: FormatV1,
    /// Free text: what the plant is, where it came from.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// The above-ground L-system (`l`, `b`).
    #[serde(deserialize_with = "shoot_system")]
    pub shoot: LSystem,
    /// The below-ground L-system (`r`, `c`).
    #[serde(deserialize_with = "root_system")]
    pub root: LSystem,
    /// Rotation angles of `+ -`, `< >` and `$ &`.
    pub angles: Angles,
    /// Module shapes.
    pub modules: Modules,
    /// The transport-resistance constants (not evolved).
    #[serde(default, skip_serializing_if = "Physiology::is_default")]
    pub physiology: Physiology,
}

impl LSystemGenome {
    /// The paper's starting point for evolution: axioms `[A]` and no rules; it does not
    /// germinate.
    pub fn empty() -> LSystemGenome {
        LSystemGenome {
            model: LSystemTag,
            format: FormatV1,
            description: String::new(),
            shoot: LSystem::empty(),
            root: LSystem::empty(),
            angles: Angles {
                turn: 30.0,
                pitch: 30.0,
                roll: 30.0,
            },
            modules: Modules::default(),
            physiology: Physiology::default(),
        }
    }

    /// A random genome built to grow, for a person who asks for a random plant (the
    /// paper's evolution starts from [`LSystemGenome::empty`], which does not germinate):
    /// each compartment has one to three rules, and each rule lays a wood module, then one to
    /// three bracketed laterals (rolled apart; each a pitch or turn or two, then an organ or
    /// an apex), and most often continues its own axis. The first rule's first lateral is an
    /// organ (a leaf, a fine root), so the plant feeds from its first year, and its second
    /// an apex, so it branches. Angles and module shapes are the bush's, nudged by half.
    pub fn random_growing<R: Rng + ?Sized>(rng: &mut R) -> LSystemGenome {
        let mut genome = LSystemGenome::empty();
        genome.shoot.rules = growing_rules(Compartment::Shoot, rng);
        genome.root.rules = growing_rules(Compartment::Root, rng);
        mutate_parameter(&mut genome, 0.5, rng);
        genome
    }

    /// The bush of the paper's Figure 5 (with its misprinted `B -> >>|` read as `B -> >>l`).
    pub fn bush() -> LSystemGenome {
        let shoot = LSystem::parse(
            "[A]",
            &["A -> [>b[B]A]$$$$[>b[B]A]$$$$[>b[B]A]", "B -> >>l"],
            Compartment::Shoot,
        );
        let root = LSystem::parse(
            "[A]",
            &["A -> [<c[B]$$A][[B]$$A]", "B -> >r"],
            Compartment::Root,
        );
        match (shoot, root) {
            (Ok(shoot), Ok(root)) => LSystemGenome {
                description: "The bush of Bornhofen and Lattaud's Figure 5.".into(),
                shoot,
                root,
                ..LSystemGenome::empty()
            },
            _ => unreachable!("the bush's rules are valid"),
        }
    }

    /// Reads a genome file of this model.
    pub fn from_json(text: &str) -> Result<LSystemGenome, sylva_model::GenomeError> {
        Ok(serde_json::from_str(text)?)
    }

    /// The genome as pretty JSON, ending with a newline.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self)
            .unwrap_or_else(|e| unreachable!("genomes hold finite numbers and strings: {e}"));
        s.push('\n');
        s
    }

    /// The stable fingerprint of the genome's JSON.
    pub fn hash(&self) -> u64 {
        sylva_model::genome_hash(self)
    }

    /// The rules of a compartment.
    pub fn rules(&self, c: Compartment) -> &RuleSet {
        match c {
            Compartment::Shoot => &self.shoot.rules,
            Compartment::Root => &self.root.rules,
        }
    }
}

/// The rules of [`LSystemGenome::random_growing`] for one compartment.
fn growing_rules<R: Rng + ?Sized>(compartment: Compartment, rng: &mut R) -> RuleSet {
    let (wood, organ) = match compartment {
        Compartment::Shoot => (Module::Branch, Module::Leaf),
        Compartment::Root => (Module::RootBranch, Module::FineRoot),
    };
    let count = rng.random_range(1..=3u8);
    let rules = (0..count)
        .map(|rule| {
            let mut word = vec![Symbol::Module(wood)];
            let laterals = if rule == 0 { 2..=3 } else { 1..=3 };
            for lateral in 0..rng.random_range(laterals) {
                if lateral > 0 {
                    let rolls = rng.random_range(1..=3);
                    word.extend((0..rolls).map(|_| Symbol::Rotate(Axis::Roll, true)));
                }
                word.push(Symbol::Push);
                for _ in 0..rng.random_range(1..=2) {
                    let axis = if rng.random_bool(0.5) {
                        Axis::Pitch
                    } else {
                        Axis::Turn
                    };
                    word.push(Symbol::Rotate(axis, rng.random_bool(0.5)));
                }
                // The first rule feeds the plant first and branches second.
                let organ_here = match (rule, lateral) {
                    (0, 0) => true,
                    (0, 1) => false,
                    _ => rng.random_bool(0.4),
                };
                word.push(if organ_here {
                    Symbol::Module(organ)
                } else {
                    Symbol::Apex(rng.random_range(0..count))
                });
                word.push(Symbol::Pop);
            }
            if rule == 0 || rng.random_bool(0.7) {
                word.push(Symbol::Apex(rule));
            }
            Rule { successor: word }
        })
        .collect();
    RuleSet { rules }
}

/// The paper's "mutate parameter": nudges every module shape by up to ±`scale` of itself
/// and every angle by up to ±`scale`·50 degrees, each clamped to its range.
pub fn mutate_parameter<R: Rng + ?Sized>(genome: &mut LSystemGenome, scale: f64, rng: &mut R) {
    for m in Module::ALL {
        let shape = genome.modules.get_mut(m);
        shape.length =
            (shape.length * (1.0 + scale * rng.random_range(-1.0..=1.0))).clamp(0.005, 2.0);
        shape.radius =
            (shape.radius * (1.0 + scale * rng.random_range(-1.0..=1.0))).clamp(0.001, 0.5);
    }
    let a = &mut genome.angles;
    for angle in [&mut a.turn, &mut a.pitch, &mut a.roll] {
        *angle = (*angle + scale * 50.0 * rng.random_range(-1.0..=1.0)).clamp(-180.0, 180.0);
    }
}

/// The section 3.3 operators on a whole genome: the character and rule operators on both
/// compartments' rules, then, with its probability, [`mutate_parameter`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LSystemMutation {
    /// The operators' probabilities.
    pub rates: MutationRates,
    /// Size of a parameter nudge (see [`mutate_parameter`]); 0 means the default 0.1.
    pub parameter_scale: f64,
}

impl Mutate<LSystemGenome> for LSystemMutation {
    fn mutate<R: Rng + ?Sized>(&self, genome: &mut LSystemGenome, rng: &mut R) {
        let rates = self.rates.legal();
        mutate_rules(&mut genome.shoot.rules, &rates, Compartment::Shoot, rng);
        mutate_rules(&mut genome.root.rules, &rates, Compartment::Root, rng);
        if rng.random_bool(rates.mutate_parameter) {
            let scale = if self.parameter_scale > 0.0 {
                self.parameter_scale
            } else {
                0.1
            };
            mutate_parameter(genome, scale, rng);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_growing_genomes_are_well_formed_and_feed_and_branch() {
        for seed in 0..200 {
            let g = LSystemGenome::random_growing(&mut sylva_core::rng::seeded(seed));
            assert_eq!(
                LSystemGenome::from_json(&g.to_json()).unwrap(),
                g,
                "seed {seed}"
            );
            for (system, organ) in [(&g.shoot, Module::Leaf), (&g.root, Module::FineRoot)] {
                let first = &system.rules.rules[0].successor;
                assert!(crate::mutate::balanced(first), "seed {seed}");
                assert!(first.contains(&Symbol::Module(organ)), "seed {seed} feeds");
                assert!(first.contains(&Symbol::Apex(0)), "seed {seed} goes on");
                let laterals = first
                    .iter()
                    .filter(|s| matches!(s, Symbol::Apex(_)))
                    .count();
                assert!(laterals >= 2, "seed {seed} branches");
            }
        }
    }

    #[test]
    fn the_bush_round_trips() {
        let bush = LSystemGenome::bush();
        let text = bush.to_json();
        assert!(!text.contains("physiology"), "defaults are left out");
        let back = LSystemGenome::from_json(&text).unwrap();
        assert_eq!(back, bush);
        assert_eq!(back.to_json(), text);
    }

    #[test]
    fn a_bad_rule_points_at_its_string() {
        let text = LSystemGenome::bush()
            .to_json()
            .replace("B -> >>l", "B -> >>|");
        let e = LSystemGenome::from_json(&text).unwrap_err();
        assert!(e.message.contains("shoot rule 2 (`B`), column 8"), "{e}");
        assert!(e.message.contains("`B -> >>|`"), "{e}");
        let line = text.lines().position(|l| l.contains(">>|")).unwrap() + 1;
        assert_eq!(e.line, line, "{e:?}");
        let text = LSystemGenome::bush()
            .to_json()
            .replace("B -> >r", "B -> >l");
        let e = LSystemGenome::from_json(&text).unwrap_err();
        assert!(e.message.contains("root rule 2"), "{e}");
        assert!(e.message.contains("does not grow in the root"), "{e}");
    }

    #[test]
    fn mutation_keeps_parameters_in_range() {
        let mut g = LSystemGenome::bush();
        let mut rng = sylva_core::rng::seeded(3);
        for _ in 0..500 {
            mutate_parameter(&mut g, 0.5, &mut rng);
        }
        let text = g.to_json();
        assert_eq!(LSystemGenome::from_json(&text).unwrap(), g);
    }
}

/// How a crossover of two L-system plants mixes them (Sylva's addition; the paper breeds by
/// mutation alone), from the largest parts to the smallest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LSystemCrossover {
    /// Both L-systems from one parent, the angles and module shapes from the other.
    Halves,
    /// Each compartment's L-system, the angles and the module shapes, each from either
    /// parent ([`CompartmentCrossover`]). The default.
    #[default]
    Compartments,
    /// Each axiom and rule of each compartment, each angle and each module's shape from
    /// either parent. Rules are matched by position (rule `i` rewrites the `i`-th letter), so
    /// any mix is a legal genome; a rule one parent lacks comes from the other.
    Rules,
}

impl sylva_evolve::Crossover<LSystemGenome> for LSystemCrossover {
    fn crossover<R: Rng + ?Sized>(
        &self,
        a: &LSystemGenome,
        b: &LSystemGenome,
        rng: &mut R,
    ) -> LSystemGenome {
        match self {
            LSystemCrossover::Halves => {
                let (systems, shapes) = if rng.random_bool(0.5) { (a, b) } else { (b, a) };
                LSystemGenome {
                    shoot: systems.shoot.clone(),
                    root: systems.root.clone(),
                    angles: shapes.angles,
                    modules: shapes.modules,
                    ..a.clone()
                }
            }
            LSystemCrossover::Compartments => CompartmentCrossover.crossover(a, b, rng),
            LSystemCrossover::Rules => {
                let mut coin = || rng.random_bool(0.5);
                let mut child = a.clone();
                child.shoot = mix_rules(&a.shoot, &b.shoot, &mut coin);
                child.root = mix_rules(&a.root, &b.root, &mut coin);
                let angles = [
                    &mut child.angles.turn,
                    &mut child.angles.pitch,
                    &mut child.angles.roll,
                ];
                let theirs = [b.angles.turn, b.angles.pitch, b.angles.roll];
                for (mine, other) in angles.into_iter().zip(theirs) {
                    if coin() {
                        *mine = other;
                    }
                }
                let shapes = [
                    (&mut child.modules.leaf, b.modules.leaf),
                    (&mut child.modules.branch, b.modules.branch),
                    (&mut child.modules.fine_root, b.modules.fine_root),
                    (&mut child.modules.root_branch, b.modules.root_branch),
                ];
                for (mine, other) in shapes {
                    if coin() {
                        *mine = other;
                    }
                }
                child
            }
        }
    }
}

/// An L-system whose axiom and each rule come from `a` or `b`, each as `coin` says (true:
/// `b`); a rule only one of them has comes from that one.
fn mix_rules(a: &LSystem, b: &LSystem, coin: &mut impl FnMut() -> bool) -> LSystem {
    let axiom = if coin() { &b.axiom } else { &a.axiom };
    let n = a.rules.rules.len().max(b.rules.rules.len());
    let rules = (0..n)
        .filter_map(|i| {
            let (x, y) = (a.rules.rules.get(i), b.rules.rules.get(i));
            if coin() { y.or(x) } else { x.or(y) }.cloned()
        })
        .collect();
    LSystem {
        axiom: axiom.clone(),
        rules: RuleSet { rules },
    }
}

/// Crossover of two L-system plants (Sylva's addition; the paper breeds by mutation alone):
/// the child takes each compartment's L-system, the angles and the module shapes, each from
/// either parent with equal odds, and the first parent's physiology. Whole L-systems travel
/// together, so rules keep the letters they refer to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CompartmentCrossover;

impl sylva_evolve::Crossover<LSystemGenome> for CompartmentCrossover {
    fn crossover<R: Rng + ?Sized>(
        &self,
        a: &LSystemGenome,
        b: &LSystemGenome,
        rng: &mut R,
    ) -> LSystemGenome {
        let mut child = a.clone();
        if rng.random_bool(0.5) {
            child.shoot = b.shoot.clone();
        }
        if rng.random_bool(0.5) {
            child.root = b.root.clone();
        }
        if rng.random_bool(0.5) {
            child.angles = b.angles;
        }
        if rng.random_bool(0.5) {
            child.modules = b.modules;
        }
        child
    }
}
