//! Camera controls for the window: look around from the eye, orbit around
//! a point (the surface under the cursor, or the look-at point), move
//! towards a point and stop in front of it, walk, and reset. Pure geometry
//! on a [`Camera`], so it is tested without a window.
//!
//! Orbiting is scaled to the scene ([`CameraControl::orbit_per_pixel`]):
//! around an object seen from outside, a drag across a 640-pixel window
//! turns the eye by about 290°; inside a room (the eye within the scene's
//! bounds, [`CameraControl::within`]) the eye moves by a fixed share of the
//! room's size per pixel, and an orbit, a walk, a zoom or a move towards
//! the cursor stops short of the room's walls, floor and ceiling rather
//! than take the eye out of the room.

use crate::scene::Camera;
use glam::{Quat, Vec3};

/// Closest the eye may come to the look-at point, as a fraction of the
/// scene camera's distance: zooming never passes (or reaches) the point.
pub const MIN_DISTANCE_FRACTION: f32 = 0.02;
/// Farthest the eye may go, as a multiple of the scene camera's distance.
pub const MAX_DISTANCE_FACTOR: f32 = 50.0;
/// Smallest angle, in radians, kept between the view direction and the up
/// direction when orbiting, so the view never flips over the pole.
pub const POLE_MARGIN: f32 = 0.02;

/// Radians of orbit per pixel of drag around an object seen from outside
/// (and the most anywhere).
pub const ORBIT_PER_PIXEL: f32 = 0.008;

/// Inside a room, how far the eye moves per pixel of orbit drag, as a
/// fraction of the room's smallest side (usually its height): on the
/// bundled `rtable` (3 high) around a point of the table top 2.5 away, a
/// 200-pixel drag turns the eye by about 40°, where [`ORBIT_PER_PIXEL`]
/// would turn it by 92° and lift it through the ceiling.
pub const ROOM_ORBIT_TRAVEL_PER_PIXEL: f32 = 0.003;

/// How close an orbit inside a room lets the eye come to the room's
/// bounds, as a fraction of their smallest side: it stops there, inside.
pub const ROOM_WALL_MARGIN: f32 = 0.02;

/// Halvings of an orbit that would leave the room, to find how much of it
/// keeps the eye inside (the last one is `2^-16` of the drag).
const ORBIT_CLAMP_STEPS: u32 = 16;

/// The window's camera: starts as the scene's camera and moves with input.
///
/// Invariants: `eye != lookat`; the view direction is never parallel to
/// `up`; `up`, the field of view and the picture size never change; a
/// move (orbit, walk, zoom, dolly) that starts with the eye inside the
/// room ([`CameraControl::within`]) ends with it inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraControl {
    home: Camera,
    camera: Camera,
    /// The scene's bounds `(min, max)` in scene units, when known.
    room: Option<(Vec3, Vec3)>,
}

impl CameraControl {
    /// Controls starting at (and resetting to) `home`.
    pub fn new(home: Camera) -> Self {
        CameraControl {
            home,
            camera: home,
            room: None,
        }
    }

    /// The same controls, told the scene's bounds `lo..hi` (scene units):
    /// with the eye inside them the scene is a room, and orbits are scaled
    /// and kept inside it.
    pub fn within(mut self, lo: Vec3, hi: Vec3) -> Self {
        let ok = lo.is_finite() && hi.is_finite() && (hi - lo).min_element() > 0.0;
        self.room = ok.then_some((lo, hi));
        self
    }

    /// The room the eye stands in, shrunk by the margin it keeps from the
    /// walls: the scene's bounds less [`ROOM_WALL_MARGIN`] (or, for an eye
    /// already nearer a wall, the bounds themselves); `None` when the eye
    /// is outside the bounds or they are unknown.
    fn room_around_eye(&self) -> Option<(Vec3, Vec3)> {
        let (lo, hi) = self.room?;
        let eye = self.camera.eye;
        let inside = |(a, b): (Vec3, Vec3)| eye.cmpgt(a).all() && eye.cmplt(b).all();
        let margin = Vec3::splat(ROOM_WALL_MARGIN * (hi - lo).min_element());
        let shrunk = (lo + margin, hi - margin);
        if inside(shrunk) {
            Some(shrunk)
        } else {
            inside((lo, hi)).then_some((lo, hi))
        }
    }

    /// The share in `[0, 1]` of a straight move of the eye by `delta`
    /// (scene units) that keeps it in the room it stands in: the move
    /// stops at the room's bounds less [`ROOM_WALL_MARGIN`], and an eye
    /// already within that margin of a wall moves no nearer to it. 1 when
    /// the eye is not in a room ([`CameraControl::room_around_eye`]).
    fn share_inside(&self, delta: Vec3) -> f32 {
        let (Some((lo, hi)), Some(_)) = (self.room, self.room_around_eye()) else {
            return 1.0;
        };
        let margin = Vec3::splat(ROOM_WALL_MARGIN * (hi - lo).min_element());
        let (lo, hi) = (lo + margin, hi - margin);
        let eye = self.camera.eye;
        let mut share = 1.0f32;
        for axis in 0..3 {
            let d = delta[axis];
            let room = if d > 0.0 {
                hi[axis] - eye[axis]
            } else if d < 0.0 {
                lo[axis] - eye[axis]
            } else {
                continue;
            };
            share = share.min((room / d).max(0.0));
        }
        share.clamp(0.0, 1.0)
    }

    /// Moves eye and look-at point together by `delta`, or by as much of
    /// it as keeps the eye in its room.
    fn shift(&mut self, delta: Vec3) {
        let delta = delta * self.share_inside(delta);
        if delta.is_finite() {
            self.camera.eye += delta;
            self.camera.lookat += delta;
        }
    }

    /// Radians of orbit per pixel of drag around `pivot` (scene units):
    /// [`ORBIT_PER_PIXEL`], or inside a room less, so that the eye moves
    /// [`ROOM_ORBIT_TRAVEL_PER_PIXEL`] of the room's smallest side per
    /// pixel at its distance from the pivot.
    pub fn orbit_per_pixel(&self, pivot: Vec3) -> f32 {
        let Some((lo, hi)) = self.room.filter(|_| self.room_around_eye().is_some()) else {
            return ORBIT_PER_PIXEL;
        };
        let radius = self.camera.eye.distance(pivot);
        let scaled = ROOM_ORBIT_TRAVEL_PER_PIXEL * (hi - lo).min_element() / radius;
        if scaled.is_finite() {
            scaled.min(ORBIT_PER_PIXEL)
        } else {
            ORBIT_PER_PIXEL
        }
    }

    /// The current camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Back to the scene's camera.
    pub fn reset(&mut self) {
        self.camera = self.home;
    }

    /// The scene camera's distance from its eye to its look-at point, in
    /// scene units: the scale movements are measured in.
    pub fn home_distance(&self) -> f32 {
        self.home.eye.distance(self.home.lookat)
    }

    /// Distance from the eye to the look-at point, in scene units.
    pub fn distance(&self) -> f32 {
        self.camera.eye.distance(self.camera.lookat)
    }

    /// Turns the eye around the look-at point: `yaw` radians about the up
    /// direction, then `pitch` radians about the camera's right axis
    /// (positive looks down from higher up). The distance is kept; a pitch
    /// that would pass over the pole stops at [`POLE_MARGIN`].
    pub fn orbit(&mut self, yaw: f32, pitch: f32) {
        self.orbit_about(self.camera.lookat, yaw, pitch);
    }

    /// Turns the whole camera (eye and look-at point) rigidly around
    /// `pivot`, a point in scene units (in the window, the surface point
    /// under the cursor): `yaw` radians about the up direction, then
    /// `pitch` radians about the axis across the eye's offset from the
    /// pivot (positive raises the eye). The eye keeps its distance to the
    /// pivot and the pivot stays where it is in the picture (the pitch
    /// turns about the camera's own right axis, so the view never rolls).
    /// A pitch that would tilt the view direction past straight down or up
    /// stops at [`POLE_MARGIN`]; non-finite input changes nothing.
    ///
    /// With the eye inside a room ([`CameraControl::within`]), the orbit
    /// goes only as far as keeps the eye [`ROOM_WALL_MARGIN`] inside it.
    pub fn orbit_about(&mut self, pivot: Vec3, yaw: f32, pitch: f32) {
        if !pivot.is_finite() {
            return;
        }
        let room = self.room_around_eye();
        let turned = |share: f32| {
            let view = self.camera.lookat - self.camera.eye;
            let rotation = orbit_rotation(view, self.camera.up, yaw * share, pitch * share)?;
            let eye = pivot + rotation * (self.camera.eye - pivot);
            let lookat = pivot + rotation * (self.camera.lookat - pivot);
            let stays = room.is_none_or(|(lo, hi)| eye.cmpgt(lo).all() && eye.cmplt(hi).all());
            (eye.is_finite() && lookat.is_finite() && stays).then_some((eye, lookat))
        };
        let mut best = turned(1.0);
        if best.is_none() && room.is_some() {
            // The largest share of the orbit found, by halving, that keeps
            // the eye in the room.
            let (mut inside, mut outside) = (0.0, 1.0);
            for _ in 0..ORBIT_CLAMP_STEPS {
                let mid = 0.5 * (inside + outside);
                match turned(mid) {
                    Some(found) => {
                        inside = mid;
                        best = Some(found);
                    }
                    None => outside = mid,
                }
            }
        }
        if let Some((eye, lookat)) = best {
            self.camera.eye = eye;
            self.camera.lookat = lookat;
        }
    }

    /// Turns the view about the eye (the eye stays where it is, so from
    /// inside a room the view stays inside it): `yaw` radians about the up
    /// direction (positive turns left), then `pitch` radians about the
    /// camera's right axis (positive looks up). The look-at point keeps its
    /// distance; a pitch that would look past straight up or down stops at
    /// [`POLE_MARGIN`].
    pub fn look(&mut self, yaw: f32, pitch: f32) {
        let view = self.camera.lookat - self.camera.eye;
        if let Some(view) = turn(view, self.camera.up, yaw, pitch) {
            self.camera.lookat = self.camera.eye + view;
        }
    }

    /// Multiplies the distance to the look-at point by `factor` (below 1
    /// moves closer), kept within [`MIN_DISTANCE_FRACTION`] and
    /// [`MAX_DISTANCE_FACTOR`] of the scene camera's distance; inside a
    /// room, the eye backs away only as far as the room lets it.
    pub fn zoom(&mut self, factor: f32) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let home = self.home_distance();
        let distance = (self.distance() * factor)
            .clamp(home * MIN_DISTANCE_FRACTION, home * MAX_DISTANCE_FACTOR);
        let direction = (self.camera.eye - self.camera.lookat).normalize();
        let delta = self.camera.lookat + direction * distance - self.camera.eye;
        let delta = delta * self.share_inside(delta);
        if delta.is_finite() {
            self.camera.eye += delta;
        }
    }

    /// Moves the camera (eye and look-at point together, so the view keeps
    /// its direction) along the line from the eye to `target`, a point in
    /// scene units (in the window, the surface under the cursor), until
    /// the eye's distance to it is `factor` times what it was (below 1
    /// moves closer). Moving closer stops `stop` scene units in front of
    /// the target, so the eye never reaches the surface it moves towards;
    /// an eye already that close does not move closer. Moving away is
    /// limited to [`MAX_DISTANCE_FACTOR`] scene-camera distances, and
    /// inside a room to the room. Non-finite or non-positive input changes
    /// nothing.
    pub fn dolly(&mut self, target: Vec3, factor: f32, stop: f32) {
        if !(factor.is_finite()
            && factor > 0.0
            && stop.is_finite()
            && stop >= 0.0
            && target.is_finite())
        {
            return;
        }
        let offset = target - self.camera.eye;
        let d = offset.length();
        if !(d.is_finite() && d > 0.0) {
            return;
        }
        let wanted = if factor < 1.0 {
            (d * factor).max(stop.min(d))
        } else {
            (d * factor).min(d.max(self.home_distance() * MAX_DISTANCE_FACTOR))
        };
        self.shift(offset / d * (d - wanted));
    }

    /// Moves eye and look-at point together: `right`, `up` and `forward`
    /// in units of the current distance to the look-at point; inside a
    /// room, only as far as keeps the eye in it.
    pub fn walk(&mut self, right: f32, up: f32, forward: f32) {
        let view = (self.camera.lookat - self.camera.eye).normalize();
        let side = view.cross(self.camera.up).normalize_or_zero();
        let true_up = side.cross(view);
        let d = self.distance();
        self.shift((side * right + true_up * up + view * forward) * d);
    }
}

/// The rotation that turns `v` by `yaw` radians about `up`, then tilts it
/// towards `up` by `pitch` radians (about `up × v`), its angle to `up`
/// kept within [`POLE_MARGIN`] of either pole; `None` for a zero `up` or
/// non-finite angles.
fn rotation(v: Vec3, up: Vec3, yaw: f32, pitch: f32) -> Option<Quat> {
    let up = up.normalize_or_zero();
    if up == Vec3::ZERO || !yaw.is_finite() || !pitch.is_finite() || !v.is_finite() {
        return None;
    }
    let spin = Quat::from_axis_angle(up, yaw);
    let v = spin * v;
    // Angle between `v` and up, in [0, π].
    let current = v.normalize_or_zero().dot(up).clamp(-1.0, 1.0).acos();
    let target = (current - pitch).clamp(POLE_MARGIN, std::f32::consts::PI - POLE_MARGIN);
    let right = up.cross(v).normalize_or_zero();
    Some(if right == Vec3::ZERO {
        spin
    } else {
        // About `up × v`, a positive angle turns `v` away from `up`,
        // increasing its angle to it by that much.
        Quat::from_axis_angle(right, target - current) * spin
    })
}

/// The rigid rotation of an orbit for a camera looking along `view`:
/// `yaw` radians about `up`, then about the camera's right axis (after the
/// yaw) so that the view direction's angle to `up` grows by `pitch`
/// radians (positive raises the eye and looks down more), kept within
/// [`POLE_MARGIN`] of either pole. `None` for a zero `up` or non-finite
/// input.
fn orbit_rotation(view: Vec3, up: Vec3, yaw: f32, pitch: f32) -> Option<Quat> {
    let up = up.normalize_or_zero();
    if up == Vec3::ZERO || !yaw.is_finite() || !pitch.is_finite() || !view.is_finite() {
        return None;
    }
    let spin = Quat::from_axis_angle(up, yaw);
    let v = spin * view;
    let current = v.normalize_or_zero().dot(up).clamp(-1.0, 1.0).acos();
    let target = (current + pitch).clamp(POLE_MARGIN, std::f32::consts::PI - POLE_MARGIN);
    let right = v.cross(up).normalize_or_zero();
    Some(if right == Vec3::ZERO {
        spin
    } else {
        // About `v × up`, a positive angle tilts `v` towards `up`,
        // decreasing its angle to it by that much.
        Quat::from_axis_angle(right, current - target) * spin
    })
}

/// `v` turned `yaw` radians about `up`, then tilted towards `up` by
/// `pitch` radians, its angle to `up` kept within [`POLE_MARGIN`] of
/// either pole (see [`rotation`]); `None` for a zero `up` or non-finite
/// angles. The length is kept.
fn turn(v: Vec3, up: Vec3, yaw: f32, pitch: f32) -> Option<Vec3> {
    rotation(v, up, yaw, pitch).map(|q| q * v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn home() -> Camera {
        Camera {
            eye: Vec3::new(2.5, 1.5, -4.0),
            lookat: Vec3::new(2.5, 1.5, 2.5),
            up: Vec3::Y,
            fov_y: 0.8,
            width: 64,
            height: 48,
        }
    }

    #[test]
    fn orbit_keeps_the_distance_to_the_lookat_point() {
        let mut c = CameraControl::new(home());
        let d = c.distance();
        for (yaw, pitch) in [
            (0.3, 0.0),
            (0.0, 0.4),
            (-1.2, -0.7),
            (2.0, 3.0),
            (0.1, -3.0),
        ] {
            c.orbit(yaw, pitch);
            assert!(
                (c.distance() - d).abs() < 1e-4 * d,
                "{} vs {d}",
                c.distance()
            );
            assert_eq!(c.camera().lookat, home().lookat);
            let view = (c.camera().lookat - c.camera().eye).normalize();
            assert!(
                view.cross(Vec3::Y).length() > 0.01,
                "view flipped onto the pole"
            );
        }
    }

    #[test]
    fn orbit_yaw_turns_about_up_and_pitch_raises_the_eye() {
        let mut c = CameraControl::new(home());
        c.orbit(std::f32::consts::FRAC_PI_2, 0.0);
        // A quarter turn about +y takes the eye from -z of the point to -x or +x.
        let offset = c.camera().eye - c.camera().lookat;
        assert!(offset.z.abs() < 1e-4 && offset.x.abs() > 6.0, "{offset}");
        let mut c = CameraControl::new(home());
        c.orbit(0.0, 0.5);
        assert!(c.camera().eye.y > home().eye.y);
    }

    #[test]
    fn looking_around_keeps_the_eye_and_turns_the_view() {
        let mut c = CameraControl::new(home());
        let eye = c.camera().eye;
        let d = c.distance();
        // A quarter turn left: from looking down +z to looking down +x
        // (the camera's right is -x).
        c.look(std::f32::consts::FRAC_PI_2, 0.0);
        assert_eq!(c.camera().eye, eye);
        let view = (c.camera().lookat - eye).normalize();
        assert!(view.distance(Vec3::X) < 1e-5, "{view}");
        assert!((c.distance() - d).abs() < 1e-4 * d);
        // Looking up: the view rises, and never past straight up.
        c.look(0.0, 0.5);
        assert!((c.camera().lookat - eye).normalize().y > 0.4);
        c.look(0.0, 10.0);
        let up = (c.camera().lookat - eye).normalize().dot(Vec3::Y);
        // Stopped at the margin from straight up.
        assert!(
            up <= (POLE_MARGIN * 0.9).cos() && up > (POLE_MARGIN * 2.0).cos(),
            "{up}"
        );
        assert_eq!(c.camera().eye, eye);
        // Nonsense input changes nothing.
        let before = *c.camera();
        c.look(f32::NAN, 0.0);
        assert_eq!(*c.camera(), before);
    }

    #[test]
    fn zoom_never_passes_the_lookat_point() {
        let mut c = CameraControl::new(home());
        for _ in 0..1000 {
            c.zoom(0.5);
        }
        let min = home().eye.distance(home().lookat) * MIN_DISTANCE_FRACTION;
        assert!((c.distance() - min).abs() < 1e-4);
        // Still on the same side of the point.
        assert!((c.camera().eye - c.camera().lookat).dot(home().eye - home().lookat) > 0.0);
        for _ in 0..1000 {
            c.zoom(2.0);
        }
        assert!(c.distance() <= home().eye.distance(home().lookat) * MAX_DISTANCE_FACTOR * 1.0001);
        c.zoom(0.0);
        c.zoom(f32::NAN);
        assert!(c.distance().is_finite() && c.distance() > 0.0);
    }

    #[test]
    fn reset_restores_the_scene_camera() {
        let mut c = CameraControl::new(home());
        c.orbit(1.0, 0.3);
        c.zoom(0.3);
        c.walk(0.2, 0.1, 0.5);
        assert_ne!(*c.camera(), home());
        c.reset();
        assert_eq!(*c.camera(), home());
    }

    #[test]
    fn walking_moves_eye_and_lookat_together() {
        let mut c = CameraControl::new(home());
        c.walk(0.0, 0.0, 0.1);
        let step = c.camera().eye - home().eye;
        assert_eq!(c.camera().lookat - home().lookat, step);
        assert!(step.z > 0.0 && step.x.abs() < 1e-5);
        // Right in the picture is forward × up.
        let mut c = CameraControl::new(home());
        c.walk(0.1, 0.0, 0.0);
        let right = (home().lookat - home().eye).normalize().cross(Vec3::Y);
        assert!((c.camera().eye - home().eye).normalize().dot(right) > 0.999);
    }

    #[test]
    fn orbiting_a_point_keeps_it_in_place_on_the_picture() {
        let mut c = CameraControl::new(home());
        // A point off the view's centre, as picked under the cursor.
        let pivot = Vec3::new(1.5, 0.5, 1.0);
        let before = crate::render::View::new(c.camera())
            .unwrap()
            .project(pivot)
            .unwrap();
        let d = c.camera().eye.distance(pivot);
        for (yaw, pitch) in [(0.3, 0.0), (0.0, 0.2), (-0.5, -0.3), (0.2, 0.1)] {
            c.orbit_about(pivot, yaw, pitch);
            assert!((c.camera().eye.distance(pivot) - d).abs() < 1e-4 * d);
            let now = crate::render::View::new(c.camera())
                .unwrap()
                .project(pivot)
                .unwrap();
            assert!(now.distance(before) < 0.01, "{now} vs {before}");
        }
        // Yaw moves the eye around the pivot, not around the look-at point.
        assert_ne!(c.camera().eye, home().eye);
        assert!((c.distance() - home().eye.distance(home().lookat)).abs() < 1e-3);
        // A turn that would look straight down is refused, not flipped.
        let mut c = CameraControl::new(home());
        for _ in 0..100 {
            c.orbit_about(pivot, 0.0, 0.3);
            let view = (c.camera().lookat - c.camera().eye).normalize();
            assert!(
                view.cross(Vec3::Y).length() > 0.01,
                "view flipped onto the pole"
            );
        }
        let before = *c.camera();
        c.orbit_about(Vec3::NAN, 0.1, 0.1);
        c.orbit_about(pivot, f32::INFINITY, 0.1);
        assert_eq!(*c.camera(), before);
    }

    /// The bundled `rtable`'s camera, in its room 5 × 3 × 5.
    fn rtable() -> (Camera, Vec3, Vec3) {
        let scene = crate::scene::parse_str(crate::config::BUNDLED_SCENE, "rtable.sc").unwrap();
        let (lo, hi) = scene.bounds();
        assert_eq!((lo, hi), (Vec3::ZERO, Vec3::new(5.0, 3.0, 5.0)));
        (scene.camera, lo, hi)
    }

    /// Holding an arrow key, turning the wheel or backing away from the
    /// look-at point in `rtable` stops at its walls; outside a room the
    /// same moves go as far as asked.
    #[test]
    fn walking_zooming_and_the_wheel_stay_in_the_room() {
        let (start, lo, hi) = rtable();
        let inside = |c: &CameraControl| {
            let eye = c.camera().eye;
            eye.cmpgt(lo).all() && eye.cmplt(hi).all()
        };
        for (right, up, forward) in [
            (0.0, 0.0, 0.2),
            (0.0, 0.0, -0.2),
            (0.2, 0.0, 0.0),
            (-0.2, 0.0, 0.0),
            (0.0, 0.2, 0.0),
            (0.0, -0.2, 0.0),
            (0.15, 0.1, 0.15),
        ] {
            let mut c = CameraControl::new(start).within(lo, hi);
            // As the window repeats a held key, a hundred frames.
            for _ in 0..100 {
                c.walk(right, up, forward);
                assert!(
                    inside(&c),
                    "walk ({right}, {up}, {forward}): {}",
                    c.camera().eye
                );
            }
            assert_ne!(c.camera().eye, start.eye);
            // It went most of the way to the wall it walked towards.
            let room = hi - lo;
            let margin = ROOM_WALL_MARGIN * room.min_element();
            let to_wall = (c.camera().eye - lo).min(hi - c.camera().eye).min_element();
            assert!(
                to_wall < margin + 0.01 * room.min_element(),
                "{}",
                c.camera().eye
            );
            // The view keeps its direction.
            let view = c.camera().lookat - c.camera().eye;
            let home_view = start.lookat - start.eye;
            assert!(view.normalize().dot(home_view.normalize()) > 0.9999);
        }
        let mut c = CameraControl::new(start).within(lo, hi);
        for _ in 0..100 {
            c.zoom(1.3);
            assert!(inside(&c), "zoom: {}", c.camera().eye);
        }
        let mut c = CameraControl::new(start).within(lo, hi);
        let target = Vec3::new(2.5, 0.78, 2.8);
        for _ in 0..100 {
            c.dolly(target, 1.3, 0.05);
            assert!(inside(&c), "wheel back: {}", c.camera().eye);
        }
        // Seen from outside (no room around the eye) nothing is clamped.
        let mut c = CameraControl::new(home());
        c.walk(0.0, 0.0, 5.0);
        let walked = c.camera().eye.distance(home().eye);
        assert!((walked - 5.0 * home().eye.distance(home().lookat)).abs() < 1e-3 * walked);
    }

    #[test]
    fn a_200_pixel_drag_around_the_table_top_stays_in_the_room() {
        let (home, lo, hi) = rtable();
        // Points of the table top (y 0.78, x 1.7..3.3, z 2.2..3.4), as
        // picked under the cursor.
        for pivot in [
            Vec3::new(2.5, 0.78, 2.8),
            Vec3::new(1.8, 0.78, 2.3),
            Vec3::new(3.2, 0.78, 3.3),
        ] {
            for (dx, dy) in [
                (200.0, 0.0),
                (-200.0, 0.0),
                (0.0, 200.0),
                (0.0, -200.0),
                (141.0, 141.0),
                (-141.0, 141.0),
            ] {
                let mut c = CameraControl::new(home).within(lo, hi);
                // As the window applies a drag: a few pixels a frame.
                for _ in 0..20 {
                    let k = c.orbit_per_pixel(pivot);
                    c.orbit_about(pivot, -dx / 20.0 * k, dy / 20.0 * k);
                }
                let eye = c.camera().eye;
                assert!(
                    eye.cmpgt(lo).all() && eye.cmplt(hi).all(),
                    "{pivot} ({dx}, {dy}): the eye left the room: {eye}"
                );
                // It still turned, and kept its distance to the pivot.
                assert_ne!(eye, home.eye);
                let d = home.eye.distance(pivot);
                assert!((eye.distance(pivot) - d).abs() < 1e-3 * d);
            }
        }
    }

    #[test]
    fn orbit_speed_is_scaled_to_the_room_and_unchanged_around_objects() {
        let (home, lo, hi) = rtable();
        let pivot = Vec3::new(2.5, 0.78, 2.8);
        let c = CameraControl::new(home).within(lo, hi);
        let k = c.orbit_per_pixel(pivot);
        // The eye moves the stated share of the room's height per pixel.
        let travel = k * home.eye.distance(pivot);
        assert!(
            (travel - ROOM_ORBIT_TRAVEL_PER_PIXEL * 3.0).abs() < 1e-6,
            "{travel}"
        );
        assert!(k < ORBIT_PER_PIXEL);
        // Without bounds, or from outside them, the object speed.
        assert_eq!(
            CameraControl::new(home).orbit_per_pixel(pivot),
            ORBIT_PER_PIXEL
        );
        let outside = Camera {
            eye: Vec3::new(2.5, 1.5, -8.0),
            ..home
        };
        let c = CameraControl::new(outside).within(lo, hi);
        assert_eq!(c.orbit_per_pixel(pivot), ORBIT_PER_PIXEL);
        // From outside, an orbit is not held back by the bounds.
        let mut free = c;
        free.orbit_about(pivot, 1.5, 0.0);
        let mut unbounded = CameraControl::new(outside);
        unbounded.orbit_about(pivot, 1.5, 0.0);
        assert_eq!(free.camera(), unbounded.camera());
    }

    #[test]
    fn dolly_moves_towards_the_target_and_stops_in_front_of_it() {
        let mut c = CameraControl::new(home());
        let target = Vec3::new(3.0, 1.0, 1.0);
        let view = c.camera().lookat - c.camera().eye;
        let d = c.camera().eye.distance(target);
        c.dolly(target, 0.5, 0.1);
        assert!((c.camera().eye.distance(target) - d * 0.5).abs() < 1e-4 * d);
        // The view keeps its direction: both points moved alike.
        assert!((c.camera().lookat - c.camera().eye - view).length() < 1e-4);
        // The eye moved along the line towards the target.
        let moved = (c.camera().eye - home().eye).normalize();
        assert!(moved.dot((target - home().eye).normalize()) > 0.9999);
        // Many steps closer stop `stop` in front of the target.
        for _ in 0..200 {
            c.dolly(target, 0.5, 0.1);
        }
        assert!((c.camera().eye.distance(target) - 0.1).abs() < 1e-4);
        // Moving away grows the distance again; nonsense changes nothing.
        c.dolly(target, 2.0, 0.1);
        assert!((c.camera().eye.distance(target) - 0.2).abs() < 1e-4);
        let before = *c.camera();
        c.dolly(target, f32::NAN, 0.1);
        c.dolly(target, 0.0, 0.1);
        c.dolly(Vec3::INFINITY, 0.5, 0.1);
        c.dolly(c.camera().eye, 0.5, 0.1);
        assert_eq!(*c.camera(), before);
    }
}
