//! The module layering written in docs/ARCHITECTURE.md ("Layers"), checked on the source: a
//! module may use modules of lower layers only, never one of its own layer or above.
//!
//! Each file is parsed with `syn`, so that only `#[cfg(test)]` items are skipped (whatever comes
//! after them is checked), grouped and nested `use` trees are read, and every path in the code
//! (bodies, types, the paths of macros called) counts, not only `use` lines; the tokens inside a
//! macro's call are not read. In the library a module is
//! named by `crate::X`, or by `super::…` climbing to the crate root; in the binary (`src/main.rs`
//! and `src/cli`) by `galvoplan::X`. Files named `tests*.rs` are test code.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use syn::visit::Visit;

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

/// A source file as the check sees it.
struct Source {
    /// Its top-level module (`src/order/tsp/lk.rs` → `order`).
    module: String,
    /// How deep its module is below the crate root (`src/order.rs` 1, `src/order/tsp/lk.rs` 3).
    depth: usize,
    /// The binary's code: the library is reached as `galvoplan::X`.
    binary: bool,
}

impl Source {
    fn of(path: &Path) -> Option<Self> {
        let rel = path.strip_prefix("src").ok()?;
        let parts: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        let first = parts.first()?.trim_end_matches(".rs").to_string();
        if first == "lib" {
            return None;
        }
        let last = parts.last()?;
        // `a/b/mod.rs` is module `a::b`: depth 2; `a/b/c.rs` is `a::b::c`: depth 3
        let depth = if last == "mod.rs" {
            parts.len() - 1
        } else {
            parts.len()
        };
        Some(Self {
            binary: first == "main" || first == "cli",
            module: if first == "main" { "cli".into() } else { first },
            depth,
        })
    }
}

/// True for an item that only exists in tests.
fn test_only(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.parse_args::<syn::Meta>()
                .is_ok_and(|m| m.path().is_ident("test"))
    })
}

/// Collects the top-level modules a file's non-test code names, with their lines.
struct Uses<'s> {
    source: &'s Source,
    /// Depth of the module being visited (inline `mod x { … }` adds one).
    depth: usize,
    found: Vec<(usize, String)>,
}

impl Uses<'_> {
    /// The top-level module a path of these segments names, if it names one.
    fn module_of(&self, segments: &[String]) -> Option<String> {
        let first = segments.first()?;
        if self.source.binary {
            return (first == "galvoplan").then(|| segments.get(1).cloned())?;
        }
        match first.as_str() {
            "crate" => segments.get(1).cloned(),
            "super" => {
                let ups = segments.iter().take_while(|s| *s == "super").count();
                (ups == self.depth).then(|| segments.get(ups).cloned())?
            }
            _ => None,
        }
    }

    fn record(&mut self, segments: Vec<String>, line: usize) {
        if let Some(m) = self.module_of(&segments) {
            self.found.push((line, m));
        }
    }

    /// Every full path of a `use` tree (groups and nesting expanded).
    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        let line = |i: &syn::Ident| i.span().start().line;
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                let mut s = prefix.clone();
                s.push(n.ident.to_string());
                self.record(s, line(&n.ident));
            }
            syn::UseTree::Rename(r) => {
                let mut s = prefix.clone();
                s.push(r.ident.to_string());
                self.record(s, line(&r.ident));
            }
            syn::UseTree::Glob(g) => {
                let mut s = prefix.clone();
                s.push("*".into());
                self.record(s, g.star_token.span.start().line);
            }
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(prefix, t);
                }
            }
        }
    }
}

impl<'ast> Visit<'ast> for Uses<'_> {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        let attrs = match item {
            syn::Item::Const(i) => &i.attrs,
            syn::Item::Enum(i) => &i.attrs,
            syn::Item::Fn(i) => &i.attrs,
            syn::Item::Impl(i) => &i.attrs,
            syn::Item::Mod(i) => &i.attrs,
            syn::Item::Static(i) => &i.attrs,
            syn::Item::Struct(i) => &i.attrs,
            syn::Item::Trait(i) => &i.attrs,
            syn::Item::Type(i) => &i.attrs,
            syn::Item::Use(i) => &i.attrs,
            syn::Item::Macro(i) => &i.attrs,
            _ => return syn::visit::visit_item(self, item),
        };
        if test_only(attrs) {
            return;
        }
        syn::visit::visit_item(self, item);
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if !test_only(&f.attrs) {
            syn::visit::visit_impl_item_fn(self, f);
        }
    }

    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if m.content.is_some() {
            self.depth += 1;
            syn::visit::visit_item_mod(self, m);
            self.depth -= 1;
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        self.use_tree(&mut Vec::new(), &u.tree);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        if let Some(s) = p.segments.first() {
            self.record(segments, s.ident.span().start().line);
        }
        syn::visit::visit_path(self, p);
    }
}

/// The modules the non-test code of `text` names, with their lines.
fn uses(text: &str, source: &Source) -> Result<Vec<(usize, String)>, String> {
    let file = syn::parse_file(text).map_err(|e| e.to_string())?;
    let mut v = Uses {
        source,
        depth: source.depth,
        found: Vec::new(),
    };
    v.visit_file(&file);
    v.found.sort();
    v.found.dedup();
    Ok(v.found)
}

/// What is wrong with `source`'s uses under the layers `rank`; `at` names the file.
fn violations(text: &str, source: &Source, rank: &HashMap<String, usize>, at: &str) -> Vec<String> {
    let Some(&mine) = rank.get(&source.module) else {
        return vec![format!(
            "{at}: module `{}` is not in the layers of docs/ARCHITECTURE.md",
            source.module
        )];
    };
    let found = match uses(text, source) {
        Ok(f) => f,
        Err(e) => return vec![format!("{at}: does not parse: {e}")],
    };
    let mut bad = Vec::new();
    for (line, used) in found {
        if used == source.module || used == "*" {
            continue;
        }
        match rank.get(&used) {
            Some(&theirs) if theirs < mine => {}
            Some(&theirs) => bad.push(format!(
                "{at}:{line}: `{}` (layer {mine}) uses `{used}` (layer {theirs})",
                source.module
            )),
            // a crate-root item (`crate::Foo`) or a library item re-exported at the root
            None if used.chars().next().is_some_and(char::is_uppercase) => {}
            None => bad.push(format!(
                "{at}:{line}: `{used}` is not in the layers of docs/ARCHITECTURE.md"
            )),
        }
    }
    bad
}

#[test]
fn no_module_uses_one_of_its_own_layer_or_above() {
    let rank = layers();
    let mut files = Vec::new();
    rust_files(Path::new("src"), &mut files);
    files.sort();
    let mut bad = Vec::new();
    for f in &files {
        let Some(source) = Source::of(f) else {
            continue;
        };
        let name = f.file_name().map(|n| n.to_string_lossy().into_owned());
        if name.is_some_and(|n| n.starts_with("tests")) {
            continue;
        }
        let text = std::fs::read_to_string(f).expect("source readable");
        bad.extend(violations(&text, &source, &rank, &f.display().to_string()));
    }
    assert!(bad.is_empty(), "layering broken:\n{}", bad.join("\n"));
}

/// The check's own cases: each planted upward use is found, test code is not checked.
#[test]
fn the_check_sees_every_kind_of_upward_use() {
    let rank: HashMap<String, usize> = [
        ("geom", 0),
        ("order", 4),
        ("pipeline", 5),
        ("app", 7),
        ("cli", 8),
    ]
    .map(|(m, n)| (m.to_string(), n))
    .into_iter()
    .collect();
    let order = |depth| Source {
        module: "order".into(),
        depth,
        binary: false,
    };
    let bad = |text: &str, s: &Source| violations(text, s, &rank, "f.rs");
    // allowed: a lower layer, grouped
    assert!(bad("use crate::{geom::Pt, order::x};", &order(1)).is_empty());
    // a grouped use
    assert_eq!(bad("use crate::{geom::Pt, app::App};", &order(1)).len(), 1);
    // a nested group
    assert_eq!(
        bad(
            "use crate::{geom::{Pt, BBox}, pipeline::{a, b}};",
            &order(1)
        )
        .len(),
        1
    );
    // a path in a body, not in a `use`
    let body = "fn f() { let x = crate::pipeline::run(); }";
    assert_eq!(bad(body, &order(1)).len(), 1);
    // `super` climbing to the crate root from a nested file
    assert_eq!(bad("use super::super::app::App;", &order(2)).len(), 1);
    assert!(bad("use super::lk;", &order(2)).is_empty());
    // code after a test module is still checked; the test module is not
    let after_test =
        "#[cfg(test)]\nmod tests { use crate::app::App; }\nfn f() { crate::app::go(); }";
    let found = bad(after_test, &order(1));
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("f.rs:3:"), "{found:?}");
    // a comment names nothing
    assert!(bad("// crate::app\nfn f() {}", &order(1)).is_empty());
    // the binary names the library as `galvoplan::X`
    let cli = Source {
        module: "cli".into(),
        depth: 1,
        binary: true,
    };
    assert!(bad("use galvoplan::app::App;", &cli).is_empty());
    let app = Source {
        module: "app".into(),
        depth: 1,
        binary: false,
    };
    assert_eq!(
        bad("use crate::pipeline::x; fn f() { crate::app::g(); }", &app).len(),
        0
    );
    let rank_cli_beside_app: HashMap<String, usize> = [("app", 7), ("cli", 7)]
        .map(|(m, n)| (m.to_string(), n))
        .into_iter()
        .collect();
    let beside = violations(
        "use galvoplan::app::App;",
        &cli,
        &rank_cli_beside_app,
        "cli.rs",
    );
    assert_eq!(beside.len(), 1, "{beside:?}");
}
