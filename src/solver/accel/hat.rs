//! A vertex's hat: the elements around it, over which the picture
//! interpolates its value, and the point the sky step asks from.
//!
//! The picture draws each element by interpolating its corners' values
//! (Gouraud), so a vertex's value is the peak of a "hat" that falls to zero
//! at the far side of each element it touches. The value that draws
//! closest to the true radiosity is near the light's mean under the hat
//! (the lumped projection onto the hat functions), not its value at the
//! vertex. The two differ most at a surface's edge, where the hat lies on
//! one side: a floor vertex at the foot of a step, evaluated a few
//! centimetres from the riser ([`crate::mesh::Mesh::sample_positions`]),
//! sees a third of its sky blocked, where its 1.3 m elements, on the whole,
//! lose a few percent; drawn across them, the point's value darkens the
//! whole fan.
//!
//! So the sky step asks each vertex's hemisphere from the centroid of its
//! hat, weighted by the hat: the light there is the hat's mean to first
//! order (exactly, for light that varies linearly). Inside a surface,
//! where the hat surrounds the vertex, the centroid is the vertex itself;
//! at an edge it lies a third of an element in. A shared receivers' leader
//! ([`super::shared`]) takes its whole group's hat: the elements around
//! every member at that point whose polygon lies in the leader's plane
//! ([`crate::visibility::Visibility::coplanar`], so that no ray from the
//! centroid meets them). A centroid that falls outside every element of
//! the hat (a hat wrapped round a corner) is moved back towards the
//! vertex until it lies in one, or else the vertex's own point is kept.
//!
//! The twin ([`crate::solver::Approximations::hat_centroids`] off) asks from
//! the vertex's own point. Spreading each direction over its own random
//! point of the hat, rather than one centroid, was tried: the same
//! accuracy on real levels at 14 to 26 % more time (the rays leave the
//! surface's corners, where walls end them early), and vertex-to-vertex
//! noise under a skylight (docs/changelog.md).

use crate::mesh::{Element, Mesh};
use crate::scene::PolygonId;
use crate::solver::accel::shared::ALONE;
use glam::Vec3;

/// Which elements touch each vertex, and each leader's followers.
///
/// Invariants: `element_starts` and `follower_starts` have one entry per
/// mesh vertex plus one, non-decreasing; each entry of `corners` is an
/// element index times 4 plus the vertex's corner in it; `followers` are
/// grouped by leader.
#[derive(Clone, Debug, Default)]
pub struct Hats {
    element_starts: Vec<u32>,
    corners: Vec<u32>,
    follower_starts: Vec<u32>,
    followers: Vec<u32>,
}

/// Counts per key into CSR starts: `starts[k]..starts[k + 1]` will hold
/// key `k`'s entries.
fn starts_of(n: usize, keys: impl Iterator<Item = usize>) -> Vec<u32> {
    let mut starts = vec![0u32; n + 1];
    for k in keys {
        starts[k + 1] += 1;
    }
    for i in 0..n {
        starts[i + 1] += starts[i];
    }
    starts
}

impl Hats {
    /// The hats of `mesh`'s vertices, with `leaders` as
    /// [`super::shared::leaders`] gives them (empty when off).
    pub fn new(mesh: &Mesh, leaders: &[u32]) -> Hats {
        let n = mesh.vertex_count();
        let corner_keys = || {
            mesh.elements
                .iter()
                .flat_map(|e| e.corners().iter().map(|c| c.index()))
        };
        let element_starts = starts_of(n, corner_keys());
        let mut fill = element_starts.clone();
        let mut corners = vec![0u32; element_starts[n] as usize];
        for (i, e) in mesh.elements.iter().enumerate() {
            for (k, c) in e.corners().iter().enumerate() {
                let at = &mut fill[c.index()];
                corners[*at as usize] = i as u32 * 4 + k as u32;
                *at += 1;
            }
        }
        let led = || leaders.iter().filter(|&&x| x != ALONE).map(|&x| x as usize);
        let follower_starts = starts_of(n, led());
        let mut fill = follower_starts.clone();
        let mut followers = vec![0u32; follower_starts[n] as usize];
        for (l, &x) in leaders.iter().enumerate() {
            if x != ALONE {
                let at = &mut fill[x as usize];
                followers[*at as usize] = l as u32;
                *at += 1;
            }
        }
        Hats {
            element_starts,
            corners,
            follower_starts,
            followers,
        }
    }

    /// Where vertex `l` asks from: the centroid of its hat (its own
    /// elements and those of its followers whose polygon `same_plane`
    /// accepts; between the corners' evaluation points, weighted by the
    /// hat), when it lies in one of those elements; else the nearest of
    /// the points a half, a quarter and an eighth of the way back to the
    /// vertex's evaluation point that does; else that point. Always a
    /// point of an element of the hat, or the vertex's own evaluation
    /// point.
    pub fn centroid(&self, mesh: &Mesh, l: u32, same_plane: impl Fn(PolygonId) -> bool) -> Vec3 {
        let own = mesh.sample_positions[l as usize];
        let (mut sum, mut weight) = (glam::DVec3::ZERO, 0.0f64);
        for (e, k) in self.pieces(mesh, l, &same_plane) {
            let c = e.corners();
            let at = |i: usize| mesh.sample_positions[c[(k + i) % c.len()].index()];
            let share = mesh.element_area(e) / c.len() as f64;
            // A triangle's hat centroid is at barycentric (1/2, 1/4, 1/4)
            // from the vertex; a quad's at bilinear (1/3, 1/3).
            let centre = if c.len() == 3 {
                at(0) * 0.5 + (at(1) + at(2)) * 0.25
            } else {
                at(0) * (4.0 / 9.0) + (at(1) + at(3)) * (2.0 / 9.0) + at(2) * (1.0 / 9.0)
            };
            sum += centre.as_dvec3() * share;
            weight += share;
        }
        if weight <= 0.0 {
            return own;
        }
        let centroid = (sum / weight).as_vec3();
        // Where an element is: its corners' own positions, as an inset
        // leaves gaps between neighbouring elements' evaluation points.
        let inside = |p: Vec3| {
            self.pieces(mesh, l, &same_plane).any(|(e, _)| {
                let c = e.corners();
                let q = |i: usize| mesh.positions[c[i.min(c.len() - 1)].index()];
                in_element(&[q(0), q(1), q(2), q(3)], p)
            })
        };
        [1.0, 0.5, 0.25, 0.125]
            .into_iter()
            .map(|t| own + (centroid - own) * t)
            .find(|&p| inside(p))
            .unwrap_or(own)
    }

    /// The elements of vertex `l`'s hat with area, each with the corner
    /// (`0..4`) of the vertex or follower it belongs to: those around `l`
    /// and around its followers whose polygon `same_plane` accepts.
    fn pieces<'m>(
        &'m self,
        mesh: &'m Mesh,
        l: u32,
        same_plane: &'m impl Fn(PolygonId) -> bool,
    ) -> impl Iterator<Item = (&'m Element, usize)> + 'm {
        let followers = &self.followers[self.follower_starts[l as usize] as usize
            ..self.follower_starts[l as usize + 1] as usize];
        std::iter::once(l)
            .chain(followers.iter().copied())
            .filter(move |&m| m == l || same_plane(mesh.vertex_polygon[m as usize]))
            .flat_map(move |m| {
                self.corners[self.element_starts[m as usize] as usize
                    ..self.element_starts[m as usize + 1] as usize]
                    .iter()
                    .map(move |&ec| (&mesh.elements[(ec / 4) as usize], (ec % 4) as usize))
            })
            .filter(move |(e, _)| {
                let area = mesh.element_area(e);
                area > 0.0 && area.is_finite()
            })
    }
}

/// Whether `p` (in the element's plane, up to rounding) lies in the
/// triangle `q[0..3]` or, when `q[3]` differs from `q[2]`, in the quad
/// `q`: in one of its triangles `0 1 2`, `0 2 3`, edges included with a
/// relative tolerance.
fn in_element(q: &[Vec3; 4], p: Vec3) -> bool {
    let in_triangle = |a: Vec3, b: Vec3, c: Vec3| {
        let n = (b - a).cross(c - a);
        let tolerance = -1e-5 * n.length_squared();
        (b - a).cross(p - a).dot(n) >= tolerance
            && (c - b).cross(p - b).dot(n) >= tolerance
            && (a - c).cross(p - c).dot(n) >= tolerance
    };
    in_triangle(q[0], q[1], q[2]) || (q[3] != q[2] && in_triangle(q[0], q[2], q[3]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{build, MeshOptions};
    use crate::testutil;

    /// A `4 × 4` floor meshed at `lenmax` without inset (elements of 1 at
    /// a lenmax just over 1: every element edge is shorter than it), and
    /// the vertex nearest to `at`.
    fn floor(lenmax: f32, at: Vec3) -> (Mesh, u32) {
        let s = testutil::scene(
            vec![testutil::polygon(
                0,
                &[[0., 0., 0.], [0., 0., 4.], [4., 0., 4.], [4., 0., 0.]],
            )],
            vec![testutil::grey("floor", 0.0, 0.5)],
        );
        let mesh = build(&s, &MeshOptions { lenmax, inset: 0.0 }).unwrap();
        let l = (0..mesh.vertex_count() as u32)
            .min_by(|&a, &b| {
                let d = |v: u32| mesh.positions[v as usize].distance(at);
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        (mesh, l)
    }

    /// Polygons of one floor material meshed at `lenmax` without inset,
    /// their shared receivers' leaders, and the leader at `at`.
    fn leader_at(
        polygons: Vec<crate::scene::Polygon>,
        lenmax: f32,
        at: Vec3,
    ) -> (Mesh, Vec<u32>, u32) {
        let s = testutil::scene(polygons, vec![testutil::grey("floor", 0.0, 0.5)]);
        let mesh = build(&s, &MeshOptions { lenmax, inset: 0.0 }).unwrap();
        let visibility = crate::visibility::Visibility::new(&s);
        let leaders = crate::solver::accel::shared::leaders(&s, &mesh, &visibility, true);
        let l = (0..mesh.vertex_count() as u32)
            .find(|&v| mesh.positions[v as usize] == at && leaders[v as usize] == ALONE)
            .expect("a leader there");
        (mesh, leaders, l)
    }

    #[test]
    fn inside_a_surface_the_centroid_is_the_vertex() {
        let (mesh, l) = floor(1.01, Vec3::new(2.0, 0.0, 2.0));
        let c = Hats::new(&mesh, &[]).centroid(&mesh, l, |_| true);
        assert!(c.distance(mesh.positions[l as usize]) < 1e-6, "{c}");
    }

    #[test]
    fn at_an_edge_the_centroid_is_a_third_of_an_element_in() {
        // On the edge x = 0, a half hat of quads 1 wide: the bilinear
        // weight (1 − s) puts the centroid at s = 1/3 across.
        let (mesh, l) = floor(1.01, Vec3::new(0.0, 0.0, 2.0));
        let v = mesh.positions[l as usize];
        let c = Hats::new(&mesh, &[]).centroid(&mesh, l, |_| true);
        assert!(
            (c - v - Vec3::new(1.0 / 3.0, 0.0, 0.0)).length() < 1e-5,
            "{v} → {c}"
        );
        // At a corner, a third in along both edges.
        let (mesh, l) = floor(1.01, Vec3::new(4.0, 0.0, 4.0));
        let v = mesh.positions[l as usize];
        let c = Hats::new(&mesh, &[]).centroid(&mesh, l, |_| true);
        assert!(
            (c - v - Vec3::new(-1.0, 0.0, -1.0) / 3.0).length() < 1e-5,
            "{v} → {c}"
        );
    }

    #[test]
    fn a_centroid_outside_the_hat_falls_back_to_the_vertex() {
        // Two thin triangles of one floor meeting only at the origin, as
        // a V: their hat's centroid lies between the arms, on neither,
        // and so does every point back towards the vertex.
        let (mesh, leaders, l) = leader_at(
            vec![
                testutil::polygon(0, &[[0., 0., 0.], [1., 0., -0.1], [1., 0., -0.2]]),
                testutil::polygon(0, &[[0., 0., 0.], [-0.2, 0., 1.], [-0.1, 0., 1.]]),
            ],
            10.0,
            Vec3::ZERO,
        );
        let hats = Hats::new(&mesh, &leaders);
        let own = mesh.sample_positions[l as usize];
        assert_eq!(hats.centroid(&mesh, l, |_| true), own);
        // One arm alone holds its centroid.
        let one = hats.centroid(&mesh, l, |_| false);
        assert!(one != own && one.x > 0.4, "{one}");
    }

    #[test]
    fn a_point_is_in_an_element_when_in_one_of_its_triangles() {
        let quad = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        assert!(in_element(&quad, Vec3::new(0.2, 0.0, 0.9)));
        assert!(in_element(&quad, Vec3::new(0.9, 0.0, 0.2)));
        assert!(in_element(&quad, Vec3::new(1.0, 0.0, 0.5)));
        assert!(!in_element(&quad, Vec3::new(1.1, 0.0, 0.5)));
        let triangle = [quad[0], quad[1], quad[2], quad[2]];
        assert!(in_element(&triangle, Vec3::new(0.9, 0.0, 0.2)));
        assert!(!in_element(&triangle, Vec3::new(0.2, 0.0, 0.9)));
    }

    #[test]
    fn followers_in_the_plane_join_the_leaders_hat() {
        // Two floors side by side, 0 ≤ x ≤ 2 and 2 ≤ x ≤ 4: a vertex on
        // the seam at x = 2 has half a hat on each.
        let seam = Vec3::new(2.0, 0.0, 2.0);
        let (mesh, leaders, l) = leader_at(
            vec![
                testutil::polygon(0, &[[0., 0., 0.], [0., 0., 4.], [2., 0., 4.], [2., 0., 0.]]),
                testutil::polygon(0, &[[2., 0., 0.], [2., 0., 4.], [4., 0., 4.], [4., 0., 0.]]),
            ],
            1.01,
            seam,
        );
        let hats = Hats::new(&mesh, &leaders);
        let both = hats.centroid(&mesh, l, |_| true);
        assert!(both.distance(seam) < 1e-5, "{both}");
        // Without its follower, the leader's half hat pulls a third in.
        let alone = hats.centroid(&mesh, l, |_| false);
        assert!((alone - seam).length() > 0.3, "{alone}");
    }
}
