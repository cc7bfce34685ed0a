//! Emitters first ([`Progressive::choose_pending_emitter`]): every light
//! whose power must be shot before the solve can stop shoots before any
//! reflector, even when a reflector holds more unshot power by then, and
//! a light too weak to matter is left to the power order.

use super::*;
use crate::testutil::{closed_box, grey, polygon, regular_mesh, scene};

/// The unit box of grey walls (reflectance 0.8) with four square lamps
/// 0.2 across just under its ceiling, facing down, of emission
/// `emissions` (materials 1 to 4, polygons 6 to 9 in order).
fn lamps_room(emissions: [f64; 4]) -> Scene {
    let mut polygons = closed_box(1.0, [0; 6]);
    let corners = [(0.15, 0.15), (0.65, 0.15), (0.15, 0.65), (0.65, 0.65)];
    for (k, &(x, z)) in corners.iter().enumerate() {
        polygons.push(polygon(
            k as u32 + 1,
            &[
                [x, 0.999, z],
                [x + 0.2, 0.999, z],
                [x + 0.2, 0.999, z + 0.2],
                [x, 0.999, z + 0.2],
            ],
        ));
    }
    let mut materials = vec![grey("wall", 0.0, 0.8)];
    materials.extend(
        emissions
            .iter()
            .enumerate()
            .map(|(k, &e)| grey(&format!("lamp{k}"), e, 0.0)),
    );
    scene(polygons, materials)
}

/// A solver of `s` on a mesh of 0.1, clustered or not.
fn solver<'a>(
    s: &'a Scene,
    mesh: &'a Mesh,
    vis: &'a Visibility,
    clustering: bool,
) -> Progressive<'a> {
    let options = SolverOptions {
        threshold: 1e-3,
        approximations: Approximations::DEFAULT.with(Heuristic::Clusters, clustering),
        ..Default::default()
    };
    Progressive::new(s, mesh, vis, options)
}

#[test]
fn every_lamp_shoots_before_a_brighter_reflector() {
    // Once the bright lamp has shot, the floor holds more unshot power
    // than each dim lamp: the power order alone would shoot it first.
    let s = lamps_room([20.0, 1.0, 1.0, 1.0]);
    let mesh = regular_mesh(&s, 0.1);
    let vis = Visibility::new(&s);
    for clustering in [true, false] {
        let mut solver = solver(&s, &mesh, &vis, clustering);
        let mut shooters = Vec::new();
        let mut reflector_ahead = false;
        for _ in 0..4 {
            let next = solver.next_shooter().expect("a shooter");
            // Whether some wall holds more than this lamp.
            let lamp = solver.polygon_power(next.index(), Shot::PLAIN);
            reflector_ahead |= (0..6).any(|w| solver.polygon_power(w, Shot::PLAIN) > lamp);
            let report = solver.step().expect("a step");
            shooters.push(report.shooter.index());
        }
        assert_eq!(shooters[0], 6, "the bright lamp first");
        let mut dim = shooters[1..].to_vec();
        dim.sort_unstable();
        assert_eq!(
            dim,
            vec![7, 8, 9],
            "then the dim ones, clustering {clustering}"
        );
        assert!(
            reflector_ahead,
            "the scene must put a wall ahead of a dim lamp by power"
        );
        // Then the walls, in the power order.
        let next = solver.next_shooter().expect("a shooter");
        assert!(next.index() < 6, "a wall next, not {next:?}");
    }
}

#[test]
fn a_lamp_too_weak_to_matter_waits_its_turn() {
    // A lamp holding less than the threshold's share of the initial power
    // need never shoot; it must not hold up the walls.
    let s = lamps_room([20.0, 1e-5, 1e-5, 1e-5]);
    let mesh = regular_mesh(&s, 0.1);
    let vis = Visibility::new(&s);
    let mut solver = solver(&s, &mesh, &vis, true);
    assert_eq!(solver.step().expect("a step").shooter.index(), 6);
    let second = solver.step().expect("a step").shooter.index();
    assert!(second < 6, "a wall second, not polygon {second}");
}

#[test]
fn a_lamp_that_reflects_is_not_pending_once_it_has_shot() {
    // A lamp that also reflects holds light again after its shot, far
    // less than it emits: it then waits for the power order like any
    // reflector.
    let mut s = lamps_room([5.0, 5.0, 5.0, 5.0]);
    for m in &mut s.materials[1..] {
        m.k_diffrefl = 0.5;
    }
    let mesh = regular_mesh(&s, 0.1);
    let vis = Visibility::new(&s);
    let mut solver = solver(&s, &mesh, &vis, true);
    let mut first = Vec::new();
    for _ in 0..4 {
        first.push(solver.step().expect("a step").shooter.index());
    }
    first.sort_unstable();
    assert_eq!(first, vec![6, 7, 8, 9]);
    let pending = solver.choose_pending_emitter();
    assert!(pending.is_none(), "no lamp still pending: {pending:?}");
}
