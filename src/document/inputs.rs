//! What a plan is made from ([`PlanInputs`]), the geometry revisions plans refer to, and why a
//! plan no longer matches the document ([`staleness`]), in the operator's words.

use super::{Document, Geometry, Layer, MachineProfile, Plan, ScanField, SolverSettings};
use serde::{Deserialize, Serialize};

/// The exact inputs of a solve besides the geometries and fields: a plan records them
/// ([`Plan::new`]), and its figures, lowering and exports are of them.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanInputs {
    /// Revision of the geometries ([`Document::geometry_rev`]).
    pub geometry_rev: u64,
    /// The machine.
    pub profile: MachineProfile,
    /// The layers and their pens (speeds, powers, passes, hatch).
    pub layers: Vec<Layer>,
    /// The solver settings, with the algorithm and motion of this solve.
    pub settings: SolverSettings,
}

impl PlanInputs {
    /// The document's current inputs.
    pub fn of(doc: &Document) -> Self {
        Self {
            geometry_rev: doc.geometry_rev,
            profile: doc.profile.clone(),
            layers: doc.layers.clone(),
            settings: doc.settings.clone(),
        }
    }
    /// The inputs a plan was made from: the motion asked for (automatic, or the plan's own).
    pub fn of_plan(plan: &Plan) -> Self {
        let motion = match plan.settings.motion {
            super::MotionMode::Auto => super::MotionMode::Auto,
            _ => plan.motion.into(),
        };
        Self {
            geometry_rev: plan.geometry_rev,
            profile: plan.profile.clone(),
            layers: plan.layers.clone(),
            settings: SolverSettings {
                algo: plan.algo,
                motion,
                ..plan.settings.clone()
            },
        }
    }
}

/// An earlier list of geometries that plans still refer to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeometryRevision {
    /// Its revision.
    pub rev: u64,
    /// The geometries of that revision.
    pub geometries: Vec<Geometry>,
}

impl Document {
    /// Replaces the geometries. When they differ, the revision goes up, the fields (which
    /// refer to geometry indices) are cleared, and plans keep the list they were planned on.
    /// Returns true when the geometries changed.
    pub fn set_geometries(&mut self, geometries: Vec<Geometry>) -> bool {
        if geometries == self.geometries {
            return false;
        }
        let rev = self.geometry_rev;
        let referred = self.plans.iter().any(|p| p.geometry_rev == rev);
        if referred && !self.kept_geometries.iter().any(|k| k.rev == rev) {
            self.kept_geometries.push(GeometryRevision {
                rev,
                geometries: std::mem::take(&mut self.geometries),
            });
        }
        let newest = self
            .kept_geometries
            .iter()
            .map(|k| k.rev)
            .max()
            .unwrap_or(0);
        self.geometry_rev = rev.max(newest) + 1;
        self.geometries = geometries;
        self.fields.clear();
        self.prune_kept_geometries();
        true
    }
    /// Drops kept geometry lists no plan refers to any longer.
    pub fn prune_kept_geometries(&mut self) {
        let plans = &self.plans;
        self.kept_geometries
            .retain(|k| plans.iter().any(|p| p.geometry_rev == k.rev));
    }
    /// The geometries `plan` was planned on (none: a plan of a revision the document lost).
    pub fn plan_geometries(&self, plan: &Plan) -> Option<&[Geometry]> {
        if plan.geometry_rev == self.geometry_rev {
            return Some(&self.geometries);
        }
        self.kept_geometries
            .iter()
            .find(|k| k.rev == plan.geometry_rev)
            .map(|k| k.geometries.as_slice())
    }
}

/// Why `plan` no longer matches the document, in words (empty: it is current): what changed
/// since it was planned, e.g. `fill: speed 600 → 300 mm/s`.
pub fn staleness(plan: &Plan, doc: &Document) -> Vec<String> {
    let mut why = Vec::new();
    if plan.geometry_rev != doc.geometry_rev {
        why.push("the geometries changed (artwork, layers or hatch)".to_string());
    } else if fields_key(&plan.fields) != fields_key(&doc.fields) {
        why.push("the scan fields changed".to_string());
    }
    // rows of an axis the new machine does not have are not said (its Y on a rotary machine)
    let profile_rows: Vec<_> = super::spec::profile_specs()
        .into_iter()
        .filter(|s| super::spec::profile_row_present(s, &doc.profile))
        .collect();
    why.extend(super::spec::differences(
        &profile_rows,
        &plan.profile,
        &doc.profile,
    ));
    why.extend(layer_differences(
        (&plan.layers, &plan.profile),
        (&doc.layers, &doc.profile),
    ));
    let planned = PlanInputs::of_plan(plan).settings;
    let now = SolverSettings {
        algo: plan.algo,
        ..doc.settings.clone()
    };
    why.extend(super::spec::differences(
        &super::spec::settings_specs(),
        &planned,
        &now,
    ));
    why.extend(super::spec::differences(
        &super::spec::cylinder_specs(),
        &planned,
        &now,
    ));
    why
}

/// Pen changes between two layer tables (each with the profile its unset values come from),
/// per layer by name. A value a pen leaves to its profile is compared, and said, as the
/// profile's value ("mark speed 1000 → 500 mm/s", not "none → 500"): a pen that now sets what
/// the profile gave is no change.
fn layer_differences(
    (planned, planned_profile): (&[Layer], &super::MachineProfile),
    (now, profile): (&[Layer], &super::MachineProfile),
) -> Vec<String> {
    let specs = super::spec::pen_specs();
    let mut why = Vec::new();
    for l in now {
        match planned.iter().find(|p| p.name == l.name) {
            Some(p) => why.extend(
                super::spec::differences(
                    &specs,
                    &with_profile(&p.pen, planned_profile),
                    &with_profile(&l.pen, profile),
                )
                .into_iter()
                .map(|d| format!("{}: {d}", super::layer_label(&l.name))),
            ),
            None if !planned.is_empty() => {
                why.push(format!("{}: a new layer", super::layer_label(&l.name)))
            }
            None => {}
        }
    }
    why
}

/// `pen` with the values it leaves to `profile` (speed, power, dot dwell) set to the profile's.
fn with_profile(pen: &super::Pen, profile: &super::MachineProfile) -> super::Pen {
    super::Pen {
        mark_speed_mm_s: Some(pen.mark_speed_mm_s(profile)),
        power: pen.power(profile),
        dot_dwell_s: Some(pen.dot_dwell_s(profile)),
        ..pen.clone()
    }
}

/// The fields as a comparable key (ids, centres and sizes to the bit, allocation as a set).
fn fields_key(fields: &[ScanField]) -> Vec<(usize, [u64; 4], Vec<usize>)> {
    let mut v: Vec<_> = fields
        .iter()
        .filter(|f| !f.geometries.is_empty())
        .map(|f| {
            let mut g = f.geometries.clone();
            g.sort_unstable();
            let b = [f.center.x, f.center.y, f.size[0], f.size[1]].map(f64::to_bits);
            (f.id, b, g)
        })
        .collect();
    v.sort();
    v
}
