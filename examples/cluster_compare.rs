//! Compares the clustered, overshooting solver with its twins on one
//! scene and mesh (`docs/accuracy.md`, `docs/performance.md`): the
//! original algorithm (`--no-clustering --no-overshoot`, the reference),
//! `--exact-receivers` and `--no-overshoot`:
//!
//! ```sh
//! cargo run --release --example sphere_box -- 32 > spheres32.sc
//! cargo run --release --example cluster_compare -- spheres32.sc
//! cargo run --release --example cluster_compare -- hall.sc 0.25
//! ```
//!
//! Arguments: the scene and, optionally, `lenmax` in scene units (`-` or
//! absent for the program's default) and the threshold (default 0.001).
//! `CC_SHOOTER_SAMPLES=N` makes every mode shoot from at most N cells;
//! `CC_CAMERA=FILE.sc` takes the pictures with that file's camera, as
//! `--camera` does (for an OBJ or glTF model without one).
//! `CC_REFERENCE=FILE` keeps the reference's vertex radiosity in FILE:
//! read from it when it exists and fits the mesh (the reference mode is
//! then not solved again), written to it otherwise, so a slow converged
//! reference is solved once for many comparisons.
//! Solves in each mode (`CC_SKIP_BRUTE=1` skips the slow reference, and
//! the solve with exact receivers is then the reference; `CC_MODES=--o,c-o`
//! runs the modes listed instead, the first the reference: three
//! letters each, `c` clustering, `i` receiver interpolation, `o`
//! overshooting, `-` off, optionally followed by `@THRESHOLD`, that
//! mode's own threshold) and prints for
//! each the steps, rays and solve seconds, and for all but the reference
//! their difference from it: the picture's relative L1 error (mean
//! absolute luminance difference over mean luminance, over the pixels
//! the scene's camera shows, lamps excluded), the same over vertices
//! (area-weighted, emitters excluded), and the largest difference of a
//! polygon's mean radiosity, relative to it (polygons whose mean is at
//! least a thousandth of the brightest non-emitting polygon's).

use radiosity::color::Rgb;
use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare::{self, Prepared};
use radiosity::render::Frame;
use radiosity::session::{Session, SessionOptions};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn luminance(c: Rgb) -> f64 {
    0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(scene) = args.first() else {
        eprintln!("usage: cluster_compare SCENE [LENMAX|-] [THRESHOLD]");
        std::process::exit(2);
    };
    let mut config = RunConfig::new(SceneSource::File(PathBuf::from(scene)));
    config.lenmax = args.get(1).and_then(|l| l.parse().ok());
    // CC_CAMERA=FILE.sc: that file's camera for the pictures (`--camera`),
    // for models that bring none.
    config.camera = std::env::var_os("CC_CAMERA").map(PathBuf::from);
    if let Some(t) = args.get(2).and_then(|t| t.parse().ok()) {
        config.solver.threshold = t;
    }
    // CC_SHOOTER_SAMPLES=N: every mode shoots from at most N cells.
    if let Some(n) = std::env::var("CC_SHOOTER_SAMPLES")
        .ok()
        .and_then(|n| n.parse().ok())
    {
        config.solver.shooter_samples = radiosity::solver::ShooterSamples::AtMost(n);
    }
    let prepared: Prepared = match prepare::prepare(&config) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let view = prepared.view(&config).expect("the scene's camera");
    let emitting: Vec<bool> = prepared
        .scene
        .polygons
        .iter()
        .map(|p| {
            !prepared.scene.materials[p.material.index()]
                .emission()
                .is_black()
        })
        .collect();
    // The first run is the reference. CC_SKIP_BRUTE=1 skips the (slow)
    // unclustered solve, so the clustered solve with exact receivers is
    // the reference.
    let skip_brute = std::env::var_os("CC_SKIP_BRUTE").is_some();
    // (clustering, receiver interpolation, overshooting, label)
    let modes = [
        (false, false, false, "--no-clustering --no-overshoot"),
        (true, false, true, "--exact-receivers"),
        (true, true, false, "--no-overshoot"),
        (true, true, true, "default"),
    ];
    // CC_MODES=cio,c-o,--o,...: other modes to run instead, the first the
    // reference; each three letters, `c` clustering, `i` receiver
    // interpolation, `o` overshooting, `-` for off.
    // A mode may end in `@THRESHOLD`, its own threshold (`---@0.00001,cio`
    // compares the default solve with the converged brute-force one).
    let chosen: Vec<(bool, bool, bool, Option<f64>, String)> = match std::env::var("CC_MODES") {
        Ok(list) => list
            .split(',')
            .map(|m| {
                let (letters, threshold) = match m.split_once('@') {
                    Some((l, t)) => match t.parse::<f64>() {
                        Ok(t) if t > 0.0 && t < 1.0 => (l, Some(t)),
                        _ => {
                            eprintln!("CC_MODES: {t:?} in {m:?} is not a threshold in (0, 1)");
                            std::process::exit(2);
                        }
                    },
                    None => (m, None),
                };
                let on: Vec<bool> = letters.chars().map(|c| c != '-').collect();
                if on.len() != 3 {
                    eprintln!("CC_MODES: {m:?} is not three letters such as c-o");
                    std::process::exit(2);
                }
                (on[0], on[1], on[2], threshold, m.to_string())
            })
            .collect(),
        Err(_) => modes[skip_brute as usize..]
            .iter()
            .map(|&(c, i, o, l)| (c, i, o, None, l.to_string()))
            .collect(),
    };
    println!(
        "# {scene}: {} polygons, {} vertices, lenmax {}",
        prepared.scene.polygons.len(),
        prepared.mesh.vertex_count(),
        prepared.lenmax
    );
    println!("| solver | clusters | steps | rays | solve s | picture relL1 | vertex relL1 | worst polygon mean |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut reference: Option<(Frame, Vec<Rgb>, Vec<Rgb>)> = None;
    let cache = std::env::var_os("CC_REFERENCE").map(PathBuf::from);
    for (clustering, interpolation, overshoot, threshold, label) in chosen {
        let mut c = config.clone();
        if let Some(t) = threshold {
            c.solver.threshold = t;
        }
        c.solver.approximations.clusters = clustering;
        c.solver.approximations = if interpolation {
            c.solver.approximations
        } else {
            c.solver
                .approximations
                .without(&radiosity::solver::Heuristic::RECEIVERS)
        };
        c.solver.approximations.overshoot = overshoot;
        let mesh = &prepared.mesh;
        if reference.is_none() {
            if let Some(radiosity) = cache
                .as_deref()
                .and_then(|f| read_cache(f, mesh.vertex_count()))
            {
                let frame = radiosity::render::render(mesh, &radiosity, &view).expect("renders");
                let means = polygon_means(mesh, &radiosity);
                println!("| {label} | | | | | (reference, from CC_REFERENCE) | | |");
                reference = Some((frame, radiosity, means));
                continue;
            }
        }
        let t = Instant::now();
        let mut session =
            Session::from_prepared(&prepared, SessionOptions::for_run(&c, &prepared, false));
        session
            .run_to_end(&AtomicBool::new(false))
            .expect("an uncancelled solve");
        let seconds = t.elapsed().as_secs_f64();
        let mesh = session.mesh();
        let radiosity = session.radiosity().to_vec();
        if reference.is_none() {
            if let Some(f) = &cache {
                write_cache(f, &radiosity);
            }
        }
        let frame = radiosity::render::render(mesh, &radiosity, &view).expect("renders");
        let areas = mesh.vertex_areas();
        let means = polygon_means(mesh, &radiosity);
        let solver = session.solver().as_progressive();
        let clusters = solver.expect("a progressive solve").clusters();
        let head = format!(
            "| {label} | {} ({} grouped) | {} | {:.1} M | {seconds:.1} |",
            clusters.len(),
            clusters.grouped(),
            session.totals().steps,
            session.totals().rays as f64 / 1e6,
        );
        match &reference {
            None => {
                println!("{head} (reference) | | |");
                reference = Some((frame, radiosity, means));
            }
            Some((rf, rr, rm)) => {
                // Lamps: pixels where a mask of the emitters renders lit.
                let mask: Vec<Rgb> = mesh
                    .vertex_polygon
                    .iter()
                    .map(|p| {
                        if emitting[p.index()] {
                            Rgb::new(1.0, 1.0, 1.0)
                        } else {
                            Rgb::BLACK
                        }
                    })
                    .collect();
                let lamps = radiosity::render::render(mesh, &mask, &view).expect("renders");
                let (mut diff, mut total) = (0.0, 0.0);
                for k in 0..rf.pixels.len() {
                    if !rf.covered[k] || lamps.pixels[k][0] > 0.0 {
                        continue;
                    }
                    let px =
                        |p: [f32; 3]| luminance(Rgb::new(p[0].into(), p[1].into(), p[2].into()));
                    diff += (px(frame.pixels[k]) - px(rf.pixels[k])).abs();
                    total += px(rf.pixels[k]);
                }
                let picture = diff / total.max(f64::MIN_POSITIVE);
                let (mut vd, mut vt) = (0.0, 0.0);
                for (l, p) in mesh.vertex_polygon.iter().enumerate() {
                    if emitting[p.index()] {
                        continue;
                    }
                    vd += (luminance(radiosity[l]) - luminance(rr[l])).abs() * areas[l];
                    vt += luminance(rr[l]) * areas[l];
                }
                let brightest = rm
                    .iter()
                    .zip(&emitting)
                    .filter(|(_, e)| !**e)
                    .map(|(m, _)| luminance(*m))
                    .fold(0.0, f64::max);
                let mut worst = (0.0f64, 0usize);
                let mut over = 0;
                for (j, (a, b)) in means.iter().zip(rm).enumerate() {
                    let b = luminance(*b);
                    if emitting[j] || b < 1e-3 * brightest {
                        continue;
                    }
                    let d = (luminance(*a) - b).abs() / b;
                    over += (d > 0.02) as usize;
                    if std::env::var_os("CC_LIST").is_some() && d > 0.02 {
                        eprintln!(
                            "polygon {j} line {} area {:.4}: {:.5} vs {:.5} ({:+.2} %)",
                            prepared.scene.polygons[j].origin.line,
                            mesh.polygons[j].area,
                            luminance(*a),
                            b,
                            (luminance(*a) / b - 1.0) * 100.0
                        );
                    }
                    if d > worst.0 {
                        worst = (d, j);
                    }
                }
                eprintln!("{over} polygons differ by more than 2 %");
                let line = prepared.scene.polygons[worst.1].origin.line;
                println!(
                    "{head} {:.2} % | {:.2} % | {:.2} % (line {line}, area {:.3}, {:.4} vs {:.4}) |",
                    picture * 100.0,
                    vd / vt.max(f64::MIN_POSITIVE) * 100.0,
                    worst.0 * 100.0,
                    mesh.polygons[worst.1].area,
                    luminance(means[worst.1]),
                    luminance(rm[worst.1]),
                );
            }
        }
    }
}

/// Every polygon's area-weighted mean radiosity.
fn polygon_means(mesh: &radiosity::mesh::Mesh, radiosity: &[Rgb]) -> Vec<Rgb> {
    let areas = mesh.vertex_areas();
    mesh.polygons
        .iter()
        .map(|pm| {
            let mut sum = Rgb::BLACK;
            for l in pm.vertices.clone() {
                sum += radiosity[l as usize] * areas[l as usize];
            }
            if pm.area > 0.0 {
                sum / pm.area
            } else {
                Rgb::BLACK
            }
        })
        .collect()
}

/// The reference radiosity kept in `file` (three little-endian `f64` per
/// vertex), when it is there and holds `vertices` of them.
fn read_cache(file: &std::path::Path, vertices: usize) -> Option<Vec<Rgb>> {
    let bytes = std::fs::read(file).ok()?;
    if bytes.len() != vertices * 24 {
        eprintln!(
            "CC_REFERENCE: {} does not fit this mesh; solving the reference again",
            file.display()
        );
        return None;
    }
    let f = |k: usize| f64::from_le_bytes(bytes[k * 8..k * 8 + 8].try_into().expect("8 bytes"));
    Some(
        (0..vertices)
            .map(|l| Rgb::new(f(3 * l), f(3 * l + 1), f(3 * l + 2)))
            .collect(),
    )
}

/// Keeps `radiosity` in `file` for [`read_cache`].
fn write_cache(file: &std::path::Path, radiosity: &[Rgb]) {
    let bytes: Vec<u8> = radiosity
        .iter()
        .flat_map(|c| [c.r, c.g, c.b])
        .flat_map(f64::to_le_bytes)
        .collect();
    if let Err(e) = std::fs::write(file, bytes) {
        eprintln!("CC_REFERENCE: cannot write {}: {e}", file.display());
    }
}
