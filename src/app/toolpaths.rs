//! The GUI's one lowering: each plan's [`Toolpath`] (from [`lower_plan`]) kept at run time, so
//! that the canvas, its hover, the captions and the playback all read the same timed job.
//! Nothing here is saved; a plan that cannot be lowered keeps the error in words.

use super::axis_plot::AxisSamples;
use super::motion_plots::{route_points_mm, MotionSamples};
use crate::document::{Document, MachineProfile, Motion, Plan};
use crate::geom::Pt;
use crate::motion::{ScanMotion, Toolpath};
use crate::pipeline::lower_plan;
use std::sync::Arc;

/// A plan's lowered toolpath with the time window of each stroke's mark.
#[derive(Debug, Clone)]
pub struct Lowered {
    /// The toolpath.
    pub toolpath: Toolpath,
    /// Per stroke (index into `toolpath.strokes`): (start, end) of its mark, s.
    pub mark_s: Vec<(f64, f64)>,
    /// The stage route sampled for the canvas, mm (empty for step-and-scan).
    pub route_mm: Vec<Pt>,
    /// The on-the-fly motion sampled for the plots (`None` for step-and-scan).
    pub motion: Option<MotionSamples>,
    /// Each axis's speed sampled for the plot of a step-and-scan job that turns Z, A or B
    /// (`None` for any other).
    pub axes: Option<AxisSamples>,
    /// Where Z, A and B stand over the job (a job that turns them; `None` for any other).
    pub poses: Option<crate::motion::PoseTrack>,
    /// Which of Z, A and B the job turns or holds away from zero.
    pub pose_axes: [bool; 3],
    /// Per geometry (index), where its first stroke comes in the marking order, 0…1 (−1: not
    /// marked): the canvas colours marks by it.
    pub rank_by_geometry: Vec<f32>,
    /// A cylinder job seen on its unrolled surface, as the canvas draws it (`None`: flat).
    pub unrolled: Option<Unrolled>,
    /// The machine moves its stage in Y (a rotary machine without Y turns the part instead).
    pub has_y: bool,
}

/// A cylinder job on the unrolled surface: the canvas shows the drawing where it lands, not
/// the scanner's pre-distorted moves.
#[derive(Debug, Clone)]
pub struct Unrolled {
    /// The cylinder.
    pub cylinder: crate::document::Cylinder,
    /// The stage's Y while marking (over the cylinder's axis), mm.
    pub stage_y_mm: f64,
    /// The strips' height in focus, mm (none: the profile says no depth of focus).
    pub strip_mm: Option<f64>,
    /// The toolpath with every stroke's points on the unrolled surface.
    pub points: Toolpath,
}

impl Lowered {
    /// Wraps a toolpath and indexes its mark segments by stroke.
    pub fn new(toolpath: Toolpath) -> Self {
        let mut mark_s = vec![(f64::INFINITY, f64::INFINITY); toolpath.strokes.len()];
        for seg in &toolpath.segments {
            if let ScanMotion::Mark { stroke, .. } = seg.scan {
                if let Some(m) = mark_s.get_mut(stroke) {
                    // a stroke marked in parts (on the fly): from its first to its last
                    *m = (m.0.min(seg.start_s), seg.end_s());
                }
            }
        }
        let route_mm = route_points_mm(&toolpath);
        let motion = MotionSamples::of(&toolpath);
        // a job that turns Z, A or B: where they stand, and their speeds for the plot
        let poses = toolpath.moves_extra_axes().then(|| toolpath.pose_track());
        let axes = poses.as_ref().and_then(|t| AxisSamples::of(&toolpath, t));
        let start = toolpath.start_pose.values();
        let pose_axes = [0, 1, 2].map(|k| {
            start[k] != 0.0
                || toolpath
                    .stage_moves
                    .iter()
                    .any(|m| m.extra[k].distance_mm != 0.0)
        });
        let rank_by_geometry = rank_by_geometry(&toolpath);
        Self {
            toolpath,
            mark_s,
            route_mm,
            motion,
            axes,
            poses,
            pose_axes,
            rank_by_geometry,
            unrolled: None,
            has_y: true,
        }
    }

    /// `toolpath` of `plan` indexed ([`Lowered::new`]), and on a cylinder seen on its unrolled
    /// surface.
    pub fn of(plan: &Plan, toolpath: Toolpath) -> Self {
        let mut l = Self::new(toolpath);
        l.has_y = plan.profile.has_y();
        if let Some(cylinder) = plan.settings.cylinder {
            let angle: std::collections::HashMap<usize, f64> =
                plan.fields.iter().map(|f| (f.id, f.pose.a_deg)).collect();
            let points = l.toolpath.with_points_mapped(|st, p| {
                let a = angle.get(&st.field).copied().unwrap_or(0.0);
                cylinder.unrolled(p, a, st.stage.y)
            });
            let dof = plan.profile.scanner.depth_of_focus_mm;
            l.unrolled = Some(Unrolled {
                cylinder,
                stage_y_mm: crate::document::Cylinder::stage_y_mm(&plan.profile),
                strip_mm: dof.map(|d| cylinder.strip_height_mm(d, plan.profile.field_mm[1])),
                points,
            });
        }
        l
    }

    /// Stroke `k`'s points as the canvas draws them: on the unrolled surface for a cylinder.
    pub fn points(&self, k: usize) -> &[Pt] {
        match &self.unrolled {
            Some(u) => u.points.stroke_points(k),
            None => self.toolpath.stroke_points(k),
        }
    }

    /// Where the canvas shows the tool point and the stage at `t_s` (on a cylinder: the surface
    /// point under the scanner, and the middle of the strip under the head, with the part as
    /// turned then).
    pub fn shown_at(&self, t_s: f64) -> (Pt, Pt) {
        let state = self.toolpath.state_at(t_s);
        let (Some(u), Some(track)) = (&self.unrolled, &self.poses) else {
            return (state.tcp(), state.stage);
        };
        let a = track.at(t_s).a_deg;
        let tcp = u.cylinder.unrolled(state.tcp(), a, u.stage_y_mm);
        let stage = u
            .cylinder
            .unrolled(Pt::new(state.stage.x, u.stage_y_mm), a, u.stage_y_mm);
        (tcp, stage)
    }

    /// True when the stage moves on a continuous route while the scanner marks.
    pub fn on_the_fly(&self) -> bool {
        self.toolpath.route.is_some()
    }

    /// The job time, s.
    pub fn duration_s(&self) -> f64 {
        self.toolpath.duration_s()
    }

    /// How many strokes are completely marked at `t_s` (strokes are marked in order).
    pub fn strokes_done(&self, t_s: f64) -> usize {
        self.mark_s.partition_point(|&(_, end_s)| end_s <= t_s)
    }

    /// The position (from 0) of the first stroke of geometry `g` in marking order.
    pub fn stroke_of_geometry(&self, g: usize) -> Option<usize> {
        self.toolpath.strokes.iter().position(|s| s.geometry == g)
    }
}

/// Per geometry, the place of its first stroke in the marking order, 0…1 (−1: not marked).
fn rank_by_geometry(toolpath: &Toolpath) -> Vec<f32> {
    let strokes = &toolpath.strokes;
    let len = strokes.iter().map(|s| s.geometry + 1).max().unwrap_or(0);
    let mut r = vec![-1.0; len];
    let n = (strokes.len().max(2) - 1) as f32;
    for (i, st) in strokes.iter().enumerate() {
        if r[st.geometry] < 0.0 {
            r[st.geometry] = i as f32 / n;
        }
    }
    r
}

/// Which plan a cached toolpath was lowered from; a different key means lowering again. A plan
/// is lowered on its own inputs only (geometry revision, profile, pens, motion), so the key is
/// the plan's identity, not the document's settings.
#[derive(Debug, Clone, PartialEq)]
struct Key {
    name: String,
    steps: usize,
    job_time_bits: Option<u64>,
    fields: usize,
    geometry_rev: u64,
    profile: MachineProfile,
    motion: Motion,
}

impl Key {
    fn of(plan: &Plan) -> Self {
        Self {
            name: plan.name.clone(),
            steps: plan.order.len(),
            job_time_bits: plan.metrics.job_time_s.map(f64::to_bits),
            fields: plan.fields.len(),
            geometry_rev: plan.geometry_rev,
            profile: plan.profile.clone(),
            motion: plan.motion,
        }
    }
}

/// One plan's lowering: the toolpath, or why there is none.
#[derive(Debug, Clone)]
struct Entry {
    key: Key,
    result: Result<Arc<Lowered>, String>,
}

/// Lowers `plan` of `doc` and indexes it (or says in words why it cannot be lowered).
fn lower(doc: &Document, plan: &Plan) -> Result<Arc<Lowered>, String> {
    lower_plan(doc, plan)
        .map(|t| Arc::new(Lowered::of(plan, t)))
        .map_err(|e| format!("cannot lower {} to a toolpath: {e}", plan.name))
}

/// A plan lowered by a background job on the document it was solved on, for
/// [`ToolpathCache::adopt`]: the UI thread then need not lower it again.
#[derive(Debug, Clone)]
pub struct Prelowered(Entry);

impl Prelowered {
    /// Wraps the toolpath `plan` of `doc` was lowered to on the job's thread (by
    /// [`order_document_lowered`](crate::pipeline::order_document_lowered)) and indexes it.
    pub fn of(plan: &Plan, toolpath: Toolpath) -> Self {
        Self(Entry {
            key: Key::of(plan),
            result: Ok(Arc::new(Lowered::of(plan, toolpath))),
        })
    }

    /// The plan was renamed after its job (e.g. "(stopped)"): the key follows.
    pub fn renamed(mut self, name: &str) -> Self {
        self.0.key.name = name.to_string();
        self
    }
}

/// The toolpaths of a document's plans, by plan index.
#[derive(Debug, Clone, Default)]
pub struct ToolpathCache {
    entries: Vec<Entry>,
}

impl ToolpathCache {
    /// Lowers the plans that are new or changed (a plan added, loaded or removed, another
    /// profile, another motion mode, other geometries); returns how many were lowered. Cheap when nothing changed.
    pub fn sync(&mut self, doc: &Document) -> usize {
        self.entries.truncate(doc.plans.len());
        let mut lowered = 0;
        for (k, plan) in doc.plans.iter().enumerate() {
            let key = Key::of(plan);
            if self.entries.get(k).is_some_and(|e| e.key == key) {
                continue;
            }
            let entry = Entry {
                key,
                result: lower(doc, plan),
            };
            self.put(k, entry);
            lowered += 1;
        }
        lowered
    }

    /// Takes the lowering a job made of plan `k` (which must already be in the document); a
    /// following [`sync`](Self::sync) lowers it again only if the document changed meanwhile.
    pub fn adopt(&mut self, k: usize, lowered: Prelowered) {
        self.put(k, lowered.0);
    }

    /// Puts `entry` at plan index `k`. The entries are dense: when plans before `k` have none
    /// yet, the entry is not kept and the next sync lowers plan `k` itself (same result, on the
    /// UI thread).
    fn put(&mut self, k: usize, entry: Entry) {
        if k < self.entries.len() {
            self.entries[k] = entry;
        } else if k == self.entries.len() {
            self.entries.push(entry);
        }
    }

    /// Plan `k`'s toolpath, or the lowering error in words (`None`: no such plan, or not yet
    /// synchronised).
    pub fn get(&self, k: usize) -> Option<Result<&Lowered, &str>> {
        self.entries
            .get(k)
            .map(|e| e.result.as_deref().map_err(String::as_str))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::document::{
        Algo, Geometry, Metrics, MotionMode, PlanInputs, ScanField, Source, Step,
    };
    use crate::geom::Pt;

    fn doc_with_plan(bad_geometry: bool) -> Document {
        let line = Geometry::new(
            vec![Pt::new(10.0, 10.0), Pt::new(20.0, 10.0)],
            false,
            Source::default(),
        );
        let field = ScanField {
            id: 0,
            center: Pt::new(15.0, 10.0),
            size: [70.0; 2],
            locked: false,
            geometries: vec![0],
            pose: Default::default(),
        };
        let plan = Plan {
            name: "P".into(),
            algo: Algo::AsIs,
            fields: vec![field.clone()],
            order: vec![Step {
                geometry: if bad_geometry { 7 } else { 0 },
                field: 0,
                start_vertex: 0,
                reversed: false,
            }],
            metrics: Metrics::default(),
            history: Vec::new(),
            motion: Motion::Step,
            stage_route: None,
            layers: Vec::new(),
            ..Plan::new(
                &PlanInputs::of(&Document::default()),
                Motion::Step,
                Vec::new(),
                Vec::new(),
            )
        };
        Document {
            geometries: vec![line],
            fields: vec![field],
            plans: vec![plan],
            ..Document::default()
        }
    }

    #[test]
    fn lowers_once_and_again_only_when_the_plan_changes() {
        let mut doc = doc_with_plan(false);
        let mut cache = ToolpathCache::default();
        assert_eq!(cache.sync(&doc), 1);
        assert_eq!(cache.sync(&doc), 0);
        let l = cache.get(0).unwrap().unwrap();
        assert_eq!(l.toolpath.strokes.len(), 1);
        let (s0, s1) = l.mark_s[0];
        assert!(0.0 < s0 && s0 < s1 && s1 <= l.duration_s());
        assert_eq!(l.strokes_done(s0), 0);
        assert_eq!(l.strokes_done(s1), 1);
        // a plan is lowered on its own profile: the document's does not matter
        doc.profile.scanner.mark_speed_mm_s *= 2.0;
        assert_eq!(cache.sync(&doc), 0);
        doc.plans[0].profile.scanner.mark_speed_mm_s *= 2.0;
        assert_eq!(cache.sync(&doc), 1);
        assert!(!cache.get(0).unwrap().unwrap().on_the_fly());
        // a plan is lowered with the motion it was planned for
        doc.settings.motion = MotionMode::OnTheFly;
        cache.sync(&doc);
        assert!(!cache.get(0).unwrap().unwrap().on_the_fly());
        doc.plans[0].motion = Motion::OnTheFly;
        doc.settings.motion = MotionMode::Step;
        assert_eq!(cache.sync(&doc), 1);
        let l = cache.get(0).unwrap().unwrap();
        assert!(l.on_the_fly() && !l.route_mm.is_empty() && l.motion.is_some());
        doc.plans.clear();
        cache.sync(&doc);
        assert!(cache.get(0).is_none());
    }

    #[test]
    fn a_lowering_error_is_kept_in_words() {
        let doc = doc_with_plan(true);
        let mut cache = ToolpathCache::default();
        cache.sync(&doc);
        let e = cache.get(0).unwrap().unwrap_err();
        assert!(e.starts_with("cannot lower P to a toolpath:"), "{e}");
    }

    #[test]
    fn a_job_lowering_is_adopted_and_redone_only_if_the_plan_changed() {
        let mut doc = doc_with_plan(false);
        let job_doc = doc.clone();
        let toolpath = lower_plan(&job_doc, &job_doc.plans[0]).unwrap();
        let lowered = Prelowered::of(&job_doc.plans[0], toolpath).renamed("P (stopped)");
        doc.plans[0].name = "P (stopped)".into();
        let mut cache = ToolpathCache::default();
        cache.adopt(0, lowered.clone());
        assert_eq!(cache.sync(&doc), 0, "the job's lowering is taken as it is");
        assert_eq!(cache.get(0).unwrap().unwrap().toolpath.strokes.len(), 1);
        // the document's profile changed while the job ran: the plan is its own
        let mut cache = ToolpathCache::default();
        doc.profile.scanner.mark_speed_mm_s *= 2.0;
        cache.adopt(0, lowered.clone());
        assert_eq!(cache.sync(&doc), 0);
        // another plan in that place is lowered again
        let mut cache = ToolpathCache::default();
        doc.plans[0].profile.scanner.mark_speed_mm_s *= 2.0;
        cache.adopt(0, lowered.clone());
        assert_eq!(cache.sync(&doc), 1);
        // a plan index past the lowered ones is not kept: sync lowers it itself
        let mut cache = ToolpathCache::default();
        doc.plans.push(doc.plans[0].clone());
        cache.adopt(1, lowered);
        assert_eq!(cache.sync(&doc), 2);
    }
}
