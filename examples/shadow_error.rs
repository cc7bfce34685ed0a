//! Measures how adaptive subdivision changes the error of the picture near
//! shadow boundaries (`docs/accuracy.md`):
//!
//! ```sh
//! cargo run --release --example shadow_error -- scenes/cornell.sc scenes/cameras/cornell-base.sc
//! ```
//!
//! Solves the scene on a reference mesh (an eighth of the default `lenmax`
//! everywhere: the element size three adaptive levels reach), then on
//! regular meshes of the default `lenmax`, a half and a quarter of it, and
//! on the default mesh with one, two and three adaptive levels. Each solution is rendered from the camera file's
//! camera and compared pixel by pixel with the reference: the mean absolute
//! luminance error over every covered pixel, and over the pixels near a
//! shadow boundary (where the reference's luminance changes by more than
//! 20 % of the local maximum within two pixels), both relative to the
//! reference's mean luminance there.

use radiosity::config::{RunConfig, SceneSource};
use radiosity::mesh::refine::RefineOptions;
use radiosity::prepare::{self, Prepared};
use radiosity::render::Frame;
use radiosity::session::{Session, SessionOptions};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// Relative luminance change within [`BAND_RADIUS`] pixels that puts a
/// pixel in the shadow-boundary band.
const BAND_CONTRAST: f64 = 0.2;
/// Radius of the neighbourhood for [`BAND_CONTRAST`], in pixels.
const BAND_RADIUS: i64 = 2;

fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

fn main() {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let (Some(scene), Some(camera)) = (args.first(), args.get(1)) else {
        eprintln!("usage: shadow_error SCENE CAMERA.sc");
        std::process::exit(2);
    };
    let base = {
        let mut c = RunConfig::new(SceneSource::File(scene.clone()));
        c.camera = Some(camera.clone());
        c
    };
    let default_lenmax = match prepare::prepare(&base) {
        Ok(p) => p.lenmax,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let adaptive = |levels| {
        Some(RefineOptions {
            levels,
            ..RefineOptions::default()
        })
    };
    let runs = [
        ("reference: lenmax / 8", default_lenmax / 8.0, None),
        ("regular, default lenmax", default_lenmax, None),
        ("regular, lenmax / 2", default_lenmax / 2.0, None),
        ("regular, lenmax / 4", default_lenmax / 4.0, None),
        ("--adaptive-levels 1", default_lenmax, adaptive(1)),
        ("--adaptive (2 levels)", default_lenmax, adaptive(2)),
        ("--adaptive-levels 3", default_lenmax, adaptive(3)),
    ];
    let mut reference: Option<(Frame, Vec<bool>)> = None;
    println!(
        "| mesh | vertices | solve s | mean error | error near shadow edges |\n|---|---|---|---|---|"
    );
    for (name, lenmax, refine) in runs {
        let mut config = base.clone();
        config.lenmax = Some(lenmax);
        config.adaptive = refine;
        let prepared: Prepared =
            prepare::prepare(&config).expect("the scene prepared once already");
        let view = prepared.view(&config).expect("the camera file's camera");
        let t = Instant::now();
        let mut session = Session::from_prepared(
            &prepared,
            SessionOptions::for_run(&config, &prepared, false),
        );
        session
            .run_to_end(&AtomicBool::new(false))
            .expect("an uncancelled solve");
        let seconds = t.elapsed().as_secs_f64();
        let frame = radiosity::render::render(session.mesh(), session.radiosity(), &view)
            .expect("the solution renders");
        let vertices = session.mesh().vertex_count();
        match &reference {
            None => {
                let band = shadow_band(&frame);
                println!(
                    "| {name} | {vertices} | {seconds:.2} | (reference) | ({} pixels in the band) |",
                    band.iter().filter(|b| **b).count()
                );
                reference = Some((frame, band));
            }
            Some((r, band)) => {
                let all = relative_error(r, &frame, |k| r.covered[k]);
                let near = relative_error(r, &frame, |k| band[k]);
                println!(
                    "| {name} | {vertices} | {seconds:.2} | {:.2} % | {:.2} % |",
                    all * 100.0,
                    near * 100.0
                );
            }
        }
    }
}

/// Pixels near a shadow boundary of `frame`: covered, with a covered pixel
/// within [`BAND_RADIUS`] whose luminance differs by more than
/// [`BAND_CONTRAST`] of the larger of the two, on the same surface depth
/// (both covered).
fn shadow_band(frame: &Frame) -> Vec<bool> {
    let (w, h) = (frame.width as i64, frame.height as i64);
    let lum: Vec<f64> = frame.pixels.iter().map(luminance).collect();
    let mut band = vec![false; lum.len()];
    for y in 0..h {
        for x in 0..w {
            let k = (y * w + x) as usize;
            if !frame.covered[k] {
                continue;
            }
            'search: for dy in -BAND_RADIUS..=BAND_RADIUS {
                for dx in -BAND_RADIUS..=BAND_RADIUS {
                    let (u, v) = (x + dx, y + dy);
                    if u < 0 || v < 0 || u >= w || v >= h {
                        continue;
                    }
                    let j = (v * w + u) as usize;
                    let top = lum[k].max(lum[j]);
                    if frame.covered[j]
                        && top > 0.0
                        && (lum[k] - lum[j]).abs() > BAND_CONTRAST * top
                    {
                        band[k] = true;
                        break 'search;
                    }
                }
            }
        }
    }
    band
}

/// Mean absolute luminance difference over the pixels `keep` selects,
/// relative to the reference's mean luminance over them.
fn relative_error(reference: &Frame, frame: &Frame, keep: impl Fn(usize) -> bool) -> f64 {
    let (mut diff, mut total) = (0.0, 0.0);
    for (k, (a, b)) in reference.pixels.iter().zip(&frame.pixels).enumerate() {
        if keep(k) {
            diff += (luminance(a) - luminance(b)).abs();
            total += luminance(a);
        }
    }
    if total > 0.0 {
        diff / total
    } else {
        0.0
    }
}
