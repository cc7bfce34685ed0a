//! Daylight factors on a work plane (`--daylight-factor`): each point's
//! illuminance over the unobstructed horizontal illuminance outside
//! under the CIE overcast sky, `DF = 100 % · E_in / E_out`, with the
//! figures of EN 17037:2018 and the plan in false colour.
//!
//! EN 17037's daylight-factor method (its method 1, for vertical and
//! inclined openings) asks, at its minimum level, a target daylight
//! factor `D_T` over 50 % of the reference plane and a minimum target
//! `D_TM` over 95 % of it. Both follow from the site's median external
//! diffuse illuminance (300 lx and 100 lx over it); for the
//! 15,000 lx of many European sites they are the [`TARGET_DF`] of 2 % and
//! [`MINIMUM_DF`] of 0.7 % reported here. The standard's reference plane is
//! 0.85 m above the floor; `--workplane` gives the height.

use super::{write_rgb8, OutputError};
use crate::render::falsecolor::{self, Mapping, Scale};
use image::RgbImage;
use std::path::Path;

/// EN 17037's target daylight factor at the minimum level, %.
pub const TARGET_DF: f64 = 2.0;
/// The share of the reference plane that must reach [`TARGET_DF`].
pub const TARGET_SHARE: f64 = 0.5;
/// EN 17037's minimum target daylight factor at the minimum level, %.
pub const MINIMUM_DF: f64 = 0.7;
/// The share of the reference plane that must reach [`MINIMUM_DF`].
pub const MINIMUM_SHARE: f64 = 0.95;

/// The colour of the [`TARGET_DF`] line in the plan: white.
pub const TARGET_LINE: [u8; 3] = [255, 255, 255];
/// The colour of the [`MINIMUM_DF`] line in the plan: magenta, which the
/// false-colour ramp and its dark isolux lines never are.
pub const MINIMUM_LINE: [u8; 3] = [255, 0, 255];

/// The value the plan shows red, %: a daylight factor of 10 % is a very
/// bright spot by a window.
pub const PLAN_MAX_DF: f64 = 10.0;

/// The figures of a work plane's daylight factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DaylightFactors {
    /// Mean, %.
    pub mean: f64,
    /// Smallest, %.
    pub min: f64,
    /// Largest, %.
    pub max: f64,
    /// The share of the points at [`TARGET_DF`] or more, `0..=1`.
    pub at_target: f64,
    /// The share of the points at [`MINIMUM_DF`] or more, `0..=1`.
    pub at_minimum: f64,
}

impl DaylightFactors {
    /// The figures of the daylight factors `df` (%; at least one).
    pub fn of(df: &[f64]) -> DaylightFactors {
        let n = df.len().max(1) as f64;
        let share = |t: f64| df.iter().filter(|&&v| v >= t).count() as f64 / n;
        DaylightFactors {
            mean: df.iter().sum::<f64>() / n,
            min: df.iter().copied().fold(f64::INFINITY, f64::min),
            max: df.iter().copied().fold(0.0, f64::max),
            at_target: share(TARGET_DF),
            at_minimum: share(MINIMUM_DF),
        }
    }

    /// Whether both EN 17037 minimum-level criteria are met.
    pub fn meets_en17037(&self) -> bool {
        self.at_target >= TARGET_SHARE && self.at_minimum >= MINIMUM_SHARE
    }

    /// The printed lines: the mean and minimum, then the EN 17037 figures.
    pub fn lines(&self) -> [String; 2] {
        let verdict = |ok: bool| if ok { "met" } else { "not met" };
        [
            format!(
                "DF mean {:.2} %, DF min {:.2} %, DF max {:.2} %",
                self.mean, self.min, self.max
            ),
            format!(
                "EN 17037 minimum level: DF >= {TARGET_DF} % over {:.1} % of the plane \
                 (needs {:.0} %): {}; DF >= {MINIMUM_DF} % over {:.1} % (needs {:.0} %): {}",
                100.0 * self.at_target,
                100.0 * TARGET_SHARE,
                verdict(self.at_target >= TARGET_SHARE),
                100.0 * self.at_minimum,
                100.0 * MINIMUM_SHARE,
                verdict(self.at_minimum >= MINIMUM_SHARE)
            ),
        ]
    }
}

/// Writes the plan of daylight factors `df` (%, `None` for a point inside
/// a solid, drawn grey) on a grid of `nx × ny` points, `pixels` a grid
/// step: the work plane's false-colour plan ([`falsecolor::plan`], linear
/// up to [`PLAN_MAX_DF`]) with the [`TARGET_DF`] line drawn over it in
/// [`TARGET_LINE`] and the [`MINIMUM_DF`] line in [`MINIMUM_LINE`], two
/// pixels wide.
pub fn write_plan(
    png: &Path,
    df: &[Option<f64>],
    nx: usize,
    ny: usize,
    pixels: u32,
) -> Result<(), OutputError> {
    let img = plan(df, nx, ny, pixels);
    write_rgb8(png, &img)
}

/// The picture [`write_plan`] writes.
pub fn plan(df: &[Option<f64>], nx: usize, ny: usize, pixels: u32) -> RgbImage {
    let mapping = Mapping::new(&[], Some(PLAN_MAX_DF), Scale::Linear);
    let mut img = falsecolor::plan(df, nx, ny, pixels, mapping, "daylight factor", "%");
    let w = ((nx.max(2) - 1) as u32 * pixels).max(1);
    let h = ((ny.max(2) - 1) as u32 * pixels).max(1);
    // The plan's field, sampled as falsecolor::plan samples it: bilinear
    // between the grid points that have values.
    let at = |i: usize, j: usize| df[j.min(ny - 1) * nx + i.min(nx - 1)];
    let sample = |x: u32, y: u32| -> Option<f64> {
        let gx = ((x as f64 + 0.5) / pixels as f64).min((nx - 1) as f64);
        let gy = ((h as f64 - y as f64 - 0.5) / pixels as f64).clamp(0.0, (ny - 1) as f64);
        let (i, j) = (gx.floor() as usize, gy.floor() as usize);
        let (fx, fy) = (gx - i as f64, gy - j as f64);
        at(gx.round() as usize, gy.round() as usize)?;
        let (sum, weight) = [
            (at(i, j), (1.0 - fx) * (1.0 - fy)),
            (at(i + 1, j), fx * (1.0 - fy)),
            (at(i, j + 1), (1.0 - fx) * fy),
            (at(i + 1, j + 1), fx * fy),
        ]
        .iter()
        .filter_map(|&(v, wt)| v.map(|v| (v * wt, wt)))
        .fold((0.0, 0.0), |(s, t), (v, wt)| (s + v, t + wt));
        (weight > 0.0).then(|| sum / weight)
    };
    let field: Vec<Option<f64>> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| sample(x, y))
        .collect();
    let get = |x: u32, y: u32| field[(y * w + x) as usize];
    for y in 0..h {
        for x in 0..w {
            let Some(v) = get(x, y) else { continue };
            for (target, colour) in [(TARGET_DF, TARGET_LINE), (MINIMUM_DF, MINIMUM_LINE)] {
                // A crossing of the target between this pixel and a
                // neighbour to the right or below marks both.
                let crosses = |o: Option<f64>| o.is_some_and(|o| (v >= target) != (o >= target));
                let right = x + 1 < w && crosses(get(x + 1, y));
                let below = y + 1 < h && crosses(get(x, y + 1));
                if right || below {
                    img.put_pixel(falsecolor::LEGEND_WIDTH + x, y, image::Rgb(colour));
                    if right {
                        img.put_pixel(falsecolor::LEGEND_WIDTH + x + 1, y, image::Rgb(colour));
                    }
                    if below {
                        img.put_pixel(falsecolor::LEGEND_WIDTH + x, y + 1, image::Rgb(colour));
                    }
                }
            }
        }
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_figures_count_the_shares_at_the_targets() {
        let f = DaylightFactors::of(&[0.5, 1.0, 2.0, 4.0]);
        assert_eq!((f.mean, f.min, f.max), (1.875, 0.5, 4.0));
        assert_eq!((f.at_target, f.at_minimum), (0.5, 0.75));
        assert!(!f.meets_en17037());
        assert!(DaylightFactors::of(&[0.8, 2.0, 3.0]).meets_en17037());
        let [first, second] = f.lines();
        assert_eq!(first, "DF mean 1.88 %, DF min 0.50 %, DF max 4.00 %");
        assert!(
            second.contains("DF >= 2 % over 50.0 % of the plane (needs 50 %): met"),
            "{second}"
        );
        assert!(
            second.contains("DF >= 0.7 % over 75.0 % (needs 95 %): not met"),
            "{second}"
        );
    }

    #[test]
    fn the_plan_draws_both_target_lines_where_the_factor_crosses_them() {
        // A ramp from 0 to 5 % along x: the 0.7 % line near x = 0.14 of
        // the width, the 2 % line at 0.4, both vertical.
        let (nx, ny) = (11, 3);
        let df: Vec<Option<f64>> = (0..ny)
            .flat_map(|_| (0..nx).map(|i| Some(i as f64 * 0.5)))
            .collect();
        let img = plan(&df, nx, ny, 10);
        let row = 5;
        let columns = |c: [u8; 3]| -> Vec<u32> {
            (0..100)
                .filter(|&x| img.get_pixel(falsecolor::LEGEND_WIDTH + x, row).0 == c)
                .collect()
        };
        let white = columns(TARGET_LINE);
        let black = columns(MINIMUM_LINE);
        assert!(
            !white.is_empty() && white.iter().all(|&x| (39..=41).contains(&x)),
            "{white:?}"
        );
        assert!(
            !black.is_empty() && black.iter().all(|&x| (13..=15).contains(&x)),
            "{black:?}"
        );
    }
}
