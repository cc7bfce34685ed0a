//! Polygons in one plane: they never block each other, and where they
//! overlap the picture shows one of them deterministically.
//!
//! A segment that leaves a point of a plane can meet that plane again only
//! at its start, so a polygon lying in the plane of a segment's end cannot
//! block it: the two sides of a two-sided face, a rug on a floor and a
//! lamp flush with a ceiling would otherwise shadow each other wherever
//! `f32` rounding puts the hit a hair past the segment's start.
//! [`plane_classes`] numbers the planes (polygons whose planes coincide
//! within [`PLANE_NORMAL_TOLERANCE`] and [`PLANE_OFFSET_TOLERANCE`], facing
//! either way, share a class) so the visibility tests can skip them.
//!
//! Overlapping coplanar polygons that face the same way would z-fight in
//! the picture, each winning the pixels where rounding favours it.
//! [`draw_layers`] stacks them: a polygon is drawn one layer above every
//! earlier one it overlaps, and an emitter above every non-emitter it
//! overlaps, so the later in the file, or the emitter, is on top.

use crate::scene::{Polygon, Scene};
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// Two planes are one when their unit normals (the second flipped if they
/// face apart) differ by at most this much in every component: about
/// 0.06°, far above the rounding of a normal computed from `f32` vertices
/// of any polygon that is not a sliver.
pub const PLANE_NORMAL_TOLERANCE: f64 = 1e-3;

/// ... and their distances from the origin by at most this fraction of the
/// scene's extent: well above `f32` rounding of coordinates (6e-8
/// relative), well below any gap a model means (a rug 1 mm thick on a 10 m
/// floor is 1e-4).
pub const PLANE_OFFSET_TOLERANCE: f64 = 1e-5;

/// The most layers [`draw_layers`] stacks; a deeper stack shares the top.
pub const MAX_DRAW_LAYER: u8 = 7;

/// Overlap below this fraction of the smaller polygon's extent (squared
/// for areas) is a shared edge or corner, not an overlap.
const OVERLAP_TOLERANCE: f64 = 1e-6;

/// The plane of a polygon as a normal with a canonical sign (its largest
/// component positive) and the offset along it.
fn canonical_plane(p: &Polygon) -> (DVec3, f64) {
    let n = p.normal.as_dvec3();
    let largest = if n.x.abs() >= n.y.abs() && n.x.abs() >= n.z.abs() {
        n.x
    } else if n.y.abs() >= n.z.abs() {
        n.y
    } else {
        n.z
    };
    let n = if largest < 0.0 { -n } else { n };
    let d = p.vertices.iter().map(|v| n.dot(v.as_dvec3())).sum::<f64>() / p.vertices.len() as f64;
    (n, d)
}

/// Union-find root with path halving.
fn root(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        parent[i as usize] = parent[parent[i as usize] as usize];
        i = parent[i as usize];
    }
    i
}

/// One number per polygon: equal for polygons whose planes coincide (see
/// the module docs), facing either way. The numbers are the smallest
/// polygon index of each class, so they are deterministic.
///
/// Cost: one hash insertion and at most 16 look-ups per polygon (each
/// plane is binned in cells twice the tolerance wide, and looked up in the
/// cells its tolerance box touches).
pub fn plane_classes(scene: &Scene) -> Vec<u32> {
    let n = scene.polygons.len();
    let extent = f64::from(scene.extent()).max(f64::MIN_POSITIVE);
    let (cell_n, cell_d) = (
        2.0 * PLANE_NORMAL_TOLERANCE,
        2.0 * PLANE_OFFSET_TOLERANCE * extent,
    );
    let planes: Vec<(DVec3, f64)> = scene.polygons.iter().map(canonical_plane).collect();
    let cell = |x: f64, size: f64| (x / size).floor() as i64;
    let mut bins: HashMap<[i64; 4], Vec<u32>> = HashMap::new();
    for (i, &(normal, d)) in planes.iter().enumerate() {
        let key = [
            cell(normal.x, cell_n),
            cell(normal.y, cell_n),
            cell(normal.z, cell_n),
            cell(d, cell_d),
        ];
        bins.entry(key).or_default().push(i as u32);
    }
    let mut parent: Vec<u32> = (0..n as u32).collect();
    let same = |a: (DVec3, f64), b: (DVec3, f64)| {
        (a.0 - b.0).abs().max_element() <= PLANE_NORMAL_TOLERANCE
            && (a.1 - b.1).abs() <= PLANE_OFFSET_TOLERANCE * extent
    };
    for (i, &(normal, d)) in planes.iter().enumerate() {
        // The cells within tolerance of this plane: at most two per axis.
        let range = |x: f64, size: f64, tol: f64| (cell(x - tol, size), cell(x + tol, size));
        let axes = [
            range(normal.x, cell_n, PLANE_NORMAL_TOLERANCE),
            range(normal.y, cell_n, PLANE_NORMAL_TOLERANCE),
            range(normal.z, cell_n, PLANE_NORMAL_TOLERANCE),
            range(d, cell_d, PLANE_OFFSET_TOLERANCE * extent),
        ];
        for a in axes[0].0..=axes[0].1 {
            for b in axes[1].0..=axes[1].1 {
                for c in axes[2].0..=axes[2].1 {
                    for e in axes[3].0..=axes[3].1 {
                        let Some(others) = bins.get(&[a, b, c, e]) else {
                            continue;
                        };
                        for &j in others {
                            if (j as usize) < i && same(planes[i], planes[j as usize]) {
                                let (ri, rj) = (root(&mut parent, i as u32), root(&mut parent, j));
                                parent[ri.max(rj) as usize] = ri.min(rj);
                            }
                        }
                    }
                }
            }
        }
    }
    (0..n as u32).map(|i| root(&mut parent, i)).collect()
}

/// The polygon's vertices in 2-D coordinates of a plane with unit normal
/// `n` (shared by every polygon of a class, so the coordinates agree).
fn in_plane(p: &Polygon, n: DVec3) -> Vec<DVec2> {
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    p.vertices
        .iter()
        .map(|x| DVec2::new(u.dot(x.as_dvec3()), v.dot(x.as_dvec3())))
        .collect()
}

/// True when two convex 2-D polygons overlap by more than `tolerance`
/// along every separating-axis candidate (their edge normals).
fn convex_overlap(a: &[DVec2], b: &[DVec2], tolerance: f64) -> bool {
    let separated_along = |poly: &[DVec2]| {
        (0..poly.len()).any(|k| {
            let e = poly[(k + 1) % poly.len()] - poly[k];
            let axis = DVec2::new(-e.y, e.x).normalize_or_zero();
            if axis == DVec2::ZERO {
                return false;
            }
            let span = |q: &[DVec2]| {
                q.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        let s = axis.dot(*x);
                        (lo.min(s), hi.max(s))
                    })
            };
            let ((alo, ahi), (blo, bhi)) = (span(a), span(b));
            ahi.min(bhi) - alo.max(blo) <= tolerance
        })
    };
    !separated_along(a) && !separated_along(b)
}

/// The plane classes of two or more polygons, each as its polygons' scene
/// indices in the order they are laid down: non-emitters first, then
/// emitters, each in scene order. Classes in a fixed order.
fn class_members(scene: &Scene, classes: &[u32]) -> Vec<Vec<usize>> {
    let mut by_class: HashMap<u32, Vec<usize>> = HashMap::new();
    for (i, &c) in classes.iter().enumerate() {
        by_class.entry(c).or_default().push(i);
    }
    let emits = |i: usize| {
        scene
            .material_of(crate::scene::PolygonId(i as u32))
            .emission()
            .max_channel()
            > 0.0
    };
    let mut all: Vec<Vec<usize>> = by_class.into_values().filter(|m| m.len() > 1).collect();
    all.sort_unstable();
    for members in &mut all {
        members.sort_by_key(|&i| (emits(i), i));
    }
    all
}

/// For polygons of one plane class, `members` (scene indices, at least
/// two) in the order they are laid down: for each, the positions in
/// `members` of the earlier ones it overlaps facing the same way, which
/// it covers.
fn laid_over(scene: &Scene, members: &[usize]) -> Vec<Vec<usize>> {
    let normal = canonical_plane(&scene.polygons[members[0]]).0;
    let flat: Vec<Vec<DVec2>> = members
        .iter()
        .map(|&i| in_plane(&scene.polygons[i], normal))
        .collect();
    // Bounding boxes in the plane, for a sweep along the first axis.
    let boxes: Vec<(DVec2, DVec2)> = flat
        .iter()
        .map(|q| {
            q.iter()
                .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(*x), hi.max(*x))
                })
        })
        .collect();
    let mut order: Vec<usize> = (0..members.len()).collect();
    order.sort_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x));
    // Pairs whose boxes overlap, found by the sweep.
    let mut below: Vec<Vec<usize>> = vec![Vec::new(); members.len()];
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if boxes[b].0.x >= boxes[a].1.x {
                break;
            }
            let (pa, pb) = (&scene.polygons[members[a]], &scene.polygons[members[b]]);
            let same_facing = pa.normal.dot(pb.normal) > 0.0;
            let size = (boxes[a].1 - boxes[a].0)
                .max_element()
                .min((boxes[b].1 - boxes[b].0).max_element());
            let boxes_meet = boxes[a].0.y < boxes[b].1.y && boxes[b].0.y < boxes[a].1.y;
            if same_facing
                && boxes_meet
                && convex_overlap(&flat[a], &flat[b], OVERLAP_TOLERANCE * size)
            {
                // The one laid down later covers the other.
                let (lower, upper) = if a < b { (a, b) } else { (b, a) };
                below[upper].push(lower);
            }
        }
    }
    below
}

/// The draw layer of every polygon (see the module docs): 0 for a polygon
/// that overlaps no earlier coplanar polygon facing its way; otherwise one
/// more than the highest layer among the coplanar polygons it covers,
/// capped at [`MAX_DRAW_LAYER`]. "Covers": it overlaps them and comes later
/// in the scene, or it emits and they do not.
///
/// `classes` is [`plane_classes`] of the same scene.
pub fn draw_layers(scene: &Scene, classes: &[u32]) -> Vec<u8> {
    let mut layers = vec![0u8; scene.polygons.len()];
    for members in class_members(scene, classes) {
        let below = laid_over(scene, &members);
        for k in 0..members.len() {
            let top = below[k]
                .iter()
                .map(|&j| layers[members[j]] + 1)
                .max()
                .unwrap_or(0);
            layers[members[k]] = top.min(MAX_DRAW_LAYER);
        }
    }
    layers
}

/// For every polygon, the coplanar polygons laid over it (see
/// [`draw_layers`]): they overlap it, face its way, and come later in the
/// scene or emit where it does not. Where they cover it, it is hidden: it
/// still shows a radiosity under them, but a receiver there would count
/// the light they intercept a second time (a rug and the floor under it,
/// the inside of a box and the floor it stands on, both catching the same
/// light), so the solver leaves the covered part out of its unshot power
/// (see `mesh::covered_vertices`).
///
/// `classes` is [`plane_classes`] of the same scene.
pub fn covered_by(scene: &Scene, classes: &[u32]) -> Vec<Vec<u32>> {
    let mut over = vec![Vec::new(); scene.polygons.len()];
    for members in class_members(scene, classes) {
        let below = laid_over(scene, &members);
        for (upper, lowers) in below.iter().enumerate() {
            for &lower in lowers {
                over[members[lower]].push(members[upper] as u32);
            }
        }
    }
    over
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil;

    fn rect(x0: f32, x1: f32, z: f32, material: u32) -> Polygon {
        testutil::polygon(
            material,
            &[[x0, 0.0, z], [x1, 0.0, z], [x1, 1.0, z], [x0, 1.0, z]],
        )
    }

    fn scene(polygons: Vec<Polygon>) -> Scene {
        testutil::scene(
            polygons,
            vec![
                testutil::grey("floor", 0.0, 0.5),
                testutil::grey("lamp", 1.0, 0.5),
            ],
        )
    }

    #[test]
    fn coplanar_polygons_share_a_class_whichever_way_they_face() {
        let mut flipped = rect(5.0, 6.0, 0.0, 0);
        flipped.vertices.reverse();
        flipped.normal = -flipped.normal;
        let s = scene(vec![
            rect(0.0, 1.0, 0.0, 0),
            rect(0.0, 1.0, 0.5, 0),
            flipped,
            // Off the plane by rounding only.
            rect(0.2, 0.4, 1e-7, 0),
        ]);
        assert_eq!(plane_classes(&s), vec![0, 1, 0, 0]);
    }

    #[test]
    fn a_rug_is_drawn_over_the_floor_and_a_lamp_over_both() {
        // File order: lamp, floor, rug, a tile beside the floor.
        let s = scene(vec![
            rect(0.4, 0.6, 0.0, 1),
            rect(0.0, 1.0, 0.0, 0),
            rect(0.2, 0.8, 0.0, 0),
            rect(1.0, 2.0, 0.0, 0),
        ]);
        let classes = plane_classes(&s);
        assert_eq!(draw_layers(&s, &classes), vec![2, 0, 1, 0]);
    }

    #[test]
    fn opposite_faces_do_not_stack() {
        let mut back = rect(0.0, 1.0, 0.0, 0);
        back.vertices.reverse();
        back.normal = -back.normal;
        let s = scene(vec![rect(0.0, 1.0, 0.0, 0), back]);
        let classes = plane_classes(&s);
        assert_eq!(draw_layers(&s, &classes), vec![0, 0]);
    }
}
