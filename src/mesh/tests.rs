//! Meshing each polygon shape: element counts, edge lengths and areas,
//! shared vertices, the inset of sample points, and the checks on options
//! and on a mesh's size.

use super::*;
use crate::testutil;

/// A polygon built without the parser, of the shape the test names.
fn polygon(vertices: &[[f32; 3]], shape: Shape) -> Polygon {
    let p = testutil::polygon(0, vertices);
    assert_eq!(p.shape, shape);
    p
}

fn scene(polygons: Vec<Polygon>) -> Scene {
    testutil::scene(polygons, vec![testutil::grey("m", 0.0, 0.5)])
}

/// One polygon of every shape the mesher knows, in parallel planes
/// `z = 0, 1, 2, …` (also used by the refinement tests).
pub(super) fn all_shapes() -> Vec<Polygon> {
    vec![
        polygon(
            &[[0., 0., 0.], [2., 0., 0.], [2., 1., 0.], [0., 1., 0.]],
            Shape::Parallelogram,
        ),
        polygon(
            &[[0., 0., 1.], [2., 0., 1.], [1.5, 1., 1.], [0.2, 1.3, 1.]],
            Shape::Quad,
        ),
        polygon(
            &[[0., 0., 2.], [1., 0., 2.], [0.3, 1.7, 2.]],
            Shape::Triangle,
        ),
        polygon(
            &[
                [1., 0., 3.],
                [0.5, 0.87, 3.],
                [-0.5, 0.87, 3.],
                [-1., 0., 3.],
                [-0.5, -0.87, 3.],
                [0.5, -0.87, 3.],
            ],
            Shape::Convex,
        ),
        // A pentagon with a collinear vertex (allowed by the format).
        polygon(
            &[
                [0., 0., 4.],
                [1., 0., 4.],
                [2., 0., 4.],
                [2., 1., 4.],
                [0., 1., 4.],
            ],
            Shape::Convex,
        ),
    ]
}

fn opts(lenmax: f32, inset: f32) -> MeshOptions {
    MeshOptions { lenmax, inset }
}

#[test]
fn parallelogram_grid_counts() {
    let s = scene(vec![all_shapes().remove(0)]);
    let m = build(&s, &opts(0.3, 0.0)).unwrap();
    let pm = &m.polygons[0];
    assert_eq!((pm.nu, pm.nv), (7, 4)); // ⌊2/0.3⌋+1, ⌊1/0.3⌋+1
    assert_eq!(m.vertex_count(), 8 * 5);
    assert_eq!(m.elements.len(), 28);
    m.validate().unwrap();
}

#[test]
fn exact_multiple_of_lenmax_still_gives_shorter_edges() {
    let s = scene(vec![all_shapes().remove(0)]);
    let m = build(&s, &opts(0.5, 0.0)).unwrap();
    assert_eq!((m.polygons[0].nu, m.polygons[0].nv), (5, 3));
}

#[test]
fn triangle_subdivision_counts() {
    let s = scene(vec![all_shapes().remove(2)]);
    let m = build(&s, &opts(0.25, 0.0)).unwrap();
    let n = m.polygons[0].nu as usize;
    assert!(n >= 2);
    assert_eq!(m.vertex_count(), (n + 1) * (n + 2) / 2);
    assert_eq!(m.elements.len(), n * n);
}

#[test]
fn every_edge_is_shorter_than_lenmax() {
    for lenmax in [0.07f32, 0.2, 0.33, 1.0, 5.0] {
        let m = build(&scene(all_shapes()), &opts(lenmax, 0.0)).unwrap();
        for e in &m.elements {
            let c = e.corners();
            for k in 0..c.len() {
                let (a, b) = (
                    m.positions[c[k].index()],
                    m.positions[c[(k + 1) % c.len()].index()],
                );
                assert!(
                    a.distance(b) < lenmax,
                    "edge {} >= lenmax {lenmax}",
                    a.distance(b)
                );
            }
        }
    }
}

#[test]
fn element_areas_sum_to_polygon_area() {
    let s = scene(all_shapes());
    let m = build(&s, &opts(0.13, 0.0)).unwrap();
    for (p, pm) in s.polygons.iter().zip(&m.polygons) {
        let sum: f64 = pm
            .elements
            .clone()
            .map(|e| m.element_area(&m.elements[e as usize]))
            .sum();
        assert!((sum - p.area).abs() < 1e-5 * p.area, "{sum} vs {}", p.area);
    }
    let shares = m.vertex_areas();
    for (p, pm) in s.polygons.iter().zip(&m.polygons) {
        let sum: f64 = pm.vertices.clone().map(|v| shares[v as usize]).sum();
        assert!((sum - p.area).abs() < 1e-5 * p.area);
    }
}

#[test]
fn elements_face_the_polygons_front() {
    let s = scene(all_shapes());
    let m = build(&s, &opts(0.2, 0.0)).unwrap();
    for (e, p) in m.elements.iter().zip(&m.element_polygon) {
        for [a, b, c] in e.triangles() {
            let (a, b, c) = (
                m.positions[a.index()],
                m.positions[b.index()],
                m.positions[c.index()],
            );
            let n = (b - a).cross(c - a);
            assert!(n.dot(s.polygons[p.index()].normal) > 0.0);
        }
    }
}

#[test]
fn vertices_are_shared_not_duplicated() {
    let s = scene(all_shapes());
    let m = build(&s, &opts(0.2, 0.0)).unwrap();
    m.validate().unwrap();
    for pm in &m.polygons {
        let vs = &m.positions[pm.vertices.start as usize..pm.vertices.end as usize];
        for (i, a) in vs.iter().enumerate() {
            for b in &vs[i + 1..] {
                assert!(a.distance(*b) > 1e-6, "duplicate vertex at {a}");
            }
        }
        // Every vertex is a corner of some element.
        let mut used = vec![false; vs.len()];
        for e in pm.elements.clone() {
            for c in m.elements[e as usize].corners() {
                used[(c.0 - pm.vertices.start) as usize] = true;
            }
        }
        assert!(used.iter().all(|&u| u));
    }
    // Interior vertices of a quad grid are shared by four elements.
    let pm = &m.polygons[0];
    let mut uses = vec![0; pm.vertex_count() as usize];
    for e in pm.elements.clone() {
        for c in m.elements[e as usize].corners() {
            uses[c.index()] += 1;
        }
    }
    let corner_uses = uses.iter().filter(|&&u| u == 1).count();
    let interior_uses = uses.iter().filter(|&&u| u == 4).count();
    assert_eq!(corner_uses, 4);
    assert_eq!(interior_uses, ((pm.nu - 1) * (pm.nv - 1)) as usize);
}

#[test]
fn inset_moves_boundary_vertices_inward_only() {
    let s = scene(vec![all_shapes().remove(0)]);
    let m = build(&s, &opts(0.5, 0.1)).unwrap();
    // A tenth of lenmax (the 2 × 1 polygon is larger).
    let d = 0.1 * 0.5;
    assert_eq!(m.polygons[0].inset, d);
    for (p, q) in m.positions.iter().zip(&m.sample_positions) {
        let on_x_edge = p.x == 0.0 || p.x == 2.0;
        let on_y_edge = p.y == 0.0 || p.y == 1.0;
        let expect_dx = if p.x == 0.0 {
            d
        } else if p.x == 2.0 {
            -d
        } else {
            0.0
        };
        let expect_dy = if p.y == 0.0 {
            d
        } else if p.y == 1.0 {
            -d
        } else {
            0.0
        };
        assert!((q.x - p.x - expect_dx).abs() < 1e-6, "{p} -> {q}");
        assert!((q.y - p.y - expect_dy).abs() < 1e-6, "{p} -> {q}");
        assert_eq!(q.z, p.z);
        if !on_x_edge && !on_y_edge {
            assert_eq!(p, q);
        }
    }
    // The corner at the origin moved diagonally.
    assert!((m.sample_positions[0] - Vec3::new(d, d, 0.0)).length() < 1e-6);
}

/// A polygon meshed as one element has its corners evaluated
/// [`ONE_ELEMENT_INSET`] times as far in as the boundary vertices of the
/// same polygon meshed as many.
#[test]
fn a_one_element_polygons_corners_are_evaluated_farther_in() {
    let s = scene(vec![all_shapes().remove(0)]);
    // lenmax 4 is longer than the 2 × 1 polygon: one element, its scale
    // the polygon's diameter.
    let one = build(&s, &opts(4.0, 0.05)).unwrap();
    assert_eq!(one.polygons[0].elements.len(), 1);
    let d = 0.05 * 5f32.sqrt();
    assert!((one.polygons[0].inset - d).abs() < 1e-6);
    let far = ONE_ELEMENT_INSET * d;
    for (p, q) in one.positions.iter().zip(&one.sample_positions) {
        let expect = Vec3::new(
            if p.x == 0.0 { far } else { -far },
            if p.y == 0.0 { far } else { -far },
            0.0,
        );
        assert!((*q - *p - expect).length() < 1e-5, "{p} -> {q}");
    }
    // Many elements: every boundary vertex a twentieth of lenmax in.
    let many = build(&s, &opts(0.5, 0.05)).unwrap();
    assert!(many.polygons[0].elements.len() > 1);
    assert!((many.sample_positions[0] - Vec3::new(0.025, 0.025, 0.0)).length() < 1e-6);
    assert_eq!(sample_inset(d, 2), d);
    assert_eq!(sample_inset(d, 1), ONE_ELEMENT_INSET * d);
}

#[test]
fn zero_inset_leaves_samples_on_the_vertices() {
    let m = build(&scene(all_shapes()), &opts(0.3, 0.0)).unwrap();
    assert_eq!(m.positions, m.sample_positions);
}

#[test]
fn inset_samples_stay_inside_the_polygon() {
    let s = scene(all_shapes());
    let m = build(&s, &opts(0.3, DEFAULT_INSET)).unwrap();
    for (q, pid) in m.sample_positions.iter().zip(&m.vertex_polygon) {
        let p = &s.polygons[pid.index()];
        let v = &p.vertices;
        for k in 0..v.len() {
            let edge = v[(k + 1) % v.len()] - v[k];
            let inward = p.normal.cross(edge);
            assert!(
                inward.dot(*q - v[k]) > 0.0,
                "sample {q} is not strictly inside"
            );
        }
    }
}

/// A sliver's apex (2.9° here) moves the full inset distance along its
/// bisector, not the few percent of it its two edges' nearly opposite
/// normals add up to; a vertex on a long edge moves at most half the way
/// across. Every sample stays strictly inside.
#[test]
fn a_slivers_samples_leave_its_apex_and_stay_inside() {
    let sliver = polygon(
        &[[0., 0., 0.], [4., 0., 0.], [4., 0.2, 0.]],
        Shape::Triangle,
    );
    let d = 0.05;
    let got: Vec<Vec3> = inset_positions(&sliver, &sliver.vertices, d).collect();
    let apex = got[0] - sliver.vertices[0];
    assert!((apex.length() - d).abs() < 1e-6, "apex moved {apex}");
    let bisector = (Vec3::X + Vec3::new(4.0, 0.2, 0.0).normalize()).normalize();
    assert!(apex.normalize().dot(bisector) > 0.9999, "{apex}");
    // Midway along the long edge y = 0 the sliver is 0.1 across: a move
    // of 0.2 is cut to half of that.
    let mid = Vec3::new(2.0, 0.0, 0.0);
    let moved: Vec<Vec3> = inset_positions(&sliver, &[mid], 0.2).collect();
    assert!(
        (moved[0] - mid - Vec3::new(0.0, 0.05, 0.0)).length() < 1e-6,
        "{}",
        moved[0]
    );
    for q in got.iter().chain(&moved) {
        let v = &sliver.vertices;
        for k in 0..3 {
            let inward = sliver.normal.cross(v[(k + 1) % 3] - v[k]);
            assert!(inward.dot(*q - v[k]) > 0.0, "{q} is not strictly inside");
        }
    }
}

#[test]
fn lenmax_and_inset_checks_accept_exactly_their_ranges() {
    for good in [f32::MIN_POSITIVE, 0.01, 1e6] {
        assert_eq!(check_lenmax(good), Ok(good));
    }
    for bad in [0.0, -0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(matches!(check_lenmax(bad), Err(MeshError::BadLenmax(_))));
    }
    for good in [0.0, DEFAULT_INSET, 0.499] {
        assert_eq!(check_inset(good), Ok(good));
    }
    for bad in [-0.01, 0.5, 1.0, f32::NAN, f32::INFINITY] {
        assert!(matches!(check_inset(bad), Err(MeshError::BadInset(_))));
    }
}

#[test]
fn bad_options_and_huge_meshes_are_refused() {
    let s = scene(all_shapes());
    assert!(matches!(
        build(&s, &opts(0.0, 0.0)),
        Err(MeshError::BadLenmax(_))
    ));
    assert!(matches!(
        build(&s, &opts(f32::NAN, 0.0)),
        Err(MeshError::BadLenmax(_))
    ));
    assert!(matches!(
        build(&s, &opts(1.0, 0.6)),
        Err(MeshError::BadInset(_))
    ));
    match build(&s, &opts(1e-5, 0.0)) {
        Err(MeshError::TooManyElements {
            suggested: Some(suggested),
            ..
        }) => {
            let m = build(&s, &opts(suggested, 0.0)).unwrap();
            assert!(m.elements.len() as u64 <= MAX_ELEMENTS);
        }
        other => panic!("expected TooManyElements, got {other:?}"),
    }
}

/// The inset of a polygon of many edges, whose edges near each point are
/// found through a grid, moves every point exactly as testing every edge
/// does: on a vertex (two edges), on an edge, just off it, and inside.
#[test]
fn the_edge_grid_finds_every_edge_a_point_lies_on() {
    let n = 300;
    let disc: Vec<[f32; 3]> = (0..n)
        .map(|k| {
            let a = std::f32::consts::TAU * k as f32 / n as f32;
            [3.0 * a.cos(), 0.5 * a.sin() - 1.0, 2.0 * a.sin()]
        })
        .collect();
    let p = testutil::polygon(0, &disc);
    let v = &p.vertices;
    let mut points = Vec::new();
    for k in 0..n {
        let (a, b) = (v[k], v[(k + 1) % n]);
        points.extend([a, (a + b) * 0.5, a.lerp(b, 0.1), a.lerp(b, 0.5) * 0.999]);
    }
    points.push(Vec3::new(0.0, -1.0, 0.0));
    let d = 0.01;
    let extent = crate::scene::polygon_extent_f32(v);
    let tolerance = ON_EDGE_TOLERANCE * extent;
    let every_edge = |q: Vec3| {
        let mut sum = Vec3::ZERO;
        for k in 0..n {
            let (a, b) = (v[k], v[(k + 1) % n]);
            let dir = (b - a).normalize_or_zero();
            let inward = p.normal.cross(dir).normalize_or_zero();
            let rel = q - a;
            if (rel - rel.dot(dir) * dir).length() <= tolerance {
                sum += inward;
            }
        }
        // At least `d` along the sum of the edges' normals.
        q + sum.normalize_or_zero() * d * sum.length().max(1.0)
    };
    let got: Vec<Vec3> = inset_positions(&p, &points, d).collect();
    let mut moved = 0;
    for (q, g) in points.iter().zip(&got) {
        assert!((*g - every_edge(*q)).length() < 1e-6, "at {q}: {g}");
        moved += (*g != *q) as usize;
    }
    // Every vertex and point on an edge moved; the others did not.
    assert_eq!(moved, 3 * n);
}
