//! The automatic camera of a scene without one: a room is seen from
//! inside, an object from outside.
//!
//! Polygons are one-sided, so where the eye stands decides whether the
//! picture shows anything: the walls of a closed room face inwards, and
//! from outside the room the camera sees only their black backs.
//! [`frame_camera`] therefore looks at the polygons, not only at their
//! bounds.
//!
//! **The rule.** Rays are cast from the centre of the bounds, in
//! [`FRAMING_RAYS`] fixed directions spread evenly over the sphere. When at
//! least [`ROOM_MIN_FRONT_FRACTION`] of them first hit a front face, the
//! centre is enclosed by surfaces facing it: the scene is a *room*. When
//! a ray from the centre hits a back face, the centre is inside (or
//! behind) something, a piece of furniture say, and the next of six more
//! points, moved from the centre by [`ROOM_PROBE_OFFSET`] of the size
//! along each axis, is asked instead; the first that sees no back face
//! decides. An object seen from its inside shows back faces wherever it
//! is asked, and from outside most rays miss it, so it stays an *object*;
//! so does an open box (a Cornell box), whose opening takes about a sixth
//! of the rays from its middle.
//!
//! - An **open box** is an object whose middle sees no back face, front
//!   faces in at least [`OPEN_BOX_MIN_FRONT_FRACTION`] of the rays, and
//!   the rest leave through one side: the mean direction of the rays that
//!   leave lies within 60° ([`OPEN_SIDE_MIN_ALIGNMENT`]) of a horizontal
//!   axis (±x, ±z). The camera stands on that side, as far as
//!   [`Camera::frame`] would, and looks in: a Cornell box exported open
//!   towards +z (McGuire's) is looked into, not at its closed back.
//! - Any other **object** gets [`Camera::frame`] of its bounds, unchanged
//!   (from the −z side, looking along +z); so does an open box whose
//!   opening faces −z, the bundled Cornell box's.
//! - A **room** gets an eye inside. The candidates, in order of preference,
//!   stand [`EYE_ALONG_FRACTIONS`] of the way along the longest horizontal
//!   axis (x or z; z when they tie), at [`EYE_HEIGHT_FRACTIONS`] of the
//!   height (up is +y) and [`EYE_ACROSS_FRACTIONS`] of the way across. The
//!   first candidate that is *free*
//!   is taken: every ray's nearest hit is a front face (no back face: the
//!   eye is not inside furniture), none nearer than
//!   [`EYE_CLEARANCE_FRACTION`] of the bounds' smallest side, and the view
//!   straight ahead is open for that distance too. When none is free, the
//!   point that made the scene a room is taken. The camera looks
//!   horizontally along the long axis towards its far end (+x or +z), with
//!   up +y, the wider field of view [`ROOM_FOV_DEG`] and the default
//!   picture size.
//!
//! Where a face and its back copy (or a face written twice, once each
//! way) lie in one plane, a ray sees the side that faces it.
//!
//! **Rooms that hold the lights.** The loaders frame a scene before
//! `--emit` and the repair passes, when an OBJ room modelled with its
//! faces pointing out (a scaled cube in Blender) shows only back faces
//! from inside and is framed from outside, where its outer walls get no
//! light. Once the lights are set and the back copies made, the run asks
//! [`Scene::frame_inside_lights`]: when the rays from one of the lights
//! ([`LIGHTS_PROBED`] at most, the most powerful) nearly all hit a surface
//! and those from the automatic eye do not, the eye stands outside the
//! closed surface that holds the lights, and the scene is framed again:
//! its back copies now face in, so it is a room, seen from inside. The
//! same test names that reason when a picture comes out dark
//! ([`Scene::eye_outside_lights`]).
//!
//! An explicit camera (in the file, or `--camera`) never comes here.

use super::{polygon_bounds, Polygon, Scene};
use crate::camera::{Camera, DEFAULT_SIZE};
use glam::{DVec3, Vec3};

/// Number of fixed ray directions cast from each candidate eye point: a
/// Fibonacci spiral over the sphere, a few dozen so that the test costs
/// little beside loading, yet a door or a window is seen as a few misses.
pub const FRAMING_RAYS: usize = 64;

/// The fraction of [`FRAMING_RAYS`] that must first hit a front face from
/// some candidate point for the scene to count as a room (dimensionless).
///
/// 0.9 lets a closed room have an opening or two (a door, a window: each
/// ray that leaves is a miss), while a box with a whole side missing (a
/// Cornell box, which is meant to be looked into from outside) sees about a
/// sixth of the rays leave and stays an object.
pub const ROOM_MIN_FRONT_FRACTION: f64 = 0.9;

/// The fraction of [`FRAMING_RAYS`] from the middle of an object that must
/// hit a front face (and none a back face) for it to be an open box
/// (dimensionless): a box missing one side sends about five sixths of its
/// rays to its inside, an object seen from outside sends none there.
pub const OPEN_BOX_MIN_FRONT_FRACTION: f64 = 0.5;

/// The least cosine between the mean direction of the rays that leave an
/// open box and the horizontal axis chosen as its open side
/// (dimensionless, 0.5 = 60°): below it the opening is up, down or spread
/// round, and the box is framed as any object.
pub const OPEN_SIDE_MIN_ALIGNMENT: f64 = 0.5;

/// Vertical field of view of a camera inside a room, in degrees: wider
/// than [`crate::camera::DEFAULT_FOV_DEG`] so that a room seen from near
/// one end shows its side walls, floor and ceiling (about 80° across in the
/// default 4:3 picture).
pub const ROOM_FOV_DEG: f32 = 65.0;

/// Candidate eye positions along the longest horizontal axis, as fractions
/// of the bounds from its near end, in order of preference: near the end
/// wall (seeing most of the room), then further in, then the middle.
pub const EYE_ALONG_FRACTIONS: [f64; 3] = [0.1, 0.25, 0.5];

/// Candidate eye heights as fractions of the bounds' height (+y), in order
/// of preference: 0.6 is standing eye height (1.6 m) in a room 2.7 m high,
/// and needs no knowledge of the scene's units.
pub const EYE_HEIGHT_FRACTIONS: [f64; 3] = [0.6, 0.75, 0.45];

/// Candidate eye positions across the room (the other horizontal axis), as
/// fractions of the bounds, in order of preference: the middle, then to
/// either side of something standing there.
pub const EYE_ACROSS_FRACTIONS: [f64; 3] = [0.5, 0.3, 0.7];

/// A free eye keeps at least this fraction of the bounds' smallest side
/// (usually the room's height) between itself and every surface its rays
/// hit, and as much open view straight ahead (dimensionless).
pub const EYE_CLEARANCE_FRACTION: f64 = 0.1;

/// Where the room test looks from when the centre of the bounds is inside
/// something: the centre moved by this fraction of the bounds' size along
/// each axis, either way (dimensionless). Small, so that the probes stay
/// in the middle of the room.
pub const ROOM_PROBE_OFFSET: f64 = 0.125;

/// A ray's hit point counts as inside a polygon when it is outside an edge
/// by at most this fraction of the scene's diagonal (dimensionless), so
/// that rays through a shared edge or corner do not leak between polygons.
pub const RAY_EDGE_TOLERANCE: f64 = 1e-7;

/// A ray this close to parallel to a polygon's plane (the cosine between
/// the ray and the normal) misses it: the polygon is seen edge-on.
pub const RAY_PARALLEL_COSINE: f64 = 1e-12;

/// The steps between consecutive rays in the Fibonacci spiral's order
/// (coprime with [`FRAMING_RAYS`]), so that the first rays cast are spread
/// over the sphere and a point that is not enclosed is found out early.
const RAY_ORDER_STRIDE: usize = 29;

/// The camera of a scene without one: from inside when the polygons form
/// a room, else [`Camera::frame`] of their bounds (see the module's rule).
///
/// The object case is bit-for-bit [`Camera::frame`], so pictures of
/// objects are what they were before rooms were recognised. The result is
/// always a valid camera (it passes [`Camera::check`]).
pub fn frame_camera(polygons: &[Polygon]) -> Camera {
    let (lo, hi) = polygon_bounds(polygons);
    room_camera(polygons, lo, hi)
        .or_else(|| open_box_camera(polygons, lo, hi))
        .unwrap_or_else(|| Camera::frame(lo, hi))
}

/// The horizontal axis (a unit ±x or ±z) through which the middle of an
/// open box sees out, or `None` when the polygons are no open box (see the
/// module's rule).
fn open_side(polygons: &[Polygon], lo: Vec3, hi: Vec3) -> Option<DVec3> {
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let size = hi - lo;
    if !(size.min_element() > 0.0 && size.is_finite()) {
        return None;
    }
    let edge_tol = RAY_EDGE_TOLERANCE * size.length();
    let centre = 0.5 * (lo + hi);
    let mut front = 0usize;
    let mut out = DVec3::ZERO;
    for d in directions() {
        match nearest_hit(polygons, centre, d, edge_tol) {
            Some(hit) if hit.front => front += 1,
            // Inside something, or looking at an object's inside.
            Some(_) => return None,
            None => out += d,
        }
    }
    if (front as f64) < OPEN_BOX_MIN_FRONT_FRACTION * FRAMING_RAYS as f64 {
        return None;
    }
    let mean = out.try_normalize()?;
    let axis = if mean.x.abs() > mean.z.abs() {
        DVec3::X * mean.x.signum()
    } else {
        DVec3::Z * mean.z.signum()
    };
    (axis.dot(mean) >= OPEN_SIDE_MIN_ALIGNMENT).then_some(axis)
}

/// The camera outside an open box's open side, looking in, or `None` when
/// it is no open box or its opening faces −z (then [`Camera::frame`] is
/// that camera already, bit for bit).
fn open_box_camera(polygons: &[Polygon], lo: Vec3, hi: Vec3) -> Option<Camera> {
    let side = open_side(polygons, lo, hi)?;
    if side == DVec3::NEG_Z {
        return None;
    }
    // As Camera::frame, turned to the open side.
    let framed = Camera::frame(lo, hi);
    let centre = framed.lookat.as_dvec3();
    let radius = 0.5 * (hi - lo).as_dvec3().length();
    let distance = (radius / (0.5 * f64::from(framed.fov_y)).sin())
        .max(centre.dot(side).abs() * crate::camera::FRAME_MIN_RELATIVE_DISTANCE);
    let camera = Camera {
        eye: (centre + side * distance).as_vec3(),
        ..framed
    };
    camera.check().ok().map(|_| camera)
}

/// What the rays from one point first hit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Survey {
    /// Rays whose nearest hit is a front face.
    front: usize,
    /// Rays whose nearest hit is a back face.
    back: usize,
    /// Rays that hit nothing.
    miss: usize,
    /// Distance to the nearest hit of any ray, scene units (infinite when
    /// nothing was hit).
    nearest: f64,
}

/// The nearest polygon a ray hits: its distance and whether its front
/// faces the ray's origin.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Hit {
    t: f64,
    front: bool,
}

/// The ray directions, unit vectors, in the order they are cast.
fn directions() -> Vec<DVec3> {
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..FRAMING_RAYS)
        .map(|k| {
            let i = (k * RAY_ORDER_STRIDE) % FRAMING_RAYS;
            let z = 1.0 - (2 * i + 1) as f64 / FRAMING_RAYS as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden_angle * i as f64;
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// Where the ray `origin + t * dir` meets polygon `p`: its `t > 0`, or
/// `None` when it misses it, runs parallel to its plane (within
/// [`RAY_PARALLEL_COSINE`]) or meets it behind the origin. A hit outside
/// an edge by at most `edge_tol` (scene units) counts, so that rays
/// through a shared edge do not leak between polygons.
pub(super) fn ray_polygon_hit(
    p: &Polygon,
    origin: DVec3,
    dir: DVec3,
    edge_tol: f64,
) -> Option<f64> {
    let n = p.normal.as_dvec3();
    let cosine = n.dot(dir);
    if cosine.abs() < RAY_PARALLEL_COSINE {
        return None;
    }
    let first = p.vertices.first()?;
    let t = n.dot(first.as_dvec3() - origin) / cosine;
    // Also refuses a NaN `t` (a degenerate polygon).
    if t.is_nan() || t <= 0.0 {
        return None;
    }
    let x = origin + t * dir;
    let k = p.vertices.len();
    let inside = (0..k).all(|j| {
        let a = p.vertices[j].as_dvec3();
        let b = p.vertices[(j + 1) % k].as_dvec3();
        let edge = b - a;
        // Counter-clockwise from the front: inside is to the left.
        edge.cross(x - a).dot(n) >= -edge_tol * edge.length()
    });
    inside.then_some(t)
}

/// The nearest polygon hit by the ray `origin + t * dir`, `t > 0`
/// (brute force: the scene sits below the BVH in the crate).
fn nearest_hit(polygons: &[Polygon], origin: DVec3, dir: DVec3, edge_tol: f64) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    // The sky encloses everything: it is no wall of a room.
    for p in polygons.iter().filter(|p| !p.surface.sky) {
        let Some(t) = ray_polygon_hit(p, origin, dir, edge_tol) else {
            continue;
        };
        let front = p.normal.as_dvec3().dot(dir) < 0.0;
        // A face and its back copy (or a face written twice, once each
        // way) lie in one plane: within the tolerance, the side facing the
        // ray is the one seen.
        let nearer = match best {
            None => true,
            Some(b) if (t - b.t).abs() <= edge_tol && front != b.front => front,
            Some(b) => t < b.t,
        };
        if nearer {
            best = Some(Hit { t, front });
        }
    }
    best
}

/// Casts the framing rays from `origin`; stops early (with a partial
/// count) once more than `max_bad` rays missed or hit a back face.
fn survey(
    polygons: &[Polygon],
    origin: DVec3,
    dirs: &[DVec3],
    max_bad: usize,
    edge_tol: f64,
) -> Survey {
    let mut s = Survey {
        nearest: f64::INFINITY,
        ..Survey::default()
    };
    for &d in dirs {
        match nearest_hit(polygons, origin, d, edge_tol) {
            Some(hit) => {
                s.nearest = s.nearest.min(hit.t);
                if hit.front {
                    s.front += 1;
                } else {
                    s.back += 1;
                }
            }
            None => s.miss += 1,
        }
        if s.back + s.miss > max_bad {
            break;
        }
    }
    s
}

/// The rays that must hit a front face for a room:
/// `ceil(ROOM_MIN_FRONT_FRACTION * FRAMING_RAYS)`.
fn front_rays_needed() -> usize {
    (ROOM_MIN_FRONT_FRACTION * FRAMING_RAYS as f64).ceil() as usize
}

/// The eye point and the horizontal axis to look along (a unit vector, +x
/// or +z) when the polygons form a room; `None` for an object.
fn room_eye(polygons: &[Polygon], lo: Vec3, hi: Vec3) -> Option<(DVec3, DVec3)> {
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let size = hi - lo;
    // A room encloses a volume: flat or non-finite bounds are no room.
    if !(size.min_element() > 0.0 && size.is_finite()) {
        return None;
    }
    let (along, across) = if size.x > size.z {
        (DVec3::X, DVec3::Z)
    } else {
        (DVec3::Z, DVec3::X)
    };
    let edge_tol = RAY_EDGE_TOLERANCE * size.length();
    let clearance = EYE_CLEARANCE_FRACTION * size.min_element();
    let dirs = directions();
    let needed = front_rays_needed();
    let max_bad = FRAMING_RAYS - needed;
    let at = |fa: f64, fh: f64, fc: f64| lo + size * (along * fa + DVec3::Y * fh + across * fc);
    // Is it a room? Judged from the middle, where a closed room shows
    // front faces all round and an open box shows its opening.
    let centre = 0.5 * (lo + hi);
    let mut probes = vec![centre];
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        for sign in [1.0, -1.0] {
            probes.push(centre + sign * ROOM_PROBE_OFFSET * size * axis);
        }
    }
    // The first probe that is not inside (or behind) something decides.
    let (room_point, s) = probes
        .into_iter()
        .map(|p| (p, survey(polygons, p, &dirs, max_bad, edge_tol)))
        .find(|(_, s)| s.back == 0)?;
    if s.front < needed {
        return None;
    }

    // Where to stand in it.
    let mut candidates = Vec::new();
    for &fa in &EYE_ALONG_FRACTIONS {
        for &fh in &EYE_HEIGHT_FRACTIONS {
            for &fc in &EYE_ACROSS_FRACTIONS {
                candidates.push(at(fa, fh, fc));
            }
        }
    }
    let free = |eye: DVec3| {
        let s = survey(polygons, eye, &dirs, max_bad, edge_tol);
        let ahead_open = match nearest_hit(polygons, eye, along, edge_tol) {
            Some(hit) => hit.front && hit.t >= clearance,
            None => true,
        };
        s.front >= needed && s.back == 0 && s.nearest >= clearance && ahead_open
    };
    let eye = candidates
        .into_iter()
        .find(|&e| free(e))
        .unwrap_or(room_point);
    Some((eye, along))
}

/// The camera inside a room (see the module's rule), or `None` when the
/// polygons are no room or the camera would not pass [`Camera::check`]
/// (a room so small against its distance from the origin that `f32`
/// rounding merges the eye and the look-at point).
fn room_camera(polygons: &[Polygon], lo: Vec3, hi: Vec3) -> Option<Camera> {
    let (eye, along) = room_eye(polygons, lo, hi)?;
    // Towards the far end of the long axis, at the eye's height.
    let to_far_end = along.dot(hi.as_dvec3() - eye);
    let camera = Camera {
        eye: eye.as_vec3(),
        lookat: (eye + along * to_far_end).as_vec3(),
        up: Vec3::Y,
        fov_y: ROOM_FOV_DEG.to_radians(),
        width: DEFAULT_SIZE.0,
        height: DEFAULT_SIZE.1,
    };
    camera.check().ok().map(|_| camera)
}

/// How far in front of an emitting polygon the point that stands for its
/// light lies, as a fraction of the scene's diagonal (dimensionless):
/// off the polygon's plane, so that its own rays do not graze it, and
/// still inside whatever holds the lamp.
pub const LIGHT_POINT_OFFSET: f64 = 1e-4;

/// At most this many emitting polygons, the most powerful first, are asked
/// whether a closed surface holds them: each costs one survey of
/// [`FRAMING_RAYS`] rays against every polygon.
pub const LIGHTS_PROBED: usize = 4;

/// Whether most rays from `point` hit some polygon, from either side:
/// at least [`ROOM_MIN_FRONT_FRACTION`] of them, as for a room. Stops at
/// the first miss too many.
fn enclosed(polygons: &[Polygon], point: DVec3, edge_tol: f64) -> bool {
    let max_miss = FRAMING_RAYS - front_rays_needed();
    let mut misses = 0;
    for d in directions() {
        if nearest_hit(polygons, point, d, edge_tol).is_none() {
            misses += 1;
            if misses > max_miss {
                return false;
            }
        }
    }
    true
}

impl Scene {
    /// The points that stand for the scene's lights: in front of the
    /// centre of each emitting polygon (the sky's facets left out), by
    /// [`LIGHT_POINT_OFFSET`], the [`LIGHTS_PROBED`] most powerful ones.
    fn light_points(&self) -> Vec<DVec3> {
        let diagonal = f64::from(self.extent()).max(f64::MIN_POSITIVE);
        let mut lights: Vec<(f64, DVec3)> = self
            .polygons
            .iter()
            .filter(|p| !p.surface.sky)
            .filter_map(|p| {
                let power = self.materials[p.material.index()].emission().luminance() * p.area;
                let centre = p.vertices.iter().map(|v| v.as_dvec3()).sum::<DVec3>()
                    / p.vertices.len().max(1) as f64;
                let point = centre + p.normal.as_dvec3() * LIGHT_POINT_OFFSET * diagonal;
                (power > 0.0 && point.is_finite()).then_some((power, point))
            })
            .collect();
        lights.sort_by(|a, b| b.0.total_cmp(&a.0));
        lights.truncate(LIGHTS_PROBED);
        lights.into_iter().map(|(_, point)| point).collect()
    }

    /// True when `eye` stands outside a closed surface that holds the
    /// lights: the rays from some light (a point just in front of one of
    /// the [`LIGHTS_PROBED`] most powerful emitting polygons) nearly
    /// all hit a surface (as a room's do, [`ROOM_MIN_FRONT_FRACTION`]) and
    /// those from the eye do not. A camera there sees the unlit outside of
    /// the room, or nothing.
    pub fn eye_outside_lights(&self, eye: Vec3) -> bool {
        let (lo, hi) = self.bounds();
        let edge_tol = RAY_EDGE_TOLERANCE * (hi - lo).as_dvec3().length();
        let polygons = &self.polygons;
        let lights = self.light_points();
        !lights.is_empty()
            && !enclosed(polygons, eye.as_dvec3(), edge_tol)
            && lights.iter().any(|&l| enclosed(polygons, l, edge_tol))
    }

    /// Frames the camera again ([`frame_camera`]) when it was framed
    /// automatically and stands outside a closed surface that holds the
    /// lights ([`Scene::eye_outside_lights`]); true when the camera moved.
    ///
    /// For the scene after the repair passes: a room modelled with its
    /// faces pointing out (a scaled cube in Blender) is only a room once
    /// its faces have their back copies facing in, and only the lights,
    /// set by `--emit`, say that its inside is what is to be seen (a
    /// closed car body, or a house seen from the street, with no light
    /// inside, keeps the camera outside).
    pub fn frame_inside_lights(&mut self) -> bool {
        if self.camera_source != super::CameraSource::AutoFramed
            || !self.eye_outside_lights(self.camera.eye)
        {
            return false;
        }
        let camera = frame_camera(&self.polygons);
        if camera == self.camera || self.eye_outside_lights(camera.eye) {
            return false;
        }
        self.camera = camera;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{cuboid, polygon};

    fn room() -> Vec<Polygon> {
        cuboid([0.0, 0.0, 0.0], [6.0, 2.7, 4.0], true)
    }

    /// The fraction of the framing rays from `eye` that first hit a front
    /// face, casting them all.
    fn front_fraction(polygons: &[Polygon], eye: Vec3) -> f64 {
        let s = survey(
            polygons,
            eye.as_dvec3(),
            &directions(),
            FRAMING_RAYS,
            RAY_EDGE_TOLERANCE,
        );
        s.front as f64 / FRAMING_RAYS as f64
    }

    fn inside(p: Vec3, lo: Vec3, hi: Vec3) -> bool {
        p.cmpgt(lo).all() && p.cmplt(hi).all()
    }

    #[test]
    fn directions_are_unit_and_spread() {
        let d = directions();
        assert_eq!(d.len(), FRAMING_RAYS);
        for v in &d {
            assert!((v.length() - 1.0).abs() < 1e-12);
        }
        // Every octant gets some rays, and they average out near zero.
        let mean: DVec3 = d.iter().sum::<DVec3>() / d.len() as f64;
        assert!(mean.length() < 0.05, "{mean}");
        let mut octants = [0; 8];
        for v in &d {
            let o =
                usize::from(v.x > 0.0) + 2 * usize::from(v.y > 0.0) + 4 * usize::from(v.z > 0.0);
            octants[o] += 1;
        }
        assert!(octants.iter().all(|&n| n >= 4), "{octants:?}");
    }

    #[test]
    fn an_inward_box_is_a_room_seen_from_inside() {
        let polygons = room();
        let (lo, hi) = polygon_bounds(&polygons);
        let c = frame_camera(&polygons);
        assert!(inside(c.eye, lo, hi), "{c:?}");
        assert_eq!(c.fov_y, ROOM_FOV_DEG.to_radians());
        assert_eq!(c.up, Vec3::Y);
        // The long horizontal axis is x: looking along +x, level.
        let forward = (c.lookat - c.eye).normalize();
        assert!((forward - Vec3::X).length() < 1e-6, "{forward}");
        // The first choice: near the end wall, standing height, middle.
        assert!((c.eye - Vec3::new(0.6, 0.6 * 2.7, 2.0)).length() < 1e-5);
        assert_eq!(front_fraction(&polygons, c.eye), 1.0);
        assert!(c.check().is_ok());
    }

    #[test]
    fn an_outward_box_is_an_object_framed_as_before() {
        let polygons = cuboid([0.0, 0.0, 0.0], [6.0, 2.7, 4.0], false);
        let (lo, hi) = polygon_bounds(&polygons);
        // Bit for bit the bounds' framing.
        assert_eq!(frame_camera(&polygons), Camera::frame(lo, hi));
        // From its centre, an object shows back faces.
        assert_eq!(front_fraction(&polygons, 0.5 * (lo + hi)), 0.0);
    }

    #[test]
    fn open_and_flat_scenes_are_objects() {
        // A box missing its -z wall (a Cornell box) is looked into from
        // outside, as before.
        let mut open = room();
        open.retain(|p| p.normal.z <= 0.5);
        assert_eq!(open.len(), 5);
        let (lo, hi) = polygon_bounds(&open);
        assert_eq!(frame_camera(&open), Camera::frame(lo, hi));
        // The same with a cube, the Cornell box's shape.
        let mut cube = cuboid([0.0, 0.0, 0.0], [5.5, 5.5, 5.5], true);
        cube.retain(|p| p.normal.z <= 0.5);
        let (lo, hi) = polygon_bounds(&cube);
        assert_eq!(frame_camera(&cube), Camera::frame(lo, hi));
        // One square: flat bounds.
        let square = vec![polygon(
            0,
            &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
        )];
        let (lo, hi) = polygon_bounds(&square);
        assert_eq!(frame_camera(&square), Camera::frame(lo, hi));
        // Nothing at all.
        assert_eq!(frame_camera(&[]), Camera::frame(Vec3::ZERO, Vec3::ZERO));
    }

    #[test]
    fn an_open_box_is_looked_into_through_its_open_side() {
        let lo = Vec3::new(-1.0, 0.0, -1.0);
        let hi = Vec3::new(1.0, 2.0, 1.0);
        for (open_side, normal_away) in [
            (DVec3::Z, Vec3::Z),
            (DVec3::NEG_Z, Vec3::NEG_Z),
            (DVec3::X, Vec3::X),
            (DVec3::NEG_X, Vec3::NEG_X),
        ] {
            // Inward walls; the wall on the open side (its inward normal
            // points away from that side) is left out.
            let mut walls = cuboid(lo.into(), hi.into(), true);
            walls.retain(|p| p.normal.dot(normal_away) > -0.5);
            assert_eq!(walls.len(), 5);
            let camera = frame_camera(&walls);
            let framed = Camera::frame(lo, hi);
            if open_side == DVec3::NEG_Z {
                assert_eq!(camera, framed, "the old framing, bit for bit");
                continue;
            }
            let eye = camera.eye.as_dvec3();
            let centre = 0.5 * (lo + hi).as_dvec3();
            assert_eq!(camera.lookat, framed.lookat);
            assert_eq!(camera.fov_y, framed.fov_y);
            let off = eye - centre;
            // As far away as the default framing, on the open side.
            let default_distance = (framed.eye - framed.lookat).length() as f64;
            assert!((off.length() / default_distance - 1.0).abs() < 1e-6);
            assert!(
                off.normalize().dot(open_side) > 1.0 - 1e-9,
                "{open_side}: {off}"
            );
            // Looking in, the eye sees the inside of the far wall: a front face.
            let hit = nearest_hit(&walls, eye, -off.normalize(), RAY_EDGE_TOLERANCE);
            assert!(hit.is_some_and(|h| h.front), "{open_side}: {hit:?}");
        }
        // Open upwards: no horizontal side, the default framing.
        let mut tray = cuboid(lo.into(), hi.into(), true);
        tray.retain(|p| p.normal.y > -0.5);
        assert_eq!(frame_camera(&tray), Camera::frame(lo, hi));
    }

    #[test]
    fn the_bundled_cornell_box_keeps_its_old_framing() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.sc");
        let scene = crate::scene::load(&path).expect("the bundled Cornell box loads");
        let (lo, hi) = scene.bounds();
        assert_eq!(frame_camera(&scene.polygons), Camera::frame(lo, hi));
    }

    #[test]
    fn a_room_with_one_window_is_still_a_room() {
        // A 2 x 1.5 hole in the far +x wall, made by building that wall
        // from four panels around it.
        let mut polygons = room();
        polygons.retain(|p| p.normal.x >= -0.5);
        let x = 6.0;
        let panel = |y0: f32, y1: f32, z0: f32, z1: f32| {
            // Facing -x (inwards): counter-clockwise seen from -x.
            polygon(0, &[[x, y0, z0], [x, y0, z1], [x, y1, z1], [x, y1, z0]])
        };
        polygons.push(panel(0.0, 0.8, 0.0, 4.0));
        polygons.push(panel(2.3, 2.7, 0.0, 4.0));
        polygons.push(panel(0.8, 2.3, 0.0, 1.0));
        polygons.push(panel(0.8, 2.3, 3.0, 4.0));
        assert_eq!(polygons.len(), 9);
        let (lo, hi) = polygon_bounds(&polygons);
        let c = frame_camera(&polygons);
        assert!(inside(c.eye, lo, hi), "{c:?}");
        assert_eq!(c.fov_y, ROOM_FOV_DEG.to_radians());
    }

    #[test]
    fn a_room_with_a_table_puts_the_eye_in_a_free_spot() {
        let mut polygons = room();
        // A table top slab right where the first choice of eye would
        // stand (x 0.6, y 1.62, z 2), and a tall cupboard at the second.
        polygons.extend(cuboid([0.2, 1.4, 1.5], [1.2, 1.8, 2.5], false));
        polygons.extend(cuboid([0.2, 0.0, 0.8], [1.2, 2.6, 1.6], false));
        let (lo, hi) = polygon_bounds(&polygons);
        let c = frame_camera(&polygons);
        assert!(inside(c.eye, lo, hi), "{c:?}");
        // Not inside either piece of furniture, and every ray sees a
        // front face, none closer than the clearance.
        let s = survey(
            &polygons,
            c.eye.as_dvec3(),
            &directions(),
            FRAMING_RAYS,
            RAY_EDGE_TOLERANCE,
        );
        assert_eq!(s.front, FRAMING_RAYS, "{s:?}");
        assert!(s.nearest >= EYE_CLEARANCE_FRACTION * 2.7 - 1e-6, "{s:?}");
        assert!((c.lookat - c.eye).normalize().dot(Vec3::X) > 0.999);
    }

    #[test]
    fn a_room_with_furniture_in_its_middle_is_still_a_room() {
        let mut polygons = room();
        polygons.extend(cuboid([2.5, 0.0, 1.5], [3.5, 1.6, 2.5], false));
        let (lo, hi) = polygon_bounds(&polygons);
        let c = frame_camera(&polygons);
        assert_eq!(c.fov_y, ROOM_FOV_DEG.to_radians());
        assert!(inside(c.eye, lo, hi), "{c:?}");
    }

    #[test]
    fn a_deep_room_looks_along_z() {
        let polygons = cuboid([-2.0, 0.0, -5.0], [2.0, 3.0, 5.0], true);
        let c = frame_camera(&polygons);
        let forward = (c.lookat - c.eye).normalize();
        assert!((forward - Vec3::Z).length() < 1e-6, "{forward}");
        assert!(c.eye.z < -3.0, "{c:?}");
    }

    #[test]
    fn framed_rooms_pass_the_check_even_when_tiny_and_far() {
        let far = 1e7;
        let polygons = cuboid([0.0, 0.0, far], [1e-3, 1e-3, far + 1e-3], true);
        let c = frame_camera(&polygons);
        assert!(c.check().is_ok(), "{c:?}");
    }
}
