//! What can go wrong, as typed errors with their causes kept.
//!
//! [`InputError`] is anything wrong with what a user gave: a file (a genome, a config, a
//! checkpoint), a value of a field or a flag. It names where (the file with its line and
//! column, or the flag) and what was expected, and keeps the offending text so a front end
//! can show it. Every other failure is an [`Error`] variant that says what Sylva was doing,
//! with the reason as its [`source`](std::error::Error::source): print the chain (as
//! `anyhow`'s `{:#}` does) to see both.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use sylva_model::{DevelopError, GenomeError};

/// An error in a value built in code rather than read from a file (a front end's form):
/// the field by its JSON path in the value (`run.population`, `automata.fitness.target`)
/// and what is wrong. The path never holds one of the value's values.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{field}`: {message}")]
pub struct FieldError {
    /// The field's JSON path (empty: the value as a whole).
    pub field: String,
    /// What is wrong and what was expected.
    pub message: String,
}

impl FieldError {
    /// An error about `field`.
    pub fn new(field: impl Into<String>, message: impl ToString) -> FieldError {
        FieldError {
            field: field.into(),
            message: message.to_string(),
        }
    }

    /// A serde error found reading `sent`, naming the field where it was found; for a
    /// missing field, that field; for an unknown field or variant, or a message naming a
    /// field (`` `radius` must be ... ``, from a table read whole), that field when it is a
    /// key of the object there.
    pub fn of<E: std::fmt::Display>(
        e: &serde_path_to_error::Error<E>,
        sent: &serde_json::Value,
    ) -> FieldError {
        let path = e.path().to_string();
        let path = if path == "." || path == "?" {
            ""
        } else {
            &path
        };
        let message = e.inner().to_string();
        let quoted = message.split('`').nth(1).unwrap_or("");
        let is_key =
            !quoted.is_empty() && at_path(sent, path).is_some_and(|v| v.get(quoted).is_some());
        let field = if message.starts_with("missing field `") || is_key {
            join(path, quoted)
        } else {
            path.to_owned()
        };
        FieldError { field, message }
    }
}

/// `name` under the JSON path `path` (`a.b` and `c` give `a.b.c`; `[2]` gives `a.b[2]`).
pub fn join(path: &str, name: &str) -> String {
    match (path.is_empty(), name.is_empty()) {
        (true, _) => name.to_owned(),
        (false, true) => path.to_owned(),
        (false, false) if name.starts_with('[') => format!("{path}{name}"),
        (false, false) => format!("{path}.{name}"),
    }
}

/// The value at a JSON path (`a.b[1].c`) of `value`.
pub fn at_path<'v>(value: &'v serde_json::Value, path: &str) -> Option<&'v serde_json::Value> {
    let mut at = value;
    for part in path.split('.').filter(|p| !p.is_empty()) {
        let (name, indices) = part.split_at(part.find('[').unwrap_or(part.len()));
        if !name.is_empty() {
            at = at.get(name)?;
        }
        for index in indices.split(['[', ']']).filter(|s| !s.is_empty()) {
            at = at.get(index.parse::<usize>().ok()?)?;
        }
    }
    Some(at)
}

/// Bad input: a malformed file, or a value a field or flag cannot take.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
#[error("{location}: {message}")]
pub struct InputError {
    /// `path:line:column`, the path alone, or the flag.
    pub location: String,
    /// The file, if the input was one.
    pub path: Option<PathBuf>,
    /// 1-based line of the offending text; 0 when unknown.
    pub line: usize,
    /// 1-based column (in characters) of the offending text; 0 when unknown.
    pub column: usize,
    /// What is wrong and what was expected.
    pub message: String,
    /// The text the error is in and the byte range of the offending part (boxed: errors
    /// stay small to return).
    pub snippet: Option<Box<(Arc<str>, Range<usize>)>>,
    /// For a file that could not be opened or read, why, as the system said (not found,
    /// permission denied), so front ends can raise their own kind of error (Python's
    /// `FileNotFoundError`).
    pub io: Option<std::io::ErrorKind>,
    /// Whether it refuses legal input that asks for more than a limit or the memory or time
    /// budget allows ([`Error::is_limit`]), rather than malformed input.
    pub limit: bool,
}

impl InputError {
    /// An error about a whole file, a flag or a value, without a position.
    pub fn new(location: impl Into<String>, message: impl ToString) -> Self {
        InputError {
            location: location.into(),
            path: None,
            line: 0,
            column: 0,
            message: message.to_string(),
            snippet: None,
            io: None,
            limit: false,
        }
    }

    /// This error, marked as a limit's refusal ([`InputError::limit`]).
    pub fn over_limit(mut self) -> Self {
        self.limit = true;
        self
    }

    /// An error about a whole file, from a library error and its causes.
    pub fn file_error(path: &Path, e: &dyn std::error::Error) -> Self {
        InputError::file(path, chain(e))
    }

    /// An error about a whole file.
    pub fn file(path: &Path, message: impl ToString) -> Self {
        InputError {
            path: Some(path.to_owned()),
            ..InputError::new(path.display().to_string(), message)
        }
    }

    /// An error at 1-based `line` and `column` of `text`, read from `path`. Parsers such as
    /// serde_json report the position just past the offending token; the error is moved back
    /// to the token's start and spans it. Line 0 means the position is unknown.
    pub fn at(path: &Path, text: &str, line: usize, column: usize, message: String) -> Self {
        if line == 0 {
            return InputError::file(path, message);
        }
        let mut end = offset_of(text, line, column);
        let mut start = token_start(text, end);
        // serde_json reports a bad value in an object's last field at the closing bracket
        // after it (it looked ahead for more fields): point at the value instead. A missing
        // field belongs to the whole object, so it stays at the bracket.
        let closing = text[end..].starts_with(['}', ']']);
        if start == end && closing && !message.starts_with("missing field") {
            end = text[..end].trim_end().len();
            start = token_start(text, end);
        }
        Self::spanned(path, text, start..end, message)
    }

    /// An error over a byte range of `text`, read from `path`.
    pub fn spanned(path: &Path, text: &str, range: Range<usize>, message: String) -> Self {
        let start = text.floor_char_boundary(range.start.min(text.len()));
        let end = text.floor_char_boundary(range.end.clamp(start, text.len()));
        let (line, column) = line_column(text, start);
        InputError {
            location: format!("{}:{line}:{column}", path.display()),
            path: Some(path.to_owned()),
            line,
            column,
            message,
            snippet: Some(Box::new((Arc::from(text), start..end))),
            io: None,
            limit: false,
        }
    }

    /// A genome-file error found in `text`, read from `path`.
    pub fn genome(path: &Path, text: &str, e: GenomeError) -> Self {
        InputError::at(path, text, e.line, e.column, e.message)
    }

    /// A TOML error found in `text`, read from `path`.
    pub fn toml(path: &Path, text: &str, e: &toml::de::Error) -> Self {
        let message = e.message().to_owned();
        match e.span() {
            Some(span) => InputError::spanned(path, text, span, message),
            None => InputError::file(path, message),
        }
    }

    /// A JSON error found in `text`, read from `path`.
    pub fn json(path: &Path, text: &str, e: &serde_json::Error) -> Self {
        InputError::genome(path, text, GenomeError::from_json(e))
    }
}

/// Why something Sylva was asked to do failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Bad input: the user's to fix.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A file or folder could not be read, written or made.
    #[error("{action} {}", path.display())]
    Io {
        /// `"reading"`, `"writing"` or `"creating"`.
        action: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A genome could not grow.
    #[error("growing the {model} genome")]
    Develop {
        /// The model.
        model: &'static str,
        /// Why.
        #[source]
        source: DevelopError,
    },
    /// A plant could not be dressed with leaves and bark (a part out of range).
    #[error("dressing the plant")]
    Dress(#[from] sylva_core::PlantError),
    /// A plant could not be meshed (too many triangles, bad options).
    #[error("meshing")]
    Mesh(#[from] sylva_mesh::mesher::MeshError),
    /// A scene could not be written.
    #[error(transparent)]
    Export(#[from] sylva_gltf::export::ExportError),
    /// A picture could not be drawn or written.
    #[error("drawing a picture")]
    Render(#[from] sylva_render::RenderError),
    /// Work that would not fit in the memory budget (`--max-memory`).
    #[error("not enough memory")]
    Budget(#[from] sylva_core::budget::OverBudget),
    /// A plot could not be drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// The worker threads could not start.
    #[error("starting the worker threads")]
    Threads(#[from] sylva_core::par::ThreadPoolBuildError),
    /// Work was cut short by its [`Stop`](sylva_core::par::Stop) (a front end's Ctrl-C).
    #[error(transparent)]
    Stopped(#[from] sylva_core::par::Stopped),
    /// A run's own fitness function (a front end's code,
    /// [`PlantScorer`](crate::evolution::PlantScorer)) failed; its error is kept whole.
    #[error("scoring plants with the run's own fitness function")]
    Scorer(#[source] crate::evolution::ScorerError),
}

impl Error {
    /// Bad input, the user's to fix (exit code 2 on the command line), rather than a
    /// failure of Sylva or the machine.
    pub fn is_input(&self) -> bool {
        matches!(self, Error::Input(_))
    }

    /// A refusal of legal input that asks for more than a limit or the memory or time budget
    /// allows (a plant, mesh or file too large, growth too long): the user's to change, like
    /// bad input.
    pub fn is_limit(&self) -> bool {
        use sylva_gltf::export::ExportError;
        use sylva_mesh::mesher::MeshError;
        // `Export` is transparent: its source is the export error's source, not itself.
        if matches!(
            self,
            Error::Export(ExportError::TooLarge { .. })
                | Error::Input(InputError { limit: true, .. })
        ) {
            return true;
        }
        let mut cause: Option<&(dyn std::error::Error + 'static)> = Some(self);
        while let Some(e) = cause {
            let limit = e.is::<sylva_core::budget::OverBudget>()
                || e.is::<sylva_core::budget::OverTime>()
                || matches!(e.downcast_ref(), Some(DevelopError::TooLarge { .. }))
                || matches!(
                    e.downcast_ref(),
                    Some(MeshError::TooManyTriangles { .. } | MeshError::TooManyVertices { .. })
                )
                || matches!(e.downcast_ref(), Some(ExportError::TooLarge { .. }))
                || matches!(
                    e.downcast_ref(),
                    Some(sylva_model::gardens::GardenError::TooManyPlants(_))
                );
            if limit {
                return true;
            }
            cause = e.source();
        }
        false
    }

    /// This error as bad input in `path` when it is a limit's refusal ([`Error::is_limit`]),
    /// so it names the file; otherwise unchanged.
    pub fn in_file(self, path: &Path) -> Error {
        if self.is_limit() {
            Error::Input(InputError::file_error(path, &self).over_limit())
        } else {
            self
        }
    }
}

/// An error and its causes, joined by ": " (as `anyhow`'s `{:#}` prints them).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
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

/// Why a plot could not be drawn ([`crate::report::fitness_svg`]).
#[derive(Debug, thiserror::Error)]
#[error("could not draw the fitness plot: {0}")]
pub struct PlotError(pub(crate) String);
