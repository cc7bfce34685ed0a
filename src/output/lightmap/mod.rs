//! Baked light for game engines and viewers (`--lightmap FILE.glb`,
//! `--lightmap-texture FILE.png|.exr`): the user's own model with a
//! lightmap texture over a second UV set, instead of the solver's element
//! mesh with vertex colours ([`super::mesh_export`]).
//!
//! **The model.** A glTF scene comes back as its file draws it
//! ([`crate::scene::import::gltf::source`]): each node instance's
//! primitives with their positions, normals, `TEXCOORD_0`, indices and
//! materials (textures and images embedded), in world space (the node
//! hierarchy is flattened: one node per drawn mesh, transforms applied).
//! An OBJ file comes back as its faces with their texture coordinates,
//! normals, colours and `map_Kd` textures
//! ([`crate::scene::import::obj::source`]); a `.sc` scene becomes a glTF
//! of its own faces ([`model`]); neither is the element mesh.
//!
//! **The sides** ([`backs`]): a triangle whose back the solver lit (a
//! two-sided face) gets a back copy with texels of its own, unless the
//! model brings its own lightmap UVs.
//!
//! **The UVs** ([`uv`]): the model's `TEXCOORD_1` when every primitive has
//! one, else made by automatic chart packing, [`uv::PADDING`] texels of
//! padding around every chart, at the density asked for or the highest
//! that fits a [`uv::DEFAULT_SIDE`]² page.
//!
//! **The texels** ([`fill`]): the solved light at the 3D point each texel
//! stands for, found through the visibility structure and interpolated
//! over the element vertices as the picture's Gouraud shading does
//! ([`locate`]), so both sides of a seam hold the same edge's light;
//! dilated into the padding.
//!
//! **What the texture holds, and why.** Plain viewers (three.js's
//! `GLTFLoader` without extra code, Blender's importer, Godot) read core
//! glTF only; the one core slot that adds light regardless of the
//! viewer's lamps is `emissiveTexture`. So every material shows the
//! lightmap as its `emissiveTexture` on texture coordinate 1 with
//! `emissiveFactor` 1, and the texture holds the **radiosity as the
//! program's picture draws it**: `sRGB(clamp(exposure × radiosity, 0, 1))`
//! with the picture's own exposure ([`crate::render::tonemap`]). A viewer
//! with no lamps of its own and no tone mapping (three.js's defaults)
//! then shows what the picture shows. `baseColor` is kept, so lamps added
//! in a viewer light the model on top of the baked light. The exposure is
//! in the file's `extras.lightmap`, so `radiosity = decoded texel /
//! exposure` where it is not clipped. The emission the model's materials
//! had is replaced: the baked radiosity includes it.
//!
//! For engines that multiply a lightmap by their own albedo (Godot's
//! `LightmapGI`, Unity, Unreal), `--lightmap-texture FILE.exr` writes the
//! **irradiance** (light arriving, `(radiosity − emission) /
//! reflectance`, in the scene's radiosity units, linear, 32-bit float);
//! `FILE.png` writes the 8-bit emissive texture the `.glb` holds.

pub mod backs;
pub mod fill;
pub mod glb;
pub mod locate;
pub mod model;
pub mod uv;

#[cfg(test)]
mod tests;

use super::{write_atomically, OutputError};
use crate::cancel::{Cancel, Cancelled};
use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::render::{to_srgb8, Exposure};
use crate::scene::import::gltf::source::SourceModel;
use crate::scene::Scene;
use crate::visibility::Visibility;
use std::io;
use std::path::Path;

pub use fill::Texture;
pub use uv::Layout;

/// The extensions `--lightmap-texture` writes, for messages.
pub const TEXTURE_EXTENSIONS: &str = ".png, .exr";

/// A model with its lightmap laid out and filled.
#[derive(Clone, Debug)]
pub struct Baked {
    /// The model, every primitive with `uv1`.
    pub model: SourceModel,
    /// The texture's size and density.
    pub layout: Layout,
    /// The texels.
    pub texture: Texture,
}

/// Why [`bake`] made no lightmap.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BakeError {
    /// The layout is impossible: too dense for the largest texture, or a
    /// model with no surface.
    #[error("{0}")]
    Layout(String),
    /// The bake's [`Cancel`] was set.
    #[error("interrupted")]
    Cancelled(#[from] Cancelled),
}

/// Lays out and fills the lightmap of `model` from the solution: `mesh`
/// (built from `scene`, with `visibility` over its polygons), `shown` (the
/// radiosity the picture draws) and `radiosity` (the solved), one value
/// per mesh vertex. `density` is texels per scene unit (`None`: the
/// default, see [`uv::lay_out`]). Errors say why the layout is
/// impossible (too dense, or a model with no surface), or that `cancel`
/// was set: the layout runs to its end, the filling stops within a
/// texel's work.
#[allow(clippy::too_many_arguments)]
pub fn bake(
    mut model: SourceModel,
    scene: &Scene,
    mesh: &Mesh,
    visibility: &Visibility,
    shown: &[Rgb],
    radiosity: &[Rgb],
    density: Option<f32>,
    cancel: &Cancel,
) -> Result<Baked, BakeError> {
    let locator = locate::Locator::new(scene, mesh, visibility, shown, radiosity);
    // A model with its own lightmap UVs keeps them: back copies would
    // share their fronts' texels.
    if !model.primitives.iter().all(|p| p.uv1.is_some()) {
        backs::add_backs(&mut model, &locator);
    }
    cancel.check()?;
    let layout = uv::lay_out(&mut model, density).map_err(BakeError::Layout)?;
    cancel.check()?;
    let texture = fill::fill(&model, layout.width, layout.height, &locator, scene, cancel)?;
    Ok(Baked {
        model,
        layout,
        texture,
    })
}

/// The emissive lightmap as PNG bytes: [`Texture::shown`] tone-mapped
/// with `exposure` as the picture is.
pub fn emissive_png(texture: &Texture, exposure: f32) -> Result<Vec<u8>, ::image::ImageError> {
    let image = to_srgb8(&texture.shown, exposure);
    let mut bytes = io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, ::image::ImageFormat::Png)?;
    Ok(bytes.into_inner())
}

/// Writes the baked model to `path` (`.glb`) atomically; `exposure` is
/// the picture's, `name` names the glTF scene.
pub fn write_glb(path: &Path, baked: &Baked, exposure: f32, name: &str) -> Result<(), OutputError> {
    check_glb_path(path)?;
    let png = emissive_png(&baked.texture, exposure).map_err(|error| OutputError::Encode {
        path: path.to_path_buf(),
        error,
    })?;
    let info = glb::LightmapInfo {
        exposure,
        texels_per_unit: baked.layout.texels_per_unit,
    };
    let bytes = glb::glb_bytes(&baked.model, &png, &info, name);
    write_atomically(path, |w| w.write_all(&bytes))
}

/// Writes the bare lightmap to `path`: `.png` the emissive texture of the
/// `.glb`, `.exr` the irradiance (see the module docs).
pub fn write_texture(path: &Path, baked: &Baked, exposure: f32) -> Result<(), OutputError> {
    match texture_kind(path)? {
        TextureKind::Png => {
            super::write_picture(path, &baked.texture.shown, Exposure::Fixed(exposure))
        }
        TextureKind::Exr => {
            super::write_picture(path, &baked.texture.irradiance, Exposure::Fixed(1.0))
        }
    }
}

/// What `--lightmap-texture` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TextureKind {
    Png,
    Exr,
}

/// The kind of texture `path`'s extension names.
fn texture_kind(path: &Path) -> Result<TextureKind, OutputError> {
    match extension(path).as_deref() {
        Some("png") => Ok(TextureKind::Png),
        Some("exr") => Ok(TextureKind::Exr),
        other => Err(bad_extension(path, other, TEXTURE_EXTENSIONS)),
    }
}

/// Refuses a `--lightmap-texture` path whose extension is not
/// [`TEXTURE_EXTENSIONS`].
pub fn check_texture_path(path: &Path) -> Result<(), OutputError> {
    texture_kind(path).map(|_| ())
}

/// Refuses a `--lightmap` path whose extension is not `.glb`.
pub fn check_glb_path(path: &Path) -> Result<(), OutputError> {
    match extension(path).as_deref() {
        Some("glb") => Ok(()),
        other => Err(bad_extension(path, other, ".glb")),
    }
}

/// The path's extension, lower case.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
}

/// The error for an extension that is not one of `supported`.
fn bad_extension(path: &Path, ext: Option<&str>, supported: &str) -> OutputError {
    OutputError::Io {
        path: path.to_path_buf(),
        error: io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{}; a lightmap is written as {supported}",
                match ext {
                    None => "the file name has no extension".to_string(),
                    Some(e) => format!("unknown extension .{e}"),
                }
            ),
        ),
    }
}
