//! The one configuration value the library sees: what to solve, how, and
//! what to write. The command line ([`crate::cli`]) builds it from the
//! arguments; tests and examples build it with [`RunConfig::new`] and
//! field updates. Values here are already validated.

use crate::budget::MemoryBudget;
use crate::color::Rgb;
use crate::mesh::{self, refine::RefineOptions};
use crate::render::falsecolor::{Quantity, Scale};
use crate::render::Exposure;
use crate::scene::{Sides, Units};
use crate::solver::SolverOptions;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Default for [`RunConfig::max_elements`]: [`mesh::MAX_ELEMENTS`], 20
/// million elements. A mesh that large needs about 12 GB by
/// [`mesh::memory_estimate`], which `--max-memory` refuses on smaller
/// machines; the bundled scenes at their default `lenmax` have about
/// 15,000.
pub const DEFAULT_MAX_ELEMENTS: u64 = mesh::MAX_ELEMENTS;

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
    /// A scene file: `.obj` (Wavefront OBJ with MTL materials), `.gltf`
    /// or `.glb` (glTF 2.0), or `.sc`.
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
    /// ([`mesh::MeshOptions::within_budget`]), which `prepare` picks.
    pub lenmax: Option<f32>,
    /// Boundary inset as a fraction of lenmax (or of the polygon's
    /// diameter when smaller).
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
    /// `--eye`, `--look-at`, `--up`, `--fov`: parts of the camera that
    /// replace those of the scene's (its own, [`RunConfig::camera`]'s or
    /// the automatic one); empty by default.
    pub camera_override: crate::camera::CameraOverride,
    /// Where to write the solved mesh (`.glb` or `.ply`), if anywhere.
    pub export: Option<PathBuf>,
    /// Where to write the model with its baked lightmap (`.glb`), if
    /// anywhere ([`crate::output::lightmap`]).
    pub lightmap: Option<PathBuf>,
    /// Where to write the bare lightmap texture (`.png` or `.exr`), if
    /// anywhere.
    pub lightmap_texture: Option<PathBuf>,
    /// Lightmap texels per scene unit (`> 0`); `None` for the default.
    pub lightmap_density: Option<f32>,
    /// Where to write the per-step CSV log, if anywhere.
    pub log: Option<PathBuf>,
    /// Where to write the convergence plot (`.png`), if anywhere.
    pub plot: Option<PathBuf>,
    /// Show a progress bar (only drawn when stderr is a terminal).
    pub progress: bool,
    /// Refuse meshes with more elements than this (see
    /// [`DEFAULT_MAX_ELEMENTS`]); at most [`mesh::MAX_ADDRESSABLE_ELEMENTS`].
    pub max_elements: u64,
    /// The memory the run may take (`--max-memory`): every stage that
    /// could grow far beyond its input checks its estimate against it
    /// before allocating ([`crate::budget`]). Default
    /// [`MemoryBudget::for_machine`].
    pub max_memory: MemoryBudget,
    /// Where to save the solver state during the solve, if anywhere.
    pub checkpoint: Option<PathBuf>,
    /// How often to save the checkpoint (wall clock).
    pub checkpoint_every: Duration,
    /// A checkpoint to continue from instead of starting the solve afresh.
    pub resume: Option<PathBuf>,
    /// `--allow-outside-paths`: a model may name files outside its folder
    /// (see [`crate::scene::import::input`]); off by default.
    pub allow_outside_paths: bool,
    /// Add the ambient term ([`crate::solver::Progressive::ambient`]) to the radiosity
    /// shown: `None` for the default, on in the window and off for files.
    pub ambient: Option<bool>,
    /// Refine the mesh where the solution changes sharply and solve again
    /// ([`mesh::refine`]), or `None` to solve on the regular mesh only.
    pub adaptive: Option<RefineOptions>,
    /// Without [`RunConfig::adaptive`], refine once when the vertex budget
    /// coarsened the default mesh ([`RunConfig::refinement`]); off with
    /// `--no-adaptive`.
    pub refine_coarsened: bool,
    /// Draw the element mesh over the picture (8-bit pictures only).
    pub mesh_lines: bool,
    /// Samples per pixel side of written pictures
    /// ([`crate::render::antialias`]), `1..=MAX_AA`.
    pub aa: u32,
    /// `--emit NAME=VALUE`, in order: the material, OBJ object or group
    /// `NAME` emits `VALUE` (radiosity in the scene's units, every channel
    /// finite, `>= 0` and at most [`crate::scene::MAX_EMISSION`]). Applied
    /// after loading by [`crate::scene::Scene::set_emission`]; an unknown
    /// name fails the run. Empty by default.
    pub emit: Vec<(String, Rgb)>,
    /// Which sides of the polygons take part: as the file says (OBJ faces
    /// both, `.sc` the front), or `--one-sided` / `--two-sided` for all.
    /// Applied after `--emit` by [`crate::scene::Scene::with_sides`].
    pub sides: Sides,
    /// `--sky VALUE`: a uniform diffuse sky of this radiosity (scene units,
    /// every channel finite, `>= 0` and at most
    /// [`crate::scene::MAX_EMISSION`]) all around the scene, added after
    /// `--emit` by [`crate::scene::Scene::add_sky`]; `None` by default.
    pub sky: Option<Rgb>,
    /// Photometric options and outputs (`--units`, `--ies`,
    /// `--illuminance-at`, `--workplane`, `--falsecolor`); all off by
    /// default.
    pub photometry: PhotometryConfig,
    /// Daylight: a standard sky (`--sky cie-...`), the sun and north; all
    /// off by default.
    pub daylight: DaylightConfig,
}

/// The daylight part of a run: a standard sky, where the sun is and
/// which way north lies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DaylightConfig {
    /// `--sky cie-...`: the standard sky and its level, if asked for
    /// (never with a uniform [`RunConfig::sky`]).
    pub sky: Option<(crate::scene::SkyModel, Option<crate::scene::SkyLevel>)>,
    /// `--sun`: where the sun is (below the horizon only when a date put
    /// it there).
    pub sun: Option<crate::scene::SunPosition>,
    /// `--sun`'s day of the year, when it gave a date.
    pub sun_day: Option<u32>,
    /// `--sun`'s direct normal illuminance (`,Nlx`), lux, when given.
    pub sun_lux: Option<f64>,
    /// `--north`: true north clockwise from the model's north, radians.
    pub north: f64,
}

impl DaylightConfig {
    /// The standard sky made definite, `None` when none is asked for.
    /// A sky shaped by the sun needs it above the horizon.
    pub fn resolve(
        &self,
    ) -> Result<Option<crate::scene::DaylightSky>, crate::scene::DaylightError> {
        self.sky
            .map(|(model, level)| {
                crate::scene::DaylightSky::new(model, level, self.sun, self.north)
            })
            .transpose()
    }

    /// Whether `--sun` lights the scene itself: a sun is given, and no
    /// standard sky or one that has a sun ([`crate::scene::SkyModel::has_sun`]:
    /// not under the overcast types, where `--sun` only shapes the sky).
    /// A sun below the horizon still "shines" here; it gives no light
    /// ([`DaylightConfig::sun_light`]).
    pub fn sun_shines(&self) -> bool {
        self.sun.is_some() && self.sky.is_none_or(|(model, _)| model.has_sun())
    }

    /// The direct normal illuminance of the sun, lux: as given, else the
    /// IES clear-sky figure for its altitude (and day, when a date gave
    /// it, [`crate::scene::clear_sky_normal_illuminance`]); `None` when the
    /// sun does not shine ([`DaylightConfig::sun_shines`]).
    pub fn sun_normal_lux(&self) -> Option<f64> {
        let sun = self.sun.filter(|_| self.sun_shines())?;
        Some(self.sun_lux.unwrap_or_else(|| {
            crate::scene::clear_sky_normal_illuminance(sun.altitude, self.sun_day)
        }))
    }

    /// The sun as a light in the frame of a model whose camera's up is
    /// `camera_up` ([`crate::scene::HorizonFrame`]): `None` when it does
    /// not shine or stands below the horizon.
    pub fn sun_light(&self, camera_up: glam::Vec3) -> Option<crate::scene::Sun> {
        let frame = crate::scene::HorizonFrame::new(camera_up, self.north);
        crate::scene::Sun::new(self.sun?, self.sun_normal_lux()?, &frame)
    }
}

/// The photometric part of a run: what a scene unit is, the luminaires,
/// and the photometric results to write.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PhotometryConfig {
    /// `--units`: what one scene unit is; `None` when not given (a glTF
    /// scene is in metres by its specification all the same, see
    /// [`RunConfig::units`]).
    pub units: Option<Units>,
    /// `--ies NAME=FILE`, in order: the polygons of `NAME` emit with the
    /// distribution of the IES file ([`crate::scene::Scene::set_luminaire`]).
    pub ies: Vec<(String, PathBuf)>,
    /// `--illuminance-at` and `--illuminance-out`: the points file to read
    /// and the CSV to write.
    pub illuminance: Option<(PathBuf, PathBuf)>,
    /// `--workplane` and `--workplane-out`.
    pub workplane: Option<WorkplaneConfig>,
    /// `--falsecolor` and its options.
    pub falsecolor: Option<FalsecolorConfig>,
}

/// A work plane to compute and write.
#[derive(Clone, Debug, PartialEq)]
pub struct WorkplaneConfig {
    /// Height above the floor of the scene's bounds, scene units, `>= 0`.
    pub height: f32,
    /// Grid spacing in scene units (`> 0`), `None` for the default
    /// ([`crate::output::illuminance::default_spacing_metres`]).
    pub spacing: Option<f32>,
    /// The CSV to write (`PREFIX.csv`).
    pub csv: PathBuf,
    /// The plan to write (`PREFIX.png`).
    pub png: PathBuf,
    /// With `--daylight-factor`, the plan of daylight factors to write
    /// (`PREFIX-df.png`).
    pub daylight_factor: Option<PathBuf>,
    /// The plan's false-colour scale (`--falsecolor-scale`).
    pub scale: crate::render::falsecolor::Scale,
    /// The value the plan shows red (`--falsecolor-max`), in lux with a
    /// unit, else in the scene's radiosity units; `None` for the largest,
    /// rounded up.
    pub max: Option<f64>,
}

/// A false-colour picture of the view to write.
#[derive(Clone, Debug, PartialEq)]
pub struct FalsecolorConfig {
    /// The picture (`.png`, `.tif` or `.tiff`).
    pub path: PathBuf,
    /// What it shows.
    pub quantity: Quantity,
    /// Linear or logarithmic.
    pub scale: Scale,
    /// The value shown red, in the quantity's unit (`> 0`); `None` for
    /// the picture's largest, rounded up.
    pub max: Option<f64>,
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
            camera_override: crate::camera::CameraOverride::default(),
            export: None,
            lightmap: None,
            lightmap_texture: None,
            lightmap_density: None,
            log: None,
            plot: None,
            max_elements: DEFAULT_MAX_ELEMENTS,
            max_memory: MemoryBudget::for_machine(),
            checkpoint: None,
            checkpoint_every: DEFAULT_CHECKPOINT_EVERY,
            resume: None,
            allow_outside_paths: false,
            ambient: None,
            adaptive: None,
            refine_coarsened: true,
            mesh_lines: false,
            aa: crate::render::antialias::DEFAULT_AA,
            emit: Vec::new(),
            sides: Sides::AsLoaded,
            sky: None,
            photometry: PhotometryConfig::default(),
            daylight: DaylightConfig::default(),
        }
    }

    /// What one scene unit is: `--units`, else metres for a glTF scene
    /// (by the format's specification), else unknown.
    pub fn units(&self) -> Option<Units> {
        self.photometry.units.or_else(|| match &self.scene {
            SceneSource::File(p)
                if p.extension().is_some_and(|e| {
                    e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb")
                }) =>
            {
                Some(Units::M)
            }
            _ => None,
        })
    }

    /// True when a photometric result (illuminance, work plane, false
    /// colour) is asked for.
    pub fn wants_photometry(&self) -> bool {
        let p = &self.photometry;
        p.illuminance.is_some() || p.workplane.is_some() || p.falsecolor.is_some()
    }
}

impl RunConfig {
    /// The refinement this run does, `coarsened` saying whether the vertex
    /// budget made the default mesh coarser than the default lenmax
    /// ([`mesh::MeshOptions::within_budget`]): `--adaptive`'s; else, on a
    /// coarsened mesh and with [`RunConfig::refine_coarsened`], one pass
    /// of [`RefineOptions::default`]'s threshold and split limit, so that
    /// the budget's vertices are spent where the light changes; none when
    /// a checkpoint is written or resumed (it holds one mesh).
    pub fn refinement(&self, coarsened: bool) -> Option<RefineOptions> {
        let checkpointed = self.checkpoint.is_some() || self.resume.is_some();
        match self.adaptive {
            Some(refine) => Some(refine),
            None if coarsened && self.refine_coarsened && !checkpointed => Some(RefineOptions {
                levels: 1,
                max_elements: self.max_elements,
                ..RefineOptions::default()
            }),
            None => None,
        }
    }

    /// True when the run asks for results only a batch run writes (the
    /// mesh export, the log, the plot or mesh lines on the picture), so no
    /// window should open.
    pub fn wants_batch_outputs(&self) -> bool {
        self.export.is_some()
            || self.wants_lightmap()
            || self.log.is_some()
            || self.plot.is_some()
            || self.mesh_lines
            || self.wants_photometry()
    }

    /// True when the run bakes a lightmap (`--lightmap` or
    /// `--lightmap-texture`).
    pub fn wants_lightmap(&self) -> bool {
        self.lightmap.is_some() || self.lightmap_texture.is_some()
    }

    /// Every file the batch run writes besides the picture.
    pub fn extra_outputs(&self) -> impl Iterator<Item = &PathBuf> {
        [
            &self.stats,
            &self.export,
            &self.lightmap,
            &self.lightmap_texture,
            &self.log,
            &self.plot,
            &self.checkpoint,
        ]
        .into_iter()
        .flatten()
        .chain(self.photometry.illuminance.iter().map(|(_, out)| out))
        .chain(
            self.photometry
                .workplane
                .iter()
                .flat_map(|w| [Some(&w.csv), Some(&w.png), w.daylight_factor.as_ref()])
                .flatten(),
        )
        .chain(self.photometry.falsecolor.iter().map(|f| &f.path))
    }
}

impl RunConfig {
    /// The picture path a batch run writes: `-o`, or `<scene-stem>.png`
    /// in the current directory.
    pub fn output_path(&self) -> PathBuf {
        self.output
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("{}.png", self.scene.stem())))
    }
}
