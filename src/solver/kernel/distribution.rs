//! Emission with a light distribution: the form factor of a luminaire's
//! shot ([`crate::scene::Luminaire`]).
//!
//! A Lambertian sample of area `a_k` gives a receiver at distance `r` the
//! form factor `cosθ_s cosθ_x a_k / (π r²)` ([`super::formfactor`]). A
//! luminaire of flux `Φ` (lumens below its plane) spread over its area
//! `A` emits the exitance `e = Φ / A`; a sample standing for `a_k / A` of
//! it sends intensity `I(θ, φ) a_k / A` towards the receiver, which then
//! receives `E = I a_k cosθ_x / (A r²)`. As a form factor (`E / e`):
//!
//! ```text
//! F_k = (I(θ, φ) / Φ) · a_k · cosθ_x / r²
//! ```
//!
//! in any length unit, since `a_k / r²` is dimensionless: the scene's unit
//! enters only through `e` ([`crate::scene::Scene::set_luminaire`]). For a
//! cosine distribution `I / Φ = cosθ / π` and this is Lambert's term. A
//! receiver within [`crate::solver::tuning::NEAR_FIELD_RATIO`] cell diameters
//! of a sample sums the term over the cell's quadrature points instead.
//! Visibility is the same one ray per sample as for any shooter.

use super::formfactor::{weighted_point_to_samples, ShooterSample};
use crate::color::Rgb;
use crate::scene::{Photometry, Scene};
use crate::solver::accel::subcells::Split;
use glam::{DVec3, Vec3};
use std::sync::Arc;

/// A polygon's light distribution in scene space.
///
/// Invariants: `nadir`, `c0` and `c90` are orthonormal; `flux > 0`.
#[derive(Clone, Debug)]
pub struct Directional {
    photometry: Arc<Photometry>,
    flux: f64,
    /// The photometric nadir: the luminaire front's normal.
    nadir: DVec3,
    c0: DVec3,
    c90: DVec3,
    /// The polygon is the luminaire's back ([`crate::scene::Luminaire::
    /// upper`]): it emits away from the nadir, the table's θ > 90°.
    upper: bool,
}

impl Directional {
    /// Per polygon of `scene`: its distribution when its material is a
    /// luminaire's, else `None`.
    pub fn for_scene(scene: &Scene) -> Vec<Option<Directional>> {
        scene
            .polygons
            .iter()
            .map(|p| {
                let l = scene.luminaire_of(p.material)?;
                // A back faces away from the nadir.
                let side = if l.upper { -1.0 } else { 1.0 };
                let nadir = p.normal.as_dvec3().normalize() * side;
                // The C0 direction made exactly perpendicular to this
                // polygon's normal (a split piece or back keeps the
                // luminaire's).
                let c0 = l.c0.as_dvec3();
                let c0 = (c0 - nadir * nadir.dot(c0)).normalize_or_zero();
                let c0 = if c0 == DVec3::ZERO {
                    nadir.any_orthonormal_vector()
                } else {
                    c0
                };
                Some(Directional {
                    photometry: l.photometry.clone(),
                    flux: l.flux,
                    nadir,
                    c0,
                    c90: nadir.cross(c0),
                    upper: l.upper,
                })
            })
            .collect()
    }

    /// `I(ω) / Φ` (per steradian) in the direction `d` (any length, from
    /// the luminaire); 0 behind the polygon (above a front's plane, below
    /// a back's).
    pub fn relative_intensity(&self, d: DVec3) -> f64 {
        let len = d.length();
        if len <= 0.0 {
            return 0.0;
        }
        let cos_theta = self.nadir.dot(d) / len;
        let in_front = if self.upper {
            cos_theta < 0.0
        } else {
            cos_theta > 0.0
        };
        if !in_front {
            return 0.0;
        }
        let theta = cos_theta.clamp(-1.0, 1.0).acos();
        let phi = self.c90.dot(d).atan2(self.c0.dot(d));
        self.photometry.intensity(theta, phi) / self.flux
    }

    /// The term `(I / Φ) a cosθ_x / r²` of one point of area `a` at `s`,
    /// seen from `x` with normal `nx`; 0 behind either.
    fn point_term(&self, x: DVec3, nx: DVec3, s: DVec3, a: f64) -> f64 {
        let d = x - s;
        let r2 = d.length_squared();
        if r2 <= 0.0 {
            return 0.0;
        }
        let cos_x = -nx.dot(d) / r2.sqrt();
        if cos_x <= 0.0 {
            return 0.0;
        }
        self.relative_intensity(d) * a * cos_x / r2
    }

    /// [`weighted_point_to_samples`] for this distribution: `Σ_k weight(k)
    /// F_k` over `samples` (the luminaire's) seen from `x` (normal `nx`),
    /// and the number of visibility questions asked.
    pub fn weighted<W>(
        &self,
        x: Vec3,
        nx: Vec3,
        samples: &[ShooterSample],
        weight: impl Fn(usize) -> W,
        mut occluded: impl FnMut(usize, Vec3) -> bool,
    ) -> (W, u64)
    where
        W: Default + std::ops::AddAssign + std::ops::Mul<f64, Output = W>,
    {
        let (xd, nd) = (x.as_dvec3(), nx.as_dvec3());
        let mut sum = W::default();
        let mut rays = 0;
        for (k, s) in samples.iter().enumerate() {
            let r2 = x.distance_squared(s.position);
            let term = if s.cell.is_some() && r2 < s.near_r2 {
                let q = &s.quadrature;
                (0..4)
                    .map(|l| {
                        let p = DVec3::new(q.x[l] as f64, q.y[l] as f64, q.z[l] as f64);
                        self.point_term(xd, nd, p, q.area[l] as f64)
                    })
                    .sum()
            } else {
                self.point_term(xd, nd, s.position.as_dvec3(), s.area)
            };
            if term <= 0.0 {
                continue;
            }
            rays += 1;
            if !occluded(k, s.position) {
                sum += weight(k) * term;
            }
        }
        (sum, rays)
    }

    /// The irradiance at `x` (normal `nx`) from the luminaire's `samples`
    /// carrying `radiosity` (its emission), in radiosity units.
    pub fn gather(
        &self,
        x: Vec3,
        nx: Vec3,
        samples: &[ShooterSample],
        radiosity: &[Rgb],
        occluded: impl FnMut(usize, Vec3) -> bool,
    ) -> Rgb {
        self.weighted(x, nx, samples, |k| radiosity[k], occluded).0
    }
}

/// The form factor of a shot from a polygon: [`Directional::weighted`]
/// when it has a distribution (its cells taken whole, each with its
/// sub-cells' mean), else [`weighted_point_to_samples`] (the arguments as
/// there). The one place the solver's emitters differ.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn shot_point_to_samples<W>(
    directional: Option<&Directional>,
    x: Vec3,
    nx: Vec3,
    ns: Vec3,
    samples: &[ShooterSample],
    weight: impl Fn(usize) -> W,
    split: Option<&Split<W>>,
    near_field: bool,
    occluded: impl FnMut(usize, Vec3) -> bool,
) -> (W, u64)
where
    W: Copy + Default + std::ops::AddAssign + std::ops::Mul<f64, Output = W>,
{
    match directional {
        Some(d) => d.weighted(x, nx, samples, weight, occluded),
        None => weighted_point_to_samples(x, nx, ns, samples, weight, split, near_field, occluded),
    }
}
