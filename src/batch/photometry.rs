//! The photometric results of a batch run: illuminance at points
//! (`--illuminance-at`), the work plane (`--workplane`) and its daylight
//! factors (`--daylight-factor`), and the view in false colour
//! (`--falsecolor`), from the converged solution.
//!
//! Each says on stderr what it computed and how long it took (unless
//! quiet); the work plane's figures go to stdout whatever `--quiet` says,
//! as they are a result. Without a scene unit (`--units`, or a glTF file)
//! values are in the scene's radiosity units, not lux, and a warning says
//! so once.

use super::{RunError, Written};
use crate::cancel::Cancel;
use crate::color::Rgb;
use crate::config::RunConfig;
use crate::mesh::Mesh;
use crate::output::daylight_factor::{self, DaylightFactors};
use crate::output::{self, illuminance as out};
use crate::prepare::Prepared;
use crate::render::falsecolor::{self, Mapping, Quantity};
use crate::render::{Frame, View};
use crate::scene::import::points::{self, MeasurementPoint};
use crate::scene::Photometric;
use crate::solver::final_gather::{vertex_irradiance, FinalGather};
use std::time::Instant;

/// Checks what can be checked before solving: the points file parses and
/// the work plane lies within the scene. Returns the points of
/// `--illuminance-at`, read here once (the file may be a pipe), for
/// the photometric results written after the solve.
pub fn check(
    config: &RunConfig,
    prepared: &Prepared,
) -> Result<Option<Vec<MeasurementPoint>>, RunError> {
    let p = &config.photometry;
    let points = match &p.illuminance {
        Some((at, _)) => Some(points::load_points_within(at, &config.max_memory)?),
        None => None,
    };
    if let Some(w) = &p.workplane {
        out::workplane_grid(&prepared.scene, w.height, w.spacing, config.units())
            .map_err(|e| RunError::Options(e.to_string()))?;
    }
    Ok(points)
}

/// Computes and writes every photometric result `config` asks for, from
/// `radiosity` (per vertex of `mesh`, the solution) and the picture's
/// linear `frame` seen through `view`, adding each file to `written` once
/// complete; `points` are those [`check`] read for `--illuminance-at`.
/// Returns the seconds spent. The gathers stop with
/// [`RunError::Interrupted`] soon after `cancel` is set.
#[allow(clippy::too_many_arguments)]
pub(super) fn write(
    config: &RunConfig,
    prepared: &Prepared,
    mesh: &Mesh,
    radiosity: &[Rgb],
    frame: &Frame,
    view: &View,
    points: Option<&[MeasurementPoint]>,
    written: &mut Written,
    cancel: &Cancel,
) -> Result<f64, RunError> {
    let start = Instant::now();
    if !config.wants_photometry() {
        return Ok(0.0);
    }
    let units = config.units();
    let photometric = Photometric { units };
    if units.is_none() {
        eprintln!(
            "warning: no --units: photometric results are in the scene's radiosity units, \
             not lux; give --units m|cm|mm|in|ft to read emission as lm/m² and get lux"
        );
    }
    let say = |what: String| {
        if config.progress {
            eprintln!("{what}");
        }
    };
    let p = &config.photometry;
    let near_field = config.solver.approximations.near_field;
    let gather = || {
        FinalGather::new(
            &prepared.scene,
            mesh,
            prepared.visibility(),
            radiosity,
            near_field,
        )
    };
    if let (Some((_, to)), Some(points)) = (&p.illuminance, points) {
        let t = Instant::now();
        let values = gather().irradiance_at_cancellable(points, cancel)?;
        say(format!(
            "illuminance at {} points: {:.2} s",
            points.len(),
            t.elapsed().as_secs_f64()
        ));
        out::write_illuminance(to, points, &values).map_err(RunError::Write)?;
        written.push(to);
    }
    if let Some(w) = &p.workplane {
        let grid = out::workplane_grid(&prepared.scene, w.height, w.spacing, units)
            .map_err(|e| RunError::Options(e.to_string()))?;
        let t = Instant::now();
        let plane = gather();
        let values = plane.irradiance_at_cancellable(&grid.points, cancel)?;
        say(format!(
            "work plane of {} × {} points {} apart: {:.2} s",
            grid.nx,
            grid.ny,
            super::short(f64::from(grid.spacing)),
            t.elapsed().as_secs_f64()
        ));
        let (scale, max) = (w.scale, w.max);
        let behind: Vec<bool> = grid
            .points
            .iter()
            .map(|&(x, n)| plane.behind_surfaces(x, n))
            .collect();
        cancel.check()?;
        let hidden = behind.iter().filter(|&&i| i).count();
        let u = out::write_workplane(
            &w.csv,
            &w.png,
            &grid,
            &values,
            &behind,
            scale,
            max,
            photometric,
        )
        .map_err(RunError::Write)?;
        written.push(&w.csv);
        written.push(&w.png);
        // Printed whatever -q says, with the points left out, so the
        // figures are never read without knowing what they cover.
        let left_out = if hidden > 0 {
            format!(
                " ({hidden} of {} points inside solid objects or outside the walls left out; \
                 they read 0 in the CSV and are grey in the plan)",
                grid.points.len()
            )
        } else {
            String::new()
        };
        println!(
            "work plane at {}: {}{left_out}",
            w.height,
            u.line(photometric.illuminance_unit())
        );
        if let Some(png) = &w.daylight_factor {
            let sky = config.daylight.resolve().ok().flatten().ok_or_else(|| {
                RunError::Options("--daylight-factor needs a standard sky".into())
            })?;
            let outside = sky.horizontal_illuminance();
            let df: Vec<Option<f64>> = values
                .iter()
                .zip(&behind)
                .map(|(e, &hidden)| (!hidden).then(|| 100.0 * e.luminance() / outside))
                .collect();
            let open: Vec<f64> = df.iter().flatten().copied().collect();
            let all: Vec<f64> = values
                .iter()
                .map(|e| 100.0 * e.luminance() / outside)
                .collect();
            let figures = DaylightFactors::of(if open.is_empty() { &all } else { &open });
            let steps = grid.nx.max(grid.ny).max(2) as u32 - 1;
            let pixels = (out::PLAN_PIXELS / steps)
                .max(out::PLAN_MIN_PIXELS.div_ceil(steps))
                .max(1);
            daylight_factor::write_plan(png, &df, grid.nx, grid.ny, pixels)
                .map_err(RunError::Write)?;
            written.push(png);
            let [first, second] = figures.lines();
            println!(
                "daylight factor at {} (outside {:.0} lx, {} sky): {first}",
                w.height,
                outside,
                sky.model.name()
            );
            println!("{second}");
        }
    }
    if let Some(f) = &p.falsecolor {
        cancel.check()?;
        let (values, title, unit): (Vec<Option<f64>>, &str, &str) = match f.quantity {
            Quantity::Luminance => (
                frame
                    .pixels
                    .iter()
                    .zip(&frame.covered)
                    .map(|(px, &c)| {
                        let rgb = Rgb::new(px[0] as f64, px[1] as f64, px[2] as f64);
                        c.then(|| rgb.luminance() / std::f64::consts::PI)
                    })
                    .collect(),
                "luminance",
                photometric.luminance_unit(),
            ),
            Quantity::Illuminance => {
                let irradiance = vertex_irradiance(&prepared.scene, mesh, radiosity);
                let mut rasterizer = crate::render::Rasterizer::new();
                let e = rasterizer.render_cancellable(mesh, &irradiance, view, cancel)?;
                (
                    e.pixels
                        .iter()
                        .zip(&e.covered)
                        .map(|(px, &c)| {
                            let rgb = Rgb::new(px[0] as f64, px[1] as f64, px[2] as f64);
                            c.then(|| rgb.luminance())
                        })
                        .collect(),
                    "illuminance",
                    photometric.illuminance_unit(),
                )
            }
        };
        let finite: Vec<f64> = values.iter().flatten().copied().collect();
        let mapping = Mapping::new(&finite, f.max, f.scale);
        let img = falsecolor::picture(&values, frame.width, frame.height, mapping, title, unit);
        output::write_rgb8(&f.path, &img).map_err(RunError::Write)?;
        written.push(&f.path);
    }
    Ok(start.elapsed().as_secs_f64())
}
