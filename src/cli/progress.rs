//! An indicatif progress bar on stderr for stages that take long.

use galvoplan::job::{Progress, ProgressSink};
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Shows a bar once a stage has run for half a second (hidden when stderr is not a terminal).
pub struct BarProgress {
    state: Mutex<State>,
}

struct State {
    stage: &'static str,
    since: Instant,
    bar: Option<ProgressBar>,
}

impl BarProgress {
    /// A sink with no bar yet.
    pub fn new() -> Self {
        Self {
            state: Mutex::new(State {
                stage: "",
                since: Instant::now(),
                bar: None,
            }),
        }
    }
    /// Removes the bar.
    pub fn finish(&self) {
        if let Ok(mut s) = self.state.lock() {
            if let Some(b) = s.bar.take() {
                b.finish_and_clear();
            }
        }
    }
}

impl ProgressSink for BarProgress {
    fn report(&self, p: &Progress) {
        let Ok(mut s) = self.state.lock() else {
            return;
        };
        if s.stage != p.stage {
            if let Some(b) = s.bar.take() {
                b.finish_and_clear();
            }
            s.stage = p.stage;
            s.since = Instant::now();
        }
        if s.bar.is_none() && s.since.elapsed() > Duration::from_millis(500) {
            let bar = ProgressBar::new(p.total.max(1));
            let style = ProgressStyle::with_template(
                "{prefix:>8} [{elapsed_precise}] {bar:30} {pos}/{len} {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            bar.set_prefix(p.stage);
            s.bar = Some(bar);
        }
        if let Some(b) = &s.bar {
            b.set_length(p.total.max(1));
            b.set_position(p.done);
            b.set_message(p.message.clone());
        }
    }
}
