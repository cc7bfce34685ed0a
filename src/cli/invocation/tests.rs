//! Arguments to configuration: defaults, every option reaching the config,
//! the values clap refuses, which runs are batch runs, and the help text.

use super::*;
use crate::config::DEFAULT_MAX_ELEMENTS;
use crate::solver::{FormFactorMethod, ShooterSamples, UnshotScheme};
use clap::CommandFactory;
use std::path::PathBuf;

/// Parses as the program does ([`crate::cli::parse_from`]).
fn parse(args: &[&str]) -> Result<Args, clap::Error> {
    crate::cli::parse_from(std::iter::once("radiosity").chain(args.iter().copied()))
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
    // crate::solver::tuning::DEFAULT_SHOOTER_SAMPLES.
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
        "--checkpoint",
        "c.bin",
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
            approximations: crate::solver::Approximations::DEFAULT.without(&[
                Heuristic::NearField,
                Heuristic::ShaftCulling,
                Heuristic::Clusters,
                Heuristic::ReceiverInterpolation,
                Heuristic::WeakStrata,
                Heuristic::CrowdedCells,
                Heuristic::FacetRays,
                Heuristic::SkyProbes,
                Heuristic::FarShooters,
                Heuristic::SharedReceivers,
                Heuristic::Overshoot,
            ]),
            unshot: UnshotScheme::Vertex,
            hemicube_res: crate::solver::hemicube::HemicubeRes::default(),
            part_budget: None,
            tail: crate::solver::TailOption::Auto,
            tail_particles: crate::solver::tuning::TAIL_PARTICLES_PER_VERTEX,
        }
    );
    assert_eq!(c.size, Some((32, 24)));
    assert_eq!(c.aa, 5);
    assert_eq!(c.exposure, Exposure::Stops(2.0));
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
        config(&["--form-factor", "hemicube", "--hemicube-res", "64"])
            .solver
            .hemicube_res
            .get(),
        64
    );
    for bad in ["0", "7", "100000", "lots"] {
        let e = parse(&["--form-factor", "hemicube", "--hemicube-res", bad]).unwrap_err();
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
            // A negative number is a value, not an option: it reaches
            // the range check and gets its message.
            &["--lenmax", "-1"],
            UsageError::Mesh(MeshError::BadLenmax(-1.0)),
            "--lenmax must be a positive number of scene units, got -1",
        ),
        (
            &["--threshold", "-0.5"],
            UsageError::Threshold(-0.5),
            "--threshold must be between 0 and 1, got -0.5",
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
            &["--checkpoint", "c.bin", "--checkpoint-every", "-1"],
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
            &["--adaptive", "--adaptive-max-splits", "0"],
            UsageError::Refine(refine::OptionsError::MaxSplits(0)),
            "--adaptive-max-splits must be at least 1, got 0",
        ),
        (
            &["--exposure", "40.5"],
            UsageError::Exposure(40.5),
            "--exposure must be a number of stops from -40 to 40 (0 is the automatic exposure, \
             +1 twice as bright), got 40.5",
        ),
        (
            &["--threads", "0"],
            UsageError::Threads(0),
            "--threads must be from 1 to 1024, got 0",
        ),
        (
            // Thousands of threads is a typo, not a request: refused
            // before any is started.
            &["--threads", "10000"],
            UsageError::Threads(10000),
            "--threads must be from 1 to 1024, got 10000",
        ),
    ];
    for (args, error, message) in cases {
        let e = invocation(args).unwrap_err();
        assert_eq!(&e, error, "{args:?}");
        assert!(e.to_string().starts_with(message), "{args:?}: {e}");
    }
    assert!(matches!(
        invocation(&["--exposure", "nan"]),
        Err(UsageError::Exposure(x)) if x.is_nan()
    ));
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
            "--adaptive-max-splits",
            "70",
            "--max-elements",
            "900",
        ])
        .adaptive,
        Some(RefineOptions {
            threshold: 0.1,
            levels: 3,
            max_splits: 70,
            max_elements: 900,
        })
    );
    // Without --adaptive they are refused by clap, not ignored.
    assert!(parse(&["--adaptive-levels", "3"]).is_err());
    assert!(parse(&["--adaptive-max-splits", "3"]).is_err());
    assert!(parse(&["--adaptive", "--checkpoint", "c.bin"]).is_err());
}

/// Without `--adaptive`, a run refines once when the vertex budget
/// coarsened its default mesh, with the default threshold and split
/// limit; `--no-adaptive`, a checkpoint written or resumed, or a mesh the
/// budget left alone refine nothing.
#[test]
fn a_coarsened_default_mesh_is_refined_once_unless_told_not_to() {
    let once = RefineOptions {
        levels: 1,
        max_elements: DEFAULT_MAX_ELEMENTS,
        ..RefineOptions::default()
    };
    assert_eq!(config(&[]).refinement(true), Some(once));
    assert_eq!(config(&[]).refinement(false), None);
    assert_eq!(config(&["--no-adaptive"]).refinement(true), None);
    assert_eq!(config(&["--checkpoint", "c.bin"]).refinement(true), None);
    assert_eq!(config(&["--resume", "c.bin"]).refinement(true), None);
    // --max-elements bounds the pass as it bounds --adaptive's.
    assert_eq!(
        config(&["--max-elements", "900"])
            .refinement(true)
            .map(|r| r.max_elements),
        Some(900)
    );
    // --adaptive's own passes, whatever the budget did.
    let adaptive = config(&["--adaptive", "--adaptive-levels", "3"]);
    assert_eq!(adaptive.refinement(false), adaptive.adaptive);
    assert_eq!(adaptive.refinement(true).map(|r| r.levels), Some(3));
    assert!(parse(&["--adaptive", "--no-adaptive"]).is_err());
}

/// `--exposure` counts stops from the automatic exposure: 0 is the
/// automatic one, negative values darken.
#[test]
fn exposure_is_in_stops() {
    assert_eq!(config(&[]).exposure, Exposure::Auto);
    assert_eq!(config(&["--exposure", "0"]).exposure, Exposure::Stops(0.0));
    assert_eq!(
        config(&["--exposure", "-2"]).exposure,
        Exposure::Stops(-2.0)
    );
    assert_eq!(
        config(&["--exposure", "+1.5"]).exposure,
        Exposure::Stops(1.5)
    );
    assert_eq!(
        config(&["--exposure", "40"]).exposure,
        Exposure::Stops(40.0)
    );
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
    assert_eq!(
        (w.scale, w.max),
        (crate::render::falsecolor::Scale::Log, None)
    );
    // The plan takes the false-colour scale and maximum without
    // --falsecolor too.
    let plan = config(&[
        "--workplane",
        "0.8",
        "--falsecolor-scale",
        "linear",
        "--falsecolor-max",
        "500",
    ]);
    let w = plan.photometry.workplane.unwrap();
    assert_eq!(
        (w.scale, w.max),
        (crate::render::falsecolor::Scale::Linear, Some(500.0))
    );
    assert_eq!(plan.photometry.falsecolor, None);
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
        invocation(&["--falsecolor", "f.png", "--falsecolor-max", "0"]),
        Err(UsageError::FalsecolorMax(0.0))
    );
}

/// Cameras as the window leaves them: rounding noise in every field,
/// negative and tiny and large coordinates, fields of view from degrees.
fn cameras_to_print() -> Vec<Camera> {
    let mut orbited = crate::viewer::controls::CameraControl::new(Camera {
        eye: Vec3::new(2.5, 1.7, 0.35),
        lookat: Vec3::new(2.5, 0.75, 3.0),
        up: Vec3::Y,
        fov_y: 55f32.to_radians(),
        width: 640,
        height: 480,
    });
    orbited.orbit_about(Vec3::new(1.0, 0.5, 2.0), 0.37, -0.11);
    orbited.walk(0.013, 0.0, 0.2);
    vec![
        *orbited.camera(),
        Camera {
            eye: Vec3::new(-0.1 - 0.2, 1e-7, -3.4e11),
            lookat: Vec3::new(1.0 / 3.0, -2.0 / 7.0, 1e11),
            up: Vec3::new(0.01, -1.0, 0.003),
            fov_y: crate::scene::ROOM_FOV_DEG.to_radians(),
            width: 1,
            height: 8192,
        },
        crate::scene::frame_camera(&crate::testutil::cuboid(
            [0.0, 0.0, 0.0],
            [6.0, 2.7, 4.0],
            true,
        )),
    ]
}

#[test]
fn a_printed_camera_block_reads_back_as_the_same_camera() {
    for camera in cameras_to_print() {
        let text = crate::camera::sc_block(&camera);
        let back = crate::scene::parse_camera_str(&text, "printed.sc").expect("the block parses");
        assert_eq!(back, camera, "{text}");
    }
}

#[test]
fn printed_camera_options_read_back_as_the_same_camera() {
    // Whatever the scene's camera was, the options replace all of it.
    let scene_camera = Camera::frame(Vec3::ZERO, Vec3::ONE);
    for camera in cameras_to_print() {
        let text = crate::camera::options_text(&camera);
        let words: Vec<&str> = text.split_whitespace().collect();
        let config = config(&words);
        let (width, height) = config.size.expect("--size is printed");
        let back = config
            .camera_override
            .apply(&scene_camera)
            .expect("a usable camera");
        assert_eq!(
            Camera {
                width,
                height,
                ..back
            },
            camera,
            "{text}"
        );
    }
}

#[test]
fn camera_options_reach_the_config_and_say_what_is_wrong() {
    let c = config(&["--eye", "-1,2,-3.5", "--fov", "30"]);
    assert_eq!(
        c.camera_override,
        crate::camera::CameraOverride {
            eye: Some(Vec3::new(-1.0, 2.0, -3.5)),
            fov_deg: Some(30.0),
            ..Default::default()
        }
    );
    assert!(config(&[]).camera_override.is_empty());
    let same = invocation(&["--eye", "1,2,3", "--look-at", "1,2,3"]).unwrap_err();
    assert_eq!(
        same.to_string(),
        "--eye 1,2,3 and --look-at 1,2,3 are the same point: the camera has no view direction"
    );
    let parallel =
        invocation(&["--eye", "0,0,0", "--look-at", "0,5,0", "--up", "0,-2,0"]).unwrap_err();
    assert!(
        parallel
            .to_string()
            .starts_with("--up 0,-2,0 is parallel to the view direction"),
        "{parallel}"
    );
    // Looking straight down with no --up given is for the scene to judge.
    assert!(invocation(&["--eye", "0,5,0", "--look-at", "0,0,0"]).is_ok());
    for (args, message) in [
        (
            &["--fov", "180"][..],
            "--fov must be a vertical field of view",
        ),
        (&["--eye", "1,2"][..], "--eye must be a point X,Y,Z"),
        (
            &["--look-at", "1,nan,2"][..],
            "--look-at must be a point X,Y,Z",
        ),
        (&["--up", "0,0,0"][..], "--up must be a direction X,Y,Z"),
    ] {
        let e = parse(args).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains(message), "{args:?}: {e}");
    }
}

#[test]
fn info_describes_without_a_window_and_writes_nothing() {
    assert_eq!(invocation(&["--info"]).unwrap().mode, Mode::Info);
    assert_eq!(
        invocation(&["x.obj", "--info", "--emit", "Lamp=3"])
            .unwrap()
            .mode,
        Mode::Info
    );
    for clash in [
        &["-o", "x.png"][..],
        &["--export", "x.glb"],
        &["--no-window"],
    ] {
        let mut args = vec!["--info"];
        args.extend_from_slice(clash);
        assert!(parse(&args).is_err(), "{clash:?}");
    }
}
