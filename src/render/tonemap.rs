//! From linear radiosity to 8-bit sRGB pictures.
//!
//! A [`Frame`] holds radiosity in the scene's own units, which say nothing
//! about how bright a picture should be. Tone mapping here is the simplest
//! that keeps the radiosity proportional: multiply by an exposure, clip to
//! `[0, 1]`, encode with the sRGB transfer curve, round to 8 bits. The
//! exposure is chosen from the frame ([`auto_exposure`]), in stops around
//! that ([`Exposure::Stops`], as photographers and Radiance's `pfilt -e`
//! count), or given ([`Exposure::Fixed`]).

use super::raster::Frame;
use crate::color::Rgb;
use image::RgbImage;
use rayon::prelude::*;

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

/// The most stops [`Exposure::Stops`] may be from the automatic exposure,
/// either way: 2^40 is about 10^12, past any picture worth looking at,
/// and far from overflowing an `f32` factor.
pub const MAX_EXPOSURE_STOPS: f32 = 40.0;

/// How a frame's linear values are scaled before encoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// Chosen from the frame by [`auto_exposure`].
    Auto,
    /// This many stops above (below, when negative) [`auto_exposure`]:
    /// the factor is the automatic one × 2^stops, so `Stops(0.0)` is
    /// `Auto`. Finite, within [`MAX_EXPOSURE_STOPS`].
    Stops(f32),
    /// This factor, dimensionless: linear value `v` is shown as `v * factor`.
    Fixed(f32),
}

impl Exposure {
    /// The factor to use for `frame`.
    pub fn resolve(self, frame: &Frame) -> f32 {
        match self {
            Exposure::Fixed(k) => k,
            relative => relative.with_auto(auto_exposure(frame)),
        }
    }

    /// The factor when the frame's automatic exposure is `auto`.
    pub fn with_auto(self, auto: f32) -> f32 {
        match self {
            Exposure::Auto => auto,
            Exposure::Stops(stops) => auto * stops.exp2(),
            Exposure::Fixed(k) => k,
        }
    }

    /// How many stops the factor is from the automatic exposure `auto`:
    /// 0 for `Auto`, the stops given for `Stops`, `log2(k / auto)` for
    /// `Fixed(k)`.
    pub fn stops(self, auto: f32) -> f32 {
        match self {
            Exposure::Auto => 0.0,
            Exposure::Stops(stops) => stops,
            Exposure::Fixed(k) => (k / auto).log2(),
        }
    }
}

/// The exposure that maps the [`AUTO_PERCENTILE`] of the luminance (Rec. 709
/// weights) of the covered pixels to [`AUTO_TARGET`]. Pixels wholly on back
/// faces ([`Frame::back`] of 1) do not count: they hold no light, and a
/// wall the eye stepped through must not darken or brighten the rest.
///
/// If that percentile is zero (a mostly dark picture), the brightest pixel is
/// used instead; if the frame has no covered pixel with a positive finite
/// luminance, the result is [`FALLBACK_EXPOSURE`]. Always finite and `> 0`.
pub fn auto_exposure(frame: &Frame) -> f32 {
    lit_exposure(frame).unwrap_or(FALLBACK_EXPOSURE)
}

/// How much darker than [`auto_exposure`] a picture that shows the ambient
/// term is exposed when nothing in its view has any solved light
/// (dimensionless: a sixteenth, four stops): the unlit surfaces show their
/// share of the ambient estimate dimly, so the shapes stay visible to
/// steer by, never as a bright picture.
pub const UNLIT_EXPOSURE_SHARE: f32 = 0.0625;

/// The longest side, in pixels, of the picture of the solution alone that
/// [`auto_exposure_beside`] measures: its statistics need no more, and it
/// costs a sixteenth of a 640-pixel window.
pub const EXPOSURE_PROBE_SIDE: u32 = 160;

/// The size of the solution's picture for [`auto_exposure_beside`] of a
/// `width × height` picture: the same shape, its longest side at most
/// [`EXPOSURE_PROBE_SIDE`], each side at least 1.
pub fn exposure_probe_size(width: u32, height: u32) -> (u32, u32) {
    let longest = width.max(height).max(1);
    if longest <= EXPOSURE_PROBE_SIDE {
        return (width.max(1), height.max(1));
    }
    let scale = |side: u32| {
        ((u64::from(side) * u64::from(EXPOSURE_PROBE_SIDE)).div_ceil(u64::from(longest)) as u32)
            .max(1)
    };
    (scale(width), scale(height))
}

/// The automatic exposure of a picture `shown` that adds the ambient term
/// ([`crate::solver::Progressive::ambient`]) to the solution, given the
/// picture of the same view of the solution alone, `solution` (any size,
/// [`exposure_probe_size`]): [`auto_exposure`] of `shown`, but never more
/// than that of `solution`, and [`UNLIT_EXPOSURE_SHARE`] of it when no
/// pixel of `solution` holds light.
///
/// The ambient term estimates what is still to come, spread evenly over
/// every surface; it may brighten a picture, but it must not set its
/// exposure: seen from outside a room lit from within, the walls hold
/// nothing but the ambient term, and exposing for it scaled a dim estimate
/// up thousands of times into a bright, flat picture. Where the solution
/// has light in view, its own exposure is the larger one (the ambient only
/// adds), so the rule changes nothing there.
pub fn auto_exposure_beside(shown: &Frame, solution: &Frame) -> f32 {
    let exposure = auto_exposure(shown);
    match lit_exposure(solution) {
        Some(lit) => exposure.min(lit),
        None => exposure * UNLIT_EXPOSURE_SHARE,
    }
}

/// [`auto_exposure`] without its fallback: `None` when no covered pixel
/// (back faces not counted) has a positive finite luminance.
fn lit_exposure(frame: &Frame) -> Option<f32> {
    // Read twice or three times rather than collected: a frame has about a
    // million pixels, and the selection needs only one bucket of them.
    // A few work items a thread: each carries a table of bucket counts.
    let chunk = frame
        .pixels
        .len()
        .div_ceil(4 * rayon::current_num_threads())
        .max(MIN_EXPOSURE_CHUNK);
    let luminances = || {
        frame
            .pixels
            .par_chunks(chunk)
            .zip(frame.covered.par_chunks(chunk))
            .enumerate()
            .flat_map_iter(move |(k, (pixels, covered))| {
                let back = frame.back.get(k * chunk..).unwrap_or_default();
                pixels
                    .iter()
                    .zip(covered)
                    .enumerate()
                    .filter(move |&(i, (_, &c))| c && back.get(i).is_none_or(|&b| b < 1.0))
                    .map(|(_, (p, _))| {
                        Rgb::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])).luminance()
                    })
                    .filter(|l| l.is_finite())
            })
    };
    let at_rank = nth_smallest(luminances, |n| {
        // Nearest-rank percentile: the smallest value with at least that
        // fraction of the pixels at or below it.
        ((AUTO_PERCENTILE * n as f64).ceil() as usize).clamp(1, n) - 1
    })?;
    let reference = if at_rank > 0.0 {
        at_rank
    } else {
        luminances().reduce(|| 0.0, f64::max)
    };
    let exposure = (AUTO_TARGET / reference) as f32;
    (reference > 0.0 && exposure.is_finite() && exposure > 0.0).then_some(exposure)
}

/// Fewest pixels per parallel work item of [`auto_exposure`].
const MIN_EXPOSURE_CHUNK: usize = 64 * 1024;

/// Bits of the order key that pick a bucket in [`nth_smallest`]: sign,
/// exponent and four mantissa bits, so a bucket spans 1/16 of an octave.
const SELECT_BUCKET_BITS: u32 = 16;

/// The `rank(n)`-th smallest (from 0) of the `n` values `values()` yields,
/// in the order of [`f64::total_cmp`]; `None` when there are none (or the
/// rank is not below `n`).
///
/// One parallel pass counts the values per bucket of their leading bits,
/// which finds the bucket holding the rank; a second collects that bucket
/// only, which is searched. The value is the same as a full sort's,
/// whatever the thread count.
fn nth_smallest<I, F>(values: F, rank: impl Fn(usize) -> usize) -> Option<f64>
where
    F: Fn() -> I,
    I: ParallelIterator<Item = f64>,
{
    // `total_cmp`'s order as unsigned integers.
    let key = |v: f64| {
        let bits = v.to_bits();
        (bits ^ ((((bits as i64) >> 63) as u64) >> 1)) ^ (1 << 63)
    };
    let shift = 64 - SELECT_BUCKET_BITS;
    let bucket_of = |v: f64| (key(v) >> shift) as usize;
    let buckets = 1usize << SELECT_BUCKET_BITS;
    let counts = values()
        .fold(
            || vec![0u32; buckets],
            |mut counts, v| {
                counts[bucket_of(v)] += 1;
                counts
            },
        )
        .reduce_with(|mut a, b| {
            for (a, b) in a.iter_mut().zip(&b) {
                *a += b;
            }
            a
        })?;
    let n: usize = counts.iter().map(|&c| c as usize).sum();
    if n == 0 {
        return None;
    }
    let rank = rank(n);
    let mut below = 0usize;
    for (bucket, &count) in counts.iter().enumerate() {
        let count = count as usize;
        if rank < below + count {
            let mut inside: Vec<f64> = values().filter(|&v| bucket_of(v) == bucket).collect();
            let (_, &mut at, _) = inside.select_nth_unstable_by(rank - below, f64::total_cmp);
            return Some(at);
        }
        below += count;
    }
    None
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

/// Buckets of the exposed linear value in `[0, 1)` in [`Srgb8Table`]: the
/// 8-bit code changes at most once within one, because the sRGB curve's
/// slope never exceeds 12.92, so codes change at most `255 × 12.92 ≈ 3,295`
/// times per unit, fewer than the buckets.
const TABLE_BUCKETS: usize = 4096;

/// [`srgb8`] as a table: the code at the start of each bucket of the
/// exposed linear value, and where in the bucket it steps up by one. Built
/// from [`srgb8`]'s own curve, so the codes are the same bits.
struct Srgb8Table {
    base: Vec<u8>,
    /// The smallest value of the bucket whose code is `base + 1`
    /// (infinite where the code does not change).
    step: Vec<f64>,
}

/// The code of an exposed linear value, [`srgb8`]'s curve.
fn code(x: f64) -> u8 {
    (srgb_encode(x) * 255.0).round() as u8
}

impl Srgb8Table {
    fn new() -> Srgb8Table {
        let n = TABLE_BUCKETS as f64;
        let mut base = Vec::with_capacity(TABLE_BUCKETS);
        let mut step = Vec::with_capacity(TABLE_BUCKETS);
        for i in 0..TABLE_BUCKETS {
            let lo = i as f64 / n;
            let b = code(lo);
            // The last value of the bucket: positive floats are ordered as
            // their bits, so one bit less is the next smaller value.
            let last = f64::from_bits(((i + 1) as f64 / n).to_bits() - 1);
            base.push(b);
            if code(last) == b {
                step.push(f64::INFINITY);
                continue;
            }
            // Bisection over the bits for the first value with a higher code.
            let (mut below, mut at) = (lo.to_bits(), last.to_bits());
            while at - below > 1 {
                let mid = below + (at - below) / 2;
                if code(f64::from_bits(mid)) > b {
                    at = mid;
                } else {
                    below = mid;
                }
            }
            step.push(f64::from_bits(at));
        }
        Srgb8Table { base, step }
    }

    /// The shared table, built on first use (a few thousand evaluations
    /// of the curve).
    fn get() -> &'static Srgb8Table {
        static TABLE: std::sync::OnceLock<Srgb8Table> = std::sync::OnceLock::new();
        TABLE.get_or_init(Srgb8Table::new)
    }

    /// `code(x)` by lookup.
    fn code(&self, x: f64) -> u8 {
        // NaN and negative values are clipped to black, as `srgb_encode` does.
        if x.is_nan() || x <= 0.0 {
            return 0;
        }
        if x >= 1.0 {
            return 255;
        }
        // Exact (a power of two times x), and below the bucket count.
        let i = ((x * TABLE_BUCKETS as f64) as usize).min(TABLE_BUCKETS - 1);
        self.base[i] + u8::from(x >= self.step[i])
    }
}

/// The two 8-bit sRGB colours of pixels that show the back of a polygon,
/// in diagonal stripes [`BACK_FACE_STRIPE`] pixels wide: a dim,
/// desaturated blue-grey, never black and unlike any lit wall, so a user
/// whose eye went through a wall sees where they are. Fixed, whatever the
/// exposure.
pub const BACK_FACE_COLORS: [[u8; 3]; 2] = [[60, 66, 84], [46, 51, 66]];

/// Width of the stripes of [`BACK_FACE_COLORS`], in pixels along a row.
pub const BACK_FACE_STRIPE: u32 = 4;

/// The 8-bit colour of a back face at column `x`, row `y` of a picture:
/// stripes running from bottom-left to top-right.
pub fn back_face_color(x: u32, y: u32) -> [u8; 3] {
    BACK_FACE_COLORS[((x.wrapping_add(y) / BACK_FACE_STRIPE) % 2) as usize]
}

/// The inverse of [`srgb_encode`]: an encoded value in `[0, 1]` to linear.
fn srgb_decode(e: f64) -> f64 {
    if e <= 12.92 * SRGB_LINEAR_LIMIT {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

/// The frame as an 8-bit sRGB picture, each linear channel multiplied by
/// `exposure` (dimensionless), clipped to `[0, 1]` and encoded: per
/// channel exactly [`srgb8`]. Rows are in the frame's order (top first).
/// Pixels the frame lacks (a frame whose buffers are shorter than its
/// size) are black.
///
/// Pixels showing back faces ([`Frame::back`]) are painted
/// [`back_face_color`]; a pixel partly a back face (antialiased) mixes
/// that colour in linear light, in proportion, with its exposed radiosity.
pub fn to_srgb8(frame: &Frame, exposure: f32) -> RgbImage {
    let mut img = RgbImage::new(frame.width, frame.height);
    let w = frame.width as usize;
    if w == 0 {
        return img;
    }
    let table = Srgb8Table::get();
    let e = f64::from(exposure);
    let back_linear = BACK_FACE_COLORS.map(|c| c.map(|k| srgb_decode(f64::from(k) / 255.0)));
    let bytes: &mut [u8] = &mut img;
    bytes
        .par_chunks_mut(3 * w)
        .zip(frame.pixels.par_chunks(w))
        .enumerate()
        .for_each(|(y, (out, pixels))| {
            let back = frame.back.get(y * w..).unwrap_or_default();
            for (x, (o, p)) in out.chunks_exact_mut(3).zip(pixels).enumerate() {
                let f = back.get(x).copied().unwrap_or(0.0);
                if f <= 0.0 {
                    for k in 0..3 {
                        o[k] = table.code(f64::from(p[k]) * e);
                    }
                } else if f >= 1.0 {
                    o.copy_from_slice(&back_face_color(x as u32, y as u32));
                } else {
                    let stripe = &back_linear[((x + y) / BACK_FACE_STRIPE as usize) % 2];
                    for k in 0..3 {
                        o[k] = table.code(f64::from(p[k]) * e + f64::from(f) * stripe[k]);
                    }
                }
            }
        });
    img
}

#[cfg(test)]
mod tests;
