//! The studio's breeding steps through its real router and a real archive file, as the
//! page makes them: nine PlantMaker offspring developed, previewed for the grid (simplified,
//! meshed, encoded as GLB) and stored; a random start of nine; a garden step of nine L-system
//! plants grown for 100 steps.
//!
//! And the plant panel's sketch (`POST /api/plants/{id}/sketch.png`: the plant with a field
//! set, grown, previewed and drawn at 320 × 320) of every example the studio offers, species
//! presets' genomes included, each with its first shape-moving number set halfway along its
//! slider: what a moving slider waits for, less the browser's decoding of the PNG.
//!
//! Run with `cargo bench -p sylva-studio --bench steps` (`-- sketch` for the sketches alone).
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use axum::body::Body;
use axum::http::{Request, StatusCode};
use criterion::{Criterion, criterion_group, criterion_main};
use serde_json::{Value, json};
use sylva::schema::{Kind, Schema};
use sylva_studio::guard::Guard;
use sylva_studio::{Archive, Studio, router};
use tower::ServiceExt;

fn call(runtime: &tokio::runtime::Runtime, studio: &Studio, path: &str, body: &Value) -> Value {
    serde_json::from_slice(&send(runtime, studio, "POST", path, body)).unwrap()
}

fn get(runtime: &tokio::runtime::Runtime, studio: &Studio, path: &str) -> Value {
    serde_json::from_slice(&send(runtime, studio, "GET", path, &Value::Null)).unwrap()
}

fn send(
    runtime: &tokio::runtime::Runtime,
    studio: &Studio,
    method: &str,
    path: &str,
    body: &Value,
) -> Vec<u8> {
    runtime.block_on(async {
        let body = if body.is_null() {
            Body::empty()
        } else {
            Body::from(body.to_string())
        };
        let request = Request::builder()
            .method(method)
            .uri(path)
            .header("host", "127.0.0.1")
            .header("content-type", "application/json")
            .body(body)
            .unwrap();
        let response = router(studio.clone()).oneshot(request).await.unwrap();
        assert_eq!(response.status(), StatusCode::OK, "{method} {path}");
        axum::body::to_bytes(response.into_body(), usize::MAX)
            .await
            .unwrap()
            .to_vec()
    })
}

fn steps(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("sylva-studio-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let archive = Archive::open(&dir.join("bench.db")).unwrap();
    let studio = Studio::new(archive, Guard::default());
    for id in 0..127 {
        sylva::mesh::texture::texture_png(id).unwrap();
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .unwrap();

    let session = call(
        &runtime,
        &studio,
        "/api/sessions",
        &json!({"mode": "breed"}),
    );
    let id = session["id"].as_i64().unwrap();
    let grid: Vec<i64> = session["state"]["grid"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["plant"].as_i64().unwrap())
        .collect();
    let mut group = c.benchmark_group("studio");
    group.sample_size(20);
    // The fern and the tulip crossed, nine children (the parents stay in the archive).
    let mut seed = 0u64;
    group.bench_function("breed: cross two examples, nine offspring", |b| {
        b.iter(|| {
            seed += 1;
            call(
                &runtime,
                &studio,
                &format!("/api/sessions/{id}/cross"),
                &json!({"parents": [{"plant": grid[0]}, {"plant": grid[1]}], "children": 9, "seed": seed}),
            )
        })
    });
    group.bench_function("breed: mutate an example, nine offspring", |b| {
        b.iter(|| {
            seed += 1;
            call(
                &runtime,
                &studio,
                &format!("/api/sessions/{id}/mutate"),
                &json!({"plant": grid[2], "children": 9, "seed": seed}),
            )
        })
    });
    // A random start: nine random PlantMaker plants (up to a million triangles each) grown,
    // archived and previewed for the grid (textures made already, as the studio makes them
    // while it starts).
    group.bench_function("breed: a random start of nine PlantMaker plants", |b| {
        b.iter(|| {
            seed += 1;
            call(
                &runtime,
                &studio,
                "/api/sessions",
                &json!({"mode": "breed", "start": {"random": 9}, "seed": seed}),
            )
        })
    });
    let garden = call(
        &runtime,
        &studio,
        "/api/sessions",
        &json!({"mode": "garden", "settings": {"steps": 100, "spacing": 2.5}}),
    );
    let g = garden["id"].as_i64().unwrap();
    group.bench_function("garden: nine L-system plants, 100 steps", |b| {
        b.iter(|| {
            call(
                &runtime,
                &studio,
                &format!("/api/sessions/{g}/grow"),
                &json!({"settings": {"steps": 100, "children": 8}}),
            )
        })
    });
    group.finish();
    drop(studio);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The plant panel's sketch of every example, one field moved.
fn sketches(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("sylva-studio-sketch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let studio = Studio::new(
        Archive::open(&dir.join("bench.db")).unwrap(),
        Guard::default(),
    );
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .unwrap();
    let examples = get(&runtime, &studio, "/api/examples");
    let mut by_model: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    for e in examples.as_array().unwrap() {
        let (name, model) = (e["name"].as_str().unwrap(), e["model"].as_str().unwrap());
        by_model
            .entry(model.to_owned())
            .or_default()
            .push(name.to_owned());
    }
    let mut group = c.benchmark_group("sketch");
    group.sample_size(10);
    group.warm_up_time(std::time::Duration::from_millis(500));
    group.measurement_time(std::time::Duration::from_secs(2));
    for (model, names) in by_model {
        let schema = studio.registry.get(&model).unwrap().schema();
        for chunk in names.chunks(9) {
            let session = call(
                &runtime,
                &studio,
                "/api/sessions",
                &json!({"mode": "breed", "model": model, "start": {"examples": chunk}}),
            );
            let plants = get(
                &runtime,
                &studio,
                &format!("/api/plants?session={}", session["id"]),
            );
            for listed in plants["plants"].as_array().unwrap() {
                let plant = get(&runtime, &studio, &format!("/api/plants/{}", listed["id"]));
                let Some(name) = plant["settings"]["example"].as_str() else {
                    continue;
                };
                let Some((path, value)) = halfway(&schema, &plant) else {
                    continue;
                };
                let body = json!({"fields": [{"path": path, "value": value}]});
                let url = format!("/api/plants/{}/sketch.png", plant["id"]);
                group.bench_function(format!("{name}: {path}"), |b| {
                    b.iter(|| send(&runtime, &studio, "POST", &url, &body))
                });
            }
        }
    }
    group.finish();
    drop(studio);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The plant's first shape-moving number and the value halfway along its slider.
fn halfway(schema: &Schema, plant: &Value) -> Option<(String, Value)> {
    plant["fields"].as_array()?.iter().find_map(|f| {
        let path = f["path"].as_str()?;
        let spec = schema
            .field(path)
            .filter(|spec| spec.shapes && f["value"].is_number())?;
        let value = match spec.kind {
            Kind::Integer {
                soft_min, soft_max, ..
            } => json!((soft_min + soft_max) / 2),
            Kind::Number {
                soft_min, soft_max, ..
            } => json!(0.5 * (soft_min + soft_max)),
            _ => return None,
        };
        Some((path.to_owned(), value))
    })
}

criterion_group!(benches, steps, sketches);
criterion_main!(benches);
