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
use crate::config::{FalsecolorConfig, PhotometryConfig, RunConfig, SceneSource, WorkplaneConfig};
use crate::mesh::refine::{self, RefineOptions};
use crate::mesh::{self, MeshError};
use crate::render::Exposure;
use crate::scene::Sides;
use crate::solver::SolverOptions;
use std::num::NonZeroUsize;
use std::time::Duration;

/// The longest checkpoint interval, in seconds (about 32 years): longer
/// ones mean "never" and would overflow a [`Duration`] for infinite input.
const MAX_CHECKPOINT_EVERY_SECS: f64 = 1e9;

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
    /// `--adaptive-threshold` or `--adaptive-levels` is out of range; the
    /// refinement's messages start with the field's name (`threshold`,
    /// `levels`), which the flag spells with `adaptive-` before it.
    #[error("--adaptive-{0}")]
    Refine(#[from] refine::OptionsError),
    /// `--exposure` is not a positive finite number.
    #[error("--exposure must be a positive number, got {0}")]
    Exposure(f32),
    /// `--threads 0`.
    #[error("--threads must be at least 1")]
    Threads,
    /// `--falsecolor-max` is not a positive finite number.
    #[error("--falsecolor-max must be a positive number, got {0}")]
    FalsecolorMax(f64),
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
    falsecolor: Option<std::path::PathBuf>,
    falsecolor_of: crate::render::falsecolor::Quantity,
    falsecolor_scale: crate::render::falsecolor::Scale,
    falsecolor_max: Option<f64>,
}

/// The photometric part of the configuration; the work plane's files are
/// `PREFIX.csv` and `PREFIX.png`, `PREFIX` by default
/// `<scene-stem>-workplane`.
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
            max_elements: args.max_elements,
        };
        refine.validate()?;
        let exposure = match args.exposure {
            None => Exposure::Auto,
            Some(x) if x.is_finite() && x > 0.0 => Exposure::Fixed(x),
            Some(x) => return Err(UsageError::Exposure(x)),
        };
        let threads = match args.threads {
            None => None,
            Some(n) => Some(NonZeroUsize::new(n).ok_or(UsageError::Threads)?),
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
            falsecolor: args.falsecolor.clone(),
            falsecolor_of: args.falsecolor_of,
            falsecolor_scale: args.falsecolor_scale,
            falsecolor_max: args.falsecolor_max,
        };
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
                near_field: !args.no_near_field,
                shaft_culling: !args.no_shaft_culling,
                unshot: args.unshot,
                clustering: !args.no_clustering,
                receiver_interpolation: !args.exact_receivers,
                hemicube_res: args.hemicube_res,
                overshoot: !args.no_overshoot,
                // A window asks for parts ([`crate::viewer`]); a batch run
                // has no picture between steps.
                part_budget: None,
            },
            size: args.size,
            exposure,
            stats: args.stats,
            camera: args.camera,
            export: args.export,
            log: args.log,
            plot: args.plot,
            progress: !args.quiet,
            max_elements: args.max_elements,
            checkpoint: args.checkpoint,
            checkpoint_every: Duration::from_secs_f64(
                args.checkpoint_every.min(MAX_CHECKPOINT_EVERY_SECS),
            ),
            resume: args.resume,
            ambient: match (args.ambient, args.no_ambient) {
                (true, _) => Some(true),
                (_, true) => Some(false),
                (false, false) => None,
            },
            adaptive: args.adaptive.then_some(refine),
            mesh_lines: args.mesh_lines,
            aa: args.aa,
            emit: args.emit,
            sides: match (args.one_sided, args.two_sided) {
                (true, _) => Sides::One,
                (_, true) => Sides::Two,
                (false, false) => Sides::AsLoaded,
            },
            sky: args.sky,
            photometry: photometry(&args_photometry),
        };
        let mode = if args.no_window
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
mod tests {
    use super::*;
    use crate::config::DEFAULT_MAX_ELEMENTS;
    use crate::solver::{FormFactorMethod, ShooterSamples, UnshotScheme};
    use clap::{CommandFactory, Parser};
    use std::path::PathBuf;

    fn parse(args: &[&str]) -> Result<Args, clap::Error> {
        Args::try_parse_from(std::iter::once("radiosity").chain(args.iter().copied()))
    }

    fn invocation(args: &[&str]) -> Result<Invocation, UsageError> {
        Invocation::try_from(parse(args).expect("the arguments parse"))
    }

    fn config(args: &[&str]) -> RunConfig {
        invocation(args).expect("the arguments are valid").config
    }

    #[test]
    fn no_arguments_give_the_library_defaults_and_the_window() {
        let i = invocation(&[]).unwrap();
        // Also keeps the literal default of --shooter-samples equal to
        // solver::DEFAULT_SHOOTER_SAMPLES.
        assert_eq!(
            i.config,
            RunConfig {
                progress: true,
                ..RunConfig::new(SceneSource::Bundled)
            }
        );
        assert_eq!(i.mode, Mode::Window);
        assert_eq!(i.threads, None);
        assert!(!i.quiet());
    }

    #[test]
    fn antialiasing_takes_1_to_8_samples_a_side() {
        assert_eq!(config(&[]).aa, crate::render::antialias::DEFAULT_AA);
        assert_eq!(config(&["--aa", "1"]).aa, 1);
        assert_eq!(config(&["--aa", "8"]).aa, 8);
        for bad in ["0", "9", "-1", "two"] {
            assert!(parse(&["--aa", bad]).is_err(), "--aa {bad}");
        }
    }

    #[test]
    fn every_option_reaches_the_config() {
        let c = config(&[
            "room.sc",
            "-o",
            "out.exr",
            "--lenmax",
            "0.25",
            "--inset",
            "0",
            "--threshold",
            "0.01",
            "--settle",
            "0.05",
            "--max-steps",
            "7",
            "--shooter-samples",
            "all",
            "--no-near-field",
            "--no-shaft-culling",
            "--no-clustering",
            "--exact-receivers",
            "--no-overshoot",
            "--aa",
            "5",
            "--size",
            "32x24",
            "--exposure",
            "2",
            "--stats",
            "s.json",
            "--camera",
            "cam.sc",
            "--export",
            "m.ply",
            "--log",
            "l.csv",
            "--plot",
            "p.png",
            "--max-elements",
            "5000",
            "--checkpoint-every",
            "2.5",
            "--no-ambient",
            "--emit",
            "Lamp=10",
            "--emit",
            "shade=1,2,3",
            "--sky",
            "0.5,0.6,0.7",
            "-q",
        ]);
        assert_eq!(c.scene, SceneSource::File(PathBuf::from("room.sc")));
        assert_eq!(c.output, Some(PathBuf::from("out.exr")));
        assert_eq!((c.lenmax, c.inset), (Some(0.25), 0.0));
        assert_eq!(
            c.solver,
            SolverOptions {
                form_factor: FormFactorMethod::Wallace,
                shooter_samples: ShooterSamples::All,
                threshold: 0.01,
                settle: 0.05,
                max_steps: Some(7),
                near_field: false,
                shaft_culling: false,
                unshot: UnshotScheme::Vertex,
                clustering: false,
                receiver_interpolation: false,
                hemicube_res: crate::solver::hemicube::HemicubeRes::default(),
                overshoot: false,
                part_budget: None,
            }
        );
        assert_eq!(c.size, Some((32, 24)));
        assert_eq!(c.aa, 5);
        assert_eq!(c.exposure, Exposure::Fixed(2.0));
        assert_eq!(c.stats, Some(PathBuf::from("s.json")));
        assert_eq!(c.camera, Some(PathBuf::from("cam.sc")));
        assert_eq!(c.export, Some(PathBuf::from("m.ply")));
        assert_eq!(c.log, Some(PathBuf::from("l.csv")));
        assert_eq!(c.plot, Some(PathBuf::from("p.png")));
        assert_eq!(c.max_elements, 5000);
        assert_eq!(c.checkpoint_every, Duration::from_millis(2500));
        assert_eq!(c.ambient, Some(false));
        assert_eq!(
            c.emit,
            [
                ("Lamp".to_string(), crate::color::Rgb::splat(10.0)),
                ("shade".to_string(), crate::color::Rgb::new(1.0, 2.0, 3.0)),
            ]
        );
        assert_eq!(c.sky, Some(crate::color::Rgb::new(0.5, 0.6, 0.7)));
        assert!(!c.progress);
        assert_eq!(config(&["--ambient"]).ambient, Some(true));
        assert_eq!(config(&[]).sky, None);
    }

    #[test]
    fn form_factor_takes_each_method_by_name() {
        for (name, method) in [
            ("wallace", FormFactorMethod::Wallace),
            ("center", FormFactorMethod::Center),
            ("hemicube", FormFactorMethod::Hemicube),
        ] {
            assert_eq!(config(&["--form-factor", name]).solver.form_factor, method);
        }
        assert_eq!(
            config(&["--hemicube-res", "64"]).solver.hemicube_res.get(),
            64
        );
        for bad in ["0", "7", "100000", "lots"] {
            let e = parse(&["--hemicube-res", bad]).unwrap_err();
            assert_eq!(e.kind(), clap::error::ErrorKind::ValueValidation, "{bad}");
            assert!(e.to_string().contains("even whole number"), "{e}");
        }
        let e = parse(&["--form-factor", "magic"]).unwrap_err();
        assert_eq!(e.kind(), clap::error::ErrorKind::InvalidValue);
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn unshot_takes_each_scheme_by_name() {
        for (name, scheme) in [
            ("vertex", UnshotScheme::Vertex),
            ("polygon", UnshotScheme::Polygon),
        ] {
            assert_eq!(config(&["--unshot", name]).solver.unshot, scheme);
        }
        for bad in ["Polygon", "element", ""] {
            let e = parse(&["--unshot", bad]).unwrap_err();
            assert_eq!(e.kind(), clap::error::ErrorKind::InvalidValue, "{bad}");
        }
    }

    #[test]
    fn structured_values_are_parsed_or_refused_by_clap() {
        assert_eq!(
            config(&["--shooter-samples", "16"]).solver.shooter_samples,
            ShooterSamples::AtMost(16)
        );
        assert_eq!(config(&["--size", "640X480"]).size, Some((640, 480)));
        for args in [
            &["--shooter-samples", "0"][..],
            &["--shooter-samples", "zero"],
            &["--size", "10by10"],
            &["--size", "0x10"],
            &["--emit", "Lamp=-1"],
            &["--emit", "Lamp=a,b"],
            &["--sky=-1"],
            &["--sky", "1,2"],
        ] {
            let e = parse(args).unwrap_err();
            assert_eq!(
                e.kind(),
                clap::error::ErrorKind::ValueValidation,
                "{args:?}"
            );
            assert_eq!(e.exit_code(), 2);
        }
    }

    #[test]
    fn out_of_range_values_are_usage_errors_naming_the_option() {
        let cases: &[(&[&str], UsageError, &str)] = &[
            (
                &["--threshold", "2"],
                UsageError::Threshold(2.0),
                "--threshold must be between 0 and 1, got 2",
            ),
            (
                &["--settle", "1"],
                UsageError::Settle(1.0),
                "--settle must be at least 0 and below 1, got 1",
            ),
            (
                &["--lenmax", "0"],
                UsageError::Mesh(MeshError::BadLenmax(0.0)),
                "--lenmax must be a positive number of scene units, got 0",
            ),
            (
                &["--lenmax", "inf"],
                UsageError::Mesh(MeshError::BadLenmax(f32::INFINITY)),
                "--lenmax must be a positive number of scene units, got inf",
            ),
            (
                &["--inset", "0.5"],
                UsageError::Mesh(MeshError::BadInset(0.5)),
                "--inset must be at least 0 and below 0.5",
            ),
            (
                &["--max-elements", "0"],
                UsageError::MaxElements(0),
                "--max-elements must be between 1 and ",
            ),
            (
                &["--checkpoint-every=-1"],
                UsageError::CheckpointEvery(-1.0),
                "--checkpoint-every must be a number of seconds >= 0, got -1",
            ),
            (
                &["--adaptive", "--adaptive-threshold", "1"],
                UsageError::Refine(refine::OptionsError::Threshold(1.0)),
                "--adaptive-threshold must be above 0 and below 1, got 1",
            ),
            (
                &["--adaptive", "--adaptive-levels", "0"],
                UsageError::Refine(refine::OptionsError::Levels(0)),
                "--adaptive-levels must be between 1 and 6, got 0",
            ),
            (
                &["--exposure", "0"],
                UsageError::Exposure(0.0),
                "--exposure must be a positive number, got 0",
            ),
            (
                &["--threads", "0"],
                UsageError::Threads,
                "--threads must be at least 1",
            ),
        ];
        for (args, error, message) in cases {
            let e = invocation(args).unwrap_err();
            assert_eq!(&e, error, "{args:?}");
            assert!(e.to_string().starts_with(message), "{args:?}: {e}");
        }
        let over = (mesh::MAX_ADDRESSABLE_ELEMENTS + 1).to_string();
        assert!(matches!(
            invocation(&["--max-elements", &over]),
            Err(UsageError::MaxElements(_))
        ));
    }

    #[test]
    fn adaptive_options_reach_the_config_only_with_adaptive() {
        assert_eq!(config(&[]).adaptive, None);
        assert_eq!(
            config(&["--adaptive"]).adaptive,
            Some(RefineOptions {
                max_elements: DEFAULT_MAX_ELEMENTS,
                ..RefineOptions::default()
            })
        );
        assert_eq!(
            config(&[
                "--adaptive",
                "--adaptive-threshold",
                "0.1",
                "--adaptive-levels",
                "3",
                "--max-elements",
                "900",
            ])
            .adaptive,
            Some(RefineOptions {
                threshold: 0.1,
                levels: 3,
                max_elements: 900,
            })
        );
        // Without --adaptive they are refused by clap, not ignored.
        assert!(parse(&["--adaptive-levels", "3"]).is_err());
        assert!(parse(&["--adaptive", "--checkpoint", "c.bin"]).is_err());
    }

    #[test]
    fn threads_are_a_positive_count() {
        assert_eq!(
            invocation(&["--threads", "3"]).unwrap().threads,
            NonZeroUsize::new(3)
        );
    }

    #[test]
    fn batch_is_chosen_by_any_file_only_a_batch_run_writes() {
        for args in [
            &["-o", "out.png"][..],
            &["--no-window"],
            &["--export", "m.glb"],
            &["--log", "l.csv"],
            &["--plot", "p.png"],
            &["--mesh-lines"],
            &["--checkpoint", "c.bin"],
            &["--resume", "c.bin"],
        ] {
            assert_eq!(invocation(args).unwrap().mode, Mode::Batch, "{args:?}");
        }
        // The window takes everything else, even options that only a file
        // uses (it falls back to a file when it cannot open).
        for args in [
            &[][..],
            &["scene.sc"],
            &["--stats", "s.json"],
            &["--size", "64x48", "-q"],
            &["--adaptive"],
        ] {
            assert_eq!(invocation(args).unwrap().mode, Mode::Window, "{args:?}");
        }
    }

    #[test]
    fn every_option_has_a_one_line_summary_for_short_help() {
        let command = Args::command();
        for arg in command.get_arguments() {
            let help = arg.get_help().map(ToString::to_string).unwrap_or_default();
            assert!(!help.is_empty(), "{} has no help", arg.get_id());
            assert!(
                !help.contains('\n') && help.len() <= 80,
                "{}: `{help}` is not a one-line summary",
                arg.get_id()
            );
        }
        command.debug_assert();
    }

    #[test]
    fn photometric_options_reach_the_config() {
        let c = config(&[
            "room.sc",
            "--units",
            "mm",
            "--ies",
            "lamp=a.ies",
            "--ies",
            "x=y=b.ies",
            "--illuminance-at",
            "p.csv",
            "--illuminance-out",
            "e.csv",
            "--workplane",
            "750,250",
            "--falsecolor",
            "f.png",
            "--falsecolor-of",
            "illuminance",
            "--falsecolor-scale",
            "linear",
            "--falsecolor-max",
            "800",
        ]);
        let p = &c.photometry;
        assert_eq!(p.units, Some(crate::scene::Units::Mm));
        assert_eq!(
            p.ies,
            vec![
                ("lamp".to_string(), PathBuf::from("a.ies")),
                ("x=y".to_string(), PathBuf::from("b.ies"))
            ]
        );
        assert_eq!(
            p.illuminance,
            Some((PathBuf::from("p.csv"), PathBuf::from("e.csv")))
        );
        let w = p.workplane.as_ref().unwrap();
        assert_eq!((w.height, w.spacing), (750.0, Some(250.0)));
        // The default prefix is the scene's stem.
        assert_eq!(w.csv, PathBuf::from("room-workplane.csv"));
        assert_eq!(w.png, PathBuf::from("room-workplane.png"));
        let f = p.falsecolor.as_ref().unwrap();
        assert_eq!(f.path, PathBuf::from("f.png"));
        assert_eq!(f.quantity, crate::render::falsecolor::Quantity::Illuminance);
        assert_eq!(f.scale, crate::render::falsecolor::Scale::Linear);
        assert_eq!(f.max, Some(800.0));
        assert!(c.wants_batch_outputs());
        let prefixed = config(&["--workplane", "0.8", "--workplane-out", "out/plan"]);
        let w = prefixed.photometry.workplane.unwrap();
        assert_eq!((w.spacing, w.csv), (None, PathBuf::from("out/plan.csv")));
        // glTF is in metres without --units; .sc has no unit.
        assert_eq!(config(&["m.glb"]).units(), Some(crate::scene::Units::M));
        assert_eq!(config(&["m.sc"]).units(), None);
        for bad in [
            &["--workplane", "-1"][..],
            &["--workplane", "1,0"],
            &["--workplane", "a"],
            &["--ies", "=x.ies"],
            &["--ies", "lamp="],
            &["--units", "furlong"],
            &["--illuminance-at", "p.csv"],
        ] {
            assert!(parse(bad).is_err(), "{bad:?}");
        }
        assert_eq!(
            invocation(&["--falsecolor-max", "0"]),
            Err(UsageError::FalsecolorMax(0.0))
        );
    }
}
