//! Checks on the files a batch run will write, made before any time is
//! spent solving: each output is a regular file or a new one, none is an
//! input of the run (the files it names before loading, and those
//! loading read, through every link), no two are the same file, and each
//! can be created where it is to go.

use super::checkpoint::CheckpointError;
use super::RunError;
use crate::config::{RunConfig, SceneSource};
use crate::output::{self, convergence, MeshFormat, OutputError, PictureFormat};
use crate::prepare;
use crate::scene::import::input::{
    check_readable, what_it_is, InputError, InputFile, InputKind, InputSet,
};
use std::path::{Path, PathBuf};

/// Refuses unusable outputs before anything is loaded: an unknown
/// extension, a missing directory, a path that is no regular file (a
/// directory, a device, a FIFO), a path that is an input `config` names
/// (the scene, `--camera`, `--ies`, `--illuminance-at`, `--resume`, hard
/// or symbolic links to them), two outputs that are the same file, a file
/// that cannot be created in its directory (read-only, a name too long),
/// or a checkpoint to resume from that cannot be read. The inputs loading
/// finds (libraries, textures, buffers) are checked by
/// [`check_outputs_against`] once loaded.
pub fn check_outputs(config: &RunConfig) -> Result<(), RunError> {
    let output = config.output_path();
    if config.mesh_lines {
        PictureFormat::eight_bit(&output, "--mesh-lines draws on 8-bit pictures")
    } else {
        PictureFormat::from_path(&output)
    }
    .map_err(RunError::BadOutput)?;
    if let Some(export) = &config.export {
        MeshFormat::from_path(export).map_err(RunError::BadOutput)?;
    }
    if let Some(path) = &config.lightmap {
        output::lightmap::check_glb_path(path).map_err(RunError::BadOutput)?;
    }
    if let Some(path) = &config.lightmap_texture {
        output::lightmap::check_texture_path(path).map_err(RunError::BadOutput)?;
    }
    if config.lightmap_density.is_some() && !config.wants_lightmap() {
        return Err(RunError::Options(
            "--lightmap-density sets the density of a lightmap: give --lightmap FILE.glb or \
             --lightmap-texture FILE too"
                .into(),
        ));
    }
    if let Some(plot) = &config.plot {
        convergence::check_plot_path(plot).map_err(RunError::BadOutput)?;
    }
    // False-colour pictures and plans are 8-bit, as the plot is (the
    // plan is always PREFIX.png).
    if let Some(f) = &config.photometry.falsecolor {
        PictureFormat::eight_bit(&f.path, "--falsecolor writes an 8-bit picture")
            .map_err(RunError::BadOutput)?;
    }
    let named = named_inputs(config);
    check_against(config, &named.files())?;
    if let Some(resume) = &config.resume {
        // Refused now rather than after the load if it cannot be read or
        // is no regular file; nothing is read yet.
        match check_readable(resume, InputKind::Checkpoint) {
            Ok(()) => {}
            Err(InputError::Io { error, .. }) => {
                return Err(CheckpointError::Read {
                    path: resume.clone(),
                    error,
                }
                .into())
            }
            Err(refused) => return Err(CheckpointError::Refused(refused).into()),
        }
    }
    Ok(())
}

/// Refuses an output that is one of `inputs` (the files loading read: a
/// material library, a texture, a glTF buffer), checked once they are
/// known, after loading and before any solving; [`check_outputs`] has
/// checked the rest.
pub fn check_outputs_against(config: &RunConfig, inputs: &InputSet) -> Result<(), RunError> {
    check_against(config, &inputs.files())
}

/// The inputs `config` names itself (the scene, `--camera`, `--ies`,
/// `--illuminance-at`, `--resume`), recorded by identity where they
/// exist, before anything is read.
pub fn named_inputs(config: &RunConfig) -> InputSet {
    let inputs = prepare::declared_inputs(config);
    if let SceneSource::File(scene) = &config.scene {
        inputs.declare(scene, InputKind::Scene);
    }
    if let Some(camera) = &config.camera {
        inputs.declare(camera, InputKind::Camera);
    }
    for (_, ies) in &config.photometry.ies {
        inputs.declare(ies, InputKind::Ies);
    }
    inputs
}

/// Every file a run writes, with the option that names it, in the order
/// they are written.
pub fn named_outputs(config: &RunConfig) -> Vec<(&'static str, PathBuf)> {
    let picture = if config.output.is_some() {
        "-o"
    } else {
        "the picture (by default <scene>.png)"
    };
    let mut outputs = vec![(picture, config.output_path())];
    let optional = [
        ("--stats", &config.stats),
        ("--export", &config.export),
        ("--lightmap", &config.lightmap),
        ("--lightmap-texture", &config.lightmap_texture),
        ("--log", &config.log),
        ("--plot", &config.plot),
        ("--checkpoint", &config.checkpoint),
    ];
    for (option, path) in optional {
        outputs.extend(path.iter().map(|p| (option, p.clone())));
    }
    let photometry = &config.photometry;
    if let Some((_, out)) = &photometry.illuminance {
        outputs.push(("--illuminance-out", out.clone()));
    }
    if let Some(w) = &photometry.workplane {
        outputs.push(("--workplane-out", w.csv.clone()));
        outputs.push(("--workplane-out", w.png.clone()));
    }
    if let Some(f) = &photometry.falsecolor {
        outputs.push(("--falsecolor", f.path.clone()));
    }
    outputs
}

/// Every option that names an output, for messages.
const OUTPUT_OPTIONS: &str = "the picture (-o), --stats, --export, --lightmap, \
                              --lightmap-texture, --log, --plot, --checkpoint, \
                              --illuminance-out, --workplane-out and --falsecolor";

/// Refuses any output of `config` that is no regular file (a directory,
/// a FIFO, a device), that is one of `inputs`, that another output also
/// names, or that cannot be created where it is to go.
fn check_against(config: &RunConfig, inputs: &[InputFile]) -> Result<(), RunError> {
    let outputs = named_outputs(config);
    for (k, (option, out)) in outputs.iter().enumerate() {
        output::check_destination(out).map_err(RunError::BadOutput)?;
        if let Ok(meta) = std::fs::metadata(out) {
            if !meta.is_file() {
                return Err(refuse(
                    out,
                    format!(
                        "{option} names {}, not a regular file; an output replaces a file \
                         or makes a new one",
                        what_it_is(&meta)
                    ),
                ));
            }
        }
        // A resumed solve goes on saving to the checkpoint it resumed
        // from: the one output that may be an input, as the state is
        // read whole before the first save replaces it.
        let updates_its_checkpoint =
            |input: &&InputFile| *option == "--checkpoint" && input.kind == InputKind::Checkpoint;
        if let Some(input) = inputs
            .iter()
            .find(|input| input.is(out) && !updates_its_checkpoint(input))
        {
            let also = if input.path == *out {
                String::new()
            } else {
                format!(" {}", input.path.display())
            };
            return Err(refuse(
                out,
                format!(
                    "{option} would overwrite the {}{also}, an input of this run: \
                     refusing to overwrite an input file",
                    input.kind.name()
                ),
            ));
        }
        if let Some((earlier, _)) = outputs[..k]
            .iter()
            .find(|(_, earlier)| earlier == out || same_file(earlier, out))
        {
            return Err(refuse(
                out,
                format!(
                    "two outputs would write this same file ({earlier} and {option}): \
                     {OUTPUT_OPTIONS} must be different files"
                ),
            ));
        }
        output::check_creatable(out).map_err(RunError::BadOutput)?;
    }
    Ok(())
}

/// The error refusing output `path` for `why`.
fn refuse(path: &Path, why: String) -> RunError {
    RunError::BadOutput(OutputError::Io {
        path: path.to_path_buf(),
        error: std::io::Error::new(std::io::ErrorKind::InvalidInput, why),
    })
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
