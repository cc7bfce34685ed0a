//! Smooth surfaces and watertight shared edges, on models written as
//! Blender writes them (header comment, `mtllib`, `o`, `vn`, `s`,
//! `f a//n`): the welded radiosity in the exported mesh, and no
//! background pixel between polygons that share an edge.

mod common;

use glam::Vec3;
use radiosity::color::Rgb;
use radiosity::mesh::{self, MeshOptions, MAX_ELEMENTS};
use radiosity::render::{Rasterizer, View};
use radiosity::scene::{self, Camera};
use std::collections::HashMap;
use std::path::Path;

const MTL: &str = "# Blender 3.4.1 MTL File: 'None'\n\
# www.blender.org\n\
\n\
newmtl Light\n\
Ns 250.000000\n\
Ka 1.000000 1.000000 1.000000\n\
Kd 0.000000 0.000000 0.000000\n\
Ks 0.500000 0.500000 0.500000\n\
Ke 10.000000 10.000000 10.000000\n\
Ni 1.450000\n\
d 1.000000\n\
illum 2\n\
\n\
newmtl Material\n\
Ns 250.000000\n\
Ka 1.000000 1.000000 1.000000\n\
Kd 0.800000 0.800000 0.800000\n\
Ks 0.500000 0.500000 0.500000\n\
Ke 0.000000 0.000000 0.000000\n\
Ni 1.450000\n\
d 1.000000\n\
illum 2\n";

/// An icosphere of radius 1 at the origin (an icosahedron subdivided
/// once: 80 faces), counter-clockwise seen from outside.
fn icosphere() -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        [-1., t, 0.],
        [1., t, 0.],
        [-1., -t, 0.],
        [1., -t, 0.],
        [0., -1., t],
        [0., 1., t],
        [0., -1., -t],
        [0., 1., -t],
        [t, 0., -1.],
        [t, 0., 1.],
        [-t, 0., -1.],
        [-t, 0., 1.],
    ]
    .iter()
    .map(|a| Vec3::from_array(*a).normalize())
    .collect();
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
    let mut out = Vec::new();
    for [a, b, c] in faces {
        let mut m = |x: usize, y: usize| {
            *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                v.push(((v[x] + v[y]) * 0.5).normalize());
                v.len() - 1
            })
        };
        let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
        out.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
    }
    for f in &mut out {
        let n = (v[f[1]] - v[f[0]]).cross(v[f[2]] - v[f[0]]);
        if n.dot(v[f[0]]) < 0.0 {
            f.swap(1, 2);
        }
    }
    (v, out)
}

/// A Blender-style OBJ of a lamp above a mesh. `smooth` writes `s 1` and
/// one shared `vn` per vertex (Shade Smooth); otherwise `s 0` and one
/// `vn` per face (Shade Flat), as Blender does.
fn blender_obj(name: &str, v: &[Vec3], faces: &[Vec<usize>], smooth: bool) -> String {
    let mut s = String::from(
        "# Blender 3.4.1\r\n# www.blender.org\r\nmtllib model.mtl\r\n\
         o Light\r\nv -1.0 3.0 -1.0\r\nv 1.0 3.0 -1.0\r\nv 1.0 3.0 1.0\r\nv -1.0 3.0 1.0\r\n\
         vn -0.0000 -1.0000 -0.0000\r\ns 0\r\nusemtl Light\r\nf 1//1 2//1 3//1 4//1\r\n",
    );
    s += &format!("o {name}\r\n");
    for p in v {
        s += &format!("v {:.6} {:.6} {:.6}\r\n", p.x, p.y, p.z);
    }
    let normal = |f: &Vec<usize>| (v[f[1]] - v[f[0]]).cross(v[f[2]] - v[f[0]]).normalize();
    if smooth {
        for p in v {
            let n = p.normalize();
            s += &format!("vn {:.4} {:.4} {:.4}\r\n", n.x, n.y, n.z);
        }
    } else {
        for f in faces {
            let n = normal(f);
            s += &format!("vn {:.4} {:.4} {:.4}\r\n", n.x, n.y, n.z);
        }
    }
    s += if smooth { "s 1\r\n" } else { "s 0\r\n" };
    s += "usemtl Material\r\n";
    for (k, f) in faces.iter().enumerate() {
        s += "f";
        for &i in f {
            let n = if smooth { i + 2 } else { k + 2 };
            s += &format!(" {}//{}", i + 5, n);
        }
        s += "\r\n";
    }
    s
}

/// Position and red radiosity of every vertex of a binary PLY export.
fn read_ply(path: &Path) -> Vec<(Vec3, f32)> {
    let bytes = std::fs::read(path).expect("the PLY export exists");
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .expect("a PLY header")
        + 11;
    let header = String::from_utf8_lossy(&bytes[..end]);
    let count: usize = header
        .lines()
        .find_map(|l| l.strip_prefix("element vertex "))
        .expect("a vertex count")
        .parse()
        .unwrap();
    let f = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    (0..count)
        .map(|k| {
            let at = end + 27 * k;
            (Vec3::new(f(at), f(at + 4), f(at + 8)), f(at + 12))
        })
        .collect()
}

/// Solves `obj` and exports it; for every position held by two or more
/// exported vertices of the model (not the lamp, at `y = 3`), the largest
/// relative spread of their radiosities.
fn spreads(dir: &Path, obj: &str) -> Vec<f32> {
    common::write(dir, "model.mtl", MTL);
    common::write(dir, "model.obj", obj);
    let out = common::run_in(
        dir,
        &[
            "model.obj",
            "--lenmax",
            "0.6",
            "--size",
            "64x48",
            "-o",
            "model.png",
            "--export",
            "model.ply",
        ],
    );
    assert!(out.status.success(), "{}", common::stderr(&out));
    let mut at: HashMap<[u32; 3], Vec<f32>> = HashMap::new();
    for (p, r) in read_ply(&dir.join("model.ply")) {
        if p.y < 2.5 {
            at.entry(p.to_array().map(f32::to_bits))
                .or_default()
                .push(r);
        }
    }
    at.values()
        .filter(|r| r.len() >= 2)
        .map(|r| {
            let (lo, hi) = r
                .iter()
                .fold((f32::INFINITY, 0f32), |(l, h), &x| (l.min(x), h.max(x)));
            (hi - lo) / hi.max(1e-9)
        })
        .collect()
}

#[test]
fn a_smooth_icosphere_has_no_radiosity_jump_across_its_facet_edges() {
    let (v, faces) = icosphere();
    let faces: Vec<Vec<usize>> = faces.iter().map(|f| f.to_vec()).collect();
    let dir = tempfile::tempdir().unwrap();
    let smooth = spreads(dir.path(), &blender_obj("Icosphere", &v, &faces, true));
    // Every facet corner and every stitched edge vertex is shared.
    assert!(smooth.len() > 100, "{} shared positions", smooth.len());
    assert!(
        smooth.iter().all(|&s| s == 0.0),
        "largest jump {}",
        smooth.iter().fold(0f32, |a, &b| a.max(b))
    );
    let flat = spreads(dir.path(), &blender_obj("Icosphere", &v, &faces, false));
    let largest = flat.iter().fold(0f32, |a, &b| a.max(b));
    assert!(flat.len() > 100);
    assert!(largest > 0.05, "flat facets differ by only {largest}");
}

#[test]
fn a_smooth_cube_keeps_its_edges_sharp() {
    let v: Vec<Vec3> = (0..8)
        .map(|k| {
            let c = |b: usize| if k & b != 0 { 0.8 } else { -0.8 };
            Vec3::new(c(1), c(2), c(4))
        })
        .collect();
    // Counter-clockwise seen from outside.
    let faces: Vec<Vec<usize>> = vec![
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
    ];
    let dir = tempfile::tempdir().unwrap();
    let s = spreads(dir.path(), &blender_obj("Cube", &v, &faces, true));
    // The lit top and the sides meet at 90°: never welded.
    let largest = s.iter().fold(0f32, |a, &b| a.max(b));
    assert!(largest > 0.2, "the cube's edges were smoothed: {largest}");
}

/// Background pixels inside the projected convex outline `hull` (pixel
/// coordinates), at least 1.5 pixels from its edges, when `mesh` is drawn
/// in white through `view`.
fn holes(mesh: &mesh::Mesh, view: &View, hull: &[Vec3]) -> usize {
    let corners: Vec<glam::Vec2> = hull.iter().map(|&p| view.project(p).unwrap()).collect();
    let radiosity = vec![Rgb::WHITE; mesh.vertex_count()];
    let mut raster = Rasterizer::new();
    let frame = raster.render(mesh, &radiosity, view).unwrap();
    let n = corners.len();
    let area: f32 = (0..n)
        .map(|k| corners[k].perp_dot(corners[(k + 1) % n]))
        .sum();
    let mut count = 0;
    for y in 0..view.height() {
        for x in 0..view.width() {
            let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let inside = (0..n).all(|k| {
                let (a, b) = (corners[k], corners[(k + 1) % n]);
                let d = (b - a).perp_dot(p - a) * area.signum() / (b - a).length();
                d > 1.5
            });
            if inside && !frame.is_covered(x, y) {
                count += 1;
            }
        }
    }
    count
}

/// Pinholes before and after stitching of an OBJ drawn by an oblique
/// camera: `(unstitched, stitched)`.
fn pinholes(obj: &str, hull: &[Vec3], lenmax: f32) -> (usize, usize) {
    let dir = tempfile::tempdir().unwrap();
    let path = common::write(dir.path(), "m.obj", obj);
    let scene = scene::load(&path).unwrap();
    let centre = hull.iter().copied().sum::<Vec3>() / hull.len() as f32;
    let camera = Camera {
        eye: centre + Vec3::new(0.31, -0.47, 2.3),
        lookat: centre,
        up: Vec3::new(0.1, 1.0, 0.0),
        fov_y: 1.0,
        width: 800,
        height: 600,
    };
    let view = View::new(&camera).unwrap();
    let options = MeshOptions {
        lenmax,
        inset: mesh::DEFAULT_INSET,
    };
    let before = mesh::build_unstitched_with_limit(&scene, &options, MAX_ELEMENTS).unwrap();
    let after = mesh::build(&scene, &options).unwrap();
    (holes(&before, &view, hull), holes(&after, &view, hull))
}

/// The element sizes the pinhole tests try.
const LENMAXES: [f32; 7] = [0.05, 0.07, 0.09, 0.11, 0.13, 0.2, 0.3];

/// Rotated off the axes so that no edge falls on a pixel row or column.
fn turn(p: [f32; 3]) -> Vec3 {
    let (s, c) = 0.37f32.sin_cos();
    Vec3::new(
        c * p[0] - s * p[1],
        s * p[0] + c * p[1],
        0.1 * p[0] + 0.05 * p[1],
    )
}

fn obj_of(polygons: &[&[[f32; 3]]]) -> String {
    let mut s = String::from("# Blender 3.4.1\n# www.blender.org\no Plane\n");
    let mut index = HashMap::new();
    let mut faces = String::new();
    for poly in polygons {
        faces += "f";
        for p in *poly {
            let key = p.map(f32::to_bits);
            let next = index.len() + 1;
            let i = *index.entry(key).or_insert_with(|| {
                let q = turn(*p);
                s += &format!("v {:.6} {:.6} {:.6}\n", q.x, q.y, q.z);
                next
            });
            faces += &format!(" {i}");
        }
        faces += "\n";
    }
    s + "s 0\n" + &faces
}

#[test]
fn triangles_sharing_an_edge_cut_differently_leave_no_pinhole() {
    let obj = obj_of(&[
        &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]],
        &[[0., 0., 0.], [1., 1., 0.], [-3., 1., 0.]],
    ]);
    let hull = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [-3., 1., 0.]].map(turn);
    // Pinholes are single pixels where rounding falls one way: summed
    // over several subdivisions.
    let (mut before, mut after) = (0, 0);
    for lenmax in LENMAXES {
        let (b, a) = pinholes(&obj, &hull, lenmax);
        before += b;
        after += a;
    }
    eprintln!("shared edge: {before} background pixels unstitched, {after} stitched");
    assert!(before > 0);
    assert_eq!(after, 0);
}

#[test]
fn a_t_junction_leaves_no_pinhole() {
    let obj = obj_of(&[
        &[[0., 0., 0.], [1., 0., 0.], [1., 2., 0.], [0., 2., 0.]],
        &[[1., 0., 0.], [2., 0., 0.], [2., 1., 0.], [1., 1., 0.]],
        &[[1., 1., 0.], [2., 1., 0.], [2., 2., 0.], [1., 2., 0.]],
    ]);
    let hull = [[0., 0., 0.], [2., 0., 0.], [2., 2., 0.], [0., 2., 0.]].map(turn);
    // Pinholes are single pixels where rounding falls one way: summed
    // over several subdivisions.
    let (mut before, mut after) = (0, 0);
    for lenmax in LENMAXES {
        let (b, a) = pinholes(&obj, &hull, lenmax);
        before += b;
        after += a;
    }
    eprintln!("T-junction: {before} background pixels unstitched, {after} stitched");
    assert!(before > 0);
    assert_eq!(after, 0);
}
