//! Shared receivers: element vertices of different polygons at one point
//! of one surface receive as one.
//!
//! Polygons never share element vertices ([`crate::mesh`]): each keeps its
//! own radiosity, as a crease or a material edge needs. But a real export
//! is mostly triangles that continue one surface: a flat wall of a game
//! level written as hundreds of coplanar triangles, a sphere of thousands
//! of facets a few degrees apart. Where such triangles meet, each has its
//! own vertex at the same point, and a step evaluated each of them: on a
//! 70,000-triangle level 766,000 element vertices stand at 485,000 points
//! of its surfaces, and on Godot's room of 16 spheres 262,000 at 97,000.
//!
//! Vertices at the same position (bit for bit: stitching makes shared
//! boundary points exact) join a group when their polygons have one
//! material, are both smooth surfaces of one id or both not smooth, and
//! have normals at most [`SHARE_CREASE_DEG`] apart: one surface, locally
//! one plane. The vertex of lowest index leads the group; in a step, a
//! follower whose leader is evaluated exactly (its polygon receives, and
//! neither is interpolated) takes the leader's `Δrad` instead of its own
//! ([`crate::solver::step::gather`]).
//!
//! A member follows a leader only when it sees it: no polygon out of
//! their planes crosses the segment between their evaluation points,
//! lifted off the surface by half its length. A
//! wall standing on the point splits the group into its sides, each led
//! by its lowest vertex. Without this test, a game level's floor on both
//! sides of a fin's foot followed one leader: on `pandora.obj` a vertex
//! took 0.42 from a leader beside a shooting wall where its own point
//! got 0.0015, and over a step the followers took 3 % more light than
//! they would have alone; shooting to 10 % unshot made the picture 6 %
//! too bright, 3 points of it from the shared receivers. The error left is that of
//! evaluating a point a few degrees off its own normal, or at its
//! neighbour's inset point (a twentieth of an element away); a back copy
//! (normal reversed), another material, a crease or a sky facet never
//! shares. Off ([`crate::solver::Approximations::shared_receivers`]),
//! every vertex is evaluated alone.
//!
//! [`SHARE_CREASE_DEG`]: crate::solver::tuning::SHARE_CREASE_DEG

use crate::mesh::weld::find;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solver::tuning::SHARE_CREASE_DEG;
use crate::visibility::Visibility;
use rayon::prelude::*;

/// No leader: the vertex is evaluated alone.
pub const ALONE: u32 = u32::MAX;

/// Per mesh vertex, the vertex it takes its `Δrad` from, or [`ALONE`].
///
/// Invariants: a leader has a lower index than its followers (so its
/// polygon comes first) and is itself [`ALONE`]; a vertex and its leader
/// stand at the same position on two polygons of one material, and no
/// polygon of `visibility` (other than in their planes) crosses the
/// segment between their evaluation points, each lifted along its
/// polygon's normal by half the points' distance.
pub fn leaders(scene: &Scene, mesh: &Mesh, visibility: &Visibility, on: bool) -> Vec<u32> {
    let n = mesh.vertex_count();
    let mut leader = vec![ALONE; if on { n } else { 0 }];
    if !on || n < 2 {
        return leader;
    }
    let cos_crease = f64::from(SHARE_CREASE_DEG).to_radians().cos() - 1e-9;
    let polygon_of = |v: u32| &scene.polygons[mesh.vertex_polygon[v as usize].index()];
    let mut by_position: Vec<([u32; 3], u32)> = (0..n as u32)
        .filter(|&v| {
            let p = polygon_of(v);
            !p.surface.sky
        })
        .map(|v| (mesh.positions[v as usize].to_array().map(f32::to_bits), v))
        .collect();
    by_position.sort_unstable();
    let mut parent: Vec<usize> = Vec::new();
    // (group root, member) for every member that is not its root.
    let mut groups: Vec<(u32, u32)> = Vec::new();
    let mut s = 0;
    while s < by_position.len() {
        let mut e = s + 1;
        while e < by_position.len() && by_position[e].0 == by_position[s].0 {
            e += 1;
        }
        let run = &by_position[s..e];
        s = e;
        if run.len() < 2 {
            continue;
        }
        parent.clear();
        parent.extend(0..run.len());
        for i in 0..run.len() {
            for j in i + 1..run.len() {
                let (a, b) = (polygon_of(run[i].1), polygon_of(run[j].1));
                let apart = mesh.vertex_polygon[run[i].1 as usize]
                    != mesh.vertex_polygon[run[j].1 as usize];
                if apart
                    && a.material == b.material
                    && a.surface.smooth == b.surface.smooth
                    && a.normal.as_dvec3().dot(b.normal.as_dvec3()) >= cos_crease
                {
                    let (ra, rb) = (find(&mut parent, i), find(&mut parent, j));
                    parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        // The run is sorted by vertex within equal positions, so each
        // group's members are listed lowest vertex first.
        for i in 0..run.len() {
            let root = find(&mut parent, i);
            if root != i {
                groups.push((run[root].1, run[i].1));
            }
        }
    }
    // Per group (its root's run of pairs), who follows whom: each member
    // follows the lowest member it sees, in turn.
    groups.sort_unstable();
    let runs: Vec<&[(u32, u32)]> = groups.chunk_by(|a, b| a.0 == b.0).collect();
    let follow: Vec<Vec<(u32, u32)>> = runs
        .par_iter()
        .map(|run| {
            let mut left: Vec<u32> = std::iter::once(run[0].0)
                .chain(run.iter().map(|g| g.1))
                .collect();
            let mut out = Vec::new();
            while let Some((&lead, rest)) = left.split_first() {
                // The segment is lifted off the surface by half its
                // length: in the plane it would only graze the foot of
                // a wall standing on the point, along the wall's edge.
                let sees = |v: u32| {
                    let (pv, pl) = (
                        mesh.vertex_polygon[v as usize],
                        mesh.vertex_polygon[lead as usize],
                    );
                    let (a, b) = (
                        mesh.sample_positions[v as usize],
                        mesh.sample_positions[lead as usize],
                    );
                    let lift = 0.5 * a.distance(b);
                    let up = |p: crate::scene::PolygonId| {
                        mesh.polygons[p.index()].normal.normalize_or_zero() * lift
                    };
                    !visibility.occluded(a + up(pv), b + up(pl), (pv, pl))
                };
                let (with, apart): (Vec<u32>, Vec<u32>) = rest.iter().partition(|&&v| sees(v));
                out.extend(with.into_iter().map(|v| (v, lead)));
                left = apart;
            }
            out
        })
        .collect();
    for (v, lead) in follow.into_iter().flatten() {
        leader[v as usize] = lead;
    }
    leader
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{build, MeshOptions};
    use crate::scene::SmoothId;
    use crate::testutil;

    /// Two unit squares hinged along x = 0, the second folded by `angle`
    /// degrees, of materials `m`; with `smooth`, both of smooth surface 0.
    fn hinge(angle: f32, m: [u32; 2], smooth: bool) -> (Scene, Mesh) {
        let (s, c) = angle.to_radians().sin_cos();
        let mut polygons = vec![
            testutil::polygon(
                m[0],
                &[[-1., 0., 0.], [0., 0., 0.], [0., 1., 0.], [-1., 1., 0.]],
            ),
            testutil::polygon(m[1], &[[0., 0., 0.], [c, 0., s], [c, 1., s], [0., 1., 0.]]),
        ];
        if smooth {
            for p in &mut polygons {
                p.surface.smooth = Some(SmoothId(0));
            }
        }
        let scene = testutil::scene(
            polygons,
            vec![testutil::grey("a", 0.0, 0.5), testutil::grey("b", 0.0, 0.5)],
        );
        let mesh = build(
            &scene,
            &MeshOptions {
                lenmax: 0.25,
                inset: crate::mesh::DEFAULT_INSET,
            },
        )
        .unwrap();
        (scene, mesh)
    }

    /// The followers of `leader` and the vertices they follow.
    fn pairs(leader: &[u32]) -> Vec<(u32, u32)> {
        leader
            .iter()
            .enumerate()
            .filter(|(_, &l)| l != ALONE)
            .map(|(v, &l)| (v as u32, l))
            .collect()
    }

    #[test]
    fn a_flat_seam_of_one_material_shares_every_vertex_along_it() {
        let (scene, mesh) = hinge(0.0, [0, 0], false);
        let leader = leaders(&scene, &mesh, &Visibility::new(&scene), true);
        let shared = pairs(&leader);
        // Every point of the first square's mesh on the seam x = 0.
        let seam = mesh.polygons[0]
            .vertices
            .clone()
            .filter(|&v| mesh.positions[v as usize].x == 0.0)
            .count();
        assert!(seam >= 2);
        assert_eq!(shared.len(), seam, "{shared:?}");
        for (v, l) in shared {
            assert!(l < v);
            assert_eq!(leader[l as usize], ALONE);
            assert_eq!(mesh.positions[v as usize], mesh.positions[l as usize]);
            assert_ne!(
                mesh.vertex_polygon[v as usize],
                mesh.vertex_polygon[l as usize]
            );
        }
    }

    #[test]
    fn a_crease_or_another_material_shares_nothing() {
        let crease = SHARE_CREASE_DEG + 5.0;
        for (angle, m, smooth) in [
            (crease, [0, 0], false),
            (crease, [0, 0], true),
            (0.0, [0, 1], false),
        ] {
            let (scene, mesh) = hinge(angle, m, smooth);
            assert!(
                pairs(&leaders(&scene, &mesh, &Visibility::new(&scene), true)).is_empty(),
                "{angle} {m:?}"
            );
        }
        // Within the crease, a smooth pair shares.
        let (scene, mesh) = hinge(SHARE_CREASE_DEG - 5.0, [0, 0], true);
        assert!(!pairs(&leaders(&scene, &mesh, &Visibility::new(&scene), true)).is_empty());
    }

    #[test]
    fn a_wall_standing_on_a_seam_splits_it_into_its_sides() {
        // Two floor squares meeting along x = 0, and a wall of another
        // material standing on that seam.
        let floor = |x0: f32, x1: f32| {
            testutil::polygon(0, &[[x0, 0., 0.], [x1, 0., 0.], [x1, 1., 0.], [x0, 1., 0.]])
        };
        let wall = testutil::polygon(1, &[[0., 0., 0.], [0., 1., 0.], [0., 1., 1.], [0., 0., 1.]]);
        let scene = testutil::scene(
            vec![floor(-1.0, 0.0), floor(0.0, 1.0), wall],
            vec![
                testutil::grey("floor", 0.0, 0.5),
                testutil::grey("wall", 0.0, 0.5),
            ],
        );
        let options = MeshOptions {
            lenmax: 0.25,
            inset: crate::mesh::DEFAULT_INSET,
        };
        let mesh = build(&scene, &options).unwrap();
        let visibility = Visibility::new(&scene);
        assert!(pairs(&leaders(&scene, &mesh, &visibility, true)).is_empty());
        // Without the wall, the same seam is shared.
        let open = testutil::scene(
            vec![floor(-1.0, 0.0), floor(0.0, 1.0)],
            vec![testutil::grey("floor", 0.0, 0.5)],
        );
        let mesh = build(&open, &options).unwrap();
        let shared = pairs(&leaders(&open, &mesh, &Visibility::new(&open), true));
        assert!(shared.len() >= 5, "{shared:?}");
    }

    #[test]
    fn off_shares_nothing() {
        let (scene, mesh) = hinge(0.0, [0, 0], false);
        assert!(leaders(&scene, &mesh, &Visibility::new(&scene), false).is_empty());
    }
}
