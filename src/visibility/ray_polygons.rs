//! The polygons as a ray test reads them, laid out in the order of the
//! wide BVH's leaves.
//!
//! A shadow ray's traversal spends most of its time waiting for memory.
//! A polygon tested in a leaf needs its plane, its plane class, its
//! tolerance and its edges; kept together with the shaft data (vertices
//! in `f64`, exact bounds) and with the edges in a vector of their own,
//! one test touched three or four cache lines scattered over the heap
//! (on `fortitude.obj`'s sky step a third of the traversal's time was in
//! the polygon tests, mostly in two loads). Here each polygon's test data
//! is one 64-byte entry, the entries are in the BVH's primitive order so
//! that the polygons of one leaf are neighbours, and the edges of all
//! polygons are one array in the same order. The arithmetic is the same
//! as before, so are the answers.

use glam::Vec3A;
use obvhs::ray::Ray;

/// One polygon's ray test: its plane, its plane class and where its edges
/// are in [`RayPolygons::edges`].
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
pub(super) struct RayPolygon {
    /// First vertex (a point of the plane), scene units.
    origin: Vec3A,
    /// Unit normal.
    normal: Vec3A,
    /// The polygon's index in the scene.
    pub(super) polygon: u32,
    /// Its plane's number ([`crate::scene::plane_classes`]).
    pub(super) plane: u32,
    /// How far outside an edge still counts as inside, scene units.
    tolerance: f32,
    /// Its first edge in [`RayPolygons::edges`].
    first_edge: u32,
    /// Its number of edges (edges of zero length left out).
    edge_count: u32,
}

/// The data of a polygon's test before it is laid out: `origin`, unit
/// `normal`, plane class, tolerance (scene units) and edges (start, unit
/// in-plane inward normal).
pub(super) struct RayPolygonParts {
    pub(super) origin: Vec3A,
    pub(super) normal: Vec3A,
    pub(super) plane: u32,
    pub(super) tolerance: f32,
    pub(super) edges: Vec<(Vec3A, Vec3A)>,
}

/// Every polygon's ray test, in a given order of slots. The visibility
/// keeps two: in the BVH's order for its traversal, and in the polygons'
/// own order for candidate lists (which are sorted by polygon, so a
/// list's tests are read in the order they lie in memory; reached through
/// a map from polygon to slot, testing every polygon took a quarter more
/// time).
pub(super) struct RayPolygons {
    /// By slot.
    entries: Vec<RayPolygon>,
    /// Every edge (start, unit in-plane inward normal), slot by slot.
    edges: Vec<(Vec3A, Vec3A)>,
}

impl RayPolygons {
    /// Lays out `parts` (by polygon index) in the order `order` (polygon
    /// indices, the BVH's primitive order: slot `k` is `order[k]`, repeats
    /// included), then every polygon `order` leaves out, so every polygon
    /// has a slot. An index of `order` out of range gets a slot whose test
    /// never hits.
    /// With an empty `order`, slot `p` is polygon `p`.
    pub(super) fn new(parts: &[RayPolygonParts], order: &[u32]) -> Self {
        let n = parts.len();
        let mut placed = vec![false; n];
        let mut sequence: Vec<u32> = Vec::with_capacity(order.len().max(n));
        for p in order.iter().copied().chain(0..n as u32) {
            match placed.get_mut(p as usize) {
                Some(seen) if !*seen => *seen = true,
                // A polygon already laid out: a repeat of `order` keeps
                // its slot; the tail lists only those left out.
                Some(_) if sequence.len() >= order.len() => continue,
                _ => {}
            }
            sequence.push(p);
        }
        let mut edges = Vec::with_capacity(parts.iter().map(|p| p.edges.len()).sum());
        let entries = sequence
            .iter()
            .map(|&p| {
                let Some(part) = parts.get(p as usize) else {
                    // A zero normal: no ray meets its plane.
                    return RayPolygon {
                        origin: Vec3A::ZERO,
                        normal: Vec3A::ZERO,
                        polygon: u32::MAX,
                        plane: u32::MAX,
                        tolerance: 0.0,
                        first_edge: edges.len() as u32,
                        edge_count: 0,
                    };
                };
                let first_edge = edges.len() as u32;
                edges.extend_from_slice(&part.edges);
                RayPolygon {
                    origin: part.origin,
                    normal: part.normal,
                    polygon: p,
                    plane: part.plane,
                    tolerance: part.tolerance,
                    first_edge,
                    edge_count: part.edges.len() as u32,
                }
            })
            .collect();
        RayPolygons { entries, edges }
    }

    /// The test in `slot` (a BVH primitive index); panics out of range.
    #[inline(always)]
    pub(super) fn at_slot(&self, slot: u32) -> &RayPolygon {
        &self.entries[slot as usize]
    }

    /// The test in `slot`, `None` out of range.
    #[inline]
    pub(super) fn get(&self, slot: u32) -> Option<&RayPolygon> {
        self.entries.get(slot as usize)
    }

    /// Every polygon's test, in slot order.
    #[cfg(test)]
    pub(super) fn iter(&self) -> impl Iterator<Item = &RayPolygon> {
        self.entries.iter()
    }

    /// `t` of the hit of `entry`'s polygon in `ray.tmin..=ray.tmax`, or
    /// infinity: the plane, then inside every edge (within the
    /// tolerance).
    #[inline(always)]
    pub(super) fn intersect(&self, entry: &RayPolygon, ray: &Ray) -> f32 {
        let denom = entry.normal.dot(ray.direction);
        if denom == 0.0 {
            return f32::INFINITY;
        }
        let t = entry.normal.dot(entry.origin - ray.origin) / denom;
        if !(t >= ray.tmin && t <= ray.tmax) {
            return f32::INFINITY;
        }
        let p = ray.origin + t * ray.direction;
        let first = entry.first_edge as usize;
        let edges = self
            .edges
            .get(first..first + entry.edge_count as usize)
            .unwrap_or(&[]);
        for &(start, inward) in edges {
            if inward.dot(p - start) < -entry.tolerance {
                return f32::INFINITY;
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_square(z: f32, plane: u32) -> RayPolygonParts {
        let v = [
            Vec3A::new(0.0, 0.0, z),
            Vec3A::new(1.0, 0.0, z),
            Vec3A::new(1.0, 1.0, z),
            Vec3A::new(0.0, 1.0, z),
        ];
        RayPolygonParts {
            origin: v[0],
            normal: Vec3A::Z,
            plane,
            tolerance: 0.0,
            edges: (0..4)
                .map(|k| (v[k], Vec3A::Z.cross(v[(k + 1) % 4] - v[k]).normalize()))
                .collect(),
        }
    }

    /// Every slot of the order given is its polygon's, then come the
    /// polygons it leaves out; each polygon's test is its own.
    #[test]
    fn every_polygon_has_one_slot_and_keeps_its_test() {
        let parts: Vec<_> = (0..4).map(|k| unit_square(k as f32, 10 + k)).collect();
        // 7 is out of range and 2 repeated; 3 is left out.
        let rp = RayPolygons::new(&parts, &[2, 0, 7, 2, 1]);
        let by_slot: Vec<u32> = rp.iter().map(|e| e.polygon).collect();
        assert_eq!(by_slot, [2, 0, u32::MAX, 2, 1, 3]);
        let up = Ray::new(Vec3A::new(0.5, 0.5, -1.0), Vec3A::Z, 0.0, f32::INFINITY);
        assert_eq!(rp.intersect(rp.at_slot(2), &up), f32::INFINITY);
        let by_polygon = RayPolygons::new(&parts, &[]);
        for p in 0..4 {
            let e = by_polygon.get(p).unwrap();
            assert_eq!(e.polygon, rp.at_slot([1, 4, 0, 5][p as usize]).polygon);
            assert_eq!((e.polygon, e.plane), (p, 10 + p));
            // A ray up through the square's middle from below z = 0
            // crosses the plane z = p at t = p + 1.
            let ray = Ray::new(Vec3A::new(0.5, 0.5, -1.0), Vec3A::Z, 0.0, f32::INFINITY);
            assert_eq!(rp.intersect(e, &ray), p as f32 + 1.0);
            let beside = Ray::new(Vec3A::new(1.5, 0.5, -1.0), Vec3A::Z, 0.0, f32::INFINITY);
            assert_eq!(rp.intersect(e, &beside), f32::INFINITY);
        }
        assert!(by_polygon.get(4).is_none());
    }
}
