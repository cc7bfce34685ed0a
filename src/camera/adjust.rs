//! A camera changed in parts from the command line: `--eye`, `--look-at`,
//! `--up` and `--fov` (what Radiance's `-vp`, `-vd`, `-vu` and `-vv` set),
//! each replacing its part of whatever camera the scene has (its own, the
//! `--camera FILE.sc` one, or the automatic one) and leaving the rest.
//!
//! [`CameraOverride::apply`] makes the new camera and checks it with
//! [`Camera::check`]; its errors ([`OverrideError`]) name the options at
//! fault, since an eye that is fine alone may sit on the scene's own
//! look-at point.

use super::print::{fmt_point, fmt_value};
use super::{Camera, CameraError};
use glam::Vec3;
use thiserror::Error;

/// The parts of the camera the command line gives; `None` keeps the
/// scene's. Values are as parsed: finite, `up` non-zero, the field of view
/// strictly between 0 and 180 degrees (the parsers in `cli` check that).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraOverride {
    /// `--eye X,Y,Z`: the viewpoint, in scene units.
    pub eye: Option<Vec3>,
    /// `--look-at X,Y,Z`: the point looked at, in scene units.
    pub lookat: Option<Vec3>,
    /// `--up X,Y,Z`: the up direction (any length but zero; need not be
    /// orthogonal to the view).
    pub up: Option<Vec3>,
    /// `--fov DEG`: the vertical field of view, in degrees.
    pub fov_deg: Option<f32>,
}

/// Why the camera made from the options is unusable: one sentence naming
/// the options to change.
#[derive(Clone, Debug, PartialEq, Error)]
#[error("{0}")]
pub struct OverrideError(pub String);

impl CameraOverride {
    /// True when no part is given: [`CameraOverride::apply`] returns the
    /// camera unchanged.
    pub fn is_empty(&self) -> bool {
        *self == CameraOverride::default()
    }

    /// `camera` with the given parts replaced, checked by
    /// [`Camera::check`]. The field of view is turned into radians as a
    /// `.sc` file's `fov` is (in `f32`), so options and a camera block
    /// with the same numbers give the same camera, bit for bit.
    pub fn apply(&self, camera: &Camera) -> Result<Camera, OverrideError> {
        let mut out = *camera;
        if let Some(eye) = self.eye {
            out.eye = eye;
        }
        if let Some(lookat) = self.lookat {
            out.lookat = lookat;
        }
        if let Some(up) = self.up {
            out.up = up;
        }
        if let Some(deg) = self.fov_deg {
            out.fov_y = deg.to_radians();
        }
        if self.is_empty() {
            return Ok(out);
        }
        out.check().map(|_| out).map_err(|e| self.explain(&out, e))
    }

    /// The message for the error `e` of the camera `made` by the options.
    fn explain(&self, made: &Camera, e: CameraError) -> OverrideError {
        let (eye, lookat, up) = (
            fmt_point(made.eye),
            fmt_point(made.lookat),
            fmt_point(made.up),
        );
        let message = match e {
            CameraError::NoViewDirection => match (self.eye, self.lookat) {
                (Some(_), Some(_)) => format!(
                    "--eye {eye} and --look-at {lookat} are the same point: the camera has no \
                     view direction"
                ),
                (Some(_), None) => format!(
                    "--eye {eye} is the scene camera's look-at point: the camera has no view \
                     direction; give --look-at too"
                ),
                _ => format!(
                    "--look-at {lookat} is the scene camera's eye: the camera has no view \
                     direction; give --eye too"
                ),
            },
            CameraError::UpParallel if self.up.is_some() => format!(
                "--up {up} is parallel to the view direction (from {eye} to {lookat}): \
                 give an --up across the view"
            ),
            CameraError::UpParallel => format!(
                "the view from {eye} to {lookat} is parallel to the camera's up direction \
                 {up}: give --up across the view"
            ),
            CameraError::UpZero => "--up must not be zero".to_string(),
            CameraError::FovOutOfRange(rad) => format!(
                "--fov {} is out of range: it must be more than 0 and less than 180 degrees",
                fmt_value(rad.to_degrees())
            ),
            e => format!("the camera made by --eye, --look-at, --up and --fov is unusable: {e}"),
        };
        OverrideError(message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_camera() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 1.0, -5.0),
            lookat: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fov_y: 45f32.to_radians(),
            width: 64,
            height: 48,
        }
    }

    #[test]
    fn each_option_replaces_its_part_only() {
        let c = scene_camera();
        assert_eq!(CameraOverride::default().apply(&c), Ok(c));
        let eye = Vec3::new(1.0, 2.0, -3.0);
        let moved = CameraOverride {
            eye: Some(eye),
            ..CameraOverride::default()
        }
        .apply(&c)
        .unwrap();
        assert_eq!(moved, Camera { eye, ..c });
        let wide = CameraOverride {
            fov_deg: Some(90.0),
            ..CameraOverride::default()
        }
        .apply(&c)
        .unwrap();
        assert_eq!(wide.fov_y, 90f32.to_radians());
        assert_eq!((wide.eye, wide.lookat, wide.up), (c.eye, c.lookat, c.up));
    }

    #[test]
    fn each_bad_combination_names_its_options() {
        let c = scene_camera();
        let with = |o: CameraOverride| o.apply(&c).unwrap_err().to_string();
        let p = Vec3::new(1.0, 2.0, 3.0);
        let both = with(CameraOverride {
            eye: Some(p),
            lookat: Some(p),
            ..CameraOverride::default()
        });
        assert_eq!(
            both,
            "--eye 1,2,3 and --look-at 1,2,3 are the same point: the camera has no view direction"
        );
        let onto = with(CameraOverride {
            eye: Some(c.lookat),
            ..CameraOverride::default()
        });
        assert!(
            onto.starts_with("--eye 0,1,0 is the scene camera's look-at point"),
            "{onto}"
        );
        assert!(onto.ends_with("give --look-at too"), "{onto}");
        let up = with(CameraOverride {
            up: Some(Vec3::Z),
            ..CameraOverride::default()
        });
        assert_eq!(
            up,
            "--up 0,0,1 is parallel to the view direction (from 0,1,-5 to 0,1,0): give an --up \
             across the view"
        );
        let down = with(CameraOverride {
            eye: Some(Vec3::new(0.0, 9.0, 0.0)),
            ..CameraOverride::default()
        });
        assert!(
            down.contains("parallel to the camera's up direction 0,1,0"),
            "{down}"
        );
    }
}
