//! The mutation operators of section 3.3, each with its own probability.
//!
//! Character operators (delete, insert, permute, duplicate, mutate) are tried once per rule;
//! rule operators (delete, insert, duplicate) and the parameter operator once per genome.
//! Brackets stay balanced after every operator, by construction:
//!
//! - **delete** a bracket deletes its partner too;
//! - **insert** puts in one symbol of the compartment's alphabet, or, one time in five, a
//!   bracket pair around a balanced stretch (possibly empty);
//! - **permute** swaps two adjacent symbols, skipping swaps that would unbalance brackets;
//! - **duplicate** a bracket duplicates the whole bracketed group after itself;
//! - **mutate** replaces a non-bracket symbol by another one.
//!
//! Deleting rule `i` shifts the later rules down a letter (rule `i + 1` now rewrites the
//! `i`-th letter), as rules are matched to letters by position. Inserting appends an empty
//! rule; duplicating appends a copy. Both stop at 26 rules.

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

use crate::grammar::{Axis, Compartment, MAX_RULES, Module, Rule, RuleSet, Symbol};

/// Probabilities of the operators (each 0 to 1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MutationRates {
    /// Delete a character, per rule. Default 0.1.
    #[serde(deserialize_with = "delete_char")]
    pub delete_char: f64,
    /// Insert a character, per rule. Default 0.1.
    #[serde(deserialize_with = "insert_char")]
    pub insert_char: f64,
    /// Permute two adjacent characters, per rule. Default 0.1.
    #[serde(deserialize_with = "permute_char")]
    pub permute_char: f64,
    /// Duplicate a character, per rule. Default 0.1.
    #[serde(deserialize_with = "duplicate_char")]
    pub duplicate_char: f64,
    /// Replace a character, per rule. Default 0.1.
    #[serde(deserialize_with = "mutate_char")]
    pub mutate_char: f64,
    /// Delete a rule, per rule set. Default 0.05.
    #[serde(deserialize_with = "delete_rule")]
    pub delete_rule: f64,
    /// Append an empty rule, per rule set. Default 0.1.
    #[serde(deserialize_with = "insert_rule")]
    pub insert_rule: f64,
    /// Append a copy of a rule, per rule set. Default 0.05.
    #[serde(deserialize_with = "duplicate_rule")]
    pub duplicate_rule: f64,
    /// Nudge the shapes and angles, per genome. Default 0.3.
    #[serde(deserialize_with = "mutate_parameter")]
    pub mutate_parameter: f64,
}

sylva_core::ranged!(delete_char: f64, "delete_char", 0.0, 1.0);
sylva_core::ranged!(insert_char: f64, "insert_char", 0.0, 1.0);
sylva_core::ranged!(permute_char: f64, "permute_char", 0.0, 1.0);
sylva_core::ranged!(duplicate_char: f64, "duplicate_char", 0.0, 1.0);
sylva_core::ranged!(mutate_char: f64, "mutate_char", 0.0, 1.0);
sylva_core::ranged!(delete_rule: f64, "delete_rule", 0.0, 1.0);
sylva_core::ranged!(insert_rule: f64, "insert_rule", 0.0, 1.0);
sylva_core::ranged!(duplicate_rule: f64, "duplicate_rule", 0.0, 1.0);
sylva_core::ranged!(mutate_parameter: f64, "mutate_parameter", 0.0, 1.0);

impl MutationRates {
    /// Every probability multiplied by `factor` (at most 1).
    pub fn scaled(self, factor: f64) -> MutationRates {
        let f = |p: f64| (p * factor).clamp(0.0, 1.0);
        MutationRates {
            delete_char: f(self.delete_char),
            insert_char: f(self.insert_char),
            permute_char: f(self.permute_char),
            duplicate_char: f(self.duplicate_char),
            mutate_char: f(self.mutate_char),
            delete_rule: f(self.delete_rule),
            insert_rule: f(self.insert_rule),
            duplicate_rule: f(self.duplicate_rule),
            mutate_parameter: f(self.mutate_parameter),
        }
    }
}

impl Default for MutationRates {
    fn default() -> Self {
        MutationRates {
            delete_char: 0.1,
            insert_char: 0.1,
            permute_char: 0.1,
            duplicate_char: 0.1,
            mutate_char: 0.1,
            delete_rule: 0.05,
            insert_rule: 0.1,
            duplicate_rule: 0.05,
            mutate_parameter: 0.3,
        }
    }
}

impl MutationRates {
    /// Every rate made a legal probability (rates built in code are not range-checked).
    pub fn legal(&self) -> MutationRates {
        let p = sylva_core::rng::probability;
        MutationRates {
            delete_char: p(self.delete_char),
            insert_char: p(self.insert_char),
            permute_char: p(self.permute_char),
            duplicate_char: p(self.duplicate_char),
            mutate_char: p(self.mutate_char),
            delete_rule: p(self.delete_rule),
            insert_rule: p(self.insert_rule),
            duplicate_rule: p(self.duplicate_rule),
            mutate_parameter: p(self.mutate_parameter),
        }
    }
}

/// Index of the bracket matching the one at `at` (either direction), if balanced.
pub fn partner(word: &[Symbol], at: usize) -> Option<usize> {
    match word.get(at)? {
        Symbol::Push => {
            let mut depth = 0usize;
            for (i, s) in word.iter().enumerate().skip(at) {
                match s {
                    Symbol::Push => depth += 1,
                    Symbol::Pop => {
                        depth -= 1;
                        if depth == 0 {
                            return Some(i);
                        }
                    }
                    _ => {}
                }
            }
            None
        }
        Symbol::Pop => {
            let mut depth = 0usize;
            for i in (0..=at).rev() {
                match word[i] {
                    Symbol::Pop => depth += 1,
                    Symbol::Push => {
                        depth -= 1;
                        if depth == 0 {
                            return Some(i);
                        }
                    }
                    _ => {}
                }
            }
            None
        }
        _ => None,
    }
}

/// True when every `[` has a later matching `]`.
pub fn balanced(word: &[Symbol]) -> bool {
    let mut depth = 0i64;
    for s in word {
        match s {
            Symbol::Push => depth += 1,
            Symbol::Pop => {
                depth -= 1;
                if depth < 0 {
                    return false;
                }
            }
            _ => {}
        }
    }
    depth == 0
}

/// A random non-bracket symbol of a compartment: a module, an apex among the existing rules
/// (and one more, so new rules can be reached), or a rotation.
fn random_symbol<R: Rng + ?Sized>(rng: &mut R, compartment: Compartment, rules: usize) -> Symbol {
    let modules = match compartment {
        Compartment::Shoot => [Module::Leaf, Module::Branch],
        Compartment::Root => [Module::FineRoot, Module::RootBranch],
    };
    let axes = [Axis::Turn, Axis::Pitch, Axis::Roll];
    match rng.random_range(0..3) {
        0 => Symbol::Module(modules[rng.random_range(0..2)]),
        1 => Symbol::Apex(rng.random_range(0..=rules.min(MAX_RULES - 1)) as u8),
        _ => Symbol::Rotate(axes[rng.random_range(0..3)], rng.random_bool(0.5)),
    }
}

/// Applies the character operators to one rule.
fn mutate_rule<R: Rng + ?Sized>(
    rule: &mut Rule,
    rates: &MutationRates,
    compartment: Compartment,
    rules: usize,
    rng: &mut R,
) {
    let w = &mut rule.successor;
    if !w.is_empty() && rng.random_bool(rates.delete_char) {
        let at = rng.random_range(0..w.len());
        match partner(w, at) {
            Some(p) => {
                let (a, b) = (at.min(p), at.max(p));
                w.remove(b);
                w.remove(a);
            }
            None => {
                w.remove(at);
            }
        }
    }
    if rng.random_bool(rates.insert_char) {
        let at = rng.random_range(0..=w.len());
        if rng.random_bool(0.2) {
            // A bracket pair around a balanced stretch starting at `at`.
            let ends: Vec<usize> = (at..=w.len()).filter(|&e| balanced(&w[at..e])).collect();
            let end = ends[rng.random_range(0..ends.len())];
            w.insert(end, Symbol::Pop);
            w.insert(at, Symbol::Push);
        } else {
            w.insert(at, random_symbol(rng, compartment, rules));
        }
    }
    if w.len() >= 2 && rng.random_bool(rates.permute_char) {
        let at = rng.random_range(0..w.len() - 1);
        w.swap(at, at + 1);
        if !balanced(w) {
            w.swap(at, at + 1);
        }
    }
    if !w.is_empty() && rng.random_bool(rates.duplicate_char) {
        let at = rng.random_range(0..w.len());
        let (a, b) = match partner(w, at) {
            Some(p) => (at.min(p), at.max(p)),
            None => (at, at),
        };
        let group: Vec<Symbol> = w[a..=b].to_vec();
        w.splice(b + 1..b + 1, group);
    }
    if rng.random_bool(rates.mutate_char) {
        let plain: Vec<usize> = (0..w.len())
            .filter(|&i| !matches!(w[i], Symbol::Push | Symbol::Pop))
            .collect();
        if !plain.is_empty() {
            let at = plain[rng.random_range(0..plain.len())];
            w[at] = random_symbol(rng, compartment, rules);
        }
    }
}

/// Applies the character and rule operators to one compartment's rules.
pub fn mutate_rules<R: Rng + ?Sized>(
    set: &mut RuleSet,
    rates: &MutationRates,
    compartment: Compartment,
    rng: &mut R,
) {
    let rates = &rates.legal();
    let count = set.rules.len();
    for rule in &mut set.rules {
        mutate_rule(rule, rates, compartment, count, rng);
    }
    if !set.rules.is_empty() && rng.random_bool(rates.delete_rule) {
        let at = rng.random_range(0..set.rules.len());
        set.rules.remove(at);
    }
    if set.rules.len() < MAX_RULES && rng.random_bool(rates.insert_rule) {
        set.rules.push(Rule::default());
    }
    if !set.rules.is_empty() && set.rules.len() < MAX_RULES && rng.random_bool(rates.duplicate_rule)
    {
        let at = rng.random_range(0..set.rules.len());
        set.rules.push(set.rules[at].clone());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn always() -> MutationRates {
        MutationRates {
            delete_char: 1.0,
            insert_char: 1.0,
            permute_char: 1.0,
            duplicate_char: 1.0,
            mutate_char: 1.0,
            delete_rule: 0.3,
            insert_rule: 1.0,
            duplicate_rule: 1.0,
            mutate_parameter: 1.0,
        }
    }

    #[test]
    fn partners() {
        let w = crate::grammar::parse_word("[a[b]]c", Compartment::Shoot);
        assert!(w.is_err(), "`a` is not a symbol");
        let w = crate::grammar::parse_word("[l[b]]b", Compartment::Shoot).unwrap();
        assert_eq!(partner(&w, 0), Some(5));
        assert_eq!(partner(&w, 5), Some(0));
        assert_eq!(partner(&w, 2), Some(4));
        assert_eq!(partner(&w, 1), None);
    }

    proptest! {
        #[test]
        fn operators_keep_rules_well_formed(seed in any::<u64>(), rounds in 1usize..40) {
            let mut rng = sylva_core::rng::seeded(seed);
            for compartment in [Compartment::Shoot, Compartment::Root] {
                let mut set = RuleSet::default();
                for _ in 0..rounds {
                    mutate_rules(&mut set, &always(), compartment, &mut rng);
                    prop_assert!(set.rules.len() <= MAX_RULES);
                    // Printing and parsing again proves balance and the alphabet.
                    let reparsed = RuleSet::parse(&set.to_lines(), compartment);
                    prop_assert!(reparsed.is_ok(), "{:?}: {:?}", set.to_lines(), reparsed);
                    prop_assert_eq!(reparsed.unwrap(), set.clone());
                }
            }
        }
    }

    #[test]
    fn evolution_can_start_from_empty_rules() {
        let mut rng = sylva_core::rng::seeded(5);
        let mut set = RuleSet::default();
        let mut grew = false;
        for _ in 0..50 {
            mutate_rules(
                &mut set,
                &MutationRates::default(),
                Compartment::Shoot,
                &mut rng,
            );
            grew |= set.rules.iter().any(|r| !r.successor.is_empty());
        }
        assert!(
            grew,
            "mutations reach non-empty rules: {:?}",
            set.to_lines()
        );
    }
}
