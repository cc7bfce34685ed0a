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
/// polygon index of each class, so they are deterministic. A class is a
/// connected set of the "within tolerance" relation, which is not
/// transitive: two planes a little more than the tolerance apart share a
/// class when a third lies between them.
///
/// Cost: `O(n)` hash operations for `n` polygons, however many share one
/// plane. Planes are binned in fine cells an eighth of the tolerance wide,
/// whose members are within tolerance of each other and so one class;
/// only cells are compared with cells (in coarse bins twice the tolerance
/// wide), by the boxes their members span, and member pairs are looked at
/// only for the rare two cells that are neither surely within tolerance nor
/// surely apart. Twenty thousand tiles of one floor are one fine cell, not
/// two hundred million pairs.
pub fn plane_classes(scene: &Scene) -> Vec<u32> {
    let extent = f64::from(scene.extent()).max(f64::MIN_POSITIVE);
    let planes: Vec<[f64; 4]> = scene
        .polygons
        .iter()
        .map(|p| {
            let (n, d) = canonical_plane(p);
            [n.x, n.y, n.z, d]
        })
        .collect();
    let tolerance = [
        PLANE_NORMAL_TOLERANCE,
        PLANE_NORMAL_TOLERANCE,
        PLANE_NORMAL_TOLERANCE,
        PLANE_OFFSET_TOLERANCE * extent,
    ];
    plane_components(&planes, tolerance)
}

/// The classes of [`plane_classes`] for planes given as `[nx, ny, nz, d]`:
/// two planes are joined when they differ by at most `tolerance[k]` in
/// every coordinate `k`. Numbered by each class's smallest index.
fn plane_components(planes: &[[f64; 4]], tolerance: [f64; 4]) -> Vec<u32> {
    type Key = [i64; 4];
    let key = |p: &[f64; 4], size: [f64; 4]| -> Key {
        std::array::from_fn(|k| (p[k] / size[k]).floor() as i64)
    };
    let within = |a: &[f64; 4], b: &[f64; 4]| (0..4).all(|k| (a[k] - b[k]).abs() <= tolerance[k]);
    // Fine cells: two planes in one differ by less than an eighth of the
    // tolerance in every coordinate.
    let fine_size = tolerance.map(|t| t / 8.0);
    let mut fine: HashMap<Key, u32> = HashMap::new();
    let mut members: Vec<Vec<u32>> = Vec::new();
    for (i, p) in planes.iter().enumerate() {
        let cell = *fine.entry(key(p, fine_size)).or_insert_with(|| {
            members.push(Vec::new());
            (members.len() - 1) as u32
        });
        members[cell as usize].push(i as u32);
    }
    let mut parent: Vec<u32> = (0..planes.len() as u32).collect();
    let union = |parent: &mut Vec<u32>, a: u32, b: u32| {
        let (ra, rb) = (root(parent, a), root(parent, b));
        parent[ra.max(rb) as usize] = ra.min(rb);
    };
    for cell in &members {
        for &i in &cell[1..] {
            union(&mut parent, cell[0], i);
        }
    }
    // The box each cell's members span.
    let spans: Vec<([f64; 4], [f64; 4])> = members
        .iter()
        .map(|cell| {
            cell.iter().fold(
                ([f64::INFINITY; 4], [f64::NEG_INFINITY; 4]),
                |(lo, hi), &i| {
                    let p = &planes[i as usize];
                    (
                        std::array::from_fn(|k| lo[k].min(p[k])),
                        std::array::from_fn(|k| hi[k].max(p[k])),
                    )
                },
            )
        })
        .collect();
    // Coarse bins of cells, by their lowest corner.
    let coarse_size = tolerance.map(|t| 2.0 * t);
    let mut coarse: HashMap<Key, Vec<u32>> = HashMap::new();
    for (c, (lo, _)) in spans.iter().enumerate() {
        coarse
            .entry(key(lo, coarse_size))
            .or_default()
            .push(c as u32);
    }
    for (a, (lo, hi)) in spans.iter().enumerate() {
        // A cell within reach has its lowest corner within the tolerance
        // of this cell's box, less the width of a fine cell.
        let range: [(i64, i64); 4] = std::array::from_fn(|k| {
            let cell = |x: f64| (x / coarse_size[k]).floor() as i64;
            (
                cell(lo[k] - tolerance[k] - fine_size[k]),
                cell(hi[k] + tolerance[k]),
            )
        });
        for x in range[0].0..=range[0].1 {
            for y in range[1].0..=range[1].1 {
                for z in range[2].0..=range[2].1 {
                    for w in range[3].0..=range[3].1 {
                        let Some(others) = coarse.get(&[x, y, z, w]) else {
                            continue;
                        };
                        for &b in others {
                            let b = b as usize;
                            if b >= a {
                                continue;
                            }
                            let (blo, bhi) = &spans[b];
                            let apart =
                                (0..4).any(|k| (blo[k] - hi[k]).max(lo[k] - bhi[k]) > tolerance[k]);
                            if apart {
                                continue;
                            }
                            let (ra, rb) = (members[a][0], members[b][0]);
                            if root(&mut parent, ra) == root(&mut parent, rb) {
                                continue;
                            }
                            let surely = (0..4)
                                .all(|k| (hi[k] - blo[k]).max(bhi[k] - lo[k]) <= tolerance[k]);
                            let joined = surely
                                || members[a].iter().any(|&i| {
                                    members[b]
                                        .iter()
                                        .any(|&j| within(&planes[i as usize], &planes[j as usize]))
                                });
                            if joined {
                                union(&mut parent, ra, rb);
                            }
                        }
                    }
                }
            }
        }
    }
    (0..planes.len() as u32)
        .map(|i| root(&mut parent, i))
        .collect()
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

    /// `n` × `n` square tiles 0.1 wide in the floor plane.
    fn floor_tiles(n: usize) -> Vec<Polygon> {
        (0..n * n)
            .map(|k| {
                let (x, z) = ((k % n) as f32 * 0.1, (k / n) as f32 * 0.1);
                testutil::polygon(
                    0,
                    &[
                        [x, 0.0, z],
                        [x, 0.0, z + 0.1],
                        [x + 0.1, 0.0, z + 0.1],
                        [x + 0.1, 0.0, z],
                    ],
                )
            })
            .collect()
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

    /// The classes by brute force: every pair compared.
    fn components_by_pairs(planes: &[[f64; 4]], tolerance: [f64; 4]) -> Vec<u32> {
        let mut parent: Vec<u32> = (0..planes.len() as u32).collect();
        for i in 0..planes.len() {
            for j in 0..i {
                if (0..4).all(|k| (planes[i][k] - planes[j][k]).abs() <= tolerance[k]) {
                    let (ri, rj) = (root(&mut parent, i as u32), root(&mut parent, j as u32));
                    parent[ri.max(rj) as usize] = ri.min(rj);
                }
            }
        }
        (0..planes.len() as u32)
            .map(|i| root(&mut parent, i))
            .collect()
    }

    #[test]
    fn classes_are_those_of_every_pair_compared() {
        // Planes in clusters a few tolerances wide, so that cells are
        // joined surely, by a member pair, or not at all, and chains of
        // planes each within tolerance of the next join across cells.
        let tolerance = [1e-3, 1e-3, 1e-3, 1e-2];
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for spread in [0.5, 2.0, 6.0, 30.0] {
            let mut planes = Vec::new();
            for cluster in 0..12 {
                let centre = [0.0, (cluster % 3) as f64 * 0.01, 1.0, cluster as f64 * 0.05];
                for _ in 0..40 {
                    planes.push(std::array::from_fn(|k| {
                        centre[k] + (unit() - 0.5) * spread * tolerance[k]
                    }));
                }
            }
            assert_eq!(
                plane_components(&planes, tolerance),
                components_by_pairs(&planes, tolerance),
                "spread {spread}"
            );
        }
    }

    #[test]
    fn many_tiles_of_one_floor_are_one_class() {
        // 40,000 tiles (8e8 pairs: `benches/visibility.rs` times it).
        let s = scene(floor_tiles(200));
        assert!(plane_classes(&s).iter().all(|&c| c == 0));
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
