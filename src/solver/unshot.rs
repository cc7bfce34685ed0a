//! The unshot radiosity `Δb` of a progressive solve, kept per polygon or
//! per element vertex ([`UnshotScheme`]).
//!
//! The two schemes differ in where light waits between shooting steps and
//! so in four places: how much a polygon has left to shoot, what each of
//! its shooter samples carries, how received light is added, and what is
//! cleared after a polygon shoots. [`UnshotField`] holds the values with
//! what its scheme needs to answer those questions, so the solver asks
//! without knowing which scheme it runs.

use super::cell_integrals::cell_weights;
use super::formfactor::{SampleSet, ShooterSample};
use super::subcells::SubCells;
use super::UnshotScheme;
use crate::color::Rgb;
#[cfg(doc)]
use crate::mesh::covered::covered_vertices;
use crate::mesh::refine::Refiner;
use crate::mesh::{Mesh, PolygonMesh};
use crate::solver::tuning::MAX_SPEND_SCALE;
use rayon::prelude::*;

/// Unshot radiosity `Δb` (in the scene's emission units) and how it is laid
/// out over a mesh.
///
/// Invariant: [`UnshotField::fits`] the mesh it was made for, that is one
/// value per polygon ([`UnshotScheme::Polygon`]) or one per mesh vertex
/// ([`UnshotScheme::Vertex`]); [`super::Progressive::validate`] checks it
/// and that every value is finite. Values are negative where an
/// overshooting step ([`Shot`]) sent out more than was there; without
/// overshooting they stay `>= 0`.
#[derive(Clone, Debug)]
pub(crate) struct UnshotField {
    /// One value per polygon or per mesh vertex, by `layout`.
    values: Vec<Rgb>,
    /// The scheme, with what it needs beyond the values.
    layout: Layout,
}

/// What each scheme needs to read and write its values.
#[derive(Clone, Debug)]
enum Layout {
    /// One value per polygon.
    Polygon {
        /// Per vertex: its weight in its polygon's mean
        /// ([`Mesh::polygon_vertex_weights`]), with which received light
        /// is averaged into the polygon's value.
        mean_weight: Vec<f64>,
    },
    /// One value per element vertex.
    Vertex {
        /// Per vertex: the area it stands for ([`Mesh::vertex_areas`]), in
        /// square scene units, for polygon means.
        vertex_area: Vec<f64>,
        /// Per vertex: hidden under a coplanar polygon laid over its own
        /// ([`covered_vertices`]); its unshot radiosity stays 0. Empty
        /// when nothing is covered.
        covered: Vec<bool>,
        /// Per polygon and shooter sample: where its unshot radiosity is
        /// read from.
        sources: Vec<Vec<SampleSource>>,
        /// Per polygon and sub-cell of a split cell ([`SubCells::cells`]):
        /// where its unshot radiosity is read from.
        subcell_sources: Vec<Vec<SampleSource>>,
        /// Per polygon: the weights of the cells and sub-cells that read
        /// their integral ([`SampleSource::Region`]), cell after cell.
        regions: Vec<Vec<(u32, f32)>>,
    },
}

/// Where a shooter sample's unshot radiosity comes from in the per-vertex
/// scheme.
#[derive(Clone, Copy, Debug, PartialEq)]
enum SampleSource {
    /// The sample is this element vertex.
    Vertex(u32),
    /// Linear interpolation in an element triangle: its corners and
    /// barycentric weights (summing to 1).
    Triangle([u32; 3], [f32; 3]),
    /// The area-weighted mean over the polygon's vertices (the one-sample
    /// centre estimate).
    PolygonMean,
    /// The mean over the sample's cell of the field as the elements
    /// interpolate it: `Σ w·field / Σ w` over the polygon's region weights
    /// `[start, end)` ([`super::cell_integrals`]).
    Region(u32, u32),
}

/// What a step sends out of a shooter's unshot radiosity: the part of one
/// sign, raised by the light each point still expects (overshooting, Feda
/// and Purgathofer 1992).
///
/// A point that shoots now would shoot again for every bounce of light
/// that reaches it later. With overshooting it sends that light ahead: it
/// expects `over = min(gain · r, cap)` more, per channel, where `r` is
/// the light it has received so far, `b − e` (its radiosity less its
/// emission, at least 0; 0 on a polygon that reflects nothing). A point in a dark
/// corner thus sends ahead little. The positive part sends `max(Δb + over,
/// 0)`; the negative part sends `max(−(Δb + over), 0)` as negative light
/// (what it sent ahead beyond what it still expects). Either way what is
/// sent is `>= 0`, so every gather works on non-negative light and the
/// step's sign is applied once, to what it gathered; the point is left at
/// `Δb = −over` on every channel that sent anything, and that is filled as
/// the light arrives. Without overshooting `gain` and `cap` are 0 and a
/// step sends exactly the positive part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Shot {
    /// Send the negative part instead of the positive one.
    pub(crate) negative: bool,
    /// Light still expected per unit of light received so far, `>= 0`.
    pub(crate) gain: f64,
    /// The most light a point expects, per channel, `>= 0`, in the
    /// scene's emission units.
    pub(crate) cap: Rgb,
    /// The shooter's emission `e`: what a point has received so far is its
    /// radiosity less this.
    pub(crate) emission: Rgb,
}

impl Shot {
    /// The positive part with no overshoot: what a step without
    /// overshooting sends out.
    pub(crate) const PLAIN: Shot = Shot {
        negative: false,
        gain: 0.0,
        cap: Rgb::BLACK,
        emission: Rgb::BLACK,
    };

    /// The whole negative part.
    pub(crate) const NEGATIVE: Shot = Shot {
        negative: true,
        gain: 0.0,
        cap: Rgb::BLACK,
        emission: Rgb::BLACK,
    };

    /// The shot at a point that has received `received` so far.
    fn at(&self, received: Rgb) -> Part {
        Part {
            negative: self.negative,
            over: (received.max(Rgb::BLACK) * self.gain).min(self.cap),
        }
    }
}

/// [`Shot`] at one point: its sign and the light `over >= 0` the point
/// still expects, per channel, in the scene's emission units.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Part {
    negative: bool,
    over: Rgb,
}

impl Part {
    /// What a value `v` sends out, per channel, `>= 0`.
    fn sent(&self, v: Rgb) -> Rgb {
        if self.negative {
            (-(v + self.over)).max(Rgb::BLACK)
        } else {
            (v + self.over).max(Rgb::BLACK)
        }
    }

    /// `v` after sending [`Part::sent`] out: `v − sent` for the positive
    /// part, `v + sent` for the negative one; `−over` on every channel
    /// that sent anything.
    fn left(&self, v: Rgb) -> Rgb {
        if self.negative {
            v + self.sent(v)
        } else {
            v - self.sent(v)
        }
    }
}

impl UnshotField {
    /// The field at the start of a solve: every polygon's (or vertex's)
    /// `Δb = e`, its polygon's emission. `samples` are every polygon's
    /// shooter samples, chosen as `sets` (one per polygon) say.
    ///
    /// `covered` ([`covered_vertices`], empty when nothing is covered)
    /// marks the vertices hidden under a coplanar polygon laid over their
    /// own: they hold no unshot radiosity, and what they receive is not
    /// added to it, so light is not sent out twice from one place.
    /// `subcells` are every polygon's split cells ([`SubCells`]), read in the
    /// per-vertex scheme (a polygon's one value has no sub-cells to tell).
    pub(crate) fn new(
        scheme: UnshotScheme,
        mesh: &Mesh,
        emission: &[Rgb],
        samples: &[Vec<ShooterSample>],
        sets: &[SampleSet],
        subcells: &[SubCells],
        covered: Vec<bool>,
    ) -> Self {
        let is_covered = |l: usize| covered.get(l).copied().unwrap_or(false);
        match scheme {
            UnshotScheme::Polygon => {
                let mut mean_weight: Vec<f64> = mesh
                    .polygons
                    .iter()
                    .flat_map(|pm| mesh.polygon_vertex_weights(pm))
                    .collect();
                let mut values = emission.to_vec();
                if !covered.is_empty() {
                    // Not renormalised: the weights then sum to the open
                    // share of the polygon, and `value × area` is the
                    // power of its open part.
                    for (j, pm) in mesh.polygons.iter().enumerate() {
                        let range = pm.vertices.start as usize..pm.vertices.end as usize;
                        if !range.clone().any(is_covered) {
                            continue;
                        }
                        let mut open = 0.0;
                        for l in range {
                            if is_covered(l) {
                                mean_weight[l] = 0.0;
                            }
                            open += mean_weight[l];
                        }
                        values[j] *= open;
                    }
                }
                UnshotField {
                    values,
                    layout: Layout::Polygon { mean_weight },
                }
            }
            UnshotScheme::Vertex => {
                let (sources, (subcell_sources, regions)): (Vec<_>, (Vec<_>, Vec<_>)) = samples
                    .par_iter()
                    .zip(&mesh.polygons)
                    .zip(sets)
                    .zip(subcells)
                    .map(|(((s, pm), &set), subs)| polygon_sources(mesh, pm, s, set, subs))
                    .map(|(a, b, c)| (a, (b, c)))
                    .unzip();
                UnshotField {
                    values: mesh
                        .vertex_polygon
                        .iter()
                        .enumerate()
                        .map(|(l, p)| {
                            if is_covered(l) {
                                Rgb::BLACK
                            } else {
                                emission[p.index()]
                            }
                        })
                        .collect(),
                    layout: Layout::Vertex {
                        vertex_area: mesh.vertex_areas(),
                        covered,
                        sources,
                        subcell_sources,
                        regions,
                    },
                }
            }
        }
    }

    /// The values: one per polygon or one per mesh vertex, by the scheme.
    pub(crate) fn values(&self) -> &[Rgb] {
        &self.values
    }

    /// The number of values this field has on `mesh`.
    pub(crate) fn expected_len(&self, mesh: &Mesh) -> usize {
        match self.layout {
            Layout::Polygon { .. } => mesh.polygons.len(),
            Layout::Vertex { .. } => mesh.vertex_count(),
        }
    }

    /// True when the field has one value per unit of its scheme on `mesh`.
    pub(crate) fn fits(&self, mesh: &Mesh) -> bool {
        self.values.len() == self.expected_len(mesh)
    }

    /// What one value stands for ("polygon" or "vertex"), for messages.
    pub(crate) fn unit(&self) -> &'static str {
        match self.layout {
            Layout::Polygon { .. } => "polygon",
            Layout::Vertex { .. } => "vertex",
        }
    }

    /// Replaces the values; the caller has checked that there are
    /// [`UnshotField::expected_len`] of them, each finite.
    pub(crate) fn set_values(&mut self, values: Vec<Rgb>) {
        self.values = values;
        // A field carried over from a coarser mesh knows nothing of which
        // of this mesh's vertices are hidden.
        if let Layout::Vertex { covered, .. } = &self.layout {
            for (value, _) in self.values.iter_mut().zip(covered).filter(|x| *x.1) {
                *value = Rgb::BLACK;
            }
        }
    }

    /// Scales every value by `k` (in `[0, 1]`): what a step that shot
    /// `1 − k` of every polygon's unshot light at once leaves
    /// ([`crate::solver::step::tail`]).
    pub(crate) fn scale(&mut self, k: f64) {
        for v in &mut self.values {
            *v *= k;
        }
    }

    /// Area-weighted mean unshot radiosity of polygon `j`.
    pub(crate) fn mean(&self, mesh: &Mesh, j: usize) -> Rgb {
        match &self.layout {
            Layout::Polygon { .. } => self.values[j],
            Layout::Vertex { vertex_area, .. } => {
                polygon_mean(&mesh.polygons[j], vertex_area, |l| self.values[l])
            }
        }
    }

    /// The power polygon `j` sends out in a step that sends `shot`
    /// ([`Shot`]), per channel: `Σ sent(Δb) · area` over its vertices (its
    /// value times its area in the per-polygon scheme), `>= 0`, in radiosity
    /// × area units. `radiosity` is `b` per mesh vertex, from which the
    /// overshoot reads what each point has received. [`Shot::PLAIN`] gives
    /// the power of the positive part, `mean(Δb_j) · A_j` while nothing is
    /// negative.
    pub(crate) fn sent_power(&self, mesh: &Mesh, j: usize, shot: Shot, radiosity: &[Rgb]) -> Rgb {
        let pm = &mesh.polygons[j];
        match &self.layout {
            Layout::Polygon { mean_weight } => {
                let part = shot.at(polygon_received(pm, mean_weight, |l| {
                    radiosity[l] - shot.emission
                }));
                part.sent(self.values[j]) * pm.area
            }
            Layout::Vertex {
                vertex_area,
                covered,
                ..
            } => {
                let mut sum = Rgb::BLACK;
                for l in pm.vertices.clone() {
                    let l = l as usize;
                    if !covered.get(l).copied().unwrap_or(false) {
                        sum += shot.at(radiosity[l] - shot.emission).sent(self.values[l])
                            * vertex_area[l];
                    }
                }
                sum
            }
        }
    }

    /// The part of [`UnshotField::sent_power`] from points that have not
    /// settled: whose sent radiosity (channel mean) exceeds `tolerance`
    /// times their radiosity `b` (at least `floor`), in radiosity × area
    /// units.
    pub(crate) fn unsettled_power(
        &self,
        mesh: &Mesh,
        j: usize,
        shot: Shot,
        radiosity: &[Rgb],
        tolerance: f64,
        floor: f64,
    ) -> f64 {
        let pm = &mesh.polygons[j];
        match &self.layout {
            Layout::Polygon { mean_weight } => {
                let b = polygon_received(pm, mean_weight, |l| radiosity[l]);
                let part = shot.at(b - shot.emission);
                let sent = part.sent(self.values[j]).mean();
                if sent > tolerance * b.mean().max(floor) {
                    sent * pm.area
                } else {
                    0.0
                }
            }
            Layout::Vertex {
                vertex_area,
                covered,
                ..
            } => {
                let mut sum = 0.0;
                for l in pm.vertices.clone() {
                    let l = l as usize;
                    if covered.get(l).copied().unwrap_or(false) {
                        continue;
                    }
                    let sent = shot
                        .at(radiosity[l] - shot.emission)
                        .sent(self.values[l])
                        .mean();
                    if sent > tolerance * radiosity[l].mean().max(floor) {
                        sum += sent * vertex_area[l];
                    }
                }
                sum
            }
        }
    }

    /// Writes into `out` (cleared first) the radiosity each of shooter
    /// `i`'s `samples` samples sends in a step that sends `shot`
    /// ([`Shot`], `>= 0`; `radiosity` as for [`UnshotField::sent_power`]):
    /// read from the polygon's value, or (per-vertex scheme) from the field
    /// at the sample. A vertex hidden under a coplanar polygon sends
    /// nothing. `subcell_readings` (cleared first) gets the same for each sub-cell of the
    /// polygon's split cells ([`SubCells`]), in the per-vertex scheme.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn read_shooter(
        &self,
        mesh: &Mesh,
        i: usize,
        samples: usize,
        shot: Shot,
        radiosity: &[Rgb],
        out: &mut Vec<Rgb>,
        subcell_readings: &mut Vec<Rgb>,
    ) {
        out.clear();
        subcell_readings.clear();
        let pm = &mesh.polygons[i];
        match &self.layout {
            Layout::Polygon { mean_weight } => {
                let part = shot.at(polygon_received(pm, mean_weight, |l| {
                    radiosity[l] - shot.emission
                }));
                out.resize(samples, part.sent(self.values[i]));
            }
            Layout::Vertex {
                vertex_area,
                sources,
                subcell_sources,
                covered,
                regions,
            } => {
                let sent = |l: usize| {
                    if covered.get(l).copied().unwrap_or(false) {
                        Rgb::BLACK
                    } else {
                        shot.at(radiosity[l] - shot.emission).sent(self.values[l])
                    }
                };
                let mean = polygon_mean(pm, vertex_area, sent);
                read_at_samples(&sources[i], &regions[i], sent, mean, out);
                read_at_samples(
                    &subcell_sources[i],
                    &regions[i],
                    sent,
                    mean,
                    subcell_readings,
                );
            }
        }
    }

    /// Adds what polygon `j` received in a step, `delta` (per mesh vertex,
    /// read at `j`'s vertices), to its unshot radiosity.
    pub(crate) fn accumulate(&mut self, mesh: &Mesh, j: usize, delta: &[Rgb]) {
        let pm = &mesh.polygons[j];
        match &self.layout {
            Layout::Polygon { mean_weight } => {
                // Weighted as the polygon's mean is ([`Mesh::
                // polygon_vertex_weights`]): 1/n on a regular mesh, as
                // the original algorithm, area shares on a refined one.
                let mut gathered = Rgb::BLACK;
                for l in pm.vertices.clone() {
                    gathered += delta[l as usize] * mean_weight[l as usize];
                }
                self.values[j] += gathered;
            }
            Layout::Vertex { covered, .. } => {
                for l in pm.vertices.clone() {
                    if !covered.get(l as usize).copied().unwrap_or(false) {
                        self.values[l as usize] += delta[l as usize];
                    }
                }
            }
        }
    }

    /// Takes from shooter `i`'s unshot radiosity what a step sending `shot`
    /// sent out ([`Shot`]; `radiosity` as for [`UnshotField::sent_power`]):
    /// without overshoot, its positive part becomes 0.
    pub(crate) fn spend(&mut self, mesh: &Mesh, i: usize, shot: Shot, radiosity: &[Rgb]) {
        let pm = &mesh.polygons[i];
        match &self.layout {
            Layout::Polygon { mean_weight } => {
                let part = shot.at(polygon_received(pm, mean_weight, |l| {
                    radiosity[l] - shot.emission
                }));
                self.values[i] = part.left(self.values[i]);
            }
            Layout::Vertex { covered, .. } => {
                let range = pm.vertices.start as usize..pm.vertices.end as usize;
                for (l, (value, b)) in self.values[range.clone()]
                    .iter_mut()
                    .zip(&radiosity[range.clone()])
                    .enumerate()
                {
                    if !covered.get(range.start + l).copied().unwrap_or(false) {
                        *value = shot.at(*b - shot.emission).left(*value);
                    }
                }
            }
        }
    }

    /// The light polygon `j` has shot so far, per channel, in radiosity ×
    /// area units: `Σ (b − Δb) · area` over its vertices (`radiosity` is
    /// `b` per mesh vertex; hidden vertices never shoot), or `(mean b −
    /// Δb) · A` in the per-polygon scheme. At the start `b = Δb = e` and it
    /// is 0; a step adds what the shooter sent and leaves every receiver's
    /// unchanged.
    pub(crate) fn shot_so_far(&self, mesh: &Mesh, j: usize, radiosity: &[Rgb]) -> Rgb {
        let pm = &mesh.polygons[j];
        match &self.layout {
            Layout::Polygon { mean_weight } => {
                (polygon_received(pm, mean_weight, |l| radiosity[l]) - self.values[j]) * pm.area
            }
            Layout::Vertex {
                vertex_area,
                covered,
                ..
            } => {
                let mut sum = Rgb::BLACK;
                for l in pm.vertices.start as usize..pm.vertices.end as usize {
                    if !covered.get(l).copied().unwrap_or(false) {
                        sum += (radiosity[l] - self.values[l]) * vertex_area[l];
                    }
                }
                sum
            }
        }
    }

    /// The unshot field carried over to the mesh `refiner` returned last
    /// ([`Refiner::carry`]), so that every polygon keeps its unshot power;
    /// `None` for the per-polygon scheme, which does not continue a solve
    /// on a refined mesh.
    pub(crate) fn carried(&self, refiner: &Refiner) -> Option<Vec<Rgb>> {
        match self.layout {
            Layout::Polygon { .. } => None,
            Layout::Vertex { .. } => Some(refiner.carry(&self.values)),
        }
    }

    /// Per polygon, what each of its shooter samples has shot so far:
    /// `b − Δb` (clamped at zero per channel) read at the sample as
    /// shooting reads `Δb`, and the same for each sub-cell of its split cells
    /// ([`SubCells`]). `radiosity` is `b` per mesh vertex. `None` for the
    /// per-polygon scheme, which cannot tell where on a polygon the light
    /// it shot came from.
    #[allow(clippy::type_complexity)]
    pub(crate) fn shot_at_samples(
        &self,
        mesh: &Mesh,
        radiosity: &[Rgb],
    ) -> Option<Vec<(Vec<Rgb>, Vec<Rgb>)>> {
        let Layout::Vertex {
            vertex_area,
            sources,
            subcell_sources,
            covered,
            regions,
        } = &self.layout
        else {
            return None;
        };
        let shot_field: Vec<Rgb> = radiosity
            .iter()
            .zip(&self.values)
            .enumerate()
            .map(|(l, (b, u))| {
                // A hidden vertex shows light but never sent any out.
                if covered.get(l).copied().unwrap_or(false) {
                    return Rgb::BLACK;
                }
                Rgb::new(
                    (b.r - u.r).max(0.0),
                    (b.g - u.g).max(0.0),
                    (b.b - u.b).max(0.0),
                )
            })
            .collect();
        Some(
            mesh.polygons
                .iter()
                .zip(sources.iter().zip(subcell_sources).zip(regions))
                .map(|(pm, ((sources, subcell_sources), regions))| {
                    let (mut values, mut subcells) = (Vec::new(), Vec::new());
                    let field = |l: usize| shot_field[l];
                    let mean = polygon_mean(pm, vertex_area, field);
                    read_at_samples(sources, regions, field, mean, &mut values);
                    read_at_samples(subcell_sources, regions, field, mean, &mut subcells);
                    (values, subcells)
                })
                .collect(),
        )
    }
}

/// The light polygon `pm` has received so far in the per-polygon scheme:
/// `received` (per vertex) averaged with the weights its value is averaged
/// with, which leave hidden vertices out (so it is scaled by the open
/// share, as the value is).
fn polygon_received(pm: &PolygonMesh, mean_weight: &[f64], received: impl Fn(usize) -> Rgb) -> Rgb {
    let mut sum = Rgb::BLACK;
    for l in pm.vertices.clone() {
        sum += received(l as usize) * mean_weight[l as usize];
    }
    sum
}

/// Scales, per channel, the radiosity `values` that a shooter's `samples`
/// send (one each, in the samples' order) so that they send `spent`
/// altogether, `Σ value · area = spent`: the power the step takes from
/// the polygon's unshot radiosity ([`UnshotField::sent_power`]).
///
/// Read at the centres of cells much larger than the elements, the
/// values did not add up to it: in a hall whose tables stand on a regular
/// grid, every centre of the floor's 64 cells fell between the tables'
/// shadows, and a step of the floor sent up to 7 % more light than it
/// spent, which left the whole converged picture 3.7 % too bright (0.8 %
/// at 128 samples, whose cells fall elsewhere). Cells and sub-cells now read
/// their integrals ([`super::cell_integrals`]), which add up to it but
/// for what the hats' areas and the vertices' areas disagree on and
/// for the samples that still read a point (a cell the elements do not
/// reach, a sample without a cell): the factor stays near 1 and is kept
/// for those. It is the one step that is not linear in the unshot light,
/// so the nearer to 1, the less the converged answer depends on the order
/// of the steps. A channel whose reading
/// and whose target differ in sign, or by more than
/// [`MAX_SPEND_SCALE`], is left as read. Returns what was done, for the
/// sub-cells of split cells ([`Rescale::apply`]) to follow their cells.
pub(crate) fn send_what_is_spent(
    values: &mut [Rgb],
    samples: &[ShooterSample],
    spent: Rgb,
) -> Rescale {
    let mut read = Rgb::BLACK;
    for (value, sample) in values.iter().zip(samples) {
        read += *value * sample.area;
    }
    // A channel that no sample reads (the polygon's unshot light lies
    // between its cells' centres, where every reading is zero) is sent
    // evenly over the polygon, or the step would spend it and send
    // nothing: energy lost, and a cluster of such members shoots no cell.
    let total: f64 = samples.iter().map(|s| s.area).sum();
    let fill = per_channel(spent, read, |spent, read| {
        if read == 0.0 && spent > 0.0 && total > 0.0 {
            spent / total
        } else {
            0.0
        }
    });
    if !fill.is_black() {
        for value in values.iter_mut() {
            *value += fill;
        }
        read += fill * total;
    }
    let k = per_channel(spent, read, |spent, read| {
        let k = spent / read;
        if k.is_finite() && (1.0 / MAX_SPEND_SCALE..=MAX_SPEND_SCALE).contains(&k) {
            k
        } else {
            1.0
        }
    });
    let rescale = Rescale { fill, scale: k };
    if k != Rgb::splat(1.0) {
        for value in values {
            *value = Rgb::new(value.r * k.r, value.g * k.g, value.b * k.b);
        }
    }
    rescale
}

/// What [`send_what_is_spent`] did to a shooter's readings, per channel:
/// added `fill`, then multiplied by `scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rescale {
    fill: Rgb,
    scale: Rgb,
}

impl Rescale {
    /// Does the same to `values` (the sub-cells of the shooter's split cells,
    /// whose cells carry their mean, so cells and sub-cells still agree).
    pub(crate) fn apply(&self, values: &mut [Rgb]) {
        if self.fill.is_black() && self.scale == Rgb::splat(1.0) {
            return;
        }
        for v in values {
            let w = *v + self.fill;
            *v = Rgb::new(w.r * self.scale.r, w.g * self.scale.g, w.b * self.scale.b);
        }
    }
}

/// `f` of each channel of `a` and `b`.
fn per_channel(a: Rgb, b: Rgb, f: impl Fn(f64, f64) -> f64) -> Rgb {
    Rgb::new(f(a.r, b.r), f(a.g, b.g), f(a.b, b.b))
}

/// Area-weighted mean of a per-vertex `field` (read by vertex index) over
/// polygon `pm`, with `vertex_area` the area each vertex stands for.
fn polygon_mean(pm: &PolygonMesh, vertex_area: &[f64], field: impl Fn(usize) -> Rgb) -> Rgb {
    let mut sum = Rgb::BLACK;
    for l in pm.vertices.clone() {
        sum += field(l as usize) * vertex_area[l as usize];
    }
    if pm.area > 0.0 {
        sum / pm.area
    } else {
        Rgb::BLACK
    }
}

/// Appends to `out` the per-vertex `field` (read by vertex index) at each
/// of a polygon's samples, whose `sources` say where (interpolated within
/// the element triangle holding the sample, or integrated over its cell
/// with the polygon's `regions` weights); `mean` for samples that stand
/// for the whole polygon.
fn read_at_samples(
    sources: &[SampleSource],
    regions: &[(u32, f32)],
    field: impl Fn(usize) -> Rgb,
    mean: Rgb,
    out: &mut Vec<Rgb>,
) {
    for source in sources {
        let value = match *source {
            SampleSource::Vertex(l) => field(l as usize),
            SampleSource::Triangle(v, w) => {
                let mut sum = Rgb::BLACK;
                for (l, weight) in v.iter().zip(w) {
                    sum += field(*l as usize) * f64::from(weight.max(0.0));
                }
                sum / f64::from(
                    w.iter()
                        .map(|x| x.max(0.0))
                        .sum::<f32>()
                        .max(f32::MIN_POSITIVE),
                )
            }
            SampleSource::PolygonMean => mean,
            SampleSource::Region(start, end) => {
                let (mut sum, mut area) = (Rgb::BLACK, 0.0);
                for &(l, w) in &regions[start as usize..end as usize] {
                    sum += field(l as usize) * f64::from(w);
                    area += f64::from(w);
                }
                // A cell whose weights are all zero (no element overlaps
                // it) has no integral of its own: it reads the polygon's
                // mean, as a one-sample polygon does, not `0 / 0`.
                if area > 0.0 {
                    sum / area
                } else {
                    mean
                }
            }
        };
        out.push(value);
    }
}

/// Where polygon `pm`'s shooter `samples` (chosen as `set` says) and the
/// sub-cells of its split cells (`subs`) read their unshot radiosity, and the
/// weights of those that read their cell's integral: every cell of a
/// grid ([`SampleSet::AtMost`]) and every sub-cell
/// ([`super::cell_integrals`]). A sample without a cell, a sky facet's
/// jittered one, and a cell the elements do not reach read the field at
/// their point.
fn polygon_sources(
    mesh: &Mesh,
    pm: &PolygonMesh,
    samples: &[ShooterSample],
    set: SampleSet,
    subs: &SubCells,
) -> (Vec<SampleSource>, Vec<SampleSource>, Vec<(u32, f32)>) {
    let mut regions = Vec::new();
    let sources = if matches!(set, SampleSet::AtMost(_)) {
        let cells: Vec<_> = samples.iter().map(|s| (s.position, s.cell)).collect();
        cell_sources(mesh, pm, &cells, &mut regions)
    } else {
        sample_sources(mesh, pm, samples, set)
    };
    let subcells: Vec<_> = subs.all().map(|c| (c.position, Some(c.corners))).collect();
    let subcell_sources = cell_sources(mesh, pm, &subcells, &mut regions);
    (sources, subcell_sources, regions)
}

/// Where each of `cells` (a point of polygon `pm` and the cell it stands
/// for, if any) reads its unshot radiosity: its cell's integral, whose
/// weights are appended to `regions`, or, without a cell or where the
/// elements do not reach it, the field at its point (a search of every
/// element, so done only for those).
fn cell_sources(
    mesh: &Mesh,
    pm: &PolygonMesh,
    cells: &[(glam::Vec3, Option<[glam::Vec3; 4]>)],
    regions: &mut Vec<(u32, f32)>,
) -> Vec<SampleSource> {
    let with_cell: Vec<usize> = (0..cells.len()).filter(|&k| cells[k].1.is_some()).collect();
    let corners: Vec<[glam::Vec3; 4]> = with_cell.iter().filter_map(|&k| cells[k].1).collect();
    let mut sources: Vec<Option<SampleSource>> = vec![None; cells.len()];
    for (&k, weights) in with_cell.iter().zip(cell_weights(mesh, pm, &corners)) {
        let area: f64 = weights.iter().map(|&(_, w)| f64::from(w)).sum();
        if area > 0.0 {
            let start = regions.len() as u32;
            regions.extend(weights);
            sources[k] = Some(SampleSource::Region(start, regions.len() as u32));
        }
    }
    // The cells without a region read the field at their point.
    let bare: Vec<usize> = (0..cells.len()).filter(|&k| sources[k].is_none()).collect();
    let read = point_sources(mesh, pm, bare.iter().map(|&k| cells[k].0));
    for (k, source) in bare.into_iter().zip(read) {
        sources[k] = Some(source);
    }
    sources.into_iter().flatten().collect()
}

/// Where a polygon's shooter samples read their unshot radiosity.
fn sample_sources(
    mesh: &Mesh,
    pm: &PolygonMesh,
    samples: &[ShooterSample],
    set: SampleSet,
) -> Vec<SampleSource> {
    match set {
        SampleSet::Centre => return vec![SampleSource::PolygonMean; samples.len()],
        SampleSet::Vertices => return pm.vertices.clone().map(SampleSource::Vertex).collect(),
        SampleSet::AtMost(_) | SampleSet::Sky(_) => {}
    }
    point_sources(mesh, pm, samples.iter().map(|s| s.position))
}

/// Where the unshot radiosity at each of `points` (on polygon `pm`) is
/// read from ([`point_source`]). Many points on a polygon of many elements
/// are located through a grid of the element triangles, which gives the
/// same triangles as the search of every element, in time linear in the
/// points and triangles rather than their product (a convex face of
/// 100,000 vertices has millions of element triangles).
fn point_sources(
    mesh: &Mesh,
    pm: &PolygonMesh,
    points: impl ExactSizeIterator<Item = glam::Vec3>,
) -> Vec<SampleSource> {
    let triangles: u64 = 2 * u64::from(pm.elements.end - pm.elements.start);
    if (points.len() as u64) * triangles < LOCATOR_MIN_WORK {
        return points.map(|p| point_source(mesh, pm, p)).collect();
    }
    let locator = Locator::new(mesh, pm);
    points.map(|p| locator.source(mesh, pm, p)).collect()
}

/// Points times element triangles below which [`point_sources`] searches
/// every element for each point rather than build a [`Locator`].
const LOCATOR_MIN_WORK: u64 = 1 << 14;

/// Where the unshot radiosity at point `p` (on polygon `pm`) is read
/// from: the element triangle holding it, the one whose smallest
/// barycentric weight is largest (>= 0 inside), the first in element order
/// among equals.
fn point_source(mesh: &Mesh, pm: &PolygonMesh, p: glam::Vec3) -> SampleSource {
    let mut best = (f32::NEG_INFINITY, SampleSource::PolygonMean);
    for e in pm.elements.clone() {
        for tri in mesh.elements[e as usize].triangles() {
            let [a, b, c] = tri.map(|v| mesh.positions[v.index()]);
            let w = barycentric(p, a, b, c);
            let least = w[0].min(w[1]).min(w[2]);
            if least > best.0 {
                best = (least, SampleSource::Triangle(tri.map(|v| v.0), w));
            }
        }
    }
    best.1
}

/// A polygon's element triangles binned by their bounds in its plane, to
/// find the triangles that may hold a point without looking at the rest.
#[derive(Debug)]
struct Locator {
    /// Every element triangle of the polygon, in element order.
    triangles: Vec<[crate::mesh::VertexId; 3]>,
    /// Triangles whose weights are all zero whatever the point
    /// ([`barycentric`] of a degenerate triangle): candidates everywhere.
    degenerate: Vec<u32>,
    /// In-plane axes.
    u: glam::Vec3,
    v: glam::Vec3,
    lo: glam::Vec2,
    size: glam::Vec2,
    n: usize,
    /// Per bucket, the triangles whose (slightly grown) bounds meet it, in
    /// ascending order.
    buckets: Vec<Vec<u32>>,
}

impl Locator {
    fn new(mesh: &Mesh, pm: &PolygonMesh) -> Locator {
        let triangles: Vec<[crate::mesh::VertexId; 3]> = pm
            .elements
            .clone()
            .flat_map(|e| mesh.elements[e as usize].triangles())
            .collect();
        let (u, v) = pm.normal.normalize().any_orthonormal_pair();
        let flat = |p: glam::Vec3| glam::Vec2::new(p.dot(u), p.dot(v));
        let boxes: Vec<(glam::Vec2, glam::Vec2)> = triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| flat(mesh.positions[i.index()]));
                (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
            })
            .collect();
        let (lo, hi) = boxes.iter().fold(
            (glam::Vec2::INFINITY, glam::Vec2::NEG_INFINITY),
            |(lo, hi), &(a, b)| (lo.min(a), hi.max(b)),
        );
        // Grown by far more than f32 rounding of the projection, so a
        // point on a triangle's edge finds it.
        let grow = glam::Vec2::splat(1e-4 * (hi - lo).max_element().max(f32::MIN_POSITIVE));
        let n = ((triangles.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let size = ((hi - lo + 2.0 * grow) / n as f32).max(glam::Vec2::splat(f32::MIN_POSITIVE));
        let lo = lo - grow;
        let mut locator = Locator {
            degenerate: Vec::new(),
            u,
            v,
            lo,
            size,
            n,
            buckets: vec![Vec::new(); n * n],
            triangles: Vec::new(),
        };
        for (k, (t, &(a, b))) in triangles.iter().zip(&boxes).enumerate() {
            let [pa, pb, pc] = t.map(|i| mesh.positions[i.index()]);
            if barycentric(pa, pa, pb, pc) == [0.0; 3] {
                locator.degenerate.push(k as u32);
                continue;
            }
            let ((x0, y0), (x1, y1)) = (locator.bucket(a - grow), locator.bucket(b + grow));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    locator.buckets[y * n + x].push(k as u32);
                }
            }
        }
        locator.triangles = triangles;
        locator
    }

    /// The bucket holding in-plane point `p`, clamped to the grid.
    fn bucket(&self, p: glam::Vec2) -> (usize, usize) {
        let at = (p - self.lo) / self.size;
        let clamp = |x: f32| (x.max(0.0) as usize).min(self.n - 1);
        (clamp(at.x), clamp(at.y))
    }

    /// [`point_source`] of `p`: the candidates of its bucket and the
    /// degenerate triangles hold every triangle that contains `p`, so when
    /// one does, the best of them (largest smallest weight, then first in
    /// element order) is the best of all; otherwise every triangle is
    /// searched.
    fn source(&self, mesh: &Mesh, pm: &PolygonMesh, p: glam::Vec3) -> SampleSource {
        match self.best(mesh, p) {
            Some((least, k, w)) if least >= 0.0 => {
                SampleSource::Triangle(self.triangles[k as usize].map(|v| v.0), w)
            }
            _ => point_source(mesh, pm, p),
        }
    }

    /// The candidate triangle nearest to holding `p`: its smallest
    /// barycentric weight (negative when `p` lies outside it), its index
    /// and the weights; `None` when the bucket and the degenerate list
    /// are empty.
    fn best(&self, mesh: &Mesh, p: glam::Vec3) -> Option<(f32, u32, [f32; 3])> {
        let (x, y) = self.bucket(glam::Vec2::new(p.dot(self.u), p.dot(self.v)));
        let mut best: Option<(f32, u32, [f32; 3])> = None;
        for &k in self.buckets[y * self.n + x].iter().chain(&self.degenerate) {
            let [a, b, c] = self.triangles[k as usize].map(|v| mesh.positions[v.index()]);
            let w = barycentric(p, a, b, c);
            let least = w[0].min(w[1]).min(w[2]);
            let better = match best {
                None => true,
                Some((l, i, _)) => least > l || (least == l && k < i),
            };
            if better {
                best = Some((least, k, w));
            }
        }
        best
    }
}

/// A polygon's element triangles binned in its plane, to find the one
/// holding a point: where a particle of the tail lands
/// ([`crate::solver::step::tail`]).
#[derive(Debug)]
pub(crate) struct TriangleLocator(Locator);

impl TriangleLocator {
    /// The locator of polygon mesh `pm` of `mesh`.
    pub(crate) fn new(mesh: &Mesh, pm: &PolygonMesh) -> TriangleLocator {
        TriangleLocator(Locator::new(mesh, pm))
    }

    /// The element triangle of `pm` holding `p` (or nearest to holding it,
    /// when rounding puts `p` a hair outside them all): its corners and
    /// `p`'s barycentric weights there (a weight may be a hair below
    /// zero); `None` for a polygon without triangles.
    ///
    /// A point of the polygon always lands: a particle that found no
    /// triangle holding it within rounding (a sliver's, whose weights
    /// `f32` once could not resolve) was dropped, and its light lost.
    pub(crate) fn find(
        &self,
        mesh: &Mesh,
        pm: &PolygonMesh,
        p: glam::Vec3,
    ) -> Option<([u32; 3], [f32; 3])> {
        match self.0.best(mesh, p) {
            Some((_, k, w)) => Some((self.0.triangles[k as usize].map(|v| v.0), w)),
            // No candidate in the bucket: every triangle is searched.
            None => match point_source(mesh, pm, p) {
                SampleSource::Triangle(t, w) => Some((t, w)),
                _ => None,
            },
        }
    }
}

/// Barycentric weights of `p` (projected into the triangle's plane) in
/// the triangle `a b c`; zeros for a degenerate triangle. Computed in
/// `f64`: in `f32` the determinant of a sliver a thousandth as wide as
/// long cancels to noise, and points far outside it came out inside.
fn barycentric(p: glam::Vec3, a: glam::Vec3, b: glam::Vec3, c: glam::Vec3) -> [f32; 3] {
    let (p, a, b, c) = (p.as_dvec3(), a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    let (e1, e2, d) = (b - a, c - a, p - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (dp1, dp2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 0.0 {
        return [0.0; 3];
    }
    let v = (d22 * dp1 - d12 * dp2) / det;
    let w = (d11 * dp2 - d12 * dp1) / det;
    [(1.0 - v - w) as f32, v as f32, w as f32]
}

#[cfg(test)]
mod tests {
    use super::Shot;
    use crate::color::Rgb;

    /// The grid of a polygon's element triangles finds, for points inside,
    /// on element edges and vertices, and outside, the same triangle and
    /// weights as the search of every element.
    #[test]
    fn the_locator_finds_what_the_search_of_every_element_finds() {
        use super::{point_source, Locator, SampleSource};
        use crate::testutil::{grey, polygon, regular_mesh, scene, Xorshift};
        // A 40-gon, meshed as a rim and lattice: elements of many shapes.
        let disc: Vec<[f32; 3]> = (0..40)
            .map(|k| {
                let a = -std::f32::consts::TAU * k as f32 / 40.0;
                [a.cos(), 0.0, a.sin()]
            })
            .collect();
        let s = scene(vec![polygon(0, &disc)], vec![grey("floor", 0.0, 0.5)]);
        let mesh = regular_mesh(&s, 0.2);
        let pm = &mesh.polygons[0];
        let locator = Locator::new(&mesh, pm);
        let mut rng = Xorshift(7);
        let mut points: Vec<glam::Vec3> = mesh.positions.clone();
        points.extend(mesh.sample_positions.iter().copied());
        for _ in 0..2000 {
            let (x, z) = (2.4 * rng.unit_f32() - 1.2, 2.4 * rng.unit_f32() - 1.2);
            points.push(glam::Vec3::new(x, 1e-4 * (rng.unit_f32() - 0.5), z));
        }
        let mut inside = 0;
        let total = points.len();
        for p in points {
            let found = point_source(&mesh, pm, p);
            inside += matches!(found, SampleSource::Triangle(_, w) if w.iter().all(|&x| x >= 0.0))
                as usize;
            assert_eq!(locator.source(&mesh, pm, p), found, "at {p}");
        }
        // Most points are inside the disc, so the grid answered them.
        assert!(2 * inside > total, "{inside} of {total} points inside");
    }

    /// A shot sends, per channel, its sign's part beyond what the point
    /// still expects (`gain` times what it has received, at most `cap`),
    /// and leaves it at minus that where it sent.
    #[test]
    fn a_shot_leaves_the_light_still_expected() {
        let received = Rgb::new(1.0, 1.0, -3.0);
        let v = Rgb::new(2.0, -0.25, -1.0);
        let cap = Rgb::new(1.0, 0.25, 1.0);
        let up = Shot {
            negative: false,
            gain: 0.5,
            cap,
            emission: Rgb::BLACK,
        }
        .at(received);
        // Green is capped; a negative "received" (rounding) expects nothing.
        assert_eq!(up.over, Rgb::new(0.5, 0.25, 0.0));
        assert_eq!(up.sent(v), Rgb::new(2.5, 0.0, 0.0));
        assert_eq!(up.left(v), Rgb::new(-0.5, -0.25, -1.0));
        let down = Shot {
            negative: true,
            gain: 0.5,
            cap,
            emission: Rgb::BLACK,
        }
        .at(received);
        assert_eq!(down.sent(v), Rgb::new(0.0, 0.0, 1.0));
        assert_eq!(down.left(v), Rgb::new(2.0, -0.25, 0.0));
        // Without overshoot: the positive part all sent, the rest kept.
        assert_eq!(Shot::PLAIN.at(received).left(v), Rgb::new(0.0, -0.25, -1.0));
        assert_eq!(
            Shot::NEGATIVE.at(received).sent(v),
            Rgb::new(0.0, 0.25, 1.0)
        );
    }

    /// Readings are scaled per channel to send what the step spends; a
    /// channel every sample reads as zero is sent evenly (none of it
    /// lost); a sign change or a scale beyond the limit is left as read.
    #[test]
    fn samples_send_what_is_spent_even_when_none_reads_it() {
        use crate::solver::formfactor::ShooterSample;
        let samples = [
            ShooterSample::point(glam::Vec3::ZERO, 1.0),
            ShooterSample::point(glam::Vec3::X, 3.0),
        ];
        let sent = |values: &[Rgb]| {
            values
                .iter()
                .zip(&samples)
                .fold(Rgb::BLACK, |sum, (v, s)| sum + *v * s.area)
        };
        // Red read 2 + 3 = 5 for 6 spent: scaled by 1.2. Green read
        // nothing for 8 spent: 2 on each (8 over an area of 4). Blue read
        // 4 for 40 spent: beyond the limit, left as read.
        let mut values = vec![Rgb::new(2.0, 0.0, 1.0), Rgb::new(1.0, 0.0, 1.0)];
        super::send_what_is_spent(&mut values, &samples, Rgb::new(6.0, 8.0, 40.0));
        let total = sent(&values);
        assert!((total.r - 6.0).abs() < 1e-12, "{total:?}");
        assert!((total.g - 8.0).abs() < 1e-12, "{total:?}");
        assert_eq!(values[0].g, values[1].g);
        assert_eq!(total.b, 4.0);
        // Nothing spent, nothing read: nothing sent.
        let mut dark = vec![Rgb::BLACK; 2];
        super::send_what_is_spent(&mut dark, &samples, Rgb::BLACK);
        assert_eq!(dark, vec![Rgb::BLACK; 2]);
    }

    #[test]
    fn a_slivers_weights_tell_inside_from_outside() {
        // A triangle ten units long and a thousandth wide, ten units from
        // the origin, as a real export's slivers are.
        let (a, b, c) = (
            glam::Vec3::new(10.0, 0.0, 10.0),
            glam::Vec3::new(20.0, 0.0, 10.0),
            glam::Vec3::new(20.0, 0.0, 10.001),
        );
        let inside = a * 0.3 + b * 0.3 + c * 0.4;
        let w = super::barycentric(inside, a, b, c);
        assert!(
            (w[0] - 0.3).abs() < 1e-3 && (w[1] - 0.3).abs() < 1e-3 && (w[2] - 0.4).abs() < 1e-3,
            "{w:?}"
        );
        // Points a few widths off its long edges, along its whole length.
        for k in 1..10 {
            let along = a.lerp(b, k as f32 / 10.0);
            for off in [-0.003f32, 0.003 + 0.001 * k as f32 / 10.0] {
                let p = along + glam::Vec3::new(0.0, 0.0, off);
                let w = super::barycentric(p, a, b, c);
                assert!(w[0].min(w[1]).min(w[2]) < 0.0, "{p} came out inside: {w:?}");
            }
        }
    }

    #[test]
    fn barycentric_weights_reproduce_the_point() {
        let (a, b, c) = (
            glam::Vec3::ZERO,
            glam::Vec3::new(2.0, 0.0, 0.0),
            glam::Vec3::new(0.0, 1.0, 1.0),
        );
        let p = a * 0.2 + b * 0.5 + c * 0.3;
        let w = super::barycentric(p, a, b, c);
        assert!(
            (w[0] - 0.2).abs() < 1e-6 && (w[1] - 0.5).abs() < 1e-6 && (w[2] - 0.3).abs() < 1e-6,
            "{w:?}"
        );
        assert_eq!(super::barycentric(p, a, a, a), [0.0; 3]);
    }
}
