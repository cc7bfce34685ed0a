//! Raw arguments to the one validated value the library sees: an
//! [`Invocation`], the run's [`RunConfig`] plus what only the front end
//! decides (window or batch, the thread count).
//!
//! Every value is checked once, by the module that owns its meaning where
//! there is one ([`mesh::check_lenmax`], [`mesh::check_inset`],
//! [`RefineOptions::validate`]); the ranges that belong to no module below
//! the front end (the threshold, exposure, element limit, checkpoint
//! interval and thread count) are checked here.

use super::args::Args;
use super::values::SkyArg;
use crate::budget::MemoryBudget;
use crate::camera::{Camera, CameraOverride};
use crate::config::{
    DaylightConfig, FalsecolorConfig, PhotometryConfig, RunConfig, SceneSource, WorkplaneConfig,
};
use crate::mesh::refine::{self, RefineOptions};
use crate::mesh::{self, MeshError};
use crate::render::{Exposure, MAX_EXPOSURE_STOPS};
use crate::scene::{Sides, SkyModel};
use crate::solver::{Approximations, Heuristic, SolverOptions};
use glam::Vec3;
use std::num::NonZeroUsize;
use std::time::Duration;

/// The longest checkpoint interval, in seconds (about 32 years): longer
/// ones mean "never" and would overflow a [`Duration`] for infinite input.
const MAX_CHECKPOINT_EVERY_SECS: f64 = 1e9;

/// The most worker threads `--threads` may ask for. The solver and
/// renderer gain nothing past the machine's cores, and a count in the
/// thousands is a typo that would start that many threads (each with its
/// stack) before anything useful happens. A fixed number rather than one
/// derived from the cores, so a command valid on one machine is valid on
/// every other.
pub const MAX_THREADS: usize = 1024;

/// How the run is driven, decided once from the options.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Solve, then write the picture and every other output asked for:
    /// chosen by `-o`, `--no-window`, any output only a batch run writes
    /// (`--export`, `--log`, `--plot`, `--mesh-lines`), `--checkpoint` or
    /// `--resume`.
    Batch,
    /// Open the window; when it cannot open (no display, or the display
    /// refuses), say why and run as [`Mode::Batch`] instead, writing
    /// `<scene>.png` in the current directory.
    Window,
    /// `--info`: load the scene, apply the options that change it, print
    /// what it holds and exit, without meshing or solving.
    Info,
}

/// Everything one invocation of the program needs, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Invocation {
    /// The run itself: scene, mesh, solver and output options.
    pub config: RunConfig,
    /// Window or batch.
    pub mode: Mode,
    /// Worker threads for the global pool; `None` for one per core.
    pub threads: Option<NonZeroUsize>,
}

impl Invocation {
    /// `-q`: no progress bar, no summary line and no notice when the
    /// window falls back to a file. The library sees it as
    /// `!config.progress`, its only source.
    pub fn quiet(&self) -> bool {
        !self.config.progress
    }
}

/// Options that parsed but cannot be used: exit code 2. The messages name
/// the option as it is spelled on the command line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum UsageError {
    /// `--threshold` is outside `[0, 1]`.
    #[error("--threshold must be between 0 and 1, got {0}")]
    Threshold(f64),
    /// `--settle` is outside `[0, 1)`.
    #[error("--settle must be at least 0 and below 1, got {0}")]
    Settle(f64),
    /// `--lenmax` or `--inset` is refused by the mesh; its messages start
    /// with the option's name (`lenmax`, `inset`), spelled as the flag is.
    #[error("--{0}")]
    Mesh(#[from] MeshError),
    /// `--max-elements` is 0 or more than [`mesh::MAX_ADDRESSABLE_ELEMENTS`].
    #[error("--max-elements must be between 1 and {max}, got {0}", max = mesh::MAX_ADDRESSABLE_ELEMENTS)]
    MaxElements(u64),
    /// `--checkpoint-every` is negative or not a number.
    #[error("--checkpoint-every must be a number of seconds >= 0, got {0}")]
    CheckpointEvery(f64),
    /// `--adaptive-threshold`, `--adaptive-levels` or
    /// `--adaptive-max-splits` is out of range; the refinement's messages
    /// start with the field's name (`threshold`, `levels`, `max-splits`),
    /// which the flag spells with `adaptive-` before it.
    #[error("--adaptive-{0}")]
    Refine(#[from] refine::OptionsError),
    /// `--exposure` is not a number of stops within
    /// [`MAX_EXPOSURE_STOPS`] either way.
    #[error(
        "--exposure must be a number of stops from -{MAX_EXPOSURE_STOPS} to {MAX_EXPOSURE_STOPS} \
         (0 is the automatic exposure, +1 twice as bright), got {0}"
    )]
    Exposure(f32),
    /// `--threads 0`, or more than `MAX_THREADS` (1024).
    #[error(
        "--threads must be from 1 to {MAX_THREADS}, got {0} (this machine has {cores} cores; \
         omit --threads to use them all)",
        cores = std::thread::available_parallelism().map_or(1, |n| n.get())
    )]
    Threads(usize),
    /// A standard sky cannot be made as asked (it needs `--sun`).
    #[error("{0}")]
    Daylight(#[from] crate::scene::DaylightError),
    /// `--daylight-factor` without the overcast sky it is defined under.
    #[error(
        "--daylight-factor needs --sky cie-overcast (or cie:1): the daylight factor is \
         defined under the CIE overcast sky"
    )]
    DaylightFactorSky,
    /// `--sun` under an overcast sky that does not depend on the sun
    /// (`cie-overcast`, `cie:1`, `cie:3`, `cie:5`): it has no sun to give
    /// and nothing to shape.
    #[error(
        "--sun has no effect under --sky {0}: an overcast sky has no sun, and its luminance \
         does not depend on where the sun is; drop --sun, or choose --sky cie-clear or \
         cie:6 to cie:15 for sunlight"
    )]
    SunWithoutSky(String),
    /// `--sun` with an illuminance under an overcast sky: it has no sun.
    #[error(
        "--sun gives the sun an illuminance, but --sky {0} is overcast and has no sun \
         (under cie:2 and cie:4 --sun only shapes the sky): drop the `,Nlx`, or choose \
         --sky cie-clear or cie:6 to cie:15 for sunlight"
    )]
    SunUnderOvercast(String),
    /// `--falsecolor-max` is not a positive finite number.
    #[error("--falsecolor-max must be a positive number, got {0}")]
    FalsecolorMax(f64),
    /// `--eye`, `--look-at` and `--up` make no camera whatever the scene
    /// (the eye on the look-at point, up along the view).
    #[error("{0}")]
    Camera(#[from] crate::camera::OverrideError),
}

/// The camera parts given on the command line, checked where they
/// decide the camera alone: `--eye` and `--look-at` together, and with
/// them `--up`. What they make with the scene's camera is checked once it
/// is loaded ([`CameraOverride::apply`]).
fn camera_override(args: &Args) -> Result<CameraOverride, UsageError> {
    let given = CameraOverride {
        eye: args.eye,
        lookat: args.look_at,
        up: args.up,
        fov_deg: args.fov,
    };
    if let (Some(eye), Some(lookat)) = (given.eye, given.lookat) {
        // Any up across the view stands for one not given.
        let view = (lookat - eye).normalize_or_zero();
        let across = if view.cross(Vec3::Y).length() > 0.5 {
            Vec3::Y
        } else {
            Vec3::X
        };
        let probe = Camera {
            eye,
            lookat,
            up: across,
            fov_y: crate::camera::DEFAULT_FOV_DEG.to_radians(),
            width: 1,
            height: 1,
        };
        given.apply(&probe)?;
    }
    Ok(given)
}

/// The photometric options as given, before they become a
/// [`PhotometryConfig`].
struct PhotometryArgs {
    stem: String,
    units: Option<crate::scene::Units>,
    ies: Vec<(String, std::path::PathBuf)>,
    illuminance_at: Option<std::path::PathBuf>,
    illuminance_out: Option<std::path::PathBuf>,
    workplane: Option<(f32, Option<f32>)>,
    workplane_out: Option<std::path::PathBuf>,
    daylight_factor: bool,
    falsecolor: Option<std::path::PathBuf>,
    falsecolor_of: crate::render::falsecolor::Quantity,
    falsecolor_scale: crate::render::falsecolor::Scale,
    falsecolor_max: Option<f64>,
}

/// The photometric part of the configuration; the work plane's files are
/// `PREFIX.csv` and `PREFIX.png`, `PREFIX` by default
/// `<scene-stem>-workplane`.
/// The solver's heuristics as the switches ask: `--exact` starts from the
/// brute-force twin, and `--without` and the older single switches
/// (`--no-clustering`, `--exact-receivers`, ...) turn theirs off.
fn approximations(args: &Args) -> Approximations {
    let start = if args.exact {
        Approximations::EXACT
    } else {
        Approximations::DEFAULT
    };
    let singles = [
        (args.no_near_field, Heuristic::NearField),
        (args.no_shaft_culling, Heuristic::ShaftCulling),
        (args.no_clustering, Heuristic::Clusters),
        (args.no_overshoot, Heuristic::Overshoot),
    ];
    let mut off = args.without.clone();
    off.extend(singles.iter().filter(|(on, _)| *on).map(|&(_, h)| h));
    if args.exact_receivers {
        off.extend(Heuristic::RECEIVERS);
    }
    start.without(&off)
}

fn photometry(a: &PhotometryArgs) -> PhotometryConfig {
    PhotometryConfig {
        units: a.units,
        ies: a.ies.clone(),
        illuminance: a.illuminance_at.clone().zip(a.illuminance_out.clone()),
        workplane: a.workplane.map(|(height, spacing)| {
            let prefix = a
                .workplane_out
                .clone()
                .unwrap_or_else(|| format!("{}-workplane", a.stem).into());
            let with = |ext: &str| {
                let mut p = prefix.clone().into_os_string();
                p.push(ext);
                std::path::PathBuf::from(p)
            };
            WorkplaneConfig {
                height,
                spacing,
                csv: with(".csv"),
                png: with(".png"),
                daylight_factor: a.daylight_factor.then(|| with("-df.png")),
                scale: a.falsecolor_scale,
                max: a.falsecolor_max,
            }
        }),
        falsecolor: a.falsecolor.clone().map(|path| FalsecolorConfig {
            path,
            quantity: a.falsecolor_of,
            scale: a.falsecolor_scale,
            max: a.falsecolor_max,
        }),
    }
}

impl TryFrom<Args> for Invocation {
    type Error = UsageError;

    /// Checks every value, in a fixed order so that a command line with
    /// several bad values always reports the same one, builds the
    /// [`RunConfig`] and decides the [`Mode`].
    fn try_from(args: Args) -> Result<Invocation, UsageError> {
        if !(0.0..=1.0).contains(&args.threshold) {
            return Err(UsageError::Threshold(args.threshold));
        }
        if !(0.0..1.0).contains(&args.settle) {
            return Err(UsageError::Settle(args.settle));
        }
        let lenmax = args.lenmax.map(mesh::check_lenmax).transpose()?;
        let inset = mesh::check_inset(args.inset)?;
        if args.max_elements == 0 || args.max_elements > mesh::MAX_ADDRESSABLE_ELEMENTS {
            return Err(UsageError::MaxElements(args.max_elements));
        }
        if !(args.checkpoint_every.is_finite() && args.checkpoint_every >= 0.0) {
            return Err(UsageError::CheckpointEvery(args.checkpoint_every));
        }
        // Checked with or without --adaptive (clap refuses them without it
        // unless they are the defaults, which are valid).
        let refine = RefineOptions {
            threshold: args.adaptive_threshold,
            levels: args.adaptive_levels,
            max_splits: args.adaptive_max_splits,
            max_elements: args.max_elements,
        };
        refine.validate()?;
        let exposure = match args.exposure {
            None => Exposure::Auto,
            Some(stops) if stops.abs() <= MAX_EXPOSURE_STOPS => Exposure::Stops(stops),
            Some(x) => return Err(UsageError::Exposure(x)),
        };
        let threads = match args.threads {
            None => None,
            Some(n) if n > MAX_THREADS => return Err(UsageError::Threads(n)),
            Some(n) => Some(NonZeroUsize::new(n).ok_or(UsageError::Threads(n))?),
        };
        if let Some(max) = args.falsecolor_max {
            if !(max.is_finite() && max > 0.0) {
                return Err(UsageError::FalsecolorMax(max));
            }
        }
        let args_photometry = PhotometryArgs {
            stem: args
                .scene
                .as_ref()
                .map_or(SceneSource::Bundled, |p| SceneSource::File(p.clone()))
                .stem(),
            units: args.units,
            ies: args.ies.clone(),
            illuminance_at: args.illuminance_at.clone(),
            illuminance_out: args.illuminance_out.clone(),
            workplane: args.workplane,
            workplane_out: args.workplane_out.clone(),
            daylight_factor: args.daylight_factor,
            falsecolor: args.falsecolor.clone(),
            falsecolor_of: args.falsecolor_of,
            falsecolor_scale: args.falsecolor_scale,
            falsecolor_max: args.falsecolor_max,
        };
        let daylight = DaylightConfig {
            sky: match args.sky {
                Some(SkyArg::Standard(model, level)) => Some((model, level)),
                _ => None,
            },
            sun: args.sun.map(|s| s.position),
            sun_day: args.sun.and_then(|s| s.day),
            sun_lux: args.sun.and_then(|s| s.normal_lux),
            north: args.north.unwrap_or(0.0).to_radians(),
        };
        // Under the overcast types the sun has no light of its own: it
        // shapes the skies that depend on it (cie:2, cie:4), and is refused
        // where it would do nothing or was given a brightness.
        if let (Some(sun), Some((model, _))) = (args.sun, daylight.sky) {
            if !model.has_sun() && sun.normal_lux.is_some() {
                return Err(UsageError::SunUnderOvercast(model.name()));
            }
            if !model.has_sun() && !model.needs_sun() {
                return Err(UsageError::SunWithoutSky(model.name()));
            }
        }
        daylight.resolve()?;
        if args.daylight_factor
            && !matches!(
                daylight.sky,
                Some((SkyModel::CieOvercast | SkyModel::Cie(1), _))
            )
        {
            return Err(UsageError::DaylightFactorSky);
        }
        let approximations = approximations(&args);
        let camera_override = camera_override(&args)?;
        let config = RunConfig {
            scene: args.scene.map_or(SceneSource::Bundled, SceneSource::File),
            output: args.output,
            lenmax,
            inset,
            solver: SolverOptions {
                form_factor: args.form_factor,
                shooter_samples: args.shooter_samples,
                threshold: args.threshold,
                settle: args.settle,
                max_steps: args.max_steps,
                approximations,
                unshot: args.unshot,
                hemicube_res: args.hemicube_res,
                // A window asks for parts ([`crate::viewer`]); a batch run
                // has no picture between steps.
                part_budget: None,
                tail: args.tail,
                tail_particles: args.tail_particles,
            },
            size: args.size,
            exposure,
            stats: args.stats,
            camera: args.camera,
            camera_override,
            export: args.export,
            lightmap: args.lightmap,
            lightmap_texture: args.lightmap_texture,
            lightmap_density: args.lightmap_density,
            log: args.log,
            plot: args.plot,
            progress: !args.quiet,
            max_elements: args.max_elements,
            max_memory: args
                .max_memory
                .map_or_else(MemoryBudget::for_machine, MemoryBudget::new),
            checkpoint: args.checkpoint,
            checkpoint_every: Duration::from_secs_f64(
                args.checkpoint_every.min(MAX_CHECKPOINT_EVERY_SECS),
            ),
            resume: args.resume,
            allow_outside_paths: args.allow_outside_paths,
            ambient: match (args.ambient, args.no_ambient) {
                (true, _) => Some(true),
                (_, true) => Some(false),
                (false, false) => None,
            },
            adaptive: args.adaptive.then_some(refine),
            refine_coarsened: !args.no_adaptive,
            mesh_lines: args.mesh_lines,
            aa: args.aa,
            emit: args.emit,
            sides: match (args.one_sided, args.two_sided) {
                (true, _) => Sides::One,
                (_, true) => Sides::Two,
                (false, false) => Sides::AsLoaded,
            },
            sky: match args.sky {
                Some(SkyArg::Uniform(rgb)) => Some(rgb),
                _ => None,
            },
            photometry: photometry(&args_photometry),
            daylight,
        };
        let mode = if args.info {
            Mode::Info
        } else if args.no_window
            || config.output.is_some()
            || config.wants_batch_outputs()
            || config.checkpoint.is_some()
            || config.resume.is_some()
        {
            Mode::Batch
        } else {
            Mode::Window
        };
        Ok(Invocation {
            config,
            mode,
            threads,
        })
    }
}

#[cfg(test)]
mod tests;
