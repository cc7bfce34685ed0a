//! The sun's direct light ([`crate::scene::Sun`], `--sun`), shot once
//! before the solver's first step.
//!
//! The sun is a parallel light with a disc of
//! [`SUN_DISC_DEGREES`](crate::scene::SUN_DISC_DEGREES): a point `x` with
//! unit normal `n` receives
//!
//! ```text
//! E(x) = E_n · max(0, n·s) · V(x)
//! ```
//!
//! with `E_n` the direct normal illuminance, `s` the direction towards the
//! sun's centre and `V` the share of the disc's
//! [`SUN_DISC_SAMPLES`](crate::scene::SUN_DISC_SAMPLES) stratified
//! directions ([`crate::scene::Sun::disc_directions`]) whose rays from
//! `x` reach past the scene's bounds unblocked, each through the BVH. A
//! shadow's edge so gets the penumbra of a disc, `V` passing from 0 to 1
//! over the angle the sun spans. A sky's enclosure lies farther out than
//! the rays go, so it does not block them.
//!
//! Before the first step every element vertex `l` of a reflecting polygon
//! gets `b_l += ρ E(x_l)`, and its unshot radiosity the same (when
//! [`Progressive::new`] starts the solve): the steps then reflect the sunlight as
//! any light they received, and the window shows it from the first
//! picture. The final gather adds `E` at its points with the same rays
//! ([`super::final_gather`]), and a refined mesh's new vertices get it as
//! they gather the light shot so far ([`Progressive::refined_state`]).

use super::Progressive;
use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::{PolygonId, Scene, Sun};
use crate::visibility::{LastBlocker, Visibility};
use glam::Vec3;
use rayon::prelude::*;

/// No polygon: the segment ends of a point that lies on none (a work
/// plane's, a light meter's), so that no polygon is left out of its
/// shadow test.
pub const NO_POLYGON: PolygonId = PolygonId(u32::MAX);

/// Vertices per parallel run of [`SunShot::vertex_irradiance`].
const VERTEX_RUN: usize = 256;

/// The sun made ready to light points of one scene: its disc's directions
/// and how far a ray must go to leave the scene.
///
/// Invariant: `directions` are unit vectors over the sun's disc;
/// `centre` and `extent` are the scene's bounds' (the sky's facets left
/// out).
#[derive(Clone, Debug)]
pub struct SunShot {
    sun: Sun,
    directions: Vec<Vec3>,
    /// The centre of the scene's bounds, scene units.
    centre: Vec3,
    /// The diagonal of the scene's bounds, scene units.
    extent: f32,
}

impl SunShot {
    /// The scene's sun made ready, `None` when it has none.
    pub fn for_scene(scene: &Scene) -> Option<SunShot> {
        let sun = scene.sun?;
        let (lo, hi) = scene.bounds();
        Some(SunShot {
            sun,
            directions: sun.disc_directions(),
            centre: (lo + hi) * 0.5,
            extent: scene.extent(),
        })
    }

    /// The sun.
    pub fn sun(&self) -> &Sun {
        &self.sun
    }

    /// The share of the sun's disc seen from `x` (scene units), in
    /// `[0, 1]`: the disc directions whose segments from `x` to past the
    /// scene's bounds no polygon crosses, but `ends` and the polygons in
    /// their planes ([`Visibility::occluded`]).
    pub fn visible_fraction(
        &self,
        visibility: &Visibility,
        x: Vec3,
        ends: (PolygonId, PolygonId),
    ) -> f64 {
        // Past the bounds from anywhere inside them, and well inside a
        // sky's enclosure (at least ten half-diagonals out).
        let reach = (x - self.centre).length() + self.extent.max(f32::MIN_POSITIVE);
        let mut last = LastBlocker::default();
        let open = self
            .directions
            .iter()
            .filter(|&&d| !visibility.occluded_remembering(x, x + d * reach, ends, &mut last))
            .count();
        open as f64 / self.directions.len() as f64
    }

    /// The sun's direct irradiance at `x` on a surface of unit normal
    /// `n`, in the scene's radiosity units: `E_n max(0, n·s) V`, with `V`
    /// from [`SunShot::visible_fraction`] (no rays when `n` faces away).
    pub fn irradiance(
        &self,
        visibility: &Visibility,
        x: Vec3,
        n: Vec3,
        ends: (PolygonId, PolygonId),
    ) -> f64 {
        let cosine = f64::from(n.dot(self.sun.direction));
        if cosine <= 0.0 {
            return 0.0;
        }
        self.sun.normal_illuminance * cosine * self.visible_fraction(visibility, x, ends)
    }

    /// Per vertex of `mesh`, the sun's direct irradiance at its sample
    /// position on its polygon's front; 0 on sky facets and on polygons
    /// of black `reflectance` (per polygon), which would reflect none of
    /// it. Runs in parallel; the same bits whatever the thread count.
    /// Also the rays cast.
    pub fn vertex_irradiance(
        &self,
        mesh: &Mesh,
        visibility: &Visibility,
        reflectance: &[Rgb],
    ) -> (Vec<f64>, u64) {
        let lit: Vec<(f64, u64)> = (0..mesh.vertex_count())
            .into_par_iter()
            .with_min_len(VERTEX_RUN)
            .map(|l| {
                let j = mesh.vertex_polygon[l];
                let pm = &mesh.polygons[j.index()];
                let black = reflectance.get(j.index()).is_none_or(|r| r.is_black());
                if pm.sky || black || pm.normal.dot(self.sun.direction) <= 0.0 {
                    return (0.0, 0);
                }
                let x = mesh.sample_positions[l];
                let e = self.irradiance(visibility, x, pm.normal, (j, j));
                (e, self.directions.len() as u64)
            })
            .collect();
        let rays = lit.iter().map(|x| x.1).sum();
        (lit.into_iter().map(|x| x.0).collect(), rays)
    }
}

impl Progressive<'_> {
    /// Adds the sun's direct light, reflected, to every vertex's radiosity
    /// and unshot radiosity (`ρ E`, see the module docs); nothing without
    /// a sun. Called once, by [`Progressive::new`], before the first step
    /// and before the initial unshot power is taken.
    pub(super) fn receive_sun(&mut self) {
        let Some(shot) = &self.sun else {
            return;
        };
        let mesh = self.mesh.clone();
        let (irradiance, rays) = shot.vertex_irradiance(&mesh, self.visibility, &self.reflectance);
        let delta: Vec<Rgb> = irradiance
            .iter()
            .zip(&mesh.vertex_polygon)
            .map(|(&e, j)| self.reflectance[j.index()] * e)
            .collect();
        for (b, d) in self.radiosity.iter_mut().zip(&delta) {
            *b += *d;
        }
        for j in 0..mesh.polygons.len() {
            self.unshot.accumulate(&mesh, j, &delta);
        }
        self.rays += rays;
        self.changed();
    }

    /// The sun's direct irradiance at a point `x` of polygon `j` with
    /// unit normal `n` (a refined mesh's new vertex); 0 without a sun.
    pub(super) fn sun_irradiance(&self, x: Vec3, n: Vec3, j: PolygonId) -> f64 {
        self.sun
            .as_ref()
            .map_or(0.0, |shot| shot.irradiance(self.visibility, x, n, (j, j)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{floor_under_a_plate, regular_mesh};

    #[test]
    fn points_in_the_open_get_the_full_sun_and_points_under_the_plate_none() {
        let s = floor_under_a_plate();
        let vis = Visibility::new(&s);
        let shot = SunShot::for_scene(&s).unwrap();
        let e = |x: Vec3| shot.irradiance(&vis, x, Vec3::Z, (NO_POLYGON, NO_POLYGON));
        assert!((e(Vec3::new(0.5, 0.5, 0.0)) - 1000.0).abs() < 1e-9);
        assert_eq!(e(Vec3::new(2.0, 2.0, 0.0)), 0.0);
        // A surface facing away gets nothing, and one tilted 60° half.
        assert_eq!(
            shot.irradiance(&vis, Vec3::ZERO, -Vec3::Z, (NO_POLYGON, NO_POLYGON)),
            0.0
        );
        let tilted = Vec3::new(0.0, 60f32.to_radians().sin(), 60f32.to_radians().cos());
        let half = shot.irradiance(
            &vis,
            Vec3::new(0.5, 0.5, 0.0),
            tilted,
            (NO_POLYGON, NO_POLYGON),
        );
        assert!((half - 500.0).abs() < 1e-3, "{half}");
        // Right under the plate's edge half the disc is hidden.
        let edge = shot.visible_fraction(&vis, Vec3::new(1.0, 2.0, 0.0), (NO_POLYGON, NO_POLYGON));
        assert!((edge - 0.5).abs() < 0.07, "{edge}");
    }

    #[test]
    fn the_solver_starts_from_the_reflected_sun() {
        let s = floor_under_a_plate();
        let mesh = regular_mesh(&s, 0.25);
        let vis = Visibility::new(&s);
        let solver = Progressive::new(&s, &mesh, &vis, crate::solver::SolverOptions::default());
        let b = solver.radiosity();
        for (l, p) in mesh.vertex_polygon.iter().enumerate() {
            let x = mesh.sample_positions[l];
            let want = if p.0 == 1 {
                0.0
            } else {
                let open = !(1.01..2.99).contains(&x.x) || !(1.01..2.99).contains(&x.y);
                let shaded = (1.0..3.0).contains(&x.x) && (1.0..3.0).contains(&x.y);
                if open && !shaded {
                    500.0
                } else if !open {
                    0.0
                } else {
                    continue;
                }
            };
            assert!((b[l].r - want).abs() < 1e-9, "{x}: {} vs {want}", b[l].r);
        }
        assert!(solver.initial_unshot_power() > 0.0);
        // Without the sun nothing is lit.
        let mut dark = s.clone();
        dark.sun = None;
        let solver = Progressive::new(&dark, &mesh, &vis, crate::solver::SolverOptions::default());
        assert!(solver.radiosity().iter().all(|b| b.is_black()));
    }
}
