//! Checks the final gather's illuminance against an independent Monte
//! Carlo estimate of the same quantity (`docs/accuracy.md`):
//!
//! ```sh
//! cargo run --release --example illuminance_reference -- \
//!     scenes/office.sc luminaire=scenes/luminaires/panel.ies 0.25 4096
//! ```
//!
//! Arguments: the scene (in metres), `NAME=FILE.ies` (or `-` for the
//! scene's own emitters), the spacing of the floor grid in metres, and the
//! hemisphere samples per point.
//!
//! The scene is solved as the program solves it; then, at every point of
//! a grid on the floor (facing up; points inside furniture, where a ray
//! straight up meets the back of a face first, are left out), the
//! illuminance is computed twice:
//!
//! - by the program's final gather ([`FinalGather`]): cell form factors
//!   with the near field, shaft-culled shadow rays, the luminaires'
//!   intensity tables through the solver's distribution hook;
//! - by Monte Carlo with nothing of that code: the direct light by
//!   sampling uniform random points on every emitter (a parallelogram),
//!   `I cosθ_x / r²` with a shadow ray, `I` a luminaire's intensity table
//!   read by `Photometry::intensity` or `e A cosθ / π` for a Lambertian
//!   emitter; the reflected light by cosine-weighted directions over the
//!   hemisphere, each traced to the nearest polygon by brute force and
//!   given the radiosity there, interpolated over the element's triangles
//!   (what the picture shows), less the emission the direct part counted.
//!
//! Both estimate the same quantity from the same converged solution, so
//! the difference measures the gather (its form factors, near field and
//! visibility), not the solver. It prints the relative L1 difference
//! `Σ|E_gather − E_mc| / Σ E_mc`, the largest relative difference, the
//! Monte Carlo standard error, and the seconds each took.

#[path = "support/tracer.rs"]
mod tracer;

use glam::{DVec3, Vec3};
use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare;
use radiosity::scene::{Scene, Units};
use radiosity::session::{Session, SessionOptions};
use radiosity::solver::final_gather::FinalGather;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;
use tracer::{Rng, Tracer};

/// Random points per luminaire for the direct light.
const LIGHT_SAMPLES: usize = 1024;

/// The material of a polygon.
trait MaterialOf {
    fn material_of_polygon(&self, p: &radiosity::scene::Polygon) -> &radiosity::scene::Material;
}

impl MaterialOf for Scene {
    fn material_of_polygon(&self, p: &radiosity::scene::Polygon) -> &radiosity::scene::Material {
        &self.materials[p.material.index()]
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 5 {
        eprintln!("usage: illuminance_reference SCENE NAME=FILE.ies|- SPACING SAMPLES");
        std::process::exit(2);
    }
    let mut config = RunConfig::new(SceneSource::File(PathBuf::from(&args[1])));
    config.photometry.units = Some(Units::M);
    if let Some((name, file)) = args[2].split_once('=') {
        config.photometry.ies = vec![(name.to_string(), PathBuf::from(file))];
    }
    let spacing: f64 = args[3].parse().expect("a spacing in metres");
    let samples: usize = args[4].parse().expect("a number of samples");
    let prepared = prepare::prepare(&config).unwrap_or_else(|e| panic!("{e}"));
    let mut session = Session::from_prepared(
        &prepared,
        SessionOptions::for_run(&config, &prepared, false),
    );
    session
        .run_to_end(&AtomicBool::new(false))
        .unwrap_or_else(|e| panic!("{e}"));
    let scene = &prepared.scene;
    let mesh = session.mesh();
    let radiosity = session.radiosity();
    let tracer = Tracer {
        scene,
        mesh,
        radiosity,
        t_min: 1e-6,
    };

    // The floor grid: cell centres over the bounds at y = 0, facing up,
    // without the points inside furniture.
    let (lo, hi) = scene.bounds();
    let nx = ((f64::from(hi.x - lo.x) / spacing).round() as usize).max(1);
    let nz = ((f64::from(hi.z - lo.z) / spacing).round() as usize).max(1);
    let points: Vec<(Vec3, Vec3)> = (0..nz)
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|(i, j)| {
            let x = lo.x + (i as f32 + 0.5) / nx as f32 * (hi.x - lo.x);
            let z = lo.z + (j as f32 + 0.5) / nz as f32 * (hi.z - lo.z);
            (Vec3::new(x, lo.y, z), Vec3::Y)
        })
        .filter(|(x, _)| {
            let up = DVec3::Y;
            match tracer.hit(x.as_dvec3(), up) {
                Some((p, _)) => scene.polygons[p].normal.as_dvec3().dot(up) < 0.0,
                None => false,
            }
        })
        .collect();

    let t = Instant::now();
    let gather = FinalGather::new(
        scene,
        mesh,
        prepared.visibility(),
        radiosity,
        config.solver.approximations.near_field,
    );
    let gathered: Vec<f64> = gather
        .irradiance_at(&points)
        .iter()
        .map(|e| e.luminance())
        .collect();
    let gather_seconds = t.elapsed().as_secs_f64();

    // The emitters: IES luminaires by their tables, the others as
    // Lambertian parallelograms of their emission (`I = e A cosθ / π`).
    let lights: Vec<usize> = scene
        .polygons
        .iter()
        .enumerate()
        .filter(|(_, p)| !scene.material_of_polygon(p).emission().is_black())
        .map(|(i, _)| i)
        .collect();
    for &i in &lights {
        assert_eq!(
            scene.polygons[i].vertices.len(),
            4,
            "the reference samples emitters as parallelograms"
        );
    }
    let t = Instant::now();
    let reference: Vec<(f64, f64)> = points
        .par_iter()
        .enumerate()
        .map(|(k, &(x, n))| {
            let mut rng = Rng(0x5eed ^ (k as u64).wrapping_mul(0x9e37_79b9));
            let (x, n) = (x.as_dvec3(), n.as_dvec3());
            // Direct: uniform points on each luminaire (a parallelogram
            // v0 + s (v1 − v0) + t (v3 − v0)).
            let mut direct = 0.0;
            for &i in &lights {
                let p = &scene.polygons[i];
                let v: Vec<DVec3> = p.vertices.iter().map(|v| v.as_dvec3()).collect();
                let nadir = p.normal.as_dvec3();
                let luminaire = scene.luminaire_of(p.material);
                let lambert = scene.material_of_polygon(p).emission().luminance() * p.area / PI;
                let mut sum = 0.0;
                for _ in 0..LIGHT_SAMPLES {
                    let q = v[0] + (v[1] - v[0]) * rng.next() + (v[3] - v[0]) * rng.next();
                    let d = x - q;
                    let r2 = d.length_squared();
                    let cos_x = -n.dot(d) / r2.sqrt();
                    let cos_t = nadir.dot(d) / r2.sqrt();
                    if cos_x <= 0.0 || cos_t <= 0.0 || tracer.blocked(q, x) {
                        continue;
                    }
                    let intensity = match luminaire {
                        Some(l) => {
                            let c0 = l.c0.as_dvec3();
                            let phi = nadir.cross(c0).dot(d).atan2(c0.dot(d));
                            l.photometry.intensity(cos_t.acos(), phi)
                        }
                        None => lambert * cos_t,
                    };
                    sum += intensity * cos_x / r2;
                }
                direct += sum / LIGHT_SAMPLES as f64;
            }
            // Indirect: cosine-weighted directions, E = mean of B at hits.
            let (t1, t2) = (DVec3::X, DVec3::Z);
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..samples {
                let (u1, u2) = (rng.next(), rng.next());
                let r = u1.sqrt();
                let a = 2.0 * PI * u2;
                let d = t1 * (r * a.cos()) + t2 * (r * a.sin()) + n * (1.0 - u1).sqrt();
                // The light reflected at the hit: its radiosity less its
                // emission, which the direct part counted.
                let b = match tracer.hit(x, d) {
                    Some((p, t)) if scene.polygons[p].normal.as_dvec3().dot(d) < 0.0 => {
                        let e = scene.material_of_polygon(&scene.polygons[p]).emission();
                        (tracer.radiosity_at(p, x + d * t).luminance() - e.luminance()).max(0.0)
                    }
                    _ => 0.0,
                };
                sum += b;
                sum2 += b * b;
            }
            let mean = sum / samples as f64;
            let var = (sum2 / samples as f64 - mean * mean).max(0.0) / samples as f64;
            (direct + mean, var.sqrt())
        })
        .collect();
    let mc_seconds = t.elapsed().as_secs_f64();

    let total: f64 = reference.iter().map(|r| r.0).sum();
    let l1: f64 = gathered
        .iter()
        .zip(&reference)
        .map(|(g, r)| (g - r.0).abs())
        .sum();
    let (worst_at, worst) = gathered
        .iter()
        .zip(&reference)
        .map(|(g, r)| (g / r.0 - 1.0).abs())
        .enumerate()
        .fold((0, 0.0), |a, (k, d)| if d > a.1 { (k, d) } else { a });
    let se = reference.iter().map(|r| r.1).sum::<f64>() / total;
    println!(
        "{}: {} floor points, mean {:.1} lx; gather {:.3} s ({:.0} points/s), \
         Monte Carlo ({LIGHT_SAMPLES} light + {samples} hemisphere samples) {:.1} s",
        args[1],
        points.len(),
        total / points.len() as f64,
        gather_seconds,
        points.len() as f64 / gather_seconds,
        mc_seconds
    );
    println!(
        "relL1 {:.3} %, largest relative difference {:.2} % (at {}: {:.1} lx vs {:.1} ± {:.1} lx), \
         Monte Carlo standard error (indirect, relative to the mean) {:.3} %",
        100.0 * l1 / total,
        100.0 * worst,
        points[worst_at].0,
        gathered[worst_at],
        reference[worst_at].0,
        reference[worst_at].1,
        100.0 * se
    );
}
