//! The particle tail: once little light is left unshot, a step carries
//! a share of all of it at once by tracing particles, every bounce.
//!
//! Progressive shooting converges fast while a few polygons hold most of
//! the unshot power, and slowly once the light is spread thin over the
//! whole model: then each step shoots one cluster's sliver to every
//! receiver. On a 260,000-vertex room that reflects 0.8, about a thousand
//! such steps took the last 27 % of the light to 0.1 %. A tail step
//! instead shoots the unshot radiosity of every polygon together, as
//! particles (Pattanaik and Mudur 1993; Bekaert's stochastic radiosity
//! and RenderPark's random walks use the same collision estimator):
//!
//! - a particle starts on an element triangle chosen in proportion to its
//!   unshot power (area times the mean of its corners' `|Δb|`), at a
//!   uniform point of it, carrying the unshot radiosity interpolated
//!   there times the power's share (signed: light sent ahead comes back
//!   as negative particles: overshooting, [`crate::solver::Approximations`]);
//! - it leaves in a cosine-weighted direction, and where it first lands
//!   on the front of a reflecting polygon the power reflected there,
//!   `ρ · Φ`, is added to the corners of the element triangle it landed
//!   in, by their barycentric weights;
//! - it then goes on from there with the reflected power, by Russian
//!   roulette (survival the largest channel of `ρ`, at most
//!   [`TAIL_SURVIVAL_MAX`]), until it is absorbed or leaves the model.
//!
//! A vertex's radiosity rises by what landed on it over the area its
//! weight stands for (the integral of its Gouraud hat, a third of each
//! triangle round it): the expected value is the reflected light
//! averaged over that hat, the same light the shooting steps put at the
//! vertex itself, smoothed over its neighbours. The noise falls as one
//! over the square root of the particles; they are
//! [`TAIL_PARTICLES_PER_VERTEX`] per element vertex
//! by default over the whole tail, in at most [`TAIL_STEPS`] steps (each
//! takes the unshot fraction down to the next of the levels `from · k /
//! TAIL_STEPS`, so the picture moves between them, and a solve resumed
//! from a checkpoint takes the same steps).
//!
//! The last step ends with a final gather ([`super::tail_gather`]):
//! where few particles landed on a vertex, one bounce of their light
//! gathered over its hemisphere takes the place of their deposits.
//!
//! An automatic tail also takes over early (at an unshot fraction of at
//! most [`TAIL_EARLY_FROM`]) after a shooting step that cost more rays
//! for its light than particles would ([`TAIL_COSTLY_RATIO`],
//! `costly`): on a game level each shooting step after the sky's cost
//! 5 to 8 times the rays of the particles for the light it carried, one
//! of a cluster spanning a quarter of the level 69 times. Its levels
//! then count down from the fraction it took over at, which a
//! checkpoint keeps.
//!
//! Every particle's random numbers come from its own index, and the
//! particles' deposits are summed in particle order, so the bits do not
//! depend on the thread count. The brute-force twin is the shooting
//! steps themselves (`--tail off`); `src/solver/tests/tail.rs` checks the
//! tail against them, against the uniform enclosure's closed form and for
//! energy balance.

use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::{PolygonId, Scene};
use crate::solver::accel::shared::ALONE;
use crate::solver::step::tail_gather::{Began, FinalGather};
use crate::solver::tuning::{
    TAIL_BATCH, TAIL_CHUNK, TAIL_COSTLY_RATIO, TAIL_EARLY_FROM, TAIL_GATHER_BATCH,
    TAIL_GATHER_PART_BATCH, TAIL_GATHER_RAYS, TAIL_MAX_BOUNCES, TAIL_PARTICLES_PER_VERTEX,
    TAIL_PART_BATCH, TAIL_STEPS, TAIL_SURVIVAL_MAX,
};
use crate::solver::unshot::TriangleLocator;
use crate::solver::{Progressive, StepReport, TailOption};
use crate::visibility::Visibility;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

/// The tail's settings and what it has done: where it starts, how many
/// particles it traces, and its tables (built at its first step).
#[derive(Debug)]
pub(in crate::solver) struct Tail {
    /// The unshot fraction at or below which it takes over, `None` when
    /// it is off.
    pub(in crate::solver) from: Option<f64>,
    /// Whether it is automatic, and so takes over early after a costly
    /// shooting step ([`Tail::hand_over_if_costly`]).
    auto: bool,
    /// Particles over the whole tail per element vertex, `> 0`.
    per_vertex: f64,
    /// Particles traced so far.
    pub(in crate::solver) particles: u64,
    /// Per polygon: its other side, when it has one (a two-sided face's
    /// back copy, or the face a back copy belongs to).
    twin: Vec<Option<u32>>,
    tables: OnceLock<Tables>,
    /// The tail step begun and not finished, when it is delivered in
    /// parts ([`crate::solver::SolverOptions::part_budget`]).
    pub(in crate::solver) underway: Option<Box<TailUnderway>>,
    /// Whether the last step ends with the final gather
    /// ([`super::tail_gather`]).
    gather: bool,
    /// The state when the tail began in this solve, which the final
    /// gather reads; taken by it.
    began: Option<Box<Began>>,
}

impl Tail {
    /// The tail `option` asks for on `mesh` of `scene`: on from the
    /// option's fraction, or, when automatic, from
    /// [`crate::solver::tuning::TAIL_AUTO_FROM`] on meshes of at least
    /// [`crate::solver::tuning::TAIL_AUTO_VERTICES`] vertices.
    pub(in crate::solver) fn new(
        option: TailOption,
        per_vertex: f64,
        gather: bool,
        scene: &Scene,
        mesh: &Mesh,
    ) -> Tail {
        use crate::solver::tuning::{TAIL_AUTO_FROM, TAIL_AUTO_VERTICES};
        let from = match option {
            TailOption::Off => None,
            TailOption::From(f) => Some(f),
            TailOption::Auto => {
                (mesh.vertex_count() as u64 >= TAIL_AUTO_VERTICES).then_some(TAIL_AUTO_FROM)
            }
        };
        Tail {
            from,
            auto: option == TailOption::Auto && from.is_some(),
            per_vertex: if per_vertex.is_finite() && per_vertex > 0.0 {
                per_vertex
            } else {
                TAIL_PARTICLES_PER_VERTEX
            },
            particles: 0,
            twin: scene
                .polygons
                .iter()
                .map(|p| p.surface.back.or(p.surface.back_of).map(|b| b.0))
                .collect(),
            tables: OnceLock::new(),
            underway: None,
            gather,
            began: None,
        }
    }

    /// The share of the unshot light a tail step shoots when the unshot
    /// fraction is `fraction` (`> 0`): what takes it down to the next
    /// of the levels `from · k / TAIL_STEPS` below it, so the tail ends
    /// in at most [`TAIL_STEPS`] steps. A function of the state alone, so
    /// a resumed solve takes the same steps as an uninterrupted one.
    fn share(&self, fraction: f64) -> f64 {
        let from = self.from.unwrap_or(0.0);
        let level = levels_below(from, fraction).next().unwrap_or(0.0);
        (1.0 - level / fraction).clamp(0.0, 1.0)
    }

    /// The state the final gather reads, as a checkpoint stores it: per
    /// vertex the radiosity, then the unshot radiosity, when the tail
    /// began, then the particles' landings since (their count by weight
    /// in `r`, the sum of their deposits' squares in `g`); empty when
    /// none is held.
    pub(in crate::solver) fn began_values(&self) -> Vec<Rgb> {
        self.began
            .as_ref()
            .map(|b| {
                let landed = b.landed.iter().map(|&(w, q)| Rgb::new(w, q, 0.0));
                b.radiosity
                    .iter()
                    .chain(&b.unshot)
                    .copied()
                    .chain(landed)
                    .collect()
            })
            .unwrap_or_default()
    }

    /// Takes the state [`Tail::began_values`] gave (empty: none; else
    /// three entries per vertex, checked by the caller). A tail without
    /// the final gather holds none.
    pub(in crate::solver) fn set_began(&mut self, mut values: Vec<Rgb>) {
        self.began = (self.gather && !values.is_empty()).then(|| {
            let n = values.len() / 3;
            let landed = values.split_off(2 * n).iter().map(|c| (c.r, c.g)).collect();
            let unshot = values.split_off(n);
            Box::new(Began {
                radiosity: values,
                unshot,
                landed,
            })
        });
    }

    /// The unshot fraction at or below which the tail takes over; `None`
    /// when it is off (for [`TailOption::Auto`], as this mesh decided).
    pub(in crate::solver) fn from(&self) -> Option<f64> {
        self.from
    }

    /// Test hook: an automatic tail from `from` on any mesh (the option
    /// turns one on only from [`crate::solver::tuning::TAIL_AUTO_VERTICES`]
    /// element vertices).
    #[cfg(test)]
    pub(in crate::solver) fn automatic_from(&mut self, from: f64) {
        self.from = Some(from);
        self.auto = true;
    }

    /// After a shooting step that cast `rays` shadow rays to shoot `shot`
    /// of power, leaving `unshot` power at unshot fraction `fraction` on
    /// a mesh of `vertices` element vertices: whether an automatic tail
    /// takes over now, before its fraction, because the step was
    /// [`costly`] and at most [`TAIL_EARLY_FROM`] is left. If so, the
    /// tail's fraction becomes `fraction`.
    pub(in crate::solver) fn hand_over_if_costly(
        &mut self,
        rays: u64,
        shot: f64,
        (unshot, fraction): (f64, f64),
        vertices: usize,
    ) -> bool {
        let due = self.auto
            && self.from.is_some_and(|from| fraction > from)
            && fraction <= TAIL_EARLY_FROM
            && costly(rays, shot, unshot, self.per_vertex * vertices as f64);
        if due {
            self.from = Some(fraction);
        }
        due
    }
}

/// Whether a shooting step that cast `rays` shadow rays for `shot` of
/// power (either sign) cost more than [`TAIL_COSTLY_RATIO`] times what a
/// tail of `particles` particles for the `unshot` power left would per
/// unit of power, counting a particle as a ray: `rays / |shot| >
/// TAIL_COSTLY_RATIO · particles / unshot`. Powers in radiosity × area
/// units. A step that shot nothing, or with nothing left, is not.
pub(in crate::solver) fn costly(rays: u64, shot: f64, unshot: f64, particles: f64) -> bool {
    let shot = shot.abs();
    shot > 0.0
        && unshot > 0.0
        && particles > 0.0
        && rays as f64 * unshot > TAIL_COSTLY_RATIO * particles * shot
}

/// The levels `from · k / TAIL_STEPS` (`k` from `TAIL_STEPS − 1` down to
/// 0) that a tail step at unshot fraction `fraction` may take it down to,
/// highest first: those at least an eighth of a level below it, past the
/// rounding of a level just reached, and no step of a sliver when the
/// tail begins just above a level.
fn levels_below(from: f64, fraction: f64) -> impl Iterator<Item = f64> {
    let below = fraction * (1.0 - 0.5 / f64::from(TAIL_STEPS));
    (0..TAIL_STEPS)
        .rev()
        .map(move |k| from * f64::from(k) / f64::from(TAIL_STEPS))
        .filter(move |&l| l < below)
}

/// Tail steps left at unshot fraction `fraction` for a tail from `from`
/// (0 once nothing is unshot): what a progress bar's estimate of the
/// time left counts.
pub fn steps_left(from: f64, fraction: f64) -> u32 {
    if fraction <= 0.0 {
        0
    } else {
        levels_below(from, fraction).count() as u32
    }
}

/// What the tail needs of the mesh, built once: every element triangle,
/// the area each vertex's hat covers, and per polygon a triangle locator.
#[derive(Debug)]
struct Tables {
    /// Every element triangle: its corners and area (square scene units).
    triangles: Vec<([u32; 3], f64)>,
    /// Per vertex: `Σ A_T / 3` over the triangles round it, the integral
    /// of its Gouraud hat, in square scene units.
    hat: Vec<f64>,
    /// Per polygon: its triangles' locator, built when a particle first
    /// lands on it.
    locators: Vec<OnceLock<TriangleLocator>>,
    /// How far off a surface a particle starts, in scene units: a
    /// millionth of the model's size, far above `f32` rounding at its
    /// coordinates and far below any gap in it.
    offset: f32,
}

impl Tables {
    fn new(mesh: &Mesh) -> Tables {
        let mut triangles = Vec::new();
        let mut hat = vec![0.0; mesh.vertex_count()];
        for e in &mesh.elements {
            for t in e.triangles() {
                let [a, b, c] = t.map(|v| mesh.positions[v.index()].as_dvec3());
                let area = (b - a).cross(c - a).length() * 0.5;
                for v in t {
                    hat[v.index()] += area / 3.0;
                }
                triangles.push((t.map(|v| v.0), area));
            }
        }
        let (lo, hi) = mesh
            .polygons
            .iter()
            .filter(|pm| !pm.sky)
            .flat_map(|pm| pm.vertices.clone())
            .map(|l| mesh.positions[l as usize])
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let size = (hi - lo).length();
        Tables {
            triangles,
            hat,
            locators: (0..mesh.polygons.len()).map(|_| OnceLock::new()).collect(),
            offset: if size.is_finite() && size > 0.0 {
                size * 1e-6
            } else {
                1e-6
            },
        }
    }
}

/// One particle's deposit: the reflected power that landed at a vertex,
/// in radiosity × area units, and the landing's barycentric weight there.
type Deposit = (u32, Rgb, f32);

/// A random stream for one particle: SplitMix64 (Steele, Lea and Flood
/// 2014) from a hash of the step and the particle's index, so that every
/// particle draws the same numbers on any thread.
pub(in crate::solver) struct Stream(u64);

impl Stream {
    /// The stream of particle (or vertex) `particle` of step (or pass)
    /// `step`.
    pub(in crate::solver) fn new(step: u64, particle: u64) -> Stream {
        Stream(
            step.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ particle.wrapping_mul(0xD1B5_4A32_D192_ED03),
        )
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub(in crate::solver) fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// A cosine-weighted direction about the unit `normal`.
fn cosine_direction(normal: DVec3, s: &mut Stream) -> DVec3 {
    let (u1, u2) = (s.uniform(), s.uniform());
    let (t, b) = normal.any_orthonormal_pair();
    cosine(normal, t, b, u1, u2)
}

/// The cosine-weighted direction of the unit square's point `(u1, u2)`
/// about the unit `normal`, with `t` and `b` completing its frame.
pub(in crate::solver) fn cosine(normal: DVec3, t: DVec3, b: DVec3, u1: f64, u2: f64) -> DVec3 {
    let r = u1.sqrt();
    let phi = std::f64::consts::TAU * u2;
    (t * (r * phi.cos()) + b * (r * phi.sin()) + normal * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// What one tail step needs to trace: read-only views of the solve.
pub(in crate::solver) struct Tracer<'t> {
    mesh: &'t Mesh,
    visibility: &'t Visibility,
    reflectance: &'t [Rgb],
    /// Per polygon: whether light landing on it is reflected (not a sky
    /// facet, not a luminaire with a light distribution).
    reflects: &'t [bool],
    twin: &'t [Option<u32>],
    tables: &'t Tables,
}

impl Tracer<'_> {
    /// The polygon whose front a particle travelling along `d` lands on
    /// when it hits `hit`: `hit`, or its other side, or `None` when it
    /// meets a back (a one-sided face's, which absorbs).
    fn receiver(&self, hit: PolygonId, d: Vec3) -> Option<usize> {
        let facing = |j: usize| self.mesh.polygons[j].normal.dot(d) < 0.0;
        let j = hit.index();
        if facing(j) {
            return Some(j);
        }
        self.twin
            .get(j)
            .copied()
            .flatten()
            .map(|b| b as usize)
            .filter(|&b| facing(b))
    }

    /// How far off a surface a ray starts, in scene units
    /// ([`Tables::offset`]).
    pub(in crate::solver) fn offset(&self) -> f32 {
        self.tables.offset
    }

    /// Where a ray from `start` along unit `d` lands: the polygon whose
    /// front it meets (one that reflects), the point, and the element
    /// triangle there with its barycentric weights; `None` when it leaves
    /// the model, meets a back that absorbs, or lands where nothing is
    /// reflected.
    pub(in crate::solver) fn land(&self, start: Vec3, d: Vec3) -> Option<Landing> {
        let (hit, t) = self.visibility.first_hit(start, d)?;
        let r = self.receiver(hit, d)?;
        if !self.reflects[r] {
            return None;
        }
        let at = start + d * t;
        let (corners, weights) = self.landing(r, at)?;
        Some(Landing {
            polygon: r,
            at,
            corners,
            weights,
        })
    }

    /// The element triangle of polygon `j` holding `p`, its corners and
    /// barycentric weights (`>= 0`, summing to 1).
    fn landing(&self, j: usize, p: Vec3) -> Option<([u32; 3], [f64; 3])> {
        let pm = &self.mesh.polygons[j];
        let locator = self.tables.locators[j].get_or_init(|| TriangleLocator::new(self.mesh, pm));
        let (corners, w) = locator.find(self.mesh, pm, p)?;
        let w = w.map(|x| f64::from(x).max(0.0));
        let sum = w[0] + w[1] + w[2];
        (sum > 0.0).then(|| (corners, w.map(|x| x / sum)))
    }

    /// Traces one particle from `origin` on polygon `j` carrying `power`
    /// (signed, radiosity × area units), appending what it deposits;
    /// returns the rays it cast.
    fn trace(
        &self,
        mut j: usize,
        mut origin: Vec3,
        mut power: Rgb,
        s: &mut Stream,
        out: &mut Vec<Deposit>,
    ) -> u64 {
        let mut rays = 0;
        for _ in 0..TAIL_MAX_BOUNCES {
            let normal = self.mesh.polygons[j].normal.normalize().as_dvec3();
            let d = cosine_direction(normal, s).as_vec3();
            let start = origin + normal.as_vec3() * self.tables.offset;
            rays += 1;
            let Some(Landing {
                polygon: r,
                at,
                corners,
                weights: w,
            }) = self.land(start, d)
            else {
                break;
            };
            let reflected = power * self.reflectance[r];
            for (c, w) in corners.iter().zip(w) {
                out.push((*c, reflected * w, w as f32));
            }
            let survival = self.reflectance[r].max_channel().min(TAIL_SURVIVAL_MAX);
            if survival <= 0.0 || s.uniform() >= survival {
                break;
            }
            power = reflected * (1.0 / survival);
            j = r;
            origin = at;
        }
        rays
    }
}

/// Where a ray lands ([`Tracer::land`]).
pub(in crate::solver) struct Landing {
    /// The polygon whose front it meets.
    pub(in crate::solver) polygon: usize,
    /// The point, in scene units.
    pub(in crate::solver) at: Vec3,
    /// The element triangle's corners (mesh vertices) and the point's
    /// barycentric weights in it (`>= 0`, summing to 1).
    pub(in crate::solver) corners: [u32; 3],
    pub(in crate::solver) weights: [f64; 3],
}

/// The emitting triangles of one tail step, for choosing where each
/// particle starts: their cumulative weights and what each carries.
#[derive(Debug)]
struct Sources {
    /// Indices into [`Tables::triangles`] of triangles with unshot light.
    triangles: Vec<u32>,
    /// Cumulative weights (area × mean corner `|Δb|`), ascending.
    cumulative: Vec<f64>,
    total: f64,
}

/// A tail step under way: what it shoots, and what its particles have
/// brought so far.
#[derive(Debug)]
pub(in crate::solver) struct TailUnderway {
    share: f64,
    sources: Sources,
    /// Per vertex, the unshot radiosity the particles carry.
    unshot: Vec<Rgb>,
    /// Per polygon, whether particles land on it and go on.
    reflects: Vec<bool>,
    /// Per polygon, its share of the sources' weight.
    per_polygon: Vec<f64>,
    /// Particles the step traces, and the power scale each carries.
    count: u64,
    scale: f64,
    /// The step's number, which seeds its particles' streams.
    step_number: u64,
    /// Chunks of [`TAIL_CHUNK`] particles, and the next to trace.
    chunks: u64,
    next: u64,
    /// Received power per vertex, summed in particle order.
    received: Vec<Rgb>,
    /// Per vertex, the landings on it, each counted by its barycentric
    /// weight there.
    landed: Vec<(f64, f64)>,
    rays: u64,
    /// Parts delivered so far.
    part: u32,
    /// The radiosity before the step, once a part has shown the light so
    /// far in its place.
    base: Option<Vec<Rgb>>,
    /// The final gather, once the last step's particles are all traced.
    gather: Option<Box<FinalGather>>,
}

impl<'a> Progressive<'a> {
    /// Whether the next step is a tail step: the tail is on, its fraction
    /// reached, no step underway, no emitter still to shoot its own light
    /// (a lamp's shadows need its own samples), and no sky facet or
    /// luminaire holding light (they shoot from their own directions).
    pub(in crate::solver) fn tail_due(&self) -> bool {
        let Some(from) = self.tail.from else {
            return false;
        };
        if self.underway.is_some() || self.unshot_power() <= 0.0 || self.unshot_fraction() > from {
            return false;
        }
        if self.choose_pending_emitter().is_some() {
            return false;
        }
        self.mesh.polygons.iter().enumerate().all(|(j, pm)| {
            !(pm.sky || self.directional[j].is_some()) || self.unshot.mean(&self.mesh, j).is_black()
        })
    }

    /// Per vertex, its unshot radiosity as the shooters read it: the
    /// vertex's own value, or its polygon's in the per-polygon scheme.
    pub(in crate::solver) fn unshot_at_vertices(&self) -> Vec<Rgb> {
        let values = self.unshot.values();
        if values.len() == self.mesh.vertex_count() {
            values.to_vec()
        } else {
            self.mesh
                .vertex_polygon
                .iter()
                .map(|p| values[p.index()])
                .collect()
        }
    }

    /// One tail step: shoots `share` of every polygon's unshot light by
    /// particles ([module docs](self)), or with a part budget
    /// ([`crate::solver::SolverOptions::part_budget`]) the particles that
    /// fit in it since `start`: the report says whether the step is
    /// complete, and between parts the solution shows the light landed
    /// so far (the finished step is bit-identical to the step in one
    /// piece). `None` when cancelled (without a part budget nothing
    /// changed; with one, the next call continues after the last part)
    /// or when nothing is left to shoot.
    pub(in crate::solver) fn tail_step(
        &mut self,
        start: std::time::Instant,
        cancel: &AtomicBool,
    ) -> Option<StepReport> {
        let mut u = match self.tail.underway.take() {
            Some(u) => u,
            None => {
                let u = Box::new(self.begin_tail()?);
                if self.tail.gather && self.tail.began.is_none() {
                    self.tail.began = Some(Box::new(Began {
                        radiosity: self.radiosity.clone(),
                        unshot: self.unshot_at_vertices(),
                        landed: vec![(0.0, 0.0); self.mesh.vertex_count()],
                    }));
                }
                u
            }
        };
        let budget = self.options.part_budget;
        let tracer = self.tracer(&u.reflects);
        let mut received = std::mem::take(&mut u.received);
        let mut cancelled = false;
        while u.next < u.chunks {
            if cancel.load(Ordering::Relaxed) {
                cancelled = true;
                break;
            }
            let batch = if budget.is_some() {
                TAIL_PART_BATCH
            } else {
                TAIL_BATCH
            };
            let batch_end = (u.next + batch).min(u.chunks);
            let (sources, unshot) = (&u.sources, &u.unshot);
            let (count, scale, step_number) = (u.count, u.scale, u.step_number);
            let results: Vec<(Vec<Deposit>, u64)> = (u.next..batch_end)
                .into_par_iter()
                .map(|c| {
                    let mut out = Vec::new();
                    let mut rays = 0;
                    let first = c * TAIL_CHUNK;
                    for i in first..(first + TAIL_CHUNK).min(count) {
                        if cancel.load(Ordering::Relaxed) {
                            break;
                        }
                        let mut s = Stream::new(step_number, i);
                        let pick = s.uniform() * sources.total;
                        let n = sources
                            .cumulative
                            .partition_point(|&c| c <= pick)
                            .min(sources.triangles.len() - 1);
                        let before = if n == 0 {
                            0.0
                        } else {
                            sources.cumulative[n - 1]
                        };
                        let weight = sources.cumulative[n] - before;
                        let (corners, area) =
                            tracer.tables.triangles[sources.triangles[n] as usize];
                        // A uniform point of the triangle.
                        let (r1, r2) = (s.uniform().sqrt(), s.uniform());
                        let b = [1.0 - r1, r1 * (1.0 - r2), r1 * r2];
                        let p = corners
                            .iter()
                            .zip(b)
                            .fold(DVec3::ZERO, |acc, (&c, b)| {
                                acc + tracer.mesh.positions[c as usize].as_dvec3() * b
                            })
                            .as_vec3();
                        let carried = corners
                            .iter()
                            .zip(b)
                            .fold(Rgb::BLACK, |acc, (&c, b)| acc + unshot[c as usize] * b);
                        // Δb(x) / p(x) with p(x) = weight / (total · area),
                        // over the step's particles and times its share.
                        let power = carried * (area * scale / weight);
                        let j = tracer.mesh.vertex_polygon[corners[0] as usize].index();
                        rays += tracer.trace(j, p, power, &mut s, &mut out);
                    }
                    (out, rays)
                })
                .collect();
            // A batch cut short by a cancel is dropped whole.
            if cancel.load(Ordering::Relaxed) {
                cancelled = true;
                break;
            }
            for (out, r) in results {
                u.rays += r;
                for (v, p, w) in out {
                    received[v as usize] += p;
                    let at = &mut u.landed[v as usize];
                    at.0 += f64::from(w);
                    at.1 += p.mean() * p.mean();
                }
            }
            u.next = batch_end;
            self.gauge.set(
                u.next,
                u.chunks + self.gather_units(&u, self.mesh.vertex_count()),
            );
            if budget.is_some_and(|b| start.elapsed() >= b) && u.next < u.chunks {
                break;
            }
        }
        u.received = received;
        if cancelled {
            self.tail_cancelled(u);
            return None;
        }
        let delta = self.tail_delta(&u.received);
        if u.next < u.chunks {
            return Some(self.tail_part(u, &delta));
        }
        if !delta.iter().all(|d| d.is_finite()) {
            if let Some(base) = u.base.take() {
                self.radiosity = base;
                self.changed();
            }
            return None;
        }
        // The last step ends with the final gather (`tail_gather`).
        let mut gathered = None;
        if u.share >= 1.0 {
            if let Some(began) = self.tail.began.take() {
                match self.run_final_gather(&mut u, &began, &delta, start, cancel) {
                    Some(true) => {
                        let g = u.gather.take().expect("a final gather that is done");
                        u.rays += g.rays;
                        let after = self.after_particles(&u, &delta);
                        let hat = &self.tail.tables.get_or_init(|| Tables::new(&self.mesh)).hat;
                        gathered =
                            Some(self.final_gather_result(&g, &began, &after, &u.landed, hat));
                    }
                    Some(false) => {
                        self.tail.began = Some(began);
                        return Some(self.tail_part(u, &delta));
                    }
                    None => {
                        self.tail.began = Some(began);
                        self.tail_cancelled(u);
                        return None;
                    }
                }
            }
        }
        let shot_power = u.share * self.net_unshot_power();
        let shooter = heaviest(&u.per_polygon);
        let polygons = u.per_polygon.iter().filter(|&&w| w > 0.0).count() as u32;
        // Negative particles (light sent ahead coming back) may take a
        // dark vertex a hair below zero by their noise.
        match (gathered, u.base.take()) {
            (Some(gathered), _) => self.radiosity = gathered,
            (None, Some(base)) => {
                for ((b, before), d) in self.radiosity.iter_mut().zip(&base).zip(&delta) {
                    *b = (*before + *d).max(Rgb::BLACK);
                }
            }
            (None, None) => {
                for (b, d) in self.radiosity.iter_mut().zip(&delta) {
                    *b = (*b + *d).max(Rgb::BLACK);
                }
            }
        }
        self.unshot.scale(1.0 - u.share);
        self.changed();
        if let Some(b) = self.tail.began.as_mut() {
            for (a, w) in b.landed.iter_mut().zip(&u.landed) {
                a.0 += w.0;
                a.1 += w.1;
            }
        }
        self.tail.particles += u.count;
        self.steps += 1;
        self.rays += u.rays;
        self.pairs += u.rays;
        let fraction = self.unshot_fraction();
        self.last_fraction = fraction;
        let receivers = self
            .mesh
            .polygons
            .iter()
            .filter(|pm| pm.vertices.clone().any(|l| !delta[l as usize].is_black()))
            .count() as u64;
        Some(StepReport {
            step: self.steps,
            shooter: PolygonId(shooter as u32),
            polygons,
            shot_power,
            unshot_fraction: fraction,
            rays: u.rays,
            pairs: u.rays,
            receivers,
            clear_receivers: 0,
            part: u.part + 1,
            complete: true,
            particles: u.count,
        })
    }

    /// Tail step `u` was cancelled: without parts it never happened (the
    /// radiosity before it comes back); with them the next call goes on
    /// after the last part delivered.
    fn tail_cancelled(&mut self, mut u: Box<TailUnderway>) {
        if self.options.part_budget.is_some() {
            self.tail.underway = Some(u);
        } else if let Some(base) = u.base.take() {
            self.radiosity = base;
            self.changed();
        }
    }

    /// What tail particles and the final gather trace with, `reflects`
    /// per polygon.
    pub(in crate::solver) fn tracer<'t>(&'t self, reflects: &'t [bool]) -> Tracer<'t> {
        Tracer {
            mesh: &self.mesh,
            visibility: self.visibility,
            reflectance: &self.reflectance,
            reflects,
            twin: &self.tail.twin,
            tables: self.tail.tables.get_or_init(|| Tables::new(&self.mesh)),
        }
    }

    /// A part of tail step `u`: the light landed so far (`delta` per
    /// vertex) shown over the radiosity before the step, and its report;
    /// the step stays under way.
    fn tail_part(&mut self, mut u: Box<TailUnderway>, delta: &[Rgb]) -> StepReport {
        u.part += 1;
        let base = u.base.get_or_insert_with(|| self.radiosity.clone());
        for ((b, before), d) in self.radiosity.iter_mut().zip(base.iter()).zip(delta) {
            *b = (*before + *d).max(Rgb::BLACK);
        }
        self.changed();
        let gather_rays = u.gather.as_ref().map_or(0, |g| g.rays);
        let report = StepReport {
            step: self.steps + 1,
            shooter: PolygonId(heaviest(&u.per_polygon) as u32),
            polygons: u.per_polygon.iter().filter(|&&w| w > 0.0).count() as u32,
            shot_power: u.share * self.net_unshot_power(),
            unshot_fraction: self.unshot_fraction(),
            rays: u.rays + gather_rays,
            pairs: u.rays + gather_rays,
            receivers: 0,
            clear_receivers: 0,
            part: u.part,
            complete: false,
            particles: u.next.saturating_mul(TAIL_CHUNK).min(u.count),
        };
        self.tail.underway = Some(u);
        report
    }

    /// The radiosity once step `u`'s particles have all landed, `delta`
    /// per vertex: over the radiosity before the step.
    fn after_particles(&self, u: &TailUnderway, delta: &[Rgb]) -> Vec<Rgb> {
        let before = u.base.as_ref().unwrap_or(&self.radiosity);
        before
            .iter()
            .zip(delta)
            .map(|(b, d)| (*b + *d).max(Rgb::BLACK))
            .collect()
    }

    /// The final gather's work for step `u` over `vertices` gathering
    /// vertices ([`gather_units`]): 0 unless `u` is the tail's last step
    /// and ends with the gather.
    fn gather_units(&self, u: &TailUnderway, vertices: usize) -> u64 {
        if u.share >= 1.0 && self.tail.began.is_some() {
            gather_units(vertices as u64)
        } else {
            0
        }
    }

    /// Runs step `u`'s final gather (begun from `began` and the
    /// particles' `delta` if not yet) until it is done (`Some(true)`),
    /// the part budget since `start` is spent (`Some(false)`) or `cancel`
    /// is set (`None`; the batch cut short is dropped).
    fn run_final_gather(
        &mut self,
        u: &mut TailUnderway,
        began: &Began,
        delta: &[Rgb],
        start: std::time::Instant,
        cancel: &AtomicBool,
    ) -> Option<bool> {
        if u.gather.is_none() {
            let after = self.after_particles(u, delta);
            u.gather = Some(Box::new(self.begin_final_gather(
                began,
                &after,
                &u.reflects,
            )));
        }
        let budget = self.options.part_budget;
        let batch = if budget.is_some() {
            TAIL_GATHER_PART_BATCH
        } else {
            TAIL_GATHER_BATCH
        };
        let tracer = self.tracer(&u.reflects);
        let g = u.gather.as_mut().expect("begun above");
        while !g.done() {
            if cancel.load(Ordering::Relaxed) || !self.final_gather_batch(g, &tracer, batch, cancel)
            {
                return None;
            }
            let (done, heads) = g.progress();
            self.gauge.set(
                u.chunks + gather_units(done),
                u.chunks + gather_units(heads),
            );
            if budget.is_some_and(|b| start.elapsed() >= b) && !g.done() {
                return Some(false);
            }
        }
        Some(true)
    }

    /// Begins a tail step: its share, where its particles start and what
    /// they carry; `None` when nothing is left to shoot.
    fn begin_tail(&self) -> Option<TailUnderway> {
        let share = self.tail.share(self.unshot_fraction());
        let tables = self.tail.tables.get_or_init(|| Tables::new(&self.mesh));
        let unshot = self.unshot_at_vertices();
        // Sky facets and luminaires neither start particles (the tail is
        // due only once they hold no light) nor reflect them.
        let reflects: Vec<bool> = self
            .mesh
            .polygons
            .iter()
            .enumerate()
            .map(|(j, pm)| !pm.sky && self.directional[j].is_none())
            .collect();
        // Where particles start.
        let mut sources = Sources {
            triangles: Vec::new(),
            cumulative: Vec::new(),
            total: 0.0,
        };
        let mut per_polygon = vec![0.0f64; self.mesh.polygons.len()];
        for (k, (corners, area)) in tables.triangles.iter().enumerate() {
            let j = self.mesh.vertex_polygon[corners[0] as usize].index();
            if !reflects[j] {
                continue;
            }
            let magnitude: f64 = corners
                .iter()
                .map(|&c| {
                    unshot[c as usize]
                        .to_array()
                        .map(f64::abs)
                        .iter()
                        .sum::<f64>()
                        / 3.0
                })
                .sum::<f64>()
                / 3.0;
            let w = area * magnitude;
            if w > 0.0 && w.is_finite() {
                sources.total += w;
                per_polygon[j] += w;
                sources.triangles.push(k as u32);
                sources.cumulative.push(sources.total);
            }
        }
        if sources.total <= 0.0 {
            return None;
        }
        let vertices = self.mesh.vertex_count() as f64;
        let count =
            ((self.tail.per_vertex * vertices / f64::from(TAIL_STEPS)).ceil() as u64).max(1);
        // A particle from a triangle of weight `w` and area `A` carries
        // `Δb(x) · scale · A / w`.
        let scale = share * sources.total / count as f64;
        Some(TailUnderway {
            share,
            sources,
            unshot,
            reflects,
            per_polygon,
            count,
            scale,
            step_number: self.steps + 1,
            chunks: count.div_ceil(TAIL_CHUNK),
            next: 0,
            received: vec![Rgb::BLACK; self.mesh.vertex_count()],
            landed: vec![(0.0, 0.0); self.mesh.vertex_count()],
            rays: 0,
            part: 0,
            base: None,
            gather: None,
        })
    }

    /// Per vertex, the rise that `received` (power landed per vertex)
    /// makes: what landed on its hat over the hat's area; vertices that
    /// receive as one ([`crate::solver::accel::shared`]) pool what landed
    /// on them all.
    fn tail_delta(&self, received: &[Rgb]) -> Vec<Rgb> {
        let tables = self.tail.tables.get_or_init(|| Tables::new(&self.mesh));
        let mut received = received.to_vec();
        let mut hat = tables.hat.clone();
        if !self.leaders.is_empty() {
            for l in 0..received.len() {
                let leader = self.leaders[l];
                if leader != ALONE {
                    let (p, a) = (received[l], hat[l]);
                    received[leader as usize] += p;
                    hat[leader as usize] += a;
                }
            }
        }
        (0..received.len())
            .map(|l| {
                let lead = match self.leaders.get(l) {
                    Some(&leader) if leader != ALONE => leader as usize,
                    _ => l,
                };
                if hat[lead] > 0.0 {
                    received[lead] * (1.0 / hat[lead])
                } else {
                    Rgb::BLACK
                }
            })
            .collect()
    }
}

/// The final gather's work over `vertices` gathering vertices, in the
/// units of the particles' chunks (a chunk's particles cast about four
/// rays each), for the step's gauge.
fn gather_units(vertices: u64) -> u64 {
    (vertices * TAIL_GATHER_RAYS as u64).div_ceil(4 * TAIL_CHUNK)
}

/// The index of the largest of `weights` (the first on ties; 0 when
/// empty).
fn heaviest(weights: &[f64]) -> usize {
    weights
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |best, (j, &w)| {
            if w > best.1 {
                (j, w)
            } else {
                best
            }
        })
        .0
}
