//! Checkpoint files (`sylva evolve --resume`): `Evolution::resume` of the bintree run
//! configured by `checkpoint.toml` (population 6), then one generation bred and the
//! checkpoint written back.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use std::sync::OnceLock;
include!("common.rs");

fn config() -> &'static sylva::Config {
    static CONFIG: OnceLock<sylva::Config> = OnceLock::new();
    CONFIG.get_or_init(|| {
        sylva::Config::parse(Path::new("config.toml"), include_str!("checkpoint.toml"))
            .expect("the checkpoint target's config parses")
    })
}

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let pool = sylva_core::par::Pool::Serial;
    let Ok(mut evolution) =
        sylva::Evolution::resume(config(), Path::new("checkpoint.json"), text, pool)
    else {
        return;
    };
    let _ = evolution.step();
    let _ = evolution.checkpoint();
});
