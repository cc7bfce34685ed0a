//! The light a shooter cell holds: the integral over the cell of the
//! unshot radiosity as the elements interpolate it, as fixed weights on
//! the polygon's vertices.
//!
//! A shooter cell ([`super::formfactor`]) stands for a piece of its
//! polygon, often dozens of elements. Read at its centre, it sends as if
//! the light there covered the whole cell: in a hall whose tables stand
//! on a regular grid, every centre of the floor's cells fell between the
//! tables' shadows. Each step then scaled all of a shooter's readings by
//! one factor so that they sent what the step spent, and since that factor
//! depended on where the light lay in that step, the converged solution
//! depended on the order of the steps (`docs/accuracy.md`).
//!
//! Read as its integral, a cell sends exactly the light its piece of the
//! polygon holds: the readings are linear in the unshot field (the same
//! operator whatever the order of the steps), they add up over the cells
//! to the polygon's light, and a uniform field reads the same in every
//! cell. For vertex `l` and cell `C` the weight is `∫_C λ_l dA`, `λ_l` the
//! piecewise linear hat of `l` over the element triangles; each triangle
//! is clipped against each cell it overlaps, and a linear function's
//! integral over the clipped piece is its area times the function's value
//! at its centroid.

use crate::mesh::{Mesh, PolygonMesh};
use glam::{DVec2, Vec3};

/// Per cell (its corners counter-clockwise from the polygon's front, a
/// triangle repeating its last; the cells lying in polygon `pm`'s plane),
/// the vertices of `pm` whose light it holds and their weights
/// `∫_cell λ_l dA`, in square scene units, each vertex once, in vertex
/// order. The weights of a cell sum to the area of the cell that the
/// elements cover; a cell the elements do not reach gets none.
pub(crate) fn cell_weights(
    mesh: &Mesh,
    pm: &PolygonMesh,
    cells: &[[Vec3; 4]],
) -> Vec<Vec<(u32, f32)>> {
    let mut out: Vec<Vec<(u32, f32)>> = vec![Vec::new(); cells.len()];
    if cells.is_empty() {
        return out;
    }
    let frame = Frame::new(pm.normal);
    let polygons: Vec<Vec<DVec2>> = cells.iter().map(|c| frame.convex(c)).collect();
    let boxes: Vec<(DVec2, DVec2)> = polygons.iter().map(|p| bounds(p)).collect();
    let grid = Buckets::new(&boxes);
    let mut seen = vec![u32::MAX; cells.len()];
    let mut clipped = Vec::with_capacity(8);
    let mut scratch = Vec::with_capacity(8);
    let mut candidates = Vec::new();
    let mut stamp = 0u32;
    for e in pm.elements.clone() {
        for tri in mesh.elements[e as usize].triangles() {
            let p = tri.map(|v| frame.project(mesh.positions[v.index()]));
            let twice = cross(p[1] - p[0], p[2] - p[0]);
            if twice.abs() <= f64::MIN_POSITIVE {
                continue;
            }
            let (lo, hi) = bounds(&p);
            stamp = stamp.wrapping_add(1);
            candidates.clear();
            grid.visit_triangle(&p, |k| {
                if seen[k] != stamp {
                    seen[k] = stamp;
                    candidates.push(k);
                }
            });
            for &k in &candidates {
                let (clo, chi) = boxes[k];
                if clo.x > hi.x || clo.y > hi.y || chi.x < lo.x || chi.y < lo.y {
                    continue;
                }
                clipped.clear();
                clipped.extend_from_slice(&p);
                clip(&mut clipped, &polygons[k], &mut scratch);
                let Some((area, centroid)) = area_centroid(&clipped) else {
                    continue;
                };
                // Barycentric weights of the piece's centroid: λ_i is
                // linear, so its integral is area × λ_i(centroid).
                for i in 0..3 {
                    let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
                    let lambda = (cross(b - a, centroid - a) / twice).clamp(0.0, 1.0);
                    if lambda > 0.0 {
                        out[k].push((tri[i].0, (area * lambda) as f32));
                    }
                }
            }
        }
    }
    for weights in &mut out {
        weights.sort_unstable_by_key(|&(l, _)| l);
        weights.dedup_by(|next, kept| {
            if next.0 == kept.0 {
                kept.1 += next.1;
                true
            } else {
                false
            }
        });
    }
    out
}

/// Two axes in a polygon's plane.
struct Frame {
    u: Vec3,
    v: Vec3,
}

impl Frame {
    fn new(normal: Vec3) -> Frame {
        let (u, v) = normal.normalize().any_orthonormal_pair();
        Frame { u, v }
    }

    fn project(&self, p: Vec3) -> DVec2 {
        DVec2::new(f64::from(p.dot(self.u)), f64::from(p.dot(self.v)))
    }

    /// A cell's corners in the plane, the repeated last corner of a
    /// triangle dropped, counter-clockwise.
    fn convex(&self, cell: &[Vec3; 4]) -> Vec<DVec2> {
        let mut p: Vec<DVec2> = cell.iter().map(|&c| self.project(c)).collect();
        if cell[3] == cell[2] {
            p.pop();
        }
        let mut twice = 0.0;
        for i in 0..p.len() {
            twice += cross(p[i], p[(i + 1) % p.len()]);
        }
        if twice < 0.0 {
            p.reverse();
        }
        p
    }
}

/// The z component of the cross product.
fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Smallest and largest corner of `points`.
fn bounds(points: &[DVec2]) -> (DVec2, DVec2) {
    points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Clips `subject` (a convex polygon) against convex, counter-clockwise
/// `clipper` (Sutherland and Hodgman), in place.
fn clip(subject: &mut Vec<DVec2>, clipper: &[DVec2], scratch: &mut Vec<DVec2>) {
    for i in 0..clipper.len() {
        if subject.is_empty() {
            return;
        }
        let (a, b) = (clipper[i], clipper[(i + 1) % clipper.len()]);
        let side = |p: DVec2| cross(b - a, p - a);
        scratch.clear();
        for j in 0..subject.len() {
            let (p, q) = (subject[j], subject[(j + 1) % subject.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                scratch.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                scratch.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
        std::mem::swap(subject, scratch);
    }
}

/// Area and centroid of a simple polygon; `None` when it has no area.
fn area_centroid(p: &[DVec2]) -> Option<(f64, DVec2)> {
    if p.len() < 3 {
        return None;
    }
    let (mut twice, mut c) = (0.0, DVec2::ZERO);
    let o = p[0];
    for i in 1..p.len() - 1 {
        let (a, b) = (p[i] - o, p[i + 1] - o);
        let t = cross(a, b);
        twice += t;
        c += (a + b) * t;
    }
    if twice.abs() <= f64::MIN_POSITIVE {
        return None;
    }
    Some((twice.abs() * 0.5, o + c / (3.0 * twice)))
}

/// A coarse grid over the cells' bounds: which cells may overlap a box.
struct Buckets {
    lo: DVec2,
    size: DVec2,
    n: usize,
    cells: Vec<Vec<usize>>,
}

impl Buckets {
    fn new(boxes: &[(DVec2, DVec2)]) -> Buckets {
        let (lo, hi) = boxes.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &(a, b)| (lo.min(a), hi.max(b)),
        );
        let n = ((boxes.len() as f64).sqrt().ceil() as usize).clamp(1, 64);
        let size = ((hi - lo) / n as f64).max(DVec2::splat(f64::MIN_POSITIVE));
        let mut grid = Buckets {
            lo,
            size,
            n,
            cells: vec![Vec::new(); n * n],
        };
        for (k, &(a, b)) in boxes.iter().enumerate() {
            let ((x0, y0), (x1, y1)) = (grid.index(a), grid.index(b));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    grid.cells[y * n + x].push(k);
                }
            }
        }
        grid
    }

    /// The bucket holding `p`, clamped to the grid.
    fn index(&self, p: DVec2) -> (usize, usize) {
        let at = (p - self.lo) / self.size;
        let clamp = |x: f64| (x.max(0.0) as usize).min(self.n - 1);
        (clamp(at.x), clamp(at.y))
    }

    /// Calls `f` with every cell of the buckets the triangle `t` meets (a
    /// cell may come more than once): per row of buckets, those between
    /// the triangle's least and greatest `x` within the row. A long thin
    /// triangle across the grid (the fan of a polygon of many vertices)
    /// meets a row or two of buckets, where its bounding box would meet
    /// most of the grid.
    fn visit_triangle(&self, t: &[DVec2; 3], mut f: impl FnMut(usize)) {
        let (lo, hi) = bounds(t);
        // Far above rounding, so a bucket the triangle touches is visited.
        let pad = 1e-9 * (self.size.x + self.size.y) * self.n as f64;
        let (y0, y1) = (self.index(lo).1, self.index(hi).1);
        for y in y0..=y1 {
            // The row's band; the first and last rows hold everything
            // beyond the grid, as `index` clamps it there.
            let band_lo = if y == 0 {
                f64::NEG_INFINITY
            } else {
                self.lo.y + y as f64 * self.size.y - pad
            };
            let band_hi = if y + 1 == self.n {
                f64::INFINITY
            } else {
                self.lo.y + (y + 1) as f64 * self.size.y + pad
            };
            let (mut xmin, mut xmax) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut take = |x: f64| {
                xmin = xmin.min(x);
                xmax = xmax.max(x);
            };
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                if (band_lo..=band_hi).contains(&a.y) {
                    take(a.x);
                }
                // Where the edge crosses the band's two lines.
                for line in [band_lo, band_hi] {
                    if line.is_finite() && (a.y - line) * (b.y - line) < 0.0 {
                        take(a.x + (b.x - a.x) * ((line - a.y) / (b.y - a.y)));
                    }
                }
            }
            if xmin > xmax {
                continue;
            }
            let x0 = self.index(DVec2::new(xmin - pad, lo.y)).0;
            let x1 = self.index(DVec2::new(xmax + pad, lo.y)).0;
            for x in x0..=x1 {
                for &k in &self.cells[y * self.n + x] {
                    f(k);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{grey, polygon, regular_mesh, scene};

    /// The fan of a 64-gon (long thin triangles across the grid of
    /// buckets), read by 12 × 12 cells: each cell's weights sum to the
    /// area of its overlap with the elements, found by clipping every
    /// triangle against every cell, so the buckets a triangle visits miss
    /// no cell it overlaps.
    #[test]
    fn thin_triangles_reach_every_cell_they_cross() {
        let disc: Vec<[f32; 3]> = (0..64)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / 64.0;
                [a.cos(), a.sin(), 0.0]
            })
            .collect();
        let s = scene(vec![polygon(0, &disc)], vec![grey("floor", 0.0, 0.5)]);
        let mesh = regular_mesh(&s, 0.4);
        let pm = &mesh.polygons[0];
        let side = 2.2 / 12.0;
        let cells: Vec<[Vec3; 4]> = (0..144)
            .map(|k| {
                let (x, y) = (-1.1 + (k % 12) as f32 * side, -1.1 + (k / 12) as f32 * side);
                [
                    Vec3::new(x, y, 0.0),
                    Vec3::new(x + side, y, 0.0),
                    Vec3::new(x + side, y + side, 0.0),
                    Vec3::new(x, y + side, 0.0),
                ]
            })
            .collect();
        let weights = cell_weights(&mesh, pm, &cells);
        let frame = Frame::new(pm.normal);
        let (mut clipped, mut scratch) = (Vec::new(), Vec::new());
        for (cell, w) in cells.iter().zip(&weights) {
            let square = frame.convex(cell);
            let mut covered = 0.0;
            for e in pm.elements.clone() {
                for tri in mesh.elements[e as usize].triangles() {
                    clipped.clear();
                    clipped.extend(tri.map(|v| frame.project(mesh.positions[v.index()])));
                    clip(&mut clipped, &square, &mut scratch);
                    covered += area_centroid(&clipped).map_or(0.0, |(a, _)| a);
                }
            }
            let got: f64 = w.iter().map(|&(_, a)| f64::from(a)).sum();
            assert!((got - covered).abs() < 1e-6, "{got} against {covered}");
        }
    }

    /// A unit square meshed into 5 × 5 elements, read by 3 × 3 cells: every
    /// cell's weights sum to its area, every vertex's over the cells to
    /// the area it stands for, and a linear field reads its value at
    /// the cell's centroid.
    #[test]
    fn weights_integrate_the_element_field_over_each_cell() {
        let square = polygon(
            0,
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
        );
        let s = scene(vec![square], vec![grey("wall", 0.0, 0.5)]);
        let mesh = regular_mesh(&s, 0.2);
        let pm = &mesh.polygons[0];
        let third = 1.0 / 3.0;
        let cells: Vec<[Vec3; 4]> = (0..9)
            .map(|k| {
                let (x, y) = ((k % 3) as f32 * third, (k / 3) as f32 * third);
                [
                    Vec3::new(x, y, 0.0),
                    Vec3::new(x + third, y, 0.0),
                    Vec3::new(x + third, y + third, 0.0),
                    Vec3::new(x, y + third, 0.0),
                ]
            })
            .collect();
        let weights = cell_weights(&mesh, pm, &cells);
        let field = |l: u32| {
            let p = mesh.positions[l as usize];
            1.0 + 2.0 * f64::from(p.x) + 3.0 * f64::from(p.y)
        };
        let mut per_vertex = vec![0.0; mesh.vertex_count()];
        for (cell, w) in cells.iter().zip(&weights) {
            let area: f64 = w.iter().map(|&(_, a)| f64::from(a)).sum();
            assert!((area - 1.0 / 9.0).abs() < 1e-6, "{area}");
            let mean: f64 = w.iter().map(|&(l, a)| field(l) * f64::from(a)).sum::<f64>() / area;
            let centre = (cell[0] + cell[2]) * 0.5;
            let exact = 1.0 + 2.0 * f64::from(centre.x) + 3.0 * f64::from(centre.y);
            assert!((mean - exact).abs() < 1e-5, "{mean} against {exact}");
            for &(l, a) in w {
                per_vertex[l as usize] += f64::from(a);
            }
        }
        let hats: f64 = per_vertex.iter().sum();
        assert!((hats - 1.0).abs() < 1e-5, "{hats}");
        // A corner vertex's hat is a quarter of one element's two
        // triangles' thirds, an inner vertex's six triangles' thirds.
        let areas = mesh.vertex_areas();
        for (l, &a) in per_vertex.iter().enumerate() {
            assert!(
                a > 0.0 && a < 4.0 * areas[l],
                "vertex {l}: {a} against {}",
                areas[l]
            );
        }
    }

    /// A cell beyond the polygon gets no weights; a triangular cell holds
    /// half of the square it halves.
    #[test]
    fn cells_outside_get_nothing_and_triangles_their_share() {
        let square = polygon(
            0,
            &[
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [2.0, 2.0, 0.0],
                [0.0, 2.0, 0.0],
            ],
        );
        let s = scene(vec![square], vec![grey("wall", 0.0, 0.5)]);
        let mesh = regular_mesh(&s, 0.3);
        let cells = [
            [
                Vec3::new(3.0, 0.0, 0.0),
                Vec3::new(4.0, 0.0, 0.0),
                Vec3::new(4.0, 1.0, 0.0),
                Vec3::new(3.0, 1.0, 0.0),
            ],
            [
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(2.0, 2.0, 0.0),
                Vec3::new(2.0, 2.0, 0.0),
            ],
        ];
        let weights = cell_weights(&mesh, &mesh.polygons[0], &cells);
        assert!(weights[0].is_empty());
        let area: f64 = weights[1].iter().map(|&(_, a)| f64::from(a)).sum();
        assert!((area - 2.0).abs() < 1e-5, "{area}");
    }
}
