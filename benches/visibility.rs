//! Shadow-ray throughput of the visibility queries alone, on `cornell` and
//! on the 1,000-polygon hall: the wide BVH against testing every polygon,
//! on one thread and on all threads. The segments are the solver's own:
//! from shooter samples (cell centres) of random polygons to random
//! element vertices of the mesh, fixed by a seed. And the plane classes
//! the visibility tests skip by, on floors of 2,500 to 40,000 coplanar
//! tiles (issue: compared pair by pair, 20,000 tiles took minutes).
//! And the rays of a sky's step on a real game level,
//! `tests/models/redeclipse/fortitude.obj` (106,000 polygons): from the
//! middle of random polygons out along cosine-weighted directions to
//! beyond the level, most of which cross it whole.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec3;
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{self, PolygonId, Scene};
use radiosity::visibility::Visibility;
use rayon::prelude::*;
use std::path::Path;

#[path = "../examples/support/hall.rs"]
mod hall;

/// Segments per measured batch.
const SEGMENTS: usize = 20_000;

fn segments(scene: &Scene) -> Vec<(Vec3, Vec3, (PolygonId, PolygonId))> {
    let mesh = mesh::build(scene, &MeshOptions::for_scene(scene)).expect("mesh");
    let mut seed = 0x5eed_1234_abcd_ef01u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut out = Vec::with_capacity(SEGMENTS);
    while out.len() < SEGMENTS {
        let l = (next() % mesh.vertex_count() as u64) as usize;
        let m = (next() % mesh.vertex_count() as u64) as usize;
        let (i, j) = (mesh.vertex_polygon[l], mesh.vertex_polygon[m]);
        if i == j {
            continue;
        }
        let (a, b) = (mesh.sample_positions[l], mesh.sample_positions[m]);
        // Only pairs that face each other, as the solver asks.
        let (ni, nj) = (
            mesh.polygons[i.index()].normal,
            mesh.polygons[j.index()].normal,
        );
        if ni.dot(b - a) > 0.0 && nj.dot(a - b) > 0.0 {
            out.push((a, b, (i, j)));
        }
    }
    out
}

fn bench_visibility(c: &mut Criterion) {
    let cornell = scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.sc"))
        .expect("cornell");
    let hall = scene::parse_str(&hall::hall_sc(15), "hall.sc").expect("hall");
    let mut group = c.benchmark_group("shadow rays");
    group.throughput(Throughput::Elements(SEGMENTS as u64));
    group.sample_size(10);
    for (name, scene) in [("cornell", &cornell), ("hall-1000", &hall)] {
        let vis = Visibility::new(scene);
        let segs = segments(scene);
        let blocked = segs
            .iter()
            .filter(|(a, b, e)| vis.occluded(*a, *b, *e))
            .count();
        eprintln!(
            "{name}: {} polygons, {:.1} % of the segments blocked",
            scene.polygons.len(),
            100.0 * blocked as f64 / SEGMENTS as f64
        );
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            group.bench_function(BenchmarkId::new(format!("{name}/bvh"), threads), |bch| {
                bch.iter(|| {
                    pool.install(|| {
                        segs.par_iter()
                            .filter(|(a, b, e)| vis.occluded(*a, *b, *e))
                            .count()
                    })
                })
            });
            group.bench_function(
                BenchmarkId::new(format!("{name}/every-polygon"), threads),
                |bch| {
                    bch.iter(|| {
                        pool.install(|| {
                            segs.par_iter()
                                .filter(|(a, b, e)| vis.occluded_brute_force(*a, *b, *e))
                                .count()
                        })
                    })
                },
            );
        }
    }
    group.finish();
}

/// An OBJ floor of `n` × `n` tiles 0.1 wide, each its own face.
fn floor_tiles_obj(n: usize) -> String {
    let mut text = String::new();
    for k in 0..n * n {
        let (x, z) = ((k % n) as f32 * 0.1, (k / n) as f32 * 0.1);
        for (dx, dz) in [(0.0, 0.0), (0.0, 0.1), (0.1, 0.1), (0.1, 0.0)] {
            text += &format!("v {} 0 {}\n", x + dx, z + dz);
        }
        let v = 4 * k + 1;
        text += &format!("f {} {} {} {}\n", v, v + 1, v + 2, v + 3);
    }
    text
}

fn bench_plane_classes(c: &mut Criterion) {
    let mut group = c.benchmark_group("plane classes");
    group.sample_size(10);
    for n in [50, 100, 200] {
        let no_library = |name: &str| Err(format!("no library {name}"));
        let floor =
            radiosity::scene::import::obj::parse_obj(&floor_tiles_obj(n), "tiles.obj", &no_library)
                .expect("tiles");
        group.throughput(Throughput::Elements((n * n) as u64));
        group.bench_with_input(BenchmarkId::new("coplanar tiles", n * n), &floor, |b, s| {
            b.iter(|| scene::plane_classes(s))
        });
    }
    group.finish();
}

/// Segments from the middle of random polygons of `scene` along
/// cosine-weighted directions about their normals, to twice the scene's
/// extent away, with the polygon as both ends (as the sky's step asks).
fn sky_segments(scene: &Scene) -> Vec<(Vec3, Vec3, (PolygonId, PolygonId))> {
    let mut seed = 0x0dd5_ca1e_5eed_0042u64;
    let mut unit = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    let reach = 2.0 * scene.extent();
    (0..SEGMENTS)
        .map(|_| {
            let j = ((unit() * scene.polygons.len() as f32) as usize).min(scene.polygons.len() - 1);
            let p = &scene.polygons[j];
            let middle = p.vertices.iter().sum::<Vec3>() / p.vertices.len() as f32;
            // Malley: a uniform point of the disc lifted onto the hemisphere.
            let (r, phi) = (unit().sqrt(), std::f32::consts::TAU * unit());
            let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r * r).max(0.0).sqrt());
            let n = p.normal.normalize();
            let (t, b) = n.any_orthonormal_pair();
            let d = t * local.x + b * local.y + n * local.z;
            (
                middle,
                middle + d * reach,
                (PolygonId(j as u32), PolygonId(j as u32)),
            )
        })
        .collect()
}

fn bench_level_rays(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/models/redeclipse/fortitude.obj");
    let level = scene::load(&path).expect("fortitude.obj");
    let vis = Visibility::new(&level);
    let segs = sky_segments(&level);
    let blocked = segs
        .iter()
        .filter(|(a, b, e)| vis.occluded(*a, *b, *e))
        .count();
    eprintln!(
        "fortitude.obj: {} polygons, {:.1} % of the sky rays blocked",
        level.polygons.len(),
        100.0 * blocked as f64 / SEGMENTS as f64
    );
    let mut group = c.benchmark_group("sky rays");
    group.throughput(Throughput::Elements(SEGMENTS as u64));
    group.sample_size(20);
    group.bench_function("fortitude.obj/bvh", |bch| {
        bch.iter(|| {
            segs.iter()
                .filter(|(a, b, e)| vis.occluded(*a, *b, *e))
                .count()
        })
    });
    group.finish();
}

criterion_group!(
    benches,
    bench_visibility,
    bench_plane_classes,
    bench_level_rays
);
criterion_main!(benches);
