//! The batch run's progress bar on stderr: how far the unshot power has
//! fallen towards the threshold, in log scale, with the rate of rays and
//! an estimate of the time left.

use crate::solver::StepReport;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::VecDeque;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Ticks of the bar: fine enough for a smooth bar on any terminal width.
const TICKS: u64 = 1000;

/// A progress bar drawn only when asked for and stderr is a terminal.
/// Its position is the fraction of the way, in log scale, from the initial
/// unshot power to the threshold; the ETA extrapolates the recent rate at
/// which the log of the unshot power falls. Past the threshold the bar is
/// full and says the solve is settling ([`crate::solver::SolverOptions::
/// settle`]), which has no rate to extrapolate.
pub struct Progress {
    bar: ProgressBar,
    threshold: f64,
    total_log: f64,
    start: Instant,
    rate: RateEstimate,
}

impl Progress {
    /// A bar for a solve that stops at `threshold` (a fraction of the
    /// emitted power); hidden unless `show` and stderr is a terminal.
    pub fn new(show: bool, threshold: f64) -> Progress {
        let target = if show && std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(TICKS), target);
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Progress {
            bar,
            threshold,
            total_log: (1.0 / threshold.max(f64::MIN_POSITIVE)).ln(),
            start: Instant::now(),
            rate: RateEstimate::default(),
        }
    }

    /// Shows a finished step; `rays` is every ray cast so far.
    pub fn step(&mut self, report: &StepReport, rays: u64) {
        let elapsed = self.start.elapsed();
        let fraction = report.unshot_fraction.max(f64::MIN_POSITIVE);
        let done_log = (1.0 / fraction).ln().max(0.0);
        self.rate.push(elapsed, done_log);
        let eta =
            self.rate.per_second().filter(|r| *r > 0.0).map(|r| {
                Duration::from_secs_f64(((self.total_log - done_log) / r).clamp(0.0, 1e7))
            });
        let rays_per_s = rays as f64 / elapsed.as_secs_f64().max(1e-9);
        self.bar
            .set_position(((done_log / self.total_log).clamp(0.0, 1.0) * TICKS as f64) as u64);
        let left = if report.unshot_fraction <= self.threshold {
            "settling".to_string()
        } else {
            format!(
                "ETA {}",
                eta.map(|d| format!("{:.0}s", d.as_secs_f64()))
                    .unwrap_or_else(|| "?".into())
            )
        };
        self.bar.set_message(format!(
            "step {} · unshot {:.3}% · {:.2} Mrays/s · {left}",
            report.step,
            report.unshot_fraction * 100.0,
            rays_per_s / 1e6,
        ));
    }

    /// Prints `line` on stderr above the bar, which stays.
    pub fn say(&self, line: &str) {
        self.bar.suspend(|| eprintln!("{line}"));
    }

    /// Removes the bar from the terminal.
    pub fn clear(&self) {
        self.bar.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.clear();
    }
}

/// The rate at which `log(1 / unshot fraction)` grows, over a sliding
/// window of recent steps.
#[derive(Default)]
struct RateEstimate {
    samples: VecDeque<(Duration, f64)>,
}

impl RateEstimate {
    /// Steps in the window: enough to smooth the step-to-step jitter of
    /// which polygon shoots, few enough to follow the slowing down.
    const WINDOW: usize = 20;

    fn push(&mut self, t: Duration, progress: f64) {
        self.samples.push_back((t, progress));
        if self.samples.len() > Self::WINDOW {
            self.samples.pop_front();
        }
    }

    fn per_second(&self) -> Option<f64> {
        let (t0, p0) = *self.samples.front()?;
        let (t1, p1) = *self.samples.back()?;
        let dt = (t1 - t0).as_secs_f64();
        (dt > 0.0).then(|| (p1 - p0) / dt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_follows_the_recent_window() {
        let mut rate = RateEstimate::default();
        assert_eq!(rate.per_second(), None);
        for k in 0..40u64 {
            // Slow at first, then one unit of log progress per second.
            let p = if k < 20 {
                k as f64 * 0.1
            } else {
                2.0 + (k - 20) as f64
            };
            rate.push(Duration::from_secs(k), p);
        }
        let r = rate.per_second().unwrap();
        assert!((r - 1.0).abs() < 1e-12, "{r}");
    }
}
