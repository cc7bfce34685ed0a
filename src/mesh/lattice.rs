//! Meshing a convex polygon of many vertices: its rim cut every `lenmax`,
//! a triangular lattice of spacing about `lenmax` inside it, and the
//! Delaunay triangulation of both.
//!
//! A fan around the centroid would cut each of the `m` fan triangles `n`
//! times per edge (`m · n²` elements, `n` set by the spokes), and its long
//! thin triangles meet at one point: a 1,000-vertex disc became 722,722
//! elements, a 100,000-vertex one never finished meshing. The lattice's
//! element count follows the polygon's area and perimeter instead
//! (about `2 · area / (0.87 · lenmax²) + perimeter / lenmax + m`), its
//! interior elements are equilateral, and no element reaches across the
//! polygon.
//!
//! The rim (after collinear vertices are dropped) is the convex hull of
//! every point inserted, so the Delaunay triangulation covers exactly the
//! polygon; points added on rim edges lie on those edges, where
//! [`super::stitch`] and the inset look for them.
//!
//! **Rim vertices closer to a chord than the on-edge tolerance** (a
//! fraction of the polygon's size, [`super::ON_EDGE_TOLERANCE`]) are left
//! out ([`simplify`]): the mesher counts them as lying on that chord
//! anyway, and stitching puts a neighbour's vertex there back into the
//! element edge. A 100,000-vertex circle keeps about 500.

use glam::{DVec2, DVec3, Vec3};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

/// Lattice spacing as a fraction of `lenmax`: below one, so that the
/// triangles between the lattice and the rim stay under about `lenmax`.
const SPACING: f64 = 0.95;

/// Lattice points keep at least this fraction of the spacing from the
/// rim, so no element between them and the rim is a sliver across it.
const MARGIN: f64 = 0.45;

/// The triangles of a convex polygon meshed at `lenmax`.
#[derive(Debug, Default)]
pub struct LatticeMesh {
    /// Vertex positions, in scene units: the rim vertices and the points
    /// on rim edges first (exactly on their edges), then the lattice.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`, counter-clockwise about the
    /// polygon's normal.
    pub triangles: Vec<[u32; 3]>,
    /// The shortest triangle edge, in scene units.
    pub min_edge: f32,
}

/// One point inserted into the triangulation, remembering which of
/// [`LatticeMesh::positions`] it is.
struct Site {
    at: Point2<f64>,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.at
    }
}

/// Meshes the convex polygon `rim` (counter-clockwise about `normal`, no
/// collinear vertices, at least three) with elements of about `lenmax`
/// (scene units, > 0).
pub fn mesh(rim: &[Vec3], normal: Vec3, lenmax: f32) -> LatticeMesh {
    let plane = Plane::new(rim, normal);
    let lenmax = f64::from(lenmax);
    let mut out = LatticeMesh::default();
    let mut sites: Vec<(DVec2, Vec3)> = Vec::new();

    // The rim, each edge cut into pieces shorter than lenmax.
    let m = rim.len();
    for k in 0..m {
        let (a, b) = (rim[k], rim[(k + 1) % m]);
        let pieces = super::divisions(a.distance(b), lenmax as f32);
        for t in 0..pieces {
            let p = a.lerp(b, t as f32 / pieces as f32);
            sites.push((plane.project(p), p));
        }
    }

    // The lattice: rows `SPACING · lenmax · √3/2` apart, alternate rows
    // shifted by half a spacing, each point at least `MARGIN` spacings
    // inside every edge's line (for a convex polygon, inside the rim and
    // that far from it).
    let h = SPACING * lenmax;
    let margin = MARGIN * h;
    let edges: Vec<(DVec2, DVec2)> = (0..m)
        .map(|k| {
            let (a, b) = (plane.project(rim[k]), plane.project(rim[(k + 1) % m]));
            let d = (b - a).normalize_or_zero();
            (a, DVec2::new(-d.y, d.x))
        })
        .collect();
    let (lo, hi) = edges.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &(a, _)| (lo.min(a), hi.max(a)),
    );
    let dy = h * 3f64.sqrt() / 2.0;
    let rows = ((hi.y - lo.y) / dy).floor() as i64;
    for row in 0..=rows {
        let y = lo.y + row as f64 * dy;
        // Where the row is at least `margin` inside every edge's line:
        // inward · (p − a) ≥ margin, solved for x.
        let (mut x0, mut x1) = (lo.x, hi.x);
        for &(a, inward) in &edges {
            let rest = margin - inward.y * (y - a.y) + inward.x * a.x;
            if inward.x > 1e-12 {
                x0 = x0.max(rest / inward.x);
            } else if inward.x < -1e-12 {
                x1 = x1.min(rest / inward.x);
            } else if rest > 0.0 {
                x1 = f64::NEG_INFINITY;
            }
        }
        if x0 > x1 {
            continue;
        }
        // Columns on the global lattice, so neighbouring rows interleave.
        let shift = if row % 2 == 1 { 0.5 * h } else { 0.0 };
        let first = ((x0 - lo.x - shift) / h).ceil() as i64;
        let last = ((x1 - lo.x - shift) / h).floor() as i64;
        for col in first..=last {
            let p = DVec2::new(lo.x + shift + col as f64 * h, y);
            sites.push((p, plane.lift(p)));
        }
    }

    let mut triangulation: DelaunayTriangulation<Site> = DelaunayTriangulation::new();
    // The triangulation's vertex index → position index; a point equal to
    // one already inserted (a rim vertex repeated within rounding) is
    // merged with it.
    let mut index_of: Vec<u32> = Vec::with_capacity(sites.len());
    for &(p, world) in &sites {
        let site = Site {
            at: Point2::new(p.x, p.y),
        };
        let Ok(handle) = triangulation.insert(site) else {
            // Not finite: a degenerate polygon, which the loader refuses.
            continue;
        };
        if handle.index() == index_of.len() {
            index_of.push(out.positions.len() as u32);
            out.positions.push(world);
        }
    }

    let mut shortest = f64::INFINITY;
    for face in triangulation.inner_faces() {
        let v = face.vertices();
        let ids = v.map(|v| index_of[v.fix().index()]);
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (p, q) = (v[a].position(), v[b].position());
            shortest = shortest.min((p.x - q.x).hypot(p.y - q.y));
        }
        out.triangles.push(ids);
    }
    out.min_edge = shortest as f32;
    out
}

/// The rim without the vertices within `tolerance` (scene units) of the
/// chord between the vertices kept on either side; the first vertex is
/// always kept.
pub fn simplify(rim: &[Vec3], tolerance: f32) -> Vec<Vec3> {
    // A chord is tried over at most this many vertices, so a rim of
    // many vertices all near one line costs linear time, not quadratic.
    const LONGEST_RUN: usize = 4096;
    let m = rim.len();
    let at = |k: usize| rim[k % m].as_dvec3();
    let tolerance = f64::from(tolerance);
    let within = |i: usize, j: usize| {
        let (a, b) = (at(i), at(j));
        let dir = (b - a).normalize_or_zero();
        (i + 1..j).all(|k| {
            let rel = at(k) - a;
            (rel - rel.dot(dir) * dir).length() <= tolerance
        })
    };
    let mut kept = vec![rim[0]];
    let mut i = 0;
    let mut j = 2;
    while j <= m {
        if j - i > LONGEST_RUN || !within(i, j) {
            i = j - 1;
            kept.push(rim[i]);
        }
        j += 1;
    }
    if kept.len() >= 3 {
        kept
    } else {
        rim.to_vec()
    }
}

/// The polygon's plane: 2D coordinates along an orthonormal basis
/// `(u, v)` with `u × v` the polygon's normal, so counter-clockwise in
/// the plane is counter-clockwise about the normal.
struct Plane {
    origin: DVec3,
    u: DVec3,
    v: DVec3,
}

impl Plane {
    fn new(rim: &[Vec3], normal: Vec3) -> Plane {
        let origin = rim[0].as_dvec3();
        let n = normal.as_dvec3().normalize();
        // The longest edge from the first vertex gives a well-conditioned
        // first axis.
        let far = rim
            .iter()
            .map(|p| p.as_dvec3())
            .max_by(|a, b| a.distance(origin).total_cmp(&b.distance(origin)))
            .unwrap_or(origin);
        let along = far - origin;
        let u = (along - along.dot(n) * n).normalize();
        Plane {
            origin,
            u,
            v: n.cross(u),
        }
    }

    fn project(&self, p: Vec3) -> DVec2 {
        let d = p.as_dvec3() - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.v))
    }

    fn lift(&self, p: DVec2) -> Vec3 {
        (self.origin + p.x * self.u + p.y * self.v).as_vec3()
    }
}

/// Upper bounds of the lattice mesh's `(elements, vertices)` at `lenmax`
/// for a convex polygon of `rim` vertices, `area` and `perimeter` (scene
/// units): for a mesh size estimate, without building it.
pub fn size_at(area: f32, perimeter: f32, rim: u32, lenmax: f32) -> (u64, u64) {
    let h = SPACING * f64::from(lenmax);
    let boundary = f64::from(perimeter) / f64::from(lenmax) + f64::from(rim);
    let lattice = f64::from(area) / (h * h * 3f64.sqrt() / 2.0) + f64::from(perimeter) / h + 1.0;
    let saturate = |x: f64| {
        if x >= u64::MAX as f64 / 4.0 {
            u64::MAX / 4
        } else {
            x.ceil() as u64
        }
    };
    let (boundary, lattice) = (saturate(boundary), saturate(lattice));
    // A triangulation of V points, B of them on the hull, has 2V − B − 2
    // triangles.
    let elements = boundary.saturating_add(lattice.saturating_mul(2));
    (elements, boundary.saturating_add(lattice))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn regular(m: usize, radius: f32) -> Vec<Vec3> {
        (0..m)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / m as f32;
                Vec3::new(radius * a.cos(), 0.0, -radius * a.sin())
            })
            .collect()
    }

    fn area_of(mesh: &LatticeMesh, normal: Vec3) -> f64 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
                (b - a).cross(c - a).dot(normal.as_dvec3()) / 2.0
            })
            .sum()
    }

    #[test]
    fn covers_the_polygon_counter_clockwise_with_short_edges() {
        let rim = regular(1000, 1.0);
        let normal = Vec3::Y;
        let lenmax = 0.1;
        let mesh = mesh(&rim, normal, lenmax);
        // Every triangle faces the normal (a clockwise one would subtract).
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
            assert!((b - a).cross(c - a).dot(DVec3::Y) > 0.0);
        }
        // The triangles tile the polygon: their areas sum to its area.
        let exact = 0.5 * 1000.0 * (std::f64::consts::TAU / 1000.0).sin();
        assert!((area_of(&mesh, normal) - exact).abs() < 1e-5 * exact);
        // No element reaches far past lenmax.
        let longest = mesh
            .triangles
            .iter()
            .flat_map(|t| {
                let p = t.map(|i| mesh.positions[i as usize]);
                [
                    p[0].distance(p[1]),
                    p[1].distance(p[2]),
                    p[2].distance(p[0]),
                ]
            })
            .fold(0.0f32, f32::max);
        assert!(longest < 1.6 * lenmax, "longest edge {longest}");
        // Linear in the area, not the fan's m · n² (= 1000 · 121 here).
        let (elements, vertices) = size_at(exact as f32, std::f32::consts::TAU, 1000, lenmax);
        assert!(mesh.triangles.len() as u64 <= elements);
        assert!(mesh.positions.len() as u64 <= vertices);
        assert!(
            mesh.triangles.len() < 3000,
            "{} triangles",
            mesh.triangles.len()
        );
    }

    #[test]
    fn rim_points_lie_on_rim_edges_every_lenmax() {
        let rim = vec![
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.5, 1.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(-0.5, 1.0, 0.0),
            Vec3::new(-0.6, 0.4, 0.0),
            Vec3::new(-0.4, 0.1, 0.0),
        ];
        let mesh = mesh(&rim, Vec3::Z, 0.3);
        // The rim's own vertices come first, in order, at their positions.
        assert_eq!(mesh.positions[0], rim[0]);
        // The first edge (length 2) is cut into ⌊2/0.3⌋ + 1 = 7 pieces.
        let on_first: Vec<f32> = mesh
            .positions
            .iter()
            .filter(|p| p.y.abs() < 1e-6)
            .map(|p| p.x)
            .collect();
        assert_eq!(on_first.len(), 8);
        let exact = {
            let mut s = 0.0;
            for k in 0..rim.len() {
                s += rim[k].cross(rim[(k + 1) % rim.len()]).z as f64 / 2.0;
            }
            s
        };
        assert!((area_of(&mesh, Vec3::Z) - exact).abs() < 1e-5 * exact);
    }

    #[test]
    fn simplify_keeps_every_vertex_farther_than_the_tolerance() {
        // A 16-gon of radius 1: each vertex is 1 − cos(π/8) ≈ 0.076 off
        // the chord of its neighbours.
        let rim = regular(16, 1.0);
        assert_eq!(simplify(&rim, 0.05).len(), 16);
        // With a tolerance above that but below the 0.149 a vertex is off
        // a chord over three edges, every other vertex goes.
        assert_eq!(simplify(&rim, 0.1).len(), 8);
        // A fine circle keeps about π / √(2 · tolerance / radius).
        let kept = simplify(&regular(100_000, 1.0), 2e-5).len();
        assert!((400..=800).contains(&kept), "{kept} kept");
    }

    #[test]
    fn a_hundred_thousand_vertex_rim_meshes_in_linear_size() {
        let rim = regular(100_000, 1.0);
        let mesh = mesh(&rim, Vec3::Y, 0.05);
        // Every point once; a triangulation of V points has under 2V
        // triangles (2V − B − 2, B on the hull: in f32 not every rim
        // vertex of a circle this fine is strictly convex).
        let lattice = mesh.positions.len() - 100_000;
        assert!(lattice > 1000 && lattice < 2000, "{lattice} lattice points");
        assert!(mesh.triangles.len() < 2 * mesh.positions.len());
        let exact = std::f64::consts::PI;
        assert!((area_of(&mesh, Vec3::Y) - exact).abs() < 1e-4 * exact);
        assert!(mesh.min_edge > 0.0);
    }
}
