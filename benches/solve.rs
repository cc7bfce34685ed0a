//! Solve benchmarks: the bundled `rtable`, `cornell` and `table_chair`
//! scenes at their README settings (default lenmax, 64 shooter samples,
//! 0.1 % threshold, settling), from mesh to converged solution, with
//! clusters (the default), with clusters stopping at the threshold alone
//! (`--settle 0`), and without clusters (`--no-clustering`). Rays per
//! second are printed once per run; criterion reports the time per solve.

use criterion::{criterion_group, criterion_main, Criterion};
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{self, Scene};
use radiosity::solver::tuning::DEFAULT_SETTLE;
use radiosity::solver::{Approximations, Heuristic, Progressive, SolverOptions};
use radiosity::visibility::Visibility;
use std::path::Path;
use std::time::Instant;

fn load(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    scene::load(&path).expect("bundled scene loads")
}

/// One full solve; returns (steps, rays).
fn solve(scene: &Scene, clustering: bool, settle: f64) -> (u64, u64) {
    let mesh = mesh::build(scene, &MeshOptions::for_scene(scene)).expect("mesh");
    let visibility = Visibility::new(scene);
    let options = SolverOptions {
        approximations: Approximations::DEFAULT.with(Heuristic::Clusters, clustering),
        settle,
        ..SolverOptions::default()
    };
    let mut solver = Progressive::new(scene, &mesh, &visibility, options);
    while !solver.is_done() && solver.step().is_some() {}
    (solver.steps(), solver.rays())
}

fn bench_solve(c: &mut Criterion) {
    let mut group = c.benchmark_group("solve");
    group.sample_size(10);
    for name in ["rtable.sc", "cornell.sc", "table_chair.sc"] {
        let scene = load(name);
        let variants = [
            (true, DEFAULT_SETTLE, name.to_string()),
            (true, 0.0, format!("{name} --settle 0")),
            (false, DEFAULT_SETTLE, format!("{name} --no-clustering")),
        ];
        for (clustering, settle, label) in variants {
            let t = Instant::now();
            let (steps, rays) = solve(&scene, clustering, settle);
            let secs = t.elapsed().as_secs_f64();
            eprintln!(
                "{label}: {steps} steps, {:.1} M rays, {:.2} s, {:.2} M rays/s",
                rays as f64 / 1e6,
                secs,
                rays as f64 / secs / 1e6
            );
            group.bench_function(&label, |b| b.iter(|| solve(&scene, clustering, settle)));
        }
    }
    group.finish();
}

criterion_group!(benches, bench_solve);
criterion_main!(benches);
