//! Errors the command line reports, and their exit codes.
//!
//! [`InputError`] is anything wrong with what the user gave (a file, a flag's value): it
//! names the file, line and column, says what was expected, shows the offending text, and
//! exits with code 2. Everything else exits with code 1.

use std::path::Path;

use miette::{Diagnostic, LabeledSpan, NamedSource, SourceCode, SourceSpan};

/// Bad input: a malformed genome, config or flag value.
#[derive(Debug, thiserror::Error)]
#[error("{location}: {message}")]
pub struct InputError {
    /// `path:line:column` (or just the path, or the flag).
    pub location: String,
    /// What is wrong and what was expected.
    pub message: String,
    /// The text and the offending span, shown under the message.
    snippet: Option<Box<(NamedSource<String>, SourceSpan)>>,
}

impl Diagnostic for InputError {
    fn source_code(&self) -> Option<&dyn SourceCode> {
        self.snippet.as_ref().map(|s| &s.0 as &dyn SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let span = self.snippet.as_ref()?.1;
        Some(Box::new(std::iter::once(LabeledSpan::new_with_span(
            Some("here".to_owned()),
            span,
        ))))
    }
}

impl InputError {
    /// An error about a whole file or a flag, without a position.
    pub fn new(location: impl Into<String>, message: impl Into<String>) -> Self {
        InputError {
            location: location.into(),
            message: message.into(),
            snippet: None,
        }
    }

    /// An error at 1-based `line` and `column` of `text`, read from `path`. Parsers such as
    /// serde_json report the position just past the offending token; the error is moved back
    /// to the token's start and spans it.
    pub fn at(path: &Path, text: &str, line: usize, column: usize, message: String) -> Self {
        let end = offset_of(text, line, column);
        let start = token_start(text, end);
        Self::spanned(path, text, start..end, message)
    }

    /// An error over a byte range of `text`, read from `path`.
    pub fn spanned(
        path: &Path,
        text: &str,
        range: std::ops::Range<usize>,
        message: String,
    ) -> Self {
        let start = range.start.min(text.len());
        let (line, column) = line_column(text, start);
        let len = range.end.clamp(start, text.len()) - start;
        InputError {
            location: format!("{}:{line}:{column}", path.display()),
            message,
            snippet: Some(Box::new((
                NamedSource::new(path.display().to_string(), text.to_owned()),
                SourceSpan::from((start, len.max(1).min(text.len() - start))),
            ))),
        }
    }
}

/// Byte offset of a 1-based line and column (columns count characters); clamped to the text.
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let mut offset = 0;
    for (i, l) in text.split_inclusive('\n').enumerate() {
        if i + 1 == line {
            let col = l
                .char_indices()
                .nth(column.saturating_sub(1))
                .map_or(l.len(), |(b, _)| b);
            return offset + col;
        }
        offset += l.len();
    }
    text.len()
}

/// Start of the token that ends at `end` (JSON and TOML tokens end at white space or
/// punctuation).
fn token_start(text: &str, end: usize) -> usize {
    let end = text.floor_char_boundary(end);
    text[..end]
        .char_indices()
        .rev()
        .take_while(|(_, c)| !c.is_whitespace() && !matches!(c, ':' | ',' | '[' | '{' | '='))
        .last()
        .map_or(end, |(i, _)| i)
}

/// 1-based line and column of a byte offset.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..text.floor_char_boundary(offset)];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_and_positions_agree() {
        let text = "a = 1\nbé = 2\nc = 3\n";
        let off = offset_of(text, 2, 3);
        assert_eq!(&text[off..off + 1], " ");
        assert_eq!(line_column(text, off), (2, 3));
        assert_eq!(offset_of(text, 9, 9), text.len());
    }

    #[test]
    fn positions_move_to_the_token_start() {
        let text = "{\n  \"a\": -0.5,\n}";
        let e = InputError::at(Path::new("g.json"), text, 2, 12, "bad".into());
        assert_eq!(e.location, "g.json:2:8");
        assert_eq!(token_start("x", 0), 0);
    }

    #[test]
    fn location_names_file_line_column() {
        let e = InputError::spanned(Path::new("x.toml"), "a\nbb\n", 3..4, "bad".into());
        assert_eq!(e.to_string(), "x.toml:2:2: bad");
    }
}
