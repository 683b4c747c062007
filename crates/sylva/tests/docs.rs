//! The docs stay true to the tree: every relative link in the README and `docs/` names a
//! file that exists, and the summary of `docs/fidelity.md` counts its own tables.
#![allow(clippy::unwrap_used)] // Tests may panic on broken setup.

use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn markdown_files() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    for entry in fs::read_dir(root().join("docs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            files.push(path);
        }
    }
    files.sort();
    files
}

/// Targets of the `[text](target)` links in a markdown text.
fn link_targets(text: &str) -> Vec<&str> {
    text.match_indices("](")
        .filter_map(|(at, _)| {
            let rest = &text[at + 2..];
            rest.find(')').map(|end| &rest[..end])
        })
        .collect()
}

#[test]
fn relative_links_name_files_that_exist() {
    let mut broken = Vec::new();
    for file in markdown_files() {
        let text = fs::read_to_string(&file).unwrap();
        for target in link_targets(&text) {
            let path = target.split('#').next().unwrap();
            if path.is_empty() || path.contains("://") || path.starts_with("mailto:") {
                continue;
            }
            if !file.parent().unwrap().join(path).exists() {
                broken.push(format!("{}: {target}", file.display()));
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// A table row's cells, with `\|` kept inside its cell.
fn cells(row: &str) -> Vec<String> {
    let mut cells = vec![String::new()];
    let mut chars = row.trim().trim_matches('|').chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek() == Some(&'|') => {
                cells.last_mut().unwrap().push('|');
                chars.next();
            }
            '|' => cells.push(String::new()),
            _ => cells.last_mut().unwrap().push(c),
        }
    }
    cells.iter().map(|c| c.trim().to_owned()).collect()
}

#[test]
fn the_fidelity_summary_counts_its_tables() {
    const STATUSES: [&str; 3] = ["as written", "Sylva's choice", "not yet"];
    let text = fs::read_to_string(root().join("docs/fidelity.md")).unwrap();
    let (summary, sections) = text.split_once("\n## ").unwrap();
    let summary_rows: Vec<Vec<String>> = summary
        .lines()
        .filter(|l| l.starts_with("| [") && l.contains("](#"))
        .map(cells)
        .collect();
    let sections: Vec<&str> = sections.split("\n## ").collect();
    assert_eq!(summary_rows.len(), 4, "one summary row per paper");
    assert_eq!(sections.len(), 4, "one section per paper");
    for (row, section) in summary_rows.iter().zip(&sections) {
        let mut counts = [0usize; 3];
        let mut elements = 0;
        for line in section.lines().filter(|l| l.starts_with("| ")) {
            let cells = cells(line);
            let group = cells[1..].iter().all(|c| c.is_empty());
            if cells[0] == "Paper (section)" || cells[0].starts_with("---") || group {
                continue;
            }
            elements += 1;
            let status = cells.last().unwrap();
            let kind = STATUSES.iter().position(|s| status.starts_with(s));
            let kind = kind.unwrap_or_else(|| panic!("row without a status: {line}"));
            counts[kind] += 1;
        }
        let numbers: Vec<usize> = row[2..].iter().map(|c| c.parse().unwrap()).collect();
        assert_eq!(
            numbers,
            [elements, counts[0], counts[1], counts[2]],
            "summary of {}",
            section.lines().next().unwrap()
        );
    }
}
