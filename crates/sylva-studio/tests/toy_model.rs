//! A studio given its own registry serves a model outside Sylva's four: the toy cylinder of
//! `sylva_testkit::toy` is listed, started, crossed, mutated, exported and archived through
//! the same endpoints as the standard models, and a studio of the standard registry does
//! not know it.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use axum::body::Body;
use axum::http::{Request, StatusCode};
use serde_json::{Value, json};
use sylva::{ModelEntry, Registry};
use sylva_studio::guard::Guard;
use sylva_studio::{Archive, Studio, router};
use sylva_testkit::toy::Cylinder;
use tower::ServiceExt;

fn send(studio: &Studio, method: &str, path: &str, body: Option<Value>) -> (StatusCode, Vec<u8>) {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let mut request = Request::builder()
            .method(method)
            .uri(path)
            .header("host", "127.0.0.1");
        if body.is_some() {
            request = request.header("content-type", "application/json");
        }
        let body = body.map_or_else(Body::empty, |b| Body::from(b.to_string()));
        let response = router(studio.clone())
            .oneshot(request.body(body).unwrap())
            .await
            .unwrap();
        let status = response.status();
        let bytes = axum::body::to_bytes(response.into_body(), usize::MAX)
            .await
            .unwrap();
        (status, bytes.to_vec())
    })
}

fn json_of(studio: &Studio, method: &str, path: &str, body: Option<Value>) -> Value {
    let (status, bytes) = send(studio, method, path, body);
    assert_eq!(
        status,
        StatusCode::OK,
        "{method} {path}: {}",
        String::from_utf8_lossy(&bytes)
    );
    serde_json::from_slice(&bytes).unwrap()
}

fn studio(name: &str, registry: Registry) -> (Studio, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("sylva-toy-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let archive = Archive::open(&dir.join("studio.db")).unwrap();
    (
        Studio::with_registry(archive, Guard::default(), registry),
        dir,
    )
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
fn a_studio_of_a_users_registry_breeds_its_models() {
    let registry = Registry::standard()
        .clone()
        .with(ModelEntry::of::<Cylinder>());
    let (studio, dir) = studio("own", registry);
    // Listed, with the modes that hold every model's plants.
    let models = json_of(&studio, "GET", "/api/models", None);
    let cylinder = models
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == "cylinder")
        .cloned()
        .unwrap_or_else(|| panic!("listed: {models}"));
    assert_eq!(cylinder["title"], "Cylinders");
    assert_eq!(cylinder["modes"], json!(["breed", "match", "map"]));
    // Started at random, crossed and mutated.
    let session = json_of(
        &studio,
        "POST",
        "/api/sessions",
        Some(json!({"mode": "breed", "model": "cylinder", "start": {"random": 4}, "seed": 3})),
    );
    assert_eq!(session["model"], "cylinder");
    let id = session["id"].as_i64().unwrap();
    let plants = grid(&session);
    assert_eq!(plants.len(), 9, "filled to nine: {session}");
    let crossed = json_of(
        &studio,
        "POST",
        &format!("/api/sessions/{id}/cross"),
        Some(json!({"parents": [{"plant": plants[0]}, {"plant": plants[1]}], "seed": 1})),
    );
    let child = grid(&crossed)[2];
    let row = json_of(&studio, "GET", &format!("/api/plants/{child}"), None);
    assert_eq!(row["model"], "cylinder");
    assert_eq!(row["operator"], "cross");
    let parent_height = |p: i64| {
        json_of(&studio, "GET", &format!("/api/plants/{p}"), None)["genome"]["height"].clone()
    };
    assert_eq!(row["genome"]["height"], parent_height(plants[0]));
    let mutated = json_of(
        &studio,
        "POST",
        &format!("/api/sessions/{id}/mutate"),
        Some(json!({"plant": child, "depth": 5, "seed": 2})),
    );
    assert_eq!(grid(&mutated)[0], child);
    // Exported like any plant, carrying its genome.
    let (status, glb) = send(
        &studio,
        "GET",
        &format!("/api/plants/{child}/plant.glb"),
        None,
    );
    assert_eq!(status, StatusCode::OK);
    assert_eq!(&glb[..4], b"glTF");
    assert!(String::from_utf8_lossy(&glb).contains(r#""model":"cylinder""#));
    let (status, file) = send(
        &studio,
        "GET",
        &format!("/api/plants/{child}/genome.json"),
        None,
    );
    assert_eq!(status, StatusCode::OK);
    assert!(String::from_utf8_lossy(&file).contains(r#""model": "cylinder""#));
    // A map of its plants (it has no example map: its own settings and the default map).
    let map = json_of(
        &studio,
        "POST",
        "/api/sessions",
        Some(json!({"mode": "map", "map": {
            "model": "cylinder", "x": {"name": "height_to_width", "cells": 4}, "generations": 5,
        }})),
    );
    let m = map["id"].as_i64().unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(300);
    let done = loop {
        let view = json_of(&studio, "GET", &format!("/api/sessions/{m}/map"), None);
        if view["status"] != "running" {
            break view;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "the map is stuck: {view}"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    assert_eq!(done["status"], "done", "{done}");
    let cells = done["cells"].as_array().unwrap();
    assert!(!cells.is_empty(), "{done}");
    let elite = json_of(
        &studio,
        "GET",
        &format!("/api/plants/{}", cells[0]["plant"]),
        None,
    );
    assert_eq!(elite["model"], "cylinder");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_studio_of_the_standard_registry_does_not_know_it() {
    let (studio, dir) = studio("standard", Registry::standard().clone());
    let (status, body) = send(
        &studio,
        "POST",
        "/api/sessions",
        Some(json!({"mode": "breed", "model": "cylinder", "start": {"random": 2}})),
    );
    assert_eq!(status, StatusCode::BAD_REQUEST);
    let error: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(error["field"], "model");
    std::fs::remove_dir_all(&dir).unwrap();
}
