//! How errors reach the person at the terminal: bad input as a miette report that shows the
//! offending text (exit code 2), anything else as its message and causes (exit code 1).

use std::process::ExitCode;

use miette::{Diagnostic, LabeledSpan, NamedSource, SourceCode, SourceSpan};
use sylva::InputError;

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

/// An input error as miette shows it: the message, and the offending text underlined.
#[derive(Debug, thiserror::Error)]
#[error("{location}: {message}")]
struct Shown {
    location: String,
    message: String,
    snippet: Option<(NamedSource<String>, SourceSpan)>,
}

impl Shown {
    fn of(e: &InputError) -> Shown {
        let snippet = e.snippet.as_ref().map(|(text, range)| {
            let name = e
                .path
                .as_ref()
                .map_or_else(|| e.location.clone(), |p| p.display().to_string());
            let len = (range.end - range.start)
                .max(1)
                .min(text.len() - range.start);
            (
                NamedSource::new(name, text.to_string()),
                SourceSpan::from((range.start, len)),
            )
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
