//! Progress on stderr for stages that take long: an indicatif bar on a terminal; otherwise (a
//! batch log, a pipe) one line every few seconds with the stage and how far it is, so that a
//! long job shows life.

use galvoplan::job::{Progress, ProgressSink};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::mpsc::{channel, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Seconds between progress lines when stderr is not a terminal.
const LOG_INTERVAL_S: f64 = 5.0;
/// Overrides [`LOG_INTERVAL_S`] (seconds; 0 turns the lines off).
const LOG_INTERVAL_ENV: &str = "GALVOPLAN_PROGRESS_S";

/// Shows a bar once a stage has run for half a second on a terminal; elsewhere prints a line
/// every [`LOG_INTERVAL_S`] seconds.
pub struct BarProgress {
    state: Arc<Mutex<State>>,
    ticker: Mutex<Option<(Sender<()>, JoinHandle<()>)>>,
    terminal: bool,
}

struct State {
    stage: &'static str,
    since: Instant,
    started: Instant,
    latest: Option<Progress>,
    bar: Option<ProgressBar>,
}

/// The interval of progress lines off a terminal: the environment's, else the default.
fn log_interval() -> Option<Duration> {
    let s = std::env::var(LOG_INTERVAL_ENV)
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .unwrap_or(LOG_INTERVAL_S);
    (s.is_finite() && s > 0.0).then(|| Duration::from_secs_f64(s))
}

/// One progress line: `galvoplan: order 3/4 (HHA: refine), 12 s in this stage, 47 s in all`.
fn line(s: &State) -> String {
    let all = s.started.elapsed().as_secs_f64();
    match &s.latest {
        Some(p) => {
            let count = if p.total > 0 {
                format!(" {}/{}", p.done, p.total)
            } else {
                String::new()
            };
            let msg = if p.message.is_empty() {
                String::new()
            } else {
                format!(" ({})", p.message)
            };
            format!(
                "galvoplan: {}{count}{msg}, {:.0} s in this stage, {all:.0} s in all",
                p.stage,
                s.since.elapsed().as_secs_f64()
            )
        }
        None => format!("galvoplan: working, {all:.0} s"),
    }
}

impl BarProgress {
    /// A sink with no bar yet; off a terminal its line printer starts now.
    pub fn new() -> Self {
        let now = Instant::now();
        let state = Arc::new(Mutex::new(State {
            stage: "",
            since: now,
            started: now,
            latest: None,
            bar: None,
        }));
        let terminal = std::io::stderr().is_terminal();
        let ticker = if terminal {
            None
        } else {
            log_interval().map(|every| {
                let (stop, wait) = channel::<()>();
                let shared = state.clone();
                let handle = std::thread::spawn(move || {
                    while let Err(RecvTimeoutError::Timeout) = wait.recv_timeout(every) {
                        let s = shared.lock().unwrap_or_else(PoisonError::into_inner);
                        eprintln!("{}", line(&s));
                    }
                });
                (stop, handle)
            })
        };
        Self {
            state,
            ticker: Mutex::new(ticker),
            terminal,
        }
    }

    /// Removes the bar and stops the line printer.
    pub fn finish(&self) {
        if let Some((stop, handle)) = self
            .ticker
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
        {
            // the printer ends on the message, or on the channel closing
            let _ = stop.send(());
            let _ = handle.join();
        }
        if let Ok(mut s) = self.state.lock() {
            if let Some(b) = s.bar.take() {
                b.finish_and_clear();
            }
        }
    }
}

impl Drop for BarProgress {
    fn drop(&mut self) {
        self.finish();
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
        s.latest = Some(p.clone());
        if !self.terminal {
            return;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_names_the_stage_and_how_far_it_is() {
        let mut s = State {
            stage: "order",
            since: Instant::now(),
            started: Instant::now(),
            latest: None,
            bar: None,
        };
        assert_eq!(line(&s), "galvoplan: working, 0 s");
        s.latest = Some(Progress {
            stage: "order",
            done: 3,
            total: 4,
            message: "HHA: refine".into(),
        });
        assert_eq!(
            line(&s),
            "galvoplan: order 3/4 (HHA: refine), 0 s in this stage, 0 s in all"
        );
    }
}
