//! Settling ([`SolverOptions::settle`]): a pocket (the narrow gap between
//! two slabs in a lit room) is a small share of the scene's power, so
//! the threshold alone stops before the pocket has traded its light back
//! and forth, and leaves it dark. Settling must bring it to the converged
//! solution of the same mesh, and stay deterministic: a solve saved while
//! it settles resumes to the same bits, and one thread or two give the
//! same bits.

use super::*;
use super::{on_threads, same_bits};
use crate::testutil::{closed_box, cuboid, grey, mean_radiosity, polygon, regular_mesh, scene};

/// The unit box of grey walls (reflectance 0.8) lit by a square lamp 0.2
/// across under its ceiling, with two slabs 0.4 across and 0.04 thick
/// (reflectance 0.8) stacked in its middle `gap` apart: the lower one's
/// top and the upper one's underside form a pocket, lit only through the
/// gap at its edges. Both are small polygons that shoot only when they
/// hold the most unshot power, as the back of a lamp hung under a
/// ceiling.
fn pocket_room(gap: f32) -> Scene {
    let mut polygons = closed_box(1.0, [0; 6]);
    let slabs = [
        cuboid([0.3, 0.3, 0.3], [0.7, 0.34, 0.7], false),
        cuboid([0.3, 0.34 + gap, 0.3], [0.7, 0.38 + gap, 0.7], false),
    ];
    polygons.extend(slabs.into_iter().flatten().map(|mut p| {
        p.material = crate::scene::MaterialId(2);
        p
    }));
    // Facing down, just under the ceiling (`y = 1`).
    polygons.push(polygon(
        1,
        &[
            [0.4, 0.999, 0.4],
            [0.6, 0.999, 0.4],
            [0.6, 0.999, 0.6],
            [0.4, 0.999, 0.6],
        ],
    ));
    scene(
        polygons,
        vec![
            grey("wall", 0.0, 0.8),
            grey("lamp", 10.0, 0.0),
            grey("slab", 0.0, 0.8),
        ],
    )
}

/// The index of the upper slab's underside in [`pocket_room`]: the `-y`
/// face of the second cuboid after the six walls.
const UNDERSIDE: usize = 12 + 2;

/// The solve of `s` on a mesh of 0.05 to `threshold` with `settle`:
/// the mesh, the radiosity and the steps.
fn solve(s: &Scene, threshold: f64, settle: f64, clustering: bool) -> (Mesh, Vec<Rgb>, u64) {
    let mesh = regular_mesh(s, 0.05);
    let vis = Visibility::new(s);
    let options = SolverOptions {
        threshold,
        settle,
        approximations: Approximations::DEFAULT.with(Heuristic::Clusters, clustering),
        ..Default::default()
    };
    let mut solver = Progressive::new(s, &mesh, &vis, options);
    while !solver.is_done() {
        if solver.step().is_none() {
            break;
        }
        assert!(solver.steps() < 20_000, "the solve does not converge");
    }
    assert_eq!(solver.stop_reason(), Some(StopReason::Converged));
    solver.validate().unwrap();
    let (radiosity, steps) = (solver.radiosity().to_vec(), solver.steps());
    drop(solver);
    (mesh, radiosity, steps)
}

/// Every polygon's mean against the converged solve (threshold 10⁻⁷, no
/// settling), the lamp's left out: the worst relative difference and
/// the underside's.
fn errors(s: &Scene, run: &(Mesh, Vec<Rgb>, u64), converged: &[Rgb]) -> (f64, f64) {
    let (mesh, radiosity, _) = run;
    let error = |p: usize| {
        let exact = mean_radiosity(mesh, converged, p).mean();
        (mean_radiosity(mesh, radiosity, p).mean() - exact).abs() / exact
    };
    let worst = (0..s.polygons.len() - 1).map(error).fold(0.0, f64::max);
    (worst, error(UNDERSIDE))
}

/// With settling (the default) every polygon's mean is within 1.5 % of
/// the converged solve, in both modes (measured 0.74 % clustered, 0.93 %
/// not, the slab's underside both times); with the threshold alone the
/// pocket is more than 3 % too dark (measured 6.6 % and 5.9 %), so
/// settling is what brings it there, for 10 and 8 more steps than 59 and
/// 69.
#[test]
fn settling_converges_a_pocket() {
    let s = pocket_room(0.001);
    for clustering in [true, false] {
        let (_, converged, _) = solve(&s, 1e-7, 0.0, clustering);
        let settled = solve(&s, DEFAULT_THRESHOLD, DEFAULT_SETTLE, clustering);
        let plain = solve(&s, DEFAULT_THRESHOLD, 0.0, clustering);
        let (worst, underside) = errors(&s, &settled, &converged);
        let (worst0, underside0) = errors(&s, &plain, &converged);
        eprintln!(
            "clustering {clustering}: settled {} steps, worst polygon {worst}, \
             underside {underside}; threshold alone {} steps, worst {worst0}, \
             underside {underside0}",
            settled.2, plain.2
        );
        assert!(
            worst < 0.015,
            "clustering {clustering}: worst polygon {worst}"
        );
        assert!(
            underside0 > 0.03,
            "clustering {clustering}: the threshold alone already gives {underside0}"
        );
    }
}

/// A solve saved while it settles ([`Progressive::state`], as a
/// checkpoint does) and restored into a fresh solver ends on the same
/// bits, in the same steps, as the solve left alone: settling reads
/// nothing but the saved state.
#[test]
fn a_solve_saved_while_settling_resumes_to_the_same_bits() {
    let s = pocket_room(0.001);
    let mesh = regular_mesh(&s, 0.05);
    let vis = Visibility::new(&s);
    let options = SolverOptions::default();
    let run_to_end = |solver: &mut Progressive| {
        while !solver.is_done() && solver.step().is_some() {}
    };
    let mut whole = Progressive::new(&s, &mesh, &vis, options);
    run_to_end(&mut whole);

    let mut first = Progressive::new(&s, &mesh, &vis, options);
    while first.unshot_fraction() > options.threshold {
        first.step().expect("light left to shoot");
    }
    // Two steps into settling.
    for _ in 0..2 {
        assert!(!first.is_done(), "the pocket settles in fewer steps");
        first.step().expect("a settling step");
    }
    let mut resumed = Progressive::new(&s, &mesh, &vis, options);
    resumed.restore(first.state()).unwrap();
    run_to_end(&mut resumed);

    assert_eq!(resumed.steps(), whole.steps());
    assert!(same_bits(resumed.radiosity(), whole.radiosity()));
}

/// The settled solve of the pocket on one thread and on two gives the
/// same bits, in both modes.
#[test]
fn settling_gives_the_same_bits_on_one_thread_and_two() {
    let s = pocket_room(0.001);
    for clustering in [true, false] {
        let [one, two] = [1, 2].map(|threads| {
            on_threads(threads, || {
                solve(&s, DEFAULT_THRESHOLD, DEFAULT_SETTLE, clustering).1
            })
        });
        assert!(same_bits(&one, &two), "clustering {clustering}");
    }
}
