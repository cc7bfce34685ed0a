//! How far the step under way has got, readable from another thread
//! while the step runs.
//!
//! A batch run delivers every step in one piece, and the sky's step (all
//! of the sky at once, [`crate::solver::step::sky`]) or a particle tail
//! step ([`crate::solver::step::tail`]) can take a minute on a real
//! model: its progress bar reads this gauge to say how much of the step
//! is done and how long the rest should take, rather than stand still.
//! The steps that fill it count their own units of work (vertices
//! gathered, batches of particles traced); a step that does not fill it
//! leaves it idle.

use std::sync::atomic::{AtomicU64, Ordering};

/// The step under way's progress: `done` of `total` units of work.
/// Idle (`total` 0) between steps and during steps that do not report.
/// Written by the solver's thread, read by any; the two counts are read
/// apart, so a reader may see a `done` from just before a new `total`
/// (it clamps).
#[derive(Debug, Default)]
pub struct StepGauge {
    done: AtomicU64,
    total: AtomicU64,
}

impl StepGauge {
    /// A step of `total` units begins (or goes on) with `done` of them
    /// done; `total` 0 means idle.
    pub fn set(&self, done: u64, total: u64) {
        self.done.store(done, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }

    /// The step has ended or stopped: idle.
    pub fn idle(&self) {
        self.set(0, 0);
    }

    /// The fraction of the step under way done, in `[0, 1]`, or `None`
    /// when idle.
    pub fn fraction(&self) -> Option<f64> {
        let total = self.total.load(Ordering::Relaxed);
        let done = self.done.load(Ordering::Relaxed);
        (total > 0).then(|| (done.min(total)) as f64 / total as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gauge_reads_its_fraction_and_idles() {
        let g = StepGauge::default();
        assert_eq!(g.fraction(), None);
        g.set(25, 100);
        assert_eq!(g.fraction(), Some(0.25));
        // A stale `done` past a new `total` reads as the whole step.
        g.set(300, 100);
        assert_eq!(g.fraction(), Some(1.0));
        g.idle();
        assert_eq!(g.fraction(), None);
    }
}
