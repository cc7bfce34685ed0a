//! Emitting sides that face a surface across a narrow gap.
//!
//! OBJ faces are read as two-sided, and so are the faces of a glTF
//! material marked `doubleSided` (see [`super::sides`]): each side of an
//! emitting face then emits. That is what Blender does with an emitting
//! plane, and right for a lamp hanging in a room. It is wrong for the lamp
//! modelled as one face just under a ceiling, as in McGuire's widely used
//! `CornellBox-Original.obj` (1 cm below a ceiling, 0.4 m across): its
//! back sends as much light as its front into the gap, where it bounces
//! between the two surfaces and seeps out at the lamp's edge as a bright
//! halo. The modeller meant a ceiling lamp. The halo is also where a
//! mesh of elements is at its worst: the gap's light reaches the room only
//! through the ceiling's cells that straddle the lamp's edge, so the
//! picture depended on where their samples fell (its mean moved by 13 %
//! between 64 and 256 shooter samples).
//!
//! [`Scene::silence_covered_sides`] finds each such side and makes it
//! emit nothing (it still reflects), with one warning for the file.

use crate::scene::error::Warning;
use crate::scene::{Material, MaterialId, Polygon, Scene};
use glam::Vec3;
use std::collections::HashMap;

/// A side is covered when every probe ray from it along its normal meets
/// a surface within this share of the face's width, 4 × area / perimeter
/// (the side of a square, the diameter of a disc, twice the width of a
/// long strip). Of the light a square face sends into such a gap, 9 %
/// meets the surface outside the face's outline (95 % stays inside at
/// McGuire's 2.4 %); the rest bounces between the two. A lamp hanging
/// lower, a suspended panel lighting its ceiling too, is taken as meant to
/// light both ways.
pub const COVERED_GAP_SHARE: f32 = 0.05;

/// How far above its face a probe ray starts, as a share of the face's
/// width: clear of the face and of its coplanar other side, far below the
/// gap that counts.
const PROBE_LIFT_SHARE: f32 = 1e-3;

/// The face's width as [`COVERED_GAP_SHARE`] measures it, in scene units.
fn width(p: &Polygon) -> f32 {
    let perimeter: f32 = p
        .vertices
        .iter()
        .zip(p.vertices.iter().cycle().skip(1))
        .map(|(a, b)| a.distance(*b))
        .sum();
    if perimeter > 0.0 {
        (4.0 * p.area) as f32 / perimeter
    } else {
        0.0
    }
}

/// Points spread over the (convex) face where probes start: its centroid
/// and, a tenth of the way in towards it, every vertex and every edge's
/// midpoint, so the gap must span the whole face, edges and corners too.
fn probe_points(p: &Polygon) -> Vec<Vec3> {
    let n = p.vertices.len();
    let centre = p.vertices.iter().copied().sum::<Vec3>() / n as f32;
    let inward = |q: Vec3| q + 0.1 * (centre - q);
    let mut points = Vec::with_capacity(2 * n + 1);
    points.push(centre);
    for i in 0..n {
        let (a, b) = (p.vertices[i], p.vertices[(i + 1) % n]);
        points.push(inward(a));
        points.push(inward(0.5 * (a + b)));
    }
    points
}

/// The farthest that a probe from `p`'s front went before meeting a
/// surface, in scene units, or `None` when some probe met nothing within
/// `reach`. `first_hit(origin, direction)` is the distance to the nearest
/// surface along the ray, as [`crate::visibility::Visibility::first_hit`]
/// gives it.
fn covered_within(
    p: &Polygon,
    reach: f32,
    first_hit: &impl Fn(Vec3, Vec3) -> Option<f32>,
) -> Option<f32> {
    let lift = PROBE_LIFT_SHARE * width(p);
    let mut farthest = 0.0f32;
    for point in probe_points(p) {
        let t = first_hit(point + lift * p.normal, p.normal)? + lift;
        if t > reach {
            return None;
        }
        farthest = farthest.max(t);
    }
    Some(farthest)
}

impl Scene {
    /// True when some face emits from both its sides (a front and its
    /// back copy, neither a luminaire): the faces
    /// [`Scene::silence_covered_sides`] looks at.
    pub fn emits_from_both_sides(&self) -> bool {
        self.polygons.iter().any(|back| {
            back.surface.back_of.is_some_and(|front| {
                self.emits_like_a_lamp(back)
                    && self.emits_like_a_lamp(&self.polygons[front.index()])
            })
        })
    }

    /// True when `p` emits by its material and is no luminaire.
    fn emits_like_a_lamp(&self, p: &Polygon) -> bool {
        self.materials[p.material.index()].emission().max_channel() > 0.0
            && self.luminaire_of(p.material).is_none()
    }

    /// Makes every emitting side that faces a surface across a narrow gap
    /// emit nothing, when the other side of its face is open: a side is
    /// covered when rays along its normal from its centroid, corners and
    /// edges all meet a surface within [`COVERED_GAP_SHARE`] of the face's
    /// width. Only faces with both sides are looked at (a front and its
    /// back copy from [`Scene::with_sides`]); a face covered on both sides
    /// is left alone, and so are luminaires, whose backs
    /// [`Scene::light_luminaire_backs`] gives the light of their files.
    ///
    /// A silenced side gets a material of its own, its old one with no
    /// emission, named `NAME (covered side)`; the reflectance is kept.
    /// Run after everything that adds polygons, with `first_hit` built on
    /// the finished scene: it gives the distance along a ray from `origin`
    /// in `direction` to the nearest polygon, or `None` when the ray leaves
    /// the scene ([`crate::visibility::Visibility::first_hit`]). Returns one
    /// warning for `file`, at the first silenced face's position, or
    /// `None` when nothing changed.
    pub fn silence_covered_sides(
        &mut self,
        first_hit: impl Fn(Vec3, Vec3) -> Option<f32>,
        file: &str,
    ) -> Option<Warning> {
        // (covered side, its face's front, the gap) for each face whose
        // other side is open.
        let mut silenced: Vec<(usize, usize, f32)> = Vec::new();
        for (b, back) in self.polygons.iter().enumerate() {
            let Some(front) = back.surface.back_of else {
                continue;
            };
            let front_polygon = &self.polygons[front.index()];
            if !self.emits_like_a_lamp(back) || !self.emits_like_a_lamp(front_polygon) {
                continue;
            }
            let reach = COVERED_GAP_SHARE * width(front_polygon);
            let sides = (
                covered_within(front_polygon, reach, &first_hit),
                covered_within(back, reach, &first_hit),
            );
            match sides {
                (Some(gap), None) => silenced.push((front.index(), front.index(), gap)),
                (None, Some(gap)) => silenced.push((b, front.index(), gap)),
                _ => {}
            }
        }
        if silenced.is_empty() {
            return None;
        }
        // One dark twin per material, in the order first needed.
        let mut dark: HashMap<MaterialId, MaterialId> = HashMap::new();
        for &(i, _, _) in &silenced {
            let material = self.polygons[i].material;
            let twin = *dark.entry(material).or_insert_with(|| {
                let lit = &self.materials[material.index()];
                self.materials.push(Material {
                    name: format!("{} (covered side)", lit.name),
                    k_emission: 0.0,
                    ..lit.clone()
                });
                MaterialId(self.materials.len() as u32 - 1)
            });
            self.polygons[i].material = twin;
        }
        let (first, face, gap) = silenced
            .iter()
            .copied()
            .min_by_key(|&(_, face, _)| (self.polygons[face].origin.line, face))
            .expect("at least one side was silenced");
        let which = if first == face { "front" } else { "back" };
        let message = match silenced.len() {
            1 => format!(
                "this emitting face's {which} has a surface {gap:.3} units behind it, closer than \
                 {:.0} % of the face's width: that side now emits nothing, as light sent into so \
                 narrow a gap would only seep out at its edge",
                100.0 * COVERED_GAP_SHARE
            ),
            n => format!(
                "{n} emitting faces have a surface behind one side, closer than {:.0} % of the \
                 face's width (first: this face's {which}, {gap:.3} units): those sides now emit \
                 nothing, as light sent into so narrow a gap would only seep out at its edge",
                100.0 * COVERED_GAP_SHARE
            ),
        };
        let origin = self.polygons[face].origin;
        Some(if origin.line == 0 {
            Warning::file(file, message)
        } else {
            Warning::at(file, origin, message)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Sides, Surface};
    use crate::testutil;
    use crate::visibility::Visibility;

    fn quad(z: f32, size: f32, material: u32) -> Polygon {
        testutil::polygon(
            material,
            &[
                [0.0, 0.0, z],
                [size, 0.0, z],
                [size, size, z],
                [0.0, size, z],
            ],
        )
    }

    fn two_sided(mut p: Polygon) -> Polygon {
        p.surface = Surface {
            two_sided: true,
            ..p.surface
        };
        p
    }

    /// A 1 × 1 two-sided lamp at height 1 under a 2 × 2 one-sided
    /// ceiling (facing down) at `1 + gap`.
    fn lamp_under_ceiling(gap: f32, lamp_faces_up: bool) -> Scene {
        let mut lamp = quad(1.0, 1.0, 1);
        if !lamp_faces_up {
            lamp.vertices.reverse();
            lamp.normal = -lamp.normal;
        }
        let mut ceiling = testutil::polygon(
            0,
            &[
                [-0.5, -0.5, 1.0 + gap],
                [-0.5, 1.5, 1.0 + gap],
                [1.5, 1.5, 1.0 + gap],
                [1.5, -0.5, 1.0 + gap],
            ],
        );
        ceiling.origin.line = 1;
        lamp.origin = crate::scene::SourcePos { line: 7, col: 1 };
        testutil::scene(
            vec![ceiling, two_sided(lamp)],
            vec![
                testutil::grey("wall", 0.0, 0.5),
                testutil::grey("lamp", 1.0, 0.5),
            ],
        )
        .with_sides(Sides::AsLoaded)
    }

    fn silence(scene: &mut Scene) -> Option<Warning> {
        let visibility = Visibility::new(scene);
        scene.silence_covered_sides(|o, d| visibility.first_hit(o, d).map(|h| h.1), "lamp.obj")
    }

    fn emits(scene: &Scene, i: usize) -> bool {
        scene.materials[scene.polygons[i].material.index()]
            .emission()
            .max_channel()
            > 0.0
    }

    #[test]
    fn a_lamp_just_under_a_ceiling_emits_downwards_only() {
        for faces_up in [false, true] {
            let mut s = lamp_under_ceiling(0.02, faces_up);
            assert_eq!(s.polygons.len(), 3, "the lamp has a back copy");
            let w = silence(&mut s).expect("a warning");
            // Polygon 1 is the lamp's front, 2 its back copy.
            let (up, down) = if faces_up { (1, 2) } else { (2, 1) };
            assert!(!emits(&s, up), "the side facing the ceiling is silenced");
            assert!(emits(&s, down), "the open side still emits");
            let dark = &s.materials[s.polygons[up].material.index()];
            assert_eq!(dark.name, "lamp (covered side)");
            assert_eq!(dark.reflectance(), s.materials[1].reflectance());
            let side = if faces_up { "front" } else { "back" };
            assert_eq!(
                w.to_string(),
                format!(
                    "lamp.obj:7:1: warning: this emitting face's {side} has a surface 0.020 \
                     units behind it, closer than 5 % of the face's width: that side now emits \
                     nothing, as light sent into so narrow a gap would only seep out at its edge"
                )
            );
        }
    }

    #[test]
    fn a_lamp_hanging_lower_or_over_an_edge_emits_both_ways() {
        // 0.08 below: more than a twentieth of its width.
        let mut low = lamp_under_ceiling(0.08, false);
        assert!(silence(&mut low).is_none());
        assert!(emits(&low, 1) && emits(&low, 2));
        // Half of it past the ceiling's edge: the probes there go free.
        let mut over = lamp_under_ceiling(0.02, false);
        for v in &mut over.polygons[0].vertices {
            v.x = v.x.min(0.5);
        }
        assert!(silence(&mut over).is_none());
    }

    #[test]
    fn one_sided_lamps_and_sandwiched_lamps_are_left_alone() {
        let mut one = testutil::scene(
            vec![quad(1.02, 2.0, 0), quad(1.0, 1.0, 1)],
            vec![
                testutil::grey("wall", 0.0, 0.5),
                testutil::grey("lamp", 1.0, 0.5),
            ],
        );
        assert!(
            silence(&mut one).is_none(),
            "no back copy, nothing to choose"
        );
        let mut sandwich = lamp_under_ceiling(0.02, false);
        let mut floor = quad(0.98, 2.0, 0);
        floor
            .vertices
            .iter_mut()
            .for_each(|v| *v -= Vec3::new(0.5, 0.5, 0.0));
        sandwich.polygons.push(floor);
        assert!(silence(&mut sandwich).is_none(), "covered on both sides");
    }
}
