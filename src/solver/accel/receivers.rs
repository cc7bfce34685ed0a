//! Hierarchical receivers: a step of reflected light evaluates a
//! receiving grid at coarse vertices and interpolates the others where a
//! check shows the interpolation holds.
//!
//! A step visits every receiving element vertex, and on a wall of
//! thousands of vertices that visit (a sum over the shooter's strata or
//! samples, a shadow ray each) is where the time goes, though most of what
//! a step of reflected light brings there is smooth. So each polygon
//! meshed as a regular grid ([`CoarseGrid`]: parallelograms and convex
//! quadrilaterals, not refined) has a coarse grid: every
//! [`RECEIVER_STRIDE`]-th row and column, and the last. Each other vertex
//! lies in a coarse cell, and each cell with a middle in both directions
//! has a **check vertex** there. A step evaluates the coarse and check
//! vertices exactly first; then a cell whose corners predict its check
//! vertex (bilinearly, in grid coordinates, as the elements are
//! parametrised) within [`CHECK_TOLERANCE`] of the exact value, or within
//! [`RECEIVER_WEAK_SHARE`] of the radiosity the check vertex already holds, has its
//! other vertices interpolated; any other cell is evaluated exactly at
//! every vertex ([`accept`]). An accepted cell is interpolated through
//! all five of its exact values ([`interpolate`]): the corners' bilinear
//! blend plus the check vertex's misfit spread as a quadratic bubble. A
//! bilinear blend alone is low wherever the light is highest inside the
//! cell, as on every wall of a closed room, and lost 0.5 % of a closed
//! box's light. A cell near the shooter (closer to its
//! bounds than [`RECEIVER_NEAR_RATIO`] of the cell's diagonal) is always exact:
//! there the field bends within a cell in ways one check cannot see.
//!
//! The second rule is the power oracle of Hanrahan, Salzman and
//! Aupperle's BF refinement, measured against what the receiver holds: a
//! step that changes a cell by a twentieth of a percent may be smoothed
//! there. The first catches shadows and bright spots that fall on the
//! check vertex; what lies wholly between the five points is missed, as a
//! hierarchical solver's coarse link misses it. Visibility is sampled, not
//! proven: the shafts the solver builds between a cluster and a receiver
//! hold some polygon for nearly every receiver of a furnished room (0.6 %
//! of them are empty on the 30-table hall), so a proof of uniform
//! visibility would rarely apply.
//!
//! Evaluated exactly at every vertex, always: emitters' shots (they shoot
//! alone and draw the sharpest shadows), the shooting cluster's own
//! members (they are in each other's near field), strips one element
//! wide, triangles, fans and refined meshes, and every step of
//! `--no-clustering` and `--exact-receivers`. Each vertex's value depends
//! only on its own and the first pass's values, so the result does not
//! depend on the thread count.

use crate::color::Rgb;
use crate::mesh::{Mesh, PolygonMesh};
use crate::solver::tuning::{
    CHECK_TOLERANCE, CROWD_RATIO, RECEIVER_ERROR_BUDGET, RECEIVER_NEAR_RATIO, RECEIVER_STRIDE,
    RECEIVER_WEAK_SHARE,
};
use glam::Vec3;

/// Per mesh vertex, true where it is the first corner of a crowded cell
/// of a receiving grid ([`CROWD_RATIO`]); `crowds(polygon, corners,
/// normal, depth)` answers whether another polygon reaches into the box
/// over the cell's `corners` up to `depth` along its unit `normal`.
pub fn crowded_cells(
    mesh: &Mesh,
    grids: &[Option<CoarseGrid>],
    crowds: impl Fn(usize, [Vec3; 4], Vec3, f32) -> bool,
) -> Vec<bool> {
    let mut crowded = vec![false; mesh.positions.len()];
    for (j, grid) in grids.iter().enumerate() {
        let Some(grid) = grid else { continue };
        let normal = mesh.polygons[j].normal;
        for cell in grid.cells() {
            let corners = cell.map(|c| mesh.positions[c as usize]);
            let diagonal = corners[0]
                .distance(corners[2])
                .max(corners[1].distance(corners[3]));
            if crowds(j, corners, normal, CROWD_RATIO * diagonal) {
                crowded[cell[0] as usize] = true;
            }
        }
    }
    crowded
}

/// The regular grid of a polygon's mesh: its first `(nu + 1)(nv + 1)`
/// vertices are the grid points `(a, b)`, `a` running fastest, as
/// [`crate::mesh::build`] lays out parallelograms and quadrilaterals
/// (vertices stitching inserted come after them and are evaluated
/// exactly).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoarseGrid {
    first: u32,
    nu: u32,
    nv: u32,
}

/// Where a vertex's value comes from when it may be interpolated: the four
/// corners of its coarse cell (mesh vertex indices) and their bilinear
/// weights, and the cell's check vertex (evaluated exactly, to test the
/// interpolation) with its own weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interpolation {
    /// The cell's corners, mesh vertex indices.
    pub corners: [u32; 4],
    /// The vertex's weights, each in `[0, 1]`, summing to 1.
    pub weights: [f64; 4],
    /// The cell's check vertex (its middle), a mesh vertex index.
    pub check: u32,
    /// The check vertex's weights.
    pub check_weights: [f64; 4],
}

/// How a vertex of a receiving grid is evaluated in a clustered step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Role {
    /// Exactly, first: a coarse vertex, or a vertex outside the grid
    /// (inserted by stitching).
    Exact,
    /// Exactly, first: the check vertex of this cell (the vertex is
    /// [`Interpolation::check`]).
    Check(Interpolation),
    /// After the exact ones: interpolated if its cell passes [`accept`],
    /// else exactly.
    Fine(Interpolation),
}

impl CoarseGrid {
    /// The grid of `pm`, when its mesh is one (checked from the vertex
    /// positions, so triangles, fans and refined meshes are refused) and
    /// some of its vertices lie between coarse rows or columns.
    pub fn detect(mesh: &Mesh, pm: &PolygonMesh) -> Option<CoarseGrid> {
        let (nu, nv) = (pm.nu, pm.nv);
        if pm.levels != 0 || pm.sky || (nu <= 1 && nv <= 1) {
            return None;
        }
        let count = (nu as u64 + 1) * (nv as u64 + 1);
        if count > u64::from(pm.vertex_count()) {
            return None;
        }
        let grid = CoarseGrid {
            first: pm.vertices.start,
            nu,
            nv,
        };
        let at = |a: u32, b: u32| mesh.positions[grid.index(a, b) as usize];
        let corners = [at(0, 0), at(nu, 0), at(nu, nv), at(0, nv)];
        let extent = corners[0]
            .distance(corners[2])
            .max(corners[1].distance(corners[3]));
        // Stitching snaps boundary vertices by far less than this.
        let tolerance = 1e-4 * extent;
        for b in 0..=nv {
            for a in 0..=nu {
                let (u, w) = (a as f32 / nu as f32, b as f32 / nv as f32);
                let expected = (1.0 - u) * (1.0 - w) * corners[0]
                    + u * (1.0 - w) * corners[1]
                    + u * w * corners[2]
                    + (1.0 - u) * w * corners[3];
                if at(a, b).distance(expected) > tolerance {
                    return None;
                }
            }
        }
        Some(grid)
    }

    fn index(&self, a: u32, b: u32) -> u32 {
        self.first + b * (self.nu + 1) + a
    }

    /// Every cell [`CoarseGrid::role`] may interpolate, by its corners
    /// (mesh vertex indices, in the order of [`Interpolation::corners`]):
    /// the cells with a middle in both directions.
    pub fn cells(&self) -> Vec<[u32; 4]> {
        let spans = |n: u32| {
            (0..n)
                .step_by(RECEIVER_STRIDE as usize)
                .map(move |lo| (lo, (lo + RECEIVER_STRIDE).min(n)))
                .filter(|(lo, hi)| hi - lo >= 2)
        };
        let mut cells = Vec::new();
        for (b0, b1) in spans(self.nv) {
            for (a0, a1) in spans(self.nu) {
                cells.push([
                    self.index(a0, b0),
                    self.index(a1, b0),
                    self.index(a1, b1),
                    self.index(a0, b1),
                ]);
            }
        }
        cells
    }

    /// How mesh vertex `l` of this grid's polygon is evaluated.
    pub fn role(&self, l: u32) -> Role {
        let Some(k) = l.checked_sub(self.first) else {
            return Role::Exact;
        };
        let (a, b) = (k % (self.nu + 1), k / (self.nu + 1));
        if b > self.nv {
            return Role::Exact;
        }
        // The coarse rows (columns) around `x`: `(lo, hi)`, equal when `x`
        // is one.
        let span = |x: u32, n: u32| {
            let lo = x / RECEIVER_STRIDE * RECEIVER_STRIDE;
            if lo == x || x == n {
                (x, x)
            } else {
                (lo, (lo + RECEIVER_STRIDE).min(n))
            }
        };
        let (a0, a1) = span(a, self.nu);
        let (b0, b1) = span(b, self.nv);
        // A coarse vertex (`span` gives `(x, x)` exactly for coarse `x`).
        if a0 == a1 && b0 == b1 {
            return Role::Exact;
        }
        // A vertex on a coarse column (row) lies in the cells on either
        // side; take the one on the side away from the grid's end.
        let widen = |x: u32, n: u32, (lo, hi): (u32, u32)| match (lo == hi, hi < n) {
            (false, _) => (lo, hi),
            (true, true) => (lo, span(x + 1, n).1),
            (true, false) => (span(x - 1, n).0, hi),
        };
        let (a0, a1) = widen(a, self.nu, (a0, a1));
        let (b0, b1) = widen(b, self.nv, (b0, b1));
        // Only cells with a middle in both directions are interpolated: a
        // strip one element wide (the edge of a table top) has no vertex
        // inside to check the interpolation with.
        if a1 - a0 < 2 || b1 - b0 < 2 {
            return Role::Exact;
        }
        let (ac, bc) = ((a0 + a1) / 2, (b0 + b1) / 2);
        let weights = |x: u32, y: u32| {
            let t = f64::from(x - a0) / f64::from(a1 - a0);
            let u = f64::from(y - b0) / f64::from(b1 - b0);
            [(1.0 - t) * (1.0 - u), t * (1.0 - u), t * u, (1.0 - t) * u]
        };
        let cell = Interpolation {
            corners: [
                self.index(a0, b0),
                self.index(a1, b0),
                self.index(a1, b1),
                self.index(a0, b1),
            ],
            weights: weights(a, b),
            check: self.index(ac, bc),
            check_weights: weights(ac, bc),
        };
        if (a, b) == (ac, bc) {
            Role::Check(cell)
        } else {
            Role::Fine(cell)
        }
    }
}

/// The oracle: may a step's `Δrad` be interpolated across a coarse cell,
/// and at what cost? `corners` is what the step gives the cell's corners,
/// `check` what it gives the cell's check vertex (exact), `held` the
/// radiosity the check vertex holds before the step and `spent` the
/// interpolation error already charged to it. Per channel, the bilinear
/// blend of the corners must predict the check vertex
///
/// - within [`CHECK_TOLERANCE`] of its exact value (free), or
/// - within [`RECEIVER_WEAK_SHARE`] of what it holds, with the error charged to the
///   check vertex, whose charges may not exceed [`RECEIVER_ERROR_BUDGET`] of what
///   it holds: however many weak steps are smoothed, the error they leave
///   at the check vertex stays within that budget.
///
/// `None` refuses the cell; `Some(cost)` accepts it, `cost` being what to
/// add to the check vertex's charges.
pub fn accept(
    corners: [Rgb; 4],
    check: Rgb,
    check_weights: [f64; 4],
    held: Rgb,
    spent: Rgb,
) -> Option<Rgb> {
    let predicted = blend(corners, check_weights);
    let channel = |p: f64, e: f64, h: f64, s: f64| {
        let err = (p - e).abs();
        if err <= CHECK_TOLERANCE * e.max(p) {
            Some(0.0)
        } else if err <= RECEIVER_WEAK_SHARE * h && s + err <= RECEIVER_ERROR_BUDGET * h {
            Some(err)
        } else {
            None
        }
    };
    Some(Rgb::new(
        channel(predicted.r, check.r, held.r, spent.r)?,
        channel(predicted.g, check.g, held.g, spent.g)?,
        channel(predicted.b, check.b, held.b, spent.b)?,
    ))
}

/// Whether a coarse cell with corners at `corners` (scene units) is far
/// enough from the shooter's bounds `(min, max)` to be interpolated: at
/// least [`RECEIVER_NEAR_RATIO`] of its diagonal away. Near the shooter (a wall
/// meeting the shooting floor, a seat above the floor) the field bends
/// sharply within a cell, and the check vertex in its middle does not see
/// how.
pub fn far_from(corners: [Vec3; 4], shooter: (Vec3, Vec3)) -> bool {
    let (lo, hi) = corners
        .iter()
        .fold((corners[0], corners[0]), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
    let gap = (shooter.0 - hi).max(lo - shooter.1).max(Vec3::ZERO);
    gap.length() >= RECEIVER_NEAR_RATIO * (hi - lo).length()
}

/// The value of an accepted cell at a vertex: the bilinear blend of the
/// corners' values (`weights`, the vertex's) plus the check vertex's
/// misfit (`check`, exact, minus the blend at `check_weights`) spread as a
/// quadratic bubble, `t(1 − t) + u(1 − u)` in the cell's coordinates,
/// scaled to 1 at the check vertex and 0 at the corners. A field bent the
/// same way across the cell (the light on a wall, highest at its middle)
/// is then interpolated without the bias a bilinear blend has, which is
/// one-signed over a closed room: it predicts the check vertex exactly,
/// and any quadratic with equal curvature in both directions everywhere.
/// Per channel the result is held within the range of the five exact
/// values, so that it keeps their sign (a step's light is all of one
/// sign) and never overshoots a steep cell.
pub fn interpolate(
    corners: [Rgb; 4],
    weights: [f64; 4],
    check: Rgb,
    check_weights: [f64; 4],
) -> Rgb {
    let bubble = |w: [f64; 4]| {
        // Bilinear weights in the corner order (0,0), (1,0), (1,1), (0,1).
        let (t, u) = (w[1] + w[2], w[2] + w[3]);
        t * (1.0 - t) + u * (1.0 - u)
    };
    let at_check = bubble(check_weights);
    let misfit = check - blend(corners, check_weights);
    let share = if at_check > 0.0 {
        bubble(weights) / at_check
    } else {
        0.0
    };
    let value = blend(corners, weights) + misfit * share;
    let held = |pick: fn(&Rgb) -> f64, v: f64| {
        let (lo, hi) = corners
            .iter()
            .fold((pick(&check), pick(&check)), |(lo, hi), c| {
                (lo.min(pick(c)), hi.max(pick(c)))
            });
        v.clamp(lo, hi)
    };
    Rgb::new(
        held(|c| c.r, value.r),
        held(|c| c.g, value.g),
        held(|c| c.b, value.b),
    )
}

/// The bilinear blend of the corners' values.
pub fn blend(values: [Rgb; 4], weights: [f64; 4]) -> Rgb {
    let mut sum = Rgb::BLACK;
    for (v, w) in values.into_iter().zip(weights) {
        sum += v * w;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{self, MeshOptions};
    use crate::testutil::{grey, polygon, scene};

    fn mesh_of(vertices: &[[f32; 3]], lenmax: f32) -> Mesh {
        let s = scene(vec![polygon(0, vertices)], vec![grey("m", 0.0, 0.5)]);
        mesh::build(
            &s,
            &MeshOptions {
                lenmax,
                inset: mesh::DEFAULT_INSET,
            },
        )
        .unwrap()
    }

    const SQUARE: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];

    #[test]
    fn a_grid_interpolates_its_fine_vertices_from_its_coarse_cell() {
        // 11 × 11 elements: coarse rows and columns 0, 4, 8 and 11.
        let m = mesh_of(&SQUARE, 0.099);
        let pm = &m.polygons[0];
        assert_eq!((pm.nu, pm.nv), (11, 11));
        let grid = CoarseGrid::detect(&m, pm).expect("a square is a grid");
        let at = |c: u32, w: [f64; 4], corners: [u32; 4]| {
            corners.iter().zip(w).fold(glam::DVec3::ZERO, |s, (&c, w)| {
                s + m.positions[c as usize].as_dvec3() * w
            }) - m.positions[c as usize].as_dvec3()
        };
        let mut exact = 0;
        for l in pm.vertices.clone() {
            match grid.role(l) {
                Role::Exact => exact += 1,
                Role::Check(i) => {
                    exact += 1;
                    assert_eq!(i.check, l);
                }
                Role::Fine(i) => {
                    // The blends of the corners' positions are the vertex
                    // and the check vertex.
                    assert!(at(l, i.weights, i.corners).length() < 1e-6);
                    assert!(at(i.check, i.check_weights, i.corners).length() < 1e-6);
                    assert!((i.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                    assert_eq!(
                        grid.role(i.check),
                        Role::Check(Interpolation {
                            weights: i.check_weights,
                            ..i
                        })
                    );
                    for c in i.corners {
                        assert_eq!(grid.role(c), Role::Exact, "corners are exact");
                    }
                }
            }
        }
        // 16 coarse vertices and 9 cells' checks, of 144.
        assert_eq!(exact, 25);
    }

    #[test]
    fn triangles_and_fans_are_not_grids() {
        let tri = mesh_of(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], 0.1);
        assert_eq!(CoarseGrid::detect(&tri, &tri.polygons[0]), None);
        let pentagon = mesh_of(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.3, 0.6, 0.0],
                [0.5, 1.2, 0.0],
                [-0.3, 0.6, 0.0],
            ],
            0.1,
        );
        assert_eq!(CoarseGrid::detect(&pentagon, &pentagon.polygons[0]), None);
        // A quad of one element has nothing to interpolate.
        let one = mesh_of(&SQUARE, 2.0);
        assert_eq!(CoarseGrid::detect(&one, &one.polygons[0]), None);
    }

    #[test]
    fn the_oracle_interpolates_what_the_corners_predict() {
        let mid = [0.25; 4];
        let held = Rgb::splat(1.0);
        let none = Rgb::BLACK;
        let even = [
            Rgb::splat(0.5),
            Rgb::splat(0.52),
            Rgb::splat(0.49),
            Rgb::splat(0.5),
        ];
        // The check vertex as predicted: interpolated, free.
        assert_eq!(
            accept(even, Rgb::splat(0.5025), mid, held, none),
            Some(none)
        );
        // In a shadow the corners miss: exact.
        assert_eq!(accept(even, Rgb::splat(0.2), mid, held, none), None);
        // Off by 4 % of a step that brings little against what is held:
        // interpolated, the error charged.
        let weak = [Rgb::splat(0.01); 4];
        let cost = accept(weak, Rgb::splat(0.0104), mid, held, none).expect("weak");
        assert!((cost.r - 0.0004).abs() < 1e-12);
        // ... but not once the charges reach the budget.
        let spent = Rgb::splat(RECEIVER_ERROR_BUDGET - 0.0002);
        assert_eq!(accept(weak, Rgb::splat(0.0104), mid, held, spent), None);
        // A dark channel held is not a licence for the others.
        let red = Rgb::new(1.0, 0.0, 0.0);
        assert_eq!(accept(weak, Rgb::splat(0.0104), mid, red, none), None);
        // No light anywhere: interpolated (nothing to miss at the check).
        assert_eq!(accept([none; 4], none, mid, held, none), Some(none));
    }

    #[test]
    fn cells_near_the_shooter_are_exact() {
        let cell = [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let at = |z: f32| (Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 1.0, z + 1.0));
        // The diagonal is 1.41: a shooter 1 away is near, 1.5 away far.
        assert!(!far_from(cell, at(1.0)));
        assert!(far_from(cell, at(1.5)));
        // Touching, or around the cell: near.
        assert!(!far_from(cell, at(0.0)));
        assert!(!far_from(cell, (Vec3::splat(-5.0), Vec3::splat(5.0))));
    }

    /// Bilinear weights of `(t, u)` in the corner order (0,0), (1,0),
    /// (1,1), (0,1).
    fn weights_at(t: f64, u: f64) -> [f64; 4] {
        [(1.0 - t) * (1.0 - u), t * (1.0 - u), t * u, (1.0 - t) * u]
    }

    #[test]
    fn interpolation_follows_a_field_bent_alike_both_ways() {
        // A plane plus a bump of equal curvature both ways, as the light
        // on a wall from the room's middle: f = 1 + t + 2u + 3(t(1 − t) +
        // u(1 − u)). The bilinear blend misses the bump everywhere inside
        // (0.75 low at a middle of an edge, one-signed); the bubble
        // through the check vertex takes it exactly.
        let f = |t: f64, u: f64| 1.0 + t + 2.0 * u + 3.0 * (t * (1.0 - t) + u * (1.0 - u));
        let corners =
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(t, u)| Rgb::splat(f(t, u)));
        let check_weights = weights_at(0.5, 0.5);
        let check = Rgb::splat(f(0.5, 0.5));
        for (t, u) in [
            (0.25, 0.0),
            (0.5, 0.0),
            (0.25, 0.75),
            (0.5, 0.5),
            (0.75, 0.25),
        ] {
            let exact = f(t, u);
            let w = weights_at(t, u);
            let got = interpolate(corners, w, check, check_weights).r;
            assert!((got - exact).abs() < 1e-12, "({t}, {u}): {got} vs {exact}");
            let bilinear = blend(corners, w).r;
            if t * (1.0 - t) + u * (1.0 - u) > 0.0 {
                assert!(bilinear < exact - 0.1, "the blend alone is low");
            }
        }
        // A check vertex off the middle (a cell of 3 × 2 elements checked
        // at (1/3, 1/2)) still gets its own exact value.
        let off = weights_at(1.0 / 3.0, 0.5);
        let c = Rgb::splat(f(1.0 / 3.0, 0.5));
        let got = interpolate(corners, off, c, off);
        assert!((got.r - c.r).abs() < 1e-12);
    }

    #[test]
    fn interpolation_stays_within_the_exact_values() {
        let mid = weights_at(0.5, 0.5);
        let at = |t, u| weights_at(t, u);
        // One bright corner and a shadow on the check vertex: the bubble's
        // negative misfit would take (0.75, 0.5) to −0.094; it stays at
        // the darkest exact value, zero, in a step of positive light.
        let one = [Rgb::splat(1.0), Rgb::BLACK, Rgb::BLACK, Rgb::BLACK];
        let v = interpolate(one, at(0.75, 0.5), Rgb::BLACK, mid);
        assert_eq!(v, Rgb::BLACK);
        // A step of negative light (taking light back) keeps its sign.
        let v = interpolate(one.map(|c| c * -1.0), at(0.75, 0.5), Rgb::BLACK, mid);
        assert_eq!(v, Rgb::BLACK);
        // A slope with a bright check vertex: 2.375 at (0.75, 0.5), above
        // every exact value; held at the brightest, 2.
        let slope = [Rgb::BLACK, Rgb::splat(2.0), Rgb::splat(2.0), Rgb::BLACK];
        let v = interpolate(slope, at(0.75, 0.5), Rgb::splat(2.0), mid);
        assert_eq!(v, Rgb::splat(2.0));
        // Inside the range nothing is held: (0.25, 0.5) takes
        // 0.5 + 0.875 = 1.375.
        let v = interpolate(slope, at(0.25, 0.5), Rgb::splat(2.0), mid);
        assert!((v.r - 1.375).abs() < 1e-12, "{v:?}");
    }

    #[test]
    fn blend_weights_the_corners() {
        let v = [
            Rgb::splat(1.0),
            Rgb::splat(2.0),
            Rgb::splat(3.0),
            Rgb::splat(4.0),
        ];
        let b = blend(v, [0.25; 4]);
        assert!((b.r - 2.5).abs() < 1e-12);
    }
}
