//! Phase 3 of a step: marking the receivers and culling their shadow-ray
//! candidates.
//!
//! Heuristics acting here:
//! - **receiver marking**: a polygon receives only when some vertex of it
//!   is in front of the shooter and some sample in front of it (a
//!   cluster's step marks every reflecting polygon);
//! - **shaft culling** ([`crate::solver::Approximations::shaft_culling`]):
//!   the polygons in each receiver's shaft to the shooter (a cluster's
//!   bounds), then in each thin shaft between a tile of
//!   [`crate::solver::tuning::TILE_VERTICES`] receiving vertices and a group of
//!   [`crate::solver::tuning::SHOOTER_GROUP`] samples or strata, searched by
//!   culling group; small receivers ([`crate::solver::tuning::SHAFT_MIN_VERTICES`])
//!   and crowded shafts ([`crate::solver::tuning::REFINE_MAX`]) ask the BVH
//!   instead.

use super::{How, Underway};
use crate::mesh::Mesh;
use crate::scene::PolygonId;
use crate::solver::accel::cluster::Clusters;
use crate::solver::tuning::{REFINE_MAX, SHOOTER_GROUP};
use crate::solver::Progressive;
use rayon::prelude::*;
use std::ops::Range;

impl<'a> Progressive<'a> {
    /// Shooter samples of polygon `i` are culled in groups of
    /// [`SHOOTER_GROUP`]: the number of groups, at least 1.
    pub(in crate::solver) fn shooter_groups(&self, i: usize) -> usize {
        self.samples[i].len().div_ceil(SHOOTER_GROUP).max(1)
    }

    /// Marks the polygons that can receive from shooter `i`: not `i`
    /// itself, with some reflectance, some vertex in front of `i`'s plane
    /// and some sample of `i` in front of their own plane. The others get
    /// nothing and need no per-vertex work.
    pub(in crate::solver) fn mark_receivers(&mut self, i: usize) {
        let mesh: &Mesh = &self.mesh;
        let shooter = &mesh.polygons[i];
        let origin = self.samples[i]
            .first()
            .map(|s| s.position)
            .unwrap_or_default();
        for (j, pm) in mesh.polygons.iter().enumerate() {
            let visible_side = || {
                let range = pm.vertices.start as usize..pm.vertices.end as usize;
                let in_front = mesh.sample_positions[range.clone()]
                    .iter()
                    .any(|&x| shooter.normal.dot(x - origin) > 0.0);
                let x0 = mesh.sample_positions[range.start];
                // A cell counts by its corners: the floor cell under a
                // table leg facing a wall has its sample behind the leg's
                // face and a part in front of it, which lights the face
                // ([`formfactor::front_point`]).
                in_front
                    && self.samples[i].iter().any(|s| {
                        pm.normal.dot(s.position - x0) > 0.0
                            || s.cell
                                .is_some_and(|c| c.iter().any(|&p| pm.normal.dot(p - x0) > 0.0))
                    })
            };
            self.receives[j] = j != i
                && !self.reflectance[j].is_black()
                && !self
                    .visibility
                    .coplanar(PolygonId(i as u32), PolygonId(j as u32))
                && pm.vertex_count() > 0
                && visible_side();
        }
    }

    /// Cluster step, marking: every polygon with some reflectance
    /// receives, the cluster's own members included (they see each
    /// other). Keeps the strata's bounds, two corners a stratum, for the
    /// thin shafts ([`Progressive::cull_chunk`]).
    pub(in crate::solver) fn mark_cluster_receivers(&mut self) {
        let mesh: &Mesh = &self.mesh;
        for (j, pm) in mesh.polygons.iter().enumerate() {
            self.receives[j] = !self.reflectance[j].is_black() && pm.vertex_count() > 0;
        }
        self.group_points.clear();
        for &r in &self.strata.roots {
            let s = &self.strata.nodes[r as usize];
            self.group_points.extend([s.bounds.0, s.bounds.1]);
        }
    }

    /// Phase 3 for the receiving polygons `polygons` of step `u`: with
    /// shaft culling, the polygons in each one's shaft to the shooter (or
    /// the cluster's bounds), then in each thin shaft between a receiver
    /// tile and a group of shooter samples (or strata).
    pub(in crate::solver) fn cull_chunk(&mut self, u: &Underway, polygons: Range<usize>) {
        if !self.options.approximations.shaft_culling {
            return;
        }
        match u.how {
            How::Alone => {
                self.cull_polygon_shafts(u.shooter, polygons.clone());
                let groups = self.shooter_groups(u.shooter.index());
                self.cull_tile_shafts_from(groups, 1, polygons);
            }
            How::Cluster { .. } => {
                self.cull_cluster_shafts(u.cluster, polygons.clone());
                let groups = self.strata.roots.len().div_ceil(SHOOTER_GROUP).max(1);
                self.cull_tile_shafts_from(groups, 2, polygons);
            }
        }
    }

    /// Per receiver among `polygons`: the polygons in its shaft to
    /// `shooter` (`self.candidates`; empty for polygons that do not
    /// receive).
    pub(in crate::solver) fn cull_polygon_shafts(
        &mut self,
        shooter: PolygonId,
        polygons: Range<usize>,
    ) {
        let visibility = self.visibility;
        let receives = &self.receives;
        let small = &self.small;
        let groups = &self.culling_groups;
        let start = polygons.start;
        self.candidates[polygons.clone()]
            .par_iter_mut()
            .zip(self.candidate_runs[polygons].par_iter_mut())
            .enumerate()
            .for_each(|(k, (c, runs))| {
                let j = start + k;
                if receives[j] && !small[j] {
                    visibility.shaft_candidates(shooter, PolygonId(j as u32), REFINE_MAX, c);
                } else {
                    c.clear();
                }
                group_candidates(groups, c, runs);
            });
    }

    /// Cluster step, phase 3 for `polygons`: the polygons in each
    /// non-member's shaft to the cluster's bounds (members always test
    /// their rays against the whole scene).
    pub(in crate::solver) fn cull_cluster_shafts(
        &mut self,
        cluster: usize,
        polygons: Range<usize>,
    ) {
        let (lo, hi) = self.clusters.bounds(cluster);
        let bounds = (lo.as_dvec3(), hi.as_dvec3());
        let visibility = self.visibility;
        let receives = &self.receives;
        let clusters = &self.clusters;
        let small = &self.small;
        let groups = &self.culling_groups;
        let start = polygons.start;
        self.candidates[polygons.clone()]
            .par_iter_mut()
            .zip(self.candidate_runs[polygons].par_iter_mut())
            .enumerate()
            .for_each(|(k, (c, runs))| {
                let j = start + k;
                let member = clusters.of(PolygonId(j as u32)) == cluster;
                if receives[j] && !member && !small[j] {
                    visibility.box_shaft_candidates(bounds, PolygonId(j as u32), REFINE_MAX, c);
                } else {
                    c.clear();
                }
                group_candidates(groups, c, runs);
            });
    }

    /// Thin shafts between small groups of shooter samples and of receiver
    /// vertices of `polygons`, searched among their polygons'
    /// candidates: per tile and sample group, the polygons in the shaft
    /// between them (`self.tile_candidates`). The shooter's points are in
    /// `self.group_points`: `per_sample` points for each sample (shooter
    /// sample or stratum), in `groups` groups of [`SHOOTER_GROUP`]
    /// samples.
    pub(in crate::solver) fn cull_tile_shafts_from(
        &mut self,
        groups: usize,
        per_sample: usize,
        polygons: Range<usize>,
    ) {
        let mesh: &Mesh = &self.mesh;
        let visibility = self.visibility;
        let group_len = SHOOTER_GROUP * per_sample;
        let receives = &self.receives;
        let group_points = &self.group_points;
        let polygon_candidates = &self.candidates;
        let candidate_runs = &self.candidate_runs;
        let tiles = &self.tiles;
        self.tile_candidates
            .resize_with(tiles.len() * groups, Vec::new);
        // The tiles of `polygons`: theirs are consecutive, as their
        // vertices are.
        let first = mesh.polygons[polygons.start].vertices.start as usize;
        let end = mesh.polygons[polygons.end - 1].vertices.end as usize;
        if first == end {
            return;
        }
        let tile_range = self.tile_of[first] as usize..self.tile_of[end - 1] as usize + 1;
        self.tile_candidates[tile_range.start * groups..tile_range.end * groups]
            .par_iter_mut()
            .enumerate()
            .for_each(|(k, c)| {
                let index = tile_range.start * groups + k;
                let (t, g) = (index / groups, index % groups);
                let Some(tile) = tiles.get(t) else {
                    c.clear();
                    return;
                };
                let j = mesh.vertex_polygon[tile.start as usize].index();
                let pc = &polygon_candidates[j];
                if receives[j] && !pc.is_empty() && pc.len() <= REFINE_MAX {
                    let to = &mesh.sample_positions[tile.start as usize..tile.end as usize];
                    let from = &group_points[(g * group_len).min(group_points.len())
                        ..((g + 1) * group_len).min(group_points.len())];
                    visibility.refine_candidates_in_runs(
                        from,
                        to,
                        &polygon_candidates[j],
                        &candidate_runs[j],
                        c,
                    );
                } else {
                    c.clear();
                }
            });
    }
}

/// Orders one receiver's shaft candidates `c` by culling group (of
/// `groups`) and records their runs with the group's bounds, for
/// [`Visibility::refine_candidates_in_runs`].
pub(in crate::solver) fn group_candidates(
    groups: &Clusters,
    c: &mut [u32],
    runs: &mut Vec<crate::visibility::CandidateRun>,
) {
    runs.clear();
    c.sort_unstable_by_key(|&p| (groups.of(PolygonId(p)), p));
    let mut start = 0;
    while start < c.len() {
        let g = groups.of(PolygonId(c[start]));
        let mut end = start + 1;
        while end < c.len() && groups.of(PolygonId(c[end])) == g {
            end += 1;
        }
        let (lo, hi) = groups.bounds(g);
        runs.push((start as u32..end as u32, (lo.as_dvec3(), hi.as_dvec3())));
        start = end;
    }
}
