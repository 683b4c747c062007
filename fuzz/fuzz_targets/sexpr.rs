//! GP S-expressions of the automata model: `GpTree::parse`; a tree that parses is
//! printed, compiled and run with the default options.
#![no_main]
use libfuzzer_sys::fuzz_target;
use sylva_automata::{Detail, GpTree, GrowOptions, Program, Semantics, Simulator};
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    set_budget();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(tree) = GpTree::parse(text) else {
        return;
    };
    let _ = tree.to_string();
    let program = Program::compile(&tree, &Semantics::default());
    let mut plant = sylva_core::Plant::default();
    let _ = Simulator::new().run(&program, &GrowOptions::default(), Detail::Full, &mut plant);
});
