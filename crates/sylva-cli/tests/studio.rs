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

#[path = "../../sylva/tests/common/mod.rs"]
mod common;

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

/// A folder that stands in for the installed three.js (the page's files are not under test
/// here; the browser test loads the real one).
fn three(dir: &Path) -> PathBuf {
    let three = dir.join("three");
    std::fs::create_dir_all(three.join("build")).unwrap();
    std::fs::write(
        three.join("build/three.module.js"),
        "export const REVISION = 'test';\n",
    )
    .unwrap();
    three
}

fn start(dir: &Path, host: &str) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(["studio", "--port", "0", "--host", host, "--db"])
        .arg(dir.join("studio.db"))
        .arg("--three")
        .arg(three(dir))
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

/// One HTTP/1.1 request; the status and the body.
fn request(server: &Server, method: &str, path: &str, body: &[u8], auth: bool) -> (u16, Vec<u8>) {
    let mut stream = TcpStream::connect(&server.address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    let auth = match (&server.token, auth) {
        (Some(t), true) => format!("Authorization: Bearer {t}\r\n"),
        _ => String::new(),
    };
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n{auth}Content-Type: application/json\r\nContent-Length: {}\r\n\r\n",
        server.address,
        body.len()
    );
    stream.write_all(head.as_bytes()).unwrap();
    // A server may answer (413) before reading the whole of a large body.
    let _ = stream.write_all(body);
    let mut response = Vec::new();
    let _ = stream.read_to_end(&mut response);
    let split = response
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("a response head");
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
    assert_eq!(first.len(), 5, "the five PlantMaker examples: {session}");

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
    assert_eq!(
        get(&server, &format!("/api/plants/{}", g3[1]))["operator"],
        "regrow"
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
    common::validate(std::slice::from_ref(&file));
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

#[test]
fn hostile_requests_get_a_4xx_that_names_the_field() {
    let dir = temp_dir("hostile");
    let server = start(&dir, "127.0.0.1");
    let session = post(
        &server,
        "/api/sessions",
        json!({"mode": "breed", "model": "bintree", "start": {"random": 3}}),
    );
    let id = session["id"].as_i64().unwrap();
    let p = grid(&session);
    let big = vec![b'x'; 2 << 20];
    let cases: Vec<(&str, String, Vec<u8>, u16, &str)> = vec![
        ("POST", "/api/sessions".into(), b"{".to_vec(), 400, ""),
        ("POST", "/api/sessions".into(), br#"{"mode": "jungle"}"#.to_vec(), 400, "mode"),
        ("POST", "/api/sessions".into(), br#"{"mode": "breed", "model": "oak"}"#.to_vec(), 400, "model"),
        ("POST", "/api/sessions".into(), br#"{"mode": "breed", "start": {"random": 0}}"#.to_vec(), 400, "start.random"),
        ("POST", "/api/sessions".into(), br#"{"mode": "breed", "start": {"random": 1e99}}"#.to_vec(), 400, ""),
        ("POST", "/api/sessions".into(), br#"{"mode": "breed", "start": {"examples": ["nope"]}}"#.to_vec(), 400, "start.examples[0]"),
        ("POST", "/api/sessions".into(), br#"{"mode": "breed", "start": {"genomes": ["{\"model\": \"bintree\", \"format\": 1, \"depth\": -4}"]}}"#.to_vec(), 422, "start.genomes[0]"),
        ("POST", "/api/sessions".into(), br#"{"mode": "breed", "colour": "red"}"#.to_vec(), 400, ""),
        ("POST", "/api/sessions".into(), br#"{"mode": "family", "config": {"run": {"population": -3}}}"#.to_vec(), 422, "config.run.population"),
        ("POST", "/api/sessions".into(), br#"{"mode": "family", "config": {"run": {"population": 20000}}}"#.to_vec(), 400, "config.run.population"),
        ("POST", "/api/sessions".into(), br#"{"mode": "design", "design": {"population": 5}}"#.to_vec(), 400, "design.population"),
        ("POST", "/api/sessions".into(), br#"{"mode": "design", "design": {"target": {"shape": "sphere", "radius": -1}}}"#.to_vec(), 422, "design.target.radius"),
        ("POST", "/api/sessions".into(), br#"{"mode": "garden", "settings": {"elevation": 91}}"#.to_vec(), 400, "settings.elevation"),
        ("POST", "/api/sessions".into(), big.clone(), 413, ""),
        ("POST", format!("/api/sessions/{id}/cross"), format!(r#"{{"parents": [{{"plant": {}}}]}}"#, p[0]).into_bytes(), 400, "parents"),
        ("POST", format!("/api/sessions/{id}/cross"), format!(r#"{{"parents": [{{"plant": {}}}, {{"plant": {}, "dominance": -1}}]}}"#, p[0], p[1]).into_bytes(), 400, "parents[1].dominance"),
        ("POST", format!("/api/sessions/{id}/cross"), format!(r#"{{"parents": [{{"plant": {}}}, {{"plant": {}}}], "children": 10}}"#, p[0], p[1]).into_bytes(), 400, "children"),
        ("POST", format!("/api/sessions/{id}/cross"), format!(r#"{{"parents": [{{"plant": {}}}, {{"plant": {}}}], "level": "max"}}"#, p[0], p[1]).into_bytes(), 400, "level"),
        ("POST", format!("/api/sessions/{id}/cross"), format!(r#"{{"parents": [{{"plant": {}}}, {{"plant": 999999}}]}}"#, p[0]).into_bytes(), 400, "parents[1]"),
        ("POST", format!("/api/sessions/{id}/mutate"), format!(r#"{{"plant": {}, "depth": 11}}"#, p[0]).into_bytes(), 400, "depth"),
        ("POST", format!("/api/sessions/{id}/mutate"), format!(r#"{{"plant": {}, "seed": -1}}"#, p[0]).into_bytes(), 400, "seed"),
        ("POST", format!("/api/sessions/{id}/edit"), format!(r#"{{"plant": {}, "genome": "{{\"model\": \"bintree\"}}"}}"#, p[0]).into_bytes(), 422, "genome"),
        ("POST", format!("/api/sessions/{id}/edit"), format!(r#"{{"plant": {}}}"#, p[0]).into_bytes(), 400, "genome"),
        ("POST", format!("/api/sessions/{id}/grow"), b"{}".to_vec(), 409, ""),
        ("POST", format!("/api/sessions/{id}/redo"), b"".to_vec(), 409, ""),
        ("POST", "/api/sessions/424242/undo".into(), b"".to_vec(), 404, ""),
        ("GET", "/api/sessions/abc".into(), b"".to_vec(), 400, ""),
        ("GET", "/api/plants/424242/plant.glb".into(), b"".to_vec(), 404, ""),
        ("GET", format!("/api/plants/{}/plant.png?size=99999x2", p[0]), b"".to_vec(), 400, "size"),
        ("GET", format!("/api/plants/{}/plant.png?view=under", p[0]), b"".to_vec(), 400, "view"),
        ("GET", format!("/api/plants/{}/lineage?depth=0", p[0]), b"".to_vec(), 400, "depth"),
        ("GET", "/api/plants?limit=100000".into(), b"".to_vec(), 400, "limit"),
        ("GET", "/api/nothing".into(), b"".to_vec(), 404, ""),
        ("GET", format!("/api/plants/{}/plant_tex99999.png", p[0]), b"".to_vec(), 404, ""),
        ("GET", format!("/api/plants/{}/secrets.txt", p[0]), b"".to_vec(), 404, ""),
        ("GET", "/vendor/three/../../../../etc/passwd".into(), b"".to_vec(), 404, ""),
        ("GET", "/vendor/three/build/three.module.js".into(), b"".to_vec(), 200, ""),
    ];
    for (method, path, body, status, field) in &cases {
        let (got, answer) = request(&server, method, path, body, true);
        let text = String::from_utf8_lossy(&answer);
        assert_eq!(got, *status, "{method} {path}: {text}");
        if *status >= 400 && path.starts_with("/api") {
            let answer: Value = serde_json::from_slice(&answer)
                .unwrap_or_else(|_| panic!("{path}: JSON error, got {text}"));
            assert!(!answer["error"].as_str().unwrap().is_empty());
            assert_eq!(answer["field"], *field, "{method} {path}: {text}");
        }
    }
    // The server is still up and the session untouched.
    assert_eq!(
        get(&server, &format!("/api/sessions/{id}"))["history"],
        json!([])
    );
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
    let local = Server {
        child: Command::new("true").spawn().unwrap(),
        address: server.address.replace("0.0.0.0", "127.0.0.1"),
        token: Some(token.clone()),
    };
    for path in ["/", "/api/models", "/vendor/three/build/three.module.js"] {
        let (status, body) = request(&local, "GET", path, b"", false);
        assert_eq!(status, 401, "{path}");
        assert!(String::from_utf8_lossy(&body).contains("token"));
    }
    let (status, _) = request(&local, "GET", "/api/models", b"", true);
    assert_eq!(status, 200);
    let (status, _) = request(
        &local,
        "GET",
        &format!("/api/models?token={token}"),
        b"",
        false,
    );
    assert_eq!(status, 200);
    let (status, _) = request(&local, "GET", "/api/models?token=0000", b"", false);
    assert_eq!(status, 401);
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
    assert_eq!(next["state"]["mother"], pick);
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
    common::validate(std::slice::from_ref(&file));
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
