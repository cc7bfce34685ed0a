//! A solve that stops on an error leaves its evidence.
//!
//! A solver error is a bug ([`SolverError`]), and it may come after hours
//! of work. Instead of ending with nothing, the run writes what it has
//! up to the last good step: the step log (`--log`) and the convergence
//! plot (`--plot`) of the steps that finished, and the checkpoint
//! (`--checkpoint`) when the solution is still the last good step's (a
//! step that fails while reading or gathering is dropped before it
//! changes anything; one that fails while applying has changed it, and
//! the checkpoint saved before, if any, stays). The error names the step,
//! its shooter with the line of the scene file it comes from, the phase,
//! and the files written. No picture is written: it would show a solution
//! that is not one.

use super::checkpoint;
use crate::config::RunConfig;
use crate::output::convergence::{self, StepRecord};
use crate::prepare::Prepared;
use crate::session::Session;
use crate::solver::SolverError;
use std::path::PathBuf;

/// A solve stopped by a solver error, with what was written of it.
#[derive(Debug)]
pub struct Failure {
    /// What went wrong.
    pub error: SolverError,
    /// The failed step's shooter: its polygon index, the scene's name
    /// and the line (from 1) of the scene file it comes from; `None` when
    /// the error is not a step's.
    pub shooter: Option<(u32, String, u32)>,
    /// The last step that finished well (its state is what was written).
    pub last_good: u64,
    /// The files written up to that step, in the order log, plot,
    /// checkpoint.
    pub written: Vec<PathBuf>,
    /// Why a file asked for could not be written, if one could not.
    pub not_written: Vec<String>,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.error)?;
        if let Some((polygon, scene, line)) = &self.shooter {
            write!(f, "; polygon {polygon} comes from line {line} of {scene}")?;
        }
        if !self.written.is_empty() {
            let names: Vec<String> = self
                .written
                .iter()
                .map(|p| p.display().to_string())
                .collect();
            write!(
                f,
                "; written up to step {}: {}",
                self.last_good,
                names.join(", ")
            )?;
        }
        for reason in &self.not_written {
            write!(f, "; {reason}")?;
        }
        Ok(())
    }
}

/// Writes the evidence of a solve that stopped on `error`: the step log
/// and plot of `records` (the steps that finished) and, when the solution
/// is still the last good step's, the checkpoint (saved for
/// `fingerprint`). Failing to write one of them is said in the returned
/// failure, not raised over the solver's error.
pub(super) fn stopped(
    config: &RunConfig,
    prepared: &Prepared,
    session: &Session,
    records: &[StepRecord],
    error: SolverError,
    fingerprint: u64,
) -> Failure {
    let (shooter, last_good) = match &error {
        SolverError::NotFinite { step, shooter, .. } => (
            prepared
                .scene
                .polygons
                .get(shooter.index())
                .map(|p| (shooter.0, config.scene.display_name(), p.origin.line)),
            step - 1,
        ),
        _ => (None, session.totals().steps),
    };
    let mut written = Vec::new();
    let mut not_written = Vec::new();
    if let Some(path) = &config.log {
        match convergence::write_log_file(path, records) {
            Ok(()) => written.push(path.clone()),
            Err(e) => not_written.push(e.to_string()),
        }
    }
    if let Some(path) = &config.plot {
        let title = config.scene.display_name();
        match convergence::write_plot_file(path, records, config.solver.threshold, &title) {
            Ok(()) => written.push(path.clone()),
            Err(e) => not_written.push(e.to_string()),
        }
    }
    if let Some(path) = &config.checkpoint {
        let solver = session.solver();
        if solver.values_are_finite() && !solver.in_step() {
            match checkpoint::save(path, fingerprint, &solver.state(), records) {
                Ok(()) => written.push(path.clone()),
                Err(e) => not_written.push(e.to_string()),
            }
        } else {
            not_written.push(format!(
                "the checkpoint {} was not updated: the failed step changed the solution",
                path.display()
            ));
        }
    }
    Failure {
        error,
        shooter,
        last_good,
        written,
        not_written,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::{run, RunError};
    use crate::config::SceneSource;
    use crate::solver::step::POISON_READ_AT;
    use std::path::Path;

    /// A quick run of the bundled Cornell box writing `out.png`, the step
    /// log, the plot and a checkpoint into `dir`.
    fn quick_run(dir: &Path) -> RunConfig {
        let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.sc");
        let mut config = RunConfig::new(SceneSource::File(scene));
        config.output = Some(dir.join("out.png"));
        config.log = Some(dir.join("steps.csv"));
        config.plot = Some(dir.join("plot.png"));
        config.checkpoint = Some(dir.join("solve.ckpt"));
        config.size = Some((32, 32));
        config.lenmax = Some(60.0);
        config.solver.max_steps = Some(12);
        config
    }

    /// A step that fails writes the log, the plot and the checkpoint of
    /// the steps before it, names the step, shooter, line and phase, and
    /// the checkpoint resumes to the same end as a run that never failed.
    #[test]
    fn a_failed_step_leaves_the_log_plot_and_checkpoint_before_it() {
        let dir = tempfile::tempdir().unwrap();
        let config = quick_run(dir.path());
        POISON_READ_AT.set(5);
        let result = run(&config, &crate::cancel::Cancel::never());
        POISON_READ_AT.set(0);
        let Err(RunError::Failed(failure)) = result else {
            panic!("the run did not fail as injected: {result:?}");
        };
        let message = failure.to_string();
        assert!(message.starts_with("step 5 (shooter polygon "), "{message}");
        assert!(
            message.contains("while reading what the shooter sends"),
            "{message}"
        );
        assert!(message.contains("comes from line "), "{message}");
        assert!(message.contains("written up to step 4: "), "{message}");
        assert!(failure.not_written.is_empty(), "{message}");
        assert_eq!(failure.written.len(), 3, "{message}");
        assert!(!dir.path().join("out.png").exists());
        assert!(dir.path().join("plot.png").exists());
        let log = std::fs::read_to_string(dir.path().join("steps.csv")).unwrap();
        assert_eq!(log.lines().count(), 1 + 4, "{log}");
        assert_eq!(RunError::Failed(failure).exit_code(), 1);

        // Resumed, the checkpoint reaches what a run that never failed
        // reaches.
        let mut resumed = config.clone();
        resumed.resume = resumed.checkpoint.take();
        resumed.output = Some(dir.path().join("resumed.png"));
        resumed.log = Some(dir.path().join("resumed.csv"));
        resumed.plot = None;
        let resumed = run(&resumed, &crate::cancel::Cancel::never()).unwrap();
        let fresh = tempfile::tempdir().unwrap();
        let mut whole = quick_run(fresh.path());
        whole.checkpoint = None;
        let whole = run(&whole, &crate::cancel::Cancel::never()).unwrap();
        assert_eq!(resumed.steps, whole.steps);
        assert_eq!(
            resumed.unshot_fraction.to_bits(),
            whole.unshot_fraction.to_bits()
        );
        let a = std::fs::read(dir.path().join("resumed.png")).unwrap();
        let b = std::fs::read(fresh.path().join("out.png")).unwrap();
        assert!(a == b, "the resumed picture differs");
    }
}
