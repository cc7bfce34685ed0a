//! The rasterizer's coverage, depth order, clipping, shading and watertight
//! edges, and its tiled, parallel drawing against drawing every triangle over
//! the whole picture.

use super::*;
use crate::mesh::{Element, PolygonMesh};
use crate::scene::{Camera, PolygonId};
use glam::Vec3;

/// Tolerance on interpolated radiosity, relative to values of order one.
const VALUE_TOLERANCE: f32 = 1e-5;

/// A 100x100 picture looking down -z from the origin with a 90° field of
/// view: at depth `d` the picture spans `[-d, d]` in x and y, so one
/// pixel is `d / 50` wide.
fn view() -> View {
    let camera = Camera {
        eye: Vec3::ZERO,
        lookat: Vec3::new(0.0, 0.0, -1.0),
        up: Vec3::Y,
        fov_y: std::f32::consts::FRAC_PI_2,
        width: 100,
        height: 100,
    };
    View::new(&camera).unwrap()
}

/// A mesh builder: quads (one element each, counter-clockwise from the
/// front) with per-corner radiosity.
#[derive(Default)]
struct Builder {
    mesh: Option<Mesh>,
    radiosity: Vec<Rgb>,
}

impl Builder {
    fn polygon(&mut self, corners: &[Vec3], values: &[f64]) -> &mut Self {
        let mesh = self.mesh.get_or_insert_with(|| Mesh {
            positions: vec![],
            sample_positions: vec![],
            vertex_polygon: vec![],
            elements: vec![],
            element_polygon: vec![],
            polygons: vec![],
        });
        let first = mesh.positions.len() as u32;
        let pid = PolygonId(mesh.polygons.len() as u32);
        let normal = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize();
        for (&p, &v) in corners.iter().zip(values) {
            mesh.positions.push(p);
            mesh.sample_positions.push(p);
            mesh.vertex_polygon.push(pid);
            self.radiosity.push(Rgb::splat(v));
        }
        let id = |i: u32| VertexId(first + i);
        let element = if corners.len() == 4 {
            Element::quad(id(0), id(1), id(2), id(3))
        } else {
            Element::triangle(id(0), id(1), id(2))
        };
        let e = mesh.elements.len() as u32;
        mesh.elements.push(element);
        mesh.element_polygon.push(pid);
        mesh.polygons.push(PolygonMesh {
            nu: 1,
            nv: 1,
            vertices: first..mesh.positions.len() as u32,
            elements: e..e + 1,
            normal,
            area: 1.0,
            min_edge: 1.0,
            inset: 0.0,
            levels: 0,
            layer: 0,
            has_back: false,
            sky: false,
            stitched: false,
        });
        self
    }

    fn render(&self) -> Frame {
        let mesh = self.mesh.as_ref().unwrap();
        Rasterizer::new()
            .render(mesh, &self.radiosity, &view())
            .unwrap()
            .clone()
    }
}

/// An axis-aligned rectangle facing +z (towards the eye) at depth `d`,
/// given in pixel bounds of the 100x100 picture of [`view`].
fn rect(px0: f32, py0: f32, px1: f32, py1: f32, d: f32) -> [Vec3; 4] {
    let wx = |px: f32| (px / 50.0 - 1.0) * d;
    let wy = |py: f32| (1.0 - py / 50.0) * d;
    [
        Vec3::new(wx(px0), wy(py1), -d),
        Vec3::new(wx(px1), wy(py1), -d),
        Vec3::new(wx(px1), wy(py0), -d),
        Vec3::new(wx(px0), wy(py0), -d),
    ]
}

fn covered_count(f: &Frame) -> usize {
    f.covered.iter().filter(|&&c| c).count()
}

#[test]
fn facing_quad_covers_its_rectangle() {
    let frame = Builder::default()
        .polygon(&rect(10.0, 20.0, 30.0, 60.0, 5.0), &[0.5; 4])
        .render();
    assert_eq!(covered_count(&frame), 20 * 40);
    for y in 0..100 {
        for x in 0..100 {
            let inside = (10..30).contains(&x) && (20..60).contains(&y);
            assert_eq!(frame.is_covered(x, y), inside, "({x}, {y})");
            let v = frame.pixel(x, y).unwrap();
            let want = if inside { 0.5 } else { 0.0 };
            assert!(
                v.iter().all(|&c| (c - want).abs() < VALUE_TOLERANCE),
                "{v:?}"
            );
        }
    }
}

#[test]
fn nearer_quad_wins_in_either_order() {
    let near = rect(10.0, 10.0, 60.0, 60.0, 2.0);
    let far = rect(30.0, 30.0, 90.0, 90.0, 4.0);
    let a = Builder::default()
        .polygon(&near, &[1.0; 4])
        .polygon(&far, &[0.25; 4])
        .render();
    let b = Builder::default()
        .polygon(&far, &[0.25; 4])
        .polygon(&near, &[1.0; 4])
        .render();
    assert_eq!(a, b);
    assert_eq!(a.pixel(40, 40), Some([1.0; 3]));
    assert_eq!(a.pixel(70, 70), Some([0.25; 3]));
    assert_eq!(covered_count(&a), 50 * 50 + 60 * 60 - 30 * 30);
}

#[test]
fn back_face_holds_no_light_is_flagged_and_occludes() {
    let mut back = rect(10.0, 10.0, 60.0, 60.0, 2.0);
    back.reverse();
    let lit = rect(0.0, 0.0, 100.0, 100.0, 4.0);
    let frame = Builder::default()
        .polygon(&lit, &[1.0; 4])
        .polygon(&back, &[3.0; 4])
        .render();
    assert_eq!(covered_count(&frame), 100 * 100);
    assert_eq!(frame.pixel(30, 30), Some([0.0; 3]));
    assert_eq!(frame.back[30 * 100 + 30], 1.0);
    assert_eq!(frame.pixel(80, 80), Some([1.0; 3]));
    assert_eq!(frame.back[80 * 100 + 80], 0.0);
    // The 8-bit picture paints it, not black; the lit quad is as before.
    let img = crate::render::to_srgb8(&frame, 1.0);
    assert_eq!(
        img.get_pixel(30, 30).0,
        crate::render::back_face_color(30, 30)
    );
    assert_ne!(img.get_pixel(30, 30).0, [0, 0, 0]);
    assert_eq!(img.get_pixel(80, 80).0, [255; 3]);
}

#[test]
fn front_faces_tell_back_faces_from_front_and_background() {
    let mut back = rect(10.0, 10.0, 60.0, 60.0, 2.0);
    back.reverse();
    let lit = rect(0.0, 0.0, 100.0, 50.0, 4.0);
    let mut b = Builder::default();
    b.polygon(&lit, &[1.0; 4]).polygon(&back, &[3.0; 4]);
    let mut r = Rasterizer::new();
    r.render(b.mesh.as_ref().unwrap(), &b.radiosity, &view())
        .unwrap();
    let front = r.front_faces();
    assert_eq!(front.len(), 100 * 100);
    let at = |x: usize, y: usize| front[y * 100 + x];
    // Back face over the lit quad, the lit quad alone, background.
    assert!(!at(30, 30) && r.frame().is_covered(30, 30));
    assert!(at(80, 20));
    assert!(!at(80, 80) && !r.frame().is_covered(80, 80));
}

#[test]
fn triangle_through_the_eye_plane_covers_the_lower_half() {
    // A floor at y = -1 reaching from far in front to behind the eye:
    // it covers everything below the horizon (rows 50..100).
    let floor = [
        Vec3::new(-1000.0, -1.0, -1000.0),
        Vec3::new(0.0, -1.0, 1000.0),
        Vec3::new(1000.0, -1.0, -1000.0),
    ];
    let frame = Builder::default().polygon(&floor, &[1.0; 3]).render();
    for y in 0..100 {
        let row = (0..100).filter(|&x| frame.is_covered(x, y)).count();
        if y >= 51 {
            assert_eq!(row, 100, "row {y}");
        }
        if y < 49 {
            assert_eq!(row, 0, "row {y}");
        }
    }
    assert!(frame.pixels.iter().all(|p| p.iter().all(|c| c.is_finite())));
}

#[test]
fn shared_edges_have_no_gaps_or_overlaps() {
    // A fan of thin triangles around an off-grid centre, plus the quads'
    // own diagonals: every pixel of the covered square is drawn once.
    let c = Vec3::new(0.123, -0.077, -3.0);
    let ring: Vec<Vec3> = (0..24)
        .map(|k| {
            let a = k as f32 / 24.0 * std::f32::consts::TAU;
            c + Vec3::new(a.cos(), a.sin(), 0.0) * 2.0
        })
        .collect();
    let mut b = Builder::default();
    for k in 0..24 {
        b.polygon(&[c, ring[k], ring[(k + 1) % 24]], &[1.0; 3]);
    }
    let counts = coverage_counts(b.mesh.as_ref().unwrap(), &b.radiosity);
    assert!(counts.iter().all(|&n| n <= 1), "a pixel drawn twice");
    let all = b.render();
    assert_eq!(
        counts.iter().filter(|&&n| n == 1).count(),
        covered_count(&all)
    );
    // No gap: the centre pixel's neighbourhood is fully covered.
    let centre = view().project(c).unwrap();
    let (cx, cy) = (centre.x as u32, centre.y as u32);
    for y in cy - 20..cy + 20 {
        for x in cx - 20..cx + 20 {
            assert!(all.is_covered(x, y), "gap at ({x}, {y})");
        }
    }
}

#[test]
fn adaptively_refined_mesh_has_no_cracks() {
    // A square facing the camera, refined twice across a step, so split
    // elements, fans around hanging vertices and unsplit elements meet:
    // every pixel inside it is drawn exactly once.
    use crate::mesh::refine::{RefineOptions, Refiner};
    use crate::testutil;
    let d = 3.0;
    let corners = [
        [-1.5, -1.5, -d],
        [1.5, -1.5, -d],
        [1.5, 1.5, -d],
        [-1.5, 1.5, -d],
    ];
    let scene = testutil::scene(
        vec![testutil::polygon(0, &corners)],
        vec![testutil::grey("m", 0.0, 0.5)],
    );
    let options = crate::mesh::MeshOptions {
        lenmax: 0.4,
        inset: 0.0,
    };
    let mut mesh = crate::mesh::build(&scene, &options).unwrap();
    let mut refiner = Refiner::new(&mesh);
    let mut fans = 0;
    while let Some((next, report)) = refiner.refine(
        &scene,
        &mesh
            .positions
            .iter()
            .map(|p| if p.x + 0.3 * p.y < 0.21 { 0.1 } else { 1.0 })
            .collect::<Vec<_>>(),
        &RefineOptions::default(),
    ) {
        fans += report.fans;
        mesh = next;
    }
    assert!(fans > 0);
    let radiosity = vec![Rgb::splat(1.0); mesh.vertex_count()];
    let counts = coverage_counts(&mesh, &radiosity);
    assert!(counts.iter().all(|&n| n <= 1), "a pixel drawn twice");
    // The square spans pixels 25..75 (one pixel is d/50 = 0.06 wide);
    // one pixel in from its edges every pixel must be drawn.
    for y in 26..74 {
        for x in 26..74 {
            assert_eq!(counts[y * 100 + x], 1, "crack at ({x}, {y})");
        }
    }
}

/// How many triangles cover each pixel, drawing each triangle alone.
fn coverage_counts(mesh: &Mesh, radiosity: &[Rgb]) -> Vec<u32> {
    let mut counts = vec![0u32; 100 * 100];
    for (e, element) in mesh.elements.iter().enumerate() {
        for tri in element.triangles() {
            let mut single = mesh.clone();
            single.elements = vec![Element::triangle(tri[0], tri[1], tri[2])];
            single.element_polygon = vec![mesh.element_polygon[e]];
            let f = Rasterizer::new()
                .render(&single, radiosity, &view())
                .unwrap()
                .clone();
            for (n, &cov) in counts.iter_mut().zip(&f.covered) {
                *n += u32::from(cov);
            }
        }
    }
    counts
}

#[test]
fn edges_through_pixel_centres_follow_the_top_left_rule() {
    // Edges exactly on pixel centres: the left and top ones include
    // them, the right and bottom ones do not, and the quad's diagonal
    // (through centres as well, it is square) is drawn once.
    let mut b = Builder::default();
    b.polygon(&rect(10.5, 20.5, 30.5, 40.5, 2.0), &[1.0; 4]);
    let frame = b.render();
    assert_eq!(covered_count(&frame), 20 * 20);
    assert!(frame.is_covered(10, 20) && frame.is_covered(29, 39));
    assert!(!frame.is_covered(30, 20) && !frame.is_covered(10, 40));
    let counts = coverage_counts(b.mesh.as_ref().unwrap(), &b.radiosity);
    assert!(counts.iter().all(|&n| n <= 1));
    assert_eq!(counts.iter().filter(|&&n| n == 1).count(), 20 * 20);
}

#[test]
fn shared_edge_crossing_the_eye_plane_stays_watertight() {
    // A floor quad reaching behind the eye, split along its 0–2 diagonal,
    // which crosses the near plane off-centre: the two clipped halves
    // must meet exactly.
    let floor = [
        Vec3::new(-30.0, -1.0, 7.0),
        Vec3::new(40.0, -1.0, 9.0),
        Vec3::new(33.0, -1.0, -50.0),
        Vec3::new(-45.0, -1.0, -41.0),
    ];
    let mut b = Builder::default();
    b.polygon(&floor, &[1.0; 4]);
    let counts = coverage_counts(b.mesh.as_ref().unwrap(), &b.radiosity);
    assert!(counts.iter().all(|&n| n <= 1), "a pixel drawn twice");
    // Everything well below the horizon is floor.
    for y in 60..100 {
        for x in 0..100 {
            assert_eq!(counts[y * 100 + x], 1, "gap at ({x}, {y})");
        }
    }
}

#[test]
fn camera_inside_a_room_sees_walls_everywhere() {
    // A box around an off-centre eye, every wall facing inwards with its
    // own radiosity: every pixel is covered and lit, none is a back face.
    let (lo, hi) = (Vec3::new(-2.0, -1.5, -4.0), Vec3::new(3.0, 2.5, 1.0));
    let corner = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    // Each face counter-clockwise seen from inside the box.
    let faces = [
        [0, 2, 6, 4],
        [1, 5, 7, 3],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 6, 7, 5],
    ];
    let mut b = Builder::default();
    for (k, f) in faces.iter().enumerate() {
        let quad = f.map(corner);
        b.polygon(&quad, &[k as f64 + 1.0; 4]);
    }
    let frame = b.render();
    assert_eq!(covered_count(&frame), 100 * 100);
    assert!(
        frame.pixels.iter().all(|p| p[0] >= 1.0 - VALUE_TOLERANCE),
        "a black pixel"
    );
    // The eye looks down -z, so the centre shows the far wall (face 4).
    assert_eq!(frame.pixel(50, 50), Some([5.0; 3]));
}

#[test]
fn gradient_increases_across_a_row() {
    let r = rect(0.0, 0.0, 100.0, 100.0, 2.0);
    // Corners: bottom-left, bottom-right, top-right, top-left.
    let frame = Builder::default()
        .polygon(&r, &[0.0, 1.0, 1.0, 0.0])
        .render();
    for y in [0, 37, 99] {
        let row: Vec<f32> = (0..100).map(|x| frame.pixel(x, y).unwrap()[0]).collect();
        assert!(row.windows(2).all(|w| w[1] > w[0]), "row {y}: {row:?}");
        // Facing the camera, perspective-correct is linear in x.
        assert!((row[0] - 0.005).abs() < VALUE_TOLERANCE, "{}", row[0]);
        assert!((row[99] - 0.995).abs() < VALUE_TOLERANCE, "{}", row[99]);
    }
}

#[test]
fn perspective_correct_on_a_slanted_quad() {
    // A floor strip from depth 1 to 3 with radiosity equal to its depth:
    // each pixel must show the depth of the point it sees.
    let corners = [
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(1.0, -1.0, -3.0),
        Vec3::new(-1.0, -1.0, -3.0),
    ];
    let frame = Builder::default()
        .polygon(&corners, &[1.0, 1.0, 3.0, 3.0])
        .render();
    for y in 0..100u32 {
        if frame.is_covered(50, y) {
            // Row centre at ndc_y = 1 - (y + 0.5) / 50 sees y=-1 at z = 1 / -ndc_y.
            let ndc = 1.0 - (y as f32 + 0.5) / 50.0;
            let want = -1.0 / ndc;
            let got = frame.pixel(50, y).unwrap()[0];
            assert!((got - want).abs() < 1e-4 * want, "row {y}: {got} vs {want}");
        }
    }
}

#[test]
fn same_bits_with_any_thread_count() {
    let mut b = Builder::default();
    for k in 0..40 {
        let t = k as f32 * 0.37;
        let c = Vec3::new(t.sin() * 2.0, t.cos() * 1.5, -3.0 - (k % 7) as f32);
        b.polygon(
            &[
                c,
                c + Vec3::new(1.3, 0.2, 0.5),
                c + Vec3::new(0.4, 1.1, -0.3),
            ],
            &[k as f64, 1.0, 0.5],
        );
    }
    let mesh = b.mesh.clone().unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            Rasterizer::new()
                .render(&mesh, &b.radiosity, &view())
                .unwrap()
                .clone()
        })
    };
    let one = run(1);
    assert!(covered_count(&one) > 0);
    assert_eq!(one, run(4));
    assert_eq!(one, run(7));
}

/// The brute-force twin of [`Rasterizer::render`]: serial setup with
/// every plane clipped, then every triangle tested at every pixel of
/// its bounding box over the whole picture, in mesh order. Returns the
/// frame, `1 / z` and the front-face flags.
fn render_brute_force(mesh: &Mesh, radiosity: &[Rgb], view: &View) -> (Frame, Vec<f64>, Vec<bool>) {
    let setup = Setup::new(view);
    let mut triangles = Vec::new();
    let mut local = Vec::new();
    for (e, element) in mesh.elements.iter().enumerate() {
        let polygon = &mesh.polygons[mesh.element_polygon[e].index()];
        if polygon.sky {
            continue;
        }
        for tri in element.triangles() {
            let front = polygon
                .normal
                .dot(view.eye() - mesh.positions[tri[0].index()])
                > 0.0;
            if !front && polygon.has_back {
                continue;
            }
            let corner = |v: VertexId| ClipVertex {
                p: view.to_camera(mesh.positions[v.index()]).as_dvec3(),
                c: radiosity[v.index()].to_array(),
            };
            setup.push_clipped(
                [corner(tri[0]), corner(tri[1]), corner(tri[2])],
                front,
                polygon.layer,
                0,
                &mut local,
                &mut triangles,
            );
        }
    }
    let (w, h) = (view.width() as usize, view.height() as usize);
    let mut frame = Frame::new(view.width(), view.height());
    let mut depth = vec![0.0; w * h];
    let mut front = vec![false; w * h];
    let mut band = Band {
        width: w,
        first_row: 0,
        rows: h,
        pixels: &mut frame.pixels,
        covered: &mut frame.covered,
        depth: &mut depth,
        front: &mut front,
        back: &mut frame.back,
    };
    for t in &triangles {
        band.draw_every_pixel(t, t.v.map(|i| &local[(i & !LOCAL_VERTEX) as usize]));
    }
    (frame, depth, front)
}

#[test]
fn binned_tiles_match_drawing_every_triangle_everywhere() {
    // Triangles from a few pixels to far beyond the picture, crossing
    // tile borders, the near plane and each other, some seen from the
    // back, some on higher draw layers, on a picture whose size is no
    // multiple of the tile size.
    let mut b = Builder::default();
    for k in 0..300 {
        let t = k as f32 * 0.618;
        let size = 0.05 + (k % 13) as f32 * (k % 5) as f32 * 0.15;
        let c = Vec3::new(
            (t * 1.3).sin() * 3.0,
            (t * 0.7).cos() * 2.0,
            -0.5 - (k % 11) as f32 * 0.7,
        );
        let mut tri = [
            c,
            c + Vec3::new(size, 0.3 * size, 0.4 * size * t.cos()),
            c + Vec3::new(0.2 * size, size, -0.6 * size),
        ];
        if k % 7 == 0 {
            tri.reverse();
        }
        b.polygon(&tri, &[k as f64, 1.0, 0.5]);
    }
    let mut mesh = b.mesh.clone().unwrap();
    for (k, p) in mesh.polygons.iter_mut().enumerate() {
        p.layer = (k % 3) as u8;
    }
    let camera = Camera {
        eye: Vec3::ZERO,
        lookat: Vec3::new(0.0, 0.0, -1.0),
        up: Vec3::Y,
        fov_y: 1.2,
        width: 333,
        height: 177,
    };
    let view = View::new(&camera).unwrap();
    let (want, want_depth, want_front) = render_brute_force(&mesh, &b.radiosity, &view);
    assert!(covered_count(&want) > 333 * 177 / 2);
    assert!(
        want_front.iter().any(|&f| f)
            && want_front.iter().zip(&want.covered).any(|(&f, &c)| c && !f)
    );
    let mut r = Rasterizer::new();
    let got = r.render(&mesh, &b.radiosity, &view).unwrap().clone();
    assert_eq!(got, want);
    assert_eq!(r.inv_depth(), &want_depth[..]);
    assert_eq!(r.front_faces(), &want_front[..]);
}

#[test]
fn bad_input_is_an_error() {
    let mut b = Builder::default();
    b.polygon(&rect(10.0, 10.0, 20.0, 20.0, 2.0), &[1.0; 4]);
    let mesh = b.mesh.clone().unwrap();
    let mut r = Rasterizer::new();
    assert_eq!(
        r.render(&mesh, &b.radiosity[..3], &view()).err(),
        Some(RenderError::RadiosityCount {
            expected: 4,
            found: 3
        })
    );
    let mut broken = mesh.clone();
    broken
        .elements
        .push(Element::triangle(VertexId(0), VertexId(1), VertexId(9)));
    broken.element_polygon.push(PolygonId(0));
    assert!(matches!(
        r.render(&broken, &b.radiosity, &view()),
        Err(RenderError::BadMesh(_))
    ));
}

#[test]
fn buffers_follow_the_view_size() {
    let mut b = Builder::default();
    b.polygon(&rect(0.0, 0.0, 100.0, 100.0, 2.0), &[1.0; 4]);
    let mesh = b.mesh.clone().unwrap();
    let mut r = Rasterizer::new();
    let camera = Camera {
        eye: Vec3::ZERO,
        lookat: Vec3::new(0.0, 0.0, -1.0),
        up: Vec3::Y,
        fov_y: std::f32::consts::FRAC_PI_2,
        width: 33,
        height: 21,
    };
    let small = View::new(&camera).unwrap();
    let f = r.render(&mesh, &b.radiosity, &small).unwrap();
    assert_eq!((f.width, f.height, f.pixels.len()), (33, 21, 33 * 21));
    assert!(f.is_consistent());
    let f = r.render(&mesh, &b.radiosity, &view()).unwrap();
    assert_eq!(covered_count(f), 100 * 100);
}
