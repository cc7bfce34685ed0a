//! Final-gather benchmarks: the illuminance at the 310 floor points of
//! `scenes/office.sc` (0.25 m grid) with its IES panels, from the converged
//! solution, with the near field (the default) and without it; and the
//! solve itself, for the ratio of the two. Points per second are printed
//! once per run; criterion reports the time per batch of points.

use criterion::{criterion_group, criterion_main, Criterion};
use glam::Vec3;
use radiosity::color::Rgb;
use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare::{self, Prepared};
use radiosity::scene::Units;
use radiosity::session::{Session, SessionOptions};
use radiosity::solver::final_gather::FinalGather;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn office() -> (RunConfig, Prepared) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut config = RunConfig::new(SceneSource::File(root.join("scenes/office.sc")));
    config.photometry.units = Some(Units::M);
    config.photometry.ies = vec![("luminaire".into(), root.join("scenes/luminaires/panel.ies"))];
    let prepared = prepare::prepare(&config).expect("the office prepares");
    (config, prepared)
}

fn solve(config: &RunConfig, prepared: &Prepared) -> Vec<Rgb> {
    let mut session =
        Session::from_prepared(prepared, SessionOptions::for_run(config, prepared, false));
    session.run_to_end(&AtomicBool::new(false)).expect("solves");
    session.radiosity().to_vec()
}

/// The floor grid of the accuracy study (`docs/accuracy.md`), all 320
/// cell centres of a 0.25 m grid (points inside furniture included).
fn floor_points() -> Vec<(Vec3, Vec3)> {
    (0..16)
        .flat_map(|j| (0..20).map(move |i| (i, j)))
        .map(|(i, j)| {
            let p = Vec3::new(0.125 + 0.25 * i as f32, 0.0, 0.125 + 0.25 * j as f32);
            (p, Vec3::Y)
        })
        .collect()
}

fn bench_gather(c: &mut Criterion) {
    let (config, prepared) = office();
    let radiosity = solve(&config, &prepared);
    let points = floor_points();
    let mut group = c.benchmark_group("final_gather");
    group.sample_size(10);
    for near_field in [true, false] {
        let label = if near_field {
            "office 320 floor points"
        } else {
            "office 320 floor points, no near field"
        };
        let gather = || {
            let g = FinalGather::new(
                &prepared.scene,
                &prepared.mesh,
                prepared.visibility(),
                &radiosity,
                near_field,
            );
            g.irradiance_at(&points)
        };
        let t = Instant::now();
        gather();
        eprintln!(
            "{label}: {:.0} points/s",
            points.len() as f64 / t.elapsed().as_secs_f64()
        );
        group.bench_function(label, |b| b.iter(gather));
    }
    group.bench_function("office solve", |b| b.iter(|| solve(&config, &prepared)));
    group.finish();
}

criterion_group!(benches, bench_gather);
criterion_main!(benches);
