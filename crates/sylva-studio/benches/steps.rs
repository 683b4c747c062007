//! The studio's breeding steps through its real router and a real archive file, as the
//! page makes them: nine PlantMaker offspring developed, previewed for the grid (simplified,
//! meshed, encoded as GLB) and stored; a random start of nine; a garden step of nine L-system
//! plants grown for 100 steps.
//!
//! Run with `cargo bench -p sylva-studio --bench steps`.
#![allow(clippy::unwrap_used)] // Benches may panic on broken setup.

use axum::body::Body;
use axum::http::{Request, StatusCode};
use criterion::{Criterion, criterion_group, criterion_main};
use serde_json::{Value, json};
use sylva_studio::guard::Guard;
use sylva_studio::{Archive, Studio, router};
use tower::ServiceExt;

fn call(runtime: &tokio::runtime::Runtime, studio: &Studio, path: &str, body: &Value) -> Value {
    runtime.block_on(async {
        let request = Request::post(path)
            .header("host", "127.0.0.1")
            .header("content-type", "application/json")
            .body(Body::from(body.to_string()))
            .unwrap();
        let response = router(studio.clone()).oneshot(request).await.unwrap();
        assert_eq!(response.status(), StatusCode::OK);
        let bytes = axum::body::to_bytes(response.into_body(), usize::MAX)
            .await
            .unwrap();
        serde_json::from_slice(&bytes).unwrap()
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

criterion_group!(benches, steps);
criterion_main!(benches);
