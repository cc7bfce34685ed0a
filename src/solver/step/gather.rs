//! Phase 4 of a step: the gather of a polygon shooting alone, and the
//! two passes every gather runs.
//!
//! Every receiving vertex sums `ρ_j · Σ_k Δb_k · F(l → sample k)`, in
//! parallel, each vertex independent of the others. Heuristics acting
//! here:
//! - **receiver interpolation** (with clusters, reflected light only):
//!   a grid's vertices between coarse rows and columns interpolated when
//!   a check vertex shows it holds, never in crowded cells nor near the
//!   shooter ([`crate::solver::accel::receivers`], `Interpolating`);
//! - **shadow-ray choice**: no ray in an empty shaft, a short candidate
//!   list tested one by one, else the BVH ([`ShadowQuery`],
//!   [`crate::solver::tuning::LINEAR_CANDIDATES`]);
//! - **shared facet rays** ([`crate::solver::accel::facets`]);
//! - **sky probes** and **far shooters**: a few rays first, their answer
//!   for all when they agree ([`crate::solver::accel::probes`],
//!   [`crate::solver::accel::far_shooters`]);
//! - **sub-cells**: a split cell near the receiver sends as its sub-cells
//!   ([`crate::solver::accel::subcells`]);
//! - the **near field** of the form factor
//!   ([`crate::solver::Approximations::near_field`]).

use super::{How, Underway};
use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::PolygonId;
use crate::solver::accel::cluster::Clusters;
use crate::solver::accel::facets::Facets;
use crate::solver::accel::facets::Scratch;
use crate::solver::accel::probes::{self, Probed};
use crate::solver::accel::receivers::CoarseGrid;
use crate::solver::accel::{receivers, shared, subcells};
use crate::solver::kernel::distribution;
use crate::solver::tuning::{
    LINEAR_CANDIDATES, PARALLEL_CHARGES, PAR_RUN, REFINE_MAX, SHOOTER_GROUP,
};
use crate::solver::Progressive;
use crate::visibility::{LastBlocker, ShadowQuery, Visibility};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

impl<'a> Progressive<'a> {
    /// Phase 4 for `vertices` in `stage`, by the step's kind.
    pub(in crate::solver) fn gather_chunk(
        &mut self,
        u: &Underway,
        vertices: Range<usize>,
        stage: Stage,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        match u.how {
            How::Alone => self.gather(u.shooter, vertices, stage, cancel),
            How::Cluster { from_top } => {
                self.gather_cluster(u.cluster, from_top, vertices, stage, cancel)
            }
        }
    }

    /// Phase 4, gather: every receiving vertex's `Δrad = ρ_j · Σ_k Δb_k ·
    /// F(l → sample k)` into `self.delta` (black for the others), in
    /// parallel; with clusters, a non-emitter's shot interpolates where
    /// [`gather_passes`] allows. Each vertex's value depends only on its
    /// own sum and the first pass, so the bits do not depend on the thread
    /// count. Returns `None` once `cancel` is set, with the solution
    /// untouched (only scratch written).
    pub(in crate::solver) fn gather(
        &mut self,
        shooter: PolygonId,
        vertices: Range<usize>,
        stage: Stage,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        let groups = self.shooter_groups(shooter.index());
        self.gather_with(groups, |p, g, sums| {
            let i = shooter.index();
            let (mesh, visibility, facets) = (g.mesh, g.visibility, g.facets);
            let samples = &p.samples[i];
            let shooter_normal = mesh.polygons[i].normal;
            let near_field = g.near_field;
            let shot = &p.shot;
            let directional = p.directional[i].as_ref();
            let split = subcells::Split::of_polygon(&p.subcells[i], &p.subcell_readings);
            // The exact `Δrad` at receiving vertex `l` of polygon `j`, with
            // the pairs and rays it took.
            let sky_probes = p.probes[i].as_ref();
            let far_shooter = p.far_shooters[i].as_ref();
            let exact = |l: usize, j: PolygonId, scratch: &mut Scratch| -> (Rgb, u64, u64) {
                let x = mesh.sample_positions[l];
                let tile = g.tile(l);
                let mut rays = 0u64;
                let memo = &mut scratch.memo;
                let nx = mesh.polygons[j.index()].normal;
                let mut last = LastBlocker::default();
                // Whether sample `k` at `s` is hidden from this vertex.
                let mut ray = |k: usize, s: glam::Vec3| -> bool {
                    // A ray from elsewhere than the sample (the part of a
                    // near cell in front of the vertex) is the vertex's own
                    // and outside the shafts, which were built from the
                    // samples.
                    if s != samples[k].position {
                        rays += 1;
                        return visibility.occluded_remembering(s, x, (shooter, j), &mut last);
                    }
                    // A small facet's vertices share one ray per sample.
                    if let Some((hit, cast)) = facets.shared_ray(
                        memo,
                        visibility,
                        (shooter, j),
                        k as u32,
                        s,
                        samples[k].exact_r2,
                    ) {
                        rays += cast;
                        return hit;
                    }
                    // The thin shaft's polygons, when the receiver has a
                    // complete list of them.
                    let blockers = g.culled(j).then(|| g.thin_shaft(tile, k / SHOOTER_GROUP));
                    let query = ShadowQuery::choose(blockers, LINEAR_CANDIDATES);
                    rays += query.rays();
                    visibility.shadow_remembering(query, s, x, (shooter, j), &mut last)
                };
                // A sky facet's probes, when they agree, stand for all its
                // directions; so do a far shooter's for all its samples.
                let far_probes = far_shooter.and_then(|f| f.probes_from(x));
                let probed = match (sky_probes, far_probes) {
                    (None, None) => Probed::Unknown,
                    (None, Some(far)) => match probes::verdict(far, samples, x, nx, &mut ray) {
                        Some(blocked) => Probed::Whole(blocked),
                        None => Probed::Unknown,
                    },
                    (Some(sky), _) => sky.ask(samples, x, nx, &mut ray),
                };
                // Wholly hidden: nothing arrives, whatever the cosines (the
                // sum below would add nothing), and no pair is counted.
                if probed == Probed::Whole(true) {
                    return (Rgb::BLACK, 0, rays);
                }
                let (f, pairs) = distribution::shot_point_to_samples(
                    directional,
                    x,
                    nx,
                    shooter_normal,
                    samples,
                    |k| shot[k],
                    split.as_ref(),
                    near_field,
                    |k, s| {
                        let seen = match (sky_probes, probed) {
                            (_, Probed::Unknown) => None,
                            (Some(sky), probed) => sky.seen(probed, k),
                            (None, Probed::Whole(blocked)) => Some(blocked),
                            (None, Probed::Regions { .. }) => None,
                        };
                        seen.unwrap_or_else(|| ray(k, s))
                    },
                );
                (g.reflectance[j.index()] * f, pairs, rays)
            };
            // Reflected light may be interpolated across receiving grids;
            // an emitter's shot, which draws the sharpest shadows, never is.
            let on = p.clustered
                && p.options.approximations.receiver_interpolation
                && p.emission[i].is_black();
            let cells = p.interpolating(on, p.clusters.of(shooter));
            gather_passes(sums, mesh, &cells, cancel, exact, Work { vertices, stage })
        })
    }

    /// Runs a gather `f` with its [`GatherContext`] (the shooter's points
    /// culled in `groups` groups) and the buffers it writes ([`Sums`]),
    /// which are taken out of the solver for the call, so that the
    /// context and `f` may read all the rest of it, and put back after.
    pub(in crate::solver) fn gather_with<F>(&mut self, groups: usize, f: F) -> Option<Gathered>
    where
        F: FnOnce(&Self, &GatherContext, Sums) -> Option<Gathered>,
    {
        let mut delta = std::mem::take(&mut self.delta);
        let mut first = std::mem::take(&mut self.coarse_delta);
        let mut spent = std::mem::take(&mut self.spent);
        let sums = Sums {
            delta: &mut delta,
            first: &mut first,
            spent: &mut spent,
        };
        let gathered = f(self, &GatherContext::new(self, groups), sums);
        self.delta = delta;
        self.coarse_delta = first;
        self.spent = spent;
        gathered
    }

    /// The receiving grids' interpolation of a step shot by `cluster`
    /// ([`Interpolating`]), `on` unless the step evaluates every vertex
    /// exactly.
    pub(in crate::solver) fn interpolating(&self, on: bool, cluster: usize) -> Interpolating<'_> {
        Interpolating {
            on,
            coarse: &self.coarse,
            crowded: &self.crowded,
            clusters: &self.clusters,
            receives: &self.receives,
            cluster,
            shooter: self.clusters.bounds(cluster),
            positions: &self.mesh.positions,
            held: &self.radiosity,
            leaders: &self.leaders,
        }
    }
}

/// What both gathers (a polygon's, a cluster's) read of the step: the
/// solver's inputs, the receivers and their shadow-ray candidates.
pub(in crate::solver) struct GatherContext<'g> {
    /// The mesh whose vertices receive.
    pub(in crate::solver) mesh: &'g Mesh,
    pub(in crate::solver) visibility: &'g Visibility,
    /// The small facets whose vertices share their shadow rays.
    pub(in crate::solver) facets: &'g Facets,
    /// Per polygon: front reflectance.
    pub(in crate::solver) reflectance: &'g [Rgb],
    /// [`crate::solver::Approximations::near_field`].
    pub(in crate::solver) near_field: bool,
    /// [`crate::solver::Approximations::shaft_culling`].
    culling: bool,
    /// Per polygon: too small for a shaft of its own.
    small: &'g [bool],
    /// Per polygon: the polygons in its shaft to the shooter.
    candidates: &'g [Vec<u32>],
    /// Per tile and shooter group: the polygons in the thin shaft between
    /// them.
    tile_candidates: &'g [Vec<u32>],
    /// Per vertex: its tile.
    tile_of: &'g [u32],
    /// Shooter groups per tile in `tile_candidates`.
    groups: usize,
}

impl<'g> GatherContext<'g> {
    /// The context of a gather by `p` whose shooter points were culled in
    /// `groups` groups.
    fn new(p: &'g Progressive, groups: usize) -> Self {
        GatherContext {
            mesh: &p.mesh,
            visibility: p.visibility,
            facets: &p.facets,
            reflectance: &p.reflectance,
            near_field: p.options.approximations.near_field,
            culling: p.options.approximations.shaft_culling,
            small: &p.small,
            candidates: &p.candidates,
            tile_candidates: &p.tile_candidates,
            tile_of: &p.tile_of,
            groups,
        }
    }

    /// Whether receiver `j`'s rays are culled by its shafts: with shaft
    /// culling, unless it is small or its shaft held too many polygons
    /// to list ([`REFINE_MAX`]).
    pub(in crate::solver) fn culled(&self, j: PolygonId) -> bool {
        self.culling && !self.small[j.index()] && self.candidates[j.index()].len() <= REFINE_MAX
    }

    /// The polygons in receiver `j`'s shaft to the shooter.
    pub(in crate::solver) fn shaft(&self, j: PolygonId) -> &'g [u32] {
        &self.candidates[j.index()]
    }

    /// Where vertex `l`'s tile's thin shafts start ([`GatherContext::thin_shaft`]).
    pub(in crate::solver) fn tile(&self, l: usize) -> usize {
        self.tile_of[l] as usize * self.groups
    }

    /// The polygons in the thin shaft between the tile starting at `tile`
    /// ([`GatherContext::tile`]) and shooter group `group`; empty when
    /// none were culled.
    pub(in crate::solver) fn thin_shaft(&self, tile: usize, group: usize) -> &'g [u32] {
        self.tile_candidates
            .get(tile + group)
            .map_or(&[][..], |c| &c[..])
    }
}

/// What a gather writes, per mesh vertex ([`gather_passes`]).
pub(in crate::solver) struct Sums<'b> {
    /// The step's `Δrad`.
    pub(in crate::solver) delta: &'b mut [Rgb],
    /// The first pass's `Δrad`, which the second reads.
    pub(in crate::solver) first: &'b mut [Rgb],
    /// The interpolation error charged to check vertices
    /// ([`Progressive::charges`]).
    pub(in crate::solver) spent: &'b mut [Rgb],
}

/// The vertices a gather call takes and the passes it runs over them
/// ([`gather_passes`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::solver) struct Work {
    /// Mesh vertices: whole polygons with [`Stage::All`], else some of
    /// one polygon's.
    pub(in crate::solver) vertices: Range<usize>,
    pub(in crate::solver) stage: Stage,
}

/// Which passes a gather call runs ([`gather_passes`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::solver) enum Stage {
    /// Whole polygons: both passes and the check charges.
    All,
    /// The first pass over some of one polygon's vertices; with `copy`,
    /// the last such piece, then keeps the polygon's first-pass values
    /// for the second.
    Exact { copy: Option<Range<usize>> },
    /// The second pass over some of one polygon's vertices; with
    /// `charge`, the last such piece, then charges the polygon's checks.
    Interpolated { charge: Option<Range<usize>> },
}

/// What the gather phase of a step counted.
#[derive(Clone, Copy, Debug)]
pub(in crate::solver) struct Gathered {
    /// Sample–vertex pairs whose visibility mattered.
    pub(in crate::solver) pairs: u64,
    /// Shadow rays cast.
    pub(in crate::solver) rays: u64,
}

impl Gathered {
    pub(in crate::solver) fn add(&mut self, other: Gathered) {
        self.pairs += other.pairs;
        self.rays += other.rays;
    }
}

/// Which receiving vertices a step may interpolate
/// ([`receivers`]): those of a receiving grid, not a member of the
/// shooting cluster (those are near it), neither coarse nor a check.
pub(in crate::solver) struct Interpolating<'s> {
    /// False when the step evaluates every vertex exactly.
    pub(in crate::solver) on: bool,
    pub(in crate::solver) coarse: &'s [Option<CoarseGrid>],
    /// Per mesh vertex, whether the cell it is the first corner of is
    /// crowded (empty: none is).
    pub(in crate::solver) crowded: &'s [bool],
    pub(in crate::solver) clusters: &'s Clusters,
    pub(in crate::solver) receives: &'s [bool],
    /// The shooting cluster.
    pub(in crate::solver) cluster: usize,
    /// The shooting cluster's bounds.
    pub(in crate::solver) shooter: (glam::Vec3, glam::Vec3),
    /// Element vertex positions.
    pub(in crate::solver) positions: &'s [glam::Vec3],
    /// Per vertex, the radiosity before the step.
    pub(in crate::solver) held: &'s [Rgb],
    /// Per vertex, the vertex whose `Δrad` it takes ([`shared`]); empty
    /// when receivers are not shared.
    pub(in crate::solver) leaders: &'s [u32],
}

impl Interpolating<'_> {
    /// The vertex whose first-pass `Δrad` vertex `l` of polygon `j` takes
    /// ([`shared`]): its leader, when its polygon receives and both are
    /// evaluated exactly in the first pass. The leader's polygon comes
    /// first, so its first pass is done by the end of the first pass over
    /// `l`'s chunk, however the step is cut into chunks; what decides
    /// depends on the step alone, so the bits do not depend on the cut.
    fn leader(&self, l: usize, j: PolygonId, poly: &[PolygonId]) -> Option<usize> {
        let m = *self.leaders.get(l)?;
        if m == shared::ALONE {
            return None;
        }
        let m = m as usize;
        let k = poly[m];
        (self.receives[k.index()] && self.cell(m, k).is_none() && self.cell(l, j).is_none())
            .then_some(m)
    }

    /// The coarse cell vertex `l` of polygon `j` may be interpolated from.
    fn cell(&self, l: usize, j: PolygonId) -> Option<receivers::Interpolation> {
        if !self.on || !self.receives[j.index()] || self.clusters.of(j) == self.cluster {
            return None;
        }
        match self.coarse[j.index()]?.role(l as u32) {
            receivers::Role::Fine(cell) => self.usable(cell),
            receivers::Role::Exact | receivers::Role::Check(_) => None,
        }
    }

    /// The coarse cell vertex `l` of polygon `j` is the check vertex of,
    /// when the step may interpolate that cell.
    fn checked_cell(&self, l: usize, j: PolygonId) -> Option<receivers::Interpolation> {
        if !self.on || !self.receives[j.index()] || self.clusters.of(j) == self.cluster {
            return None;
        }
        match self.coarse[j.index()]?.role(l as u32) {
            receivers::Role::Check(cell) => self.usable(cell),
            receivers::Role::Exact | receivers::Role::Fine(_) => None,
        }
    }

    /// `cell`, unless it is too near the shooter ([`receivers::far_from`]).
    fn usable(&self, cell: receivers::Interpolation) -> Option<receivers::Interpolation> {
        if self.crowded.get(cell.corners[0] as usize) == Some(&true) {
            return None;
        }
        let corners = cell.corners.map(|c| self.positions[c as usize]);
        receivers::far_from(corners, self.shooter).then_some(cell)
    }
}

/// A step's gather, phase 4, in two passes over the vertices: first every
/// receiving vertex `cells` does not offer (by `exact`, which returns a
/// vertex's `Δrad`, pairs and rays), then the others, each interpolated
/// from its coarse cell when [`receivers::accept`] allows and exact
/// otherwise; last, each check vertex of a cell accepted by the weak rule
/// is charged its error in `spent`. Writes `delta` (black for
/// non-receivers). Each vertex depends only on itself and the
/// first pass, so the bits do not depend on the thread count, nor on how
/// `work` cuts a step ([`parts`]): over whole polygons it runs all three,
/// over a piece of one polygon the pass its [`Stage`] names (the first
/// pass's values kept, in `coarse_delta`, and the charges made, once the
/// polygon's last piece of that pass is done). `None` once `cancel` is
/// set, with only scratch written.
pub(in crate::solver) fn gather_passes<E>(
    sums: Sums,
    mesh: &Mesh,
    cells: &Interpolating,
    cancel: &AtomicBool,
    exact: E,
    work: Work,
) -> Option<Gathered>
where
    E: Fn(usize, PolygonId, &mut Scratch) -> (Rgb, u64, u64) + Sync,
{
    let (receives, held) = (cells.receives, cells.held);
    let Work { vertices, stage } = work;
    let Sums {
        delta,
        first: coarse_delta,
        spent,
    } = sums;
    let start = vertices.start;
    let mut gathered = Gathered { pairs: 0, rays: 0 };
    if let Stage::All | Stage::Exact { .. } = stage {
        // Shared receivers follow a leader gathered in the same call.
        let poly = &mesh.vertex_polygon[..];
        let follows = |l: usize, j: PolygonId| cells.leader(l, j, poly);
        let (pairs, rays) = par_runs(
            mesh,
            &mut delta[vertices.clone()],
            start,
            |scratch, l, delta| {
                let j = mesh.vertex_polygon[l];
                if !receives[j.index()]
                    || cancel.load(Ordering::Relaxed)
                    || cells.cell(l, j).is_some()
                    || follows(l, j).is_some()
                {
                    *delta = Rgb::BLACK;
                    return (0, 0);
                }
                let (d, pairs, rays) = exact(l, j, scratch);
                *delta = d;
                (pairs, rays)
            },
        );
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        if !cells.leaders.is_empty() {
            for l in vertices.clone() {
                let j = poly[l];
                if receives[j.index()] {
                    if let Some(m) = follows(l, j) {
                        delta[l] = delta[m];
                    }
                }
            }
        }
        gathered.add(Gathered { pairs, rays });
        if !cells.on {
            return Some(gathered);
        }
        // The first pass's values, which the second reads (over the whole
        // polygon, once its last piece is done).
        let keep = match &stage {
            Stage::All => Some(vertices.clone()),
            Stage::Exact { copy } => copy.clone(),
            Stage::Interpolated { .. } => None,
        };
        if let Some(r) = keep {
            coarse_delta[r.clone()].copy_from_slice(&delta[r]);
        }
        if let Stage::Exact { .. } = stage {
            return Some(gathered);
        }
    }
    if !cells.on {
        return Some(gathered);
    }
    let first = &*coarse_delta;
    let spent_now = &*spent;
    let (pairs2, rays2) = par_runs(
        mesh,
        &mut delta[vertices.clone()],
        start,
        |scratch, l, delta| {
            let j = mesh.vertex_polygon[l];
            let Some(cell) = cells.cell(l, j) else {
                return (0, 0);
            };
            if cancel.load(Ordering::Relaxed) {
                return (0, 0);
            }
            let corners = cell.corners.map(|c| first[c as usize]);
            let c = cell.check as usize;
            if receivers::accept(corners, first[c], cell.check_weights, held[c], spent_now[c])
                .is_some()
            {
                *delta =
                    receivers::interpolate(corners, cell.weights, first[c], cell.check_weights);
                return (0, 0);
            }
            let (d, pairs, rays) = exact(l, j, scratch);
            *delta = d;
            (pairs, rays)
        },
    );
    if cancel.load(Ordering::Relaxed) {
        return None;
    }
    gathered.add(Gathered {
        pairs: pairs2,
        rays: rays2,
    });
    // The check charges, once the second pass read them all.
    let charge = match stage {
        Stage::All => Some(vertices),
        Stage::Interpolated { charge } => charge,
        Stage::Exact { .. } => None,
    };
    if let Some(r) = charge {
        let first_l = r.start;
        let charge_one = |(k, s): (usize, &mut Rgb)| {
            let l = first_l + k;
            let j = mesh.vertex_polygon[l];
            if let Some(cell) = cells.checked_cell(l, j) {
                let corners = cell.corners.map(|c| first[c as usize]);
                if let Some(cost) =
                    receivers::accept(corners, first[l], cell.check_weights, held[l], *s)
                {
                    *s += cost;
                }
            }
        };
        // A chunk's few thousand vertices cost less than waking the
        // workers.
        if r.len() < PARALLEL_CHARGES {
            spent[r].iter_mut().enumerate().for_each(charge_one);
        } else {
            spent[r]
                .par_iter_mut()
                .enumerate()
                .with_min_len(256)
                .for_each(charge_one);
        }
    }
    Some(gathered)
}

/// Runs `f` (scratch, vertex, its `Δrad`; returns pairs and rays) on
/// every vertex of `delta`, which holds the vertices from `start`, in
/// parallel, in runs of at most [`PAR_RUN`] vertices of one polygon: a
/// small facet's vertices stay with one worker, which shares their rays
/// ([`facets`]), and the threads finish a chunk of a few hundred vertices
/// ([`parts`]) within a few vertices' time of each other. Returns the
/// summed pairs and rays.
pub(in crate::solver) fn par_runs<F>(
    mesh: &Mesh,
    delta: &mut [Rgb],
    start: usize,
    f: F,
) -> (u64, u64)
where
    F: Fn(&mut Scratch, usize, &mut Rgb) -> (u64, u64) + Sync,
{
    let mut runs = Vec::with_capacity(delta.len() / PAR_RUN + 1);
    let (mut rest, mut l) = (delta, start);
    while !rest.is_empty() {
        let polygon_end = mesh.polygons[mesh.vertex_polygon[l].index()].vertices.end as usize;
        let n = (polygon_end - l).min(PAR_RUN).min(rest.len());
        let (run, tail) = std::mem::take(&mut rest).split_at_mut(n);
        runs.push((l, run));
        rest = tail;
        l += n;
    }
    runs.into_par_iter()
        // One scratch per worker, reused from run to run.
        .map_init(Scratch::default, |scratch: &mut Scratch, (first, run)| {
            let mut sum = (0, 0);
            for (k, d) in run.iter_mut().enumerate() {
                let (pairs, rays) = f(scratch, first + k, d);
                sum.0 += pairs;
                sum.1 += rays;
            }
            sum
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}
