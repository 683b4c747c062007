//! The L-system of Bornhofen and Lattaud (Table 1): alphabet, rules, parsing and printing.
//!
//! | symbol | compartment | meaning |
//! | --- | --- | --- |
//! | `l` | shoot | leaf module: captures light |
//! | `b` | shoot | branch module |
//! | `r` | root | fine-root module: takes up minerals |
//! | `c` | root | root-branch module |
//! | `A`..`Z` | both | apexes: the predecessors of the rules (`A` the first rule, `B` the second...) |
//! | `[` `]` | both | a ramification: push and pop the turtle |
//! | `+` `-` | both | turn (yaw) by ± the genome's turn angle |
//! | `<` `>` | both | pitch by ± the genome's pitch angle |
//! | `$` `&` | both | roll by ± the genome's roll angle |
//!
//! Rules are written as in the paper, `A -> [>b[B]A]$$$$[>b[B]A]`; the predecessor must be
//! the rule's letter (the first rule rewrites `A`). Spaces are ignored. A shoot rule may not
//! hold `r` or `c`, a root rule not `l` or `b`. Brackets must balance. Parse errors give the
//! rule, the column (1-based, in characters) and what was expected.

use std::fmt;

use serde::{Deserialize, Serialize};

/// Above or below ground.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Compartment {
    /// Above ground: `l` and `b`.
    Shoot,
    /// Below ground: `r` and `c`.
    Root,
}

/// A module: a sphyll (cylinder with spherical ends) of the plant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Module {
    /// `l`: captures light.
    Leaf,
    /// `b`: a branch.
    Branch,
    /// `r`: takes up minerals.
    FineRoot,
    /// `c`: a root branch.
    RootBranch,
}

impl Module {
    /// All four, in the order of [`Module::index`].
    pub const ALL: [Module; 4] = [
        Module::Leaf,
        Module::Branch,
        Module::FineRoot,
        Module::RootBranch,
    ];

    /// 0 to 3.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Its character.
    pub fn symbol(self) -> char {
        match self {
            Module::Leaf => 'l',
            Module::Branch => 'b',
            Module::FineRoot => 'r',
            Module::RootBranch => 'c',
        }
    }

    /// The compartment it grows in.
    pub fn compartment(self) -> Compartment {
        match self {
            Module::Leaf | Module::Branch => Compartment::Shoot,
            Module::FineRoot | Module::RootBranch => Compartment::Root,
        }
    }
}

/// The three rotation axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Axis {
    /// `+` / `-`: about U (yaw).
    Turn,
    /// `<` / `>`: about L (pitch).
    Pitch,
    /// `$` / `&`: about H (roll).
    Roll,
}

/// One symbol of a string.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Symbol {
    /// A module.
    Module(Module),
    /// An apex: the predecessor of rule `n` (`A` is 0).
    Apex(u8),
    /// `[`.
    Push,
    /// `]`.
    Pop,
    /// A rotation by plus (`true`) or minus the axis' angle.
    Rotate(Axis, bool),
}

/// Most rules a system can hold: one per letter.
pub const MAX_RULES: usize = 26;

impl Symbol {
    /// Its character.
    pub fn char(self) -> char {
        match self {
            Symbol::Module(m) => m.symbol(),
            Symbol::Apex(i) => char::from(b'A' + i.min(25)),
            Symbol::Push => '[',
            Symbol::Pop => ']',
            Symbol::Rotate(Axis::Turn, true) => '+',
            Symbol::Rotate(Axis::Turn, false) => '-',
            Symbol::Rotate(Axis::Pitch, true) => '>',
            Symbol::Rotate(Axis::Pitch, false) => '<',
            Symbol::Rotate(Axis::Roll, true) => '$',
            Symbol::Rotate(Axis::Roll, false) => '&',
        }
    }

    /// The symbol of a character, if it is in the alphabet.
    pub fn from_char(c: char) -> Option<Symbol> {
        Some(match c {
            'l' => Symbol::Module(Module::Leaf),
            'b' => Symbol::Module(Module::Branch),
            'r' => Symbol::Module(Module::FineRoot),
            'c' => Symbol::Module(Module::RootBranch),
            'A'..='Z' => Symbol::Apex(c as u8 - b'A'),
            '[' => Symbol::Push,
            ']' => Symbol::Pop,
            '+' => Symbol::Rotate(Axis::Turn, true),
            '-' => Symbol::Rotate(Axis::Turn, false),
            '>' => Symbol::Rotate(Axis::Pitch, true),
            '<' => Symbol::Rotate(Axis::Pitch, false),
            '$' => Symbol::Rotate(Axis::Roll, true),
            '&' => Symbol::Rotate(Axis::Roll, false),
            _ => return None,
        })
    }
}

/// Why a rule was refused. `rule` is 0-based (rule 0 rewrites `A`); `column` is 1-based.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("rule {} (`{}`), column {column}: {message}", rule + 1, char::from(b'A' + (*rule as u8).min(25)))]
pub struct RuleError {
    /// Which rule.
    pub rule: usize,
    /// Column of the offending character, 1-based.
    pub column: usize,
    /// What is wrong and what was expected.
    pub message: String,
}

/// A rule: its successor (the predecessor is implied by its position).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Rule {
    /// What the apex becomes.
    pub successor: Vec<Symbol>,
}

/// The rules of one compartment.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct RuleSet {
    /// Rule `i` rewrites apex `i`.
    pub rules: Vec<Rule>,
}

impl RuleSet {
    /// Parses rules written one per entry in the paper's notation (`A -> [>b[B]A]`).
    pub fn parse(lines: &[String], compartment: Compartment) -> Result<RuleSet, RuleError> {
        if lines.len() > MAX_RULES {
            return Err(RuleError {
                rule: MAX_RULES,
                column: 1,
                message: format!("at most {MAX_RULES} rules (one per letter A to Z)"),
            });
        }
        let rules = lines
            .iter()
            .enumerate()
            .map(|(i, line)| parse_rule(i, line, compartment))
            .collect::<Result<_, _>>()?;
        Ok(RuleSet { rules })
    }

    /// The rules as text, one per line, in the notation [`RuleSet::parse`] reads.
    pub fn to_lines(&self) -> Vec<String> {
        self.rules
            .iter()
            .enumerate()
            .map(|(i, r)| format!("{} -> {}", char::from(b'A' + i as u8), Word(&r.successor)))
            .collect()
    }

    /// The successor of apex `i`, if it has a rule.
    pub fn successor(&self, apex: u8) -> Option<&[Symbol]> {
        self.rules
            .get(usize::from(apex))
            .map(|r| r.successor.as_slice())
    }
}

/// Displays a string of symbols.
pub struct Word<'a>(pub &'a [Symbol]);

impl fmt::Display for Word<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.iter().try_for_each(|s| write!(f, "{}", s.char()))
    }
}

/// Parses rule `index` (0 rewrites `A`) of a compartment, written `A -> successor`.
pub fn parse_rule(index: usize, line: &str, compartment: Compartment) -> Result<Rule, RuleError> {
    let err = |column: usize, message: String| RuleError {
        rule: index,
        column,
        message,
    };
    let letter = char::from(b'A' + index as u8);
    let chars: Vec<(usize, char)> = line
        .chars()
        .enumerate()
        .map(|(i, c)| (i + 1, c))
        .filter(|(_, c)| !c.is_whitespace())
        .collect();
    let end_column = line.chars().count() + 1;
    match chars.first() {
        Some(&(_, c)) if c == letter => {}
        Some(&(col, c)) => {
            return Err(err(
                col,
                format!(
                    "expected the predecessor `{letter}` (rule {} rewrites `{letter}`), found `{c}`",
                    index + 1
                ),
            ));
        }
        None => {
            return Err(err(
                1,
                format!("expected `{letter} -> ...`, found an empty line"),
            ));
        }
    }
    match (chars.get(1), chars.get(2)) {
        (Some((_, '-')), Some((_, '>'))) => {}
        (Some(&(col, _)), _) => return Err(err(col, "expected `->` after the predecessor".into())),
        (None, _) => {
            return Err(err(
                end_column,
                "expected `->` after the predecessor".into(),
            ));
        }
    }
    let mut successor = Vec::with_capacity(chars.len().saturating_sub(3));
    let mut open: Vec<usize> = Vec::new();
    for &(col, c) in &chars[3..] {
        let symbol = Symbol::from_char(c).ok_or_else(|| {
            err(
                col,
                format!("`{c}` is not in the alphabet (l b r c A-Z [ ] + - < > $ &)"),
            )
        })?;
        match symbol {
            Symbol::Module(m) if m.compartment() != compartment => {
                let (here, allowed) = match compartment {
                    Compartment::Shoot => ("the shoot", "`l` and `b`"),
                    Compartment::Root => ("the root", "`r` and `c`"),
                };
                return Err(err(
                    col,
                    format!("`{c}` does not grow in {here}; its modules are {allowed}"),
                ));
            }
            Symbol::Push => open.push(col),
            Symbol::Pop if open.pop().is_none() => {
                return Err(err(col, "`]` without a matching `[`".into()));
            }
            _ => {}
        }
        successor.push(symbol);
    }
    if let Some(col) = open.pop() {
        return Err(err(col, "`[` is never closed by a `]`".into()));
    }
    Ok(Rule { successor })
}

/// Why a derivation stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Bounded {
    /// The length the string would have reached.
    pub would_be: usize,
    /// The limit.
    pub limit: usize,
}

/// Rewrites the apex at `at` in `word` by its rule; an apex without a rule stays. Refuses (and
/// leaves `word` unchanged) when the result would exceed `limit` symbols.
pub fn rewrite_at(
    word: &mut Vec<Symbol>,
    at: usize,
    rules: &RuleSet,
    limit: usize,
) -> Result<(), Bounded> {
    let Some(&Symbol::Apex(apex)) = word.get(at) else {
        return Ok(());
    };
    let Some(successor) = rules.successor(apex) else {
        return Ok(());
    };
    let would_be = word.len() - 1 + successor.len();
    if would_be > limit {
        return Err(Bounded { would_be, limit });
    }
    word.splice(at..=at, successor.iter().copied());
    Ok(())
}

/// One parallel derivation step of the whole word (every apex with a rule rewritten at once),
/// as in a plain DOL system; refuses when the result would exceed `limit` symbols.
pub fn derive(word: &[Symbol], rules: &RuleSet, limit: usize) -> Result<Vec<Symbol>, Bounded> {
    let would_be: usize = word
        .iter()
        .map(|s| match s {
            Symbol::Apex(a) => rules.successor(*a).map_or(1, <[Symbol]>::len),
            _ => 1,
        })
        .sum();
    if would_be > limit {
        return Err(Bounded { would_be, limit });
    }
    let mut out = Vec::with_capacity(would_be);
    for s in word {
        match s {
            Symbol::Apex(a) => match rules.successor(*a) {
                Some(succ) => out.extend_from_slice(succ),
                None => out.push(*s),
            },
            _ => out.push(*s),
        }
    }
    Ok(out)
}

/// Parses a bare word such as an axiom (`[A]`), with the same checks as a successor.
pub fn parse_word(text: &str, compartment: Compartment) -> Result<Vec<Symbol>, RuleError> {
    parse_rule(0, &format!("A->{text}"), compartment)
        .map(|r| r.successor)
        .map_err(|mut e| {
            e.column = e.column.saturating_sub(3);
            e
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(rules: &[&str]) -> Vec<String> {
        rules.iter().map(|s| (*s).to_owned()).collect()
    }

    #[test]
    fn the_papers_bush_parses_and_prints() {
        let shoot = lines(&["A -> [>b[B]A]$$$$[>b[B]A]$$$$[>b[B]A]", "B -> >>l"]);
        let rules = RuleSet::parse(&shoot, Compartment::Shoot).unwrap();
        assert_eq!(rules.rules[0].successor.len(), 32);
        assert_eq!(rules.to_lines(), shoot);
        let root = lines(&["A -> [<c[B]$$A][[B]$$A]", "B -> >r"]);
        let rules = RuleSet::parse(&root, Compartment::Root).unwrap();
        assert_eq!(rules.to_lines(), root);
    }

    #[test]
    fn errors_point_at_the_character() {
        let check = |rule: &str, compartment, column, needle: &str| {
            let e = RuleSet::parse(&lines(&[rule]), compartment).unwrap_err();
            assert_eq!(e.column, column, "{rule}: {e}");
            assert!(e.message.contains(needle), "{rule}: {e}");
        };
        // The paper's misprint: `B -> >>|` has `|` for `l`.
        let e = RuleSet::parse(&lines(&["A -> [B]", "B -> >>|"]), Compartment::Shoot).unwrap_err();
        assert_eq!((e.rule, e.column), (1, 8));
        assert!(e.message.contains("alphabet"));
        check("A -> [b", Compartment::Shoot, 6, "never closed");
        check("A -> b]", Compartment::Shoot, 7, "without a matching");
        check(
            "A -> br",
            Compartment::Shoot,
            7,
            "does not grow in the shoot",
        );
        check("A -> rl", Compartment::Root, 7, "does not grow in the root");
        check("B -> b", Compartment::Shoot, 1, "predecessor `A`");
        check("A => b", Compartment::Shoot, 3, "`->`");
        check("", Compartment::Shoot, 1, "empty");
        assert_eq!(
            e.to_string(),
            "rule 2 (`B`), column 8: `|` is not in the alphabet (l b r c A-Z [ ] + - < > $ &)"
        );
    }

    #[test]
    fn empty_rules_are_legal() {
        let rules = RuleSet::parse(&lines(&["A ->"]), Compartment::Shoot).unwrap();
        assert!(rules.rules[0].successor.is_empty());
    }

    #[test]
    fn derivation_is_bounded() {
        let rules = RuleSet::parse(&lines(&["A -> AA"]), Compartment::Shoot).unwrap();
        let mut word = parse_word("[A]", Compartment::Shoot).unwrap();
        for _ in 0..5 {
            word = derive(&word, &rules, 1000).unwrap();
        }
        assert_eq!(word.len(), 34);
        let e = (0..10)
            .try_fold(word, |w, _| derive(&w, &rules, 1000))
            .unwrap_err();
        assert_eq!(e.limit, 1000);
        let mut w = parse_word("[A]", Compartment::Shoot).unwrap();
        rewrite_at(&mut w, 1, &rules, 10).unwrap();
        assert_eq!(Word(&w).to_string(), "[AA]");
        assert!(rewrite_at(&mut w, 1, &rules, 4).is_err());
        assert_eq!(Word(&w).to_string(), "[AA]", "unchanged when refused");
    }
}
