//! Smooth surfaces: which element vertices of different polygons show one
//! radiosity, so that a curved surface modelled with flat facets (an
//! icosphere saved with Blender's Shade Smooth) is drawn without visible
//! facet edges.
//!
//! The solver stays per polygon: every element vertex gets its own
//! radiosity from its own polygon's plane, and visibility and front/back
//! use the geometric normals. A [`Weld`] is a map over the mesh, built with
//! it (and again after each refinement): groups of vertices at the same
//! position, bit for bit (stitching, [`super::stitch`], makes shared
//! boundary positions exact), that belong to polygons of one smooth surface
//! ([`crate::scene::Surface::smooth`]), with one material, and whose
//! geometric normals differ by at most [`CREASE_ANGLE_DEG`] (joined in
//! pairs: two facets farther apart can still be in one group through the
//! facets between them, as around the tip of a cone). [`Weld::apply`]
//! replaces the radiosity of each group's vertices by their area-weighted
//! mean ([`Mesh::vertex_areas`]), so the picture is continuous across the
//! facet edge, as Blender's Shade Smooth interpolates one vertex normal.
//!
//! A polygon's back copy (reversed, `Surface::back_of`) has the opposite
//! normal, 180° from its front: the two are never welded.

use super::Mesh;
use crate::color::Rgb;
use crate::scene::Scene;

/// Largest angle between two facets' normals, in degrees, at which their
/// common vertices are welded. The smoothing groups and shared normals of
/// a file say which faces form one surface; this guards against the hard
/// edges such a surface may still have (Blender writes one `s 1` for a
/// whole object shaded smooth, a box included). 60° keeps a cube's 90°
/// edges sharp and welds everything coarser surfaces need: an
/// icosahedron's facets are 41.8° apart, a hexagonal cylinder's 60°,
/// a UV sphere of 8 segments 45°. (Blender's own Auto Smooth default is
/// 30°, which would leave an icosahedron and an octagonal cylinder
/// faceted.)
pub const CREASE_ANGLE_DEG: f64 = 60.0;

/// Groups of welded vertices (see the module docs).
///
/// Invariants: every group has at least two vertices, all of them
/// vertices of the mesh it was built from; no vertex is in two groups;
/// `weights` are non-negative and sum to 1 over each group.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Weld {
    /// Vertex ids of every group, one group after the other.
    members: Vec<u32>,
    /// Each member's weight in its group's mean: its share of the
    /// group's vertex area.
    weights: Vec<f64>,
    /// Where each group starts in `members`, plus the end.
    starts: Vec<u32>,
}

impl Weld {
    /// The welds of `mesh`, built from `scene` (whose polygons say which
    /// smooth surface each belongs to).
    pub fn new(scene: &Scene, mesh: &Mesh) -> Weld {
        let cos_crease = CREASE_ANGLE_DEG.to_radians().cos() - 1e-9;
        let smooth_of = |v: u32| {
            let p = mesh.vertex_polygon[v as usize];
            scene.polygons[p.index()].surface.smooth
        };
        // Vertices of smooth polygons, by exact position.
        let mut candidates: Vec<([u32; 3], u32)> = (0..mesh.vertex_count() as u32)
            .filter(|&v| smooth_of(v).is_some())
            .map(|v| (mesh.positions[v as usize].to_array().map(f32::to_bits), v))
            .collect();
        if candidates.len() < 2 {
            return Weld::default();
        }
        candidates.sort_unstable();
        let areas = mesh.vertex_areas();
        let mut weld = Weld {
            starts: vec![0],
            ..Weld::default()
        };
        let mut parent: Vec<usize> = Vec::new();
        let mut groups: Vec<(usize, u32)> = Vec::new();
        let mut s = 0;
        while s < candidates.len() {
            let mut e = s + 1;
            while e < candidates.len() && candidates[e].0 == candidates[s].0 {
                e += 1;
            }
            let run: Vec<u32> = candidates[s..e].iter().map(|c| c.1).collect();
            s = e;
            if run.len() < 2 {
                continue;
            }
            // Join pairs of one surface and material within the crease.
            parent.clear();
            parent.extend(0..run.len());
            for i in 0..run.len() {
                for j in i + 1..run.len() {
                    let (pi, pj) = (
                        &scene.polygons[mesh.vertex_polygon[run[i] as usize].index()],
                        &scene.polygons[mesh.vertex_polygon[run[j] as usize].index()],
                    );
                    if pi.surface.smooth == pj.surface.smooth
                        && pi.material == pj.material
                        && pi.normal.as_dvec3().dot(pj.normal.as_dvec3()) >= cos_crease
                    {
                        let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                        parent[a.max(b)] = a.min(b);
                    }
                }
            }
            groups.clear();
            groups.extend((0..run.len()).map(|i| (find(&mut parent, i), run[i])));
            groups.sort_unstable();
            let mut g = 0;
            while g < groups.len() {
                let mut h = g + 1;
                while h < groups.len() && groups[h].0 == groups[g].0 {
                    h += 1;
                }
                if h - g >= 2 {
                    let total: f64 = groups[g..h].iter().map(|m| areas[m.1 as usize]).sum();
                    for m in &groups[g..h] {
                        weld.members.push(m.1);
                        weld.weights.push(if total > 0.0 {
                            areas[m.1 as usize] / total
                        } else {
                            1.0 / (h - g) as f64
                        });
                    }
                    weld.starts.push(weld.members.len() as u32);
                }
                g = h;
            }
        }
        weld
    }

    /// Number of groups.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// True when nothing is welded.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The vertex ids of group `g`.
    pub fn group(&self, g: usize) -> &[u32] {
        &self.members[self.starts[g] as usize..self.starts[g + 1] as usize]
    }

    /// Gives every vertex of each group the group's area-weighted mean
    /// radiosity; `radiosity` holds one value per vertex of the mesh the
    /// weld was built from.
    pub fn apply(&self, radiosity: &mut [Rgb]) {
        for g in 0..self.len() {
            let range = self.starts[g] as usize..self.starts[g + 1] as usize;
            let mean = self.members[range.clone()]
                .iter()
                .zip(&self.weights[range.clone()])
                .fold(Rgb::splat(0.0), |sum, (&v, &w)| {
                    sum + radiosity[v as usize] * w
                });
            for &v in &self.members[range] {
                radiosity[v as usize] = mean;
            }
        }
    }
}

/// The root of `i` in the union-find forest `parent` (each entry its
/// parent, a root its own), halving the path on the way.
pub(crate) fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{build, MeshOptions};
    use crate::scene::{PolygonId, SmoothId};
    use crate::testutil;

    /// Two unit squares hinged along x = 0, the second folded by `angle`
    /// degrees, both in smooth surface `smooth` of `a` and `b`, and the
    /// reversed copy of the first (a back side) when `back`.
    fn hinge(angle: f32, smooth: [Option<u32>; 2], back: bool) -> Scene {
        let (s, c) = angle.to_radians().sin_cos();
        let mut polygons = vec![
            testutil::polygon(
                0,
                &[[-1., 0., 0.], [0., 0., 0.], [0., 1., 0.], [-1., 1., 0.]],
            ),
            testutil::polygon(0, &[[0., 0., 0.], [c, 0., s], [c, 1., s], [0., 1., 0.]]),
        ];
        for (p, id) in polygons.iter_mut().zip(smooth) {
            p.surface.smooth = id.map(SmoothId);
        }
        if back {
            let mut b = polygons[0].clone();
            b.vertices.reverse();
            b.normal = -b.normal;
            b.surface.back_of = Some(PolygonId(0));
            polygons.push(b);
        }
        testutil::scene(polygons, vec![testutil::grey("m", 0.0, 0.5)])
    }

    fn weld_of(scene: &Scene) -> (Mesh, Weld) {
        let mesh = build(
            scene,
            &MeshOptions {
                lenmax: 0.3,
                inset: 0.05,
            },
        )
        .unwrap();
        let weld = Weld::new(scene, &mesh);
        (mesh, weld)
    }

    #[test]
    fn a_fold_within_the_crease_is_welded_along_the_hinge_only() {
        let s = hinge(40.0, [Some(0), Some(0)], false);
        let (mesh, weld) = weld_of(&s);
        // The hinge x = 0 carries the same 5 positions on both sides.
        assert_eq!(weld.len(), 5);
        for g in 0..weld.len() {
            let group = weld.group(g);
            assert_eq!(group.len(), 2);
            assert!(group.iter().all(|&v| mesh.positions[v as usize].x == 0.0));
        }
        // The area-weighted mean: equal areas here, so the plain mean.
        let mut values: Vec<Rgb> = (0..mesh.vertex_count())
            .map(|v| Rgb::splat(mesh.vertex_polygon[v].0 as f64 + 1.0))
            .collect();
        weld.apply(&mut values);
        for (v, value) in values.iter().enumerate() {
            let expect = if mesh.positions[v].x == 0.0 {
                1.5
            } else {
                mesh.vertex_polygon[v].0 as f64 + 1.0
            };
            assert!((value.luminance() - expect).abs() < 1e-5);
        }
    }

    #[test]
    fn creases_other_surfaces_faceted_faces_and_back_sides_are_not_welded() {
        for s in [
            hinge(CREASE_ANGLE_DEG as f32 + 1.0, [Some(0), Some(0)], false),
            hinge(20.0, [Some(0), Some(1)], false),
            hinge(20.0, [None, None], false),
        ] {
            assert!(weld_of(&s).1.is_empty());
        }
        // The back copy shares every position of the front but faces
        // the other way: only the hinge (front with front) is welded.
        let (mesh, weld) = weld_of(&hinge(20.0, [Some(0), Some(0)], true));
        assert_eq!(weld.len(), 5);
        for g in 0..weld.len() {
            assert!(weld
                .group(g)
                .iter()
                .all(|&v| mesh.vertex_polygon[v as usize] != PolygonId(2)));
        }
    }
}
