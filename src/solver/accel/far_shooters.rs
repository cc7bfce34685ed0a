//! A shooter seen from far away is probed first: a receiving vertex asks
//! a few of its samples' shadow rays, and when they agree takes that
//! answer for all of them.
//!
//! A polygon that shoots alone (an emitter, above all) shoots from its
//! samples, and every receiving vertex asks one shadow ray per sample so
//! that the penumbra of an occluder is sampled by as many rays. A lamp's
//! near surroundings need that; but the lamps of a large room light every
//! vertex of it, and most of those vertices are many lamp widths away,
//! where penumbrae are narrow: a shooter `D` across, seen from `R · D`
//! away, gives an occluder at distance `a` from the receiver a penumbra
//! about `D · a / (R · D − a) ≈ a / R` wide. There most vertices see all
//! of the shooter or none of it. So a vertex at least
//! [`FAR_SHOOTER_RATIO`] diameters from the shooter's middle first asks
//! [`FAR_PROBES`] of its samples, spread over it ([`probes::spread`]);
//! when all of them are in front of the receiver and agree (all open, all
//! blocked), that is the visibility of every sample ([`probes::verdict`]);
//! otherwise every sample is asked, as before. The form factor is always
//! summed over every sample: only visibility is shared.
//!
//! What the probes can miss is an occluder whose shadow falls wholly
//! between them: at the occluder, the probes' rays are at most
//! `D · a / (R · D)`, so about `a / R`, apart, which a chair leg can slip
//! through. Such a leg then hides none of the lamp from a vertex it should
//! partly shade, by the leg's share of the lamp seen from there.
//! Measured on the 60-table hall against the unclustered solve
//! (`docs/accuracy.md`, Far lamps probed): the picture 0.31 % before,
//! 0.29 % with four probes from 6 diameters, the lamps' steps casting 38 %
//! of their rays; from 4 diameters 0.32 % and 32 %; one ray from the
//! middle instead of probes 0.44 % and 17 %, with spots beside every
//! leg. Per polygon, 6 diameters still left chair-leg faces 2.5 % too
//! bright; the probes now start at 12 ([`FAR_SHOOTER_RATIO`]).
//!
//! It goes with the other receiver approximations: off with
//! `--exact-receivers` and `--no-clustering`. A vertex's answer depends
//! only on its own rays, so the bits do not depend on the thread count.

use super::probes;
use crate::solver::kernel::formfactor::ShooterSample;
use crate::solver::tuning::{FAR_PROBES, FAR_SHOOTER_RATIO};
use glam::Vec3;

/// Where a shooter is far, and the samples that probe it there.
///
/// Invariant: `probes` index the shooter's samples, [`FAR_PROBES`] of
/// them, distinct; `far_r2 > 0`.
#[derive(Clone, Debug, PartialEq)]
pub struct FarShooter {
    /// The middle of the bounding box of the samples' cells, scene units.
    centre: Vec3,
    /// `(FAR_SHOOTER_RATIO · diameter)²`, square scene units, the
    /// diameter being that box's.
    far_r2: f32,
    /// The probe samples, increasing.
    probes: Vec<u32>,
}

impl FarShooter {
    /// For a shooter with `samples`: `None` when it has no more samples
    /// than probes (probing would save nothing) or no extent.
    pub fn new(samples: &[ShooterSample]) -> Option<FarShooter> {
        if samples.len() <= FAR_PROBES {
            return None;
        }
        let (lo, hi) = samples
            .iter()
            .map(ShooterSample::bounds)
            .reduce(|(lo, hi), (l, h)| (lo.min(l), hi.max(h)))?;
        let diameter = (hi - lo).length();
        if !(diameter > 0.0 && diameter.is_finite()) {
            return None;
        }
        let far = FAR_SHOOTER_RATIO * diameter;
        Some(FarShooter {
            centre: (lo + hi) * 0.5,
            far_r2: far * far,
            probes: probes::spread(samples, FAR_PROBES),
        })
    }

    /// The probes to ask first from a receiver at `x`: `Some` when `x` is
    /// at least [`FAR_SHOOTER_RATIO`] diameters from the shooter's middle,
    /// `None` when every sample must ask its own ray.
    #[inline]
    pub fn probes_from(&self, x: Vec3) -> Option<&[u32]> {
        (x.distance_squared(self.centre) >= self.far_r2).then_some(&self.probes[..])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 4 grid of unit cells in the plane y = 3, from (0, 3, 0) to
    /// (4, 3, 4), facing down.
    fn lamp() -> Vec<ShooterSample> {
        (0..16)
            .map(|k| {
                let (a, b) = ((k % 4) as f32, (k / 4) as f32);
                let corners = [
                    Vec3::new(a, 3.0, b),
                    Vec3::new(a + 1.0, 3.0, b),
                    Vec3::new(a + 1.0, 3.0, b + 1.0),
                    Vec3::new(a, 3.0, b + 1.0),
                ];
                ShooterSample {
                    cell: Some(corners),
                    ..ShooterSample::point(Vec3::new(a + 0.5, 3.0, b + 0.5), 1.0)
                }
            })
            .collect()
    }

    #[test]
    fn far_receivers_probe_samples_spread_over_the_shooter() {
        let samples = lamp();
        let far = FarShooter::new(&samples).expect("a lamp of 16 cells");
        // Diameter √32 = 5.66: far from FAR_SHOOTER_RATIO diameters of the
        // middle (2, 3, 2), 67.9 units at 12.
        let reach = FAR_SHOOTER_RATIO * 32f32.sqrt();
        let at = |d: f32| far.probes_from(Vec3::new(2.0 + d, 3.0, 2.0));
        assert_eq!(at(reach - 0.5), None, "just inside the reach is near");
        let probes = at(reach + 0.5).expect("just past the reach is far");
        assert_eq!(
            at(-reach - 6.0),
            Some(probes),
            "the same probes from any side"
        );
        assert_eq!(probes.len(), FAR_PROBES);
        assert!(probes.windows(2).all(|w| w[0] < w[1]), "sorted, distinct");
        // Spread: no two probes in neighbouring cells, and they reach
        // into at least three of the lamp's four quarters.
        let cell = |k: u32| ((k % 4) as i32, (k / 4) as i32);
        for (i, &p) in probes.iter().enumerate() {
            for &q in &probes[i + 1..] {
                let ((a, b), (c, d)) = (cell(p), cell(q));
                assert!(
                    (a - c).abs().max((b - d).abs()) >= 2,
                    "{p} and {q} adjacent"
                );
            }
        }
        let mut quarters: Vec<_> = probes
            .iter()
            .map(|&k| (cell(k).0 / 2, cell(k).1 / 2))
            .collect();
        quarters.sort_unstable();
        quarters.dedup();
        assert!(quarters.len() >= 3, "quarters {quarters:?}");
    }

    #[test]
    fn a_shooter_of_few_samples_or_no_extent_is_never_probed() {
        let samples = lamp();
        assert_eq!(FarShooter::new(&samples[..FAR_PROBES]), None);
        let points = vec![ShooterSample::point(Vec3::ONE, 1.0); 8];
        assert_eq!(FarShooter::new(&points), None, "no extent");
    }
}
