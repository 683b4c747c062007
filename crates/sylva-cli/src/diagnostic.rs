//! How errors reach the person at the terminal: bad input as a miette report that shows the
//! offending text (exit code 2), anything else as its message and causes (exit code 1).
//!
//! The text shown is a window: the offending line cut to [`WIDTH`] characters around the
//! error, and the lines either side cut to [`WIDTH`], whatever the file's line lengths (a
//! minified 50 MB genome prints a few lines, not the file). Line and column numbers are the
//! file's.

use std::ops::Range;
use std::process::ExitCode;

use miette::{
    Diagnostic, LabeledSpan, MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents,
};
use sylva::InputError;

/// Most characters of a line shown under an error.
const WIDTH: usize = 120;

/// Sets up miette: long messages stay on one line, so they can be searched for and copied
/// whole.
pub fn install() {
    let _ = miette::set_hook(Box::new(|_| {
        Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())
    }));
}

/// Prints an error and returns its exit code.
pub fn report(e: &anyhow::Error) -> ExitCode {
    let input = e
        .downcast_ref::<InputError>()
        .or_else(|| match e.downcast_ref() {
            Some(sylva::Error::Input(input)) => Some(input),
            _ => None,
        });
    match input {
        Some(input) => {
            eprintln!("{:?}", miette::Report::new(Shown::of(input)));
            ExitCode::from(2)
        }
        None => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

/// Reports a panic (a bug in Sylva, never an answer to bad input) in one line.
pub fn report_bug(info: &std::panic::PanicHookInfo<'_>) {
    eprintln!(
        "error: internal error, a bug in Sylva (please report it with the command that \
         caused it): {info}"
    );
}

/// An input error as miette shows it: the message, and the offending text underlined.
#[derive(Debug, thiserror::Error)]
#[error("{location}: {message}")]
struct Shown {
    location: String,
    message: String,
    snippet: Option<(Snippet, SourceSpan)>,
}

impl Shown {
    fn of(e: &InputError) -> Shown {
        let snippet = e.snippet.as_deref().map(|(text, range)| {
            let name = e
                .path
                .as_ref()
                .map_or_else(|| e.location.clone(), |p| p.display().to_string());
            Snippet::around(name, text, range.clone())
        });
        Shown {
            location: e.location.clone(),
            message: e.message.clone(),
            snippet,
        }
    }
}

impl Diagnostic for Shown {
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

/// A few short lines of a file around an error, numbered as in the file.
#[derive(Debug)]
struct Snippet {
    name: String,
    text: String,
    /// The file's 0-based line of the snippet's first line.
    first_line: usize,
    /// The snippet's 0-based line that holds the error.
    error_line: usize,
    /// Where the error's line starts in the snippet, after any "…".
    error_line_start: usize,
    /// Characters cut from the start of the error's line.
    cut: usize,
}

impl Snippet {
    /// The window of `text` around `range`, and the range within it.
    fn around(name: String, text: &str, range: Range<usize>) -> (Snippet, SourceSpan) {
        let start = text.floor_char_boundary(range.start.min(text.len()));
        let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let line_no = text[..line_start].matches('\n').count();
        // The error's line, from WIDTH / 2 characters before the error.
        let before: Vec<usize> = text[line_start..start]
            .char_indices()
            .map(|(i, _)| line_start + i)
            .collect();
        let (cut_from, cut) = if before.len() > WIDTH / 2 {
            let keep = before.len() - WIDTH / 2;
            (before[keep], keep)
        } else {
            (line_start, 0)
        };
        let marker = if cut_from > line_start { "…" } else { "" };
        let line = clip(&text[cut_from..line_end], WIDTH);
        let mut out = String::new();
        let mut first_line = line_no;
        if line_start > 0 {
            let prev_start = text[..line_start - 1].rfind('\n').map_or(0, |i| i + 1);
            out.push_str(&clip(&text[prev_start..line_start - 1], WIDTH));
            out.push('\n');
            first_line -= 1;
        }
        let error_line = line_no - first_line;
        out.push_str(marker);
        let error_line_start = out.len();
        let offset = out.len() + (start - cut_from);
        out.push_str(&line);
        if line_end < text.len() {
            let next_end = text[line_end + 1..]
                .find('\n')
                .map_or(text.len(), |i| line_end + 1 + i);
            out.push('\n');
            out.push_str(&clip(&text[line_end + 1..next_end], WIDTH));
        }
        let span_end = (range.end.max(start) - cut_from).min(line.len());
        let len = span_end.saturating_sub(start - cut_from).max(1);
        let offset = offset.min(out.len());
        let len = len.min(out.len() - offset);
        let snippet = Snippet {
            name,
            text: out,
            first_line,
            error_line,
            error_line_start,
            cut,
        };
        (snippet, SourceSpan::from((offset, len)))
    }
}

/// A line cut to `width` characters, with "…" when cut.
fn clip(line: &str, width: usize) -> String {
    match line.char_indices().nth(width) {
        Some((i, _)) => format!("{}…", &line[..i]),
        None => line.to_owned(),
    }
}

impl SourceCode for Snippet {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let inner = self.text.read_span(span, before, after)?;
        // Columns count characters, as the error's location does.
        let offset = inner.span().offset().min(self.text.len());
        let column = if inner.line() == self.error_line && offset >= self.error_line_start {
            self.cut + self.text[self.error_line_start..offset].chars().count()
        } else {
            let line_start = self.text[..offset].rfind('\n').map_or(0, |i| i + 1);
            self.text[line_start..offset].chars().count()
        };
        Ok(Box::new(MietteSpanContents::new_named(
            self.name.clone(),
            inner.data(),
            *inner.span(),
            inner.line() + self.first_line,
            column,
            inner.line_count(),
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shown(text: &str, at: usize) -> String {
        let (snippet, span) = Snippet::around("f.json".into(), text, at..at + 2);
        let label = &snippet.text[span.offset()..span.offset() + span.len()];
        format!("{}|{}|{label}", snippet.first_line, snippet.text)
    }

    #[test]
    fn long_lines_are_cut_around_the_error() {
        let text = format!("{{\n\"a\": {}\"x\": -5}}\n", " ".repeat(100_000));
        let at = text.find("-5").unwrap();
        let s = shown(&text, at);
        assert!(s.len() < 400, "{}", s.len());
        assert!(s.starts_with("0|{\n…"), "{s}");
        assert!(s.ends_with("|-5"), "{s}");
        // The snippet reports the file's line and column.
        let (snippet, span) = Snippet::around("f.json".into(), &text, at..at + 2);
        let c = snippet.read_span(&span, 0, 0).unwrap();
        assert_eq!((c.line(), c.column()), (1, at - 2));
    }

    #[test]
    fn short_files_are_shown_whole_around_the_error() {
        let text = "a = 1\nb = bad\nc = 3\n";
        assert_eq!(shown(text, 10), "0|a = 1\nb = bad\nc = 3|ba");
        assert_eq!(shown("x", 0), "0|x|x");
        assert_eq!(shown("", 0), "0||");
    }

    #[test]
    fn reports_never_panic_on_huge_columns() {
        let text = format!("{}bad", "x".repeat(70_000));
        let e = InputError::spanned(
            std::path::Path::new("f.json"),
            &text,
            70_000..70_003,
            "no".into(),
        );
        let out = format!("{:?}", miette::Report::new(Shown::of(&e)));
        assert!(out.contains("f.json:1:70001"), "{out}");
        assert!(out.len() < 2000, "{}", out.len());
    }
}
