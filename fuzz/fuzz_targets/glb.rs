//! The GLB (binary glTF 2.0) reader: `sylva_mesh::import::read_glb`.
#![no_main]
use libfuzzer_sys::fuzz_target;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let _ = sylva_mesh::import::read_glb(data);
});
