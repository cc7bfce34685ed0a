//! Checkpoint files: the batch run saves the solver's state (encoded by
//! [`crate::solver::checkpoint`]) atomically, and a resumed run reads it
//! back, refusing a file that is damaged or was saved for another solve.
//!
//! The run's step log rides along as the checkpoint's driver record, so a
//! resumed run's `--log` and `--plot` continue the interrupted run's
//! instead of starting at the resumed step. The record is
//! [`LOG_RECORD_LEN`] bytes a step, little-endian: step (u64), shooter
//! (u64), shooter line (u64), shot power (f64 bits), unshot fraction (f64
//! bits), rays (u64), seconds (f64 bits).

use crate::output::convergence::StepRecord;
use crate::output::{self, OutputError};
use crate::scene::import::input::{read_file, InputError, InputKind};
use crate::solver::checkpoint::{self, DecodeError, SolverState};
use crate::solver::SolverError;
use std::path::{Path, PathBuf};

/// Why a checkpoint could not be read or used. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file could not be read: `FILE: error: cannot read: REASON`, as
    /// for every input file that cannot be read.
    #[error("{}: error: cannot read: {error}", path.display())]
    Read {
        /// The checkpoint file.
        path: PathBuf,
        /// What the operating system said.
        error: std::io::Error,
    },
    /// The file is no regular file, or is over the size limit of a
    /// checkpoint ([`InputKind::max_bytes`]).
    #[error("{0}")]
    Refused(InputError),
    /// The file is not a checkpoint of a supported version, or is damaged.
    #[error("{} is not a usable checkpoint: {reason}", path.display())]
    Invalid {
        /// The checkpoint file.
        path: PathBuf,
        /// What is wrong with its bytes.
        reason: DecodeError,
    },
    /// The checkpoint was written for another scene, mesh or solver options.
    #[error(
        "checkpoint {} was saved for a different scene, mesh or solver options \
         (give the same scene, --emit, --ies, --sky, --lenmax, --inset, --form-factor, \
         --hemicube-res, --shooter-samples, --unshot and the same solver switches \
         (--no-near-field, --no-shaft-culling, --no-clustering, --no-overshoot, \
         --exact-receivers, --without, --exact) as the run that saved it)",
        path.display()
    )]
    Mismatch {
        /// The checkpoint file.
        path: PathBuf,
    },
    /// The state does not fit the solver (a bug if the fingerprint matched).
    #[error("checkpoint {} does not fit this solve: {reason}", path.display())]
    Restore {
        /// The checkpoint file.
        path: PathBuf,
        /// What the solver refused.
        reason: SolverError,
    },
    /// The step log saved with it is damaged (its checksum matched, so
    /// it was written wrong: a bug).
    #[error(
        "checkpoint {}'s step log has {len} bytes, not a whole number of {LOG_RECORD_LEN}-byte steps",
        path.display()
    )]
    Log {
        /// The checkpoint file.
        path: PathBuf,
        /// The log's length in bytes.
        len: usize,
    },
    /// Writing the checkpoint failed.
    #[error("{0}")]
    Write(#[from] OutputError),
}

/// Bytes of one step in the log saved with a checkpoint.
pub const LOG_RECORD_LEN: usize = 56;

/// Saves a solver's `state` and the step log so far to `path` atomically
/// (temporary file + rename): the file is always either the previous
/// checkpoint or the new one.
pub fn save(
    path: &Path,
    fingerprint: u64,
    state: &SolverState,
    log: &[StepRecord],
) -> Result<(), CheckpointError> {
    let bytes = checkpoint::encode(fingerprint, state, &encode_log(log));
    Ok(output::write_atomically(path, |w| w.write_all(&bytes))?)
}

/// Reads the checkpoint at `path`, checks it was saved for a solve with
/// `fingerprint`, and returns the state and the step log saved with it
/// (empty for a checkpoint of an older version).
pub fn load(
    path: &Path,
    fingerprint: u64,
) -> Result<(SolverState, Vec<StepRecord>), CheckpointError> {
    let (bytes, _) = read_file(path, InputKind::Checkpoint).map_err(|e| match e {
        InputError::Io { error, .. } => CheckpointError::Read {
            path: path.to_path_buf(),
            error,
        },
        refused => CheckpointError::Refused(refused),
    })?;
    let decoded = checkpoint::decode(&bytes).map_err(|reason| CheckpointError::Invalid {
        path: path.to_path_buf(),
        reason,
    })?;
    if decoded.fingerprint != fingerprint {
        return Err(CheckpointError::Mismatch {
            path: path.to_path_buf(),
        });
    }
    let log = decode_log(&decoded.record).ok_or_else(|| CheckpointError::Log {
        path: path.to_path_buf(),
        len: decoded.record.len(),
    })?;
    Ok((decoded.state, log))
}

/// The step log as the checkpoint's driver record.
fn encode_log(log: &[StepRecord]) -> Vec<u8> {
    let mut out = Vec::with_capacity(log.len() * LOG_RECORD_LEN);
    for r in log {
        for w in [
            r.step,
            u64::from(r.shooter),
            u64::from(r.shooter_line),
            r.shot_power.to_bits(),
            r.unshot_fraction.to_bits(),
            r.rays,
            r.seconds.to_bits(),
        ] {
            out.extend_from_slice(&w.to_le_bytes());
        }
    }
    out
}

/// The step log back from a driver record; `None` when its length is not
/// a whole number of steps.
fn decode_log(bytes: &[u8]) -> Option<Vec<StepRecord>> {
    if !bytes.len().is_multiple_of(LOG_RECORD_LEN) {
        return None;
    }
    let words = |chunk: &[u8]| -> [u64; 7] {
        std::array::from_fn(|k| {
            let mut w = [0u8; 8];
            w.copy_from_slice(&chunk[8 * k..8 * k + 8]);
            u64::from_le_bytes(w)
        })
    };
    Some(
        bytes
            .chunks_exact(LOG_RECORD_LEN)
            .map(|chunk| {
                let [step, shooter, line, power, unshot, rays, seconds] = words(chunk);
                StepRecord {
                    step,
                    shooter: shooter as u32,
                    shooter_line: line as u32,
                    shot_power: f64::from_bits(power),
                    unshot_fraction: f64::from_bits(unshot),
                    rays,
                    seconds: f64::from_bits(seconds),
                }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;

    #[test]
    fn files_are_checked_against_the_fingerprint() {
        let state = SolverState {
            radiosity: vec![Rgb::new(0.1, 0.2, 0.3), Rgb::new(1.0 / 3.0, 0.0, 5e-324)],
            unshot: vec![Rgb::new(7.0, 8.0, 9.0)],
            steps: 42,
            rays: 1 << 40,
            charges: Vec::new(),
            tail_from: None,
            tail_began: Vec::new(),
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("solve.ckpt");
        let log = vec![StepRecord {
            step: 42,
            shooter: 3,
            shooter_line: 17,
            shot_power: 0.1,
            unshot_fraction: 1.0 / 3.0,
            rays: 1 << 33,
            seconds: 2.5,
        }];
        let bytes = checkpoint::encode(7, &state, &encode_log(&log));
        output::write_atomically(&path, |w| w.write_all(&bytes)).unwrap();
        assert_eq!(load(&path, 7).unwrap(), (state, log));
        let e = load(&path, 8).unwrap_err();
        assert!(matches!(e, CheckpointError::Mismatch { .. }), "{e}");
        assert!(e.to_string().contains("different scene"), "{e}");
        // Every option the fingerprint covers is named, so a user can
        // tell which one to repeat.
        for option in [
            "--emit",
            "--ies",
            "--sky",
            "--lenmax",
            "--inset",
            "--form-factor",
            "--hemicube-res",
            "--shooter-samples",
            "--unshot",
            "--no-near-field",
            "--no-shaft-culling",
            "--no-clustering",
            "--no-overshoot",
            "--exact-receivers",
            "--without",
            "--exact)",
        ] {
            assert!(e.to_string().contains(option), "{option} missing: {e}");
        }
        let e = load(&dir.path().join("missing"), 7).unwrap_err();
        assert!(
            e.to_string().contains("missing: error: cannot read: "),
            "{e}"
        );
    }

    #[test]
    fn a_log_of_a_broken_length_is_refused() {
        let log = encode_log(&[StepRecord {
            step: 1,
            shooter: 0,
            shooter_line: 1,
            shot_power: 1.0,
            unshot_fraction: 0.5,
            rays: 10,
            seconds: 0.1,
        }]);
        assert_eq!(log.len(), LOG_RECORD_LEN);
        assert!(decode_log(&log).is_some());
        assert!(decode_log(&log[..LOG_RECORD_LEN - 1]).is_none());
        assert_eq!(decode_log(&[]), Some(Vec::new()));
    }
}
