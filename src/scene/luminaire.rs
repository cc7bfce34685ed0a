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
//! opening of a luminaire, like Radiance's `light` material. Only the
//! light below the polygon's plane (θ ≤ 90°) is emitted; what the file
//! sends upwards is dropped, and [`Luminaire::upward_fraction`] says how
//! much that is.

use super::emit::UnknownName;
use super::ies::Photometry;
use super::{Material, MaterialId, PolygonId, Scene, Units};
use crate::color::Rgb;
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
    /// Luminous flux emitted below the polygon's plane (θ ≤ 90°), lumens.
    pub flux: f64,
    /// The fraction of the file's whole flux that is sent upwards (θ >
    /// 90°) and so not emitted.
    pub upward_fraction: f64,
}

/// Why `--ies` could not be applied.
#[derive(Debug, thiserror::Error)]
pub enum LuminaireError {
    /// No material, object or group has the name.
    #[error("{0}")]
    UnknownName(#[from] UnknownName),
    /// The distribution sends no light below the horizontal.
    #[error("the distribution sends no light downwards (θ ≤ 90°), so `{0}` would emit nothing")]
    Dark(String),
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
            let exitance = flux / units.square_metres(polygon.area);
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
            });
        }
        Ok(members.len())
    }

    /// The luminaire whose material `material` is, if any.
    pub fn luminaire_of(&self, material: MaterialId) -> Option<&Luminaire> {
        self.luminaires.iter().find(|l| l.material == material)
    }

    /// Gives the back copies of luminaires ([`Scene::with_sides`]) a black
    /// material of their own: a luminaire emits from its front only.
    pub fn darken_luminaire_backs(&mut self) {
        if self.luminaires.is_empty() {
            return;
        }
        let mut black = None;
        for i in 0..self.polygons.len() {
            let p = &self.polygons[i];
            if p.surface.back_of.is_none() || self.luminaire_of(p.material).is_none() {
                continue;
            }
            let id = *black.get_or_insert_with(|| {
                self.materials.push(Material {
                    name: "luminaire back".into(),
                    color: Rgb::BLACK,
                    k_diffrefl: 0.0,
                    k_emission: 0.0,
                });
                MaterialId(self.materials.len() as u32 - 1)
            });
            self.polygons[i].material = id;
        }
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
        scene.darken_luminaire_backs();
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
}
