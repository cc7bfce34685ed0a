//! The batch driver: prepare → solve → render → write, with progress on
//! the terminal and timings for `--stats`; optionally the solved mesh
//! (`--export`), the per-step log (`--log`) and the convergence plot
//! (`--plot`).
//!
//! The command line turns its arguments into a [`RunConfig`] and calls
//! [`run`] with its Ctrl-C flag; nothing here reads `argv` or installs
//! signal handlers. The solve itself is a [`Session`] loop, the same one
//! the window's worker thread runs.
//!
//! **Limits.** Before meshing, [`prepare`](crate::prepare::prepare)
//! computes the exact element and vertex counts and an estimate of the
//! memory they need, and refuses a mesh over [`RunConfig::max_elements`]
//! with the `lenmax` that would fit ([`crate::mesh::check_size`]).
//!
//! **Interruption and checkpoints.** A run checks its [`Cancel`] token in
//! every phase: loading, splitting and meshing
//! ([`prepare_cancellable`](crate::prepare::prepare_cancellable)), every
//! shooting step, the photometric gathers, rendering and every buffer of
//! every file written ([`output::cancelling_writes`]). Once it is set,
//! nothing more is written except the checkpoint (when asked for), and
//! the run ends with [`RunError::Interrupted`], which names the files
//! already written and those that were not. With a checkpoint path
//! the solver state is saved every [`RunConfig::checkpoint_every`], on
//! interruption and at the end ([`checkpoint`]); a resumed run continues
//! to the same bits an uninterrupted one gives.
//!
//! **Failures.** A solve that stops on a solver error (a bug) still
//! writes its step log, plot and checkpoint up to the last good step, and
//! says which step, shooter and phase failed ([`failure`]).

pub mod checkpoint;
pub mod daylight;
pub mod failure;
pub mod outputs;
pub mod photometry;
pub mod progress;
pub mod sky_watch;

pub use checkpoint::CheckpointError;
pub use outputs::{check_outputs, check_outputs_against};

use crate::cancel::{Cancel, Cancelled};
use crate::config::{RunConfig, SceneSource};
use crate::mesh::MeshRef;
use crate::output::convergence::{self, StepRecord};
use crate::output::{self, OutputError};
use crate::prepare::{self, PhaseSeconds, PrepareError, Prepared};
use crate::render::{self, antialias, Exposure, Frame, Rasterizer, RenderError, View, ViewError};
use crate::scene::MeasurementPoint;
use crate::session::{Event, PassStats, Session, SessionOptions};
use crate::solver::checkpoint::fingerprint;
use crate::solver::SolverError;
use progress::Progress;
use serde::Serialize;
use sky_watch::SkyWatch;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scene could not be loaded or meshed as asked.
    #[error("{0}")]
    Prepare(#[from] PrepareError),
    /// The checkpoint to resume from is unusable, or saving one failed.
    #[error("{0}")]
    Checkpoint(#[from] CheckpointError),
    /// Ctrl-C (or the caller's token) stopped the run; the message names
    /// the files written before it and those not written.
    #[error("{}", interrupted_message(*steps, written, not_written, checkpoint.as_deref()))]
    Interrupted {
        /// Shooting steps completed.
        steps: u64,
        /// The results complete in place before the interruption, in the
        /// order they were written (the checkpoint not among them).
        written: Vec<PathBuf>,
        /// The results asked for that were not written (an existing file
        /// of that name is as it was).
        not_written: Vec<PathBuf>,
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
    /// The solver's state broke an invariant (a bug if it happens).
    #[error("{0}")]
    Solver(#[from] SolverError),
    /// The solve stopped on a solver error (a bug if it happens), having
    /// written its evidence up to the last good step.
    #[error("{0}")]
    Failed(Box<failure::Failure>),
    /// Rendering failed (a bug if it happens).
    #[error("{0}")]
    Render(#[from] RenderError),
    /// Writing a result failed.
    #[error("{0}")]
    Write(OutputError),
    /// The `--illuminance-at` points file is bad or unreadable; the
    /// message reads `FILE:LINE:COL: error: ...`.
    #[error("{0}")]
    Points(#[from] crate::scene::PointsError),
}

/// The message of [`RunError::Interrupted`]: `interrupted after N steps;
/// wrote a.png, a.json; not written: a.glb`, or `nothing was written`
/// when nothing was, then the checkpoint to resume from.
fn interrupted_message(
    steps: u64,
    written: &[PathBuf],
    not_written: &[PathBuf],
    checkpoint: Option<&Path>,
) -> String {
    let list = |paths: &[PathBuf]| {
        paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut message = format!("interrupted after {steps} steps; ");
    if written.is_empty() {
        message.push_str("nothing was written");
    } else {
        message.push_str(&format!("wrote {}", list(written)));
        if !not_written.is_empty() {
            message.push_str(&format!("; not written: {}", list(not_written)));
        }
    }
    if let Some(p) = checkpoint {
        let saved = if written.is_empty() {
            " but the checkpoint"
        } else {
            "; saved the checkpoint"
        };
        message.push_str(&format!(
            "{saved} {}: resume with --resume {}",
            p.display(),
            p.display()
        ));
    }
    message
}

/// The results of a run written so far, for [`RunError::Interrupted`].
#[derive(Debug, Default)]
struct Written {
    paths: Vec<PathBuf>,
}

impl Written {
    /// Records `path` as complete and in place.
    fn push(&mut self, path: &Path) {
        self.paths.push(path.to_path_buf());
    }

    /// The interruption after `steps` steps: what was written, and what
    /// `config` asked for that was not; the checkpoint is named if one was
    /// asked for and the solve began (it saves one on its way out).
    fn interrupted(self, config: &RunConfig, steps: u64, solved: bool) -> RunError {
        let not_written = std::iter::once(config.output_path())
            .chain(config.extra_outputs().cloned())
            .filter(|p| !self.paths.contains(p) && Some(p) != config.checkpoint.as_ref())
            .collect();
        RunError::Interrupted {
            steps,
            written: self.paths,
            not_written,
            checkpoint: config.checkpoint.clone().filter(|_| solved),
        }
    }
}

impl RunError {
    /// True when the user's input or options are at fault (exit code 2),
    /// false for failures of the machine (exit code 1).
    pub fn is_bad_input(&self) -> bool {
        !matches!(
            self,
            RunError::Render(_)
                | RunError::Solver(_)
                | RunError::Failed(_)
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

    /// True when the message already carries its own file and kind
    /// (`FILE:LINE:COL: error: ...`, `FILE: error: cannot read: ...`, or
    /// the interruption notice), so it is printed without an `error: `
    /// prefix.
    pub fn is_self_describing(&self) -> bool {
        matches!(
            self,
            RunError::Prepare(PrepareError::Load(_))
                | RunError::Prepare(PrepareError::Ies(_))
                | RunError::Points(_)
                | RunError::Checkpoint(CheckpointError::Read { .. })
                | RunError::Interrupted { .. }
        )
    }
}

/// What a run did, as written by `--stats`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunStats {
    /// The scene as named by the user.
    pub scene: String,
    /// The picture written.
    pub output: String,
    /// Every file written besides the picture (stats, export, log, plot,
    /// checkpoint), in that order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub also_written: Vec<String>,
    /// The warnings said on loading, as printed (`FILE:LINE:COL: warning:
    /// ...`), then the one about a sky that lights nothing
    /// ([`sky_watch::SKY_BLOCKED`]) and the one about a (nearly) black
    /// picture ([`render::PictureCoverage::dark_warning`]) if they were
    /// said; empty (and not written) when there were none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Scene polygons (after splitting along intersections; the sky's
    /// facets not counted).
    pub polygons: usize,
    /// Polygons cut along the lines where others pass through them, and
    /// the pieces they became
    /// ([`Scene::split_intersections`](crate::scene::Scene::split_intersections));
    /// written only when something was cut.
    #[serde(skip_serializing_if = "crate::scene::SplitStats::is_empty")]
    pub split: crate::scene::SplitStats,
    /// Mesh elements (the sky's not counted).
    pub elements: usize,
    /// Mesh element vertices (the sky's not counted).
    pub vertices: usize,
    /// The `--sky` radiosity `[r, g, b]` in the scene's units, when the
    /// scene was lit by a sky (not written otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sky: Option<[f64; 3]>,
    /// The standard sky (`--sky cie-...`): its name, horizontal
    /// illuminance and zenith luminance (not written otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub daylight_sky: Option<daylight::SkyStats>,
    /// The sun that lit the scene (`--sun`): where it was and how bright
    /// (not written otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sun: Option<daylight::SunStats>,
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
    /// Particles the last solve's tail traced (`--tail`), 0 when it
    /// shot to the end.
    pub particles: u64,
    /// The exposure the 8-bit picture and the exported display colours
    /// used (dimensionless): `auto_exposure × 2^exposure_stops`.
    pub exposure: f32,
    /// The picture's automatic exposure (dimensionless): the factor that
    /// maps its 95th-percentile luminance to 0.9 ([`render::auto_exposure`]).
    pub auto_exposure: f32,
    /// The stops `--exposure` gave from the automatic exposure (0 without).
    pub exposure_stops: f32,
    /// True when the threshold was reached and every point settled
    /// ([`crate::solver::SolverOptions::settle`]); false at the step limit, and
    /// false when nothing emits (`nothing_emits`): then nothing was
    /// solved, and a picture that is black is no converged solution.
    pub converged: bool,
    /// True when no polygon emits light (see
    /// [`Scene::emits`](crate::scene::Scene::emits)), after `--emit`: the
    /// picture is black and the load warnings say so. Written only when
    /// true.
    #[serde(skip_serializing_if = "is_false")]
    pub nothing_emits: bool,
    /// With `--adaptive`, one entry per pass, the coarsest first; then
    /// `elements` and `vertices` above are the last mesh's and the steps,
    /// rays and pairs totals over every pass. Empty (and not written)
    /// without.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub adaptive: Vec<PassStats>,
    /// Seconds per phase.
    pub seconds: PhaseSeconds,
}

/// Runs the whole batch pipeline once and writes the picture and the other
/// results asked for. Stops promptly in any phase once `cancel` is set (by
/// a Ctrl-C handler, say) with [`RunError::Interrupted`], writing nothing
/// more but the checkpoint.
pub fn run(config: &RunConfig, cancel: &Cancel) -> Result<RunStats, RunError> {
    let prepared = prepare(config, cancel)?;
    run_prepared(config, &prepared, cancel)
}

/// The first half of [`run`]: checks the outputs, then loads, splits and
/// meshes the scene ([`prepare::prepare_cancellable`]), stopping with
/// [`RunError::Interrupted`] once `cancel` is set. [`run_prepared`] is
/// the second.
pub fn prepare(config: &RunConfig, cancel: &Cancel) -> Result<Prepared, RunError> {
    check_outputs(config)?;
    remove_stale_temporaries(config);
    match prepare::prepare_cancellable(config, cancel) {
        Err(PrepareError::Interrupted(_)) => Err(Written::default().interrupted(config, 0, false)),
        prepared => Ok(prepared?),
    }
}

/// Removes the temporaries a killed run left in the folders `config`
/// writes to ([`output::remove_stale_temporaries`]), saying so in one line.
fn remove_stale_temporaries(config: &RunConfig) {
    let mut dirs: Vec<PathBuf> = std::iter::once(config.output_path())
        .chain(config.extra_outputs().cloned())
        .map(|p| match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        })
        .collect();
    dirs.sort();
    dirs.dedup();
    for dir in dirs {
        let removed = output::remove_stale_temporaries(&dir);
        if removed.is_empty() {
            continue;
        }
        let bytes: u64 = removed.iter().map(|t| t.bytes).sum();
        eprintln!(
            "note: removed {} temporary file{} ({:.1} MB) that a killed run left in {}",
            removed.len(),
            if removed.len() == 1 { "" } else { "s" },
            bytes as f64 / 1e6,
            dir.display()
        );
    }
}

/// The solved state a batch run draws and writes.
struct Solved<'p> {
    mesh: MeshRef<'p>,
    radiosity: Vec<crate::color::Rgb>,
    shown: Vec<crate::color::Rgb>,
    records: Vec<StepRecord>,
    /// The warnings the solve said ([`sky_watch::SKY_BLOCKED`]), as
    /// printed.
    warnings: Vec<String>,
}

/// [`run`] from a prepared scene: solve, render, write.
pub fn run_prepared(
    config: &RunConfig,
    prepared: &Prepared,
    cancel: &Cancel,
) -> Result<RunStats, RunError> {
    check_outputs(config)?;
    remove_stale_temporaries(config);
    // The files loading read (libraries, textures, buffers) are known now.
    outputs::check_outputs_against(config, &prepared.inputs)?;
    if config.adaptive.is_some() && (config.checkpoint.is_some() || config.resume.is_some()) {
        return Err(RunError::Options(
            "--adaptive cannot be combined with --checkpoint or --resume: \
             a checkpoint holds one mesh, and refinement changes it"
                .into(),
        ));
    }
    let output = config.output_path();
    // Built here if a window that could not open left it to be built.
    prepared.visibility();
    let mut seconds = prepared.phase_seconds();
    let view = prepared.view(config)?;
    // Bad points or a work plane outside the scene are said before solving.
    // The points are read once, here: a file given as a pipe has no
    // second reading.
    let points = photometry::check(config, prepared)?;
    if let (true, Some(d)) = (config.wants_lightmap(), config.lightmap_density) {
        output::lightmap::uv::check_scene_density(&prepared.scene, d)
            .map_err(|why| RunError::Options(format!("cannot bake the lightmap: {why}")))?;
    }

    let t = Instant::now();
    // A file shows the solution; the ambient term only when asked for.
    let mut session =
        Session::from_prepared(prepared, SessionOptions::for_run(config, prepared, false));
    let solved = solve(config, prepared, &mut session, cancel)?;
    seconds.solve = t.elapsed().as_secs_f64();
    let mesh: &crate::mesh::Mesh = &solved.mesh;
    let totals = session.totals();

    let mut written = Written::default();
    if cancel.is_set() {
        return Err(written.interrupted(config, totals.steps, true));
    }
    let t = Instant::now();
    let drawn = match draw(config, prepared, &view, mesh, &solved.shown, cancel) {
        Err(RunError::Render(RenderError::Cancelled(_))) => {
            return Err(written.interrupted(config, totals.steps, true))
        }
        drawn => drawn?,
    };
    let frame = drawn.frame();
    seconds.render = t.elapsed().as_secs_f64();
    // One line on a (nearly) black picture, whatever `--quiet` says, like
    // the load warnings: it explains a picture the user did not expect.
    // Not when nothing emits: the load warning has said why already.
    let dark =
        render::PictureCoverage::of(drawn.rasterizer.frame(), drawn.rasterizer.front_faces())
            .dark_warning_with(|| prepared.scene.eye_outside_lights(view.eye()))
            .filter(|_| prepared.scene.emits())
            .map(|w| format!("warning: {w}"));
    if let Some(line) = &dark {
        eprintln!("{line}");
    }

    if cancel.is_set() {
        return Err(written.interrupted(config, totals.steps, true));
    }
    let t = Instant::now();
    // Resolved once, so the picture and the exported colours agree; with
    // the ambient term shown (--ambient), as the window does, the
    // automatic exposure is at most the solution's own.
    let auto = if session.options().ambient && totals.steps > 0 {
        let (w, h) = render::exposure_probe_size(view.width(), view.height());
        let probe = View::with_size(&prepared.scene.camera, w, h)?;
        let mut alone = Rasterizer::new();
        render::auto_exposure_beside(frame, alone.render(mesh, &solved.radiosity, &probe)?)
    } else {
        render::auto_exposure(frame)
    };
    let exposure = (config.exposure.with_auto(auto), auto);
    if cancel.is_set() {
        return Err(written.interrupted(config, totals.steps, true));
    }
    let results = Results {
        config,
        prepared,
        output: &output,
        solved: &solved,
        drawn: &drawn,
        view: &view,
        exposure: exposure.0,
        points: points.as_deref(),
    };
    let wrote = output::cancelling_writes(cancel, || {
        results.write(&mut written, cancel)?;
        let said = solved.warnings.iter().cloned().chain(dark).collect();
        let mut stats = run_stats(config, prepared, &session, mesh, said, exposure, seconds);
        stats.seconds.write = t.elapsed().as_secs_f64();
        if let Some(path) = &config.stats {
            cancel.check()?;
            let json = serde_json::to_string_pretty(&stats).map_err(|e| {
                RunError::Write(OutputError::Io {
                    path: path.clone(),
                    error: std::io::Error::other(e),
                })
            })?;
            output::write_atomically(path, |w| writeln!(w, "{json}")).map_err(RunError::Write)?;
            written.push(path);
        }
        Ok(stats)
    });
    match wrote {
        Ok(stats) => Ok(stats),
        // The interrupt seen between two results, a write abandoned on it,
        // or a failure after it (a gather cut short): the files so far
        // stay, and are named.
        Err(e) if cancel.is_set() || is_interruption(&e) => {
            Err(written.interrupted(config, totals.steps, true))
        }
        Err(e) => Err(e),
    }
}

/// True for an interruption seen inside a phase, or a write abandoned on
/// one.
fn is_interruption(e: &RunError) -> bool {
    match e {
        RunError::Interrupted { .. } => true,
        RunError::Write(e) => output::is_cancelled(e),
        _ => false,
    }
}

/// An interruption seen inside a phase, before anyone could say what was
/// written: [`run_prepared`] replaces it with the full account.
impl From<Cancelled> for RunError {
    fn from(_: Cancelled) -> Self {
        RunError::Interrupted {
            steps: 0,
            written: Vec::new(),
            not_written: Vec::new(),
            checkpoint: None,
        }
    }
}

/// The picture a batch run drew: the rasterizer's frame at `aa × aa`
/// samples a pixel, and that frame averaged to the view's size when
/// `aa > 1`.
struct Drawn {
    /// The rasterizer after drawing, with its frame, depths and front faces
    /// at the sampled size.
    rasterizer: Rasterizer,
    /// Samples a pixel along each side (1 without antialiasing).
    aa: u32,
    /// The sampled frame averaged to the view's size; `None` when `aa` is 1.
    downsampled: Option<Frame>,
}

impl Drawn {
    /// The picture's linear frame, at the view's size.
    fn frame(&self) -> &Frame {
        self.downsampled.as_ref().unwrap_or(self.rasterizer.frame())
    }
}

/// Draws `shown` (per vertex of `mesh`) through `view`, antialiased as
/// `config.aa` asks; stops with [`RenderError::Cancelled`] once `cancel`
/// is set.
fn draw(
    config: &RunConfig,
    prepared: &Prepared,
    view: &View,
    mesh: &crate::mesh::Mesh,
    shown: &[crate::color::Rgb],
    cancel: &Cancel,
) -> Result<Drawn, RunError> {
    // Rendered at `aa × aa` samples a pixel, averaged to the picture.
    let camera = crate::camera::Camera {
        width: view.width(),
        height: view.height(),
        ..prepared.scene.camera
    };
    let mut rasterizer = Rasterizer::new();
    let drawn =
        antialias::draw(&mut rasterizer, mesh, shown, &camera, config.aa, cancel).map_err(|e| {
            match e {
                antialias::DrawError::View(e) => RunError::View(e),
                antialias::DrawError::Render(e) => RunError::Render(e),
            }
        })?;
    Ok(Drawn {
        rasterizer,
        aa: drawn.aa,
        downsampled: drawn.downsampled,
    })
}

/// What [`Results::write`] writes: the solved and drawn run.
struct Results<'a, 'p> {
    config: &'a RunConfig,
    prepared: &'a Prepared,
    /// The picture's path.
    output: &'a Path,
    solved: &'a Solved<'p>,
    drawn: &'a Drawn,
    view: &'a View,
    /// The picture's exposure, which the exported colours share.
    exposure: f32,
    /// The `--illuminance-at` points, read once before the solve.
    points: Option<&'a [MeasurementPoint]>,
}

impl Results<'_, '_> {
    /// Writes the picture to `output` and every other result `config`
    /// asks for: the solved mesh, the step log, the convergence plot and
    /// the photometric results, each added to `written` once complete.
    /// Checks `cancel` between them; the writes themselves are cancelled
    /// by the caller's [`output::cancelling_writes`].
    fn write(&self, written: &mut Written, cancel: &Cancel) -> Result<(), RunError> {
        let Results {
            config,
            prepared,
            output,
            solved,
            drawn,
            view,
            exposure,
            points,
        } = *self;
        let mesh: &crate::mesh::Mesh = &solved.mesh;
        let frame = drawn.frame();
        let aa = drawn.aa;
        if config.mesh_lines {
            let mut picture = render::to_srgb8(frame, exposure);
            let depth = if aa > 1 {
                antialias::nearest_depth(drawn.rasterizer.inv_depth(), view.width() * aa, aa)
            } else {
                drawn.rasterizer.inv_depth().to_vec()
            };
            render::draw_mesh_edges(&mut picture, mesh, view, &depth, render::MESH_LINES);
            cancel.check()?;
            output::write_rgb8(output, &picture).map_err(RunError::Write)?;
        } else {
            output::write_picture(output, frame, Exposure::Fixed(exposure))
                .map_err(RunError::Write)?;
        }
        written.push(output);
        if let Some(path) = &config.export {
            cancel.check()?;
            // The sky lights the model; it is no part of it.
            let without_sky = mesh.without_sky(&solved.radiosity);
            let (mesh, radiosity) = match &without_sky {
                Some((m, r)) => (m, &r[..]),
                None => (mesh, &solved.radiosity[..]),
            };
            output::write_mesh(
                path,
                &prepared.scene,
                mesh,
                radiosity,
                exposure,
                &config.scene.stem(),
            )
            .map_err(RunError::Write)?;
            written.push(path);
        }
        if config.wants_lightmap() {
            cancel.check()?;
            write_lightmap(config, prepared, solved, exposure, written, cancel)?;
        }
        if let Some(path) = &config.log {
            cancel.check()?;
            convergence::write_log_file(path, &solved.records).map_err(RunError::Write)?;
            written.push(path);
        }
        if let Some(path) = &config.plot {
            cancel.check()?;
            write_plot(config, path, &solved.records, cancel)?;
            written.push(path);
        }
        cancel.check()?;
        photometry::write(
            config,
            prepared,
            mesh,
            &solved.radiosity,
            frame,
            view,
            points,
            written,
            cancel,
        )?;
        Ok(())
    }
}

/// Bakes the lightmap of the scene's model from the solution and writes
/// what `config` asks for (`--lightmap`, `--lightmap-texture`), saying its
/// size, density and time in one line unless quiet.
fn write_lightmap(
    config: &RunConfig,
    prepared: &Prepared,
    solved: &Solved<'_>,
    exposure: f32,
    written: &mut Written,
    cancel: &Cancel,
) -> Result<(), RunError> {
    use output::lightmap;
    let t = Instant::now();
    let model = match &config.scene {
        SceneSource::File(path) if is_gltf(path) => {
            let model =
                crate::scene::import::gltf::source::load_gltf_source(path, &prepared.inputs)
                    .map_err(|e| RunError::Prepare(PrepareError::Load(e)))?;
            if let Some(why) = &model.textures_dropped {
                eprintln!(
                    "{}: warning: the lightmap's model has no textures: {why}",
                    path.display()
                );
            }
            model
        }
        SceneSource::File(path) if is_obj(path) => {
            let source = crate::scene::import::obj::source::load_obj_source(
                path,
                &prepared.inputs,
                &config.scene.stem(),
            )
            .map_err(|e| RunError::Prepare(PrepareError::Load(e)))?;
            // Said whatever `-q` says, as the load's warnings are: the
            // model lacks what the user gave it.
            for warning in &source.warnings {
                eprintln!("{warning}");
            }
            source.model
        }
        _ => lightmap::model::scene_model(&prepared.scene, &config.scene.stem()),
    };
    let mesh: &crate::mesh::Mesh = &solved.mesh;
    let baked = lightmap::bake(
        model,
        &prepared.scene,
        mesh,
        prepared.visibility(),
        &solved.shown,
        &solved.radiosity,
        config.lightmap_density,
        cancel,
    )
    .map_err(|why| match why {
        lightmap::BakeError::Cancelled(c) => RunError::from(c),
        lightmap::BakeError::Layout(why) => {
            RunError::Options(format!("cannot bake the lightmap: {why}"))
        }
    })?;
    let layout = &baked.layout;
    if config.progress {
        let how = match (layout.generated, config.lightmap_density) {
            (false, _) => "the model's own TEXCOORD_1".to_string(),
            (true, Some(_)) => format!("{} charts at --lightmap-density", layout.charts),
            (true, None) => format!(
                "{} charts, the highest density that fits {side}x{side}; \
                 --lightmap-density sets it",
                layout.charts,
                side = lightmap::uv::DEFAULT_SIDE
            ),
        };
        eprintln!(
            "lightmap: {}x{} texels, {:.4} texels per unit ({how}), baked in {:.1} s",
            layout.width,
            layout.height,
            layout.texels_per_unit,
            t.elapsed().as_secs_f64()
        );
    }
    if baked.texture.unmatched > 0 {
        // Said whatever `-q` says: the texture has holes the user should
        // know of.
        eprintln!(
            "warning: lightmap: {} texel(s) stand for points of the model on no solved \
             surface (a face dropped on loading?); they are filled from their neighbours",
            baked.texture.unmatched
        );
    }
    if let Some(path) = &config.lightmap {
        lightmap::write_glb(path, &baked, exposure, &config.scene.stem())
            .map_err(RunError::Write)?;
        written.push(path);
    }
    if let Some(path) = &config.lightmap_texture {
        lightmap::write_texture(path, &baked, exposure).map_err(RunError::Write)?;
        written.push(path);
    }
    Ok(())
}

/// True when `path` names an OBJ file (`.obj`, as [`crate::scene::load`]
/// reads it).
fn is_obj(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// True when `path` names a glTF file (`.gltf` or `.glb`).
fn is_gltf(path: &Path) -> bool {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .is_some_and(|e| e == "gltf" || e == "glb")
}

/// Draws and writes the convergence plot of `records` to `path`; the
/// drawing, in a library that cannot be asked to stop, is abandoned once
/// `cancel` is set ([`crate::cancel::abandonable`]).
fn write_plot(
    config: &RunConfig,
    path: &Path,
    records: &[StepRecord],
    cancel: &Cancel,
) -> Result<(), RunError> {
    let records = records.to_vec();
    let threshold = config.solver.threshold;
    let title = config.scene.display_name();
    let plot = crate::cancel::abandonable(cancel, move || {
        convergence::plot(&records, threshold, &title)
    })?;
    convergence::write_plot_image(path, plot).map_err(RunError::Write)
}

/// The figures of a finished run: what was solved and written, with the
/// warnings `said` while solving and drawing (the sky that lights nothing,
/// the dark picture); `seconds.write` is left for the caller to fill.
/// `exposure` is the factor used and the automatic one.
fn run_stats(
    config: &RunConfig,
    prepared: &Prepared,
    session: &Session,
    mesh: &crate::mesh::Mesh,
    said: Vec<String>,
    (exposure, auto): (f32, f32),
    seconds: PhaseSeconds,
) -> RunStats {
    let totals = session.totals();
    RunStats {
        scene: config.scene.display_name(),
        output: config.output_path().display().to_string(),
        also_written: config
            .extra_outputs()
            .map(|p| p.display().to_string())
            .collect(),
        warnings: prepared
            .scene
            .warnings
            .iter()
            .map(|w| w.to_string())
            .chain(said)
            .collect(),
        polygons: prepared
            .scene
            .polygons
            .iter()
            .filter(|p| !p.surface.sky)
            .count(),
        split: prepared.split,
        elements: drawn(mesh).0,
        vertices: drawn(mesh).1,
        sky: prepared.scene.sky().map(|s| s.to_array()),
        daylight_sky: daylight::sky_stats(config),
        sun: daylight::sun_stats(&prepared.scene),
        lenmax: prepared.lenmax,
        steps: totals.steps,
        rays: totals.rays,
        pairs: totals.pairs,
        clear_shaft_fraction: if totals.receiver_pairs > 0 {
            totals.clear_receiver_pairs as f64 / totals.receiver_pairs as f64
        } else {
            0.0
        },
        unshot_fraction: session.unshot_fraction(),
        particles: session.solver().particles(),
        exposure,
        auto_exposure: auto,
        exposure_stops: config.exposure.stops(auto),
        converged: session.converged() && prepared.scene.emits(),
        nothing_emits: !prepared.scene.emits(),
        adaptive: if session.refines() {
            session.passes().to_vec()
        } else {
            Vec::new()
        },
        seconds,
    }
}

/// Runs `session` to its end: resumes from the checkpoint asked for,
/// draws the progress bar, saves checkpoints, keeps the step log and says
/// what each adaptive pass did. An interruption saves the checkpoint (of
/// the state after the last complete step) and returns
/// [`RunError::Interrupted`].
fn solve<'p>(
    config: &RunConfig,
    prepared: &'p Prepared,
    session: &mut Session<'p>,
    cancel: &Cancel,
) -> Result<Solved<'p>, RunError> {
    let fingerprint = fingerprint(&prepared.scene, session.mesh(), &config.solver);
    // The step log: a resumed run's continues the one saved with its
    // checkpoint, and its clock continues from that log's last step.
    let mut records = Vec::new();
    if let Some(path) = &config.resume {
        let (state, log) = checkpoint::load(path, fingerprint)?;
        session
            .restore(state)
            .map_err(|reason| CheckpointError::Restore {
                path: path.clone(),
                reason,
            })?;
        records = log;
    }
    let clock_offset = records.last().map_or(0.0, |r: &StepRecord| r.seconds);
    let save = |session: &Session, records: &[StepRecord]| -> Result<(), RunError> {
        if let Some(path) = &config.checkpoint {
            checkpoint::save(path, fingerprint, &session.solver().state(), records)?;
        }
        Ok(())
    };
    let mut progress = Progress::new(
        config.progress,
        config.solver.threshold,
        session.solver().tail_from(),
    );
    let mut last_save = Instant::now();
    let start = Instant::now();
    // A resumed solve's sky may have shot already: it is not watched.
    let mut sky_watch = SkyWatch::new(
        &prepared.scene,
        session.mesh(),
        session.radiosity(),
        prepared.visibility(),
    )
    .filter(|_| config.resume.is_none());
    // Said whatever -q says, as the load warnings.
    let sky_blocked = || format!("warning: {}", sky_watch::SKY_BLOCKED);
    let mut warnings = Vec::new();
    loop {
        if cancel.is_set() {
            progress.clear();
            save(session, &records)?;
            return Err(Written::default().interrupted(config, session.totals().steps, true));
        }
        progress.follow(session.solver().gauge());
        let event = match session.advance(cancel.flag()) {
            Ok(event) => event,
            Err(error) => {
                progress.clear();
                let failure =
                    failure::stopped(config, prepared, session, &records, error, fingerprint);
                return Err(RunError::Failed(Box::new(failure)));
            }
        };
        match event {
            // A batch run asks for no parts: every report ends a step.
            Event::Step(report) if report.complete => {
                records.push(StepRecord {
                    step: report.step,
                    shooter: report.shooter.0,
                    shooter_line: prepared.scene.polygons[report.shooter.index()].origin.line,
                    shot_power: report.shot_power,
                    unshot_fraction: report.unshot_fraction,
                    rays: report.rays,
                    seconds: clock_offset + start.elapsed().as_secs_f64(),
                });
                if config.checkpoint.is_some() && last_save.elapsed() >= config.checkpoint_every {
                    save(session, &records)?;
                    last_save = Instant::now();
                }
                if let Some(watch) = &mut sky_watch {
                    if let Some(blocked) = watch.step(&report, session.mesh(), session.radiosity())
                    {
                        sky_watch = None;
                        if blocked {
                            progress.say(&sky_blocked());
                            warnings.push(sky_blocked());
                        }
                    }
                }
                progress.set_tail(session.solver().tail_from());
                progress.step(&report, session.solver().rays());
            }
            Event::Stopped(crate::solver::StopReason::Converged)
                if config.progress && session.pass() <= session.max_refinements() =>
            {
                // The refinement's gather at the new vertices takes a
                // while on a large model, with no step to show.
                progress.say(&format!(
                    "adaptive pass {} converged: refining, the new vertices gather the light shot so far",
                    session.pass()
                ));
                progress.refining();
            }
            Event::Step(_) | Event::Stopped(_) | Event::Cancelled => {}
            Event::Refined(report) => {
                // The sky shoots in the first pass; the watch does not
                // follow the mesh to the next.
                sky_watch = None;
                // A bar of its own for each pass, under the line saying
                // what the last pass did.
                progress.clear();
                if config.progress {
                    say_pass(session, Some(&report));
                }
                progress = Progress::new(
                    config.progress,
                    config.solver.threshold,
                    session.solver().tail_from(),
                );
                // A fresh solve numbers its steps from 1 again: the log
                // and plot show only the last one.
                if session.solver().steps() == 0 {
                    records.clear();
                }
            }
            Event::Refused(refused) => {
                progress.clear();
                eprintln!("warning: {refused}");
            }
            Event::Finished => break,
        }
    }
    progress.clear();
    // A sky much weaker than the lamps may be left partly unshot.
    if sky_watch.is_some_and(|watch| watch.finish()) {
        eprintln!("{}", sky_blocked());
        warnings.push(sky_blocked());
    }
    if config.progress && session.refines() {
        say_pass(session, None);
    }
    save(session, &records)?;
    session.validate()?;
    let mut shown = Vec::new();
    session.shown(&mut shown);
    let mut radiosity = Vec::new();
    session.solution(&mut radiosity);
    Ok(Solved {
        mesh: session.mesh_ref(),
        radiosity,
        shown,
        records,
        warnings,
    })
}

/// Says on stderr what the last finished pass of an adaptive run did, and
/// what its refinement split (`None`: it was the last).
fn say_pass(session: &Session, refined: Option<&crate::mesh::refine::RefineReport>) {
    let passes = session.passes();
    let Some(pass) = passes.last() else {
        return;
    };
    eprintln!(
        "adaptive pass {}: {} elements, {} steps, {:.2} s{}",
        passes.len(),
        pass.elements,
        pass.steps,
        pass.seconds,
        match refined {
            Some(r) if r.marked < r.over_threshold => format!(
                "; splitting the {} of its {} elements over the threshold with the most light to gain \
                 (--adaptive-max-splits; +{} to stay conforming)",
                r.marked, r.over_threshold, r.closure
            ),
            Some(r) => format!(
                "; splitting {} elements (+{} to stay conforming)",
                r.marked, r.closure
            ),
            None => "; final".to_string(),
        }
    );
}

/// A one-line summary of a finished run, naming every file written; for a
/// scene in which nothing emits, only that.
pub fn summary(stats: &RunStats) -> String {
    let steps = match (stats.adaptive.first(), stats.adaptive.len()) {
        (Some(first), solves) if solves > 1 => format!(
            "{solves} passes refining {} to {} vertices, {} steps in all",
            first.vertices, stats.vertices, stats.steps
        ),
        _ => format!("{} steps", stats.steps),
    };
    let steps = if stats.particles > 0 {
        format!(
            "{steps} (the tail by {:.1} M particles)",
            stats.particles as f64 / 1e6
        )
    } else {
        steps
    };
    let mut written = stats.output.clone();
    for also in &stats.also_written {
        written.push_str(", ");
        written.push_str(also);
    }
    if stats.nothing_emits {
        // No steps, no unshot power: there was nothing to solve.
        return format!("{}: nothing emits, nothing solved → {written}", stats.scene);
    }
    let uniform = match stats.sky {
        Some([r, g, b]) if r == g && g == b => Some(short(r)),
        Some([r, g, b]) => Some(format!("{},{},{}", short(r), short(g), short(b))),
        None => None,
    };
    let sky = daylight::summary_words(stats.daylight_sky.as_ref(), uniform, stats.sun.as_ref());
    format!(
        "{}{sky}: {steps}, {:.2} s solving, {:.1} M rays, {:.3}% unshot{}, {} → {written}",
        stats.scene,
        stats.seconds.solve,
        stats.rays as f64 / 1e6,
        stats.unshot_fraction * 100.0,
        if stats.converged { "" } else { " (step limit)" },
        exposure_text(stats.exposure, stats.auto_exposure, stats.exposure_stops),
    )
}

/// The exposure as the summary line says it: `exposure 2.42 (automatic)`,
/// or with the stops given, `exposure 9.67 (automatic 2.42, +2 stops)`;
/// three significant digits.
fn exposure_text(exposure: f32, auto: f32, stops: f32) -> String {
    let num = |x: f32| crate::scene::fmt_num(f64::from(x));
    if stops == 0.0 {
        return format!("exposure {} (automatic)", num(exposure));
    }
    let unit = if stops.abs() == 1.0 { "stop" } else { "stops" };
    let sign = if stops > 0.0 { "+" } else { "" };
    format!(
        "exposure {} (automatic {}, {sign}{} {unit})",
        num(exposure),
        num(auto),
        num(stops)
    )
}

/// The elements and vertices of `mesh` that are drawn: every one but the
/// sky's.
fn drawn(mesh: &crate::mesh::Mesh) -> (usize, usize) {
    let sky = mesh.polygons.iter().filter(|pm| pm.sky);
    let (elements, vertices) = sky.fold((0, 0), |(e, v), pm| {
        (e + pm.elements.len(), v + pm.vertex_count() as usize)
    });
    (
        mesh.elements.len() - elements,
        mesh.vertex_count() - vertices,
    )
}

/// For `skip_serializing_if`: the field is written only when true.
fn is_false(b: &bool) -> bool {
    !*b
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paths(names: &[&str]) -> Vec<PathBuf> {
        names.iter().map(PathBuf::from).collect()
    }

    #[test]
    fn the_summary_gives_the_exposure_and_the_automatic_one() {
        assert_eq!(
            exposure_text(2.4168, 2.4168, 0.0),
            "exposure 2.42 (automatic)"
        );
        assert_eq!(
            exposure_text(9.6672, 2.4168, 2.0),
            "exposure 9.67 (automatic 2.42, +2 stops)"
        );
        assert_eq!(
            exposure_text(1.2084, 2.4168, -1.0),
            "exposure 1.21 (automatic 2.42, -1 stop)"
        );
    }

    #[test]
    fn the_interruption_names_what_was_written_and_what_was_not() {
        let m = interrupted_message(12, &paths(&["a.png", "a.json"]), &paths(&["a.glb"]), None);
        assert_eq!(
            m,
            "interrupted after 12 steps; wrote a.png, a.json; not written: a.glb"
        );
        let m = interrupted_message(3, &[], &paths(&["a.png"]), None);
        assert_eq!(m, "interrupted after 3 steps; nothing was written");
        let m = interrupted_message(3, &[], &paths(&["a.png"]), Some(Path::new("c.ckpt")));
        assert_eq!(
            m,
            "interrupted after 3 steps; nothing was written but the checkpoint c.ckpt: \
             resume with --resume c.ckpt"
        );
        let m = interrupted_message(3, &paths(&["a.png"]), &[], Some(Path::new("c.ckpt")));
        assert_eq!(
            m,
            "interrupted after 3 steps; wrote a.png; saved the checkpoint c.ckpt: \
             resume with --resume c.ckpt"
        );
    }
}

/// `x` to four significant digits, without trailing zeros (`1`, `0.6667`,
/// `5438`), for the lines a person reads; files keep every digit.
pub(crate) fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    let decimals = (3 - magnitude).clamp(0, 17) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

#[cfg(test)]
mod short_tests {
    use super::short;

    #[test]
    fn numbers_read_to_four_significant_digits() {
        assert_eq!(short(1.0), "1");
        assert_eq!(short(5438.146010915304), "5438");
        assert_eq!(short(0.6666667), "0.6667");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(123456.0), "123456");
        assert_eq!(short(0.0), "0");
    }
}
