//! The sky step: every sky facet's unshot light at once, each receiving
//! vertex gathering it over its own hemisphere of directions
//! ([`crate::solver::accel::sky_dome`]).
//!
//! The step is due while a sky facet holds light and no other step is
//! under way, so under `--sky` it is the first: it replaces the 80 steps
//! of shooting the sky facet by facet. It gathers the element vertices
//! in index order, in chunks of [`SKY_CHUNK_VERTICES`] gathered in
//! parallel; with a part budget
//! ([`crate::solver::SolverOptions::part_budget`]) it applies each
//! polygon once all its vertices are gathered and returns between
//! chunks, so a window shows the sky arriving; without one it applies
//! them all at the end, so a cancelled step leaves nothing changed. Vertices that receive as one
//! ([`crate::solver::accel::shared`]) take their leader's value, and a
//! vertex asks from the centroid of the elements around it (of its whole
//! group's, for a leader: [`crate::solver::accel::hat`]). The bits
//! do not depend on the thread count or on the parts. The step's gauge
//! ([`crate::solver::gauge`]) counts the vertices that have gathered.

use crate::color::Rgb;
use crate::scene::PolygonId;
use crate::solver::accel::hat::Hats;
use crate::solver::accel::shared::ALONE;
use crate::solver::accel::sky_dome::{Dome, Hemisphere, SkyLight};
use crate::solver::step::StepPhase;
use crate::solver::tuning::{SKY_CELLS, SKY_CELL_STRATA, SKY_CHUNK_VERTICES};
use crate::solver::unshot::Shot;
use crate::solver::{Progressive, SolverError, StepReport};
use crate::visibility::LastBlocker;
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The sky step's tables, and the step under way.
#[derive(Debug)]
pub(in crate::solver) struct SkyGather {
    /// The directions and the dome, when the sky is gathered at once
    /// (the switch is on, the solve clusters and the scene has a sky).
    tables: Option<(Hemisphere, Dome)>,
    /// Whether a vertex's probes may answer for their cells.
    probing: bool,
    /// Whether a vertex asks from its hat's centroid
    /// ([`crate::solver::accel::hat`]).
    hat_centroids: bool,
    /// The sky step begun and not finished, when steps come in parts.
    pub(in crate::solver) underway: Option<Box<SkyUnderway>>,
}

impl SkyGather {
    /// The sky step of `mesh`: on when `on` and the mesh has a sky.
    pub(in crate::solver) fn new(
        mesh: &crate::mesh::Mesh,
        on: bool,
        probing: bool,
        hat_centroids: bool,
    ) -> SkyGather {
        SkyGather {
            tables: on
                .then(|| Dome::new(mesh))
                .flatten()
                .map(|dome| (Hemisphere::new(SKY_CELLS, SKY_CELL_STRATA), dome)),
            probing,
            hat_centroids,
            underway: None,
        }
    }
}

/// A sky step under way.
#[derive(Debug)]
pub(in crate::solver) struct SkyUnderway {
    /// What the facets sent, read when the step began.
    light: SkyLight,
    /// The power they sent, weighted as [`Progressive::unshot_power`].
    shot_power: f64,
    /// The vertices before this one are gathered.
    next: usize,
    /// The polygons before this one are applied.
    applied: usize,
    /// Per vertex, what it gathered before its reflectance (for a vertex
    /// evaluated itself; black for the others until then).
    gathered: Vec<Rgb>,
    rays: u64,
    receivers: u64,
    /// Vertices that gather themselves, and how many have: the step's
    /// gauge ([`crate::solver::gauge`]).
    heads: u64,
    heads_done: u64,
    /// Parts delivered so far.
    part: u32,
    /// Whether the facets' unshot light has been spent.
    spent: bool,
    /// The elements around each vertex, when it asks from its hat's
    /// centroid.
    hats: Option<Hats>,
    /// The unshot fraction before the step.
    fraction_before: f64,
}

impl<'a> Progressive<'a> {
    /// Whether polygon `j` receives sky light: it reflects, it has
    /// vertices, and it is not the sky.
    fn receives_sky(&self, j: usize) -> bool {
        let pm = &self.mesh.polygons[j];
        !pm.sky && pm.vertex_count() > 0 && !self.reflectance[j].is_black()
    }

    /// Whether a vertex asks the sky from its hat's centroid
    /// ([`crate::solver::accel::hat`]).
    pub(in crate::solver) fn hat_centroids(&self) -> bool {
        self.sky.hat_centroids
    }

    /// Whether element vertex `l` gathers the sky itself: its polygon
    /// receives, and it is not a shared receiver's follower.
    fn gathers_sky(&self, l: usize) -> bool {
        self.receives_sky(self.mesh.vertex_polygon[l].index())
            && self.leaders.get(l).is_none_or(|&x| x == ALONE)
    }

    /// What the sky's facets hold now, `None` when the sky is shot by
    /// facets.
    fn sky_light(&self) -> Option<SkyLight> {
        let (_, dome) = self.sky.tables.as_ref()?;
        Some(SkyLight::of(dome, |j| self.unshot.mean(&self.mesh, j)))
    }

    /// Whether the next step is a sky step: the sky is gathered at once,
    /// no other step is under way, and some facet holds light.
    pub(in crate::solver) fn sky_due(&self) -> bool {
        self.underway.is_none()
            && self.tail.underway.is_none()
            && self.sky_light().is_some_and(|l| !l.is_black())
    }

    /// One sky step ([module docs](self)), or with a part budget the
    /// chunks that fit in it since `start` (the report says whether the
    /// step is complete). `None` when cancelled (without a part budget
    /// nothing changed; with one, the next call continues after the last
    /// part), when nothing is left to shoot, or when a value stopped being
    /// finite ([`Progressive::fault`]).
    pub(in crate::solver) fn sky_step(
        &mut self,
        start: std::time::Instant,
        cancel: &AtomicBool,
    ) -> Option<StepReport> {
        let mut u = match self.sky.underway.take() {
            Some(u) => u,
            None => Box::new(self.begin_sky()?),
        };
        let budget = self.options.part_budget;
        let vertices = self.mesh.vertex_count();
        let mut longest = std::time::Duration::ZERO;
        self.gauge.set(u.heads_done, u.heads);
        while u.next < vertices {
            if cancel.load(Ordering::Relaxed) {
                if budget.is_some() {
                    self.sky.underway = Some(u);
                }
                return None;
            }
            let chunk_start = std::time::Instant::now();
            let chunk = u.next..(u.next + SKY_CHUNK_VERTICES).min(vertices);
            if !self.gather_sky(&mut u, chunk.clone(), cancel) {
                if budget.is_some() {
                    self.sky.underway = Some(u);
                }
                return None;
            }
            if !u.gathered[chunk.clone()].iter().all(|g| g.is_finite()) {
                self.fault = Some(SolverError::NotFinite {
                    step: self.steps + 1,
                    shooter: self.sky_shooter(),
                    phase: StepPhase::Gather,
                });
                return None;
            }
            u.next = chunk.end;
            self.gauge.set(u.heads_done, u.heads);
            if budget.is_some() {
                self.apply_sky(&mut u);
            }
            longest = longest.max(chunk_start.elapsed());
            if let Some(b) = budget {
                if u.next < vertices && start.elapsed() + longest >= b {
                    u.part += 1;
                    let report = self.sky_report(&u, false);
                    self.sky.underway = Some(u);
                    return Some(report);
                }
            }
        }
        self.apply_sky(&mut u);
        self.steps += 1;
        self.rays += u.rays;
        self.pairs += u.rays;
        self.receiver_pairs += u.receivers;
        self.last_fraction = self.unshot_fraction();
        u.part += 1;
        let report = self.sky_report(&u, true);
        if !report.unshot_fraction.is_finite() {
            self.fault = Some(SolverError::NotFinite {
                step: self.steps,
                shooter: self.sky_shooter(),
                phase: StepPhase::Apply,
            });
        }
        Some(report)
    }

    /// The facet that stands for the sky in reports: the first.
    fn sky_shooter(&self) -> PolygonId {
        let first = self
            .sky
            .tables
            .as_ref()
            .and_then(|(_, d)| d.facets().first());
        PolygonId(first.copied().unwrap_or(0) as u32)
    }

    /// Begins a sky step: what the facets hold; `None` when nothing.
    fn begin_sky(&self) -> Option<SkyUnderway> {
        let light = self.sky_light()?;
        if light.is_black() {
            return None;
        }
        let (_, dome) = self.sky.tables.as_ref()?;
        let shot_power = dome
            .facets()
            .iter()
            .map(|&j| self.polygon_power(j, Shot::PLAIN))
            .sum();
        Some(SkyUnderway {
            light,
            shot_power,
            next: 0,
            applied: 0,
            gathered: vec![Rgb::BLACK; self.mesh.vertex_count()],
            rays: 0,
            receivers: 0,
            heads: (0..self.mesh.vertex_count())
                .filter(|&l| self.gathers_sky(l))
                .count() as u64,
            heads_done: 0,
            part: 0,
            spent: false,
            hats: self
                .sky
                .hat_centroids
                .then(|| Hats::new(&self.mesh, &self.leaders)),
            fraction_before: self.last_fraction,
        })
    }

    /// Gathers the vertices among `vertices` that are evaluated themselves
    /// (of a polygon that receives, and not a shared receiver's follower)
    /// into `u.gathered`, in parallel; false when cancelled (then `u` is
    /// as before).
    fn gather_sky(
        &self,
        u: &mut SkyUnderway,
        vertices: std::ops::Range<usize>,
        cancel: &AtomicBool,
    ) -> bool {
        let Some((hemisphere, dome)) = self.sky.tables.as_ref() else {
            return true;
        };
        let mesh = &self.mesh;
        let heads: Vec<u32> = vertices
            .filter(|&l| self.gathers_sky(l))
            .map(|l| l as u32)
            .collect();
        let (light, probing, visibility) = (&u.light, self.sky.probing, self.visibility);
        let hats = u.hats.as_ref();
        let results: Vec<(Rgb, u64)> = heads
            .par_iter()
            .map(|&l| {
                if cancel.load(Ordering::Relaxed) {
                    return (Rgb::BLACK, 0);
                }
                let j = mesh.vertex_polygon[l as usize];
                let n = mesh.polygons[j.index()].normal.normalize_or_zero();
                let x = match hats {
                    Some(hats) => hats.centroid(mesh, l, |m| visibility.coplanar(j, m)),
                    None => mesh.sample_positions[l as usize],
                };
                let mut last = LastBlocker::default();
                hemisphere.gather(dome, light, x, n, probing, |end| {
                    visibility.occluded_remembering(x, end, (j, j), &mut last)
                })
            })
            .collect();
        if cancel.load(Ordering::Relaxed) {
            return false;
        }
        for (&l, (e, rays)) in heads.iter().zip(results) {
            u.gathered[l as usize] = e;
            u.rays += rays;
        }
        u.heads_done += heads.len() as u64;
        true
    }

    /// Applies the polygons not yet applied whose vertices are all
    /// gathered: each vertex's
    /// `Δrad = ρ · gathered` (its leader's, for a follower) to its
    /// radiosity and unshot radiosity; before the first, spends the
    /// facets' light.
    fn apply_sky(&mut self, u: &mut SkyUnderway) {
        self.changed();
        if !u.spent {
            let facets: Vec<usize> = self
                .sky
                .tables
                .as_ref()
                .map(|(_, d)| d.facets().to_vec())
                .unwrap_or_default();
            for m in facets {
                self.unshot
                    .spend(&self.mesh, m, Shot::PLAIN, &self.radiosity);
            }
            u.spent = true;
        }
        let done = self.mesh.polygons[u.applied..]
            .iter()
            .take_while(|pm| pm.vertices.end as usize <= u.next)
            .count();
        for j in u.applied..u.applied + done {
            if !self.receives_sky(j) {
                continue;
            }
            u.receivers += 1;
            let rho = self.reflectance[j];
            for l in self.mesh.polygons[j].vertices.clone() {
                let l = l as usize;
                let head = match self.leaders.get(l) {
                    Some(&x) if x != ALONE => x as usize,
                    _ => l,
                };
                let d = u.gathered[head] * rho;
                self.delta[l] = d;
                self.radiosity[l] += d;
            }
            self.unshot.accumulate(&self.mesh, j, &self.delta);
        }
        u.applied += done;
    }

    /// The report of the sky step `u` so far.
    fn sky_report(&self, u: &SkyUnderway, complete: bool) -> StepReport {
        StepReport {
            step: self.steps + u64::from(!complete),
            shooter: self.sky_shooter(),
            polygons: self
                .sky
                .tables
                .as_ref()
                .map_or(0, |(_, d)| d.facets().len() as u32),
            shot_power: u.shot_power,
            unshot_fraction: if complete {
                self.unshot_fraction()
            } else {
                u.fraction_before
            },
            rays: u.rays,
            pairs: u.rays,
            receivers: u.receivers,
            clear_receivers: 0,
            part: u.part,
            complete,
            particles: 0,
        }
    }
}

impl Progressive<'_> {
    /// What the sky's facets have sent so far (`e − Δb`, by facet), when
    /// the sky is gathered at once; `None` when it is shot by facets.
    pub(in crate::solver) fn sky_shot_light(&self) -> Option<SkyLight> {
        let (_, dome) = self.sky.tables.as_ref()?;
        Some(SkyLight::of(dome, |j| {
            self.emission[j] - self.unshot.mean(&self.mesh, j)
        }))
    }

    /// What a point `x` on polygon `j` with unit normal `n` receives of
    /// the sky's `light` before its reflectance, asked as the sky step
    /// asks a vertex (probes first where they are on), and the rays
    /// cast; black without a sky gathered at once.
    pub(in crate::solver) fn gather_sky_at(
        &self,
        light: &SkyLight,
        x: Vec3,
        n: Vec3,
        j: PolygonId,
    ) -> (Rgb, u64) {
        let Some((hemisphere, dome)) = self.sky.tables.as_ref() else {
            return (Rgb::BLACK, 0);
        };
        let mut last = LastBlocker::default();
        hemisphere.gather(dome, light, x, n, self.sky.probing, |end| {
            self.visibility
                .occluded_remembering(x, end, (j, j), &mut last)
        })
    }
}
