//! Helpers shared by the integration tests.
#![allow(dead_code)] // Each test file uses some of them.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs the Khronos glTF validator; every GLB must have zero errors and zero warnings.
pub fn validate(glbs: &[PathBuf]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let script = root.join("tools/gltf-validator/validate.mjs");
    assert!(
        root.join("tools/gltf-validator/node_modules/gltf-validator")
            .exists(),
        "the validator is not installed: run `npm ci --prefix tools/gltf-validator`"
    );
    let out = Command::new("node")
        .arg(&script)
        .args(glbs)
        .output()
        .expect("node runs (install Node.js)");
    assert!(
        out.status.success(),
        "validator: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
