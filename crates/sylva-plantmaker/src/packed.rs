//! The packed face: the genome as the paper's "string of numbers", one number per variable.
//!
//! The paper stores a genome as a bit string laid out by its tables, which a person "can
//! freely access and modify". Raw bits are hard to edit by hand, so Sylva writes the value
//! each variable's bits hold, in decimal, in table order, one line per segment:
//!
//! ```text
//! plantmaker 1
//! seed 42
//! branch 0 0 0 0 0 0 1 0 10 10 1 8 30 8 30 0 12 12 1 356 4 356 4
//! fan 2 5 4 7 12 4 20 40 0 10 10 0 #6b4a2f #6b4a2f 0
//! inflorescence 0 0 45 10000
//! ```
//!
//! - Options are their table codes (`segment_pattern` 3 is diamond), factors are in tenths
//!   (Table 2's 1–30 and 1–50), angles in whole degrees.
//! - Colours are written `#rrggbb`, the 24-bit number in hexadecimal.
//! - An inflorescence's fan set is the paper's m binary digits, first fan leftmost
//!   (`10100` is fans 1 and 3), and its "expressed" variable keeps the table's code:
//!   0 = yes, 1 = no.
//! - Blank lines and lines starting with `#` are comments; [`PlantMaker::to_packed`] writes
//!   one naming the columns above each kind of segment.
//!
//! The counts n, m and k are the numbers of `branch`, `fan` and `inflorescence` lines, in
//! the order written. Every number is checked against its table row; an error names the
//! line and column, the segment, and the variable's number and name with its range.

use std::fmt::{self, Write};

use crate::PlantMaker;
use crate::genes::{
    BRANCH_VARIABLES, Branch, FAN_VARIABLES, Fan, GeneKind, INFLORESCENCE_VARIABLES, Inflorescence,
    MAX_BRANCHES, MAX_FANS, MAX_INFLORESCENCES, Rgb, Variable,
};
use sylva_model::FormatV1;

/// Why a packed genome was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct PackedError {
    /// 1-based line, 0 when the error concerns the whole text.
    pub line: usize,
    /// 1-based column (in characters) of the offending token, 0 when none.
    pub column: usize,
    /// The segment, e.g. `"fan 2"`, when the error is inside one.
    pub segment: Option<String>,
    /// The variable's number in its table and its name, when the error is about one.
    pub variable: Option<(u8, &'static str)>,
    /// What is wrong and what was expected.
    pub message: String,
}

impl fmt::Display for PackedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "line {}, column {}: ", self.line, self.column)?;
        }
        if let Some(s) = &self.segment {
            write!(f, "{s}")?;
            if let Some((n, name)) = self.variable {
                write!(f, ", variable {n} (`{name}`)")?;
            }
            f.write_str(": ")?;
        }
        f.write_str(&self.message)
    }
}

/// One whitespace-separated word and its 1-based column.
#[derive(Clone, Copy, Debug)]
struct Token<'a> {
    text: &'a str,
    column: usize,
}

fn tokens(line: &str) -> Vec<Token<'_>> {
    let mut out = Vec::new();
    let mut start = None;
    for (col, (i, c)) in line.char_indices().enumerate() {
        match (c.is_whitespace(), start) {
            (false, None) => start = Some((i, col + 1)),
            (true, Some((s, column))) => {
                out.push(Token {
                    text: &line[s..i],
                    column,
                });
                start = None;
            }
            _ => {}
        }
    }
    if let Some((s, column)) = start {
        out.push(Token {
            text: &line[s..],
            column,
        });
    }
    out
}

/// A segment line waiting for the counts of the others.
struct SegmentLine<'a> {
    line: usize,
    /// Column just past the last token, for "missing value" errors.
    end: usize,
    values: Vec<Token<'a>>,
}

fn error(line: usize, column: usize, message: impl Into<String>) -> PackedError {
    PackedError {
        line,
        column,
        segment: None,
        variable: None,
        message: message.into(),
    }
}

/// Reads one segment's codes against its table.
fn read_segment<const N: usize>(
    kind: &str,
    index: usize,
    seg: &SegmentLine,
    table: &[Variable; N],
    branches: usize,
    fans: usize,
) -> Result<[u32; N], PackedError> {
    let segment = format!("{kind} {}", index + 1);
    let fail = |column: usize, v: Option<&Variable>, message: String| PackedError {
        line: seg.line,
        column,
        segment: Some(segment.clone()),
        variable: v.map(|v| (v.number, v.name)),
        message,
    };
    if seg.values.len() > N {
        let extra = seg.values[N];
        return Err(fail(
            extra.column,
            None,
            format!(
                "a {kind} has {N} variables, this line has {}",
                seg.values.len()
            ),
        ));
    }
    let mut codes = [0u32; N];
    for (i, v) in table.iter().enumerate() {
        let Some(token) = seg.values.get(i) else {
            return Err(fail(
                seg.end,
                Some(v),
                format!(
                    "missing (a {kind} has {N} variables, this line has {})",
                    seg.values.len()
                ),
            ));
        };
        let (min, max) = v.range(branches, fans);
        let code = match v.kind {
            GeneKind::Color => Rgb::parse(token.text).map(Rgb::code).ok_or_else(|| {
                fail(
                    token.column,
                    Some(v),
                    format!("expected a colour #rrggbb, got `{}`", token.text),
                )
            })?,
            GeneKind::FanSet => {
                let digits = token.text;
                if digits.len() != fans || !digits.bytes().all(|b| b == b'0' || b == b'1') {
                    return Err(fail(
                        token.column,
                        Some(v),
                        format!(
                            "expected {fans} binary digits, one per fan (first fan leftmost), got `{digits}`"
                        ),
                    ));
                }
                digits
                    .bytes()
                    .enumerate()
                    .filter(|&(_, b)| b == b'1')
                    .fold(0, |m, (f, _)| m | 1 << f)
            }
            _ => {
                let value: i64 = token.text.parse().map_err(|_| {
                    fail(
                        token.column,
                        Some(v),
                        format!(
                            "expected a whole number from {min} to {max}, got `{}`",
                            token.text
                        ),
                    )
                })?;
                if !(i64::from(min)..=i64::from(max)).contains(&value) {
                    return Err(fail(
                        token.column,
                        Some(v),
                        format!("{value} is out of range (expected {min} to {max})"),
                    ));
                }
                value as u32
            }
        };
        codes[i] = code;
    }
    Ok(codes)
}

impl PlantMaker {
    /// The packed face (see the [module docs](self)); [`PlantMaker::from_packed`] reads it
    /// back to the same genome.
    pub fn to_packed(&self) -> String {
        let mut s = String::new();
        let m = self.fans.len();
        let names = |table: &[Variable]| table.iter().map(|v| v.name).collect::<Vec<_>>().join(" ");
        let _ = writeln!(s, "plantmaker 1");
        let _ = writeln!(s, "seed {}", self.seed);
        let _ = writeln!(s, "# branch: {}", names(&BRANCH_VARIABLES));
        for b in &self.branches {
            let codes = b.codes().map(|c| c.to_string());
            let _ = writeln!(s, "branch {}", codes.join(" "));
        }
        let _ = writeln!(s, "# fan: {}", names(&FAN_VARIABLES));
        for f in &self.fans {
            let mut words: Vec<String> = f.codes().iter().map(u32::to_string).collect();
            words[12] = f.min_color.to_string();
            words[13] = f.max_color.to_string();
            let _ = writeln!(s, "fan {}", words.join(" "));
        }
        let _ = writeln!(s, "# inflorescence: {}", names(&INFLORESCENCE_VARIABLES));
        for i in &self.inflorescences {
            let c = i.codes();
            let _ = writeln!(
                s,
                "inflorescence {} {} {} {}",
                c[0],
                c[1],
                c[2],
                i.fans.digits(m)
            );
        }
        s
    }

    /// Reads the packed face, refusing anything out of range with its position.
    pub fn from_packed(text: &str) -> Result<PlantMaker, PackedError> {
        let mut header = false;
        let mut seed = None;
        let (mut branches, mut fans, mut infls) = (Vec::new(), Vec::new(), Vec::new());
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let words = tokens(raw);
            let Some(first) = words.first() else {
                continue;
            };
            if first.text.starts_with('#') {
                continue;
            }
            if !header {
                if words.len() == 2 && first.text == "plantmaker" && words[1].text == "1" {
                    header = true;
                    continue;
                }
                return Err(error(
                    line,
                    first.column,
                    "a packed genome starts with the line `plantmaker 1`",
                ));
            }
            let end = raw.chars().count() + 1;
            let seg = SegmentLine {
                line,
                end,
                values: words[1..].to_vec(),
            };
            match first.text {
                "seed" => {
                    if seed.is_some() {
                        return Err(error(line, first.column, "a second `seed` line"));
                    }
                    let [value] = seg.values[..] else {
                        return Err(error(line, end, "expected `seed` and one whole number"));
                    };
                    seed = Some(value.text.parse::<u64>().map_err(|_| {
                        error(
                            line,
                            value.column,
                            format!(
                                "the seed is a whole number from 0 to {}, got `{}`",
                                u64::MAX,
                                value.text
                            ),
                        )
                    })?);
                }
                "branch" => branches.push(seg),
                "fan" => fans.push(seg),
                "inflorescence" => infls.push(seg),
                other => {
                    return Err(error(
                        line,
                        first.column,
                        format!(
                            "expected `seed`, `branch`, `fan` or `inflorescence`, got `{other}`"
                        ),
                    ));
                }
            }
        }
        if !header {
            return Err(error(
                0,
                0,
                "a packed genome starts with the line `plantmaker 1`",
            ));
        }
        let seed = seed.ok_or_else(|| error(0, 0, "the `seed` line is missing"))?;
        let (n, m) = (branches.len(), fans.len());
        for (what, lines, max) in [
            ("branch", &branches, MAX_BRANCHES),
            ("fan", &fans, MAX_FANS),
            ("inflorescence", &infls, MAX_INFLORESCENCES),
        ] {
            if lines.is_empty() {
                return Err(error(
                    0,
                    0,
                    format!("a genome needs at least one `{what}` line"),
                ));
            }
            if lines.len() > max {
                return Err(error(
                    lines[max].line,
                    1,
                    format!("a genome has at most {max} `{what}` lines"),
                ));
            }
        }
        let invalid = "codes were checked against the same table";
        let branches = branches
            .iter()
            .enumerate()
            .map(|(i, s)| {
                read_segment("branch", i, s, &BRANCH_VARIABLES, n, m)
                    .map(|c| Branch::from_codes(&c).expect(invalid))
            })
            .collect::<Result<_, _>>()?;
        let fans = fans
            .iter()
            .enumerate()
            .map(|(i, s)| {
                read_segment("fan", i, s, &FAN_VARIABLES, n, m)
                    .map(|c| Fan::from_codes(&c, n).expect(invalid))
            })
            .collect::<Result<_, _>>()?;
        let inflorescences = infls
            .iter()
            .enumerate()
            .map(|(i, s)| {
                read_segment("inflorescence", i, s, &INFLORESCENCE_VARIABLES, n, m)
                    .map(|c| Inflorescence::from_codes(&c, m).expect(invalid))
            })
            .collect::<Result<_, _>>()?;
        Ok(PlantMaker {
            model: crate::PlantMakerTag,
            format: FormatV1,
            seed,
            branches,
            fans,
            inflorescences,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_round_trips() {
        let g = PlantMaker::default();
        let text = g.to_packed();
        assert_eq!(PlantMaker::from_packed(&text).unwrap(), g);
        assert!(text.contains("inflorescence 0 0 45 10000"), "{text}");
        assert!(text.contains("inflorescence 0 1 30 00001"), "{text}");
    }

    #[test]
    fn errors_name_segment_variable_and_position() {
        let g = PlantMaker::default();
        let text = g.to_packed();
        let bad = text.replacen("fan 2 5", "fan 2 99", 1);
        let e = PlantMaker::from_packed(&bad).unwrap_err();
        assert_eq!(e.segment.as_deref(), Some("fan 1"));
        assert_eq!(e.variable, Some((2, "count")));
        assert_eq!(e.column, 7);
        assert!(
            e.to_string()
                .contains("99 is out of range (expected 1 to 72)"),
            "{e}"
        );
        let bad = text.replacen("inflorescence 0 0 45 10000", "inflorescence 0 0 45 1000", 1);
        let e = PlantMaker::from_packed(&bad).unwrap_err();
        assert_eq!(e.variable, Some((4, "fans")));
        assert!(e.message.contains("5 binary digits"), "{e}");
        let bad = text.replacen("fan 2 5", "fan 6 5", 1);
        let e = PlantMaker::from_packed(&bad).unwrap_err();
        assert!(e.message.contains("expected 1 to 5"), "{e}");
        let bad = text.replacen("#6b4a2f", "#6b4a2", 1);
        let e = PlantMaker::from_packed(&bad).unwrap_err();
        assert_eq!(e.variable, Some((13, "min_color")));
        let short = text.replacen(" 356 4\n", "\n", 1);
        let e = PlantMaker::from_packed(&short).unwrap_err();
        assert_eq!(e.variable, Some((22, "min_noise_y_angle")));
        assert!(PlantMaker::from_packed("seed 1\n").is_err());
    }
}
