//! The default lenmax within a vertex budget: the finest that fits, the
//! default kept when it fits, the floor of one element per polygon, and
//! the line that says what was chosen.

use super::*;
use crate::mesh::{build, estimate};
use crate::scene::Polygon;
use crate::testutil;

fn scene(polygons: Vec<Polygon>) -> Scene {
    testutil::scene(polygons, vec![testutil::grey("m", 0.0, 0.5)])
}

/// A unit square in the plane `z`: at lenmax `l` it has `(⌊1/l⌋ + 2)²`
/// vertices.
fn unit_square(z: f32) -> Polygon {
    testutil::polygon(0, &[[0., 0., z], [1., 0., z], [1., 1., z], [0., 1., z]])
}

#[test]
fn a_scene_over_the_budget_gets_the_finest_three_digit_lenmax_within_it() {
    let s = scene(vec![unit_square(0.0)]);
    // 100 vertices need ⌊1/l⌋ ≤ 8, so l > 1/9: 0.112 to three digits,
    // where 0.111 gives ⌊9.009⌋ + 2 = 11 vertices a side, 121.
    let chosen = default_lenmax(&s, 0.01, 100);
    assert_eq!(chosen.lenmax, 0.112);
    let coarsened = chosen.coarsened.expect("the budget coarsens the mesh");
    assert_eq!(coarsened.lenmax, 0.112);
    assert_eq!(coarsened.vertices, 100);
    assert_eq!(coarsened.fine_lenmax, 0.01);
    assert_eq!(coarsened.fine_vertices, 101 * 101 + 2 * 101 + 1);
    assert!(!coarsened.over_budget);
    let finer = MeshOptions {
        lenmax: 0.111,
        inset: 0.0,
    };
    assert_eq!(estimate(&s, &finer).unwrap().vertices, 121);
    // The estimate is the mesh built (one polygon: nothing to stitch).
    let mesh = build(
        &s,
        &MeshOptions {
            lenmax: chosen.lenmax,
            inset: 0.0,
        },
    )
    .unwrap();
    assert_eq!(mesh.vertex_count(), 100);
}

#[test]
fn a_scene_within_the_budget_keeps_the_default_to_the_bit() {
    let s = scene(vec![unit_square(0.0), unit_square(2.0)]);
    let fine = MeshOptions::for_scene(&s).lenmax;
    let vertices = estimate(
        &s,
        &MeshOptions {
            lenmax: fine,
            inset: 0.0,
        },
    )
    .unwrap()
    .vertices;
    // Exactly at the budget counts as within it.
    for budget in [vertices, vertices + 1, VERTEX_BUDGET] {
        let (options, coarsened) = MeshOptions::within_budget(&s, budget);
        assert_eq!(options, MeshOptions::for_scene(&s));
        assert_eq!(coarsened, None);
    }
    let (options, coarsened) = MeshOptions::within_budget(&s, vertices - 1);
    assert!(options.lenmax > fine);
    assert!(coarsened.is_some_and(|c| c.vertices < vertices));
}

#[test]
fn below_the_corner_count_the_mesh_is_one_element_per_polygon() {
    // 50 triangles, 1 unit across: 150 corners, over a budget of 100.
    let triangles: Vec<Polygon> = (0..50)
        .map(|k| {
            let z = k as f32;
            testutil::polygon(0, &[[0., 0., z], [1., 0., z], [0., 1., z]])
        })
        .collect();
    let s = scene(triangles);
    let chosen = default_lenmax(&s, 0.1, 100);
    let coarsened = chosen.coarsened.expect("the budget coarsens the mesh");
    assert!(coarsened.over_budget);
    assert_eq!(coarsened.vertices, 150);
    // The longest edge is √2: every triangle is one element just above
    // it, and 1.42 is the first three-digit lenmax that is.
    assert_eq!(chosen.lenmax, 1.42);
    let sizes = Sizes::of(&s);
    assert_eq!(sizes.at(1.42), sizes.least());
    assert!(sizes.at(1.41).vertices > 150);
    let line = coarsened.to_string();
    assert!(
        line.starts_with("mesh coarsened to lenmax 1.42, one element per polygon (an estimated 150 vertices, over the budget of 100;"),
        "{line}"
    );
}

#[test]
fn a_default_already_one_element_per_polygon_is_kept_over_the_budget() {
    let s = scene(vec![unit_square(0.0), unit_square(1.0)]);
    let chosen = default_lenmax(&s, 10.0, 4);
    assert_eq!(chosen.lenmax, 10.0);
    assert_eq!(chosen.coarsened, None);
}

#[test]
fn the_line_says_what_was_chosen_and_how_to_get_finer() {
    let coarsened = Coarsened {
        lenmax: 41.2,
        vertices: 299_613,
        fine_lenmax: 13.852257,
        fine_vertices: 765_478,
        budget: 300_000,
        over_budget: false,
    };
    assert_eq!(
        coarsened.to_string(),
        "mesh coarsened to lenmax 41.2 (an estimated 300,000 vertices, within the budget of \
         300,000; the default 13.85 would give 765,000): give --lenmax for a finer one"
    );
    let small = Coarsened {
        lenmax: 0.00172,
        vertices: 9_999,
        fine_lenmax: 0.0012346,
        fine_vertices: 1_234_567,
        budget: 10_000,
        over_budget: false,
    };
    assert_eq!(
        small.to_string(),
        "mesh coarsened to lenmax 0.00172 (an estimated 9,999 vertices, within the budget of \
         10,000; the default 0.001235 would give 1,235,000): give --lenmax for a finer one"
    );
}
