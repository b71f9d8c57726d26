//! Shared test helpers: an in-process plan checker (the invariants of ../shared/tools/check_job.py).
#![allow(dead_code)]

use galvoplan::document::{Document, Plan};
use std::collections::HashSet;

/// Runs the galvoplan binary with `args`.
pub fn galvoplan(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_galvoplan"))
        .args(args)
        .output()
        .unwrap()
}

/// A refusal in one line: exit status not zero, one line on stderr (returned).
pub fn one_line_error(out: &std::process::Output) -> String {
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

/// Repository root.
pub fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Checks a plan: every geometry exactly once, every stroke inside its field, every field
/// visited in one contiguous run, fields' allocation consistent with the order.
pub fn check_plan(doc: &Document, plan: &Plan) {
    let n = doc.geometries.len();
    assert_eq!(plan.order.len(), n, "one stroke per geometry");
    let mut seen = vec![false; n];
    for s in &plan.order {
        assert!(!seen[s.geometry], "geometry {} marked twice", s.geometry);
        seen[s.geometry] = true;
        let f = plan
            .fields
            .iter()
            .find(|f| f.id == s.field)
            .unwrap_or_else(|| panic!("unknown field {}", s.field));
        let g = &doc.geometries[s.geometry];
        assert!(
            f.bbox().contains_box(&g.bbox(), 1e-6),
            "geometry {} leaves field {}",
            s.geometry,
            f.id
        );
        let p = doc.profile.stroke_mm;
        assert!(
            f.center.x >= -1e-9
                && f.center.x <= p[0] + 1e-9
                && f.center.y >= -1e-9
                && f.center.y <= p[1] + 1e-9
        );
        if g.closed {
            assert!(s.start_vertex < g.points.len());
        } else {
            assert!(
                s.start_vertex == 0 && !s.reversed
                    || s.start_vertex == g.points.len() - 1 && s.reversed
            );
        }
    }
    let mut runs = Vec::new();
    for s in &plan.order {
        if runs.last() != Some(&s.field) {
            runs.push(s.field);
        }
    }
    let distinct: HashSet<_> = runs.iter().collect();
    assert_eq!(
        distinct.len(),
        runs.len(),
        "a field is entered twice: {runs:?}"
    );
    let visit: Vec<usize> = plan.fields.iter().map(|f| f.id).collect();
    assert_eq!(runs, visit, "fields listed in visiting order");
}
