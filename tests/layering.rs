//! The module layering written in docs/ARCHITECTURE.md ("Layers"), checked on the source: a
//! module may use modules of lower layers only, never one of its own layer or above. Test code
//! (files named `tests*.rs`, and everything after a file's first `#[cfg(test)]`) and comments
//! are not checked.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// `layer N  module module …` lines of the architecture document.
fn layers() -> HashMap<String, usize> {
    let doc = std::fs::read_to_string("docs/ARCHITECTURE.md").expect("docs/ARCHITECTURE.md");
    let mut rank = HashMap::new();
    for line in doc.lines() {
        let mut words = line.split_whitespace();
        if words.next() != Some("layer") {
            continue;
        }
        let Some(n) = words.next().and_then(|n| n.parse::<usize>().ok()) else {
            continue;
        };
        for m in words {
            rank.insert(m.to_string(), n);
        }
    }
    assert!(
        rank.len() >= 10,
        "docs/ARCHITECTURE.md lists the layers as `layer N  module …` lines"
    );
    rank
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src readable") {
        let path = entry.expect("dir entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a source file belongs to (`src/order/tsp/lk.rs` → `order`).
fn module_of(path: &Path) -> Option<String> {
    let rel = path.strip_prefix("src").ok()?;
    let first = rel.components().next()?.as_os_str().to_string_lossy();
    let name = first.trim_end_matches(".rs").to_string();
    (name != "lib" && name != "main").then_some(name)
}

/// The modules `crate::X` named in the file's non-test code.
fn uses(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            let after = &rest[i + "crate::".len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.push((k + 1, name));
            }
            rest = after;
        }
    }
    out
}

#[test]
fn no_module_uses_one_of_its_own_layer_or_above() {
    let rank = layers();
    let mut files = Vec::new();
    rust_files(Path::new("src"), &mut files);
    files.sort();
    let mut bad = Vec::new();
    for f in &files {
        let Some(module) = module_of(f) else { continue };
        let name = f.file_name().map(|n| n.to_string_lossy().into_owned());
        if name.is_some_and(|n| n.starts_with("tests")) {
            continue;
        }
        let Some(&mine) = rank.get(&module) else {
            bad.push(format!(
                "{}: module `{module}` is not in the layers of docs/ARCHITECTURE.md",
                f.display()
            ));
            continue;
        };
        let text = std::fs::read_to_string(f).expect("source readable");
        for (line, used) in uses(&text) {
            if used == module {
                continue;
            }
            match rank.get(&used) {
                Some(&theirs) if theirs < mine => {}
                Some(&theirs) => bad.push(format!(
                    "{}:{line}: `{module}` (layer {mine}) uses `{used}` (layer {theirs})",
                    f.display()
                )),
                None => bad.push(format!(
                    "{}:{line}: `{used}` is not in the layers of docs/ARCHITECTURE.md",
                    f.display()
                )),
            }
        }
    }
    assert!(bad.is_empty(), "layering broken:\n{}", bad.join("\n"));
}

#[test]
fn the_check_sees_an_upward_use() {
    let found =
        uses("use crate::order::x;\n// crate::app in a comment\n#[cfg(test)]\nuse crate::app;");
    assert_eq!(found, vec![(1, "order".to_string())]);
}
