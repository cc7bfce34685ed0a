//! The batch run's progress bar on stderr: how far the unshot power has
//! fallen towards the threshold, in log scale, with the rate of rays and
//! an estimate of the time left; and, while a long step runs, how much of
//! it is done and how long the rest should take.

use crate::solver::{StepGauge, StepReport};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::VecDeque;
use std::io::IsTerminal;
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How often the bar is redrawn while a step runs.
const REDRAW: Duration = Duration::from_millis(250);

/// How long a step runs before the bar speaks of it: shorter steps come
/// and go faster than anyone reads.
const LONG_STEP: Duration = Duration::from_secs(1);

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
    /// What the redrawing thread reads.
    shown: Arc<Mutex<Shown>>,
    /// The thread that redraws the bar while a step runs.
    redraw: Option<JoinHandle<()>>,
}

/// The bar's message after the last step, and the step under way.
struct Shown {
    /// The message [`Progress::step`] set.
    base: String,
    /// The number of the step under way.
    step: u64,
    /// What is under way when it is not a step (the refinement's
    /// gather): named instead of `step N`.
    activity: Option<&'static str>,
    /// When it began.
    began: Instant,
    /// Its solver's gauge, if the solver has one.
    gauge: Option<Arc<StepGauge>>,
    /// When the gauge was first seen filling in this step, and how full:
    /// the pace is measured from there, not from the step's start (its
    /// set-up and the first chunk's are not the rest's).
    since: Option<(Instant, f64)>,
    /// Set when the bar is cleared: not redrawn until the next step.
    cleared: bool,
    /// Set when the bar is dropped: the thread ends.
    done: bool,
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
        let shown = Arc::new(Mutex::new(Shown {
            base: String::new(),
            step: 1,
            activity: None,
            began: Instant::now(),
            gauge: None,
            since: None,
            cleared: false,
            done: false,
        }));
        // Only a bar someone sees is redrawn.
        let redraw = (!bar.is_hidden()).then(|| {
            let (bar, shown) = (bar.clone(), Arc::clone(&shown));
            std::thread::spawn(move || loop {
                std::thread::park_timeout(REDRAW);
                let mut shown = shown.lock().unwrap_or_else(PoisonError::into_inner);
                if shown.done {
                    break;
                }
                if shown.cleared {
                    continue;
                }
                bar.set_message(shown.message(Instant::now()));
                bar.tick();
            })
        });
        Progress {
            bar,
            threshold,
            total_log: (1.0 / threshold.max(f64::MIN_POSITIVE)).ln(),
            tail,
            tail_step: None,
            last: Duration::ZERO,
            start: Instant::now(),
            rate: RateEstimate::default(),
            shown,
            redraw,
        }
    }

    /// The solver whose steps come next reports their progress on
    /// `gauge` (`None`: it does not).
    pub fn follow(&self, gauge: Option<Arc<StepGauge>>) {
        self.shown().gauge = gauge;
    }

    fn shown(&self) -> std::sync::MutexGuard<'_, Shown> {
        self.shown.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The unshot fraction where the particle tail takes over is now
    /// `tail` (an automatic tail may take over early after a costly
    /// step: [`crate::solver::step::tail`]).
    pub fn set_tail(&mut self, tail: Option<f64>) {
        self.tail = tail;
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
        let message = format!(
            "step {} · unshot {:.3}% · {:.2} Mrays/s · {left}",
            report.step,
            report.unshot_fraction * 100.0,
            rays_per_s / 1e6,
        );
        self.bar.set_message(message.clone());
        let mut shown = self.shown();
        shown.base = message;
        shown.step = report.step + 1;
        shown.activity = None;
        shown.began = Instant::now();
        shown.since = None;
        shown.cleared = false;
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

    /// The pass has converged and its refinement's gather begins (the
    /// solver's gauge counts the new vertices gathered): the bar says so
    /// in place of the next step, with how far the gather has got.
    pub fn refining(&self) {
        let mut shown = self.shown();
        shown.base = "converged".to_string();
        shown.activity = Some("refining: new vertices gathering");
        shown.began = Instant::now();
        shown.since = None;
    }

    /// Prints `line` on stderr above the bar, which stays.
    pub fn say(&self, line: &str) {
        self.bar.suspend(|| eprintln!("{line}"));
    }

    /// Removes the bar from the terminal (until the next step).
    pub fn clear(&self) {
        // Under the lock the redrawing thread holds while it draws: it
        // draws nothing after this.
        self.shown().cleared = true;
        self.bar.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.shown().done = true;
        if let Some(thread) = self.redraw.take() {
            thread.thread().unpark();
            // A redraw thread that panicked has nothing left to clean up.
            let _ = thread.join();
        }
        self.clear();
    }
}

impl Shown {
    /// The bar's message at `now`: the last step's, and once the step
    /// under way has run past [`LONG_STEP`] how far it has got by its
    /// gauge and the time its pace since the gauge was first seen leaves
    /// (or only how long it has run, when it does not report).
    fn message(&mut self, now: Instant) -> String {
        let running = now.saturating_duration_since(self.began);
        let fraction = self.gauge.as_ref().and_then(|g| g.fraction());
        if let Some(f) = fraction {
            self.since.get_or_insert((now, f));
        }
        if running < LONG_STEP {
            return self.base.clone();
        }
        let now_says = match (fraction, self.since) {
            (Some(f), Some((t0, f0))) => {
                let pace = (f - f0) / now.saturating_duration_since(t0).as_secs_f64();
                let left = if pace > 0.0 {
                    format!(", {:.0}s left in it", (1.0 - f) / pace)
                } else {
                    String::new()
                };
                format!("{} {:.0}% done{left}", self.doing(), f * 100.0)
            }
            _ => format!("{} running {:.0}s", self.doing(), running.as_secs_f64()),
        };
        if self.base.is_empty() {
            now_says
        } else {
            format!("{} · {now_says}", self.base)
        }
    }

    /// What is under way: `step N`, or the activity named.
    fn doing(&self) -> String {
        match self.activity {
            Some(what) => what.to_string(),
            None => format!("step {}", self.step),
        }
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

    /// Past a second, a step's gauge says how much of it is done and
    /// what its pace since the gauge was first seen leaves; a step
    /// without one says how long it runs.
    #[test]
    fn a_long_step_says_how_far_it_has_got() {
        let gauge = Arc::new(StepGauge::default());
        let t0 = Instant::now();
        let mut shown = Shown {
            base: String::new(),
            step: 1,
            activity: None,
            began: t0,
            gauge: Some(Arc::clone(&gauge)),
            since: None,
            cleared: false,
            done: false,
        };
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        // The step's set-up: nothing done for the first two seconds.
        assert_eq!(shown.message(at(500)), "");
        gauge.set(0, 100);
        assert_eq!(shown.message(at(2_000)), "step 1 0% done");
        // 25 % in the next 5 s: 15 s for the 75 % left.
        gauge.set(25, 100);
        assert_eq!(shown.message(at(7_000)), "step 1 25% done, 15s left in it");
        gauge.idle();
        assert_eq!(shown.message(at(10_000)), "step 1 running 10s");
        // The next step's message keeps the last step's.
        shown.base = "step 1 · unshot 33.000%".to_string();
        shown.step = 2;
        shown.began = at(10_000);
        shown.since = None;
        gauge.set(3, 4);
        assert_eq!(shown.message(at(10_500)), "step 1 · unshot 33.000%");
        gauge.set(9, 10);
        assert_eq!(
            shown.message(at(11_500)),
            "step 1 · unshot 33.000% · step 2 90% done, 1s left in it"
        );
        shown.gauge = None;
        assert_eq!(
            shown.message(at(13_000)),
            "step 1 · unshot 33.000% · step 2 running 3s"
        );
    }

    /// Once a pass converges, the refinement's gather fills the gauge:
    /// the bar names it in place of a step, and the next step's report
    /// names steps again.
    #[test]
    fn the_refinements_gather_is_named_on_the_bar() {
        let gauge = Arc::new(StepGauge::default());
        let mut p = Progress::new(false, 0.001, None);
        p.follow(Some(Arc::clone(&gauge)));
        p.step(&report(5, 0.0005, 0), 10);
        p.refining();
        let later = |p: &Progress, s: u64| {
            let mut shown = p.shown();
            let began = shown.began;
            shown.message(began + Duration::from_secs(s))
        };
        gauge.set(0, 200);
        assert_eq!(
            later(&p, 2),
            "converged · refining: new vertices gathering 0% done"
        );
        gauge.set(50, 200);
        assert_eq!(
            later(&p, 4),
            "converged · refining: new vertices gathering 25% done, 6s left in it"
        );
        gauge.idle();
        p.step(&report(6, 0.0004, 0), 20);
        assert!(
            later(&p, 3).ends_with("step 7 running 3s"),
            "{}",
            later(&p, 3)
        );
    }

    /// A step's report is the base of the next one's message.
    #[test]
    fn a_finished_step_starts_the_next_ones_clock() {
        let mut p = Progress::new(false, 0.001, None);
        p.follow(Some(Arc::new(StepGauge::default())));
        p.step(&report(4, 0.5, 0), 10);
        let shown = p.shown();
        assert_eq!(shown.step, 5);
        assert!(
            shown.base.starts_with("step 4 · unshot 50.000%"),
            "{}",
            shown.base
        );
        assert!(shown.gauge.is_some());
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
