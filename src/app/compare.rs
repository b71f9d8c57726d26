//! The compare view: two plans side by side (synchronised canvases) or overlaid, a metrics
//! table with the better value highlighted, and the GA convergence plot.

use super::canvas::{Canvas, CanvasState, Layers, PathLayer};
use super::paint::colour;
use crate::document::{Algo, Document, Metrics, Plan};
use egui::{Color32, RichText, Vec2};
use egui_plot::{HLine, Legend, Line, LineStyle, Plot, PlotPoints};

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
    /// Shows `new` as B and the previous B as A (after a solve).
    pub fn push(&mut self, new: usize) {
        if self.b != Some(new) {
            self.a = self.b.or(self.a);
            self.b = Some(new);
        }
    }
}

/// One row of the metrics table.
struct Row {
    key: &'static str,
    help: &'static str,
    value: fn(&Metrics) -> Option<f64>,
    decimals: usize,
    /// Lower is better (else: information only).
    ranked: bool,
}

const ROWS: &[Row] = &[
    Row {
        key: "idle_mm",
        help: "laser-off travel between strokes, mm",
        value: |m| Some(m.idle_mm),
        decimals: 1,
        ranked: true,
    },
    Row {
        key: "base_mm",
        help: "base-stage travel through the field centres, mm",
        value: |m| Some(m.base_mm),
        decimals: 1,
        ranked: true,
    },
    Row {
        key: "fields",
        help: "number of scan fields",
        value: |m| Some(m.fields as f64),
        decimals: 0,
        ranked: true,
    },
    Row {
        key: "direction_changes",
        help: "reversals of the travel direction along the base path",
        value: |m| Some(m.direction_changes as f64),
        decimals: 0,
        ranked: true,
    },
    Row {
        key: "solve_s",
        help: "wall time of the solve, s",
        value: |m| Some(m.solve_s.total),
        decimals: 3,
        ranked: true,
    },
    Row {
        key: "job_time_s",
        help: "estimated step-and-scan machine time, s (when known)",
        value: |m| m.job_time_s,
        decimals: 2,
        ranked: true,
    },
    Row {
        key: "marked_mm",
        help: "marked length, mm (the same for every plan)",
        value: |m| Some(m.marked_mm),
        decimals: 1,
        ranked: false,
    },
];

const BETTER_BG: Color32 = Color32::from_rgb(220, 252, 231);
const BETTER_FG: Color32 = Color32::from_rgb(21, 128, 61);
const WORSE_FG: Color32 = Color32::from_rgb(185, 28, 28);

/// The metrics table of plan `a` and optionally `b`, with the better value highlighted and the
/// difference of B against A in %.
pub fn metrics_table(ui: &mut egui::Ui, id: &str, a: &Plan, b: Option<&Plan>) {
    egui::Grid::new(id)
        .num_columns(4)
        .striped(true)
        .spacing([14.0, 4.0])
        .show(ui, |ui| {
            ui.label(RichText::new("metric").strong());
            ui.label(RichText::new(&a.name).strong().color(colour::PATH_A));
            if let Some(b) = b {
                ui.label(RichText::new(&b.name).strong().color(colour::PATH_B));
                ui.label(RichText::new("B vs A").strong());
            }
            ui.end_row();
            for row in ROWS {
                ui.label(row.key).on_hover_text(row.help);
                let va = (row.value)(&a.metrics);
                let vb = b.and_then(|b| (row.value)(&b.metrics));
                let text = |v: Option<f64>| {
                    v.map_or("–".to_string(), |v| format!("{v:.*}", row.decimals))
                };
                let better = |mine: Option<f64>, other: Option<f64>| {
                    row.ranked && matches!((mine, other), (Some(x), Some(y)) if x < y)
                };
                let cell = |ui: &mut egui::Ui, mine: Option<f64>, other: Option<f64>| {
                    let t = RichText::new(text(mine)).monospace();
                    if better(mine, other) {
                        ui.label(t.strong().color(BETTER_FG).background_color(BETTER_BG));
                    } else {
                        ui.label(t);
                    }
                };
                cell(ui, va, vb);
                if b.is_some() {
                    cell(ui, vb, va);
                    match (va, vb) {
                        (Some(x), Some(y)) if x.abs() > 1e-12 => {
                            let pct = (y - x) / x * 100.0;
                            let t = RichText::new(format!("{pct:+.1} %")).monospace();
                            let t = if !row.ranked || pct.abs() < 0.05 {
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
                ui.end_row();
            }
        });
}

/// The GA convergence plot: best and mean idle travel per generation of every plan with a
/// history, and the HHA plan's idle travel as a horizontal line.
pub fn convergence_plot(ui: &mut egui::Ui, plans: &[(&Plan, Color32)], hha: Option<&Plan>) {
    let with_history: Vec<_> = plans
        .iter()
        .filter(|(p, _)| !p.history.is_empty())
        .collect();
    if with_history.is_empty() {
        ui.label("GA convergence: no generation history among the compared plans (run HGA).");
    }
    Plot::new("convergence")
        .legend(Legend::default())
        .x_axis_label("generation")
        .y_axis_label("idle mm")
        .allow_scroll(false)
        .show(ui, |pui| {
            for (p, col) in &with_history {
                let best: PlotPoints = p
                    .history
                    .iter()
                    .map(|h| [h.generation as f64, h.best_idle_mm])
                    .collect();
                let mean: PlotPoints = p
                    .history
                    .iter()
                    .map(|h| [h.generation as f64, h.mean_idle_mm])
                    .collect();
                pui.line(
                    Line::new(format!("{} best", p.name), best)
                        .color(*col)
                        .width(2.0),
                );
                pui.line(
                    Line::new(format!("{} mean", p.name), mean)
                        .color(col.gamma_multiply(0.6))
                        .style(LineStyle::dashed_loose()),
                );
            }
            if let Some(h) = hha {
                pui.hline(
                    HLine::new(format!("{} (HHA)", h.name), h.metrics.idle_mm)
                        .color(Color32::from_rgb(22, 163, 74))
                        .width(1.5),
                );
            }
        });
}

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

/// The whole compare view.
pub fn show(ui: &mut egui::Ui, st: &mut CompareState, doc: &Document, layers: Layers) {
    st.fix(doc.plans.len());
    ui.horizontal(|ui| {
        plan_combo(ui, "Plan A", &mut st.a, &doc.plans);
        plan_combo(ui, "Plan B", &mut st.b, &doc.plans);
        if ui.button("Swap A/B").clicked() {
            std::mem::swap(&mut st.a, &mut st.b);
        }
        ui.separator();
        ui.selectable_value(&mut st.overlay, false, "Side by side");
        ui.selectable_value(&mut st.overlay, true, "Overlay");
        ui.separator();
        if ui.button("Fit view").clicked() {
            st.canvas.fit_requested = true;
        }
    });
    let a = st.a.and_then(|k| doc.plans.get(k));
    let b = st.b.and_then(|k| doc.plans.get(k));
    let (a, b) = match (a, b) {
        (Some(a), b) => (a, b),
        (None, Some(b)) => (b, None),
        (None, None) => {
            ui.centered_and_justified(|ui| {
                ui.label("No plans yet: run HHA (or HGA) to compare plans.");
            });
            return;
        }
    };
    fn canvas<'a>(doc: &'a Document, p: &'a Plan, col: Color32, layers: Layers) -> Canvas<'a> {
        Canvas {
            label: "",
            geometries: &doc.geometries,
            profile: &doc.profile,
            fields: &p.fields,
            number_by_order: true,
            paths: vec![PathLayer {
                plan: p,
                colour: col,
            }],
            uncovered: &[],
            selected: None,
            editable: false,
            add_tool: false,
            layers,
            stale: false,
        }
    }
    let bottom = 270.0_f32.min(ui.available_height() * 0.45);
    let top = (ui.available_height() - bottom - 8.0).max(100.0);
    let width = ui.available_width();
    if st.overlay || b.is_none() {
        let mut c = canvas(doc, a, colour::PATH_A, layers);
        c.label = "Compare (overlay)";
        if let Some(b) = b {
            c.paths.push(PathLayer {
                plan: b,
                colour: colour::PATH_B,
            });
            c.layers.order_colours = false;
        }
        c.show(ui, &mut st.canvas, Some(Vec2::new(width, top)));
    } else if let Some(b) = b {
        let half = (width - ui.spacing().item_spacing.x) / 2.0;
        ui.horizontal(|ui| {
            let mut ca = canvas(doc, a, colour::PATH_A, layers);
            ca.label = "Plan A";
            ca.show(ui, &mut st.canvas, Some(Vec2::new(half, top)));
            let mut cb = canvas(doc, b, colour::PATH_B, layers);
            cb.label = "Plan B";
            cb.show(ui, &mut st.canvas, Some(Vec2::new(half, top)));
        });
    }
    ui.add_space(4.0);
    ui.horizontal_top(|ui| {
        ui.vertical(|ui| {
            ui.set_width((width * 0.42).min(480.0));
            metrics_table(ui, "compare-metrics", a, b);
        });
        ui.separator();
        ui.vertical(|ui| {
            let hha = [Some(a), b]
                .into_iter()
                .flatten()
                .find(|p| p.algo == Algo::Hha)
                .or_else(|| doc.plans.iter().rev().find(|p| p.algo == Algo::Hha));
            let mut plans = vec![(a, colour::PATH_A)];
            if let Some(b) = b {
                plans.push((b, colour::PATH_B));
            }
            ui.set_height(bottom);
            convergence_plot(ui, &plans, hha);
        });
    });
}
