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
//! the visibility of the whole facet from it ([`verdict`]), and the form
//! factor is still summed over every direction. Otherwise every direction
//! is asked, as before.
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

/// The visibility of a whole sky facet from the receiver at `x` with unit
/// normal `nx`, when its probes (`probes`, indices into `samples`) say it:
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
