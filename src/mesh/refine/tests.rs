//! Adaptive refinement: its options, which fields refine and which do not,
//! and meshes that stay conforming, on chosen and on random fields.

use super::*;
use crate::mesh::{build, MeshOptions};
use crate::testutil;

/// A parallelogram, a bilinear quad, a triangle, a hexagon and a
/// pentagon (fans), in parallel planes `z = 0 … 4`.
fn shapes() -> Scene {
    testutil::scene(
        crate::mesh::tests::all_shapes(),
        vec![testutil::grey("m", 0.0, 0.5)],
    )
}

fn options() -> MeshOptions {
    MeshOptions {
        lenmax: 0.3,
        inset: 0.05,
    }
}

/// A field with a sharp step along the line `x = 0.63` (a shadow edge).
fn step(mesh: &Mesh) -> Vec<f64> {
    mesh.positions
        .iter()
        .map(|p| if p.x < 0.63 { 0.1 } else { 1.0 })
        .collect()
}

/// Checks that every vertex of polygon `p` on its edge `y = 0` is
/// evaluated the polygon's inset inside it; returns how many there are.
fn inset_along_y0(mesh: &Mesh, p: usize) -> usize {
    let pm = &mesh.polygons[p];
    let mut boundary = 0;
    for v in pm.vertices.clone() {
        let (at, s) = (
            mesh.positions[v as usize],
            mesh.sample_positions[v as usize],
        );
        if at.y == 0.0 {
            boundary += 1;
            assert!((s.y - pm.inset).abs() < 1e-6, "{at} evaluated at {s}");
        }
    }
    boundary
}

/// No vertex of a polygon lies inside an edge of one of its elements
/// (a T-vertex), and the elements tile the polygon without overlap.
fn assert_conforming(scene: &Scene, mesh: &Mesh) {
    mesh.validate().unwrap();
    for (p, pm) in mesh.polygons.iter().enumerate() {
        let range = pm.vertices.start as usize..pm.vertices.end as usize;
        let area: f64 = mesh.elements[pm.elements.start as usize..pm.elements.end as usize]
            .iter()
            .map(|e| mesh.element_area(e))
            .sum();
        let expected = scene.polygons[p].area;
        assert!(
            (area - expected).abs() < 1e-4 * expected,
            "polygon {p}: elements cover {area}, polygon {expected}"
        );
        for e in &mesh.elements[pm.elements.start as usize..pm.elements.end as usize] {
            // Counter-clockwise from the front: no flipped element.
            for [a, b, c] in e.triangles() {
                let [a, b, c] = [a, b, c].map(|v| mesh.positions[v.index()]);
                let n = (b - a).cross(c - a);
                assert!(
                    n.dot(pm.normal) > 0.0,
                    "polygon {p}: a degenerate or flipped triangle"
                );
            }
            let c = e.corners();
            for k in 0..c.len() {
                let (a, b) = (
                    mesh.positions[c[k].index()],
                    mesh.positions[c[(k + 1) % c.len()].index()],
                );
                let len = a.distance(b);
                for (v, &x) in mesh.positions[range.clone()].iter().enumerate() {
                    let v = VertexId(pm.vertices.start + v as u32);
                    if c.contains(&v) {
                        continue;
                    }
                    let t = (x - a).dot(b - a) / (len * len);
                    let off = (a + t * (b - a)).distance(x);
                    assert!(
                        !(t > 1e-4 && t < 1.0 - 1e-4 && off < 1e-5 * len.max(1.0)),
                        "polygon {p}: vertex {} hangs on an element edge",
                        v.0
                    );
                }
            }
        }
    }
}

#[test]
fn options_are_validated_against_their_documented_ranges() {
    assert_eq!(RefineOptions::default().validate(), Ok(()));
    let with = |threshold, levels| RefineOptions {
        threshold,
        levels,
        ..RefineOptions::default()
    };
    assert_eq!(with(0.999, MAX_LEVELS).validate(), Ok(()));
    for t in [0.0, 1.0, -0.5, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            with(t, 1).validate(),
            Err(OptionsError::Threshold(_))
        ));
    }
    for levels in [0, MAX_LEVELS + 1] {
        assert_eq!(
            with(0.5, levels).validate(),
            Err(OptionsError::Levels(levels))
        );
    }
}

#[test]
fn a_uniform_field_needs_no_refinement() {
    let scene = shapes();
    let mesh = build(&scene, &options()).unwrap();
    let mut refiner = Refiner::new(&mesh);
    let flat = vec![0.7; mesh.vertex_count()];
    assert!(refiner
        .refine(&scene, &flat, &RefineOptions::default())
        .is_none());
    // Below the threshold is not enough either: a 20 % gradient.
    let gentle: Vec<f64> = mesh
        .positions
        .iter()
        .map(|p| 1.0 + 0.1 * p.x as f64)
        .collect();
    assert!(refiner
        .refine(&scene, &gentle, &RefineOptions::default())
        .is_none());
    assert_eq!(refiner.passes(), 0);
}

#[test]
fn a_step_is_refined_along_its_edge_only_and_stays_conforming() {
    let scene = shapes();
    let mesh = build(&scene, &options()).unwrap();
    let mut refiner = Refiner::new(&mesh);
    let (once, report) = refiner
        .refine(&scene, &step(&mesh), &RefineOptions::default())
        .unwrap();
    assert!(report.marked > 0 && report.fans > 0, "{report:?}");
    assert_conforming(&scene, &once);
    assert_eq!(once.polygons.iter().map(|p| p.levels).max(), Some(1));
    // The new vertices crowd the step: none is far from x = 0.63.
    let initial_edge = 0.3;
    for p in &once.positions[..] {
        if !mesh.positions.contains(p) {
            assert!((p.x - 0.63).abs() < 2.0 * initial_edge, "new vertex at {p}");
        }
    }
    let (twice, _) = refiner
        .refine(&scene, &step(&once), &RefineOptions::default())
        .unwrap();
    assert_conforming(&scene, &twice);
    assert!(twice.vertex_count() > once.vertex_count());
    // Two levels: nothing more to split, however sharp the step.
    assert!(refiner
        .refine(&scene, &step(&twice), &RefineOptions::default())
        .is_none());
    for (pm, initial) in twice.polygons.iter().zip(&mesh.polygons) {
        assert!(pm.min_edge >= initial.min_edge / 4.0 * 0.999, "{pm:?}");
    }
}

#[test]
fn closure_splits_what_a_fan_cannot_take() {
    // A bright band between x = 0.4 and x = 1.0 on the first polygon
    // (columns of width 2/7): the columns holding its two edges split,
    // the column between them does not, and is left with hanging
    // vertices on two opposite edges, which no fan takes: the closure
    // must split it.
    let scene = shapes();
    let mut mesh = build(&scene, &options()).unwrap();
    let mut refiner = Refiner::new(&mesh);
    let options = RefineOptions {
        levels: 3,
        ..RefineOptions::default()
    };
    let band = |m: &Mesh| -> Vec<f64> {
        m.positions
            .iter()
            .map(|p| if p.x > 0.4 && p.x < 1.0 { 1.0 } else { 0.1 })
            .collect()
    };
    let mut closure = 0;
    while let Some((next, report)) = refiner.refine(&scene, &band(&mesh), &options) {
        closure += report.closure;
        assert_conforming(&scene, &next);
        mesh = next;
    }
    assert_eq!(refiner.passes(), 3);
    assert_eq!(mesh.polygons[0].levels, 3);
    assert!(closure > 0, "the band needs closure splits");
}

#[test]
fn untouched_polygons_keep_their_mesh_and_new_boundary_vertices_are_inset() {
    let scene = shapes();
    let mesh = build(&scene, &options()).unwrap();
    let mut refiner = Refiner::new(&mesh);
    // A step on the first polygon only (the others are at z > 0).
    let values: Vec<f64> = mesh
        .positions
        .iter()
        .map(|p| if p.z == 0.0 && p.x < 0.63 { 0.1 } else { 1.0 })
        .collect();
    let (refined, _) = refiner
        .refine(&scene, &values, &RefineOptions::default())
        .unwrap();
    for p in 1..mesh.polygons.len() {
        let (a, b) = (&mesh.polygons[p], &refined.polygons[p]);
        assert_eq!(a.vertex_count(), b.vertex_count());
        assert_eq!(b.levels, 0);
        let shift = b.vertices.start as i64 - a.vertices.start as i64;
        for (v, w) in a.vertices.clone().zip(b.vertices.clone()) {
            assert_eq!(mesh.positions[v as usize], refined.positions[w as usize]);
            assert_eq!(
                mesh.sample_positions[v as usize],
                refined.sample_positions[w as usize]
            );
        }
        for (e, f) in a.elements.clone().zip(b.elements.clone()) {
            let moved: Vec<i64> = mesh.elements[e as usize]
                .corners()
                .iter()
                .map(|c| c.0 as i64 + shift)
                .collect();
            let got: Vec<i64> = refined.elements[f as usize]
                .corners()
                .iter()
                .map(|c| c.0 as i64)
                .collect();
            assert_eq!(moved, got);
        }
    }
    // New vertices on the first polygon's edge y = 0 are evaluated
    // inside it, as far in as the old ones.
    let boundary = inset_along_y0(&refined, 0);
    assert!(boundary > mesh.polygons[0].nu as usize + 1);
}

#[test]
fn random_fields_always_give_conforming_meshes() {
    // Noise marks elements all over, in every pattern the closure has
    // to handle; every pass on every shape must stay conforming and
    // tile its polygon, carry a field exactly at old vertices, and
    // number each vertex once.
    let scene = shapes();
    let mut stream = testutil::Xorshift(0x9e37_79b9_7f4a_7c15);
    let mut rand = move || stream.unit_f64();
    let refine = RefineOptions {
        levels: 3,
        ..RefineOptions::default()
    };
    // A coarse start keeps three levels of noise small enough for the
    // quadratic conformity check.
    let coarse = MeshOptions {
        lenmax: 0.7,
        inset: 0.05,
    };
    for _ in 0..6 {
        let mut mesh = build(&scene, &coarse).unwrap();
        let mut refiner = Refiner::new(&mesh);
        let sparse = rand() * 0.3;
        loop {
            let values: Vec<f64> = (0..mesh.vertex_count())
                .map(|_| if rand() < sparse { 0.1 } else { 1.0 })
                .collect();
            let Some((next, _)) = refiner.refine(&scene, &values, &refine) else {
                break;
            };
            assert_conforming(&scene, &next);
            let carried = refiner.carry(&values);
            for (l, previous) in refiner.previous_index().iter().enumerate() {
                match previous {
                    Some(k) => assert_eq!(carried[l], values[*k as usize]),
                    None => assert!((0.1..=1.0).contains(&carried[l])),
                }
            }
            mesh = next;
        }
    }
}

#[test]
fn dark_noise_is_not_refined() {
    // Values differing by 100 % but all under the dark floor of a
    // bright scene: nothing to see, nothing to split.
    let scene = shapes();
    let mesh = build(&scene, &options()).unwrap();
    let mut refiner = Refiner::new(&mesh);
    let values: Vec<f64> = mesh
        .positions
        .iter()
        .map(|p| match (p.z == 0.0, p.x < 0.63) {
            (true, true) => 0.0,
            (true, false) => 0.001,
            _ => 1.0,
        })
        .collect();
    assert!(refiner
        .refine(&scene, &values, &RefineOptions::default())
        .is_none());
}

/// A polygon meshed as one element has its corners evaluated farther in
/// ([`crate::mesh::sample_inset`]). Refined into many elements, every
/// boundary vertex, old or new, takes the polygon's own inset; a
/// one-element polygon refinement leaves alone keeps its corners' samples.
#[test]
fn a_refined_one_element_polygon_takes_the_inset_of_many() {
    let mut shapes = crate::mesh::tests::all_shapes();
    // The 2 × 1 parallelogram at z = 0 and the triangle at z = 2.
    let scene = testutil::scene(
        vec![shapes.remove(0), shapes.remove(1)],
        vec![testutil::grey("m", 0.0, 0.5)],
    );
    let mesh = build(
        &scene,
        &MeshOptions {
            lenmax: 4.0,
            inset: 0.05,
        },
    )
    .unwrap();
    for pm in &mesh.polygons {
        assert_eq!(pm.elements.len(), 1);
    }
    let pm = &mesh.polygons[0];
    let far = crate::mesh::sample_inset(pm.inset, 1);
    assert!(far > pm.inset);
    assert!((mesh.sample_positions[0].y - far).abs() < 1e-6);
    // A step across the parallelogram only.
    let values: Vec<f64> = mesh
        .positions
        .iter()
        .map(|p| if p.z == 0.0 && p.x < 0.63 { 0.1 } else { 1.0 })
        .collect();
    let mut refiner = Refiner::new(&mesh);
    let (refined, _) = refiner
        .refine(&scene, &values, &RefineOptions::default())
        .unwrap();
    assert!(refined.polygons[0].elements.len() > 1);
    let boundary = inset_along_y0(&refined, 0);
    assert!(boundary >= 3, "{boundary}");
    let (before, after) = (&mesh.polygons[1], &refined.polygons[1]);
    assert_eq!(after.elements.len(), 1);
    for (v, w) in before.vertices.clone().zip(after.vertices.clone()) {
        assert_eq!(
            mesh.sample_positions[v as usize],
            refined.sample_positions[w as usize]
        );
    }
}

/// Two squares apart, `A` of side 1 and `B` of side `side_b`, meshed at
/// lenmax 0.3 (four elements a side each, so `B`'s are larger when it
/// is), under a step across `x − x₀ = 0.63` of each: `A` from 0.1 to 1,
/// `B` from `low_b` to 1. Returns the scene, its mesh and the field.
fn two_steps(side_b: f32, low_b: f64) -> (Scene, Mesh, Vec<f64>) {
    let square = |x0: f32, side: f32| {
        testutil::polygon(
            0,
            &[
                [x0, 0., 0.],
                [x0 + side, 0., 0.],
                [x0 + side, side, 0.],
                [x0, side, 0.],
            ],
        )
    };
    let scene = testutil::scene(
        vec![square(0.0, 1.0), square(3.0, side_b)],
        vec![testutil::grey("m", 0.0, 0.5)],
    );
    let mesh = build(&scene, &options()).unwrap();
    let field = mesh
        .positions
        .iter()
        .map(
            |p| match (p.x < 2.0, p.x - if p.x < 2.0 { 0.0 } else { 3.0 } < 0.63) {
                (_, false) => 1.0,
                (true, true) => 0.1,
                (false, true) => low_b,
            },
        )
        .collect();
    (scene, mesh, field)
}

/// The polygons that got new vertices in a refinement of `mesh` to
/// `refined`: `(A, B)`.
fn refined_polygons(mesh: &Mesh, refined: &Mesh) -> (bool, bool) {
    let new = |p: usize| refined.polygons[p].vertex_count() > mesh.polygons[p].vertex_count();
    (new(0), new(1))
}

#[test]
fn past_max_splits_the_leaves_with_the_most_light_to_gain_split() {
    let limited = |max_splits| RefineOptions {
        max_splits,
        ..RefineOptions::default()
    };
    // Equal elements: the steeper step (0.9 against 0.5 of light) first.
    let (scene, mesh, field) = two_steps(1.0, 0.5);
    let (_, all) = Refiner::new(&mesh)
        .refine(&scene, &field, &limited(u64::MAX))
        .unwrap();
    assert_eq!(all.marked, all.over_threshold);
    assert!(all.marked % 2 == 0 && all.marked > 0, "{all:?}");
    let half = all.marked as u64 / 2;
    let (refined, report) = Refiner::new(&mesh)
        .refine(&scene, &field, &limited(half))
        .unwrap();
    assert_eq!(
        (report.marked, report.over_threshold),
        (half as usize, all.marked)
    );
    assert_eq!(refined_polygons(&mesh, &refined), (true, false));
    assert_conforming(&scene, &refined);
    // Equal steps: the larger elements (B's, 1.1 a side against 1) first.
    let (scene, mesh, field) = two_steps(1.1, 0.1);
    let (refined, report) = Refiner::new(&mesh)
        .refine(&scene, &field, &limited(half))
        .unwrap();
    assert_eq!(report.marked, half as usize);
    assert_eq!(refined_polygons(&mesh, &refined), (false, true));
    assert_conforming(&scene, &refined);
    // Zero is refused by the options' check.
    assert_eq!(limited(0).validate(), Err(OptionsError::MaxSplits(0)));
}
