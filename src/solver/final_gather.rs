//! The final gather: irradiance at any point of space, from a converged
//! solution.
//!
//! A point `x` with unit normal `n` (a light meter's cell, a work plane,
//! a point off every polygon) receives
//!
//! ```text
//! E(x) = Σ_e B_e · F(x → e)
//! ```
//!
//! over every element `e` of every polygon, `B_e` the element's radiosity
//! (the mean of its corners' radiosities: the mean of the Gouraud-shaded
//! values over it) and `F` the form factor from a differential area at `x`
//! to the element, with the visibility of one ray from the element's
//! centre. The form factor is the solver's own
//! ([`super::formfactor::weighted_point_to_samples`]): each element is a cell
//! sample, so a point within [`crate::solver::tuning::NEAR_FIELD_RATIO`] cell
//! diameters gets the cell's quadrature and within
//! [`crate::solver::tuning::EXACT_RATIO`] the exact point-to-cell form factor, and a
//! point on a polygon's edge or in a room's corner stays finite. The rays
//! are the solver's: shaft culling between the point and each polygon
//! ([`Visibility::box_shaft_candidates`]), the BVH where the shaft holds
//! many candidates.
//!
//! A sky facet (one element) is gathered from its own grid of samples
//! ([`crate::solver::tuning::SKY_FACET_SAMPLES`]), a ray each, as the
//! solver shoots it, weighted as it by a standard sky's luminance in each
//! direction ([`super::formfactor::polygon_samples`]): one ray from the
//! centre of a facet of 0.16 sr let a window in a room's wall pass all of
//! its light or none, and put points on a work plane 20 % to 70 % off a
//! window's sky component.
//!
//! Luminaires with a light distribution ([`crate::scene::Luminaire`]) are
//! gathered with their intensity in the direction of the point instead of
//! Lambert's cosine ([`super::distribution`]); they reflect nothing, so
//! their radiosity is their emission.
//!
//! The sun (`--sun`) is no polygon: its direct light is added at each
//! point with the rays the solver lit the vertices with
//! ([`super::sun::SunShot::irradiance`]), the share of its disc the point
//! sees.
//!
//! The result is irradiance in the scene's radiosity units: lux when
//! emission is luminous exitance in lm/m² (see [`crate::scene::Units`]).
//! Every point is independent, so [`FinalGather::irradiance_at`] runs in
//! parallel and gives the same bits whatever the thread count.

use super::distribution::Directional;
use super::formfactor::{polygon_samples, weighted_point_to_samples, SampleSet, ShooterSample};
use super::tuning::{LINEAR_CANDIDATES, SHAFT_MIN_VERTICES};
use crate::cancel::{Cancel, Cancelled};
use crate::color::Rgb;
use crate::mesh::{area_centroid, Mesh};
use crate::scene::{PolygonId, Scene};
use crate::visibility::{ShadowQuery, Visibility};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// One polygon as a source of the gather: its elements as cell samples and
/// their radiosities.
struct Source {
    polygon: PolygonId,
    normal: Vec3,
    /// One cell sample per element, at the element's area centroid.
    samples: Vec<ShooterSample>,
    /// Per sample: the element's radiosity (mean of its corners), in the
    /// scene's radiosity units.
    radiosity: Vec<Rgb>,
    /// The polygon's intensity distribution when it is a luminaire.
    directional: Option<Directional>,
}

/// A converged solution made ready to be gathered at arbitrary points.
///
/// Invariant: `sources` hold only polygons with some non-black radiosity;
/// every radiosity is finite and `>= 0` (as the solver's are).
pub struct FinalGather<'a> {
    visibility: &'a Visibility,
    near_field: bool,
    sources: Vec<Source>,
    /// Per polygon, its unit normal and whether its back is another
    /// polygon (a two-sided face): what [`FinalGather::behind_surfaces`]
    /// needs to tell the back of a surface.
    faces: Vec<(Vec3, bool)>,
    /// The scene has a sky ([`crate::scene::Scene::add_sky`]): a ray that
    /// leaves the model reaches it (the ray BVH leaves its facets out).
    sky: bool,
    /// The scene's sun, whose direct light each point adds.
    sun: Option<super::sun::SunShot>,
}

impl<'a> FinalGather<'a> {
    /// Prepares the gather over `mesh` (built from `scene`, refined or not)
    /// with `radiosity` one value per mesh vertex (the solver's solution,
    /// in the scene's radiosity units). `near_field` as
    /// [`super::Approximations::near_field`].
    pub fn new(
        scene: &Scene,
        mesh: &Mesh,
        visibility: &'a Visibility,
        radiosity: &[Rgb],
        near_field: bool,
    ) -> FinalGather<'a> {
        let directional = Directional::for_scene(scene);
        let mut sources = Vec::new();
        for (i, pm) in mesh.polygons.iter().enumerate() {
            let elements = &mesh.elements[pm.elements.start as usize..pm.elements.end as usize];
            let mut samples = Vec::with_capacity(elements.len());
            let mut values = Vec::with_capacity(elements.len());
            for e in elements {
                let corners = e.corners();
                let p: Vec<Vec3> = corners.iter().map(|c| mesh.positions[c.index()]).collect();
                let b = corners
                    .iter()
                    .map(|c| radiosity.get(c.index()).copied().unwrap_or_default())
                    .fold(Rgb::BLACK, |a, b| a + b)
                    * (1.0 / corners.len() as f64);
                let cell = [p[0], p[1], p[2], *p.get(3).unwrap_or(&p[2])];
                samples.push(ShooterSample::cell(
                    area_centroid(&p),
                    mesh.element_area(e),
                    cell,
                ));
                values.push(b);
            }
            if values.iter().all(|b| b.is_black()) {
                continue;
            }
            // A sky facet is one element far larger than a window seen
            // from inside: one ray from its centre would let all of its
            // light in or none. It is gathered from the samples it shoots
            // from, each with its own ray, as the solver lights the
            // scene's vertices with it.
            if let Some(polygon) = scene.polygons.get(i).filter(|_| pm.sky) {
                let set = SampleSet::for_polygon(SampleSet::Centre, polygon);
                samples = polygon_samples(scene, i, pm, mesh, set);
                values = vec![values[0]; samples.len()];
            }
            sources.push(Source {
                polygon: PolygonId(i as u32),
                normal: pm.normal,
                samples,
                radiosity: values,
                directional: directional.get(i).cloned().flatten(),
            });
        }
        FinalGather {
            visibility,
            near_field,
            sources,
            faces: mesh
                .polygons
                .iter()
                .map(|pm| (pm.normal, pm.has_back))
                .collect(),
            sky: scene.polygons.iter().any(|p| p.surface.sky),
            sun: super::sun::SunShot::for_scene(scene),
        }
    }

    /// Whether `x` lies behind the scene's surfaces: inside a solid object
    /// (a work-plane point inside a cabinet) or outside the walls (a grid
    /// over a room's bounds reaching past a leaning wall). Looking from
    /// `x` along `n` and four directions square to it, every ray meets
    /// the back of a single-sided surface or leaves the scene, and at
    /// least one meets a back. A point under a table top sees the walls'
    /// fronts sideways and is not behind; one in open space meets no back;
    /// one that sees the sky (a ray leaving a model with a sky) is lit,
    /// so not behind.
    /// Two-sided surfaces have no back, so nothing inside them is found.
    /// Such points receive no light, and a lighting designer leaves them
    /// out of a work plane's figures.
    pub fn behind_surfaces(&self, x: Vec3, n: Vec3) -> bool {
        let n = n.normalize_or_zero();
        if n == Vec3::ZERO {
            return false;
        }
        let (t1, t2) = n.any_orthonormal_pair();
        let mut backs = 0;
        for d in [n, t1, -t1, t2, -t2] {
            match self.visibility.first_hit(x, d) {
                None if self.sky => return false,
                None => {}
                Some((p, _)) => match self.faces.get(p.index()) {
                    Some(&(normal, false)) if normal.dot(d) > 0.0 => backs += 1,
                    _ => return false,
                },
            }
        }
        backs > 0
    }

    /// Irradiance at `x` (scene units) on a surface of unit normal `n`, in
    /// the scene's radiosity units (lux with luminous exitance): light
    /// arriving from behind the surface does not count.
    pub fn irradiance(&self, x: Vec3, n: Vec3) -> Rgb {
        let mut candidates = Vec::new();
        let mut sum = Rgb::BLACK;
        let point_box = (DVec3::from(x), DVec3::from(x));
        for source in &self.sources {
            let id = source.polygon;
            // A shaft is worth building only for polygons of many elements.
            let culled = source.samples.len() >= SHAFT_MIN_VERTICES as usize;
            if culled {
                self.visibility.box_shaft_candidates(
                    point_box,
                    id,
                    LINEAR_CANDIDATES,
                    &mut candidates,
                );
            }
            let visibility = self.visibility;
            let query = ShadowQuery::choose(culled.then_some(&candidates[..]), LINEAR_CANDIDATES);
            let occluded = |s: Vec3| visibility.shadow(query, s, x, (id, id));
            let e = match &source.directional {
                Some(d) => d.gather(x, n, &source.samples, &source.radiosity, |_, s| occluded(s)),
                None => {
                    weighted_point_to_samples(
                        x,
                        n,
                        source.normal,
                        &source.samples,
                        |k| source.radiosity[k],
                        None,
                        self.near_field,
                        |_, s| occluded(s),
                    )
                    .0
                }
            };
            sum += e;
        }
        if let Some(sun) = &self.sun {
            let ends = (super::sun::NO_POLYGON, super::sun::NO_POLYGON);
            sum += Rgb::splat(sun.irradiance(self.visibility, x, n, ends));
        }
        sum
    }

    /// [`FinalGather::irradiance`] at every `(position, unit normal)` of
    /// `points`, in order, in parallel.
    pub fn irradiance_at(&self, points: &[(Vec3, Vec3)]) -> Vec<Rgb> {
        points
            .par_iter()
            .map(|&(x, n)| self.irradiance(x, n))
            .collect()
    }

    /// [`FinalGather::irradiance_at`], stopping with [`Cancelled`] soon
    /// after `cancel` is set: each point checks it (one atomic load) before
    /// its gather, which takes a millisecond or so.
    pub fn irradiance_at_cancellable(
        &self,
        points: &[(Vec3, Vec3)],
        cancel: &Cancel,
    ) -> Result<Vec<Rgb>, Cancelled> {
        let values = points
            .par_iter()
            .map(|&(x, n)| {
                if cancel.is_set() {
                    Rgb::BLACK
                } else {
                    self.irradiance(x, n)
                }
            })
            .collect();
        cancel.check()?;
        Ok(values)
    }
}

/// The irradiance at every mesh vertex implied by its radiosity:
/// `(b − e) / ρ` per channel, `b` the vertex's radiosity, `e` and `ρ` its
/// polygon's emission and reflectance, in the scene's radiosity units. On
/// a channel whose reflectance is 0 nothing is reflected, so nothing tells
/// what arrives: the value is 0 there (a black surface, a luminaire; use
/// [`FinalGather`] for such points). This is what the solver itself
/// gathered at the vertex, without a second gather.
pub fn vertex_irradiance(scene: &Scene, mesh: &Mesh, radiosity: &[Rgb]) -> Vec<Rgb> {
    radiosity
        .iter()
        .zip(&mesh.vertex_polygon)
        .map(|(&b, &p)| {
            let m = scene.material_of(p);
            let (e, rho) = (m.emission(), m.reflectance());
            let channel = |b: f64, e: f64, rho: f64| {
                if rho > 0.0 {
                    ((b - e) / rho).max(0.0)
                } else {
                    0.0
                }
            };
            Rgb::new(
                channel(b.r, e.r, rho.r),
                channel(b.g, e.g, rho.g),
                channel(b.b, e.b, rho.b),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bundled office: a cabinet (a one-sided box) against the back
    /// wall, a desk on four legs, open floor.
    #[test]
    fn points_inside_a_box_are_behind_surfaces_and_points_under_a_desk_are_not() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/office.sc");
        let s = crate::scene::load(&path).unwrap();
        let mesh = crate::mesh::build(&s, &crate::mesh::MeshOptions::for_scene(&s)).unwrap();
        let vis = Visibility::new(&s);
        let radiosity = vec![Rgb::splat(1.0); mesh.vertex_count()];
        let g = FinalGather::new(&s, &mesh, &vis, &radiosity, true);
        // Cabinet: 0.3..1.5 × 0..0.7 × 3.5..3.98.
        assert!(g.behind_surfaces(Vec3::new(0.9, 0.3, 3.7), Vec3::Y));
        assert!(g.behind_surfaces(Vec3::new(0.31, 0.69, 3.51), Vec3::Y));
        // Under the desk top (0.72 high), between its legs.
        assert!(!g.behind_surfaces(Vec3::new(2.5, 0.3, 2.0), Vec3::Y));
        // Open floor, and just outside the cabinet's front.
        assert!(!g.behind_surfaces(Vec3::new(1.0, 0.3, 1.0), Vec3::Y));
        assert!(!g.behind_surfaces(Vec3::new(0.9, 0.3, 3.45), Vec3::Y));
        assert!(!g.behind_surfaces(Vec3::new(0.9, 0.3, 3.7), Vec3::ZERO));
        // Outside the room, beside its wall at x = 0: the wall's back one
        // way, nothing the other ways.
        assert!(g.behind_surfaces(Vec3::new(-0.5, 0.3, 2.0), Vec3::Y));
        assert!(g.behind_surfaces(Vec3::new(-0.5, 1.5, 2.0), Vec3::Y));
        // Above the ceiling, in open space: no ray meets anything.
        assert!(!g.behind_surfaces(Vec3::new(2.0, 3.5, 2.0), Vec3::Y));
    }
}
