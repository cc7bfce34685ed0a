//! Whether `--sky` lights anything: in a closed room no sky light gets
//! in, and the sky's facets only cost steps (on the bundled rtable, four
//! times as many) for the same picture. The batch run says so, once.
//!
//! Two facts decide it. First, the camera's eye is enclosed: of
//! [`SKY_EYE_RAYS`] rays from it, spread evenly over the sphere, none
//! reaches the sky (a window or a missing wall the camera can see lets
//! one out). Second, the sky's steps lit the scene with less than
//! [`SKY_BLOCKED_SHARE`] of what they would give it in the open. Every
//! sky facet is an emitter that shoots alone and receives nothing
//! (see `Scene::add_sky`), so it shoots once, and its step
//! changes nothing but the radiosity of what its light reaches; what the
//! facets that shot added to the scene's reflected power `Σ b·A` is
//! compared with their share of what the whole sky `S` would add to the
//! scene standing in the open, `Σ ρ·S·A` over the polygons' fronts. A
//! closed room still gets a little from outside: through the seams of
//! its walls, and on the bottoms of boxes resting on its floor, which
//! face the outside below it (measured 0.01 % on rtable, 0.5 % on the
//! office and 1.1 % on table_chair), so the eye must be enclosed too.
//!
//! The verdict comes once every facet has shot, or at the end of the
//! solve when a sky much weaker than the lamps was left partly unshot.

use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solver::StepReport;
use crate::visibility::Visibility;
use glam::Vec3;

/// Rays cast from the camera's eye looking for the sky, spread evenly
/// over the sphere: one per 0.012 sr, so a window 1 m across seen from
/// 5 m (0.04 sr) is met by about three.
pub const SKY_EYE_RAYS: u32 = 1024;

/// The share of what the sky would give the scene in the open
/// ([`SkyWatch`]) below which a scene whose camera is enclosed counts as
/// closed to the sky: above what closed rooms get from outside (1.1 % at
/// most on the bundled ones, see the module docs).
pub const SKY_BLOCKED_SHARE: f64 = 0.02;

/// The warning said when the sky lights nothing ([`SkyWatch`]).
pub const SKY_BLOCKED: &str = "--sky: no sky light reaches the scene (it is closed): the \
     camera sees no opening and the sky's light lit nothing inside; the sky costs steps and adds \
     nothing to the picture (leave it out, or open the model)";

/// The watch over the sky's steps of one solve.
#[derive(Debug)]
pub struct SkyWatch {
    /// Per polygon: whether it is a sky facet that has not shot yet.
    unshot_facets: Vec<bool>,
    /// Sky facets in all.
    facets: usize,
    /// Sky facets that have shot.
    shot: usize,
    /// The area each mesh vertex stands for ([`Mesh::vertex_areas`]).
    areas: Vec<f64>,
    /// The scene's reflected power `Σ b·A` (channel mean, sky facets left
    /// out) after the last step seen.
    power: f64,
    /// What the sky's steps added to it so far.
    delivered: f64,
    /// What the whole sky would add in the open: `Σ ρ·S·A` over the
    /// polygons' fronts (channel means).
    open: f64,
}

impl SkyWatch {
    /// A watch for a solve of `scene` on `mesh` whose solution is
    /// `radiosity` before its next step; `None` when there is nothing to
    /// watch: no sky, a sky that could light nothing (no reflectance), or
    /// a camera that sees the sky through an opening (`visibility` is
    /// the scene's, its sky included).
    pub fn new(
        scene: &Scene,
        mesh: &Mesh,
        radiosity: &[Rgb],
        visibility: &Visibility,
    ) -> Option<SkyWatch> {
        let sky = scene.sky()?;
        let unshot_facets: Vec<bool> = mesh.polygons.iter().map(|pm| pm.sky).collect();
        let facets = unshot_facets.iter().filter(|&&s| s).count();
        let open: f64 = scene
            .polygons
            .iter()
            .zip(&mesh.polygons)
            .filter(|(_, pm)| !pm.sky)
            .map(|(p, pm)| {
                let rho = scene
                    .materials
                    .get(p.material.index())
                    .map_or(0.0, |m| m.reflectance().mean());
                rho * sky.mean() * pm.area
            })
            .sum();
        if facets == 0 || open.is_nan() || open <= 0.0 || eye_sees_sky(scene, visibility) {
            return None;
        }
        let areas = mesh.vertex_areas();
        let power = reflected_power(mesh, &areas, radiosity);
        Some(SkyWatch {
            unshot_facets,
            facets,
            shot: 0,
            areas,
            power,
            delivered: 0.0,
            open,
        })
    }

    /// Takes the finished step `report`, after which the solution on
    /// `mesh` is `radiosity`. Once every facet has shot, returns whether
    /// the sky lit the scene with less than [`SKY_BLOCKED_SHARE`] of what
    /// it would in the open (then say [`SKY_BLOCKED`]; the watch is over
    /// either way); `None` while it goes on. Facets below the scene light
    /// the bottoms of what rests on the floor far more than the others
    /// light anything, so no verdict is drawn from a part of them.
    pub fn step(&mut self, report: &StepReport, mesh: &Mesh, radiosity: &[Rgb]) -> Option<bool> {
        let before = self.power;
        self.power = reflected_power(mesh, &self.areas, radiosity);
        let shooter = report.shooter.index();
        if !self.unshot_facets.get(shooter).copied().unwrap_or(false) {
            return None;
        }
        self.unshot_facets[shooter] = false;
        self.shot += 1;
        self.delivered += self.power - before;
        (self.shot == self.facets).then(|| self.blocked())
    }

    /// At the end of the solve: whether the facets that shot (at least
    /// one) lit the scene with too little ([`SkyWatch::step`]).
    pub fn finish(&self) -> bool {
        self.shot > 0 && self.blocked()
    }

    /// Whether what the facets that shot delivered is under
    /// [`SKY_BLOCKED_SHARE`] of their share of the open sky's.
    fn blocked(&self) -> bool {
        let their_share = self.open * self.shot as f64 / self.facets as f64;
        self.delivered < SKY_BLOCKED_SHARE * their_share
    }
}

/// Whether one of [`SKY_EYE_RAYS`] rays from the scene camera's eye, in
/// directions spread evenly over the sphere (a Fibonacci lattice),
/// reaches a sky facet before any other polygon.
fn eye_sees_sky(scene: &Scene, visibility: &Visibility) -> bool {
    let eye = scene.camera.eye;
    let golden = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
    (0..SKY_EYE_RAYS).any(|k| {
        let z = 1.0 - (2 * k + 1) as f32 / SKY_EYE_RAYS as f32;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (golden * k as f32).sin_cos();
        let direction = Vec3::new(r * c, r * s, z);
        match visibility.first_hit(eye, direction) {
            None => true,
            Some((id, _)) => scene
                .polygons
                .get(id.index())
                .is_some_and(|p| p.surface.sky),
        }
    })
}

/// `Σ b·A` over the vertices of the polygons of `mesh` that are not sky
/// facets (channel means), in a fixed order.
fn reflected_power(mesh: &Mesh, areas: &[f64], radiosity: &[Rgb]) -> f64 {
    mesh.polygons
        .iter()
        .filter(|pm| !pm.sky)
        .flat_map(|pm| pm.vertices.clone())
        .map(|l| {
            let l = l as usize;
            radiosity.get(l).map_or(0.0, |b| b.mean()) * areas.get(l).copied().unwrap_or(0.0)
        })
        .sum()
}
