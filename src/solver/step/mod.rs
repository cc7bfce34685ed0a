//! One shooting step, in five phases, one file each:
//!
//! 1. [`choose`]: choose the shooter (a polygon or a cluster) and what it
//!    sends;
//! 2. [`read`]: read what its samples (or a cluster's strata) carry;
//! 3. [`cull`]: mark the receivers and cull their shadow-ray candidates;
//! 4. [`gather`] (a polygon's) and [`gather_cluster`]: every receiving
//!    vertex's `Δrad`;
//! 5. [`apply`]: add it to the receivers and report the step.
//!
//! Phases 3 to 5 run over the receivers in chunks, and with a part budget
//! a step returns between chunks ([`parts`]). This module begins a step
//! (phases 1 and 2) and runs it. Another method may compose these phases
//! with its own: the hemicube ([`crate::solver::methods::hemicube`])
//! takes phases 1, 3 and 5 and reads and gathers by rendering.

use crate::scene::PolygonId;
use crate::solver::unshot::Shot;
use crate::solver::{Expectation, Progressive, SolverError, StepReport};
use gather::Gathered;
use std::sync::atomic::AtomicBool;

pub mod apply;
pub mod choose;
pub mod cull;
pub mod gather;
pub mod gather_cluster;
pub mod parts;
pub mod read;
pub mod sky;
pub mod tail;
pub mod tail_gather;

/// A step begun: what it shoots, how, and how far it has got.
#[derive(Clone, Debug)]
pub(in crate::solver) struct Underway {
    /// The shooting cluster (without clustering, the polygon's own).
    cluster: usize,
    /// Its member holding the most unshot power.
    pub(in crate::solver) shooter: PolygonId,
    /// What [`Progressive::choose_shooter`] found it to send, signed.
    shot_power: f64,
    /// The expected light the shooters were read with.
    expected: Expectation,
    how: How,
    /// The receivers' chunks and how far they have been taken.
    plan: parts::Plan,
    /// Whether the shooters' unshot radiosity has been spent (with the
    /// first receivers applied).
    pub(in crate::solver) spent: bool,
    /// Counts so far.
    pub(in crate::solver) gathered: Gathered,
    receivers: u64,
    clear: u64,
    /// Parts reported so far, the one running included.
    pub(in crate::solver) part: u32,
    /// The unshot fraction the last finished step left.
    fraction_before: f64,
}

/// How a step shoots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::solver) enum How {
    /// One polygon from its own samples.
    Alone,
    /// A cluster (or a polygon of weak light) from strata, descending from
    /// the strata tree's top when `from_top`.
    Cluster { from_top: bool },
}

/// The phase of a step in which a value stopped being finite, as a failed
/// step names it ([`crate::solver::SolverError::NotFinite`]). Each phase's
/// products are checked before the next phase uses them, which costs a
/// pass over what the phase made (the shooter's readings or strata, the
/// receivers' `Δrad`): little beside making it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepPhase {
    /// Phases 1 and 2: what the shooter sends, per sample or per stratum.
    Read,
    /// Phases 3 and 4: what each receiving vertex gathered.
    Gather,
    /// Phase 5: the radiosity and unshot radiosity after adding it.
    Apply,
}

impl std::fmt::Display for StepPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            StepPhase::Read => "reading what the shooter sends",
            StepPhase::Gather => "gathering at the receivers",
            StepPhase::Apply => "applying to the receivers",
        })
    }
}

#[cfg(test)]
thread_local! {
    /// Test hook: the step (from 1) whose reading is made NaN on this
    /// thread, to exercise what follows a failed step; 0 for none.
    pub(crate) static POISON_READ_AT: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// A step chosen (phase 1) and not yet begun: its shooter and what it
/// sends. A method shoots it its own way ([`Progressive::begin_chosen`]
/// for progressive shooting; the hemicube renders it,
/// [`crate::solver::methods::hemicube`]).
pub(in crate::solver) struct Chosen {
    /// The step so far: shooter, cluster, signed power and expected light
    /// chosen, shooting [`How::Alone`] in one part, nothing gathered.
    pub(in crate::solver) underway: Underway,
    /// Strata or hemicubes the step may use ([`Progressive::step_roots`]).
    pub(in crate::solver) roots: usize,
    /// Whether the step shoots negative light.
    pub(in crate::solver) negative: bool,
    /// What each point of the shooter sends.
    pub(in crate::solver) shot: Shot,
}

impl<'a> Progressive<'a> {
    /// One shooting step from the polygon with the most unshot power, or
    /// with a [`crate::solver::SolverOptions::part_budget`] one part of it (the report
    /// says whether the step is `complete`; the next call continues it).
    /// Returns `None` (and does nothing) when no polygon has unshot power.
    /// Does not look at the threshold or step limit: see
    /// [`Progressive::is_done`].
    pub fn step(&mut self) -> Option<StepReport> {
        self.step_cancellable(&AtomicBool::new(false))
    }

    /// [`Progressive::step`] that gives up as soon as `cancel` is set (from
    /// another thread) and returns `None`, leaving the state exactly as
    /// before the step, or, in a step delivered in parts, as after its
    /// last part (the next call continues it). A window uses it to quit
    /// promptly during a long step.
    pub fn step_cancellable(&mut self, cancel: &AtomicBool) -> Option<StepReport> {
        if self.fault.is_some() {
            return None;
        }
        // A step's first part counts choosing the shooter and reading it
        // (building its strata) against its budget.
        let start = std::time::Instant::now();
        // The gauge reads the step under way; between calls none is.
        if self.sky.underway.is_some() || self.sky_due() {
            let report = self.sky_step(start, cancel);
            self.gauge.idle();
            return report;
        }
        if self.tail.underway.is_some() || (self.underway.is_none() && self.tail_due()) {
            let report = self.tail_step(start, cancel);
            self.gauge.idle();
            return report;
        }
        if self.underway.is_none() {
            let chosen = self.choose_step()?;
            self.underway = Some(self.begin_chosen(chosen)?);
        }
        self.continue_step(start, cancel)
    }

    /// The step that made a non-finite value, if one did
    /// ([`SolverError::NotFinite`]): the solve cannot go on, and
    /// [`Progressive::step`] returns `None` from then on.
    pub fn fault(&self) -> Option<&SolverError> {
        self.fault.as_ref()
    }

    /// Records that step `u`, numbered `step`, made a non-finite value in
    /// `phase`.
    pub(in crate::solver) fn fail(&mut self, step: u64, u: &Underway, phase: StepPhase) {
        self.fault = Some(SolverError::NotFinite {
            step,
            shooter: u.shooter,
            phase,
        });
    }

    /// Whether what the shooter of step `u` sends, as read in phase 2,
    /// is finite: its samples' readings or its cluster's strata.
    pub(in crate::solver) fn read_is_finite(&self, u: &Underway) -> bool {
        match u.how {
            How::Alone => self.shot.iter().all(|s| s.is_finite()),
            How::Cluster { .. } => self.strata.nodes.iter().all(|n| {
                n.power.is_finite()
                    && n.mean_normal.is_finite()
                    && n.centroid.is_finite()
                    && n.axis.is_finite()
                    && n.bins.iter().all(|b| b.0.is_finite() && b.1.is_finite())
            }),
        }
    }

    /// Test hook ([`POISON_READ_AT`]): makes step `u`'s reading NaN when
    /// it is the step asked for.
    #[cfg(test)]
    pub(in crate::solver) fn poison_read(&mut self, u: &Underway) {
        if POISON_READ_AT.get() != self.steps + 1 {
            return;
        }
        let nan = crate::color::Rgb::splat(f64::NAN);
        match u.how {
            How::Alone => self.shot.iter_mut().for_each(|s| *s = nan),
            How::Cluster { .. } => self.strata.nodes.iter_mut().for_each(|n| n.power = nan),
        }
    }

    /// Whether a step delivered in parts ([`crate::solver::SolverOptions::part_budget`])
    /// has begun and not finished: the next [`Progressive::step`]
    /// continues it. The solution then holds the receivers done so far.
    pub fn in_step(&self) -> bool {
        self.underway.is_some() || self.tail.underway.is_some() || self.sky.underway.is_some()
    }

    /// Phase 1 of a step: chooses the shooter and what it sends; `None`
    /// when nothing is due. Changes nothing.
    pub(in crate::solver) fn choose_step(&self) -> Option<Chosen> {
        let expected = self.expectation();
        let (cluster, shot_power, negative) = self.choose_shooter(expected)?;
        let shooter = self.strongest_member(cluster, negative, expected);
        let roots = self.step_roots(shot_power);
        let shot = self.polygon_shot(shooter.index(), negative, expected);
        let signed = if negative { -shot_power } else { shot_power };
        let underway = Underway {
            cluster,
            shooter,
            shot_power: signed,
            expected,
            how: How::Alone,
            plan: parts::Plan::new(1, false, false),
            spent: false,
            gathered: Gathered { pairs: 0, rays: 0 },
            receivers: 0,
            clear: 0,
            part: 0,
            fraction_before: self.last_fraction,
        };
        Some(Chosen {
            underway,
            roots,
            negative,
            shot,
        })
    }

    /// Phase 2 of a progressive step: reads what the chosen shooter sends
    /// (its samples, or a cluster's strata) and marks its receivers;
    /// [`Progressive::continue_step`] then gathers and applies.
    pub(in crate::solver) fn begin_chosen(&mut self, chosen: Chosen) -> Option<Underway> {
        let Chosen {
            mut underway,
            roots,
            negative,
            shot,
        } = chosen;
        let (cluster, shooter, expected) = (underway.cluster, underway.shooter, underway.expected);
        // Emitters, every polygon without clustering and every polygon of
        // a scene where nothing clusters (a room of large walls, where
        // strata would only add work) keep their own samples; a polygon
        // whose light is weak shoots through strata, as a cluster of one.
        let alone = self.clusters.members(cluster).len() == 1
            && (!self.clustered
                || self.clusters.grouped() == 0
                || !self.emission[shooter.index()].is_black()
                || roots >= self.samples[shooter.index()].len());
        let in_parts = self.options.part_budget.is_some();
        if alone {
            self.read_shooter(shooter, shot);
            self.mark_receivers(shooter.index());
            self.group_points.clear();
            self.group_points
                .extend(self.samples[shooter.index()].iter().map(|s| s.position));
            // Reflected light may be interpolated across receiving grids;
            // an emitter's shot, which draws the sharpest shadows, never is.
            let interpolating = self.clustered
                && self.options.approximations.receiver_interpolation
                && self.emission[shooter.index()].is_black();
            let per_vertex = self.samples[shooter.index()].len();
            underway.plan = parts::Plan::new(per_vertex, interpolating, in_parts);
        } else {
            self.read_cluster(cluster, roots, negative, expected);
            self.mark_cluster_receivers();
            let from_top = roots < self.step_roots(f64::INFINITY);
            underway.how = How::Cluster { from_top };
            let per_vertex = self.strata.roots.len();
            let interpolating = self.options.approximations.receiver_interpolation;
            underway.plan = parts::Plan::new(per_vertex, interpolating, in_parts);
        }
        #[cfg(test)]
        self.poison_read(&underway);
        if !self.read_is_finite(&underway) {
            self.fail(self.steps + 1, &underway, StepPhase::Read);
            return None;
        }
        Some(underway)
    }
}
