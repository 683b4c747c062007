//! L-system experiment files (TOML): `toml::from_str::<Simulation>`, and the error turned
//! into an `InputError` as `sylva simulate` does.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sylva_lsystem::experiments::Simulation;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match toml::from_str::<Simulation>(text) {
        Ok(s) => {
            let _ = s.genome_files();
        }
        Err(e) => {
            let _ = sylva::InputError::toml(std::path::Path::new("e.toml"), text, &e);
        }
    }
});
