//! Writing results to files: pictures (png, tiff, exr, pfm, hdr), the solved
//! mesh (glb, ply), the convergence log and plot, illuminance at points and
//! over work planes (CSV, plan), daylight factors, and the atomic-write helper every output
//! shares.
//!
//! Every file is written to a temporary file in its destination directory
//! and renamed into place once complete ([`write_atomically`]), so a failed
//! or interrupted run never leaves a partial file behind, and an existing
//! file is either fully replaced or untouched.
//!
//! **Temporaries.** A temporary is named `.radiosity-<pid>-<random>`, the
//! writing process's id in its name. It is removed when its write fails,
//! is cancelled (inside [`cancelling_writes`] every buffer written checks
//! the run's [`Cancel`] token) or unwinds from a panic, and by
//! [`remove_temporaries`] when the program must exit at once (a second
//! Ctrl-C). Only SIGKILL can leave one behind; the next run writing to
//! that folder removes it ([`remove_stale_temporaries`]).
//!
//! Errors are [`OutputError`]s; each names the path it is about and, when
//! the operating system or an encoder failed, says why in the same message.

pub mod convergence;
pub mod daylight_factor;
pub mod illuminance;
pub mod image;
pub mod lightmap;
pub mod mesh_export;

pub use self::image::{
    write_picture, write_rgb8, PictureFormat, EIGHT_BIT_EXTENSIONS, SUPPORTED_EXTENSIONS,
};
pub use self::mesh_export::{write_mesh, MeshFormat, MESH_EXTENSIONS};

use crate::cancel::{Cancel, Cancelled};
use std::cell::RefCell;
use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, SystemTime};
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
    /// The picture format cannot be told from the path's extension, or is
    /// not one this output writes.
    #[error("cannot write {}: {reason}", path.display())]
    UnknownFormat {
        /// The file that was to be written.
        path: PathBuf,
        /// What is wrong with its extension, and the formats this output
        /// accepts.
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
    write: impl FnOnce(&mut BufWriter<TempWriter<'_>>) -> Result<(), OutputError>,
) -> Result<(), OutputError> {
    let dir = destination_dir(path)?;
    // Same directory as the destination, so the final rename stays on one
    // file system and is atomic.
    let tmp = Temporary::new(&dir).map_err(|e| OutputError::io(path, e))?;
    let cancel = WRITE_CANCEL.with(|c| c.borrow().clone());
    {
        let mut writer = BufWriter::new(TempWriter {
            file: tmp.as_file(),
            cancel: cancel.clone(),
        });
        write(&mut writer)?;
        writer.flush().map_err(|e| OutputError::io(path, e))?;
    }
    // Sync before the rename so that after a crash the name points either
    // to the old file or to the complete new one.
    tmp.as_file()
        .sync_all()
        .map_err(|e| OutputError::io(path, e))?;
    // The last moment to abandon the file: once renamed it is written.
    if let Some(cancel) = &cancel {
        cancel
            .check()
            .map_err(|c| OutputError::io(path, io::Error::other(c)))?;
    }
    tmp.persist(path)
        .map_err(|e| OutputError::io(path, e.error))?;
    Ok(())
}

thread_local! {
    /// The token of the innermost [`cancelling_writes`] on this thread.
    static WRITE_CANCEL: RefCell<Option<Cancel>> = const { RefCell::new(None) };
}

/// Runs `f` with every write [`write_atomically`] makes on this thread
/// cancellable by `cancel`: once it is set, the next buffer written fails
/// (an [`io::Error`] wrapping [`Cancelled`]), the temporary is removed and
/// the destination is left as it was. Writes outside (a checkpoint saved
/// on the way out of an interrupted run) are never cancelled.
pub fn cancelling_writes<T>(cancel: &Cancel, f: impl FnOnce() -> T) -> T {
    /// Puts back the outer token, on unwinding too.
    struct Restore(Option<Cancel>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let outer = self.0.take();
            WRITE_CANCEL.with(|c| *c.borrow_mut() = outer);
        }
    }
    let _restore = Restore(WRITE_CANCEL.with(|c| c.replace(Some(cancel.clone()))));
    f()
}

/// The file under a [`BufWriter`] of [`write_atomically_seekable`]: the
/// temporary, checking the write's cancellation token before every buffer
/// it is handed (a [`BufWriter`]'s worth, 8 KiB, or one large write).
pub struct TempWriter<'f> {
    file: &'f File,
    cancel: Option<Cancel>,
}

impl Write for TempWriter<'_> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if let Some(cancel) = &self.cancel {
            // Not `ErrorKind::Interrupted`, which `write_all` retries.
            cancel.check().map_err(io::Error::other)?;
        }
        self.file.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

impl Seek for TempWriter<'_> {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.file.seek(pos)
    }
}

/// The token of the enclosing [`cancelling_writes`] on this thread.
pub(crate) fn write_cancel() -> Option<Cancel> {
    WRITE_CANCEL.with(|c| c.borrow().clone())
}

/// `Err` (as a write abandoned by [`cancelling_writes`]) once the token of
/// the enclosing [`cancelling_writes`] is set: for a writer to check
/// between long passes of its own before it starts writing.
pub(crate) fn check_cancelled(path: &Path) -> Result<(), OutputError> {
    WRITE_CANCEL.with(|c| match &*c.borrow() {
        Some(cancel) => cancel
            .check()
            .map_err(|c| OutputError::io(path, io::Error::other(c))),
        None => Ok(()),
    })
}

/// True when `error` is a write abandoned by [`cancelling_writes`].
pub fn is_cancelled(error: &OutputError) -> bool {
    match error {
        OutputError::Io { error, .. } => {
            error.get_ref().is_some_and(|inner| inner.is::<Cancelled>())
        }
        _ => false,
    }
}

/// What every temporary's name starts with.
pub const TEMP_PREFIX: &str = ".radiosity-";

/// The temporaries this process has open, for [`remove_temporaries`].
static LIVE_TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The list of live temporaries, even if a panic poisoned its lock.
fn live_temporaries() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LIVE_TEMPORARIES
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes every temporary this process is writing: for a program about
/// to exit without unwinding (`std::process::exit` on a second Ctrl-C).
/// The writes themselves then fail, which no longer matters.
pub fn remove_temporaries() {
    for path in live_temporaries().drain(..) {
        let _ = std::fs::remove_file(path);
    }
}

/// A temporary file being written, listed in [`LIVE_TEMPORARIES`] from its
/// creation until it is renamed into place or dropped (which removes it).
struct Temporary {
    /// Always `Some` but while [`Temporary::persist`] moves it out.
    file: Option<NamedTempFile>,
    /// Its path, as listed.
    path: PathBuf,
}

impl Temporary {
    /// A temporary file in `dir` named after this process (see the module
    /// docs) that, once renamed, has the permissions an ordinary new file
    /// would (`0666` less the umask on Unix), not the owner-only `0600`
    /// temporary files get by default.
    fn new(dir: &Path) -> io::Result<Temporary> {
        let prefix = format!("{TEMP_PREFIX}{}-", std::process::id());
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let file = builder.tempfile_in(dir)?;
        let path = file.path().to_path_buf();
        live_temporaries().push(path.clone());
        Ok(Temporary {
            file: Some(file),
            path,
        })
    }

    /// The open file.
    fn as_file(&self) -> &File {
        self.file
            .as_ref()
            .expect("present until persisted")
            .as_file()
    }

    /// Renames the temporary to `path`.
    fn persist(mut self, path: &Path) -> Result<(), tempfile::PersistError> {
        let file = self.file.take().expect("persisted once");
        // `self` is dropped after the rename, taking the name off the list.
        file.persist(path).map(|_| ())
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        // The file itself, if not renamed, is removed by `NamedTempFile`.
        forget(&self.path);
    }
}

/// Takes `path` off [`LIVE_TEMPORARIES`].
fn forget(path: &Path) {
    let mut live = live_temporaries();
    if let Some(k) = live.iter().position(|p| p == path) {
        live.swap_remove(k);
    }
}

/// A temporary without its writer's id in its name (an older version's)
/// is taken as left behind once it is this old: a write in progress
/// touches its file far more often.
pub const STALE_AFTER: Duration = Duration::from_secs(60);

/// A temporary left behind by a killed run, removed by
/// [`remove_stale_temporaries`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StaleTemporary {
    /// Where it was.
    pub path: PathBuf,
    /// Its size in bytes.
    pub bytes: u64,
}

/// Removes from `dir` the temporaries ([`TEMP_PREFIX`]) whose writer no
/// longer runs: the process named in the file name is gone (on Linux; on
/// other systems, or for a name without a process id, the file has not
/// been modified for [`STALE_AFTER`]). Returns what it removed; files it
/// cannot read or remove are left alone, silently.
pub fn remove_stale_temporaries(dir: &Path) -> Vec<StaleTemporary> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        // Not `entry.metadata()` through a symbolic link: only plain files.
        let Ok(meta) = entry.path().symlink_metadata() else {
            continue;
        };
        if !meta.is_file() {
            continue;
        }
        let age = meta
            .modified()
            .ok()
            .and_then(|m| SystemTime::now().duration_since(m).ok())
            .unwrap_or_default();
        if is_stale(name, age) && std::fs::remove_file(entry.path()).is_ok() {
            removed.push(StaleTemporary {
                path: entry.path(),
                bytes: meta.len(),
            });
        }
    }
    removed.sort_by(|a, b| a.path.cmp(&b.path));
    removed
}

/// True when a file named `name`, last modified `age` ago, is a temporary
/// whose writer is gone (see [`remove_stale_temporaries`]).
fn is_stale(name: &str, age: Duration) -> bool {
    let Some(rest) = name.strip_prefix(TEMP_PREFIX) else {
        return false;
    };
    let pid = rest
        .split_once('-')
        .and_then(|(pid, _)| pid.parse::<u32>().ok());
    match pid {
        Some(pid) if pid == std::process::id() => false,
        Some(pid) => match process_runs(pid) {
            Some(runs) => !runs,
            None => age >= STALE_AFTER,
        },
        None => age >= STALE_AFTER,
    }
}

/// Whether process `pid` exists, where the system can tell cheaply.
fn process_runs(pid: u32) -> Option<bool> {
    // Without `/proc` mounted every process would look gone.
    if cfg!(target_os = "linux") && Path::new("/proc/self").exists() {
        Some(Path::new("/proc").join(pid.to_string()).exists())
    } else {
        None
    }
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
    fn a_cancelled_write_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.png");
        std::fs::write(&path, b"old").unwrap();
        let cancel = Cancel::new();
        let err = cancelling_writes(&cancel, || {
            write_atomically(&path, |w| {
                w.write_all(&[1; 1 << 16])?;
                cancel.set();
                // The next buffer handed to the file fails.
                for _ in 0..16 {
                    w.write_all(&[2; 1 << 16])?;
                }
                Ok(())
            })
        })
        .unwrap_err();
        assert!(is_cancelled(&err), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(entries(dir.path()), vec![path.clone()]);
        assert!(live_temporaries()
            .iter()
            .all(|p| !p.starts_with(dir.path())));
        // Outside the scope the same token cancels nothing.
        write_atomically(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
    }

    #[test]
    fn temporaries_are_named_after_the_writer_and_listed_while_open() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("stats.json");
        write_atomically(&path, |_| {
            let listed: Vec<PathBuf> = live_temporaries()
                .iter()
                .filter(|p| p.starts_with(dir.path()))
                .cloned()
                .collect();
            assert_eq!(listed.len(), 1);
            let name = listed[0].file_name().unwrap().to_str().unwrap().to_owned();
            let own = format!("{TEMP_PREFIX}{}-", std::process::id());
            assert!(name.starts_with(&own), "{name}");
            // Our own temporary is never stale, however old.
            assert!(!is_stale(&name, Duration::from_secs(86_400)));
            Ok(())
        })
        .unwrap();
        assert!(live_temporaries()
            .iter()
            .all(|p| !p.starts_with(dir.path())));
    }

    /// The id of a process that has ended.
    fn ended_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        pid
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn stale_temporaries_are_those_of_ended_writers_or_old_unnamed_ones() {
        let dir = tempfile::tempdir().unwrap();
        let dead = ended_pid();
        let write = |name: &str, bytes: usize| {
            let path = dir.path().join(name);
            std::fs::write(&path, vec![0u8; bytes]).unwrap();
            path
        };
        let killed = write(&format!("{TEMP_PREFIX}{dead}-a1b2c3"), 1000);
        let own = write(&format!("{TEMP_PREFIX}{}-d4e5f6", std::process::id()), 10);
        // pid 1 always runs.
        let running = write(&format!("{TEMP_PREFIX}1-g7h8i9"), 10);
        let fresh_unnamed = write(&format!("{TEMP_PREFIX}xyz123"), 10);
        let old_unnamed = write(&format!("{TEMP_PREFIX}abc456"), 500);
        let hour_ago = SystemTime::now() - Duration::from_secs(3600);
        File::options()
            .write(true)
            .open(&old_unnamed)
            .unwrap()
            .set_modified(hour_ago)
            .unwrap();
        let unrelated = write("picture.png", 10);
        std::fs::create_dir(dir.path().join(format!("{TEMP_PREFIX}{dead}-dir"))).unwrap();

        let removed = remove_stale_temporaries(dir.path());
        let mut expected = vec![
            StaleTemporary {
                path: killed.clone(),
                bytes: 1000,
            },
            StaleTemporary {
                path: old_unnamed.clone(),
                bytes: 500,
            },
        ];
        expected.sort_by(|a, b| a.path.cmp(&b.path));
        assert_eq!(removed, expected);
        assert!(!killed.exists() && !old_unnamed.exists());
        for kept in [own, running, fresh_unnamed, unrelated] {
            assert!(kept.exists(), "{}", kept.display());
        }
        assert!(dir.path().join(format!("{TEMP_PREFIX}{dead}-dir")).is_dir());
        // Nothing more the second time.
        assert!(remove_stale_temporaries(dir.path()).is_empty());
    }

    #[test]
    fn staleness_by_name_and_age() {
        let minute = STALE_AFTER;
        assert!(!is_stale("picture.png", minute * 100));
        assert!(!is_stale(".radiosity", minute * 100));
        assert!(!is_stale(".radiosity-abc", minute / 2));
        assert!(is_stale(".radiosity-abc", minute));
        let own = format!("{TEMP_PREFIX}{}-x", std::process::id());
        assert!(!is_stale(&own, minute * 100));
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
