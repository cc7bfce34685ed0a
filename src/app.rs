//! The batch driver: load → mesh → solve → render → write, with progress
//! on the terminal and timings for `--stats`; optionally the solved mesh
//! (`--export`), the per-step log (`--log`) and the convergence plot
//! (`--plot`).
//!
//! The command-line front end turns its arguments into a [`RunConfig`] and
//! calls [`run`]; nothing here reads `argv`. A future window drives the
//! same solver and renderer.

use crate::color::Rgb;
use crate::mesh::{self, Mesh, MeshError, MeshOptions};
use crate::output::convergence::{self, StepRecord};
use crate::output::{self, MeshFormat, OutputError, PictureFormat};
use crate::render::{Exposure, Frame, Rasterizer, RenderError, View, ViewError};
use crate::scene::{self, LoadError, Scene};
use crate::solver::{Progressive, SolverOptions, StepReport, StopReason};
use crate::visibility::Visibility;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The bundled default scene, compiled into the binary so it works from
/// any directory.
pub const BUNDLED_SCENE: &str = include_str!("../scenes/rtable.sc");
/// The name the bundled scene goes by in messages and default file names.
pub const BUNDLED_SCENE_NAME: &str = "scenes/rtable.sc";

/// Where the scene comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneSource {
    /// The bundled `rtable.sc`.
    Bundled,
    /// A scene file: `.obj` (Wavefront OBJ with MTL materials) or `.sc`.
    File(PathBuf),
}

impl SceneSource {
    /// The scene's name for messages: the path as given.
    pub fn display_name(&self) -> String {
        match self {
            SceneSource::Bundled => BUNDLED_SCENE_NAME.to_string(),
            SceneSource::File(p) => p.display().to_string(),
        }
    }

    /// The file stem, for default output names (`rtable` for the bundled).
    pub fn stem(&self) -> String {
        let path = match self {
            SceneSource::Bundled => Path::new(BUNDLED_SCENE_NAME),
            SceneSource::File(p) => p.as_path(),
        };
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".to_string())
    }
}

/// Everything one batch run needs, validated by the front end.
#[derive(Clone, Debug, PartialEq)]
pub struct RunConfig {
    /// The scene to solve.
    pub scene: SceneSource,
    /// The picture to write; `None` writes `<scene-stem>.png` in the
    /// current directory.
    pub output: Option<PathBuf>,
    /// Longest element edge in scene units; `None` for the default
    /// ([`MeshOptions::for_scene`]).
    pub lenmax: Option<f32>,
    /// Boundary inset as a fraction of an element edge.
    pub inset: f32,
    /// Solver settings.
    pub solver: SolverOptions,
    /// Picture size override in pixels (width, height).
    pub size: Option<(u32, u32)>,
    /// Exposure for 8-bit pictures.
    pub exposure: Exposure,
    /// Where to write the statistics JSON, if anywhere.
    pub stats: Option<PathBuf>,
    /// A `.sc` file whose `camera` block replaces the scene's camera.
    pub camera: Option<PathBuf>,
    /// Where to write the solved mesh (`.glb` or `.ply`), if anywhere.
    pub export: Option<PathBuf>,
    /// Where to write the per-step CSV log, if anywhere.
    pub log: Option<PathBuf>,
    /// Where to write the convergence plot (`.png`), if anywhere.
    pub plot: Option<PathBuf>,
    /// Show a progress bar (only drawn when stderr is a terminal).
    pub progress: bool,
}

impl RunConfig {
    /// True when the run asks for results only a batch run writes (the
    /// mesh export, the log or the plot), so no window should open.
    pub fn wants_batch_outputs(&self) -> bool {
        self.export.is_some() || self.log.is_some() || self.plot.is_some()
    }

    /// Every file the batch run writes besides the picture.
    fn extra_outputs(&self) -> impl Iterator<Item = &PathBuf> {
        [&self.stats, &self.export, &self.log, &self.plot]
            .into_iter()
            .flatten()
    }
}

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scene file is bad or unreadable.
    #[error("{0}")]
    Load(#[from] LoadError),
    /// The mesh options do not suit the scene.
    #[error("{0}")]
    Mesh(#[from] MeshError),
    /// The camera or picture size is unusable.
    #[error("{0}")]
    View(#[from] ViewError),
    /// An output path is unusable before anything was computed.
    #[error("{0}")]
    BadOutput(OutputError),
    /// Rendering failed (a bug if it happens).
    #[error("{0}")]
    Render(#[from] RenderError),
    /// Writing a result failed.
    #[error("{0}")]
    Write(OutputError),
}

impl RunError {
    /// True when the user's input or options are at fault (exit code 2),
    /// false for failures of the machine (exit code 1).
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, RunError::Render(_) | RunError::Write(_))
    }
}

/// Seconds spent in each phase.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PhaseSeconds {
    /// Reading and validating the scene.
    pub load: f64,
    /// Building the element mesh.
    pub mesh: f64,
    /// Building the visibility BVH.
    pub bvh: f64,
    /// Shooting.
    pub solve: f64,
    /// Rasterising the picture.
    pub render: f64,
    /// Encoding and writing files.
    pub write: f64,
}

/// What a run did, as written by `--stats`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunStats {
    /// The scene as named by the user.
    pub scene: String,
    /// The picture written.
    pub output: String,
    /// Scene polygons.
    pub polygons: usize,
    /// Mesh elements.
    pub elements: usize,
    /// Mesh element vertices.
    pub vertices: usize,
    /// The lenmax used, in scene units.
    pub lenmax: f32,
    /// Shooting steps taken.
    pub steps: u64,
    /// Shadow rays cast.
    pub rays: u64,
    /// Sample–vertex pairs whose visibility mattered; `pairs - rays` rays
    /// were saved by shaft culling.
    pub pairs: u64,
    /// Fraction of shooter–receiver polygon pairs whose shaft was clear,
    /// so that no ray at all was cast between them.
    pub clear_shaft_fraction: f64,
    /// Unshot power left as a fraction of the emitted power.
    pub unshot_fraction: f64,
    /// The exposure the 8-bit picture and the exported display colours
    /// used (dimensionless): the given one, or the automatic one.
    pub exposure: f32,
    /// True when the threshold was reached (false: step limit).
    pub converged: bool,
    /// Seconds per phase.
    pub seconds: PhaseSeconds,
}

/// A scene loaded, meshed and put in a BVH: what both the batch run and
/// the window start from.
pub struct Prepared {
    /// The scene.
    pub scene: Scene,
    /// Its element mesh.
    pub mesh: Mesh,
    /// Its visibility structure.
    pub visibility: Visibility,
    /// The lenmax the mesh was built with, in scene units.
    pub lenmax: f32,
    /// Seconds spent so far (load, mesh, bvh).
    pub seconds: PhaseSeconds,
}

impl Prepared {
    /// The view of the scene's camera, with the configured size override.
    pub fn view(&self, config: &RunConfig) -> Result<View, ViewError> {
        match config.size {
            Some((w, h)) => View::with_size(&self.scene.camera, w, h),
            None => View::new(&self.scene.camera),
        }
    }
}

/// Loads, validates, meshes and builds the BVH.
pub fn prepare(config: &RunConfig) -> Result<Prepared, RunError> {
    let mut seconds = PhaseSeconds::default();
    let t = Instant::now();
    let scene = load_scene_with_camera(&config.scene, config.camera.as_deref())?;
    seconds.load = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let mut mesh_options = MeshOptions::for_scene(&scene);
    mesh_options.inset = config.inset;
    if let Some(lenmax) = config.lenmax {
        mesh_options.lenmax = lenmax;
    }
    let mesh = mesh::build(&scene, &mesh_options)?;
    seconds.mesh = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let visibility = Visibility::new(&scene);
    seconds.bvh = t.elapsed().as_secs_f64();
    Ok(Prepared {
        scene,
        mesh,
        visibility,
        lenmax: mesh_options.lenmax,
        seconds,
    })
}

/// The picture path a batch run writes: `-o`, or `<scene-stem>.png` in
/// the current directory.
pub fn output_path(config: &RunConfig) -> PathBuf {
    config
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.png", config.scene.stem())))
}

/// Refuses unusable outputs before any time is spent solving: an unknown
/// extension, a missing directory, a path that is an input (the scene, its
/// camera file), or two outputs that are the same file.
pub fn check_outputs(config: &RunConfig) -> Result<(), RunError> {
    let output = output_path(config);
    PictureFormat::from_path(&output).map_err(RunError::BadOutput)?;
    if let Some(export) = &config.export {
        MeshFormat::from_path(export).map_err(RunError::BadOutput)?;
    }
    if let Some(plot) = &config.plot {
        convergence::check_plot_path(plot).map_err(RunError::BadOutput)?;
    }
    let outputs: Vec<&PathBuf> = std::iter::once(&output)
        .chain(config.extra_outputs())
        .collect();
    for out in &outputs {
        output::check_destination(out).map_err(RunError::BadOutput)?;
    }
    for (i, a) in outputs.iter().enumerate() {
        if outputs[..i].iter().any(|b| a == b || same_file(a, b)) {
            return Err(RunError::BadOutput(OutputError::Io {
                path: a.to_path_buf(),
                error: std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "two outputs would be written to this same file",
                ),
            }));
        }
    }
    let inputs = match &config.scene {
        SceneSource::File(input) => Some(input),
        SceneSource::Bundled => None,
    };
    for input in inputs.into_iter().chain(config.camera.as_ref()) {
        for out in &outputs {
            if same_file(input, out) {
                return Err(RunError::BadOutput(OutputError::Io {
                    path: out.to_path_buf(),
                    error: std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        "refusing to overwrite an input file",
                    ),
                }));
            }
        }
    }
    Ok(())
}

/// Runs the whole batch pipeline once and writes the picture (and stats).
pub fn run(config: &RunConfig) -> Result<RunStats, RunError> {
    check_outputs(config)?;
    let prepared = prepare(config)?;
    run_prepared(config, &prepared)
}

/// The batch run from a prepared scene: solve, render, write.
pub fn run_prepared(config: &RunConfig, prepared: &Prepared) -> Result<RunStats, RunError> {
    check_outputs(config)?;
    let output = output_path(config);
    let mut seconds = prepared.seconds;
    let view = prepared.view(config)?;

    let t = Instant::now();
    let mut solver = Progressive::new(
        &prepared.scene,
        &prepared.mesh,
        &prepared.visibility,
        config.solver,
    );
    let steps = solve_with_progress(&mut solver, config.progress);
    seconds.solve = t.elapsed().as_secs_f64();
    solver
        .validate()
        .map_err(|e| RunError::Render(RenderError::BadMesh(e)))?;

    let t = Instant::now();
    let frame = render(&prepared.mesh, solver.radiosity(), &view)?;
    seconds.render = t.elapsed().as_secs_f64();

    let t = Instant::now();
    // Resolved once, so the picture and the exported colours agree.
    let exposure = config.exposure.resolve(&frame);
    output::write_picture(&output, &frame, Exposure::Fixed(exposure)).map_err(RunError::Write)?;
    if let Some(path) = &config.export {
        output::write_mesh(path, &prepared.mesh, solver.radiosity(), exposure)
            .map_err(RunError::Write)?;
    }
    let records: Vec<StepRecord> = steps
        .iter()
        .map(|&(report, elapsed)| StepRecord {
            report,
            shooter_line: prepared.scene.polygons[report.shooter.index()].origin.line,
            seconds: elapsed.as_secs_f64(),
        })
        .collect();
    if let Some(path) = &config.log {
        convergence::write_log_file(path, &records).map_err(RunError::Write)?;
    }
    if let Some(path) = &config.plot {
        convergence::write_plot_file(
            path,
            &records,
            config.solver.threshold,
            &config.scene.display_name(),
        )
        .map_err(RunError::Write)?;
    }
    let mut stats = RunStats {
        scene: config.scene.display_name(),
        output: output.display().to_string(),
        polygons: prepared.scene.polygons.len(),
        elements: prepared.mesh.elements.len(),
        vertices: prepared.mesh.vertex_count(),
        lenmax: prepared.lenmax,
        steps: solver.steps(),
        rays: solver.rays(),
        pairs: solver.pairs(),
        clear_shaft_fraction: {
            let (all, clear) = solver.receiver_pairs();
            if all > 0 {
                clear as f64 / all as f64
            } else {
                0.0
            }
        },
        unshot_fraction: solver.unshot_fraction(),
        exposure,
        converged: solver.stop_reason() == Some(StopReason::Converged),
        seconds,
    };
    stats.seconds.write = t.elapsed().as_secs_f64();
    if let Some(path) = &config.stats {
        let json = serde_json::to_string_pretty(&stats).map_err(|e| {
            RunError::Write(OutputError::Io {
                path: path.clone(),
                error: std::io::Error::other(e),
            })
        })?;
        output::write_atomically(path, |w| writeln!(w, "{json}")).map_err(RunError::Write)?;
    }
    Ok(stats)
}

/// Loads the scene from its source.
pub fn load_scene(source: &SceneSource) -> Result<Scene, LoadError> {
    load_scene_with_camera(source, None)
}

/// Loads the scene from its source, with the camera of the `.sc` file
/// `camera` when given (see [`scene::load_with_camera`]).
pub fn load_scene_with_camera(
    source: &SceneSource,
    camera: Option<&Path>,
) -> Result<Scene, LoadError> {
    match source {
        SceneSource::Bundled => {
            let mut scene = scene::parse_str(BUNDLED_SCENE, BUNDLED_SCENE_NAME)?;
            if let Some(camera) = camera {
                scene.camera = scene::load_camera(camera)?;
                scene.camera_source = scene::CameraSource::File;
            }
            Ok(scene)
        }
        SceneSource::File(path) => scene::load_with_camera(path, camera),
    }
}

/// Renders one frame of a solution.
pub fn render(mesh: &Mesh, radiosity: &[Rgb], view: &View) -> Result<Frame, RenderError> {
    let mut rasterizer = Rasterizer::new();
    Ok(rasterizer.render(mesh, radiosity, view)?.clone())
}

/// True when both paths name the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Steps the solver until it stops, drawing a progress bar on stderr when
/// it is a terminal. The bar's position is the fraction of the way, in
/// log scale, from the initial unshot power to the threshold; the ETA
/// extrapolates the recent rate at which the log of the unshot power falls.
///
/// Returns every step's report with the time from the start of this call
/// to the end of that step.
pub fn solve_with_progress(
    solver: &mut Progressive,
    progress: bool,
) -> Vec<(StepReport, Duration)> {
    let target = if progress && std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    const TICKS: u64 = 1000;
    let bar = ProgressBar::with_draw_target(Some(TICKS), target);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let threshold = solver.options().threshold.max(f64::MIN_POSITIVE);
    let total_log = (1.0 / threshold).ln();
    let start = Instant::now();
    let mut rate = RateEstimate::default();
    let mut steps = Vec::new();
    while !solver.is_done() {
        let Some(report) = solver.step() else {
            break;
        };
        let elapsed = start.elapsed();
        steps.push((report, elapsed));
        let fraction = report.unshot_fraction.max(f64::MIN_POSITIVE);
        let done_log = (1.0 / fraction).ln().max(0.0);
        rate.push(elapsed, done_log);
        let eta = rate
            .per_second()
            .filter(|r| *r > 0.0)
            .map(|r| Duration::from_secs_f64(((total_log - done_log) / r).clamp(0.0, 1e7)));
        let rays_per_s = solver.rays() as f64 / elapsed.as_secs_f64().max(1e-9);
        bar.set_position(((done_log / total_log).clamp(0.0, 1.0) * TICKS as f64) as u64);
        bar.set_message(format!(
            "step {} · unshot {:.3}% · {:.2} Mrays/s · ETA {}",
            report.step,
            report.unshot_fraction * 100.0,
            rays_per_s / 1e6,
            eta.map(|d| format!("{:.0}s", d.as_secs_f64()))
                .unwrap_or_else(|| "?".into())
        ));
    }
    bar.finish_and_clear();
    steps
}

/// The rate at which `log(1 / unshot fraction)` grows, over a sliding
/// window of recent steps.
#[derive(Default)]
struct RateEstimate {
    samples: std::collections::VecDeque<(Duration, f64)>,
}

impl RateEstimate {
    /// Steps in the window: enough to smooth the step-to-step jitter of
    /// which polygon shoots, few enough to follow the slowing down.
    const WINDOW: usize = 20;

    fn push(&mut self, t: Duration, progress: f64) {
        self.samples.push_back((t, progress));
        if self.samples.len() > Self::WINDOW {
            self.samples.pop_front();
        }
    }

    fn per_second(&self) -> Option<f64> {
        let (t0, p0) = *self.samples.front()?;
        let (t1, p1) = *self.samples.back()?;
        let dt = (t1 - t0).as_secs_f64();
        (dt > 0.0).then(|| (p1 - p0) / dt)
    }
}

/// A one-line summary of a finished run.
pub fn summary(stats: &RunStats) -> String {
    format!(
        "{}: {} steps, {:.2} s solving, {:.1} M rays, {:.3}% unshot{} → {}",
        stats.scene,
        stats.steps,
        stats.seconds.solve,
        stats.rays as f64 / 1e6,
        stats.unshot_fraction * 100.0,
        if stats.converged { "" } else { " (step limit)" },
        stats.output
    )
}
