//! Lines drawn over a finished picture: the element mesh, so a user can see
//! how fine the solution is sampled.
//!
//! Edges are clipped to the near plane, projected, clipped to the picture
//! and stepped pixel by pixel. A pixel of an edge is drawn only when the
//! edge is not behind the surface the picture shows there (depth test
//! against the rasterizer's `1/z` buffer, with a small bias so an edge lying
//! on its own surface wins).

use super::camera::View;
use crate::mesh::Mesh;
use glam::{DVec2, DVec3};
use image::RgbImage;

/// Colour of element mesh lines, in the window and in pictures: a cyan
/// that stands out from the warm and grey tones of lit interiors.
pub const MESH_COLOR: [u8; 3] = [40, 220, 255];

/// An edge pixel is drawn when its `1/z` is at least the surface's times
/// `1 − LINE_DEPTH_BIAS`: edges lie exactly on their surface, and the
/// picture's depth is interpolated per triangle, so equality needs slack.
pub const LINE_DEPTH_BIAS: f64 = 1e-3;

/// Draws every element edge of `mesh` (sky facets left out, as the
/// picture leaves them out) seen through `view` onto `image` in
/// `color`, hidden where a nearer surface covers it. `inv_depth` is the
/// rasterizer's depth buffer for the same view ([`super::Rasterizer::inv_depth`]),
/// one `1/z` per pixel; if its size does not match the image, nothing is drawn.
pub fn draw_mesh_edges(
    image: &mut RgbImage,
    mesh: &Mesh,
    view: &View,
    inv_depth: &[f64],
    color: [u8; 3],
) {
    let (w, h) = (image.width() as usize, image.height() as usize);
    if inv_depth.len() != w * h || w == 0 || h == 0 {
        return;
    }
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
            draw_segment(image, view, inv_depth, ca, cb, color);
        }
    }
}

/// One camera-space segment, clipped to the near plane and the picture.
fn draw_segment(
    image: &mut RgbImage,
    view: &View,
    inv_depth: &[f64],
    a: DVec3,
    b: DVec3,
    color: [u8; 3],
) {
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
        if inv_z >= inv_depth[y * width + x] * (1.0 - LINE_DEPTH_BIAS) {
            image.put_pixel(x as u32, y as u32, image::Rgb(color));
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
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::mesh::{self, MeshOptions};
    use crate::render::{to_srgb8, Rasterizer};
    use crate::testutil;

    #[test]
    fn edges_are_drawn_where_visible_and_hidden_behind_nearer_surfaces() {
        // A 2 × 2 grid facing the camera, and a black square in front of
        // its left half.
        let s = testutil::scene(
            vec![
                testutil::polygon(
                    0,
                    &[[-1., -1., 0.], [1., -1., 0.], [1., 1., 0.], [-1., 1., 0.]],
                ),
                testutil::polygon(
                    1,
                    &[
                        [-1.2, -1.2, 1.],
                        [0., -1.2, 1.],
                        [0., 1.2, 1.],
                        [-1.2, 1.2, 1.],
                    ],
                ),
            ],
            vec![
                testutil::grey("white", 1.0, 0.0),
                testutil::grey("black", 0.0, 0.0),
            ],
        );
        let mut camera = s.camera;
        camera.eye = glam::Vec3::new(0.0, 0.0, 4.0);
        camera.lookat = glam::Vec3::ZERO;
        camera.width = 64;
        camera.height = 64;
        let m = mesh::build(
            &s,
            &MeshOptions {
                lenmax: 1.5,
                inset: 0.0,
            },
        )
        .unwrap();
        let radiosity: Vec<Rgb> = m
            .vertex_polygon
            .iter()
            .map(|p| {
                if p.0 == 0 {
                    Rgb::splat(0.5)
                } else {
                    Rgb::BLACK
                }
            })
            .collect();
        let view = View::new(&camera).unwrap();
        let mut r = Rasterizer::new();
        let frame = r.render(&m, &radiosity, &view).unwrap().clone();
        let mut img = to_srgb8(&frame, 1.0);
        let before = img.clone();
        draw_mesh_edges(&mut img, &m, &view, r.inv_depth(), [255, 0, 0]);
        let red = |img: &RgbImage, x: u32, y: u32| img.get_pixel(x, y).0 == [255, 0, 0];
        // The grey grid's middle vertical line (x = 0 in the world) is at
        // the picture's centre column; below the black square's edge it is
        // visible on the right half.
        let centre = view.project(glam::Vec3::new(0.5, 0.0, 0.0)).unwrap();
        let mid_line = view.project(glam::Vec3::new(1.0, 0.0, 0.0)).unwrap();
        assert!(mid_line.x > centre.x);
        let row = centre.y as u32;
        let right_edge_x = (mid_line.x as u32).min(63);
        assert!((right_edge_x.saturating_sub(1)..=right_edge_x.min(63)).any(|x| red(&img, x, row)));
        // Behind the black square (left of the centre) the grid's edges
        // are hidden: only the black square's own edges may be drawn there.
        // The grey grid's left border at x = -1 lies behind the black square.
        let hidden = view.project(glam::Vec3::new(-1.0, 0.6, 0.0)).unwrap();
        assert!(!red(&img, hidden.x as u32, hidden.y as u32));
        // Without the black square in front it would be drawn: its twin on
        // the right border at x = +1 is.
        let twin = view.project(glam::Vec3::new(1.0, 0.6, 0.0)).unwrap();
        let tx = (twin.x as u32).min(63);
        assert!((tx.saturating_sub(1)..=tx).any(|x| red(&img, x, twin.y as u32)));
        // Something was drawn, and untouched pixels are unchanged.
        let changed = img
            .pixels()
            .zip(before.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert!(changed > 50, "{changed}");
        assert!(img
            .pixels()
            .zip(before.pixels())
            .all(|(a, b)| a == b || a.0 == [255, 0, 0]));
    }

    #[test]
    fn mismatched_depth_buffer_draws_nothing() {
        let s = testutil::scene(
            vec![testutil::polygon(
                0,
                &[[-1., -1., 0.], [1., -1., 0.], [1., 1., 0.], [-1., 1., 0.]],
            )],
            vec![testutil::grey("white", 1.0, 0.0)],
        );
        let m = mesh::build(
            &s,
            &MeshOptions {
                lenmax: 0.5,
                inset: 0.0,
            },
        )
        .unwrap();
        let view = View::new(&s.camera).unwrap();
        let mut img = RgbImage::new(view.width(), view.height());
        draw_mesh_edges(&mut img, &m, &view, &[], [255, 0, 0]);
        assert!(img.pixels().all(|p| p.0 == [0, 0, 0]));
    }

    #[test]
    fn clipping_to_the_picture() {
        assert_eq!(
            clip_to_rect(DVec2::new(-10.0, 5.0), DVec2::new(20.0, 5.0), 10.0, 10.0),
            Some((1.0 / 3.0, 2.0 / 3.0))
        );
        assert_eq!(
            clip_to_rect(DVec2::new(-10.0, 50.0), DVec2::new(20.0, 50.0), 10.0, 10.0),
            None
        );
    }
}
