//! Opening input files: the one door through which every file a run reads
//! comes in (the scene, its material libraries, textures and glTF buffers,
//! `--camera`, `--ies`, `--illuminance-at` points, the `--resume`
//! checkpoint).
//!
//! Reading through here gives three things by construction:
//!
//! - Only regular files are read. The path is looked up first and a FIFO,
//!   a device (`/dev/zero`), a directory or a socket is refused with a
//!   message saying what it is, so a run never blocks on a pipe nor reads
//!   a device without end.
//! - Reads are bounded: each [`InputKind`] has a size limit
//!   ([`InputKind::max_bytes`]), checked against the file's size before
//!   anything is allocated and again while reading (at most one byte over
//!   the limit is read), so a file that grows while it is read stays
//!   bounded too.
//! - Every file read is recorded in the run's [`InputSet`] with its
//!   identity (device and inode, and its canonical path), so that the
//!   outputs can be checked against every input, links included.
//!
//! Files named by a model (OBJ `mtllib` and `map_Kd`, glTF buffer and
//! image URIs) are read through a [`ModelFolder`], which keeps them inside
//! the model's folder: an absolute path or one that climbs out with `..` is
//! refused unless [`InputSet::allow_outside_paths`] says otherwise. The
//! check is on the path as written; a symbolic link inside the folder is
//! the folder owner's choice and is followed.

use std::fs::{File, Metadata};
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// One mebibyte, the unit of the size limits.
const MIB: u64 = 1 << 20;

/// What an input file is to the run; it names the file in messages and
/// sets its size limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    /// The scene (`.sc`, `.obj`, `.gltf`, `.glb`).
    Scene,
    /// A `.sc` file read for its camera (`--camera`).
    Camera,
    /// An OBJ material library (`mtllib`).
    Material,
    /// An OBJ `map_Kd` texture.
    Texture,
    /// A file a glTF names by URI: a buffer or an image.
    GltfData,
    /// An IES photometric file (`--ies`).
    Ies,
    /// A measurement points file (`--illuminance-at`).
    Points,
    /// A solver checkpoint (`--resume`).
    Checkpoint,
}

impl InputKind {
    /// How messages name a file of this kind.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Scene => "scene file",
            InputKind::Camera => "camera file",
            InputKind::Material => "material library",
            InputKind::Texture => "texture",
            InputKind::GltfData => "glTF buffer or image",
            InputKind::Ies => "IES file",
            InputKind::Points => "points file",
            InputKind::Checkpoint => "checkpoint",
        }
    }

    /// The largest file of this kind that is read, in bytes. Each is far
    /// above any real file of its kind and far below what would exhaust a
    /// machine's memory before the other limits are checked: scenes and
    /// glTF data 2 GiB (a glb holds at most 4 GiB and real ones a few
    /// hundred MB); a material library 64 MiB; a texture 512 MiB encoded;
    /// an IES file 64 MiB (its documented maximum of a million values
    /// takes about 15 MB); a points file 1 GiB (tens of millions of
    /// points); a checkpoint 16 GiB (about 500 MB at the default element
    /// limit, more when `--max-elements` is raised); a camera file, which may be a whole `.sc` scene, as a
    /// scene.
    pub fn max_bytes(self) -> u64 {
        match self {
            InputKind::Scene | InputKind::Camera | InputKind::GltfData => 2048 * MIB,
            InputKind::Material | InputKind::Ies => 64 * MIB,
            InputKind::Texture => 512 * MIB,
            InputKind::Points => 1024 * MIB,
            InputKind::Checkpoint => 16384 * MIB,
        }
    }
}

/// A file's identity on its file system: the same for every name (hard or
/// symbolic link) of one file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FileId {
    /// The device the file lives on.
    pub device: u64,
    /// Its inode number on that device.
    pub inode: u64,
}

impl FileId {
    /// The identity of the file `meta` describes; `None` where the
    /// platform has no inodes (then paths are compared instead).
    pub fn of(meta: &Metadata) -> Option<FileId> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            Some(FileId {
                device: meta.dev(),
                inode: meta.ino(),
            })
        }
        #[cfg(not(unix))]
        {
            let _ = meta;
            None
        }
    }
}

/// One file a run read (or will read).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputFile {
    /// The path as it was named (joined to the model's folder for files a
    /// model names).
    pub path: PathBuf,
    /// The path with every link resolved, or made absolute when that
    /// failed.
    pub canonical: PathBuf,
    /// Device and inode, where the platform has them.
    pub id: Option<FileId>,
    /// What the file is to the run.
    pub kind: InputKind,
}

impl InputFile {
    /// The record of the file at `path`, described by `meta`.
    fn new(path: &Path, meta: &Metadata, kind: InputKind) -> InputFile {
        InputFile {
            path: path.to_path_buf(),
            canonical: canonical(path),
            id: FileId::of(meta),
            kind,
        }
    }

    /// True when `path` names this file: the same device and inode if
    /// `path` exists, else the same canonical path.
    pub fn is(&self, path: &Path) -> bool {
        if let (Some(id), Ok(meta)) = (self.id, std::fs::metadata(path)) {
            if let Some(other) = FileId::of(&meta) {
                return id == other;
            }
        }
        self.canonical == canonical(path)
    }
}

/// `path` with its links resolved, or made absolute when it cannot be
/// (it does not exist).
fn canonical(path: &Path) -> PathBuf {
    path.canonicalize()
        .or_else(|_| std::path::absolute(path))
        .unwrap_or_else(|_| path.to_path_buf())
}

/// Why an input file was not read. Every message names the file and what
/// it was to be.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The operating system could not open or read it (it does not exist,
    /// say).
    #[error("cannot read the {} {}: {error}", kind.name(), path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What it was to be.
        kind: InputKind,
        /// Why.
        error: io::Error,
    },
    /// It is no regular file (a FIFO, a device, a directory, a socket).
    #[error(
        "refusing to read the {} {}: it is {what}, not a regular file",
        kind.name(),
        path.display()
    )]
    NotRegular {
        /// The file.
        path: PathBuf,
        /// What it was to be.
        kind: InputKind,
        /// What it is instead.
        what: &'static str,
    },
    /// It is larger than its kind's limit ([`InputKind::max_bytes`]).
    #[error(
        "refusing to read the {} {}: it holds {}{size} bytes, over the limit of {} MiB for a {}",
        kind.name(),
        path.display(),
        if *at_least { "at least " } else { "" },
        kind.max_bytes() / MIB,
        kind.name()
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// What it was to be.
        kind: InputKind,
        /// Its size, or how much of it was read when it grew past the
        /// limit while being read (then `at_least`).
        size: u64,
        /// True when `size` is only what was read before stopping.
        at_least: bool,
    },
    /// A model named a file outside its folder (an absolute path, or one
    /// climbing out with `..`) and that is not allowed.
    #[error(
        "refusing to read the {} `{name}`: it lies outside the model's folder {} (an absolute \
         path, one climbing out with `..`, or a link to outside); --allow-outside-paths reads it",
        kind.name(),
        folder_name(folder)
    )]
    Outside {
        /// The name as the model wrote it.
        name: String,
        /// The model's folder.
        folder: PathBuf,
        /// What it was to be.
        kind: InputKind,
    },
}

impl InputError {
    /// True when the file was refused for what it is or where it lies (not
    /// a regular file, too large, outside the model's folder), rather than
    /// because it could not be read: a refusal ends the load even where an
    /// unreadable file would only be warned about.
    pub fn is_refusal(&self) -> bool {
        !matches!(self, InputError::Io { .. })
    }
}

/// The folder as messages show it: `.` for the working directory.
fn folder_name(folder: &Path) -> String {
    if folder.as_os_str().is_empty() {
        ".".to_string()
    } else {
        folder.display().to_string()
    }
}

/// What a file that is no regular file is, for messages (`a directory`,
/// `a FIFO (named pipe)`, `a character device`, ...).
pub fn what_it_is(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "something other than a file"
}

/// Refuses `meta` unless it describes a regular file within `kind`'s
/// size limit.
fn check_file(path: &Path, meta: &Metadata, kind: InputKind) -> Result<(), InputError> {
    if !meta.is_file() {
        return Err(InputError::NotRegular {
            path: path.to_path_buf(),
            kind,
            what: what_it_is(meta),
        });
    }
    if meta.len() > kind.max_bytes() {
        return Err(InputError::TooLarge {
            path: path.to_path_buf(),
            kind,
            size: meta.len(),
            at_least: false,
        });
    }
    Ok(())
}

/// Reads the whole file at `path` as a `kind`, refusing anything but a
/// regular file within the kind's size limit, and says what was read.
/// The record is not kept anywhere: [`InputSet::read`] keeps it.
pub fn read_file(path: &Path, kind: InputKind) -> Result<(Vec<u8>, InputFile), InputError> {
    let io_error = |error| InputError::Io {
        path: path.to_path_buf(),
        kind,
        error,
    };
    let (file, meta) = open_checked(path, kind)?;
    let cap = kind.max_bytes();
    // The size is within the cap, so this allocation is bounded.
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(io_error)?;
    if bytes.len() as u64 > cap {
        return Err(InputError::TooLarge {
            path: path.to_path_buf(),
            kind,
            size: bytes.len() as u64,
            at_least: true,
        });
    }
    Ok((bytes, InputFile::new(path, &meta, kind)))
}

/// Checks that the file at `path` could be read as a `kind` (it exists,
/// is a regular file within the kind's size limit, and opens) without
/// reading it.
pub fn check_readable(path: &Path, kind: InputKind) -> Result<(), InputError> {
    open_checked(path, kind).map(drop)
}

/// Opens `path` ([`open`]) and checks what was opened as a `kind`
/// ([`check_file`]): what was opened is what is checked, with no name
/// lookup between the check and the read for another file to take its
/// place.
fn open_checked(path: &Path, kind: InputKind) -> Result<(File, Metadata), InputError> {
    let io_error = |error| InputError::Io {
        path: path.to_path_buf(),
        kind,
        error,
    };
    let file = open(path).map_err(io_error)?;
    let meta = file.metadata().map_err(io_error)?;
    check_file(path, &meta, kind)?;
    Ok((file, meta))
}

/// Opens `path` for reading without blocking: a FIFO opens at once (and
/// is then refused as not a regular file) instead of waiting for a
/// writer, a device without waiting for a carrier. Reads from a regular
/// file are the same either way.
fn open(path: &Path) -> io::Result<File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    options.open(path)
}

/// The files a run reads, with their identities, and whether models may
/// name files outside their folder. Shared by reference: reading records
/// through `&self`, so one set can follow a load through every reader.
#[derive(Debug, Default)]
pub struct InputSet {
    /// Whether a model may name files outside its folder
    /// (`--allow-outside-paths`).
    pub allow_outside_paths: bool,
    files: Mutex<Vec<InputFile>>,
}

impl InputSet {
    /// An empty set; `allow_outside_paths` as [`InputSet::allow_outside_paths`].
    pub fn new(allow_outside_paths: bool) -> InputSet {
        InputSet {
            allow_outside_paths,
            files: Mutex::new(Vec::new()),
        }
    }

    fn files_mut(&self) -> MutexGuard<'_, Vec<InputFile>> {
        // A panic elsewhere cannot leave the list half-changed: pushes are
        // whole.
        self.files.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// [`read_file`], recording the file in the set.
    pub fn read(&self, path: &Path, kind: InputKind) -> Result<Vec<u8>, InputError> {
        let (bytes, file) = read_file(path, kind)?;
        self.add(file);
        Ok(bytes)
    }

    /// Records the file at `path` as an input that will be read later
    /// (a `--resume` checkpoint, a points file), so that outputs are
    /// checked against it before then. A path that does not exist is not
    /// recorded: reading it will fail with its own message.
    pub fn declare(&self, path: &Path, kind: InputKind) {
        if let Ok(meta) = std::fs::metadata(path) {
            self.add(InputFile::new(path, &meta, kind));
        }
    }

    fn add(&self, file: InputFile) {
        let mut files = self.files_mut();
        if !files.contains(&file) {
            files.push(file);
        }
    }

    /// Every file recorded so far, in the order first read.
    pub fn files(&self) -> Vec<InputFile> {
        self.files_mut().clone()
    }

    /// The recorded input that `path` names, if any (see [`InputFile::is`]).
    pub fn find(&self, path: &Path) -> Option<InputFile> {
        self.files_mut().iter().find(|f| f.is(path)).cloned()
    }
}

/// The folder of a model (the OBJ or glTF file's), through which the files
/// the model names are read: relative to it, kept inside it unless the
/// set allows otherwise, and recorded in the set.
pub struct ModelFolder<'a> {
    dir: PathBuf,
    inputs: &'a InputSet,
    refused: Mutex<Option<String>>,
}

impl<'a> ModelFolder<'a> {
    /// The folder of the model file at `model`, reading into `inputs`.
    pub fn of(model: &Path, inputs: &'a InputSet) -> ModelFolder<'a> {
        ModelFolder {
            dir: model.parent().map(Path::to_path_buf).unwrap_or_default(),
            inputs,
            refused: Mutex::new(None),
        }
    }

    /// `name` (as the model wrote it) joined to the folder: what messages
    /// call it.
    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.dir.join(name)
    }

    /// Reads the file at `path`, a path under the folder as
    /// [`ModelFolder::join`] makes it (a file a library in a subfolder
    /// names is joined to that library's folder), as a `kind`.
    pub fn read(&self, path: &Path, kind: InputKind) -> Result<Vec<u8>, InputError> {
        let result = self
            .check_inside(path, kind)
            .and_then(|()| self.inputs.read(path, kind));
        if let Err(e) = &result {
            // A texture outside the folder only tints a material: it is
            // skipped with the loader's warning, as a missing one is (real
            // exports name `../textures/...`). A buffer outside fails the
            // load by itself.
            let skipped = matches!(e, InputError::Outside { .. })
                && matches!(kind, InputKind::Texture | InputKind::GltfData);
            if e.is_refusal() && !skipped {
                let mut refused = self.refused.lock().unwrap_or_else(|e| e.into_inner());
                refused.get_or_insert_with(|| e.to_string());
            }
        }
        result
    }

    /// The message of the first file refused (see
    /// [`InputError::is_refusal`]), if any: the loader ends with it even
    /// where the model's reader only warned. A texture or glTF file
    /// refused only for lying outside the folder is not counted: the
    /// reader's warning says it was skipped.
    pub fn refused(&self) -> Option<String> {
        self.refused
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// Refuses `path` when it is not below the folder, by its components
    /// as written, unless the set allows it.
    fn check_inside(&self, path: &Path, kind: InputKind) -> Result<(), InputError> {
        if self.inputs.allow_outside_paths || stays_inside(&self.dir, path) {
            return Ok(());
        }
        let name = path.strip_prefix(&self.dir).unwrap_or(path);
        Err(InputError::Outside {
            name: name.display().to_string(),
            folder: self.dir.clone(),
            kind,
        })
    }
}

/// True when `path` is `dir` joined to a relative path that never climbs
/// above `dir` (`a/../b` stays inside, `../b` and `/b` do not), and, when
/// it exists, its real path (symbolic links followed) lies below `dir`'s
/// real path: a link inside the folder to `/etc/passwd` is outside.
fn stays_inside(dir: &Path, path: &Path) -> bool {
    if !stays_inside_as_written(dir, path) {
        return false;
    }
    // The empty folder is the working directory.
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    match (dir.canonicalize(), path.canonicalize()) {
        (Ok(dir), Ok(path)) => path.starts_with(dir),
        // Missing: the read that follows says so.
        _ => true,
    }
}

/// [`stays_inside`] by the components of `path` as written.
fn stays_inside_as_written(dir: &Path, path: &Path) -> bool {
    let Ok(rest) = path.strip_prefix(dir) else {
        return false;
    };
    let mut depth = 0usize;
    for component in rest.components() {
        match component {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => match depth.checked_sub(1) {
                Some(d) => depth = d,
                None => return false,
            },
            Component::RootDir | Component::Prefix(_) => return false,
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mkfifo(path: &Path) {
        let ok = std::process::Command::new("mkfifo")
            .arg(path)
            .status()
            .expect("mkfifo runs")
            .success();
        assert!(ok, "mkfifo made {}", path.display());
    }

    #[test]
    fn a_regular_file_is_read_and_recorded_with_its_identity() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.sc");
        std::fs::write(&path, b"hello").unwrap();
        let set = InputSet::default();
        assert_eq!(set.read(&path, InputKind::Scene).unwrap(), b"hello");
        let files = set.files();
        assert_eq!(files.len(), 1);
        assert_eq!(files[0].canonical, path.canonicalize().unwrap());
        // A hard link and a symbolic link are the same input.
        let hard = dir.path().join("hard.sc");
        std::fs::hard_link(&path, &hard).unwrap();
        assert!(set.find(&hard).is_some());
        #[cfg(unix)]
        {
            let soft = dir.path().join("soft.sc");
            std::os::unix::fs::symlink(&path, &soft).unwrap();
            assert!(set.find(&soft).is_some());
        }
        // Another file with the same bytes is not.
        let other = dir.path().join("other.sc");
        std::fs::write(&other, b"hello").unwrap();
        assert!(set.find(&other).is_none());
    }

    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.mtl");
        mkfifo(&fifo);
        // Opening it would block for ever: the refusal comes first.
        let err = read_file(&fifo, InputKind::Material).unwrap_err();
        assert!(err.is_refusal());
        let message = err.to_string();
        assert!(
            message.contains("a FIFO (named pipe), not a regular file"),
            "{message}"
        );
        assert!(message.contains("pipe.mtl"), "{message}");
        assert!(message.contains("material library"), "{message}");
    }

    #[test]
    fn devices_and_directories_are_refused() {
        let err = read_file(Path::new("/dev/zero"), InputKind::Points).unwrap_err();
        assert!(err.to_string().contains("a character device"), "{err}");
        let dir = tempfile::tempdir().unwrap();
        let err = read_file(dir.path(), InputKind::Scene).unwrap_err();
        assert!(err.to_string().contains("a directory"), "{err}");
    }

    #[test]
    fn a_file_over_its_kind_limit_is_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.ies");
        // Sparse: the size is over the limit without writing the bytes.
        let file = File::create(&path).unwrap();
        file.set_len(InputKind::Ies.max_bytes() + 1).unwrap();
        let err = read_file(&path, InputKind::Ies).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("67108865 bytes, over the limit of 64 MiB"),
            "{message}"
        );
        // At the limit it is read.
        file.set_len(InputKind::Ies.max_bytes()).unwrap();
        let (bytes, _) = read_file(&path, InputKind::Ies).unwrap();
        assert_eq!(bytes.len() as u64, InputKind::Ies.max_bytes());
    }

    #[test]
    fn a_missing_file_is_an_error_that_is_no_refusal() {
        let err = read_file(Path::new("no/such/file.obj"), InputKind::Scene).unwrap_err();
        assert!(!err.is_refusal());
        assert!(err
            .to_string()
            .starts_with("cannot read the scene file no/such/file.obj"));
    }

    #[test]
    fn model_paths_stay_inside_the_model_folder() {
        let dir = Path::new("models/house");
        assert!(stays_inside(dir, &dir.join("tex/a.png")));
        assert!(stays_inside(dir, &dir.join("tex/../a.png")));
        assert!(stays_inside(dir, &dir.join("./a.png")));
        assert!(!stays_inside(dir, &dir.join("../a.png")));
        assert!(!stays_inside(dir, &dir.join("tex/../../a.png")));
        // What joining an absolute name to the folder gives.
        assert!(!stays_inside(dir, Path::new("/etc/passwd")));
        // A model in the working directory.
        assert!(stays_inside(Path::new(""), Path::new("a.mtl")));
        assert!(!stays_inside(Path::new(""), Path::new("../a.mtl")));
    }

    #[cfg(unix)]
    #[test]
    fn a_link_inside_the_folder_to_outside_is_outside() {
        let root = tempfile::tempdir().unwrap();
        std::fs::write(root.path().join("secret"), b"secret bytes").unwrap();
        let dir = root.path().join("model");
        std::fs::create_dir(&dir).unwrap();
        std::fs::write(dir.join("real.png"), b"png").unwrap();
        std::os::unix::fs::symlink(root.path().join("secret"), dir.join("out.png")).unwrap();
        std::os::unix::fs::symlink(dir.join("real.png"), dir.join("in.png")).unwrap();
        assert!(!stays_inside(&dir, &dir.join("out.png")));
        assert!(stays_inside(&dir, &dir.join("in.png")));
        assert!(stays_inside(&dir, &dir.join("real.png")));
        // A folder reached through a link is still itself.
        std::os::unix::fs::symlink(&dir, root.path().join("alias")).unwrap();
        let alias = root.path().join("alias");
        assert!(stays_inside(&alias, &alias.join("real.png")));
        assert!(!stays_inside(&alias, &alias.join("out.png")));
    }

    #[test]
    fn a_model_folder_refuses_outside_paths_unless_allowed() {
        let root = tempfile::tempdir().unwrap();
        std::fs::write(root.path().join("secret"), b"secret bytes").unwrap();
        let model_dir = root.path().join("model");
        std::fs::create_dir(&model_dir).unwrap();
        let model = model_dir.join("m.gltf");
        let strict = InputSet::default();
        let folder = ModelFolder::of(&model, &strict);
        let err = folder
            .read(&folder.join("../secret"), InputKind::GltfData)
            .unwrap_err();
        let message = err.to_string();
        assert!(message.contains("`../secret`"), "{message}");
        assert!(message.contains("--allow-outside-paths"), "{message}");
        assert!(!message.contains("secret bytes"), "{message}");
        // Skipped with a warning by the glTF reader (a buffer fails by
        // itself); a material library outside ends the load.
        assert_eq!(folder.refused(), None);
        let err = folder
            .read(&folder.join("../secret"), InputKind::Material)
            .unwrap_err();
        assert_eq!(folder.refused(), Some(err.to_string()));
        assert!(strict.files().is_empty());

        let lenient = InputSet::new(true);
        let folder = ModelFolder::of(&model, &lenient);
        let bytes = folder
            .read(&folder.join("../secret"), InputKind::GltfData)
            .unwrap();
        assert_eq!(bytes, b"secret bytes");
        assert_eq!(lenient.files().len(), 1);
        assert_eq!(folder.refused(), None);
    }

    /// Every file the program reads goes through this module: outside it
    /// (and outside tests), no source file opens or reads a file itself.
    /// The memory budget's reads of the system's own files (`/proc`,
    /// `/sys`) are the exception.
    #[test]
    fn no_other_module_reads_files_itself() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let allowed = ["scene/import/input.rs", "budget.rs"];
        let forbidden = [
            "fs::read(",
            "fs::read_to_string(",
            "File::open(",
            "image::open(",
            "OpenOptions::new().read(",
        ];
        let mut stack = vec![root.clone()];
        let mut checked = 0;
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                    continue;
                }
                let name = path
                    .strip_prefix(&root)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                if !name.ends_with(".rs")
                    || allowed.contains(&name.as_str())
                    || name.ends_with("tests.rs")
                {
                    continue;
                }
                let text = std::fs::read_to_string(&path).unwrap();
                // Unit tests sit after the module's `#[cfg(test)]`.
                let code = text.split("#[cfg(test)]").next().unwrap_or_default();
                for pattern in forbidden {
                    assert!(
                        !code.contains(pattern),
                        "src/{name} calls `{pattern}`: read files through scene::import::input"
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 100, "only {checked} source files found");
    }
}
