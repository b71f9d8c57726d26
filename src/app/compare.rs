//! The compare view: two plans side by side (synchronised canvases) or overlaid, played back on
//! one clock, a metrics table led by the job time (the better value highlighted), and the GA
//! convergence plot.

use super::canvas::CanvasState;
use super::draw::colour;
use super::playback::{self, Playback};
use super::scene::{Canvas, Layers, PathLayer};
use super::toolpaths::{Lowered, ToolpathCache};
use crate::document::{Algo, Document, Metrics, ObjectiveKind, Plan, TimeBreakdown};
use egui::{Color32, RichText, Vec2};
use egui_plot::{HLine, Legend, Line, LineStyle, Plot, PlotPoints, Points};

/// State of the compare view.
#[derive(Debug, Default)]
pub struct CompareState {
    /// Index (into the document's plans) of plan A.
    pub a: Option<usize>,
    /// Index of plan B.
    pub b: Option<usize>,
    /// One canvas with both paths instead of two side by side.
    pub overlay: bool,
    /// Pan and zoom, shared by both canvases.
    pub canvas: CanvasState,
    /// Playback of both plans on one clock (run time only).
    pub playback: Playback,
}

impl CompareState {
    /// Keeps the selection valid for `n` plans; fills empty slots with the newest plans.
    pub fn fix(&mut self, n: usize) {
        for s in [&mut self.a, &mut self.b] {
            if s.is_some_and(|k| k >= n) {
                *s = None;
            }
        }
        if self.b.is_none() && n > 0 {
            self.b = Some(n - 1).filter(|&k| Some(k) != self.a);
        }
        if self.a.is_none() && n > 1 {
            self.a = (0..n).rev().find(|&k| Some(k) != self.b);
        }
    }
    /// Shows the new plan `new` (an index into `plans`) as B after a solve. A plan of the same
    /// algorithm as B (a re-run) takes B's place and A stays, so that a race set up between
    /// two algorithms stays on screen; otherwise the previous B moves to A.
    pub fn push(&mut self, new: usize, plans: &[Plan]) {
        if self.b == Some(new) {
            return;
        }
        let algo = |k: Option<usize>| k.and_then(|k| plans.get(k)).map(|p| p.algo);
        let rerun = algo(self.b).is_some() && algo(self.b) == algo(Some(new));
        if !rerun {
            self.a = self.b.or(self.a);
        }
        self.b = Some(new);
    }
}

/// What a row of the metrics table says about the plans.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowKind {
    /// The figure that decides (job time): emphasised, the better plan marked.
    Decides,
    /// A part of the job time (indented, not ranked).
    Part,
    /// Lower is better (highlighted in green).
    Ranked,
    /// Information only (never highlighted).
    Info,
    /// The computer's effort (solve time): shown, never ranked, no B against A.
    Effort,
}

/// One row of the metrics table.
struct Row {
    label: &'static str,
    help: &'static str,
    value: fn(&Plan) -> Option<f64>,
    decimals: usize,
    kind: RowKind,
    /// Shown only when a plan has the figure, and it is not zero (seams where nothing is cut).
    only_some: bool,
}

fn part(m: &Metrics, pick: fn(&TimeBreakdown) -> f64) -> Option<f64> {
    m.job_time_breakdown_s.as_ref().map(pick)
}

const ROWS: &[Row] = &[
    Row {
        label: "Job time (s)",
        help: "machine time of the whole job, from the lowered toolpath (stage moves, settling, \
               scanner jumps, marking, laser delays): the figure that decides",
        value: |p| p.metrics.job_time_s,
        decimals: 3,
        kind: RowKind::Decides,
        only_some: false,
    },
    Row {
        label: "Stage moves (s)",
        help: "part of the job time: the stage travelling between fields",
        value: |p| part(&p.metrics, |b| b.stage),
        decimals: 2,
        kind: RowKind::Part,
        only_some: false,
    },
    Row {
        label: "Stage settling (s)",
        help: "part of the job time: the stage settling after its moves",
        value: |p| part(&p.metrics, |b| b.settle),
        decimals: 2,
        kind: RowKind::Part,
        only_some: false,
    },
    Row {
        label: "Scanner jumps (s)",
        help: "part of the job time: scanner jumps and jump delays not hidden in a stage move",
        value: |p| part(&p.metrics, |b| b.jump),
        decimals: 2,
        kind: RowKind::Part,
        only_some: false,
    },
    Row {
        label: "Marking (s)",
        help: "part of the job time: marking, at the pens' mark speeds (on the fly slower where \
               the stage cannot follow, and on a controller clock in whole ticks)",
        value: |p| part(&p.metrics, |b| b.mark),
        decimals: 2,
        kind: RowKind::Part,
        only_some: false,
    },
    Row {
        label: "Laser delays (s)",
        help: "part of the job time: laser-on and laser-off delays around the marks",
        value: |p| part(&p.metrics, |b| b.laser_delays),
        decimals: 2,
        kind: RowKind::Part,
        only_some: false,
    },
    Row {
        label: "In step-and-scan fields (s)",
        help: "a mixed job (on the fly, some fields marked with the stage at rest): the time of \
               its step-and-scan stretches, from the end of the mark before each to its last \
               mark; the rest of the job runs on the fly",
        value: |p| {
            let regions = &p.metrics.motion_regions;
            (!regions.is_empty()).then(|| {
                regions
                    .iter()
                    .filter(|r| r.motion == crate::document::Motion::Step)
                    .map(|r| r.end_s - r.start_s)
                    .sum()
            })
        },
        decimals: 2,
        kind: RowKind::Info,
        only_some: true,
    },
    Row {
        label: "Idle travel (mm)",
        help: "laser-off travel of the tool point between strokes",
        value: |p| Some(p.metrics.idle_mm),
        decimals: 1,
        kind: RowKind::Ranked,
        only_some: false,
    },
    Row {
        label: "Stage travel (mm)",
        help: "base-stage travel through the field centres in visiting order (step-and-scan; \
               on the fly the stage follows its route instead: see Stage route)",
        value: |p| Some(p.metrics.base_mm),
        decimals: 1,
        kind: RowKind::Ranked,
        only_some: false,
    },
    Row {
        label: "Stage route (mm)",
        help: "length of the stage's route, sampled every millisecond (on the fly: the route it \
               follows while the scanner marks; step-and-scan: its moves between fields)",
        value: |p| p.metrics.motion.map(|f| f.stage_route_mm),
        decimals: 1,
        kind: RowKind::Ranked,
        only_some: false,
    },
    Row {
        label: "Peak stage speed (mm/s)",
        help: "the stage's largest speed (both axes together), sampled every millisecond (not \
               ranked: a faster job may well move faster)",
        value: |p| p.metrics.motion.map(|f| f.stage_peak_speed_mm_s),
        decimals: 0,
        kind: RowKind::Info,
        only_some: false,
    },
    Row {
        label: "Stage acceleration (mm/s²)",
        help: "mean: the stage's speed changes averaged over the job (their sum, sampled every \
               millisecond, divided by the job time): lower is a smoother ride; the report \
               keeps the sum as stage_speed_variation_mm_s (not ranked: the job time decides)",
        value: |p| {
            let f = p.metrics.motion?;
            let t = p.metrics.job_time_s.filter(|t| *t > 0.0)?;
            Some(f.stage_speed_variation_mm_s / t)
        },
        decimals: 0,
        kind: RowKind::Info,
        only_some: false,
    },
    Row {
        label: "Peak scanner offset (mm)",
        help: "the largest distance of the laser point from the field centre on either axis",
        value: |p| p.metrics.motion.map(|f| f.scan_peak_offset_mm),
        decimals: 1,
        kind: RowKind::Info,
        only_some: false,
    },
    Row {
        label: "Fields or regions",
        help: "number of scan fields the job visits (on the fly: regions, which may be larger \
               than the scan field)",
        value: |p| Some(p.metrics.fields as f64),
        decimals: 0,
        kind: RowKind::Ranked,
        only_some: false,
    },
    Row {
        label: "Seams",
        help: "seam lines where artwork larger than a field is cut (each a place where two \
               fields' marks meet)",
        value: |p| Some(p.seams.seams() as f64),
        decimals: 0,
        kind: RowKind::Ranked,
        only_some: true,
    },
    Row {
        label: "Seam crossings",
        help: "places where a mark crosses a seam and two fields' marks meet: where \
               stitching errors can show",
        value: |p| Some(p.seams.cuts as f64),
        decimals: 0,
        kind: RowKind::Ranked,
        only_some: true,
    },
    Row {
        label: "Marks along seams (mm)",
        help: "length marked along a seam line (fills and lines that run on it), shown when \
               some plan has any",
        value: |p| Some(p.seams.length_mm()),
        decimals: 1,
        kind: RowKind::Ranked,
        only_some: true,
    },
    Row {
        label: "Strokes split at seams",
        help: "strokes cut at seams, each into pieces marked from different fields (the \
               warnings say how many pieces each became)",
        value: |p| Some(p.seams.split_strokes as f64),
        decimals: 0,
        kind: RowKind::Ranked,
        only_some: true,
    },
    Row {
        label: "Direction changes",
        help: "reversals of the travel direction along the stage path",
        value: |p| Some(p.metrics.direction_changes as f64),
        decimals: 0,
        kind: RowKind::Ranked,
        only_some: false,
    },
    Row {
        label: "Marked length (mm)",
        help: "marked length (the same for every plan)",
        value: |p| Some(p.metrics.marked_mm),
        decimals: 1,
        kind: RowKind::Info,
        only_some: false,
    },
    Row {
        label: "Solve time (s)",
        help: "how long the computer took to make the plan: says nothing about the plan's quality",
        value: |p| Some(p.metrics.solve_s.total),
        decimals: 3,
        kind: RowKind::Effort,
        only_some: false,
    },
];

const BETTER_BG: Color32 = Color32::from_rgb(220, 252, 231);
const BETTER_FG: Color32 = Color32::from_rgb(21, 128, 61);
const WORSE_FG: Color32 = Color32::from_rgb(185, 28, 28);
/// Text size of the job-time row.
const DECIDES_PT: f32 = 16.0;

/// The metrics table of plan `a` and optionally `b`: job time first and emphasised (the
/// faster plan marked), its parts, the other metrics with the better value in green, and the
/// difference of B against A in %.
///
/// Plan names say what a plan is and run long, so the columns are headed "A" and "B" under the
/// names written out (wrapped) above the table; a table of one plan heads its column "Value".
pub fn metrics_table(ui: &mut egui::Ui, id: &str, a: &Plan, b: Option<&Plan>) {
    egui::Grid::new(id)
        .num_columns(4)
        .striped(true)
        .spacing([14.0, 3.0])
        .show(ui, |ui| {
            ui.label(RichText::new("Metric").strong());
            if b.is_some() {
                ui.label(RichText::new("A").strong().color(colour::PATH_A));
                ui.label(RichText::new("B").strong().color(colour::PATH_B));
                ui.label(RichText::new("B vs A").strong());
            } else {
                ui.label(RichText::new("Value").strong().color(colour::PATH_A));
            }
            ui.end_row();
            for row in ROWS.iter().filter(|row| row_shown(row, a, b)) {
                metrics_row(ui, row, a, b);
                ui.end_row();
            }
        });
}

/// Whether `row` is shown for plans `a` and `b`: a figure no plan shown has (a mixed job's),
/// or has as zero (seams of a job that cuts nothing), is left out, not shown as dashes.
fn row_shown(row: &Row, a: &Plan, b: Option<&Plan>) -> bool {
    let has = |p: &Plan| (row.value)(p).is_some_and(|v| v != 0.0);
    !row.only_some || has(a) || b.is_some_and(has)
}

/// The rows of the metrics table of `a` and `b`.
fn rows_shown(a: &Plan, b: Option<&Plan>) -> usize {
    ROWS.iter().filter(|row| row_shown(row, a, b)).count()
}

fn metrics_row(ui: &mut egui::Ui, row: &Row, a: &Plan, b: Option<&Plan>) {
    let label = RichText::new(row.label);
    match row.kind {
        RowKind::Decides => ui.label(label.strong().size(DECIDES_PT)),
        RowKind::Part => {
            ui.horizontal(|ui| {
                ui.add_space(14.0);
                ui.label(label)
            })
            .inner
        }
        RowKind::Ranked | RowKind::Info | RowKind::Effort => ui.label(label),
    }
    .on_hover_text(row.help);
    let va = (row.value)(a);
    let vb = b.and_then(|b| (row.value)(b));
    // values that differ are shown with the decimals that tell them apart
    let decimals = match (va, vb) {
        (Some(x), Some(y)) => decimals_to_differ(x, y, row.decimals),
        _ => row.decimals,
    };
    value_cell(ui, row, (va, vb), decimals);
    if b.is_none() {
        return;
    }
    value_cell(ui, row, (vb, va), decimals);
    match (va, vb) {
        (Some(x), Some(y)) if x.abs() > 1e-12 && row.kind != RowKind::Effort => {
            let pct = (y - x) / x * 100.0;
            // the deciding figure to 0.01 %: plans of a race (HHA, HGA) differ by tenths; a
            // difference the values show is never said as 0 %
            let least = if row.kind == RowKind::Decides { 2 } else { 1 };
            let decimals = if with_decimals(x, decimals) == with_decimals(y, decimals) {
                least
            } else {
                decimals_to_differ(pct, 0.0, least as usize) as i32
            };
            let zero = 0.5 * 10f64.powi(-decimals);
            let text = if pct.abs() < zero {
                format!("{:.*} %", decimals as usize, 0.0)
            } else {
                format!("{pct:+.*} %", decimals as usize)
            };
            let t = RichText::new(text).monospace();
            let ranked = matches!(row.kind, RowKind::Decides | RowKind::Ranked);
            let t = if !ranked || pct.abs() < zero {
                t
            } else if pct < 0.0 {
                t.color(BETTER_FG)
            } else {
                t.color(WORSE_FG)
            };
            ui.label(t);
        }
        _ => {
            ui.label("–");
        }
    }
}

/// The decimals to show `x` and `y` with: `least`, or up to three more where they differ but
/// would read the same.
fn decimals_to_differ(x: f64, y: f64, least: usize) -> usize {
    (least..=least + 3)
        .find(|&d| with_decimals(x, d) != with_decimals(y, d))
        .unwrap_or(least)
}

/// `v` with `d` decimals, never a negative zero ("-0.0" reads as "0.0").
fn with_decimals(v: f64, d: usize) -> String {
    let text = format!("{v:.d$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => text,
    }
}

/// One plan's value of `row` with `decimals`; the better of the two (lower, and reading
/// lower) highlighted: equal values are no win.
fn value_cell(
    ui: &mut egui::Ui,
    row: &Row,
    (mine, other): (Option<f64>, Option<f64>),
    decimals: usize,
) {
    let show = |v: f64| with_decimals(v, decimals);
    let text = mine.map_or("–".to_string(), show);
    let better = matches!((mine, other), (Some(x), Some(y)) if x < y && show(x) != show(y));
    let t = RichText::new(text).monospace();
    match row.kind {
        RowKind::Decides => {
            let t = t.strong().size(DECIDES_PT);
            if better {
                ui.horizontal(|ui| {
                    ui.label(t.color(BETTER_FG).background_color(BETTER_BG));
                    ui.label(RichText::new("faster").strong().color(BETTER_FG));
                });
            } else {
                ui.label(t);
            }
        }
        RowKind::Ranked if better => {
            ui.label(t.color(BETTER_FG));
        }
        RowKind::Ranked | RowKind::Part | RowKind::Info | RowKind::Effort => {
            ui.label(t);
        }
    }
}

/// Which plan is A and which is B, in their colours (the compare table's columns): above the
/// table, so that they stay in view when it scrolls.
fn plan_names(ui: &mut egui::Ui, a: &Plan, b: &Plan) {
    for (letter, p, col) in [("A", a, colour::PATH_A), ("B", b, colour::PATH_B)] {
        ui.add(
            egui::Label::new(
                RichText::new(format!("{letter}: {}", p.name))
                    .strong()
                    .color(col),
            )
            .wrap(),
        );
    }
}

/// A visible note under a metrics table for each stale plan: what changed since it was made
/// (its figures are those of its own inputs, not of the document's current ones).
pub fn stale_notes(ui: &mut egui::Ui, plans: &[(&Plan, &[String])]) {
    for (plan, why) in plans {
        let Some(first) = why.first() else { continue };
        ui.add(
            egui::Label::new(
                RichText::new(format!(
                    "{} is stale: {first} since it was made; its figures are those of the plan \
                     as made",
                    plan.name
                ))
                .color(colour::STALE),
            )
            .wrap(),
        )
        .on_hover_text(super::words::stale_text(why));
        if why.len() > 1 {
            // the other reasons, one click away
            egui::CollapsingHeader::new(
                RichText::new(format!("and {} more", why.len() - 1)).color(colour::STALE),
            )
            .id_salt(("stale-more", plan.name.as_str()))
            .show(ui, |ui| {
                for w in &why[1..] {
                    ui.add(
                        egui::Label::new(RichText::new(format!("• {w}")).color(colour::STALE))
                            .wrap(),
                    );
                }
            });
        }
    }
}

/// Says so plainly when an HGA plan that was not seeded with HHA's plan is slower than the
/// HHA plan beside it (seeded, HGA never is).
fn unseeded_note(ui: &mut egui::Ui, a: &Plan, b: &Plan) {
    for (ga, hha) in [(a, b), (b, a)] {
        if ga.algo != Algo::Hga || hha.algo != Algo::Hha || ga.settings.ga.seed_with_hha {
            continue;
        }
        // on the GA's own objective (the job time when it ranked on an estimate)
        let kind = ObjectiveKind::of(ga.settings.cost_model, ga.motion);
        let figure = |p: &Plan| kind.of_metrics(&p.metrics).or(p.metrics.job_time_s);
        let (Some(vg), Some(vh)) = (figure(ga), figure(hha)) else {
            continue;
        };
        if vg > vh {
            let pct = (vg - vh) / vh * 100.0;
            let worse = if kind == ObjectiveKind::IdleMm {
                format!("has {pct:.2} % more idle travel")
            } else {
                format!("is {pct:.2} % slower")
            };
            ui.add(
                egui::Label::new(
                    RichText::new(format!(
                        "{} was not seeded with the HHA plan (\"Seed the GA with the HHA plan\" \
                         is off in Solver settings), and {worse} than {}.",
                        ga.name, hha.name
                    ))
                    .color(WORSE_FG),
                )
                .wrap(),
            );
        }
    }
}

/// Width kept for the convergence plot's y tick labels (e.g. `12 345.6`), px.
const Y_AXIS_WIDTH_PX: f32 = 56.0;

/// The GA convergence plot: best (solid) and population mean (dotted, paler) per generation
/// of every plan with a history, in the plan's objective (job time, s, or idle travel, mm),
/// ending at the plan's table figure (a marked point); the HHA plan's table figure in the same
/// objective as a horizontal line.
///
/// Plans are named in the legend by their letter (A, B: the table's columns, whose headings
/// carry the full names), so that the legend stays short on a small window.
pub fn convergence_plot(ui: &mut egui::Ui, plans: &[(&Plan, Color32, &str)], hha: Option<&Plan>) {
    let with_history: Vec<_> = plans
        .iter()
        .filter(|(p, _, _)| !p.history.is_empty())
        .collect();
    let kind = with_history
        .first()
        .and_then(|(p, _, _)| p.history.first())
        .map_or(ObjectiveKind::JobTimeS, |h| h.objective);
    if with_history.is_empty() {
        ui.label("GA convergence: no generation history among the compared plans (run HGA).");
    } else if kind == ObjectiveKind::StepJobTimeEstimateS {
        ui.label(
            "On the fly the GA ranks plans on their job time as if marked step-and-scan (the \
             on-the-fly time needs the stage route); the table's job times are on the fly.",
        );
    }
    let hha_figure = hha.and_then(|h| kind.of_metrics(&h.metrics));
    Plot::new("convergence")
        .legend(Legend::default())
        .x_axis_label("Generation")
        .y_axis_label(kind.words())
        // ticks with as many decimals as their spacing needs, in a column wide enough for them
        .y_axis_formatter(|mark, _| {
            let decimals = (-mark.step_size.log10()).ceil().clamp(0.0, 3.0) as usize;
            format!("{:.*}", decimals, mark.value)
        })
        .y_axis_min_width(Y_AXIS_WIDTH_PX)
        .allow_scroll(false)
        .show(ui, |pui| {
            // first, dashed and thin: the GA's lines are drawn over it where they meet it
            if let Some(v) = hha_figure {
                pui.hline(
                    HLine::new(format!("HHA plan: {} {}", kind.show(v), kind.unit()), v)
                        .color(Color32::from_rgb(22, 163, 74))
                        .width(1.0)
                        .style(LineStyle::dashed_dense()),
                );
            }
            for (p, col, letter) in &with_history {
                let best: PlotPoints = p
                    .history
                    .iter()
                    .map(|h| [h.generation as f64, h.best])
                    .collect();
                let mean: PlotPoints = p
                    .history
                    .iter()
                    .filter(|h| !h.finished)
                    .map(|h| [h.generation as f64, h.mean])
                    .collect();
                pui.line(
                    Line::new(format!("{letter}: best"), best)
                        .color(*col)
                        .width(2.5),
                );
                pui.line(
                    Line::new(format!("{letter}: population mean"), mean)
                        .color(MEAN_GREY.lerp_to_gamma(*col, 0.12))
                        .width(1.5)
                        .style(LineStyle::dotted_dense()),
                );
                if let Some(last) = p.history.last().filter(|h| h.finished) {
                    let label =
                        format!("{letter} as made: {} {}", kind.show(last.best), kind.unit());
                    pui.points(
                        Points::new(label, vec![[last.generation as f64, last.best]])
                            .color(*col)
                            .radius(5.0),
                    );
                }
            }
        });
}

/// The grey the population-mean lines are drawn towards (they stay apart from the best lines).
const MEAN_GREY: Color32 = Color32::from_rgb(140, 140, 140);

fn plan_combo(ui: &mut egui::Ui, label: &str, slot: &mut Option<usize>, plans: &[Plan]) {
    let l = ui.label(label);
    let current = slot
        .and_then(|k| plans.get(k))
        .map_or("–", |p| p.name.as_str());
    egui::ComboBox::from_id_salt(label)
        .selected_text(current)
        .width(140.0)
        .show_ui(ui, |ui| {
            for (k, p) in plans.iter().enumerate() {
                ui.selectable_value(slot, Some(k), &p.name);
            }
        })
        .response
        .labelled_by(l.id);
}

/// The plans compared: A (or B alone) and B, as indices into the document's plans.
fn shown(st: &CompareState, n: usize) -> Option<(usize, Option<usize>)> {
    let a = st.a.filter(|&k| k < n);
    let b = st.b.filter(|&k| k < n);
    match (a, b) {
        (Some(a), b) => Some((a, b)),
        (None, Some(b)) => Some((b, None)),
        (None, None) => None,
    }
}

/// What the compare view's playback plays: the longer of the two jobs (both canvases follow
/// its clock), or the first lowering error.
fn played(
    toolpaths: &ToolpathCache,
    ka: usize,
    kb: Option<usize>,
) -> Option<Result<&Lowered, &str>> {
    let a = toolpaths.get(ka)?;
    let Some(b) = kb.and_then(|k| toolpaths.get(k)) else {
        return Some(a);
    };
    Some(match (a, b) {
        (Ok(x), Ok(y)) => Ok(if y.duration_s() > x.duration_s() {
            y
        } else {
            x
        }),
        (Err(e), _) | (_, Err(e)) => Err(e),
    })
}

fn toolbar(ui: &mut egui::Ui, st: &mut CompareState, plans: &[Plan]) {
    // wraps on a narrow view: a wider row would widen the whole view under the side panel
    ui.horizontal_wrapped(|ui| {
        plan_combo(ui, "Plan A", &mut st.a, plans);
        plan_combo(ui, "Plan B", &mut st.b, plans);
        if ui.button("Swap A/B").clicked() {
            std::mem::swap(&mut st.a, &mut st.b);
        }
        ui.separator();
        // how two plans are shown: nothing to choose with one
        let two = plans.len() > 1;
        ui.add_enabled_ui(two, |ui| {
            ui.selectable_value(&mut st.overlay, false, "Side by side");
            ui.selectable_value(&mut st.overlay, true, "Overlay");
        })
        .response
        .on_disabled_hover_text("one plan: solve another to compare two");
        ui.separator();
        if ui.button("Fit view").clicked() {
            st.canvas.fit_requested = true;
        }
    });
}

/// The whole compare view; `toolpaths` holds the plans' lowered toolpaths, `stale` what
/// changed since each plan was made.
pub fn show(
    ui: &mut egui::Ui,
    st: &mut CompareState,
    doc: &Document,
    toolpaths: &ToolpathCache,
    stale: &[Vec<String>],
    layers: Layers,
    revision: u64,
) {
    let stale_of = |k: usize| stale.get(k).map_or(&[][..], Vec::as_slice);
    st.fix(doc.plans.len());
    toolbar(ui, st, &doc.plans);
    let Some((ka, kb)) = shown(st, doc.plans.len()) else {
        ui.centered_and_justified(|ui| {
            ui.label("No plans yet: run HHA (or HGA) to compare plans.");
        });
        return;
    };
    let job = played(toolpaths, ka, kb);
    playback::controls(ui, "compare", &mut st.playback, job, false);
    let playback_t_s = job
        .and_then(Result::ok)
        .and_then(|_| st.playback.shown_t_s());
    let canvas = |k: usize, col: Color32| {
        plan_canvas(
            doc,
            toolpaths,
            k,
            col,
            (layers, stale_of(k), playback_t_s, revision),
        )
    };
    // the metrics table's height (its rows, the plans' names and a stale note), or less on a
    // small window (it scrolls then)
    let row_px = ui.text_style_height(&egui::TextStyle::Body) + 4.0;
    let rows = rows_shown(&doc.plans[ka], kb.map(|k| &doc.plans[k])) as f32;
    // a stale note takes about three lines, its "and N more" one
    let notes = [Some(ka), kb]
        .into_iter()
        .flatten()
        .filter(|&k| !stale_of(k).is_empty())
        .count() as f32;
    let needed = (rows + 5.0 + 4.0 * notes) * row_px + 16.0;
    let bottom = needed.min(ui.available_height() * 0.7);
    let top = (ui.available_height() - bottom - 8.0).max(100.0);
    let width = ui.available_width();
    match kb {
        Some(kb) if !st.overlay => {
            let half = (width - ui.spacing().item_spacing.x) / 2.0;
            ui.horizontal(|ui| {
                let mut ca = canvas(ka, colour::PATH_A);
                ca.label = "Plan A";
                ca.show(ui, &mut st.canvas, Some(Vec2::new(half, top)));
                let mut cb = canvas(kb, colour::PATH_B);
                cb.label = "Plan B";
                cb.show(ui, &mut st.canvas, Some(Vec2::new(half, top)));
            });
        }
        _ => {
            let mut c = canvas(ka, colour::PATH_A);
            // one plan is shown alone, whichever way two would be
            c.label = match kb {
                Some(_) => "Compare (overlay)",
                None => "One plan: solve another to compare two",
            };
            if let Some(kb) = kb {
                let mut other = canvas(kb, colour::PATH_B).paths;
                c.paths.append(&mut other);
                c.layers.order_colours = false;
            }
            c.show(ui, &mut st.canvas, Some(Vec2::new(width, top)));
        }
    }
    ui.add_space(4.0);
    figures(ui, doc, (ka, kb), &stale_of, (width, bottom));
}

/// The compared plans' figures: stale notes, the metrics table and, when a plan has a GA
/// history, the convergence plot beside it; `(width, bottom)` is the space they have, px.
fn figures<'s>(
    ui: &mut egui::Ui,
    doc: &Document,
    (ka, kb): (usize, Option<usize>),
    stale_of: &dyn Fn(usize) -> &'s [String],
    (width, bottom): (f32, f32),
) {
    let a = &doc.plans[ka];
    let b = kb.map(|k| &doc.plans[k]);
    let mut plans = vec![(a, colour::PATH_A, if b.is_some() { "A" } else { "Plan" })];
    if let Some(b) = b {
        plans.push((b, colour::PATH_B, "B"));
    }
    let history = plans.iter().any(|(p, _, _)| !p.history.is_empty());
    // the lines above the table (a note, the plans' names) come out of its height
    let end_y = ui.cursor().min.y + bottom;
    let metrics = |ui: &mut egui::Ui| {
        if let Some(b) = b {
            plan_names(ui, a, b);
        }
        // both ways: on a narrow view the table scrolls sideways rather than losing columns
        egui::ScrollArea::both()
            .id_salt("compare-metrics-scroll")
            .max_height((end_y - ui.cursor().min.y).max(80.0))
            .show(ui, |ui| {
                // stale figures are said to be so before they are shown
                let mut notes = vec![(a, stale_of(ka))];
                if let (Some(b), Some(kb)) = (b, kb) {
                    notes.push((b, stale_of(kb)));
                }
                stale_notes(ui, &notes);
                if let Some(b) = b {
                    unseeded_note(ui, a, b);
                }
                metrics_table(ui, "compare-metrics", a, b);
            });
    };
    if !history {
        // no GA history among the plans: the table has the whole width, the plot a line
        ui.label(
            RichText::new(
                "GA convergence: no generation history among the compared plans (run HGA).",
            )
            .weak(),
        );
        metrics(ui);
        return;
    }
    ui.horizontal_top(|ui| {
        ui.vertical(|ui| {
            ui.set_width((width * 0.5).clamp(METRICS_MIN_PX.min(width * 0.6), 480.0));
            metrics(ui);
        });
        ui.separator();
        ui.vertical(|ui| {
            let hha = [Some(a), b]
                .into_iter()
                .flatten()
                .find(|p| p.algo == Algo::Hha)
                .or_else(|| doc.plans.iter().rev().find(|p| p.algo == Algo::Hha));
            ui.set_height(bottom);
            convergence_plot(ui, &plans, hha);
        });
    });
}

/// The canvas of plan `k` drawn in `col`, with the canvas `layers`, the plan's staleness, the
/// playback time and the canvases' revision (`look`).
fn plan_canvas<'a>(
    doc: &'a Document,
    toolpaths: &'a ToolpathCache,
    k: usize,
    col: Color32,
    (layers, stale, playback_t_s, revision): (Layers, &'a [String], Option<f64>, u64),
) -> Canvas<'a> {
    let plan = &doc.plans[k];
    Canvas {
        label: "",
        geometries: &doc.geometries,
        profile: doc.reach_profile(),
        cylinder: plan.settings.cylinder,
        fields: &plan.fields,
        seams: &plan.seams.lines,
        tiling: plan.tiling.as_ref(),
        cell_max_mm: crate::fields::cell_max_mm(&plan.layers, plan.profile.field_mm),
        visiting: Some(&plan.fields),
        colours: None,
        out_of_reach: &[],
        paths: vec![PathLayer {
            plan,
            lowered: toolpaths.get(k).unwrap_or(Err("not lowered yet")),
            colour: col,
        }],
        uncovered: &[],
        selected: None,
        editable: false,
        add_tool: false,
        layers,
        stale,
        playback_t_s,
        parts: &[],
        codes: &[],
        revision,
    }
}

/// Width the compare view's metrics table would like beside the convergence plot, px.
const METRICS_MIN_PX: f32 = 400.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_that_differ_get_the_decimals_that_tell_them_apart() {
        assert_eq!(decimals_to_differ(9.108, 9.105, 3), 3);
        assert_eq!(decimals_to_differ(9.1081, 9.1079, 3), 4);
        assert_eq!(decimals_to_differ(791.61, 791.64, 1), 2);
        assert_eq!(decimals_to_differ(12.0, 12.0, 1), 1);
        // a −0.03 % difference is not said as 0.0 %
        assert_eq!(decimals_to_differ(-0.033, 0.0, 1), 2);
    }
}
