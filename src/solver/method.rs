//! The seam between a solve and its drivers: [`Method`], what every
//! solver method offers the session, the batch run, the window and the
//! tests, and [`build`], which chooses the method from the options.
//!
//! A method owns a solution on one mesh and advances it a step at a time
//! (after rpkCpp's `RadianceMethod`, whose `doStep` and `getRadiance` it
//! mirrors, and pbrt-v4's `Integrator`): a driver asks it whether to stop,
//! steps it, reads its radiosity per mesh vertex and its counts, saves and
//! restores its state for checkpoints, and hands its solution on to a
//! refined mesh. Nothing a driver calls depends on how the method shoots,
//! gathers or iterates.
//!
//! Today's methods ([`super::methods`]): progressive shooting with
//! Wallace's ray-traced form factors or the centre estimate
//! ([`super::Progressive`]), and the hemicube
//! ([`super::methods::hemicube::HemicubeMethod`]), which composes
//! progressive shooting's phases with its own reading and gathering.

use super::checkpoint::SolverState;
use super::methods::hemicube::HemicubeMethod;
use super::{FormFactorMethod, Progressive, SolverError, SolverOptions, StepReport, StopReason};
use crate::cancel::Cancelled;
use crate::color::Rgb;
use crate::mesh::refine::Refiner;
use crate::mesh::{Mesh, MeshRef};
use crate::scene::Scene;
use crate::visibility::Visibility;
use std::sync::atomic::AtomicBool;

/// A radiosity solver method: a solution on one mesh of one scene that is
/// advanced one step at a time until [`Method::stop_reason`] says to stop.
///
/// Radiosity is exitance per mesh vertex, in the units of the scene's
/// emission; power is radiosity × area, in those units times square scene
/// units. What a *step* is belongs to the method (one shooter's light for
/// progressive shooting, one sweep for a Jacobi iteration); the counts a
/// method cannot give (shadow rays of a method that casts none) stay 0.
///
/// Invariants every method keeps between calls (checked by
/// [`Method::validate`]): one finite, non-negative radiosity per vertex
/// of [`Method::mesh`]; its state is a function of the scene, the mesh,
/// the options and the steps taken, and not of the thread count, so a
/// solve gives the same bits on any machine.
pub trait Method<'a> {
    /// One step, or with [`SolverOptions::part_budget`] one part of it
    /// ([`StepReport::complete`] says whether the step is finished; the
    /// next call continues it). `None` when nothing is left to do (the
    /// solution has converged as far as the method can take it), or once
    /// `cancel` is set (from another thread), which a method checks often
    /// enough to return promptly; a cancelled call leaves the state as
    /// before it, and the next call tries the step (or part) again. Does
    /// not look at the threshold or step limit: see
    /// [`Method::stop_reason`].
    fn step_cancellable(&mut self, cancel: &AtomicBool) -> Option<StepReport>;

    /// [`Method::step_cancellable`] without a way to cancel.
    fn step(&mut self) -> Option<StepReport> {
        self.step_cancellable(&AtomicBool::new(false))
    }

    /// Whether a step delivered in parts has begun and not finished: the
    /// next [`Method::step`] continues it, and the solution holds the
    /// part done so far. Never true without
    /// [`SolverOptions::part_budget`].
    fn in_step(&self) -> bool;

    /// Why the solve should stop now, or `None` to go on: converged by
    /// the method's own rule under [`SolverOptions::threshold`], or at
    /// [`SolverOptions::max_steps`]. Always `None` while
    /// [`Method::in_step`].
    fn stop_reason(&self) -> Option<StopReason>;

    /// True when [`Method::stop_reason`] says to stop.
    fn is_done(&self) -> bool {
        self.stop_reason().is_some()
    }

    /// Radiosity per vertex of [`Method::mesh`], in the scene's emission
    /// units: the solution so far.
    fn radiosity(&self) -> &[Rgb];

    /// The radiosity to show while unconverged, written into `out`
    /// (resized to the vertex count): the solution plus the method's
    /// estimate of the light still missing from it (for progressive
    /// shooting, the ambient term), at least 0 per channel. For display
    /// only; the solution is not changed.
    fn radiosity_with_ambient(&self, out: &mut Vec<Rgb>);

    /// Power still to be distributed, in radiosity × area units: how far
    /// the solution is from converged, `>= 0`, tending to 0.
    fn unshot_power(&self) -> f64;

    /// The signed power still to be distributed (light still to send less
    /// light sent ahead), in radiosity × area units: energy balance reads
    /// it, emitted = absorbed + escaped + this. Equal to
    /// [`Method::unshot_power`] for a method that never sends ahead.
    fn net_unshot_power(&self) -> f64;

    /// [`Method::unshot_power`] before the first step (the emitted power,
    /// as the method weighs it).
    fn initial_unshot_power(&self) -> f64;

    /// [`Method::unshot_power`] as a fraction of
    /// [`Method::initial_unshot_power`], in `[0, ∞)`; 0 when nothing
    /// emits. The threshold is read against it.
    fn unshot_fraction(&self) -> f64;

    /// Steps taken so far (a restored state's included).
    fn steps(&self) -> u64;

    /// Shadow rays cast so far (a restored state's included).
    fn rays(&self) -> u64;

    /// Sample–vertex pairs whose visibility mattered so far: rays cast
    /// plus rays saved (clear shafts, or a form factor read off a buffer).
    fn pairs(&self) -> u64;

    /// Shooter–receiver polygon pairs processed so far, and how many of
    /// them needed no shadow ray at all.
    fn receiver_pairs(&self) -> (u64, u64);

    /// Particles the method's particle tail has traced so far
    /// ([`super::step::tail`]); 0 for a method without one.
    fn particles(&self) -> u64 {
        0
    }

    /// The unshot fraction at or below which the particle tail takes
    /// over ([`super::step::tail`]), as this solve resolved
    /// [`super::SolverOptions::tail`]; `None` without one.
    fn tail_from(&self) -> Option<f64> {
        None
    }

    /// How far the step under way has got, for a progress display on
    /// another thread ([`super::gauge`]); `None` for a method whose steps
    /// do not report it.
    fn gauge(&self) -> Option<std::sync::Arc<super::StepGauge>> {
        None
    }

    /// The mesh it solves on.
    fn mesh(&self) -> &Mesh;

    /// The mesh it solves on, as a handle that can outlive this method.
    fn mesh_ref(&self) -> MeshRef<'a>;

    /// The options it runs with.
    fn options(&self) -> &SolverOptions;

    /// A copy of everything [`Method::restore`] needs to continue this
    /// solve bit for bit (a checkpoint, [`super::checkpoint`]). Taken
    /// between steps, not while [`Method::in_step`].
    fn state(&self) -> SolverState;

    /// Replaces the solve's state by one saved from a solve of the same
    /// scene, mesh and options, before or between steps; refuses (and
    /// changes nothing) when the state does not fit this solve.
    fn restore(&mut self, state: SolverState) -> Result<(), SolverError>;

    /// The state a solve on `refined` starts from to continue this one
    /// rather than start afresh ([`Method::restore`] it into a method
    /// built on `refined`), or `None` when this method starts a refined
    /// mesh afresh. `refined` must be the mesh `refiner` returned last,
    /// refining this solve's mesh; rays cast to carry the solution over
    /// are counted in the state's [`SolverState::rays`]. Stops promptly
    /// with [`Cancelled`] once `cancel` is set (this solve unchanged).
    fn refined_state(
        &self,
        scene: &Scene,
        refined: &Mesh,
        refiner: &Refiner,
        cancel: &AtomicBool,
    ) -> Result<Option<SolverState>, Cancelled>;

    /// Checks the invariants; returns the first broken one.
    fn validate(&self) -> Result<(), SolverError>;

    /// The step that made a non-finite value, if one did
    /// ([`SolverError::NotFinite`]): the method then takes no more steps,
    /// and its solution is the last good step's unless the failure came
    /// in applying.
    fn fault(&self) -> Option<&SolverError>;

    /// Whether every radiosity and unshot value is finite (a pass over
    /// the mesh: for checks, not for every step).
    fn values_are_finite(&self) -> bool;

    /// The progressive shooter underneath, for measurements of its
    /// internals (its clusters); `None` for a method that is not
    /// progressive shooting.
    fn as_progressive(&self) -> Option<&Progressive<'a>> {
        None
    }
}

/// The method `options` ask for ([`SolverOptions::form_factor`]), starting
/// a solve of `scene` on `mesh` (every vertex at its emission): the
/// hemicube for [`FormFactorMethod::Hemicube`], else progressive
/// shooting. `mesh` and `visibility` must be built from `scene`.
pub fn build<'a>(
    scene: &Scene,
    mesh: impl Into<MeshRef<'a>>,
    visibility: &'a Visibility,
    options: SolverOptions,
) -> Box<dyn Method<'a> + 'a> {
    match options.form_factor {
        FormFactorMethod::Hemicube => {
            Box::new(HemicubeMethod::new(scene, mesh, visibility, options))
        }
        FormFactorMethod::Wallace | FormFactorMethod::Center => {
            Box::new(Progressive::new(scene, mesh, visibility, options))
        }
    }
}
