//! Occlusion queries against brute force: blockers, grazing and shared
//! edges, crowded cells, and shaft candidates.

use super::*;
use crate::scene::{MaterialId, Polygon, Shape, SourcePos, Surface};
use crate::testutil;

fn square(z: f32, size: f32, offset: (f32, f32)) -> Polygon {
    let (x, y) = offset;
    Polygon {
        material: MaterialId(0),
        vertices: vec![
            Vec3::new(x, y, z),
            Vec3::new(x + size, y, z),
            Vec3::new(x + size, y + size, z),
            Vec3::new(x, y + size, z),
        ],
        normal: Vec3::Z,
        area: (size * size) as f64,
        shape: Shape::Parallelogram,
        origin: SourcePos::default(),
        surface: Surface::default(),
    }
}

fn scene(polygons: Vec<Polygon>) -> Scene {
    testutil::scene(polygons, vec![testutil::grey("m", 0.0, 0.5)])
}

/// A polygon of four `corners` with unit `normal`.
fn quad(corners: [[f32; 3]; 4], normal: Vec3) -> Polygon {
    let mut p = square(0.0, 1.0, (0.0, 0.0));
    p.vertices = corners.iter().map(|&c| Vec3::from(c)).collect();
    p.normal = normal;
    p
}

#[test]
fn crowds_sees_what_reaches_in_front_of_a_cell() {
    let s = scene(vec![
        // 0: the floor, facing +z.
        square(0.0, 8.0, (0.0, 0.0)),
        // 1: a lamp 0.05 over it at (1, 1).
        square(0.05, 0.2, (0.9, 0.9)),
        // 2: a square 0.1 under it at (3, 3).
        square(-0.1, 0.5, (2.9, 2.9)),
        // 3: a square far over it at (5, 5).
        square(4.0, 0.5, (4.9, 4.9)),
        // 4: a leg standing on it at x = 7, y 1 to 1.2.
        quad(
            [
                [7.0, 1.0, 0.0],
                [7.0, 1.2, 0.0],
                [7.0, 1.2, 0.5],
                [7.0, 1.0, 0.5],
            ],
            Vec3::X,
        ),
        // 5: a square in the floor's plane beyond it.
        square(0.0, 1.0, (9.0, 9.0)),
    ]);
    let v = Visibility::new(&s);
    let cell = |x: f32, y: f32| {
        [
            Vec3::new(x - 0.5, y - 0.5, 0.0),
            Vec3::new(x + 0.5, y - 0.5, 0.0),
            Vec3::new(x + 0.5, y + 0.5, 0.0),
            Vec3::new(x - 0.5, y + 0.5, 0.0),
        ]
    };
    let floor = PolygonId(0);
    assert!(v.crowds(floor, &cell(1.0, 1.0), Vec3::Z, 0.3), "the lamp");
    assert!(
        !v.crowds(floor, &cell(1.0, 1.0), Vec3::Z, 0.01),
        "too shallow"
    );
    assert!(!v.crowds(floor, &cell(3.0, 3.0), Vec3::Z, 0.3), "behind");
    assert!(!v.crowds(floor, &cell(5.0, 5.0), Vec3::Z, 0.3), "far");
    assert!(v.crowds(floor, &cell(7.0, 1.0), Vec3::Z, 0.3), "the leg");
    assert!(!v.crowds(floor, &cell(8.9, 8.9), Vec3::Z, 0.3), "coplanar");
    // Seen from the lamp's own cell, facing down onto the floor.
    assert!(v.crowds(
        PolygonId(1),
        &cell(1.0, 1.0).map(|c| c + Vec3::Z * 0.05),
        -Vec3::Z,
        0.3
    ));
}

#[test]
fn blocker_between_ends_occludes() {
    let s = scene(vec![
        square(0.0, 1.0, (0.0, 0.0)),
        square(1.0, 1.0, (0.0, 0.0)),
        square(2.0, 1.0, (0.0, 0.0)),
    ]);
    let v = Visibility::new(&s);
    let ends = (PolygonId(0), PolygonId(2));
    assert!(v.occluded(Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.5, 0.5, 2.0), ends));
    // Beside the blocker.
    assert!(!v.occluded(Vec3::new(1.5, 0.5, 0.0), Vec3::new(1.5, 0.5, 2.0), ends));
    // The blocker itself as an end is ignored.
    assert!(!v.occluded(
        Vec3::new(0.5, 0.5, 0.0),
        Vec3::new(0.5, 0.5, 2.0),
        (PolygonId(0), PolygonId(1))
    ));
    assert!(!v.occluded(
        Vec3::new(0.5, 0.5, 0.5),
        Vec3::new(0.5, 0.5, 1.0),
        (PolygonId(1), PolygonId(1))
    ));
}

/// A direction with negative-zero components (a segment from `+0.0`
/// to `-0.0`, a mirrored exporter's coordinates) still meets what is
/// in its way, in both ray queries.
#[test]
fn negative_zero_directions_find_their_blockers() {
    let s = scene(vec![
        square(-1.0, 2.0, (-1.0, -1.0)),
        square(1.0, 2.0, (-1.0, -1.0)),
        square(3.0, 2.0, (5.0, 5.0)),
    ]);
    let v = Visibility::new(&s);
    let none = (PolygonId(99), PolygonId(99));
    let (a, b) = (Vec3::ZERO, Vec3::new(-0.0, -0.0, -2.0));
    assert!((b - a).x.is_sign_negative());
    assert!(v.occluded(a, b, none));
    let down = v.first_hit(Vec3::ZERO, Vec3::new(-0.0, -0.0, -1.0));
    assert_eq!(down.map(|(p, _)| p), Some(PolygonId(0)));
    assert!((down.unwrap().1 - 1.0).abs() < 1e-5);
    let up = v.first_hit(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0));
    assert_eq!(up.map(|(p, _)| p), Some(PolygonId(1)));
    assert_eq!(v.first_hit(Vec3::ZERO, Vec3::X), None);
    assert_eq!(v.first_hit(Vec3::ZERO, Vec3::ZERO), None);
}

#[test]
fn segment_ending_before_blocker_is_clear() {
    let s = scene(vec![square(1.0, 1.0, (0.0, 0.0))]);
    let v = Visibility::new(&s);
    let none = (PolygonId(99), PolygonId(99));
    assert!(!v.occluded(Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.5, 0.5, 0.9), none));
    assert!(v.occluded(Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.5, 0.5, 1.1), none));
    assert!(!v.occluded(Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.5, 0.5, 0.0), none));
}

/// A ray exactly through a square's diagonal, or through the edge two
/// squares share, is blocked: no crack to leak through.
#[test]
fn no_leak_through_diagonals_or_shared_edges() {
    let s = scene(vec![
        square(1.0, 1.0, (0.0, 0.0)),
        square(1.0, 1.0, (1.0, 0.0)),
    ]);
    let v = Visibility::new(&s);
    let none = (PolygonId(99), PolygonId(99));
    for x in [0.25f32, 0.5, 0.75, 1.0, 1.5] {
        let (a, b) = (Vec3::new(x, x.min(1.0), 0.0), Vec3::new(x, x.min(1.0), 2.0));
        assert!(v.occluded(a, b, none), "leak at x = {x}");
    }
}

#[test]
fn empty_scene_blocks_nothing() {
    let v = Visibility::new(&scene(vec![]));
    assert!(!v.occluded(Vec3::ZERO, Vec3::ONE, (PolygonId(0), PolygonId(0))));
}

/// Sixty squares of sides 0.3 to 1.3 scattered over 5 × 5 × 10 scene
/// units, drawn from `rand`.
fn scattered_squares(rand: &mut impl FnMut() -> f32) -> Scene {
    scene(
        (0..60)
            .map(|_| square(rand() * 10.0, 0.3 + rand(), (rand() * 5.0, rand() * 5.0)))
            .collect(),
    )
}

/// The BVH answers exactly as testing every triangle does, on a field
/// of scattered squares and many pseudo-random segments.
#[test]
fn bvh_agrees_with_brute_force() {
    let mut stream = crate::testutil::Xorshift(0x2545_f491_4f6c_dd1d);
    let mut rand = move || stream.unit_f32();
    let v_scene = scattered_squares(&mut rand);
    let v = Visibility::new(&v_scene);
    // The same search built for baseline x86-64, which CPUs without
    // SSE4.2 run (this one may run the other).
    #[cfg(target_arch = "x86_64")]
    let baseline = Visibility {
        sse42: false,
        ..Visibility::new(&v_scene)
    };
    let mut blocked = 0;
    for _ in 0..5000 {
        let a = Vec3::new(rand() * 6.0, rand() * 6.0, -1.0 + rand() * 12.0);
        let b = Vec3::new(rand() * 6.0, rand() * 6.0, -1.0 + rand() * 12.0);
        let ends = (
            PolygonId((rand() * 60.0) as u32),
            PolygonId((rand() * 60.0) as u32),
        );
        let fast = v.occluded(a, b, ends);
        assert_eq!(fast, v.occluded_brute_force(a, b, ends), "{a} -> {b}");
        #[cfg(target_arch = "x86_64")]
        assert_eq!(fast, baseline.occluded(a, b, ends), "{a} -> {b}");
        blocked += fast as u32;
    }
    // Both outcomes are exercised.
    assert!(blocked > 500 && blocked < 4500, "{blocked}");
}

/// The nearest hit along a ray (the particle tail's query) is the one
/// testing every polygon finds.
#[test]
fn first_hit_agrees_with_brute_force() {
    let mut stream = crate::testutil::Xorshift(0x9e37_79b9_7f4a_7c15);
    let mut rand = move || stream.unit_f32();
    let v_scene = scattered_squares(&mut rand);
    let v = Visibility::new(&v_scene);
    let mut hits = 0;
    for _ in 0..5000 {
        let origin = Vec3::new(rand() * 6.0, rand() * 6.0, -1.0 + rand() * 12.0);
        let direction = Vec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5);
        let fast = v.first_hit(origin, direction);
        let ray = Ray::new(
            origin.into(),
            without_negative_zeros(direction.normalize_or_zero()).into(),
            SEGMENT_END_EPSILON,
            f32::INFINITY,
        );
        let nearest = (0..v.polygon_count())
            .map(|p| {
                let by_polygon = &v.rays_by_polygon;
                (
                    p,
                    by_polygon.intersect(by_polygon.get(p as u32).unwrap(), &ray),
                )
            })
            .filter(|(_, t)| t.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1));
        assert_eq!(
            fast.map(|(_, t)| t),
            nearest.map(|(_, t)| t),
            "{origin} along {direction}"
        );
        hits += fast.is_some() as u32;
    }
    assert!(hits > 500 && hits < 4500, "{hits}");
}

/// Shaft culling loses no blocker: for segments between random points
/// of two polygons, testing only the shaft's candidates answers exactly
/// as testing every polygon.
#[test]
fn shaft_candidates_agree_with_brute_force() {
    let mut stream = crate::testutil::Xorshift(0x1234_5678_9abc_def1);
    let mut rand = move || stream.unit_f32();
    let polygons: Vec<Polygon> = (0..80)
        .map(|_| square(rand() * 10.0, 0.3 + rand(), (rand() * 5.0, rand() * 5.0)))
        .collect();
    let s = scene(polygons);
    let v = Visibility::new(&s);
    let mut candidates = Vec::new();
    let (mut culled, mut blocked) = (0, 0);
    for _ in 0..300 {
        let (i, j) = ((rand() * 80.0) as usize % 80, (rand() * 80.0) as usize % 80);
        if i == j {
            continue;
        }
        let ends = (PolygonId(i as u32), PolygonId(j as u32));
        v.shaft_candidates(ends.0, ends.1, usize::MAX, &mut candidates);
        culled += 80 - 2 - candidates.len();
        let point_on = |p: &Polygon, u: f32, w: f32| {
            let q = &p.vertices;
            q[0] + (q[1] - q[0]) * u + (q[3] - q[0]) * w
        };
        for _ in 0..40 {
            let a = point_on(&s.polygons[i], rand(), rand());
            let b = point_on(&s.polygons[j], rand(), rand());
            let expect = v.occluded_brute_force(a, b, ends);
            assert_eq!(v.occluded_among(a, b, &candidates), expect);
            blocked += expect as u32;
        }
    }
    // The test means something: shafts do cull, and rays are blocked.
    assert!(
        culled > 300 * 40 && blocked > 100,
        "culled {culled}, blocked {blocked}"
    );
}

/// A candidate search with a limit gives the whole list when it is no
/// longer than the limit, and otherwise more than the limit, all of
/// them real candidates, in increasing order.
#[test]
fn shaft_candidates_stop_past_the_limit() {
    let mut stream = crate::testutil::Xorshift(0x0bad_5eed_1234_5678);
    let mut rand = move || stream.unit_f32();
    let polygons: Vec<Polygon> = (0..120)
        .map(|_| square(rand() * 10.0, 0.3 + rand(), (rand() * 5.0, rand() * 5.0)))
        .collect();
    let v = Visibility::new(&scene(polygons));
    let (mut all, mut some) = (Vec::new(), Vec::new());
    let (mut whole, mut cut) = (0, 0);
    for _ in 0..300 {
        let (i, j) = ((rand() * 120.0) as u32 % 120, (rand() * 120.0) as u32 % 120);
        let limit = (rand() * 12.0) as usize;
        let ends = (PolygonId(i), PolygonId(j));
        v.shaft_candidates(ends.0, ends.1, usize::MAX, &mut all);
        v.shaft_candidates(ends.0, ends.1, limit, &mut some);
        let from = v.blockers[i as usize].exact_bounds;
        let mut boxed = Vec::new();
        v.box_shaft_candidates(from, ends.1, usize::MAX, &mut boxed);
        let mut boxed_some = Vec::new();
        v.box_shaft_candidates(from, ends.1, limit, &mut boxed_some);
        for (all, some) in [(&all, &some), (&boxed, &boxed_some)] {
            if all.len() <= limit {
                assert_eq!(some, all);
                whole += 1;
            } else {
                assert!(some.len() > limit, "{} of {}", some.len(), all.len());
                assert!(some.windows(2).all(|w| w[0] < w[1]));
                assert!(some.iter().all(|p| all.binary_search(p).is_ok()));
                cut += 1;
            }
        }
    }
    // Both cases are exercised.
    assert!(whole > 50 && cut > 50, "whole {whole}, cut {cut}");
}

/// A sky's facets are not in the ray BVH: a ray that leaves the model
/// meets nothing (not a facet), a segment out to the enclosure is clear
/// unless the model blocks it, and every other first hit is the nearest
/// of the model's own polygons.
#[test]
fn the_skys_facets_block_nothing_and_are_never_hit() {
    let mut with_sky = testutil::floor_under_a_plate();
    let model = with_sky.polygons.len();
    with_sky.add_sky(crate::color::Rgb::splat(1.0)).unwrap();
    assert!(with_sky.polygons.len() > model);
    assert!(with_sky.polygons[model..].iter().all(|p| p.surface.sky));
    let v = Visibility::new(&with_sky);
    let without = Visibility::new(&testutil::floor_under_a_plate());
    let mut stream = crate::testutil::Xorshift(0x2545_f491_4f6c_dd1d);
    let mut rand = move || stream.unit_f32();
    let (lo, hi) = with_sky.bounds();
    let (mut left, mut blocked) = (0, 0);
    for _ in 0..2000 {
        let origin = lo + (hi - lo) * Vec3::new(rand(), rand(), rand());
        let direction = Vec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5);
        let hit = v.first_hit(origin, direction);
        assert_eq!(
            hit,
            without.first_hit(origin, direction),
            "{origin} {direction}"
        );
        if let Some((p, _)) = hit {
            assert!(p.index() < model);
        } else {
            left += 1;
        }
        // Out to well past the enclosure's facets.
        let far = origin + direction.normalize_or_zero() * 1e3 * (hi - lo).length();
        let ends = (PolygonId(0), PolygonId(0));
        let occluded = v.occluded(origin, far, ends);
        assert_eq!(occluded, without.occluded(origin, far, ends));
        blocked += occluded as u32;
    }
    assert!(left > 200 && blocked > 100, "{left} {blocked}");
}
