//! PlantMaker garden files (JSON): `Garden::from_json` (not grown: growing is slow).
#![no_main]
use libfuzzer_sys::fuzz_target;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = sylva_plantmaker::Garden::from_json(text);
});
