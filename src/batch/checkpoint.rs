//! Checkpoint files: the batch run saves the solver's state (encoded by
//! [`crate::solver::checkpoint`]) atomically, and a resumed run reads it
//! back, refusing a file that is damaged or was saved for another solve.

use crate::output::{self, OutputError};
use crate::solver::checkpoint::{self, DecodeError, SolverState};
use crate::solver::{Progressive, SolverError};
use std::path::{Path, PathBuf};

/// Why a checkpoint could not be read or used. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file could not be read.
    #[error("cannot read checkpoint {}: {error}", path.display())]
    Read {
        /// The checkpoint file.
        path: PathBuf,
        /// What the operating system said.
        error: std::io::Error,
    },
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
        "checkpoint {} was saved for a different scene, mesh or form-factor options \
         (give the same scene, --lenmax, --inset, --form-factor, --shooter-samples and \
         --no-near-field as the run that saved it)",
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
    /// Writing the checkpoint failed.
    #[error("{0}")]
    Write(#[from] OutputError),
}

/// Saves `solver`'s state to `path` atomically (temporary file + rename):
/// the file is always either the previous checkpoint or the new one.
pub fn save(path: &Path, fingerprint: u64, solver: &Progressive) -> Result<(), CheckpointError> {
    let bytes = checkpoint::encode(fingerprint, solver);
    Ok(output::write_atomically(path, |w| w.write_all(&bytes))?)
}

/// Reads the checkpoint at `path` and checks it was saved for a solve with
/// `fingerprint`.
pub fn load(path: &Path, fingerprint: u64) -> Result<SolverState, CheckpointError> {
    let bytes = std::fs::read(path).map_err(|error| CheckpointError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    let (found, state) = checkpoint::decode(&bytes).map_err(|reason| CheckpointError::Invalid {
        path: path.to_path_buf(),
        reason,
    })?;
    if found != fingerprint {
        return Err(CheckpointError::Mismatch {
            path: path.to_path_buf(),
        });
    }
    Ok(state)
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
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("solve.ckpt");
        let bytes = checkpoint::encode_state(7, &state);
        output::write_atomically(&path, |w| w.write_all(&bytes)).unwrap();
        assert_eq!(load(&path, 7).unwrap(), state);
        let e = load(&path, 8).unwrap_err();
        assert!(matches!(e, CheckpointError::Mismatch { .. }), "{e}");
        assert!(e.to_string().contains("different scene"), "{e}");
        let e = load(&dir.path().join("missing"), 7).unwrap_err();
        assert!(e.to_string().contains("cannot read checkpoint"), "{e}");
    }
}
