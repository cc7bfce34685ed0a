//! A sky facet's light is first probed: a receiving vertex asks a few of
//! the facet's directions, spread over it, and when they all agree (all
//! open, all blocked) takes that answer for every direction of the facet.
//!
//! A sky facet shoots from [`crate::solver::tuning::SKY_FACET_SAMPLES`]
//! directions so that a window's or an overhang's edge draws a smooth
//! penumbra, and a step cast a ray along each of them from every
//! receiving vertex that faces them: 125 rays per vertex per step on a
//! real export under `--sky`. Yet most vertices see a facet's whole patch
//! of sky, or none of it; only those near a shadow's edge see part. So a
//! vertex first asks [`SKY_PROBES`](crate::solver::tuning::SKY_PROBES) of the facet's directions, chosen
//! once per facet to cover it evenly ([`spread`]); when every probe it
//! faces agrees, and it faces at least [`MIN_PROBES`] of them, that is
//! the visibility of the whole facet from it ([`SkyProbes::ask`]), and the form
//! factor is still summed over every direction.
//!
//! When they disagree, a shadow's edge crosses the facet, and most of the
//! facet still lies away from it. Each direction belongs to the region of
//! its nearest probe ([`SkyProbes`]); a region whose probe and every
//! probe of the regions touching it see the sky takes that answer, and
//! one whose probes two rings deep are all blocked takes that; only the
//! directions of the other regions, those along the edge, are asked one
//! by one. Blocked needs the wider ring because an opening (a door seen
//! from inside) is a small open patch in a blocked facet, which can poke
//! into a region past its nearest probes: answered one ring deep, the view
//! into `tests/models/godot/room.glb` came out 0.44 % darker. On that
//! model's sky a vertex whose probes disagreed asked 236 of a facet's 256
//! directions, and such vertices cast three quarters of the sky's rays.
//!
//! What the probes can miss is an occluder, or an opening, that falls
//! wholly between them: one no wider than the gap between probes, about a
//! quarter of the facet across (a facet is 1/80 of the sphere of
//! directions, so a patch about 6° across). That patch brings at most
//! about a sixteenth of the facet's light. Probing is off with
//! `--exact-receivers` and `--no-clustering`. A vertex's verdict depends
//! only on its own rays, so the bits do not depend on the thread count.

use crate::solver::kernel::formfactor::ShooterSample;
use crate::solver::tuning::MIN_PROBES;
use glam::Vec3;

/// `n` of `samples` spread evenly over them (indices, increasing):
/// farthest-point sampling from the sample nearest their centroid, each
/// next one the farthest from those already chosen (ties to the lower
/// index, so the choice is the same on every run). All of them when there
/// are at most `n`.
pub fn spread(samples: &[ShooterSample], n: usize) -> Vec<u32> {
    if samples.len() <= n {
        return (0..samples.len() as u32).collect();
    }
    let centroid = samples.iter().map(|s| s.position).sum::<Vec3>() / samples.len() as f32;
    let nearest_to = |p: Vec3| {
        samples
            .iter()
            .enumerate()
            .fold((0, f32::INFINITY), |(best, d), (k, s)| {
                let e = s.position.distance_squared(p);
                if e < d {
                    (k, e)
                } else {
                    (best, d)
                }
            })
            .0
    };
    let mut chosen = vec![nearest_to(centroid)];
    // Per sample, its squared distance to the nearest chosen one.
    let mut gap: Vec<f32> = samples
        .iter()
        .map(|s| s.position.distance_squared(samples[chosen[0]].position))
        .collect();
    while chosen.len() < n {
        let (next, _) =
            gap.iter().enumerate().fold(
                (0, -1.0f32),
                |(best, d), (k, &e)| if e > d { (k, e) } else { (best, d) },
            );
        chosen.push(next);
        let p = samples[next].position;
        for (g, s) in gap.iter_mut().zip(samples) {
            *g = g.min(s.position.distance_squared(p));
        }
    }
    let mut out: Vec<u32> = chosen.into_iter().map(|k| k as u32).collect();
    out.sort_unstable();
    out
}

/// A sky facet's probes ([`spread`]) and the regions of its directions
/// they stand for: each direction's nearest probe, and per probe the
/// probes whose regions touch its own (two regions touch where some
/// direction has one's probe nearest and the other's second nearest).
#[derive(Clone, Debug, Default)]
pub struct SkyProbes {
    /// Indices into the facet's samples, increasing; at most 32.
    probes: Vec<u32>,
    /// Per sample of the facet: the index into `probes` of its nearest.
    region: Vec<u8>,
    /// Per probe: a bit per probe whose region touches its own (its own
    /// bit set).
    touching: Vec<u32>,
    /// Per probe: `touching` and the probes touching those.
    ring2: Vec<u32>,
}

impl SkyProbes {
    /// `n` (at most 32) probes spread over `samples`, and their regions.
    pub fn new(samples: &[ShooterSample], n: usize) -> SkyProbes {
        assert!(n <= 32, "a region mask holds 32 probes");
        let probes = spread(samples, n);
        let mut touching: Vec<u32> = (0..probes.len()).map(|p| 1 << p).collect();
        let region = samples
            .iter()
            .map(|s| {
                // The nearest and second nearest probes.
                let (mut best, mut next) = ((0usize, f32::INFINITY), (usize::MAX, f32::INFINITY));
                for (p, &k) in probes.iter().enumerate() {
                    let d = samples[k as usize].position.distance(s.position);
                    if d < best.1 {
                        next = best;
                        best = (p, d);
                    } else if d < next.1 {
                        next = (p, d);
                    }
                }
                // The regions of its two nearest probes meet near it.
                if next.0 != usize::MAX {
                    touching[best.0] |= 1 << next.0;
                    touching[next.0] |= 1 << best.0;
                }
                best.0 as u8
            })
            .collect();
        let ring2 = touching
            .iter()
            .map(|&near| {
                (0..probes.len())
                    .filter(|&q| near & (1 << q) != 0)
                    .fold(near, |m, q| m | touching[q])
            })
            .collect();
        SkyProbes {
            probes,
            region,
            touching,
            ring2,
        }
    }

    /// The probe indices (into the facet's samples), increasing.
    pub fn probes(&self) -> &[u32] {
        &self.probes
    }

    /// What the probes say of the facet seen from the receiver at `x`
    /// with unit normal `nx` ([`Probed`]); each probe in front of the
    /// receiver's plane is asked by `blocked(k, position)` at most once.
    pub fn ask(
        &self,
        samples: &[ShooterSample],
        x: Vec3,
        nx: Vec3,
        mut blocked: impl FnMut(usize, Vec3) -> bool,
    ) -> Probed {
        let (mut front, mut hidden) = (0u32, 0u32);
        for (p, &k) in self.probes.iter().enumerate() {
            let s = samples[k as usize].position;
            if (s - x).dot(nx) <= 0.0 {
                continue;
            }
            front |= 1 << p;
            if blocked(k as usize, s) {
                hidden |= 1 << p;
            }
        }
        if front.count_ones() < MIN_PROBES as u32 {
            return Probed::Unknown;
        }
        if hidden == 0 || hidden == front {
            return Probed::Whole(hidden != 0);
        }
        Probed::Regions { front, hidden }
    }

    /// The visibility of sample `k` of the facet by what the probes said,
    /// `None` where it must be asked: in a region whose probe is behind
    /// the receiver, or where the probes of the touching regions are not
    /// all open and those two rings deep not all blocked (behind the
    /// receiver counts as neither).
    pub fn seen(&self, probed: Probed, k: usize) -> Option<bool> {
        match probed {
            Probed::Unknown => None,
            Probed::Whole(blocked) => Some(blocked),
            Probed::Regions { front, hidden } => {
                let r = usize::from(self.region[k]);
                let near = self.touching[r];
                if front & (1 << r) == 0 || near & !front != 0 {
                    return None;
                }
                let near_hidden = hidden & near;
                // Blocked is answered only two rings deep: an opening (a
                // door, a window) is a small open patch in a blocked
                // facet, and can poke into a region past its neighbours.
                let ring2 = self.ring2[r];
                if near_hidden == 0 {
                    Some(false)
                } else if ring2 & !front == 0 && hidden & ring2 == ring2 {
                    Some(true)
                } else if self.probes[r] as usize == k {
                    // The probe itself was asked.
                    Some(hidden & (1 << r) != 0)
                } else {
                    None
                }
            }
        }
    }
}

/// What a sky facet's probes said from one receiver ([`SkyProbes::ask`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Probed {
    /// Too few probes in front of the receiver to judge: every direction
    /// is asked.
    Unknown,
    /// Every probe in front agreed: the whole facet is blocked (`true`)
    /// or open.
    Whole(bool),
    /// They disagreed; bit `p` set in `front` for each probe in front,
    /// and in `hidden` for each of those found blocked.
    Regions {
        /// The probes in front of the receiver.
        front: u32,
        /// Those of them blocked.
        hidden: u32,
    },
}

/// The visibility of a whole shooter from the receiver at `x` with unit
/// normal `nx`, when its probes (`probes`, indices into `samples`) say it
/// (a far shooter's, [`crate::solver::accel::far_shooters`]; a sky facet's
/// probes also answer for regions, [`SkyProbes`]):
/// `Some(blocked)` when every probe in front of the receiver's plane gives
/// the same answer (asked by `blocked(k, position)`) and at least
/// [`MIN_PROBES`] are in front; `None` when they disagree or too few face
/// it (then every direction must be asked). Stops at the first
/// disagreement.
pub fn verdict(
    probes: &[u32],
    samples: &[ShooterSample],
    x: Vec3,
    nx: Vec3,
    mut blocked: impl FnMut(usize, Vec3) -> bool,
) -> Option<bool> {
    let (mut seen, mut asked) = (None, 0usize);
    for &p in probes {
        let s = samples[p as usize].position;
        if (s - x).dot(nx) <= 0.0 {
            continue;
        }
        asked += 1;
        let b = blocked(p as usize, s);
        match seen {
            None => seen = Some(b),
            Some(v) if v != b => return None,
            _ => {}
        }
    }
    seen.filter(|_| asked >= MIN_PROBES)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::formfactor::ShooterSample;
    use crate::solver::tuning::SKY_PROBES;

    fn grid(n: usize) -> Vec<ShooterSample> {
        (0..n * n)
            .map(|k| ShooterSample {
                position: Vec3::new((k % n) as f32, 10.0, (k / n) as f32),
                ..ShooterSample::point(Vec3::ZERO, 1.0)
            })
            .collect()
    }

    #[test]
    fn probes_cover_the_facet_evenly() {
        let samples = grid(16);
        let probes = spread(&samples, SKY_PROBES);
        assert_eq!(probes.len(), SKY_PROBES);
        assert!(probes.windows(2).all(|w| w[0] < w[1]), "sorted, distinct");
        // Every sample lies within 4.3 grid steps of some probe: no hole
        // larger than a quarter of the facet (a regular 4 × 4 lattice
        // would leave 2.2; farthest-point sampling is within 2× of the
        // best covering).
        for s in &samples {
            let d = probes
                .iter()
                .map(|&p| samples[p as usize].position.distance(s.position))
                .fold(f32::INFINITY, f32::min);
            assert!(d <= 4.3, "a sample {d} from every probe");
        }
        assert_eq!(spread(&samples[..10], SKY_PROBES).len(), 10);
    }

    /// A straight shadow edge across a facet of 16 × 16 directions, at
    /// every offset and three slopes: the regions answer for about a third
    /// of the directions (measured: 35 %) and nearly all rightly
    /// (measured: 8 of 4,059 wrong, where the edge clips a region at the
    /// facet's border between two probes: what the whole facet's verdict
    /// misses too).
    #[test]
    fn regions_answer_away_from_an_edge_and_ask_along_it() {
        let samples = grid(16);
        let sky = SkyProbes::new(&samples, SKY_PROBES);
        assert_eq!(sky.probes().len(), SKY_PROBES);
        let (below, up) = (Vec3::new(7.5, 0.0, 7.5), Vec3::Y);
        let (mut answered, mut total, mut wrong) = (0, 0, 0);
        for slope in [0.0f32, 0.5, 2.0] {
            for offset in 1..16 {
                // Blocked where x + slope * z < offset (+ slope * 7.5).
                let edge = |s: Vec3| s.x + slope * (s.z - 7.5) < offset as f32 - 0.5;
                let mut asked = 0;
                let probed = sky.ask(&samples, below, up, |_, s| {
                    asked += 1;
                    edge(s)
                });
                assert_eq!(asked, SKY_PROBES, "every probe in front is asked once");
                for (k, s) in samples.iter().enumerate() {
                    total += 1;
                    if let Some(blocked) = sky.seen(probed, k) {
                        answered += 1;
                        if blocked != edge(s.position) {
                            wrong += 1;
                        }
                    }
                }
            }
        }
        let share = answered as f64 / total as f64;
        assert!(
            (wrong as f64) < 0.005 * answered as f64,
            "{wrong} of {answered} answered wrongly"
        );
        assert!(
            share > 0.3,
            "regions answered only {share} of the directions"
        );
        assert!(
            share < 0.95,
            "regions answered {share}: the edge is never asked"
        );
        // All open: the whole facet, every direction answered.
        let open = sky.ask(&samples, below, up, |_, _| false);
        assert_eq!(open, Probed::Whole(false));
        assert!((0..samples.len()).all(|k| sky.seen(open, k) == Some(false)));
        // Facing away: nothing asked, nothing answered.
        let away = sky.ask(&samples, below, -up, |_, _| panic!("no ray behind"));
        assert_eq!(away, Probed::Unknown);
        assert_eq!(sky.seen(away, 0), None);
    }

    #[test]
    fn a_verdict_needs_agreeing_probes_in_front() {
        let samples = grid(16);
        let probes = spread(&samples, SKY_PROBES);
        let up = Vec3::Y;
        let below = Vec3::new(7.5, 0.0, 7.5);
        // All open, all blocked.
        assert_eq!(
            verdict(&probes, &samples, below, up, |_, _| false),
            Some(false)
        );
        assert_eq!(
            verdict(&probes, &samples, below, up, |_, _| true),
            Some(true)
        );
        // A shadow edge across the facet: no verdict.
        assert_eq!(
            verdict(&probes, &samples, below, up, |_, s| s.x < 8.0),
            None
        );
        // Facing away: no probe in front, no verdict.
        let mut asked = 0;
        assert_eq!(
            verdict(&probes, &samples, below, -up, |_, _| {
                asked += 1;
                false
            }),
            None
        );
        assert_eq!(asked, 0, "no ray behind the receiver");
        // Fewer than MIN_PROBES in front: no verdict, however they agree.
        let few: Vec<u32> = probes[..MIN_PROBES - 1].to_vec();
        assert_eq!(verdict(&few, &samples, below, up, |_, _| false), None);
        assert_eq!(
            verdict(&probes[..MIN_PROBES], &samples, below, up, |_, _| false),
            Some(false)
        );
    }
}
