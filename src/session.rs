//! One solve, from a prepared scene to a converged (and, with adaptive
//! subdivision, refined) solution: the loop every driver runs.
//!
//! A [`Session`] owns the solver (a [`Method`], built by
//! [`crate::solver::build`] from the options), the [`Refiner`] with its
//! element-limit clamp, the per-pass statistics and the choice of what is
//! shown (the solution, or the solution with the ambient term). It
//! advances by one call, [`Session::advance`], which returns what happened
//! as an [`Event`]:
//!
//! ```text
//!   Step … Step  Stopped ─┬─ Finished                       (no refinement)
//!                          ├─ Refined  Step … Step  Stopped …  (next pass)
//!                          └─ Refused  Finished                (element limit)
//! ```
//!
//! The batch driver loops it with a progress bar and checkpoints, the
//! window's worker thread loops it and publishes pictures, the tests loop
//! it bare. Nothing else constructs a [`Refiner`] outside tests.
//!
//! **Refined passes continue the solve.** With per-vertex unshot radiosity
//! the solve on the refined mesh starts from
//! [`Method::refined_state`]: the vertices both meshes share keep
//! their values, the new ones gather the light every polygon has shot so
//! far, and shooting goes on from there. With per-polygon unshot each
//! refined mesh is solved afresh.

use crate::color::Rgb;
use crate::config::RunConfig;
use crate::mesh::refine::{RefineOptions, RefineReport, Refiner, Refused};
use crate::mesh::weld::Weld;
use crate::mesh::{Mesh, MeshRef};
use crate::prepare::Prepared;
use crate::scene::Scene;
use crate::solver::{self, Method, SolverError, SolverOptions, StepReport, StopReason};
use crate::visibility::Visibility;
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// How a session solves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SessionOptions {
    /// Solver settings.
    pub solver: SolverOptions,
    /// Refine and continue after each converged pass, or `None` to solve
    /// the prepared mesh only.
    pub refine: Option<RefineOptions>,
    /// The run's element limit (the smaller of `--max-elements` and the
    /// elements `--max-memory` holds): a refinement is refused (with
    /// [`Event::Refused`]) before its mesh would have more elements than
    /// this or than [`RefineOptions::max_elements`], whichever is smaller.
    pub max_elements: u64,
    /// Show the ambient term ([`Method::radiosity_with_ambient`]) on top
    /// of the solution in [`Session::shown`].
    pub ambient: bool,
}

impl SessionOptions {
    /// The options a run configured by `config` solves `prepared` with
    /// (refined as [`RunConfig::refinement`] says for its mesh);
    /// `ambient_default` is whether the ambient term is shown when the
    /// user did not say (on in the window, off for files).
    pub fn for_run(
        config: &RunConfig,
        prepared: &Prepared,
        ambient_default: bool,
    ) -> SessionOptions {
        SessionOptions {
            solver: config.solver,
            refine: config.refinement(prepared.coarsened),
            // Refinement stops where the memory budget would, too.
            max_elements: config.max_elements.min(config.max_memory.elements_within()),
            ambient: config.ambient.unwrap_or(ambient_default),
        }
    }
}

/// What one [`Session::advance`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// One shooting step on the current mesh, or a part of one
    /// ([`crate::solver::SolverOptions::part_budget`]; see
    /// [`StepReport::complete`]).
    Step(StepReport),
    /// The current pass stopped: converged, or at the step limit. The
    /// session's radiosity is this pass's final solution on
    /// [`Session::mesh`]; the next call refines or finishes.
    Stopped(StopReason),
    /// The mesh was refined where the last pass's solution changes
    /// sharply; a new pass begins on the finer mesh.
    Refined(RefineReport),
    /// A refinement was refused because its mesh would pass the element
    /// limit; the next call finishes.
    Refused(Refused),
    /// The solve is over; every later call says so again.
    Finished,
    /// `cancel` was set during a step; the state is as before that step
    /// (or that part), and the next call tries it again.
    Cancelled,
}

/// One pass of a session: a solve on one mesh and the refinement of its
/// result (written by `--stats` for adaptive runs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassStats {
    /// Mesh elements of this solve.
    pub elements: usize,
    /// Mesh vertices of this solve.
    pub vertices: usize,
    /// Shooting steps it took.
    pub steps: u64,
    /// Shadow rays it cast, the new vertices' gather included.
    pub rays: u64,
    /// Seconds it took, refinement of its result included.
    pub seconds: f64,
    /// Of those, seconds spent refining the mesh after the solve and
    /// gathering the light at the new vertices.
    pub refine_seconds: f64,
    /// Elements its result marked for splitting (0 for the last solve).
    pub split: usize,
    /// Elements over the threshold: `split`, or more when
    /// `--adaptive-max-splits` kept the rest whole.
    pub over_threshold: usize,
    /// Further elements split to keep the mesh conforming.
    pub closure: usize,
}

/// Counts over every pass of a session so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Totals {
    /// Shooting steps (those of a resumed checkpoint included).
    pub steps: u64,
    /// Shadow rays, the gathers at refined vertices included.
    pub rays: u64,
    /// Sample–vertex pairs whose visibility mattered.
    pub pairs: u64,
    /// Shooter–receiver polygon pairs processed.
    pub receiver_pairs: u64,
    /// Of those, the ones whose shaft was clear (no ray cast).
    pub clear_receiver_pairs: u64,
}

/// Where the session is between two calls.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    Solving,
    Stopped(StopReason),
    Finished,
}

/// A solve from a prepared scene to its final solution; see the module
/// docs.
///
/// Invariants: [`Session::mesh`] is the mesh the solver works on; the
/// finished passes' statistics are in `passes`, the current pass's start
/// in `pass_start`.
pub struct Session<'p> {
    scene: &'p Scene,
    visibility: &'p Visibility,
    options: SessionOptions,
    /// The refiner and its options with the element limit applied.
    refiner: Option<(Refiner, RefineOptions)>,
    /// A refined mesh whose carry-over gather an interrupt stopped
    /// ([`Method::refined_state`]): the next [`Session::advance`] gathers
    /// on it again rather than refine a second time.
    pending: Option<(Mesh, RefineReport)>,
    /// The current pass's solver: `None` only inside
    /// [`Session::refine_or_finish`], between dropping one pass's solver
    /// and building the next's.
    solver: Option<Box<dyn Method<'p> + 'p>>,
    phase: Phase,
    passes: Vec<PassStats>,
    /// Counts of the finished passes' solvers.
    finished: Totals,
    pass_start: PassStart,
    /// The smooth surfaces' welded vertices of the current mesh, applied
    /// in [`Session::shown`].
    weld: Weld,
}

/// Where the current pass began: its clock and the solver's counters
/// then (a continued pass starts from the last one's counts).
#[derive(Clone, Copy, Debug)]
struct PassStart {
    time: Instant,
    steps: u64,
    rays: u64,
}

impl<'p> Session<'p> {
    /// Starts a session on `mesh`, which must be built from `scene` (as
    /// must `visibility`).
    pub fn new(
        scene: &'p Scene,
        mesh: &'p Mesh,
        visibility: &'p Visibility,
        options: SessionOptions,
    ) -> Session<'p> {
        let refiner = options.refine.map(|refine| {
            let clamped = RefineOptions {
                max_elements: refine.max_elements.min(options.max_elements),
                ..refine
            };
            (Refiner::new(mesh), clamped)
        });
        let solver = solver::build(scene, mesh, visibility, options.solver);
        Session {
            weld: Weld::new(scene, mesh),
            scene,
            visibility,
            options,
            refiner,
            pending: None,
            solver: Some(solver),
            phase: Phase::Solving,
            passes: Vec::new(),
            finished: Totals::default(),
            pass_start: PassStart {
                time: Instant::now(),
                steps: 0,
                rays: 0,
            },
        }
    }

    /// Starts a session on a prepared scene's mesh.
    pub fn from_prepared(prepared: &'p Prepared, options: SessionOptions) -> Session<'p> {
        Session::new(
            &prepared.scene,
            &prepared.mesh,
            prepared.visibility(),
            options,
        )
    }

    /// Continues from a saved state of a solve of the same scene, mesh and
    /// solver options (a checkpoint), before the first step. Its steps and
    /// rays count as this session's.
    pub fn restore(
        &mut self,
        state: crate::solver::checkpoint::SolverState,
    ) -> Result<(), SolverError> {
        self.solver_mut().restore(state)
    }

    /// Does the next thing: one shooting step, the end of a pass, a
    /// refinement, or nothing once finished (see [`Event`]). Stops a step
    /// promptly once `cancel` is set. Fails only if a step made a value
    /// that is not finite ([`crate::solver::Progressive::fault`]) or a
    /// refined pass could not take over the last one's state, which are
    /// bugs.
    pub fn advance(&mut self, cancel: &AtomicBool) -> Result<Event, SolverError> {
        match self.phase {
            Phase::Finished => Ok(Event::Finished),
            Phase::Stopped(reason) => self.refine_or_finish(reason, cancel),
            Phase::Solving => {
                if let Some(reason) = self.solver().stop_reason() {
                    self.phase = Phase::Stopped(reason);
                    return Ok(Event::Stopped(reason));
                }
                let stepped = self.solver_mut().step_cancellable(cancel);
                // A step that made a non-finite value ends the solve; its
                // report, if it finished, is not passed on.
                if let Some(fault) = self.solver().fault() {
                    return Err(fault.clone());
                }
                match stepped {
                    Some(report) => Ok(Event::Step(report)),
                    None if cancel.load(Ordering::SeqCst) => Ok(Event::Cancelled),
                    // Nothing left to shoot: converged.
                    None => {
                        self.phase = Phase::Stopped(StopReason::Converged);
                        Ok(Event::Stopped(StopReason::Converged))
                    }
                }
            }
        }
    }

    /// Advances until the session finishes (`Ok(true)`) or `cancel` is set
    /// (`Ok(false)`), dropping the events: for callers that want only the
    /// final solution (examples, measurements). A refused refinement is
    /// not reported; see [`Session::passes`].
    pub fn run_to_end(&mut self, cancel: &AtomicBool) -> Result<bool, SolverError> {
        loop {
            match self.advance(cancel)? {
                Event::Finished => return Ok(true),
                Event::Cancelled => return Ok(false),
                _ => {}
            }
        }
    }

    /// After a pass stopped: refines and starts the next pass, or closes
    /// the session. A pass cut short by the step limit is not refined
    /// (that would mark what is merely unfinished); nor one after the
    /// allowed levels, nor one whose refinement would pass the element
    /// limit. The gather that carries the solution over to the refined
    /// mesh stops once `cancel` is set: this returns [`Event::Cancelled`],
    /// the session still on its mesh, and keeps the refined mesh for the
    /// next call to gather on again.
    fn refine_or_finish(
        &mut self,
        reason: StopReason,
        cancel: &AtomicBool,
    ) -> Result<Event, SolverError> {
        let refining = Instant::now();
        let mut next = None;
        let mut refused = None;
        let held = held(&self.solver);
        if let Some((refiner, options)) = &mut self.refiner {
            let refined = match self.pending.take() {
                Some(pending) => Some(pending),
                None if reason == StopReason::Converged && refiner.passes() < options.levels => {
                    let luminance: Vec<f64> =
                        held.radiosity().iter().map(|b| b.luminance()).collect();
                    let refined = refiner.refine(self.scene, &luminance, options);
                    if refined.is_none() {
                        refused = refiner.refused();
                    }
                    refined
                }
                None => None,
            };
            if let Some((mesh, report)) = refined {
                match held.refined_state(self.scene, &mesh, refiner, cancel) {
                    Ok(start) => next = Some((mesh, report, start)),
                    Err(crate::cancel::Cancelled) => {
                        self.pending = Some((mesh, report));
                        return Ok(Event::Cancelled);
                    }
                }
            }
        }
        let mut pass = self.pass_stats();
        let Some((mesh, report, start)) = next else {
            pass.refine_seconds = refining.elapsed().as_secs_f64();
            pass.seconds = self.pass_start.time.elapsed().as_secs_f64();
            self.close_pass(pass);
            self.phase = Phase::Finished;
            return Ok(match refused {
                Some(refused) => Event::Refused(refused),
                None => Event::Finished,
            });
        };
        // The gather for the new vertices is this pass's work too.
        if let Some(state) = &start {
            pass.rays += state.rays - self.solver().rays();
        }
        pass.split = report.marked;
        pass.closure = report.closure;
        pass.over_threshold = report.over_threshold;
        pass.refine_seconds = refining.elapsed().as_secs_f64();
        pass.seconds = self.pass_start.time.elapsed().as_secs_f64();
        self.close_pass(pass);
        // This pass's solver goes before the next one is built: both at
        // once set a refinement's peak memory (`pandora.obj`: 887 MB,
        // against 688 MB just before the build). A carried state that
        // fails to restore leaves the new solver as built, a consistent
        // start on the refined mesh, and the error is returned.
        self.solver = None;
        let mut solver = solver::build(
            self.scene,
            Arc::new(mesh),
            self.visibility,
            self.options.solver,
        );
        let restored = start.map_or(Ok(()), |state| solver.restore(state));
        self.weld = Weld::new(self.scene, solver.mesh());
        self.pass_start = PassStart {
            time: Instant::now(),
            steps: solver.steps(),
            rays: solver.rays(),
        };
        self.solver = Some(solver);
        self.phase = Phase::Solving;
        restored?;
        Ok(Event::Refined(report))
    }

    /// The current pass's statistics so far (times and refinement not
    /// filled in).
    fn pass_stats(&self) -> PassStats {
        let mesh = self.mesh();
        PassStats {
            elements: mesh.elements.len(),
            vertices: mesh.vertex_count(),
            steps: self.solver().steps() - self.pass_start.steps,
            rays: self.solver().rays() - self.pass_start.rays,
            seconds: 0.0,
            refine_seconds: 0.0,
            split: 0,
            over_threshold: 0,
            closure: 0,
        }
    }

    /// Records a finished pass and its solver's counts.
    fn close_pass(&mut self, pass: PassStats) {
        let (receivers, clear) = self.solver().receiver_pairs();
        self.finished.steps += pass.steps;
        self.finished.rays += pass.rays;
        self.finished.pairs += self.solver().pairs();
        self.finished.receiver_pairs += receivers;
        self.finished.clear_receiver_pairs += clear;
        self.passes.push(pass);
    }

    /// Whether the session refines its mesh after a converged pass
    /// ([`SessionOptions::refine`]).
    pub fn refines(&self) -> bool {
        self.refiner.is_some()
    }

    /// True once [`Event::Finished`] (or [`Event::Refused`]) was returned.
    pub fn is_finished(&self) -> bool {
        self.phase == Phase::Finished
    }

    /// The solver of the current pass.
    pub fn solver(&self) -> &(dyn Method<'p> + 'p) {
        held(&self.solver)
    }

    /// The solver of the current pass, to step or restore.
    fn solver_mut(&mut self) -> &mut (dyn Method<'p> + 'p) {
        self.solver
            .as_deref_mut()
            .expect("a session holds a solver outside refine_or_finish")
    }

    /// The mesh of the current pass: the prepared one, or its latest
    /// refinement.
    pub fn mesh(&self) -> &Mesh {
        self.solver().mesh()
    }

    /// The mesh of the current pass as a cheap handle another thread or a
    /// later stage can keep.
    pub fn mesh_ref(&self) -> MeshRef<'p> {
        self.solver().mesh_ref()
    }

    /// The options it was started with.
    pub fn options(&self) -> &SessionOptions {
        &self.options
    }

    /// The pass running now, from 1.
    pub fn pass(&self) -> u32 {
        self.passes.len() as u32 + u32::from(!self.is_finished())
    }

    /// The most refinements that can follow the first pass (0 without
    /// adaptive subdivision).
    pub fn max_refinements(&self) -> u32 {
        self.refiner.as_ref().map_or(0, |(_, o)| o.levels)
    }

    /// The finished passes, the first one first. The last pass is among
    /// them once the session is finished.
    pub fn passes(&self) -> &[PassStats] {
        &self.passes
    }

    /// Counts over every pass so far, the current one included.
    pub fn totals(&self) -> Totals {
        let mut totals = self.finished;
        if !self.is_finished() {
            let (receivers, clear) = self.solver().receiver_pairs();
            totals.steps += self.solver().steps() - self.pass_start.steps;
            totals.rays += self.solver().rays() - self.pass_start.rays;
            totals.pairs += self.solver().pairs();
            totals.receiver_pairs += receivers;
            totals.clear_receiver_pairs += clear;
        }
        totals
    }

    /// The radiosity per vertex of [`Session::mesh`], in the scene's
    /// emission units.
    pub fn radiosity(&self) -> &[Rgb] {
        self.solver().radiosity()
    }

    /// The radiosity to draw, written into `out` (resized to the vertex
    /// count): with the ambient term when [`SessionOptions::ambient`] asks
    /// for it, else the solution itself; then made continuous across the
    /// facet edges of smooth surfaces ([`Weld::apply`]). The one place
    /// the window, the pictures and the mesh exports get their values.
    pub fn shown(&self, out: &mut Vec<Rgb>) {
        if self.options.ambient {
            self.solver().radiosity_with_ambient(out);
            self.weld.apply(out);
        } else {
            self.solution(out);
        }
    }

    /// The solution without the ambient term, made continuous across the
    /// facet edges of smooth surfaces like [`Session::shown`]: what a mesh
    /// export carries.
    pub fn solution(&self, out: &mut Vec<Rgb>) {
        out.clear();
        out.extend_from_slice(self.solver().radiosity());
        self.weld.apply(out);
    }

    /// The welded vertices of the current mesh (see [`Session::shown`]).
    pub fn weld(&self) -> &Weld {
        &self.weld
    }

    /// Unshot power left as a fraction of the emitted power, on the
    /// current mesh.
    pub fn unshot_fraction(&self) -> f64 {
        self.solver().unshot_fraction()
    }

    /// True when the last pass reached the threshold (false while solving
    /// or when it stopped at the step limit).
    pub fn converged(&self) -> bool {
        self.solver().stop_reason() == Some(StopReason::Converged) && self.phase != Phase::Solving
    }

    /// Checks the solver's invariants.
    pub fn validate(&self) -> Result<(), SolverError> {
        self.solver().validate()
    }
}

/// The solver in a session's slot, which holds one outside
/// [`Session::refine_or_finish`].
fn held<'s, 'p>(slot: &'s Option<Box<dyn Method<'p> + 'p>>) -> &'s (dyn Method<'p> + 'p) {
    slot.as_deref()
        .expect("a session holds a solver outside refine_or_finish")
}

#[cfg(test)]
mod tests;
