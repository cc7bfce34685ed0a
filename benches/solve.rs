//! Solve benchmarks: the bundled `rtable`, `cornell` and `table_chair`
//! scenes at their README settings (default lenmax, 64 shooter samples,
//! 0.1 % threshold, settling), from mesh to converged solution, with
//! clusters (the default), with clusters stopping at the threshold alone
//! (`--settle 0`), without clusters (`--no-clustering`), and with the
//! particle tail carrying the last 10 % (`--tail 0.1`); and `rtable`
//! under a uniform sky (`--sky 1`), the sky gathered at once (the
//! default) and shot facet by facet (`--without sky-at-once`). Rays per
//! second are printed once per run; criterion reports the time per solve.

use criterion::{criterion_group, criterion_main, Criterion};
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{self, Scene};
use radiosity::solver::tuning::DEFAULT_SETTLE;
use radiosity::solver::{Approximations, Heuristic, Progressive, SolverOptions, TailOption};
use radiosity::visibility::Visibility;
use std::path::Path;
use std::time::Instant;

fn load(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    scene::load(&path).expect("bundled scene loads")
}

/// One full solve with these approximations; returns (steps, rays).
fn solve_with(
    scene: &Scene,
    approximations: Approximations,
    settle: f64,
    tail: TailOption,
) -> (u64, u64) {
    let mesh = mesh::build(scene, &MeshOptions::for_scene(scene)).expect("mesh");
    let visibility = Visibility::new(scene);
    let options = SolverOptions {
        approximations,
        settle,
        tail,
        ..SolverOptions::default()
    };
    let mut solver = Progressive::new(scene, &mesh, &visibility, options);
    while !solver.is_done() && solver.step().is_some() {}
    (solver.steps(), solver.rays())
}

/// Prints one solve's steps, rays and rate, then benches it as `label`.
fn bench_one(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    label: &str,
    scene: &Scene,
    approximations: Approximations,
    settle: f64,
    tail: TailOption,
) {
    let t = Instant::now();
    let (steps, rays) = solve_with(scene, approximations, settle, tail);
    let secs = t.elapsed().as_secs_f64();
    eprintln!(
        "{label}: {steps} steps, {:.1} M rays, {:.2} s, {:.2} M rays/s",
        rays as f64 / 1e6,
        secs,
        rays as f64 / secs / 1e6
    );
    group.bench_function(label, |b| {
        b.iter(|| solve_with(scene, approximations, settle, tail))
    });
}

fn bench_solve(c: &mut Criterion) {
    let mut group = c.benchmark_group("solve");
    group.sample_size(10);
    for name in ["rtable.sc", "cornell.sc", "table_chair.sc"] {
        let scene = load(name);
        let auto = TailOption::Auto;
        let variants = [
            (true, DEFAULT_SETTLE, auto, name.to_string()),
            (true, 0.0, auto, format!("{name} --settle 0")),
            (
                false,
                DEFAULT_SETTLE,
                auto,
                format!("{name} --no-clustering"),
            ),
            (
                true,
                DEFAULT_SETTLE,
                TailOption::From(0.1),
                format!("{name} --tail 0.1"),
            ),
        ];
        for (clustering, settle, tail, label) in variants {
            let approximations = Approximations::DEFAULT.with(Heuristic::Clusters, clustering);
            bench_one(&mut group, &label, &scene, approximations, settle, tail);
        }
    }
    group.finish();
}

fn bench_sky(c: &mut Criterion) {
    let mut group = c.benchmark_group("sky");
    group.sample_size(10);
    let mut scene = load("rtable.sc");
    scene
        .add_sky(radiosity::color::Rgb::splat(1.0))
        .expect("a sky fits");
    for (at_once, label) in [
        (true, "rtable.sc --sky 1"),
        (false, "rtable.sc --sky 1 --without sky-at-once"),
    ] {
        let approximations = Approximations::DEFAULT.with(Heuristic::SkyAtOnce, at_once);
        bench_one(
            &mut group,
            label,
            &scene,
            approximations,
            DEFAULT_SETTLE,
            TailOption::Auto,
        );
    }
    group.finish();
}

criterion_group!(benches, bench_solve, bench_sky);
criterion_main!(benches);
