//! Closed solids: two-sided faces whose inside nobody can see.
//!
//! OBJ faces are two-sided ([`super::sides`]): a back copy lets a room
//! modelled with outward normals be lit from inside. But most closed
//! meshes of a model are *solids*, a box on a floor, a table leg, a
//! statue: their inside is sealed off. Back copies there cost elements and
//! steps for surfaces nobody sees, and they form sealed cavities whose
//! walls trade light at reflectances near 1 that converge slowly and
//! gather what leaks in through the joints.
//!
//! [`Scene::orient_solids`] finds them before the back copies are made: a
//! **closed component** is a set of two-sided polygons joined along
//! shared edges (the same vertex positions, bit for bit, as exporters
//! write shared vertices) in which every edge is used exactly once in each
//! direction (closed and consistently oriented). It is a **solid** when
//! none of its faces emits (a room whose ceiling glows is seen from
//! inside) and no other polygon of the scene lies inside it (a room with
//! a lamp or furniture in it is seen from inside). A solid keeps one side:
//! the outside. Its faces get no back copies ([`crate::scene::Surface::solid`]);
//! when they all face inward (a negative enclosed volume, normals flipped
//! in the modeller), each is turned to face out, with one warning.

use crate::scene::error::Warning;
use crate::scene::{Polygon, Scene, Sides};
use glam::DVec3;
use std::collections::HashMap;

/// At most this many polygons outside a closed component, among those
/// whose centre lies in its bounding box, are tested for being inside it
/// (evenly spread over them): enough to find a room's contents, bounded so
/// that a large closed mesh around many small parts costs little.
pub const SOLID_CONTENT_PROBES: usize = 64;

/// A vertex position's exact bits: shared edges are found by equal bits.
type Key = [u32; 3];

fn key(v: glam::Vec3) -> Key {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// The centre of a polygon's vertices.
fn centre(p: &Polygon) -> DVec3 {
    p.vertices.iter().map(|v| v.as_dvec3()).sum::<DVec3>() / p.vertices.len().max(1) as f64
}

/// Six times the volume a closed, consistently oriented set of faces
/// encloses: positive when their fronts face out.
fn signed_volume6(polygons: &[Polygon], faces: &[u32], origin: DVec3) -> f64 {
    let mut sum = 0.0;
    for &f in faces {
        let v = &polygons[f as usize].vertices;
        let a = v[0].as_dvec3() - origin;
        for k in 1..v.len().saturating_sub(1) {
            let b = v[k].as_dvec3() - origin;
            let c = v[k + 1].as_dvec3() - origin;
            sum += a.dot(b.cross(c));
        }
    }
    sum
}

/// True when `x` is inside the closed faces `faces`: a ray from `x` along
/// a fixed, generic direction crosses them an odd number of times.
fn inside(polygons: &[Polygon], faces: &[u32], x: DVec3) -> bool {
    // Not along an axis or a diagonal, where modelled edges line up.
    let dir = DVec3::new(0.573_462, 0.688_791, 0.443_296).normalize();
    let crossings = faces
        .iter()
        .filter(|&&f| {
            crate::scene::framing::ray_polygon_hit(&polygons[f as usize], x, dir, 0.0).is_some()
        })
        .count();
    crossings % 2 == 1
}

impl Scene {
    /// Finds the closed solids among the polygons that `sides` makes
    /// two-sided (see the module docs), marks their polygons
    /// [`crate::scene::Surface::solid`] so that [`Scene::with_sides`] gives them
    /// no back copies, and turns the faces of solids that face inward to
    /// face out. Returns one warning for `file` when it turned any.
    /// Returns at once with [`Sides::One`].
    pub fn orient_solids(&mut self, sides: Sides, file: &str) -> Option<Warning> {
        let two = |p: &Polygon| match sides {
            Sides::AsLoaded => p.surface.two_sided,
            Sides::One => false,
            Sides::Two => true,
        };
        let n = self.polygons.len();
        if !self.polygons.iter().any(two) {
            return None;
        }
        // Directed edges of the two-sided polygons: (from, to) -> (count,
        // a polygon that has it).
        let mut edges: HashMap<(Key, Key), (u32, u32)> = HashMap::new();
        for (i, p) in self.polygons.iter().enumerate().filter(|(_, p)| two(p)) {
            let k = p.vertices.len();
            for j in 0..k {
                let e = (key(p.vertices[j]), key(p.vertices[(j + 1) % k]));
                let entry = edges.entry(e).or_insert((0, i as u32));
                entry.0 += 1;
            }
        }
        let mut parent: Vec<u32> = (0..n as u32).collect();
        let mut open = vec![false; n];
        for (i, p) in self.polygons.iter().enumerate().filter(|(_, p)| two(p)) {
            let k = p.vertices.len();
            for j in 0..k {
                let (a, b) = (key(p.vertices[j]), key(p.vertices[(j + 1) % k]));
                let once = edges.get(&(a, b)).is_some_and(|e| e.0 == 1);
                match edges.get(&(b, a)) {
                    Some(&(1, other)) if once => {
                        let (ra, rb) = (find(&mut parent, i as u32), find(&mut parent, other));
                        parent[ra.max(rb) as usize] = ra.min(rb);
                    }
                    _ => open[i] = true,
                }
            }
        }
        let mut components: HashMap<u32, Vec<u32>> = HashMap::new();
        for (i, p) in self.polygons.iter().enumerate() {
            if two(p) {
                let r = find(&mut parent, i as u32);
                components.entry(r).or_default().push(i as u32);
            }
        }
        let mut components: Vec<Vec<u32>> = components
            .into_values()
            .filter(|c| c.len() >= 4 && !c.iter().any(|&f| open[f as usize]))
            .collect();
        components.sort_unstable();
        if components.is_empty() {
            return None;
        }
        let emits = |p: &Polygon| self.materials[p.material.index()].emission().max_channel() > 0.0;
        let centres: Vec<DVec3> = self.polygons.iter().map(centre).collect();
        // Polygons by the x of their centre, so that each component finds
        // those in its bounds by a binary search, not a pass over all.
        let mut by_x: Vec<usize> = (0..n).filter(|&i| !self.polygons[i].surface.sky).collect();
        by_x.sort_by(|&a, &b| centres[a].x.total_cmp(&centres[b].x));
        let mut turned = (0usize, 0usize);
        let mut member = vec![false; n];
        for faces in components {
            if faces.iter().any(|&f| emits(&self.polygons[f as usize])) {
                continue;
            }
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for &f in &faces {
                member[f as usize] = true;
                for v in &self.polygons[f as usize].vertices {
                    lo = lo.min(v.as_dvec3());
                    hi = hi.max(v.as_dvec3());
                }
            }
            let start = by_x.partition_point(|&i| centres[i].x <= lo.x);
            let end = by_x.partition_point(|&i| centres[i].x < hi.x);
            let candidates: Vec<usize> = by_x[start..end.max(start)]
                .iter()
                .copied()
                .filter(|&i| !member[i] && centres[i].cmpgt(lo).all() && centres[i].cmplt(hi).all())
                .collect();
            let stride = candidates.len().div_ceil(SOLID_CONTENT_PROBES).max(1);
            let holds_something = candidates
                .iter()
                .step_by(stride)
                .any(|&i| inside(&self.polygons, &faces, centres[i]));
            for &f in &faces {
                member[f as usize] = false;
            }
            if holds_something {
                continue;
            }
            let inward = signed_volume6(&self.polygons, &faces, 0.5 * (lo + hi)) < 0.0;
            if inward {
                turned.0 += 1;
                turned.1 += faces.len();
            }
            for &f in &faces {
                let p = &mut self.polygons[f as usize];
                p.surface.solid = true;
                if inward {
                    // The first vertex stays first, so a parallelogram
                    // stays one.
                    p.vertices[1..].reverse();
                    p.normal = -p.normal;
                }
            }
        }
        (turned.0 > 0).then(|| {
            Warning::file(
                file,
                format!(
                    "{} closed object(s) ({} faces) faced inward with nothing inside them: \
                     turned to face out, as solids lit from outside",
                    turned.0, turned.1
                ),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{cuboid, grey, scene};

    /// The box of side `size` from `at`, two-sided, its faces facing out
    /// (`outward`) or in.
    fn cube(at: [f32; 3], size: f32, outward: bool) -> Vec<Polygon> {
        let hi = at.map(|x| x + size);
        cuboid(at, hi, !outward)
            .into_iter()
            .map(|mut p| {
                p.surface.two_sided = true;
                p
            })
            .collect()
    }

    fn materials() -> Vec<crate::scene::Material> {
        vec![grey("white", 0.0, 0.8), grey("lamp", 1.0, 0.0)]
    }

    #[test]
    fn an_empty_closed_box_is_a_solid_and_keeps_one_side() {
        let mut s = scene(cube([0.0; 3], 1.0, true), materials());
        assert_eq!(s.orient_solids(Sides::AsLoaded, "m.obj"), None);
        assert!(s.polygons.iter().all(|p| p.surface.solid));
        let s = s.with_sides(Sides::AsLoaded);
        assert_eq!(s.polygons.len(), 6, "no back copies");
    }

    #[test]
    fn an_inward_solid_is_turned_out_with_a_warning() {
        let mut s = scene(cube([0.0; 3], 1.0, false), materials());
        let before: Vec<_> = s.polygons.iter().map(|p| p.normal).collect();
        let w = s.orient_solids(Sides::Two, "m.obj").expect("a warning");
        assert_eq!(
            w.to_string(),
            "m.obj: warning: 1 closed object(s) (6 faces) faced inward with nothing inside \
             them: turned to face out, as solids lit from outside"
        );
        for (p, n) in s.polygons.iter().zip(before) {
            assert_eq!(p.normal, -n);
            // Outward: the normal points away from the cube's centre.
            let c = centre(p) - DVec3::splat(0.5);
            assert!(p.normal.as_dvec3().dot(c) > 0.0);
        }
    }

    #[test]
    fn a_room_with_something_inside_or_a_glowing_wall_keeps_both_sides() {
        // A room of outward faces with a small box inside it.
        let mut polygons = cube([0.0; 3], 10.0, true);
        polygons.extend(cube([4.0, 0.0, 4.0], 1.0, true));
        let mut s = scene(polygons, materials());
        s.orient_solids(Sides::AsLoaded, "m.obj");
        let solid: Vec<bool> = s.polygons.iter().map(|p| p.surface.solid).collect();
        assert!(
            solid[..6].iter().all(|x| !x),
            "the room is seen from inside"
        );
        assert!(solid[6..].iter().all(|x| *x), "the box in it is a solid");
        assert_eq!(s.with_sides(Sides::AsLoaded).polygons.len(), 12 + 6);
        // An empty room whose ceiling glows.
        let mut polygons = cube([0.0; 3], 10.0, true);
        polygons[5].material = crate::scene::MaterialId(1);
        let mut s = scene(polygons, materials());
        s.orient_solids(Sides::AsLoaded, "m.obj");
        assert!(s.polygons.iter().all(|p| !p.surface.solid));
    }

    #[test]
    fn open_boxes_and_one_sided_faces_are_left_alone() {
        let mut open = cube([0.0; 3], 1.0, true);
        open.pop();
        let mut s = scene(open, materials());
        s.orient_solids(Sides::AsLoaded, "m.obj");
        assert!(s.polygons.iter().all(|p| !p.surface.solid));
        let mut s = scene(cube([0.0; 3], 1.0, false), materials());
        assert_eq!(s.orient_solids(Sides::One, "m.obj"), None);
        assert!(s.polygons.iter().all(|p| !p.surface.solid));
    }
}
