//! Checks how well a converged solution satisfies the radiosity equation
//! on chosen polygons, by Monte Carlo, with nothing of the solver's form
//! factors or visibility (`docs/accuracy.md`):
//!
//! ```sh
//! cargo run --release --example hall -- 1 > hall1.sc
//! cargo run --release --example consistency -- hall1.sc 0.25 44,48,49
//! ```
//!
//! Arguments: the scene, `lenmax` (`-` for the program's default), the
//! polygons to check (indices, comma-separated, as `cluster_compare`'s
//! `CC_LIST=1` prints them) and optionally the points per polygon
//! (default 20,000). `SHOOTER_SAMPLES=N` sets `--shooter-samples` for
//! both solves, `THRESHOLD=T` their threshold (default 0.001); `BINS=1`
//! prints each polygon's two means in ten bands of height, and `HITS=1`
//! where its rays went (per polygon hit: the count and its share of the
//! right-hand side).
//!
//! The right-hand side reads the radiosity the picture shows, so a
//! surface that sees an element straddling a hidden bright patch reads
//! high there: on McGuire's `CornellBox-Original.obj`, while its lamp's
//! back still lit the ceiling a centimetre above it, the short box's top
//! came out 7.5 % below its right-hand side in both modes, most of the
//! difference in what its rays found on the ceiling around the lamp
//! (−1.1 % ± 0.9 % since that side emits nothing).
//!
//! Solves the scene twice, without clustering or overshooting (the
//! original algorithm) and with the defaults. For each solution and
//! polygon it takes random points on the polygon and, at each, one
//! cosine-weighted direction over its front hemisphere, traced to the
//! nearest polygon by brute force. A converged solution should satisfy
//! `B(x) = E(x) + ρ(x) · B(y)` in the mean over such pairs (the
//! irradiance over π is the mean of the radiosity seen along
//! cosine-weighted directions), with `B` both sides interpolated over the
//! element's triangles as the picture draws it. It prints the polygon's
//! mean `B(x)`, the mean right-hand side, their difference relative to
//! the right-hand side and that estimate's standard error: the solution
//! whose difference is beyond its error is the one that is off there.

#[path = "support/tracer.rs"]
mod tracer;

use radiosity::color::Rgb;
use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare;
use radiosity::session::{Session, SessionOptions};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use tracer::{Rng, Tracer};

/// Per polygon: (mean luminance of `B(x)`, of `E + ρ B(y)`, the standard
/// error of the difference's mean).
fn check(tracer: &Tracer, polygons: &[usize], points: usize) -> Vec<(f64, f64, f64)> {
    polygons
        .par_iter()
        .map(|&p| {
            let poly = &tracer.scene.polygons[p];
            let material = &tracer.scene.materials[poly.material.index()];
            let (e, rho) = (material.emission(), material.reflectance());
            let n = poly.normal.as_dvec3();
            let (u, w) = n.any_orthonormal_pair();
            let mut rng = Rng(0x5eed ^ p as u64);
            let (mut sum_b, mut sum_rhs, mut sum_d2) = (0.0, 0.0, 0.0);
            let mut bins = [(0.0f64, 0.0f64, 0usize); 10];
            let debug_hits = std::env::var_os("HITS").is_some();
            let mut hits = std::collections::BTreeMap::new();
            let (lo, hi) = poly
                .vertices
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(f64::from(v.y)), hi.max(f64::from(v.y)))
                });
            for _ in 0..points {
                let x = tracer.point_on(p, &mut rng);
                let b = tracer.radiosity_at(p, x).luminance();
                // A cosine-weighted direction (Malley's method).
                let (r, phi) = (rng.next().sqrt(), 2.0 * PI * rng.next());
                let d = u * (r * phi.cos()) + w * (r * phi.sin()) + n * (1.0 - r * r).sqrt();
                let seen = match tracer.hit(x + n * 1e-6, d) {
                    // Only a polygon's front radiates.
                    Some((q, t)) if tracer.scene.polygons[q].normal.as_dvec3().dot(d) < 0.0 => {
                        tracer.radiosity_at(q, x + d * t)
                    }
                    _ => Rgb::BLACK,
                };
                if debug_hits {
                    let q = tracer.hit(x + n * 1e-6, d).map_or(usize::MAX, |h| h.0);
                    let e = hits.entry(q).or_insert((0usize, 0.0f64));
                    e.0 += 1;
                    e.1 += (rho * seen).luminance() / points as f64;
                }
                let rhs = (e + rho * seen).luminance();
                sum_b += b;
                sum_rhs += rhs;
                sum_d2 += (rhs - b) * (rhs - b);
                if hi > lo {
                    let k = (((x.y - lo) / (hi - lo)) * 10.0).clamp(0.0, 9.0) as usize;
                    bins[k].0 += b;
                    bins[k].1 += rhs;
                    bins[k].2 += 1;
                }
            }
            if debug_hits {
                eprintln!("polygon {p} normal {} hits {hits:?}", poly.normal);
            }
            if std::env::var_os("BINS").is_some() {
                let row: Vec<String> = bins
                    .iter()
                    .map(|(b, r, n)| format!("{:.4}/{:.4}", b / *n as f64, r / *n as f64))
                    .collect();
                eprintln!("polygon {p} by height: {}", row.join(" "));
            }
            let k = points as f64;
            let mean_d = (sum_rhs - sum_b) / k;
            let var = (sum_d2 / k - mean_d * mean_d).max(0.0);
            (sum_b / k, sum_rhs / k, (var / k).sqrt())
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: consistency SCENE LENMAX|- POLYGON[,POLYGON...] [POINTS]");
        std::process::exit(2);
    }
    let mut config = RunConfig::new(SceneSource::File(PathBuf::from(&args[0])));
    config.lenmax = args[1].parse().ok();
    if let Some(n) = std::env::var("SHOOTER_SAMPLES")
        .ok()
        .and_then(|n| n.parse().ok())
    {
        config.solver.shooter_samples = radiosity::solver::ShooterSamples::AtMost(n);
    }
    if let Some(t) = std::env::var("THRESHOLD").ok().and_then(|t| t.parse().ok()) {
        config.solver.threshold = t;
    }
    let polygons: Vec<usize> = args[2]
        .split(',')
        .map(|p| p.trim().parse().expect("a polygon index"))
        .collect();
    let points: usize = args.get(3).map_or(20_000, |p| p.parse().expect("a count"));
    let prepared = prepare::prepare(&config).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2);
    });
    let count = prepared.scene.polygons.len();
    if let Some(p) = polygons.iter().find(|&&p| p >= count) {
        eprintln!("polygon {p} is not in the scene ({count} polygons)");
        std::process::exit(2);
    }
    println!("| solver | polygon | line | B | E + ρ B(seen) | B off by | ± |");
    println!("|---|---|---|---|---|---|---|");
    for (clustering, overshoot, label) in [
        (false, false, "--no-clustering --no-overshoot"),
        (true, true, "default"),
    ] {
        let mut c = config.clone();
        c.solver.approximations.clusters = clustering;
        c.solver.approximations.overshoot = overshoot;
        let mut session =
            Session::from_prepared(&prepared, SessionOptions::for_run(&c, &prepared, false));
        session
            .run_to_end(&AtomicBool::new(false))
            .expect("an uncancelled solve");
        let tracer = Tracer {
            scene: &prepared.scene,
            mesh: session.mesh(),
            radiosity: session.radiosity(),
            t_min: 1e-6,
        };
        for (&p, (b, rhs, err)) in polygons.iter().zip(check(&tracer, &polygons, points)) {
            println!(
                "| {label} | {p} | {} | {b:.5} | {rhs:.5} | {:+.2} % | {:.2} % |",
                prepared.scene.polygons[p].origin.line,
                (b / rhs - 1.0) * 100.0,
                err / rhs * 100.0
            );
        }
    }
}
