//! Phase 1 of a step: choosing the shooter.
//!
//! The cluster (without clustering, the polygon) with the most unshot
//! power due shoots next, its member with the most shooting for it.
//! Heuristics acting here:
//! - **emitters first**: an emitter that has not shot its light yet
//!   ([`crate::solver::tuning::PENDING_EMISSION`]) shoots before any reflector;
//! - **overshooting**: what each point expects to receive later
//!   (`Expectation`, `OVERSHOOT_SHARE`),
//!   sent ahead, and the negative part shot once the expectation no
//!   longer covers it;
//! - **settling**: past the threshold, the cluster holding the most light
//!   of points not yet settled ([`crate::solver::SolverOptions::settle`],
//!   [`crate::solver::tuning::SETTLE_FLOOR`]);
//! - **sky power weights**: a sky facet's power counts as the light it
//!   can bring (`sky_power_weights`).

use crate::color::Rgb;
use crate::scene::PolygonId;
use crate::solver::tuning::{OVERSHOOT_SHARE, PENDING_EMISSION, SETTLE_FLOOR};
use crate::solver::unshot::Shot;
use crate::solver::{Expectation, Progressive};

impl<'a> Progressive<'a> {
    /// The power polygon `j` sends out in a step that sends `shot`
    /// ([`UnshotField::sent_power`], the channel mean), in radiosity ×
    /// area units, as it counts for choosing the shooter and for the
    /// threshold: a sky facet's weighted by [`sky_power_weights`].
    pub(in crate::solver) fn polygon_power(&self, j: usize, shot: Shot) -> f64 {
        let sent = self.unshot.sent_power(&self.mesh, j, shot, &self.radiosity);
        sent.mean() * self.power_weight[j]
    }

    /// The unshot power of polygon `j` due to be shot in a step of sign
    /// `negative`, weighted as [`Progressive::polygon_power`]: the
    /// positive part as it is (what it expects to receive does not count:
    /// it would only be sent ahead), the negative part beyond what it still
    /// expects ([`Progressive::polygon_shot`]; what it sent ahead waits for
    /// the light to arrive, and is taken back once the expectation,
    /// shrinking as the solve converges, no longer covers it).
    pub(in crate::solver) fn polygon_due(
        &self,
        j: usize,
        negative: bool,
        expected: Expectation,
    ) -> f64 {
        if negative {
            self.polygon_power(j, self.polygon_shot(j, true, expected))
        } else {
            self.polygon_power(j, Shot::PLAIN)
        }
    }

    /// What the next step expects every point to receive later
    /// ([`Expectation`]); nothing without [`Approximations::overshoot`].
    pub(in crate::solver) fn expectation(&self) -> Expectation {
        if !self.options.approximations.overshoot {
            return Expectation::NONE;
        }
        if let Some(expected) = self.kept(|s| s.expectation) {
            return expected;
        }
        let expected = self.expectation_scanned();
        self.keep(|s| s.expectation = Some(expected));
        expected
    }

    /// [`Progressive::expectation`] with overshooting on, scanned afresh.
    fn expectation_scanned(&self) -> Expectation {
        let ambient = self.ambient().max(Rgb::BLACK) * OVERSHOOT_SHARE;
        let shot_so_far = self.per_polygon(|j| {
            self.unshot
                .shot_so_far(&self.mesh, j, &self.radiosity)
                .mean()
                * self.power_weight[j]
        });
        let (mut shot, mut area, mut reflected) = (0.0, 0.0, 0.0);
        for (j, pm) in self.mesh.polygons.iter().enumerate() {
            shot += shot_so_far[j];
            if !pm.sky {
                area += pm.area;
                reflected += self.reflectance[j].mean() * pm.area;
            }
        }
        let left = self.net_unshot_power();
        if shot <= 0.0 || left <= 0.0 || area <= 0.0 {
            return Expectation::NONE;
        }
        let r = 1.0 / (1.0 - reflected / area);
        Expectation {
            gain: r * left / shot,
            ambient,
        }
    }

    /// The shot of polygon `j` in a step of sign `negative` ([`Shot`]):
    /// each of its points expects `gain` times what it has received, at
    /// most `ρ_j ·` the step's share of the ambient term.
    pub(in crate::solver) fn polygon_shot(
        &self,
        j: usize,
        negative: bool,
        expected: Expectation,
    ) -> Shot {
        Shot {
            negative,
            gain: expected.gain,
            cap: self.reflectance[j] * expected.ambient,
            emission: self.emission[j],
        }
    }

    /// The member of `cluster` with the most unshot power due of sign
    /// `negative` ([`Progressive::polygon_due`]; the first on ties).
    pub(in crate::solver) fn strongest_member(
        &self,
        cluster: usize,
        negative: bool,
        expected: Expectation,
    ) -> PolygonId {
        let mut best = (0u32, f64::NEG_INFINITY);
        for &m in self.clusters.members(cluster) {
            let power = self.polygon_due(m as usize, negative, expected);
            if power > best.1 {
                best = (m, power);
            }
        }
        PolygonId(best.0)
    }

    /// Phase 1, choose the shooter: the cluster (without clustering, the
    /// polygon) with the most unshot power due of one sign
    /// ([`Progressive::polygon_due`] with the step's `expected` light; the
    /// lowest index on ties, the positive part before the negative), that
    /// power in radiosity × area units and whether it is the negative part;
    /// `None` when nothing is due. Past the threshold, the settling step
    /// instead ([`Progressive::choose_unsettled`]) while there is one. A
    /// linear pass over the polygons: it costs far less than the gather,
    /// which visits every receiving vertex.
    pub(in crate::solver) fn choose_shooter(
        &self,
        expected: Expectation,
    ) -> Option<(usize, f64, bool)> {
        // Past the threshold, what is left to shoot is what has not settled.
        if self.settling() && self.unshot_fraction() <= self.options.threshold {
            if let Some(chosen) = self.choose_unsettled(expected) {
                return Some(chosen);
            }
        }
        if self.options.approximations.emitters_first {
            if let Some(chosen) = self.choose_pending_emitter() {
                return Some(chosen);
            }
        }
        let overshoot = self.options.approximations.overshoot;
        let due = self.per_polygon(|i| {
            let negative = if overshoot {
                self.polygon_due(i, true, expected)
            } else {
                0.0
            };
            (self.polygon_due(i, false, expected), negative)
        });
        let mut positive = vec![0.0f64; self.clusters.len()];
        let mut negative = vec![0.0f64; self.clusters.len()];
        for (i, (p, n)) in due.into_iter().enumerate() {
            let c = self.clusters.of(PolygonId(i as u32));
            positive[c] += p;
            negative[c] += n;
        }
        let mut best: Option<(usize, f64, bool)> = None;
        for (c, (&p, &n)) in positive.iter().zip(&negative).enumerate() {
            for (power, sign) in [(p, false), (n, true)] {
                if power > 0.0 && best.is_none_or(|(_, b, _)| power > b) {
                    best = Some((c, power, sign));
                }
            }
        }
        best
    }

    /// The emitter that has not shot its own light yet holding the most
    /// unshot power, as [`Progressive::choose_shooter`] returns a step
    /// (emitters are clusters of their own): one whose unshot power is
    /// still at least [`PENDING_EMISSION`] of its emitted power, and more
    /// than the threshold's share of the initial power (less could be left
    /// unshot at the end). Every such light must be shot before the solve
    /// can stop, and a reflector that shoots before it does shoots again
    /// once it has, so emitters go first: on the 150-table hall the floor
    /// and ceiling had shot 17 times in between the 42 lamps. Sky facets
    /// are left to the power order, as their light is spread over many.
    pub(in crate::solver) fn choose_pending_emitter(&self) -> Option<(usize, f64, bool)> {
        let least = self.options.threshold * self.initial_unshot_power;
        let mut best: Option<(usize, f64, bool)> = None;
        for (j, (e, pm)) in self.emission.iter().zip(&self.mesh.polygons).enumerate() {
            if e.is_black() || pm.sky {
                continue;
            }
            let own = e.mean() * pm.area * self.power_weight[j];
            let due = self.polygon_power(j, Shot::PLAIN);
            if due >= PENDING_EMISSION * own && due > least && best.is_none_or(|(_, b, _)| due > b)
            {
                best = Some((self.clusters.of(PolygonId(j as u32)), due, false));
            }
        }
        best
    }

    /// Whether the solve settles past the threshold
    /// ([`Approximations::settling`] with a tolerance above 0).
    fn settling(&self) -> bool {
        self.options.approximations.settling && self.options.settle > 0.0
    }

    /// Whether some point has not settled ([`SolverOptions::settle`]).
    pub(in crate::solver) fn unsettled(&self) -> bool {
        self.settling() && self.choose_unsettled(self.expectation()).is_some()
    }

    /// The radiosity below which a point counts as that bright for
    /// settling: [`SETTLE_FLOOR`] of the mean radiosity (channel mean)
    /// over the reflecting polygons' area, sky facets left out.
    pub(in crate::solver) fn settle_floor(&self) -> f64 {
        let areas = &self.vertex_area;
        let parts = self.per_polygon(|j| {
            let pm = &self.mesh.polygons[j];
            let (mut sum, mut area) = (0.0, 0.0);
            if pm.sky || self.reflectance[j].is_black() {
                return (sum, area);
            }
            let range = pm.vertices.start as usize..pm.vertices.end as usize;
            for (b, a) in self.radiosity[range.clone()].iter().zip(&areas[range]) {
                sum += b.mean() * a;
                area += a;
            }
            (sum, area)
        });
        let (sum, area) = parts
            .into_iter()
            .fold((0.0, 0.0), |(s, a), (ps, pa)| (s + ps, a + pa));
        if area > 0.0 {
            SETTLE_FLOOR * sum / area
        } else {
            0.0
        }
    }

    /// The settling step due ([`SolverOptions::settle`]), as
    /// [`Progressive::choose_shooter`] returns a step: the cluster and
    /// sign holding the most power of points that have not settled, with
    /// all the power due of that sign (the whole cluster shoots, as in any
    /// step); `None` when every point has settled. Sky facets bring light
    /// only from outside and reflect nothing: they never hold it up.
    pub(in crate::solver) fn choose_unsettled(
        &self,
        expected: Expectation,
    ) -> Option<(usize, f64, bool)> {
        let floor = self.settle_floor();
        let tolerance = self.options.settle;
        let signs: &[bool] = if self.options.approximations.overshoot {
            &[false, true]
        } else {
            &[false]
        };
        // Per polygon, for each sign: (unsettled power, power due).
        let parts = self.per_polygon(|i| {
            let mut part = [(0.0f64, 0.0f64); 2];
            if self.mesh.polygons[i].sky {
                return part;
            }
            for &negative in signs {
                let shot = if negative {
                    self.polygon_shot(i, true, expected)
                } else {
                    Shot::PLAIN
                };
                let unsettled = self.unshot.unsettled_power(
                    &self.mesh,
                    i,
                    shot,
                    &self.radiosity,
                    tolerance,
                    floor,
                );
                part[negative as usize] = (
                    unsettled * self.power_weight[i],
                    self.polygon_due(i, negative, expected),
                );
            }
            part
        });
        // Per cluster, for each sign: (unsettled power, power due).
        let mut sums = vec![[(0.0f64, 0.0f64); 2]; self.clusters.len()];
        for (i, part) in parts.into_iter().enumerate() {
            if self.mesh.polygons[i].sky {
                continue;
            }
            let c = self.clusters.of(PolygonId(i as u32));
            for (sum, p) in sums[c].iter_mut().zip(part) {
                sum.0 += p.0;
                sum.1 += p.1;
            }
        }
        let mut best: Option<(usize, f64, bool, f64)> = None;
        for (c, pair) in sums.iter().enumerate() {
            for (negative, &(unsettled, due)) in pair.iter().enumerate() {
                if unsettled > 0.0 && due > 0.0 && best.is_none_or(|b| unsettled > b.3) {
                    best = Some((c, due, negative == 1, unsettled));
                }
            }
        }
        best.map(|(c, due, negative, _)| (c, due, negative))
    }
}
