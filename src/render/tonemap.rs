//! From linear radiosity to 8-bit sRGB pictures.
//!
//! A [`Frame`] holds radiosity in the scene's own units, which say nothing
//! about how bright a picture should be. Tone mapping here is the simplest
//! that keeps the radiosity proportional: multiply by an exposure, clip to
//! `[0, 1]`, encode with the sRGB transfer curve, round to 8 bits. The
//! exposure is given ([`Exposure::Fixed`]) or chosen from the frame
//! ([`auto_exposure`]).

use super::raster::Frame;
use crate::color::Rgb;
use image::RgbImage;

/// Which luminance percentile of the covered pixels [`auto_exposure`] puts
/// at [`AUTO_TARGET`]. Below one so that a few very bright pixels (the light
/// sources) may clip rather than darken the whole picture.
pub const AUTO_PERCENTILE: f64 = 0.95;

/// The linear value, after exposure, that [`auto_exposure`] maps the
/// [`AUTO_PERCENTILE`] luminance to. Below one to leave headroom for colour:
/// a saturated pixel of that luminance still has room in its brightest
/// channel.
pub const AUTO_TARGET: f64 = 0.9;

/// Exposure used when a frame gives nothing to measure (no covered pixel, or
/// all of them black).
pub const FALLBACK_EXPOSURE: f32 = 1.0;

/// The linear value below which the sRGB curve is a straight line
/// (IEC 61966-2-1).
pub const SRGB_LINEAR_LIMIT: f64 = 0.003_130_8;

/// How a frame's linear values are scaled before encoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// Chosen from the frame by [`auto_exposure`].
    Auto,
    /// This factor, dimensionless: linear value `v` is shown as `v * factor`.
    Fixed(f32),
}

impl Exposure {
    /// The factor to use for `frame`.
    pub fn resolve(self, frame: &Frame) -> f32 {
        match self {
            Exposure::Auto => auto_exposure(frame),
            Exposure::Fixed(k) => k,
        }
    }
}

/// The exposure that maps the [`AUTO_PERCENTILE`] of the luminance (Rec. 709
/// weights) of the covered pixels to [`AUTO_TARGET`].
///
/// If that percentile is zero (a mostly dark picture), the brightest pixel is
/// used instead; if the frame has no covered pixel with a positive finite
/// luminance, the result is [`FALLBACK_EXPOSURE`]. Always finite and `> 0`.
pub fn auto_exposure(frame: &Frame) -> f32 {
    let mut lum: Vec<f64> = frame
        .pixels
        .iter()
        .zip(&frame.covered)
        .filter(|(_, &c)| c)
        .map(|(p, _)| Rgb::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])).luminance())
        .filter(|l| l.is_finite())
        .collect();
    if lum.is_empty() {
        return FALLBACK_EXPOSURE;
    }
    // Nearest-rank percentile: the smallest value with at least that
    // fraction of the pixels at or below it.
    let rank = ((AUTO_PERCENTILE * lum.len() as f64).ceil() as usize).clamp(1, lum.len()) - 1;
    let (_, &mut at_rank, _) = lum.select_nth_unstable_by(rank, f64::total_cmp);
    let reference = if at_rank > 0.0 {
        at_rank
    } else {
        lum.iter().copied().fold(0.0, f64::max)
    };
    let exposure = (AUTO_TARGET / reference) as f32;
    if reference > 0.0 && exposure.is_finite() && exposure > 0.0 {
        exposure
    } else {
        FALLBACK_EXPOSURE
    }
}

/// The sRGB transfer function (OETF): linear `v` in `[0, 1]` to the encoded
/// value in `[0, 1]`, the exact piecewise curve of IEC 61966-2-1. Inputs
/// outside `[0, 1]` (and NaN) are clipped first.
pub fn srgb_encode(v: f64) -> f64 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    if v <= SRGB_LINEAR_LIMIT {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// One linear value, scaled by `exposure`, as an 8-bit sRGB code.
pub fn srgb8(v: f32, exposure: f32) -> u8 {
    let encoded = srgb_encode(f64::from(v) * f64::from(exposure));
    // In [0, 255] after the clip, so the conversion cannot saturate.
    (encoded * 255.0).round() as u8
}

/// The frame as an 8-bit sRGB picture, each linear channel multiplied by
/// `exposure` (dimensionless), clipped to `[0, 1]` and encoded. Rows are in
/// the frame's order (top first). Pixels the frame lacks (a frame whose
/// buffers are shorter than its size) are black.
pub fn to_srgb8(frame: &Frame, exposure: f32) -> RgbImage {
    let mut img = RgbImage::new(frame.width, frame.height);
    for (out, p) in img.pixels_mut().zip(&frame.pixels) {
        out.0 = [
            srgb8(p[0], exposure),
            srgb8(p[1], exposure),
            srgb8(p[2], exposure),
        ];
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tolerance of exposure comparisons, relative.
    const EXPOSURE_TOLERANCE: f32 = 1e-6;

    fn frame(values: &[f32], covered: &[bool]) -> Frame {
        let mut f = Frame::new(values.len() as u32, 1);
        for (i, (&v, &c)) in values.iter().zip(covered).enumerate() {
            f.pixels[i] = [v; 3];
            f.covered[i] = c;
        }
        f
    }

    #[test]
    fn srgb_known_values() {
        assert_eq!(srgb8(0.0, 1.0), 0);
        assert_eq!(srgb8(1.0, 1.0), 255);
        assert_eq!(srgb8(0.5, 1.0), 188);
        assert_eq!(srgb8(2.0, 1.0), 255);
        assert_eq!(srgb8(-1.0, 1.0), 0);
        assert_eq!(srgb8(f32::NAN, 1.0), 0);
        assert_eq!(srgb8(0.25, 2.0), 188);
        // At the joint both pieces give 0.0404500..., i.e. code 10.
        let linear = 12.92 * SRGB_LINEAR_LIMIT;
        let curved = 1.055 * SRGB_LINEAR_LIMIT.powf(1.0 / 2.4) - 0.055;
        assert!((linear - curved).abs() < 1e-7);
        assert_eq!(srgb_encode(SRGB_LINEAR_LIMIT), linear);
        assert_eq!(srgb8(SRGB_LINEAR_LIMIT as f32, 1.0), 10);
        assert_eq!(srgb8(0.001, 1.0), 3); // 12.92e-3 * 255 = 3.29
    }

    #[test]
    fn auto_exposure_of_uniform_frame() {
        let f = frame(&[2.0; 10], &[true; 10]);
        let k = auto_exposure(&f);
        assert!((k - 0.45).abs() < EXPOSURE_TOLERANCE * 0.45, "{k}");
        assert_eq!(Exposure::Auto.resolve(&f), k);
        assert_eq!(Exposure::Fixed(3.0).resolve(&f), 3.0);
    }

    #[test]
    fn auto_exposure_ignores_uncovered_and_the_brightest() {
        // 20 covered pixels: 19 at 1.0, one light at 100; 95% rank is a 1.0.
        let mut values = vec![1.0; 20];
        values[7] = 100.0;
        values.push(50.0);
        let mut covered = vec![true; 20];
        covered.push(false);
        let k = auto_exposure(&frame(&values, &covered));
        assert!((k - 0.9).abs() < EXPOSURE_TOLERANCE, "{k}");
    }

    #[test]
    fn dark_frames_do_not_give_nan() {
        let black = frame(&[0.0; 4], &[true; 4]);
        assert_eq!(auto_exposure(&black), FALLBACK_EXPOSURE);
        let empty = frame(&[0.0; 4], &[false; 4]);
        assert_eq!(auto_exposure(&empty), FALLBACK_EXPOSURE);
        assert_eq!(auto_exposure(&Frame::new(0, 0)), FALLBACK_EXPOSURE);
        // Mostly black with one lit pixel: the lit one sets the exposure.
        let mut values = vec![0.0; 100];
        values[3] = 3.0;
        let k = auto_exposure(&frame(&values, &[true; 100]));
        assert!((k - 0.3).abs() < EXPOSURE_TOLERANCE, "{k}");
        let img = to_srgb8(&black, auto_exposure(&black));
        assert!(img.pixels().all(|p| p.0 == [0, 0, 0]));
    }

    #[test]
    fn to_srgb8_keeps_size_and_order() {
        let mut f = Frame::new(2, 2);
        f.pixels = vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.5, 0.5],
        ];
        let img = to_srgb8(&f, 1.0);
        assert_eq!(img.dimensions(), (2, 2));
        assert_eq!(img.get_pixel(0, 0).0, [255, 0, 0]);
        assert_eq!(img.get_pixel(1, 0).0, [0, 255, 0]);
        assert_eq!(img.get_pixel(0, 1).0, [0, 0, 255]);
        assert_eq!(img.get_pixel(1, 1).0, [188, 188, 188]);
    }
}
