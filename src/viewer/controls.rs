//! Camera controls for the window: look around from the eye, orbit around
//! the look-at point, zoom towards it, walk, and reset. Pure geometry on a [`Camera`], so it is
//! tested without a window.

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

/// The window's camera: starts as the scene's camera and moves with input.
///
/// Invariants: `eye != lookat`; the view direction is never parallel to
/// `up`; `up`, the field of view and the picture size never change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraControl {
    home: Camera,
    camera: Camera,
}

impl CameraControl {
    /// Controls starting at (and resetting to) `home`.
    pub fn new(home: Camera) -> Self {
        CameraControl { home, camera: home }
    }

    /// The current camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Back to the scene's camera.
    pub fn reset(&mut self) {
        self.camera = self.home;
    }

    fn home_distance(&self) -> f32 {
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
        let offset = self.camera.eye - self.camera.lookat;
        if let Some(offset) = turn(offset, self.camera.up, yaw, pitch) {
            self.camera.eye = self.camera.lookat + offset;
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
    /// [`MAX_DISTANCE_FACTOR`] of the scene camera's distance.
    pub fn zoom(&mut self, factor: f32) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let home = self.home_distance();
        let distance = (self.distance() * factor)
            .clamp(home * MIN_DISTANCE_FRACTION, home * MAX_DISTANCE_FACTOR);
        let direction = (self.camera.eye - self.camera.lookat).normalize();
        self.camera.eye = self.camera.lookat + direction * distance;
    }

    /// Moves eye and look-at point together: `right`, `up` and `forward`
    /// in units of the current distance to the look-at point.
    pub fn walk(&mut self, right: f32, up: f32, forward: f32) {
        let view = (self.camera.lookat - self.camera.eye).normalize();
        let side = view.cross(self.camera.up).normalize_or_zero();
        let true_up = side.cross(view);
        let d = self.distance();
        let delta = (side * right + true_up * up + view * forward) * d;
        if delta.is_finite() {
            self.camera.eye += delta;
            self.camera.lookat += delta;
        }
    }
}

/// `v` turned `yaw` radians about `up`, then tilted towards `up` by
/// `pitch` radians (about `up × v`), its angle to `up` kept within
/// [`POLE_MARGIN`] of either pole; `None` for a zero `up` or non-finite
/// angles. The length is kept.
fn turn(v: Vec3, up: Vec3, yaw: f32, pitch: f32) -> Option<Vec3> {
    let up = up.normalize_or_zero();
    if up == Vec3::ZERO || !yaw.is_finite() || !pitch.is_finite() {
        return None;
    }
    let v = Quat::from_axis_angle(up, yaw) * v;
    // Angle between `v` and up, in [0, π].
    let current = v.normalize().dot(up).clamp(-1.0, 1.0).acos();
    let target = (current - pitch).clamp(POLE_MARGIN, std::f32::consts::PI - POLE_MARGIN);
    let right = up.cross(v).normalize_or_zero();
    Some(if right == Vec3::ZERO {
        v
    } else {
        // About `up × v`, a positive angle turns `v` away from `up`,
        // increasing its angle to it by that much.
        Quat::from_axis_angle(right, target - current) * v
    })
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
}
