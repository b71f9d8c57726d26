//! [`JobCtx`]: what every pipeline stage receives — a cancel token, a progress sink and an
//! optional run recorder (rerun).

use crate::document::{Geometry, Plan, ScanField};
use crate::geom::Pt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;
use thiserror::Error;

/// The work was cancelled by the operator.
#[derive(Debug, Clone, Copy, Error, PartialEq, Eq)]
#[error("cancelled")]
pub struct Cancelled;

/// A shareable cancel flag; clones observe the same flag.
#[derive(Debug, Clone, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    /// A fresh, not-cancelled token.
    pub fn new() -> Self {
        Self::default()
    }
    /// Requests cancellation.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
    /// True once cancellation was requested.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// A progress report from a running stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Stage name (`import`, `fields`, `order`, `export`, ...).
    pub stage: &'static str,
    /// Units done.
    pub done: u64,
    /// Units in all (0 when unknown).
    pub total: u64,
    /// Free text, e.g. "generation 7: best 1234.5 mm".
    pub message: String,
}

/// Receives progress; implemented by the CLI's progress bar and the GUI's job state.
pub trait ProgressSink: Send + Sync {
    /// Called from the worker thread(s); must be cheap.
    fn report(&self, progress: &Progress);
}

/// A sink that drops everything.
#[derive(Debug, Default)]
pub struct NoProgress;

impl ProgressSink for NoProgress {
    fn report(&self, _: &Progress) {}
}

/// A sink that prefixes every message with a label ([`JobCtx::labelled`]).
struct Labelled {
    label: &'static str,
    inner: Arc<dyn ProgressSink>,
}

impl ProgressSink for Labelled {
    fn report(&self, p: &Progress) {
        self.inner.report(&Progress {
            message: format!("{}: {}", self.label, p.message),
            ..p.clone()
        });
    }
}

/// Records a run for later inspection (implemented with rerun behind the `rerun` feature).
pub trait RunRecorder: Send + Sync {
    /// The imported geometry.
    fn geometry(&self, geometries: &[Geometry]);
    /// The scan fields.
    fn fields(&self, fields: &[ScanField]);
    /// A finished plan: the tool-centre polylines of its marks in marking order, from its
    /// lowered toolpath (idle moves join one mark's end to the next's start).
    fn plan(&self, plan: &Plan, marks: &[&[Pt]]);
    /// One GA generation: best and mean objective (job time, s, or idle travel, mm).
    fn generation(&self, generation: usize, best: f64, mean: f64);
}

/// Context handed to every stage.
#[derive(Clone)]
pub struct JobCtx {
    cancel: CancelToken,
    progress: Arc<dyn ProgressSink>,
    recorder: Option<Arc<dyn RunRecorder>>,
    started: Instant,
}

impl Default for JobCtx {
    fn default() -> Self {
        Self::new(CancelToken::new(), Arc::new(NoProgress))
    }
}

impl std::fmt::Debug for JobCtx {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JobCtx")
            .field("cancelled", &self.cancel.is_cancelled())
            .field("recording", &self.recorder.is_some())
            .finish()
    }
}

impl JobCtx {
    /// A context with the given cancel token and progress sink, no recorder.
    pub fn new(cancel: CancelToken, progress: Arc<dyn ProgressSink>) -> Self {
        Self {
            cancel,
            progress,
            recorder: None,
            started: Instant::now(),
        }
    }
    /// The same job (cancel, recorder, clock) with every progress message prefixed by `label`
    /// ("Marked whole: "): what candidates planned side by side report, so that their
    /// interleaved words say which is which.
    pub fn labelled(&self, label: &'static str) -> Self {
        Self {
            progress: Arc::new(Labelled {
                label,
                inner: self.progress.clone(),
            }),
            ..self.clone()
        }
    }
    /// Adds a run recorder.
    pub fn with_recorder(mut self, recorder: Arc<dyn RunRecorder>) -> Self {
        self.recorder = Some(recorder);
        self
    }
    /// The recorder, if any.
    pub fn recorder(&self) -> Option<&dyn RunRecorder> {
        self.recorder.as_deref()
    }
    /// The cancel token.
    pub fn cancel_token(&self) -> &CancelToken {
        &self.cancel
    }
    /// True once cancellation was requested.
    pub fn is_cancelled(&self) -> bool {
        self.cancel.is_cancelled()
    }
    /// `Err(Cancelled)` once cancellation was requested.
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.cancel.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
    /// Seconds since the context was made.
    pub fn elapsed_s(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }
    /// Reports progress.
    pub fn progress(&self, stage: &'static str, done: u64, total: u64, message: impl Into<String>) {
        self.progress.report(&Progress {
            stage,
            done,
            total,
            message: message.into(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    struct Collect(Mutex<Vec<Progress>>);
    impl ProgressSink for Collect {
        fn report(&self, p: &Progress) {
            self.0.lock().unwrap().push(p.clone());
        }
    }

    #[test]
    fn cancel_and_progress() {
        let sink = Arc::new(Collect(Mutex::new(Vec::new())));
        let token = CancelToken::new();
        let ctx = JobCtx::new(token.clone(), sink.clone());
        assert!(ctx.check().is_ok());
        ctx.progress("fields", 1, 4, "x");
        token.cancel();
        assert_eq!(ctx.check(), Err(Cancelled));
        assert_eq!(sink.0.lock().unwrap()[0].total, 4);
    }
}
