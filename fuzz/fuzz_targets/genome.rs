//! Genome files of any model: `Registry::standard().parse_genome` (through
//! `sylva::parse_genome`, which also turns its errors into `InputError`s with positions),
//! then growth of every parsed genome but L-systems (slow), and its JSON face.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(genome) = sylva::parse_genome(Path::new("g.json"), text) else {
        return;
    };
    let _ = genome.to_json();
    if genome.model() != "lsystem" {
        let _ = genome.develop(genome.default_seed());
    }
});
