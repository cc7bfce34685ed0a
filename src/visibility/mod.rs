//! Occlusion queries: is the segment between two points blocked by any
//! polygon of the scene?
//!
//! The scene's polygons go into a compressed wide BVH from `obvhs`, whose
//! traversal tests four child boxes at a time with SIMD. A shadow query is
//! an any-hit traversal that stops at the first blocker; on x86-64 CPUs
//! with SSE4.2 and POPCNT it runs a build of the search for those
//! instructions, chosen at run time (the same answers, a tenth faster on
//! large scenes). Polygons are
//! intersected whole (plane, then inside every edge), not as triangles: a
//! ray through the diagonal between two triangles of a split quad can slip
//! between them, and symmetric scenes put vertices exactly below such
//! diagonals. A polygon's ray test is laid out in the BVH's leaf order
//! (`ray_polygons.rs`), so a leaf's polygons are neighbours in memory.
//! The two polygons a segment joins are never counted as
//! blockers: a segment from a receiver vertex to a shooter sample touches
//! both.

mod query;
mod ray_polygons;
pub mod shaft;

pub use query::ShadowQuery;

use crate::scene::{self, PolygonId, Scene};
use glam::{DVec3, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::{Boundable, BvhBuildParams};
use ray_polygons::{RayPolygon, RayPolygonParts, RayPolygons};
use shaft::Shaft;
use std::ops::ControlFlow;
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

/// Shafts count anything this fraction of the scene's extent outside them
/// as inside, so that culling is conservative against the rounding of
/// `f32` geometry, [`BOX_PADDING`] and [`EDGE_TOLERANCE`].
pub const SHAFT_TOLERANCE: f64 = 1e-5;

/// Polygons within this fraction of the scene's extent of a blocker's
/// plane count as lying in it when deciding whether a segment between them
/// can cross that plane. Tiny, because a segment with both ends this close
/// to the plane runs along it; such segments join polygons that meet the
/// blocker's plane, where the cosine factors make their rays worthless.
pub const PLANE_SIDE_TOLERANCE: f64 = 1e-9;

/// A run of a candidate list: a range of its entries, all of one group of
/// nearby polygons, and the group's bounds `(min, max)` in scene units
/// (see [`Visibility::refine_candidates_in_runs`]).
pub type CandidateRun = (std::ops::Range<u32>, (DVec3, DVec3));

/// The polygon that last blocked one of a receiver's segments, which the
/// next query tries before any other (the shadow cache of Haines and
/// Greenberg's light buffer): the rays from one point to the samples of
/// a shooter mostly end on the same table top or chair back, and one
/// polygon test then stands for a traversal of the whole scene. Keep one
/// per receiving point; it only changes how fast an answer is found,
/// never the answer.
#[derive(Clone, Copy, Debug, Default)]
pub struct LastBlocker(Option<u32>);

/// A polygon prepared for the BVHs and the shaft tests (its ray test is
/// in [`RayPolygons`]).
struct Blocker {
    /// First vertex (a point of the plane).
    origin: Vec3A,
    /// Unit normal.
    normal: Vec3A,
    /// Padded bounds.
    bounds: Aabb,
    /// Its vertices, for shaft tests.
    vertices: Vec<DVec3>,
    /// Exact bounds of its vertices `(min, max)`, for building shafts.
    exact_bounds: (DVec3, DVec3),
}

impl Boundable for Blocker {
    fn aabb(&self) -> Aabb {
        self.bounds
    }
}

/// The scene's polygons in two BVHs: a compressed wide one for rays (the
/// sky's facets left out) and a binary one for shaft queries.
pub struct Visibility {
    bvh: Option<CwBvh>,
    regions: Option<Bvh2>,
    blockers: Vec<Blocker>,
    /// The ray tests, in the order of `bvh`'s primitives.
    rays: RayPolygons,
    /// The ray tests, slot `p` polygon `p`.
    rays_by_polygon: RayPolygons,
    /// Per polygon, its plane's number ([`scene::plane_classes`]): a
    /// polygon never blocks a segment from or to a polygon in its plane.
    planes: Vec<u32>,
    shaft_tolerance: f64,
    plane_side_tolerance: f64,
    /// The CPU has SSE4.2 and POPCNT ([`Visibility::traverse_sse42`]).
    #[cfg(target_arch = "x86_64")]
    sse42: bool,
}

impl Visibility {
    /// Builds the BVHs over the polygons of `scene` (the ray BVH over
    /// those that are not sky facets: [`Visibility::first_hit`] never
    /// returns one, and a segment is never blocked by one).
    pub fn new(scene: &Scene) -> Self {
        let pad = BOX_PADDING * scene.extent().max(f32::MIN_POSITIVE);
        let planes = scene::plane_classes(scene);
        let (blockers, parts): (Vec<Blocker>, Vec<RayPolygonParts>) = scene
            .polygons
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let plane = planes.get(i).copied().unwrap_or(i as u32);
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
                let vertices: Vec<DVec3> = p.vertices.iter().map(|v| v.as_dvec3()).collect();
                let exact_bounds = vertices
                    .iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                        (lo.min(v), hi.max(v))
                    });
                let blocker = Blocker {
                    origin: v[0],
                    normal,
                    bounds,
                    vertices,
                    exact_bounds,
                };
                let part = RayPolygonParts {
                    origin: v[0],
                    normal,
                    plane,
                    tolerance: EDGE_TOLERANCE * extent,
                    edges,
                };
                (blocker, part)
            })
            .unzip();
        // The sky's facets stay out of the ray BVH: they enclose the
        // model, so none stands between two points inside the enclosure,
        // and a ray that leaves the model has reached the sky whether it
        // meets a facet or nothing. In the BVH they only cost: every ray
        // that leaves the model wandered through the boxes of the facets
        // ahead of it (on `fortitude.obj` a sixth of the sky step).
        let traced: Vec<u32> = (0..blockers.len() as u32)
            .filter(|&i| !scene.polygons[i as usize].surface.sky)
            .collect();
        let boxes: Vec<Aabb> = traced
            .iter()
            .map(|&i| blockers[i as usize].bounds)
            .collect();
        let bvh = (!boxes.is_empty()).then(|| {
            let mut bvh = build_cwbvh(
                &boxes,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            );
            // The builder numbers the boxes it was given; the ray tests
            // are laid out by polygon.
            for p in &mut bvh.primitive_indices {
                *p = traced[*p as usize];
            }
            bvh
        });
        let regions = (!blockers.is_empty()).then(|| {
            build_bvh2(
                &blockers,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        });
        let rays = RayPolygons::new(
            &parts,
            bvh.as_ref().map_or(&[], |b| b.primitive_indices.as_slice()),
        );
        let rays_by_polygon = RayPolygons::new(&parts, &[]);
        Visibility {
            bvh,
            regions,
            blockers,
            rays,
            rays_by_polygon,
            planes,
            shaft_tolerance: SHAFT_TOLERANCE * f64::from(scene.extent()),
            plane_side_tolerance: PLANE_SIDE_TOLERANCE * f64::from(scene.extent()),
            #[cfg(target_arch = "x86_64")]
            sse42: std::is_x86_feature_detected!("sse4.2")
                && std::is_x86_feature_detected!("popcnt"),
        }
    }

    /// The polygons that may block a segment from any point of polygon
    /// `from` to any point of polygon `to` (those two excluded), by the
    /// shaft between their bounding boxes; written to `out` (cleared
    /// first) in increasing order. Polygons not listed block no such
    /// segment. The search stops once more than `limit` polygons are
    /// found: a list of at most `limit` is complete, a longer one is only
    /// some of the candidates (a caller that would not use so long a list
    /// then pays for no more of it; pass `usize::MAX` for all).
    pub fn shaft_candidates(
        &self,
        from: PolygonId,
        to: PolygonId,
        limit: usize,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let (Some(regions), Some(a), Some(b)) = (
            &self.regions,
            self.blockers.get(from.index()),
            self.blockers.get(to.index()),
        ) else {
            return;
        };
        let shaft = Shaft::between(a.exact_bounds, b.exact_bounds, self.shaft_tolerance);
        self.polygons_in_shaft(regions, &shaft, limit, out, |p, blocker| {
            !self.in_plane_of(p, (from, to))
                && shaft.may_overlap_points(blocker.vertices.iter().copied())
                && self.straddles(blocker, a.vertices.iter().chain(&b.vertices).copied())
        });
    }

    /// The polygons that may block a segment from any point of the box
    /// `from` (`(min, max)`, a cluster of shooting polygons) to any point
    /// of polygon `to`, by the shaft between their bounding boxes; written
    /// to `out` (cleared first) in increasing order. Unlike
    /// [`Visibility::shaft_candidates`] only `to` and the polygons in its
    /// plane are left out: the polygons inside the box are listed when they
    /// may block, and the ray test leaves out each segment's own shooter
    /// ([`Visibility::occluded_among_ends`]). At most `limit` as in
    /// [`Visibility::shaft_candidates`].
    pub fn box_shaft_candidates(
        &self,
        from: (DVec3, DVec3),
        to: PolygonId,
        limit: usize,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let (Some(regions), Some(b)) = (&self.regions, self.blockers.get(to.index())) else {
            return;
        };
        let shaft = Shaft::between(from, b.exact_bounds, self.shaft_tolerance);
        self.polygons_in_shaft(regions, &shaft, limit, out, |p, blocker| {
            !self.in_plane_of(p, (to, to))
                && shaft.may_overlap_points(blocker.vertices.iter().copied())
                && self.boxes_straddle(blocker, from, b.exact_bounds)
        });
    }

    /// Appends to `out` every polygon whose box the binary BVH `regions`
    /// finds overlapping `shaft` and that `keep` accepts (given its index
    /// and its blocker), sorted and without repeats, stopping once more
    /// than `limit` distinct polygons are listed. In a large room the
    /// shaft from the floor to a chair holds most of the scene: listing it
    /// all for every receiver made culling cost the square of the
    /// polygons per step, for lists too long to be used.
    fn polygons_in_shaft(
        &self,
        regions: &Bvh2,
        shaft: &Shaft,
        limit: usize,
        out: &mut Vec<u32>,
        keep: impl Fn(u32, &Blocker) -> bool,
    ) {
        // Stopped past the limit: the list is already sorted and deduped.
        let stopped = self.visit_regions(
            regions,
            |lo, hi| shaft.may_overlap_box(lo, hi),
            |p, blocker| {
                if keep(p, blocker) {
                    out.push(p);
                    if out.len() > limit {
                        out.sort_unstable();
                        out.dedup();
                        if out.len() > limit {
                            return ControlFlow::Break(());
                        }
                    }
                }
                ControlFlow::Continue(())
            },
        );
        if stopped.is_continue() {
            out.sort_unstable();
            out.dedup();
        }
    }

    /// True unless all `points` lie in one closed half-space of
    /// `blocker`'s plane (within [`PLANE_SIDE_TOLERANCE`]). A segment
    /// between two of them then cannot cross the blocker's plane except at
    /// an end, where hits are ignored anyway. This is what makes shafts
    /// useful in rooms: every wall touches the shaft between two other
    /// walls, but both lie on its front side.
    fn straddles(&self, blocker: &Blocker, points: impl Iterator<Item = DVec3>) -> bool {
        let n = blocker.normal.as_dvec3();
        let d = n.dot(blocker.origin.as_dvec3());
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in points {
            let s = n.dot(v) - d;
            lo = lo.min(s);
            hi = hi.max(s);
        }
        let eps = self.plane_side_tolerance;
        lo < -eps && hi > eps
    }

    /// Narrows `within` (candidates for a shooter and a receiver polygon,
    /// from [`Visibility::shaft_candidates`] or
    /// [`Visibility::box_shaft_candidates`]) to those that may block a
    /// segment from one of `from` (a group of shooter points) to one of
    /// `to` (a group of receiver points), using the thin shaft between the
    /// two groups' bounding boxes. `within` comes in runs: each run a range
    /// of it and the bounds `(min, max)` of its polygons (a cluster of a
    /// tessellated object, say). A run whose bounds miss the thin shaft is
    /// passed over whole, so a sphere of a thousand triangles beside the
    /// shaft costs one box test, not a thousand. Written to `out`, cleared
    /// first, in the order of `within`.
    pub fn refine_candidates_in_runs(
        &self,
        from: &[Vec3],
        to: &[Vec3],
        within: &[u32],
        runs: &[CandidateRun],
        out: &mut Vec<u32>,
    ) {
        out.clear();
        if from.is_empty() || to.is_empty() {
            return;
        }
        let bounds = |points: &[Vec3]| {
            points
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
                })
        };
        let (a, b) = (bounds(from), bounds(to));
        let shaft = Shaft::between(a, b, self.shaft_tolerance);
        for (range, (lo, hi)) in runs {
            let run = within
                .get(range.start as usize..range.end as usize)
                .unwrap_or(&[]);
            if run.len() > 1 && !shaft.may_overlap_box(*lo, *hi) {
                continue;
            }
            for &p in run {
                let Some(blocker) = self.blockers.get(p as usize) else {
                    continue;
                };
                let (lo, hi) = blocker.exact_bounds;
                if shaft.may_overlap_box(lo, hi)
                    && self.boxes_straddle(blocker, a, b)
                    && shaft.may_overlap_points(blocker.vertices.iter().copied())
                {
                    out.push(p);
                }
            }
        }
    }

    /// [`Visibility::straddles`] for the points of two boxes, from the
    /// boxes alone: false when both boxes lie in one closed half-space of
    /// the blocker's plane.
    fn boxes_straddle(&self, blocker: &Blocker, a: (DVec3, DVec3), b: (DVec3, DVec3)) -> bool {
        let n = blocker.normal.as_dvec3();
        let d = n.dot(blocker.origin.as_dvec3());
        // Lowest and highest n·x over a box: its corners picked by sign.
        let range = |(lo, hi): (DVec3, DVec3)| {
            let low = DVec3::select(n.cmpge(DVec3::ZERO), lo, hi);
            let high = DVec3::select(n.cmpge(DVec3::ZERO), hi, lo);
            (n.dot(low) - d, n.dot(high) - d)
        };
        let ((a_lo, a_hi), (b_lo, b_hi)) = (range(a), range(b));
        let eps = self.plane_side_tolerance;
        a_lo.min(b_lo) < -eps && a_hi.max(b_hi) > eps
    }

    /// True when some polygon other than `own`, and not in its plane,
    /// reaches into the box bounding the points `corners` and those
    /// points moved `depth` scene units along the unit `normal`, and has
    /// some vertex in front of `own`'s plane there (by the boxes of the
    /// polygons, so a slanted polygon near the box may count).
    pub fn crowds(&self, own: PolygonId, corners: &[Vec3], normal: Vec3, depth: f32) -> bool {
        let Some(regions) = &self.regions else {
            return false;
        };
        let n = normal.as_dvec3();
        let Some(&first) = corners.first() else {
            return false;
        };
        let (lo, hi) = corners
            .iter()
            .flat_map(|c| [c.as_dvec3(), c.as_dvec3() + n * f64::from(depth)])
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let tol = self.shaft_tolerance;
        let (lo, hi) = (lo - DVec3::splat(tol), hi + DVec3::splat(tol));
        let d = n.dot(first.as_dvec3());
        let overlaps = |a: DVec3, b: DVec3| a.cmple(hi).all() && b.cmpge(lo).all();
        self.visit_regions(regions, overlaps, |p, b| {
            let reaches = p != own.0
                && !self.coplanar(own, PolygonId(p))
                && overlaps(b.exact_bounds.0, b.exact_bounds.1)
                && b.vertices.iter().any(|v| n.dot(*v) - d > tol);
            if reaches {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .is_break()
    }

    /// Visits the polygons in the leaves of `regions` whose boxes
    /// `node_overlaps(min, max)` accepts (and their ancestors'), until
    /// `visit` breaks; returns whether it did.
    fn visit_regions(
        &self,
        regions: &Bvh2,
        node_overlaps: impl Fn(DVec3, DVec3) -> bool,
        mut visit: impl FnMut(u32, &Blocker) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let mut stack: Vec<u32> = vec![0];
        while let Some(k) = stack.pop() {
            let Some(node) = regions.nodes.get(k as usize) else {
                continue;
            };
            if !node_overlaps(node.aabb.min.as_dvec3(), node.aabb.max.as_dvec3()) {
                continue;
            }
            if node.prim_count == 0 {
                stack.push(node.first_index);
                stack.push(node.first_index + 1);
                continue;
            }
            let first = node.first_index as usize;
            for &p in regions
                .primitive_indices
                .get(first..first + node.prim_count as usize)
                .unwrap_or(&[])
            {
                visit(p, &self.blockers[p as usize])?;
            }
        }
        ControlFlow::Continue(())
    }

    /// True when one of the `candidates` (polygon indices) crosses the open
    /// segment from `a` to `b`: [`Visibility::occluded`] restricted to a
    /// list from [`Visibility::shaft_candidates`], testing each in turn.
    pub fn occluded_among(&self, a: Vec3, b: Vec3, candidates: &[u32]) -> bool {
        self.occluded_among_remembering(a, b, candidates, &mut LastBlocker::default())
    }

    /// [`Visibility::occluded_among`], trying `last` first and keeping in
    /// it the blocker found; `last` must only ever name blockers of
    /// segments between the same two polygons, so that the answer is the
    /// same.
    pub fn occluded_among_remembering(
        &self,
        a: Vec3,
        b: Vec3,
        candidates: &[u32],
        last: &mut LastBlocker,
    ) -> bool {
        let Some(ray) = segment_ray(a, b) else {
            return false;
        };
        let hits = |p: u32| self.hits(p, &ray);
        if last.0.is_some_and(hits) {
            return true;
        }
        let found = candidates.iter().copied().find(|&p| hits(p));
        if found.is_some() {
            last.0 = found;
        }
        found.is_some()
    }

    /// [`Visibility::occluded_among`] leaving out `ends` and the polygons
    /// in their planes, as [`Visibility::occluded`] does: for candidates
    /// from [`Visibility::box_shaft_candidates`], which may list the
    /// segment's own shooter.
    pub fn occluded_among_ends(
        &self,
        a: Vec3,
        b: Vec3,
        candidates: &[u32],
        ends: (PolygonId, PolygonId),
    ) -> bool {
        self.occluded_among_ends_remembering(a, b, candidates, ends, &mut LastBlocker::default())
    }

    /// [`Visibility::occluded_among_ends`], trying `last` first and
    /// keeping in it the blocker found. The answer is the same, as the
    /// candidates hold every polygon that can block such a segment.
    pub fn occluded_among_ends_remembering(
        &self,
        a: Vec3,
        b: Vec3,
        candidates: &[u32],
        ends: (PolygonId, PolygonId),
        last: &mut LastBlocker,
    ) -> bool {
        let Some(ray) = segment_ray(a, b) else {
            return false;
        };
        let planes = self.end_planes(ends);
        if last.0.is_some_and(|p| self.blocks(p, &ray, ends, planes)) {
            return true;
        }
        let found = candidates
            .iter()
            .copied()
            .find(|&p| self.blocks(p, &ray, ends, planes));
        if found.is_some() {
            last.0 = found;
        }
        found.is_some()
    }

    /// True when polygon `p` lies in the plane of one of `ends` (or is
    /// one of them): a segment from or to a point of that plane can meet
    /// it only at its end, so it never blocks.
    #[inline]
    fn in_plane_of(&self, p: u32, ends: (PolygonId, PolygonId)) -> bool {
        let own = self.planes.get(p as usize).copied().unwrap_or(p);
        let (a, b) = self.end_planes(ends);
        p == ends.0 .0 || p == ends.1 .0 || own == a || own == b
    }

    /// Whether polygon `p` crosses `ray` (false for an index out of
    /// range).
    #[inline]
    fn hits(&self, p: u32, ray: &Ray) -> bool {
        let by_polygon = &self.rays_by_polygon;
        by_polygon
            .get(p)
            .is_some_and(|e| by_polygon.intersect(e, ray).is_finite())
    }

    /// Whether polygon `p` crosses `ray` and is neither one of `ends` nor
    /// in the plane of one (their classes `planes`, from
    /// [`Visibility::end_planes`]); false for an index out of range.
    #[inline]
    fn blocks(&self, p: u32, ray: &Ray, ends: (PolygonId, PolygonId), planes: (u32, u32)) -> bool {
        let by_polygon = &self.rays_by_polygon;
        by_polygon.get(p).is_some_and(|e| {
            !Self::entry_in_plane_of(e, ends, planes) && by_polygon.intersect(e, ray).is_finite()
        })
    }

    /// [`Visibility::in_plane_of`] for a ray test, given the plane classes
    /// `planes` of `ends` (looked up once per ray).
    #[inline(always)]
    fn entry_in_plane_of(e: &RayPolygon, ends: (PolygonId, PolygonId), planes: (u32, u32)) -> bool {
        e.polygon == ends.0 .0
            || e.polygon == ends.1 .0
            || e.plane == planes.0
            || e.plane == planes.1
    }

    /// The plane classes of `ends`, as [`Visibility::in_plane_of`] reads
    /// them (a polygon out of range is its own class).
    #[inline]
    fn end_planes(&self, ends: (PolygonId, PolygonId)) -> (u32, u32) {
        let plane = |q: PolygonId| self.planes.get(q.index()).copied().unwrap_or(q.0);
        (plane(ends.0), plane(ends.1))
    }

    /// True when polygons `a` and `b` lie in one plane
    /// ([`scene::plane_classes`]), facing the same way or not: a point of
    /// one sees the other edge-on, so they exchange no light. (The exact
    /// near-field form factor of a source cell to a point lying inside
    /// it, in its plane, is not 0 but ±1: the two sides of a two-sided
    /// face would copy each other's light.)
    pub fn coplanar(&self, a: PolygonId, b: PolygonId) -> bool {
        match (self.planes.get(a.index()), self.planes.get(b.index())) {
            (Some(pa), Some(pb)) => pa == pb,
            _ => false,
        }
    }

    /// Number of polygons.
    pub fn polygon_count(&self) -> usize {
        self.blockers.len()
    }

    /// True when some polygon other than `ends.0` and `ends.1`, and not in
    /// the plane of either, crosses the
    /// open segment from `a` to `b` (ignoring hits within
    /// [`SEGMENT_END_EPSILON`] of either end).
    pub fn occluded(&self, a: Vec3, b: Vec3, ends: (PolygonId, PolygonId)) -> bool {
        self.occluded_remembering(a, b, ends, &mut LastBlocker::default())
    }

    /// [`Visibility::occluded`], trying `last` first and keeping in it the
    /// blocker found. The answer is the same: a blocker `last` names that
    /// crosses the segment is one the traversal would find.
    pub fn occluded_remembering(
        &self,
        a: Vec3,
        b: Vec3,
        ends: (PolygonId, PolygonId),
        last: &mut LastBlocker,
    ) -> bool {
        let Some(bvh) = &self.bvh else {
            return false;
        };
        let Some(ray) = segment_ray(a, b) else {
            return false;
        };
        let planes = self.end_planes(ends);
        if last.0.is_some_and(|p| self.blocks(p, &ray, ends, planes)) {
            return true;
        }
        #[cfg(target_arch = "x86_64")]
        if self.sse42 {
            // SAFETY: `sse42` is set only where the CPU reports the
            // features `traverse_sse42` is compiled for.
            return unsafe { self.traverse_sse42(bvh, ray, ends, planes, last) };
        }
        self.traverse(bvh, ray, ends, planes, last)
    }

    /// [`Visibility::traverse`] compiled for SSE4.2 and POPCNT: the wide
    /// BVH's child masks are counted by the instruction rather than by a
    /// bit trick in baseline x86-64, and its node boxes are decoded with
    /// SSE4.1's conversions (same answers, about a tenth less time per
    /// solve: `docs/performance.md`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse4.1,sse4.2,popcnt")]
    fn traverse_sse42(
        &self,
        bvh: &CwBvh,
        ray: Ray,
        ends: (PolygonId, PolygonId),
        planes: (u32, u32),
        last: &mut LastBlocker,
    ) -> bool {
        self.traverse(bvh, ray, ends, planes, last)
    }

    /// The BVH search of [`Visibility::occluded_remembering`] (`planes`:
    /// the plane classes of `ends`, [`Visibility::end_planes`]), keeping
    /// the blocker it finds in `last`.
    #[inline(always)]
    fn traverse(
        &self,
        bvh: &CwBvh,
        ray: Ray,
        ends: (PolygonId, PolygonId),
        planes: (u32, u32),
        last: &mut LastBlocker,
    ) -> bool {
        use glam::UVec2;
        // `CwBvh::ray_traverse_miss` spelled out with the crate's own
        // macro, whose parts are all inlined: a call to that function
        // would run its baseline build inside `traverse_sse42`.
        let mut state = bvh.new_traversal(ray.direction);
        let mut node;
        let mut found = None;
        'search: {
            obvhs::traverse!(
                bvh,
                node,
                state,
                node.intersect_ray(&ray, state.oct_inv4),
                {
                    let e = self.rays.at_slot(state.primitive_id);
                    if !Self::entry_in_plane_of(e, ends, planes)
                        && self.rays.intersect(e, &ray) < ray.tmax
                    {
                        found = Some(e.polygon);
                        break 'search;
                    }
                }
            );
        }
        if found.is_some() {
            last.0 = found;
        }
        found.is_some()
    }

    /// The nearest polygon that the ray from `origin` along `direction`
    /// (any non-zero length) crosses, beyond [`SEGMENT_END_EPSILON`] scene
    /// units, and the distance to it in scene units; `None` when the ray
    /// leaves the scene or `direction` is zero or not finite.
    pub fn first_hit(&self, origin: Vec3, direction: Vec3) -> Option<(PolygonId, f32)> {
        let bvh = self.bvh.as_ref()?;
        let d = direction.normalize_or_zero();
        if d == Vec3::ZERO || !origin.is_finite() {
            return None;
        }
        let ray = Ray::new(
            origin.into(),
            without_negative_zeros(d).into(),
            SEGMENT_END_EPSILON,
            f32::INFINITY,
        );
        let mut hit = obvhs::ray::RayHit::none();
        bvh.ray_traverse(ray, &mut hit, |ray, id| {
            self.rays.intersect(self.rays.at_slot(id as u32), ray)
        })
        .then(|| {
            (
                PolygonId(self.rays.at_slot(hit.primitive_id).polygon),
                hit.t,
            )
        })
    }

    /// The same answer as [`Visibility::occluded`] by testing every
    /// polygon: the reference the BVH is checked against.
    pub fn occluded_brute_force(&self, a: Vec3, b: Vec3, ends: (PolygonId, PolygonId)) -> bool {
        let Some(ray) = segment_ray(a, b) else {
            return false;
        };
        let planes = self.end_planes(ends);
        (0..self.blockers.len() as u32).any(|p| self.blocks(p, &ray, ends, planes))
    }
}

/// `v` with every `-0.0` component made `+0.0`. The wide BVH's box test
/// takes the sign of a direction component to pick the near slab, and a
/// negative zero (its reciprocal is `-inf`, met by `+inf` from the other
/// slab) makes it miss every box: a ray along `-x` written `(-1, -0, -0)`
/// would cross the whole scene unseen.
fn without_negative_zeros(v: Vec3) -> Vec3 {
    // IEEE 754: -0.0 + 0.0 == +0.0, and x + 0.0 == x for every other x.
    v + Vec3::ZERO
}

/// The segment as a ray with `t = 0` at `a` and `t = 1` at `b`; `None` for
/// a zero-length segment.
fn segment_ray(a: Vec3, b: Vec3) -> Option<Ray> {
    let d = without_negative_zeros(b - a);
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
mod tests;
