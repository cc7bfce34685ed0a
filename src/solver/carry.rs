//! Carrying a solve over to a refined mesh (`--adaptive`): the vertices
//! both meshes share keep their values, and each new vertex gathers the
//! light shot so far, so the solve goes on from where it was.
//!
//! A new vertex at `x` on polygon `j` takes `b = e + ρ · G(x)`, `G` what
//! has been shot towards it. Two ways of gathering `G`:
//!
//! - **From every polygon** (the brute-force twin, the solve without
//!   clusters): `G = Σ_i F(x → i) (b − Δb)_i`, each polygon's shot light
//!   read at its samples with the form factors and shadow rays of a
//!   step. Exact as a step is, but it asks every polygon's samples: on a
//!   game level of 138,000 polygons one new vertex cast millions of rays,
//!   and one refinement ran for most of an hour.
//! - **Over the vertex's hemisphere** (with clusters, the default). The
//!   light splits three ways, each gathered where it is sharp or smooth:
//!   - the lamps (polygons that emit, sky facets shot by facets among
//!     them) as the twin gathers them, polygon by polygon: few polygons,
//!     and their direct light has the hard shadows;
//!   - the sky, when gathered at once, as the sky step asks a vertex
//!     ([`super::accel::sky_dome`]), with what its facets have sent;
//!   - the light the other surfaces have reflected, by
//!     [`CARRY_GATHER_RAYS`] cosine-weighted stratified rays, each
//!     bringing the reflected radiosity those surfaces have shot
//!     (`b − Δb` of a surface that does not emit), interpolated in the
//!     element triangle it lands in, as the picture draws it. This is
//!     the smooth part, and the tail's final gather
//!     ([`super::step::tail_gather`]) reads the same field the same way.
//!
//!   Its cost is a sky step's and a final gather's per vertex, whatever
//!   the polygon count. It is taken when the twin would cost more than
//!   [`CARRY_EXACT_SAMPLES`] rays a vertex: a scene of a few hundred
//!   polygons keeps the exact twin. Against the twin
//!   (`solver::tests::meshes`) new vertices differ by about 1 % of their
//!   mean, 5 % at worst, at a fifth of its rays; on `pandora.obj`
//!   (138,429 polygons) one refinement's 305,000 new vertices gathered in
//!   60 s on 2 cores, where the twin had not finished after 20 minutes.
//!
//! New vertices of one surface at one point (a split edge's midpoint, on
//! both triangles beside it) gather as one, as a step's shared receivers
//! do ([`crate::solver::accel::shared`]), from their group's hat.
//!
//! The gather goes in chunks of [`CARRY_CHUNK_VERTICES`] vertices, and
//! the step gauge ([`crate::solver::gauge`]) counts the new vertices that
//! gather themselves as they are done, so a progress bar shows the
//! minute it takes on a real level.
//!
//! A new vertex's unshot radiosity is the coarse field carried over
//! ([`Refiner::carry`]) either way, so each polygon's unshot power is
//! unchanged.

use crate::cancel::Cancelled;
use crate::color::Rgb;
use crate::mesh::refine::Refiner;
use crate::mesh::Mesh;
use crate::scene::{PolygonId, Scene};
use crate::solver::accel::hat::Hats;
use crate::solver::accel::shared::{self, ALONE};
use crate::solver::accel::subcells;
use crate::solver::checkpoint::SolverState;
use crate::solver::kernel::distribution;
use crate::solver::step::tail::Stream;
use crate::solver::step::tail_gather::over_hemisphere;
use crate::solver::tuning::{CARRY_CHUNK_VERTICES, CARRY_EXACT_SAMPLES, CARRY_GATHER_RAYS};
use crate::solver::Progressive;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// How new vertices gather the light shot so far ([module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::solver) enum Carry {
    /// From every polygon's samples (the twin).
    EveryPolygon,
    /// Lamps by polygon, the sky by the sky step's directions, reflected
    /// light over the hemisphere.
    Hemisphere,
}

/// Seeds the new vertices' streams apart from the tail's particles and
/// its final gather's.
const CARRY_SEED: u64 = u64::MAX - 1;

impl Progressive<'_> {
    /// The state a solve on `refined`, a refinement of this solve's mesh,
    /// starts from to continue this one rather than start afresh (per-vertex
    /// scheme only; `None` for the per-polygon one): a vertex both meshes
    /// have keeps its radiosity and unshot radiosity, a new one gathers the
    /// light shot so far ([module docs](self)): over its hemisphere when the
    /// solve clusters and its polygons have more than
    /// [`CARRY_EXACT_SAMPLES`] samples in all, else from every polygon.
    ///
    /// `refined` must be the mesh `refiner` returned last, refining this
    /// solve's mesh. The gather's rays are added to the ray count. The
    /// gather checks `cancel` as it goes and stops with [`Cancelled`] once
    /// it is set.
    pub fn refined_state(
        &self,
        scene: &Scene,
        refined: &Mesh,
        refiner: &Refiner,
        cancel: &AtomicBool,
    ) -> Result<Option<SolverState>, Cancelled> {
        // The twin's cost per new vertex is a ray per sample of every
        // polygon; below the bound it is cheap, and exact as a step.
        let samples: usize = self.samples.iter().map(|s| s.len()).sum();
        let how = if self.clustered && samples > CARRY_EXACT_SAMPLES {
            Carry::Hemisphere
        } else {
            Carry::EveryPolygon
        };
        self.refined_state_by(scene, refined, refiner, cancel, how)
    }

    /// [`Progressive::refined_state`], gathering as `how` says.
    pub(in crate::solver) fn refined_state_by(
        &self,
        scene: &Scene,
        refined: &Mesh,
        refiner: &Refiner,
        cancel: &AtomicBool,
        how: Carry,
    ) -> Result<Option<SolverState>, Cancelled> {
        let Some(unshot) = self.unshot.carried(refiner) else {
            return Ok(None);
        };
        let previous = refiner.previous_index();
        if previous.len() != refined.vertex_count() || unshot.len() != refined.vertex_count() {
            return Ok(None);
        }
        // Each polygon's cells as a step of it reads them: a split cell by
        // its sub-cells.
        let Some(shot_at_samples) = self.unshot.shot_at_samples(&self.mesh, &self.radiosity) else {
            return Ok(None);
        };
        let shot: Vec<(Vec<Rgb>, Vec<Rgb>)> = shot_at_samples
            .into_iter()
            .zip(&self.subcells)
            .map(|((mut values, readings), subs)| {
                subcells::carry_means(subs, &readings, &mut values);
                (values, readings)
            })
            .collect();
        let sky_light = match how {
            Carry::Hemisphere => self.sky_shot_light(),
            Carry::EveryPolygon => None,
        };
        // The polygons gathered one by one: all of them for the twin;
        // else those that emit, but for sky facets the sky step's
        // directions gather.
        let by_polygon: Vec<usize> = (0..self.mesh.polygons.len())
            .filter(|&i| match how {
                Carry::EveryPolygon => true,
                Carry::Hemisphere => {
                    let by_dome = self.mesh.polygons[i].sky && sky_light.is_some();
                    !self.emission[i].is_black() && !by_dome
                }
            })
            .collect();
        // The hemisphere's rays read what the surfaces that neither emit
        // nor are sky have reflected and shot, per vertex of this mesh.
        let reads: Vec<bool> = (0..self.mesh.polygons.len())
            .map(|i| {
                how == Carry::Hemisphere
                    && !self.mesh.polygons[i].sky
                    && self.emission[i].is_black()
            })
            .collect();
        let reflected: Vec<Rgb> = match how {
            Carry::Hemisphere => self
                .unshot_at_vertices()
                .iter()
                .zip(&self.radiosity)
                .map(|(&u, &b)| b - u)
                .collect(),
            Carry::EveryPolygon => Vec::new(),
        };
        let tracer = self.tracer(&reads);
        // New vertices of one surface at one point gather as one, as in a
        // step ([`crate::solver::accel::shared`]).
        let leaders = shared::leaders(
            scene,
            refined,
            self.visibility,
            how == Carry::Hemisphere && self.options.approximations.shared_receivers,
        );
        let follows = |l: usize| leaders.get(l).copied().filter(|&x| x != ALONE);
        let hats = (how == Carry::Hemisphere && self.hat_centroids())
            .then(|| Hats::new(refined, &leaders));
        let side = (CARRY_GATHER_RAYS as f64).sqrt().round().max(1.0) as usize;
        let visibility = self.visibility;
        let gather_one = |l: usize| -> (Rgb, u64) {
            let j = refined.vertex_polygon[l];
            let b = match previous[l] {
                Some(old) => return (self.radiosity[old as usize], 0),
                None => self.emission[j.index()],
            };
            if follows(l).is_some() {
                // Its leader's value, set below.
                return (b, 0);
            }
            let rho = self.reflectance[j.index()];
            if rho.is_black() || cancel.load(Ordering::Relaxed) {
                return (b, 0);
            }
            let own = refined.sample_positions[l];
            let normal = refined.polygons[j.index()].normal.normalize_or_zero();
            let Some((mut sum, mut rays)) =
                self.gather_from_polygons(own, normal, j, &by_polygon, &shot, cancel)
            else {
                return (Rgb::BLACK, 0);
            };
            if how == Carry::Hemisphere {
                // The sky and the reflected light from the hat's
                // centroid, as the sky step and the final gather ask.
                let x = match &hats {
                    Some(h) => h.centroid(refined, l as u32, |m| visibility.coplanar(j, m)),
                    None => own,
                };
                if let Some(light) = &sky_light {
                    let (s, r) = self.gather_sky_at(light, x, normal, j);
                    sum += s;
                    rays += r;
                }
                let start = x + normal * tracer.offset();
                let mut s = Stream::new(CARRY_SEED, l as u64);
                let mut field = Rgb::BLACK;
                let n = normal.as_dvec3();
                over_hemisphere(&tracer, start, n, side, &mut s, &reflected, |f| field += f);
                sum += field * (1.0 / (side * side) as f64);
                rays += (side * side) as u64;
            }
            // The sun's light reaches it as it reached the old ones.
            let sun = self.sun_irradiance(own, normal, j);
            (b + rho * (sum + Rgb::splat(sun)), rays)
        };
        // In chunks, so that the gauge ([`crate::solver::gauge`]) counts
        // the new vertices that gather themselves as they are done: on a
        // real level the gather takes a minute.
        let n = refined.vertex_count();
        let gathers = |range: std::ops::Range<usize>| {
            range
                .filter(|&l| previous[l].is_none() && follows(l).is_none())
                .count() as u64
        };
        let total = gathers(0..n);
        let mut done = 0;
        self.gauge.set(done, total);
        let mut gathered: Vec<(Rgb, u64)> = Vec::with_capacity(n);
        for start in (0..n).step_by(CARRY_CHUNK_VERTICES) {
            let chunk = start..(start + CARRY_CHUNK_VERTICES).min(n);
            gathered.par_extend(
                chunk
                    .clone()
                    .into_par_iter()
                    .with_min_len(16)
                    .map(gather_one),
            );
            done += gathers(chunk);
            self.gauge.set(done, total);
            if cancel.load(Ordering::Relaxed) {
                break;
            }
        }
        self.gauge.idle();
        if cancel.load(Ordering::Relaxed) {
            return Err(Cancelled);
        }
        let rays = gathered.iter().map(|g| g.1).sum::<u64>();
        let mut radiosity: Vec<Rgb> = gathered.into_iter().map(|g| g.0).collect();
        // A leader comes before its followers and follows no one, and
        // both have one material: a new follower takes its leader's
        // radiosity, whether the leader is new or kept.
        for l in 0..radiosity.len() {
            if let (None, Some(x)) = (previous[l], follows(l)) {
                radiosity[l] = radiosity[x as usize];
            }
        }
        Ok(Some(SolverState {
            radiosity,
            unshot,
            steps: self.steps,
            rays: self.rays + rays,
            // Interpolation on the refined mesh starts with no charges.
            charges: Vec::new(),
            tail_from: self.tail.from(),
            // A tail on the refined mesh gathers from where it resumes.
            tail_began: Vec::new(),
        }))
    }

    /// What a point `x` on polygon `j` with unit normal `normal` receives
    /// before its reflectance from each polygon of `polygons`, their light
    /// shot so far (`shot`, per polygon: values at its samples and its
    /// sub-cells' readings) read as a step reads it, and the rays cast;
    /// `None` once `cancel` is set.
    fn gather_from_polygons(
        &self,
        x: glam::Vec3,
        normal: glam::Vec3,
        j: PolygonId,
        polygons: &[usize],
        shot: &[(Vec<Rgb>, Vec<Rgb>)],
        cancel: &AtomicBool,
    ) -> Option<(Rgb, u64)> {
        let visibility = self.visibility;
        let near_field = self.options.approximations.near_field;
        let mut sum = Rgb::BLACK;
        let mut rays = 0;
        for &i in polygons {
            // A vertex may read every polygon, so its gather alone is
            // long on a real level.
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            // Coplanar polygons exchange no light (see
            // `Visibility::coplanar`).
            let shooter = PolygonId(i as u32);
            if i == j.index() || visibility.coplanar(shooter, j) {
                continue;
            }
            let (values, readings) = &shot[i];
            let subs = &self.subcells[i];
            let (f, asked) = distribution::shot_point_to_samples(
                self.directional[i].as_ref(),
                x,
                normal,
                self.mesh.polygons[i].normal,
                &self.samples[i],
                |k| values[k],
                subcells::Split::of_polygon(subs, readings).as_ref(),
                near_field,
                |_, s| visibility.occluded(s, x, (shooter, j)),
            );
            sum += f;
            rays += asked;
        }
        Some((sum, rays))
    }
}
