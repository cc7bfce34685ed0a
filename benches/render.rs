//! Redraw speed: one picture of a solution (z-buffer Gouraud rasterization
//! plus automatic exposure and tone mapping to 8-bit sRGB), what the window
//! does every time the camera moves. Frames per second = 1 / time.
//!
//! Three cases:
//!
//! - `rtable` converged, 640×480 (the historical case);
//! - `table_chair` converged, 1280×720 (target: 60 frames per second);
//! - `table_chair` meshed finely enough for at least [`BIG_TRIANGLES`]
//!   triangles, at 1280×720 (target: 15 frames per second). Its radiosity
//!   comes from a few shooting steps only ([`BIG_STEPS`]), enough to light
//!   the room plausibly: the rasterizer's cost does not depend on the
//!   values it interpolates, only on the mesh and the view, so a converged
//!   solution would time the same while taking minutes to set up.

use criterion::{criterion_group, criterion_main, Criterion};
use radiosity::color::Rgb;
use radiosity::mesh::{self, Mesh, MeshOptions};
use radiosity::render::{auto_exposure, to_srgb8, Rasterizer, View};
use radiosity::scene::{self, Scene};
use radiosity::solver::{Progressive, SolverOptions};
use radiosity::visibility::Visibility;
use std::path::Path;

/// Fewest triangles of the big mesh.
const BIG_TRIANGLES: usize = 1_000_000;

/// Shooting steps of the big mesh's solution (the brightest emitters shoot
/// first, so a few steps light the whole room).
const BIG_STEPS: u64 = 4;

/// How much finer than the scene's default `lenmax` the big mesh is:
/// triangles grow with its inverse square (6.5² × 26,000 ≈ 1.1 M).
const BIG_REFINEMENT: f32 = 6.5;

fn load(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    scene::load(&path).expect("bundled scene loads")
}

fn triangles(mesh: &Mesh) -> usize {
    mesh.elements.iter().map(|e| e.triangles().count()).sum()
}

/// The solution after at most `max_steps` steps (`None`: converged).
fn solve(scene: &Scene, mesh: &Mesh, max_steps: Option<u64>) -> Vec<Rgb> {
    let visibility = Visibility::new(scene);
    let options = SolverOptions {
        max_steps,
        ..SolverOptions::default()
    };
    let mut solver = Progressive::new(scene, mesh, &visibility, options);
    while !solver.is_done() && solver.step().is_some() {}
    solver.radiosity().to_vec()
}

fn bench_case(
    c: &mut Criterion,
    name: &str,
    scene: &Scene,
    mesh: &Mesh,
    radiosity: &[Rgb],
    size: (u32, u32),
) {
    let view = View::with_size(&scene.camera, size.0, size.1).expect("view");
    let mut rasterizer = Rasterizer::new();
    c.bench_function(name, |b| {
        b.iter(|| {
            let frame = rasterizer.render(mesh, radiosity, &view).expect("render");
            to_srgb8(frame, auto_exposure(frame))
        })
    });
}

fn bench_redraw(c: &mut Criterion) {
    let scene = load("rtable.sc");
    let mesh = mesh::build(&scene, &MeshOptions::for_scene(&scene)).expect("mesh");
    let radiosity = solve(&scene, &mesh, None);
    bench_case(
        c,
        "redraw rtable 640x480",
        &scene,
        &mesh,
        &radiosity,
        (640, 480),
    );

    let scene = load("table_chair.sc");
    let mesh = mesh::build(&scene, &MeshOptions::for_scene(&scene)).expect("mesh");
    let radiosity = solve(&scene, &mesh, None);
    bench_case(
        c,
        "redraw table_chair 1280x720",
        &scene,
        &mesh,
        &radiosity,
        (1280, 720),
    );

    let default = MeshOptions::for_scene(&scene);
    let fine = MeshOptions {
        lenmax: default.lenmax / BIG_REFINEMENT,
        ..default
    };
    let mesh = mesh::build(&scene, &fine).expect("mesh");
    let n = triangles(&mesh);
    assert!(n >= BIG_TRIANGLES, "{n} triangles, want {BIG_TRIANGLES}");
    let radiosity = solve(&scene, &mesh, Some(BIG_STEPS));
    eprintln!("big mesh: {n} triangles, {} vertices", mesh.positions.len());
    bench_case(
        c,
        "redraw table_chair 1M triangles 1280x720",
        &scene,
        &mesh,
        &radiosity,
        (1280, 720),
    );
}

criterion_group!(benches, bench_redraw);
criterion_main!(benches);
