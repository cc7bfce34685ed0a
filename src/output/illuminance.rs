//! Photometric results: illuminance at points as CSV, and work planes
//! (a grid of points over the floor, its CSV, its false-colour plan and
//! its uniformity figures).
//!
//! Values are in the scene's radiosity units, which are lux when the scene
//! has a unit (`--units`, or a glTF file) and its emission is luminous
//! exitance in lm/m² (see [`crate::scene::Units`]). The single figure `e`
//! of a point weights the channels by the Rec. 709 luminance weights
//! ([`Rgb::luminance`]: 0.2126, 0.7152, 0.0722).

use super::{write_atomically, write_rgb8, OutputError};
use crate::color::Rgb;
use crate::render::falsecolor::{self, Mapping, Scale};
use crate::scene::MeasurementPoint;
use crate::scene::{Photometric, Scene, Units};
use glam::Vec3;
use std::path::Path;

/// The header of an illuminance CSV (without the line break).
pub const ILLUMINANCE_HEADER: &str = "x,y,z,nx,ny,nz,e_r,e_g,e_b,e";

/// Pixels a grid step of a work plane's plan, so that a plan of a room of
/// 20 × 20 steps is about 600 pixels wide; at least [`PLAN_MIN_PIXELS`]
/// pixels a side in all.
pub const PLAN_PIXELS: u32 = 600;

/// The smallest side of a plan in pixels (a grid of few points is drawn
/// larger a step).
pub const PLAN_MIN_PIXELS: u32 = 240;

/// The most grid points a work plane may have: a 0.1 m grid over a hall
/// of 300 × 300 m. More is refused with the spacing that would fit.
pub const MAX_WORKPLANE_POINTS: usize = 10_000_000;

/// Writes `points` and their irradiance `values` (one each, in order) as
/// CSV with [`ILLUMINANCE_HEADER`], atomically.
pub fn write_illuminance(
    path: &Path,
    points: &[MeasurementPoint],
    values: &[Rgb],
) -> Result<(), OutputError> {
    write_atomically(path, |w| {
        writeln!(w, "{ILLUMINANCE_HEADER}")?;
        for ((x, n), e) in points.iter().zip(values) {
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{}",
                x.x,
                x.y,
                x.z,
                n.x,
                n.y,
                n.z,
                e.r,
                e.g,
                e.b,
                e.luminance()
            )?;
        }
        Ok(())
    })
}

/// A horizontal grid at a height above the floor of the scene's bounds.
///
/// Invariants: `points.len() == nx * ny`, row `j` (along the plan's
/// vertical) at `j * nx`; `nx, ny >= 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct WorkplaneGrid {
    /// Points along the plan's horizontal axis.
    pub nx: usize,
    /// Points along the plan's vertical axis.
    pub ny: usize,
    /// The grid spacing used, in scene units.
    pub spacing: f32,
    /// The points (normal: up), in scene units.
    pub points: Vec<MeasurementPoint>,
}

/// The default spacing of a work-plane grid, in metres, for a plane whose
/// longer side is `d` metres: `0.2 × 5^log10(d)`, the rule of EN 12464-1
/// (and CIE 97), so that a 5 m office gets about 0.6 m and a 50 m hall
/// about 3 m.
pub fn default_spacing_metres(d: f64) -> f64 {
    0.2 * 5f64.powf(d.max(1e-6).log10())
}

/// Why a work plane cannot be laid out.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum WorkplaneError {
    /// The height or spacing is not a positive finite number, or the
    /// height lies outside the scene's bounds.
    #[error("--workplane: {0}")]
    Bad(String),
}

/// The up direction of a scene: its camera's up, snapped to the nearest
/// axis (`+y` for the bundled scenes and glTF files), and the index of
/// that axis.
pub fn scene_up(scene: &Scene) -> (Vec3, usize) {
    let up = scene.camera.up;
    let axis = (0..3)
        .max_by(|&a, &b| up[a].abs().total_cmp(&up[b].abs()))
        .unwrap_or(1);
    let mut v = Vec3::ZERO;
    v[axis] = if up[axis] < 0.0 { -1.0 } else { 1.0 };
    (v, axis)
}

/// Lays out the work plane `height` (scene units) above the floor of the
/// scene's bounds (their lowest point along [`scene_up`]) with `spacing`
/// (scene units; `None` for [`default_spacing_metres`], converted by
/// `units`, read as metres without a unit): points at the centres of
/// cells of about that size covering the bounds' floor, facing up.
pub fn workplane_grid(
    scene: &Scene,
    height: f32,
    spacing: Option<f32>,
    units: Option<Units>,
) -> Result<WorkplaneGrid, WorkplaneError> {
    let (up, axis) = scene_up(scene);
    let (lo, hi) = scene.bounds();
    let extent = hi[axis] - lo[axis];
    if !(height.is_finite() && height >= 0.0 && height <= extent) {
        return Err(WorkplaneError::Bad(format!(
            "the height must be between 0 and the scene's height {extent} (scene units), got {height}"
        )));
    }
    // The plan's axes: `a` to the right, `b = up × a` upwards, as seen
    // from above.
    let a_axis = (axis + 1) % 3;
    let mut a = Vec3::ZERO;
    a[a_axis] = 1.0;
    let b = up.cross(a);
    let b_axis = (0..3).find(|&k| b[k] != 0.0).unwrap_or((axis + 2) % 3);
    let (la, lb) = (hi[a_axis] - lo[a_axis], hi[b_axis] - lo[b_axis]);
    let metres = units.map_or(1.0, |u| u.metres_per_unit());
    let spacing = match spacing {
        Some(s) if s.is_finite() && s > 0.0 => s,
        Some(s) => {
            return Err(WorkplaneError::Bad(format!(
                "the spacing must be a positive number, got {s}"
            )))
        }
        None => (default_spacing_metres(f64::from(la.max(lb)) * metres) / metres) as f32,
    };
    let count = |l: f32| ((l / spacing).round() as usize).max(1);
    let (nx, ny) = (count(la), count(lb));
    if nx.saturating_mul(ny) > MAX_WORKPLANE_POINTS {
        return Err(WorkplaneError::Bad(format!(
            "a spacing of {spacing} gives {nx} × {ny} points, more than {MAX_WORKPLANE_POINTS}; \
             use a spacing of at least {}",
            (la * lb / MAX_WORKPLANE_POINTS as f32).sqrt()
        )));
    }
    let floor = if up[axis] > 0.0 { lo[axis] } else { hi[axis] };
    let level = floor + up[axis] * height;
    let mut points = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        // Row 0 at the low end of `b`.
        let tb = (j as f32 + 0.5) / ny as f32;
        let vb = if b[b_axis] > 0.0 {
            lo[b_axis] + tb * lb
        } else {
            hi[b_axis] - tb * lb
        };
        for i in 0..nx {
            let mut p = Vec3::ZERO;
            p[axis] = level;
            p[a_axis] = lo[a_axis] + (i as f32 + 0.5) / nx as f32 * la;
            p[b_axis] = vb;
            points.push((p, up));
        }
    }
    Ok(WorkplaneGrid {
        nx,
        ny,
        spacing: la / nx as f32,
        points,
    })
}

/// The uniformity figures of a set of illuminances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniformity {
    /// Mean.
    pub average: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
}

impl Uniformity {
    /// The figures of `values` (at least one).
    pub fn of(values: &[f64]) -> Uniformity {
        let n = values.len().max(1) as f64;
        Uniformity {
            average: values.iter().sum::<f64>() / n,
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(0.0, f64::max),
        }
    }

    /// `Emin / Eavg`, the uniformity EN 12464-1 asks of a task area (0 when
    /// the average is 0).
    pub fn ratio(&self) -> f64 {
        if self.average > 0.0 {
            self.min / self.average
        } else {
            0.0
        }
    }

    /// One line: `Eavg … Emin … Emax … Emin/Eavg …` in `unit`.
    pub fn line(&self, unit: &str) -> String {
        format!(
            "Eavg {:.1} {unit}, Emin {:.1} {unit}, Emax {:.1} {unit}, Emin/Eavg {:.3}",
            self.average,
            self.min,
            self.max,
            self.ratio()
        )
    }
}

/// Writes a work plane: `PREFIX.csv` (as [`write_illuminance`]) and
/// `PREFIX.png`, its plan in false colour with isolux lines and a legend
/// (points inside a solid drawn grey);
/// returns its [`Uniformity`] over the points not `inside` a solid object
/// or outside the walls (one flag per grid point: such a point gets no
/// light and is no part of the area being lit). When every point is
/// flagged, the figures are those of all the points.
#[allow(clippy::too_many_arguments)]
pub fn write_workplane(
    csv: &Path,
    png: &Path,
    grid: &WorkplaneGrid,
    values: &[Rgb],
    inside: &[bool],
    scale: Scale,
    max: Option<f64>,
    photometric: Photometric,
) -> Result<Uniformity, OutputError> {
    write_illuminance(csv, &grid.points, values)?;
    let e: Vec<f64> = values.iter().map(|v| v.luminance()).collect();
    let steps = grid.nx.max(grid.ny).max(2) as u32 - 1;
    let pixels = (PLAN_PIXELS / steps)
        .max(PLAN_MIN_PIXELS.div_ceil(steps))
        .max(1);
    let known: Vec<Option<f64>> = e
        .iter()
        .zip(inside.iter().chain(std::iter::repeat(&false)))
        .map(|(&v, &inside)| (!inside).then_some(v))
        .collect();
    let open: Vec<f64> = known.iter().flatten().copied().collect();
    let lit = if open.is_empty() { &e } else { &open };
    let mapping = Mapping::new(lit, max, scale);
    let img = falsecolor::plan(
        &known,
        grid.nx,
        grid.ny,
        pixels,
        mapping,
        "illuminance",
        photometric.illuminance_unit(),
    );
    write_rgb8(png, &img)?;
    Ok(Uniformity::of(lit))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil;

    #[test]
    fn the_default_spacing_follows_en_12464() {
        assert!((default_spacing_metres(10.0) - 1.0).abs() < 1e-12);
        assert!((default_spacing_metres(1.0) - 0.2).abs() < 1e-12);
        assert!((default_spacing_metres(100.0) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn a_workplane_covers_the_floor_at_its_height() {
        // A room 4 (x) by 3 (y, up) by 2 (z): the plan's right is +z and
        // its up is +x (up × right), 0.5 apart.
        let scene = testutil::scene(
            testutil::cuboid([0.0, 0.0, 0.0], [4.0, 3.0, 2.0], true),
            vec![testutil::grey("m", 0.0, 0.5)],
        );
        let g = workplane_grid(&scene, 0.75, Some(0.5), None).unwrap();
        assert_eq!((g.nx, g.ny), (4, 8));
        assert!(g.points.iter().all(|(p, n)| p.y == 0.75 && *n == Vec3::Y));
        // Cell centres, row by row.
        assert_eq!(g.points[0].0, Vec3::new(0.25, 0.75, 0.25));
        assert_eq!(g.points[1].0, Vec3::new(0.25, 0.75, 0.75));
        assert_eq!(g.points[4].0, Vec3::new(0.75, 0.75, 0.25));
        assert_eq!(g.points[31].0, Vec3::new(3.75, 0.75, 1.75));
        assert!(workplane_grid(&scene, 9.0, None, None).is_err());
        assert!(workplane_grid(&scene, 1.0, Some(0.0), None).is_err());
        let u = Uniformity::of(&[100.0, 200.0, 300.0]);
        assert_eq!((u.average, u.min, u.max), (200.0, 100.0, 300.0));
        assert_eq!(u.ratio(), 0.5);
    }
}
