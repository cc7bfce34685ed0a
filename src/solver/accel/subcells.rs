//! Sub-cells: a shooter cell much larger than its polygon's elements,
//! shot as [`SUBCELLS`] sub-cells, each with the light it holds, and the sub-cells
//! near a receiver as their leaves.
//!
//! A large polygon shoots from at most 64 cells ([`crate::solver::kernel::formfactor`]),
//! one shadow ray each. Light pooled in a spot narrower than a cell (where
//! a sphere rests on the floor, the floor's light gathers around the
//! contact) is then sent as if spread over the whole cell, and the facets
//! just above the pool, which see it under a large angle, receive far
//! less than its light would give them: both solver modes left the
//! contact 30 to 40 % dark, and by different amounts, as they shoot in
//! different orders.
//!
//! A cell that stands for more than [`SUBCELL_ELEMENTS_PER_CELL`] elements and
//! has something close over it (`Over`: a sphere's bottom, a block's
//! foot, a lamp under the ceiling) is cut into 4 × 4 sub-cells (a triangle
//! into 16 congruent triangles), and each sub-cell again into 4 × 4 leaves.
//! Each sub-cell and each leaf reads the light it holds (its integral over
//! the elements, `cell_integrals`), and *every* receiver takes
//! the cell as its sub-cells: each sub-cell's own value and form factor (the
//! quadrature of a cell or its point term), under the cell's one shadow
//! ray, so the sub-cells cost arithmetic, not rays. A receiver within
//! [`EXACT_RATIO`] of a sub-cell's diameters takes that sub-cell as its leaves,
//! each by Lambert's exact form factor or its quadrature: so close, the
//! light varies across the sub-cell (under a sphere's contact it falls to
//! nothing), and a facet just above sees the dark under it, not the
//! sub-cell's mean. Without leaves the facets at a sphere's contact came out
//! 4 to 11 % brighter than the light around them gives them; with them,
//! 0 to 3 %.
//!
//! Two shortcuts were tried and fail closed-form tests:
//!
//! - sub-cells for near receivers only (those farther take the cell's mean):
//!   a sub-cell near a receiver sends more of its light there than the mean
//!   does, while the receivers farther still get the mean, and a closed
//!   box lit by a small lamp lost 1.3 % of its light;
//! - sub-cells only in steps whose light is uneven over the cell (by 10 %):
//!   light that one step sends from its sub-cells and another spreads over
//!   the cell no longer adds up to what the cell has shot, and the
//!   uniform enclosure's corners came out 1.1 % bright (0.05 % either
//!   way when every step takes the same choice).
//!
//! Cells with nothing close over them stay whole: splitting every large
//! cell made the bundled scenes take 1.5 times as long, for light that
//! does not pool there.
//!
//! The cell itself carries the area-weighted mean of its sub-cells
//! ([`carry_means`]), so whatever takes it whole (a cluster's stratum seen
//! from afar, a hemicube, a luminaire's distribution) sends the same
//! power.

use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::{Polygon, Scene};
use crate::solver::kernel::formfactor::{
    cell_diameter2, lane_terms, point_to_polygon, quadrature, triangle_area, Quadrature,
    ShooterSample,
};
use crate::solver::tuning::{
    EXACT_RATIO, NEAR_FIELD_RATIO, SUBCELL_CLOSE, SUBCELL_EDGE_MARGIN, SUBCELL_ELEMENTS_PER_CELL,
    SUBCELL_LEAF_RATIO, SUBCELL_REACH,
};
use glam::Vec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Sub-cells per side of a split quadrilateral cell (a triangle is cut into
/// `SIDE²` triangles), and leaves per side of a sub-cell.
pub const SIDE: usize = 4;

/// Sub-cells per split cell.
pub const SUBCELLS: usize = SIDE * SIDE;

/// Leaves per sub-cell: each sub-cell is cut again as a cell is, and a receiver
/// within [`EXACT_RATIO`] of a sub-cell's diameters takes it as its leaves.
pub const LEAVES: usize = SIDE * SIDE;

/// Values per split cell: one per sub-cell and one per leaf.
pub const PER_CELL: usize = SUBCELLS * (1 + LEAVES);

/// "Not split" in [`SubCells::first`] and in a step's [`Split::first`].
pub const NONE: u32 = u32::MAX;

/// One sub-cell of a split cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubCell {
    /// Its centre, in scene units.
    pub position: Vec3,
    /// The area it stands for, in square scene units; a cell's sub-cells sum
    /// to the cell's area.
    pub area: f64,
    /// Its corners, counter-clockwise from the front (a triangle repeats
    /// its last).
    pub corners: [Vec3; 4],
    /// Its quadrature points (`quadrature`).
    pub quadrature: Quadrature,
    /// Squared diameter, in square scene units.
    pub diameter2: f32,
}

/// The sub-cells of one polygon's split cells.
///
/// Invariant: `first` has one entry per shooter sample of the polygon,
/// [`NONE`] or the index in `cells` of the first of the sample's
/// [`SUBCELLS`] sub-cells, and the leaves of its sub-cells.
#[derive(Clone, Debug, Default)]
pub struct SubCells {
    /// Per shooter sample: where its sub-cells start, or [`NONE`].
    pub first: Vec<u32>,
    /// The sub-cells, [`SUBCELLS`] per split cell.
    pub cells: Vec<SubCell>,
    /// The sub-cells' centres and areas, four sub-cells to a [`Quadrature`] (one
    /// per SIMD lane), in the order of `cells`.
    pub centres: Vec<Quadrature>,
    /// The sub-cells' leaves, [`LEAVES`] per sub-cell in the order of `cells`
    /// (sub-cell `p`'s from `p · LEAVES`), apart from the sub-cells so that the
    /// sub-cells every receiver takes lie together in memory.
    pub leaves: Vec<SubCell>,
}

impl SubCells {
    /// Every polygon's sub-cells: those of its cells that stand for more than
    /// [`SUBCELL_ELEMENTS_PER_CELL`] of its elements and have something close over
    /// them (`Over`). None without the near field (`near_field` false), nor
    /// for samples without a cell, whose form factors have no cell to cut.
    pub fn build_all(
        scene: &Scene,
        mesh: &Mesh,
        samples: &[Vec<ShooterSample>],
        near_field: bool,
    ) -> Vec<SubCells> {
        let over = Over::new(mesh);
        (0..mesh.polygons.len())
            .into_par_iter()
            .map(|i| {
                let pm = &mesh.polygons[i];
                let element_area = pm.area / pm.elements.len().max(1) as f64;
                let large = |s: &ShooterSample| {
                    near_field
                        && s.cell.is_some()
                        && s.near_r2 > 0.0
                        && s.area > SUBCELL_ELEMENTS_PER_CELL * element_area
                };
                if !samples[i].iter().any(large) {
                    return SubCells::build(&samples[i], |_| false);
                }
                let polygon = &scene.polygons[i];
                let inward = inward_edges(polygon);
                SubCells::build(&samples[i], |s| {
                    large(s) && over.anything_over(mesh, i, polygon.normal, &inward, s)
                })
            })
            .collect()
    }

    /// The sub-cells of the `samples` that `split` chooses (samples without a
    /// cell are never split).
    pub fn build(samples: &[ShooterSample], split: impl Fn(&ShooterSample) -> bool) -> SubCells {
        let mut out = SubCells {
            first: vec![NONE; samples.len()],
            cells: Vec::new(),
            centres: Vec::new(),
            leaves: Vec::new(),
        };
        for (k, s) in samples.iter().enumerate() {
            let Some(cell) = s.cell else { continue };
            if !split(s) {
                continue;
            }
            out.first[k] = out.cells.len() as u32;
            let start = out.cells.len();
            cut(&cell, s.area, &mut out.cells);
            for p in start..start + SUBCELLS {
                let subcell = out.cells[p];
                cut(&subcell.corners, subcell.area, &mut out.leaves);
            }
            for four in out.cells[start..].chunks(4) {
                out.centres.push(Quadrature::new(std::array::from_fn(|l| {
                    (four[l].position, four[l].area as f32)
                })));
            }
        }
        out
    }

    /// True when no cell is split.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Every sub-cell, then every leaf: the order of the values that go with
    /// them ([`Split::of_polygon`]).
    pub fn all(&self) -> impl Iterator<Item = &SubCell> + '_ {
        self.cells.iter().chain(&self.leaves)
    }

    /// How many values go with them: one per sub-cell and one per leaf.
    pub fn len(&self) -> usize {
        self.cells.len() + self.leaves.len()
    }

    /// Split cell `k`'s sub-cells' and leaves' values out of a polygon's
    /// `values` (one per sub-cell, then one per leaf, as [`SubCells::all`]),
    /// as [`Split::of_cell`] takes them; `None` unless `k` is split and
    /// `values` has one value each.
    pub fn cell_values<'v, W>(&self, k: usize, values: &'v [W]) -> Option<(&'v [W], &'v [W])> {
        let f = *self.first.get(k)? as usize;
        if f == NONE as usize || values.len() != self.len() {
            return None;
        }
        let leaves = self.cells.len() + f * LEAVES..self.cells.len() + (f + SUBCELLS) * LEAVES;
        Some((&values[f..f + SUBCELLS], &values[leaves]))
    }
}

/// Where something stands over a shooter's cell: a mesh vertex of another
/// polygon in front of the shooter's plane by less than [`SUBCELL_CLOSE`] cell
/// diameters, within [`SUBCELL_REACH`] diameters of the cell's centre, and over
/// the shooter's inside, farther than [`SUBCELL_EDGE_MARGIN`] diameters from its
/// edges.
///
/// That is where light pools narrower than a cell: under a sphere resting
/// on the floor, around a block standing on it, behind a cupboard against
/// a wall, above a lamp hung just under a ceiling. The walls around a
/// floor meet it along its edges, so all their points stand over its
/// edges and do not count: a cell in a room's corner is taken whole,
/// which the uniform enclosure checks.
struct Over {
    /// Per polygon: bounds of its mesh vertices, in scene units.
    bounds: Vec<(Vec3, Vec3)>,
}

impl Over {
    fn new(mesh: &Mesh) -> Over {
        let bounds = mesh
            .polygons
            .iter()
            .map(|pm| {
                let range = pm.vertices.start as usize..pm.vertices.end as usize;
                mesh.positions[range].iter().fold(
                    (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                    |(lo, hi), &p| (lo.min(p), hi.max(p)),
                )
            })
            .collect();
        Over { bounds }
    }

    /// Whether anything stands over cell `s` of polygon `i`, whose unit
    /// normal is `n` and whose edges are `inward` ([`inward_edges`]).
    fn anything_over(
        &self,
        mesh: &Mesh,
        i: usize,
        n: Vec3,
        inward: &[(Vec3, Vec3)],
        s: &ShooterSample,
    ) -> bool {
        let diameter =
            (s.exact_r2.sqrt() / crate::solver::tuning::EXACT_RATIO).max(f32::MIN_POSITIVE);
        let r2 = (SUBCELL_REACH * diameter).powi(2);
        let (margin, ahead) = (SUBCELL_EDGE_MARGIN * diameter, 1e-4 * diameter);
        let c = s.position;
        let over = |p: Vec3| {
            let height = n.dot(p - c);
            height > ahead
                && height < SUBCELL_CLOSE * diameter
                && p.distance_squared(c) < r2
                && inward.iter().all(|&(a, w)| w.dot(p - a) > margin)
        };
        self.bounds.iter().enumerate().any(|(j, &(lo, hi))| {
            if j == i || lo.x > hi.x {
                return false;
            }
            // The nearest point of j's bounds to the centre.
            if c.clamp(lo, hi).distance_squared(c) >= r2 {
                return false;
            }
            let pm = &mesh.polygons[j];
            mesh.positions[pm.vertices.start as usize..pm.vertices.end as usize]
                .iter()
                .any(|&p| over(p))
        })
    }
}

/// Each edge of `polygon` as a point on it and the unit normal pointing
/// inside, in its plane (its corners run counter-clockwise from the front,
/// so `normal × edge` points inside); degenerate edges are left out.
fn inward_edges(polygon: &Polygon) -> Vec<(Vec3, Vec3)> {
    let rim = &polygon.vertices;
    (0..rim.len())
        .filter_map(|k| {
            let (a, b) = (rim[k], rim[(k + 1) % rim.len()]);
            let w = polygon.normal.cross(b - a).normalize_or_zero();
            (w != Vec3::ZERO).then_some((a, w))
        })
        .collect()
}

/// Appends the [`SUBCELLS`] sub-cells of `cell` (3 or 4 corners, a triangle
/// repeating its last) to `out`, their areas scaled to sum to `area`
/// exactly (the cell's, whatever the `f32` corners round to).
fn cut(cell: &[Vec3; 4], area: f64, out: &mut Vec<SubCell>) {
    let start = out.len();
    let [a, b, c, d] = *cell;
    let n = SIDE as f32;
    if c == d {
        // The regular subdivision: SIDE² congruent triangles.
        let (e1, e2) = (b - a, c - a);
        let at = |i: f32, j: f32| a + (i / n) * e1 + (j / n) * e2;
        for j in 0..SIDE {
            for i in 0..(SIDE - j) {
                let (fi, fj) = (i as f32, j as f32);
                let (p, q, r) = (at(fi, fj), at(fi + 1.0, fj), at(fi, fj + 1.0));
                out.push(subcell([p, q, r, r]));
                if i + j + 1 < SIDE {
                    let s = at(fi + 1.0, fj + 1.0);
                    out.push(subcell([q, s, r, r]));
                }
            }
        }
    } else {
        let at = |u: f32, w: f32| {
            (1.0 - u) * (1.0 - w) * a + u * (1.0 - w) * b + u * w * c + (1.0 - u) * w * d
        };
        for j in 0..SIDE {
            for i in 0..SIDE {
                let (u0, u1) = (i as f32 / n, (i + 1) as f32 / n);
                let (w0, w1) = (j as f32 / n, (j + 1) as f32 / n);
                out.push(subcell([at(u0, w0), at(u1, w0), at(u1, w1), at(u0, w1)]));
            }
        }
    }
    let sum: f64 = out[start..].iter().map(|c| c.area).sum();
    let scale = if sum > 0.0 { area / sum } else { 1.0 };
    for c in &mut out[start..] {
        c.area *= scale;
        c.quadrature = Quadrature::new(quadrature(&c.corners, c.area));
    }
}

/// A sub-cell with the given corners: its centre is the corners' mean (the
/// centroid for a triangle, the bilinear centre for a quadrilateral). Its
/// quadrature is left for [`cut`] to set once the area is scaled.
fn subcell(corners: [Vec3; 4]) -> SubCell {
    let triangle = corners[2] == corners[3];
    let position = if triangle {
        (corners[0] + corners[1] + corners[2]) / 3.0
    } else {
        (corners[0] + corners[1] + corners[2] + corners[3]) / 4.0
    };
    let area = if triangle {
        triangle_area(corners[0], corners[1], corners[2])
    } else {
        triangle_area(corners[0], corners[1], corners[2])
            + triangle_area(corners[0], corners[2], corners[3])
    };
    let diameter2 = cell_diameter2(&corners);
    SubCell {
        position,
        area,
        corners,
        quadrature: Quadrature::new([(position, 0.0); 4]),
        diameter2,
    }
}

/// A step's split cells and what their sub-cells send.
///
/// Invariant: `first` has one entry per sample of the shooter it is
/// passed with, [`NONE`] or the index of the sample's first sub-cell in
/// `cells` and `values` (a multiple of 4, its first [`Quadrature`] in
/// `centres` being a quarter of it).
#[derive(Clone, Copy, Debug)]
pub struct Split<'a, W> {
    /// Per sample: where its sub-cells start, or [`NONE`] (taken whole).
    pub first: &'a [u32],
    /// The sub-cells' geometry.
    pub cells: &'a [SubCell],
    /// The sub-cells' centres, four to a [`Quadrature`] ([`SubCells::centres`]).
    pub centres: &'a [Quadrature],
    /// The sub-cells' leaves, [`LEAVES`] per sub-cell in the order of `cells`.
    pub leaves: &'a [SubCell],
    /// What each sub-cell sends (an unshot radiosity, say).
    pub values: &'a [W],
    /// What each leaf sends, in the order of `leaves`.
    pub leaf_values: &'a [W],
}

impl<'a, W> Split<'a, W>
where
    W: Copy + Default + std::ops::AddAssign + std::ops::Mul<f64, Output = W>,
{
    /// The split of polygon `subs` with `values` one per sub-cell, when there
    /// are as many (none in the per-polygon scheme).
    pub fn of_polygon(subs: &'a SubCells, values: &'a [W]) -> Option<Self> {
        (!subs.is_empty() && values.len() == subs.len()).then(|| {
            let (values, leaf_values) = values.split_at(subs.cells.len());
            Split {
                first: &subs.first,
                cells: &subs.cells,
                centres: &subs.centres,
                leaves: &subs.leaves,
                values,
                leaf_values,
            }
        })
    }

    /// The split of the single sample `k` of `subs` with its sub-cells'
    /// `values` ([`SUBCELLS`] of them) and their leaves' `leaf_values`
    /// ([`SubCells::cell_values`]), for a shot of that one cell.
    pub fn of_cell(
        subs: &'a SubCells,
        k: usize,
        values: &'a [W],
        leaf_values: &'a [W],
    ) -> Option<Self> {
        let f = *subs.first.get(k)? as usize;
        if f == NONE as usize || values.len() != SUBCELLS || leaf_values.len() != SUBCELLS * LEAVES
        {
            return None;
        }
        Some(Split {
            first: &[0],
            cells: &subs.cells[f..f + SUBCELLS],
            centres: &subs.centres[f / 4..f / 4 + SUBCELLS / 4],
            leaves: &subs.leaves[f * LEAVES..(f + SUBCELLS) * LEAVES],
            values,
            leaf_values,
        })
    }

    /// Where sample `k`'s sub-cells start, when it is split.
    #[inline]
    pub fn of(&self, k: usize) -> Option<usize> {
        match self.first.get(k) {
            Some(&f) if f != NONE => Some(f as usize),
            _ => None,
        }
    }

    /// `Σ value · F` over the sub-cells from `first` seen from `x` (unit normal
    /// `nx`), the shooter's unit normal being `ns`, and `Σ F` alone (whether
    /// anything is seen). `far` says the receiver is more than
    /// [`SUBCELL_FAR_SCALE`](crate::solver::tuning::SUBCELL_FAR_SCALE) of the cell's exact radius away.
    #[inline]
    pub fn sum(&self, first: usize, x: Vec3, nx: Vec3, ns: Vec3, far: bool) -> (W, f64) {
        let mut sum = W::default();
        let mut total = 0.0;
        let values = &self.values[first..first + SUBCELLS];
        let cells = &self.cells[first..first + SUBCELLS];
        if far {
            for (q, four) in self.centres[first / 4..first / 4 + SUBCELLS / 4]
                .iter()
                .zip(values.chunks_exact(4))
            {
                let terms = lane_terms(x, nx, ns, q).to_array();
                for (&t, &value) in terms.iter().zip(four) {
                    if t > 0.0 {
                        let t = f64::from(t);
                        sum += value * t;
                        total += t;
                    }
                }
            }
            return (sum, total);
        }
        for (p, (c, &value)) in cells.iter().zip(values).enumerate() {
            // A receiver this close sees the light vary across the sub-cell
            // (where a sphere touches the floor it falls to nothing under
            // the contact): each leaf sends its own.
            if x.distance_squared(c.position)
                < SUBCELL_LEAF_RATIO * SUBCELL_LEAF_RATIO * c.diameter2
            {
                let leaves = (first + p) * LEAVES..(first + p + 1) * LEAVES;
                for (leaf, &value) in self.leaves[leaves.clone()]
                    .iter()
                    .zip(&self.leaf_values[leaves])
                {
                    let term = part_term(leaf, x, nx, ns);
                    if term > 0.0 {
                        sum += value * term;
                        total += term;
                    }
                }
            } else {
                let term = part_term(c, x, nx, ns);
                if term > 0.0 {
                    sum += value * term;
                    total += term;
                }
            }
        }
        (sum, total)
    }
}

/// The form factor from a receiver at `x` (unit normal `nx`) to sub-cell or
/// leaf `c` of a shooter whose unit normal is `ns`, by the rules of a cell:
/// Lambert's exact one within [`EXACT_RATIO`] of its diameters, its
/// quadrature within [`NEAR_FIELD_RATIO`], its point term beyond; 0 when
/// it lies behind the receiver.
#[inline(always)]
fn part_term(c: &SubCell, x: Vec3, nx: Vec3, ns: Vec3) -> f64 {
    let d = x - c.position;
    let r2 = d.length_squared();
    if r2 < EXACT_RATIO * EXACT_RATIO * c.diameter2 {
        if c.corners.iter().all(|p| nx.dot(*p - x) <= 0.0) {
            return 0.0;
        }
        point_to_polygon(x, nx, &c.corners)
    } else if r2 < NEAR_FIELD_RATIO * NEAR_FIELD_RATIO * c.diameter2 {
        // A sub-cell reaching past the receiver's plane from behind it lights
        // it by its part in front, as a cell does.
        if nx.dot(d) >= 0.0 {
            if c.corners.iter().all(|p| nx.dot(*p - x) <= 0.0) {
                return 0.0;
            }
            point_to_polygon(x, nx, &c.corners)
        } else {
            f64::from(lane_terms(x, nx, ns, &c.quadrature).element_sum())
        }
    } else {
        let (cos_s, cos_x) = (ns.dot(d), -nx.dot(d));
        if cos_s <= 0.0 || cos_x <= 0.0 {
            return 0.0;
        }
        let r2 = f64::from(r2);
        f64::from(cos_s) * f64::from(cos_x) * c.area / (PI * r2 * r2)
    }
}

/// Sets each split cell's value in `cells` (one per shooter sample, as
/// read at the cells' centres) to the area-weighted mean of its sub-cells'
/// `readings` (one per sub-cell, then one per leaf, as [`SubCells::all`]):
/// what the cell sends when a step takes it whole. Does nothing unless
/// there is one reading per sub-cell and leaf.
pub fn carry_means(subs: &SubCells, readings: &[Rgb], cells: &mut [Rgb]) {
    if readings.len() != subs.len() {
        return;
    }
    for (k, &f) in subs.first.iter().enumerate() {
        if f == NONE {
            continue;
        }
        let range = f as usize..f as usize + SUBCELLS;
        let (mut sum, mut area) = (Rgb::BLACK, 0.0);
        for (c, &v) in subs.cells[range.clone()].iter().zip(&readings[range]) {
            sum += v * c.area;
            area += c.area;
        }
        if let (Some(cell), true) = (cells.get_mut(k), area > 0.0) {
            *cell = sum / area;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::formfactor::ShooterSample;

    fn square_cell(side: f32) -> ShooterSample {
        let c = [
            Vec3::ZERO,
            Vec3::new(side, 0.0, 0.0),
            Vec3::new(side, side, 0.0),
            Vec3::new(0.0, side, 0.0),
        ];
        ShooterSample::cell(
            Vec3::new(side / 2.0, side / 2.0, 0.0),
            f64::from(side * side),
            c,
        )
    }

    /// The sub-cells of a quadrilateral and of a triangle cover the cell: their
    /// areas sum to its area and their centres lie inside it.
    #[test]
    fn parts_cover_their_cell() {
        for cell in [
            [
                Vec3::ZERO,
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(2.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            [
                Vec3::ZERO,
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 3.0, 0.0),
                Vec3::new(0.0, 3.0, 0.0),
            ],
        ] {
            let mut subcells = Vec::new();
            let expected = if cell[2] == cell[3] { 3.0 } else { 2.0 };
            cut(&cell, expected, &mut subcells);
            assert_eq!(subcells.len(), SUBCELLS);
            // The sub-cells' own geometry, not the areas `cut` scaled.
            let area: f64 = subcells
                .iter()
                .map(|p| {
                    let c = p.corners;
                    triangle_area(c[0], c[1], c[2]) + triangle_area(c[0], c[2], c[3])
                })
                .sum();
            assert!((area - expected).abs() < 1e-6, "{area} against {expected}");
            for p in &subcells {
                assert!(p.position.x > 0.0 && p.position.y > 0.0, "{p:?}");
                assert!((p.area - expected / SUBCELLS as f64).abs() < 1e-6);
            }
        }
    }

    /// The sub-cells' form factors add up to the cell's exact one, near it
    /// (Lambert's and quadratures), a little farther (quadratures and
    /// point terms) and far away (point terms four at a time), within the
    /// errors the cell's own rules allow there.
    #[test]
    fn parts_add_up_to_their_cell() {
        let s = square_cell(1.0);
        let subs = SubCells::build(std::slice::from_ref(&s), |_| true);
        assert_eq!(subs.len(), PER_CELL);
        assert_eq!(subs.centres.len(), SUBCELLS / 4);
        let ones = [1.0f64; PER_CELL];
        let split = Split::of_polygon(&subs, &ones).unwrap();
        let nx = -Vec3::Z;
        for (x, far, tolerance) in [
            (Vec3::new(0.3, 0.6, 0.05), false, 0.002),
            (Vec3::new(0.3, 0.6, 0.4), false, 0.002),
            (Vec3::new(1.5, 0.2, 1.2), false, 0.005),
            (Vec3::new(0.5, 0.5, 20.0), true, 0.001),
        ] {
            let (f, total) = split.sum(0, x, nx, Vec3::Z, far);
            let whole = point_to_polygon(x, nx, s.cell.as_ref().unwrap());
            assert!(
                (f - whole).abs() < tolerance * whole,
                "at {x}: {f} against {whole}"
            );
            assert_eq!(f, total);
        }
    }

    /// Just over a cell whose light falls to nothing under the receiver
    /// (a sphere resting on the floor), the leaves follow the light across
    /// the sub-cells: at 0.8 leaf widths over the dark point, against the light
    /// integrated over 128 × 128 squares, the leaves' sum is 6 % over and
    /// the sub-cells' alone 55 % (at 1.6 leaf widths, 2 % and 21 %).
    #[test]
    fn leaves_follow_the_light_under_a_close_receiver() {
        let s = square_cell(1.0);
        let subs = SubCells::build(std::slice::from_ref(&s), |_| true);
        let contact = Vec3::new(0.3, 0.6, 0.0);
        let light = |p: Vec3| f64::from(p.distance(contact));
        let x = contact + Vec3::new(0.0, 0.0, 0.05);
        let nx = -Vec3::Z;
        let n = 128;
        let h = 1.0 / n as f32;
        let mut exact = 0.0;
        for j in 0..n {
            for i in 0..n {
                let (u, v) = (i as f32 * h, j as f32 * h);
                let corners = [
                    Vec3::new(u, v, 0.0),
                    Vec3::new(u + h, v, 0.0),
                    Vec3::new(u + h, v + h, 0.0),
                    Vec3::new(u, v + h, 0.0),
                ];
                let centre = Vec3::new(u + h / 2.0, v + h / 2.0, 0.0);
                exact += light(centre) * point_to_polygon(x, nx, &corners);
            }
        }
        let values: Vec<f64> = subs.all().map(|c| light(c.position)).collect();
        let split = Split::of_polygon(&subs, &values).unwrap();
        let (with_leaves, _) = split.sum(0, x, nx, Vec3::Z, false);
        // Each sub-cell's leaves carrying its own value: the sub-cells alone.
        let mut flat = values.clone();
        for p in 0..SUBCELLS {
            for leaf in &mut flat[SUBCELLS + p * LEAVES..SUBCELLS + (p + 1) * LEAVES] {
                *leaf = values[p];
            }
        }
        let split = Split::of_polygon(&subs, &flat).unwrap();
        let (subcells_alone, _) = split.sum(0, x, nx, Vec3::Z, false);
        assert!(
            (with_leaves - exact).abs() < 0.08 * exact,
            "leaves {with_leaves} against {exact}"
        );
        assert!(
            subcells_alone > 1.4 * exact,
            "subcells {subcells_alone} against {exact}"
        );
    }

    /// A split cell carries its sub-cells' mean; a cell without sub-cells keeps
    /// its own reading.
    #[test]
    fn a_split_cell_carries_its_parts_mean() {
        let s = square_cell(1.0);
        let mut subs = SubCells::build(&[s, s], |_| true);
        subs.first[0] = NONE;
        let mut readings = vec![Rgb::splat(1.0); 2 * PER_CELL];
        // The second cell's first sub-cell (the sub-cells come before the leaves).
        readings[SUBCELLS] = Rgb::splat(17.0);
        let mut cells = vec![Rgb::splat(3.0), Rgb::splat(5.0)];
        carry_means(&subs, &readings, &mut cells);
        assert_eq!(cells[0], Rgb::splat(3.0));
        assert!((cells[1].g - 2.0).abs() < 1e-9, "{:?}", cells[1]);
    }

    /// Cells are split where something stands over them (a cube on the
    /// floor), not in the room's far corner, where only the walls meet the
    /// floor, nor on the wall a tenth of the room from the cube (more
    /// than [`SUBCELL_CLOSE`] of its cells' diameter), nor on the ceiling.
    #[test]
    fn cells_are_split_where_something_stands_over_them() {
        use crate::solver::formfactor::{shooter_samples, SampleSet};
        use crate::testutil::{closed_box, cuboid, grey, regular_mesh, scene};
        let mut polygons = closed_box(1.0, [0; 6]);
        polygons.extend(cuboid([0.1, 0.0, 0.1], [0.2, 0.1, 0.2], false));
        let s = scene(polygons, vec![grey("wall", 0.0, 0.5)]);
        let mesh = regular_mesh(&s, 0.02);
        let samples: Vec<Vec<ShooterSample>> = s
            .polygons
            .iter()
            .zip(&mesh.polygons)
            .map(|(p, pm)| shooter_samples(p, pm, &mesh, SampleSet::AtMost(64)))
            .collect();
        let subcells = SubCells::build_all(&s, &mesh, &samples, true);
        let split_at = |polygon: usize, at: Vec3| {
            let k = samples[polygon]
                .iter()
                .position(|c| c.position.distance(at) < 1e-3)
                .expect("a cell centred there");
            subcells[polygon].first[k] != NONE
        };
        // The floor (y = 0) is polygon 2, the ceiling 3, the wall x = 0 is 0.
        assert!(split_at(2, Vec3::new(0.0625, 0.0, 0.0625)));
        assert!(split_at(2, Vec3::new(0.1875, 0.0, 0.3125)));
        assert!(!split_at(2, Vec3::new(0.9375, 0.0, 0.9375)));
        assert!(!split_at(2, Vec3::new(0.0625, 0.0, 0.9375)));
        assert!(!split_at(0, Vec3::new(0.0, 0.0625, 0.1875)));
        assert!(subcells[0].is_empty());
        assert!(subcells[3].is_empty());
        // The cube's faces are finer than their cells' split threshold.
        assert!(subcells[6..].iter().all(SubCells::is_empty));
        // Every split cell's sub-cells tile it.
        for (p, samples) in subcells.iter().zip(&samples) {
            for (k, &f) in p.first.iter().enumerate() {
                if f != NONE {
                    let f = f as usize;
                    let subcells = &p.cells[f..f + SUBCELLS];
                    let area: f64 = subcells.iter().map(|c| c.area).sum();
                    assert!((area - samples[k].area).abs() < 1e-9 * samples[k].area);
                    let leaves = &p.leaves[f * LEAVES..(f + SUBCELLS) * LEAVES];
                    for (subcell, leaves) in subcells.iter().zip(leaves.chunks(LEAVES)) {
                        let area: f64 = leaves.iter().map(|c| c.area).sum();
                        assert!((area - subcell.area).abs() < 1e-9 * subcell.area);
                    }
                }
            }
        }
    }
}
