//! Checks on the files a batch run will write, made before any time is
//! spent solving.

use super::checkpoint::CheckpointError;
use super::RunError;
use crate::config::{RunConfig, SceneSource};
use crate::output::{self, convergence, MeshFormat, OutputError, PictureFormat};
use std::path::{Path, PathBuf};

/// Refuses unusable outputs before any time is spent solving: an unknown
/// extension, a missing directory, a path that is an input (the scene, its
/// camera file, hard or symbolic links to them), two outputs that are the
/// same file, or a checkpoint to resume from that cannot be read.
pub fn check_outputs(config: &RunConfig) -> Result<(), RunError> {
    let output = config.output_path();
    let format = PictureFormat::from_path(&output).map_err(RunError::BadOutput)?;
    if config.mesh_lines && matches!(format, PictureFormat::Exr | PictureFormat::Pfm) {
        return Err(RunError::BadOutput(OutputError::UnknownFormat {
            path: output,
            reason: "mesh lines are drawn on 8-bit pictures: use .png, .tif or .tiff".into(),
        }));
    }
    if let Some(export) = &config.export {
        MeshFormat::from_path(export).map_err(RunError::BadOutput)?;
    }
    if let Some(plot) = &config.plot {
        convergence::check_plot_path(plot).map_err(RunError::BadOutput)?;
    }
    // False-colour pictures and plans are 8-bit, as the plot is.
    let photometry = &config.photometry;
    for picture in photometry
        .falsecolor
        .iter()
        .map(|f| &f.path)
        .chain(photometry.workplane.iter().map(|w| &w.png))
    {
        convergence::check_plot_path(picture).map_err(RunError::BadOutput)?;
    }
    let outputs: Vec<&PathBuf> = std::iter::once(&output)
        .chain(config.extra_outputs())
        .collect();
    let refuse = |path: &Path, why: &str| {
        RunError::BadOutput(OutputError::Io {
            path: path.to_path_buf(),
            error: std::io::Error::new(std::io::ErrorKind::InvalidInput, why.to_string()),
        })
    };
    let inputs = match &config.scene {
        SceneSource::File(input) => Some(input),
        SceneSource::Bundled => None,
    };
    for (k, out) in outputs.iter().enumerate() {
        output::check_destination(out).map_err(RunError::BadOutput)?;
        if inputs.is_some_and(|input| same_file(input, out)) {
            return Err(refuse(
                out,
                "refusing to overwrite the input scene (an input file)",
            ));
        }
        if config
            .camera
            .as_ref()
            .is_some_and(|camera| same_file(camera, out))
        {
            return Err(refuse(
                out,
                "refusing to overwrite the camera file (an input file)",
            ));
        }
        if outputs[..k]
            .iter()
            .any(|earlier| *earlier == *out || same_file(earlier, out))
        {
            return Err(refuse(
                out,
                "two outputs would be written to this same file: the picture, --stats, \
                 --checkpoint, --export, --log and --plot must be different files",
            ));
        }
    }
    if let Some(resume) = &config.resume {
        if let Err(error) = std::fs::File::open(resume) {
            return Err(CheckpointError::Read {
                path: resume.clone(),
                error,
            }
            .into());
        }
    }
    Ok(())
}

/// True when both paths name the same file: the same path once made
/// absolute, or (on Unix) the same existing file through another name, a
/// symbolic or a hard link.
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        // Neither exists yet: compare the paths as given, made absolute.
        _ => std::path::absolute(a).ok() == std::path::absolute(b).ok(),
    }
}
