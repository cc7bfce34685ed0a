//! Stitching: shared edges cut differently, T-junctions, cuts snapped to one
//! position, watertight refinement, and the time on a large mesh.

use super::*;
use crate::mesh::refine::{RefineOptions, Refiner};
use crate::mesh::{build, build_unstitched_with_limit, MeshOptions, MAX_ELEMENTS};
use crate::testutil;

fn scene(polygons: &[&[[f32; 3]]]) -> Scene {
    testutil::scene(
        polygons.iter().map(|v| testutil::polygon(0, v)).collect(),
        vec![testutil::grey("m", 0.0, 0.5)],
    )
}

/// Two triangles sharing the edge (0,0)–(1,1): the first is cut in 5
/// along it, the second (longest edge 4) in 14.
fn shared_edge() -> Scene {
    scene(&[
        &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]],
        &[[0., 0., 0.], [1., 1., 0.], [-3., 1., 0.]],
    ])
}

/// A 1 × 2 quad beside two 1 × 1 quads: the small ones' common corner
/// (1, 1) lies inside the big one's edge (a T-junction).
fn t_junction() -> Scene {
    scene(&[
        &[[0., 0., 0.], [1., 0., 0.], [1., 2., 0.], [0., 2., 0.]],
        &[[1., 0., 0.], [2., 0., 0.], [2., 1., 0.], [1., 1., 0.]],
        &[[1., 1., 0.], [2., 1., 0.], [2., 2., 0.], [1., 2., 0.]],
    ])
}

fn options(lenmax: f32) -> MeshOptions {
    MeshOptions {
        lenmax,
        inset: 0.05,
    }
}

/// Boundary vertices of other polygons lying inside a polygon's
/// boundary element edge (T-vertices across polygons), and pairs of
/// boundary vertices of different polygons closer than `eps` but not
/// at the same position bit for bit: both must be absent from a
/// watertight mesh. Brute force.
fn cracks(scene: &Scene, mesh: &Mesh) -> (usize, usize) {
    let eps = STITCH_TOLERANCE * scene.extent();
    let edges = boundary_edges(scene, mesh, eps);
    let mut boundary: Vec<u32> = edges.iter().flat_map(|e| [e.a, e.b]).collect();
    boundary.sort_unstable();
    boundary.dedup();
    let p = |v: u32| mesh.positions[v as usize];
    let poly = |v: u32| mesh.vertex_polygon[v as usize];
    let mut t_vertices = 0;
    for e in &edges {
        let (a, b) = (p(e.a), p(e.b));
        for &v in &boundary {
            if poly(v) == poly(e.a) {
                continue;
            }
            let d = b - a;
            let t = (p(v) - a).dot(d) / d.length_squared();
            if t > 0.0 && t < 1.0 && (a + t * d).distance(p(v)) <= eps && p(v) != a && p(v) != b {
                t_vertices += 1;
            }
        }
    }
    let mut near_misses = 0;
    for (i, &u) in boundary.iter().enumerate() {
        for &v in &boundary[i + 1..] {
            if poly(u) != poly(v) && p(u) != p(v) && p(u).distance(p(v)) <= eps {
                near_misses += 1;
            }
        }
    }
    (t_vertices, near_misses)
}

/// The structural invariants, the elements' orientation, and their
/// areas adding up to each polygon's.
fn assert_sound(scene: &Scene, mesh: &Mesh) {
    mesh.validate().unwrap();
    for (polygon, pm) in scene.polygons.iter().zip(&mesh.polygons) {
        let mut area = 0.0;
        for e in &mesh.elements[pm.elements.start as usize..pm.elements.end as usize] {
            for [a, b, c] in e.triangles() {
                let [a, b, c] = [a, b, c].map(|v| mesh.positions[v.index()]);
                let n = (b - a).cross(c - a);
                assert!(n.dot(polygon.normal) > 0.0, "flipped or empty element");
            }
            area += mesh.element_area(e);
        }
        assert!((area - polygon.area).abs() < 1e-5 * polygon.area);
        // Every vertex is used by an element.
        let mut used = vec![false; pm.vertex_count() as usize];
        for e in &mesh.elements[pm.elements.start as usize..pm.elements.end as usize] {
            for c in e.corners() {
                used[(c.0 - pm.vertices.start) as usize] = true;
            }
        }
        assert!(used.iter().all(|&u| u));
    }
}

#[test]
fn a_shared_edge_cut_differently_gets_both_cuts() {
    let s = shared_edge();
    let before = build_unstitched_with_limit(&s, &options(0.3), MAX_ELEMENTS).unwrap();
    assert_eq!((before.polygons[0].nu, before.polygons[1].nu), (5, 14));
    let (t_before, _) = cracks(&s, &before);
    assert!(t_before > 0);
    let after = build(&s, &options(0.3)).unwrap();
    assert_sound(&s, &after);
    assert_eq!(cracks(&s, &after), (0, 0));
    // Interior cut points: 4 and 13, and 5 and 14 share none (they
    // are coprime), so each triangle gains the other's.
    let gained: Vec<u32> = (0..2)
        .map(|k| after.polygons[k].vertex_count() - before.polygons[k].vertex_count())
        .collect();
    assert_eq!(gained, vec![13, 4]);
    assert!(after.polygons.iter().all(|pm| pm.stitched));
    // The positions on the shared edge are the same set, bit for bit.
    let on_edge = |k: usize| {
        let pm = &after.polygons[k];
        let mut v: Vec<[u32; 3]> = pm
            .vertices
            .clone()
            .map(|v| after.positions[v as usize])
            .filter(|p| (p.x - p.y).abs() < 1e-6)
            .map(|p| p.to_array().map(f32::to_bits))
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(on_edge(0), on_edge(1));
    assert_eq!(on_edge(0).len(), 2 + 4 + 13);
}

#[test]
fn inserted_vertices_are_inset_like_other_boundary_vertices() {
    let s = shared_edge();
    let m = build(&s, &options(0.3)).unwrap();
    let pm = &m.polygons[0];
    let d = pm.inset;
    assert!(d > 0.0);
    // Triangle 0's inward normal on the edge x = y is (1, -1)/√2.
    let inward = Vec3::new(1.0, -1.0, 0.0).normalize();
    for v in pm.vertices.clone() {
        let (p, q) = (m.positions[v as usize], m.sample_positions[v as usize]);
        let corner = p.length() < 1e-6 || (p - Vec3::new(1., 1., 0.)).length() < 1e-6;
        if (p.x - p.y).abs() < 1e-6 && !corner {
            assert!((q - p - inward * d).length() < 1e-5, "{p} -> {q}");
        }
    }
}

#[test]
fn a_t_junction_gets_the_corner_of_the_small_polygons() {
    let s = t_junction();
    let before = build_unstitched_with_limit(&s, &options(0.3), MAX_ELEMENTS).unwrap();
    assert!(cracks(&s, &before).0 > 0);
    let after = build(&s, &options(0.3)).unwrap();
    assert_sound(&s, &after);
    assert_eq!(cracks(&s, &after), (0, 0));
    let big = &after.polygons[0];
    let has = |pm: &crate::mesh::PolygonMesh, q: Vec3| {
        pm.vertices
            .clone()
            .any(|v| after.positions[v as usize] == q)
    };
    assert!(has(big, Vec3::new(1., 1., 0.)));
    // The big quad's right edge (7 cuts of 2/7) goes into the small
    // ones: none of its 6 interior cuts is at a quarter.
    for k in 1..7 {
        let q = Vec3::new(1., 2.0 * k as f32 / 7.0, 0.);
        let small = if q.y < 1.0 { 1 } else { 2 };
        let found = after.polygons[small]
            .vertices
            .clone()
            .any(|v| after.positions[v as usize].distance(q) < 1e-5);
        assert!(found, "cut {k} missing from the small quad");
    }
}

#[test]
fn the_same_cut_made_from_both_ends_is_snapped_to_one_position() {
    // Two triangles with the edge (0.1, 0.3)–(0.7, 1.9) in opposite
    // directions and the same subdivision count: the cut points are
    // computed from different ends and differ in the last bits.
    let s = scene(&[
        &[[0.1, 0.3, 0.2], [1.3, 0.2, 0.2], [0.7, 1.9, 0.2]],
        &[[0.1, 0.3, 0.2], [0.7, 1.9, 0.2], [-0.5, 1.2, 0.2]],
    ]);
    let m = build(&s, &options(0.17)).unwrap();
    assert_sound(&s, &m);
    assert_eq!(cracks(&s, &m), (0, 0));
}

#[test]
fn polygons_apart_are_left_as_they_are() {
    let s = scene(&[
        &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]],
        &[[0., 0., 1.], [1., 0., 1.], [1., 1., 1.]],
    ]);
    let before = build_unstitched_with_limit(&s, &options(0.3), MAX_ELEMENTS).unwrap();
    assert_eq!(build(&s, &options(0.3)).unwrap(), before);
}

#[test]
fn refinement_stays_watertight() {
    for s in [shared_edge(), t_junction()] {
        let mut mesh = build(&s, &options(0.3)).unwrap();
        let mut refiner = Refiner::new(&mesh);
        let opts = RefineOptions {
            levels: 3,
            ..RefineOptions::default()
        };
        for pass in 0..3 {
            // A sharp step across x = 0.63 + pass / 10, which splits
            // elements on the shared edges.
            let cut = 0.63 + pass as f32 / 10.0;
            let values: Vec<f64> = mesh
                .positions
                .iter()
                .map(|p| if p.x < cut { 0.1 } else { 1.0 })
                .collect();
            let Some((next, _)) = refiner.refine(&s, &values, &opts) else {
                panic!("pass {pass} refined nothing");
            };
            assert_sound(&s, &next);
            assert_eq!(cracks(&s, &next), (0, 0), "pass {pass}");
            // Every vertex of the new mesh is known to the refiner,
            // which carries values over.
            let carried = refiner.carry(&values);
            assert_eq!(carried.len(), next.vertex_count());
            mesh = next;
        }
    }
}

#[test]
fn a_large_mesh_is_stitched_quickly() {
    // A 300 × 170 grid of jittered points, each cell split into two
    // triangles (≈ 100,000 polygons) whose longest edges differ, so
    // that neighbours cut their shared edges differently.
    let mut rng = testutil::Xorshift(0x9e37_79b9_7f4a_7c15);
    let (nx, ny) = (301, 171);
    let points: Vec<[f32; 3]> = (0..nx * ny)
        .map(|k| {
            let (i, j) = ((k % nx) as f32, (k / nx) as f32);
            let jitter = |r: &mut testutil::Xorshift| 0.6 * (r.unit_f32() - 0.5);
            [i + jitter(&mut rng), j + jitter(&mut rng), 0.0]
        })
        .collect();
    let at = |i: usize, j: usize| points[j * nx + i];
    let mut polygons = Vec::new();
    for i in 0..nx - 1 {
        for j in 0..ny - 1 {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            polygons.push(testutil::polygon(0, &[a, b, c]));
            polygons.push(testutil::polygon(0, &[a, c, d]));
        }
    }
    let s = testutil::scene(polygons, vec![testutil::grey("m", 0.0, 0.5)]);
    let mesh = build_unstitched_with_limit(&s, &options(0.6), MAX_ELEMENTS).unwrap();
    let start = std::time::Instant::now();
    let stitched = stitch(&s, mesh.clone());
    let seconds = start.elapsed().as_secs_f64();
    stitched.validate().unwrap();
    assert!(stitched.vertex_count() > mesh.vertex_count());
    eprintln!(
        "stitched {} polygons, {} → {} vertices in {seconds:.3} s",
        s.polygons.len(),
        mesh.vertex_count(),
        stitched.vertex_count()
    );
    // Generous for a loaded two-core machine in a debug build; a
    // release build takes a fraction of this.
    assert!(seconds < 20.0, "{seconds} s");
}

/// A needle (10 long, 5·10⁻⁵ high, under half the stitching tolerance
/// of this 10-unit scene) along the far edge of a 10 × 1 floor. Its
/// element grid lies within the tolerance of both its long edges, so
/// found from the geometry every element edge was a boundary edge and
/// took the floor's vertices beside it: many vertices of the needle at
/// one position. Counted instead, its boundary takes each once per edge.
#[test]
fn a_needle_thinner_than_the_tolerance_takes_each_neighbour_vertex_once() {
    let h = 5e-5;
    let s = scene(&[
        &[[0., 0., 0.], [10., 0., 0.], [10., 1., 0.], [0., 1., 0.]],
        &[[0., 1., 0.], [10., 1., 0.], [5., 1. + h, 0.]],
    ]);
    let eps = STITCH_TOLERANCE * s.extent();
    assert!(h < 0.5 * eps, "the needle is thinner than the tolerance");
    let before = build_unstitched_with_limit(&s, &options(0.3), MAX_ELEMENTS).unwrap();
    let mesh = build(&s, &options(0.3)).unwrap();
    mesh.validate().unwrap();
    let needle = &mesh.polygons[1];
    let mut positions: Vec<[u32; 3]> = needle
        .vertices
        .clone()
        .map(|v| mesh.positions[v as usize].to_array().map(f32::to_bits))
        .collect();
    let all = positions.len();
    positions.sort_unstable();
    positions.dedup();
    // The floor's 35 cut points along y = 1, each near both long edges of
    // the needle: at most twice each, beside its own grid.
    let own = before.polygons[1].vertex_count() as usize;
    assert!(all <= own + 2 * 35, "{all} vertices, its own {own}");
    assert!(
        positions.len() * 3 >= all,
        "{all} vertices at {} positions",
        positions.len()
    );
}
