//! The ambient term: the light still to be shot, as if spread evenly
//! over the scene and reflected by its mean reflectance, which the
//! pictures before convergence add ([`super::Progressive::ambient`],
//! [`first_look`]); and the weights with which a sky facet's unshot power
//! counts, as the light it can bring.

use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::Scene;

/// The ambient term ([`super::Progressive::ambient`]) of a scene whose
/// polygon `j` (of `mesh`) has reflectance `reflectance[j]`, sky power weight
/// `power_weight[j]` ([`sky_power_weights`]) and mean unshot radiosity
/// `unshot_mean(j)`.
pub(super) fn ambient_term(
    mesh: &Mesh,
    reflectance: &[Rgb],
    power_weight: &[f64],
    unshot_mean: impl Fn(usize) -> Rgb,
) -> Rgb {
    let (mut area, mut unshot, mut reflected) = (0.0, Rgb::BLACK, Rgb::BLACK);
    for (j, (rho, pm)) in reflectance.iter().zip(&mesh.polygons).enumerate() {
        // The sky is no part of the scene its light is spread over;
        // what it has not shot yet is the light's source, counted as
        // the power it would bring (see `sky_power_weights`).
        if pm.sky {
            unshot += unshot_mean(j) * pm.area * power_weight[j];
            continue;
        }
        area += pm.area;
        unshot += unshot_mean(j) * pm.area;
        reflected += *rho * pm.area;
    }
    if area <= 0.0 {
        return Rgb::BLACK;
    }
    let rho = reflected / area;
    // Every reflectance channel is below 1, so their mean is too.
    let r = Rgb::new(
        1.0 / (1.0 - rho.r),
        1.0 / (1.0 - rho.g),
        1.0 / (1.0 - rho.b),
    );
    r * (unshot / area)
}

/// What a solve of `scene` on `mesh` shows before its first step, per mesh
/// vertex in the scene's radiosity units: each vertex's emission plus its
/// reflectance times the ambient term of the unshot emission (the value of
/// [`super::Progressive::radiosity_with_ambient`] for a new solver), computed
/// without building a solver (no samples, clusters or visibility), so a
/// window can show a lit scene at once on a model whose solver takes a
/// while to set up.
pub fn first_look(scene: &Scene, mesh: &Mesh) -> Vec<Rgb> {
    let material = |p: &crate::scene::Polygon| &scene.materials[p.material.index()];
    let emission: Vec<Rgb> = scene
        .polygons
        .iter()
        .map(|p| material(p).emission())
        .collect();
    let reflectance: Vec<Rgb> = scene
        .polygons
        .iter()
        .map(|p| material(p).reflectance())
        .collect();
    if emission.len() != mesh.polygons.len() {
        return vec![Rgb::BLACK; mesh.vertex_count()];
    }
    let ambient = ambient_term(mesh, &reflectance, &sky_power_weights(mesh), |j| {
        emission[j]
    });
    mesh.vertex_polygon
        .iter()
        .map(|p| emission[p.index()] + reflectance[p.index()] * ambient)
        .collect()
}

/// Per polygon of `mesh`, the factor its unshot power counts with: 1 for
/// the scene's polygons; for the facets of a sky, the scene's area (every
/// non-sky polygon's) over the sky's, so that the whole sky counts as
/// `S · A_scene`.
///
/// A sky's own power, `S` times the area of an enclosure far outside the
/// scene, is mostly light that never reaches it, and it depends on the
/// enclosure's arbitrary radius. Counted whole it would make the first
/// bounce in the scene look negligible against the initial power, and the
/// threshold would stop the solve before any light was reflected. What a
/// sky can bring to the scene is at most `S · A_scene` (each polygon's form
/// factor to the sky is at most 1), which is also what an emitter of the
/// scene's size would hold: the threshold then means what it means for
/// any scene.
pub(super) fn sky_power_weights(mesh: &Mesh) -> Vec<f64> {
    let (mut scene_area, mut sky_area) = (0.0, 0.0);
    for pm in &mesh.polygons {
        if pm.sky {
            sky_area += pm.area;
        } else {
            scene_area += pm.area;
        }
    }
    let sky_weight = if sky_area > 0.0 {
        scene_area / sky_area
    } else {
        1.0
    };
    mesh.polygons
        .iter()
        .map(|pm| if pm.sky { sky_weight } else { 1.0 })
        .collect()
}
