//! Crowded cells ([`receivers::crowded_cells`]): a receiving grid's
//! cell that another polygon reaches close in front of is never
//! interpolated, as the shadow or pocket that polygon makes is smaller
//! than the cell and its five exact points may all miss it.

use super::*;
use crate::testutil::{closed_box, grey, polygon, regular_mesh, scene};

/// The unit box of grey walls (reflectance 0.8) with a square lamp 0.3
/// across hung 0.01 under its ceiling, facing down, and its back
/// (reflectance 0.8, polygon 7) facing the ceiling: the ceiling above
/// the lamp and the back form a pocket lit only through the gap at the
/// lamp's rim, which falls across the ceiling's coarse cells.
fn hung_lamp() -> Scene {
    let mut polygons = closed_box(1.0, [0; 6]);
    let (lo, hi, y) = (0.33, 0.63, 0.99);
    polygons.push(polygon(
        1,
        &[[lo, y, lo], [hi, y, lo], [hi, y, hi], [lo, y, hi]],
    ));
    polygons.push(polygon(
        0,
        &[[lo, y, lo], [lo, y, hi], [hi, y, hi], [hi, y, lo]],
    ));
    scene(
        polygons,
        vec![grey("wall", 0.0, 0.8), grey("lamp", 10.0, 0.0)],
    )
}

/// The lamp back's index in [`hung_lamp`].
const BACK: usize = 7;

/// The lamp back's mean radiosity (channel mean) over its vertices,
/// converged to 10⁻⁶ with receiver interpolation on or off.
fn back_radiosity(s: &Scene, mesh: &Mesh, interpolate: bool) -> f64 {
    let vis = Visibility::new(s);
    let options = SolverOptions {
        threshold: 1e-6,
        approximations: if interpolate {
            Approximations::DEFAULT
        } else {
            Approximations::DEFAULT.without(&Heuristic::RECEIVERS)
        },
        ..Default::default()
    };
    let mut solver = Progressive::new(s, mesh, &vis, options);
    while !solver.is_done() {
        solver.step().expect("a step");
        assert!(solver.steps() < 5_000, "the solve does not converge");
    }
    let range = mesh.polygons[BACK].vertices.clone();
    let values = &solver.radiosity()[range.start as usize..range.end as usize];
    values.iter().map(|b| b.mean()).sum::<f64>() / values.len() as f64
}

#[test]
fn a_pocket_under_a_ceiling_is_not_lit_through_its_cells() {
    let s = hung_lamp();
    let mesh = regular_mesh(&s, 0.05);
    let interpolated = back_radiosity(&s, &mesh, true);
    let exact = back_radiosity(&s, &mesh, false);
    let error = (interpolated - exact).abs() / exact;
    // Measured: 0.011 % with crowded cells exact, 0.44 % with them
    // interpolated like any other.
    assert!(
        error < 0.001,
        "lamp back {interpolated} against {exact} with every receiver exact ({:.2} %)",
        error * 100.0
    );
}

#[test]
fn the_cells_over_a_hung_lamp_are_crowded_and_the_others_not() {
    let s = hung_lamp();
    // Cells of 0.1, so that most are clear of the lamp and the walls.
    let mesh = regular_mesh(&s, 0.025);
    let vis = Visibility::new(&s);
    let grids: Vec<Option<CoarseGrid>> = mesh
        .polygons
        .iter()
        .map(|pm| CoarseGrid::detect(&mesh, pm))
        .collect();
    let crowded = receivers::crowded_cells(&mesh, &grids, |j, corners, normal, depth| {
        vis.crowds(PolygonId(j as u32), &corners, normal, depth)
    });
    // The ceiling (+y, wall 3): its cells over the lamp are crowded,
    // those far from it and from the walls are not.
    let ceiling = grids[3].expect("the ceiling is a grid");
    let (mut over, mut clear) = (0, 0);
    for cell in ceiling.cells() {
        let corners = cell.map(|c| mesh.positions[c as usize]);
        let (lo, hi) = corners
            .iter()
            .fold((corners[0], corners[0]), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        let over_lamp = lo.x < 0.63 && hi.x > 0.33 && lo.z < 0.63 && hi.z > 0.33;
        let by_a_wall = lo.x < 0.01 || hi.x > 0.99 || lo.z < 0.01 || hi.z > 0.99;
        let is = crowded[cell[0] as usize];
        if over_lamp {
            assert!(is, "a cell over the lamp, {lo} to {hi}, is not crowded");
            over += 1;
        } else if !by_a_wall {
            assert!(!is, "a clear cell, {lo} to {hi}, is crowded");
            clear += 1;
        }
    }
    assert!(
        over >= 4 && clear >= 1,
        "{over} cells over the lamp, {clear} clear"
    );
}
