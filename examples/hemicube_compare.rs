//! Compares the three form-factor estimates, Wallace's ray-traced sum,
//! the hemicube and the one-ray centre estimate, on one scene
//! (`docs/accuracy.md`, "Hemicube"):
//!
//! ```sh
//! cargo run --release --example hemicube_compare -- scenes/rtable.sc docs/images/hemicube-rtable.png docs/images/hemicube-errors-rtable.png
//! cargo run --release --example hemicube_compare -- scenes/cornell.sc docs/images/hemicube-cornell.png docs/images/hemicube-errors-cornell.png
//! ```
//!
//! Solves the scene with Wallace's estimate on a mesh of half the default
//! `lenmax` (the reference: the finest that solves in well under a minute
//! on two cores), then on the default mesh with each estimate: Wallace,
//! hemicubes of 256, 128 (the default), 64 and 32 pixels, 128 pixels
//! with every step shooting from all its cells (`--no-clustering`: weak
//! steps' cells not merged) and with 256 cells (`--shooter-samples 256`),
//! and the centre estimate, all to the default threshold. Prints per solve the steps,
//! solve seconds, seconds per step, and the picture's relative L1 error
//! against the reference (mean absolute luminance difference over mean
//! luminance, over the pixels the camera shows, lamps excluded), at
//! 320 × 240. Writes a 2 × 2 composite of the pictures (Wallace, hemicube
//! 128, centre, hemicube 32) to the output path, all at the reference's
//! exposure, and, given a third path, the relative error maps of hemicube
//! 128 from 64 and from 256 cells side by side (red brighter, blue darker
//! than the reference, full at ±10 %).

use image::{GenericImage, RgbImage};
use radiosity::color::Rgb;
use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare;
use radiosity::render::Frame;
use radiosity::session::{Session, SessionOptions};
use radiosity::solver::hemicube::HemicubeRes;
use radiosity::solver::{FormFactorMethod, ShooterSamples};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// Width and height of each picture.
const SIZE: (u32, u32) = (320, 240);

fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// A solve of `config`: its picture, steps and solve seconds.
fn solve(config: &RunConfig) -> (Frame, Frame, u64, f64) {
    let prepared = prepare::prepare(config).expect("the scene prepares");
    let view = prepared.view(config).expect("the scene's camera");
    let t = Instant::now();
    let mut session =
        Session::from_prepared(&prepared, SessionOptions::for_run(config, &prepared, false));
    session
        .run_to_end(&AtomicBool::new(false))
        .expect("an uncancelled solve");
    let seconds = t.elapsed().as_secs_f64();
    let mesh = session.mesh();
    let frame = radiosity::render::render(mesh, session.radiosity(), &view).expect("renders");
    // Lamps: the pixels where a mask of the emitters renders lit.
    let mask: Vec<Rgb> = mesh
        .vertex_polygon
        .iter()
        .map(|p| {
            let m = &prepared.scene.materials[prepared.scene.polygons[p.index()].material.index()];
            if m.emission().is_black() {
                Rgb::BLACK
            } else {
                Rgb::WHITE
            }
        })
        .collect();
    let lamps = radiosity::render::render(mesh, &mask, &view).expect("renders");
    (frame, lamps, session.totals().steps, seconds)
}

fn main() {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let (Some(scene), Some(out)) = (args.first(), args.get(1)) else {
        eprintln!("usage: hemicube_compare SCENE OUT.png [ERRORS.png]");
        std::process::exit(2);
    };
    let error_map_out = args.get(2);
    let mut base = RunConfig::new(SceneSource::File(scene.clone()));
    base.size = Some(SIZE);
    let lenmax = prepare::prepare(&base).expect("the scene prepares").lenmax;
    let with = |method, res: u64, lenmax: f32| {
        let mut c = base.clone();
        c.lenmax = Some(lenmax);
        c.solver.form_factor = method;
        c.solver.hemicube_res = HemicubeRes::new(res).expect("a valid resolution");
        c
    };
    // The two hemicube variants beside the resolutions: every step from
    // all its cells (no merging of weak steps' cells), and 256 cells.
    let variant = |clustering: bool, cells: u32| {
        let mut c = with(FormFactorMethod::Hemicube, 128, lenmax);
        c.solver.approximations.clusters = clustering;
        c.solver.shooter_samples = ShooterSamples::AtMost(cells);
        c
    };
    let (reference, lamps, steps, seconds) =
        solve(&with(FormFactorMethod::Wallace, 128, lenmax / 2.0));
    println!("# {}: default lenmax {lenmax}", scene.display());
    println!("| estimate | steps | solve s | s per step | picture relL1 |\n|---|---|---|---|---|");
    println!(
        "| Wallace, lenmax / 2 (reference) | {steps} | {seconds:.1} | {:.3} | |",
        seconds / steps.max(1) as f64
    );
    let runs = [
        ("Wallace", with(FormFactorMethod::Wallace, 128, lenmax)),
        (
            "hemicube 256",
            with(FormFactorMethod::Hemicube, 256, lenmax),
        ),
        (
            "hemicube 128",
            with(FormFactorMethod::Hemicube, 128, lenmax),
        ),
        ("hemicube 128, every cell every step", variant(false, 64)),
        ("hemicube 128, 256 cells", variant(true, 256)),
        ("hemicube 64", with(FormFactorMethod::Hemicube, 64, lenmax)),
        ("hemicube 32", with(FormFactorMethod::Hemicube, 32, lenmax)),
        ("centre", with(FormFactorMethod::Center, 128, lenmax)),
    ];
    let exposure = radiosity::render::tonemap::auto_exposure(&reference);
    let mut composite = RgbImage::new(SIZE.0 * 2, SIZE.1 * 2);
    let mut errors = RgbImage::new(SIZE.0 * 2, SIZE.1);
    for (name, config) in runs {
        let (frame, _, steps, seconds) = solve(&config);
        let (mut diff, mut total) = (0.0, 0.0);
        for k in 0..frame.pixels.len() {
            if !reference.covered[k] || lamps.pixels[k][0] > 0.0 {
                continue;
            }
            diff += (luminance(&frame.pixels[k]) - luminance(&reference.pixels[k])).abs();
            total += luminance(&reference.pixels[k]);
        }
        println!(
            "| {name} | {steps} | {seconds:.1} | {:.3} | {:.2} % |",
            seconds / steps.max(1) as f64,
            diff / total.max(f64::MIN_POSITIVE) * 100.0
        );
        let at = match name {
            "Wallace" => Some((0, 0)),
            "hemicube 128" => Some((1, 0)),
            "centre" => Some((0, 1)),
            "hemicube 32" => Some((1, 1)),
            _ => None,
        };
        let panel = match name {
            "hemicube 128" => Some(0),
            "hemicube 128, 256 cells" => Some(1),
            _ => None,
        };
        if let Some(x) = panel {
            let map = error_map(&frame, &reference, &lamps);
            errors
                .copy_from(&map, x * SIZE.0, 0)
                .expect("the panel fits");
        }
        if let Some((x, y)) = at {
            let picture = radiosity::render::tonemap::to_srgb8(&frame, exposure);
            composite
                .copy_from(&picture, x * SIZE.0, y * SIZE.1)
                .expect("the panel fits");
        }
    }
    composite.save(out).expect("the composite is written");
    if let Some(path) = error_map_out {
        errors.save(path).expect("the error map is written");
    }
}

/// The signed relative luminance error of `frame` against `reference` per
/// pixel: red where brighter, blue where darker, full at ±10 %, over the
/// reference's luminance drawn dim in green; lamps and uncovered pixels
/// black.
fn error_map(frame: &Frame, reference: &Frame, lamps: &Frame) -> RgbImage {
    let brightest = reference
        .pixels
        .iter()
        .map(luminance)
        .fold(f64::MIN_POSITIVE, f64::max);
    RgbImage::from_fn(SIZE.0, SIZE.1, |x, y| {
        let k = (y * SIZE.0 + x) as usize;
        if !reference.covered[k] || lamps.pixels[k][0] > 0.0 {
            return image::Rgb([0, 0, 0]);
        }
        let r = luminance(&reference.pixels[k]);
        let rel = (luminance(&frame.pixels[k]) - r) / r.max(1e-9);
        let level = ((rel.abs() / 0.1).min(1.0) * 255.0) as u8;
        let dim = ((r / brightest).min(1.0) * 60.0) as u8;
        if rel > 0.0 {
            image::Rgb([level, dim, 0])
        } else {
            image::Rgb([0, dim, level])
        }
    })
}
