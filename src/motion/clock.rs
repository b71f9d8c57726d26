//! The controller clock: a controller streaming at a period can switch the laser only on a
//! tick. One rule for both motion modes ([`super::Toolpath::on_clock`] and the on-the-fly
//! lowering): every mark starts on a tick, lasts whole ticks, and at least one tick with the
//! laser off separates two marks (so that the sample after a mark's end is off).

/// Ticks closer to a whole number than this are that whole number: durations are float sums,
/// and a mark that fills exactly two ticks must not become three.
const TICK_EPS: f64 = 1e-6;

/// `t_s` rounded up to whole ticks of `period_s`.
pub(crate) fn ceil_to_tick(t_s: f64, period_s: f64) -> f64 {
    ticks_covering(t_s, period_s) as f64 * period_s
}

/// The number of whole ticks of `period_s` that cover `t_s` (0 for `t_s ≤ 0`).
pub fn ticks_covering(t_s: f64, period_s: f64) -> usize {
    (t_s / period_s - TICK_EPS).ceil().max(0.0) as usize
}

/// Places marks on the clock one after the other.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MarkClock {
    period_s: f64,
    last_mark_end_s: f64,
}

impl MarkClock {
    /// A clock of `period_s` before any mark.
    pub(crate) fn new(period_s: f64) -> Self {
        Self {
            period_s,
            last_mark_end_s: f64::NEG_INFINITY,
        }
    }

    /// A mark that could start at `t_s` and lasts `duration_s`: its start and duration on the
    /// clock (start ≥ `t_s`; duration ≥ `duration_s`, so it is marked no faster).
    pub(crate) fn place(&mut self, t_s: f64, duration_s: f64) -> (f64, f64) {
        let p = self.period_s;
        let start_s = ceil_to_tick(t_s, p).max(self.last_mark_end_s + 2.0 * p);
        let duration_s = ceil_to_tick(duration_s, p);
        self.last_mark_end_s = start_s + duration_s;
        (start_s, duration_s)
    }
}
