//! Occlusion queries: is the segment between two points blocked by any
//! polygon of the scene?
//!
//! The scene's polygons go into a compressed wide BVH from `obvhs`, whose
//! traversal tests four child boxes at a time with SIMD. A shadow query is
//! an any-hit traversal that stops at the first blocker. Polygons are
//! intersected whole (plane, then inside every edge), not as triangles: a
//! ray through the diagonal between two triangles of a split quad can slip
//! between them, and symmetric scenes put vertices exactly below such
//! diagonals. The two polygons a segment joins are never counted as
//! blockers: a segment from a receiver vertex to a shooter sample touches
//! both.

use crate::scene::{PolygonId, Scene};
use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::{Boundable, BvhBuildParams};
use std::time::Duration;

/// Hits closer to either end of a segment than this fraction of its length
/// are ignored. A receiver vertex sits on (or, inset, just off) its own
/// polygon and often on an edge shared with a neighbour, such as a table
/// leg meeting the floor; a hit within a millionth of the segment of an end
/// is that contact, not a shadow.
pub const SEGMENT_END_EPSILON: f32 = 1e-6;

/// A hit point counts as inside a polygon when it is no further outside
/// any edge than this fraction of the polygon's extent. Slightly positive,
/// so a ray through an edge shared by two polygons (a box's corner) hits
/// at least one of them instead of leaking through the crack.
pub const EDGE_TOLERANCE: f32 = 1e-6;

/// Every polygon's bounding box grows by this fraction of the scene's
/// extent before the BVH is built. Walls are axis-aligned, so their boxes
/// are flat; a little thickness keeps the quantised node boxes
/// conservative.
pub const BOX_PADDING: f32 = 1e-5;

/// A polygon prepared for ray tests.
struct Blocker {
    /// First vertex (a point of the plane).
    origin: Vec3A,
    /// Unit normal.
    normal: Vec3A,
    /// Per edge: its start and its unit in-plane inward normal.
    edges: Vec<(Vec3A, Vec3A)>,
    /// How far outside an edge still counts as inside, in scene units.
    tolerance: f32,
    /// Padded bounds.
    bounds: Aabb,
}

impl Boundable for Blocker {
    fn aabb(&self) -> Aabb {
        self.bounds
    }
}

impl Blocker {
    /// `t` of the hit in `ray.tmin..=ray.tmax`, or infinity.
    #[inline]
    fn intersect(&self, ray: &Ray) -> f32 {
        let denom = self.normal.dot(ray.direction);
        if denom == 0.0 {
            return f32::INFINITY;
        }
        let t = self.normal.dot(self.origin - ray.origin) / denom;
        if !(t >= ray.tmin && t <= ray.tmax) {
            return f32::INFINITY;
        }
        let p = ray.origin + t * ray.direction;
        for &(start, inward) in &self.edges {
            if inward.dot(p - start) < -self.tolerance {
                return f32::INFINITY;
            }
        }
        t
    }
}

/// The scene's polygons in a BVH.
pub struct Visibility {
    bvh: Option<CwBvh>,
    blockers: Vec<Blocker>,
}

impl Visibility {
    /// Builds the BVH over every polygon of `scene`.
    pub fn new(scene: &Scene) -> Self {
        let pad = BOX_PADDING * scene.extent().max(f32::MIN_POSITIVE);
        let blockers: Vec<Blocker> = scene
            .polygons
            .iter()
            .map(|p| {
                let v: Vec<Vec3A> = p.vertices.iter().map(|&v| v.into()).collect();
                let normal = Vec3A::from(p.normal);
                let mut bounds = Aabb::from_points(&v);
                bounds.min -= Vec3A::splat(pad);
                bounds.max += Vec3A::splat(pad);
                let extent = (bounds.max - bounds.min).length();
                let edges = (0..v.len())
                    .filter_map(|k| {
                        let dir = v[(k + 1) % v.len()] - v[k];
                        let inward = normal.cross(dir).normalize_or_zero();
                        (inward != Vec3A::ZERO).then_some((v[k], inward))
                    })
                    .collect();
                Blocker {
                    origin: v[0],
                    normal,
                    edges,
                    tolerance: EDGE_TOLERANCE * extent,
                    bounds,
                }
            })
            .collect();
        let bvh = (!blockers.is_empty()).then(|| {
            build_cwbvh(
                &blockers,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        });
        Visibility { bvh, blockers }
    }

    /// True when some polygon other than `ends.0` and `ends.1` crosses the
    /// open segment from `a` to `b` (ignoring hits within
    /// [`SEGMENT_END_EPSILON`] of either end).
    pub fn occluded(&self, a: Vec3, b: Vec3, ends: (PolygonId, PolygonId)) -> bool {
        let Some(bvh) = &self.bvh else {
            return false;
        };
        let Some(ray) = segment_ray(a, b) else {
            return false;
        };
        !bvh.ray_traverse_miss(ray, |ray, id| {
            let p = bvh.primitive_indices[id];
            if p == ends.0 .0 || p == ends.1 .0 {
                f32::INFINITY
            } else {
                self.blockers[p as usize].intersect(ray)
            }
        })
    }

    /// The same answer as [`Visibility::occluded`] by testing every
    /// polygon: the reference the BVH is checked against.
    pub fn occluded_brute_force(&self, a: Vec3, b: Vec3, ends: (PolygonId, PolygonId)) -> bool {
        let Some(ray) = segment_ray(a, b) else {
            return false;
        };
        self.blockers.iter().enumerate().any(|(p, blocker)| {
            let p = p as u32;
            p != ends.0 .0 && p != ends.1 .0 && blocker.intersect(&ray).is_finite()
        })
    }
}

/// The segment as a ray with `t = 0` at `a` and `t = 1` at `b`; `None` for
/// a zero-length segment.
fn segment_ray(a: Vec3, b: Vec3) -> Option<Ray> {
    let d = b - a;
    (d != Vec3::ZERO).then(|| {
        Ray::new(
            a.into(),
            d.into(),
            SEGMENT_END_EPSILON,
            1.0 - SEGMENT_END_EPSILON,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{MaterialId, Polygon, Shape, SourcePos};
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
        }
    }

    fn scene(polygons: Vec<Polygon>) -> Scene {
        testutil::scene(polygons, vec![testutil::grey("m", 0.0, 0.5)])
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

    /// The BVH answers exactly as testing every triangle does, on a field
    /// of scattered squares and many pseudo-random segments.
    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        let polygons: Vec<Polygon> = (0..60)
            .map(|_| square(rand() * 10.0, 0.3 + rand(), (rand() * 5.0, rand() * 5.0)))
            .collect();
        let v = Visibility::new(&scene(polygons));
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
            blocked += fast as u32;
        }
        // Both outcomes are exercised.
        assert!(blocked > 500 && blocked < 4500, "{blocked}");
    }
}
