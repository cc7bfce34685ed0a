//! Redraw speed: one picture of the converged `rtable` solution at 640×480
//! (z-buffer Gouraud rasterization plus tone mapping), what the window does
//! every time the camera moves. Frames per second = 1 / time.

use criterion::{criterion_group, criterion_main, Criterion};
use radiosity::mesh::{self, MeshOptions};
use radiosity::render::{auto_exposure, to_srgb8, Rasterizer, View};
use radiosity::scene;
use radiosity::solver::{Progressive, SolverOptions};
use radiosity::visibility::Visibility;
use std::path::Path;

fn bench_redraw(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/rtable.sc");
    let scene = scene::load(&path).expect("bundled scene loads");
    let mesh = mesh::build(&scene, &MeshOptions::for_scene(&scene)).expect("mesh");
    let visibility = Visibility::new(&scene);
    let mut solver = Progressive::new(&scene, &mesh, &visibility, SolverOptions::default());
    while !solver.is_done() && solver.step().is_some() {}
    let view = View::with_size(&scene.camera, 640, 480).expect("view");
    let mut rasterizer = Rasterizer::new();
    c.bench_function("redraw rtable 640x480", |b| {
        b.iter(|| {
            let frame = rasterizer
                .render(&mesh, solver.radiosity(), &view)
                .expect("render");
            to_srgb8(frame, auto_exposure(frame))
        })
    });
}

criterion_group!(benches, bench_redraw);
criterion_main!(benches);
