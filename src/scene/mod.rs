//! The scene: world-space planar polygons, their diffuse materials, and the
//! camera that looks at them.
//!
//! A [`Scene`] is what the loaders produce and what every later stage reads.
//! It knows nothing of meshing or light transport. Loading validates
//! everything the format promises (planar, convex, non-degenerate polygons;
//! reflectance below one), so later stages may rely on it.
//!
//! Here are the types, polygon validation (`polygon.rs`), the diagnostics
//! of loading ([`Diagnostic`], [`Warning`]) and camera framing
//! ([`frame_camera`]). Three rooms do the rest: [`import`] turns files
//! into a scene ([`load`] picks the reader by extension); [`repair`] runs
//! the passes that make real exports solvable, in their one order
//! ([`repair::run`]); `lighting` decides what emits (`--emit` names,
//! `--ies` luminaires, the `--sky`, photometric units).

mod error;
mod framing;
pub mod import;
mod lighting;
mod polygon;
pub mod repair;

pub(crate) use error::fmt_num;
pub use error::{escape_controls, Diagnostic, LoadError, Warning, MAX_DIAGNOSTICS};
pub use framing::{
    frame_camera, EYE_ACROSS_FRACTIONS, EYE_ALONG_FRACTIONS, EYE_CLEARANCE_FRACTION,
    EYE_HEIGHT_FRACTIONS, FRAMING_RAYS, LIGHTS_PROBED, LIGHT_POINT_OFFSET, RAY_EDGE_TOLERANCE,
    RAY_PARALLEL_COSINE, ROOM_FOV_DEG, ROOM_MIN_FRONT_FRACTION, ROOM_PROBE_OFFSET,
};
pub use import::gltf::parse_gltf;
pub use import::ies::{IesError, Photometry};
pub use import::input::{InputError, InputFile, InputKind, InputSet};
pub use import::obj::load_obj;
pub use import::points::{load_points, MeasurementPoint, PointsError};
pub use import::sc::{
    load_camera, load_camera_into, parse_bytes, parse_camera_str, parse_str, KEYWORDS, MAX_EMISSION,
};
pub use import::{load, load_with};
pub use lighting::daylight::{
    DaylightError, DaylightSky, HorizonFrame, SkyLevel, SkyLight, SkyModel, SkyPattern,
    SunPosition, CLEAR_TURBIDITY, DAYLIGHT_RADIUS_FACTOR, DEFAULT_HORIZONTAL_LUX, FACET_SPLITS,
    GROUND_REFLECTANCE,
};
pub use lighting::emit::{
    looks_like_lamp, Group, GroupKind, UnknownName, LAMP_SUBSTRINGS, LAMP_WORDS, MAX_LISTED_NAMES,
};
pub use lighting::luminaire::{Luminaire, LuminaireError};
pub use lighting::sky::{SKY_MATERIAL_NAME, SKY_RADIUS_FACTOR, SKY_SUBDIVISIONS};
pub use lighting::sun::{
    clear_sky_normal_illuminance, days_in_month, solar_position, Sun, SunTime, CLEAR_EXTINCTION,
    EXTRATERRESTRIAL_LUX, MAX_SUN_LUX, SUN_DISC_DEGREES, SUN_DISC_GRID, SUN_DISC_SAMPLES,
};
pub use lighting::units::{Photometric, Units};
pub(crate) use polygon::polygon_extent_f32;
pub use polygon::EXACT_DIAMETER_MAX_VERTICES;
pub use polygon::{
    PolygonError, Shape, COINCIDENT_TOLERANCE, CONVEXITY_TOLERANCE, COORDINATE_ROUNDING,
    MAX_COORDINATE, MIN_EXTENT, PARALLELOGRAM_TOLERANCE, PLANARITY_TOLERANCE, TURNING_TOLERANCE,
    ZERO_AREA_TOLERANCE,
};
pub use repair::coplanar::{
    covered_by, draw_layers, plane_classes, MAX_DRAW_LAYER, PLANE_NORMAL_TOLERANCE,
    PLANE_OFFSET_TOLERANCE,
};
pub use repair::sides::Sides;
pub use repair::split::{SplitStats, SplitStop, PARALLEL_SINE, SPLIT_TOLERANCE};
pub use repair::trapped::COVERED_GAP_SHARE;

/// The camera lives in [`crate::camera`], below the scene; these are
/// re-exported because every scene has one.
pub use crate::camera::{Camera, DEFAULT_FOV_DEG, DEFAULT_SIZE, UP_PARALLEL_TOLERANCE};

use crate::color::Rgb;
use glam::Vec3;
use std::path::Path;

/// Index of a material in [`Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialId(pub u32);

impl MaterialId {
    /// The index as a `usize`, for slice access.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Index of a polygon in [`Scene::polygons`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PolygonId(pub u32);

impl PolygonId {
    /// The index as a `usize`, for slice access.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A diffuse material as written in the scene file.
///
/// Invariants (checked by the loader): `color` channels, `k_diffrefl` and
/// `k_emission` are finite and `>= 0`, and every channel of
/// [`Material::reflectance`] is `< 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The name the scene file gave it.
    pub name: String,
    /// Base colour, per channel `>= 0`.
    pub color: Rgb,
    /// Diffuse reflection coefficient, `>= 0`.
    pub k_diffrefl: f64,
    /// Emission coefficient, `>= 0`.
    pub k_emission: f64,
}

impl Material {
    /// Emitted radiosity `e = k_emission * color`, in the scene's radiosity
    /// units (exitance), from the front side only.
    pub fn emission(&self) -> Rgb {
        self.color * self.k_emission
    }

    /// Diffuse reflectance `rho = k_diffrefl * color`, dimensionless, every
    /// channel in `[0, 1)`.
    pub fn reflectance(&self) -> Rgb {
        self.color * self.k_diffrefl
    }
}

/// Where something was written in a source file (both 1-based; columns
/// count Unicode characters). Both are 0 for what comes from a format
/// without lines (a glTF polygon).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SourcePos {
    /// Line, from 1.
    pub line: u32,
    /// Column in characters, from 1.
    pub col: u32,
}

/// One planar convex polygon in world space.
///
/// Invariants (checked by [`Polygon::new`]): at least three vertices, no two
/// equal consecutive vertices, planar within the format's tolerance, convex,
/// non-zero area, counter-clockwise seen from the front (so `normal` is the
/// direction of the area vector).
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// Its material.
    pub material: MaterialId,
    /// Vertices in scene units, counter-clockwise seen from the front.
    pub vertices: Vec<Vec3>,
    /// Unit normal pointing to the front (emitting, reflecting) side.
    pub normal: Vec3,
    /// Area in square scene units (from Newell's area vector, in `f64`).
    pub area: f64,
    /// What kind of polygon it is, which decides how it is meshed.
    pub shape: Shape,
    /// Where the statement that made it starts in its source file.
    pub origin: SourcePos,
    /// What it is beyond its geometry: sides, smooth surface, sky.
    pub surface: Surface,
}

/// Index of a smooth surface: polygons with the same one (an OBJ smoothing
/// group, faces sharing vertex normals, a glTF primitive with shared
/// normals) are shaded as one continuous surface where they meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SmoothId(pub u32);

/// What a polygon is beyond its geometry. The default is the `.sc`
/// reading: one-sided, faceted, an ordinary surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Surface {
    /// The loader's reading of the face: true when its back side should
    /// receive, reflect and emit too (OBJ faces, glTF `doubleSided`).
    /// Acted on by [`Scene::with_sides`], which adds the back copies.
    pub two_sided: bool,
    /// Set on a back copy made by [`Scene::with_sides`]: the polygon whose
    /// back it is. The two are coplanar and never block each other.
    pub back_of: Option<PolygonId>,
    /// The polygon that is this one's back side, once [`Scene::with_sides`]
    /// has run: its back copy, or a face of the file that is this one
    /// reversed. A polygon with a back is never drawn from behind: its
    /// back draws that side.
    pub back: Option<PolygonId>,
    /// The smooth surface it belongs to, if any.
    pub smooth: Option<SmoothId>,
    /// A facet of the sky enclosure added by `--sky` ([`Scene::add_sky`]):
    /// it emits and shoots like any emitter but reflects nothing, is meshed
    /// as one element, and is left out of the scene's bounds, the picture,
    /// the exports and adaptive refinement.
    pub sky: bool,
    /// A face of a closed solid with nothing inside
    /// ([`Scene::orient_solids`]): facing out, and one-sided whatever
    /// [`Surface::two_sided`] says, as its inside is never seen.
    pub solid: bool,
}

/// Whether the camera came from the file or was made to frame the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraSource {
    /// The file had a `camera` block.
    File,
    /// No camera in the file: see [`frame_camera`].
    AutoFramed,
}

/// A loaded, validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Every polygon, in file order.
    pub polygons: Vec<Polygon>,
    /// Every material, in file order (including unused ones).
    pub materials: Vec<Material>,
    /// The camera, from the file or auto-framed.
    pub camera: Camera,
    /// Where the camera came from.
    pub camera_source: CameraSource,
    /// What the loader accepted but changed or ignored, in file order;
    /// the drivers print them before solving.
    pub warnings: Vec<Warning>,
    /// The named sets of polygons the file defines: OBJ objects (`o`) and
    /// groups (`g`), in order of first appearance, each listing its
    /// polygons (see [`Group`]); empty for `.sc` scenes, which name
    /// materials only. Kept beside the polygons rather than on them so
    /// that a polygon may belong to several; [`Scene::set_emission`]
    /// reads them.
    pub groups: Vec<Group>,
    /// The luminaires `--ies` made ([`Scene::set_luminaire`]): materials
    /// whose polygons emit with a light distribution instead of
    /// Lambert's cosine. Empty unless asked for.
    pub luminaires: Vec<Luminaire>,
    /// The sun `--sun` made ([`Sun`]): a parallel light of its own, not a
    /// polygon, whose direct light the solver shoots once before its
    /// steps. `None` unless asked for and above the horizon.
    pub sun: Option<Sun>,
    /// How the standard sky's luminance varies within its facets
    /// ([`SkyPattern`]), by which the solver spreads each facet's light
    /// over its sample directions; `None` without a standard sky (a
    /// uniform `--sky`'s facets emit evenly).
    pub sky_pattern: Option<SkyPattern>,
}

impl Scene {
    /// The material of a polygon.
    pub fn material_of(&self, p: PolygonId) -> &Material {
        &self.materials[self.polygons[p.index()].material.index()]
    }

    /// Axis-aligned bounds `(min, max)` of the vertices of every polygon
    /// but the sky's ([`Surface::sky`]), in scene units: the sky encloses
    /// the scene and must not change its size, framing or default
    /// tolerances. For an empty scene both are zero.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        polygon_bounds(&self.polygons)
    }

    /// Length of the diagonal of [`Scene::bounds`], in scene units.
    pub fn extent(&self) -> f32 {
        let (lo, hi) = self.bounds();
        (hi - lo).length()
    }

    /// The scene with its camera taken from the `camera` block of the `.sc`
    /// file at `camera` (see [`load_camera`]) when given, and then marked
    /// [`CameraSource::File`]; unchanged when `None`.
    ///
    /// This is the one way a camera override (`--camera`) is applied,
    /// whatever format the scene came from. The scene is loaded first, so
    /// when both files are wrong the scene's mistakes are the ones reported.
    pub fn with_camera_from(self, camera: Option<&Path>) -> Result<Scene, LoadError> {
        self.with_camera_read(camera, &InputSet::default())
    }

    /// [`Scene::with_camera_from`], recording the camera file in `inputs`.
    pub fn with_camera_read(
        mut self,
        camera: Option<&Path>,
        inputs: &InputSet,
    ) -> Result<Scene, LoadError> {
        if let Some(path) = camera {
            self.camera = load_camera_into(path, inputs)?;
            self.camera_source = CameraSource::File;
        }
        Ok(self)
    }
}

/// Axis-aligned bounds `(min, max)` of the vertices of `polygons`, sky
/// facets left out, in scene units; both zero when there are none.
pub(crate) fn polygon_bounds(polygons: &[Polygon]) -> (Vec3, Vec3) {
    let mut it = polygons
        .iter()
        .filter(|p| !p.surface.sky)
        .flat_map(|p| p.vertices.iter().copied());
    match it.next() {
        None => (Vec3::ZERO, Vec3::ZERO),
        Some(first) => it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v))),
    }
}

/// [`load`], then [`Scene::with_camera_from`]: the camera of the `.sc`
/// file `camera` when given, instead of the scene's own or the
/// auto-framed one.
pub fn load_with_camera(path: &Path, camera: Option<&Path>) -> Result<Scene, LoadError> {
    load(path)?.with_camera_from(camera)
}
