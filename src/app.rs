//! The batch driver: load → mesh → solve → render → write, with progress
//! on the terminal and timings for `--stats`; optionally the solved mesh
//! (`--export`), the per-step log (`--log`) and the convergence plot
//! (`--plot`).
//!
//! The command-line front end turns its arguments into a [`RunConfig`] and
//! calls [`run`] (or [`run_cancellable`] with its Ctrl-C flag); nothing
//! here reads `argv` or installs signal handlers. The window drives the
//! same solver and renderer.
//!
//! **Limits.** Before meshing, [`prepare`] computes the exact element and
//! vertex counts ([`mesh::estimate`]) and an estimate of the memory they
//! need ([`memory_estimate`]), and refuses a mesh over
//! [`RunConfig::max_elements`] with the `lenmax` that would fit.
//!
//! **Interruption and checkpoints.** A cancellable run checks its flag
//! during every shooting step, before rendering and before each write; once
//! it is set, nothing more is written except the checkpoint (when asked
//! for), and the run ends with [`RunError::Interrupted`]. With a checkpoint
//! path the solver state is saved every [`RunConfig::checkpoint_every`],
//! on interruption and at the end (see [`checkpoint`]); a resumed run
//! continues to the same bits an uninterrupted one gives.

use crate::color::Rgb;
use crate::mesh::refine::{RefineOptions, RefineReport, Refiner};
use crate::mesh::{self, Mesh, MeshError, MeshOptions, MeshSize};
use crate::output::convergence::{self, StepRecord};
use crate::output::{self, MeshFormat, OutputError, PictureFormat};
use crate::render::{Exposure, Frame, Rasterizer, RenderError, View, ViewError};
use crate::scene::{self, LoadError, Scene};
use crate::solver::checkpoint::{self, CheckpointError};
use crate::solver::{Progressive, SolverOptions, StepReport, StopReason};
use crate::visibility::Visibility;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::borrow::Cow;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Default for [`RunConfig::max_elements`]: [`mesh::MAX_ELEMENTS`], 20
/// million elements. A mesh that large needs about 3.7 GB by
/// [`memory_estimate`]; the bundled scenes at their default `lenmax` have
/// about 15,000.
pub const DEFAULT_MAX_ELEMENTS: u64 = mesh::MAX_ELEMENTS;

/// Bytes held per mesh vertex during a batch run, for
/// [`memory_estimate`]: positions and sample points (24, up to twice that
/// while the arrays grow), the owning polygon (4), the solver's radiosity
/// and step scratch (48), the rasterizer's projected vertex (about 32) and
/// a checkpoint's copy (24). Measured peak memory stays below this estimate:
/// 639 MB for 4.7 million vertices and elements, estimated 863 MB (see
/// `docs/reliability.md`).
pub const BYTES_PER_VERTEX: u64 = 160;

/// Bytes held per mesh element: its corners and owning polygon.
pub const BYTES_PER_ELEMENT: u64 = 24;

/// Default for [`RunConfig::checkpoint_every`]: one minute, so at most a
/// minute of work is lost, and writing even a 20-million-vertex state
/// (about 500 MB) takes a small fraction of the time.
pub const DEFAULT_CHECKPOINT_EVERY: Duration = Duration::from_secs(60);

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
    /// Refuse meshes with more elements than this (see
    /// [`DEFAULT_MAX_ELEMENTS`]); at most [`mesh::MAX_ADDRESSABLE_ELEMENTS`].
    pub max_elements: u64,
    /// Where to save the solver state during the solve, if anywhere.
    pub checkpoint: Option<PathBuf>,
    /// How often to save the checkpoint (wall clock).
    pub checkpoint_every: Duration,
    /// A checkpoint to continue from instead of starting the solve afresh.
    pub resume: Option<PathBuf>,
    /// Add the ambient term ([`Progressive::ambient`]) to the radiosity
    /// shown: `None` for the default, on in the window and off for files.
    pub ambient: Option<bool>,
    /// Refine the mesh where the solution changes sharply and solve again
    /// ([`mesh::refine`]), or `None` to solve on the regular mesh only.
    pub adaptive: Option<RefineOptions>,
    /// Draw the element mesh over the picture (8-bit pictures only).
    pub mesh_lines: bool,
}

impl RunConfig {
    /// The configuration with every option at its default, for `scene`.
    pub fn new(scene: SceneSource) -> RunConfig {
        RunConfig {
            scene,
            output: None,
            lenmax: None,
            inset: mesh::DEFAULT_INSET,
            solver: SolverOptions::default(),
            size: None,
            exposure: Exposure::Auto,
            stats: None,
            progress: false,
            camera: None,
            export: None,
            log: None,
            plot: None,
            max_elements: DEFAULT_MAX_ELEMENTS,
            checkpoint: None,
            checkpoint_every: DEFAULT_CHECKPOINT_EVERY,
            resume: None,
            ambient: None,
            adaptive: None,
            mesh_lines: false,
        }
    }
}

impl RunConfig {
    /// True when the run asks for results only a batch run writes (the
    /// mesh export, the log, the plot or mesh lines on the picture), so no
    /// window should open.
    pub fn wants_batch_outputs(&self) -> bool {
        self.export.is_some() || self.log.is_some() || self.plot.is_some() || self.mesh_lines
    }

    /// Every file the batch run writes besides the picture.
    fn extra_outputs(&self) -> impl Iterator<Item = &PathBuf> {
        [
            &self.stats,
            &self.export,
            &self.log,
            &self.plot,
            &self.checkpoint,
        ]
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
    /// The mesh would have more elements than allowed.
    #[error(
        "lenmax {lenmax} would make {} elements and {} vertices, about {} of memory; \
         --max-elements allows {}: {}",
        size.elements,
        size.vertices,
        fmt_bytes(*bytes),
        max,
        match suggested {
            Some(l) => format!("use --lenmax {l} or larger (or raise --max-elements)"),
            None => "the scene has more polygons than that even unsubdivided".to_string(),
        }
    )]
    MeshTooLarge {
        /// The lenmax asked for, in scene units.
        lenmax: f32,
        /// The mesh it would make.
        size: MeshSize,
        /// Its estimated memory, in bytes ([`memory_estimate`]).
        bytes: u64,
        /// The element limit.
        max: u64,
        /// The smallest lenmax (to three significant digits) that fits, if
        /// any does.
        suggested: Option<f32>,
    },
    /// The checkpoint to resume from is unusable, or saving one failed.
    #[error("{0}")]
    Checkpoint(#[from] CheckpointError),
    /// Ctrl-C (or the caller's flag) stopped the run; no picture or stats
    /// were written.
    #[error(
        "interrupted after {steps} steps; nothing was written{}",
        match checkpoint {
            Some(p) => format!(
                " but the checkpoint {}: resume with --resume {}",
                p.display(),
                p.display()
            ),
            None => String::new(),
        }
    )]
    Interrupted {
        /// Shooting steps completed.
        steps: u64,
        /// The checkpoint saved on the way out, if one was asked for.
        checkpoint: Option<PathBuf>,
    },
    /// The camera or picture size is unusable.
    #[error("{0}")]
    View(#[from] ViewError),
    /// Options that cannot be combined.
    #[error("{0}")]
    Options(String),
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
        !matches!(
            self,
            RunError::Render(_)
                | RunError::Write(_)
                | RunError::Interrupted { .. }
                | RunError::Checkpoint(CheckpointError::Write(_))
        )
    }

    /// The process exit code for this error: 130 interrupted, 2 bad input
    /// or usage, 1 a failure of the machine.
    pub fn exit_code(&self) -> u8 {
        match self {
            RunError::Interrupted { .. } => 130,
            e if e.is_bad_input() => 2,
            _ => 1,
        }
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
    /// With `--adaptive`, one entry per pass, the coarsest first; then
    /// `elements` and `vertices` above are the last mesh's and the steps,
    /// rays and pairs totals over every pass. Empty (and not written)
    /// without.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub adaptive: Vec<PassStats>,
    /// Seconds per phase.
    pub seconds: PhaseSeconds,
}

/// One pass of an adaptive run (see [`RunStats::adaptive`]): a solve on one
/// mesh (continued from the last pass with per-vertex unshot, afresh with
/// per-polygon unshot) and the refinement of its result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassStats {
    /// Mesh elements of this solve.
    pub elements: usize,
    /// Mesh vertices of this solve.
    pub vertices: usize,
    /// Shooting steps it took.
    pub steps: u64,
    /// Shadow rays it cast, the new vertices' gather included.
    pub rays: u64,
    /// Seconds it took, refinement of its result included.
    pub seconds: f64,
    /// Of those, seconds spent refining the mesh after the solve and
    /// gathering the light at the new vertices.
    pub refine_seconds: f64,
    /// Elements its result marked for splitting (0 for the last solve).
    pub split: usize,
    /// Further elements split to keep the mesh conforming.
    pub closure: usize,
}

/// A solve's result, detached from the solver (and its mesh borrow).
#[derive(Clone, Debug)]
pub struct Solved {
    /// Radiosity per vertex of the mesh it was solved on.
    pub radiosity: Vec<Rgb>,
    /// The radiosity to draw: with the ambient term when
    /// [`RunConfig::ambient`] asks for it, else the radiosity.
    pub shown: Vec<Rgb>,
    /// Shooting steps taken.
    pub steps: u64,
    /// Shadow rays cast.
    pub rays: u64,
    /// Sample–vertex pairs whose visibility mattered.
    pub pairs: u64,
    /// Shooter–receiver polygon pairs, and how many had a clear shaft.
    pub receiver_pairs: (u64, u64),
    /// Unshot power left as a fraction of the emitted power.
    pub unshot_fraction: f64,
    /// True when the threshold was reached (false: step limit).
    pub converged: bool,
    /// Every step, with the time from the start of the solve.
    pub steps_taken: Vec<(StepReport, Duration)>,
}

/// The result of [`solve`]: the mesh the solution lives on (the prepared
/// one, or its adaptive refinement) and the solution.
#[derive(Clone, Debug)]
pub struct Solution<'p> {
    /// The mesh of the last solve.
    pub mesh: Cow<'p, Mesh>,
    /// The last solve.
    pub solved: Solved,
    /// One entry per solve with [`RunConfig::adaptive`], else empty.
    pub passes: Vec<PassStats>,
}

/// Solves the prepared scene as `config` says: once on the prepared mesh,
/// or (with [`RunConfig::adaptive`]) adaptively, refining and solving
/// again. Stops promptly with [`RunError::Interrupted`] once `cancel` is
/// set. Checkpoints are refused with adaptive refinement.
pub fn solve<'p>(
    config: &RunConfig,
    prepared: &'p Prepared,
    cancel: &AtomicBool,
) -> Result<Solution<'p>, RunError> {
    match config.adaptive {
        None => Ok(Solution {
            mesh: Cow::Borrowed(&prepared.mesh),
            solved: solve_mesh(config, prepared, &prepared.mesh, cancel)?,
            passes: Vec::new(),
        }),
        Some(options) => {
            if config.checkpoint.is_some() || config.resume.is_some() {
                return Err(RunError::Options(
                    "--adaptive cannot be combined with --checkpoint or --resume: \
                     a checkpoint holds one mesh, and refinement changes it"
                        .into(),
                ));
            }
            let (mesh, solved, passes) = solve_adaptive(config, prepared, &options, cancel)?;
            Ok(Solution {
                mesh: Cow::Owned(mesh),
                solved,
                passes,
            })
        }
    }
}

/// Solves on `mesh` (the prepared mesh or a refinement of it), resuming
/// and saving checkpoints as `config` asks.
fn solve_mesh(
    config: &RunConfig,
    prepared: &Prepared,
    mesh: &Mesh,
    cancel: &AtomicBool,
) -> Result<Solved, RunError> {
    let mut solver = Progressive::new(&prepared.scene, mesh, &prepared.visibility, config.solver);
    let fingerprint = checkpoint::fingerprint(&prepared.scene, mesh, &config.solver);
    if let Some(path) = &config.resume {
        checkpoint::resume(path, fingerprint, &mut solver)?;
    }
    let plan = config.checkpoint.as_deref().map(|path| CheckpointPlan {
        path,
        every: config.checkpoint_every,
        fingerprint,
    });
    let steps_taken = solve_cancellable(&mut solver, config.progress, cancel, plan.as_ref())?;
    solved_from(&solver, config, steps_taken)
}

/// The result of a finished solve (checked), detached from the solver.
fn solved_from(
    solver: &Progressive,
    config: &RunConfig,
    steps_taken: Vec<(StepReport, Duration)>,
) -> Result<Solved, RunError> {
    solver
        .validate()
        .map_err(|e| RunError::Render(RenderError::BadMesh(e)))?;
    // The ambient term only when asked for: a file shows the solution.
    let shown = if config.ambient == Some(true) {
        let mut shown = Vec::new();
        solver.radiosity_with_ambient(&mut shown);
        shown
    } else {
        solver.radiosity().to_vec()
    };
    Ok(Solved {
        radiosity: solver.radiosity().to_vec(),
        shown,
        steps: solver.steps(),
        rays: solver.rays(),
        pairs: solver.pairs(),
        receiver_pairs: solver.receiver_pairs(),
        unshot_fraction: solver.unshot_fraction(),
        converged: solver.stop_reason() == Some(StopReason::Converged),
        steps_taken,
    })
}

/// Solves, refines where the solution's luminance changes sharply, and
/// goes on on the refined mesh, until nothing needs splitting or
/// `options.levels` refinements are done.
///
/// With per-vertex unshot radiosity the solve continues on the refined
/// mesh ([`Progressive::refined_state`]): the vertices both meshes share
/// keep their values, the new ones gather the light every polygon has shot
/// so far, and shooting goes on from there. With per-polygon unshot each
/// refined mesh is solved afresh. The counts of the returned solve are
/// totals over every pass.
fn solve_adaptive(
    config: &RunConfig,
    prepared: &Prepared,
    options: &RefineOptions,
    cancel: &AtomicBool,
) -> Result<(Mesh, Solved, Vec<PassStats>), RunError> {
    let mut refiner = Refiner::new(&prepared.mesh);
    let options = &RefineOptions {
        max_elements: options.max_elements.min(config.max_elements),
        ..*options
    };
    let mut mesh = prepared.mesh.clone();
    let mut passes: Vec<PassStats> = Vec::new();
    let mut start: Option<checkpoint::SolverState> = None;
    let (mut steps_taken, mut pairs, mut receiver_pairs) = (Vec::new(), 0, (0, 0));
    loop {
        let t = Instant::now();
        let mut solver =
            Progressive::new(&prepared.scene, &mesh, &prepared.visibility, config.solver);
        match start.take() {
            Some(state) => solver
                .restore(state)
                .map_err(|e| RunError::Render(RenderError::BadMesh(e)))?,
            // A fresh solve numbers its steps from 1 again: the log and
            // plot show only the last one.
            None => steps_taken.clear(),
        }
        let (steps_at_start, rays_at_start) = (solver.steps(), solver.rays());
        let offset = steps_taken
            .last()
            .map_or(Duration::ZERO, |s: &(StepReport, Duration)| s.1);
        let taken = solve_cancellable(&mut solver, config.progress, cancel, None)?;
        steps_taken.extend(taken.into_iter().map(|(r, d)| (r, d + offset)));
        pairs += solver.pairs();
        receiver_pairs.0 += solver.receiver_pairs().0;
        receiver_pairs.1 += solver.receiver_pairs().1;
        let mut pass = PassStats {
            elements: mesh.elements.len(),
            vertices: mesh.vertex_count(),
            steps: solver.steps() - steps_at_start,
            rays: solver.rays() - rays_at_start,
            seconds: 0.0,
            refine_seconds: 0.0,
            split: 0,
            closure: 0,
        };
        let refining = Instant::now();
        let next = refine_solved(&solver, &mut refiner, &prepared.scene, options);
        if let Some(Refinement {
            start: Some(state), ..
        }) = &next
        {
            // The gather for the new vertices is this pass's work too.
            pass.rays += state.rays - solver.rays();
        }
        pass.refine_seconds = refining.elapsed().as_secs_f64();
        pass.seconds = t.elapsed().as_secs_f64();
        if config.progress {
            eprintln!(
                "adaptive pass {}: {} elements, {} steps, {:.2} s{}",
                passes.len() + 1,
                pass.elements,
                pass.steps,
                pass.seconds,
                match &next {
                    Some(Refinement { report: r, .. }) => format!(
                        "; splitting {} elements (+{} to stay conforming)",
                        r.marked, r.closure
                    ),
                    None => "; final".to_string(),
                }
            );
        }
        match next {
            Some(refinement) => {
                pass.split = refinement.report.marked;
                pass.closure = refinement.report.closure;
                passes.push(pass);
                start = refinement.start;
                mesh = refinement.mesh;
            }
            None => {
                passes.push(pass);
                let mut solved = solved_from(&solver, config, std::mem::take(&mut steps_taken))?;
                solved.steps = passes.iter().map(|p| p.steps).sum();
                solved.rays = passes.iter().map(|p| p.rays).sum();
                solved.pairs = pairs;
                solved.receiver_pairs = receiver_pairs;
                drop(solver);
                return Ok((mesh, solved, passes));
            }
        }
    }
}

/// The next mesh of an adaptive run, and where its solve starts.
pub struct Refinement {
    /// The refined mesh.
    pub mesh: Mesh,
    /// What the refinement split.
    pub report: RefineReport,
    /// The state that continues the solve on [`Refinement::mesh`]
    /// ([`Progressive::refined_state`]); `None` to solve it afresh
    /// (per-polygon unshot).
    pub start: Option<checkpoint::SolverState>,
}

/// After a solve on `refiner`'s last mesh: the next refinement, or `None`
/// when there is none to make. A solve cut short (by a step limit) is not
/// refined, since it would mark what is merely unfinished; nor one after
/// `options.levels` passes, nor one whose refinement would pass
/// `options.max_elements` (said on stderr as a warning).
pub fn refine_solved(
    solver: &Progressive,
    refiner: &mut Refiner,
    scene: &Scene,
    options: &RefineOptions,
) -> Option<Refinement> {
    if solver.stop_reason() != Some(StopReason::Converged) || refiner.passes() >= options.levels {
        return None;
    }
    let luminance: Vec<f64> = solver.radiosity().iter().map(|b| b.luminance()).collect();
    let Some((mesh, report)) = refiner.refine(scene, &luminance, options) else {
        if let Some(refused) = refiner.refused() {
            eprintln!("warning: {refused}");
        }
        return None;
    };
    let start = solver.refined_state(&mesh, refiner);
    Some(Refinement {
        mesh,
        report,
        start,
    })
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
    check_mesh_size(&scene, &mesh_options, config.max_elements)?;
    let mesh = mesh::build_with_limit(&scene, &mesh_options, config.max_elements)?;
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

/// Estimated peak memory of a batch run with a mesh of this size, in bytes:
/// [`BYTES_PER_VERTEX`] per vertex and [`BYTES_PER_ELEMENT`] per element.
pub fn memory_estimate(size: MeshSize) -> u64 {
    size.vertices
        .saturating_mul(BYTES_PER_VERTEX)
        .saturating_add(size.elements.saturating_mul(BYTES_PER_ELEMENT))
}

/// Refuses, before anything is allocated, a mesh with more than
/// `max_elements` elements, saying how much memory it would take and which
/// lenmax would fit.
pub fn check_mesh_size(
    scene: &Scene,
    options: &MeshOptions,
    max_elements: u64,
) -> Result<MeshSize, RunError> {
    let max = max_elements.min(mesh::MAX_ADDRESSABLE_ELEMENTS);
    let size = mesh::estimate(scene, options)?;
    if size.elements <= max {
        return Ok(size);
    }
    Err(RunError::MeshTooLarge {
        lenmax: options.lenmax,
        size,
        bytes: memory_estimate(size),
        max,
        suggested: lenmax_to_fit(scene, options, max),
    })
}

/// The smallest lenmax, rounded up to three significant digits, whose mesh
/// has at most `max_elements` elements; `None` when even one element per
/// polygon is too many.
pub fn lenmax_to_fit(scene: &Scene, options: &MeshOptions, max_elements: u64) -> Option<f32> {
    let fits = |lenmax: f32| {
        let o = MeshOptions { lenmax, ..*options };
        mesh::estimate(scene, &o).is_ok_and(|s| s.elements <= max_elements)
    };
    // Longer than every polygon: one element per triangle or quad, a fan
    // per larger polygon.
    let mut hi = (scene.extent() * 2.0)
        .max(options.lenmax)
        .max(f32::MIN_POSITIVE);
    if !fits(hi) {
        return None;
    }
    let mut lo = options.lenmax;
    // Bisection in log scale; the count only falls as lenmax grows.
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if !(mid > lo && mid < hi) {
            break;
        }
        if fits(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    // Round up to three significant digits for the message, keeping a
    // value that still fits.
    let digits = 10f64.powf((hi as f64).log10().floor() - 2.0);
    let rounded = ((hi as f64 / digits).ceil() * digits) as f32;
    Some(if fits(rounded) { rounded } else { hi })
}

/// `bytes` as `1.5 GB`, `320 MB`, `12 kB`.
fn fmt_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.0} MB", b / 1e6)
    } else {
        format!("{:.0} kB", (b / 1e3).ceil())
    }
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
/// camera file, hard or symbolic links to them), two outputs that are the
/// same file, or a checkpoint to resume from that cannot be read.
pub fn check_outputs(config: &RunConfig) -> Result<(), RunError> {
    let output = output_path(config);
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

/// Runs the whole batch pipeline once and writes the picture (and stats).
pub fn run(config: &RunConfig) -> Result<RunStats, RunError> {
    run_cancellable(config, &AtomicBool::new(false))
}

/// [`run`] that stops promptly once `cancel` is set (by a Ctrl-C handler,
/// say) with [`RunError::Interrupted`], writing nothing but the
/// checkpoint.
pub fn run_cancellable(config: &RunConfig, cancel: &AtomicBool) -> Result<RunStats, RunError> {
    check_outputs(config)?;
    let prepared = prepare(config)?;
    run_prepared_cancellable(config, &prepared, cancel)
}

/// The batch run from a prepared scene: solve, render, write.
pub fn run_prepared(config: &RunConfig, prepared: &Prepared) -> Result<RunStats, RunError> {
    run_prepared_cancellable(config, prepared, &AtomicBool::new(false))
}

/// [`run_prepared`] that stops promptly once `cancel` is set.
pub fn run_prepared_cancellable(
    config: &RunConfig,
    prepared: &Prepared,
    cancel: &AtomicBool,
) -> Result<RunStats, RunError> {
    check_outputs(config)?;
    let output = output_path(config);
    let mut seconds = prepared.seconds;
    let view = prepared.view(config)?;

    let t = Instant::now();
    let Solution {
        mesh,
        solved,
        passes,
    } = solve(config, prepared, cancel)?;
    seconds.solve = t.elapsed().as_secs_f64();
    let mesh: &Mesh = &mesh;

    let interrupted = || RunError::Interrupted {
        steps: solved.steps,
        checkpoint: config.checkpoint.clone(),
    };
    if cancel.load(Ordering::SeqCst) {
        return Err(interrupted());
    }
    let t = Instant::now();
    let mut rasterizer = Rasterizer::new();
    let frame = rasterizer.render(mesh, &solved.shown, &view)?;
    seconds.render = t.elapsed().as_secs_f64();

    if cancel.load(Ordering::SeqCst) {
        return Err(interrupted());
    }
    let t = Instant::now();
    // Resolved once, so the picture and the exported colours agree.
    let exposure = config.exposure.resolve(frame);
    if config.mesh_lines {
        let mut picture = crate::render::to_srgb8(frame, exposure);
        crate::render::draw_mesh_edges(
            &mut picture,
            mesh,
            &view,
            rasterizer.inv_depth(),
            crate::render::MESH_COLOR,
        );
        output::write_rgb8(&output, &picture).map_err(RunError::Write)?;
    } else {
        output::write_picture(&output, frame, Exposure::Fixed(exposure))
            .map_err(RunError::Write)?;
    }
    if let Some(path) = &config.export {
        output::write_mesh(path, mesh, &solved.radiosity, exposure).map_err(RunError::Write)?;
    }
    let records: Vec<StepRecord> = solved
        .steps_taken
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
        elements: mesh.elements.len(),
        vertices: mesh.vertex_count(),
        lenmax: prepared.lenmax,
        steps: solved.steps,
        rays: solved.rays,
        pairs: solved.pairs,
        clear_shaft_fraction: {
            let (all, clear) = solved.receiver_pairs;
            if all > 0 {
                clear as f64 / all as f64
            } else {
                0.0
            }
        },
        unshot_fraction: solved.unshot_fraction,
        exposure,
        converged: solved.converged,
        adaptive: passes,
        seconds,
    };
    stats.seconds.write = t.elapsed().as_secs_f64();
    if let Some(path) = &config.stats {
        // The picture is complete and stays; the stats are skipped if the
        // interrupt came while it was written.
        if cancel.load(Ordering::SeqCst) {
            return Err(interrupted());
        }
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
    let scene = match source {
        SceneSource::Bundled => scene::parse_str(BUNDLED_SCENE, BUNDLED_SCENE_NAME)?,
        SceneSource::File(path) => scene::load(path)?,
    };
    scene.with_camera_from(camera)
}

/// Renders one frame of a solution.
pub fn render(mesh: &Mesh, radiosity: &[Rgb], view: &View) -> Result<Frame, RenderError> {
    let mut rasterizer = Rasterizer::new();
    Ok(rasterizer.render(mesh, radiosity, view)?.clone())
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

/// When and where [`solve_cancellable`] saves the solver state.
#[derive(Clone, Copy, Debug)]
pub struct CheckpointPlan<'p> {
    /// The checkpoint file, replaced atomically at each save.
    pub path: &'p Path,
    /// Wall-clock time between saves.
    pub every: Duration,
    /// The solve's [`checkpoint::fingerprint`].
    pub fingerprint: u64,
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
    // Nothing can fail without a checkpoint or a cancel flag.
    solve_cancellable(solver, progress, &AtomicBool::new(false), None).unwrap_or_default()
}

/// [`solve_with_progress`] that stops promptly once `cancel` is set, and
/// saves checkpoints per `plan`: every `plan.every`, on interruption and
/// when the solve stops. An interruption leaves the solver as it was after
/// its last complete step and returns [`RunError::Interrupted`].
pub fn solve_cancellable(
    solver: &mut Progressive,
    progress: bool,
    cancel: &AtomicBool,
    plan: Option<&CheckpointPlan>,
) -> Result<Vec<(StepReport, Duration)>, RunError> {
    let save = |solver: &Progressive| -> Result<(), RunError> {
        if let Some(plan) = plan {
            checkpoint::save(plan.path, plan.fingerprint, solver)
                .map_err(|e| RunError::Checkpoint(e.into()))?;
        }
        Ok(())
    };
    let interrupted = |solver: &Progressive| -> RunError {
        match save(solver) {
            Ok(()) => RunError::Interrupted {
                steps: solver.steps(),
                checkpoint: plan.map(|p| p.path.to_path_buf()),
            },
            Err(e) => e,
        }
    };
    let mut last_save = Instant::now();
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
        if cancel.load(Ordering::SeqCst) {
            bar.finish_and_clear();
            return Err(interrupted(solver));
        }
        let Some(report) = solver.step_cancellable(cancel) else {
            if cancel.load(Ordering::SeqCst) {
                bar.finish_and_clear();
                return Err(interrupted(solver));
            }
            break;
        };
        if let Some(plan) = plan {
            if last_save.elapsed() >= plan.every {
                save(solver)?;
                last_save = Instant::now();
            }
        }
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
    save(solver)?;
    Ok(steps)
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
    let steps = match (stats.adaptive.first(), stats.adaptive.len()) {
        (Some(first), solves) if solves > 1 => format!(
            "{solves} passes refining {} to {} vertices, {} steps in all",
            first.vertices, stats.vertices, stats.steps
        ),
        _ => format!("{} steps", stats.steps),
    };
    format!(
        "{}: {steps}, {:.2} s solving, {:.1} M rays, {:.3}% unshot{} → {}",
        stats.scene,
        stats.seconds.solve,
        stats.rays as f64 / 1e6,
        stats.unshot_fraction * 100.0,
        if stats.converged { "" } else { " (step limit)" },
        stats.output
    )
}
