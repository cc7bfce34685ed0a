//! Phase 4 of a cluster's step: every receiving vertex's sum over the
//! strata of the shooting cells.
//!
//! Heuristics acting here:
//! - **far strata**: a stratum far enough away is one term and one ray
//!   ([`crate::solver::accel::cluster::Seen::Far`]), or, its cells facing every
//!   way, one term and one ray per normal bin
//!   ([`crate::solver::accel::cluster::Seen::FarBinned`]);
//! - **weak strata**: a near stratum whose light is too weak here to
//!   matter is one term all the same ([`crate::solver::tuning::WEAK_STRATUM_SHARE`]);
//! - **single cells** near by, with the rules of a polygon's shot and
//!   **sub-cells** ([`crate::solver::accel::subcells`]);
//! - **receiver interpolation**, **shadow-ray choice** and **shared facet
//!   rays** as in a polygon's gather ([`super::gather`]).

use super::gather::{gather_passes, GatherContext, Gathered, Stage, Work};
use crate::color::Rgb;
use crate::scene::PolygonId;
use crate::solver::accel::cluster::{Cell, Clusters, Seen, Strata, Stratum};
use crate::solver::accel::facets::Scratch;
use crate::solver::accel::subcells::{self, SubCells};
use crate::solver::kernel::formfactor::{weighted_point_to_samples, ShooterSample};
use crate::solver::tuning::{LINEAR_CANDIDATES, SHOOTER_GROUP, WEAK_STRATUM_SHARE};
use crate::solver::{Progressive, OWN_RAY_SLOT, RAY_SLOTS, REPRESENTATIVE_SLOT};
use crate::visibility::{LastBlocker, ShadowQuery};
use glam::Vec3;
use std::ops::Range;
use std::sync::atomic::AtomicBool;

/// (node, its cut index or NONE above the cut)
const NONE: u32 = u32::MAX;

impl<'a> Progressive<'a> {
    /// Cluster step, phase 4: every receiving vertex's `Δrad`, summed over
    /// the strata: a far stratum ([`cluster::Seen::Far`]) gives one term
    /// and one ray; one wholly behind gives nothing; any other descends to
    /// its halves, down to single cells with the rules of a polygon's
    /// shot, unless its light is too weak there to matter
    /// ([`WEAK_STRATUM_SHARE`]), when it is one term too. Cells never
    /// shoot to their own polygon or one coplanar with it. Per vertex, in
    /// the two passes of [`gather_passes`], as [`Progressive::gather`].
    pub(in crate::solver) fn gather_cluster(
        &mut self,
        cluster: usize,
        from_top: bool,
        vertices: Range<usize>,
        stage: Stage,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        let groups = self.strata.roots.len().div_ceil(SHOOTER_GROUP).max(1);
        self.gather_with(groups, |p, g, sums| {
            let shot = ClusterShot {
                g,
                cluster,
                from_top,
                clusters: &p.clusters,
                cells: &p.cells,
                cell_samples: &p.cell_samples,
                cell_subcells: &p.cell_subcells,
                cell_subcell_values: &p.cell_subcell_values,
                cell_leaf_values: &p.cell_leaf_values,
                subcells: &p.subcells,
                strata: &p.strata,
                held: &p.radiosity,
                lump_share: if p.options.approximations.weak_strata {
                    WEAK_STRATUM_SHARE
                } else {
                    0.0
                },
            };
            // The exact `Δrad` at receiving vertex `l` of polygon `j`, with
            // the pairs and rays it took.
            let exact = |l: usize, j: PolygonId, scratch: &mut Scratch| shot.vertex(l, j, scratch);
            let cells = p.interpolating(p.options.approximations.receiver_interpolation, cluster);
            gather_passes(
                sums,
                g.mesh,
                &cells,
                cancel,
                exact,
                Work { vertices, stage },
            )
        })
    }
}

/// What a cluster's gather reads besides [`GatherContext`]: the shooting
/// cells, their strata and their split cells' values.
struct ClusterShot<'g> {
    g: &'g GatherContext<'g>,
    /// The shooting cluster.
    cluster: usize,
    /// Whether receivers descend from the strata tree's top rather than
    /// from the cut.
    from_top: bool,
    clusters: &'g Clusters,
    cells: &'g [Cell],
    cell_samples: &'g [ShooterSample],
    cell_subcells: &'g [u32],
    cell_subcell_values: &'g [Rgb],
    cell_leaf_values: &'g [Rgb],
    subcells: &'g [SubCells],
    strata: &'g Strata,
    /// Per vertex, the radiosity before the step.
    held: &'g [Rgb],
    /// [`WEAK_STRATUM_SHARE`], or 0 when weak strata are not lumped.
    lump_share: f64,
}

impl ClusterShot<'_> {
    /// The exact `Δrad` at receiving vertex `l` of polygon `j`, with the
    /// pairs and rays it took: the strata descended from the top or the
    /// cut, each node taken as a far term ([`ClusterShot::far_term`],
    /// [`ClusterShot::binned_term`]), a lumped term
    /// ([`ClusterShot::lumped_term`]), a single cell
    /// ([`ClusterShot::single_cell`]) or its halves.
    fn vertex(&self, l: usize, j: PolygonId, scratch: &mut Scratch) -> (Rgb, u64, u64) {
        let g = self.g;
        let (mesh, visibility, facets) = (g.mesh, g.visibility, g.facets);
        let (strata, cells) = (self.strata, self.cells);
        let Scratch { stack, memo } = scratch;
        let member = self.clusters.of(j) == self.cluster;
        let x = mesh.sample_positions[l];
        let nx = mesh.polygons[j.index()].normal;
        // What this step may leave to lumped strata at this vertex,
        // as a bound before reflection ([`WEAK_STRATUM_SHARE`]).
        let rho = g.reflectance[j.index()].mean();
        let mut allowance = if member || rho <= 0.0 {
            0.0
        } else {
            self.lump_share * self.held[l].mean() / rho
        };
        let tile = g.tile(l);
        let (mut sum, mut pairs, mut rays) = (Rgb::BLACK, 0u64, 0u64);
        self.start(stack);
        let whole = g.shaft(j);
        let mut last = LastBlocker::default();
        while let Some((n, si)) = stack.pop() {
            // Rays from a node in or below the cut are culled by
            // its group's thin shaft; from above, by the receiver's
            // shaft to the whole cluster.
            let blockers = (!member && g.culled(j)).then(|| {
                if si == NONE {
                    whole
                } else {
                    g.thin_shaft(tile, si as usize / SHOOTER_GROUP)
                }
            });
            // A small facet's vertices share one ray per node.
            // Keyed by node and by the cell the ray leaves from (the
            // node's representative, or a normal bin's).
            let mut blocked = |from: Vec3, own: PolygonId, exact_r2: f32, slot: u32| {
                if slot == OWN_RAY_SLOT {
                    rays += 1;
                    return visibility.occluded_remembering(from, x, (own, j), &mut last);
                }
                let key = n * RAY_SLOTS + slot;
                let (hit, cast) = facets
                    .shared_ray(memo, visibility, (own, j), key, from, exact_r2)
                    .unwrap_or_else(|| {
                        let query = ShadowQuery::choose(blockers, LINEAR_CANDIDATES);
                        let hit =
                            visibility.shadow_remembering(query, from, x, (own, j), &mut last);
                        (hit, query.rays())
                    });
                rays += cast;
                hit
            };
            let node = &strata.nodes[n as usize];
            let rep = &cells[node.representative as usize];
            // Above a weak step's cut, nodes larger than any
            // stratum must lie deeper in front of the receiver.
            let depth_ratio = if si == NONE {
                crate::solver::tuning::TOP_DEPTH_RATIO
            } else {
                crate::solver::tuning::PLANE_DEPTH_RATIO
            };
            let seen = node.seen_from_at(x, nx, depth_ratio);
            if seen == Seen::Behind {
                continue;
            }
            // By normal bins in every step, not only a weak one's: a
            // strong step's strata of a game level (floors, walls and
            // steps together) otherwise descended to single cells at a
            // quarter of the receivers, 500 to 900 rays each (zdm2.obj,
            // steps of 18 to 40 s; by bins 3 to 7 s, the solution within
            // 0.05 %).
            let binned = seen == Seen::FarBinned;
            let far = (seen == Seen::Far || binned) && !visibility.coplanar(rep.polygon, j);
            // A near stratum whose light is too weak here to matter
            // is taken as one term all the same ([`WEAK_STRATUM_SHARE`]).
            // `lumped` holds the bound of such a stratum.
            let lumped = self.weak_stratum(node, far, (x, nx), j, &mut allowance);
            match node.children {
                Some((a, b)) if !far && lumped.is_none() => {
                    let child = |c: u32| {
                        let at = strata.root_index[c as usize];
                        (c, if at != NONE { at } else { si })
                    };
                    stack.push(child(b));
                    stack.push(child(a));
                    continue;
                }
                None if !far => {
                    if let Some((f, asked)) = self.single_cell(node, x, nx, j, &mut blocked) {
                        sum += f;
                        pairs += asked;
                    }
                    continue;
                }
                _ => {}
            }
            // Far: the node's power from its centroid, with its
            // mean normal and one ray from its representative; or,
            // binned (cells facing every way), each normal bin's
            // power with its own cosine and its own ray, from the
            // bin's representative (a cell facing the receiver: the
            // node's may lie on a table's underside, whose ray to
            // the ceiling the top blocks; one ray for all bins would
            // give the whole node the visibility of one face). A
            // lumped node, whose light is bounded within the
            // allowance, takes one ray, from the bin bringing most.
            let d = x - node.centroid;
            let r2 = d.length_squared();
            let cos_x = -nx.dot(d);
            if cos_x <= 0.0 || r2 <= 0.0 {
                continue;
            }
            let geometry = {
                let r2 = f64::from(r2);
                f64::from(cos_x) / (std::f64::consts::PI * r2 * r2)
            };
            // (power it brings, whether a ray finds it visible)
            let (power, seen) = if lumped.is_some() {
                self.lumped_term(node, d, &mut blocked)
            } else if binned {
                self.binned_term(node, d, &mut blocked)
            } else {
                match self.far_term(node, d, &mut blocked) {
                    Some(term) => term,
                    None => continue,
                }
            };
            if power.is_black() {
                continue;
            }
            pairs += 1;
            let term = seen * geometry;
            // A lumped stratum may be close: its term is held to the
            // bound on what it can bring (in the share its visible
            // bins have of it).
            let whole = power.mean() * geometry;
            sum += match lumped {
                Some(cap) if whole > cap => term * (cap / whole),
                _ => term,
            };
        }
        (g.reflectance[j.index()] * sum, pairs, rays)
    }

    /// Fills `stack` with the nodes a receiver's descent starts from: the
    /// strata tree's top, or the cut's roots in order.
    fn start(&self, stack: &mut Vec<(u32, u32)>) {
        let strata = self.strata;
        stack.clear();
        // No cells (every reading zero): the step sends nothing.
        if self.from_top && !strata.nodes.is_empty() {
            stack.push((0, strata.root_index.first().copied().unwrap_or(NONE)));
        } else {
            stack.extend(strata.roots.iter().enumerate().map(|(i, &r)| (r, i as u32)));
            stack.reverse();
        }
    }

    /// Whether `node`, not `far` from the receiver at `x` (unit normal
    /// `nx`) of polygon `j`, is a weak stratum taken as one term: its
    /// light too weak here to matter, while the bounds of what such terms
    /// bring stay within the `allowance` (which its bound is taken from),
    /// unless the vertex is inside its sphere ([`WEAK_STRATUM_SHARE`]).
    /// Returns the stratum's bound.
    fn weak_stratum(
        &self,
        node: &Stratum,
        far: bool,
        (x, nx): (Vec3, Vec3),
        j: PolygonId,
        allowance: &mut f64,
    ) -> Option<f64> {
        let visibility = self.g.visibility;
        let rep = &self.cells[node.representative as usize];
        if !far
            && node.children.is_some()
            && *allowance > 0.0
            && (x - node.centre).length_squared() > node.radius * node.radius
        {
            let bound = node.bound_at(x, nx);
            (bound <= *allowance && rep.polygon != j && !visibility.coplanar(rep.polygon, j)).then(
                || {
                    *allowance -= bound;
                    bound
                },
            )
        } else {
            None
        }
    }

    /// A single cell close by, `node`'s one cell, at `x` (unit normal
    /// `nx`) of polygon `j`: the exact rules of a polygon's shot, the
    /// cell's form factor times its unshot radiosity and the pairs asked
    /// (`blocked` answers the rays); `None` when the cell does not shoot
    /// to `j` (its own polygon, or one coplanar with it).
    fn single_cell(
        &self,
        node: &Stratum,
        x: Vec3,
        nx: Vec3,
        j: PolygonId,
        blocked: &mut impl FnMut(Vec3, PolygonId, f32, u32) -> bool,
    ) -> Option<(Rgb, u64)> {
        let (mesh, visibility, near_field) = (self.g.mesh, self.g.visibility, self.g.near_field);
        let (cell_subcells, subs) = (self.cell_subcells, self.subcells);
        let (cell_subcell_values, cell_leaf_values) =
            (self.cell_subcell_values, self.cell_leaf_values);
        let rep = &self.cells[node.representative as usize];
        let rep_sample = &self.cell_samples[node.representative as usize];
        if rep.polygon == j || visibility.coplanar(rep.polygon, j) {
            return None;
        }
        // A split cell by its sub-cells, as when its
        // polygon shoots alone.
        let at = cell_subcells[node.representative as usize];
        let split = (at != subcells::NONE)
            .then(|| {
                let at = at as usize;
                subcells::Split::of_cell(
                    &subs[rep.polygon.index()],
                    rep.sample as usize,
                    &cell_subcell_values[at..at + subcells::SUBCELLS],
                    &cell_leaf_values
                        [at * subcells::LEAVES..(at + subcells::SUBCELLS) * subcells::LEAVES],
                )
            })
            .flatten();
        let (f, asked) = weighted_point_to_samples(
            x,
            nx,
            mesh.polygons[rep.polygon.index()].normal,
            std::slice::from_ref(rep_sample),
            |_| rep.unshot,
            split.as_ref(),
            near_field,
            |_, from| {
                let exact_r2 = rep_sample.exact_r2;
                // Not the sample: a near cell's part in
                // front of the vertex, asked alone.
                let slot = if from == rep_sample.position {
                    REPRESENTATIVE_SLOT
                } else {
                    OWN_RAY_SLOT
                };
                blocked(from, rep.polygon, exact_r2, slot)
            },
        );
        Some((f, asked))
    }

    /// A lumped term: `node`'s power at the receiver `d` from its
    /// centroid (per normal bin, by the bin's cosine), and as much of it
    /// seen as the one ray from the bin bringing most finds visible
    /// (`blocked`): `(power, seen)`, both before the geometry factor.
    fn lumped_term(
        &self,
        node: &Stratum,
        d: Vec3,
        blocked: &mut impl FnMut(Vec3, PolygonId, f32, u32) -> bool,
    ) -> (Rgb, Rgb) {
        let (cells, cell_samples) = (self.cells, self.cell_samples);
        let (mut power, mut seen) = (Rgb::BLACK, Rgb::BLACK);
        let (mut most, mut from) = (0.0, None);
        for (b, (p, normal)) in node.bins.iter().enumerate() {
            let cos_s = normal.dot(d);
            let at = node.bin_representatives[b];
            if cos_s <= 0.0 || at == u32::MAX {
                continue;
            }
            let brings = *p * f64::from(cos_s);
            power += brings;
            if brings.mean() > most {
                most = brings.mean();
                from = Some((at, b as u32));
            }
        }
        if let Some((at, b)) = from {
            let (origin, sample) = (&cells[at as usize], &cell_samples[at as usize]);
            if !blocked(sample.position, origin.polygon, 0.0, b) {
                seen = power;
            }
        }
        (power, seen)
    }

    /// A binned far term: `node`'s cells facing every way, each normal
    /// bin's power at the receiver `d` with its own cosine, seen where its
    /// own ray from the bin's representative finds it visible (`blocked`):
    /// `(power, seen)`, both before the geometry factor.
    fn binned_term(
        &self,
        node: &Stratum,
        d: Vec3,
        blocked: &mut impl FnMut(Vec3, PolygonId, f32, u32) -> bool,
    ) -> (Rgb, Rgb) {
        let (cells, cell_samples) = (self.cells, self.cell_samples);
        let (mut power, mut seen) = (Rgb::BLACK, Rgb::BLACK);
        for (b, (p, normal)) in node.bins.iter().enumerate() {
            let cos_s = normal.dot(d);
            let at = node.bin_representatives[b];
            if cos_s <= 0.0 || at == u32::MAX {
                continue;
            }
            let brings = *p * f64::from(cos_s);
            power += brings;
            let (origin, sample) = (&cells[at as usize], &cell_samples[at as usize]);
            if !blocked(sample.position, origin.polygon, 0.0, b as u32) {
                seen += brings;
            }
        }
        (power, seen)
    }

    /// A far term: `node`'s power at the receiver `d` from its centroid
    /// with its mean normal, seen when the one ray from its representative
    /// finds it visible (`blocked`): `(power, seen)`, both before the
    /// geometry factor; `None` when the node faces away.
    fn far_term(
        &self,
        node: &Stratum,
        d: Vec3,
        blocked: &mut impl FnMut(Vec3, PolygonId, f32, u32) -> bool,
    ) -> Option<(Rgb, Rgb)> {
        let rep = &self.cells[node.representative as usize];
        let rep_sample = &self.cell_samples[node.representative as usize];
        let cos_s = node.mean_normal.dot(d);
        if cos_s <= 0.0 {
            return None;
        }
        let power = node.power * f64::from(cos_s);
        let mut seen = Rgb::BLACK;
        // Far: no vertex near a cell.
        if !blocked(rep_sample.position, rep.polygon, 0.0, REPRESENTATIVE_SLOT) {
            seen = power;
        }
        Some((power, seen))
    }
}
