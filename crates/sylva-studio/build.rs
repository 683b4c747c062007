//! Builds the studio's page into the binary, so that `sylva studio` serves it from any folder
//! (an installed or copied binary too): `web/index.html`, `web/app/*`, and the files of
//! three.js (installed by `npm ci --prefix crates/sylva-studio/web`, pinned by its
//! `package-lock.json`) that the page imports, followed import by import from the modules
//! the page names. Without three.js installed the binary is still built, and its studio
//! refuses to start, saying what to run.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn main() {
    let crate_dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let web = crate_dir.join("web");
    let three = web.join("node_modules/three");
    println!("cargo:rerun-if-changed=web/index.html");
    println!("cargo:rerun-if-changed=web/app");
    println!("cargo:rerun-if-changed=web/node_modules/three/package.json");

    let mut page: Vec<(String, PathBuf)> = vec![("index.html".into(), web.join("index.html"))];
    let mut app: Vec<PathBuf> = std::fs::read_dir(web.join("app"))
        .expect("crates/sylva-studio/web/app is part of the source")
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.is_file())
        .collect();
    app.sort();
    for path in &app {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .expect("file names are UTF-8");
        page.push((format!("app/{name}"), path.clone()));
    }

    let mut vendored: Vec<(String, PathBuf)> = Vec::new();
    let mut version = String::new();
    if three.join("package.json").is_file() {
        let package = std::fs::read_to_string(three.join("package.json")).expect("readable");
        version = package
            .split("\"version\"")
            .nth(1)
            .and_then(|rest| rest.split('"').nth(1))
            .unwrap_or("")
            .to_owned();
        // The modules the page imports, then everything they import in turn.
        let mut todo: Vec<String> = Vec::new();
        for path in &app {
            let text = std::fs::read_to_string(path).expect("readable");
            for spec in imports(&text) {
                if let Some(file) = bare(&spec) {
                    todo.push(file);
                }
            }
        }
        let mut seen = BTreeSet::new();
        let mut found = BTreeSet::new();
        while let Some(file) = todo.pop() {
            if !seen.insert(file.clone()) {
                continue;
            }
            // A specifier in a comment may name no file; a real import missing would show
            // in the browser test.
            let Ok(text) = std::fs::read_to_string(three.join(&file)) else {
                continue;
            };
            found.insert(file.clone());
            for spec in imports(&text) {
                let next = bare(&spec).or_else(|| relative(&file, &spec));
                if let Some(next) = next {
                    todo.push(next);
                }
            }
        }
        found.insert("LICENSE".into());
        for file in found {
            vendored.push((file.clone(), three.join(&file)));
        }
    } else {
        println!(
            "cargo:warning=three.js is not installed in {}: this build's `sylva studio` will not \
             start; run `npm ci --prefix crates/sylva-studio/web` and build again",
            three.display()
        );
    }

    let mut out = String::new();
    write_table(&mut out, "PAGE", &page);
    write_table(&mut out, "THREE", &vendored);
    writeln!(
        out,
        "/// The version of three.js built in (empty when none is)."
    )
    .ok();
    writeln!(out, "pub const THREE_VERSION: &str = {version:?};").ok();
    let dest = Path::new(&std::env::var("OUT_DIR").expect("cargo sets it")).join("assets.rs");
    std::fs::write(dest, out).expect("OUT_DIR is writable");
}

fn write_table(out: &mut String, name: &str, files: &[(String, PathBuf)]) {
    writeln!(out, "/// Files by their path under the served folder.").ok();
    writeln!(out, "pub static {name}: &[(&str, &[u8])] = &[").ok();
    for (served, path) in files {
        let path = path.to_str().expect("paths are UTF-8");
        writeln!(out, "    ({served:?}, include_bytes!({path:?})),").ok();
    }
    writeln!(out, "];").ok();
}

/// The module specifiers a JavaScript module imports statically (`from '...'`, `import '...'`).
fn imports(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    for keyword in ["from", "import"] {
        let mut rest = text;
        while let Some(i) = rest.find(keyword) {
            let before = rest[..i].chars().next_back();
            rest = &rest[i + keyword.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '.') {
                continue;
            }
            let after = rest.trim_start();
            let Some(quote) = after.chars().next().filter(|c| *c == '"' || *c == '\'') else {
                continue;
            };
            if let Some(end) = after[1..].find(quote) {
                found.push(after[1..1 + end].to_owned());
            }
        }
    }
    found
}

/// A bare specifier the page's import map resolves (`three`, `three/addons/...`).
fn bare(spec: &str) -> Option<String> {
    if spec == "three" {
        Some("build/three.module.js".into())
    } else {
        spec.strip_prefix("three/addons/")
            .map(|rest| format!("examples/jsm/{rest}"))
    }
}

/// A relative specifier (`./x.js`, `../utils/y.js`) from `file`, within three's folder.
fn relative(file: &str, spec: &str) -> Option<String> {
    if !(spec.starts_with("./") || spec.starts_with("../")) {
        return None;
    }
    let mut parts: Vec<&str> = file.split('/').collect();
    parts.pop();
    for part in spec.split('/') {
        match part {
            "." => {}
            ".." => {
                parts.pop()?;
            }
            name => parts.push(name),
        }
    }
    Some(parts.join("/"))
}
