//! Writing results to files: pictures (png, tiff, exr, pfm), the solved
//! mesh (glb, ply), the convergence log and plot, illuminance at points and
//! over work planes (CSV, plan), and the atomic-write helper every output
//! shares.
//!
//! Every file is written to a temporary file in its destination directory
//! and renamed into place once complete ([`write_atomically`]), so a failed
//! or interrupted run never leaves a partial file behind, and an existing
//! file is either fully replaced or untouched.
//!
//! Errors are [`OutputError`]s; each names the path it is about and, when
//! the operating system or an encoder failed, says why in the same message.

pub mod convergence;
pub mod illuminance;
pub mod image;
pub mod mesh_export;

pub use self::image::{write_picture, write_rgb8, PictureFormat, SUPPORTED_EXTENSIONS};
pub use self::mesh_export::{write_mesh, MeshFormat, MESH_EXTENSIONS};

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;
use thiserror::Error;

/// Why an output file could not be written. Every message names the path.
#[derive(Debug, Error)]
pub enum OutputError {
    /// The directory the file should go in does not exist.
    #[error("cannot write {}: directory {} does not exist", path.display(), dir.display())]
    MissingDirectory {
        /// The file that was to be written.
        path: PathBuf,
        /// Its parent directory.
        dir: PathBuf,
    },
    /// The path's parent exists but is not a directory.
    #[error("cannot write {}: {} is not a directory", path.display(), dir.display())]
    NotADirectory {
        /// The file that was to be written.
        path: PathBuf,
        /// Its parent, which is something else than a directory.
        dir: PathBuf,
    },
    /// The picture format cannot be told from the path's extension.
    #[error(
        "cannot write {}: {reason}; supported picture formats are {}",
        path.display(),
        SUPPORTED_EXTENSIONS
    )]
    UnknownFormat {
        /// The file that was to be written.
        path: PathBuf,
        /// What is wrong with its extension.
        reason: String,
    },
    /// The frame's buffers disagree with its size (a bug in its producer).
    #[error("cannot write {}: the frame's buffers do not hold {width}x{height} pixels", path.display())]
    InvalidFrame {
        /// The file that was to be written.
        path: PathBuf,
        /// Frame width in pixels.
        width: u32,
        /// Frame height in pixels.
        height: u32,
    },
    /// Creating, writing or renaming the file failed. The message includes
    /// the operating system's reason.
    #[error("cannot write {}: {error}", path.display())]
    Io {
        /// The file that was to be written.
        path: PathBuf,
        /// What the operating system said.
        error: io::Error,
    },
    /// The image encoder failed. The message includes its reason.
    #[error("cannot encode {}: {error}", path.display())]
    Encode {
        /// The file that was to be written.
        path: PathBuf,
        /// What the encoder said.
        error: ::image::ImageError,
    },
}

impl OutputError {
    /// The path of the file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            OutputError::MissingDirectory { path, .. }
            | OutputError::NotADirectory { path, .. }
            | OutputError::UnknownFormat { path, .. }
            | OutputError::InvalidFrame { path, .. }
            | OutputError::Io { path, .. }
            | OutputError::Encode { path, .. } => path,
        }
    }

    fn io(path: &Path, error: io::Error) -> OutputError {
        OutputError::Io {
            path: path.to_path_buf(),
            error,
        }
    }
}

/// Writes the file at `path` through `write`, atomically: the bytes go to a
/// temporary file in the same directory, which is flushed, synced and then
/// renamed over `path`. If `write` or any step fails, the temporary file is
/// removed and `path` is left as it was.
///
/// The writer is buffered; `write` need not buffer or flush.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    write_atomically_seekable(path, |w| {
        write(w).map_err(|error| OutputError::io(path, error))
    })
}

/// [`write_atomically`] for writers that need to seek (some image encoders
/// patch their headers at the end) and may fail with any [`OutputError`].
pub fn write_atomically_seekable(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&File>) -> Result<(), OutputError>,
) -> Result<(), OutputError> {
    let dir = destination_dir(path)?;
    // Same directory as the destination, so the final rename stays on one
    // file system and is atomic.
    let tmp = temp_file_in(&dir).map_err(|e| OutputError::io(path, e))?;
    {
        let mut writer = BufWriter::new(tmp.as_file());
        write(&mut writer)?;
        writer.flush().map_err(|e| OutputError::io(path, e))?;
    }
    // Sync before the rename so that after a crash the name points either
    // to the old file or to the complete new one.
    tmp.as_file()
        .sync_all()
        .map_err(|e| OutputError::io(path, e))?;
    tmp.persist(path)
        .map_err(|e| OutputError::io(path, e.error))?;
    Ok(())
}

/// A temporary file in `dir` that, once renamed, has the permissions an
/// ordinary new file would (`0666` less the umask on Unix), not the
/// owner-only `0600` temporary files get by default.
fn temp_file_in(dir: &Path) -> io::Result<NamedTempFile> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".radiosity-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir)
}

/// Checks, before any work is done, that `path` could be written: its
/// directory exists and is a directory.
pub fn check_destination(path: &Path) -> Result<(), OutputError> {
    destination_dir(path).map(|_| ())
}

/// Checks, before any work is done, that a file of `path`'s name can be
/// created in its directory: a temporary file whose name is as long as
/// `path`'s is created there and removed, so a read-only directory or
/// file system, or a name longer than the file system allows, is found
/// before the solve rather than after it.
pub fn check_creatable(path: &Path) -> Result<(), OutputError> {
    let dir = destination_dir(path)?;
    let length = path.file_name().map_or(1, |n| n.len()).max(1);
    let seed = std::process::id() as u64
        ^ std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64);
    for attempt in 0..16u64 {
        // A dot and letters, as long as the name in bytes; another name
        // if one of these exists.
        let mut x = seed.wrapping_add(attempt.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        // (A one-byte name gets no dot: `.` is the directory itself.)
        let name: String = (length > 1)
            .then_some('.')
            .into_iter()
            .chain(std::iter::repeat_with(|| {
                x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                char::from(b'a' + ((x >> 33) % 26) as u8)
            }))
            .take(length)
            .collect();
        let probe = dir.join(name);
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&probe)
        {
            Ok(file) => {
                drop(file);
                return std::fs::remove_file(&probe).map_err(|e| OutputError::io(path, e));
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(OutputError::io(path, e)),
        }
    }
    Ok(())
}

/// The directory `path` goes in, which must exist.
fn destination_dir(path: &Path) -> Result<PathBuf, OutputError> {
    let dir = match path.parent() {
        // A bare file name is relative to the working directory.
        Some(p) if p.as_os_str().is_empty() => PathBuf::from("."),
        Some(p) => p.to_path_buf(),
        None => {
            return Err(OutputError::io(
                path,
                io::Error::new(io::ErrorKind::InvalidInput, "not a file path"),
            ))
        }
    };
    if dir.is_dir() {
        Ok(dir)
    } else if dir.exists() {
        Err(OutputError::NotADirectory {
            path: path.to_path_buf(),
            dir,
        })
    } else {
        Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_and_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("stats.json");
        write_atomically(&path, |w| w.write_all(b"first")).unwrap();
        write_atomically(&path, |w| w.write_all(b"second")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        assert_eq!(entries(dir.path()), vec![path]);
    }

    #[test]
    fn failure_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("stats.json");
        std::fs::write(&path, b"old").unwrap();
        let err = write_atomically(&path, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("disk on fire"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("stats.json"), "{err}");
        assert!(err.to_string().contains("disk on fire"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(entries(dir.path()), vec![path]);
    }

    #[test]
    fn missing_directory_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("nowhere").join("out.json");
        let err = write_atomically(&path, |w| w.write_all(b"x")).unwrap_err();
        assert!(matches!(err, OutputError::MissingDirectory { .. }));
        let msg = err.to_string();
        assert!(
            msg.contains("does not exist") && msg.contains("nowhere"),
            "{msg}"
        );
        assert_eq!(err.path(), path);
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn parent_that_is_a_file_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("plain");
        std::fs::write(&file, b"").unwrap();
        let err = write_atomically(&file.join("out.json"), |w| w.write_all(b"x")).unwrap_err();
        assert!(matches!(err, OutputError::NotADirectory { .. }), "{err}");
    }

    #[test]
    fn a_name_too_long_to_create_is_found_by_the_probe_which_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        // Most file systems allow names of at most 255 bytes.
        let long = dir.path().join(format!("{}.png", "a".repeat(296)));
        let err = check_creatable(&long).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("File name too long"), "{msg}");
        assert!(!msg.contains("at path"), "{msg}");
        let fits = dir.path().join(format!("{}.png", "a".repeat(200)));
        check_creatable(&fits).unwrap();
        check_creatable(&dir.path().join("a")).unwrap();
        assert!(entries(dir.path()).is_empty());
    }
}
