#![allow(clippy::unwrap_used)]
//! The studio's API against the real server (`sylva studio`) and a real database file: every
//! mode's steps, hostile requests, the access token, and kills (not clean shutdowns) in the
//! middle of a running evolution.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// A studio server run by a test; killed (SIGKILL) when dropped.
struct Server {
    child: Child,
    address: String,
    token: Option<String>,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sylva-studio-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn start(dir: &Path, host: &str) -> Server {
    start_with(dir, &["--host", host])
}

/// A studio started with `args` (after `--port 0 --db FILE`); its printed address and token.
fn start_with(dir: &Path, args: &[&str]) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(["studio", "--port", "0", "--db"])
        .arg(dir.join("studio.db"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line
        .trim()
        .strip_prefix("Sylva studio: http://")
        .unwrap_or_else(|| panic!("unexpected first line {line:?}"));
    let (address, rest) = url.split_once('/').unwrap();
    let token = rest.strip_prefix("?token=").map(str::to_owned);
    Server {
        child,
        address: address.to_owned(),
        token,
    }
}

/// One HTTP/1.1 request as the page sends it (JSON, the server's own Host, the token); the
/// status and the body.
fn request(server: &Server, method: &str, path: &str, body: &[u8], auth: bool) -> (u16, Vec<u8>) {
    let auth = match (&server.token, auth) {
        (Some(t), true) => format!("Bearer {t}"),
        _ => String::new(),
    };
    request_with(server, method, path, &[("Authorization", &auth)], body)
}

/// One HTTP/1.1 request with `headers` over the page's (Host, Content-Type): a header given
/// here replaces the page's, and an empty value leaves it out.
fn request_with(
    server: &Server,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> (u16, Vec<u8>) {
    let mut all: Vec<(String, String)> = vec![
        ("Host".into(), server.address.clone()),
        ("Content-Type".into(), "application/json".into()),
    ];
    for (name, value) in headers {
        all.retain(|(n, _)| !n.eq_ignore_ascii_case(name));
        all.push(((*name).to_owned(), (*value).to_owned()));
    }
    let mut head = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\n");
    for (name, value) in all.iter().filter(|(_, v)| !v.is_empty()) {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str(&format!("Content-Length: {}\r\n\r\n", body.len()));
    let mut raw = head.into_bytes();
    raw.extend_from_slice(body);
    exchange(&server.address, &raw)
}

/// Sends `raw` bytes and reads the answer to the end: its status and body.
fn exchange(address: &str, raw: &[u8]) -> (u16, Vec<u8>) {
    let mut stream = TcpStream::connect(address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    // A server may answer (413, 414, 431) before reading the whole request.
    let _ = stream.write_all(raw);
    let mut response = Vec::new();
    let _ = stream.read_to_end(&mut response);
    let split = response
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| {
            panic!(
                "no response head in {:?}",
                String::from_utf8_lossy(&response)
            )
        });
    let head = String::from_utf8_lossy(&response[..split]).to_string();
    let status: u16 = head.split(' ').nth(1).unwrap().parse().unwrap();
    let mut body = response[split + 4..].to_vec();
    if head
        .to_ascii_lowercase()
        .contains("transfer-encoding: chunked")
    {
        body = dechunk(&body);
    }
    (status, body)
}

/// Asserts an answer is the JSON error `{error, field}` with `status` and `field`.
fn assert_refused(what: &str, (got, answer): (u16, Vec<u8>), status: u16, field: &str) {
    let text = String::from_utf8_lossy(&answer);
    assert_eq!(got, status, "{what}: {text}");
    let answer: Value = serde_json::from_slice(&answer)
        .unwrap_or_else(|_| panic!("{what}: JSON error, got {text}"));
    assert!(
        !answer["error"].as_str().unwrap_or("").is_empty(),
        "{what}: {text}"
    );
    assert_eq!(answer["field"], field, "{what}: {text}");
}

fn dechunk(mut data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let line_end = data.windows(2).position(|w| w == b"\r\n").unwrap();
        let size =
            usize::from_str_radix(std::str::from_utf8(&data[..line_end]).unwrap().trim(), 16)
                .unwrap();
        if size == 0 {
            return out;
        }
        out.extend_from_slice(&data[line_end + 2..line_end + 2 + size]);
        data = &data[line_end + 2 + size + 2..];
    }
}

fn get(server: &Server, path: &str) -> Value {
    let (status, body) = request(server, "GET", path, b"", true);
    assert_eq!(
        status,
        200,
        "GET {path}: {}",
        String::from_utf8_lossy(&body)
    );
    serde_json::from_slice(&body).unwrap()
}

fn post(server: &Server, path: &str, body: Value) -> Value {
    let (status, answer) = request(server, "POST", path, body.to_string().as_bytes(), true);
    assert_eq!(
        status,
        200,
        "POST {path} {body}: {}",
        String::from_utf8_lossy(&answer)
    );
    serde_json::from_slice(&answer).unwrap()
}

fn grid(session: &Value) -> Vec<i64> {
    session["state"]["grid"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["plant"].as_i64().unwrap())
        .collect()
}

#[test]
fn breeding_by_hand_is_archived_step_by_step_and_survives_a_kill() {
    let dir = temp_dir("breed");
    let server = start(&dir, "127.0.0.1");
    let session = post(&server, "/api/sessions", json!({"mode": "breed"}));
    let id = session["id"].as_i64().unwrap();
    let first = grid(&session);
    // The five PlantMaker examples, and four of their mutants to fill the grid.
    assert_eq!(first.len(), 9, "{session}");
    for (i, plant) in first.iter().enumerate() {
        let p = get(&server, &format!("/api/plants/{plant}"));
        if i < 5 {
            assert_eq!(p["operator"], "example", "{p}");
        } else {
            assert_eq!(p["operator"], "mutate", "{p}");
            assert_eq!(p["parents"][0]["plant"], first[i - 5], "{p}");
        }
    }

    // Cross two at a high level with dominance: the parents lead, seven children follow.
    let crossed = post(
        &server,
        &format!("/api/sessions/{id}/cross"),
        json!({"parents": [{"plant": first[0], "dominance": 3}, {"plant": first[1]}], "level": "high"}),
    );
    let g = grid(&crossed);
    assert_eq!(g.len(), 9);
    assert_eq!(&g[..2], &first[..2]);
    let child = g[2];
    let plant = get(&server, &format!("/api/plants/{child}"));
    assert_eq!(plant["operator"], "cross");
    assert_eq!(plant["settings"]["level"], "high");
    assert!(
        plant["packed"].as_str().unwrap().len() > 10,
        "PlantMaker's packed string"
    );
    let parents: Vec<i64> = plant["parents"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["plant"].as_i64().unwrap())
        .collect();
    assert!(parents.iter().all(|p| first[..2].contains(p)) && !parents.is_empty());

    // Mutate one child with a Depth: it leads, its eight mutants follow.
    let mutated = post(
        &server,
        &format!("/api/sessions/{id}/mutate"),
        json!({"plant": child, "depth": 6}),
    );
    let g2 = grid(&mutated);
    assert_eq!(g2[0], child);
    let grandchild = g2[1];
    assert_eq!(
        get(&server, &format!("/api/plants/{grandchild}"))["settings"]["depth"],
        6
    );

    // The lineage goes back to the examples.
    let lineage = get(&server, &format!("/api/plants/{grandchild}/lineage"));
    let ids: Vec<i64> = lineage["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["id"].as_i64().unwrap())
        .collect();
    assert!(
        ids.contains(&child) && parents.iter().all(|p| ids.contains(p)),
        "{lineage}"
    );

    // Regrow with another seed: a new plant takes the old one's place.
    let regrown = post(
        &server,
        &format!("/api/sessions/{id}/edit"),
        json!({"plant": grandchild, "seed": 42}),
    );
    let g3 = grid(&regrown);
    assert!(!g3.contains(&grandchild));
    let again = get(&server, &format!("/api/plants/{}", g3[1]));
    assert_eq!(again["operator"], "regrow");
    // The panel's seed, the genome's and the packed string's are the one it grew with.
    assert_eq!(again["seed"], 42);
    assert_eq!(again["genome"]["seed"], 42, "{again}");
    assert!(
        again["packed"].as_str().unwrap().contains("\nseed 42\n"),
        "{again}"
    );

    // Branch from the grandchild: a new session whose population lists it (a plant of the
    // new session with its genome and seed, whose parent it is), and a full grid.
    let branched = post(
        &server,
        &format!("/api/plants/{grandchild}/branch"),
        json!({}),
    );
    let b = branched["id"].as_i64().unwrap();
    assert_eq!(grid(&branched).len(), 9);
    let listed = get(&server, &format!("/api/plants?session={b}"));
    let first_of_branch = grid(&branched)[0];
    let copy = get(&server, &format!("/api/plants/{first_of_branch}"));
    assert_eq!(copy["operator"], "branch");
    assert_eq!(copy["parents"][0]["plant"], grandchild);
    assert_eq!(
        copy["genome"],
        get(&server, &format!("/api/plants/{grandchild}"))["genome"]
    );
    assert_eq!(listed["total"], 9);
    // In the branch, the genome's own seed edited as a field while the page sends the
    // plant's seed as it was: the edit is the plant's seed.
    let seed = copy["seed"].as_u64().unwrap();
    let other = seed.wrapping_add(1);
    let edited = post(
        &server,
        &format!("/api/sessions/{b}/edit"),
        json!({"plant": first_of_branch, "fields": [{"path": "seed", "value": other}], "seed": seed}),
    );
    let edited = get(&server, &format!("/api/plants/{}", grid(&edited)[0]));
    assert_eq!(
        (edited["seed"].as_u64(), edited["genome"]["seed"].as_u64()),
        (Some(other), Some(other))
    );

    // Undo twice, redo once.
    let undone = post(&server, &format!("/api/sessions/{id}/undo"), json!({}));
    assert_eq!(grid(&undone), g2);
    let undone = post(&server, &format!("/api/sessions/{id}/undo"), json!({}));
    assert_eq!(grid(&undone), g);
    let redone = post(&server, &format!("/api/sessions/{id}/redo"), json!({}));
    assert_eq!(grid(&redone), g2);

    // Exports: a validator-clean GLB with its origin, an OBJ, a PNG.
    let (status, glb) = request(
        &server,
        "GET",
        &format!("/api/plants/{child}/plant.glb"),
        b"",
        true,
    );
    assert_eq!(status, 200);
    let file = dir.join("child.glb");
    std::fs::write(&file, &glb).unwrap();
    sylva_testkit::validate(std::slice::from_ref(&file));
    let json_chunk = String::from_utf8_lossy(
        &glb[20..20 + u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize],
    )
    .to_string();
    assert!(
        json_chunk.contains("\"operator\":\"cross\""),
        "origin extras"
    );
    let (status, obj) = request(
        &server,
        "GET",
        &format!("/api/plants/{child}/plant.obj"),
        b"",
        true,
    );
    assert_eq!(status, 200);
    assert!(obj.starts_with(b"# Sylva") && obj.windows(2).any(|w| w == b"\nf"));
    let (status, png) = request(
        &server,
        "GET",
        &format!("/api/plants/{child}/plant.png?size=64x48"),
        b"",
        true,
    );
    assert_eq!(status, 200);
    assert_eq!(&png[1..4], b"PNG");

    // Killed, started again: the session, its history and its plants are all there.
    let before = get(&server, &format!("/api/sessions/{id}"));
    let plants = get(&server, &format!("/api/plants?session={id}&limit=1000"));
    drop(server);
    let server = start(&dir, "127.0.0.1");
    assert_eq!(get(&server, &format!("/api/sessions/{id}")), before);
    assert_eq!(
        get(&server, &format!("/api/plants?session={id}&limit=1000")),
        plants
    );
    assert_eq!(before["history"].as_array().unwrap().len(), 3);
    assert_eq!(before["can_redo"], true);
}

/// A hostile case: method, path, body, the status expected and the field it must name.
type Case = (&'static str, String, Vec<u8>, u16, &'static str);

fn case(
    method: &'static str,
    path: impl Into<String>,
    body: &str,
    status: u16,
    field: &'static str,
) -> Case {
    (method, path.into(), body.as_bytes().to_vec(), status, field)
}

#[test]
fn hostile_requests_get_a_4xx_that_names_the_field_as_sent() {
    let dir = temp_dir("hostile");
    let server = start(&dir, "127.0.0.1");
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "breed", "model": "bintree", "start": {"random": 3}}),
    );
    let id = session["id"].as_i64().unwrap();
    let p = grid(&session);
    let garden = post(
        &server,
        "/api/sessions",
        json!({"mode": "garden", "settings": {"steps": 10, "children": 2}}),
    );
    let g = garden["id"].as_i64().unwrap();
    let family = post(
        &server,
        "/api/sessions",
        json!({"mode": "family", "config": {"run": {"population": 12}}}),
    );
    let f = family["id"].as_i64().unwrap();
    let design = post(
        &server,
        "/api/sessions",
        json!({"mode": "design", "design": {"population": 10, "generations": 1}}),
    );
    let d = design["id"].as_i64().unwrap();
    let big = "x".repeat(2 << 20);
    let s = "/api/sessions";
    let cross = format!("/api/sessions/{id}/cross");
    let two = |rest: &str| {
        format!(
            r#"{{"parents": [{{"plant": {}}}, {{"plant": {}}}]{rest}}}"#,
            p[0], p[1]
        )
    };
    let mutate = format!("/api/sessions/{id}/mutate");
    let edit = format!("/api/sessions/{id}/edit");
    let add = format!("/api/sessions/{id}/add");
    let plant = |rest: &str| format!(r#"{{"plant": {}{rest}}}"#, p[0]);
    #[rustfmt::skip]
    let cases: Vec<Case> = vec![
        // The body as a whole.
        case("POST", s, "{", 400, ""),
        case("POST", s, "[]", 400, ""),
        case("POST", s, "{} {}", 400, ""),
        case("POST", s, &big, 413, ""),
        // Creating sessions: every mode's fields.
        case("POST", s, "{}", 400, "mode"),
        case("POST", s, r#"{"mode": 3}"#, 400, "mode"),
        case("POST", s, r#"{"mode": "jungle"}"#, 400, "mode"),
        case("POST", s, r#"{"mode": "breed", "model": "oak"}"#, 400, "model"),
        case("POST", s, r#"{"mode": "breed", "model": 7}"#, 400, "model"),
        case("POST", s, r#"{"mode": "breed", "seed": "abc"}"#, 400, "seed"),
        case("POST", s, r#"{"mode": "breed", "seed": -1}"#, 400, "seed"),
        case("POST", s, r#"{"mode": "breed", "seed": 1e30}"#, 400, "seed"),
        case("POST", s, r#"{"mode": "breed", "colour": "red"}"#, 400, "colour"),
        case("POST", s, r#"{"mode": "breed", "start": {"random": 0}}"#, 400, "start.random"),
        case("POST", s, r#"{"mode": "breed", "start": {"random": 1e99}}"#, 400, "start.random"),
        case("POST", s, r#"{"mode": "breed", "start": {"random": "x"}}"#, 400, "start.random"),
        case("POST", s, r#"{"mode": "breed", "start": {"meadow": 1}}"#, 400, "start.meadow"),
        case("POST", s, r#"{"mode": "breed", "start": {"examples": ["nope"]}}"#, 400, "start.examples[0]"),
        case("POST", s, r#"{"mode": "breed", "start": {"examples": "plantmaker/fern"}}"#, 400, "start.examples"),
        case("POST", s, r#"{"mode": "breed", "start": {"plants": [999999]}}"#, 400, "start.plants[0]"),
        case("POST", s, r#"{"mode": "breed", "start": {"plants": [1, "a"]}}"#, 400, "start.plants[1]"),
        case("POST", s, r#"{"mode": "breed", "start": {"genomes": [5]}}"#, 400, "start.genomes[0]"),
        case("POST", s, r#"{"mode": "breed", "start": {"genomes": ["{\"model\": \"bintree\", \"format\": 1, \"depth\": -4}"]}}"#, 422, "start.genomes[0]"),
        case("POST", s, r#"{"mode": "garden", "start": {"plant": 999999}}"#, 400, "start.plant"),
        case("POST", s, r#"{"mode": "garden", "start": {"example": "nope"}}"#, 400, "start.example"),
        case("POST", s, r#"{"mode": "garden", "start": {"genome": "{"}}"#, 422, "start.genome"),
        case("POST", s, r#"{"mode": "garden", "start": {"empty": false}}"#, 400, "start.empty"),
        case("POST", s, r#"{"mode": "garden", "settings": {"elevation": 91}}"#, 400, "settings.elevation"),
        case("POST", s, r#"{"mode": "garden", "settings": {"steps": 5000}}"#, 400, "settings.steps"),
        case("POST", s, r#"{"mode": "garden", "settings": {"azimuth": "x"}}"#, 400, "settings.azimuth"),
        case("POST", s, r#"{"mode": "garden", "settings": {"colour": 1}}"#, 400, "settings.colour"),
        case("POST", s, r#"{"mode": "garden", "seed": "abc"}"#, 400, "seed"),
        case("POST", s, r#"{"mode": "family", "config": {"run": {"population": -3}}}"#, 422, "config.run.population"),
        case("POST", s, r#"{"mode": "family", "config": {"run": {"population": 20000}}}"#, 400, "config.run.population"),
        case("POST", s, r#"{"mode": "family", "config": {"run": {"population": 1e9}}}"#, 422, "config.run.population"),
        case("POST", s, r#"{"mode": "family", "config": {"run": {"population": null}}}"#, 400, "config.run.population"),
        case("POST", s, r#"{"mode": "family", "config": {"run": {"seed": "abc"}}}"#, 422, "config.run.seed"),
        case("POST", s, r#"{"mode": "family", "config": {"run": {"speed": 1}}}"#, 422, "config.run.speed"),
        case("POST", s, r#"{"mode": "family", "config": {"bintree": {"mutation_rate": 7}}}"#, 422, "config.bintree.mutation_rate"),
        case("POST", s, r#"{"mode": "family", "config": {"bintree": {"weights": {"height": "tall"}}}}"#, 422, "config.bintree.weights.height"),
        case("POST", s, r#"{"mode": "family", "config": {"colour": 1}}"#, 400, "config.colour"),
        case("POST", s, r#"{"mode": "design", "design": {"population": 5}}"#, 400, "design.population"),
        case("POST", s, r#"{"mode": "design", "design": {"population": 1e9}}"#, 400, "design.population"),
        case("POST", s, r#"{"mode": "design", "design": {"seed": "abc"}}"#, 400, "design.seed"),
        case("POST", s, r#"{"mode": "design", "design": {"num_target": 0}}"#, 400, "design.num_target"),
        case("POST", s, r#"{"mode": "design", "design": {"target": {"shape": "sphere", "radius": -1}}}"#, 422, "design.target.radius"),
        case("POST", s, r#"{"mode": "design", "design": {"target": {"shape": "blob"}}}"#, 422, "design.target.shape"),
        case("POST", s, r#"{"mode": "design", "design": {"target": {"shape": "sphere", "radius": null}}}"#, 400, "design.target.radius"),
        case("POST", s, r#"{"mode": "design", "design": {"weights": {"pos": "high"}}}"#, 422, "design.weights.pos"),
        case("POST", s, r#"{"mode": "design", "design": {"weights": 5}}"#, 400, "design.weights"),
        case("POST", s, r#"{"mode": "design", "design": {"grid": {"min": [0,0,0], "max": [1,1,1], "divisions": [2,2,2], "cells": [{"cell": [9,0,0], "weight": 1}]}}}"#, 400, "design.grid.cells[0].cell[0]"),
        case("POST", s, r#"{"mode": "design", "design": {"grid": {"min": [0,0,0], "max": [1,1,1], "divisions": [2,2], "cells": []}}}"#, 400, "design.grid.divisions"),
        case("POST", s, r#"{"mode": "design", "design": {"grid": {"min": [0,0,0], "max": [1,1,1], "divisions": [2,2,2], "cells": [{"cell": [0,0,0], "weight": "x"}]}}}"#, 400, "design.grid.cells[0].weight"),
        case("POST", s, r#"{"mode": "design", "design": {"colour": 1}}"#, 400, "design.colour"),
        // Breeding steps.
        case("POST", &cross, &format!(r#"{{"parents": [{{"plant": {}}}]}}"#, p[0]), 400, "parents"),
        case("POST", &cross, r#"{"parents": "x"}"#, 400, "parents"),
        case("POST", &cross, r#"{"parents": [{"plant": "a"}, {"plant": 1}]}"#, 400, "parents[0].plant"),
        case("POST", &cross, &format!( r#"{{"parents": [{{"plant": {}}}, {{"plant": {}, "dominance": -1}}]}}"#, p[0], p[1]),
            400,
            "parents[1].dominance",
        ),
        case("POST", &cross, &format!( r#"{{"parents": [{{"plant": {}}}, {{"plant": {}, "dominance": "x"}}]}}"#, p[0], p[1]),
            400,
            "parents[1].dominance",
        ),
        case("POST", &cross, &format!( r#"{{"parents": [{{"plant": {}}}, {{"plant": 999999}}]}}"#, p[0]),
            400,
            "parents[1]",
        ),
        case("POST", &cross, &format!( r#"{{"parents": [{{"plant": {}}}, {{"plant": {}}}]}}"#, p[0], p[0]),
            400,
            "parents[1].plant",
        ),
        case("POST", &cross, &two(r#", "children": 10"#), 400, "children"),
        case("POST", &cross, &two(r#", "children": -1"#), 400, "children"),
        case("POST", &cross, &two(r#", "level": "max""#), 400, "level"),
        case("POST", &cross, &two(r#", "level": 3"#), 400, "level"),
        case("POST", &cross, &two(r#", "seed": 1.5"#), 400, "seed"),
        case("POST", &cross, &two(r#", "colour": 1"#), 400, "colour"),
        case("POST", &mutate, "{}", 400, "plant"),
        case("POST", &mutate, r#"{"plant": 999999}"#, 400, "plant"),
        case("POST", &mutate, &plant(r#", "depth": 11"#), 400, "depth"),
        case("POST", &mutate, &plant(r#", "depth": "deep""#), 400, "depth"),
        case("POST", &mutate, &plant(r#", "seed": -1"#), 400, "seed"),
        case("POST", &mutate, &plant(r#", "children": 0"#), 400, "children"),
        case("POST", &add, r#"{"random": 0}"#, 400, "random"),
        case("POST", &add, r#"{"plants": [999999]}"#, 400, "plants[0]"),
        case("POST", &add, r#"{"nope": 1}"#, 400, "nope"),
        case("POST", &edit, &plant(r#", "genome": "{\"model\": \"bintree\"}""#), 422, "genome"),
        case("POST", &edit, &plant(r#", "genome": 5"#), 422, "genome"),
        case("POST", &edit, &plant(""), 400, "genome"),
        case("POST", &edit, r#"{"plant": "x"}"#, 400, "plant"),
        case("POST", &edit, &plant(r#", "fields": [{"path": "nope", "value": 1}]"#), 400, "fields[0].path"),
        case("POST", &edit, &plant(r#", "fields": [{"path": 5, "value": 1}]"#), 400, "fields[0].path"),
        case("POST", &edit, &plant(r#", "fields": [{"value": 1}]"#), 400, "fields[0].path"),
        // A value the genome refuses is the edit's, not the whole list's.
        case("POST", &edit, &plant(r#", "fields": [{"path": "depth", "value": "abc"}]"#), 422, "fields[0].value"),
        case("POST", &edit, &plant(r#", "fields": [{"path": "depth", "value": 4}, {"path": "length", "value": "abc"}]"#), 422, "fields[1].value"),
        case("POST", &edit, &plant(r#", "seed": "x""#), 400, "seed"),
        case("POST", format!("/api/sessions/{id}/grow"), "{}", 409, ""),
        case("POST", format!("/api/sessions/{id}/redo"), "", 409, ""),
        case("POST", "/api/sessions/424242/undo", "", 404, ""),
        // Gardens, families and designs.
        case("POST", format!("/api/sessions/{g}/grow"), r#"{"settings": {"steps": 5000}}"#, 400, "settings.steps"),
        case("POST", format!("/api/sessions/{g}/grow"), r#"{"settings": "x"}"#, 400, "settings"),
        case("POST", format!("/api/sessions/{g}/pick"), r#"{"plant": 999999}"#, 400, "plant"),
        case("POST", format!("/api/sessions/{g}/pick"), r#"{"plant": "x"}"#, 400, "plant"),
        case("POST", format!("/api/sessions/{f}/generations"), r#"{"count": "x"}"#, 400, "count"),
        case("POST", format!("/api/sessions/{f}/generations"), r#"{"count": 99999}"#, 400, "count"),
        case("POST", format!("/api/sessions/{f}/batch"), r#"{"batch": -1}"#, 400, "batch"),
        case("POST", format!("/api/sessions/{f}/member"), r#"{"index": 99999}"#, 400, "index"),
        case("POST", format!("/api/sessions/{f}/member"), "{}", 400, "index"),
        case("POST", format!("/api/sessions/{d}/design"), r#"{"target": {"shape": "sphere", "radius": -1}}"#, 422, "target.radius"),
        case("POST", format!("/api/sessions/{d}/design"), r#"{"population": 5}"#, 400, "population"),
        case("POST", format!("/api/sessions/{d}/resume"), r#"{"generations": 0}"#, 400, "generations"),
        case("POST", format!("/api/plants/{}/branch", p[0]), r#"{"mode": "jungle"}"#, 400, "mode"),
        case("POST", format!("/api/plants/{}/branch", p[0]), r#"{"mode": 5}"#, 400, "mode"),
        // Queries and paths.
        case("GET", "/api/sessions/abc", "", 400, ""),
        case("GET", "/api/plants/424242/plant.glb", "", 404, ""),
        case("GET", format!("/api/plants/{}/plant.png?size=99999x2", p[0]), "", 400, "size"),
        case("GET", format!("/api/plants/{}/plant.png?view=under", p[0]), "", 400, "view"),
        case("GET", format!("/api/plants/{}/lineage?depth=0", p[0]), "", 400, "depth"),
        case("GET", format!("/api/plants/{}/lineage?depth=x", p[0]), "", 400, "depth"),
        case("GET", format!("/api/plants/{}/preview.glb?px=0", p[0]), "", 400, "px"),
        case("GET", format!("/api/plants/{}/plant.glb?roots=maybe", p[0]), "", 400, "roots"),
        case("GET", "/api/plants?limit=100000", "", 400, "limit"),
        case("GET", "/api/plants?limit=x", "", 400, "limit"),
        case("GET", "/api/nothing", "", 404, ""),
        case("GET", format!("/api/plants/{}/secrets.txt", p[0]), "", 404, ""),
        case("GET", "/vendor/three/../../../../etc/passwd", "", 404, ""),
        case("GET", "/vendor/three/package.json", "", 404, ""),
        case("GET", "/vendor/three/build/three.module.js", "", 200, ""),
    ];
    for (method, path, body, status, field) in &cases {
        let answer = request(&server, method, path, body, true);
        if *status == 200 {
            assert_eq!(answer.0, 200, "{method} {path}");
            continue;
        }
        let what = format!(
            "{method} {path} {}",
            String::from_utf8_lossy(&body[..body.len().min(200)])
        );
        assert_refused(&what, answer, *status, field);
    }
    // The server is still up and the session untouched.
    assert_eq!(
        get(&server, &format!("/api/sessions/{id}"))["history"],
        json!([])
    );
}

/// A request a hostile page could send: method, path, headers, the status expected.
type Refused<'a> = (&'a str, &'a str, Vec<(&'a str, &'a str)>, u16);

#[test]
fn pages_of_other_sites_and_foreign_host_names_are_refused() {
    let dir = temp_dir("sites");
    let server = start(&dir, "127.0.0.1");
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "breed", "model": "bintree", "start": {"random": 2}}),
    );
    let id = session["id"].as_i64().unwrap();
    let p = grid(&session);
    let mutate = format!("/api/sessions/{id}/mutate");
    let body = format!(r#"{{"plant": {}, "children": 1}}"#, p[0]);
    let own = format!("http://{}", server.address);
    let port = server.address.rsplit(':').next().unwrap().to_owned();
    let other_port = format!("http://127.0.0.1:{}", port.parse::<u16>().unwrap() ^ 1);
    let evil_host = format!("evil.example:{port}");
    let rebound = format!("127.0.0.1.nip.io:{port}");
    // What a page on another site can send without a preflight, and what it cannot fake.
    #[rustfmt::skip]
    let refused: Vec<Refused> = vec![
        ("POST", "/api/sessions", vec![("Content-Type", "text/plain")], 415),
        ("POST", "/api/sessions", vec![("Content-Type", "application/x-www-form-urlencoded")], 415),
        ("POST", "/api/sessions", vec![("Content-Type", "multipart/form-data; boundary=x")], 415),
        ("POST", "/api/sessions", vec![("Content-Type", "")], 415),
        ("POST", &mutate, vec![("Content-Type", "text/plain;charset=UTF-8"), ("Origin", "http://evil.example")], 403),
        ("POST", &mutate, vec![("Origin", "http://evil.example")], 403),
        ("POST", &mutate, vec![("Origin", "null")], 403),
        ("POST", &mutate, vec![("Origin", &other_port)], 403),
        ("POST", &mutate, vec![("Sec-Fetch-Site", "cross-site")], 403),
        ("POST", &mutate, vec![("Sec-Fetch-Site", "same-site")], 403),
        ("GET", "/api/sessions", vec![("Sec-Fetch-Site", "cross-site")], 403),
        ("GET", "/api/plants/999999/plant_tex65535.png", vec![("Sec-Fetch-Site", "cross-site")], 403),
        // DNS rebinding: the page's own requests, under another name.
        ("GET", "/", vec![("Host", "evil.example")], 403),
        ("GET", "/api/models", vec![("Host", &evil_host)], 403),
        ("GET", "/api/models", vec![("Host", &rebound)], 403),
        ("POST", &mutate, vec![("Host", &evil_host), ("Origin", "http://evil.example")], 403),
        ("GET", "/api/models", vec![("Host", "")], 403),
    ];
    for (method, path, headers, status) in &refused {
        let sent = if *method == "POST" {
            body.as_bytes()
        } else {
            b""
        };
        let answer = request_with(&server, method, path, headers, sent);
        assert_refused(&format!("{method} {path} {headers:?}"), answer, *status, "");
    }
    // A URL with a whole address names its host too; HTTP/1.0 without a Host is refused.
    let absolute = format!(
        "GET http://evil.example:{port}/api/models HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
        server.address
    );
    assert_refused(
        "absolute URL",
        exchange(&server.address, absolute.as_bytes()),
        403,
        "",
    );
    assert_refused(
        "HTTP/1.0",
        exchange(&server.address, b"GET /api/models HTTP/1.0\r\n\r\n"),
        403,
        "",
    );
    // Nothing happened: no step, no new plant.
    assert_eq!(
        get(&server, &format!("/api/sessions/{id}"))["history"],
        json!([])
    );
    assert_eq!(
        get(&server, &format!("/api/plants?session={id}"))["total"],
        9
    );
    // The studio's own page: its origin, loopback names, a link from another site to the
    // page, and a token-free bearer of any case are all fine.
    for (method, path, headers) in [
        (
            "POST",
            mutate.as_str(),
            vec![("Origin", own.as_str()), ("Sec-Fetch-Site", "same-origin")],
        ),
        (
            "POST",
            mutate.as_str(),
            vec![("Content-Type", "application/json; charset=utf-8")],
        ),
        ("GET", "/api/models", vec![("Host", "localhost")]),
        ("GET", "/api/models", vec![("Host", "[::1]")]),
        (
            "GET",
            "/",
            vec![
                ("Sec-Fetch-Site", "cross-site"),
                ("Sec-Fetch-Mode", "navigate"),
            ],
        ),
    ] {
        let sent = if method == "POST" {
            body.as_bytes()
        } else {
            b""
        };
        let (status, answer) = request_with(&server, method, path, &headers, sent);
        assert_eq!(
            status,
            200,
            "{method} {path} {headers:?}: {}",
            String::from_utf8_lossy(&answer)
        );
    }
}

#[test]
fn a_reverse_proxy_name_is_allowed_only_when_given() {
    let dir = temp_dir("proxy");
    let server = start_with(&dir, &["--allow-host", "plants.example.org"]);
    for (host, status) in [
        ("plants.example.org", 200),
        ("PLANTS.example.org:443", 200),
        ("example.org", 403),
    ] {
        let (got, body) = request_with(&server, "GET", "/api/models", &[("Host", host)], b"");
        assert_eq!(got, status, "{host}: {}", String::from_utf8_lossy(&body));
    }
    let (got, _) = request_with(
        &server,
        "POST",
        "/api/sessions",
        &[
            ("Host", "plants.example.org"),
            ("Origin", "https://plants.example.org"),
        ],
        br#"{"mode": "breed", "model": "bintree", "start": {"random": 1}}"#,
    );
    assert_eq!(got, 200, "a proxy serving https keeps the page's origin");
}

#[test]
fn obj_comes_as_one_zip_and_stl_for_printing() {
    let dir = temp_dir("exports");
    let server = start(&dir, "127.0.0.1");
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "breed", "start": {"examples": ["plantmaker/fern"]}}),
    );
    let fern = grid(&session)[0];
    let (status, zip) = request(
        &server,
        "GET",
        &format!("/api/plants/{fern}/plant.zip"),
        b"",
        true,
    );
    assert_eq!(status, 200);
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(zip)).unwrap();
    let mut files = std::collections::BTreeMap::new();
    for i in 0..archive.len() {
        let mut file = archive.by_index(i).unwrap();
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).unwrap();
        files.insert(file.name().unwrap().into_owned(), bytes);
    }
    let obj = String::from_utf8(files[&format!("plant-{fern}.obj")].clone()).unwrap();
    let mtl_name = obj.lines().find_map(|l| l.strip_prefix("mtllib ")).unwrap();
    let mtl = String::from_utf8(files[mtl_name].clone()).unwrap();
    let textures: std::collections::BTreeSet<&str> = mtl
        .lines()
        .filter_map(|l| l.trim().strip_prefix("map_Kd "))
        .filter_map(|l| l.split_whitespace().last())
        .collect();
    assert!(!textures.is_empty());
    for t in &textures {
        assert!(files[*t].starts_with(b"\x89PNG"), "{t}");
    }
    assert_eq!(files.len(), 2 + textures.len(), "{:?}", files.keys());
    // The same plant, the same bytes.
    let (_, again) = request(
        &server,
        "GET",
        &format!("/api/plants/{fern}/plant.zip"),
        b"",
        true,
    );
    let (_, first) = request(
        &server,
        "GET",
        &format!("/api/plants/{fern}/plant.zip"),
        b"",
        true,
    );
    assert_eq!(again, first);

    let (status, stl) = request(
        &server,
        "GET",
        &format!("/api/plants/{fern}/plant.stl"),
        b"",
        true,
    );
    assert_eq!(status, 200);
    let triangles = u32::from_le_bytes([stl[80], stl[81], stl[82], stl[83]]) as usize;
    let faces = obj.lines().filter(|l| l.starts_with("f ")).count();
    assert_eq!(triangles, faces);
    assert_eq!(stl.len(), 84 + 50 * triangles);
}

#[test]
fn a_copied_binary_serves_the_page_from_any_folder() {
    let dir = temp_dir("installed");
    // As `cargo install` leaves it: the binary alone, run from a folder of its own.
    let bin = dir.join("bin/sylva");
    std::fs::create_dir_all(bin.parent().unwrap()).unwrap();
    std::fs::copy(env!("CARGO_BIN_EXE_sylva"), &bin).unwrap();
    let work = dir.join("elsewhere");
    std::fs::create_dir_all(&work).unwrap();
    let mut child = Command::new(&bin)
        .args(["studio", "--port", "0", "--db", "studio.db"])
        .current_dir(&work)
        .env_remove("SYLVA_STUDIO_WEB")
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let address = line
        .trim()
        .strip_prefix("Sylva studio: http://")
        .and_then(|u| u.strip_suffix('/'))
        .unwrap_or_else(|| panic!("unexpected first line {line:?}"))
        .to_owned();
    let server = Server {
        child,
        address,
        token: None,
    };
    let web = Path::new(env!("CARGO_MANIFEST_DIR")).join("../sylva-studio/web");
    for (path, file) in [
        ("/", web.join("index.html")),
        ("/app/main.js", web.join("app/main.js")),
        ("/app/viewer.js", web.join("app/viewer.js")),
        (
            "/vendor/three/build/three.module.js",
            web.join("node_modules/three/build/three.module.js"),
        ),
        (
            "/vendor/three/examples/jsm/loaders/GLTFLoader.js",
            web.join("node_modules/three/examples/jsm/loaders/GLTFLoader.js"),
        ),
        (
            "/vendor/three/LICENSE",
            web.join("node_modules/three/LICENSE"),
        ),
    ] {
        let (status, body) = request(&server, "GET", path, b"", true);
        assert_eq!(status, 200, "{path}");
        assert_eq!(
            body,
            std::fs::read(&file).unwrap(),
            "{path} is {}",
            file.display()
        );
    }
    assert!(
        work.join("studio.db").is_file(),
        "the archive is made where it runs"
    );
}

/// How far apart two genomes' JSON are: each number by its relative difference, each
/// string by the share of its characters that differ (by position, and its length), each
/// value one side lacks as 1.
fn genome_distance(a: &Value, b: &Value) -> f64 {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            (x - y).abs() / (x.abs() + y.abs()).max(1e-9)
        }
        (Value::String(x), Value::String(y)) => {
            // Edit distance, so a number that gains a sign does not shift the rest of a
            // program out of place.
            let (x, y): (Vec<char>, Vec<char>) = (x.chars().collect(), y.chars().collect());
            let mut row: Vec<usize> = (0..=y.len()).collect();
            for (i, p) in x.iter().enumerate() {
                let mut diagonal = row[0];
                row[0] = i + 1;
                for (j, q) in y.iter().enumerate() {
                    let substitute = diagonal + usize::from(p != q);
                    diagonal = row[j + 1];
                    row[j + 1] = substitute.min(row[j] + 1).min(diagonal + 1);
                }
            }
            row[y.len()] as f64 / x.len().max(y.len()).max(1) as f64
        }
        (Value::Array(x), Value::Array(y)) => (0..x.len().max(y.len()))
            .map(|i| match (x.get(i), y.get(i)) {
                (Some(p), Some(q)) => genome_distance(p, q),
                _ => 1.0,
            })
            .sum(),
        (Value::Object(x), Value::Object(y)) => x
            .keys()
            .chain(y.keys().filter(|k| !x.contains_key(*k)))
            .map(|k| match (x.get(k), y.get(k)) {
                (Some(p), Some(q)) => genome_distance(p, q),
                _ => 1.0,
            })
            .sum(),
        (x, y) => f64::from(u8::from(x != y)),
    }
}

#[test]
fn models_say_which_modes_hold_their_plants() {
    let dir = temp_dir("capabilities");
    let server = start(&dir, "127.0.0.1");
    let models = get(&server, "/api/models");
    let of = |name: &str| -> Value {
        models
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == name)
            .cloned()
            .unwrap_or_else(|| panic!("{name} is listed: {models}"))
    };
    assert_eq!(of("plantmaker")["modes"], json!(["breed", "match", "map"]));
    assert_eq!(
        of("lsystem")["modes"],
        json!(["breed", "garden", "match", "map"])
    );
    assert_eq!(
        of("bintree")["modes"],
        json!(["breed", "family", "match", "map"])
    );
    assert_eq!(
        of("automata")["modes"],
        json!(["breed", "design", "match", "map"])
    );
    let defaults: Vec<&Value> = models
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["default"] == true)
        .collect();
    assert_eq!(defaults.len(), 1, "{models}");
    assert_eq!(defaults[0]["name"], "plantmaker");
    // A mode that does not start from a plant says so, naming the modes that do.
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "breed", "seed": 2}),
    );
    let plant = grid(&session)[0];
    let (status, body) = request(
        &server,
        "POST",
        &format!("/api/plants/{plant}/branch"),
        br#"{"mode": "family"}"#,
        true,
    );
    assert_eq!(status, 400, "{}", String::from_utf8_lossy(&body));
    let error: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(error["field"], "mode");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn depth_means_the_same_in_every_model() {
    let dir = temp_dir("knobs");
    let server = start(&dir, "127.0.0.1");
    for model in ["plantmaker", "bintree", "automata", "lsystem"] {
        let session = post(
            &server,
            "/api/sessions",
            json!({"mode": "breed", "model": model, "seed": 5}),
        );
        let id = session["id"].as_i64().unwrap();
        let parent = grid(&session)[0];
        let genome = get(&server, &format!("/api/plants/{parent}"))["genome"].clone();
        let mean_distance = |depth: u32| {
            let mut distances = Vec::new();
            for seed in 1..=3u64 {
                let bred = post(
                    &server,
                    &format!("/api/sessions/{id}/mutate"),
                    json!({"plant": parent, "depth": depth, "children": 8, "seed": seed}),
                );
                let children: Vec<i64> = grid(&bred)[1..].to_vec();
                for child in children {
                    let row = get(&server, &format!("/api/plants/{child}"));
                    assert_eq!(row["parents"][0]["plant"], parent);
                    distances.push(genome_distance(&genome, &row["genome"]));
                }
            }
            distances.iter().sum::<f64>() / distances.len() as f64
        };
        let (gentle, strong) = (mean_distance(1), mean_distance(10));
        assert!(
            strong > 2.0 * gentle && strong > 0.0,
            "{model}: Depth 1 moves its children {gentle:.3} on average, Depth 10 {strong:.3}"
        );
    }
}

#[test]
fn textures_are_served_only_for_what_a_real_plant_names() {
    let dir = temp_dir("textures");
    let server = start(&dir, "127.0.0.1");
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "breed", "start": {"examples": ["plantmaker/fern"]}}),
    );
    let fern = grid(&session)[0];
    let mtl = request(
        &server,
        "GET",
        &format!("/api/plants/{fern}/plant.mtl"),
        b"",
        true,
    );
    assert_eq!(mtl.0, 200);
    let mtl = String::from_utf8(mtl.1).unwrap();
    let named: Vec<&str> = mtl
        .lines()
        .filter_map(|l| l.trim().strip_prefix("map_Kd "))
        .filter_map(|options_and_file| options_and_file.split_whitespace().last())
        .collect();
    assert!(
        !named.is_empty(),
        "the fern's materials name textures: {mtl}"
    );
    for file in &named {
        let (status, png) = request(
            &server,
            "GET",
            &format!("/api/plants/{fern}/{file}"),
            b"",
            true,
        );
        assert_eq!(status, 200, "{file}");
        assert!(png.starts_with(b"\x89PNG"), "{file}");
    }
    let unnamed = (0..128u16)
        .map(|i| format!("plant_tex{i}.png"))
        .find(|f| !named.contains(&f.as_str()))
        .unwrap();
    for path in [
        format!("/api/plants/{fern}/{unnamed}"),
        format!("/api/plants/{fern}/plant_tex65535.png"),
        format!("/api/plants/{fern}/plant_tex99999.png"),
        format!("/api/plants/{fern}/plant_tex+3.png"),
        "/api/plants/999999/plant_tex3.png".to_owned(),
        "/api/plants/999999/plant_tex65535.png".to_owned(),
    ] {
        assert_refused(&path, request(&server, "GET", &path, b"", true), 404, "");
    }
}

#[test]
fn over_long_and_malformed_requests_get_json_errors() {
    let dir = temp_dir("heads");
    let server = start(&dir, "127.0.0.1");
    let host = &server.address;
    let long = |n: usize| {
        format!(
            "GET /api/plants?session=1&x={} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n",
            "a".repeat(n)
        )
    };
    for n in [9_000, 70_000, 1 << 20] {
        assert_refused(
            &format!("a URL of {n} bytes"),
            exchange(host, long(n).as_bytes()),
            414,
            "",
        );
    }
    let path = format!("/api/{}", "a".repeat(9_000));
    assert_refused(
        "a long path",
        request(&server, "GET", &path, b"", true),
        414,
        "",
    );
    let header = format!(
        "GET /api/models HTTP/1.1\r\nHost: {host}\r\nX-Big: {}\r\nConnection: close\r\n\r\n",
        "b".repeat(100_000)
    );
    assert_refused(
        "a 100 kB header",
        exchange(host, header.as_bytes()),
        431,
        "",
    );
    let huge = format!(
        "GET /api/models HTTP/1.1\r\nHost: {host}\r\nX-Big: {}\r\n\r\n",
        "b".repeat(1 << 20)
    );
    assert_refused("a 1 MB header", exchange(host, huge.as_bytes()), 431, "");
    let mut many = format!("GET /api/models HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n");
    for i in 0..200 {
        many.push_str(&format!("X-{i}: 1\r\n"));
    }
    many.push_str("\r\n");
    assert_refused("200 headers", exchange(host, many.as_bytes()), 431, "");
    for bad in [
        "GARBAGE\r\n\r\n".to_owned(),
        format!("GET /api/models HTTP/9.9\r\nHost: {host}\r\n\r\n"),
        format!(
            "POST /api/sessions HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\nContent-Length: 2\r\nContent-Length: 3\r\n\r\n{{}}"
        ),
        format!(
            "POST /api/sessions HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\nContent-Length: -1\r\n\r\n"
        ),
    ] {
        assert_refused(&format!("{bad:?}"), exchange(host, bad.as_bytes()), 400, "");
    }
    // And the studio still answers.
    assert_eq!(get(&server, "/api/models").as_array().unwrap().len(), 5);
}

/// Reads server-sent events from `reader` until `enough` says so: (name, data) pairs.
fn read_events(
    reader: &mut impl BufRead,
    enough: impl Fn(&[(String, Value)]) -> bool,
) -> Vec<(String, Value)> {
    let mut events: Vec<(String, Value)> = Vec::new();
    let mut name = String::new();
    let mut line = String::new();
    while !enough(&events) {
        line.clear();
        if reader.read_line(&mut line).unwrap() == 0 {
            break;
        }
        let line = line.trim_end();
        if let Some(n) = line.strip_prefix("event:") {
            name = n.trim().to_owned();
        } else if let Some(data) = line.strip_prefix("data:") {
            let text = data.trim();
            let value: Value = serde_json::from_str(text).unwrap_or_else(|e| panic!("{text}: {e}"));
            events.push((name.clone(), value));
        }
    }
    events
}

/// Opens a session's event stream.
fn event_stream(server: &Server, session: i64) -> BufReader<TcpStream> {
    let mut stream = TcpStream::connect(&server.address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    let head = format!(
        "GET /api/sessions/{session}/events HTTP/1.1\r\nHost: {}\r\nAccept: text/event-stream\r\n\r\n",
        server.address
    );
    stream.write_all(head.as_bytes()).unwrap();
    BufReader::new(stream)
}

#[test]
fn gardens_report_their_progress_while_they_grow() {
    let dir = temp_dir("progress");
    let server = start(&dir, "127.0.0.1");
    let garden = post(
        &server,
        "/api/sessions",
        json!({"mode": "garden", "settings": {"steps": 40, "children": 2}}),
    );
    let id = garden["id"].as_i64().unwrap();
    let mut events = event_stream(&server, id);
    // The stream is open once its head has come.
    let mut line = String::new();
    while events.read_line(&mut line).unwrap() > 0 && line != "\r\n" {
        line.clear();
    }
    let grown = std::thread::scope(|scope| {
        let grow = scope.spawn(|| {
            post(
                &server,
                &format!("/api/sessions/{id}/grow"),
                json!({"settings": {"steps": 60}}),
            )
        });
        let seen = read_events(&mut events, |e| {
            e.last().is_some_and(|(_, v)| v["step"] == v["steps"])
        });
        grow.join().unwrap();
        seen
    });
    let steps: Vec<u64> = grown
        .iter()
        .filter(|(name, v)| name == "progress" && v["what"] == "garden" && v["steps"] == 60)
        .map(|(_, v)| v["step"].as_u64().unwrap())
        .collect();
    assert!(steps.len() >= 10, "{grown:?}");
    assert!(steps.windows(2).all(|w| w[0] < w[1]), "{steps:?}");
    assert_eq!(steps.last(), Some(&60));
}

#[test]
fn design_runs_stream_valid_json_with_the_terms_named() {
    let dir = temp_dir("events");
    let server = start(&dir, "127.0.0.1");
    // A long run, stopped once two generations are seen: one that ended before the stream
    // opened would show only its final status (read below as the end, not waited past).
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "design", "design": {"population": 10, "generations": 400}}),
    );
    let id = session["id"].as_i64().unwrap();
    let mut stream = TcpStream::connect(&server.address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    let head = format!(
        "GET /api/sessions/{id}/events HTTP/1.1\r\nHost: {}\r\nAccept: text/event-stream\r\n\r\n",
        server.address
    );
    stream.write_all(head.as_bytes()).unwrap();
    let mut events: Vec<(String, Value)> = Vec::new();
    let mut reader = BufReader::new(stream);
    let mut name = String::new();
    let mut line = String::new();
    while events.iter().filter(|(n, _)| n == "generation").count() < 2 {
        line.clear();
        if reader.read_line(&mut line).unwrap() == 0 {
            break;
        }
        let line = line.trim_end();
        if let Some(n) = line
            .strip_prefix("event: ")
            .or_else(|| line.strip_prefix("event:"))
        {
            name = n.trim().to_owned();
        } else if let Some(data) = line
            .strip_prefix("data: ")
            .or_else(|| line.strip_prefix("data:"))
        {
            let text = data.trim();
            let value: Value = serde_json::from_str(text).unwrap_or_else(|e| panic!("{text}: {e}"));
            // Each key once: serde_json keeps the last of a repeated key, so count them.
            assert_eq!(text.matches("\"generation\"").count(), 1, "{text}");
            let ended = name == "status" && value["status"] != "running";
            events.push((name.clone(), value));
            if ended {
                break;
            }
        }
    }
    post(&server, &format!("/api/sessions/{id}/stop"), json!({}));
    let generations: Vec<&Value> = events
        .iter()
        .filter(|(n, _)| n == "generation")
        .map(|(_, v)| v)
        .collect();
    assert!(generations.len() >= 2, "{events:?}");
    for g in generations {
        let terms = g["terms"].as_array().unwrap();
        assert!(!terms.is_empty(), "{g}");
        assert_eq!(
            terms.len(),
            g["best_terms"].as_array().unwrap().len(),
            "{g}"
        );
        assert!(g["best"].is_number() && g["plant"].is_number(), "{g}");
    }
}

#[test]
fn two_tabs_breeding_one_session_at_once_take_turns() {
    let dir = temp_dir("tabs");
    let server = start(&dir, "127.0.0.1");
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "breed", "model": "bintree"}),
    );
    let id = session["id"].as_i64().unwrap();
    let g = grid(&session);
    let path = format!("/api/sessions/{id}/mutate");
    let answers: Vec<Value> = std::thread::scope(|scope| {
        let tabs: Vec<_> = g[..4]
            .iter()
            .map(|&plant| {
                let (server, path) = (&server, &path);
                scope.spawn(move || post(server, path, json!({"plant": plant, "children": 3})))
            })
            .collect();
        tabs.into_iter().map(|t| t.join().unwrap()).collect()
    });
    // Each step saw the one before it: four steps in the history, numbered 1 to 4, and the
    // grid holds the last step's parent and children at its head.
    let last = get(&server, &format!("/api/sessions/{id}"));
    let seqs: Vec<i64> = last["history"]
        .as_array()
        .unwrap()
        .iter()
        .map(|h| h["seq"].as_i64().unwrap())
        .collect();
    assert_eq!(seqs, [1, 2, 3, 4]);
    assert!(answers.iter().any(|a| a["state"] == last["state"]));
    let plants = get(&server, &format!("/api/plants?session={id}&limit=1000"));
    assert_eq!(plants["total"], g.len() + 4 * 3);
}

#[test]
fn beyond_loopback_every_request_needs_the_printed_token() {
    let dir = temp_dir("token");
    let server = start(&dir, "0.0.0.0");
    let token = server.token.clone().expect("a token is printed");
    assert_eq!(token.len(), 32);
    // The printed address is one a browser on this machine can open.
    assert!(
        server.address.starts_with("127.0.0.1:"),
        "{}",
        server.address
    );
    for path in ["/", "/api/models", "/vendor/three/build/three.module.js"] {
        let (status, body) = request(&server, "GET", path, b"", false);
        assert_eq!(status, 401, "{path}");
        assert!(String::from_utf8_lossy(&body).contains("token"));
    }
    let (status, _) = request(&server, "GET", "/api/models", b"", true);
    assert_eq!(status, 200);
    for scheme in ["bearer", "BEARER", "Bearer "] {
        let auth = format!("{scheme} {token}");
        let (status, _) = request_with(
            &server,
            "GET",
            "/api/models",
            &[("Authorization", &auth)],
            b"",
        );
        assert_eq!(status, 200, "{auth}");
    }
    let (status, _) = request(
        &server,
        "GET",
        &format!("/api/models?token={token}"),
        b"",
        false,
    );
    assert_eq!(status, 200);
    let (status, _) = request(&server, "GET", "/api/models?token=0000", b"", false);
    assert_eq!(status, 401);
    // Bound to every interface, any address names the studio; a name that could be rebound
    // to one does not.
    let auth = format!("Bearer {token}");
    for (host, status) in [
        ("10.1.2.3:80", 200),
        ("[fe80::1]", 200),
        ("evil.example", 403),
    ] {
        let (got, _) = request_with(
            &server,
            "GET",
            "/api/models",
            &[("Host", host), ("Authorization", &auth)],
            b"",
        );
        assert_eq!(got, status, "{host}");
    }
}

#[test]
fn gardens_and_families_step_and_undo() {
    let dir = temp_dir("garden");
    let server = start(&dir, "127.0.0.1");
    let garden = post(
        &server,
        "/api/sessions",
        json!({"mode": "garden", "settings": {"steps": 60, "children": 4}}),
    );
    let id = garden["id"].as_i64().unwrap();
    let specimens = garden["state"]["specimens"].as_array().unwrap().clone();
    assert_eq!(specimens.len(), 5);
    assert!(specimens[0]["is_mother"].as_bool().unwrap());
    assert!(
        specimens
            .iter()
            .all(|s| s["biomass"].as_f64().unwrap() > 0.0)
    );
    let pick = specimens[2]["plant"].as_i64().unwrap();
    let next = post(
        &server,
        &format!("/api/sessions/{id}/pick"),
        json!({"plant": pick}),
    );
    // The picked plant's body in her new garden is archived as her own plant.
    let mother = next["state"]["mother"].as_i64().unwrap();
    assert_ne!(mother, pick);
    let row = get(&server, &format!("/api/plants/{mother}"));
    assert_eq!(
        (row["operator"].as_str(), &row["parents"][0]["plant"]),
        (Some("mother"), &json!(pick))
    );
    assert_eq!(next["state"]["specimens"][0]["plant"], mother);
    let child = next["state"]["specimens"][1]["plant"].as_i64().unwrap();
    assert_eq!(
        get(&server, &format!("/api/plants/{child}"))["parents"][0]["plant"],
        mother
    );
    let lateral = post(
        &server,
        &format!("/api/sessions/{id}/grow"),
        json!({"settings": {"elevation": 30, "azimuth": 90}}),
    );
    assert_eq!(lateral["state"]["settings"]["elevation"], 30.0);
    let (status, glb) = request(
        &server,
        "GET",
        &format!("/api/sessions/{id}/garden.glb"),
        b"",
        true,
    );
    assert_eq!(status, 200);
    let file = dir.join("garden.glb");
    std::fs::write(&file, glb).unwrap();
    sylva_testkit::validate(std::slice::from_ref(&file));
    let undone = post(&server, &format!("/api/sessions/{id}/undo"), json!({}));
    assert_eq!(undone["state"], next["state"]);

    let family = post(
        &server,
        "/api/sessions",
        json!({"mode": "family", "config": {"run": {"population": 60, "seed": 3}}}),
    );
    let f = family["id"].as_i64().unwrap();
    let stepped = post(
        &server,
        &format!("/api/sessions/{f}/generations"),
        json!({"count": 5}),
    );
    assert_eq!(stepped["state"]["generation"], 5);
    let stats = get(&server, &format!("/api/sessions/{f}/stats"));
    assert_eq!(stats["generations"].as_array().unwrap().len(), 6);
    let best = post(
        &server,
        &format!("/api/sessions/{f}/member"),
        json!({"index": 0}),
    );
    let undone = post(&server, &format!("/api/sessions/{f}/undo"), json!({}));
    assert_eq!(undone["state"]["generation"], 0);
    assert_eq!(
        get(&server, &format!("/api/sessions/{f}/stats"))["generations"]
            .as_array()
            .unwrap()
            .len(),
        1
    );
    // Redo brings back the same generation exactly: the same best member.
    post(&server, &format!("/api/sessions/{f}/redo"), json!({}));
    let again = post(
        &server,
        &format!("/api/sessions/{f}/member"),
        json!({"index": 0}),
    );
    assert_eq!(again, best);
    assert_eq!(
        get(&server, &format!("/api/plants/{}", best["plant"]))["operator"],
        "family"
    );
}

/// Waits until a design run has made `generation` generations (or ended); its view.
fn wait_for(server: &Server, session: i64, generation: u64) -> Value {
    wait(server, session, |run| {
        run["generation"].as_u64().unwrap() >= generation
    })
}

/// Waits until a design run has ended; its view.
fn wait_end(server: &Server, session: i64) -> Value {
    wait(server, session, |_| false)
}

fn wait(server: &Server, session: i64, enough: impl Fn(&Value) -> bool) -> Value {
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let run = get(server, &format!("/api/sessions/{session}/run"));
        if enough(&run) || run["status"] != "running" {
            return run;
        }
        assert!(Instant::now() < deadline, "the run is stuck: {run}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_design_run_killed_mid_evolution_resumes_to_the_same_bytes() {
    let design = json!({"mode": "design", "design": {
        "population": 150, "generations": 12, "seed": 4, "num_target": 10,
        "target": {"shape": "cone", "base": [0, 0, 0], "radius": 100, "height": 300},
        "grid": {"min": [-200, 0, -200], "max": [200, 400, 200], "divisions": [4, 4, 4],
                 "cells": [{"cell": [0, 3, 0], "weight": -1}, {"cell": [1, 1, 1], "weight": 1}]}
    }});
    // Uninterrupted.
    let whole_dir = temp_dir("design-whole");
    let whole = start(&whole_dir, "127.0.0.1");
    let s = post(&whole, "/api/sessions", design.clone())["id"]
        .as_i64()
        .unwrap();
    let done = wait_end(&whole, s);
    assert_eq!(done["status"], "done", "{done}");
    assert_eq!(done["rows"].as_array().unwrap().len(), 13);
    assert!(
        done["terms"]
            .as_array()
            .unwrap()
            .iter()
            .any(|t| t == "f_grid")
    );

    // Killed twice in the middle, started again each time.
    let dir = temp_dir("design-killed");
    let mut server = start(&dir, "127.0.0.1");
    let s = post(&server, "/api/sessions", design)["id"]
        .as_i64()
        .unwrap();
    for at in [3, 7] {
        wait_for(&server, s, at);
        drop(server);
        server = start(&dir, "127.0.0.1");
    }
    let resumed = wait_end(&server, s);
    assert_eq!(resumed["status"], "done", "{resumed}");
    let figures = |run: &Value| -> Vec<(Value, Value, Value)> {
        run["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                (
                    r["best"].clone(),
                    r["mean"].clone(),
                    r["best_terms"].clone(),
                )
            })
            .collect()
    };
    assert_eq!(figures(&resumed), figures(&done));
    let best = |run: &Value| {
        run["rows"].as_array().unwrap().last().unwrap()["plant"]
            .as_i64()
            .unwrap()
    };
    let genome = |server: &Server, plant: i64| {
        request(
            server,
            "GET",
            &format!("/api/plants/{plant}/genome.json"),
            b"",
            true,
        )
        .1
    };
    assert_eq!(genome(&server, best(&resumed)), genome(&whole, best(&done)));

    // Stop and resume: a stop is kept across a kill, and resume goes on to more generations.
    let more = post(
        &server,
        &format!("/api/sessions/{s}/resume"),
        json!({"generations": 30}),
    );
    assert_eq!(more["mode"], "design");
    wait_for(&server, s, 14);
    post(&server, &format!("/api/sessions/{s}/stop"), json!({}));
    let stopped = get(&server, &format!("/api/sessions/{s}/run"));
    assert_eq!(stopped["status"], "stopped");
    drop(server);
    let server = start(&dir, "127.0.0.1");
    std::thread::sleep(Duration::from_millis(300));
    let after = get(&server, &format!("/api/sessions/{s}/run"));
    assert_eq!(after["status"], "stopped");
    assert!(after["generation"].as_u64().unwrap() <= stopped["generation"].as_u64().unwrap() + 1);
}

/// Waits until a map has had `generation` generations (or ended); its view.
fn wait_map(server: &Server, session: i64, generation: u64) -> Value {
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let map = get(server, &format!("/api/sessions/{session}/map"));
        if map["generation"].as_u64().unwrap() >= generation || map["status"] != "running" {
            return map;
        }
        assert!(Instant::now() < deadline, "the map is stuck: {map}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_map_fills_in_the_background_survives_a_kill_and_its_plants_branch_and_export() {
    let map = json!({"mode": "map", "map": {
        "model": "bintree", "generations": 1500, "seed": 3,
        "x": {"name": "height_to_width", "cells": 5},
        "y": {"name": "porosity", "cells": 4, "range": [0.0, 0.8]},
    }});
    // Uninterrupted.
    let whole_dir = temp_dir("map-whole");
    let whole = start(&whole_dir, "127.0.0.1");
    let s = post(&whole, "/api/sessions", map.clone())["id"]
        .as_i64()
        .unwrap();
    let done = wait_map(&whole, s, u64::MAX);
    assert_eq!(done["status"], "done", "{done}");
    assert_eq!(done["generation"], 1500);
    assert_eq!(
        done["axes"][1],
        json!({"name": "porosity", "min": 0.0, "max": 0.8, "cells": 4})
    );
    let cells = |map: &Value| -> Vec<(Value, Value, Value)> {
        map["cells"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                (
                    c["cell"].clone(),
                    c["fitness"].clone(),
                    c["descriptors"].clone(),
                )
            })
            .collect()
    };
    let filled = cells(&done).len();
    assert!(filled > 5 && filled <= 20, "{done}");
    let last = done["rows"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(last["generation"], 1500);
    assert_eq!(last["filled"], filled as f64);

    // Killed in the middle, started again.
    let dir = temp_dir("map-killed");
    let mut server = start(&dir, "127.0.0.1");
    let s = post(&server, "/api/sessions", map)["id"].as_i64().unwrap();
    wait_map(&server, s, 200);
    drop(server);
    server = start(&dir, "127.0.0.1");
    let resumed = wait_map(&server, s, u64::MAX);
    assert_eq!(resumed["status"], "done", "{resumed}");
    assert_eq!(cells(&resumed), cells(&done));
    let genome = |server: &Server, plant: &Value| {
        request(
            server,
            "GET",
            &format!("/api/plants/{plant}/genome.json"),
            b"",
            true,
        )
        .1
    };
    for (a, b) in resumed["cells"]
        .as_array()
        .unwrap()
        .iter()
        .zip(done["cells"].as_array().unwrap())
    {
        assert_eq!(genome(&server, &a["plant"]), genome(&whole, &b["plant"]));
    }

    // A cell's plant branches into breeding, and exports with wind and levels of detail.
    let plant = resumed["cells"][0]["plant"].as_i64().unwrap();
    let info = get(&server, &format!("/api/plants/{plant}"));
    assert_eq!(info["operator"], "map");
    let branched = post(&server, &format!("/api/plants/{plant}/branch"), json!({}));
    assert_eq!(branched["mode"], "breed");
    let (status, glb) = request(
        &server,
        "GET",
        &format!("/api/plants/{plant}/plant.glb?wind=true&lod=3"),
        b"",
        true,
    );
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&glb));
    let text = String::from_utf8_lossy(&glb);
    assert!(glb.starts_with(b"glTF") && text.contains("_LOD2") && text.contains("\"wind\""));
    assert!(
        text.contains("_LOD3") && text.contains("KHR_materials_unlit"),
        "the impostor"
    );
    let (status, _) = request(
        &server,
        "GET",
        &format!("/api/plants/{plant}/plant.glb?lod=9"),
        b"",
        true,
    );
    assert_eq!(status, 400);

    // Stop and resume: a stop is kept across a kill, and resume goes on.
    post(
        &server,
        &format!("/api/sessions/{s}/map/resume"),
        json!({"generations": 100000}),
    );
    wait_map(&server, s, 1600);
    post(&server, &format!("/api/sessions/{s}/map/stop"), json!({}));
    let stopped = wait_map(&server, s, 0);
    assert_eq!(stopped["status"], "stopped");
    drop(server);
    let server = start(&dir, "127.0.0.1");
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        get(&server, &format!("/api/sessions/{s}/map"))["status"],
        "stopped"
    );

    // A bad map names its field.
    for (body, field) in [
        (
            json!({"model": "bintree", "x": {"name": "leafiness"}}),
            "map.x.name",
        ),
        (
            json!({"model": "bintree", "x": {"name": "lean", "cells": 0}}),
            "map.x.cells",
        ),
        (
            json!({"model": "bintree", "x": {"name": "lean"}, "y": {"name": "lean"}}),
            "map.y.name",
        ),
        (json!({"model": "oak", "x": {"name": "lean"}}), "map.model"),
        (
            json!({"model": "bintree", "x": {"name": "lean", "range": [1, 0]}}),
            "map.x.range",
        ),
        (
            json!({"model": "bintree", "x": {"name": "lean"}, "generations": 0}),
            "map.generations",
        ),
    ] {
        let sent = json!({"mode": "map", "map": body});
        let answer = request(
            &server,
            "POST",
            "/api/sessions",
            sent.to_string().as_bytes(),
            true,
        );
        assert_refused(&sent.to_string(), answer, 400, field);
    }
    let descriptors = get(&server, "/api/descriptors");
    assert_eq!(descriptors.as_array().unwrap().len(), 8);
}

/// Waits until a match has made `generation` generations (or ended); its run's view.
fn wait_match(server: &Server, session: i64, generation: u64) -> Value {
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let run = get(server, &format!("/api/sessions/{session}/match/run"));
        if run["generation"].as_u64().unwrap() >= generation || run["status"] != "running" {
            return run;
        }
        assert!(Instant::now() < deadline, "the match is stuck: {run}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The round tuning outline: its bytes, and as a data URL for a match request.
fn round_picture() -> (Vec<u8>, String) {
    use base64::Engine;
    let round =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/match/round.png"))
            .unwrap();
    let url = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&round)
    );
    (round, url)
}

#[test]
fn a_match_to_a_picture_runs_live_survives_a_kill_and_shows_its_outline() {
    use base64::Engine;
    let (round, picture) = round_picture();
    let request_of = |model: &str, generations: u32| {
        json!({"mode": "match", "match": {
            "picture": picture, "model": model, "generations": generations,
            "population": 16, "seed": 2, "topiary": true,
        }})
    };
    // Uninterrupted.
    let whole_dir = temp_dir("match-whole");
    let whole = start(&whole_dir, "127.0.0.1");
    let s = post(&whole, "/api/sessions", request_of("bintree", 40))["id"]
        .as_i64()
        .unwrap();
    let done = wait_match(&whole, s, u64::MAX);
    assert_eq!(done["status"], "done", "{done}");
    assert_eq!(done["terms"], json!(["iou"]));
    let rows = done["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 41);
    let last = rows.last().unwrap();
    let iou = last["best_terms"][0].as_f64().unwrap();
    assert!(iou > 0.3 && iou <= 1.0, "{last}");
    assert!(last["best"].as_f64().unwrap() >= rows[0]["best"].as_f64().unwrap());
    // The target as given, and the best plant's outline over it.
    let (status, bytes) = request(
        &whole,
        "GET",
        &format!("/api/sessions/{s}/match/picture"),
        b"",
        true,
    );
    assert_eq!((status, bytes), (200, round.clone()));
    let plant = last["plant"].as_i64().unwrap();
    let (status, png) = request(
        &whole,
        "GET",
        &format!("/api/sessions/{s}/match/overlay.png?plant={plant}"),
        b"",
        true,
    );
    assert_eq!(status, 200);
    assert!(png.starts_with(b"\x89PNG"));
    assert_eq!(
        get(&whole, &format!("/api/plants/{plant}"))["operator"],
        "match"
    );
    // A topiary match's plants grow inside the outline, as the library prunes them, and so
    // does one branched into breeding; the offspring bred from it grow whole.
    let round_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/match/round.png");
    let target = sylva::evolution::MatchConfig {
        front: round_path.clone(),
        side: Some(round_path),
        threshold: sylva::picture::Threshold::default(),
        weight: 1.0,
        beside: false,
        rows: 64,
        closeness: 0.0,
        topiary: Some(true),
    };
    let space = sylva::evolution::outline::space(&target, Path::new("")).unwrap();
    let triangles = |plant: i64| {
        let path = format!("/api/plants/{plant}/plant.glb");
        let (status, glb) = request(&whole, "GET", &path, b"", true);
        assert_eq!(status, 200);
        let scene = sylva::import::read_glb(&glb).unwrap();
        scene
            .meshes
            .iter()
            .map(|(_, m)| m.triangle_count())
            .sum::<usize>()
    };
    let grown = |plant: i64, pruned_to| {
        let row = get(&whole, &format!("/api/plants/{plant}"));
        let text = row["genome_text"].as_str().unwrap();
        let options = sylva::GrowOptions {
            seed: row["seed"].as_u64(),
            pruned_to,
            ..sylva::GrowOptions::default()
        };
        let genome = sylva::Registry::standard()
            .parse_genome_at(Path::new("genome.json"), text)
            .unwrap();
        sylva::Grown::grow(genome, &options)
            .unwrap()
            .mesh
            .triangle_count()
    };
    let first = rows[0]["plant"].as_i64().unwrap();
    let (pruned, whole_plant) = (grown(first, space.clone()), grown(first, None));
    assert!(pruned < whole_plant, "{pruned} {whole_plant}");
    assert_eq!(triangles(first), pruned);
    let branched = post(&whole, &format!("/api/plants/{first}/branch"), json!({}));
    let cells = grid(&branched);
    let copy = get(&whole, &format!("/api/plants/{}", cells[0]));
    assert_eq!(copy["operator"], "branch");
    let run = get(&whole, &format!("/api/plants/{first}"))["settings"]["run"].clone();
    assert_eq!(copy["settings"]["pruned_to"], run);
    assert_eq!(triangles(cells[0]), pruned);
    let child = get(&whole, &format!("/api/plants/{}", cells[1]));
    assert_ne!(child["operator"], "branch");
    assert_eq!(triangles(cells[1]), grown(cells[1], None));

    // Killed in the middle, started again: the same run.
    let dir = temp_dir("match-killed");
    let mut server = start(&dir, "127.0.0.1");
    let k = post(&server, "/api/sessions", request_of("bintree", 40))["id"]
        .as_i64()
        .unwrap();
    wait_match(&server, k, 10);
    drop(server);
    server = start(&dir, "127.0.0.1");
    let resumed = wait_match(&server, k, u64::MAX);
    assert_eq!(resumed["status"], "done", "{resumed}");
    let figures = |run: &Value| -> Vec<(Value, Value)> {
        run["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| (r["best"].clone(), r["best_terms"].clone()))
            .collect()
    };
    assert_eq!(figures(&resumed), figures(&done));
    let genome = |server: &Server, run: &Value| {
        let plant = run["rows"].as_array().unwrap().last().unwrap()["plant"].clone();
        request(
            server,
            "GET",
            &format!("/api/plants/{plant}/genome.json"),
            b"",
            true,
        )
        .1
    };
    assert_eq!(genome(&server, &resumed), genome(&whole, &done));
    // Its pictures came back from the archive: the overlay still draws.
    let plant = resumed["rows"].as_array().unwrap().last().unwrap()["plant"].clone();
    let (status, _) = request(
        &server,
        "GET",
        &format!("/api/sessions/{k}/match/overlay.png?plant={plant}"),
        b"",
        true,
    );
    assert_eq!(status, 200);

    // Auto tries each model and goes on with the best; the session says which.
    let a = post(&server, "/api/sessions", request_of("auto", 10))["id"]
        .as_i64()
        .unwrap();
    let auto = wait_match(&server, a, u64::MAX);
    assert_eq!(auto["status"], "done", "{auto}");
    let session = get(&server, &format!("/api/sessions/{a}"));
    assert!(
        ["bintree", "automata", "plantmaker", "lsystem", "grown"]
            .contains(&session["model"].as_str().unwrap())
    );
    // The model the run went on with: its plants', in the session and in the list.
    let best = auto["rows"].as_array().unwrap().last().unwrap()["plant"].clone();
    let model = get(&server, &format!("/api/plants/{best}"))["model"].clone();
    assert_eq!(session["model"], model);
    let listed = get(&server, "/api/sessions");
    let entry = listed
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["id"] == a)
        .unwrap();
    assert_eq!(entry["model"], model);

    // Bad pictures and numbers are refused naming their fields, and keep nothing.
    let sessions = get(&server, "/api/sessions").as_array().unwrap().len();
    let text = base64::engine::general_purpose::STANDARD.encode(b"not a picture at all");
    for (body, field) in [
        (json!({"picture": text}), "match.picture"),
        (json!({"picture": "%%%"}), "match.picture"),
        (json!({"picture": picture, "side": text}), "match.side"),
        (json!({"picture": picture, "model": "oak"}), "match.model"),
        (
            json!({"picture": picture, "generations": 0}),
            "match.generations",
        ),
        (
            json!({"picture": picture, "population": 1}),
            "match.population",
        ),
    ] {
        let sent = json!({"mode": "match", "match": body});
        let answer = request(
            &server,
            "POST",
            "/api/sessions",
            sent.to_string().as_bytes(),
            true,
        );
        assert_refused(field, answer, 400, field);
    }
    assert_eq!(
        get(&server, "/api/sessions").as_array().unwrap().len(),
        sessions
    );
}

/// The figures of an auto match's trials, as the run's view lists them (wall-clock seconds
/// left out).
fn trial_figures(run: &Value) -> Vec<Value> {
    (run["trials"].as_array().unwrap().iter())
        .map(|t| {
            json!([
                t["model"],
                t["runoff"],
                t["generation"],
                t["best"],
                t["mean"],
                t["iou"]
            ])
        })
        .collect()
}

#[test]
fn an_auto_matchs_trials_are_shown_recorded_and_survive_a_kill() {
    let (_, picture) = round_picture();
    let asked = json!({"mode": "match", "match": {
        "picture": picture, "model": "auto", "generations": 25, "population": 8, "seed": 4,
    }});
    // Uninterrupted: each trial generation is told as it is bred, and recorded.
    let whole_dir = temp_dir("auto-whole");
    let whole = start(&whole_dir, "127.0.0.1");
    let s = post(&whole, "/api/sessions", asked.clone())["id"]
        .as_i64()
        .unwrap();
    let mut events = event_stream(&whole, s);
    // A trial told as it begins, then its generations (the run's own come after).
    let begun_then_bred = |e: &[(String, Value)]| {
        e.iter().enumerate().any(|(i, (n, b))| {
            n == "trial-begun"
                && (e[i + 1..].iter()).any(|(m, t)| m == "trial" && t["model"] == b["model"])
        })
    };
    let told = read_events(&mut events, |e| {
        begun_then_bred(e) || e.iter().any(|(n, _)| n == "generation")
    });
    assert!(begun_then_bred(&told), "the trials told nothing: {told:?}");
    let (_, trial) = told.iter().rev().find(|(n, _)| n == "trial").unwrap();
    for key in [
        "model",
        "runoff",
        "generation",
        "best",
        "mean",
        "iou",
        "plant",
    ] {
        assert!(
            !trial[key].is_null(),
            "a trial event without {key}: {trial}"
        );
    }
    let done = wait_match(&whole, s, u64::MAX);
    assert_eq!(done["status"], "done", "{done}");
    let rows = done["rows"].as_array().unwrap();
    let chosen = get(&whole, &format!("/api/sessions/{s}"))["model"].clone();
    // The chosen model's trial generations are the run's first: generations 0 to 25.
    assert_eq!(rows.len(), 26, "{done}");
    assert_eq!(rows[0]["generation"], 0);
    // Every model that bred, generations 0 to 2 of its trial; the best two, 3 to 5 of
    // the run-off; each generation's best archived as a plant of its model.
    let ended = done["ended"].as_array().unwrap();
    let runoffs: Vec<&Value> = ended.iter().filter(|t| t["runoff"] == true).collect();
    assert_eq!(runoffs.len(), 2, "{done}");
    assert!(runoffs.iter().any(|t| t["model"] == chosen));
    let trials = done["trials"].as_array().unwrap();
    let bred = ended.iter().filter(|t| t["outcome"]["reached"].is_object());
    assert_eq!(trials.len(), 3 * bred.count(), "{done}");
    for t in trials {
        let runoff = t["runoff"] == true;
        let generation = t["generation"].as_u64().unwrap();
        assert_eq!(generation >= 3, runoff, "{t}");
        let plant = get(&whole, &format!("/api/plants/{}", t["plant"]));
        assert_eq!(plant["model"], t["model"], "{t}");
        assert_eq!(plant["operator"], "match");
    }
    let (status, png) = request(
        &whole,
        "GET",
        &format!(
            "/api/sessions/{s}/match/overlay.png?plant={}",
            trials[0]["plant"]
        ),
        b"",
        true,
    );
    assert!(status == 200 && png.starts_with(b"\x89PNG"));

    // Killed as soon as the first trial is kept, during the others; started again.
    let dir = temp_dir("auto-killed");
    let server = start(&dir, "127.0.0.1");
    let k = post(&server, "/api/sessions", asked)["id"]
        .as_i64()
        .unwrap();
    let path = format!("/api/sessions/{k}/match/run");
    let deadline = Instant::now() + Duration::from_secs(300);
    while get(&server, &path)["ended"].as_array().unwrap().is_empty() {
        assert!(Instant::now() < deadline, "no trial ended");
        std::thread::sleep(Duration::from_millis(5));
    }
    drop(server);
    let server = start(&dir, "127.0.0.1");
    let after = get(&server, &path);
    assert!(
        after["rows"].as_array().unwrap().is_empty(),
        "killed after the trials: {after}"
    );
    let kept = after["ended"][0].clone();
    assert_eq!(kept["model"], "bintree", "{after}");
    let resumed = wait_match(&server, k, u64::MAX);
    assert_eq!(resumed["status"], "done", "{resumed}");
    // The trial kept was not bred again (its wall-clock seconds are the ones kept), and the
    // match ended as the one never killed: its trials, its generations, its best plant.
    assert_eq!(resumed["ended"][0], kept);
    assert_eq!(trial_figures(&resumed), trial_figures(&done));
    let figures = |run: &Value| -> Vec<(Value, Value)> {
        (run["rows"].as_array().unwrap().iter())
            .map(|r| (r["best"].clone(), r["best_terms"].clone()))
            .collect()
    };
    assert_eq!(figures(&resumed), figures(&done));
    let genome = |server: &Server, run: &Value| {
        let plant = run["rows"].as_array().unwrap().last().unwrap()["plant"].clone();
        request(
            server,
            "GET",
            &format!("/api/plants/{plant}/genome.json"),
            b"",
            true,
        )
        .1
    };
    assert_eq!(genome(&server, &resumed), genome(&whole, &done));
}

/// A PlantMaker plant of a match, branched into breeding, keeps the match's leaf greens and
/// bark browns when bred by hand (`palette = "foliage"`), where the model's defaults let a
/// fan's colours drift anywhere.
#[test]
fn plants_branched_from_a_match_breed_in_its_colours() {
    use sylva_plantmaker::{Palette, PlantMaker, PlantMakerModel};
    let (_, picture) = round_picture();
    let dir = temp_dir("match-colours");
    let server = start(&dir, "127.0.0.1");
    let request = json!({"mode": "match", "match": {
        "picture": picture, "model": "plantmaker", "generations": 1,
        "population": 4, "seed": 3,
    }});
    let s = post(&server, "/api/sessions", request)["id"]
        .as_i64()
        .unwrap();
    let done = wait_match(&server, s, u64::MAX);
    assert_eq!(done["status"], "done", "{done}");
    let best = done["rows"].as_array().unwrap().last().unwrap()["plant"]
        .as_i64()
        .unwrap();
    let genome_of = |plant: i64| -> sylva::Genome {
        let row = get(&server, &format!("/api/plants/{plant}"));
        sylva::Registry::standard()
            .parse_genome_at(
                Path::new("genome.json"),
                row["genome_text"].as_str().unwrap(),
            )
            .unwrap()
    };
    let in_foliage = |g: &sylva::Genome| {
        let g: &PlantMaker = g.get::<PlantMakerModel>().unwrap();
        let mut kept = g.clone();
        Palette::Foliage.apply(&mut kept);
        // Colours are bytes: one at the palette's edge may move by a unit when applied again.
        let near = |a: sylva_plantmaker::Rgb, b: sylva_plantmaker::Rgb| {
            a.0.iter().zip(b.0).all(|(&x, y)| x.abs_diff(y) <= 2)
        };
        (g.fans.iter().zip(&kept.fans))
            .all(|(f, k)| near(f.min_color, k.min_color) && near(f.max_color, k.max_color))
    };
    assert!(in_foliage(&genome_of(best)));
    let branched = post(&server, &format!("/api/plants/{best}/branch"), json!({}));
    let id = branched["id"].as_i64().unwrap();
    let cells = grid(&branched);
    // The grid's fill (Depth 2 mutants), then mutants of Depth 10 and a crossover.
    assert!(cells[1..].iter().all(|&c| in_foliage(&genome_of(c))));
    let mutated = post(
        &server,
        &format!("/api/sessions/{id}/mutate"),
        json!({"plant": cells[0], "depth": 10, "seed": 7}),
    );
    let mutants = grid(&mutated);
    assert_eq!(mutants.len(), 9);
    assert!(mutants.iter().all(|&c| in_foliage(&genome_of(c))));
    let crossed = post(
        &server,
        &format!("/api/sessions/{id}/cross"),
        json!({"parents": [{"plant": mutants[1], "dominance": 1.0}, {"plant": mutants[2], "dominance": 1.0}], "level": "high"}),
    );
    assert!(grid(&crossed).iter().all(|&c| in_foliage(&genome_of(c))));
    // Without the match's settings, the same Depth takes colours out of the palette.
    let parent = genome_of(cells[0]);
    let knobs = sylva::Knobs {
        depth: sylva::Depth::new(10).unwrap(),
        ..sylva::Knobs::default()
    };
    let drifted = (0..8)
        .map(|seed| parent.mutate(sylva::Settings::Knobs(knobs), seed).unwrap())
        .filter(|child| !in_foliage(child))
        .count();
    assert!(drifted > 0, "the default palette kept every colour");
}
