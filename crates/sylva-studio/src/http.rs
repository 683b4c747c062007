//! The HTTP plumbing: routes with a 405 that says what a path takes, typed JSON bodies with
//! limits, JSON errors, and the page's files.

use std::collections::HashMap;
use std::sync::Arc;

use axum::Router;
use axum::body::Body as AxumBody;
use axum::extract::{FromRequest, MatchedPath, Request};
use axum::handler::Handler;
use axum::http::{HeaderValue, Method, StatusCode, Uri, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::routing::MethodRouter;
use serde::de::DeserializeOwned;

use crate::Studio;
use crate::error::ApiError;

/// An endpoint: a method, a path and its handler.
pub struct Route {
    pub(crate) method: Method,
    pub(crate) path: &'static str,
    handler: MethodRouter<Studio>,
}

impl Route {
    /// `GET {path}` (and HEAD).
    pub fn get<H: Handler<T, Studio>, T: 'static>(path: &'static str, handler: H) -> Route {
        Route {
            method: Method::GET,
            path,
            handler: axum::routing::get(handler),
        }
    }

    /// `POST {path}`.
    pub fn post<H: Handler<T, Studio>, T: 'static>(path: &'static str, handler: H) -> Route {
        Route {
            method: Method::POST,
            path,
            handler: axum::routing::post(handler),
        }
    }
}

/// The methods each route's path takes, by the path as routed (`/api/sessions/{id}/cross`),
/// for the `Allow` of a 405: axum's own 405 leaves `Allow` out for routes inside a router.
#[derive(Clone, Default)]
pub struct Takes(Arc<HashMap<String, Vec<Method>>>);

impl Takes {
    /// What the paths of `routes` take, each path under its prefix (`/api`).
    pub fn of(routes: &[(&str, &[Route])]) -> Takes {
        let mut takes: HashMap<String, Vec<Method>> = HashMap::new();
        for (prefix, routes) in routes {
            for route in *routes {
                let methods = takes.entry(format!("{prefix}{}", route.path)).or_default();
                methods.push(route.method.clone());
                if route.method == Method::GET {
                    methods.push(Method::HEAD);
                }
            }
        }
        Takes(Arc::new(takes))
    }

    /// The 405 for `method` on a routed path (`None`: a path no route has, taking nothing).
    fn not_allowed(&self, method: &Method, path: &str, routed: Option<&str>) -> Response {
        let taken: Vec<&str> = routed
            .and_then(|p| self.0.get(p))
            .map(|methods| methods.iter().map(Method::as_str).collect())
            .unwrap_or_default();
        let error = if taken.is_empty() {
            format!(
                "`{method}` is not a method of `{path}`, a path the studio does not have; it \
                 takes GET, HEAD and POST on the paths docs/studio.md lists"
            )
        } else {
            format!(
                "`{method}` is not a method of `{path}`; it takes {}",
                taken.join(", ")
            )
        };
        let mut response = ApiError::new(StatusCode::METHOD_NOT_ALLOWED, "", error).into_response();
        if let Ok(allow) = HeaderValue::from_str(&taken.join(",")) {
            response.headers_mut().insert(header::ALLOW, allow);
        }
        response
    }
}

/// A router of `routes`, a path's methods merged.
pub fn routed(routes: Vec<Route>) -> Router<Studio> {
    routes
        .into_iter()
        .fold(Router::new(), |router, r| router.route(r.path, r.handler))
}

/// `router` answering a method a path does not take with a 405 and the `Allow` of `takes`.
pub fn with_405(router: Router<Studio>, takes: Takes) -> Router<Studio> {
    router.method_not_allowed_fallback(
        move |method: Method, routed: Option<MatchedPath>, uri: Uri| {
            let takes = takes.clone();
            async move {
                takes.not_allowed(
                    &method,
                    uri.path(),
                    routed.as_ref().map(MatchedPath::as_str),
                )
            }
        },
    )
}

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
    // A key given twice would silently take its later value: refused, naming it. A body
    // that is not JSON at all is left to the typed read below, which says where.
    if let Err(e) = serde_json::from_slice::<Unique>(bytes)
        && let Some(key) = e.to_string().strip_prefix(TWICE)
    {
        let (path, _) = key.split_once(" at line").unwrap_or((key, ""));
        return Err(ApiError::bad(
            path,
            format!("`{path}` is given twice; expected each key once"),
        ));
    }
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let sent = serde_json::from_slice(bytes).unwrap_or(serde_json::Value::Null);
        body_error(&e, &sent)
    })?;
    de.end()
        .map_err(|e| ApiError::bad("", format!("after the JSON value: {e}")))?;
    Ok(value)
}

/// The start of the error [`Unique`] gives for a key given twice, before the key's path.
const TWICE: &str = "duplicate key ";

/// Any JSON value whose objects name each key once, read for that check alone.
struct Unique;

impl<'de> serde::Deserialize<'de> for Unique {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueAt(String::new()))
    }
}

/// The check at a JSON path (`parents[1]`).
struct UniqueAt(String);

impl<'de> serde::de::DeserializeSeed<'de> for UniqueAt {
    type Value = Unique;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Unique, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for UniqueAt {
    type Value = Unique;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_str<E>(self, _: &str) -> Result<Unique, E> {
        Ok(Unique)
    }
    fn visit_unit<E>(self) -> Result<Unique, E> {
        Ok(Unique)
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Unique, A::Error> {
        let mut i = 0;
        while seq
            .next_element_seed(UniqueAt(format!("{}[{i}]", self.0)))?
            .is_some()
        {
            i += 1;
        }
        Ok(Unique)
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Unique, A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            let path = join(&self.0, &key);
            if !seen.insert(key) {
                return Err(serde::de::Error::custom(format!("{TWICE}{path}")));
            }
            map.next_value_seed(UniqueAt(path))?;
        }
        Ok(Unique)
    }
}

/// Reads a part of a request already parsed as JSON, naming fields under `at` (a JSON path
/// of the request, or "" for the whole of it).
pub fn from_value<T: DeserializeOwned>(value: serde_json::Value, at: &str) -> Result<T, ApiError> {
    let sent = value.clone();
    serde_path_to_error::deserialize(value).map_err(|e| {
        let mut error = body_error(&e, &sent);
        error.field = join(at, &error.field);
        error
    })
}

/// A serde error as a 400 naming the field by its JSON path in the request as sent (`sent`):
/// the path where it was found; for a missing field, that field; for an unknown field or
/// variant that is a key of the object there, that key.
fn body_error<E: std::fmt::Display>(
    e: &serde_path_to_error::Error<E>,
    sent: &serde_json::Value,
) -> ApiError {
    let path = e.path().to_string();
    let path = if path == "." || path == "?" {
        ""
    } else {
        &path
    };
    let message = e.inner().to_string();
    let quoted = |prefix: &str| {
        message
            .strip_prefix(prefix)
            .and_then(|rest| rest.split('`').next())
    };
    let field = if let Some(name) = quoted("missing field `") {
        join(path, name)
    } else if let Some(name) = quoted("unknown field `").or_else(|| quoted("unknown variant `"))
        && at_path(sent, path).is_some_and(|v| v.get(name).is_some())
    {
        join(path, name)
    } else {
        path.to_owned()
    };
    let message = in_page_words(&field, &message);
    ApiError::bad(field, message)
}

/// Labels of the page's controls by the request field they fill (its last name), so that a
/// message names the control the person typed in.
const LABELS: &[(&str, &str)] = &[
    ("children", "Children"),
    ("seed", "Seed"),
    ("depth", "Depth"),
    ("level", "Level"),
    ("dominance", "Dominance"),
    ("population", "Population"),
    ("generations", "Generations"),
    ("steps", "Steps"),
    ("spacing", "Spacing"),
    ("azimuth", "Azimuth"),
    ("elevation", "Elevation"),
    ("model", "Model"),
    ("count", "Count"),
    ("genomes", "Genome files"),
];

/// How a message names `field` (a JSON path): the page's label of its control (`Children`;
/// a parent's `Dominance (parent 2)`), or the path itself.
fn label(field: &str) -> String {
    let last = field.rsplit('.').next().unwrap_or(field);
    let name = last.split('[').next().unwrap_or(last);
    let Some((_, label)) = LABELS.iter().find(|(n, _)| *n == name) else {
        return format!("`{field}`");
    };
    // `parents[1].dominance`: the parent's place, counted from 1 as the page counts.
    let parent = field
        .strip_prefix("parents[")
        .and_then(|rest| rest.split(']').next())
        .and_then(|i| i.parse::<usize>().ok());
    match parent {
        Some(i) if name != "parents" => format!("{label} (parent {})", i + 1),
        _ => (*label).to_owned(),
    }
}

/// A serde message about `field` in the page's words: the control's label, what it takes
/// and what it got (`Children: expected a whole number from 0 to 4294967295, got 2.5`),
/// never serde's type names (`u32`) nor its place in the JSON text (`at line 1 column 100`,
/// which the person never saw).
pub fn in_page_words(field: &str, message: &str) -> String {
    let message = message
        .rfind(" at line ")
        .map_or(message, |i| &message[..i]);
    let said = message
        .strip_prefix("invalid type: ")
        .or_else(|| message.strip_prefix("invalid value: "))
        .and_then(|rest| rest.rsplit_once(", expected "))
        .map(|(got, expected)| {
            format!(
                "expected {}, got {}",
                expected_words(expected),
                got_words(got)
            )
        })
        // A choice: `unknown variant `abc`, expected one of `a`, `b``.
        .or_else(|| {
            let (got, expected) = message
                .strip_prefix("unknown variant ")?
                .split_once(", expected ")?;
            Some(format!(
                "expected {}, got {}",
                expected.replace('`', ""),
                got.trim_matches('`')
            ))
        })
        .unwrap_or_else(|| match message {
            "number out of range" => "expected a number, got one too large to read".to_owned(),
            other => other.to_owned(),
        });
    if field.is_empty() {
        said
    } else {
        format!("{}: {said}", label(field))
    }
}

/// What serde says a field expects (`u32`, `a string`), in the page's words.
fn expected_words(expected: &str) -> String {
    let most = match expected {
        "u8" => Some(u64::from(u8::MAX)),
        "u16" => Some(u64::from(u16::MAX)),
        "u32" => Some(u64::from(u32::MAX)),
        "u64" | "usize" => Some(u64::MAX),
        _ => None,
    };
    if let Some(most) = most {
        return format!("a whole number from 0 to {most}");
    }
    match expected {
        "i8" | "i16" | "i32" | "i64" | "isize" => "a whole number",
        "f32" | "f64" => "a number",
        "a string" => "text",
        "a boolean" => "true or false",
        "a sequence" => "a list",
        "a map" => "a group of settings",
        other => other,
    }
    .to_owned()
}

/// What serde says a request sent (``floating point `2.5` ``, `string "abc"`), in the
/// page's words: the value itself (long text cut short) or what kind of thing it was.
fn got_words(got: &str) -> String {
    let quoted = ["floating point `", "integer `", "boolean `"]
        .iter()
        .find_map(|p| got.strip_prefix(p))
        .map(|v| v.trim_end_matches('`'));
    if let Some(value) = quoted {
        return value.to_owned();
    }
    if let Some(text) = got.strip_prefix("string ") {
        return match text.char_indices().nth(40) {
            Some((i, _)) => format!("{}…\"", &text[..i]),
            None => text.to_owned(),
        };
    }
    match got {
        "null" => "nothing (null)",
        "map" => "a group of settings",
        "sequence" => "a list",
        other => other,
    }
    .to_owned()
}

/// The value at a JSON path (`a.b[1].c`) of `value`.
fn at_path<'v>(value: &'v serde_json::Value, path: &str) -> Option<&'v serde_json::Value> {
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

/// The JSON path (under `at`) of the first `null` in `value`: configs have no null, so a
/// request's null would otherwise fail without a field when its TOML is written.
pub fn first_null(value: &serde_json::Value, at: &str) -> Option<String> {
    match value {
        serde_json::Value::Null => Some(at.to_owned()),
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, v)| first_null(v, &format!("{at}[{i}]"))),
        serde_json::Value::Object(map) => map.iter().find_map(|(k, v)| first_null(v, &join(at, k))),
        _ => None,
    }
}

/// `name` under the JSON path `path` (`a.b` and `c` give `a.b.c`).
pub fn join(path: &str, name: &str) -> String {
    match (path.is_empty(), name.is_empty()) {
        (true, _) => name.to_owned(),
        (false, true) => path.to_owned(),
        (false, false) if name.starts_with('[') => format!("{path}{name}"),
        (false, false) => format!("{path}.{name}"),
    }
}

/// Makes every 4xx the API answers a JSON error, including the plain-text rejections of
/// axum's own extractors (a path id that is not a number, a bad query string). A method no
/// route takes (`TRACE`, `DELETE`) is a 405 on a path the studio does not have too, not a 404.
pub async fn json_errors(req: Request, next: Next) -> Response {
    let method = req.method().clone();
    let path = req.uri().path().to_owned();
    let response = next.run(req).await;
    let status = response.status();
    if status == StatusCode::NOT_FOUND
        && ![Method::GET, Method::HEAD, Method::POST].contains(&method)
    {
        return Takes::default().not_allowed(&method, &path, None);
    }
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

// The page's files and three.js's, built in by build.rs: `PAGE`, `THREE`, `THREE_VERSION`.
include!(concat!(env!("OUT_DIR"), "/assets.rs"));

/// A built-in file by its path.
fn built_in(files: &'static [(&'static str, &'static [u8])], path: &str) -> Option<&'static [u8]> {
    files
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, bytes)| *bytes)
}

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

fn file_response(path: &str, bytes: impl Into<AxumBody>) -> Response {
    (
        [
            (header::CONTENT_TYPE, content_type(path)),
            (header::CACHE_CONTROL, "no-cache"),
        ],
        bytes.into(),
    )
        .into_response()
}

/// A folder to serve the page's own files from instead of the built-in copies
/// (`SYLVA_STUDIO_WEB`, for working on the page: edit, reload, no rebuild).
static PAGE_FOLDER: std::sync::LazyLock<Option<std::path::PathBuf>> =
    std::sync::LazyLock::new(|| std::env::var_os("SYLVA_STUDIO_WEB").map(Into::into));

/// `GET /` and `GET /app/...`: the page.
pub async fn page(uri: Uri) -> Response {
    let path = uri.path().trim_start_matches('/');
    let path = if path.is_empty() { "index.html" } else { path };
    if let Some(folder) = PAGE_FOLDER.as_ref() {
        let plain = std::path::Path::new(path)
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)));
        let page_file = path == "index.html" || path.starts_with("app/");
        if plain
            && page_file
            && let Ok(bytes) = std::fs::read(folder.join(path))
        {
            return file_response(path, bytes);
        }
        return ApiError::not_found(format!("`/{path}`")).into_response();
    }
    match built_in(PAGE, path) {
        Some(bytes) => file_response(path, bytes.to_vec()),
        None => ApiError::not_found(format!("`/{path}`")).into_response(),
    }
}

/// `GET /vendor/three/...`: the files of three.js the page imports, and its licence.
pub async fn vendor(uri: Uri) -> Response {
    let rest = uri.path().trim_start_matches("/vendor/three/");
    match built_in(THREE, rest) {
        Some(bytes) => file_response(rest, bytes),
        None => ApiError::not_found(format!("`/vendor/three/{rest}`")).into_response(),
    }
}

/// An empty 204.
pub fn no_content() -> Response {
    (StatusCode::NO_CONTENT, AxumBody::empty()).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_and_three_are_built_in() {
        assert!(built_in(PAGE, "index.html").is_some());
        assert!(built_in(PAGE, "app/main.js").is_some());
        assert!(built_in(PAGE, "../Cargo.toml").is_none());
        if !THREE.is_empty() {
            assert!(built_in(THREE, "build/three.module.js").is_some());
            assert!(built_in(THREE, "build/three.core.js").is_some());
            assert!(built_in(THREE, "examples/jsm/loaders/GLTFLoader.js").is_some());
            assert!(built_in(THREE, "LICENSE").is_some());
            assert!(built_in(THREE, "build/../../../etc/passwd").is_none());
            assert!(!THREE_VERSION.is_empty());
        }
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
        // A key given twice is refused, named by its path, wherever it stands.
        let e = parse_json::<P>(br#"{"parents": [], "parents": [{"dominance": 1}]}"#).unwrap_err();
        assert_eq!(
            (e.field.as_str(), e.status),
            ("parents", StatusCode::BAD_REQUEST)
        );
        assert!(e.error.contains("given twice"), "{e}");
        let twice = br#"{"parents": [{"dominance": 1}, {"dominance": 2, "dominance": 3}]}"#;
        let e = parse_json::<P>(twice).unwrap_err();
        assert_eq!(e.field, "parents[1].dominance");
        // Not JSON at all: the typed read says where, as before.
        let e = parse_json::<P>(b"\x89PNG").unwrap_err();
        assert!(!e.error.contains("twice"), "{e}");
    }

    #[test]
    fn messages_name_the_control_and_what_it_takes_in_the_page_s_words() {
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct Cross {
            parents: Vec<Parent>,
            children: Option<u32>,
            seed: Option<u64>,
        }
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct Parent {
            plant: i64,
            dominance: f64,
        }
        let parents = r#""parents": [{"plant": 1, "dominance": 1}, {"plant": 2, "dominance": 1}]"#;
        let error = |rest: &str| {
            let body = format!("{{{parents}, {rest}}}");
            parse_json::<Cross>(body.as_bytes()).unwrap_err()
        };
        let cases = [
            (
                r#""children": 2.5"#,
                "children",
                "Children: expected a whole number from 0 to 4294967295, got 2.5",
            ),
            (
                r#""seed": 99999999999999999999999"#,
                "seed",
                "Seed: expected a whole number from 0 to 18446744073709551615, got 1e+23",
            ),
            (
                r#""seed": -1"#,
                "seed",
                "Seed: expected a whole number from 0 to 18446744073709551615, got -1",
            ),
            (
                r#""children": "two""#,
                "children",
                "Children: expected a whole number from 0 to 4294967295, got \"two\"",
            ),
        ];
        for (rest, field, said) in cases {
            let e = error(rest);
            assert_eq!(
                (e.field.as_str(), e.error.as_str()),
                (field, said),
                "{rest}"
            );
        }
        // A genome's field by its path, and a choice's options without serde's quotes.
        assert_eq!(
            in_page_words(
                "branches[0].segment_pattern",
                "unknown variant `abc`, expected one of `straight`, `triangular` at line 1 \
                 column 40"
            ),
            "`branches[0].segment_pattern`: expected one of straight, triangular, got abc"
        );
        // A parent's dominance is named by the parent's place, counted from 1.
        let e = parse_json::<Cross>(
            br#"{"parents": [{"plant": 1, "dominance": 1}, {"plant": 2, "dominance": "x"}]}"#,
        )
        .unwrap_err();
        assert_eq!(e.field, "parents[1].dominance");
        assert_eq!(
            e.error,
            "Dominance (parent 2): expected a number, got \"x\""
        );
        let e =
            parse_json::<Cross>(br#"{"parents": [{"plant": 1, "dominance": 1e400}]}"#).unwrap_err();
        assert!(
            e.error
                .starts_with("Dominance (parent 1): expected a number"),
            "{e}"
        );
        // No serde type names nor places in a JSON text the person never saw.
        for word in ["u32", "u64", "f64", "invalid type", "line 1", "column"] {
            for rest in [r#""children": 2.5"#, r#""seed": 1e30"#] {
                assert!(!error(rest).error.contains(word), "{rest}: {}", error(rest));
            }
        }
    }
}
