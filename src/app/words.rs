//! How the GUI words what it shows: counts with their noun, fields and regions and their
//! numbers, pipeline errors with what the operator can do, a plan's staleness. At the bottom of
//! the GUI's modules: nothing here imports another file of the GUI.

use crate::document::{MachineProfile, Pose, ScanField};

/// A pose in words, the axes `profile` has and any other the pose turns (`Z -60.83 mm,
/// A 29.65°, B -36.81°`): empty for a flat machine's rest pose.
pub fn pose_words(pose: &Pose, profile: &MachineProfile) -> String {
    let shown = crate::document::ExtraAxisId::ALL
        .map(|id| profile.extra_axis(id).is_some() || pose.values()[id.index()] != 0.0);
    pose_axes_words(pose, shown, 2)
}

/// The `shown` axes of a pose (Z, A, B) in words with `decimals`: `Z -60.8 mm, A 29.6°`.
pub fn pose_axes_words(pose: &Pose, shown: [bool; 3], decimals: usize) -> String {
    crate::document::ExtraAxisId::ALL
        .into_iter()
        .filter(|id| shown[id.index()])
        .map(|id| {
            let v = pose.values()[id.index()];
            match id {
                crate::document::ExtraAxisId::Z => format!("Z {v:.decimals$} mm"),
                _ => format!("{} {v:.decimals$}°", id.word()),
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// `n` and the noun for it: "1 geometry", "3 geometries".
pub fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// What to do on a machine that turns the part instead of moving it in Y.
pub const CYLINDER_ADVICE: &str = "this machine turns the part on its A axis instead of moving \
    it in Y: give the part's diameter in the Cylinder section to mark around it";

/// A pipeline error in the GUI's words: the message, then what the operator can do, naming
/// the controls that do it.
pub fn gui_error(e: &crate::pipeline::PipelineError) -> String {
    use crate::pipeline::Remedy;
    match e.remedy() {
        Some(Remedy::SplitOversize) => format!(
            "{e}; tick \"Split oversize geometries\" in Solver settings and press \"Re-place \
             automatically\" to cut them at field borders, or choose \"Automatic\" or \"On the fly\" as the motion"
        ),
        Some(Remedy::Place) => format!(
            "{e}; choose \"Placement: centred\" in the Layers panel to move it within reach"
        ),
        Some(Remedy::Cylinder) => format!("{e}; {CYLINDER_ADVICE}"),
        None => e.to_string(),
    }
}

/// What the window calls a placed field: a "region" when it is larger than the profile's scan
/// field (on the fly one region may hold what no scan field could: the stage carries the
/// field across it), else a "field".
pub fn field_word(field: &ScanField, profile: &MachineProfile) -> &'static str {
    const TOLERANCE_MM: f64 = 1e-6;
    let [w, h] = profile.field_mm;
    if field.size[0] > w + TOLERANCE_MM || field.size[1] > h + TOLERANCE_MM {
        "region"
    } else {
        "field"
    }
}

/// How many fields and regions there are, in words: "6 fields", "1 region", "2 fields and
/// 1 region".
pub fn fields_count(fields: &[ScanField], profile: &MachineProfile) -> String {
    let regions = fields
        .iter()
        .filter(|f| field_word(f, profile) == "region")
        .count();
    match (fields.len() - regions, regions) {
        (n, 0) => count(n, "field", "fields"),
        (0, r) => count(r, "region", "regions"),
        (n, r) => format!(
            "{} and {}",
            count(n, "field", "fields"),
            count(r, "region", "regions")
        ),
    }
}

/// The number shown for field `id`: 1…n in the visiting order of `visiting` (a plan's fields)
/// for the fields it has, else by placement order (`fields`), after the plan's.
pub fn field_number(fields: &[ScanField], visiting: Option<&[ScanField]>, id: usize) -> usize {
    field_numbers(fields, visiting)
        .get(&id)
        .copied()
        .unwrap_or(visiting.map_or(0, <[ScanField]>::len) + fields.len() + 1)
}

/// [`field_number`] of every field (and every visited one) at once, by id: what a frame that
/// labels thousands of fields needs (one pass, not one per field).
pub fn field_numbers(
    fields: &[ScanField],
    visiting: Option<&[ScanField]>,
) -> std::collections::HashMap<usize, usize> {
    let visited = visiting.unwrap_or(&[]);
    let mut out: std::collections::HashMap<usize, usize> = visited
        .iter()
        .enumerate()
        .map(|(k, f)| (f.id, k + 1))
        .collect();
    let mut next = visited.len() + 1;
    for f in fields {
        if let std::collections::hash_map::Entry::Vacant(e) = out.entry(f.id) {
            e.insert(next);
            next += 1;
        }
    }
    out
}

/// What changed since a plan was made, one reason a line.
pub fn stale_text(why: &[String]) -> String {
    format!("Changed since this plan was made:\n{}", why.join("\n"))
}

/// What a document holds, in an operator's two words: the drawing's shapes and, where hatch,
/// cuts or passes make them differ, the strokes to mark ("11 shapes, 200 strokes to mark").
pub fn shapes_and_strokes(doc: &crate::document::Document) -> String {
    let (shapes, strokes) = (doc.artwork.len(), doc.geometries.len());
    if shapes == strokes {
        count(shapes, "shape", "shapes")
    } else {
        format!(
            "{}, {} to mark",
            count(shapes, "shape", "shapes"),
            count(strokes, "stroke", "strokes")
        )
    }
}
