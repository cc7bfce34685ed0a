//! The pinhole view: where the camera is, which way it looks, and how a
//! point in the scene lands on a pixel.
//!
//! Three spaces appear here:
//!
//! - **world space**: the scene's coordinates, in scene units;
//! - **camera space**: origin at the eye, `x` to the right of the picture,
//!   `y` up the picture, `z` the depth along the viewing direction (positive
//!   in front of the eye), in scene units;
//! - **pixel space**: continuous picture coordinates in pixels, `x` to the
//!   right and `y` down, origin at the top-left corner of the picture. Pixel
//!   `(i, j)` (column `i`, row `j`, row 0 at the top) covers
//!   `[i, i + 1) × [j, j + 1)`; its centre, where the rasterizer samples, is
//!   `(i + 0.5, j + 0.5)`.
//!
//! Pixels are square: the vertical field of view is the camera's and the
//! horizontal one follows from the aspect ratio `width / height`.

use crate::camera::{Camera, CameraError, CheckedCamera};
use glam::{DVec2, DVec3, Vec2, Vec3};
use thiserror::Error;

/// The default near-plane distance as a fraction of the distance from the
/// eye to the look-at point.
///
/// Scenes are rooms with the camera inside, so many polygons cross the plane
/// of the eye and have to be cut by a near plane. The cut is invisible as
/// long as nothing in view is closer than this: with the look-at point in the
/// middle of a room, that is a thousandth of half the room's size. Callers
/// that know the scene's extent can choose their own with [`View::with_near`].
pub const DEFAULT_NEAR_FRACTION: f32 = 1e-3;

/// Why a [`Camera`] does not make a usable [`View`]: the camera's own
/// problems ([`CameraError`], with the same messages except that a zero up
/// and a parallel one are one case here) and the view's near plane.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ViewError {
    /// A camera vector or the field of view is NaN or infinite.
    #[error("{}", CameraError::NotFinite)]
    NotFinite,
    /// The eye and the look-at point coincide, so there is no viewing direction.
    #[error("{}", CameraError::NoViewDirection)]
    NoViewDirection,
    /// Up is zero or parallel to the viewing direction.
    #[error("the camera's up vector is zero or parallel to the viewing direction")]
    UpParallel,
    /// The vertical field of view is not in `(0, pi)` radians.
    #[error("{}", CameraError::FovOutOfRange(*.0))]
    FovOutOfRange(f32),
    /// A picture side is zero or larger than
    /// [`MAX_PICTURE_SIDE`](crate::camera::MAX_PICTURE_SIDE), or the picture
    /// has more than [`MAX_PICTURE_PIXELS`](crate::camera::MAX_PICTURE_PIXELS)
    /// pixels.
    #[error("{}", CameraError::BadSize { width: *.width, height: *.height })]
    BadSize {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
    },
    /// The near distance is not finite and positive.
    #[error("the near-plane distance {0} is not finite and positive")]
    BadNear(f32),
}

impl From<CameraError> for ViewError {
    fn from(e: CameraError) -> Self {
        match e {
            CameraError::NotFinite => ViewError::NotFinite,
            CameraError::NoViewDirection => ViewError::NoViewDirection,
            CameraError::UpZero | CameraError::UpParallel => ViewError::UpParallel,
            CameraError::FovOutOfRange(fov) => ViewError::FovOutOfRange(fov),
            CameraError::BadSize { width, height } => ViewError::BadSize { width, height },
        }
    }
}

/// A validated pinhole view made from a [`CheckedCamera`]: its orthonormal
/// camera frame, a perspective projection and a picture size.
///
/// Invariants: `right`, `up` and `forward` are unit length and mutually
/// orthogonal with `right = forward × up` (a right-handed world looks
/// right-handed in the picture: world-right is picture-right); `0 < fov_y <
/// pi`; the picture size within [`crate::camera::picture_size_ok`]; `near`
/// finite and `> 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    fov_y: f32,
    width: u32,
    height: u32,
    near: f32,
}

impl View {
    /// The view of a camera at the camera's own picture size, with the near
    /// plane at [`DEFAULT_NEAR_FRACTION`] of the eye–look-at distance.
    pub fn new(camera: &Camera) -> Result<View, ViewError> {
        View::with_size(camera, camera.width, camera.height)
    }

    /// The view of a camera rendered at another picture size (for example a
    /// resized window). The vertical field of view is kept; the horizontal one
    /// follows the new aspect ratio. The camera is checked with that size
    /// ([`Camera::check`]); its own size does not matter.
    pub fn with_size(camera: &Camera, width: u32, height: u32) -> Result<View, ViewError> {
        let sized = Camera {
            width,
            height,
            ..*camera
        };
        View::from_checked(&sized.check()?)
    }

    /// The view of a checked camera, at its picture size, with the near
    /// plane at [`DEFAULT_NEAR_FRACTION`] of the eye–look-at distance.
    pub fn from_checked(camera: &CheckedCamera) -> Result<View, ViewError> {
        let c = camera.camera();
        View {
            eye: c.eye,
            right: camera.right(),
            up: camera.up(),
            forward: camera.forward(),
            fov_y: c.fov_y,
            width: c.width,
            height: c.height,
            near: 1.0,
        }
        .with_near(camera.distance() * DEFAULT_NEAR_FRACTION)
    }

    /// The same view with the near plane at `near` scene units in front of
    /// the eye. Everything closer is cut away.
    pub fn with_near(mut self, near: f32) -> Result<View, ViewError> {
        if !(near.is_finite() && near > 0.0) {
            return Err(ViewError::BadNear(near));
        }
        self.near = near;
        Ok(self)
    }

    /// The eye position, in scene units.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// Unit vector pointing to the right of the picture, in world space.
    pub fn right(&self) -> Vec3 {
        self.right
    }

    /// Unit vector pointing up the picture, in world space (the camera's up
    /// made orthogonal to the view).
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// Unit viewing direction, in world space.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Vertical field of view in radians.
    pub fn fov_y(&self) -> f32 {
        self.fov_y
    }

    /// Picture width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Picture height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Picture width over height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Near-plane distance in scene units, `> 0`.
    pub fn near(&self) -> f32 {
        self.near
    }

    /// Focal length in pixels: the distance from the eye to a picture plane
    /// on which one scene unit is one pixel. The same horizontally and
    /// vertically, because pixels are square.
    pub fn focal_px(&self) -> f64 {
        f64::from(self.height) / (2.0 * (f64::from(self.fov_y) / 2.0).tan())
    }

    /// A world-space point in camera space: `x` right, `y` up, `z` depth in
    /// front of the eye, all in scene units.
    pub fn to_camera(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// A camera-space point projected to pixel space, in `f64` because the
    /// rasterizer snaps it to a sub-pixel grid. `None` when the point is not
    /// in front of the eye (`z <= 0`).
    pub fn camera_to_pixel(&self, c: DVec3) -> Option<DVec2> {
        if c.z.is_nan() || c.z <= 0.0 {
            return None;
        }
        let f = self.focal_px();
        let x = f64::from(self.width) / 2.0 + f * c.x / c.z;
        let y = f64::from(self.height) / 2.0 - f * c.y / c.z;
        Some(DVec2::new(x, y))
    }

    /// The world-space direction (unit length) from the eye through the
    /// point `(x, y)` of the picture, in pixels from its top-left corner
    /// (a pixel's centre is at `+0.5`).
    pub fn ray_direction(&self, x: f64, y: f64) -> Vec3 {
        let f = self.focal_px();
        let cx = (x - f64::from(self.width) / 2.0) / f;
        let cy = (f64::from(self.height) / 2.0 - y) / f;
        (self.right * cx as f32 + self.up * cy as f32 + self.forward).normalize()
    }

    /// The world-space point seen at `(x, y)` of the picture (pixels from
    /// its top-left corner) at camera-space depth `1 / inv_depth` (the
    /// rasterizer's depth buffer value; `z` in scene units along the view
    /// direction, not the distance along the ray). `None` when `inv_depth`
    /// is not finite and positive (nothing drawn there). The inverse of
    /// [`View::project`] for a point in front of the eye.
    pub fn unproject(&self, x: f64, y: f64, inv_depth: f64) -> Option<Vec3> {
        if !(inv_depth.is_finite() && inv_depth > 0.0) {
            return None;
        }
        let z = 1.0 / inv_depth;
        let f = self.focal_px();
        let cx = (x - f64::from(self.width) / 2.0) * z / f;
        let cy = (f64::from(self.height) / 2.0 - y) * z / f;
        let p = self.eye.as_dvec3()
            + self.right.as_dvec3() * cx
            + self.up.as_dvec3() * cy
            + self.forward.as_dvec3() * z;
        Some(p.as_vec3())
    }

    /// A world-space point projected to pixel space (see the module docs).
    /// `None` when the point is not in front of the eye. Points outside the
    /// field of view give coordinates outside `[0, width] × [0, height]`.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        self.camera_to_pixel(self.to_camera(p).as_dvec3())
            .map(|v| v.as_vec2())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::MAX_PICTURE_SIDE;

    /// Pixel-space tolerance of the projection tests, in pixels.
    const PIXEL_TOLERANCE: f32 = 1e-3;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            lookat: Vec3::new(1.0, 2.0, -7.0),
            up: Vec3::Y,
            fov_y: 60f32.to_radians(),
            width: 200,
            height: 100,
        }
    }

    fn close(a: Vec2, b: Vec2) -> bool {
        (a - b).abs().max_element() < PIXEL_TOLERANCE
    }

    #[test]
    fn straight_ahead_is_the_centre() {
        let v = View::new(&camera()).unwrap();
        let p = v.project(Vec3::new(1.0, 2.0, -20.0)).unwrap();
        assert!(close(p, Vec2::new(100.0, 50.0)), "{p}");
    }

    #[test]
    fn right_is_right_and_up_is_up() {
        let v = View::new(&camera()).unwrap();
        let right = v.project(Vec3::new(1.0, 2.0, -7.0) + v.right()).unwrap();
        assert!(right.x > 100.0 && (right.y - 50.0).abs() < PIXEL_TOLERANCE);
        let above = v.project(Vec3::new(1.0, 3.0, -7.0)).unwrap();
        assert!(above.y < 50.0 && (above.x - 100.0).abs() < PIXEL_TOLERANCE);
        // Looking down -z with +y up, world +x is to the right.
        assert!((v.right() - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn fov_edges_are_the_picture_edges() {
        let c = camera();
        let v = View::new(&c).unwrap();
        let t = (c.fov_y / 2.0).tan();
        let top = v.project(Vec3::new(1.0, 2.0 + 10.0 * t, -7.0)).unwrap();
        let bottom = v.project(Vec3::new(1.0, 2.0 - 10.0 * t, -7.0)).unwrap();
        assert!(close(top, Vec2::new(100.0, 0.0)), "{top}");
        assert!(close(bottom, Vec2::new(100.0, 100.0)), "{bottom}");
        // Square pixels: the horizontal edge is aspect times further out.
        let side = v.project(Vec3::new(1.0 + 20.0 * t, 2.0, -7.0)).unwrap();
        assert!(close(side, Vec2::new(200.0, 50.0)), "{side}");
    }

    #[test]
    fn up_need_not_be_orthogonal() {
        let mut c = camera();
        c.up = Vec3::new(0.0, 1.0, 0.7);
        let v = View::new(&c).unwrap();
        assert!((v.up() - Vec3::Y).length() < 1e-6);
        assert!(v.up().dot(v.forward()).abs() < 1e-6);
        assert!(v.right().dot(v.forward()).abs() < 1e-6);
    }

    #[test]
    fn size_override_keeps_vertical_fov() {
        let v = View::with_size(&camera(), 50, 100).unwrap();
        assert_eq!((v.width(), v.height()), (50, 100));
        let p = v.project(Vec3::new(1.0, 2.0, -20.0)).unwrap();
        assert!(close(p, Vec2::new(25.0, 50.0)));
    }

    #[test]
    fn behind_the_eye_does_not_project() {
        let v = View::new(&camera()).unwrap();
        assert!(v.project(Vec3::new(1.0, 2.0, 5.0)).is_none());
    }

    #[test]
    fn bad_cameras_are_errors() {
        let mut c = camera();
        c.up = Vec3::Z;
        assert_eq!(View::new(&c), Err(ViewError::UpParallel));
        let mut c = camera();
        c.lookat = c.eye;
        assert_eq!(View::new(&c), Err(ViewError::NoViewDirection));
        let mut c = camera();
        c.fov_y = 4.0;
        assert_eq!(View::new(&c), Err(ViewError::FovOutOfRange(4.0)));
        let mut c = camera();
        c.width = 0;
        assert!(matches!(View::new(&c), Err(ViewError::BadSize { .. })));
        // Each side is allowed, the product is not: 2^32 pixels would need
        // about 200 GB.
        let (w, h) = (MAX_PICTURE_SIDE, MAX_PICTURE_SIDE);
        assert!(matches!(
            View::with_size(&camera(), w, h),
            Err(ViewError::BadSize { .. })
        ));
        assert!(View::with_size(&camera(), 8192, 8192).is_ok());
        assert!(View::with_size(&camera(), 8192, 8193).is_err());
        assert!(View::with_size(&camera(), MAX_PICTURE_SIDE, 1).is_ok());
        assert!(View::with_size(&camera(), MAX_PICTURE_SIDE + 1, 1).is_err());
        let mut c = camera();
        c.eye.x = f32::NAN;
        assert_eq!(View::new(&c), Err(ViewError::NotFinite));
        let v = View::new(&camera()).unwrap();
        assert_eq!(v.with_near(0.0), Err(ViewError::BadNear(0.0)));
        assert!((v.near() - 10.0 * DEFAULT_NEAR_FRACTION).abs() < 1e-9);
    }

    #[test]
    fn unproject_inverts_project() {
        let v = View::with_size(&camera(), 320, 240).unwrap();
        for p in [
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(0.3, 2.5, -6.0),
            Vec3::new(2.2, 1.1, -20.0),
        ] {
            let px = v.project(p).unwrap();
            let z = f64::from(v.to_camera(p).z);
            let back = v
                .unproject(f64::from(px.x), f64::from(px.y), 1.0 / z)
                .unwrap();
            assert!(back.distance(p) < 1e-4 * z as f32, "{back} vs {p}");
            let ray = v.ray_direction(f64::from(px.x), f64::from(px.y));
            assert!(ray.distance((p - v.eye()).normalize()) < 1e-5, "{ray}");
        }
        assert_eq!(v.unproject(10.0, 10.0, 0.0), None);
        assert_eq!(v.unproject(10.0, 10.0, f64::NAN), None);
    }
}
