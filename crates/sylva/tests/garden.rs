//! Gardens and forests weighed before they are grown: a GLB's size and memory estimated
//! from the first plant, within 3% of the file written.

#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::path::Path;

use serde_json::json;
use sylva::garden::{
    Garden, GardenEstimate, GardenLayout, GardenNodes, estimate_garden, garden_glb,
    garden_glb_options, garden_placements, json_heap_bytes,
};
use sylva_plantmaker::PlantMakerModel;

fn conifer() -> sylva_plantmaker::PlantMaker {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/plantmaker/conifer.json"
    );
    sylva::Registry::standard()
        .load_genome_of::<PlantMakerModel>(Path::new(path), "gardens grow")
        .expect("the example is a PlantMaker genome")
}

/// The GLB a garden streams, and its estimate.
fn written_and_estimated(garden: &Garden) -> (u64, GardenEstimate) {
    let source = Path::new("conifer.json");
    let options = garden_glb_options(garden);
    let estimate = estimate_garden(garden, source, GardenLayout::Streamed, &options)
        .expect("the garden is estimated");
    let placements = garden_placements(garden, source).expect("the garden is placed");
    let nodes = GardenNodes::of(garden, &placements);
    let glb = garden_glb(garden, &placements, &nodes, options).expect("laid out");
    (glb.stats().bytes, estimate)
}

#[test]
fn a_garden_is_estimated_from_its_first_plant() {
    // Every plant its own mesh: the estimate is within 3% of the file (seeds differ).
    let planted = |count, area| sylva_plantmaker::Garden::new(conifer(), count, area, 3);
    let garden = Garden::of::<PlantMakerModel>(planted(12, [60.0, 60.0]));
    let (bytes, estimate) = written_and_estimated(&garden);
    assert_eq!((estimate.plants, estimate.meshes), (12, 12));
    let ratio = estimate.glb as f64 / bytes as f64;
    assert!((0.97..1.03).contains(&ratio), "{} / {bytes}", estimate.glb);
    // A forest of 3 variants: 3 meshes, each placement an instance.
    let mut typed = planted(40, [80.0, 80.0]);
    typed.variants = Some(3);
    let forest = Garden::of::<PlantMakerModel>(typed.clone());
    let (bytes, instanced) = written_and_estimated(&forest);
    assert_eq!((instanced.plants, instanced.meshes), (40, 3));
    let ratio = instanced.glb as f64 / bytes as f64;
    assert!((0.97..1.03).contains(&ratio), "{} / {bytes}", instanced.glb);
    // Memory grows with the plants however few the meshes: each node carries a genome.
    typed.plants[0].seeds.extend(1000..1040);
    let larger = Garden::of::<PlantMakerModel>(typed);
    let estimate = |g: &Garden, layout| {
        estimate_garden(g, Path::new("c.json"), layout, &garden_glb_options(g)).unwrap()
    };
    let grown = estimate(&larger, GardenLayout::Streamed).memory
        - estimate(&forest, GardenLayout::Streamed).memory;
    assert!(grown > 40 * 5000, "{grown}");
    // A held scene keeps its plants and meshes, and more copies of the extras.
    assert!(
        estimate(&forest, GardenLayout::Held).memory
            > estimate(&forest, GardenLayout::Streamed).memory
    );
}

#[test]
fn json_values_are_weighed_as_the_allocator_holds_them() {
    assert_eq!(json_heap_bytes(&json!(1.5)), 0);
    // 40 bytes of string: 48 bytes of chunk.
    assert_eq!(json_heap_bytes(&json!("x".repeat(40))), 48);
    // Three values of 32 bytes, each a number.
    assert_eq!(json_heap_bytes(&json!([1, 2, 3])), 112);
    // One leaf of a B-tree (eleven slots) and a short key.
    assert_eq!(json_heap_bytes(&json!({ "a": 1 })), 640 + 32);
    assert_eq!(json_heap_bytes(&json!({})), 0);
}
