//! Pictures of a solution: the camera's view, a z-buffered Gouraud
//! rasterizer and tone mapping.
//!
//! The pipeline of a picture is
//!
//! 1. [`View::new`] checks the scene's [`Camera`](crate::camera::Camera)
//!    ([`Camera::check`](crate::camera::Camera::check)) and turns its
//!    orthonormal frame into a perspective projection (row 0 at the top,
//!    world-right is picture-right);
//! 2. [`Rasterizer::render`] draws the element mesh with the per-vertex
//!    radiosity, Gouraud-shaded and z-buffered, into a linear [`Frame`]
//!    (front faces lit, back faces and background holding no light, back
//!    faces flagged in [`Frame::back`]);
//! 3. [`to_srgb8`] scales the frame by an exposure ([`Exposure`], automatic
//!    with [`auto_exposure`]) and encodes it with the sRGB curve for 8-bit
//!    pictures, painting back faces in dim blue-grey stripes
//!    ([`back_face_color`]) so an eye that walked through a wall sees where
//!    it is. High-dynamic-range outputs take the linear [`Frame`] as it is
//!    (back faces `0`).
//!
//! Written pictures are antialiased ([`antialias`]): rendered at `n × n`
//! samples a pixel and averaged in linear radiosity.
//!
//! [`PictureCoverage`] counts what a drawn picture shows (background, back
//! faces, unlit or lit front faces, from [`Rasterizer::front_faces`]) and
//! words the warning for a picture that came out (nearly) black.
//!
//! The module knows nothing of files or windows: the viewer shows and the
//! batch command writes the very same frames.

pub mod antialias;
pub mod coverage;
pub mod falsecolor;
pub mod overlay;
pub mod raster;
pub mod text;
pub mod tonemap;
pub mod view;

pub use coverage::{PictureCoverage, DARK_PICTURE_FRACTION};
pub use overlay::{draw_mesh_edges, LinePalette, MESH_COLOR, MESH_COLOR_ON_LIGHT, MESH_LINES};
pub use raster::{Frame, Rasterizer, RenderError, LAYER_DEPTH_BIAS};
pub use tonemap::{
    auto_exposure, auto_exposure_beside, back_face_color, exposure_probe_size, srgb8, srgb_encode,
    to_srgb8, Exposure, BACK_FACE_COLORS, BACK_FACE_STRIPE, EXPOSURE_PROBE_SIDE,
    MAX_EXPOSURE_STOPS, UNLIT_EXPOSURE_SHARE,
};
pub use view::{View, ViewError};

/// Renders one frame of a solution (`radiosity` per vertex of `mesh`) with
/// a rasterizer of its own: for a single picture; a window or an animation
/// keeps one [`Rasterizer`] and reuses its buffers.
pub fn render(
    mesh: &crate::mesh::Mesh,
    radiosity: &[crate::color::Rgb],
    view: &View,
) -> Result<Frame, RenderError> {
    let mut rasterizer = Rasterizer::new();
    Ok(rasterizer.render(mesh, radiosity, view)?.clone())
}
