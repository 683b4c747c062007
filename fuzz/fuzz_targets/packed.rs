//! PlantMaker packed strings: `PlantMaker::from_packed`.
#![no_main]
use libfuzzer_sys::fuzz_target;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = sylva_plantmaker::PlantMaker::from_packed(text);
});
