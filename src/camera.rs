//! The camera: where the eye is, what it looks at, which way is up, how wide
//! the view is and how many pixels the picture has.
//!
//! This module sits at the bottom of the crate with the scene: the loaders
//! build cameras, the renderer turns them into a projection, the window moves
//! them. It owns everything about a camera that is not projection:
//!
//! - [`Camera`], the plain description as a scene file writes it;
//! - [`Camera::frame`], the automatic camera of a scene without one;
//! - [`Camera::check`], the one validation every camera goes through, with
//!   its typed [`CameraError`]; it yields a [`CheckedCamera`], which carries
//!   the orthonormal camera frame and is what the renderer's `View` is made
//!   from;
//! - the picture-size limits ([`MAX_PICTURE_SIDE`], [`MAX_PICTURE_PIXELS`],
//!   [`picture_size_ok`]);
//! - [`CameraOverride`] (`adjust.rs`), the parts of a camera the command
//!   line replaces (`--eye`, `--look-at`, `--up`, `--fov`);
//! - the camera written out to be used again (`print.rs`): as those
//!   options ([`options_text`]) and as a `.sc` `camera` block
//!   ([`sc_block`]), both reading back to the same camera, bit for bit.
//!
//! It imports nothing from the renderer or the scene, so both may use it.

mod adjust;
mod print;

pub use adjust::{CameraOverride, OverrideError};
pub use print::{fmt_fov_deg, fmt_point, fmt_value, options_text, sc_block};

use glam::Vec3;
use thiserror::Error;

/// Default picture size when the scene gives none, in pixels.
pub const DEFAULT_SIZE: (u32, u32) = (640, 480);

/// Default vertical field of view when the scene gives none, in degrees.
pub const DEFAULT_FOV_DEG: f32 = 45.0;

/// `up` counts as parallel to the viewing direction when the sine of the
/// angle between their directions is below this (dimensionless).
///
/// Why this value: the picture's right vector is `normalize(forward × up)`,
/// computed in `f32` from unit vectors that each carry a rounding error of
/// about 6e-8. At a sine of 1e-4 that error moves the right vector by about
/// 1e-3 radians at most, too little to see; at 1e-6 (the renderer's former
/// limit) it could move it by a tenth of a radian, so the picture's
/// orientation was mostly rounding noise. Nothing a person writes comes near
/// it: `.sc` cameras were already refused below 1e-4 (that check ran before
/// the renderer's), the window's orbit keeps at least `POLE_MARGIN` (0.02
/// radians) from the pole, and automatic framing looks at right angles to up.
pub const UP_PARALLEL_TOLERANCE: f64 = 1e-4;

/// [`Camera::frame`] never puts the eye closer to the look-at point than
/// this fraction of the look-at point's distance from the origin along z
/// (dimensionless): a few `f32` ulps, so that `eye != lookat` survives the
/// rounding to `f32` even for a tiny scene far from the origin.
pub const FRAME_MIN_RELATIVE_DISTANCE: f64 = 1e-6;

/// The largest picture side the renderer accepts, in pixels.
///
/// It bounds the fixed-point screen coordinates of the rasterizer so that its
/// exact integer edge tests cannot overflow.
pub const MAX_PICTURE_SIDE: u32 = 1 << 16;

/// The most pixels a picture may have: 2^26 = 67,108,864 (8192 × 8192).
///
/// Rendering and writing a picture hold about 45 bytes per pixel at once
/// (the linear frame, coverage, the z-buffer, luminances for the automatic
/// exposure, the encoded copy), so this bounds a picture's memory near
/// 3 GB; a larger request is almost always a typo.
pub const MAX_PICTURE_PIXELS: u64 = 1 << 26;

/// Whether a picture of `width × height` pixels is within
/// [`MAX_PICTURE_SIDE`] and [`MAX_PICTURE_PIXELS`] (and not empty).
pub fn picture_size_ok(width: u32, height: u32) -> bool {
    (1..=MAX_PICTURE_SIDE).contains(&width)
        && (1..=MAX_PICTURE_SIDE).contains(&height)
        && width as u64 * height as u64 <= MAX_PICTURE_PIXELS
}

/// Why a [`Camera`] is unusable. The messages name no file: a loader that
/// knows where the camera was written adds the position.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum CameraError {
    /// A camera vector or the field of view is NaN or infinite.
    #[error("the camera has a non-finite eye, look-at point, up vector or field of view")]
    NotFinite,
    /// The eye and the look-at point coincide (in `f32`), so there is no
    /// viewing direction.
    #[error("the camera's eye and look-at point coincide")]
    NoViewDirection,
    /// The up vector is zero (in `f32`), so it gives no direction.
    #[error("the camera's up vector is zero")]
    UpZero,
    /// Up is parallel to the viewing direction, within
    /// [`UP_PARALLEL_TOLERANCE`].
    #[error("the camera's up vector is parallel to the viewing direction")]
    UpParallel,
    /// The vertical field of view is not in `(0, pi)` radians.
    #[error("the vertical field of view {0} rad is not strictly between 0 and pi")]
    FovOutOfRange(f32),
    /// A picture side is zero or larger than [`MAX_PICTURE_SIDE`], or the
    /// picture has more than [`MAX_PICTURE_PIXELS`] pixels.
    #[error(
        "picture size {width}x{height} is too large or empty: each side must be between 1 and \
         {MAX_PICTURE_SIDE} pixels and the picture at most {MAX_PICTURE_PIXELS} pixels (8192x8192)"
    )]
    BadSize {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
    },
}

/// The viewpoint of the picture, as a scene file describes it.
///
/// A plain value: anyone may build or change one (the window moves its
/// eye). Invariants hold only once [`Camera::check`] has accepted it:
/// every field finite, `eye != lookat`, `up` non-zero and not parallel to
/// `lookat - eye` (see [`UP_PARALLEL_TOLERANCE`]), `0 < fov_y < pi`, and
/// the picture size within [`picture_size_ok`]. Every loader checks the
/// cameras it returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Viewpoint, in scene units.
    pub eye: Vec3,
    /// Point looked at, in scene units.
    pub lookat: Vec3,
    /// Approximate up direction (need not be orthogonal to the view, nor
    /// of unit length).
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Picture width in pixels.
    pub width: u32,
    /// Picture height in pixels.
    pub height: u32,
}

impl Camera {
    /// A camera that frames the axis-aligned box `bounds_min..bounds_max`
    /// (scene units): what a scene without a camera of its own gets.
    ///
    /// The rule: look at the centre of the box along +z, from the -z side,
    /// with up +y, the default field of view ([`DEFAULT_FOV_DEG`], vertical)
    /// and size ([`DEFAULT_SIZE`]), from the distance at which the box's
    /// bounding sphere exactly fills the vertical field of view:
    /// `distance = radius / sin(fov_y / 2)`, with `radius` half the box's
    /// diagonal. The default picture is wider than tall, so the sphere fits
    /// horizontally too, and the whole scene is in view.
    ///
    /// A box of zero size gets a radius of 1 scene unit, so the result is
    /// always a valid camera (`eye != lookat`, see also
    /// [`FRAME_MIN_RELATIVE_DISTANCE`]), and every field is finite for
    /// finite bounds.
    pub fn frame(bounds_min: Vec3, bounds_max: Vec3) -> Camera {
        let (lo, hi) = (bounds_min.as_dvec3(), bounds_max.as_dvec3());
        let centre = 0.5 * (lo + hi);
        let radius = 0.5 * (hi - lo).length();
        let radius = if radius > 0.0 && radius.is_finite() {
            radius
        } else {
            1.0
        };
        let fov_y = DEFAULT_FOV_DEG.to_radians();
        let distance = (radius / (0.5 * f64::from(fov_y)).sin())
            .max(centre.z.abs() * FRAME_MIN_RELATIVE_DISTANCE);
        let limit = f64::from(f32::MAX);
        let eye_z = (centre.z - distance).clamp(-limit, limit);
        Camera {
            eye: Vec3::new(centre.x as f32, centre.y as f32, eye_z as f32),
            lookat: centre.as_vec3(),
            up: Vec3::Y,
            fov_y,
            width: DEFAULT_SIZE.0,
            height: DEFAULT_SIZE.1,
        }
    }

    /// Validates the camera (see the invariants of [`Camera`]) and derives
    /// its orthonormal frame.
    ///
    /// The checks come in this order, and the first that fails is the
    /// error: finiteness, the viewing direction, up (zero, then parallel),
    /// the field of view, the picture size.
    pub fn check(&self) -> Result<CheckedCamera, CameraError> {
        let finite = self.eye.is_finite()
            && self.lookat.is_finite()
            && self.up.is_finite()
            && self.fov_y.is_finite();
        if !finite {
            return Err(CameraError::NotFinite);
        }
        let forward = (self.lookat - self.eye)
            .try_normalize()
            .ok_or(CameraError::NoViewDirection)?;
        let up_dir = self.up.try_normalize().ok_or(CameraError::UpZero)?;
        // The sine is measured in f64 on the f32 values, so the limit means
        // the same whatever the rounding of the frame below.
        let sine = (self.lookat.as_dvec3() - self.eye.as_dvec3())
            .normalize_or_zero()
            .cross(self.up.as_dvec3().normalize_or_zero())
            .length();
        if sine < UP_PARALLEL_TOLERANCE {
            return Err(CameraError::UpParallel);
        }
        // Gram–Schmidt through the cross product: the given up only has to
        // say which way is up, it need not be orthogonal to the view.
        let right = forward
            .cross(up_dir)
            .try_normalize()
            .ok_or(CameraError::UpParallel)?;
        let up = right.cross(forward);
        if !(self.fov_y > 0.0 && self.fov_y < std::f32::consts::PI) {
            return Err(CameraError::FovOutOfRange(self.fov_y));
        }
        if !picture_size_ok(self.width, self.height) {
            return Err(CameraError::BadSize {
                width: self.width,
                height: self.height,
            });
        }
        Ok(CheckedCamera {
            camera: *self,
            right,
            up,
            forward,
        })
    }
}

/// A [`Camera`] that [`Camera::check`] accepted, with its orthonormal frame.
///
/// Only `check` makes one, so holding one proves every invariant of
/// [`Camera`]. The frame is right-handed in the picture's sense: `right =
/// normalize(forward × up)` runs left to right, `up = right × forward` bottom
/// to top, and all three are unit length and mutually orthogonal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckedCamera {
    camera: Camera,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
}

impl CheckedCamera {
    /// The camera as given.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Unit vector pointing to the right of the picture, in world space.
    pub fn right(&self) -> Vec3 {
        self.right
    }

    /// Unit vector pointing up the picture, in world space: the camera's up
    /// made orthogonal to the view.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// Unit viewing direction, from the eye towards the look-at point.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Distance from the eye to the look-at point, in scene units, `> 0`.
    pub fn distance(&self) -> f32 {
        (self.camera.lookat - self.camera.eye).length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn frame_fits_the_bounding_sphere_in_the_default_view() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 4.0, 6.0));
        let c = Camera::frame(lo, hi);
        assert_eq!(c.lookat, Vec3::new(1.0, 2.0, 4.0));
        assert_eq!(c.up, Vec3::Y);
        assert_eq!(c.fov_y, DEFAULT_FOV_DEG.to_radians());
        assert_eq!((c.width, c.height), DEFAULT_SIZE);
        // Straight down -z from the centre, at radius / sin(fov / 2).
        let radius = 0.5 * (hi - lo).length();
        let distance = radius / (0.5 * c.fov_y).sin();
        assert!((c.eye - Vec3::new(1.0, 2.0, 4.0 - distance)).length() < 1e-4);
    }

    #[test]
    fn frame_is_a_valid_camera_for_degenerate_bounds() {
        let c = Camera::frame(Vec3::ZERO, Vec3::ZERO);
        assert_ne!(c.eye, c.lookat);
        assert!(c.eye.z < 0.0);
        // A tiny scene far away still gets a view direction after rounding.
        let far = Vec3::new(0.0, 0.0, 1e7);
        let c = Camera::frame(far, far + Vec3::splat(1e-6));
        assert_ne!(c.eye, c.lookat);
        assert!(c.eye.is_finite());
        // Huge bounds stay finite.
        let c = Camera::frame(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
        assert!(c.eye.is_finite() && c.lookat.is_finite());
    }

    #[test]
    fn framed_cameras_pass_the_check() {
        for (lo, hi) in [
            (Vec3::ZERO, Vec3::ZERO),
            (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 4.0, 6.0)),
            (Vec3::new(0.0, 0.0, 1e7), Vec3::new(1e-6, 1e-6, 1e7 + 1e-6)),
        ] {
            let c = Camera::frame(lo, hi);
            assert_eq!(c.check().map(|k| *k.camera()), Ok(c));
        }
    }

    #[test]
    fn the_frame_is_orthonormal_and_right_handed() {
        let mut c = camera();
        c.up = Vec3::new(0.0, 1.0, 0.7);
        let k = c.check().unwrap();
        assert!((k.up() - Vec3::Y).length() < 1e-6);
        assert!((k.right() - Vec3::X).length() < 1e-6);
        assert!((k.forward() + Vec3::Z).length() < 1e-6);
        assert!(k.right().dot(k.forward()).abs() < 1e-6);
        assert!((k.distance() - 10.0).abs() < 1e-6);
    }

    #[test]
    fn each_invariant_has_its_error() {
        let with = |f: &dyn Fn(&mut Camera)| {
            let mut c = camera();
            f(&mut c);
            c.check().err()
        };
        assert_eq!(with(&|c| c.eye.x = f32::NAN), Some(CameraError::NotFinite));
        assert_eq!(
            with(&|c| c.fov_y = f32::INFINITY),
            Some(CameraError::NotFinite)
        );
        assert_eq!(
            with(&|c| c.lookat = c.eye),
            Some(CameraError::NoViewDirection)
        );
        assert_eq!(with(&|c| c.up = Vec3::ZERO), Some(CameraError::UpZero));
        assert_eq!(with(&|c| c.up = -Vec3::Z), Some(CameraError::UpParallel));
        assert_eq!(
            with(&|c| c.fov_y = std::f32::consts::PI),
            Some(CameraError::FovOutOfRange(std::f32::consts::PI))
        );
        assert_eq!(
            with(&|c| c.height = 0),
            Some(CameraError::BadSize {
                width: 200,
                height: 0
            })
        );
    }

    #[test]
    fn up_parallel_tolerance_is_the_limit() {
        // Up tilted from the view by an angle whose sine is just above or
        // just below the tolerance.
        let tilt = |sine: f64| {
            let angle = sine.asin() as f32;
            let mut c = camera();
            c.up = Vec3::new(0.0, angle.sin(), -angle.cos());
            c.check().err()
        };
        assert_eq!(tilt(2.0 * UP_PARALLEL_TOLERANCE), None);
        assert_eq!(
            tilt(0.5 * UP_PARALLEL_TOLERANCE),
            Some(CameraError::UpParallel)
        );
    }

    #[test]
    fn picture_size_limits() {
        assert!(picture_size_ok(1, 1));
        assert!(picture_size_ok(8192, 8192));
        assert!(!picture_size_ok(8192, 8193));
        assert!(picture_size_ok(MAX_PICTURE_SIDE, 1));
        assert!(!picture_size_ok(MAX_PICTURE_SIDE + 1, 1));
        assert!(!picture_size_ok(0, 480));
    }
}
