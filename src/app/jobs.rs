//! Background work: solves, imports, hatching, field placement and exports run on a snapshot in
//! a named thread; the GUI polls the result each frame and never blocks on the worker.

use super::files::{ExportKind, Opened};
use super::toolpaths::Prelowered;
use crate::document::{Algo, Document, Plan};
use crate::job::{CancelToken, JobCtx, Progress, ProgressSink};
use crate::pipeline::order_document_lowered;
use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Keeps the latest progress report and wakes the GUI.
struct SharedProgress {
    latest: Mutex<Option<Progress>>,
    repaint: egui::Context,
}

impl ProgressSink for SharedProgress {
    fn report(&self, progress: &Progress) {
        if let Ok(mut l) = self.latest.lock() {
            *l = Some(progress.clone());
        }
        self.repaint.request_repaint();
    }
}

/// Threads of a GUI solve: all cores but one, which stays with the GUI thread (HGA is
/// deterministic for any number of threads, so this changes speed, not plans);
/// `GALVOPLAN_SOLVER_THREADS=N` overrides it.
pub fn solver_threads() -> usize {
    std::env::var("GALVOPLAN_SOLVER_THREADS")
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, |n| n.get().saturating_sub(1).max(1))
        })
}

/// What a finished job made.
pub enum JobResult {
    /// A plan (for HGA possibly the best one found before a cancel) and its toolpath, lowered
    /// on the job's thread so that the window does not wait for it (on the fly: seconds on
    /// large jobs).
    Plan {
        /// The plan.
        plan: Box<Plan>,
        /// Its lowering.
        lowered: Box<Prelowered>,
    },
    /// A file opened (imported SVG with fields placed, or a project).
    Opened {
        /// The file.
        path: PathBuf,
        /// The document and what went wrong on the way.
        opened: Box<Opened>,
    },
    /// The document with geometries made from its layers and fields placed again.
    Placed {
        /// The new document (geometries, layers, fields, plans, warnings).
        doc: Box<Document>,
        /// What the job did, for the status line and the undo menu.
        what: String,
        /// Why fields could not be placed (the document is taken all the same, its
        /// geometries uncovered), in the GUI's words.
        problem: Option<String>,
        /// The artwork moved or grew (imported again): the canvases fit the view to it.
        refit: bool,
    },
    /// An export written.
    Exported {
        /// The file.
        path: PathBuf,
        /// What was exported.
        kind: ExportKind,
    },
}

/// How a finished job ended.
pub enum JobOutcome {
    /// Its result.
    Done(JobResult),
    /// The job failed or was cancelled without a result.
    Failed(String),
}

/// A running background job.
pub struct Job {
    /// What it does, e.g. `HHA #1` or `importing demo.svg`.
    pub name: String,
    started: Instant,
    time_limit_s: Option<f64>,
    cancel: CancelToken,
    progress: Arc<SharedProgress>,
    rx: Receiver<Result<JobResult, String>>,
}

impl Job {
    /// Runs `work` in a new thread named `galvoplan-{thread}`; `repaint` is woken on progress
    /// and when the job ends.
    pub fn spawn(
        name: String,
        thread: &str,
        time_limit_s: Option<f64>,
        repaint: &egui::Context,
        work: impl FnOnce(&JobCtx) -> Result<JobResult, String> + Send + 'static,
    ) -> std::io::Result<Job> {
        let progress = Arc::new(SharedProgress {
            latest: Mutex::new(None),
            repaint: repaint.clone(),
        });
        let cancel = CancelToken::new();
        let ctx = JobCtx::new(cancel.clone(), progress.clone());
        let (tx, rx) = mpsc::channel();
        let wake = repaint.clone();
        std::thread::Builder::new()
            .name(format!("galvoplan-{thread}"))
            .spawn(move || {
                let threads = solver_threads();
                let run = || work(&ctx);
                let result = match rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .thread_name(|k| format!("galvoplan-worker-{k}"))
                    .build()
                {
                    Ok(pool) => pool.install(run),
                    Err(_) => run(),
                };
                // the receiver is gone only when the GUI dropped the job; nothing to tell then
                let _ = tx.send(result);
                wake.request_repaint();
            })?;
        Ok(Job {
            name,
            started: Instant::now(),
            time_limit_s,
            cancel,
            progress,
            rx,
        })
    }

    /// Starts ordering a snapshot of `doc` (geometries, fields, profile, settings, layers) with
    /// `algo`.
    pub fn solve(
        doc: &Document,
        algo: Algo,
        name: String,
        repaint: &egui::Context,
    ) -> std::io::Result<Job> {
        let mut snapshot = Document {
            source: doc.source.clone(),
            page_mm: doc.page_mm,
            layers: doc.layers.clone(),
            derived_with: doc.derived_with.clone(),
            geometries: doc.geometries.clone(),
            geometry_rev: doc.geometry_rev,
            profile: doc.profile.clone(),
            settings: doc.settings.clone(),
            fields: doc.fields.clone(),
            tiling: doc.tiling.clone(),
            seams: doc.seams.clone(),
            parts: doc.parts.clone(),
            ..Document::default()
        };
        snapshot.settings.algo = algo;
        let thread = format!("solve-{}", algo.label());
        let limit = doc.settings.time_limit_s;
        Job::spawn(name, &thread, limit, repaint, move |ctx| {
            let (plan, toolpath) =
                order_document_lowered(&snapshot, ctx).map_err(|e| e.to_string())?;
            let lowered = Box::new(Prelowered::of(&plan, toolpath));
            Ok(JobResult::Plan {
                plan: Box::new(plan),
                lowered,
            })
        })
    }

    /// The result once the worker is done (then the job is over); `None` while it runs.
    pub fn poll(&self) -> Option<JobOutcome> {
        match self.rx.try_recv() {
            Ok(Ok(result)) => Some(JobOutcome::Done(result)),
            Ok(Err(e)) => Some(JobOutcome::Failed(e)),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(JobOutcome::Failed(format!(
                "{}: the worker thread ended without a result",
                self.name
            ))),
        }
    }

    /// Asks the worker to stop (HGA returns its best plan so far).
    pub fn cancel(&self) {
        self.cancel.cancel();
    }

    /// True once Cancel was pressed.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.is_cancelled()
    }

    /// Time since the start.
    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// The latest progress report.
    pub fn progress(&self) -> Option<Progress> {
        self.progress.latest.lock().ok().and_then(|l| l.clone())
    }

    /// What the job is doing, in words: its name and the latest progress message (the status
    /// bar shows it in full, wrapped, beside the bar).
    pub fn progress_text(&self) -> String {
        match self.progress() {
            Some(p) => format!("{}: {}", self.name, p.message),
            None => format!("{}: starting", self.name),
        }
    }

    /// Draws a compact progress bar (the share done, when known), the elapsed time and a
    /// Cancel button; the words are [`Job::progress_text`].
    pub fn show(&self, ui: &mut egui::Ui) {
        let p = self.progress();
        let (fraction, known) = match &p {
            Some(p) if p.total > 0 => ((p.done as f32 / p.total as f32).clamp(0.0, 1.0), true),
            // unknown total (GA generations): the share of the time limit, when there is one
            Some(_) => (
                self.time_limit_s.map_or(0.0, |t| {
                    (self.elapsed().as_secs_f64() / t.max(1e-9)).clamp(0.0, 1.0) as f32
                }),
                self.time_limit_s.is_some(),
            ),
            None => (0.0, false),
        };
        let bar = egui::ProgressBar::new(fraction)
            .desired_width(PROGRESS_BAR_PX)
            .animate(true);
        let bar = if known { bar.show_percentage() } else { bar };
        ui.add(bar).on_hover_text(self.progress_text());
        ui.label(format!("{:.1} s", self.elapsed().as_secs_f64()));
        let label = if self.is_cancelled() {
            "Cancelling…"
        } else {
            "Cancel"
        };
        if ui
            .add_enabled(!self.is_cancelled(), egui::Button::new(label))
            .clicked()
        {
            self.cancel();
        }
    }
}

/// Width of the status bar's progress bar, px (its words are beside it).
const PROGRESS_BAR_PX: f32 = 110.0;

impl Drop for Job {
    fn drop(&mut self) {
        // a dropped job (document closed) should not keep a core busy
        self.cancel.cancel();
    }
}
