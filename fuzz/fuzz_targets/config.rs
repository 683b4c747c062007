//! Evolution configs (TOML) of any model: `sylva::Config::parse`.
#![no_main]
use libfuzzer_sys::fuzz_target;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = sylva::Config::parse(std::path::Path::new("c.toml"), text);
});
