//! Two-sided faces and repeated faces.
//!
//! A `.sc` polygon reflects and emits from its front only, as the format
//! says. Blender shades both sides of every face, and its users model
//! rooms with outward normals, single-plane walls and lamps facing the
//! wrong way: an OBJ face is therefore read as **two-sided**
//! ([`Surface::two_sided`]), and glTF follows each material's
//! `doubleSided`. [`Scene::with_sides`] turns that reading into geometry:
//! every two-sided polygon gets a **back copy**, the same polygon with its
//! vertices in reverse order, appended after every polygon of the file.
//! Each side then receives, reflects and (for an emitter) emits on its
//! own, with its own element mesh and its own radiosity, so a thin wall
//! lit on one side stays dark on the other. The two sides are coplanar,
//! and coplanar polygons never block each other (see [`super::coplanar`]).
//!
//! A face that repeats an earlier one exactly (same vertices in the same
//! cyclic order, as in McGuire's widely used `CornellBox-Original.obj`)
//! would shadow its twin and show as blotches: the loaders drop it with
//! one warning ([`Scene::drop_duplicates`]). A face that repeats another
//! one *reversed* is the other's back side, written out: it is kept, and
//! [`Scene::with_sides`] makes no back copy for either.

use crate::scene::error::Warning;
use crate::scene::{Polygon, PolygonId, Scene, SourcePos};
use std::collections::HashMap;

/// Which sides of the polygons take part, as the loader read them or as
/// `--one-sided` / `--two-sided` say.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sides {
    /// Each polygon as its file says: OBJ faces two-sided, glTF per
    /// material, `.sc` front only.
    #[default]
    AsLoaded,
    /// Every polygon front only (`--one-sided`).
    One,
    /// Every polygon on both sides (`--two-sided`).
    Two,
}

/// The exact vertex bits of a polygon from its lowest vertex on, in its
/// own order: equal keys mean the same face with the same front.
pub(in crate::scene) fn face_key(vertices: &[glam::Vec3]) -> Vec<[u32; 3]> {
    let bits: Vec<[u32; 3]> = vertices
        .iter()
        .map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()])
        .collect();
    let start = (0..bits.len()).min_by_key(|&i| bits[i]).unwrap_or(0);
    bits[start..]
        .iter()
        .chain(&bits[..start])
        .copied()
        .collect()
}

/// [`face_key`] of the polygon seen from its back.
fn reversed_key(vertices: &[glam::Vec3]) -> Vec<[u32; 3]> {
    let reversed: Vec<glam::Vec3> = vertices.iter().rev().copied().collect();
    face_key(&reversed)
}

/// The back copy of `front` (polygon `id`): its vertices reversed from
/// the second on, so the first stays first, its normal negated, marked as
/// `id`'s back and with no back of its own.
pub(in crate::scene) fn back_copy(front: &Polygon, id: PolygonId) -> Polygon {
    let mut vertices = Vec::with_capacity(front.vertices.len());
    vertices.push(front.vertices[0]);
    vertices.extend(front.vertices[1..].iter().rev());
    let mut back = Polygon {
        vertices,
        normal: -front.normal,
        ..front.clone()
    };
    back.surface.back = None;
    back.surface.back_of = Some(id);
    back
}

impl Scene {
    /// Drops every polygon that repeats an earlier one exactly (the same
    /// vertices, bit for bit, in the same cyclic order), keeping one of
    /// each set: the last in the file, unless an earlier one emits and it
    /// does not (then the first emitter). Groups are renumbered. Returns
    /// one warning naming the count and the first repeat's position in
    /// `file`, or `None` when nothing repeats.
    pub fn drop_duplicates(&mut self, file: &str) -> Option<Warning> {
        let emits = |p: &Polygon| self.materials[p.material.index()].emission().max_channel() > 0.0;
        // For each key, the index of the polygon kept so far.
        let mut kept: HashMap<Vec<[u32; 3]>, usize> = HashMap::new();
        let mut keep = vec![true; self.polygons.len()];
        let mut first: Option<(SourcePos, SourcePos)> = None;
        let mut count = 0usize;
        for (i, p) in self.polygons.iter().enumerate() {
            let key = face_key(&p.vertices);
            let Some(&j) = kept.get(&key) else {
                kept.insert(key, i);
                continue;
            };
            count += 1;
            first.get_or_insert((self.polygons[j].origin, p.origin));
            // The later face wins unless only the earlier one emits.
            if emits(&self.polygons[j]) && !emits(p) {
                keep[i] = false;
            } else {
                keep[j] = false;
                kept.insert(key, i);
            }
        }
        let (earlier, later) = first?;
        self.retain_polygons(&keep);
        let faces = if count == 1 {
            "face repeats"
        } else {
            "faces repeat"
        };
        let why = "one of each was kept, as repeated faces would shadow each other";
        // Formats without lines (glTF) give their polygons no position.
        Some(if later.line == 0 {
            Warning::file(
                file,
                format!("{count} {faces} an earlier face exactly; {why}"),
            )
        } else {
            Warning::at(
                file,
                later,
                format!(
                    "{count} {faces} an earlier face exactly (first: line {} repeats line {}); {why}",
                    later.line, earlier.line
                ),
            )
        })
    }

    /// Keeps the polygons whose `keep` entry is true, in order, and
    /// renumbers the groups' polygon lists (dropping groups left empty).
    fn retain_polygons(&mut self, keep: &[bool]) {
        let mut new_id = Vec::with_capacity(keep.len());
        let mut next = 0u32;
        for &k in keep {
            new_id.push(k.then_some(next));
            next += u32::from(k);
        }
        let mut i = 0;
        self.polygons.retain(|_| {
            i += 1;
            keep[i - 1]
        });
        for group in &mut self.groups {
            group.polygons = group
                .polygons
                .iter()
                .filter_map(|p| new_id[p.index()].map(PolygonId))
                .collect();
        }
        self.groups.retain(|g| !g.polygons.is_empty());
    }

    /// The scene with the sides that take part made explicit: a reversed
    /// back copy appended for every polygon that is two-sided (as loaded,
    /// or all of them with [`Sides::Two`]; none with [`Sides::One`]).
    ///
    /// A copy has the front's material, origin and smooth surface, its
    /// vertices reversed (the first kept first, so a parallelogram stays
    /// one), its normal negated, and [`Surface::back_of`] pointing at the
    /// front, whose [`Surface::back`] points at it; it joins every group
    /// of its front. Two polygons of the file that are each other's
    /// reverse already are both sides of one face: they get no copies and
    /// point at each other through [`Surface::back`].
    ///
    /// [`Surface::two_sided`] is left as set on every polygon, and the
    /// result is deterministic (copies in the order of their fronts).
    ///
    /// [`Surface::back_of`]: crate::scene::Surface::back_of
    /// [`Surface::back`]: crate::scene::Surface::back
    /// [`Surface::two_sided`]: crate::scene::Surface::two_sided
    pub fn with_sides(self, sides: Sides) -> Scene {
        let keep = vec![true; self.polygons.len()];
        self.with_sides_where(sides, &keep)
    }

    /// Each polygon's [`face_key`], to find a face written out a second
    /// time reversed.
    fn face_keys(&self) -> HashMap<Vec<[u32; 3]>, usize> {
        self.polygons
            .iter()
            .enumerate()
            .map(|(i, p)| (face_key(&p.vertices), i))
            .collect()
    }

    /// Per polygon, whether [`Scene::with_sides`] with `sides` would give
    /// it a back copy: two-sided as `sides` reads it, not part of a closed
    /// solid, and not written out a second time reversed.
    pub fn would_get_backs(&self, sides: Sides) -> Vec<bool> {
        let keys = self.face_keys();
        self.polygons
            .iter()
            .map(|p| {
                !keys.contains_key(&reversed_key(&p.vertices))
                    && !p.surface.solid
                    && match sides {
                        Sides::AsLoaded => p.surface.two_sided,
                        Sides::One => false,
                        Sides::Two => true,
                    }
            })
            .collect()
    }

    /// [`Scene::with_sides`], making a back copy of polygon `i` only where
    /// `keep[i]` (one entry per polygon): the others stay one-sided.
    pub fn with_sides_where(mut self, sides: Sides, keep: &[bool]) -> Scene {
        let keys = self.face_keys();
        let count = self.polygons.len();
        let mut copies = Vec::new();
        for i in 0..count {
            if let Some(&j) = keys.get(&reversed_key(&self.polygons[i].vertices)) {
                // Written out both ways: the other one is this one's back.
                self.polygons[i].surface.back = Some(PolygonId(j as u32));
                continue;
            }
            let p = &self.polygons[i];
            let two = !p.surface.solid
                && keep.get(i).copied().unwrap_or(true)
                && match sides {
                    Sides::AsLoaded => p.surface.two_sided,
                    Sides::One => false,
                    Sides::Two => true,
                };
            if !two {
                continue;
            }
            let back_id = PolygonId((count + copies.len()) as u32);
            let back = back_copy(p, PolygonId(i as u32));
            self.polygons[i].surface.back = Some(back_id);
            copies.push(back);
        }
        if copies.is_empty() {
            return self;
        }
        // Each copy joins its front's groups; ids stay ascending because
        // every copy's id is above every front's.
        let mut extra: Vec<Vec<PolygonId>> = vec![Vec::new(); self.groups.len()];
        for (g, group) in self.groups.iter().enumerate() {
            for &p in &group.polygons {
                if let Some(back) = self.polygons[p.index()].surface.back {
                    if back.index() >= count {
                        extra[g].push(back);
                    }
                }
            }
        }
        for (group, mut more) in self.groups.iter_mut().zip(extra) {
            more.sort_unstable();
            group.polygons.extend(more);
        }
        self.polygons.extend(copies);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Group, GroupKind, Surface};
    use crate::testutil;

    fn quad(z: f32, material: u32) -> Polygon {
        testutil::polygon(
            material,
            &[[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
        )
    }

    fn scene(polygons: Vec<Polygon>) -> Scene {
        let mut s = testutil::scene(
            polygons,
            vec![
                testutil::grey("wall", 0.0, 0.5),
                testutil::grey("lamp", 1.0, 0.5),
            ],
        );
        s.groups = vec![Group {
            name: "Cube".into(),
            kind: GroupKind::Object,
            polygons: (0..s.polygons.len() as u32).map(PolygonId).collect(),
        }];
        s
    }

    fn two_sided(mut p: Polygon) -> Polygon {
        p.surface.two_sided = true;
        p
    }

    #[test]
    fn back_copy_is_the_reversed_front() {
        let s = scene(vec![two_sided(quad(0.0, 0)), quad(1.0, 0)]).with_sides(Sides::AsLoaded);
        assert_eq!(s.polygons.len(), 3, "only the two-sided quad is copied");
        let (front, back) = (&s.polygons[0], &s.polygons[2]);
        assert_eq!(back.normal, -front.normal);
        assert_eq!(back.vertices[0], front.vertices[0]);
        assert_eq!(back.vertices[1], front.vertices[3]);
        assert_eq!(back.area, front.area);
        assert_eq!(back.shape, front.shape);
        assert_eq!(back.surface.back_of, Some(PolygonId(0)));
        assert_eq!(front.surface.back, Some(PolygonId(2)));
        assert_eq!(s.polygons[1].surface, Surface::default());
        back.validate().expect("a valid polygon");
        assert_eq!(
            s.groups[0].polygons,
            vec![PolygonId(0), PolygonId(1), PolygonId(2)],
            "the copy joins its front's object"
        );
    }

    #[test]
    fn overrides_choose_every_polygon_or_none() {
        let s = scene(vec![two_sided(quad(0.0, 0)), quad(1.0, 0)]);
        assert_eq!(s.clone().with_sides(Sides::One).polygons.len(), 2);
        assert_eq!(s.with_sides(Sides::Two).polygons.len(), 4);
    }

    #[test]
    fn a_face_written_both_ways_gets_no_copies() {
        let front = two_sided(quad(0.0, 0));
        let mut reversed = front.clone();
        reversed.vertices.reverse();
        reversed.normal = -reversed.normal;
        let s = scene(vec![front, reversed]).with_sides(Sides::Two);
        assert_eq!(s.polygons.len(), 2);
        assert_eq!(s.polygons[0].surface.back, Some(PolygonId(1)));
        assert_eq!(s.polygons[1].surface.back, Some(PolygonId(0)));
        assert_eq!(s.polygons[0].surface.back_of, None);
    }

    #[test]
    fn exact_repeats_are_dropped_keeping_the_emitter() {
        let mut lamp = quad(0.0, 1);
        lamp.origin = SourcePos { line: 3, col: 1 };
        let mut repeat = quad(0.0, 0);
        // The same face, listed from another vertex: still a repeat.
        repeat.vertices.rotate_left(2);
        repeat.origin = SourcePos { line: 9, col: 1 };
        let mut s = scene(vec![lamp, quad(1.0, 0), repeat]);
        let w = s.drop_duplicates("box.obj").expect("a warning");
        assert_eq!(s.polygons.len(), 2);
        assert_eq!(s.polygons[0].material.0, 1, "the emitter is kept");
        assert_eq!(s.groups[0].polygons, vec![PolygonId(0), PolygonId(1)]);
        assert_eq!(
            w.to_string(),
            "box.obj:9:1: warning: 1 face repeats an earlier face exactly \
             (first: line 9 repeats line 3); one of each was kept, as repeated \
             faces would shadow each other"
        );
    }

    #[test]
    fn later_repeat_wins_and_reversed_faces_are_not_repeats() {
        let a = quad(0.0, 0);
        let b = quad(0.0, 1);
        let mut reversed = quad(0.0, 0);
        reversed.vertices.reverse();
        let mut s = scene(vec![a, reversed, b]);
        assert!(s.drop_duplicates("x.obj").is_some());
        assert_eq!(s.polygons.len(), 2);
        assert_eq!(s.polygons[1].material.0, 1, "the later one is kept");
        let mut clean = scene(vec![quad(0.0, 0), quad(1.0, 0)]);
        assert!(clean.drop_duplicates("x.obj").is_none());
    }
}
