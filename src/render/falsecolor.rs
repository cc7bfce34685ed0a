//! False colour: a picture of a quantity (luminance, illuminance) with a
//! colour scale and a legend giving values and units, as Radiance's
//! `falsecolor` draws them; and the plan of a work plane with its isolux
//! lines.
//!
//! Values map to colours through a [`Mapping`]: linear from 0 to the
//! maximum, or logarithmic over [`LOG_DECADES`] decades below it. The
//! palette runs from dark blue (low) through cyan, green and yellow to red
//! (high), and is drawn as [`LEGEND_STEPS`] bands in a legend on the left
//! of the picture, each labelled with the value at its lower edge; the
//! legend's title names the quantity and its unit. Pixels that show no
//! surface stay black. Text uses the bundled Noto Mono font (SIL Open Font
//! License, `assets/fonts/OFL.txt`).

use image::RgbImage;
use plotters::prelude::*;

/// The family name the bundled font is registered under ([`super::text`]).
const FONT: &str = super::text::FONT_FAMILY;

/// Decades a logarithmic scale spans below its maximum (Radiance's
/// `falsecolor -log` default is 2; 3 shows the dim corners of a room).
pub const LOG_DECADES: f64 = 3.0;

/// Bands in the legend (and levels of isolux lines on a plan).
pub const LEGEND_STEPS: usize = 8;

/// Width of the legend in pixels.
pub const LEGEND_WIDTH: u32 = 120;

/// Palette stops from low to high (sRGB): dark blue, blue, cyan, green,
/// yellow, orange, red.
const PALETTE: [[f64; 3]; 7] = [
    [0.10, 0.00, 0.35],
    [0.00, 0.20, 0.90],
    [0.00, 0.75, 0.95],
    [0.10, 0.80, 0.20],
    [0.95, 0.90, 0.10],
    [1.00, 0.50, 0.00],
    [0.85, 0.00, 0.00],
];

/// What a false-colour picture of the view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Quantity {
    /// Luminance, `radiosity / π` of the surface seen (cd/m² with units).
    Luminance,
    /// Illuminance on the surface seen (lux with units).
    Illuminance,
}

/// How the scale runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Scale {
    /// Logarithmic, over [`LOG_DECADES`] decades below the maximum.
    #[value(help = "Logarithmic, over three decades below the maximum")]
    Log,
    /// Linear from 0 to the maximum.
    Linear,
}

/// Values to the palette's `[0, 1]`.
///
/// Invariant: `max > 0` and finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mapping {
    /// The value shown red (and everything above it), in the quantity's
    /// unit.
    pub max: f64,
    /// Linear or logarithmic.
    pub scale: Scale,
}

impl Mapping {
    /// A mapping up to `max` (the given one, or the largest of `values`
    /// rounded up to a round number when `None`); `max` falls back to 1
    /// when nothing is positive.
    pub fn new(values: &[f64], max: Option<f64>, scale: Scale) -> Mapping {
        let max = max
            .filter(|m| m.is_finite() && *m > 0.0)
            .unwrap_or_else(|| {
                let top = values
                    .iter()
                    .copied()
                    .filter(|v| v.is_finite())
                    .fold(0.0, f64::max);
                nice_ceiling(top)
            });
        Mapping { max, scale }
    }

    /// Where `value` lies on the palette, in `[0, 1]`.
    pub fn position(&self, value: f64) -> f64 {
        let t = match self.scale {
            Scale::Linear => value / self.max,
            Scale::Log => {
                if value <= 0.0 {
                    0.0
                } else {
                    1.0 + (value / self.max).log10() / LOG_DECADES
                }
            }
        };
        if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// The value at palette position `t` in `[0, 1]` (the inverse of
    /// [`Mapping::position`]).
    pub fn value_at(&self, t: f64) -> f64 {
        match self.scale {
            Scale::Linear => t * self.max,
            Scale::Log => self.max * 10f64.powf((t - 1.0) * LOG_DECADES),
        }
    }

    /// The colour of `value`.
    pub fn colour(&self, value: f64) -> [u8; 3] {
        palette(self.position(value))
    }
}

/// The palette's sRGB colour at `t` in `[0, 1]`.
pub fn palette(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (PALETTE.len() - 1) as f64;
    let k = (x.floor() as usize).min(PALETTE.len() - 2);
    let f = x - k as f64;
    let (a, b) = (PALETTE[k], PALETTE[k + 1]);
    std::array::from_fn(|c| ((a[c] + (b[c] - a[c]) * f) * 255.0).round() as u8)
}

/// The smallest of 1, 2 or 5 times a power of ten at least `x` (1 for
/// anything not positive).
pub fn nice_ceiling(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return 1.0;
    }
    let p = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&v| v >= x * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// A value for a legend label: three significant digits at most.
pub fn label(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else if v.abs() >= 1.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// A picture of `values` (`width × height`, row-major from the top; `None`
/// where no surface is seen, drawn black) in false colour, with the legend
/// on its left titled `title` (the quantity) and `unit`.
pub fn picture(
    values: &[Option<f64>],
    width: u32,
    height: u32,
    mapping: Mapping,
    title: &str,
    unit: &str,
) -> RgbImage {
    let total_height = height.max(LEGEND_MIN_HEIGHT);
    let mut img = RgbImage::new(LEGEND_WIDTH + width, total_height);
    for y in 0..height {
        for x in 0..width {
            let c = values
                .get((y * width + x) as usize)
                .copied()
                .flatten()
                .map_or([0, 0, 0], |v| mapping.colour(v));
            img.put_pixel(LEGEND_WIDTH + x, y, image::Rgb(c));
        }
    }
    draw_legend(&mut img, mapping, title, unit);
    img
}

/// The legend needs this much height to be legible; a smaller picture is
/// padded below.
pub const LEGEND_MIN_HEIGHT: u32 = 240;

/// Draws the legend into the left [`LEGEND_WIDTH`] pixels of `img`: the
/// title and unit at the top, then [`LEGEND_STEPS`] bands, the highest on
/// top, each labelled with the value at its lower edge.
pub fn draw_legend(img: &mut RgbImage, mapping: Mapping, title: &str, unit: &str) {
    super::text::register_bundled_font();
    let (w, h) = img.dimensions();
    let top = 40i32;
    let band = ((h as i32 - top - 10) / LEGEND_STEPS as i32).max(1);
    let buf: &mut [u8] = img.as_mut();
    let root = BitMapBackend::with_buffer(buf, (w, h)).into_drawing_area();
    let white = RGBColor(255, 255, 255);
    let _ = root.draw(&Rectangle::new(
        [(0, 0), (LEGEND_WIDTH as i32 - 1, h as i32 - 1)],
        RGBColor(24, 24, 24).filled(),
    ));
    let text = |s: &str, x: i32, y: i32, size: i32| {
        let _ = root.draw(&Text::new(
            s.to_string(),
            (x, y),
            (FONT, size).into_font().color(&white),
        ));
    };
    text(title, 4, 4, 14);
    text(unit, 4, 20, 13);
    for k in 0..LEGEND_STEPS {
        let t0 = k as f64 / LEGEND_STEPS as f64;
        let t_mid = (k as f64 + 0.5) / LEGEND_STEPS as f64;
        let y1 = top + band * (LEGEND_STEPS - k) as i32;
        let y0 = y1 - band;
        let [r, g, b] = palette(t_mid);
        let _ = root.draw(&Rectangle::new(
            [(4, y0), (34, y1 - 1)],
            RGBColor(r, g, b).filled(),
        ));
        let lower = if k == 0 && mapping.scale == Scale::Log {
            format!("<{}", label(mapping.value_at(1.0 / LEGEND_STEPS as f64)))
        } else {
            label(mapping.value_at(t0))
        };
        text(&lower, 40, y1 - 14, 13);
    }
    text(&format!("{}+", label(mapping.max)), 40, top - 2, 13);
    let _ = root.present();
}

/// Colour of a plan's points that lie inside a solid object (no value):
/// a neutral grey, outside every band of the palette.
pub const PLAN_INSIDE_COLOR: [u8; 3] = [96, 96, 96];

/// Colour of a plan's isolux lines.
pub const PLAN_LINE_COLOR: [u8; 3] = [20, 20, 20];

/// A plan of a work plane in false colour: `values` on a grid of `nx × ny`
/// points (row `j` at index `j * nx`, `j = 0` the row nearest the plan's
/// bottom edge), drawn `scale` pixels a grid step, interpolated
/// bilinearly, with the isolux lines of the legend's band edges drawn dark
/// and the legend on the left. A `None` value is a point inside a solid
/// object: the area nearest it is drawn [`PLAN_INSIDE_COLOR`], and its
/// neighbours interpolate among the points that have values, so a cabinet
/// on the plane is a grey block, not a pool of darkness bleeding around it.
pub fn plan(
    values: &[Option<f64>],
    nx: usize,
    ny: usize,
    pixels_per_step: u32,
    mapping: Mapping,
    title: &str,
    unit: &str,
) -> RgbImage {
    let w = ((nx.max(2) - 1) as u32 * pixels_per_step).max(1);
    let h = ((ny.max(2) - 1) as u32 * pixels_per_step).max(1);
    let at = |i: usize, j: usize| values[j.min(ny - 1) * nx + i.min(nx - 1)];
    let sample = |px: f64, py: f64| -> Option<f64> {
        // Pixel centres to grid coordinates, row 0 of the picture on top.
        let gx = (px / pixels_per_step as f64).min((nx - 1) as f64);
        let gy = ((h as f64 - py) / pixels_per_step as f64).clamp(0.0, (ny - 1) as f64);
        let (i, j) = (gx.floor() as usize, gy.floor() as usize);
        let (fx, fy) = (gx - i as f64, gy - j as f64);
        at(gx.round() as usize, gy.round() as usize)?;
        let corners = [
            (at(i, j), (1.0 - fx) * (1.0 - fy)),
            (at(i + 1, j), fx * (1.0 - fy)),
            (at(i, j + 1), (1.0 - fx) * fy),
            (at(i + 1, j + 1), fx * fy),
        ];
        let (sum, weight) = corners
            .iter()
            .filter_map(|&(v, wt)| v.map(|v| (v * wt, wt)))
            .fold((0.0, 0.0), |(s, t), (v, wt)| (s + v, t + wt));
        // The nearest corner has a value, so some weight is positive
        // unless the pixel sits exactly on it with weight 0 elsewhere.
        Some(if weight > 0.0 {
            sum / weight
        } else {
            at(gx.round() as usize, gy.round() as usize).unwrap_or(0.0)
        })
    };
    let band = |v: Option<f64>| {
        v.map(|v| {
            (mapping.position(v) * LEGEND_STEPS as f64)
                .floor()
                .min(LEGEND_STEPS as f64 - 1.0) as i32
        })
    };
    let mut field = vec![None; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            field[(y * w + x) as usize] = sample(x as f64 + 0.5, y as f64 + 0.5);
        }
    }
    let height = h.max(LEGEND_MIN_HEIGHT);
    let mut img = RgbImage::new(LEGEND_WIDTH + w, height);
    for y in 0..h {
        for x in 0..w {
            let v = field[(y * w + x) as usize];
            let b = band(v);
            // An isolux line where the band changes to the right or below,
            // between two points that both have values.
            let changes = |other: Option<f64>| {
                let o = band(other);
                b.is_some() && o.is_some() && o != b
            };
            let edge = (x + 1 < w && changes(field[(y * w + x + 1) as usize]))
                || (y + 1 < h && changes(field[((y + 1) * w + x) as usize]));
            let c = match v {
                _ if edge => PLAN_LINE_COLOR,
                Some(v) => mapping.colour(v),
                None => PLAN_INSIDE_COLOR,
            };
            img.put_pixel(LEGEND_WIDTH + x, y, image::Rgb(c));
        }
    }
    draw_legend(&mut img, mapping, title, unit);
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The command line's help spells the decades out in words, so it
    /// must follow the constant.
    #[test]
    fn the_log_scale_help_names_its_decades() {
        use clap::ValueEnum;
        let help = Scale::Log.to_possible_value().unwrap();
        let words = ["zero", "one", "two", "three", "four", "five", "six"];
        let word = words[LOG_DECADES as usize];
        assert!(help.get_help().unwrap().to_string().contains(word));
    }

    #[test]
    fn mappings_invert_and_clamp() {
        for scale in [Scale::Log, Scale::Linear] {
            let m = Mapping::new(&[0.0, 730.0], None, scale);
            assert_eq!(m.max, 1000.0);
            for t in [0.1, 0.5, 0.9] {
                assert!((m.position(m.value_at(t)) - t).abs() < 1e-12);
            }
            assert_eq!(m.position(5000.0), 1.0);
            assert_eq!(m.position(-1.0), 0.0);
        }
        assert_eq!(nice_ceiling(0.0), 1.0);
        assert_eq!(nice_ceiling(3.0), 5.0);
        assert_eq!(nice_ceiling(0.012), 0.02);
        assert_eq!(palette(0.0), [26, 0, 89]);
        assert_eq!(palette(1.0), [217, 0, 0]);
    }

    #[test]
    fn the_legend_draws_text_with_the_bundled_font() {
        let m = Mapping::new(&[], Some(100.0), Scale::Linear);
        let img = picture(&[Some(50.0); 4], 2, 2, m, "illuminance", "lx");
        assert_eq!(img.dimensions(), (LEGEND_WIDTH + 2, LEGEND_MIN_HEIGHT));
        // White text pixels in the title area.
        let white = (0..LEGEND_WIDTH)
            .flat_map(|x| (0..36).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c > 200))
            .count();
        assert!(white > 20, "{white}");
        assert_eq!(img.get_pixel(LEGEND_WIDTH, 0).0, m.colour(50.0));
    }

    #[test]
    fn a_plan_draws_isolux_lines_between_bands() {
        // A ramp from 0 to 100 along x: vertical isolux lines.
        let (nx, ny) = (11, 3);
        let values: Vec<f64> = (0..ny)
            .flat_map(|_| (0..nx).map(|i| i as f64 * 10.0))
            .collect();
        let m = Mapping::new(&values, Some(100.0), Scale::Linear);
        let known: Vec<Option<f64>> = values.iter().copied().map(Some).collect();
        let img = plan(&known, nx, ny, 10, m, "E", "lx");
        let dark = |x: u32| img.get_pixel(LEGEND_WIDTH + x, 5).0 == PLAN_LINE_COLOR;
        let lines = (0..100).filter(|&x| dark(x)).count();
        // Band edges at 12.5, 25, ..., 87.5: seven lines.
        assert_eq!(lines, LEGEND_STEPS - 1);
    }

    #[test]
    fn points_inside_solids_are_grey_and_do_not_darken_their_neighbours() {
        // A uniform 430 (in the middle of a band, so rounding in the
        // interpolation draws no line) with the middle point of a 5 × 5
        // grid inside.
        let (nx, ny) = (5, 5);
        let mut values = vec![Some(430.0); nx * ny];
        values[2 * nx + 2] = None;
        let m = Mapping::new(&[430.0], Some(1000.0), Scale::Linear);
        let img = plan(&values, nx, ny, 10, m, "E", "lx");
        let px = |x: u32, y: u32| img.get_pixel(LEGEND_WIDTH + x, y).0;
        // The grid point (2, 2) is at pixel (20, 20).
        assert_eq!(px(20, 20), PLAN_INSIDE_COLOR);
        // Everything else is 430's colour: no darker ring, no isolux line.
        let mut other = 0;
        for y in 0..40 {
            for x in 0..40 {
                let c = px(x, y);
                if c != PLAN_INSIDE_COLOR {
                    assert_eq!(c, m.colour(430.0), "pixel ({x}, {y})");
                    other += 1;
                }
            }
        }
        assert!(other > 1400, "{other}");
    }
}
