//! The solver's unit tests, one file a topic, and the helpers they share
//! (a solve to convergence, thread pools, bit-for-bit comparison).
//!
//! The closed-form checks every method must pass (unit squares, the
//! uniform enclosure, energy balance, a shadow, thread counts) run over
//! every method and unshot scheme in the conformance suite
//! (`tests/conformance.rs`); these test what is progressive shooting's
//! own. The hemicube's tests sit beside it
//! ([`super::methods::hemicube`]).

use super::*;
use crate::mesh::{self, MeshOptions};
use crate::testutil::{
    closed_box, glowing_box, grey, mean_radiosity, polygon, scene, shadowed_box, tiled, tiled_box,
};

mod clusters;
mod crowded;
mod daylight_sky;
mod determinism;
mod emitter_order;
mod energy;
mod far_shooters;
mod form_factors;
mod meshes;
mod overshoot;
mod parts;
mod resting;
mod settle;
mod sky;
mod tail;
mod visibility;

/// Exact form factor between two coaxial parallel unit squares one unit
/// apart (Howell's catalogue, C-11).
const F_PARALLEL_UNIT_SQUARES: f64 = 0.19982;

struct Solved {
    mesh: Mesh,
    radiosity: Vec<Rgb>,
    steps: u64,
    initial_power: f64,
    unshot_power: f64,
}

fn solve(s: &Scene, lenmax: f32, inset: f32, options: SolverOptions) -> Solved {
    solve_on(
        s,
        mesh::build(s, &MeshOptions { lenmax, inset }).unwrap(),
        options,
    )
}

fn solve_on(s: &Scene, mesh: Mesh, options: SolverOptions) -> Solved {
    let vis = Visibility::new(s);
    let mut solver = Progressive::new(s, &mesh, &vis, options);
    while !solver.is_done() {
        if solver.step().is_none() {
            break;
        }
    }
    solver.validate().unwrap();
    Solved {
        radiosity: solver.radiosity().to_vec(),
        steps: solver.steps(),
        initial_power: solver.initial_unshot_power(),
        unshot_power: solver.net_unshot_power(),
        mesh,
    }
}

/// The regular mesh of `s` refined twice across the plane `x = cut`, as
/// adaptive subdivision would refine it across a shadow edge there: split
/// elements, fans around hanging vertices and unsplit elements side by
/// side on every polygon the plane crosses.
fn refined_across(s: &Scene, lenmax: f32, cut: f32) -> Mesh {
    use crate::mesh::refine::{RefineOptions, Refiner};
    let mut m = mesh::build(
        s,
        &MeshOptions {
            lenmax,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let mut refiner = Refiner::new(&m);
    let options = RefineOptions::default();
    loop {
        let field: Vec<f64> = m
            .positions
            .iter()
            .map(|p| if p.x < cut { 0.2 } else { 1.0 })
            .collect();
        match refiner.refine(s, &field, &options) {
            Some((next, _)) => m = next,
            None => break,
        }
    }
    assert!(m.polygons.iter().any(|p| p.levels == 2));
    m
}

/// Form factor from polygon 1 to emitter 0 measured through one shooting
/// step: with `e = 1` and `rho = 0.5` every receiver vertex gets
/// `0.5 · F(vertex → emitter)`; the area mean over the receiver is
/// `0.5 · F_10`.
fn measured_form_factor(
    emitter: [[f32; 3]; 4],
    receiver: [[f32; 3]; 4],
    options: SolverOptions,
) -> f64 {
    let s = scene(
        vec![polygon(0, &emitter), polygon(1, &receiver)],
        vec![grey("lamp", 1.0, 0.0), grey("wall", 0.0, 0.5)],
    );
    let solved = solve(
        &s,
        0.02,
        crate::mesh::DEFAULT_INSET,
        SolverOptions {
            max_steps: Some(1),
            ..options
        },
    );
    mean_radiosity(&solved.mesh, &solved.radiosity, 1).r / 0.5
}

const BOTTOM: [[f32; 3]; 4] = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
const TOP: [[f32; 3]; 4] = [[0., 0., 1.], [0., 1., 1.], [1., 1., 1.], [1., 0., 1.]];

/// `|absorbed + unshot − emitted| / emitted` of a solve of a closed scene
/// whose every polygon reflects.
fn energy_error(s: &Scene, solved: &Solved) -> f64 {
    let absorbed = crate::testutil::absorbed_power(s, &solved.mesh, &solved.radiosity);
    (absorbed + solved.unshot_power - solved.initial_power).abs() / solved.initial_power
}

/// A closed box `[0, size]³` of materials 1 and 2 with a square lamp
/// (material 0) a fifth of its width just below the middle of the ceiling.
fn room_with_lamp(size: f32) -> Vec<crate::scene::Polygon> {
    let mut polygons = closed_box(size, [1, 2, 1, 1, 2, 1]);
    let (lo, hi, y) = (0.4 * size, 0.6 * size, size - 0.0025 * size);
    polygons.push(polygon(
        0,
        &[[lo, y, lo], [hi, y, lo], [hi, y, hi], [lo, y, hi]],
    ));
    polygons
}

/// A lamp (material 0) and two grey reflectors (1 and 2).
fn lamp_materials() -> Vec<crate::scene::Material> {
    vec![
        grey("lamp", 10.0, 0.0),
        grey("a", 0.0, 0.7),
        grey("b", 0.0, 0.4),
    ]
}

/// Runs `f` on a pool of `threads` threads.
pub(super) fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// True when the two radiosity arrays are equal bit for bit.
pub(super) fn same_bits(a: &[Rgb], b: &[Rgb]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.to_array().map(f64::to_bits) == y.to_array().map(f64::to_bits))
}
