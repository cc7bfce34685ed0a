//! Lines drawn over a finished picture: the element mesh, so a user can see
//! how fine the solution is sampled.
//!
//! Edges are clipped to the near plane, projected, clipped to the picture
//! and stepped pixel by pixel. A pixel of an edge is drawn only when the
//! edge is not behind the surface the picture shows there: a depth test
//! against the rasterizer's `1/z` buffer with a slope-scaled offset (the
//! farthest surface among the pixel and its eight neighbours, less a small
//! bias), so an edge lying on a wall seen at a grazing angle, whose depth
//! changes by more than the bias from one pixel to the next, stays a
//! continuous line instead of breaking into dashes.
//!
//! Each pixel of a line takes the colour of [`MESH_LINES`] that contrasts
//! with the picture under it: a light cyan on dark and mid-tone surfaces, a
//! deep blue on light ones, so the mesh is readable on every wall.

use super::view::View;
use crate::mesh::Mesh;
use glam::{DVec2, DVec3};
use image::RgbImage;

/// The two colours of element mesh lines, in the window and in pictures
/// (sRGB, 8 bits a channel). A pixel of a line is drawn in `on_dark` where
/// the picture under it has a luma (Rec. 709 weights on the 8-bit values)
/// below `threshold`, else in `on_light`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinePalette {
    /// Colour over dark and mid-tone pixels.
    pub on_dark: [u8; 3],
    /// Colour over light pixels.
    pub on_light: [u8; 3],
    /// Luma, 0–255, from which a pixel counts as light.
    pub threshold: u8,
}

impl LinePalette {
    /// One colour everywhere.
    pub const fn single(color: [u8; 3]) -> LinePalette {
        LinePalette {
            on_dark: color,
            on_light: color,
            threshold: 0,
        }
    }

    /// The colour of a line pixel over the picture colour `under`.
    pub fn over(&self, under: [u8; 3]) -> [u8; 3] {
        if luma(under) < f32::from(self.threshold) {
            self.on_dark
        } else {
            self.on_light
        }
    }
}

/// Luma of an 8-bit sRGB colour, 0–255 (Rec. 709 weights).
fn luma([r, g, b]: [u8; 3]) -> f32 {
    0.2126 * f32::from(r) + 0.7152 * f32::from(g) + 0.0722 * f32::from(b)
}

/// The element mesh's line colours: a light cyan (luma 184) that stands
/// out from the warm and grey tones of lit interiors, and, on surfaces
/// lighter than luma 150 (where cyan would wash out), a deep blue (luma
/// 51). Either keeps a contrast of about 1:2.5 or more with what is under it.
pub const MESH_LINES: LinePalette = LinePalette {
    on_dark: MESH_COLOR,
    on_light: MESH_COLOR_ON_LIGHT,
    threshold: 150,
};

/// The mesh line colour on dark and mid-tone surfaces (see [`MESH_LINES`]).
pub const MESH_COLOR: [u8; 3] = [40, 220, 255];

/// The mesh line colour on light surfaces (see [`MESH_LINES`]).
pub const MESH_COLOR_ON_LIGHT: [u8; 3] = [0, 50, 140];

/// An edge pixel is drawn when its `1/z` is at least that of the farthest
/// surface among the pixel and its neighbours times `1 − LINE_DEPTH_BIAS`:
/// edges lie exactly on their surface, and the picture's depth is
/// interpolated per triangle at pixel centres, so equality needs slack.
pub const LINE_DEPTH_BIAS: f64 = 1e-3;

/// Draws every element edge of `mesh` (sky facets left out, as the
/// picture leaves them out) seen through `view` onto `image` in the
/// `palette` colour that contrasts with the picture under each pixel,
/// hidden where a nearer surface covers it. `inv_depth` is the
/// rasterizer's depth buffer for the same view ([`super::Rasterizer::inv_depth`]),
/// one `1/z` per pixel; if its size does not match the image, nothing is drawn.
pub fn draw_mesh_edges(
    image: &mut RgbImage,
    mesh: &Mesh,
    view: &View,
    inv_depth: &[f64],
    palette: LinePalette,
) {
    let (w, h) = (image.width() as usize, image.height() as usize);
    if inv_depth.len() != w * h || w == 0 || h == 0 {
        return;
    }
    // The colours are chosen against the picture as it was: an edge drawn
    // twice (shared by two elements) must not contrast with itself.
    let under = image.clone();
    let farthest = farthest_neighbour_depth(inv_depth, w, h);
    let target = Target {
        under: &under,
        farthest: &farthest,
        palette,
    };
    for (element, polygon) in mesh.elements.iter().zip(&mesh.element_polygon) {
        if mesh.polygons.get(polygon.index()).is_none_or(|pm| pm.sky) {
            continue;
        }
        let corners = element.corners();
        for k in 0..corners.len() {
            let (a, b) = (corners[k].index(), corners[(k + 1) % corners.len()].index());
            // Edges shared by two elements are drawn twice; the result is
            // the same and telling shared from boundary edges costs more.
            let (Some(pa), Some(pb)) = (mesh.positions.get(a), mesh.positions.get(b)) else {
                continue;
            };
            let ca = view.to_camera(*pa).as_dvec3();
            let cb = view.to_camera(*pb).as_dvec3();
            draw_segment(image, view, &target, ca, cb);
        }
    }
}

/// What an edge pixel is tested against and coloured by.
struct Target<'a> {
    /// The picture before any line was drawn.
    under: &'a RgbImage,
    /// Per pixel, the smallest covered `1/z` among it and its neighbours.
    farthest: &'a [f64],
    palette: LinePalette,
}

/// Per pixel, the smallest non-zero `1/z` (the farthest surface) among the
/// pixel and its eight neighbours, or 0 where none of them is covered.
/// Testing an edge against it is a slope-scaled depth offset: where the
/// surface's depth changes fast across pixels (a grazing wall), the
/// allowance grows with it.
fn farthest_neighbour_depth(inv_depth: &[f64], w: usize, h: usize) -> Vec<f64> {
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut far = f64::INFINITY;
            for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    let d = inv_depth[ny * w + nx];
                    if d > 0.0 && d < far {
                        far = d;
                    }
                }
            }
            out[y * w + x] = if far.is_finite() { far } else { 0.0 };
        }
    }
    out
}

/// One camera-space segment, clipped to the near plane and the picture.
fn draw_segment(image: &mut RgbImage, view: &View, target: &Target, a: DVec3, b: DVec3) {
    let near = f64::from(view.near());
    let (mut a, mut b) = (a, b);
    if a.z < near && b.z < near {
        return;
    }
    if a.z < near {
        a = a + (b - a) * ((near - a.z) / (b.z - a.z));
    } else if b.z < near {
        b = b + (a - b) * ((near - b.z) / (a.z - b.z));
    }
    let (Some(pa), Some(pb)) = (view.camera_to_pixel(a), view.camera_to_pixel(b)) else {
        return;
    };
    let (w, h) = (f64::from(image.width()), f64::from(image.height()));
    // 1/z is affine in screen space, so it interpolates linearly along the
    // projected segment.
    let (za, zb) = (1.0 / a.z, 1.0 / b.z);
    let Some((t0, t1)) = clip_to_rect(pa, pb, w, h) else {
        return;
    };
    let d = pb - pa;
    let steps = (d.x.abs().max(d.y.abs()) * (t1 - t0)).ceil().max(1.0) as usize;
    let width = image.width() as usize;
    for s in 0..=steps {
        let t = t0 + (t1 - t0) * s as f64 / steps as f64;
        let p = pa + d * t;
        let (x, y) = (p.x.floor(), p.y.floor());
        if x < 0.0 || y < 0.0 || x >= w || y >= h {
            continue;
        }
        let (x, y) = (x as usize, y as usize);
        let inv_z = za + (zb - za) * t;
        if inv_z >= target.farthest[y * width + x] * (1.0 - LINE_DEPTH_BIAS) {
            let under = target.under.get_pixel(x as u32, y as u32).0;
            image.put_pixel(x as u32, y as u32, image::Rgb(target.palette.over(under)));
        }
    }
}

/// Liang–Barsky: the parameter range `[t0, t1]` of the segment `a → b`
/// inside `[0, w] × [0, h]`, or `None` when it misses.
fn clip_to_rect(a: DVec2, b: DVec2, w: f64, h: f64) -> Option<(f64, f64)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-d.x, a.x), (d.x, w - a.x), (-d.y, a.y), (d.y, h - a.y)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

#[cfg(test)]
mod tests;
