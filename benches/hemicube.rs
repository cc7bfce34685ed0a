//! Hemicube benchmarks: one hemicube's form factors (five faces drawn by
//! the item-buffer z-buffer and summed) from the centre of `rtable`'s
//! lamp, on the default mesh, at 64, 128 (the default) and 256 pixels
//! across the top face. A hemicube step of the solver renders one such
//! hemicube per shooter cell (64 by default).

use criterion::{criterion_group, criterion_main, Criterion};
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene;
use radiosity::solver::hemicube::{frame, DeltaFormFactors, Hemicube, HemicubeRes, Role};
use std::path::Path;

fn bench_hemicube(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/rtable.sc");
    let scene = scene::load(&path).expect("bundled scene loads");
    let mesh = mesh::build(&scene, &MeshOptions::for_scene(&scene)).expect("mesh");
    // The brightest emitter shoots first.
    let lamp = (0..scene.polygons.len())
        .max_by(|&a, &b| {
            let e = |p: usize| {
                scene.materials[scene.polygons[p].material.index()]
                    .emission()
                    .mean()
                    * scene.polygons[p].area
            };
            e(a).total_cmp(&e(b))
        })
        .expect("a polygon");
    let corners: Vec<_> = scene.polygons.iter().map(|p| p.vertices.clone()).collect();
    let mut roles = vec![Role::Receiver; scene.polygons.len()];
    roles[lamp] = Role::Skip;
    let eye = scene.polygons[lamp]
        .vertices
        .iter()
        .copied()
        .sum::<glam::Vec3>()
        / scene.polygons[lamp].vertices.len() as f32;
    let f = frame(scene.polygons[lamp].normal, 1);
    let mut group = c.benchmark_group("hemicube");
    for n in [64, 128, 256] {
        let deltas = DeltaFormFactors::new(HemicubeRes::new(n).expect("valid"));
        let mut cube = Hemicube::new();
        let mut out = Vec::new();
        group.bench_function(format!("rtable lamp, N = {n}"), |b| {
            b.iter(|| {
                cube.form_factors(
                    &deltas, &mesh, &corners, &roles, eye, f, 1e-6, None, &mut out,
                );
                out.len()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_hemicube);
criterion_main!(benches);
