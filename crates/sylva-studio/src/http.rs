//! The HTTP plumbing: typed JSON bodies with limits, the access token, and the page's files.

use std::path::{Component, Path, PathBuf};

use axum::body::Body as AxumBody;
use axum::extract::{FromRequest, Request, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, Uri, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use rust_embed::RustEmbed;
use serde::de::DeserializeOwned;

use crate::Studio;
use crate::error::ApiError;

/// The largest request body, 1 MiB: genome files are a few kilobytes.
pub const MAX_BODY: usize = 1 << 20;

/// A JSON request body of type `T`: at most [`MAX_BODY`] bytes, unknown fields refused, and
/// every error naming the field (`parents[1].dominance`).
pub struct Body<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequest<S> for Body<T> {
    type Rejection = ApiError;

    async fn from_request(req: Request, _: &S) -> Result<Self, ApiError> {
        let bytes = axum::body::to_bytes(req.into_body(), MAX_BODY)
            .await
            .map_err(|_| {
                ApiError::new(
                    StatusCode::PAYLOAD_TOO_LARGE,
                    "",
                    format!("the request body is larger than {MAX_BODY} bytes"),
                )
            })?;
        parse_json(&bytes).map(Body)
    }
}

/// Parses a JSON request body (empty means `{}`).
pub fn parse_json<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, ApiError> {
    let bytes: &[u8] = if bytes.iter().all(u8::is_ascii_whitespace) {
        b"{}"
    } else {
        bytes
    };
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = e.path().to_string();
        let field = if field == "." || field == "?" {
            String::new()
        } else {
            field
        };
        ApiError::bad(field, e.inner())
    })?;
    de.end()
        .map_err(|e| ApiError::bad("", format!("after the JSON value: {e}")))?;
    Ok(value)
}

/// The access token check, for a studio bound beyond loopback. A page opened with
/// `?token=T` gets it as a cookie, so that its scripts and models carry it.
pub async fn require_token(State(studio): State<Studio>, req: Request, next: Next) -> Response {
    let Some(token) = studio.token.as_deref() else {
        return next.run(req).await;
    };
    let from_query = query_token(req.uri()).is_some_and(|t| same(&t, token));
    let ok = from_query || header_token(req.headers(), token);
    if !ok {
        return ApiError::new(
            StatusCode::UNAUTHORIZED,
            "token",
            "this studio needs its access token: open the address it printed at start \
             (with ?token=...), or send `Authorization: Bearer TOKEN`",
        )
        .into_response();
    }
    let mut response = next.run(req).await;
    if from_query
        && let Ok(cookie) = HeaderValue::from_str(&format!(
            "sylva_token={token}; Path=/; HttpOnly; SameSite=Strict"
        ))
    {
        response.headers_mut().append(header::SET_COOKIE, cookie);
    }
    response
}

/// Makes every 4xx the API answers a JSON error, including the plain-text rejections of
/// axum's own extractors (a path id that is not a number, a bad query string).
pub async fn json_errors(req: Request, next: Next) -> Response {
    let response = next.run(req).await;
    let status = response.status();
    let is_json = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(b"application/json"));
    if !status.is_client_error() || is_json {
        return response;
    }
    let text = axum::body::to_bytes(response.into_body(), 64 * 1024)
        .await
        .map(|b| String::from_utf8_lossy(&b).into_owned())
        .unwrap_or_default();
    let (field, error) = match text.split_once(": ") {
        // axum's query rejections name the field this way.
        Some((_, rest)) if text.starts_with("Failed to deserialize query string") => {
            let field = rest.split(':').next().unwrap_or("").trim().to_owned();
            (field, text.clone())
        }
        _ => (String::new(), text),
    };
    let error = if error.is_empty() {
        status
            .canonical_reason()
            .unwrap_or("bad request")
            .to_owned()
    } else {
        error
    };
    ApiError::new(status, field, error).into_response()
}

fn query_token(uri: &Uri) -> Option<String> {
    uri.query()?
        .split('&')
        .find_map(|pair| pair.strip_prefix("token="))
        .map(str::to_owned)
}

fn header_token(headers: &HeaderMap, token: &str) -> bool {
    let bearer = headers
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.strip_prefix("Bearer "))
        .is_some_and(|t| same(t.trim(), token));
    let cookie = headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(|kv| kv.trim().strip_prefix("sylva_token="))
        .any(|t| same(t, token));
    bearer || cookie
}

/// Compares in time independent of where the strings differ.
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

/// The page's own files, built into the binary (read from the folder in debug builds).
#[derive(RustEmbed)]
#[folder = "web/"]
#[include = "index.html"]
#[include = "app/*"]
struct Page;

fn content_type(path: &str) -> &'static str {
    match path.rsplit('.').next() {
        Some("html") => "text/html; charset=utf-8",
        Some("js" | "mjs") => "text/javascript; charset=utf-8",
        Some("css") => "text/css; charset=utf-8",
        Some("json") => "application/json",
        Some("png") => "image/png",
        Some("svg") => "image/svg+xml",
        Some("wasm") => "application/wasm",
        Some("glb") => "model/gltf-binary",
        _ => "application/octet-stream",
    }
}

fn file_response(path: &str, bytes: Vec<u8>) -> Response {
    (
        [
            (header::CONTENT_TYPE, content_type(path)),
            (header::CACHE_CONTROL, "no-cache"),
        ],
        bytes,
    )
        .into_response()
}

/// `GET /` and `GET /app/...`: the page.
pub async fn page(uri: Uri) -> Response {
    let path = uri.path().trim_start_matches('/');
    let path = if path.is_empty() { "index.html" } else { path };
    match Page::get(path) {
        Some(file) => file_response(path, file.data.into_owned()),
        None => ApiError::not_found(format!("`/{path}`")).into_response(),
    }
}

/// `GET /vendor/three/...`: three.js from the installed npm folder.
pub async fn vendor(State(studio): State<Studio>, uri: Uri) -> Response {
    let rest = uri.path().trim_start_matches("/vendor/three/");
    match vendor_path(&studio.three, rest) {
        Some(path) => match tokio::fs::read(&path).await {
            Ok(bytes) => file_response(rest, bytes),
            Err(_) => ApiError::not_found(format!("`/vendor/three/{rest}`")).into_response(),
        },
        None => ApiError::not_found(format!("`/vendor/three/{rest}`")).into_response(),
    }
}

/// A file of three.js's `build/` or `examples/jsm/` folders; nothing else (no `..`).
fn vendor_path(root: &Path, rest: &str) -> Option<PathBuf> {
    let relative = Path::new(rest);
    let plain = relative
        .components()
        .all(|c| matches!(c, Component::Normal(_)));
    let allowed = rest.starts_with("build/") || rest.starts_with("examples/jsm/");
    (plain && allowed && rest.ends_with(".js")).then(|| root.join(relative))
}

/// Where three.js is installed by default: the studio crate's `web/node_modules/three`.
pub fn default_three() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("web/node_modules/three")
}

/// An empty 204.
pub fn no_content() -> Response {
    (StatusCode::NO_CONTENT, AxumBody::empty()).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vendor_paths_stay_in_three() {
        let root = Path::new("/t");
        assert!(vendor_path(root, "build/three.module.js").is_some());
        assert!(vendor_path(root, "examples/jsm/controls/OrbitControls.js").is_some());
        assert!(vendor_path(root, "build/../../../etc/passwd.js").is_none());
        assert!(vendor_path(root, "package.json").is_none());
        assert!(vendor_path(root, "/etc/x.js").is_none());
    }

    #[test]
    fn tokens_compare_exactly() {
        assert!(same("abc", "abc"));
        assert!(!same("abc", "abd"));
        assert!(!same("abc", "abcd"));
    }

    #[test]
    fn bodies_name_the_field() {
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct P {
            parents: Vec<Q>,
        }
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct Q {
            dominance: f64,
        }
        let e =
            parse_json::<P>(br#"{"parents": [{"dominance": 1}, {"dominance": "x"}]}"#).unwrap_err();
        assert_eq!(e.field, "parents[1].dominance");
        let e = parse_json::<P>(br#"{"parents": [], "x": 1}"#).unwrap_err();
        assert!(e.error.contains("unknown field"), "{e}");
        let e = parse_json::<P>(br#"{"parents": []} []"#).unwrap_err();
        assert!(e.error.contains("after"), "{e}");
    }
}
