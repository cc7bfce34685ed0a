//! The hemicube as a solver [`Method`]: `--form-factor hemicube`.
//!
//! A [`HemicubeMethod`] is a progressive solve ([`Progressive`]) whose
//! steps it takes itself from progressive shooting's shared phases and
//! two of its own:
//!
//! 1. choose the shooter and what it sends ([`crate::solver::step::choose`]);
//! 2. read it at the shooter's samples, merged into fewer hemicubes for a
//!    weak step ([`Progressive::hemicube_points`]), and mark its receivers;
//! 3. render a hemicube at each point and spread what the elements
//!    receive to their vertices ([`Shooting::gather`]): all receivers at
//!    once, so a hemicube step is always one part;
//! 4. apply the step and report it ([`crate::solver::step::apply`]).
//!
//! Every polygon shoots alone (no clusters; every receiver exact). A sky
//! facet, which a hemicube cannot hold (it stands for a direction, not a
//! place), shoots by Wallace's rays: its step is handed to progressive
//! shooting whole, in parts when asked. Everything else a driver asks
//! (radiosity, counts, checkpoints, the carry to a refined mesh) is the
//! progressive solve's.

use super::{HemicubeRes, Shooting};
use crate::cancel::Cancelled;
use crate::color::Rgb;
use crate::mesh::refine::Refiner;
use crate::mesh::{Mesh, MeshRef};
use crate::scene::{PolygonId, Scene};
use crate::solver::accel::cluster::{Cell, Strata};
use crate::solver::checkpoint::SolverState;
use crate::solver::kernel::formfactor::ShooterSample;
use crate::solver::step::gather::Gathered;
use crate::solver::step::{Chosen, StepPhase};
use crate::solver::unshot::Shot;
use crate::solver::{Method, Progressive, SolverError, SolverOptions, StepReport, StopReason};
use crate::visibility::Visibility;
use std::sync::atomic::AtomicBool;

/// A progressive solve that shoots by hemicubes; see the module docs.
///
/// Invariants: those of [`Progressive`]; `shooting` was built for the
/// progressive solve's scene, mesh and [`SolverOptions::hemicube_res`].
pub struct HemicubeMethod<'a> {
    /// The solve's state and its shared phases.
    pub(in crate::solver) progressive: Progressive<'a>,
    /// The delta form factors, every polygon's corners, and scratch.
    shooting: Shooting,
}

impl<'a> HemicubeMethod<'a> {
    /// Starts a solve as [`Progressive::new`] does, shooting by hemicubes
    /// of [`SolverOptions::hemicube_res`] pixels. `mesh` and `visibility`
    /// must be built from `scene`.
    pub fn new(
        scene: &Scene,
        mesh: impl Into<MeshRef<'a>>,
        visibility: &'a Visibility,
        options: SolverOptions,
    ) -> Self {
        let progressive = Progressive::new(scene, mesh, visibility, options);
        let res: HemicubeRes = options.hemicube_res;
        let shooting = Shooting::new(scene, progressive.mesh(), res);
        HemicubeMethod {
            progressive,
            shooting,
        }
    }

    /// The progressive solve it shoots by hemicubes.
    pub fn progressive(&self) -> &Progressive<'a> {
        &self.progressive
    }

    /// A whole hemicube step of the `chosen` shooter (not a sky facet):
    /// `None` once `cancel` is set, with only scratch written.
    fn shoot(&mut self, chosen: Chosen, cancel: &AtomicBool) -> Option<StepReport> {
        let Chosen {
            mut underway,
            roots,
            shot,
            ..
        } = chosen;
        let shooter = underway.shooter;
        // A hemicube step renders all its receivers at once: one part.
        self.progressive.read_shooter(shooter, shot);
        self.progressive.mark_receivers(shooter.index());
        let hemicubes = if self.progressive.options().approximations.clusters {
            roots
        } else {
            usize::MAX
        };
        #[cfg(test)]
        self.progressive.poison_read(&underway);
        if !self.progressive.read_is_finite(&underway) {
            let step = self.progressive.steps + 1;
            self.progressive.fail(step, &underway, StepPhase::Read);
            return None;
        }
        let gathered = self.gather(shooter, shot, hemicubes, cancel)?;
        let p = &mut self.progressive;
        let polygons = 0..p.mesh.polygons.len();
        if !p.gathered_is_finite(polygons.clone()) {
            p.fail(p.steps + 1, &underway, StepPhase::Gather);
            return None;
        }
        p.apply_chunk(&mut underway, polygons);
        underway.gathered = gathered;
        underway.part = 1;
        Some(p.finish_step(&underway))
    }

    /// Phase 3 by hemicubes ([`Shooting::gather`]): `Δrad` of every
    /// receiving vertex into the solve's scratch, from what `shot` sends
    /// (read into its samples' scratch), from at most `hemicubes`
    /// hemicubes ([`Progressive::hemicube_points`]).
    fn gather(
        &mut self,
        shooter: PolygonId,
        shot: Shot,
        hemicubes: usize,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        let p = &mut self.progressive;
        let i = shooter.index();
        let power = p.unshot.sent_power(&p.mesh, i, shot, &p.radiosity);
        let merged = p.hemicube_points(shooter, hemicubes);
        let (samples, shot) = match &merged {
            Some((samples, shot)) => (&samples[..], &shot[..]),
            None => (&p.samples[i][..], &p.shot[..]),
        };
        let pairs = self.shooting.gather(
            &p.mesh,
            i,
            p.directional[i].as_ref(),
            samples,
            shot,
            power,
            &p.receives,
            &p.reflectance,
            &mut p.delta,
            cancel,
        )?;
        Some(Gathered { pairs, rays: 0 })
    }
}

impl<'a> Progressive<'a> {
    /// Where a hemicube step of `shooter` places its hemicubes when it may
    /// use at most `hemicubes` ([`Progressive::step_roots`]: fewer the
    /// weaker the step's light): `None` when the shooter's own samples
    /// are few enough (one hemicube each, carrying `self.shot`). Else its
    /// cells are merged into that many runs, the cut of their
    /// [`Strata`] as a cluster's weak step takes it, each a hemicube at
    /// the run's power-weighted centroid (on the polygon, which is
    /// convex) carrying the run's area and its mean unshot radiosity: the
    /// same power, from fewer points. A run is a coarser quadrature of
    /// the shooter, which only receivers within a few runs' widths notice,
    /// and a weak step carries too little light for that to show.
    pub(in crate::solver) fn hemicube_points(
        &self,
        shooter: PolygonId,
        hemicubes: usize,
    ) -> Option<(Vec<ShooterSample>, Vec<Rgb>)> {
        let i = shooter.index();
        let samples = &self.samples[i];
        if hemicubes >= samples.len() {
            return None;
        }
        let normal = self.mesh.polygons[i].normal;
        let cells: Vec<Cell> = samples
            .iter()
            .zip(&self.shot)
            .enumerate()
            .map(|(k, (sample, &unshot))| Cell {
                polygon: shooter,
                sample: k as u32,
                unshot,
                area: sample.area,
                normal,
                power: unshot.mean() * sample.area,
            })
            .filter(|c| c.power > 0.0)
            .collect();
        let strata = Strata::build(&cells, hemicubes, |c| {
            samples[cells[c].sample as usize].bounds()
        });
        let mut points = Vec::with_capacity(strata.roots.len());
        let mut shot = Vec::with_capacity(strata.roots.len());
        for &r in &strata.roots {
            let node = &strata.nodes[r as usize];
            let run = node.cells.start as usize..node.cells.end as usize;
            let area: f64 = cells[run].iter().map(|c| c.area).sum();
            if area <= 0.0 {
                continue;
            }
            points.push(ShooterSample::point(node.centroid, area));
            shot.push(node.power / area);
        }
        Some((points, shot))
    }
}

impl<'a> Method<'a> for HemicubeMethod<'a> {
    fn step_cancellable(&mut self, cancel: &AtomicBool) -> Option<StepReport> {
        if self.progressive.fault().is_some() {
            return None;
        }
        // A sky facet's step, once begun in parts, continues as it began.
        if self.progressive.in_step() {
            return self.progressive.step_cancellable(cancel);
        }
        let start = std::time::Instant::now();
        let chosen = self.progressive.choose_step()?;
        let p = &mut self.progressive;
        if !p.mesh.polygons[chosen.underway.shooter.index()].sky {
            return self.shoot(chosen, cancel);
        }
        // A sky facet shoots by Wallace's rays.
        let underway = p.begin_chosen(chosen)?;
        p.underway = Some(underway);
        p.continue_step(start, cancel)
    }

    fn in_step(&self) -> bool {
        self.progressive.in_step()
    }

    fn stop_reason(&self) -> Option<StopReason> {
        self.progressive.stop_reason()
    }

    fn radiosity(&self) -> &[Rgb] {
        self.progressive.radiosity()
    }

    fn radiosity_with_ambient(&self, out: &mut Vec<Rgb>) {
        self.progressive.radiosity_with_ambient(out)
    }

    fn unshot_power(&self) -> f64 {
        self.progressive.unshot_power()
    }

    fn net_unshot_power(&self) -> f64 {
        self.progressive.net_unshot_power()
    }

    fn initial_unshot_power(&self) -> f64 {
        self.progressive.initial_unshot_power()
    }

    fn unshot_fraction(&self) -> f64 {
        self.progressive.unshot_fraction()
    }

    fn steps(&self) -> u64 {
        self.progressive.steps()
    }

    fn rays(&self) -> u64 {
        self.progressive.rays()
    }

    fn pairs(&self) -> u64 {
        self.progressive.pairs()
    }

    fn receiver_pairs(&self) -> (u64, u64) {
        self.progressive.receiver_pairs()
    }

    fn mesh(&self) -> &Mesh {
        self.progressive.mesh()
    }

    fn mesh_ref(&self) -> MeshRef<'a> {
        self.progressive.mesh_ref()
    }

    fn options(&self) -> &SolverOptions {
        self.progressive.options()
    }

    fn state(&self) -> SolverState {
        self.progressive.state()
    }

    fn restore(&mut self, state: SolverState) -> Result<(), SolverError> {
        self.progressive.restore(state)
    }

    /// The progressive solve's carry ([`Progressive::refined_state`]): the
    /// new vertices gather by Wallace's rays.
    fn refined_state(
        &self,
        scene: &Scene,
        refined: &Mesh,
        refiner: &Refiner,
        cancel: &AtomicBool,
    ) -> Result<Option<SolverState>, Cancelled> {
        self.progressive
            .refined_state(scene, refined, refiner, cancel)
    }

    fn validate(&self) -> Result<(), SolverError> {
        self.progressive.validate()
    }

    fn fault(&self) -> Option<&SolverError> {
        self.progressive.fault()
    }

    fn values_are_finite(&self) -> bool {
        self.progressive.values_are_finite()
    }

    fn as_progressive(&self) -> Option<&Progressive<'a>> {
        Some(&self.progressive)
    }
}
