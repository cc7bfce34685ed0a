//! Form factors from a shooting polygon to a receiving point, after
//! Wallace, Elmquist and Haines (SIGGRAPH '89).
//!
//! The shooter is represented by sample points `k`, each standing for an
//! area `a_k` of it. The form factor from a differential area at a receiver
//! point `x` to the shooter is estimated as
//!
//! ```text
//! F ≈ Σ_k  v_k · cosθ_i cosθ_j · a_k / (π r² + a_k)
//! ```
//!
//! the exact form factor of a disc of area `a_k` seen head-on, applied to
//! each sample. With equal areas `a_k = A_i / n_i` this is the textbook
//! `cosθ_i cosθ_j / (1 + π n_i r² / A_i)`; the `+ a_k` keeps it bounded
//! (never above 1 per sample) when a receiver is close to the shooter.
//! A negative cosine counts as occluded and casts no ray.
//!
//! **Near and middle field.** The disc term is a one-point rule: its error
//! grows as `(size / distance)²`, and the `+ a_k` that bounds it biases it
//! low wherever the sample is not seen head-on (about −0.4 % on a wall
//! meeting the shooter at a right angle, which a closed room then loses at
//! every bounce). So for the grid samples, which know their cells, the term
//! depends on the distance `r` to the sample, in cell diameters `d`:
//!
//! - `r ≥` [`NEAR_FIELD_RATIO`]` · d`: the point term
//!   `cosθ_i cosθ_j a_k / (π r²)`, unbiased to second order;
//! - [`EXACT_RATIO`]` · d ≤ r <` [`NEAR_FIELD_RATIO`]` · d`: the sample is
//!   subdivided: the cell's point terms at a second-order quadrature rule's
//!   points (2 × 2 Gauss points of a quadrilateral, weighted by its area
//!   element; the three-point rule of a triangle), each with its own
//!   cosines;
//! - `r <` [`EXACT_RATIO`]` · d`: the exact form factor from the point to
//!   the cell (Lambert's contour integral over the cell clipped to the
//!   receiver's front half-space), which stays finite as the receiver
//!   touches the shooter.
//!
//! Each still takes the visibility of the one ray to the sample. Against
//! Lambert's formula at 2,000 random points around a unit square with 64
//! cells, the worst error is 0.3 % (the disc sum alone: 2.2 %). Vertex
//! samples ([`SampleSet::Vertices`], the original algorithm) have no cell
//! and keep the disc term; so does every sample with the near field
//! switched off.

use crate::mesh::{area_centroid, drop_collinear, Mesh, PolygonMesh};
use crate::scene::{Polygon, Scene, Shape};
use crate::solver::accel::subcells::Split;
use crate::solver::tuning::{EXACT_RATIO, NEAR_FIELD_RATIO, SKY_FACET_SAMPLES, SUBCELL_FAR_SCALE};
use glam::{DVec3, Vec3, Vec4};
use std::f64::consts::PI;

/// A point of a shooting polygon and the area it stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShooterSample {
    /// Position on the shooter, in scene units.
    pub position: Vec3,
    /// Area it stands for, in square scene units; the samples of one
    /// shooter sum to its area. A standard sky's facet's sample stands for
    /// its cell's area times the sky's luminance in its direction over the
    /// facet's mean ([`weight_by_luminance`]): its share of the facet's
    /// power, which is what every use of the area takes it for.
    pub area: f64,
    /// The cell it stands for (3 or 4 corners, counter-clockwise from the
    /// front; a triangle repeats its last corner), for grid samples.
    pub cell: Option<[Vec3; 4]>,
    /// Squared distance within which the cell's quadrature is used, in
    /// square scene units (0 without a cell).
    pub near_r2: f32,
    /// Squared distance within which the exact point-to-cell form factor is
    /// used, in square scene units (0 without a cell).
    pub exact_r2: f32,
    /// Quadrature points over the cell and the areas they stand for
    /// (summing to [`ShooterSample::area`]; a triangle's fourth is unused
    /// and stands for 0).
    pub quadrature: Quadrature,
}

/// Four quadrature points and their areas, one per SIMD lane: `x[k]`,
/// `y[k]`, `z[k]` the position of point `k` in scene units, `area[k]` the
/// square scene units it stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadrature {
    /// x coordinates.
    pub x: Vec4,
    /// y coordinates.
    pub y: Vec4,
    /// z coordinates.
    pub z: Vec4,
    /// Areas.
    pub area: Vec4,
}

impl Quadrature {
    pub(crate) fn new(points: [(Vec3, f32); 4]) -> Self {
        let lane = |f: fn(&(Vec3, f32)) -> f32| Vec4::from_array(points.each_ref().map(f));
        Quadrature {
            x: lane(|p| p.0.x),
            y: lane(|p| p.0.y),
            z: lane(|p| p.0.z),
            area: lane(|p| p.1),
        }
    }
}

impl ShooterSample {
    /// Bounds `(min, max)` of its cell's corners, or its position alone
    /// without a cell, in scene units.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.cell.map_or((self.position, self.position), |corners| {
            corners
                .iter()
                .fold((self.position, self.position), |(lo, hi), &c| {
                    (lo.min(c), hi.max(c))
                })
        })
    }

    /// A sample without a cell: always the disc approximation.
    pub fn point(position: Vec3, area: f64) -> Self {
        ShooterSample {
            position,
            area,
            cell: None,
            near_r2: 0.0,
            exact_r2: 0.0,
            quadrature: Quadrature::new([(position, 0.0); 4]),
        }
    }

    /// A sample at the centre of a cell (3 or 4 corners counter-clockwise;
    /// a triangle repeats its last corner) of `area` square scene units.
    pub fn cell(position: Vec3, area: f64, cell: [Vec3; 4]) -> Self {
        let diameter2 = cell_diameter2(&cell);
        ShooterSample {
            position,
            area,
            cell: Some(cell),
            near_r2: NEAR_FIELD_RATIO * NEAR_FIELD_RATIO * diameter2,
            exact_r2: EXACT_RATIO * EXACT_RATIO * diameter2,
            quadrature: Quadrature::new(quadrature(&cell, area)),
        }
    }
}

/// The squared diameter of a cell (3 or 4 corners, a triangle repeating
/// its last): its longest diagonal or side, in square scene units.
pub(crate) fn cell_diameter2(cell: &[Vec3; 4]) -> f32 {
    cell[0]
        .distance_squared(cell[2])
        .max(cell[1].distance_squared(cell[3]))
        .max(cell[0].distance_squared(cell[1]))
        .max(cell[1].distance_squared(cell[2]))
}

/// A second-order quadrature rule over a cell: for a quadrilateral the
/// 2 × 2 Gauss points of its bilinear map, each weighted by the area
/// element there (exact for a planar bilinear cell); for a triangle (last
/// corner repeated) the three points at barycentric `(2/3, 1/6, 1/6)` and
/// its permutations, a third of the area each. Areas sum to `area`.
pub(crate) fn quadrature(cell: &[Vec3; 4], area: f64) -> [(Vec3, f32); 4] {
    let [a, b, c, d] = *cell;
    if c == d {
        let third = (area / 3.0) as f32;
        let at = |u: f32, v: f32, w: f32| (a * u + b * v + c * w, third);
        let (big, small) = (2.0 / 3.0, 1.0 / 6.0);
        return [
            at(big, small, small),
            at(small, big, small),
            at(small, small, big),
            (a, 0.0),
        ];
    }
    let g = 0.5 / 3f32.sqrt();
    let mut points = [(a, 0.0f32); 4];
    let mut total = 0.0f64;
    for (slot, (u, w)) in points.iter_mut().zip([
        (0.5 - g, 0.5 - g),
        (0.5 + g, 0.5 - g),
        (0.5 + g, 0.5 + g),
        (0.5 - g, 0.5 + g),
    ]) {
        let p = (1.0 - u) * (1.0 - w) * a + u * (1.0 - w) * b + u * w * c + (1.0 - u) * w * d;
        let du = (1.0 - w) * (b - a) + w * (c - d);
        let dw = (1.0 - u) * (d - a) + u * (c - b);
        let jacobian = du.cross(dw).length() as f64;
        total += jacobian;
        *slot = (p, jacobian as f32);
    }
    for slot in &mut points {
        slot.1 = if total > 0.0 {
            (f64::from(slot.1) / total * area) as f32
        } else {
            (area / 4.0) as f32
        };
    }
    points
}

/// Which points of a shooter carry its power.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleSet {
    /// Its element vertices (evaluation positions), each standing for
    /// `A / n`: the scheme of the original algorithm (on an adaptively
    /// refined polygon, each for its share of the area: see
    /// [`Mesh::polygon_vertex_weights`]).
    Vertices,
    /// A regular grid of at most this many points over the polygon, and
    /// no more than it has element vertices, each at the centre of its
    /// cell and standing for that cell's area.
    AtMost(u32),
    /// One point at the area centroid standing for the whole polygon: the
    /// cheap point-to-disc approximation.
    Centre,
    /// A sky facet's samples ([`SKY_FACET_SAMPLES`]): a regular grid of
    /// about this many cells whatever its element vertices, each sampled
    /// at a pseudo-random point inside it (the same on every run), always
    /// with the far-field point term (see `sky_samples`).
    Sky(u32),
}

impl SampleSet {
    /// The set `polygon` shoots from when the solve asks for `set`: its
    /// own grid of [`SKY_FACET_SAMPLES`] for a sky facet, `set` for any
    /// other polygon.
    pub fn for_polygon(set: SampleSet, polygon: &Polygon) -> SampleSet {
        if polygon.surface.sky {
            SampleSet::Sky(SKY_FACET_SAMPLES)
        } else {
            set
        }
    }
}

/// The shooter samples of one polygon, chosen as `set` says (see
/// [`SampleSet::for_polygon`] for the set a polygon shoots from).
pub fn shooter_samples(
    polygon: &Polygon,
    pm: &PolygonMesh,
    mesh: &Mesh,
    set: SampleSet,
) -> Vec<ShooterSample> {
    match set {
        SampleSet::Centre => vec![ShooterSample::point(
            area_centroid(&polygon.vertices),
            polygon.area,
        )],
        // As many cells as vertices on a small polygon: the same rays as
        // shooting from its vertices, and cells give the near field (a
        // table leg shooting at the floor it stands on).
        SampleSet::AtMost(n) => grid_samples(polygon, n.min(pm.vertex_count()).max(1)),
        SampleSet::Sky(n) => sky_samples(polygon, n.max(1)),
        SampleSet::Vertices => mesh.sample_positions
            [pm.vertices.start as usize..pm.vertices.end as usize]
            .iter()
            .zip(mesh.polygon_vertex_weights(pm))
            .map(|(&position, weight)| ShooterSample::point(position, polygon.area * weight))
            .collect(),
    }
}

/// The shooter samples of polygon `i` of `scene` ([`shooter_samples`]),
/// a standard sky's facet's weighted by the sky's luminance in each
/// sample's direction ([`weight_by_luminance`]): what the solver shoots
/// from and the final gather gathers.
pub fn polygon_samples(
    scene: &Scene,
    i: usize,
    pm: &PolygonMesh,
    mesh: &Mesh,
    set: SampleSet,
) -> Vec<ShooterSample> {
    let polygon = &scene.polygons[i];
    let mut samples = shooter_samples(polygon, pm, mesh, set);
    if let (SampleSet::Sky(_), Some(pattern)) = (set, &scene.sky_pattern) {
        if pattern.covers(i) && !pattern.is_ground(area_centroid(&polygon.vertices)) {
            weight_by_luminance(&mut samples, |p| pattern.luminance_at(p));
        }
    }
    samples
}

/// Spreads a facet's power over its `samples` as `luminance` (at a
/// sample's position, any unit, `>= 0`) says: each sample's area (and its
/// quadrature's) times its luminance over the area-weighted mean of them
/// all, so the samples still sum to the facet's area and the facet sends
/// what its emission says, but each direction carries its own share.
/// Under a uniform luminance every factor is 1 to rounding; a facet that
/// reads nothing anywhere is left even.
///
/// The facet emits `π` times the sky's mean luminance over it; with these
/// weights sample `k` emits `π L_k` times that mean over the samples'
/// mean, which differ only by the samples' sampling of a smooth function:
/// cards at a standard sky's centre receive its illuminance within
/// 0.05 % (`solver::tests::daylight_sky`).
pub fn weight_by_luminance(samples: &mut [ShooterSample], luminance: impl Fn(Vec3) -> f64) {
    let l: Vec<f64> = samples.iter().map(|s| luminance(s.position)).collect();
    let total: f64 = samples.iter().map(|s| s.area).sum();
    let lit: f64 = samples.iter().zip(&l).map(|(s, l)| s.area * l).sum();
    if !(lit > 0.0 && total > 0.0 && lit.is_finite()) {
        return;
    }
    let mean = lit / total;
    for (s, l) in samples.iter_mut().zip(l) {
        let factor = l.max(0.0) / mean;
        s.area *= factor;
        s.quadrature.area *= factor as f32;
    }
}

/// At most `n` (`>= 1`) cell-centre samples over a polygon.
fn grid_samples(polygon: &Polygon, n: u32) -> Vec<ShooterSample> {
    let v = &polygon.vertices;
    match polygon.shape {
        Shape::Parallelogram | Shape::Quad => {
            // Cells about square: su / sv follows the polygon's aspect.
            let lu = v[0]
                .distance(v[1])
                .max(v[3].distance(v[2]))
                .max(f32::MIN_POSITIVE);
            let lv = v[0]
                .distance(v[3])
                .max(v[1].distance(v[2]))
                .max(f32::MIN_POSITIVE);
            let su = ((n as f32 * lu / lv).sqrt().round() as u32).clamp(1, n);
            let sv = (n / su).max(1);
            let at = |u: f32, w: f32| {
                (1.0 - u) * (1.0 - w) * v[0]
                    + u * (1.0 - w) * v[1]
                    + u * w * v[2]
                    + (1.0 - u) * w * v[3]
            };
            let mut samples = Vec::with_capacity((su * sv) as usize);
            for b in 0..sv {
                for a in 0..su {
                    let (u0, u1) = (a as f32 / su as f32, (a + 1) as f32 / su as f32);
                    let (w0, w1) = (b as f32 / sv as f32, (b + 1) as f32 / sv as f32);
                    let corners = [at(u0, w0), at(u1, w0), at(u1, w1), at(u0, w1)];
                    let area = triangle_area(corners[0], corners[1], corners[2])
                        + triangle_area(corners[0], corners[2], corners[3]);
                    samples.push(ShooterSample::cell(
                        at((u0 + u1) * 0.5, (w0 + w1) * 0.5),
                        area,
                        corners,
                    ));
                }
            }
            normalise_areas(&mut samples, polygon.area);
            samples
        }
        Shape::Triangle => {
            let m = ((n as f64).sqrt() as u32).max(1);
            triangle_cells(v[0], v[1], v[2], m)
        }
        Shape::Convex => {
            let rim = inscribed(&drop_collinear(v), n as usize);
            let apex = area_centroid(&rim);
            let m = ((n as f64 / rim.len() as f64).sqrt() as u32).max(1);
            let mut samples: Vec<ShooterSample> = (0..rim.len())
                .flat_map(|k| triangle_cells(apex, rim[k], rim[(k + 1) % rim.len()], m))
                .collect();
            normalise_areas(&mut samples, polygon.area);
            samples
        }
    }
}

/// The polygon of at most `n` (at least three) of the convex `rim`'s
/// vertices, spread evenly along its perimeter: the rim itself when it
/// has no more than `n`.
///
/// A fan of cells over every rim vertex would give a disc of 100,000
/// vertices 100,000 sliver cells meeting at its centre, where `n` asks for
/// 64, and the cell integrals would clip every element against most of
/// them. The caps left between the chosen chords and the rim are small
/// (0.16 % of a circle's area at 64 vertices), and the samples' areas are
/// normalised to the polygon's area.
fn inscribed(rim: &[Vec3], n: usize) -> Vec<Vec3> {
    let n = n.max(3);
    if rim.len() <= n {
        return rim.to_vec();
    }
    let m = rim.len();
    let mut along = Vec::with_capacity(m);
    let mut total = 0.0f64;
    for k in 0..m {
        along.push(total);
        total += f64::from(rim[k].distance(rim[(k + 1) % m]));
    }
    let mut kept = Vec::with_capacity(n);
    let mut k = 0;
    for i in 0..n {
        let target = total * i as f64 / n as f64;
        while k + 1 < m && along[k + 1] <= target {
            k += 1;
        }
        if kept.last() != Some(&rim[k]) {
            kept.push(rim[k]);
        }
    }
    if kept.len() >= 3 {
        kept
    } else {
        rim.to_vec()
    }
}

/// A sky facet's samples: [`grid_samples`] with each sample moved to a
/// pseudo-random point of its cell, drawn from a stream seeded by the
/// polygon's first vertex, and with no near field.
///
/// The samples are the directions sky light comes from. On a regular grid
/// they lie in rows, and a whole row enters the view through a straight
/// window edge at once: the floor under a skylight shows a staircase of
/// hard-edged copies of the window. Jittered, the directions cross the
/// edge one at a time.
///
/// The sky is far from every receiver (nine tenths of its radius at
/// least), where the point term is accurate; the near-field rules, which
/// take one ray for a whole cell, would let a large sky cell that straddles
/// a receiver's plane be seen through the receiver's own polygon from
/// behind (a leak into a closed box).
fn sky_samples(polygon: &Polygon, n: u32) -> Vec<ShooterSample> {
    let mut samples = grid_samples(polygon, n);
    let first = polygon.vertices.first().copied().unwrap_or_default();
    let mut state = first
        .to_array()
        .iter()
        .fold(0x9e37_79b9_7f4a_7c15u64, |h, c| {
            splitmix64(h ^ u64::from(c.to_bits()))
        });
    let mut unit = || {
        state = splitmix64(state);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for s in &mut samples {
        let Some([a, b, c, d]) = s.cell else {
            continue;
        };
        let (u, w) = (unit(), unit());
        s.position = if c == d {
            // Uniform in the triangle: fold the unit square's far half.
            let (u, w) = if u + w > 1.0 {
                (1.0 - u, 1.0 - w)
            } else {
                (u, w)
            };
            a + u * (b - a) + w * (c - a)
        } else {
            (1.0 - u) * (1.0 - w) * a + u * (1.0 - w) * b + u * w * c + (1.0 - u) * w * d
        };
        s.near_r2 = 0.0;
        s.exact_r2 = 0.0;
    }
    samples
}

/// One step of the SplitMix64 generator: a well-mixed 64-bit value.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Centroids of the `m²` congruent triangles of the regular subdivision of
/// a triangle, each standing for `1/m²` of its area.
fn triangle_cells(v0: Vec3, v1: Vec3, v2: Vec3, m: u32) -> Vec<ShooterSample> {
    let area = triangle_area(v0, v1, v2) / (m * m) as f64;
    let (e1, e2) = (v1 - v0, v2 - v0);
    let at = |i: f32, j: f32| v0 + (i / m as f32) * e1 + (j / m as f32) * e2;
    let mut samples = Vec::with_capacity((m * m) as usize);
    for j in 0..m {
        for i in 0..(m - j) {
            let (fi, fj) = (i as f32, j as f32);
            let (a, b, c) = (at(fi, fj), at(fi + 1.0, fj), at(fi, fj + 1.0));
            samples.push(ShooterSample::cell((a + b + c) / 3.0, area, [a, b, c, c]));
            if i + j + 1 < m {
                let d = at(fi + 1.0, fj + 1.0);
                samples.push(ShooterSample::cell((b + d + c) / 3.0, area, [b, d, c, c]));
            }
        }
    }
    samples
}

pub(crate) fn triangle_area(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    (b.as_dvec3() - a.as_dvec3())
        .cross(c.as_dvec3() - a.as_dvec3())
        .length()
        * 0.5
}

/// Scales the sample areas to sum to exactly `total` (the polygon's area
/// from the scene), removing `f32` rounding in the cell corners.
fn normalise_areas(samples: &mut [ShooterSample], total: f64) {
    let sum: f64 = samples.iter().map(|s| s.area).sum();
    if sum > 0.0 {
        for s in samples {
            s.area *= total / sum;
        }
    }
}

/// The form factor from a differential area at `x` (unit normal `nx`) to a
/// shooter (unit normal `ns`) represented by `samples`, and the number of
/// visibility questions asked. `occluded(k, position)` answers whether the
/// segment from sample `k` to `x` is blocked; it is asked only for samples
/// that can contribute. `near_field` enables the exact
/// near-field term (see the module docs).
#[inline]
pub fn point_to_samples(
    x: Vec3,
    nx: Vec3,
    ns: Vec3,
    samples: &[ShooterSample],
    near_field: bool,
    occluded: impl FnMut(usize, Vec3) -> bool,
) -> (f64, u64) {
    weighted_point_to_samples(x, nx, ns, samples, |_| 1.0, None, near_field, occluded)
}

/// [`point_to_samples`] with each sample's term multiplied by
/// `weight(k)` (an unshot radiosity, say) before summing: returns
/// `Σ_k weight(k) · F_k` and the number of visibility questions asked.
/// A sample that `split` takes by its sub-cells ([`Split`]) gives
/// `Σ value · F` over them instead, under its one ray.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn weighted_point_to_samples<W>(
    x: Vec3,
    nx: Vec3,
    ns: Vec3,
    samples: &[ShooterSample],
    weight: impl Fn(usize) -> W,
    split: Option<&Split<W>>,
    near_field: bool,
    mut occluded: impl FnMut(usize, Vec3) -> bool,
) -> (W, u64)
where
    W: Copy + Default + std::ops::AddAssign + std::ops::Mul<f64, Output = W>,
{
    let mut sum = W::default();
    let mut rays = 0u64;
    for (k, s) in samples.iter().enumerate() {
        let d = x - s.position;
        let r2 = d.length_squared();
        let cos_s = ns.dot(d);
        let cos_x = -nx.dot(d);
        if cos_s < 0.0 || r2 <= 0.0 {
            continue;
        }
        if let (Some(split), Some(cell), true) = (split, s.cell, near_field) {
            if let Some(first) = split.of(k) {
                let far = r2 >= s.exact_r2 * SUBCELL_FAR_SCALE * SUBCELL_FAR_SCALE;
                let (value, seen) = split.sum(first, x, nx, ns, far);
                if seen <= 0.0 {
                    continue;
                }
                // The cell's ray, as when it is taken whole.
                let from = if cos_x <= 0.0 {
                    front_point(x, nx, &cell).unwrap_or(s.position)
                } else {
                    s.position
                };
                rays += 1;
                if !occluded(k, from) {
                    sum += value;
                }
                continue;
            }
        }
        let term = match s.cell {
            // A receiver in the shooter's plane at its edge still sees it
            // (half of its hemisphere, at a right-angled corner).
            Some(cell) if near_field && r2 < s.exact_r2 => point_to_polygon(x, nx, &cell),
            // A cell reaching past the receiver's plane from behind it: a
            // quadrature point in front would stand for its whole share.
            // Wholly behind (the common case: a floor cell behind a
            // box's side) it brings nothing.
            Some(cell) if near_field && r2 < s.near_r2 && cos_x <= 0.0 => {
                if cell.iter().all(|c| nx.dot(*c - x) <= 0.0) {
                    continue;
                }
                point_to_polygon(x, nx, &cell)
            }
            // The cosines vary over the cell: each point has its own.
            Some(_) if near_field && r2 < s.near_r2 => quadrature_sum(x, nx, ns, &s.quadrature),
            _ if cos_s <= 0.0 || cos_x <= 0.0 => continue,
            Some(_) if near_field => {
                let r2 = r2 as f64;
                cos_s as f64 * cos_x as f64 * s.area / (PI * r2 * r2)
            }
            _ => {
                let r2 = r2 as f64;
                // (cos_s / r)(cos_x / r) with d unnormalised.
                let cosines = cos_s as f64 * cos_x as f64 / r2;
                cosines * s.area / (PI * r2 + s.area)
            }
        };
        if term <= 0.0 {
            continue;
        }
        // A near cell whose sample lies behind the receiver's plane still
        // lights it by its part in front (a floor cell around a table
        // leg, seen from the leg's inner face): the ray goes from that
        // part, since from the sample it would pass through the leg.
        let from = match s.cell {
            Some(cell) if cos_x <= 0.0 => front_point(x, nx, &cell).unwrap_or(s.position),
            _ => s.position,
        };
        rays += 1;
        if !occluded(k, from) {
            sum += weight(k) * term;
        }
    }
    (sum, rays)
}

/// The mean of the corners of the part of `cell` (3 or 4 corners, a
/// triangle repeating its last) strictly in front of the plane through
/// `x` with unit normal `n`: a point of the cell that `x`'s side sees,
/// inside it since the cell is convex. `None` when no part is in front.
pub fn front_point(x: Vec3, n: Vec3, cell: &[Vec3; 4]) -> Option<Vec3> {
    let (mut sum, mut count) = (Vec3::ZERO, 0.0f32);
    for k in 0..4 {
        let (a, b) = (cell[k], cell[(k + 1) % 4]);
        let (da, db) = (n.dot(a - x), n.dot(b - x));
        if da > 0.0 {
            sum += a;
            count += 1.0;
        }
        if (da > 0.0) != (db > 0.0) && da != db {
            sum += a + (b - a) * (da / (da - db));
            count += 1.0;
        }
    }
    let p = sum / count;
    (count > 0.0 && n.dot(p - x) > 0.0).then_some(p)
}

/// The point terms `cosθ_i cosθ_j a / (π r²)` at a cell's quadrature
/// points ([`ShooterSample::quadrature`]), those behind either surface
/// left out; the four at once, one per SIMD lane.
#[inline]
fn quadrature_sum(x: Vec3, nx: Vec3, ns: Vec3, q: &Quadrature) -> f64 {
    f64::from(lane_terms(x, nx, ns, q).element_sum())
}

/// The point terms of [`quadrature_sum`], one per lane (0 where a point
/// is behind either surface).
#[inline]
pub(crate) fn lane_terms(x: Vec3, nx: Vec3, ns: Vec3, q: &Quadrature) -> Vec4 {
    let dx = Vec4::splat(x.x) - q.x;
    let dy = Vec4::splat(x.y) - q.y;
    let dz = Vec4::splat(x.z) - q.z;
    let r2 = dx * dx + dy * dy + dz * dz;
    let cs = dx * ns.x + dy * ns.y + dz * ns.z;
    let cx = -(dx * nx.x + dy * nx.y + dz * nx.z);
    let zero = Vec4::ZERO;
    let seen = cs.cmpgt(zero) & cx.cmpgt(zero) & r2.cmpgt(zero);
    // Lanes left out divide by 1, not by a zero distance.
    let denominator = Vec4::select(seen, r2 * r2 * std::f32::consts::PI, Vec4::ONE);
    Vec4::select(seen, cs * cx * q.area / denominator, zero)
}

/// Exact unoccluded form factor from a differential area at `x` with unit
/// normal `n` to a planar polygon (a triangle may repeat its last corner),
/// by Lambert's contour integral `F = |Σ θ_k n·γ_k| / 2π` over the part of
/// the polygon in front of `x`'s tangent plane.
pub fn point_to_polygon(x: Vec3, n: Vec3, corners: &[Vec3]) -> f64 {
    let (x, n) = (x.as_dvec3(), n.as_dvec3());
    // Corners relative to x; a triangle's repeated last corner is dropped.
    let mut rel: [DVec3; 4] = [DVec3::ZERO; 4];
    let mut m = 0;
    for (k, c) in corners.iter().enumerate().take(4) {
        if k > 0 && *c == corners[k - 1] {
            continue;
        }
        rel[m] = c.as_dvec3() - x;
        m += 1;
    }
    let rel = &rel[..m];
    // Clip to the receiver's front half-space (Sutherland–Hodgman), only
    // when some corner is behind it: near-field cells are mostly in front.
    let mut clipped: [DVec3; 8] = [DVec3::ZERO; 8];
    let mut len = 0;
    if rel.iter().all(|a| n.dot(*a) > 0.0) {
        for (k, a) in rel.iter().enumerate() {
            clipped[k] = a.normalize();
        }
        len = m;
    } else {
        for k in 0..m {
            let (a, b) = (rel[k], rel[(k + 1) % m]);
            let (da, db) = (n.dot(a), n.dot(b));
            if da > 0.0 {
                clipped[len] = a;
                len += 1;
            }
            if (da > 0.0) != (db > 0.0) && da != db {
                clipped[len] = a + (b - a) * (da / (da - db));
                len += 1;
            }
        }
        for c in &mut clipped[..len] {
            *c = c.normalize_or_zero();
        }
    }
    if len < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..len {
        let (a, b) = (clipped[k], clipped[(k + 1) % len]);
        let c = a.cross(b);
        let sin = c.length();
        if sin > 0.0 {
            sum += atan2_nonnegative(sin, a.dot(b)) * n.dot(c) / sin;
        }
    }
    (sum / (2.0 * PI)).abs()
}

/// `atan2(y, x)` for `y >= 0`, by a minimax polynomial for `atan` on
/// `[0, 1]` with octant reduction: within 1e-7 radians of the exact value
/// (checked by a test), several times faster than the library call, which
/// dominated the near-field form factor.
#[inline]
fn atan2_nonnegative(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let ax = x.abs();
    let (small, large) = if y < ax { (y, ax) } else { (ax, y) };
    if large == 0.0 {
        return 0.0;
    }
    let a = small / large;
    let s = a * a;
    // atan(a) / a as a degree-7 polynomial in a², least-squares fitted
    // on Chebyshev nodes of [0, 1]: maximum error 9e-8 radians.
    const C: [f64; 8] = [
        9.999_999_582_162_316e-1,
        -3.333_230_282_580_835e-1,
        1.997_368_031_460_866e-1,
        -1.404_012_864_833_908e-1,
        9.967_885_269_468_284e-2,
        -6.021_844_773_254_042e-2,
        2.475_620_657_470_681e-2,
        -4.830_982_786_440_424e-3,
    ];
    let poly = C.iter().rev().fold(0.0, |acc, &c| acc * s + c);
    let mut r = a * poly;
    if y > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    r
}

#[cfg(test)]
mod tests {
    #[test]
    fn fast_atan2_is_accurate() {
        let mut worst = 0.0f64;
        for i in 0..=20_000 {
            let angle = std::f64::consts::PI * i as f64 / 20_000.0;
            for scale in [1e-6, 1.0, 3e5] {
                let (y, x) = (angle.sin().abs() * scale, angle.cos() * scale);
                worst = worst.max((super::atan2_nonnegative(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < 1e-7, "worst error {worst} rad");
        assert_eq!(super::atan2_nonnegative(0.0, 0.0), 0.0);
    }

    use super::*;

    /// `F` from a point to a coaxial facing disc of radius `R` at distance
    /// `h` is `R² / (h² + R²)`; the single-sample formula with the disc's
    /// area reproduces it exactly.
    #[test]
    fn single_sample_is_the_point_to_disc_form_factor() {
        for (radius, h) in [(1.0f64, 1.0f64), (0.1, 2.0), (3.0, 0.5)] {
            let samples = [ShooterSample::point(Vec3::ZERO, PI * radius * radius)];
            let (f, rays) = point_to_samples(
                Vec3::new(0.0, 0.0, h as f32),
                -Vec3::Z,
                Vec3::Z,
                &samples,
                true,
                |_, _| false,
            );
            let exact = radius * radius / (h * h + radius * radius);
            assert!((f - exact).abs() < 1e-6 * exact, "{f} vs {exact}");
            assert_eq!(rays, 1);
        }
    }

    #[test]
    fn back_facing_pairs_cast_no_rays() {
        let samples = [ShooterSample::point(Vec3::ZERO, 1.0)];
        // Receiver behind the shooter, and a receiver facing away.
        let (f, rays) = point_to_samples(
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::Z,
            Vec3::Z,
            &samples,
            true,
            |_, _| false,
        );
        assert_eq!((f, rays), (0.0, 0));
        let (f, rays) = point_to_samples(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::Z,
            Vec3::Z,
            &samples,
            true,
            |_, _| false,
        );
        assert_eq!((f, rays), (0.0, 0));
    }

    #[test]
    fn occluded_samples_contribute_nothing() {
        let samples = [ShooterSample::point(Vec3::ZERO, 1.0)];
        let (f, rays) = point_to_samples(
            Vec3::new(0.0, 0.0, 1.0),
            -Vec3::Z,
            Vec3::Z,
            &samples,
            true,
            |_, _| true,
        );
        assert_eq!((f, rays), (0.0, 1));
    }

    /// Exact point-to-square values: a unit square seen from a point one
    /// unit above its corner, normal facing it: `F = (1/2π)(2·(1/√2)·atan(1/√2))`...
    /// computed here as the quarter of the 2×2 square centred below the
    /// point, whose value is `(2/π)(x/√(1+x²)·atan(1/√(1+x²)) ·2)/4` with
    /// the standard formula `F = (2/π)[a/√(1+a²)·atan(b/√(1+a²)) + b/√(1+b²)·atan(a/√(1+b²))]/4·...`.
    #[test]
    fn point_to_polygon_matches_closed_forms() {
        // Point at height h above the centre of a coaxial square of half
        // side s: F = (2/π)·[2·a/√(1+a²)·atan(a/√(1+a²))] with a = s/h.
        for (s, h) in [(0.5f64, 1.0f64), (1.0, 0.3), (0.1, 2.0)] {
            let a = s / h;
            let q = a / (1.0 + a * a).sqrt();
            let exact = 2.0 / PI * 2.0 * q * (a / (1.0 + a * a).sqrt()).atan();
            let sq = [
                Vec3::new(-s as f32, -s as f32, 0.0),
                Vec3::new(s as f32, -s as f32, 0.0),
                Vec3::new(s as f32, s as f32, 0.0),
                Vec3::new(-s as f32, s as f32, 0.0),
            ];
            let f = point_to_polygon(Vec3::new(0.0, 0.0, h as f32), -Vec3::Z, &sq);
            assert!((f - exact).abs() < 1e-5, "{f} vs {exact}");
        }
        // A point on the edge of a perpendicular half-plane sees half of
        // its hemisphere's projected area filled: F → 0.5 for a huge square.
        let big = 1.0e3f32;
        let wall = [
            Vec3::new(0.0, -big, 0.0),
            Vec3::new(big, -big, 0.0),
            Vec3::new(big, big, 0.0),
            Vec3::new(0.0, big, 0.0),
        ];
        let f = point_to_polygon(Vec3::new(0.0, 0.0, 1e-3), Vec3::X, &wall);
        assert!((f - 0.5).abs() < 1e-3, "{f}");
        // Entirely behind the receiver: nothing.
        assert_eq!(
            point_to_polygon(Vec3::new(2e3, 0.0, 1.0), Vec3::X, &wall),
            0.0
        );
    }

    #[test]
    fn triangle_cells_cover_the_triangle_evenly() {
        let (a, b, c) = (
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        for m in 1..6 {
            let cells = triangle_cells(a, b, c, m);
            assert_eq!(cells.len() as u32, m * m);
            let total: f64 = cells.iter().map(|s| s.area).sum();
            assert!((total - 1.0).abs() < 1e-6);
            // The mean of the cell centroids is the triangle's centroid.
            let mean = cells.iter().map(|s| s.position).sum::<Vec3>() / cells.len() as f32;
            assert!(mean.distance((a + b + c) / 3.0) < 1e-5);
        }
    }
}

#[cfg(test)]
mod convex_samples {
    use super::*;
    use crate::scene::{MaterialId, SourcePos};

    fn disc(m: usize) -> Polygon {
        let rim = (0..m)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / m as f32;
                Vec3::new(a.cos(), 0.0, -a.sin())
            })
            .collect();
        Polygon::new(MaterialId(0), rim, SourcePos::default()).unwrap()
    }

    /// A polygon of more vertices than samples gets at most that many,
    /// covering its area, each inside it; one of few vertices keeps a fan
    /// cell per rim edge.
    #[test]
    fn a_disc_of_many_vertices_gets_at_most_the_samples_asked() {
        for (m, n) in [(1000, 64), (100_000, 64), (40, 64)] {
            let polygon = disc(m);
            let samples = grid_samples(&polygon, n);
            if m > n as usize {
                assert!(samples.len() <= n as usize, "{} samples", samples.len());
            } else {
                assert_eq!(samples.len(), m);
            }
            let area: f64 = samples.iter().map(|s| s.area).sum();
            assert!((area - polygon.area).abs() < 1e-4 * polygon.area);
            for s in &samples {
                assert!(s.position.length() < 1.0);
            }
        }
    }
}
