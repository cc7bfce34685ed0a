//! Steps delivered in parts ([`SolverOptions::part_budget`]) against the
//! same steps in one piece: the finished steps must be bit-identical,
//! whatever the parts, in every kind of step (a lamp alone, clusters and
//! weak polygons through strata, negative light, large receivers cut into
//! pieces in both passes of the hierarchical gather).

use super::same_bits;
use super::*;
use crate::mesh::{self, MeshOptions};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// The one-table hall at a lenmax that gives its floor more vertices than
/// one chunk holds, so the floor is cut into pieces.
fn hall() -> (Scene, Mesh) {
    let s = crate::scene::parse_str(&crate::testutil::hall::hall_sc(1), "hall.sc").unwrap();
    let m = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.075,
            inset: mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let largest = m.polygons.iter().map(|p| p.vertex_count()).max().unwrap();
    let per_chunk = crate::solver::tuning::CHUNK_WORK / u64::from(DEFAULT_SHOOTER_SAMPLES);
    assert!(u64::from(largest) > per_chunk, "{largest} vertices");
    (s, m)
}

/// The default solver with a part after every chunk.
fn chunk_by_chunk() -> SolverOptions {
    SolverOptions {
        part_budget: Some(Duration::ZERO),
        ..Default::default()
    }
}

/// Solves `steps` whole steps; returns the solver's radiosity, unshot
/// radiosity, rays and the parts it reported.
fn run(s: &Scene, m: &Mesh, options: SolverOptions, steps: u64) -> (Vec<Rgb>, Vec<Rgb>, u64, u64) {
    let vis = Visibility::new(s);
    let mut solver = Progressive::new(s, m, &vis, options);
    let mut parts = 0;
    while solver.steps() < steps {
        let report = solver.step().expect("light left to shoot");
        parts += 1;
        assert_eq!(report.complete, !solver.in_step());
        if !report.complete {
            assert!(
                solver.stop_reason().is_none(),
                "a step under way stops nothing"
            );
            assert_eq!(report.step, solver.steps() + 1);
        }
    }
    let unshot = solver.unshot().to_vec();
    (solver.radiosity().to_vec(), unshot, solver.rays(), parts)
}

#[test]
fn a_step_in_parts_is_bit_identical_to_one_in_a_piece() {
    let (s, m) = hall();
    for base in [
        SolverOptions::default(),
        SolverOptions {
            approximations: Approximations::DEFAULT.with(Heuristic::Clusters, false),
            unshot: UnshotScheme::Polygon,
            ..Default::default()
        },
    ] {
        let whole = run(&s, &m, base, 24);
        // A zero budget ends a part after every chunk.
        let cut = SolverOptions {
            part_budget: Some(Duration::ZERO),
            ..base
        };
        let parted = run(&s, &m, cut, 24);
        assert_eq!(whole.3, 24, "without a budget every report ends a step");
        assert!(parted.3 > 3 * 24, "{} parts", parted.3);
        assert!(same_bits(&whole.0, &parted.0), "radiosity");
        assert!(same_bits(&whole.1, &parted.1), "unshot radiosity");
        assert_eq!(whole.2, parted.2, "rays");
    }
}

/// On `s` and `m` in parts: a part cancelled after some receivers were
/// applied leaves the parts before it, and going on to `steps` finishes
/// as the steps in one piece do.
fn cancelled_part_keeps_the_parts_before_it(s: &Scene, m: &Mesh, steps: u64) {
    let vis = Visibility::new(s);
    let mut solver = Progressive::new(s, m, &vis, chunk_by_chunk());
    let first = solver.step().unwrap();
    assert!(!first.complete && first.part == 1);
    // On until some receivers are applied (the first parts may be pieces
    // of a large polygon, which is applied once whole).
    let mut last = first;
    while last.receivers == 0 {
        last = solver.step().unwrap();
    }
    assert!(!last.complete && last.part > 1 && last.step == 1);
    let before = (solver.radiosity().to_vec(), solver.unshot().to_vec());
    assert!(solver.step_cancellable(&AtomicBool::new(true)).is_none());
    assert!(solver.in_step());
    assert!(same_bits(&before.0, solver.radiosity()));
    assert!(same_bits(&before.1, solver.unshot()));
    while solver.steps() < steps {
        solver.step().unwrap();
    }
    let whole = run(s, m, SolverOptions::default(), steps);
    assert!(same_bits(&whole.0, solver.radiosity()));
    assert!(same_bits(&whole.1, solver.unshot()));
}

/// A cancelled part leaves the parts before it; going on finishes the
/// step as if nothing had happened.
#[test]
fn a_cancelled_part_leaves_the_parts_before_it() {
    let (s, m) = hall();
    cancelled_part_keeps_the_parts_before_it(&s, &m, 3);
}

/// A step cancelled before any of its receivers were applied is forgotten,
/// as without parts.
#[test]
fn a_step_cancelled_before_its_first_part_changes_nothing() {
    let (s, m) = hall();
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &m, &vis, chunk_by_chunk());
    assert!(solver.step_cancellable(&AtomicBool::new(true)).is_none());
    assert!(!solver.in_step());
    assert_eq!((solver.steps(), solver.rays()), (0, 0));
}

/// A floor of 3,721 vertices under a skylight in a black room, under a
/// sky: its sky step (gathered at once) spans several chunks of
/// [`crate::solver::tuning::SKY_CHUNK_VERTICES`].
fn room_under_a_sky() -> (Scene, Mesh) {
    use crate::testutil::{grey, polygon, scene};
    let w = 6.0f32;
    let floor = polygon(0, &[[0., 0., 0.], [0., 0., w], [w, 0., w], [w, 0., 0.]]);
    // A ceiling with a 2 × 2 hole in the middle, facing down.
    let ceiling = |x0: f32, x1: f32, z0: f32, z1: f32| {
        polygon(1, &[[x0, 2., z0], [x1, 2., z0], [x1, 2., z1], [x0, 2., z1]])
    };
    let mut s = scene(
        vec![
            floor,
            ceiling(0., w, 0., 2.),
            ceiling(0., w, 4., w),
            ceiling(0., 2., 2., 4.),
            ceiling(4., w, 2., 4.),
        ],
        vec![grey("floor", 0.0, 0.5), grey("ceiling", 0.0, 0.3)],
    );
    s.add_sky(Rgb::splat(1.0)).unwrap();
    let m = crate::testutil::regular_mesh(&s, 0.1);
    let floor_vertices = m.polygons[0].vertex_count() as usize;
    assert!(floor_vertices > 3 * crate::solver::tuning::SKY_CHUNK_VERTICES);
    (s, m)
}

#[test]
fn a_sky_step_in_parts_is_bit_identical_to_one_in_a_piece() {
    let (s, m) = room_under_a_sky();
    let whole = run(&s, &m, SolverOptions::default(), 2);
    let parted = run(&s, &m, chunk_by_chunk(), 2);
    assert_eq!(whole.3, 2);
    assert!(parted.3 > 4, "{} parts", parted.3);
    assert!(same_bits(&whole.0, &parted.0), "radiosity");
    assert!(same_bits(&whole.1, &parted.1), "unshot radiosity");
    assert_eq!(whole.2, parted.2, "rays");
}

#[test]
fn a_cancelled_sky_step_keeps_its_parts_or_nothing() {
    let (s, m) = room_under_a_sky();
    // In parts: a cancel keeps the parts delivered.
    cancelled_part_keeps_the_parts_before_it(&s, &m, 1);
    // In one piece: a cancel changes nothing.
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &m, &vis, SolverOptions::default());
    let fresh = solver.radiosity().to_vec();
    assert!(solver.step_cancellable(&AtomicBool::new(true)).is_none());
    assert!(!solver.in_step());
    assert_eq!((solver.steps(), solver.rays()), (0, 0));
    assert!(same_bits(&fresh, solver.radiosity()));
}
