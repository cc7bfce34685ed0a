//! Element vertices hidden under a coplanar polygon laid over theirs.
//!
//! A rug lying on a floor, the lamp flush with a ceiling, the inside of a
//! two-sided box and the floor under it: two polygons in one plane, facing
//! the same way, overlap. Neither blocks the other's light (they are in one
//! plane, see `visibility`), so the floor's vertices under the rug receive
//! the light the rug receives there. Drawn, they are hidden under the rug
//! ([`crate::scene::draw_layers`]); but counted in the floor's unshot
//! power they would send that light out a second time: energy made from
//! nothing, and in a sealed cavity (a box's two-sided bottom on a floor)
//! light that goes round the two floors again and again.
//!
//! [`covered_vertices`] marks the vertices strictly inside a polygon laid
//! over theirs; the solver keeps their displayed radiosity (so Gouraud
//! shading along the rug's edge has no dark fringe) but leaves them out of
//! their polygon's unshot power. A vertex on the covering polygon's edge
//! (within [`COVER_EDGE_TOLERANCE`]) is not covered: half its area is in
//! the open.

use super::Mesh;
use crate::scene::{covered_by, plane_classes, Polygon, Scene};
use glam::DVec3;

/// A vertex counts as covered when it is inside the covering polygon by
/// more than this fraction of that polygon's longest extent
/// (dimensionless): far below any element, above the rounding of
/// positions computed from different corners.
pub const COVER_EDGE_TOLERANCE: f64 = 1e-6;

/// Per mesh vertex of `mesh` (built from `scene`): true when it lies
/// inside a coplanar polygon laid over its own (see the module docs).
/// Empty when no polygon covers another, so that callers can skip the
/// check.
pub fn covered_vertices(scene: &Scene, mesh: &Mesh) -> Vec<bool> {
    let over = covered_by(scene, &plane_classes(scene));
    if over.iter().all(Vec::is_empty) {
        return Vec::new();
    }
    let mut covered = vec![false; mesh.vertex_count()];
    for (p, above) in over.iter().enumerate() {
        let Some(pm) = mesh.polygons.get(p) else {
            continue;
        };
        for &q in above {
            let cover = Cover::new(&scene.polygons[q as usize]);
            for l in pm.vertices.clone() {
                let l = l as usize;
                covered[l] = covered[l] || cover.strictly_inside(mesh.positions[l].as_dvec3());
            }
        }
    }
    covered
}

/// A covering convex polygon, ready for many inside tests: its edges as
/// `(start, unit direction)`, its normal and its margin.
struct Cover {
    edges: Vec<(DVec3, DVec3)>,
    normal: DVec3,
    /// [`COVER_EDGE_TOLERANCE`] of its longest extent, scene units.
    margin: f64,
}

impl Cover {
    fn new(q: &Polygon) -> Self {
        let v: Vec<DVec3> = q.vertices.iter().map(|p| p.as_dvec3()).collect();
        let extent = v
            .iter()
            .flat_map(|a| v.iter().map(move |b| a.distance(*b)))
            .fold(0.0, f64::max);
        Cover {
            // A zero-length edge has no inside: its direction stays zero
            // and no point passes it.
            edges: (0..v.len())
                .map(|k| (v[k], (v[(k + 1) % v.len()] - v[k]).normalize_or_zero()))
                .collect(),
            normal: q.normal.as_dvec3(),
            margin: COVER_EDGE_TOLERANCE * extent,
        }
    }

    /// True when `x` (in the polygon's plane) is inside it by more than
    /// the margin.
    fn strictly_inside(&self, x: DVec3) -> bool {
        // Counter-clockwise from the front: inside is to the left.
        self.edges
            .iter()
            .all(|&(a, dir)| dir.cross(x - a).dot(self.normal) > self.margin)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{build, MeshOptions};
    use crate::testutil;

    fn square(x0: f32, x1: f32, y: f32, material: u32) -> Polygon {
        // Facing up (+y): counter-clockwise seen from above.
        testutil::polygon(
            material,
            &[[x0, y, x0], [x0, y, x1], [x1, y, x1], [x1, y, x0]],
        )
    }

    fn scene(polygons: Vec<Polygon>) -> Scene {
        testutil::scene(
            polygons,
            vec![
                testutil::grey("floor", 0.0, 0.5),
                testutil::grey("rug", 0.0, 0.5),
            ],
        )
    }

    #[test]
    fn the_floor_under_a_rug_is_covered_and_the_rug_is_not() {
        let s = scene(vec![square(0.0, 4.0, 0.0, 0), square(1.0, 3.0, 0.0, 1)]);
        assert!(s.polygons[0].normal.y > 0.99);
        let mesh = build(
            &s,
            &MeshOptions {
                lenmax: 0.25,
                inset: 0.0,
            },
        )
        .unwrap();
        let covered = covered_vertices(&s, &mesh);
        assert_eq!(covered.len(), mesh.vertex_count());
        let floor = &mesh.polygons[0];
        for l in floor.vertices.clone() {
            let p = mesh.positions[l as usize];
            let inside =
                p.x > 1.0 + 1e-3 && p.x < 3.0 - 1e-3 && p.z > 1.0 + 1e-3 && p.z < 3.0 - 1e-3;
            let outside =
                p.x < 1.0 - 1e-3 || p.x > 3.0 + 1e-3 || p.z < 1.0 - 1e-3 || p.z > 3.0 + 1e-3;
            if inside {
                assert!(covered[l as usize], "{p}");
            } else if outside {
                assert!(!covered[l as usize], "{p}");
            }
        }
        // The covered share is the rug's: 4 of 16 square units.
        let areas = mesh.vertex_areas();
        let hidden: f64 = floor
            .vertices
            .clone()
            .filter(|&l| covered[l as usize])
            .map(|l| areas[l as usize])
            .sum();
        assert!((hidden / 16.0 - 0.25).abs() < 0.05, "{hidden}");
        assert!(mesh.polygons[1]
            .vertices
            .clone()
            .all(|l| !covered[l as usize]));
    }

    #[test]
    fn nothing_covered_gives_an_empty_list() {
        // Side by side, and one above the other (another plane).
        let s = scene(vec![square(0.0, 1.0, 0.0, 0), square(2.0, 3.0, 0.0, 1)]);
        let mesh = build(
            &s,
            &MeshOptions {
                lenmax: 0.5,
                inset: 0.0,
            },
        )
        .unwrap();
        assert!(covered_vertices(&s, &mesh).is_empty());
        let s = scene(vec![square(0.0, 1.0, 0.0, 0), square(0.0, 1.0, 0.5, 1)]);
        let mesh = build(
            &s,
            &MeshOptions {
                lenmax: 0.5,
                inset: 0.0,
            },
        )
        .unwrap();
        assert!(covered_vertices(&s, &mesh).is_empty());
    }
}
