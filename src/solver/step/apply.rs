//! Phase 5 of a step: applying what the receivers gathered, and the
//! step's report.
//!
//! Heuristics acting here: **overshooting** (a shooter is left holding
//! minus what it sent ahead, [`crate::solver::Approximations::overshoot`];
//! negative light takes radiosity back, never below black).

use super::{StepPhase, Underway};
use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::solver::{Progressive, StepReport};
use std::ops::Range;

impl<'a> Progressive<'a> {
    /// Phase 5, apply, for the receiving polygons `polygons` of step `u`:
    /// adds the gathered `Δrad` (subtracts it, for a step of negative
    /// light) to their radiosity and unshot radiosity (polygon by polygon
    /// in index order, so the sums are the same whatever the thread
    /// count). Before the step's first receivers, takes what the shooters
    /// sent from their unshot radiosity ([`UnshotField::spend`], with the
    /// `expected` light the step read them with): a cluster's members
    /// receive from each other in the step that empties them.
    pub(in crate::solver) fn apply_chunk(&mut self, u: &mut Underway, polygons: Range<usize>) {
        self.changed();
        let negative = u.shot_power < 0.0;
        if !u.spent {
            for &m in self.clusters.members(u.cluster) {
                let shot = self.polygon_shot(m as usize, negative, u.expected);
                self.unshot
                    .spend(&self.mesh, m as usize, shot, &self.radiosity);
            }
            u.spent = true;
        }
        let culling = self.options.approximations.shaft_culling;
        let mesh: &Mesh = &self.mesh;
        for j in polygons {
            if !self.receives[j] {
                continue;
            }
            let pm = &mesh.polygons[j];
            u.receivers += 1;
            u.clear += (culling && !self.small[j] && self.candidates[j].is_empty()) as u64;
            for l in pm.vertices.clone() {
                let l = l as usize;
                if negative {
                    self.delta[l] = -self.delta[l];
                    // Negative light takes back what overshooting sent
                    // ahead; where the two reached a vertex by other
                    // sample points, rounding could take a little more
                    // than it holds.
                    self.radiosity[l] = (self.radiosity[l] + self.delta[l]).max(Rgb::BLACK);
                } else {
                    self.radiosity[l] += self.delta[l];
                }
            }
            self.unshot.accumulate(mesh, j, &self.delta);
            if negative {
                // `delta` keeps what was gathered, whatever its sign, for
                // the whole step: a shared receiver in a later chunk takes
                // its leader's value from it ([`crate::solver::accel::shared`]).
                for l in pm.vertices.clone() {
                    self.delta[l as usize] = -self.delta[l as usize];
                }
            }
        }
    }

    /// Whether what the receiving polygons among `polygons` gathered
    /// (their vertices' `Δrad`) is finite: checked before it is applied,
    /// so a failed gather leaves the solution as the last step left it.
    pub(in crate::solver) fn gathered_is_finite(&self, polygons: Range<usize>) -> bool {
        let mesh: &Mesh = &self.mesh;
        polygons.filter(|&j| self.receives[j]).all(|j| {
            let vertices = mesh.polygons[j].vertices.clone();
            self.delta[vertices.start as usize..vertices.end as usize]
                .iter()
                .all(|d| d.is_finite())
        })
    }

    /// Whether every radiosity and unshot value is finite (a pass over
    /// the mesh: for checks, not for every step of a release build).
    pub fn values_are_finite(&self) -> bool {
        self.radiosity.iter().all(|b| b.is_finite()) && self.unshot().iter().all(|d| d.is_finite())
    }

    /// The report of a part of step `u` that leaves it unfinished.
    pub(in crate::solver) fn part_report(&self, u: &Underway, complete: bool) -> StepReport {
        StepReport {
            step: self.steps + u64::from(!complete),
            shooter: u.shooter,
            polygons: self.clusters.members(u.cluster).len() as u32,
            shot_power: u.shot_power,
            // Summing the unshot power visits every vertex: a part of a
            // step not finished says what the last finished step left.
            unshot_fraction: if complete {
                self.unshot_fraction()
            } else {
                u.fraction_before
            },
            rays: u.gathered.rays,
            pairs: u.gathered.pairs,
            receivers: u.receivers,
            clear_receivers: u.clear,
            part: u.part,
            complete,
            particles: 0,
        }
    }

    /// Counts the finished step `u` and reports it.
    pub(in crate::solver) fn finish_step(&mut self, u: &Underway) -> StepReport {
        self.pairs += u.gathered.pairs;
        self.receiver_pairs += u.receivers;
        self.clear_receiver_pairs += u.clear;
        self.steps += 1;
        self.rays += u.gathered.rays;
        let report = self.part_report(u, true);
        // The unshot fraction sums every unshot value, so a value that
        // applying made infinite or NaN makes it so: a check at no cost.
        // The step is counted; the solution holds what it applied.
        if !report.unshot_fraction.is_finite() {
            self.fail(report.step, u, StepPhase::Apply);
        }
        debug_assert!(
            self.fault.is_some() || self.values_are_finite(),
            "step {} left a radiosity or unshot value that is not finite",
            self.steps
        );
        self.last_fraction = report.unshot_fraction;
        // A step that cost far more than particles for the light it shot
        // hands the rest to an automatic tail. The power left is the
        // fraction's numerator, not summed again over every vertex.
        if self.fault.is_none() {
            self.tail.hand_over_if_costly(
                u.gathered.rays,
                u.shot_power,
                (
                    report.unshot_fraction * self.initial_unshot_power,
                    report.unshot_fraction,
                ),
                self.mesh.vertex_count(),
            );
        }
        report
    }
}
