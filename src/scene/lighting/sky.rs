//! A uniform diffuse sky all around the scene (`--sky`), as Blender's
//! world colour: light that enters a model through every opening.
//!
//! The sky is an enclosure of polygons that the solver treats like any
//! emitter: a geodesic sphere ([`SKY_SUBDIVISIONS`] times subdivided
//! icosahedron) centred on the scene's bounds, [`SKY_RADIUS_FACTOR`] times
//! their half-diagonal in radius, every facet facing inward, emitting the
//! sky's radiosity and reflecting nothing, marked [`Surface::sky`]. Inside a
//! closed enclosure whose every facet has radiosity `S`, the radiance from
//! every direction is `S / π` wherever the point is, so an unoccluded plane
//! receives irradiance `S` whatever the enclosure's size or shape: the
//! radius only has to keep the facets clear of the scene. Openings let this
//! light in because each facet shoots with ray-traced visibility; a closed
//! room stays dark because every ray to its inside meets a wall.
//!
//! The facets are left out of everything that describes the scene rather
//! than light it: [`Scene::bounds`] (so the default lenmax, tolerances and
//! framing are the scene's own), the picture, the mesh exports and
//! adaptive refinement. Each is meshed as one element (its radiosity is
//! its emission, it receives nothing), and it shoots from a grid of its own
//! (see `crate::solver::tuning::SKY_FACET_SAMPLES`).

use crate::color::Rgb;
use crate::scene::{Material, MaterialId, Polygon, PolygonError, Scene, SourcePos, Surface};
use glam::DVec3;

/// Times the icosahedron's triangles are split in four for the sky: 1
/// gives 80 facets, close enough to a sphere that the directions they
/// shoot from are spread evenly (each facet subtends about 0.16 sr; the
/// solver shoots from a grid of points on each).
pub const SKY_SUBDIVISIONS: u32 = 1;

/// The sky's radius in half-diagonals of the scene's bounding box (centred
/// on it). Any enclosure gives the same unoccluded light; ten keeps every
/// receiver far from the facets compared with their sample spacing, and
/// rays from them short enough that `f32` positions stay precise.
pub const SKY_RADIUS_FACTOR: f32 = 10.0;

/// The name of the material [`Scene::add_sky`] appends.
pub const SKY_MATERIAL_NAME: &str = "sky";

/// The radius used when the scene has no extent (no polygons), in scene
/// units: the sky is then a sphere of this radius about the origin.
const EMPTY_SCENE_HALF_DIAGONAL: f32 = 1.0;

impl Scene {
    /// Adds a uniform diffuse sky of `radiosity` (in the scene's units,
    /// every channel finite, `>= 0` and at most
    /// [`MAX_EMISSION`](crate::scene::MAX_EMISSION)) around the scene: a material
    /// named [`SKY_MATERIAL_NAME`] emitting it with no reflectance, and the
    /// inward-facing facets of the enclosure described in the module docs,
    /// appended after every other polygon with [`Surface::sky`] set. The
    /// bounds are those of the scene without any sky, so adding a second
    /// one gives the same enclosure again.
    ///
    /// Fails only when the enclosure's coordinates would pass
    /// [`MAX_COORDINATE`](crate::scene::MAX_COORDINATE) (a scene within a tenth of
    /// that limit).
    pub fn add_sky(&mut self, radiosity: Rgb) -> Result<(), PolygonError> {
        let triangles = geodesic_sphere(SKY_SUBDIVISIONS);
        let emissions = vec![radiosity];
        self.add_enclosure(triangles, emissions, SKY_RADIUS_FACTOR)
            .map(|_| ())
    }

    /// Adds the enclosure of the unit triangles `triangles` (each facing
    /// the centre), centred as the module docs say, `radius_factor` times
    /// the scene's half-diagonal in radius, appended
    /// after every other polygon with [`Surface::sky`] set: one material
    /// named [`SKY_MATERIAL_NAME`] a facet emitting `emissions[i]`, or one
    /// for all when `emissions` holds a single value. Returns the
    /// enclosure's centre, in scene units.
    pub(super) fn add_enclosure(
        &mut self,
        triangles: Vec<[DVec3; 3]>,
        emissions: Vec<Rgb>,
        radius_factor: f32,
    ) -> Result<DVec3, PolygonError> {
        let (lo, hi) = self.bounds();
        let centre = ((lo + hi) * 0.5).as_dvec3();
        let half_diagonal = match (hi - lo).length() * 0.5 {
            h if h > 0.0 => h,
            _ => EMPTY_SCENE_HALF_DIAGONAL,
        };
        let radius = f64::from(half_diagonal * radius_factor);
        let first = self.materials.len() as u32;
        let shared = emissions.len() == 1;
        let mut facets = Vec::new();
        for (i, [a, b, c]) in triangles.into_iter().enumerate() {
            let material = MaterialId(first + if shared { 0 } else { i as u32 });
            let corners = [a, b, c].map(|v| (centre + v * radius).as_vec3());
            let mut polygon = Polygon::new(material, corners.to_vec(), SourcePos::default())?;
            polygon.surface = Surface {
                sky: true,
                ..Surface::default()
            };
            facets.push(polygon);
        }
        for radiosity in emissions {
            self.materials.push(Material {
                name: SKY_MATERIAL_NAME.to_string(),
                color: radiosity,
                k_diffrefl: 0.0,
                k_emission: 1.0,
            });
        }
        self.polygons.extend(facets);
        Ok(centre)
    }

    /// The radiosity of the sky [`Scene::add_sky`] added, or for a sky
    /// whose facets differ ([`Scene::add_daylight_sky`]) their mean
    /// weighted by area; `None` when the scene has none.
    pub fn sky(&self) -> Option<Rgb> {
        let mut facets = self.polygons.iter().filter(|p| p.surface.sky);
        let first = facets.next()?;
        let emission = |p: &Polygon| self.materials.get(p.material.index()).map(|m| m.emission());
        if facets.all(|p| p.material == first.material) {
            return emission(first);
        }
        let (mut sum, mut area) = (Rgb::BLACK, 0.0);
        for p in self.polygons.iter().filter(|p| p.surface.sky) {
            sum += emission(p)? * p.area;
            area += p.area;
        }
        (area > 0.0).then(|| sum / area)
    }
}

/// The triangles of a unit geodesic sphere: the icosahedron with each
/// triangle split in four `subdivisions` times, new vertices pushed out to
/// the sphere. Each triangle is counter-clockwise seen from the centre, so
/// its front faces inward. `20 · 4^subdivisions` triangles.
pub(super) fn geodesic_sphere(subdivisions: u32) -> Vec<[DVec3; 3]> {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let v: Vec<DVec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    const FACES: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut triangles = split_on_sphere(
        FACES.iter().map(|f| f.map(|i| v[i])).collect(),
        subdivisions,
    );
    // Inward: the area vector points towards the centre.
    for t in &mut triangles {
        let [a, b, c] = *t;
        if (b - a).cross(c - a).dot(a + b + c) > 0.0 {
            *t = [a, c, b];
        }
    }
    triangles
}

/// Spherical triangles of the unit sphere, each split in four `levels`
/// times, the edge midpoints pushed out to the sphere; in the order each
/// triangle's four parts follow one another.
pub(super) fn split_on_sphere(mut triangles: Vec<[DVec3; 3]>, levels: u32) -> Vec<[DVec3; 3]> {
    for _ in 0..levels {
        triangles = triangles
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (
                    (a + b).normalize(),
                    (b + c).normalize(),
                    (c + a).normalize(),
                );
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil;
    use glam::Vec3;
    use std::f64::consts::PI;

    #[test]
    fn the_geodesic_sphere_is_closed_and_faces_inward() {
        for level in 0..3 {
            let triangles = geodesic_sphere(level);
            assert_eq!(triangles.len(), 20 * 4usize.pow(level));
            // Closed: the signed volume is the sphere's (less the chords'),
            // negative because every facet faces the centre.
            let volume: f64 = triangles
                .iter()
                .map(|[a, b, c]| a.dot(b.cross(*c)) / 6.0)
                .sum();
            let sphere = 4.0 / 3.0 * PI;
            assert!(volume < 0.0 && -volume > 0.6 * sphere && -volume < sphere);
            for [a, b, c] in &triangles {
                assert!((b - a).cross(c - a).dot(a + b + c) < 0.0);
                for v in [a, b, c] {
                    assert!((v.length() - 1.0).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn the_sky_encloses_the_scene_without_changing_its_bounds() {
        let floor = testutil::polygon(
            0,
            &[
                [0.0, 0.0, 0.0],
                [4.0, 0.0, 0.0],
                [4.0, 0.0, -2.0],
                [0.0, 0.0, -2.0],
            ],
        );
        let mut s = testutil::scene(vec![floor], vec![testutil::grey("m", 0.0, 0.5)]);
        assert_eq!(s.sky(), None);
        let (bounds, extent) = (s.bounds(), s.extent());
        let sky = Rgb::new(1.0, 2.0, 3.0);
        s.add_sky(sky).unwrap();
        assert_eq!((s.bounds(), s.extent()), (bounds, extent));
        assert_eq!(s.sky(), Some(sky));
        assert_eq!(s.polygons.len(), 1 + 80);
        let m = s.materials.last().unwrap();
        assert_eq!(
            (m.name.as_str(), m.emission(), m.reflectance()),
            ("sky", sky, Rgb::BLACK)
        );
        let centre = Vec3::new(2.0, 0.0, -1.0);
        let radius = extent * 0.5 * SKY_RADIUS_FACTOR;
        let mut area = 0.0;
        for p in &s.polygons[1..] {
            assert!(p.surface.sky && !p.surface.two_sided);
            p.validate().unwrap();
            for v in &p.vertices {
                assert!((v.distance(centre) - radius).abs() < 1e-4 * radius);
            }
            // Facing the centre.
            assert!(p.normal.dot(centre - p.vertices[0]) > 0.0);
            area += p.area;
        }
        let sphere = 4.0 * PI * f64::from(radius).powi(2);
        assert!(area < sphere && area > 0.9 * sphere, "{area} of {sphere}");
        // The sky is emitting, so the scene now does.
        assert!(s.emits());
    }
}
