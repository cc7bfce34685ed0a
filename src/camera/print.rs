//! A camera written out so that it can be used again: as command-line
//! options (`--eye X,Y,Z --look-at X,Y,Z --up X,Y,Z --fov DEG --size
//! WxH`, [`options_text`]) and as a `.sc` `camera` block ([`sc_block`]),
//! which `--camera FILE.sc` reads. The window's `c` key prints both.
//!
//! Every number is written so that it reads back to the same `f32`, the
//! way the `.sc` parser and the option parsers read it (as an `f64`,
//! rounded to `f32`): the shortest such text ([`fmt_value`]), so a view
//! found in the window renders again to the same pixels.

use super::Camera;
use glam::Vec3;

/// The shortest decimal text of `v` that reads back to `v` exactly when
/// parsed as an `f64` and rounded to `f32` (as the scene and option
/// parsers do): Rust's shortest `f32` text, or, in the rare case that
/// the double rounding moves it, the shortest text of `v` as an `f64`.
pub fn fmt_value(v: f32) -> String {
    let short = format!("{v}");
    if short
        .parse::<f64>()
        .is_ok_and(|x| (x as f32).to_bits() == v.to_bits())
    {
        short
    } else {
        format!("{}", f64::from(v))
    }
}

/// `X,Y,Z`, each as [`fmt_value`]: the form `--eye`, `--look-at` and
/// `--up` take.
pub fn fmt_point(p: Vec3) -> String {
    format!("{},{},{}", fmt_value(p.x), fmt_value(p.y), fmt_value(p.z))
}

/// `X Y Z`, each as [`fmt_value`]: the form a `.sc` file takes.
fn sc_point(p: Vec3) -> String {
    format!("{} {} {}", fmt_value(p.x), fmt_value(p.y), fmt_value(p.z))
}

/// The field of view in degrees, as text that a `.sc` file's `fov` and
/// `--fov` turn back into `fov_y` radians exactly when such a number of
/// degrees exists (every field of view written in degrees, and every
/// automatic one, has one); otherwise the nearest.
///
/// Both read the degrees as an `f32` and convert them with
/// `f32::to_radians`, which skips some `f32` values; the candidates are
/// the `f32` degrees next to the exact conversion, and the shortest text
/// among those that convert back wins.
pub fn fmt_fov_deg(fov_y: f32) -> String {
    let centre = f64::from(fov_y).to_degrees() as f32;
    let mut candidates = vec![centre];
    let (mut below, mut above) = (centre, centre);
    for _ in 0..4 {
        below = below.next_down();
        above = above.next_up();
        candidates.extend([below, above]);
    }
    candidates
        .into_iter()
        .filter(|d| d.to_radians().to_bits() == fov_y.to_bits())
        .map(fmt_value)
        .min_by_key(|s| s.len())
        .unwrap_or_else(|| fmt_value(centre))
}

/// The camera as command-line options, on one line: `--eye X,Y,Z
/// --look-at X,Y,Z --up X,Y,Z --fov DEG --size WxH`. Given to the
/// program, they make this camera again, bit for bit.
pub fn options_text(camera: &Camera) -> String {
    format!(
        "--eye {} --look-at {} --up {} --fov {} --size {}x{}",
        fmt_point(camera.eye),
        fmt_point(camera.lookat),
        fmt_point(camera.up),
        fmt_fov_deg(camera.fov_y),
        camera.width,
        camera.height
    )
}

/// The camera as a `.sc` `camera` block (see the scene format), ending
/// with a newline. As a file of its own it is a camera file for `--camera`;
/// read back it is this camera, bit for bit.
pub fn sc_block(camera: &Camera) -> String {
    format!(
        "camera\n  eye {}\n  lookat {}\n  up {}\n  fov {}\n  size {} {}\nend\n",
        sc_point(camera.eye),
        sc_point(camera.lookat),
        sc_point(camera.up),
        fmt_fov_deg(camera.fov_y),
        camera.width,
        camera.height
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_read_back_exactly_and_short() {
        for v in [
            0.0f32,
            -0.0,
            1.0,
            -2.5,
            0.1,
            1.0 / 3.0,
            1e-7,
            3.4e38,
            -f32::MIN_POSITIVE,
            16_777_217.0,
            123.456,
        ] {
            let text = fmt_value(v);
            let back = text.parse::<f64>().unwrap() as f32;
            assert_eq!(back.to_bits(), v.to_bits(), "{v} -> {text}");
        }
        assert_eq!(fmt_value(0.1), "0.1");
        assert_eq!(fmt_value(-2.5), "-2.5");
        assert_eq!(fmt_point(Vec3::new(1.0, -0.5, 2.0)), "1,-0.5,2");
    }

    #[test]
    fn fields_of_view_given_in_degrees_come_back_as_written() {
        for deg in [45.0f32, 65.0, 30.0, 90.0, 1.0, 179.0, 0.001, 33.3] {
            assert_eq!(fmt_fov_deg(deg.to_radians()), fmt_value(deg), "{deg}");
        }
    }

    #[test]
    fn the_options_and_the_block_say_every_part() {
        let c = Camera {
            eye: Vec3::new(1.0, 1.6, -0.25),
            lookat: Vec3::new(5.5, 1.6, 2.0),
            up: Vec3::Y,
            fov_y: 65f32.to_radians(),
            width: 800,
            height: 600,
        };
        assert_eq!(
            options_text(&c),
            "--eye 1,1.6,-0.25 --look-at 5.5,1.6,2 --up 0,1,0 --fov 65 --size 800x600"
        );
        assert_eq!(
            sc_block(&c),
            "camera\n  eye 1 1.6 -0.25\n  lookat 5.5 1.6 2\n  up 0 1 0\n  fov 65\n  size 800 600\nend\n"
        );
    }
}
