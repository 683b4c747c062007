//! GP trees as S-expressions, in the style of lilgp's output.
//!
//! ```text
//! tree     = "(" "Top" operator+ ")"             ; 1 to 8 automata
//! operator = "(" NAME child* ")"                  ; children typed as in `Node`
//!          | "Wait" | "Killme"                    ; also accepted bare, printed "(Wait)"
//! value    = NUMBER                               ; -10 to 10, e.g. 3.2, -0.05, 1e-3
//! var      = "Length" | "Thickness" | "Var1" | "Var2" | "Var3" | "Var4"
//! target   = "A" DIGIT+ | "Leaf" | "Flower"      ; A2 is automaton 2 (numbered from 1)
//! ```
//!
//! Names are case-sensitive. Whitespace (including newlines) separates tokens; `;` starts a
//! comment to the end of the line. Parameters (values, variables, targets) are bare atoms,
//! operators are parenthesised, so `(Top (Seq (RotateH 3.2) (Wait)) (Killme))` is a tree of
//! two automata.
//!
//! Values print with Rust's shortest round-trip formatting of `f32` (`3.2`, not
//! `3.2000000476837`), so printing and parsing give back the identical tree, bit for bit.
//! A [`ParseError`] gives the byte offset, the line and column (1-based, in characters) and
//! what was expected there.

use std::fmt::{self, Write};
use std::str::FromStr;

use thiserror::Error;

use crate::tree::{
    GpTree, MAX_AUTOMATA, MAX_TREE_DEPTH, Node, Target, Type, VALUE_LIMIT, Var, legal_targets,
};

/// Why a text is not a GP tree.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[error("line {line}, column {column}: expected {expected}, found {found}")]
pub struct ParseError {
    /// Byte offset of the offending token.
    pub offset: usize,
    /// Its line, from 1.
    pub line: usize,
    /// Its column, from 1, in characters.
    pub column: usize,
    /// What was expected there.
    pub expected: String,
    /// What was found (the token, or "end of input").
    pub found: String,
}

impl fmt::Display for GpTree {
    /// The tree on one line, e.g. `(Top (Seq (RotateH 3.2) (Wait)) (Killme))`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Children still to print for each open parenthesis.
        let mut open: Vec<usize> = Vec::with_capacity(32);
        for (i, &node) in self.nodes().iter().enumerate() {
            if i > 0 {
                f.write_char(' ')?;
            }
            match node {
                Node::Value(v) => write!(f, "{v}")?,
                Node::Var(v) => f.write_str(v.name())?,
                Node::Target(t) => write!(f, "{t}")?,
                other => {
                    f.write_char('(')?;
                    f.write_str(other.name().unwrap_or("?"))?;
                    if other.arity() > 0 {
                        open.push(other.arity());
                        continue;
                    }
                    f.write_char(')')?;
                }
            }
            // A subtree ended: close every parenthesis whose children are all printed.
            while let Some(left) = open.last_mut() {
                *left -= 1;
                if *left > 0 {
                    break;
                }
                open.pop();
                f.write_char(')')?;
            }
        }
        Ok(())
    }
}

/// A tree serialises as its S-expression (checkpoints of GP runs hold trees this way).
impl serde::Serialize for GpTree {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for GpTree {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = <String as serde::Deserialize>::deserialize(d)?;
        GpTree::parse(&text).map_err(serde::de::Error::custom)
    }
}

impl FromStr for GpTree {
    type Err = ParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        GpTree::parse(s)
    }
}

impl GpTree {
    /// Parses the text form (see the [module docs](self)).
    pub fn parse(text: &str) -> Result<GpTree, ParseError> {
        let mut p = Parser {
            text,
            at: 0,
            nodes: Vec::with_capacity(text.len() / 6 + 4),
            targets: Vec::new(),
        };
        p.root()?;
        p.skip_blank();
        if p.at < text.len() {
            let (offset, found) = p.peek_token();
            return Err(p.error(offset, "the end of the tree", found));
        }
        let nodes = std::mem::take(&mut p.nodes);
        let count = nodes[0].arity();
        for &(offset, automaton, target) in &p.targets {
            if !target.legal_in(automaton, count) {
                return Err(p.error(offset, &legal_targets(automaton, count), target.to_string()));
            }
        }
        GpTree::new(nodes).map_err(|e| p.error(0, "a valid tree", e.to_string()))
    }
}

struct Parser<'a> {
    text: &'a str,
    at: usize,
    nodes: Vec<Node>,
    /// Targets to check once the number of automata is known: (offset, automaton, target).
    targets: Vec<(usize, usize, Target)>,
}

impl<'a> Parser<'a> {
    fn error(&self, offset: usize, expected: &str, found: String) -> ParseError {
        let before = &self.text[..offset.min(self.text.len())];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        ParseError {
            offset,
            line,
            column: before[line_start..].chars().count() + 1,
            expected: expected.to_owned(),
            found,
        }
    }

    fn skip_blank(&mut self) {
        let bytes = self.text.as_bytes();
        while self.at < bytes.len() {
            match bytes[self.at] {
                b' ' | b'\t' | b'\n' | b'\r' => self.at += 1,
                b';' => {
                    while self.at < bytes.len() && bytes[self.at] != b'\n' {
                        self.at += 1;
                    }
                }
                _ => break,
            }
        }
    }

    /// The next token's offset and text, without consuming it.
    fn peek_token(&mut self) -> (usize, String) {
        self.skip_blank();
        let start = self.at;
        let rest = &self.text[start..];
        match rest.chars().next() {
            None => (start, "end of input".to_owned()),
            Some(c @ ('(' | ')')) => (start, format!("`{c}`")),
            Some(_) => (start, format!("`{}`", atom_of(rest))),
        }
    }

    /// Consumes `c` (after blanks) or fails expecting `what`.
    fn expect_char(&mut self, c: u8, what: &str) -> Result<usize, ParseError> {
        self.skip_blank();
        if self.text.as_bytes().get(self.at) == Some(&c) {
            self.at += 1;
            Ok(self.at - 1)
        } else {
            let (offset, found) = self.peek_token();
            Err(self.error(offset, what, found))
        }
    }

    /// Consumes an atom (after blanks): its offset and text; `None` at `(`, `)` or the end.
    fn atom(&mut self) -> Option<(usize, &'a str)> {
        self.skip_blank();
        let start = self.at;
        let a = atom_of(&self.text[start..]);
        if a.is_empty() {
            return None;
        }
        self.at += a.len();
        Some((start, &self.text[start..start + a.len()]))
    }

    fn root(&mut self) -> Result<(), ParseError> {
        self.expect_char(b'(', "`(Top` starting the tree")?;
        let Some((offset, name)) = self.atom() else {
            let (offset, found) = self.peek_token();
            return Err(self.error(offset, "`Top`", found));
        };
        if name != "Top" {
            return Err(self.error(offset, "`Top`", format!("`{name}`")));
        }
        self.nodes.push(Node::Top(0));
        let mut count = 0usize;
        loop {
            self.skip_blank();
            if self.text.as_bytes().get(self.at) == Some(&b')') && count > 0 {
                self.at += 1;
                break;
            }
            if count == MAX_AUTOMATA {
                let (offset, found) = self.peek_token();
                return Err(self.error(
                    offset,
                    &format!("`)`: Top has at most {MAX_AUTOMATA} automata"),
                    found,
                ));
            }
            count += 1;
            self.operator(count, 1)?;
        }
        self.nodes[0] = Node::Top(count as u8);
        Ok(())
    }

    /// One subtree of type `TreeNode` in automaton `automaton` (1-based) at `depth`.
    fn operator(&mut self, automaton: usize, depth: usize) -> Result<(), ParseError> {
        if depth > MAX_TREE_DEPTH {
            let (offset, found) = self.peek_token();
            return Err(self.error(
                offset,
                &format!("a tree at most {MAX_TREE_DEPTH} deep"),
                found,
            ));
        }
        self.skip_blank();
        let bare = self.text.as_bytes().get(self.at) != Some(&b'(');
        if !bare {
            self.at += 1;
        }
        let Some((offset, name)) = self.atom() else {
            let (offset, found) = self.peek_token();
            return Err(self.error(offset, Type::TreeNode.describe(), found));
        };
        let node = match Node::from_name(name) {
            Some(Node::Top(_)) => {
                return Err(self.error(
                    offset,
                    "an operator (Top is only allowed at the root)",
                    "`Top`".to_owned(),
                ));
            }
            Some(node) if !bare || node.arity() == 0 => node,
            Some(_) => {
                return Err(self.error(
                    offset,
                    "`(` before an operator with parameters",
                    format!("`{name}`"),
                ));
            }
            None => {
                return Err(self.error(
                    offset,
                    "an operator: Seq, IfLess, IfGreater, IfEqual, PushPop, Repeat, \
                     RepeatIndex, RotateH, RotateL, RotateU, CreateAutomaton, Assign, Add, \
                     Multiply, Wait or Killme",
                    format!("`{name}`"),
                ));
            }
        };
        self.nodes.push(node);
        for &ty in node.child_types() {
            match ty {
                Type::TreeNode => self.operator(automaton, depth + 1)?,
                Type::Value => self.value()?,
                Type::Var => self.var()?,
                Type::Automaton => self.target(automaton)?,
                Type::Root => {}
            }
        }
        if !bare {
            self.expect_char(
                b')',
                &format!("`)` closing {}", node.name().unwrap_or("the operator")),
            )?;
        }
        Ok(())
    }

    fn value(&mut self) -> Result<(), ParseError> {
        let Some((offset, text)) = self.atom() else {
            let (offset, found) = self.peek_token();
            return Err(self.error(offset, Type::Value.describe(), found));
        };
        let ok = text
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.' | b'e' | b'E'));
        match text.parse::<f32>() {
            Ok(v) if ok && v.is_finite() && v.abs() <= VALUE_LIMIT => {
                self.nodes.push(Node::Value(v));
                Ok(())
            }
            _ => Err(self.error(offset, Type::Value.describe(), format!("`{text}`"))),
        }
    }

    fn var(&mut self) -> Result<(), ParseError> {
        let Some((offset, text)) = self.atom() else {
            let (offset, found) = self.peek_token();
            return Err(self.error(offset, Type::Var.describe(), found));
        };
        match Var::from_name(text) {
            Some(v) => {
                self.nodes.push(Node::Var(v));
                Ok(())
            }
            None => Err(self.error(offset, Type::Var.describe(), format!("`{text}`"))),
        }
    }

    fn target(&mut self, automaton: usize) -> Result<(), ParseError> {
        let Some((offset, text)) = self.atom() else {
            let (offset, found) = self.peek_token();
            return Err(self.error(offset, Type::Automaton.describe(), found));
        };
        let target = match text {
            "Leaf" => Some(Target::Leaf),
            "Flower" => Some(Target::Flower),
            _ => text
                .strip_prefix('A')
                .filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
                .and_then(|d| d.parse::<u8>().ok())
                .filter(|&n| (1..=MAX_AUTOMATA as u8).contains(&n))
                .map(Target::Automaton),
        };
        match target {
            Some(t) => {
                self.targets.push((offset, automaton, t));
                self.nodes.push(Node::Target(t));
                Ok(())
            }
            None => Err(self.error(offset, Type::Automaton.describe(), format!("`{text}`"))),
        }
    }
}

/// The atom at the start of `rest`: up to a blank, a parenthesis or a `;`.
fn atom_of(rest: &str) -> &str {
    let end = rest
        .find(|c: char| c.is_whitespace() || matches!(c, '(' | ')' | ';'))
        .unwrap_or(rest.len());
    &rest[..end]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prints_and_parses() {
        let text = "(Top (Seq (RotateH 3.2) (Wait)) (Killme))";
        let t = GpTree::parse(text).unwrap();
        assert_eq!(t.to_string(), text);
        let text = "(Top (Seq (CreateAutomaton A2) (IfLess Var1 -0.5 (Wait) (Killme))) \
                    (Repeat 3 (Seq (CreateAutomaton Leaf) (Multiply Thickness 0.9))))";
        assert_eq!(GpTree::parse(text).unwrap().to_string(), text);
    }

    #[test]
    fn accepts_bare_terminals_and_comments() {
        let t = GpTree::parse("; a tree\n(Top\n  (Seq Wait Killme) ; first\n  Wait)").unwrap();
        assert_eq!(t.to_string(), "(Top (Seq (Wait) (Killme)) (Wait))");
    }

    #[test]
    fn errors_point_at_the_token() {
        let e = GpTree::parse("(Top\n  (Seq (RotateH 12) (Wait)))").unwrap_err();
        assert_eq!((e.line, e.column, e.offset), (2, 17, 21));
        assert_eq!(e.expected, "a value from -10 to 10");
        assert_eq!(e.found, "`12`");
        let e = GpTree::parse("(Top (Seq (Wait) (Top (Wait))))").unwrap_err();
        assert_eq!(e.column, 19);
        assert!(e.expected.contains("only allowed at the root"), "{e}");
        let e = GpTree::parse("(Top (CreateAutomaton A1) (Wait))").unwrap_err();
        assert_eq!(e.column, 23);
        assert!(e.expected.contains("only A2"), "{e}");
        let e = GpTree::parse("(Top (CreateAutomaton Leaf) (Wait))").unwrap_err();
        assert!(e.expected.contains("only A2"), "{e}");
        let e = GpTree::parse("(Top (Wait)").unwrap_err();
        assert_eq!(e.found, "end of input");
        let e = GpTree::parse("(Top (Wait)) x").unwrap_err();
        assert_eq!((e.column, e.expected.as_str()), (14, "the end of the tree"));
        let e = GpTree::parse("(Top (Frobnicate))").unwrap_err();
        assert_eq!(e.found, "`Frobnicate`");
        let e = GpTree::parse("(Top (Assign Var9 1))").unwrap_err();
        assert_eq!(e.found, "`Var9`");
        let e = GpTree::parse("(Top RotateH 1)").unwrap_err();
        assert!(e.expected.contains("`(`"), "{e}");
        assert!(GpTree::parse("(Top (RotateH NaN))").is_err());
        assert!(GpTree::parse("(Top (RotateH inf))").is_err());
    }

    #[test]
    fn values_round_trip_exactly() {
        for v in [0.1f32, -3.3, 1e-7, 9.999_999, -10.0, 0.0, -0.0, 2.5e-3] {
            let t = GpTree::new(vec![Node::Top(1), Node::RotateH, Node::Value(v)]).unwrap();
            let back = GpTree::parse(&t.to_string()).unwrap();
            assert_eq!(back, t, "{v}");
        }
    }
}
