//! L-system axioms and rules in the paper's notation: `LSystem::parse`, first line the
//! axiom, the other lines rules, in both compartments.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sylva_lsystem::genome::LSystem;
use sylva_lsystem::grammar::Compartment;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut lines = text.lines();
    let axiom = lines.next().unwrap_or("");
    let rules: Vec<&str> = lines.collect();
    for compartment in [Compartment::Shoot, Compartment::Root] {
        let _ = LSystem::parse(axiom, &rules, compartment);
    }
});
