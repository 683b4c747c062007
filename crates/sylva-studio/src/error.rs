//! API errors: a status, what was wrong, and which field. Answered as
//! `{"error": "...", "field": "..."}`; 5xx only for bugs and a failing disk.

use axum::Json;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::Serialize;

use crate::archive::ArchiveError;

/// An error answer.
#[derive(Debug, Clone, PartialEq)]
pub struct ApiError {
    /// The status.
    pub status: StatusCode,
    /// What was wrong and what was expected.
    pub error: String,
    /// The field, when the error is about one (`parents[1].dominance`).
    pub field: String,
}

#[derive(Serialize)]
struct Body<'a> {
    error: &'a str,
    field: &'a str,
}

impl ApiError {
    /// A 400 about `field`.
    pub fn bad(field: impl Into<String>, error: impl ToString) -> ApiError {
        ApiError::new(StatusCode::BAD_REQUEST, field, error)
    }

    /// A 422: well-formed, but not a genome or config Sylva can use.
    pub fn unprocessable(field: impl Into<String>, error: impl ToString) -> ApiError {
        ApiError::new(StatusCode::UNPROCESSABLE_ENTITY, field, error)
    }

    /// A 404 for a missing thing.
    pub fn not_found(what: impl ToString) -> ApiError {
        ApiError::new(
            StatusCode::NOT_FOUND,
            "",
            format!("{} not found", what.to_string()),
        )
    }

    /// A 409: the request does not fit the session's state.
    pub fn conflict(error: impl ToString) -> ApiError {
        ApiError::new(StatusCode::CONFLICT, "", error)
    }

    /// Any status.
    pub fn new(status: StatusCode, field: impl Into<String>, error: impl ToString) -> ApiError {
        ApiError {
            status,
            error: error.to_string(),
            field: field.into(),
        }
    }

    /// A failure of Sylva or the machine (a bug, a full disk).
    pub fn internal(error: impl ToString) -> ApiError {
        ApiError::new(StatusCode::INTERNAL_SERVER_ERROR, "", error)
    }

    /// An error of the library layer: bad input and limits are the request's (422, naming
    /// `field`), anything else is the server's.
    pub fn library(field: &str, e: sylva::Error) -> ApiError {
        match e {
            sylva::Error::Input(input) => ApiError::unprocessable(field, input_message(&input)),
            e if e.is_limit() => ApiError::unprocessable(field, sylva::error::chain(&e)),
            e => ApiError::internal(sylva::error::chain(&e)),
        }
    }
}

/// An input error's message with its line and column, when it has them.
pub fn input_message(e: &sylva::InputError) -> String {
    if e.line > 0 {
        format!("line {}, column {}: {}", e.line, e.column, e.message)
    } else {
        e.message.clone()
    }
}

impl From<ArchiveError> for ApiError {
    fn from(e: ArchiveError) -> ApiError {
        ApiError::internal(e)
    }
}

impl From<rusqlite::Error> for ApiError {
    fn from(e: rusqlite::Error) -> ApiError {
        ApiError::internal(format!("archive: {e}"))
    }
}

impl From<tokio::task::JoinError> for ApiError {
    fn from(e: tokio::task::JoinError) -> ApiError {
        ApiError::internal(format!("a worker failed: {e}"))
    }
}

impl ApiError {
    /// The answer's body: `{"error": "...", "field": "..."}`.
    pub fn body(&self) -> String {
        serde_json::to_string(&Body {
            error: &self.error,
            field: &self.field,
        })
        .unwrap_or_else(|_| r#"{"error":"","field":""}"#.to_owned())
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let body = Json(Body {
            error: &self.error,
            field: &self.field,
        });
        (self.status, body).into_response()
    }
}

impl std::fmt::Display for ApiError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}: {}", self.status, self.error)
        } else {
            write!(f, "{}: `{}`: {}", self.status, self.field, self.error)
        }
    }
}

impl std::error::Error for ApiError {}
