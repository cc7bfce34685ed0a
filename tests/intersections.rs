//! Walls sunk into floors: a room lit from its ceiling, written as Blender
//! writes OBJ files, whose left wall stops at the floor, continues 0.5
//! below it, or is a box passing through it. After splitting along the
//! intersections the wall's visible foot is as bright in all three; without
//! it the buried vertices darken the foot.

mod common;

use common::{run_in, stderr, write};
use radiosity::mesh::{self, Mesh, MeshOptions};
use radiosity::scene::{self, Scene};
use radiosity::session::{Session, SessionOptions};
use radiosity::solver::SolverOptions;
use radiosity::visibility::Visibility;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::AtomicBool;

const MTL: &str = "# Blender MTL File: 'room.blend'\r
# Material Count: 2\r
\r
newmtl Lamp\r
Ns 250.000000\r
Ka 1.000000 1.000000 1.000000\r
Kd 0.500000 0.500000 0.500000\r
Ks 0.500000 0.500000 0.500000\r
Ke 1.000000 1.000000 1.000000\r
Ni 1.450000\r
d 1.000000\r
illum 2\r
\r
newmtl White\r
Ns 250.000000\r
Ka 1.000000 1.000000 1.000000\r
Kd 0.600000 0.600000 0.600000\r
Ks 0.500000 0.500000 0.500000\r
Ke 0.000000 0.000000 0.000000\r
Ni 1.450000\r
d 1.000000\r
illum 2\r
";

/// An OBJ object: its name, material and faces (each counter-clockwise
/// seen from its front).
struct Object {
    name: &'static str,
    material: &'static str,
    faces: Vec<Vec<[f32; 3]>>,
}

/// The objects as Blender 2.93 writes them: header, `mtllib`, `o`, `v`,
/// `vn`, `usemtl`, `s off`, `f v//vn`, CRLF line ends.
fn obj_text(objects: &[Object]) -> String {
    let mut out = String::from(
        "# Blender v2.93.1 OBJ File: 'room.blend'\r\n# www.blender.org\r\nmtllib room.mtl\r\n",
    );
    let (mut nv, mut nn) = (0, 0);
    for o in objects {
        write!(out, "o {}\r\n", o.name).unwrap();
        for f in &o.faces {
            for v in f {
                write!(out, "v {:.6} {:.6} {:.6}\r\n", v[0], v[1], v[2]).unwrap();
            }
        }
        for f in &o.faces {
            let a = glam::Vec3::from(f[0]);
            let n = (glam::Vec3::from(f[1]) - a)
                .cross(glam::Vec3::from(f[2]) - a)
                .normalize();
            write!(out, "vn {:.4} {:.4} {:.4}\r\n", n.x, n.y, n.z).unwrap();
        }
        write!(out, "usemtl {}\r\ns off\r\n", o.material).unwrap();
        for (k, f) in o.faces.iter().enumerate() {
            out.push('f');
            for _ in f {
                nv += 1;
                write!(out, " {}//{}", nv, nn + k + 1).unwrap();
            }
            out.push_str("\r\n");
        }
        nn += o.faces.len();
    }
    out
}

/// The quad `{x} × [y0, y1] × [z0, z1]` facing `+x` (or `-x`).
fn x_quad(x: f32, y0: f32, y1: f32, z0: f32, z1: f32, plus: bool) -> Vec<[f32; 3]> {
    let mut f = vec![[x, y0, z0], [x, y1, z0], [x, y1, z1], [x, y0, z1]];
    if !plus {
        f.reverse();
    }
    f
}

/// The six outward faces of the box `[lo, hi]`.
fn cuboid(lo: [f32; 3], hi: [f32; 3]) -> Vec<Vec<[f32; 3]>> {
    let [a, b, c] = lo;
    let [d, e, f] = hi;
    vec![
        vec![[a, b, c], [a, b, f], [a, e, f], [a, e, c]],
        vec![[d, b, c], [d, e, c], [d, e, f], [d, b, f]],
        vec![[a, b, c], [d, b, c], [d, b, f], [a, b, f]],
        vec![[a, e, c], [a, e, f], [d, e, f], [d, e, c]],
        vec![[a, b, c], [a, e, c], [d, e, c], [d, b, c]],
        vec![[a, b, f], [d, b, f], [d, e, f], [a, e, f]],
    ]
}

/// How the room's left wall (the plane `x = 0`, facing into the room) is
/// built.
#[derive(Clone, Copy, Debug)]
enum LeftWall {
    /// One quad from the floor to the ceiling.
    StopsAtFloor,
    /// One quad continuing `SUNK` below the floor.
    ContinuesBelow,
    /// A box 0.2 thick whose foot passes `SUNK` below the floor.
    Box,
}

/// How far the sunk walls reach below the floor.
const SUNK: f32 = 0.5;

/// The room `[0, 2]³`, lit by its whole ceiling, every face facing in;
/// the floor ends at the left wall.
fn room(left: LeftWall) -> String {
    let s = 2.0;
    let mut objects = vec![
        Object {
            name: "Floor",
            material: "White",
            faces: vec![vec![[0., 0., 0.], [0., 0., s], [s, 0., s], [s, 0., 0.]]],
        },
        Object {
            name: "Ceiling",
            material: "Lamp",
            faces: vec![vec![[0., s, 0.], [s, s, 0.], [s, s, s], [0., s, s]]],
        },
        Object {
            name: "RightWall",
            material: "White",
            faces: vec![x_quad(s, 0., s, 0., s, false)],
        },
        Object {
            name: "BackWall",
            material: "White",
            faces: vec![vec![[0., 0., s], [0., s, s], [s, s, s], [s, 0., s]]],
        },
        Object {
            name: "FrontWall",
            material: "White",
            faces: vec![vec![[0., 0., 0.], [s, 0., 0.], [s, s, 0.], [0., s, 0.]]],
        },
    ];
    let faces = match left {
        LeftWall::StopsAtFloor => vec![x_quad(0., 0., s, 0., s, true)],
        LeftWall::ContinuesBelow => vec![x_quad(0., -SUNK, s, 0., s, true)],
        LeftWall::Box => cuboid([-0.2, -SUNK, 0.], [0., s, s]),
    };
    objects.push(Object {
        name: "LeftWall",
        material: "White",
        faces,
    });
    obj_text(&objects)
}

/// Loads the room from its OBJ file, splits it when asked, and solves it.
fn solve(dir: &Path, left: LeftWall, split: bool) -> (Scene, Mesh, Vec<f64>) {
    write(dir, "room.mtl", MTL);
    let path = write(dir, &format!("{left:?}.obj"), &room(left));
    let mut scene = scene::load(&path).unwrap();
    if split {
        scene.split_intersections();
    }
    let mesh = mesh::build(
        &scene,
        &MeshOptions {
            lenmax: 0.25,
            inset: mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let visibility = Visibility::new(&scene);
    let options = SessionOptions {
        solver: SolverOptions {
            threshold: 1e-4,
            ..Default::default()
        },
        refine: None,
        max_elements: mesh::MAX_ELEMENTS,
        ambient: false,
    };
    let mut session = Session::new(&scene, &mesh, &visibility, options);
    assert!(session.run_to_end(&AtomicBool::new(false)).unwrap());
    let radiosity = session.radiosity().iter().map(|b| b.r).collect();
    // The session's solver borrows both until it is gone.
    drop(session);
    (scene, mesh, radiosity)
}

/// Height of the foot band, as a fraction of the wall's visible height 2.
const BAND: f32 = 0.1;

/// The mean of the drawn (Gouraud-interpolated) radiosity over the left
/// wall's visible foot band `y ∈ [0, 2 BAND]`, `x = 0`, sampled on a
/// regular grid of points in `(z, y)`.
fn foot_band_mean(scene: &Scene, mesh: &Mesh, radiosity: &[f64]) -> f64 {
    let on_left_wall = |p: usize| {
        let poly = &scene.polygons[p];
        poly.normal.x > 0.99 && poly.vertices.iter().all(|v| v.x.abs() < 1e-6)
    };
    let triangles: Vec<[usize; 3]> = mesh
        .elements
        .iter()
        .zip(&mesh.element_polygon)
        .filter(|(_, p)| on_left_wall(p.index()))
        .flat_map(|(e, _)| {
            e.triangles()
                .map(|t| t.map(|v| v.index()))
                .collect::<Vec<_>>()
        })
        .collect();
    let (nz, ny) = (200, 20);
    let mut sum = 0.0;
    for i in 0..nz {
        for k in 0..ny {
            let z = 2.0 * (i as f32 + 0.5) / nz as f32;
            let y = 2.0 * BAND * (k as f32 + 0.5) / ny as f32;
            let value = triangles.iter().find_map(|t| {
                let [a, b, c] =
                    t.map(|v| glam::Vec2::new(mesh.positions[v].z, mesh.positions[v].y));
                let p = glam::Vec2::new(z, y);
                let d = (b - a).perp_dot(c - a);
                let wb = (p - a).perp_dot(c - a) / d;
                let wc = (b - a).perp_dot(p - a) / d;
                let wa = 1.0 - wb - wc;
                let tol = -1e-5;
                (wa >= tol && wb >= tol && wc >= tol).then(|| {
                    f64::from(wa) * radiosity[t[0]]
                        + f64::from(wb) * radiosity[t[1]]
                        + f64::from(wc) * radiosity[t[2]]
                })
            });
            sum += value.expect("every band point lies on the wall's mesh");
        }
    }
    sum / (nz * ny) as f64
}

/// The criterion: the foot of a wall that passes through the floor (one
/// quad continuing below it, or a box) is within 3 % as bright as that of
/// a wall stopping at the floor once polygons are split along their
/// intersections; without the split it is visibly darker.
#[test]
fn a_sunk_wall_foot_is_as_bright_as_a_standing_one() {
    let dir = tempfile::tempdir().unwrap();
    let (s, m, b) = solve(dir.path(), LeftWall::StopsAtFloor, true);
    assert_eq!(s.polygons.len(), 6, "nothing to split in the plain room");
    let reference = foot_band_mean(&s, &m, &b);
    assert!(reference > 0.0);
    for left in [LeftWall::ContinuesBelow, LeftWall::Box] {
        let (s, m, b) = solve(dir.path(), left, true);
        let split = foot_band_mean(&s, &m, &b);
        let (s, m, b) = solve(dir.path(), left, false);
        let unsplit = foot_band_mean(&s, &m, &b);
        let (e_split, e_unsplit) = (
            (split - reference).abs() / reference,
            (unsplit - reference).abs() / reference,
        );
        eprintln!(
            "{left:?}: foot band mean {split:.5} split, {unsplit:.5} unsplit, \
             {reference:.5} standing: off by {:.2} % split, {:.2} % unsplit",
            100.0 * e_split,
            100.0 * e_unsplit
        );
        assert!(e_split < 0.03, "{left:?}: {e_split}");
        assert!(e_unsplit > 0.1, "{left:?}: {e_unsplit}");
    }
}

/// Through the command line, the pieces are counted in `--stats` (and
/// nothing is said on stderr: this is no quirk of the file).
#[test]
fn the_stats_count_the_pieces() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", MTL);
    write(dir.path(), "room.obj", &room(LeftWall::Box));
    let out = run_in(
        dir.path(),
        &[
            "room.obj",
            "-o",
            "room.png",
            "--stats",
            "stats.json",
            "--size",
            "64x48",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("split"), "{}", stderr(&out));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("stats.json")).unwrap())
            .unwrap();
    // The box's inner face is cut at the floor; nothing else is.
    assert_eq!(stats["split"]["polygons_cut"], 1);
    assert_eq!(stats["split"]["pieces"], 2);
    // Every piece of an OBJ face has its back.
    assert_eq!(stats["polygons"], 2 * (5 + 6 + 1));
}
