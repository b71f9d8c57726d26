//! The GUI's rooms stay apart: no two files of `src/app` import each other (docs/ARCHITECTURE.md,
//! "The GUI's rooms"). A file imports another when one of its paths (a `use`, a path in code or
//! a type) names it: `super::x` or `crate::app::x` in a module file, `x::` in `src/app/mod.rs`;
//! `super::X` for an item of `mod.rs` (such as `App`) imports `mod.rs`. Files are parsed with
//! `syn`, and `#[cfg(test)]` items are left out.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::{BTreeMap, BTreeSet};
use syn::visit::Visit;

/// The sibling names a file's paths start with.
struct Refs {
    /// The file is `mod.rs` (its children are named without `super::`).
    is_mod: bool,
    modules: BTreeSet<String>,
    found: BTreeSet<String>,
}

impl Refs {
    fn segments(&mut self, idents: &[String]) {
        match idents {
            [s, next, ..] if s == "super" && !self.is_mod => {
                let target = if self.modules.contains(next) {
                    next.clone()
                } else {
                    "mod".to_string()
                };
                self.found.insert(target);
            }
            [c, a, next, ..] if c == "crate" && a == "app" => {
                self.found.insert(next.clone());
            }
            [first, _, ..] if self.is_mod && self.modules.contains(first) => {
                self.found.insert(first.clone());
            }
            _ => {}
        }
    }

    fn use_tree(&mut self, prefix: &mut Vec<String>, t: &syn::UseTree) {
        match t {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                prefix.push(n.ident.to_string());
                prefix.push(String::new());
                self.segments(prefix);
                prefix.truncate(prefix.len() - 2);
            }
            syn::UseTree::Rename(r) => {
                prefix.push(r.ident.to_string());
                prefix.push(String::new());
                self.segments(prefix);
                prefix.truncate(prefix.len() - 2);
            }
            syn::UseTree::Glob(_) => {
                prefix.push(String::new());
                self.segments(prefix);
                prefix.pop();
            }
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(prefix, t);
                }
            }
        }
    }
}

impl<'a> Visit<'a> for Refs {
    fn visit_path(&mut self, p: &'a syn::Path) {
        let idents: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        self.segments(&idents);
        syn::visit::visit_path(self, p);
    }
    fn visit_item_use(&mut self, u: &'a syn::ItemUse) {
        self.use_tree(&mut Vec::new(), &u.tree);
    }
}

fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta
                .require_list()
                .is_ok_and(|l| l.tokens.to_string().contains("test"))
    })
}

fn item_attrs(item: &syn::Item) -> &[syn::Attribute] {
    match item {
        syn::Item::Mod(m) => &m.attrs,
        syn::Item::Fn(f) => &f.attrs,
        syn::Item::Impl(i) => &i.attrs,
        syn::Item::Use(u) => &u.attrs,
        syn::Item::Struct(s) => &s.attrs,
        syn::Item::Enum(e) => &e.attrs,
        syn::Item::Const(c) => &c.attrs,
        _ => &[],
    }
}

/// Which files of a set import which: (file, sources) pairs by module name (`mod` for mod.rs).
fn graph(files: &[(String, String)]) -> BTreeMap<String, BTreeSet<String>> {
    let modules: BTreeSet<String> = files
        .iter()
        .map(|(m, _)| m.clone())
        .filter(|m| m != "mod")
        .collect();
    let mut out = BTreeMap::new();
    for (m, text) in files {
        let file = syn::parse_file(text).unwrap_or_else(|e| panic!("{m}: {e}"));
        let mut refs = Refs {
            is_mod: m == "mod",
            modules: modules.clone(),
            found: BTreeSet::new(),
        };
        for item in file.items.iter().filter(|i| !is_test(item_attrs(i))) {
            refs.visit_item(item);
        }
        refs.found.remove(m);
        out.insert(m.clone(), refs.found);
    }
    out
}

/// The pairs of files that import each other.
fn mutual(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<(String, String)> {
    let mut pairs = Vec::new();
    for (a, to) in g {
        for b in to {
            if a < b && g.get(b).is_some_and(|t| t.contains(a)) {
                pairs.push((a.clone(), b.clone()));
            }
        }
    }
    pairs
}

#[test]
fn no_two_files_of_the_gui_import_each_other() {
    let mut files = Vec::new();
    for e in std::fs::read_dir("src/app").unwrap().flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "rs") {
            let name = p.file_stem().unwrap().to_string_lossy().to_string();
            files.push((name, std::fs::read_to_string(&p).unwrap()));
        }
    }
    assert!(files.len() > 20);
    let g = graph(&files);
    let pairs = mutual(&g);
    assert!(
        pairs.is_empty(),
        "files of src/app importing each other: {pairs:?}"
    );
}

/// The check finds each planted case: a grouped `use super::{..}`, a path in a body, an item
/// of mod.rs named from a child (`super::App`) while mod.rs names the child, and it leaves out
/// `#[cfg(test)]` items.
#[test]
fn the_check_finds_planted_mutual_imports() {
    let files = |a: &str, b: &str, m: &str| {
        vec![
            ("paint".to_string(), a.to_string()),
            ("canvas".to_string(), b.to_string()),
            ("mod".to_string(), m.to_string()),
        ]
    };
    let grouped = files(
        "use super::{canvas::Canvas, draw};",
        "fn f() { super::paint::paint(); }",
        "",
    );
    assert_eq!(
        mutual(&graph(&grouped)),
        [("canvas".into(), "paint".into())]
    );
    let through_mod = files("impl super::App {}", "", "fn f() { paint::paint(); }");
    assert_eq!(
        mutual(&graph(&through_mod)),
        [("mod".into(), "paint".into())]
    );
    let in_tests = files(
        "use super::canvas::Canvas;",
        "#[cfg(test)]\nmod tests { use super::super::paint; fn f() { super::super::paint::x(); } }",
        "",
    );
    assert!(mutual(&graph(&in_tests)).is_empty());
}
