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
/// settle`]), which has no rate to extrapolate. With a particle tail
/// ([`crate::solver::step::tail`]) the estimate runs to the tail's start
/// and says so, and once a tail step has run, it is that step's time
/// times the tail steps left.
pub struct Progress {
    bar: ProgressBar,
    threshold: f64,
    total_log: f64,
    /// The unshot fraction where the particle tail takes over, if it does.
    tail: Option<f64>,
    /// How long the last tail step took, once one has run.
    tail_step: Option<Duration>,
    /// When the last step ended, since `start`.
    last: Duration,
    start: Instant,
    rate: RateEstimate,
}

impl Progress {
    /// A bar for a solve that stops at `threshold` (a fraction of the
    /// emitted power) and hands over to the particle tail at `tail` (the
    /// solver's [`crate::solver::Method::tail_from`]); hidden unless
    /// `show` and stderr is a terminal.
    pub fn new(show: bool, threshold: f64, tail: Option<f64>) -> Progress {
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
            tail,
            tail_step: None,
            last: Duration::ZERO,
            start: Instant::now(),
            rate: RateEstimate::default(),
        }
    }

    /// Shows a finished step; `rays` is every ray cast so far.
    pub fn step(&mut self, report: &StepReport, rays: u64) {
        let elapsed = self.start.elapsed();
        if report.particles > 0 {
            self.tail_step = Some(elapsed.saturating_sub(self.last));
        }
        self.last = elapsed;
        let fraction = report.unshot_fraction.max(f64::MIN_POSITIVE);
        let done_log = (1.0 / fraction).ln().max(0.0);
        if report.particles == 0 {
            self.rate.push(elapsed, done_log);
        }
        let rays_per_s = rays as f64 / elapsed.as_secs_f64().max(1e-9);
        self.bar
            .set_position(((done_log / self.total_log).clamp(0.0, 1.0) * TICKS as f64) as u64);
        let left = self.left(report.unshot_fraction, done_log);
        self.bar.set_message(format!(
            "step {} · unshot {:.3}% · {:.2} Mrays/s · {left}",
            report.step,
            report.unshot_fraction * 100.0,
            rays_per_s / 1e6,
        ));
    }

    /// What the bar says of the time left at unshot fraction `fraction`
    /// (`done_log` its log progress).
    fn left(&self, fraction: f64, done_log: f64) -> String {
        let seconds = |d: Duration| format!("{:.0}s", d.as_secs_f64());
        let by_rate = |target_log: f64| {
            self.rate
                .per_second()
                .filter(|r| *r > 0.0)
                .map(|r| Duration::from_secs_f64(((target_log - done_log) / r).clamp(0.0, 1e7)))
                .map_or_else(|| "?".to_string(), seconds)
        };
        match self.tail {
            Some(from) if fraction <= from => {
                let steps = crate::solver::step::tail::steps_left(from, fraction);
                match self.tail_step {
                    Some(d) => format!("particle tail, ETA {}", seconds(d * steps)),
                    None => "particle tail, ETA ?".to_string(),
                }
            }
            Some(from) if from > self.threshold => {
                format!(
                    "ETA {} to the particle tail",
                    by_rate((1.0 / from.max(f64::MIN_POSITIVE)).ln())
                )
            }
            _ if fraction <= self.threshold => "settling".to_string(),
            _ => format!("ETA {}", by_rate(self.total_log)),
        }
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

    /// A report of step `step` at unshot fraction `fraction`, a tail
    /// step when `particles > 0`.
    fn report(step: u64, fraction: f64, particles: u64) -> StepReport {
        StepReport {
            step,
            shooter: crate::scene::PolygonId(0),
            polygons: 1,
            shot_power: 1.0,
            unshot_fraction: fraction,
            rays: 0,
            pairs: 0,
            receivers: 0,
            clear_receivers: 0,
            part: 1,
            complete: true,
            particles,
        }
    }

    /// Before the tail the estimate runs to the tail's start, not to the
    /// threshold; once a tail step has run, it is that step's time for
    /// each tail step left.
    #[test]
    fn the_estimate_runs_to_the_tail_and_then_counts_its_steps() {
        let mut p = Progress::new(false, 0.001, Some(0.04));
        // One unit of log progress a second, from 1 to e^-2.
        for k in 0..=20u64 {
            p.rate.push(Duration::from_millis(100 * k), k as f64 * 0.1);
        }
        let left = p.left((-2.0f64).exp(), 2.0);
        // ln(1/0.04) = 3.22: 1.2 s to go.
        assert_eq!(left, "ETA 1s to the particle tail");
        assert_eq!(p.left(0.039, 3.24), "particle tail, ETA ?");
        p.tail_step = Some(Duration::from_secs(5));
        // Four tail steps from just under 4 %, then three, ... none.
        assert_eq!(p.left(0.039, 3.24), "particle tail, ETA 20s");
        assert_eq!(p.left(0.03, 3.5), "particle tail, ETA 15s");
        assert_eq!(p.left(0.0, 30.0), "particle tail, ETA 0s");
        let mut q = Progress::new(false, 0.001, None);
        q.step(&report(1, 0.5, 0), 10);
        assert_eq!(q.left(0.0005, 7.6), "settling");
        // A tail step's time is what the next estimate counts.
        let mut t = Progress::new(false, 0.001, Some(0.04));
        t.step(&report(1, 0.03, 1000), 10);
        assert!(t.tail_step.is_some());
    }

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
