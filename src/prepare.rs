//! Preparing a scene for solving: load it (with a camera override), make
//! what `--emit` names emit ([`Scene::set_emission`]) and what `--ies`
//! names luminaires ([`Scene::set_luminaire`]), run the repair passes in
//! their one order ([`repair::run`]: solids keep their outside, polygons
//! are split where others pass through them, back copies, the `--sky`
//! around it, the side of a two-sided lamp that faces a ceiling across a
//! narrow gap silenced), say on stderr what the loader and the passes
//! changed or ignored and whether nothing emits ([`scene::Warning`],
//! [`Scene::nothing_emits_warning`]), pick the default lenmax within the
//! vertex budget when none is given (and say so when that made the mesh
//! coarser, [`mesh::budget`]), check the mesh size against the element
//! limit before allocating anything, mesh it and build the visibility BVH. What the batch run, the window and the examples all
//! start from.

use crate::budget::{self, MemoryBudget, OverBudget};
use crate::cancel::{self, Cancel, Cancelled};
use crate::config::{RunConfig, SceneSource, BUNDLED_SCENE, BUNDLED_SCENE_NAME};
use crate::mesh::budget::VERTEX_BUDGET;
use crate::mesh::{self, Mesh, MeshError, MeshOptions};
use crate::render::{View, ViewError};
use crate::scene::repair::{self, FirstHit, RepairError, RepairOptions};
use crate::scene::{
    self, IesError, InputKind, InputSet, LoadError, LuminaireError, Photometry, PolygonError,
    PolygonId, Scene, SkyLight, SplitStats, UnknownName, Warning,
};
use crate::visibility::Visibility;
use glam::Vec3;
use serde::Serialize;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// Why a scene could not be prepared.
#[derive(Debug, thiserror::Error)]
pub enum PrepareError {
    /// The scene file (or the camera file) is bad or unreadable; the
    /// message reads `FILE:LINE:COL: error: ...`.
    #[error("{0}")]
    Load(#[from] LoadError),
    /// The mesh options do not suit the scene, or the mesh would be too
    /// large.
    #[error("{0}")]
    Mesh(#[from] MeshError),
    /// A name given to `--emit` is no material, object or group of the
    /// scene; the message lists the names there are.
    #[error("--emit: {0}")]
    UnknownName(#[from] UnknownName),
    /// The sky's enclosure would lie beyond the largest coordinate a
    /// polygon may have (a scene within a tenth of that limit).
    #[error("--sky: the scene is too large to put a sky around it: {0}")]
    Sky(PolygonError),
    /// An `--ies` file is bad or unreadable; the message reads
    /// `FILE:LINE:COL: error: ...`.
    #[error("{0}")]
    Ies(#[from] IesError),
    /// An `--ies` name is unknown, or its distribution is dark.
    #[error("--ies {0}: {1}")]
    Luminaire(String, Box<LuminaireError>),
    /// `--ies` on a scene without a unit: candela need metres.
    #[error(
        "--ies needs --units for {0}: a luminous intensity in candela gives lux only \
         at distances in metres (glTF scenes are in metres; OBJ and .sc have no unit)"
    )]
    NoUnits(String),
    /// A standard sky on a scene without a unit: its luminance is in cd/m².
    #[error(
        "--sky {0} needs --units for {1}: a standard sky's luminance is in cd/m² and its \
         illuminance in lux (glTF scenes are in metres; OBJ and .sc have no unit)"
    )]
    SkyNoUnits(String, String),
    /// The sun on a scene without a unit: its illuminance is in lux.
    #[error(
        "--sun needs --units for {0}: the sun's illuminance is in lux \
         (glTF scenes are in metres; OBJ and .sc have no unit)"
    )]
    SunNoUnits(String),
    /// A standard sky cannot be made as asked.
    #[error("{0}")]
    Daylight(#[from] crate::scene::DaylightError),
    /// The scene would need more memory than `--max-memory`: what the
    /// estimate is and what makes it.
    #[error("{0}")]
    Memory(#[from] OverBudget),
    /// The cancellation token was set while preparing
    /// ([`prepare_cancellable`]).
    #[error("{0}")]
    Interrupted(#[from] Cancelled),
    /// `--eye`, `--look-at`, `--up` or `--fov` make an unusable camera
    /// with the scene's other parts; the message names the options.
    #[error("{0}")]
    Camera(#[from] crate::camera::OverrideError),
}

/// Seconds spent in each phase of a run.
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

/// A scene loaded, meshed and put in a BVH: what both the batch run and
/// the window start from.
pub struct Prepared {
    /// The scene.
    pub scene: Scene,
    /// Its element mesh.
    pub mesh: Mesh,
    /// Its visibility structure and the seconds its build took, built on
    /// first use ([`Prepared::visibility`]).
    visibility: OnceLock<(Visibility, f64)>,
    /// The lenmax the mesh was built with, in scene units.
    pub lenmax: f32,
    /// Whether the vertex budget made the mesh coarser than the default
    /// lenmax ([`MeshOptions::within_budget`]): such a run refines once
    /// ([`RunConfig::refinement`]).
    pub coarsened: bool,
    /// Seconds spent so far on load and mesh; see
    /// [`Prepared::phase_seconds`] for the BVH's.
    pub seconds: PhaseSeconds,
    /// What splitting along intersections did to the loaded scene.
    pub split: SplitStats,
    /// Every file the run reads: those loading read (the scene, its
    /// libraries, textures and buffers, the camera and IES files) and
    /// those read later (points, the checkpoint to resume), which no
    /// output may overwrite.
    pub inputs: InputSet,
}

impl Prepared {
    /// The scene's visibility structure (its BVH), built on first use:
    /// [`prepare`] builds it at once; [`prepare_deferred`] leaves it to
    /// whoever first needs it, so that a window can show its first frame
    /// (emitters and the ambient estimate, which need no rays) while the
    /// solver's thread builds it.
    pub fn visibility(&self) -> &Visibility {
        &self
            .visibility
            .get_or_init(|| {
                let t = Instant::now();
                let visibility = Visibility::new(&self.scene);
                (visibility, t.elapsed().as_secs_f64())
            })
            .0
    }

    /// Seconds spent on load, mesh and, once built, the BVH.
    pub fn phase_seconds(&self) -> PhaseSeconds {
        let mut seconds = self.seconds;
        seconds.bvh = self.visibility.get().map_or(0.0, |v| v.1);
        seconds
    }

    /// The view of the scene's camera, with the configured size override.
    pub fn view(&self, config: &RunConfig) -> Result<View, ViewError> {
        match config.size {
            Some((w, h)) => View::with_size(&self.scene.camera, w, h),
            None => View::new(&self.scene.camera),
        }
    }
}

/// Loads, validates, meshes and builds the BVH; refuses a mesh over
/// [`RunConfig::max_elements`] before building it, with the lenmax that
/// would fit.
pub fn prepare(config: &RunConfig) -> Result<Prepared, PrepareError> {
    prepare_cancellable(config, &Cancel::never())
}

/// [`prepare`], returning [`PrepareError::Interrupted`] as soon as
/// `cancel` is set. Preparing writes nothing, and much of it runs in code
/// that cannot be asked to stop (the loaders' parsers, the coplanar
/// classes, stitching, the BVH build), so it runs on a thread that the
/// interrupt abandons ([`cancel::abandonable`]); that thread itself stops
/// at its next check (between the phases, per polygon split, per polygon
/// meshed) rather than finishing work nobody will use.
pub fn prepare_cancellable(config: &RunConfig, cancel: &Cancel) -> Result<Prepared, PrepareError> {
    let (config, token) = (config.clone(), cancel.clone());
    cancel::abandonable(cancel, move || {
        let prepared = prepare_deferred_cancellable(&config, &token)?;
        token.check()?;
        prepared.visibility();
        Ok(prepared)
    })?
}

/// [`prepare`] without building the BVH, which [`Prepared::visibility`]
/// builds on first use (on a scene of 100,000 triangles it takes about a
/// quarter of a second, a quarter of the time before a window's first
/// frame). A scene with a face emitting from both sides builds it here
/// all the same, to find the sides that face a surface across a narrow
/// gap ([`Scene::silence_covered_sides`]).
pub fn prepare_deferred(config: &RunConfig) -> Result<Prepared, PrepareError> {
    prepare_deferred_cancellable(config, &Cancel::never())
}

/// A scene made ready to mesh ([`ready_to_mesh`]): loaded, lit as the
/// options say, repaired, its camera final and its mesh options chosen;
/// what `--info` describes and what [`prepare`] meshes.
pub struct ReadyScene {
    /// The scene after the repair passes, with its warnings (the loader's,
    /// the passes', nothing emitting, a coarsened default lenmax), not yet
    /// printed.
    pub scene: Scene,
    /// What splitting along intersections did.
    pub split: SplitStats,
    /// Two-sided faces left without a back copy, as no light can reach
    /// their back ([`repair::RepairReport::unreached_backs`]).
    pub unreached_backs: usize,
    /// The mesh options: `--lenmax` or the default within the vertex
    /// budget, and `--inset`.
    pub mesh_options: MeshOptions,
    /// Whether the vertex budget coarsened the default mesh.
    pub coarsened: bool,
    /// Every file the run reads (see [`Prepared::inputs`]).
    pub inputs: InputSet,
    /// The BVH the repair passes built, and the seconds it took.
    rays: Option<(Visibility, f64)>,
    /// Seconds of loading and repairing (the BVH's not counted) and of
    /// choosing the mesh options.
    load_seconds: f64,
    options_seconds: f64,
}

/// Loads the scene and makes it ready to mesh: `--emit`, `--ies`, the
/// repair passes, the camera (moved inside the room that holds the lights
/// when it was framed outside it, then `--eye`, `--look-at`, `--up` and
/// `--fov`), the mesh options. Prints nothing.
pub fn ready_to_mesh(config: &RunConfig) -> Result<ReadyScene, PrepareError> {
    ready_cancellable(config, &Cancel::never())
}

/// [`ready_to_mesh`] checking `cancel` between its phases.
fn ready_cancellable(config: &RunConfig, cancel: &Cancel) -> Result<ReadyScene, PrepareError> {
    let t = Instant::now();
    let inputs = declared_inputs(config);
    let mut scene = load_scene(
        &config.scene,
        config.camera.as_deref(),
        &inputs,
        &config.max_memory,
    )?;
    cancel.check()?;
    for (name, emission) in &config.emit {
        scene.set_emission(name, *emission)?;
    }
    if !config.photometry.ies.is_empty() {
        let units = config
            .units()
            .ok_or_else(|| PrepareError::NoUnits(config.scene.display_name()))?;
        for (name, path) in &config.photometry.ies {
            let photometry = Arc::new(Photometry::load_into(path, &inputs)?);
            scene
                .set_luminaire(name, photometry, units)
                .map_err(|e| PrepareError::Luminaire(name.clone(), Box::new(e)))?;
        }
    }
    // The passes that make the geometry solvable, in their one order; the
    // BVH they build to find trapped sides is kept for the solve.
    let mut bvh_seconds = 0.0;
    let name = config.scene.display_name();
    let sky = match config.daylight.resolve()? {
        Some(daylight) => {
            if config.units().is_none() {
                return Err(PrepareError::SkyNoUnits(
                    daylight.model.name(),
                    config.scene.display_name(),
                ));
            }
            // The ground below the horizon is lit by the sun too.
            let sun = config.daylight.sun_light(scene.camera.up);
            Some(SkyLight::Daylight(
                daylight,
                sun.map_or(0.0, |s| s.horizontal_illuminance()),
            ))
        }
        None => config.sky.map(SkyLight::Uniform),
    };
    if config.daylight.sun_shines() && config.units().is_none() {
        return Err(PrepareError::SunNoUnits(config.scene.display_name()));
    }
    let options = RepairOptions {
        sides: config.sides,
        sky,
        file: &name,
        budget: config.max_memory,
    };
    let built = |scene: &Scene| {
        let t = Instant::now();
        let built = Visibility::new(scene);
        bvh_seconds += t.elapsed().as_secs_f64();
        built
    };
    let (mut scene, repaired) =
        repair::run_cancellable(scene, &options, built, cancel).map_err(|e| match e {
            RepairError::Sky(e) => PrepareError::Sky(e),
            RepairError::Memory(e) => PrepareError::Memory(e),
            RepairError::Interrupted(c) => PrepareError::Interrupted(c),
        })?;
    // In the sky's frame: the camera as the sky saw it, before overrides.
    scene.sun = config.daylight.sun_light(scene.camera.up);
    if let Some(warning) = sun_below_horizon(config) {
        scene.warnings.push(warning);
    }
    if let Some(warning) = scene.nothing_emits_warning(&config.scene.display_name()) {
        scene.warnings.push(warning);
    }
    // Once the lights are set and the back sides made: an automatic
    // camera outside the room that holds the lights goes in.
    scene.frame_inside_lights();
    scene.camera = config.camera_override.apply(&scene.camera)?;
    let load_seconds = t.elapsed().as_secs_f64() - bvh_seconds;

    let t = Instant::now();
    let (mut mesh_options, coarsened) = match config.lenmax {
        Some(lenmax) => (
            MeshOptions {
                lenmax,
                ..MeshOptions::for_scene(&scene)
            },
            false,
        ),
        None => {
            let (options, coarsened) = MeshOptions::within_budget(&scene, VERTEX_BUDGET);
            if let Some(coarsened) = &coarsened {
                let mut line = coarsened.to_string();
                // Said only of the refinement the budget brings, not of
                // one `--adaptive` asked for.
                if let (None, Some(refine)) = (config.adaptive, config.refinement(true)) {
                    line += &format!(
                        "; once solved, up to {} of its elements where the light changes \
                         most are split and solved again (--no-adaptive keeps it)",
                        crate::budget::fmt_count(refine.max_splits)
                    );
                }
                scene.warnings.push(Warning::file(&name, line));
            }
            (options, coarsened.is_some())
        }
    };
    mesh_options.inset = config.inset;
    Ok(ReadyScene {
        scene,
        split: repaired.split,
        unreached_backs: repaired.unreached_backs,
        mesh_options,
        coarsened,
        inputs,
        rays: repaired.rays.map(|built| (built, bvh_seconds)),
        load_seconds,
        options_seconds: t.elapsed().as_secs_f64(),
    })
}

/// [`prepare_deferred`] checking `cancel` as [`prepare_cancellable`] does.
fn prepare_deferred_cancellable(
    config: &RunConfig,
    cancel: &Cancel,
) -> Result<Prepared, PrepareError> {
    let ReadyScene {
        scene,
        split,
        unreached_backs: _,
        mesh_options,
        coarsened,
        inputs,
        rays,
        load_seconds,
        options_seconds,
    } = ready_cancellable(config, cancel)?;
    let mut seconds = PhaseSeconds {
        load: load_seconds,
        ..PhaseSeconds::default()
    };
    let visibility = OnceLock::new();
    if let Some(built) = rays {
        // Set once, here, before anyone can read it.
        let _ = visibility.set(built);
    }
    // Said before the solve, whatever `--quiet` says: a warning explains a
    // picture that is not what the user expected (a coarser mesh too).
    for warning in &scene.warnings {
        eprintln!("{warning}");
    }

    let t = Instant::now();
    let size = mesh::check_size(&scene, &mesh_options, config.max_elements)?;
    check_mesh_memory(&scene, &mesh_options, size, &config.max_memory)?;
    cancel.check()?;
    let mesh = mesh::build_cancellable(&scene, &mesh_options, config.max_elements, cancel)
        .map_err(|e| match e {
            MeshError::Interrupted(c) => PrepareError::Interrupted(c),
            e => PrepareError::Mesh(e),
        })?;
    seconds.mesh = options_seconds + t.elapsed().as_secs_f64();

    Ok(Prepared {
        scene,
        mesh,
        visibility,
        lenmax: mesh_options.lenmax,
        coarsened,
        seconds,
        split,
        inputs,
    })
}

/// Refuses a mesh whose run would need more than `budget`
/// ([`budget::run_bytes`]), saying its size and the lenmax that fits.
fn check_mesh_memory(
    scene: &Scene,
    options: &MeshOptions,
    size: mesh::MeshSize,
    budget: &MemoryBudget,
) -> Result<(), OverBudget> {
    let polygons = scene.polygons.len() as u64;
    let need = |s: mesh::MeshSize| budget::run_bytes(polygons, s.elements, s.vertices);
    budget.check(need(size), || {
        let fit = mesh::Sizes::of(scene)
            .smallest_fitting(options.lenmax, |s| budget.fits(need(s)))
            .map_or_else(
                || "not even one element a polygon fits".to_string(),
                |l| format!("use --lenmax {l} or larger"),
            );
        format!(
            "{} polygons meshed at lenmax {} into {} elements on {} vertices; {fit}",
            budget::fmt_count(polygons),
            options.lenmax,
            budget::fmt_count(size.elements),
            budget::fmt_count(size.vertices),
        )
    })
}

/// The BVH casts the rays of the trapped-sides pass
/// ([`Scene::silence_covered_sides`]).
impl FirstHit for Visibility {
    fn first_hit_polygon(&self, origin: Vec3, direction: Vec3) -> Option<(PolygonId, f32)> {
        self.first_hit(origin, direction)
    }
}

/// Loads the scene from its source, with the camera of the `.sc` file
/// `camera` when given (see [`Scene::with_camera_from`]), recording every
/// file read in `inputs`, within the memory budget `budget`
/// ([`scene::load_with`]).
pub fn load_scene(
    source: &SceneSource,
    camera: Option<&Path>,
    inputs: &InputSet,
    budget: &MemoryBudget,
) -> Result<Scene, LoadError> {
    let scene = match source {
        SceneSource::Bundled => scene::parse_str(BUNDLED_SCENE, BUNDLED_SCENE_NAME)?,
        SceneSource::File(path) => scene::load_with(path, inputs, budget)?,
    };
    scene.with_camera_read(camera, inputs)
}

/// The input set of a run before anything is read: empty but for the
/// files `config` names that are read only after loading (the points
/// file, the checkpoint to resume), recorded by identity so that outputs
/// are checked against them before then; a model's files may lie outside
/// its folder as `--allow-outside-paths` says.
pub fn declared_inputs(config: &RunConfig) -> InputSet {
    let inputs = InputSet::new(config.allow_outside_paths);
    if let Some((points, _)) = &config.photometry.illuminance {
        inputs.declare(points, InputKind::Points);
    }
    if let Some(resume) = &config.resume {
        inputs.declare(resume, InputKind::Checkpoint);
    }
    inputs
}

/// The warning that `--sun` puts the sun below the horizon (a date at
/// night), where it gives no light; `None` otherwise.
fn sun_below_horizon(config: &RunConfig) -> Option<crate::scene::Warning> {
    let sun = config.daylight.sun.filter(|s| s.altitude < 0.0)?;
    config.daylight.sun_shines().then(|| {
        crate::scene::Warning::file(
            &config.scene.display_name(),
            format!(
                "--sun puts the sun {:.1}° below the horizon at that time (azimuth {:.1}°): \
                 it gives no light",
                -sun.altitude.to_degrees(),
                sun.azimuth.to_degrees()
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::budget::VERTEX_BUDGET;

    /// Unit squares in [`stack_of_squares`].
    const STACKED: usize = 150;

    /// [`STACKED`] unit squares stacked 0.001 apart, facing up: at the
    /// default lenmax (1/80 of the diagonal √2.022201, 0.017776) 58 × 58
    /// vertices each, 504,600 in all, over [`VERTEX_BUDGET`]; the finest
    /// three-digit lenmax within it is 0.0186, 55 × 55 each, 453,750 in
    /// all (0.0185 gives 56 × 56, 470,400).
    fn stack_of_squares(dir: &Path) -> std::path::PathBuf {
        let mut text = String::from("material wall color 1 1 1 k_diffrefl 0.5 end\n");
        for k in 0..STACKED {
            let z = k as f64 * 0.001;
            text += &format!(
                "polygon wall vertex 0 0 {z} vertex 1 0 {z} vertex 1 1 {z} vertex 0 1 {z} end\n"
            );
        }
        let path = dir.join("stack.sc");
        std::fs::write(&path, text).expect("the scene is written");
        path
    }

    #[test]
    fn a_deferred_preparation_builds_the_bvh_on_first_use() {
        let config = RunConfig::new(SceneSource::Bundled);
        let deferred = prepare_deferred(&config).expect("the bundled scene prepares");
        assert!(
            deferred.visibility.get().is_none(),
            "no BVH before it is asked for"
        );
        assert_eq!(deferred.phase_seconds().bvh, 0.0);
        let built = deferred.visibility();
        assert_eq!(built.polygon_count(), deferred.scene.polygons.len());
        assert!(deferred.phase_seconds().bvh > 0.0);
        // The same structure on every later call.
        assert!(std::ptr::eq(built, deferred.visibility()));
        // `prepare` builds it at once, and counts its time.
        let eager = prepare(&config).expect("the bundled scene prepares");
        assert!(eager.visibility.get().is_some());
        assert!(eager.phase_seconds().bvh > 0.0);
        assert_eq!(eager.seconds.load, eager.phase_seconds().load);
    }

    #[test]
    fn a_default_mesh_over_the_vertex_budget_is_coarsened_and_says_so() {
        let dir = tempfile::tempdir().unwrap();
        let config = RunConfig::new(SceneSource::File(stack_of_squares(dir.path())));
        let prepared = prepare_deferred(&config).expect("the stack prepares");
        assert_eq!(prepared.lenmax, 0.0186);
        assert!((prepared.mesh.vertex_count() as u64) <= VERTEX_BUDGET);
        // So the session refines it once.
        assert!(prepared.coarsened);
        let refine = crate::session::SessionOptions::for_run(&config, &prepared, false).refine;
        assert_eq!(refine.map(|r| (r.levels, r.max_splits)), Some((1, 5_000)));
        // The squares share no edge: the estimate is the mesh.
        let n = (1.0 / prepared.lenmax).floor() as usize + 2;
        assert_eq!(prepared.mesh.vertex_count(), STACKED * n * n);
        // The next finer three-digit lenmax is over the budget.
        let finer = prepared.lenmax - 0.0001;
        let m = (1.0 / finer).floor() as u64 + 2;
        assert!(STACKED as u64 * m * m > VERTEX_BUDGET, "{finer}: {m}");
        let said: Vec<String> = prepared
            .scene
            .warnings
            .iter()
            .map(|w| w.to_string())
            .filter(|w| w.contains("coarsened"))
            .collect();
        assert_eq!(said.len(), 1, "{said:?}");
        assert!(
            said[0].contains(&format!(
                "stack.sc: warning: mesh coarsened to lenmax {} (an estimated",
                prepared.lenmax
            )) && said[0].contains("the default 0.01778 would give 505,000"),
            "{}",
            said[0]
        );
    }

    #[test]
    fn a_given_lenmax_is_used_as_it_is_whatever_the_budget() {
        let dir = tempfile::tempdir().unwrap();
        let mut config = RunConfig::new(SceneSource::File(stack_of_squares(dir.path())));
        // Finer than the default, coarser than the budget's choice.
        for lenmax in [0.016, 0.02] {
            config.lenmax = Some(lenmax);
            let prepared = prepare_deferred(&config).expect("the stack prepares");
            assert_eq!(prepared.lenmax, lenmax);
            assert!(!prepared.coarsened);
            let options = crate::session::SessionOptions::for_run(&config, &prepared, false);
            assert_eq!(options.refine, None);
            let n = (1.0 / lenmax).floor() as usize + 2;
            assert_eq!(prepared.mesh.vertex_count(), STACKED * n * n);
            assert!(prepared
                .scene
                .warnings
                .iter()
                .all(|w| !w.to_string().contains("coarsened")));
        }
    }

    /// The budget changes nothing on the bundled scenes: their lenmax is
    /// the diagonal's fraction, to the bit, and their meshes (14,206 to
    /// 16,957 vertices) are a twentieth of it.
    #[test]
    fn every_bundled_scene_keeps_the_default_lenmax() {
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut seen = 0;
        for entry in std::fs::read_dir(scenes).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "sc") {
                continue;
            }
            let prepared = prepare_deferred(&RunConfig::new(SceneSource::File(path.clone())))
                .expect("a bundled scene prepares");
            let fine = MeshOptions::for_scene(&prepared.scene).lenmax;
            assert_eq!(prepared.lenmax.to_bits(), fine.to_bits(), "{path:?}");
            assert!(
                (prepared.mesh.vertex_count() as u64) < VERTEX_BUDGET / 16,
                "{path:?}: {}",
                prepared.mesh.vertex_count()
            );
            seen += 1;
        }
        assert!(seen >= 4, "{seen} bundled scenes");
    }
}
