//! The lightmap's texture coordinates (`TEXCOORD_1`): the model's own
//! when every primitive has them, else made by automatic chart packing
//! ([`uvunwrap`]: charts grown within a normal cone, flattened, packed by
//! shape) over the whole model into one page.
//!
//! UVs follow glTF: `(0, 0)` is the top-left corner of the image (texel
//! row 0, column 0) and `v` grows downwards, row by row, which is also
//! how [`uvunwrap`] lays out its pages, so its coordinates are written
//! as they come.

use crate::scene::import::gltf::source::{SourceModel, SourcePrimitive};

/// The texture side the default density aims at, in texels: a 2048²
/// lightmap, what engines commonly budget for one level.
pub const DEFAULT_SIDE: u32 = 2048;

/// The largest texture side a lightmap may have, in texels: 4096² texels
/// take about 0.6 GB while they are filled, and every WebGL 2
/// implementation and engine accepts a texture this large.
pub const MAX_SIDE: u32 = 4096;

/// Empty texels around every chart: charts are at least twice this apart
/// and this far from the page's edges, so bilinear filtering (which reads
/// one texel beyond a chart's edge) never reads a neighbour's texels.
pub const PADDING: u32 = 2;

/// The fraction of the page the charts are expected to cover, for the
/// early size check of a given density (the packer reaches 0.5 to 0.7).
const EXPECTED_UTILISATION: f64 = 0.5;

/// The laid-out lightmap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// Texture width in texels.
    pub width: u32,
    /// Texture height in texels.
    pub height: u32,
    /// Texels per scene unit of length (for the model's own UVs: the mean
    /// over the model, `sqrt(texture area / surface area)`).
    pub texels_per_unit: f32,
    /// Charts packed; 0 when the model's own `TEXCOORD_1` was used.
    pub charts: u32,
    /// True when the UVs were made here, false when they were the model's.
    pub generated: bool,
}

/// Lays out the lightmap of `model`, setting every primitive's `uv1` (and,
/// when the UVs are made, splitting its vertices along chart seams: each
/// attribute is copied to the new vertices). `density` (texels per scene
/// unit, `> 0`) is the user's; `None` picks the highest density that fits
/// one [`DEFAULT_SIDE`]² page (for the model's own UVs, that page).
pub fn lay_out(model: &mut SourceModel, density: Option<f32>) -> Result<Layout, String> {
    let area: f64 = model.primitives.iter().map(surface_area).sum();
    if area <= 0.0 || !area.is_finite() {
        return Err("the model has no surface to lay a lightmap on".to_string());
    }
    if model.primitives.iter().all(|p| p.uv1.is_some()) {
        return Ok(own_layout(area, density));
    }
    if let Some(d) = density {
        check_density(area, d)?;
    }
    let density_option = match density {
        Some(d) => uvunwrap::Density::Fixed {
            texels_per_unit: d,
            page_size: None,
        },
        None => uvunwrap::Density::Auto {
            page_size: DEFAULT_SIDE,
        },
    };
    let options = uvunwrap::Options {
        density: density_option,
        padding: PADDING,
        ..uvunwrap::Options::default()
    };
    let inputs: Vec<uvunwrap::MeshInput<'_>> = model
        .primitives
        .iter()
        .map(|p| uvunwrap::MeshInput::new(&p.positions, &p.indices))
        .collect();
    let atlas = uvunwrap::generate(&inputs, &options).map_err(|e| e.to_string())?;
    if atlas.page_count != 1 {
        return Err(format!(
            "the model's {} charts need {} pages of {DEFAULT_SIDE} texels; give a lower \
             --lightmap-density",
            atlas.chart_count, atlas.page_count
        ));
    }
    if atlas.width > MAX_SIDE || atlas.height > MAX_SIDE {
        return Err(format!(
            "the lightmap would be {}x{} texels, more than {MAX_SIDE} a side; give a lower \
             --lightmap-density",
            atlas.width, atlas.height
        ));
    }
    for (p, out) in model.primitives.iter_mut().zip(&atlas.meshes) {
        remap(p, out);
    }
    Ok(Layout {
        width: atlas.width,
        height: atlas.height,
        texels_per_unit: atlas.texels_per_unit,
        charts: atlas.chart_count,
        generated: true,
    })
}

/// Refuses a density `d` (texels per unit) at which `area` square units
/// of surface would not fit a texture of [`MAX_SIDE`], at the utilisation
/// the packer usually reaches: said before solving
/// ([`check_scene_density`]) and again once the model is known.
pub fn check_density(area: f64, d: f32) -> Result<(), String> {
    let side = (area * f64::from(d) * f64::from(d) / EXPECTED_UTILISATION).sqrt();
    if side > f64::from(MAX_SIDE) {
        return Err(format!(
            "--lightmap-density {d} texels per unit would need a texture of about {side:.0} \
             texels a side for this model ({area:.4} square units of surface); the largest \
             is {MAX_SIDE}: give at most {:.4}",
            f64::from(MAX_SIDE) * EXPECTED_UTILISATION.sqrt() / area.sqrt()
        ));
    }
    Ok(())
}

/// [`check_density`] over the scene's polygons (the sky's left out), for
/// a run to refuse a density before it solves.
pub fn check_scene_density(scene: &crate::scene::Scene, d: f32) -> Result<(), String> {
    let area: f64 = scene
        .polygons
        .iter()
        .filter(|p| !p.surface.sky)
        .map(|p| p.area)
        .sum();
    check_density(area, d)
}

/// The layout of a model that has its own `TEXCOORD_1`: a square texture
/// of [`DEFAULT_SIDE`], or sized for `density` over the model's surface.
fn own_layout(area: f64, density: Option<f32>) -> Layout {
    let side = match density {
        Some(d) => ((area.sqrt() * f64::from(d)).ceil() as u32).clamp(16, MAX_SIDE),
        None => DEFAULT_SIDE,
    };
    Layout {
        width: side,
        height: side,
        texels_per_unit: (f64::from(side) / area.sqrt()) as f32,
        charts: 0,
        generated: false,
    }
}

/// The primitive with the vertices `out` made (each a copy of its input
/// vertex `xref`) and their UVs as `uv1`.
fn remap(p: &mut SourcePrimitive, out: &uvunwrap::OutputMesh) {
    let pick = |xs: &[[f32; 3]]| -> Vec<[f32; 3]> {
        out.vertices.iter().map(|v| xs[v.xref as usize]).collect()
    };
    let pick2 = |xs: &[[f32; 2]]| -> Vec<[f32; 2]> {
        out.vertices.iter().map(|v| xs[v.xref as usize]).collect()
    };
    p.positions = pick(&p.positions);
    p.normals = p.normals.as_deref().map(pick);
    p.uv0 = p.uv0.as_deref().map(pick2);
    p.uv1 = Some(out.vertices.iter().map(|v| v.uv).collect());
    p.indices.clone_from(&out.indices);
}

/// The primitive's surface area in square scene units.
pub fn surface_area(p: &SourcePrimitive) -> f64 {
    p.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| {
                let v = p.positions[i as usize];
                glam::DVec3::new(v[0].into(), v[1].into(), v[2].into())
            });
            (b - a).cross(c - a).length() / 2.0
        })
        .sum()
}
