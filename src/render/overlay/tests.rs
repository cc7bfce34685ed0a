//! Mesh lines: drawn where visible, hidden behind nearer surfaces, clipped
//! to the picture, continuous on grazing floors, and in a colour that
//! contrasts with the surface.

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
    draw_mesh_edges(
        &mut img,
        &m,
        &view,
        r.inv_depth(),
        LinePalette::single([255, 0, 0]),
    );
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
    draw_mesh_edges(&mut img, &m, &view, &[], MESH_LINES);
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

/// A floor seen at a grazing angle, lit evenly at `level`, with its
/// mesh lines drawn in the default palette; returns the picture, the
/// view and the `z` of every mesh line across the floor.
fn grazing_floor(level: f64) -> (RgbImage, View, Vec<f32>) {
    let s = testutil::scene(
        vec![testutil::polygon(
            0,
            &[[-4., 0., 0.], [4., 0., 0.], [4., 0., -40.], [-4., 0., -40.]],
        )],
        vec![testutil::grey("floor", 0.5, 0.0)],
    );
    let mut camera = s.camera;
    camera.eye = glam::Vec3::new(0.05, 0.25, 1.0);
    // Turned a little sideways, so lines across the floor are slanted.
    camera.lookat = glam::Vec3::new(3.0, 0.0, -20.0);
    camera.width = 400;
    camera.height = 300;
    let m = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 1.0,
            inset: 0.0,
        },
    )
    .unwrap();
    let radiosity = vec![Rgb::splat(level); m.vertex_count()];
    let view = View::new(&camera).unwrap();
    let mut r = Rasterizer::new();
    let frame = r.render(&m, &radiosity, &view).unwrap().clone();
    let mut img = to_srgb8(&frame, 1.0);
    draw_mesh_edges(&mut img, &m, &view, r.inv_depth(), MESH_LINES);
    let mut rows: Vec<f32> = m.positions.iter().map(|p| p.z).collect();
    rows.sort_by(f32::total_cmp);
    rows.dedup();
    (img, view, rows)
}

#[test]
fn lines_on_a_grazing_floor_stay_continuous() {
    let (img, view, rows) = grazing_floor(0.05);
    // The mesh lines across the floor, far from the eye, are seen at a
    // grazing angle: each must show in every column it crosses
    // (within a pixel above or below).
    let mut checked = 0;
    for z in rows.into_iter().filter(|z| (-30.0..-5.0).contains(z)) {
        let a = view.project(glam::Vec3::new(-3.5, 0.0, z)).unwrap();
        let b = view.project(glam::Vec3::new(3.5, 0.0, z)).unwrap();
        let (mut columns, mut drawn) = (0, 0);
        for x in (a.x.ceil() as u32)..(b.x.floor() as u32).min(399) {
            let t = (x as f32 + 0.5 - a.x) / (b.x - a.x);
            let y = (a.y + (b.y - a.y) * t).floor() as u32;
            columns += 1;
            if (y.saturating_sub(1)..=(y + 1).min(299)).any(|y| img.get_pixel(x, y).0 == MESH_COLOR)
            {
                drawn += 1;
            }
        }
        assert!(columns > 20, "{columns} columns");
        assert_eq!(drawn, columns, "the line at z = {z} is broken");
        checked += 1;
    }
    assert!(checked >= 10, "{checked} lines checked");
}

#[test]
fn line_colour_contrasts_with_the_surface() {
    let count = |img: &RgbImage, c: [u8; 3]| img.pixels().filter(|p| p.0 == c).count();
    // Dark floor: light cyan lines only.
    let (dark, _, _) = grazing_floor(0.05);
    assert!(count(&dark, MESH_COLOR) > 100);
    assert_eq!(count(&dark, MESH_COLOR_ON_LIGHT), 0);
    // White floor: deep blue lines (cyan only where a line pixel lies
    // on the black background beyond the floor's far edge).
    let (light, _, _) = grazing_floor(1.0);
    let (blue, cyan) = (
        count(&light, MESH_COLOR_ON_LIGHT),
        count(&light, MESH_COLOR),
    );
    assert!(blue > 10 * cyan && blue > 1000, "{blue} blue, {cyan} cyan");
    assert!(luma(MESH_COLOR) > 150.0 && luma(MESH_COLOR_ON_LIGHT) < 100.0);
}
