//! The standard skies of daylighting (`--sky cie-overcast`, `cie-clear`,
//! `cie:N`): a sky whose luminance varies over the dome, as Radiance's
//! `gensky` makes them, put around the scene as the same enclosure of
//! [`SKY_SUBDIVISIONS`](super::sky::SKY_SUBDIVISIONS)-times split
//! icosahedron facets as the uniform `--sky` (so it costs the same to
//! solve), each facet emitting its own radiosity.
//!
//! The models, with `Z` a direction's zenith angle and `χ` its angle to the
//! sun, `Lz` the zenith luminance in cd/m²:
//!
//! - CIE overcast (Moon and Spencer, CIE 1955): `L = Lz (1 + 2 cos Z) / 3`,
//!   the same in every azimuth; the unobstructed horizontal illuminance
//!   is `7π Lz / 9`.
//! - The CIE standard general sky (ISO 15469:2004 / CIE S 011/2003) of
//!   type `N` from 1 to 15: `L = Lz φ(Z) f(χ) / (φ(0) f(Zs))` with the
//!   gradation `φ(Z) = 1 + a exp(b / cos Z)` and the indicatrix
//!   `f(χ) = 1 + c (exp(dχ) − exp(dπ/2)) + e cos²χ`, `Zs` the sun's
//!   zenith angle, `a`..`e` from the standard's table. Type 12 is the CIE
//!   standard clear sky (`cie-clear`, gensky's `+s`/`-s` sky).
//!
//! The dome is turned so that one of the enclosure's ten-edge great
//! circles lies in the horizontal plane through its centre: every facet
//! is wholly above the horizon (sky) or wholly below it (ground). An
//! upper facet emits `π` times the mean over its area of the luminance
//! its points show seen from the centre (each facet split
//! [`FACET_SPLITS`] times for the integral): its power is the sky's in
//! its patch. The solver does not spread that power evenly over the
//! facet's sample directions but in proportion to the sky's luminance in
//! each ([`SkyPattern`]), so each direction brings the sky's own
//! luminance, not the facet's mean: a point that sees the sky only
//! through the bottom of a window sees the dark band above the horizon,
//! not the brighter facet it lies in (the overcast sky's horizon is a
//! third of its zenith). A lower facet is the ground, as in gensky: a
//! diffuse plane of reflectance [`GROUND_REFLECTANCE`] under the sky (and
//! the sun), luminance `ρ_g E_h / π` the same in every direction, so its
//! facets emit evenly. An upward-facing plane never sees it.
//!
//! Directions: the model's up is its camera's up snapped to an axis (as
//! for the work plane); its north is `−z` for a `+y` up, `+y` for a `+z`
//! up (in general `up × east` with east `+x`, or `+z` when up is along
//! `x`), turned `--north` degrees clockwise seen from above. Azimuths
//! run clockwise from north (90° is east), altitudes up from the horizon.
//! Luminance is in cd/m² and radiosity `π L` in lm/m², which the scene's
//! radiosity units are under `--units` whatever the unit of length.

use crate::color::Rgb;
use crate::scene::{PolygonError, Scene, MAX_EMISSION};
use glam::{DQuat, DVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// The reflectance of the ground below the horizon, as gensky's default
/// (`-g 0.2`).
pub const GROUND_REFLECTANCE: f64 = 0.2;

/// The unobstructed horizontal illuminance of a standard sky given
/// without a value, in lux, except the clear sky (see
/// [`DaylightSky::new`]): the usual figure of daylight-factor studies (the
/// daylight factor does not depend on it).
pub const DEFAULT_HORIZONTAL_LUX: f64 = 10_000.0;

/// Times each facet is split in four for the luminance integrals: 1,024
/// pieces of about 0.8° across a facet. The overcast sky's horizontal
/// illuminance comes out within 1e-5 of `7π Lz / 9` (measured 6.5e-6).
pub const FACET_SPLITS: u32 = 5;

/// The standard sky's radius in half-diagonals of the scene's bounds,
/// ten times the uniform sky's
/// ([`SKY_RADIUS_FACTOR`](super::sky::SKY_RADIUS_FACTOR)): a uniform
/// enclosure gives the same light anywhere inside, but a point off the
/// centre sees a varying sky's facets in directions turned by up to
/// `1 / factor` radians. At 10, the floor of a 10 m square court under
/// the clear sky (sun 40° high) ranged ±5.5 % about the exact mean from
/// side to side; at 100, ±0.6 %.
pub const DAYLIGHT_RADIUS_FACTOR: f32 = 100.0;

/// gensky's atmospheric turbidity for the clear sky's default zenith
/// luminance.
pub const CLEAR_TURBIDITY: f64 = 2.45;

/// gensky lowers a clear sky's sun higher than this (radians, 87°) to it
/// for the default zenith luminance, whose formula grows as `tan`.
const CLEAR_MAX_ALTITUDE: f64 = 87.0 * PI / 180.0;

/// A vertex dot product with up below this counts as on the horizon.
const HORIZON_TOLERANCE: f64 = 1e-9;

/// Which standard sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SkyModel {
    /// The CIE overcast sky (Moon and Spencer): `Lz (1 + 2 cos Z) / 3`.
    CieOvercast,
    /// The CIE standard general sky of this type, 1 to 15 (12 is the CIE
    /// standard clear sky).
    Cie(u8),
}

/// The CIE general sky's gradation groups (`a`, `b`), I to VI.
const GRADATION: [(f64, f64); 6] = [
    (4.0, -0.70),
    (1.1, -0.8),
    (0.0, -1.0),
    (-1.0, -0.55),
    (-1.0, -0.32),
    (-1.0, -0.15),
];

/// The CIE general sky's indicatrix groups (`c`, `d`, `e`), 1 to 6.
const INDICATRIX: [(f64, f64, f64); 6] = [
    (0.0, -1.0, 0.0),
    (2.0, -1.5, 0.15),
    (5.0, -2.5, 0.30),
    (10.0, -3.0, 0.45),
    (16.0, -3.0, 0.30),
    (24.0, -2.8, 0.15),
];

/// Per CIE general sky type 1..=15: its gradation and indicatrix groups
/// (1-based), as ISO 15469:2004 table 1 pairs them.
const TYPES: [(usize, usize); 15] = [
    (1, 1),
    (1, 2),
    (2, 1),
    (2, 2),
    (3, 1),
    (3, 2),
    (3, 3),
    (3, 4),
    (4, 2),
    (4, 3),
    (4, 4),
    (5, 4),
    (5, 5),
    (6, 5),
    (6, 6),
];

/// The CIE standard clear sky's type.
pub const CIE_CLEAR_TYPE: u8 = 12;

impl SkyModel {
    /// The CIE standard clear sky.
    pub const CLEAR: SkyModel = SkyModel::Cie(CIE_CLEAR_TYPE);

    /// `(a, b, c, d, e)` of a general sky; `None` for the overcast sky or
    /// a type outside 1..=15.
    fn parameters(self) -> Option<[f64; 5]> {
        let SkyModel::Cie(n) = self else {
            return None;
        };
        let (g, i) = *TYPES.get(usize::from(n).checked_sub(1)?)?;
        let (a, b) = GRADATION[g - 1];
        let (c, d, e) = INDICATRIX[i - 1];
        Some([a, b, c, d, e])
    }

    /// Whether the type is one the program knows (a general sky of 1..=15).
    pub fn is_valid(self) -> bool {
        self == SkyModel::CieOvercast || self.parameters().is_some()
    }

    /// Whether its luminance depends on where the sun is (every general
    /// sky whose indicatrix is not flat: all but types 1, 3 and 5).
    pub fn needs_sun(self) -> bool {
        self.parameters()
            .is_some_and(|[_, _, c, _, e]| c != 0.0 || e != 0.0)
    }

    /// Whether the sun shines under it (`--sun` then adds its direct
    /// light): the clear sky and the general skies of types 6 to 15 (partly
    /// cloudy, clear and turbid); not the overcast sky nor types 1 to 5,
    /// the overcast ones of ISO 15469:2004, under which `--sun` only shapes
    /// the sky's luminance.
    pub fn has_sun(self) -> bool {
        matches!(self, SkyModel::Cie(n) if n >= 6)
    }

    /// The name the command line gives it.
    pub fn name(self) -> String {
        match self {
            SkyModel::CieOvercast => "cie-overcast".into(),
            SkyModel::Cie(CIE_CLEAR_TYPE) => "cie-clear".into(),
            SkyModel::Cie(n) => format!("cie:{n}"),
        }
    }

    /// The luminance in the local direction `dir` (unit, `z` up; at or
    /// above the horizon) over the zenith's, for the sun in the unit
    /// direction `sun` (ignored when [`SkyModel::needs_sun`] is false).
    pub fn relative_luminance(self, dir: DVec3, sun: DVec3) -> f64 {
        let cos_z = dir.z.clamp(0.0, 1.0);
        let Some([a, b, c, d, e]) = self.parameters() else {
            return (1.0 + 2.0 * cos_z) / 3.0;
        };
        // exp(b / cos Z) → 0 at the horizon (b < 0): no division by 0.
        let gradation = |cos_z: f64| {
            if cos_z <= 0.0 {
                1.0
            } else {
                1.0 + a * (b / cos_z).exp()
            }
        };
        let indicatrix =
            |chi: f64| 1.0 + c * ((d * chi).exp() - (d * FRAC_PI_2).exp()) + e * chi.cos().powi(2);
        let chi = dir.dot(sun).clamp(-1.0, 1.0).acos();
        let sun_z = sun.z.clamp(-1.0, 1.0).acos();
        gradation(cos_z) * indicatrix(chi) / (gradation(1.0) * indicatrix(sun_z))
    }
}

/// How bright a standard sky is, as given on the command line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SkyLevel {
    /// The unobstructed horizontal illuminance from the sky, lux (`> 0`).
    Horizontal(f64),
    /// The zenith luminance, cd/m² (`> 0`).
    Zenith(f64),
}

/// Where the sun is: radians, the azimuth clockwise from north, the
/// altitude above the horizon in `[0, π/2]` (below it, negative, only
/// when a date put it there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunPosition {
    /// Clockwise from north seen from above (east is `π/2`), radians.
    pub azimuth: f64,
    /// Above the horizon, radians, `0..=π/2`; `−π/2..0` below it.
    pub altitude: f64,
}

impl SunPosition {
    /// The sun at `azimuth` and `altitude` degrees.
    pub fn from_degrees(azimuth: f64, altitude: f64) -> SunPosition {
        SunPosition {
            azimuth: azimuth.to_radians(),
            altitude: altitude.to_radians(),
        }
    }

    /// The unit direction towards the sun in the local frame (`x` east,
    /// `y` north, `z` up).
    pub fn direction(self) -> DVec3 {
        let (sa, ca) = self.azimuth.sin_cos();
        let (sh, ch) = self.altitude.sin_cos();
        DVec3::new(sa * ch, ca * ch, sh)
    }
}

/// Why a standard sky cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DaylightError {
    /// The sky's luminance depends on the sun, and none was given.
    #[error("--sky {0} needs --sun AZIMUTH,ALTITUDE: its luminance depends on where the sun is")]
    NoSun(String),
    /// The sky's luminance depends on the sun, and the date given puts it
    /// below the horizon (its altitude in degrees).
    #[error(
        "--sky {0} needs the sun above the horizon, and --sun puts it {below:.1}° below: \
         choose a time of day, or an overcast sky",
        below = .1.abs()
    )]
    SunBelowHorizon(String, f64),
    /// The sky would be darker than nothing or brighter than the program
    /// takes.
    #[error("--sky {0}: a zenith luminance of {1} cd/m² is out of range (more than 0, at most {max:e})", max = MAX_EMISSION / PI)]
    Level(String, f64),
}

/// A standard sky made definite: its model, zenith luminance and sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DaylightSky {
    /// The luminance model.
    pub model: SkyModel,
    /// The zenith luminance, cd/m², finite and `> 0`.
    pub zenith: f64,
    /// The sun the luminance is shaped by (`None` for skies that do not
    /// depend on it).
    pub sun: Option<SunPosition>,
    /// How far true north is turned clockwise from the model's default
    /// north, radians.
    pub north: f64,
}

impl DaylightSky {
    /// The sky `model` at `level`, shaped by `sun`, turned by `north`
    /// radians. Without a level: [`DEFAULT_HORIZONTAL_LUX`], but for the
    /// clear sky gensky's zenith luminance for its sun,
    /// `((1.376 T − 1.81) tan α + 0.38)` kcd/m² with `T` =
    /// [`CLEAR_TURBIDITY`] and `α` the sun's altitude (at most 87°).
    pub fn new(
        model: SkyModel,
        level: Option<SkyLevel>,
        sun: Option<SunPosition>,
        north: f64,
    ) -> Result<DaylightSky, DaylightError> {
        let sun = if model.needs_sun() {
            let sun = sun.ok_or_else(|| DaylightError::NoSun(model.name()))?;
            if sun.altitude < 0.0 {
                return Err(DaylightError::SunBelowHorizon(
                    model.name(),
                    sun.altitude.to_degrees(),
                ));
            }
            Some(sun)
        } else {
            None
        };
        let mut sky = DaylightSky {
            model,
            zenith: 1.0,
            sun,
            north,
        };
        let zenith = match (level, sun) {
            (Some(SkyLevel::Zenith(lz)), _) => lz,
            (Some(SkyLevel::Horizontal(e)), _) => e / sky.horizontal_illuminance(),
            (None, Some(s)) if model == SkyModel::CLEAR => {
                let alpha = s.altitude.min(CLEAR_MAX_ALTITUDE);
                ((1.376 * CLEAR_TURBIDITY - 1.81) * alpha.tan() + 0.38) * 1000.0
            }
            (None, _) => DEFAULT_HORIZONTAL_LUX / sky.horizontal_illuminance(),
        };
        if !(zenith.is_finite() && zenith > 0.0 && zenith * PI <= MAX_EMISSION) {
            return Err(DaylightError::Level(model.name(), zenith));
        }
        sky.zenith = zenith;
        Ok(sky)
    }

    /// The sky's luminance in the local direction `dir` (unit, `z` up),
    /// cd/m²; 0 below the horizon (the ground is not the sky's).
    pub fn luminance(&self, dir: DVec3) -> f64 {
        if dir.z < 0.0 {
            return 0.0;
        }
        let sun = self.sun.map_or(DVec3::Z, SunPosition::direction);
        self.zenith * self.model.relative_luminance(dir, sun)
    }

    /// The unobstructed horizontal illuminance from the sky alone, lux:
    /// the integral of `L cos Z` over the upper hemisphere, over the
    /// dome's upper facets each split [`FACET_SPLITS`] times.
    pub fn horizontal_illuminance(&self) -> f64 {
        dome()
            .iter()
            .filter(|t| is_upper(t))
            .map(|t| self.facet_illuminance(*t))
            .sum()
    }

    /// `∫ L cos Z dω` over the spherical triangle `t` (unit vertices,
    /// local frame), by the midpoint rule on its pieces.
    fn facet_illuminance(&self, t: [DVec3; 3]) -> f64 {
        split(t, FACET_SPLITS)
            .into_iter()
            .map(|[a, b, c]| {
                let mid = (a + b + c).normalize();
                self.luminance(mid) * mid.z.max(0.0) * solid_angle(a, b, c)
            })
            .sum()
    }

    /// The mean over the flat triangle `t` (unit vertices, local frame)
    /// of the luminance each of its points shows seen from the centre,
    /// cd/m²: the triangle cut into `4^`[`FACET_SPLITS`] congruent parts,
    /// each of equal area, read at its centroid's direction.
    fn flat_mean_luminance(&self, [a, b, c]: [DVec3; 3]) -> f64 {
        let m = 1u32 << FACET_SPLITS;
        let (e1, e2) = ((b - a) / f64::from(m), (c - a) / f64::from(m));
        let at = |i: u32, j: u32| a + e1 * f64::from(i) + e2 * f64::from(j);
        let seen = |p: DVec3, q: DVec3, r: DVec3| self.luminance(((p + q + r) / 3.0).normalize());
        let mut sum = 0.0;
        for j in 0..m {
            for i in 0..m - j {
                sum += seen(at(i, j), at(i + 1, j), at(i, j + 1));
                if i + j + 1 < m {
                    sum += seen(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                }
            }
        }
        sum / f64::from(m * m)
    }

    /// The radiosity (lm/m²) of each facet of the dome (in the order of
    /// the enclosure's facets) when the ground
    /// is lit by `ground_lux` (the horizontal illuminance from the sky and
    /// any sun): above the horizon `π` times the mean over the flat
    /// facet's area of the luminance its points show from the centre (so
    /// radiosity times area is the sky's power through it), below it
    /// [`GROUND_REFLECTANCE`] `× ground_lux`.
    pub fn facet_radiosities(&self, ground_lux: f64) -> Vec<f64> {
        dome()
            .iter()
            .map(|t| {
                if is_upper(t) {
                    PI * self.flat_mean_luminance(*t)
                } else {
                    GROUND_REFLECTANCE * ground_lux
                }
            })
            .collect()
    }
}

/// How a standard sky's luminance varies within its facets: what the
/// solver spreads each upper facet's power over its sample directions by
/// (see the module docs). [`Scene::add_daylight_sky`] keeps it in
/// [`Scene::sky_pattern`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyPattern {
    /// The sky.
    pub sky: DaylightSky,
    /// The model's horizontal frame.
    pub frame: HorizonFrame,
    /// The enclosure's centre, in scene units.
    pub centre: DVec3,
    /// The enclosure's facets: the polygons `facets.0 .. facets.1` of the
    /// scene (indices).
    pub facets: (u32, u32),
}

impl SkyPattern {
    /// Whether polygon `i` of the scene is one of the enclosure's facets.
    pub fn covers(&self, i: usize) -> bool {
        (self.facets.0 as usize..self.facets.1 as usize).contains(&i)
    }

    /// The local direction (`z` up) from the centre to the scene point `p`.
    fn local(&self, p: Vec3) -> DVec3 {
        let d = (p.as_dvec3() - self.centre).normalize_or_zero();
        let f = &self.frame;
        DVec3::new(d.dot(f.east), d.dot(f.north), d.dot(f.up))
    }

    /// Whether the scene point `p` (on a facet) lies below the horizon
    /// seen from the centre: on the ground, which is as bright in every
    /// direction.
    pub fn is_ground(&self, p: Vec3) -> bool {
        self.local(p).z < 0.0
    }

    /// The sky's luminance, cd/m², in the direction of the scene point
    /// `p` (on an upper facet) seen from the centre, a direction just
    /// below the horizon (a point of a facet's lower edge, rounded) taken
    /// at it.
    pub fn luminance_at(&self, p: Vec3) -> f64 {
        let d = self.local(p);
        let d = DVec3::new(d.x, d.y, d.z.max(0.0)).normalize_or_zero();
        self.sky.luminance(d)
    }
}

/// The enclosure's triangles in the local frame (`z` up): the
/// geodesic sphere of the uniform sky turned so that one of its vertices
/// is the zenith, which puts one of its ten-edge great circles on the
/// horizon. Each counter-clockwise seen from the centre.
pub fn dome() -> Vec<[DVec3; 3]> {
    let triangles = super::sky::geodesic_sphere(super::sky::SKY_SUBDIVISIONS);
    let top = triangles[0][0];
    let turn = DQuat::from_rotation_arc(top, DVec3::Z);
    triangles
        .into_iter()
        .map(|t| t.map(|v| (turn * v).normalize()))
        .collect()
}

/// Whether a dome triangle lies above the horizon (every vertex at or
/// above it).
fn is_upper(t: &[DVec3; 3]) -> bool {
    t.iter().all(|v| v.z >= -HORIZON_TOLERANCE)
}

/// The spherical triangle `t` split in four `levels` times (midpoints
/// pushed out to the sphere).
fn split(t: [DVec3; 3], levels: u32) -> Vec<[DVec3; 3]> {
    super::sky::split_on_sphere(vec![t], levels)
}

/// The solid angle of the spherical triangle of unit vectors `a`, `b`,
/// `c` (Van Oosterom and Strackee, 1983), steradians.
pub fn solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let num = a.dot(b.cross(c)).abs();
    let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * num.atan2(den)
}

/// The model's horizontal frame in scene coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HorizonFrame {
    /// Towards east, unit.
    pub east: DVec3,
    /// Towards true north, unit.
    pub north: DVec3,
    /// Up, unit (an axis).
    pub up: DVec3,
}

impl HorizonFrame {
    /// The frame of a model whose camera's up is `camera_up`, true north
    /// turned `north` radians clockwise (seen from above) from its
    /// default (see the module docs).
    pub fn new(camera_up: Vec3, north: f64) -> HorizonFrame {
        let axis = (0..3)
            .max_by(|&a, &b| camera_up[a].abs().total_cmp(&camera_up[b].abs()))
            .unwrap_or(1);
        let mut up = DVec3::ZERO;
        up[axis] = if camera_up[axis] < 0.0 { -1.0 } else { 1.0 };
        let east0 = if axis == 0 { DVec3::Z } else { DVec3::X };
        let north0 = up.cross(east0);
        // Clockwise seen from above is a negative turn about up.
        let turn = DQuat::from_axis_angle(up, -north);
        let north = turn * north0;
        HorizonFrame {
            east: north.cross(up),
            north,
            up,
        }
    }

    /// The scene direction of the local direction `d` (`x` east, `y`
    /// north, `z` up).
    pub fn to_scene(&self, d: DVec3) -> DVec3 {
        self.east * d.x + self.north * d.y + self.up * d.z
    }
}

/// A sky to put around the scene: uniform (`--sky V`) or standard.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SkyLight {
    /// A uniform sky of this radiosity ([`Scene::add_sky`]).
    Uniform(Rgb),
    /// A standard sky, the ground also lit by this much direct sun on the
    /// horizontal, lux ([`Scene::add_daylight_sky`]).
    Daylight(DaylightSky, f64),
}

impl Scene {
    /// Adds `sky` ([`Scene::add_sky`] or [`Scene::add_daylight_sky`]).
    pub fn add_sky_light(&mut self, sky: &SkyLight) -> Result<(), PolygonError> {
        match sky {
            SkyLight::Uniform(rgb) => self.add_sky(*rgb),
            SkyLight::Daylight(d, sun) => self.add_daylight_sky(d, *sun),
        }
    }

    /// Adds the standard sky `sky` around the scene as [`Scene::add_sky`]
    /// adds a uniform one (the same enclosure, turned as the module docs
    /// say), each facet with a material of its own named
    /// [`SKY_MATERIAL_NAME`](super::sky::SKY_MATERIAL_NAME) emitting its
    /// radiosity ([`DaylightSky::facet_radiosities`]), the ground lit by
    /// the sky and `sun_horizontal_lux` (the sun's direct illuminance on
    /// the horizontal, 0 without a sun). Up is the camera's, snapped to an
    /// axis. Fails as [`Scene::add_sky`] does.
    pub fn add_daylight_sky(
        &mut self,
        sky: &DaylightSky,
        sun_horizontal_lux: f64,
    ) -> Result<(), PolygonError> {
        let frame = HorizonFrame::new(self.camera.up, sky.north);
        let ground = sky.horizontal_illuminance() + sun_horizontal_lux;
        let radiosities = sky.facet_radiosities(ground);
        let triangles: Vec<[DVec3; 3]> = dome()
            .into_iter()
            .map(|t| t.map(|v| frame.to_scene(v)))
            .collect();
        let emissions = radiosities.into_iter().map(Rgb::splat).collect();
        let first = self.polygons.len() as u32;
        let centre = self.add_enclosure(triangles, emissions, DAYLIGHT_RADIUS_FACTOR)?;
        self.sky_pattern = Some(SkyPattern {
            sky: *sky,
            frame,
            centre,
            facets: (first, self.polygons.len() as u32),
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The overcast sky of zenith luminance 1.
    fn overcast() -> DaylightSky {
        DaylightSky::new(
            SkyModel::CieOvercast,
            Some(SkyLevel::Zenith(1.0)),
            None,
            0.0,
        )
        .unwrap()
    }

    /// `∫ L cos Z dω` over the upper hemisphere on a fine (Z, azimuth)
    /// grid by the midpoint rule: an integration apart from the dome's.
    fn hemisphere_integral(l: impl Fn(DVec3) -> f64, w: impl Fn(DVec3) -> f64) -> f64 {
        let (nz, na) = (1000, 2000);
        let (dz, da) = (FRAC_PI_2 / nz as f64, 2.0 * PI / na as f64);
        let mut sum = 0.0;
        for i in 0..nz {
            let z = (i as f64 + 0.5) * dz;
            let (sz, cz) = z.sin_cos();
            for j in 0..na {
                let a = (j as f64 + 0.5) * da;
                let d = DVec3::new(sz * a.sin(), sz * a.cos(), cz);
                sum += l(d) * w(d) * sz * dz * da;
            }
        }
        sum
    }

    #[test]
    fn the_dome_splits_at_the_horizon_into_halves() {
        let dome = dome();
        assert_eq!(dome.len(), 80);
        let upper = dome.iter().filter(|t| is_upper(t)).count();
        let lower = dome
            .iter()
            .filter(|t| t.iter().all(|v| v.z <= HORIZON_TOLERANCE))
            .count();
        assert_eq!((upper, lower), (40, 40));
        // Together they cover the sphere once.
        let total: f64 = dome.iter().map(|&[a, b, c]| solid_angle(a, b, c)).sum();
        assert!((total - 4.0 * PI).abs() < 1e-9, "{total}");
        // Still facing the centre.
        for [a, b, c] in &dome {
            assert!((*b - *a).cross(*c - *a).dot(*a + *b + *c) < 0.0);
        }
    }

    #[test]
    fn the_overcast_sky_gives_seven_ninths_pi_lz_and_is_three_times_brighter_at_the_zenith() {
        let sky = overcast();
        let e = sky.horizontal_illuminance();
        assert!((e - 7.0 * PI / 9.0).abs() < 1e-5 * e, "{e}");
        let horizon = sky.luminance(DVec3::X);
        assert!((sky.luminance(DVec3::Z) / horizon - 3.0).abs() < 1e-12);
        // Given as 10,000 lx: Lz = 9 · 10000 / 7π.
        let s = DaylightSky::new(
            SkyModel::CieOvercast,
            Some(SkyLevel::Horizontal(10_000.0)),
            None,
            0.0,
        )
        .unwrap();
        assert!(
            (s.zenith - 90_000.0 / (7.0 * PI)).abs() < 1e-5 * s.zenith,
            "{}",
            s.zenith
        );
        // The default is the same.
        let d = DaylightSky::new(SkyModel::CieOvercast, None, None, 0.0).unwrap();
        assert!((d.zenith - s.zenith).abs() < 1e-9);
    }

    /// Each upper facet emits the sky's power through it: radiosity/π
    /// times its flat area is `∫ L dA` over the flat facet, integrated
    /// here over its spherical triangle instead (`dA = h² dω / cos³θ`,
    /// `h` the plane's distance from the centre, `θ` the direction's angle
    /// to its normal), on pieces of another size. A lower facet is the
    /// ground, a fifth of the illuminance given.
    #[test]
    fn each_facet_emits_the_skys_power_through_it_and_the_ground_is_a_fifth() {
        let sun = SunPosition::from_degrees(135.0, 40.0);
        for model in [SkyModel::CieOvercast, SkyModel::CLEAR, SkyModel::Cie(7)] {
            let sky =
                DaylightSky::new(model, Some(SkyLevel::Zenith(1000.0)), Some(sun), 0.0).unwrap();
            let b = sky.facet_radiosities(5000.0);
            for (t, b) in dome().iter().zip(&b) {
                if !is_upper(t) {
                    assert_eq!(*b, 0.2 * 5000.0);
                    continue;
                }
                let [p, q, r] = *t;
                let cross = (q - p).cross(r - p);
                let (n, area) = (cross.normalize(), cross.length() / 2.0);
                let h = n.dot(p).abs();
                let (mut power, mut covered) = (0.0, 0.0);
                for [u, v, w] in split(*t, FACET_SPLITS + 1) {
                    let d = (u + v + w).normalize();
                    let da = h * h / n.dot(d).abs().powi(3) * solid_angle(u, v, w);
                    power += sky.luminance(d) * da;
                    covered += da;
                }
                assert!((covered - area).abs() < 1e-4 * area, "{covered} vs {area}");
                let emitted = b / PI * area;
                assert!(
                    (emitted - power).abs() < 1e-4 * power,
                    "{}: {emitted} vs {power}",
                    model.name()
                );
            }
        }
    }

    #[test]
    fn the_clear_sky_integrates_as_an_independent_grid_and_gensky_say() {
        for altitude in [10.0f64, 30.0, 45.0, 60.0, 80.0] {
            let sun = SunPosition::from_degrees(200.0, altitude);
            let sky =
                DaylightSky::new(SkyModel::CLEAR, Some(SkyLevel::Zenith(1.0)), Some(sun), 0.0)
                    .unwrap();
            let e = sky.horizontal_illuminance();
            let grid = hemisphere_integral(|d| sky.luminance(d), |d| d.z);
            assert!((e - grid).abs() < 2e-4 * grid, "{altitude}°: {e} vs {grid}");
            // gensky's polynomial fit of E_h f(Zs) φ(0) / Lz
            // (normsc), within the fit's accuracy.
            let x = (altitude.to_radians() - PI / 4.0) / (PI / 4.0);
            let nf = [2.766521, 0.547665, -0.369832, 0.009237, 0.059229];
            let normsc = nf.iter().rev().fold(0.0, |acc, c| acc * x + c);
            let zs = FRAC_PI_2 - altitude.to_radians();
            let f2 = 0.274 * (0.91 + 10.0 * (-3.0 * zs).exp() + 0.45 * zs.cos().powi(2));
            let gensky = normsc / f2;
            assert!(
                (e - gensky).abs() < 0.03 * gensky,
                "{altitude}°: {e} vs gensky {gensky}"
            );
        }
    }

    #[test]
    fn the_general_skies_follow_the_standards_table() {
        // Type 12 is the CIE 1973 clear sky: f(χ) = 0.91 + 10 e^{-3χ} +
        // 0.45 cos²χ, φ(Z) = 1 − e^{−0.32 / cos Z}.
        let sun = SunPosition::from_degrees(90.0, 35.0).direction();
        let d = DVec3::new(0.3, -0.5, 0.6).normalize();
        let f = |chi: f64| 0.91 + 10.0 * (-3.0 * chi).exp() + 0.45 * chi.cos().powi(2);
        let phi = |cz: f64| 1.0 - (-0.32 / cz).exp();
        let want = phi(d.z) * f(d.dot(sun).acos()) / (phi(1.0) * f(sun.z.acos()));
        let got = SkyModel::CLEAR.relative_luminance(d, sun);
        assert!((got - want).abs() < 2e-4 * want, "{got} vs {want}");
        // Types 1, 3 and 5 are the same in every azimuth, the rest not.
        for n in 1..=15u8 {
            assert_eq!(SkyModel::Cie(n).needs_sun(), ![1, 3, 5].contains(&n), "{n}");
            assert!(SkyModel::Cie(n).is_valid());
            assert_eq!(SkyModel::Cie(n).relative_luminance(DVec3::Z, sun), 1.0);
        }
        assert!(!SkyModel::Cie(0).is_valid() && !SkyModel::Cie(16).is_valid());
        // Type 1 brightens towards the zenith as steeply as the standard
        // says: at Z = 60°, (1 + 4 e^{−1.4}) / (1 + 4 e^{−0.7}).
        let z60 = DVec3::new(0.0, (60f64).to_radians().sin(), 0.5);
        let want = (1.0 + 4.0 * (-1.4f64).exp()) / (1.0 + 4.0 * (-0.7f64).exp());
        let got = SkyModel::Cie(1).relative_luminance(z60, sun);
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        // A sun-shaped sky needs the sun.
        assert_eq!(
            DaylightSky::new(SkyModel::Cie(7), None, None, 0.0),
            Err(DaylightError::NoSun("cie:7".into()))
        );
    }

    #[test]
    fn the_clear_sky_defaults_to_genskys_zenith_luminance() {
        let sun = SunPosition::from_degrees(180.0, 45.0);
        let sky = DaylightSky::new(SkyModel::CLEAR, None, Some(sun), 0.0).unwrap();
        let want = ((1.376 * 2.45 - 1.81) * 1.0 + 0.38) * 1000.0;
        assert!((sky.zenith - want).abs() < 1e-9 * want, "{}", sky.zenith);
    }

    #[test]
    fn the_frame_puts_north_where_the_option_says() {
        let f = HorizonFrame::new(Vec3::Y, 0.0);
        assert_eq!((f.up, f.north, f.east), (DVec3::Y, -DVec3::Z, DVec3::X));
        let f = HorizonFrame::new(Vec3::new(0.1, 0.2, 0.9), 0.0);
        assert_eq!((f.up, f.north, f.east), (DVec3::Z, DVec3::Y, DVec3::X));
        // Turned 90° clockwise seen from above: north is the old east.
        let f = HorizonFrame::new(Vec3::Z, FRAC_PI_2);
        assert!(f.north.distance(DVec3::X) < 1e-12 && f.east.distance(-DVec3::Y) < 1e-12);
        let sun = SunPosition::from_degrees(90.0, 0.0).direction();
        assert!(sun.distance(DVec3::X) < 1e-12);
    }
}
