//! Who may talk to the studio. A studio on loopback is still reachable from every web page
//! the person opens, so every request passes these checks before any handler runs, as
//! Jupyter's and VS Code's servers do (`docs/studio.md`, "Security"):
//!
//! 1. **Host** (DNS rebinding): the `Host` header must name the studio as it is bound: a
//!    loopback name or address, the bound address, an IP address when bound to all
//!    interfaces (a name that resolves to one can be rebound; an address cannot), the
//!    machine's own name then, or a name given with `--allow-host`. Otherwise 403.
//! 2. **Token**: a studio bound beyond loopback needs its access token (401).
//! 3. **Other sites**: a request a browser marks as coming from another site
//!    (`Sec-Fetch-Site: cross-site` or `same-site`, which includes other ports of localhost)
//!    is refused (403), but for opening the page itself; a state-changing request whose
//!    `Origin` is not the studio's own is refused (403).
//! 4. **Content type**: a POST (the one state-changing method the studio takes) must be
//!    `application/json` (415). HTML forms and `no-cors` fetches can only send `text/plain`,
//!    form encodings or nothing, and a JSON body cannot cross sites without a CORS
//!    preflight, which the studio never grants. Other methods go on to the router, which
//!    answers them 405 ([`crate::http::json_errors`]).

use std::net::IpAddr;

use axum::extract::{Request, State};
use axum::http::{HeaderMap, HeaderValue, Method, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use crate::Studio;
use crate::error::ApiError;

/// The names and addresses the studio answers to, and its token. The default answers to
/// loopback names and addresses only, without a token.
#[derive(Clone, Debug, Default)]
pub struct Guard {
    /// Host names allowed besides loopback ones, lower case.
    names: Vec<String>,
    /// The address bound.
    bound: Option<IpAddr>,
    /// The access token, when bound beyond loopback.
    token: Option<String>,
}

impl Guard {
    /// The guard of a studio bound to `host`, with extra `allowed` names and its token.
    pub fn new(host: &str, allowed: &[String], token: Option<String>) -> Guard {
        let bound = parse_ip(host);
        let mut names: Vec<String> = allowed.iter().map(|n| normal_name(n)).collect();
        if bound.is_none() {
            names.push(normal_name(host));
        }
        if bound.is_some_and(|ip| ip.is_unspecified())
            && let Some(me) = machine_name()
        {
            names.push(me);
        }
        names.retain(|n| !n.is_empty());
        Guard {
            names,
            bound,
            token,
        }
    }

    /// The access token, if the studio has one.
    pub fn token(&self) -> Option<&str> {
        self.token.as_deref()
    }

    /// Whether a `Host` header's name (its port aside) is one the studio answers to.
    pub fn host_allowed(&self, host: &str) -> bool {
        let name = host_name(host);
        if let Some(ip) = parse_ip(&name) {
            return ip.is_loopback()
                || Some(ip) == self.bound
                || self.bound.is_some_and(|b| b.is_unspecified());
        }
        name == "localhost" || self.names.contains(&name)
    }

    /// Checks a request's head; the error to answer when it may not go on.
    fn check(&self, method: &Method, path: &str, headers: &HeaderMap) -> Result<(), ApiError> {
        let host = headers
            .get(header::HOST)
            .and_then(|h| h.to_str().ok())
            .unwrap_or("");
        if host.is_empty() {
            return Err(forbidden("the request has no Host header"));
        }
        if !self.host_allowed(host) {
            return Err(forbidden(format!(
                "this studio does not answer to the host name {:?}: open it at the address it \
                 printed, or start it with `--allow-host NAME` (behind a reverse proxy)",
                host_name(host)
            )));
        }
        if let Some(token) = &self.token
            && !has_token(headers, path_query(path), token)
        {
            return Err(ApiError::new(
                StatusCode::UNAUTHORIZED,
                "token",
                "this studio needs its access token: open the address it printed at start \
                 (with ?token=...), or send `Authorization: Bearer TOKEN`",
            ));
        }
        let site = headers
            .get("sec-fetch-site")
            .and_then(|v| v.to_str().ok())
            .unwrap_or("");
        let other_site =
            site.eq_ignore_ascii_case("cross-site") || site.eq_ignore_ascii_case("same-site");
        let opens_page = matches!(*method, Method::GET | Method::HEAD) && page_path(path);
        if other_site && !opens_page {
            return Err(forbidden(
                "a page of another site may not use the studio (Sec-Fetch-Site: cross-site)",
            ));
        }
        if changes_state(method) {
            if let Some(origin) = headers.get(header::ORIGIN)
                && !same_origin(origin, host)
            {
                return Err(forbidden(format!(
                    "a page from {} may not change the studio: only the studio's own page can",
                    String::from_utf8_lossy(origin.as_bytes())
                )));
            }
            // Only POST reaches a handler; other methods are the router's 405, not a 415.
            if *method == Method::POST && !is_json(headers.get(header::CONTENT_TYPE)) {
                return Err(ApiError::new(
                    StatusCode::UNSUPPORTED_MEDIA_TYPE,
                    "",
                    "the request body must be JSON, sent with `Content-Type: application/json`",
                ));
            }
        }
        Ok(())
    }
}

/// The middleware that runs [`Guard`]'s checks on every request. A page opened with
/// `?token=T` gets the token as a cookie, so that its scripts and images carry it.
pub async fn check(State(studio): State<Studio>, req: Request, next: Next) -> Response {
    let guard = &studio.guard;
    let path = req.uri().path_and_query().map_or("/", |p| p.as_str());
    if let Err(e) = guard.check(req.method(), path, req.headers()) {
        return e.into_response();
    }
    // A request line with a whole URL (`GET http://evil.example/ HTTP/1.1`) names its host
    // there too.
    if let Some(authority) = req.uri().authority()
        && !guard.host_allowed(authority.as_str())
    {
        return forbidden(format!(
            "this studio does not answer to the host name {:?}",
            host_name(authority.as_str())
        ))
        .into_response();
    }
    let token_in_query = guard
        .token()
        .is_some_and(|t| query_token(path_query(path)).is_some_and(|q| same(q, t)));
    let token = guard.token().map(str::to_owned);
    let mut response = next.run(req).await;
    if token_in_query
        && let Some(token) = token
        && let Ok(cookie) = HeaderValue::from_str(&format!(
            "sylva_token={token}; Path=/; HttpOnly; SameSite=Strict"
        ))
    {
        response.headers_mut().append(header::SET_COOKIE, cookie);
    }
    response
}

fn forbidden(error: impl ToString) -> ApiError {
    ApiError::new(StatusCode::FORBIDDEN, "", error)
}

/// Methods that may change the studio's state (everything but reading).
fn changes_state(method: &Method) -> bool {
    !matches!(*method, Method::GET | Method::HEAD | Method::OPTIONS)
}

/// The page itself, which a link on another site may open.
fn page_path(path: &str) -> bool {
    let path = path.split('?').next().unwrap_or("");
    path == "/" || path == "/index.html"
}

/// The query of a path (`a=1&b=2`), or "".
fn path_query(path: &str) -> &str {
    path.split_once('?').map_or("", |(_, q)| q)
}

/// Whether a content type is JSON: `application/json`, parameters and case aside.
fn is_json(value: Option<&HeaderValue>) -> bool {
    value
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.split(';').next())
        .is_some_and(|t| t.trim().eq_ignore_ascii_case("application/json"))
}

/// Whether an `Origin` is the studio's own: its host and port are those of the `Host`
/// header (which passed the host check), over http or, behind a proxy, https.
fn same_origin(origin: &HeaderValue, host: &str) -> bool {
    let Ok(origin) = origin.to_str() else {
        return false;
    };
    let lower = origin.to_ascii_lowercase();
    let (authority, default_port) = match lower
        .strip_prefix("http://")
        .map(|a| (a, "80"))
        .or_else(|| lower.strip_prefix("https://").map(|a| (a, "443")))
    {
        Some(found) => found,
        None => return false, // "null" (sandboxed frames, files) and other schemes
    };
    with_port(authority, default_port) == with_port(&host.to_ascii_lowercase(), default_port)
}

/// `name:port`, with the default port filled in.
fn with_port(authority: &str, default_port: &str) -> String {
    let authority = authority.trim_end_matches('/');
    let has_port = match authority.rfind(':') {
        Some(i) => !authority[i..].contains(']'),
        None => false,
    };
    if has_port {
        authority.to_owned()
    } else {
        format!("{authority}:{default_port}")
    }
}

/// The name part of a `Host` header: no port, no brackets, lower case, no final dot.
fn host_name(host: &str) -> String {
    let host = host.trim();
    let name = if let Some(rest) = host.strip_prefix('[') {
        rest.split(']').next().unwrap_or("")
    } else {
        match host.rsplit_once(':') {
            Some((name, port)) if port.bytes().all(|b| b.is_ascii_digit()) => name,
            _ => host,
        }
    };
    normal_name(name)
}

fn normal_name(name: &str) -> String {
    name.trim()
        .trim_matches(['[', ']'])
        .trim_end_matches('.')
        .to_ascii_lowercase()
}

fn parse_ip(name: &str) -> Option<IpAddr> {
    name.trim().trim_matches(['[', ']']).parse().ok()
}

/// The machine's host name, for a studio bound to all interfaces.
pub(crate) fn machine_name() -> Option<String> {
    let name = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .ok()?;
    let name = normal_name(&name);
    (!name.is_empty()).then_some(name)
}

fn query_token(query: &str) -> Option<&str> {
    query
        .split('&')
        .find_map(|pair| pair.strip_prefix("token="))
}

/// Whether a request carries the token: in the query, as a bearer token (the scheme's case
/// does not matter, RFC 7235) or in the page's cookie.
fn has_token(headers: &HeaderMap, query: &str, token: &str) -> bool {
    let in_query = query_token(query).is_some_and(|t| same(t, token));
    let bearer = headers
        .get_all(header::AUTHORIZATION)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .filter_map(|v| {
            let (scheme, credentials) = v.trim().split_once(char::is_whitespace)?;
            scheme
                .eq_ignore_ascii_case("bearer")
                .then(|| credentials.trim())
        })
        .any(|t| same(t, token));
    let cookie = headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(|kv| kv.trim().strip_prefix("sylva_token="))
        .any(|t| same(t, token));
    in_query || bearer || cookie
}

/// Compares in time independent of where the strings differ.
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Headers by name and value.
    type Pairs<'a> = &'a [(&'static str, &'a str)];

    fn headers(pairs: &[(&'static str, &str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.append(
                *k,
                HeaderValue::from_str(v).unwrap_or(HeaderValue::from_static("")),
            );
        }
        h
    }

    fn status(guard: &Guard, method: Method, path: &str, pairs: &[(&'static str, &str)]) -> u16 {
        match guard.check(&method, path, &headers(pairs)) {
            Ok(()) => 200,
            Err(e) => e.status.as_u16(),
        }
    }

    #[test]
    fn hosts_are_the_names_the_studio_is_bound_to() {
        let local = Guard::new("127.0.0.1", &[], None);
        for ok in [
            "127.0.0.1:8417",
            "localhost:8417",
            "LOCALHOST",
            "[::1]:8417",
            "127.0.0.2",
            "localhost.",
        ] {
            assert!(local.host_allowed(ok), "{ok}");
        }
        for bad in [
            "evil.example",
            "evil.example:8417",
            "localhost.evil.example",
            "192.168.1.4:8417",
            "",
            "127.0.0.1.nip.io",
        ] {
            assert!(!local.host_allowed(bad), "{bad}");
        }
        let proxied = Guard::new("127.0.0.1", &["Plants.Example.org".into()], None);
        assert!(proxied.host_allowed("plants.example.org"));
        assert!(proxied.host_allowed("plants.example.org:443"));
        assert!(!proxied.host_allowed("example.org"));
        let lan = Guard::new("192.168.1.4", &[], Some("t".into()));
        assert!(lan.host_allowed("192.168.1.4:8417") && lan.host_allowed("localhost"));
        assert!(!lan.host_allowed("10.0.0.1") && !lan.host_allowed("evil.example"));
        let all = Guard::new("0.0.0.0", &[], Some("t".into()));
        assert!(all.host_allowed("10.0.0.1:8417") && all.host_allowed("[fe80::1]"));
        assert!(!all.host_allowed("evil.example"));
        let named = Guard::new("studio.lan", &[], Some("t".into()));
        assert!(named.host_allowed("studio.lan:8417") && !named.host_allowed("evil.lan"));
    }

    #[test]
    #[rustfmt::skip]
    fn other_sites_may_not_change_anything() {
        let g = Guard::new("127.0.0.1", &[], None);
        let host = ("host", "127.0.0.1:8417");
        let json = ("content-type", "application/json");
        let cases: &[(Method, &str, Pairs, u16)] = &[
            (Method::POST, "/api/sessions", &[host, json], 200),
            (Method::POST, "/api/sessions", &[host, ("content-type", "Application/JSON; charset=utf-8")], 200),
            (Method::POST, "/api/sessions", &[host, json, ("origin", "http://127.0.0.1:8417")], 200),
            (Method::POST, "/api/sessions", &[host, ("content-type", "text/plain")], 415),
            (Method::POST, "/api/sessions", &[host, ("content-type", "application/x-www-form-urlencoded")], 415),
            (Method::POST, "/api/sessions", &[host, ("content-type", "multipart/form-data; boundary=x")], 415),
            (Method::POST, "/api/sessions", &[host, ("content-type", "application/jsonp")], 415),
            (Method::POST, "/api/sessions", &[host], 415),
            // methods the studio takes nowhere go on to the router's 405
            (Method::DELETE, "/api/sessions", &[host], 200),
            (Method::TRACE, "/", &[host], 200),
            (Method::DELETE, "/api/sessions", &[host, ("origin", "http://evil.example")], 403),
            (Method::POST, "/api/sessions", &[host, json, ("origin", "http://evil.example")], 403),
            (Method::POST, "/api/sessions", &[host, json, ("origin", "http://127.0.0.1:3000")], 403),
            (Method::POST, "/api/sessions", &[host, json, ("origin", "http://localhost:8417")], 403),
            (Method::POST, "/api/sessions", &[host, json, ("origin", "null")], 403),
            (Method::POST, "/api/sessions", &[host, json, ("origin", "file://")], 403),
            (Method::POST, "/api/sessions", &[host, json, ("origin", "http://127.0.0.1:8417.evil.example")], 403),
            (Method::POST, "/api/sessions", &[host, json, ("sec-fetch-site", "same-site")], 403),
            (Method::GET, "/api/plants/1/plant_tex3.png", &[host, ("sec-fetch-site", "cross-site")], 403),
            // a link on another site may open the page, nothing else
            (Method::GET, "/", &[host, ("sec-fetch-site", "cross-site")], 200),
            (Method::GET, "/api/models", &[host, ("sec-fetch-site", "same-origin")], 200),
            (Method::GET, "/api/models", &[("host", "evil.example")], 403),
            (Method::GET, "/api/models", &[], 403),
        ];
        for (method, path, pairs, expected) in cases {
            assert_eq!(status(&g, method.clone(), path, pairs), *expected, "{method} {path} {pairs:?}");
        }
    }

    #[test]
    #[rustfmt::skip]
    fn tokens_come_as_bearer_of_any_case_cookie_or_query() {
        let g = Guard::new("0.0.0.0", &[], Some("abc123".into()));
        let host = ("host", "10.0.0.2:8417");
        let cases: &[(&str, Pairs, u16)] = &[
            ("/api/models", &[host], 401),
            ("/api/models", &[host, ("authorization", "Bearer abc123")], 200),
            ("/api/models", &[host, ("authorization", "bearer abc123")], 200),
            ("/api/models", &[host, ("authorization", "BEARER   abc123")], 200),
            ("/api/models", &[host, ("authorization", "Basic abc123")], 401),
            ("/api/models", &[host, ("authorization", "Bearer abc124")], 401),
            ("/api/models", &[host, ("cookie", "a=1; sylva_token=abc123")], 200),
            ("/api/models?x=1&token=abc123", &[host], 200),
            ("/api/models?token=abc12", &[host], 401),
        ];
        for (path, pairs, expected) in cases {
            assert_eq!(status(&g, Method::GET, path, pairs), *expected, "{path} {pairs:?}");
        }
    }

    #[test]
    fn tokens_compare_exactly() {
        assert!(same("abc", "abc"));
        assert!(!same("abc", "abd"));
        assert!(!same("abc", "abcd"));
    }
}
