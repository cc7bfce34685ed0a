//! `radiosity`: the command-line front end. Parses arguments, validates
//! them into a [`RunConfig`], runs the pipeline and maps the outcome to an
//! exit code: 0 success, 1 a failure writing results, 2 bad input or usage,
//! 130 interrupted (Ctrl-C).

use clap::Parser;
use radiosity::batch::{self, RunError, RunStats};
use radiosity::config::{self, RunConfig, SceneSource};
use radiosity::mesh::refine::{self, RefineOptions};
use radiosity::mesh::DEFAULT_INSET;
use radiosity::render::Exposure;
use radiosity::solver::{
    FormFactorMethod, ShooterSamples, SolverOptions, UnshotScheme, DEFAULT_SHOOTER_SAMPLES,
    DEFAULT_THRESHOLD,
};
use radiosity::viewer;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Set by the Ctrl-C handler; batch runs poll it.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Progressive-refinement radiosity renderer (ray-traced form factors after
/// Wallace, Elmquist and Haines 1989).
///
/// Reads a .sc or .obj scene, meshes every polygon into elements, shoots light from
/// the polygon with the most unshot power until the unshot power falls
/// below the threshold, and writes a Gouraud-shaded picture.
#[derive(Parser, Debug)]
#[command(name = "radiosity", version, about, long_about = None, after_help = EXIT_CODES)]
struct Args {
    /// Scene file: .sc, or .obj (Wavefront OBJ with its MTL materials).
    /// Without it, the bundled scenes/rtable.sc.
    scene: Option<PathBuf>,

    /// Picture to write: .png or .tif/.tiff (8-bit, tone-mapped), .exr or
    /// .pfm (32-bit float linear radiosity). Default: <scene-name>.png in
    /// the current directory.
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,

    /// Longest element edge, in scene units. Default: 1/80 of the scene's
    /// bounding-box diagonal.
    #[arg(long, value_name = "L")]
    lenmax: Option<f32>,

    /// Boundary vertices are evaluated this fraction of an element edge
    /// inside their polygon, so room corners do not come out dark; 0
    /// disables it.
    #[arg(long, value_name = "F", default_value_t = DEFAULT_INSET)]
    inset: f32,

    /// Stop when the unshot power falls below this fraction of the emitted
    /// power.
    #[arg(long, value_name = "T", default_value_t = DEFAULT_THRESHOLD)]
    threshold: f64,

    /// Stop after this many shooting steps at most.
    #[arg(long, value_name = "N")]
    max_steps: Option<u64>,

    /// Form factor estimate: `wallace` (rays to every shooter sample) or
    /// `center` (one ray from the shooter's centre, point-to-disc form
    /// factor: fast, blocky shadows).
    #[arg(long, value_name = "METHOD", default_value = "wallace", value_parser = ["wallace", "center"])]
    form_factor: String,

    /// Shooter sample points: each shooter shoots from a regular grid of at
    /// most N cells (no more than it has element vertices), one shadow ray
    /// each; `all` uses every element vertex as a point sample (the
    /// original scheme, without the near field; slow on fine meshes).
    /// Unit-square form factors are within 0.06 % of exact at 16 or more;
    /// more points sample penumbrae more finely.
    #[arg(long, value_name = "N|all", default_value_t = DEFAULT_SHOOTER_SAMPLES.to_string())]
    shooter_samples: String,

    /// Use the plain disc approximation a/(πr² + a) for every shooter
    /// sample, however close the receiver (by default: the exact
    /// point-to-cell form factor within 1.5 cell diameters, a quadrature
    /// of the cell to 6).
    #[arg(long)]
    no_near_field: bool,

    /// Test every shadow ray against the whole scene instead of only the
    /// polygons in the shaft between shooter and receiver (slower, same
    /// result; for comparison).
    #[arg(long)]
    no_shaft_culling: bool,

    /// Where unshot radiosity is kept: `vertex` (one value per element
    /// vertex; each shooter sample carries the value interpolated at its
    /// position) or `polygon` (one per polygon, shot as if the polygon were
    /// lit evenly: the original algorithm).
    #[arg(long, value_name = "SCHEME", default_value = "vertex", value_parser = ["vertex", "polygon"])]
    unshot: String,

    /// Adaptive subdivision: once the solve converges, split the elements
    /// whose vertex luminances differ by more than --adaptive-threshold
    /// (relative to the largest), keep the mesh crack-free, and continue
    /// the solve on the refined mesh (new vertices gather the light shot so
    /// far); repeat up to --adaptive-levels times. Sharpens shadow
    /// boundaries where the regular mesh blurs them.
    #[arg(long, conflicts_with_all = ["checkpoint", "resume"])]
    adaptive: bool,

    /// Split an element when its vertex luminances differ by more than this
    /// fraction of the largest of them (with --adaptive).
    #[arg(long, value_name = "T", default_value_t = refine::DEFAULT_THRESHOLD, requires = "adaptive")]
    adaptive_threshold: f64,

    /// Split each initial element at most this many times, each halving
    /// its edges (with --adaptive).
    #[arg(long, value_name = "N", default_value_t = refine::DEFAULT_LEVELS, requires = "adaptive")]
    adaptive_levels: u32,

    /// Draw the element mesh over the written picture (.png or .tiff), as
    /// the window's `m` key does.
    #[arg(long)]
    mesh_lines: bool,

    /// Picture size in pixels, overriding the scene's camera.
    #[arg(long, value_name = "WxH")]
    size: Option<String>,

    /// Exposure multiplier for 8-bit pictures; default: automatic (the
    /// 95th-percentile luminance maps to 0.9).
    #[arg(long, value_name = "X")]
    exposure: Option<f32>,

    /// Write counts and seconds per phase as JSON to this file.
    #[arg(long, value_name = "FILE")]
    stats: Option<PathBuf>,

    /// Take the camera from the `camera` block of this .sc file (for .obj
    /// scenes, which have none; also overrides a .sc scene's camera).
    /// Without it an .obj scene is framed automatically.
    #[arg(long, value_name = "FILE.sc")]
    camera: Option<PathBuf>,

    /// Write the solved element mesh: .glb (glTF 2.0 binary: display
    /// colours as COLOR_0, linear radiosity as _RADIOSITY) or .ply (binary
    /// little-endian: float radiosity and 8-bit colour per vertex). Runs in
    /// batch mode, as -o does.
    #[arg(long, value_name = "FILE")]
    export: Option<PathBuf>,

    /// Write one CSV row per shooting step (step, shooter, unshot fraction,
    /// rays, seconds). Runs in batch mode, as -o does.
    #[arg(long, value_name = "FILE.csv")]
    log: Option<PathBuf>,

    /// Draw the unshot fraction against the step on a log axis as a PNG.
    /// Runs in batch mode, as -o does.
    #[arg(long, value_name = "FILE.png")]
    plot: Option<PathBuf>,

    /// Worker threads for the solver and renderer; default: all cores.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,

    /// Do not open a window even when a display is available: solve and
    /// write the picture, as with -o.
    #[arg(long)]
    no_window: bool,

    /// Show the ambient term (Cohen et al. 1988: the unshot power spread
    /// evenly and reflected) on top of the solution, so early pictures are
    /// not too dark; it fades as the solve converges and never enters the
    /// solution. Default: on in the window, off for files.
    #[arg(long, conflicts_with = "no_ambient")]
    ambient: bool,

    /// Never show the ambient term (see --ambient).
    #[arg(long)]
    no_ambient: bool,

    /// Refuse meshes with more elements than this, before building them;
    /// the message says which --lenmax fits. The default allows meshes of
    /// up to about 3.7 GB (estimated; 2.7 GB measured).
    #[arg(long, value_name = "N", default_value_t = config::DEFAULT_MAX_ELEMENTS)]
    max_elements: u64,

    /// Save the solver state to this file every --checkpoint-every seconds,
    /// on Ctrl-C and at the end, so an interrupted solve can be resumed.
    /// Implies a batch run (no window).
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,

    /// Seconds between checkpoints.
    #[arg(long, value_name = "SECS", default_value_t = config::DEFAULT_CHECKPOINT_EVERY.as_secs_f64())]
    checkpoint_every: f64,

    /// Continue the solve saved in this checkpoint (same scene and mesh and
    /// form-factor options) to the same result as an uninterrupted run.
    /// Implies a batch run (no window).
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,

    /// No progress bar and no summary line.
    #[arg(short, long)]
    quiet: bool,
}

const EXIT_CODES: &str =
    "Exit codes: 0 success, 1 a result could not be written, 2 bad input or usage, \
     130 interrupted (Ctrl-C; nothing is written but the --checkpoint).";

/// Most refinement levels accepted: each can quadruple the elements where
/// it splits, and six halve an element's edges 64 times.
const MAX_ADAPTIVE_LEVELS: u32 = 6;

/// A usage error found while validating arguments.
fn usage(message: String) -> ExitCode {
    eprintln!("error: {message}");
    ExitCode::from(2)
}

fn config(args: &Args) -> Result<RunConfig, String> {
    let form_factor = match args.form_factor.as_str() {
        "center" => FormFactorMethod::Center,
        _ => FormFactorMethod::Wallace,
    };
    let shooter_samples = match args.shooter_samples.as_str() {
        "all" => ShooterSamples::All,
        n => match n.parse::<u32>() {
            Ok(n) if n >= 1 => ShooterSamples::AtMost(n),
            _ => {
                return Err(format!(
                    "--shooter-samples must be `all` or a whole number >= 1, got `{n}`"
                ))
            }
        },
    };
    if !(0.0..=1.0).contains(&args.threshold) {
        return Err(format!(
            "--threshold must be between 0 and 1, got {}",
            args.threshold
        ));
    }
    if let Some(l) = args.lenmax {
        if !(l.is_finite() && l > 0.0) {
            return Err(format!(
                "--lenmax must be a positive number of scene units, got {l}"
            ));
        }
    }
    if !(args.inset.is_finite() && (0.0..0.5).contains(&args.inset)) {
        return Err(format!(
            "--inset must be at least 0 and below 0.5, got {}",
            args.inset
        ));
    }
    let size = match &args.size {
        None => None,
        Some(s) => {
            let parsed = s
                .split_once(['x', 'X'])
                .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
            match parsed {
                Some((w, h)) if w >= 1 && h >= 1 => Some((w, h)),
                _ => {
                    return Err(format!(
                        "--size must look like 640x480 (whole numbers >= 1), got `{s}`"
                    ))
                }
            }
        }
    };
    if args.max_elements == 0 || args.max_elements > radiosity::mesh::MAX_ADDRESSABLE_ELEMENTS {
        return Err(format!(
            "--max-elements must be between 1 and {}, got {}",
            radiosity::mesh::MAX_ADDRESSABLE_ELEMENTS,
            args.max_elements
        ));
    }
    if !(args.checkpoint_every.is_finite() && args.checkpoint_every >= 0.0) {
        return Err(format!(
            "--checkpoint-every must be a number of seconds >= 0, got {}",
            args.checkpoint_every
        ));
    }
    if !(args.adaptive_threshold.is_finite()
        && args.adaptive_threshold > 0.0
        && args.adaptive_threshold < 1.0)
    {
        return Err(format!(
            "--adaptive-threshold must be above 0 and below 1, got {}",
            args.adaptive_threshold
        ));
    }
    if !(1..=MAX_ADAPTIVE_LEVELS).contains(&args.adaptive_levels) {
        return Err(format!(
            "--adaptive-levels must be between 1 and {MAX_ADAPTIVE_LEVELS}, got {}",
            args.adaptive_levels
        ));
    }
    let exposure = match args.exposure {
        None => Exposure::Auto,
        Some(x) if x.is_finite() && x > 0.0 => Exposure::Fixed(x),
        Some(x) => return Err(format!("--exposure must be a positive number, got {x}")),
    };
    Ok(RunConfig {
        scene: args
            .scene
            .clone()
            .map_or(SceneSource::Bundled, SceneSource::File),
        output: args.output.clone(),
        lenmax: args.lenmax,
        inset: args.inset,
        solver: SolverOptions {
            form_factor,
            shooter_samples,
            threshold: args.threshold,
            max_steps: args.max_steps,
            near_field: !args.no_near_field,
            shaft_culling: !args.no_shaft_culling,
            unshot: match args.unshot.as_str() {
                "polygon" => UnshotScheme::Polygon,
                _ => UnshotScheme::Vertex,
            },
        },
        size,
        exposure,
        stats: args.stats.clone(),
        camera: args.camera.clone(),
        export: args.export.clone(),
        log: args.log.clone(),
        plot: args.plot.clone(),
        progress: !args.quiet,
        max_elements: args.max_elements,
        checkpoint: args.checkpoint.clone(),
        checkpoint_every: Duration::from_secs_f64(args.checkpoint_every.min(1e9)),
        resume: args.resume.clone(),
        ambient: match (args.ambient, args.no_ambient) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
        adaptive: args.adaptive.then_some(RefineOptions {
            threshold: args.adaptive_threshold,
            levels: args.adaptive_levels,
            max_elements: args.max_elements,
        }),
        mesh_lines: args.mesh_lines,
    })
}

fn main() -> ExitCode {
    let args = Args::parse();
    let config = match config(&args) {
        Ok(c) => c,
        Err(message) => return usage(message),
    };
    if let Some(threads) = args.threads {
        if threads == 0 {
            return usage("--threads must be at least 1".into());
        }
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
        {
            eprintln!("error: cannot start {threads} threads: {e}");
            return ExitCode::from(1);
        }
    }
    let batch = args.output.is_some()
        || args.no_window
        || config.wants_batch_outputs()
        || config.checkpoint.is_some()
        || config.resume.is_some();
    let result = if batch {
        catch_ctrl_c();
        batch::run(&config, &INTERRUPTED).map(Some)
    } else {
        run_window_or_fallback(&config, args.quiet)
    };
    match result {
        Ok(None) => ExitCode::SUCCESS,
        Ok(Some(stats)) => {
            if !args.quiet {
                eprintln!("{}", batch::summary(&stats));
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            // Load errors already read `FILE:LINE:COL: error: ...`.
            if e.is_self_describing() {
                eprintln!("{e}");
            } else {
                eprintln!("error: {e}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}

/// Without -o: the window when a display is available, else (saying why)
/// the batch run writing `<scene>.png`. `Ok(None)` when the window ran.
fn run_window_or_fallback(config: &RunConfig, quiet: bool) -> Result<Option<RunStats>, RunError> {
    let fallback = |why: &str| {
        if !quiet {
            eprintln!(
                "{why}: writing {} in the current directory instead",
                config.output_path().display()
            );
        }
    };
    if let Err(why) = viewer::display_available() {
        batch::check_outputs(config)?;
        fallback(&why);
        catch_ctrl_c();
        return batch::run(config, &INTERRUPTED).map(Some);
    }
    let prepared = radiosity::prepare::prepare(config)?;
    match viewer::run(&prepared, config) {
        Ok(()) => Ok(None),
        Err(viewer::ViewerError::CannotOpen(why)) => {
            fallback(&why);
            catch_ctrl_c();
            batch::run_prepared(config, &prepared, &INTERRUPTED).map(Some)
        }
        Err(viewer::ViewerError::View(e)) => Err(RunError::View(e)),
        Err(viewer::ViewerError::Render(e)) => Err(RunError::Render(e)),
    }
}

/// Makes Ctrl-C (SIGINT, and SIGTERM) stop a batch run cleanly: the first
/// sets [`INTERRUPTED`], which the run polls during every step and before
/// every write; a second exits at once with 130. Only batch runs install
/// it: the window quits with its own keys, and a Ctrl-C in its terminal
/// ends it the ordinary way.
fn catch_ctrl_c() {
    let installed = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            eprintln!("interrupted again: exiting now");
            std::process::exit(130);
        }
        eprintln!("interrupted: stopping (Ctrl-C again to exit at once)");
    });
    if let Err(e) = installed {
        eprintln!("warning: cannot catch Ctrl-C ({e}); an interrupt will end the run abruptly");
    }
}
