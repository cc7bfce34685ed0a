//! Back sides that no light can reach.
//!
//! An OBJ face is read as two-sided, and a glTF face of a `doubleSided`
//! material too, so each gets a back copy ([`super::sides`]) that the
//! solver meshes, lights and steps over like any polygon. In a game level
//! exported face by face (Sauerbraten's and Red Eclipse's `/writeobj`, a
//! Blender conversion of one) every face is a wall between air and solid
//! rock, and its back looks into the rock: on `zdm2.obj` half of the
//! 148,000 polygons and of the 450,000 element vertices were such backs,
//! and each sky facet cast its probe rays from every one of them.
//!
//! [`reached_backs`] finds which backs light can reach. Every side of
//! every polygon casts [`PROBE_RAYS`] rays over its hemisphere (cosine
//! spread, from points spread over the face), and each ray joins the side
//! it starts from to the side it meets (the front of the polygon it hits
//! when it hits it from the front, its back when that side exists), or to
//! the *outside* when it leaves the scene. Light passes only between
//! sides joined this way, so it reaches exactly the sides joined, through
//! any chain, to a side that emits, or to the outside under `--sky`.
//! A back joined to neither is left out; the front stays whatever it
//! sees. Visibility is symmetric, so a side in a lit room is joined to it
//! by its own rays and by the room's rays that meet it: a missed link
//! takes every one of a side's rays missing every lit side, and then the
//! side could only see light through gaps narrower than the spacing of
//! its rays.
//!
//! Nothing is left out when nothing emits and there is no sky (the
//! picture is black anyway and the model is only being looked at), nor
//! with `--two-sided`, which asks for every back.

use super::FirstHit;
use crate::cancel::{Cancel, Cancelled};
use crate::scene::{Polygon, Scene};
use glam::Vec3;
use rayon::prelude::*;

/// Rays each side casts: a 4 × 4 stratified grid over its hemisphere,
/// cosine-weighted, each from its own point of the face.
pub const PROBE_RAYS: usize = 16;

/// How far off its face a probe ray starts, as a share of the face's
/// largest distance from its centroid: clear of the face and of a
/// coplanar twin, far below any gap that matters.
const LIFT_SHARE: f32 = 1e-4;

/// Polygons per parallel run of probe rays.
const RUN: usize = 64;

/// Polygons whose probe rays are cast before they are joined.
const BLOCK: usize = 1 << 16;

/// Per polygon of `scene`, whether its back side can be reached by light:
/// `back[i]` is consulted only for the polygons that would get a back
/// copy (`two_sided[i]`). Every entry is `true` when nothing emits and
/// `sky` is false. `rays` casts into `scene` as it is (no back copies, no
/// sky). Polygons are joined as the module docs say. Stops with
/// [`Cancelled`] soon after `cancel` is set (checked per block of
/// 65,536 polygons).
pub fn reached_backs<R: FirstHit + Sync>(
    scene: &Scene,
    two_sided: &[bool],
    sky: bool,
    rays: &R,
    cancel: &Cancel,
) -> Result<Vec<bool>, Cancelled> {
    let n = scene.polygons.len();
    let emits: Vec<bool> = scene
        .polygons
        .iter()
        .map(|p| {
            scene.materials[p.material.index()].emission().max_channel() > 0.0
                || scene.luminaire_of(p.material).is_some()
        })
        .collect();
    if !sky && !emits.iter().any(|&e| e) {
        return Ok(vec![true; n]);
    }
    let outside = 2 * n;
    // The node of the side of polygon `q` that a ray meets, when light can
    // leave from it: its front, its written-out reversed twin's front, or
    // its back copy.
    let side = |q: usize, front: bool| -> Option<usize> {
        if front {
            Some(2 * q)
        } else if let Some(twin) = scene.polygons[q].surface.back {
            Some(2 * twin.index())
        } else if two_sided[q] {
            Some(2 * q + 1)
        } else {
            None
        }
    };
    // Per polygon, the nodes each of its sides' rays meet, a block of
    // polygons at a time so that the links held stay bounded (about
    // 500 bytes a polygon of the block).
    let links_of = |i: usize| {
        let p = &scene.polygons[i];
        let mut out = Vec::new();
        for front in [true, false] {
            let Some(from) = side(i, front) else {
                continue;
            };
            // A written-out twin casts its own rays as a front.
            if !front && p.surface.back.is_some() {
                continue;
            }
            let normal = if front { p.normal } else { -p.normal };
            for (origin, direction) in probes(p, normal) {
                let to = match rays.first_hit_polygon(origin, direction) {
                    None => Some(outside),
                    Some((q, _)) => {
                        let q = q.index();
                        let hit_front = direction.dot(scene.polygons[q].normal) < 0.0;
                        side(q, hit_front)
                    }
                };
                if let Some(to) = to {
                    out.push((from, to));
                }
            }
        }
        out
    };
    let mut sets = Sets::new(2 * n + 1);
    for block in (0..n).step_by(BLOCK) {
        cancel.check()?;
        let links: Vec<Vec<(usize, usize)>> = (block..(block + BLOCK).min(n))
            .into_par_iter()
            .with_min_len(RUN)
            .map(links_of)
            .collect();
        for (a, b) in links.into_iter().flatten() {
            sets.join(a, b);
        }
    }
    let mut lit = vec![false; 2 * n + 1];
    let mut seed = |node: usize, sets: &mut Sets| {
        let root = sets.root(node);
        lit[root] = true;
    };
    if sky {
        seed(outside, &mut sets);
    }
    for (i, &e) in emits.iter().enumerate() {
        if e {
            seed(2 * i, &mut sets);
            seed(2 * i + 1, &mut sets);
        }
    }
    Ok((0..n).map(|i| lit[sets.root(2 * i + 1)]).collect())
}

/// The probe rays of one side of `p` facing `normal` (unit): origins
/// spread over the face (halfway from the centroid to each vertex in
/// turn), lifted off it, and directions on a stratified cosine-weighted
/// grid about `normal`.
fn probes(p: &Polygon, normal: Vec3) -> impl Iterator<Item = (Vec3, Vec3)> + '_ {
    let centroid = p.vertices.iter().copied().sum::<Vec3>() / p.vertices.len().max(1) as f32;
    let reach = p
        .vertices
        .iter()
        .map(|v| v.distance(centroid))
        .fold(0.0f32, f32::max);
    let lift = normal * (reach * LIFT_SHARE).max(1e-6 * centroid.abs().max_element().max(1.0));
    let (tangent, bitangent) = normal.any_orthonormal_pair();
    let side = (PROBE_RAYS as f32).sqrt() as usize;
    (0..PROBE_RAYS).map(move |k| {
        let v = p.vertices[k % p.vertices.len()];
        let origin = centroid + (v - centroid) * 0.5 + lift;
        let (u, w) = (
            ((k % side) as f32 + 0.5) / side as f32,
            ((k / side) as f32 + 0.5) / side as f32,
        );
        let r = u.sqrt();
        let phi = std::f32::consts::TAU * w;
        let direction =
            tangent * (r * phi.cos()) + bitangent * (r * phi.sin()) + normal * (1.0 - u).sqrt();
        (origin, direction)
    })
}

/// Disjoint sets of nodes, joined by union by size with path halving.
struct Sets {
    parent: Vec<usize>,
    size: Vec<u32>,
}

impl Sets {
    fn new(n: usize) -> Self {
        Sets {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    fn root(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    fn join(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.root(a), self.root(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::framing::ray_polygon_hit;
    use crate::scene::PolygonId;
    use crate::testutil;

    /// Every polygon tested: the reference a BVH is checked against.
    struct BruteForce<'a>(&'a Scene);

    impl FirstHit for BruteForce<'_> {
        fn first_hit_polygon(&self, origin: Vec3, direction: Vec3) -> Option<(PolygonId, f32)> {
            self.0
                .polygons
                .iter()
                .enumerate()
                .filter_map(|(i, p)| {
                    ray_polygon_hit(p, origin.as_dvec3(), direction.as_dvec3(), 0.0)
                        .map(|t| (PolygonId(i as u32), t as f32))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
        }
    }

    /// [`reached_backs`] with every polygon tested, never cancelled.
    fn reached(scene: &Scene, two_sided: &[bool], sky: bool) -> Vec<bool> {
        reached_backs(scene, two_sided, sky, &BruteForce(scene), &Cancel::never()).unwrap()
    }

    /// A cave: the six walls of the box `[0, 4]³` facing in (material 0,
    /// grey), every one two-sided, and a lamp (material 1) in its middle
    /// facing down, one-sided.
    fn cave() -> (Scene, Vec<bool>) {
        let mut polygons = testutil::cuboid([0.0; 3], [4.0; 3], true);
        polygons.push(testutil::polygon(
            1,
            &[
                [1.5, 3.0, 1.5],
                [2.5, 3.0, 1.5],
                [2.5, 3.0, 2.5],
                [1.5, 3.0, 2.5],
            ],
        ));
        let scene = testutil::scene(
            polygons,
            vec![
                testutil::grey("rock", 0.0, 0.5),
                testutil::grey("lamp", 1.0, 0.0),
            ],
        );
        let mut two_sided = vec![true; 7];
        two_sided[6] = false;
        (scene, two_sided)
    }

    #[test]
    fn the_backs_of_a_lit_cave_face_the_dark_and_are_left_out() {
        let (scene, two_sided) = cave();
        let reached = reached(&scene, &two_sided, false);
        assert_eq!(&reached[..6], &[false; 6]);
    }

    #[test]
    fn under_a_sky_the_outside_is_lit_and_every_back_kept() {
        let (scene, two_sided) = cave();
        let reached = reached(&scene, &two_sided, true);
        assert_eq!(&reached[..6], &[true; 6]);
    }

    #[test]
    fn a_wall_with_a_lamp_on_its_far_side_keeps_its_back() {
        // The cave's lamp moved outside it, below its floor and facing
        // up: the floor's back (facing down) sees it; the other walls'
        // backs see the outside, which the lamp's own rays reach too.
        let (mut scene, two_sided) = cave();
        scene.polygons[6] = testutil::polygon(
            1,
            &[
                [1.5, -1.0, 1.5],
                [1.5, -1.0, 2.5],
                [2.5, -1.0, 2.5],
                [2.5, -1.0, 1.5],
            ],
        );
        assert!(scene.polygons[6].normal.y > 0.99);
        let reached = reached(&scene, &two_sided, false);
        assert_eq!(&reached[..6], &[true; 6]);
    }

    #[test]
    fn nothing_is_left_out_of_a_scene_that_nothing_lights() {
        let (mut scene, two_sided) = cave();
        scene.materials[1].k_emission = 0.0;
        let reached = reached(&scene, &two_sided, false);
        assert!(reached.iter().all(|&r| r));
    }

    #[test]
    fn a_plane_lit_from_its_back_keeps_its_back() {
        // A floor facing down (as a modeller may leave it) under a lamp
        // facing down: only its back is lit.
        let floor = testutil::polygon(
            0,
            &[
                [4.0, 0.0, 0.0],
                [4.0, 0.0, 4.0],
                [0.0, 0.0, 4.0],
                [0.0, 0.0, 0.0],
            ],
        );
        assert!(floor.normal.y < -0.99);
        let lamp = testutil::polygon(
            1,
            &[
                [1.5, 2.0, 1.5],
                [2.5, 2.0, 1.5],
                [2.5, 2.0, 2.5],
                [1.5, 2.0, 2.5],
            ],
        );
        let scene = testutil::scene(
            vec![floor, lamp],
            vec![
                testutil::grey("floor", 0.0, 0.5),
                testutil::grey("lamp", 1.0, 0.0),
            ],
        );
        let reached = reached(&scene, &[true, false], false);
        assert!(reached[0]);
    }
}
