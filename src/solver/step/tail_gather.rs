//! The tail's final gather: once the particle tail has carried the last
//! of the light, every receiving vertex gathers one bounce from the
//! tail's whole field, and that answer is blended with what the
//! particles left on it, each by how noisy it is there.
//!
//! The particles' deposits are a collision estimate: a vertex gets what
//! happened to land on its hat, so its noise follows the particles that
//! land there, and a small hat (a game level's small triangles, one
//! element each) gets few. Over the tail the radiosity the particles add,
//! `T`, obeys `T = ρ K (U₀ + T)`: what leaves the surfaces (the light
//! unshot when the tail began, `U₀`, and what the tail added, `T`)
//! reflected once more. So from the particles' `T` one more bounce,
//! gathered at the vertex,
//!
//! ```text
//! T'(x) = ρ(x) · (1/N) Σ_k (U₀ + T)(hit_k)
//! ```
//!
//! over `N` cosine-weighted directions (a stratified grid of
//! [`TAIL_GATHER_RAYS`], jittered by the vertex's own stream), has the
//! same expected value with far less noise: each term averages the
//! particles' noise over the element triangle it hits, and the `N` hits
//! lie on many different elements (Jacobi's iteration on the particles'
//! answer: photon mapping's final gather, Christensen's "Faster Photon
//! Map Global Illumination", and Bekaert's stochastic Jacobi, which
//! gathers its last iteration for the same reason). `(U₀ + T)(hit)` is
//! interpolated in the element triangle hit, as the picture draws it; a
//! ray that leaves the model, meets a back that absorbs, or lands on a
//! sky facet or a luminaire brings nothing (they hold no unshot light
//! once the tail is due). The vertex asks from where the sky step asks
//! ([`crate::solver::accel::hat`]): its hat's centroid, so its value
//! stands for the light over its elements, as the particles' did.
//!
//! The gather alone is noisy where the particles are not: on a large
//! element (a big floor's), which catches hundreds of particles, its 64
//! directions per vertex leave blotches an element across. So each
//! vertex takes both answers weighted by the inverse of their variances
//! (`particle_weight`): a game level's small one-element triangles
//! take the gather, a large floor keeps its particles.
//!
//! Measured against the path tracer (`docs/accuracy.md`), 16 particles
//! a vertex and the gather beat 64 particles alone on five of the six
//! real models at less time (`fortitude.obj` 2.91 → 2.17 %); the house,
//! whose floor's large elements caught many particles, went from 0.57 to
//! 0.72 %. The twin is the particles' own deposits
//! ([`crate::solver::Approximations::tail_gather`] off). The
//! gather runs in the tail's last step, after its particles, in batches
//! of vertices, so a window's parts keep near their budget; every
//! vertex's directions come from its own index, so the bits do not
//! depend on the thread count or the parts.

use crate::color::Rgb;
use crate::solver::accel::hat::Hats;
use crate::solver::accel::shared::ALONE;
use crate::solver::step::tail::{cosine, Stream, Tracer};
use crate::solver::tuning::TAIL_GATHER_RAYS;
use crate::solver::Progressive;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Seeds the vertices' streams apart from every tail step's particles
/// (those are seeded by the step's number, far below this).
const GATHER_SEED: u64 = u64::MAX;

/// The radiosity and unshot radiosity per vertex when the tail began (its
/// first step in this solve): the field the final gather reads is the
/// unshot light then plus what the tail has added since.
#[derive(Debug)]
pub(in crate::solver) struct Began {
    pub(in crate::solver) radiosity: Vec<Rgb>,
    pub(in crate::solver) unshot: Vec<Rgb>,
    /// Per vertex, over the tail's steps completed since: the particles
    /// that landed on it, each counted by its barycentric weight there,
    /// and the sum of the squares of their deposits' luminance (radiosity
    /// × area units, squared).
    pub(in crate::solver) landed: Vec<(f64, f64)>,
}

/// A final gather under way.
#[derive(Debug)]
pub(in crate::solver) struct FinalGather {
    /// Per vertex, the radiosity the tail's field sends: `U₀ + T`.
    field: Vec<Rgb>,
    /// The vertices that gather (of a polygon that reflects, not a
    /// shared receiver's follower), ascending.
    heads: Vec<u32>,
    /// Per head, what it gathered (after its reflectance) and the
    /// variance of that mean's luminance (from its directions' spread);
    /// the first `next` are done.
    gathered: Vec<(Rgb, f64)>,
    next: usize,
    /// Shadow rays cast so far.
    pub(in crate::solver) rays: u64,
    hats: Option<Hats>,
}

impl FinalGather {
    /// Whether every head has gathered.
    pub(in crate::solver) fn done(&self) -> bool {
        self.next >= self.heads.len()
    }

    /// Heads gathered so far and in all.
    pub(in crate::solver) fn progress(&self) -> (u64, u64) {
        (self.next as u64, self.heads.len() as u64)
    }
}

impl Progressive<'_> {
    /// The final gather of the tail's last step, from `began` and the
    /// radiosity `after` the particles (per vertex); `reflects` per
    /// polygon as the particles land.
    pub(in crate::solver) fn begin_final_gather(
        &self,
        began: &Began,
        after: &[Rgb],
        reflects: &[bool],
    ) -> FinalGather {
        let field = (0..after.len())
            .map(|l| began.unshot[l] + (after[l] - began.radiosity[l]))
            .collect();
        let heads: Vec<u32> = (0..self.mesh.vertex_count())
            .filter(|&l| {
                let j = self.mesh.vertex_polygon[l].index();
                reflects[j]
                    && !self.reflectance[j].is_black()
                    && self.leaders.get(l).is_none_or(|&x| x == ALONE)
            })
            .map(|l| l as u32)
            .collect();
        FinalGather {
            field,
            gathered: vec![(Rgb::BLACK, 0.0); heads.len()],
            heads,
            next: 0,
            rays: 0,
            hats: self
                .hat_centroids()
                .then(|| Hats::new(&self.mesh, &self.leaders)),
        }
    }

    /// Gathers the next `count` heads of `g` in parallel; false when
    /// cancelled (then `g` is as before).
    pub(in crate::solver) fn final_gather_batch(
        &self,
        g: &mut FinalGather,
        tracer: &Tracer<'_>,
        count: usize,
        cancel: &AtomicBool,
    ) -> bool {
        let end = (g.next + count).min(g.heads.len());
        let (mesh, visibility) = (&self.mesh, self.visibility);
        let (field, hats) = (&g.field, g.hats.as_ref());
        let side = (TAIL_GATHER_RAYS as f64).sqrt().round().max(1.0) as usize;
        let results: Vec<((Rgb, f64), u64)> = g.heads[g.next..end]
            .par_iter()
            .with_min_len(16)
            .map(|&l| {
                if cancel.load(Ordering::Relaxed) {
                    return ((Rgb::BLACK, 0.0), 0);
                }
                let j = mesh.vertex_polygon[l as usize];
                let normal = mesh.polygons[j.index()].normal.normalize().as_dvec3();
                let x = match hats {
                    Some(h) => h.centroid(mesh, l, |m| visibility.coplanar(j, m)),
                    None => mesh.sample_positions[l as usize],
                };
                let start = x + normal.as_vec3() * tracer.offset();
                let mut s = Stream::new(GATHER_SEED, u64::from(l));
                let mut sum = Rgb::BLACK;
                let (mut lum, mut lum2) = (0.0f64, 0.0f64);
                over_hemisphere(tracer, start, normal, side, &mut s, field, |f| {
                    sum += f;
                    lum += f.mean();
                    lum2 += f.mean() * f.mean();
                });
                let n = (side * side) as f64;
                let rho = self.reflectance[j.index()];
                // The mean's variance from the directions' spread (the
                // strata make the true one smaller).
                let spread = (lum2 - lum * lum / n).max(0.0) / (n - 1.0).max(1.0);
                let variance = rho.mean() * rho.mean() * spread / n;
                ((sum * (1.0 / n) * rho, variance), n as u64)
            })
            .collect();
        if cancel.load(Ordering::Relaxed) {
            return false;
        }
        for (k, (v, rays)) in results.into_iter().enumerate() {
            g.gathered[g.next + k] = v;
            g.rays += rays;
        }
        g.next = end;
        true
    }

    /// The radiosity once `g` is done, `after` the particles (per
    /// vertex), with `landed` the last step's landings per vertex (as
    /// [`Began::landed`]) and `hat` each vertex's hat area: every vertex
    /// of a head's group at its radiosity when the tail `began` plus the
    /// blend of what the particles and the gather brought
    /// ([`particle_weight`]); the others at `after`.
    pub(in crate::solver) fn final_gather_result(
        &self,
        g: &FinalGather,
        began: &Began,
        after: &[Rgb],
        landed: &[(f64, f64)],
        hat: &[f64],
    ) -> Vec<Rgb> {
        let head_of = |l: usize| match self.leaders.get(l) {
            Some(&x) if x != ALONE => x as usize,
            _ => l,
        };
        // A group's landings and hat: its members' pooled, as its
        // particles' deposits are (`Progressive::tail_delta`).
        let mut pooled = vec![(0.0f64, 0.0f64, 0.0f64); after.len()];
        for l in 0..after.len() {
            let p = &mut pooled[head_of(l)];
            p.0 += began.landed[l].0 + landed[l].0;
            p.1 += began.landed[l].1 + landed[l].1;
            p.2 += hat[l];
        }
        let mut at_head = vec![None; after.len()];
        for (&l, &v) in g.heads.iter().zip(&g.gathered) {
            at_head[l as usize] = Some(v);
        }
        (0..after.len())
            .map(|l| {
                let head = head_of(l);
                match at_head[head] {
                    Some((gathered, gather_variance)) => {
                        let particles = after[l] - began.radiosity[l];
                        let (count, squares, area) = pooled[head];
                        let w = particle_weight(
                            particles.mean(),
                            count,
                            if area > 0.0 {
                                squares / (area * area)
                            } else {
                                0.0
                            },
                            gathered.mean(),
                            gather_variance,
                        );
                        (began.radiosity[l] + particles * w + gathered * (1.0 - w)).max(Rgb::BLACK)
                    }
                    None => after[l],
                }
            })
            .collect()
    }
}

/// Casts `side²` cosine-weighted directions from `start` about unit
/// normal `n`, one jittered in each cell of a `side × side` grid of the
/// unit square (jitter from `s`), and hands `each` the value of `field`
/// (per vertex) interpolated in the element triangle each direction lands
/// in; directions that land nowhere `tracer` reads bring nothing.
pub(in crate::solver) fn over_hemisphere(
    tracer: &Tracer<'_>,
    start: Vec3,
    n: DVec3,
    side: usize,
    s: &mut Stream,
    field: &[Rgb],
    mut each: impl FnMut(Rgb),
) {
    let (t, b) = n.any_orthonormal_pair();
    for k in 0..side * side {
        let u1 = ((k % side) as f64 + s.uniform()) / side as f64;
        let u2 = ((k / side) as f64 + s.uniform()) / side as f64;
        let d = cosine(n, t, b, u1, u2).as_vec3();
        if let Some(landing) = tracer.land(start, d) {
            let mut f = Rgb::BLACK;
            for (c, w) in landing.corners.iter().zip(landing.weights) {
                f += field[*c as usize] * w;
            }
            each(f);
        }
    }
}

/// The weight of the particles' answer `particles` (luminance) at a
/// vertex against the gather's `gathered`, each weighted by the inverse
/// of its variance: the particles' from their deposits' squares
/// (`squares`, over the hat's area squared: the deposits taken as
/// independent), the gather's from its directions' spread. A variance
/// measured from few samples can be far too small (a vertex that two
/// particles happened to reach alike), so each is at least its answer's
/// square over its samples: `count` landings (by barycentric weight), or
/// [`TAIL_GATHER_RAYS`] directions. A large element (a big floor's) gathers
/// hundreds of particles and keeps them: 64 directions there left blotches
/// an element across; a game level's small triangle gathers a few and
/// takes the gather.
fn particle_weight(
    particles: f64,
    count: f64,
    squares: f64,
    gathered: f64,
    gather_variance: f64,
) -> f64 {
    let scale = particles.abs().max(gathered.abs());
    let scale2 = scale * scale;
    let vp = squares.max(scale2 / (count.max(0.0) + 1.0));
    let vg = gather_variance.max(0.0);
    if vp + vg > 0.0 {
        vg / (vp + vg)
    } else {
        0.0
    }
}
