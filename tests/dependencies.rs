//! No declared dependency goes unused: every crate in Cargo.toml's `[dependencies]` is named by a
//! path in `src` (a `use`, a path in code or a type, a macro's path, or `name::` inside a macro's
//! tokens), and every `[dev-dependencies]` crate in `src` or `tests`. Files are parsed with
//! `syn`, so a crate named only in a comment or a string does not count.
//!
//! A crate that must stay declared without being named in code says why in
//! [`USED_WITHOUT_A_PATH`].

#![allow(clippy::unwrap_used, clippy::expect_used)]

use proc_macro2::{TokenStream, TokenTree};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// Crates declared for what they do without being named in code (none today).
const USED_WITHOUT_A_PATH: &[(&str, &str)] = &[];

/// The crates a set of files names: first segments of every path, `extern crate` names, and
/// `name::` inside macro tokens.
#[derive(Default)]
struct Named(BTreeSet<String>);

impl Named {
    fn tokens(&mut self, ts: TokenStream) {
        let tokens: Vec<TokenTree> = ts.into_iter().collect();
        for (k, t) in tokens.iter().enumerate() {
            match t {
                TokenTree::Ident(i) => {
                    let next_is_path = matches!(
                        (tokens.get(k + 1), tokens.get(k + 2)),
                        (Some(TokenTree::Punct(a)), Some(TokenTree::Punct(b)))
                            if a.as_char() == ':' && b.as_char() == ':'
                    );
                    if next_is_path {
                        self.0.insert(i.to_string());
                    }
                }
                TokenTree::Group(g) => self.tokens(g.stream()),
                _ => {}
            }
        }
    }
}

impl<'a> Visit<'a> for Named {
    fn visit_path(&mut self, p: &'a syn::Path) {
        if let Some(first) = p.segments.first() {
            self.0.insert(first.ident.to_string());
        }
        syn::visit::visit_path(self, p);
    }
    fn visit_use_tree(&mut self, t: &'a syn::UseTree) {
        match t {
            syn::UseTree::Path(p) => {
                self.0.insert(p.ident.to_string());
            }
            syn::UseTree::Name(n) => {
                self.0.insert(n.ident.to_string());
            }
            syn::UseTree::Rename(r) => {
                self.0.insert(r.ident.to_string());
            }
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.visit_use_tree(t);
                }
            }
            syn::UseTree::Glob(_) => {}
        }
    }
    fn visit_item_extern_crate(&mut self, e: &'a syn::ItemExternCrate) {
        self.0.insert(e.ident.to_string());
    }
    fn visit_macro(&mut self, m: &'a syn::Macro) {
        self.tokens(m.tokens.clone());
        syn::visit::visit_macro(self, m);
    }
    fn visit_attribute(&mut self, a: &'a syn::Attribute) {
        if let syn::Meta::List(l) = &a.meta {
            self.tokens(l.tokens.clone());
        }
        syn::visit::visit_attribute(self, a);
    }
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The crate names the Rust files under `dirs` use.
fn named_in(dirs: &[&str]) -> BTreeSet<String> {
    let mut files = Vec::new();
    for d in dirs {
        rust_files(Path::new(d), &mut files);
    }
    let mut named = Named::default();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        named.visit_file(&file);
    }
    named.0
}

/// The declared crates of a Cargo.toml table that `named` does not hold (a crate's name with
/// `-` is named with `_`; `package = ` renames are followed).
fn unused(manifest: &toml::Table, table: &str, named: &BTreeSet<String>) -> Vec<String> {
    let Some(deps) = manifest.get(table).and_then(|t| t.as_table()) else {
        return Vec::new();
    };
    deps.keys()
        .filter(|name| {
            let ident = name.replace('-', "_");
            !named.contains(&ident) && !USED_WITHOUT_A_PATH.iter().any(|(n, _)| n == name)
        })
        .cloned()
        .collect()
}

fn manifest() -> toml::Table {
    std::fs::read_to_string("Cargo.toml")
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn every_declared_dependency_is_used() {
    let m = manifest();
    let in_src = named_in(&["src"]);
    let lib = unused(&m, "dependencies", &in_src);
    assert!(
        lib.is_empty(),
        "declared in [dependencies] but named nowhere in src: {lib:?} (remove them, or say in \
         USED_WITHOUT_A_PATH why they stay)"
    );
    let everywhere = named_in(&["src", "tests", "benches", "examples"]);
    let dev = unused(&m, "dev-dependencies", &everywhere);
    assert!(
        dev.is_empty(),
        "declared in [dev-dependencies] but named nowhere in src or tests: {dev:?}"
    );
}

/// The check finds a planted crate that nothing names, and one named only in a comment or a
/// string; it sees crates named in a grouped `use`, a path in a body, a macro's path and a
/// macro's tokens.
#[test]
fn the_check_finds_a_planted_unused_crate() {
    let code = r#"
        // left_pad::pad is only in a comment
        use serde::{Deserialize, Serialize};
        fn f() -> f64 {
            let _ = "right_pad::pad(1)";
            let line: geo::LineString<f64> = vec![geo::coord! { x: 1.0, y: 2.0 }].into();
            assert!(rayon::current_num_threads() > 0);
            line.0.len() as f64
        }
    "#;
    let mut named = Named::default();
    named.visit_file(&syn::parse_file(code).unwrap());
    let m: toml::Table = r#"
        [dependencies]
        serde = "1"
        geo = "0.33"
        rayon = "1"
        left-pad = "1"
        right_pad = "1"
    "#
    .parse()
    .unwrap();
    assert_eq!(
        unused(&m, "dependencies", &named.0),
        ["left-pad", "right_pad"]
    );
}
