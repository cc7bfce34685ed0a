//! Luminaires: polygons that emit with a measured light distribution (an
//! IES file, [`Photometry`]) instead of Lambert's cosine.
//!
//! [`Scene::set_luminaire`] makes each polygon named `NAME` (a material,
//! an object or a group, matched as `--emit` matches them) one luminaire
//! with the file's distribution: its photometric nadir along the
//! polygon's front normal, its C0 plane through the polygon's first edge
//! (C90 = nadir × C0). Each polygon gets a material of its own that emits
//! the distribution's downward flux spread over the polygon's area (so the
//! solver's power bookkeeping holds) and reflects nothing: the luminous
//! opening of a luminaire, like Radiance's `light` material. The light
//! below the polygon's plane (θ ≤ 90°) leaves its front; what the file
//! sends upwards (a pendant's uplight) leaves its back, a polygon of its
//! own ([`Scene::light_luminaire_backs`]) with the upper half of the same
//! distribution.

use super::emit::UnknownName;
use crate::color::Rgb;
use crate::scene::import::ies::Photometry;
use crate::scene::{Material, MaterialId, PolygonId, Scene, Units};
use glam::Vec3;
use std::f64::consts::PI;
use std::sync::Arc;

/// A material whose polygons emit with a light distribution.
///
/// Invariants: `flux > 0` and finite; `c0` is a unit vector perpendicular
/// to the front normal of the polygons of `material`.
#[derive(Clone, Debug, PartialEq)]
pub struct Luminaire {
    /// The material of its polygon (and of the pieces and the back copy
    /// of that polygon).
    pub material: MaterialId,
    /// The intensity distribution, in candela.
    pub photometry: Arc<Photometry>,
    /// The direction of the C0 plane, in scene space (unit).
    pub c0: Vec3,
    /// Luminous flux its polygons emit, lumens: below the luminaire's
    /// plane (θ ≤ 90°) from a front, above it (θ > 90°) from a back.
    pub flux: f64,
    /// The fraction of the file's whole flux that is sent upwards (θ >
    /// 90°), from the luminaire's back.
    pub upward_fraction: f64,
    /// True for the back of a luminaire: its polygons face up, away from
    /// the photometric nadir (which stays the front's normal, so angles
    /// are read as the file gives them), and emit the upper half.
    pub upper: bool,
}

/// Uplight below this fraction of a file's flux is not emitted: a table
/// that ends at 90° still integrates to a few rounding lumens above it.
pub const MIN_UPWARD_FRACTION: f64 = 1e-6;

/// Why `--ies` could not be applied.
#[derive(Debug, thiserror::Error)]
pub enum LuminaireError {
    /// No material, object or group has the name.
    #[error("{0}")]
    UnknownName(#[from] UnknownName),
    /// The distribution sends no light below the horizontal.
    #[error("the distribution sends no light downwards (θ ≤ 90°), so `{0}` would emit nothing")]
    Dark(String),
    /// The flux spread over one of the polygons would be an exitance above
    /// [`MAX_EMISSION`](crate::scene::MAX_EMISSION) (a tiny polygon, or a
    /// scene in the wrong units).
    #[error(
        "`{name}`: {flux:e} lm over {area:e} m² is an exitance of {exitance:e} lm/m², above the \
         largest allowed emission, {max:e} (is the polygon tiny, or --units wrong?)",
        max = crate::scene::MAX_EMISSION
    )]
    TooBright {
        /// The name given to `--ies`.
        name: String,
        /// The luminaire's flux below its plane, lumens.
        flux: f64,
        /// The polygon's area, square metres.
        area: f64,
        /// Their quotient, lumens per square metre.
        exitance: f64,
    },
}

impl Scene {
    /// Makes every polygon named `name` (see [`Scene::set_emission`] for
    /// how names match) a luminaire with `photometry`, the scene being in
    /// `units`; returns how many polygons became luminaires. See the
    /// module docs.
    pub fn set_luminaire(
        &mut self,
        name: &str,
        photometry: Arc<Photometry>,
        units: Units,
    ) -> Result<usize, LuminaireError> {
        let members = self.polygons_named(name)?;
        let flux = photometry.flux(PI / 2.0);
        let upward = photometry.flux_between(PI / 2.0, PI);
        if !(flux > 0.0 && flux.is_finite()) {
            return Err(LuminaireError::Dark(name.to_string()));
        }
        for (k, id) in members.iter().enumerate() {
            let polygon = &self.polygons[id.index()];
            let area = units.square_metres(polygon.area);
            let exitance = flux / area;
            if !exitance.is_finite() || exitance > crate::scene::MAX_EMISSION {
                return Err(LuminaireError::TooBright {
                    name: name.to_string(),
                    flux,
                    area,
                    exitance,
                });
            }
            let c0 = (polygon.vertices[1] - polygon.vertices[0]).normalize_or_zero();
            self.materials.push(Material {
                name: format!("{name} (luminaire {})", k + 1),
                color: Rgb::WHITE,
                k_diffrefl: 0.0,
                k_emission: exitance,
            });
            let material = MaterialId(self.materials.len() as u32 - 1);
            self.polygons[id.index()].material = material;
            self.luminaires.push(Luminaire {
                material,
                photometry: photometry.clone(),
                c0,
                flux,
                upward_fraction: upward / (flux + upward),
                upper: false,
            });
        }
        Ok(members.len())
    }

    /// The luminaire whose material `material` is, if any.
    pub fn luminaire_of(&self, material: MaterialId) -> Option<&Luminaire> {
        self.luminaires.iter().find(|l| l.material == material)
    }

    /// Gives every luminaire polygon's back side its light: the upper
    /// half of the distribution when the file sends light upwards (above
    /// `MIN_UPWARD_FRACTION`), emitted by a material of its own of
    /// exitance `front exitance × upward / downward flux` (the same area),
    /// with a [`Luminaire`] marked [`Luminaire::upper`]; else a black
    /// material (a luminaire without uplight emits from its front only).
    /// A front without a back (a one-sided scene) gets a back copy here,
    /// as [`Scene::with_sides`] makes them. Run after
    /// [`Scene::with_sides`]. A back that is another face of the file (the
    /// face written the other way round) is left as it is.
    pub fn light_luminaire_backs(&mut self) {
        if self.luminaires.is_empty() {
            return;
        }
        let mut black = None;
        let fronts: Vec<Luminaire> = self
            .luminaires
            .iter()
            .filter(|l| !l.upper)
            .cloned()
            .collect();
        for l in fronts {
            let uplight = l.upward_fraction > MIN_UPWARD_FRACTION;
            let members: Vec<usize> = (0..self.polygons.len())
                .filter(|&i| {
                    let p = &self.polygons[i];
                    p.material == l.material && p.surface.back_of.is_none()
                })
                .collect();
            let mut upper_material = None;
            for i in members {
                let back = match self.polygons[i].surface.back {
                    Some(b)
                        if self.polygons[b.index()].surface.back_of
                            == Some(PolygonId(i as u32)) =>
                    {
                        b
                    }
                    Some(_) => continue,
                    // A face of a closed solid would send its uplight into
                    // the solid.
                    None if uplight && !self.polygons[i].surface.solid => self.add_back_copy(i),
                    None => continue,
                };
                let material = if uplight {
                    *upper_material.get_or_insert_with(|| {
                        let front = &self.materials[l.material.index()];
                        let upward = l.flux * l.upward_fraction / (1.0 - l.upward_fraction);
                        self.materials.push(Material {
                            name: format!("{} (uplight)", front.name),
                            color: Rgb::WHITE,
                            k_diffrefl: 0.0,
                            k_emission: front.k_emission * upward / l.flux,
                        });
                        let material = MaterialId(self.materials.len() as u32 - 1);
                        self.luminaires.push(Luminaire {
                            material,
                            flux: upward,
                            upper: true,
                            ..l.clone()
                        });
                        material
                    })
                } else {
                    *black.get_or_insert_with(|| {
                        self.materials.push(Material {
                            name: "luminaire back".into(),
                            color: Rgb::BLACK,
                            k_diffrefl: 0.0,
                            k_emission: 0.0,
                        });
                        MaterialId(self.materials.len() as u32 - 1)
                    })
                };
                self.polygons[back.index()].material = material;
            }
        }
    }

    /// Adds the back copy of polygon `i` (its vertices reversed from the
    /// second on, as [`Scene::with_sides`] makes them), linked both ways
    /// and in its front's groups; returns its id.
    fn add_back_copy(&mut self, i: usize) -> PolygonId {
        let id = PolygonId(self.polygons.len() as u32);
        let back = crate::scene::repair::sides::back_copy(&self.polygons[i], PolygonId(i as u32));
        self.polygons[i].surface.back = Some(id);
        self.polygons.push(back);
        // The new id is above every other, so the groups stay ascending.
        for group in &mut self.groups {
            if group.polygons.binary_search(&PolygonId(i as u32)).is_ok() {
                group.polygons.push(id);
            }
        }
        id
    }

    /// The polygons named `name`, as [`Scene::set_emission`] matches
    /// names: those of the materials so named, then the members of the
    /// objects and groups so named; ascending, without repeats.
    pub fn polygons_named(&self, name: &str) -> Result<Vec<PolygonId>, UnknownName> {
        let materials: Vec<bool> = self.materials.iter().map(|m| m.name == name).collect();
        if !materials.contains(&true) && !self.groups.iter().any(|g| g.name == name) {
            // The same error (listing every name) as `--emit` gives.
            return Err(self.unknown_name(name));
        }
        let mut ids: Vec<PolygonId> = self
            .polygons
            .iter()
            .enumerate()
            .filter(|(_, p)| materials.get(p.material.index()) == Some(&true))
            .map(|(i, _)| PolygonId(i as u32))
            .chain(
                self.groups
                    .iter()
                    .filter(|g| g.name == name)
                    .flat_map(|g| g.polygons.iter().copied()),
            )
            .collect();
        ids.sort_unstable();
        ids.dedup();
        Ok(ids)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sides;
    use crate::testutil;

    fn cosine() -> Arc<Photometry> {
        let text = "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n100 0\n";
        Arc::new(Photometry::parse(text, "c.ies").unwrap())
    }

    /// The brightest intensity a file may hold, over a square millimetre,
    /// is an exitance above the emission limit: refused, not solved into
    /// non-finite values.
    #[test]
    fn a_luminaire_brighter_than_the_emission_limit_is_refused() {
        let polygons = testutil::closed_box(1.0, [0, 1, 1, 1, 1, 1]);
        let materials = || {
            vec![
                testutil::grey("lamp", 1.0, 0.5),
                testutil::grey("w", 0.0, 0.5),
            ]
        };
        let text = format!(
            "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n{:e} 0\n",
            crate::scene::import::ies::MAX_CANDELA
        );
        let hot = Arc::new(Photometry::parse(&text, "hot.ies").unwrap());
        let mut scene = testutil::scene(polygons.clone(), materials());
        let e = scene
            .set_luminaire("lamp", hot.clone(), Units::Mm)
            .unwrap_err();
        assert!(matches!(e, LuminaireError::TooBright { .. }), "{e}");
        // The same over a square metre is allowed.
        let mut scene = testutil::scene(polygons, materials());
        assert_eq!(scene.set_luminaire("lamp", hot, Units::M).unwrap(), 1);
    }

    #[test]
    fn each_named_polygon_becomes_a_luminaire_of_the_files_flux() {
        // Two faces of material 0 ("lamp"), one of material 1.
        let mut polygons = testutil::closed_box(2.0, [0, 1, 1, 1, 1, 0]);
        polygons.truncate(6);
        let mut scene = testutil::scene(
            polygons,
            vec![
                testutil::grey("lamp", 1.0, 0.5),
                testutil::grey("w", 0.0, 0.5),
            ],
        );
        let p = cosine();
        // Linear between 100 cd at 0° and 0 at 90°: ∫ 100 (1 − 2θ/π) sinθ dθ dφ.
        let exact = 2.0 * PI * 100.0 * (1.0 - 2.0 / PI);
        let n = scene.set_luminaire("lamp", p, Units::Cm).unwrap();
        assert_eq!(n, 2);
        assert_eq!(scene.luminaires.len(), 2);
        for l in &scene.luminaires {
            assert!((l.flux / exact - 1.0).abs() < 1e-4, "{} vs {exact}", l.flux);
            assert_eq!(l.upward_fraction, 0.0);
            let polygon = scene
                .polygons
                .iter()
                .find(|q| q.material == l.material)
                .unwrap();
            let m = &scene.materials[l.material.index()];
            assert_eq!(m.reflectance(), Rgb::BLACK);
            // Exitance × area in m² (4 cm² here) is the flux.
            let lumens = m.emission().r * Units::Cm.square_metres(polygon.area);
            assert!((lumens / l.flux - 1.0).abs() < 1e-12);
            assert!(l.c0.dot(polygon.normal).abs() < 1e-6);
        }
        assert!(matches!(
            scene.set_luminaire("nothing", cosine(), Units::M),
            Err(LuminaireError::UnknownName(_))
        ));
        // Two-sided: the back copies are black, the fronts still emit.
        let mut scene = scene.with_sides(Sides::Two);
        scene.light_luminaire_backs();
        for p in &scene.polygons {
            let emits = !scene.materials[p.material.index()].emission().is_black();
            let luminaire = scene.luminaire_of(p.material).is_some();
            if p.surface.back_of.is_some() {
                assert!(!emits && !luminaire);
            } else {
                assert_eq!(emits, luminaire);
            }
        }
    }

    /// A table with light above the horizontal: the back copy that
    /// `--two-sided` made emits the upper half (no second copy), the
    /// front the lower half, and their exitances are in the ratio of the
    /// two fluxes.
    #[test]
    fn an_existing_back_copy_emits_the_uplight() {
        // 100 cd at 0°, 0 at 90°, 50 at 180°.
        let text = "TILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 0\n0 90 180\n0\n100 0 50\n";
        let photometry = Arc::new(Photometry::parse(text, "u.ies").unwrap());
        let mut scene = testutil::scene(
            vec![testutil::polygon(
                0,
                &[[0., 1., 0.], [0.1, 1., 0.], [0.1, 1., 0.1], [0., 1., 0.1]],
            )],
            vec![testutil::grey("lamp", 1.0, 0.5)],
        );
        scene
            .set_luminaire("lamp", photometry.clone(), Units::M)
            .unwrap();
        let mut scene = scene.with_sides(Sides::Two);
        assert_eq!(scene.polygons.len(), 2);
        scene.light_luminaire_backs();
        assert_eq!(scene.polygons.len(), 2, "the existing copy is used");
        let (front, back) = (&scene.polygons[0], &scene.polygons[1]);
        let (lf, lb) = (
            scene.luminaire_of(front.material).unwrap(),
            scene.luminaire_of(back.material).unwrap(),
        );
        assert!(!lf.upper && lb.upper);
        let up = photometry.flux_between(PI / 2.0, PI);
        assert!((lb.flux / up - 1.0).abs() < 1e-9);
        assert!((lf.upward_fraction - up / (up + lf.flux)).abs() < 1e-12);
        let e = |p: &crate::scene::Polygon| scene.materials[p.material.index()].emission().r;
        assert!((e(back) / e(front) - up / lf.flux).abs() < 1e-9);
        assert_eq!(
            scene.materials[back.material.index()].reflectance(),
            Rgb::BLACK
        );
    }
}
