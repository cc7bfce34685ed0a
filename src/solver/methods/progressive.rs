//! Progressive shooting as a [`Method`]: [`Progressive`] answers every
//! call itself (its state lives in [`crate::solver`], its step's phases
//! in [`crate::solver::step`]).

use crate::cancel::Cancelled;
use crate::color::Rgb;
use crate::mesh::refine::Refiner;
use crate::mesh::{Mesh, MeshRef};
use crate::scene::Scene;
use crate::solver::checkpoint::SolverState;
use crate::solver::{Method, Progressive, SolverError, SolverOptions, StepReport, StopReason};
use std::sync::atomic::AtomicBool;

impl<'a> Method<'a> for Progressive<'a> {
    fn step_cancellable(&mut self, cancel: &AtomicBool) -> Option<StepReport> {
        Progressive::step_cancellable(self, cancel)
    }

    fn in_step(&self) -> bool {
        Progressive::in_step(self)
    }

    fn gauge(&self) -> Option<std::sync::Arc<crate::solver::StepGauge>> {
        Some(std::sync::Arc::clone(&self.gauge))
    }

    fn stop_reason(&self) -> Option<StopReason> {
        Progressive::stop_reason(self)
    }

    fn radiosity(&self) -> &[Rgb] {
        Progressive::radiosity(self)
    }

    fn radiosity_with_ambient(&self, out: &mut Vec<Rgb>) {
        Progressive::radiosity_with_ambient(self, out)
    }

    fn unshot_power(&self) -> f64 {
        Progressive::unshot_power(self)
    }

    fn net_unshot_power(&self) -> f64 {
        Progressive::net_unshot_power(self)
    }

    fn initial_unshot_power(&self) -> f64 {
        Progressive::initial_unshot_power(self)
    }

    fn unshot_fraction(&self) -> f64 {
        Progressive::unshot_fraction(self)
    }

    fn steps(&self) -> u64 {
        Progressive::steps(self)
    }

    fn rays(&self) -> u64 {
        Progressive::rays(self)
    }

    fn pairs(&self) -> u64 {
        Progressive::pairs(self)
    }

    fn receiver_pairs(&self) -> (u64, u64) {
        Progressive::receiver_pairs(self)
    }

    fn particles(&self) -> u64 {
        Progressive::particles(self)
    }

    fn tail_from(&self) -> Option<f64> {
        Progressive::tail_from(self)
    }

    fn mesh(&self) -> &Mesh {
        Progressive::mesh(self)
    }

    fn mesh_ref(&self) -> MeshRef<'a> {
        Progressive::mesh_ref(self)
    }

    fn options(&self) -> &SolverOptions {
        Progressive::options(self)
    }

    fn state(&self) -> SolverState {
        Progressive::state(self)
    }

    fn restore(&mut self, state: SolverState) -> Result<(), SolverError> {
        Progressive::restore(self, state)
    }

    fn refined_state(
        &self,
        scene: &Scene,
        refined: &Mesh,
        refiner: &Refiner,
        cancel: &AtomicBool,
    ) -> Result<Option<SolverState>, Cancelled> {
        Progressive::refined_state(self, scene, refined, refiner, cancel)
    }

    fn validate(&self) -> Result<(), SolverError> {
        Progressive::validate(self)
    }

    fn fault(&self) -> Option<&SolverError> {
        Progressive::fault(self)
    }

    fn values_are_finite(&self) -> bool {
        Progressive::values_are_finite(self)
    }

    fn as_progressive(&self) -> Option<&Progressive<'a>> {
        Some(self)
    }
}
