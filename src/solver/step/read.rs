//! Phase 2 of a step: reading what the shooter sends.
//!
//! A polygon shooting alone reads its unshot radiosity at its samples; a
//! cluster reads every member's samples as cells and builds their strata.
//! Heuristics acting here:
//! - **cell integrals**: a sample sends the light its cell holds, and the
//!   samples together what the step takes from the polygon
//!   (`kernel::cell_integrals`);
//! - **sub-cells**: a cell much larger than its elements is read as its
//!   sub-cells and leaves ([`crate::solver::accel::subcells`]);
//! - **strata**: a cluster (or a polygon of weak light) shoots from a cut
//!   of its strata, the fewer the weaker its light
//!   ([`crate::solver::tuning::FULL_STRATA_SHARE`], [`crate::solver::tuning::MIN_STRATA`]);
//!   a weak hemicube step merges its cells into fewer hemicubes by the
//!   same cut ([`crate::solver::methods::hemicube`]).

use crate::mesh::Mesh;
use crate::scene::PolygonId;
use crate::solver::accel::cluster::{Cell, Strata};
use crate::solver::accel::subcells;
use crate::solver::tuning::{FULL_STRATA_SHARE, MIN_STRATA};
use crate::solver::unshot::Shot;
use crate::solver::{unshot, Expectation, Progressive, ShooterSamples};

impl<'a> Progressive<'a> {
    /// How many strata a clustered step shoots from at most, for a step
    /// that shoots `power` (radiosity × area units): the shooter sample
    /// cap while the step carries at least [`FULL_STRATA_SHARE`] of the
    /// initial unshot power, fewer as it carries less (by the square root
    /// of the ratio, at least [`MIN_STRATA`]). A stratum's one ray decides
    /// the visibility of its whole power, so what a lumped stratum can get
    /// wrong is at most its power: the weaker the light, the coarser its
    /// strata may be (the power oracle of Hanrahan, Salzman and
    /// Aupperle's BF refinement).
    pub(in crate::solver) fn step_roots(&self, power: f64) -> usize {
        let cap = match self.options.shooter_samples {
            ShooterSamples::AtMost(n) => n as usize,
            ShooterSamples::All => usize::MAX,
        };
        if !self.options.approximations.strata || self.initial_unshot_power <= 0.0 {
            return cap;
        }
        let share = power / (FULL_STRATA_SHARE * self.initial_unshot_power);
        if share >= 1.0 {
            return cap;
        }
        ((cap as f64 * share.sqrt()).ceil() as usize).clamp(MIN_STRATA.min(cap), cap)
    }

    /// Phase 2, read the shooter's samples: fills `self.shot` with the
    /// radiosity each sample of `shooter` sends in a step that sends
    /// `shot` ([`UnshotField::read_shooter`]).
    /// Its cells much larger than the elements carry their sub-cells'
    /// mean, and their sub-cells' own light is read into `self.subcell_readings`
    /// ([`subcells`]).
    pub(in crate::solver) fn read_shooter(&mut self, shooter: PolygonId, shot: Shot) {
        let i = shooter.index();
        let samples = self.samples[i].len();
        self.unshot.read_shooter(
            &self.mesh,
            i,
            samples,
            shot,
            &self.radiosity,
            &mut self.shot,
            &mut self.subcell_readings,
        );
        subcells::carry_means(&self.subcells[i], &self.subcell_readings, &mut self.shot);
        // The samples read the field at their cells' centres; what they
        // send together must be what the step takes from the polygon.
        let sent = self.unshot.sent_power(&self.mesh, i, shot, &self.radiosity);
        unshot::send_what_is_spent(&mut self.shot, &self.samples[i], sent)
            .apply(&mut self.subcell_readings);
    }

    /// Cluster step, phase 2: the cluster's cells (every member's shooter
    /// samples that carry unshot power, with what they carry) and their
    /// strata ([`Strata::build`]), a cut of at most `roots`
    /// ([`Progressive::step_roots`]).
    pub(in crate::solver) fn read_cluster(
        &mut self,
        cluster: usize,
        roots: usize,
        negative: bool,
        expected: Expectation,
    ) {
        self.cells.clear();
        self.cell_samples.clear();
        self.cell_subcells.clear();
        self.cell_subcell_values.clear();
        self.cell_leaf_values.clear();
        for member in 0..self.clusters.members(cluster).len() {
            let m = self.clusters.members(cluster)[member];
            let i = m as usize;
            let shot = self.polygon_shot(i, negative, expected);
            // Each member's cells read as when it shoots alone.
            self.read_shooter(PolygonId(m), shot);
            let mesh: &Mesh = &self.mesh;
            let subs = &self.subcells[i];

            for (k, (sample, &unshot)) in self.samples[i].iter().zip(&self.shot).enumerate() {
                let power = unshot.mean() * sample.area;
                if power > 0.0 {
                    self.cells.push(Cell {
                        polygon: PolygonId(m),
                        sample: k as u32,
                        unshot,
                        area: sample.area,
                        normal: mesh.polygons[i].normal,
                        power,
                    });
                    self.cell_samples.push(*sample);
                    let at = match subs.cell_values(k, &self.subcell_readings) {
                        Some((values, leaves)) => {
                            let at = self.cell_subcell_values.len() as u32;
                            self.cell_subcell_values.extend_from_slice(values);
                            self.cell_leaf_values.extend_from_slice(leaves);
                            at
                        }
                        None => subcells::NONE,
                    };
                    self.cell_subcells.push(at);
                }
            }
        }
        let k = roots.min(self.cells.len());
        let samples = &self.cell_samples;
        self.strata = Strata::build(&self.cells, k, |c| samples[c].bounds());
    }
}
