//! Two-sided OBJ faces, repeated faces and coplanar overlaps, end to end
//! through the binary, on models written as Blender writes them.

mod common;

use common::{read_json, run_in, stderr, write};
use std::path::Path;

/// Reads a PFM (`PF`, little-endian, rows bottom to top) into
/// `(width, height, rgb rows top to bottom)`.
fn read_pfm(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    let bytes = std::fs::read(path).expect("the PFM exists");
    let mut fields = Vec::new();
    let mut start = 0;
    let mut i = 0;
    while fields.len() < 4 {
        if bytes[i].is_ascii_whitespace() {
            if i > start {
                fields.push(String::from_utf8_lossy(&bytes[start..i]).into_owned());
            }
            start = i + 1;
        }
        i += 1;
    }
    assert_eq!(fields[0], "PF");
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    assert!(fields[3].parse::<f32>().unwrap() < 0.0, "little-endian");
    let data = &bytes[start..];
    let mut pixels = vec![[0.0f32; 3]; w * h];
    for row in 0..h {
        for x in 0..w {
            let k = ((h - 1 - row) * w + x) * 12;
            let f = |o: usize| f32::from_le_bytes(data[k + o..k + o + 4].try_into().unwrap());
            pixels[row * w + x] = [f(0), f(4), f(8)];
        }
    }
    (w, h, pixels)
}

fn mean_luminance(pixels: &[[f32; 3]]) -> f64 {
    pixels
        .iter()
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .sum::<f64>()
        / pixels.len() as f64
}

const MTL: &str = "# Blender MTL File: 'room.blend'\r\n\
# Material Count: 2\r\n\
\r\n\
newmtl Lamp\r\n\
Ns 250.000000\r\n\
Ka 1.000000 1.000000 1.000000\r\n\
Kd 0.800000 0.800000 0.800000\r\n\
Ks 0.500000 0.500000 0.500000\r\n\
Ke 10.000000 10.000000 10.000000\r\n\
Ni 1.450000\r\n\
d 1.000000\r\n\
illum 2\r\n\
\r\n\
newmtl Wall\r\n\
Ns 250.000000\r\n\
Kd 0.600000 0.600000 0.600000\r\n\
Ks 0.500000 0.500000 0.500000\r\n\
d 1.000000\r\n\
illum 2\r\n";

/// A room modelled as Blender users do: a cube scaled up, so its normals
/// face *out*, with a ceiling lamp whose normal points up, into the
/// ceiling. One-sided, nothing inside is lit.
const OUTWARD_ROOM: &str = "# Blender v2.93.1 OBJ File: 'room.blend'\r\n\
# www.blender.org\r\n\
mtllib room.mtl\r\n\
o Room\r\n\
v 0 0 0\r\nv 4 0 0\r\nv 4 3 0\r\nv 0 3 0\r\n\
v 0 0 4\r\nv 4 0 4\r\nv 4 3 4\r\nv 0 3 4\r\n\
vn 0 -1 0\r\nvn 0 1 0\r\nvn 0 0 -1\r\nvn 0 0 1\r\nvn -1 0 0\r\nvn 1 0 0\r\n\
usemtl Wall\r\n\
s off\r\n\
f 1//1 2//1 6//1 5//1\r\n\
f 4//2 8//2 7//2 3//2\r\n\
f 1//3 4//3 3//3 2//3\r\n\
f 5//4 6//4 7//4 8//4\r\n\
f 1//5 5//5 8//5 4//5\r\n\
f 2//6 3//6 7//6 6//6\r\n\
o Lamp\r\n\
v 1.5 2.9 1.5\r\nv 2.5 2.9 1.5\r\nv 2.5 2.9 2.5\r\nv 1.5 2.9 2.5\r\n\
usemtl Lamp\r\n\
f 9//2 12//2 11//2 10//2\r\n";

const INSIDE_CAMERA: &str =
    "camera\n  eye 2 1.5 0.4\n  lookat 2 1.1 4\n  up 0 1 0\n  fov 80\n  size 96 72\nend\n";

#[test]
fn a_room_with_outward_normals_and_an_upturned_lamp_is_lit_two_sided() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", MTL);
    write(dir.path(), "room.obj", OUTWARD_ROOM);
    write(dir.path(), "inside.sc", INSIDE_CAMERA);
    let common = ["room.obj", "--camera", "inside.sc", "--lenmax", "0.4", "-q"];

    let two = run_in(
        dir.path(),
        &[&common[..], &["-o", "two.pfm", "--stats", "two.json"]].concat(),
    );
    assert!(two.status.success(), "{}", stderr(&two));
    let stats = read_json(dir.path(), "two.json");
    assert_eq!(
        stats["polygons"], 14,
        "7 faces, each with its back: {stats}"
    );
    let (_, _, pixels) = read_pfm(&dir.path().join("two.pfm"));
    let lit = pixels.iter().filter(|p| p[1] > 0.01).count() as f64 / pixels.len() as f64;
    assert!(
        lit > 0.98,
        "two-sided: {:.1} % of the picture lit",
        lit * 100.0
    );

    let one = run_in(
        dir.path(),
        &[
            &common[..],
            &["--one-sided", "-o", "one.pfm", "--stats", "one.json"],
        ]
        .concat(),
    );
    assert!(one.status.success(), "{}", stderr(&one));
    assert_eq!(read_json(dir.path(), "one.json")["polygons"], 7);
    let (_, _, dark) = read_pfm(&dir.path().join("one.pfm"));
    assert_eq!(
        mean_luminance(&dark),
        0.0,
        "one-sided, the eye sees only backs and the lamp shines into the ceiling"
    );
}

/// `--two-sided` makes a `.sc` scene's polygons two-sided too; without
/// it the format's front-only rule stands.
#[test]
fn sc_scenes_stay_one_sided_unless_asked() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = common::scene("cornell.sc");
    let cornell = cornell.to_str().unwrap();
    let base = [cornell, "--lenmax", "200", "--max-steps", "1", "-q"];
    let one = run_in(
        dir.path(),
        &[&base[..], &["--stats", "a.json", "-o", "a.png"]].concat(),
    );
    assert!(one.status.success(), "{}", stderr(&one));
    let two = run_in(
        dir.path(),
        &[
            &base[..],
            &["--two-sided", "--stats", "b.json", "-o", "b.png"],
        ]
        .concat(),
    );
    assert!(two.status.success(), "{}", stderr(&two));
    let (a, b) = (
        read_json(dir.path(), "a.json"),
        read_json(dir.path(), "b.json"),
    );
    assert_eq!(
        b["polygons"].as_u64().unwrap(),
        2 * a["polygons"].as_u64().unwrap()
    );
    let both = run_in(
        dir.path(),
        &[cornell, "--one-sided", "--two-sided", "-o", "c.png"],
    );
    assert_eq!(both.status.code(), Some(2), "the two options conflict");
}

/// McGuire's `CornellBox-Original.obj` lists some faces twice: the repeat
/// is dropped with one warning, and the model solves as if written once.
#[test]
fn repeated_faces_are_dropped_with_one_warning() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.mtl", MTL);
    let mut obj = OUTWARD_ROOM.to_owned();
    // The floor, twice more, the second time from another vertex.
    obj.push_str(
        "o Floor.001\r\nusemtl Wall\r\nf 1//1 2//1 6//1 5//1\r\nf 6//1 5//1 1//1 2//1\r\n",
    );
    write(dir.path(), "room.obj", &obj);
    let out = run_in(
        dir.path(),
        &[
            "room.obj",
            "--lenmax",
            "1",
            "--max-steps",
            "2",
            "-o",
            "x.png",
            "--stats",
            "s.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let lines: Vec<&str> = err.lines().filter(|l| l.contains("repeat")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].starts_with("room.obj:36:1: warning: 2 faces repeat an earlier face exactly"),
        "{err}"
    );
    assert_eq!(read_json(dir.path(), "s.json")["polygons"], 14);
}

/// A rug lying on the floor, in the floor's plane: it is drawn over the
/// floor everywhere (written after it), and neither shadows the other, so
/// the rug's radiosity over its reflectance matches the floor's beside it.
#[test]
fn a_rug_in_the_floor_plane_is_drawn_on_top_and_not_shadowed() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "rug.mtl",
        "newmtl Floor\nKd 0.5 0.5 0.5\nnewmtl Rug\nKd 0.8 0.1 0.1\nnewmtl Lamp\nKd 0 0 0\nKe 5 5 5\n",
    );
    write(
        dir.path(),
        "rug.obj",
        "# Blender 3.6.0\nmtllib rug.mtl\n\
         v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\n\
         v 1 0 1\nv 3 0 1\nv 3 0 3\nv 1 0 3\n\
         v 1.5 3 1.5\nv 2.5 3 1.5\nv 2.5 3 2.5\nv 1.5 3 2.5\n\
         o Floor\nusemtl Floor\nf 1 4 3 2\n\
         o Rug\nusemtl Rug\nf 5 8 7 6\n\
         o Lamp\nusemtl Lamp\nf 9 10 11 12\n",
    );
    write(
        dir.path(),
        "top.sc",
        "camera\n  eye 2 2.5 2\n  lookat 2 0 2\n  up 0 0 1\n  fov 90\n  size 100 100\nend\n",
    );
    let out = run_in(
        dir.path(),
        &[
            "rug.obj", "--camera", "top.sc", "--lenmax", "0.25", "-o", "top.pfm", "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let (w, h, pixels) = read_pfm(&dir.path().join("top.pfm"));
    // From 2.5 above with a 90° view the picture spans 5 units: the rug
    // (x, z in 1..3) is the middle 40 % of it.
    let at = |x: usize, y: usize| pixels[y * w + x];
    let mut floor_covered = 0;
    for y in (h * 32 / 100)..(h * 68 / 100) {
        for x in (w * 32 / 100)..(w * 68 / 100) {
            let p = at(x, y);
            if p[0] < 3.0 * p[1] {
                floor_covered += 1;
            }
        }
    }
    assert_eq!(floor_covered, 0, "the floor shows through the rug");
    // A point of the rug and one of the floor at the same distance from
    // the lamp's axis (1.24 and 1.23 units: on the rug's diagonal, and
    // beside its edge), 20 pixels a unit: same irradiance within 0.6 %.
    let rug = at(32, 32)[0] as f64 / 0.8;
    let floor = 0.5 * (at(25, 49)[0] + at(25, 50)[0]) as f64 / 0.5;
    assert!(rug > 0.0 && floor > 0.0);
    assert!(
        (rug / floor - 1.0).abs() < 0.03,
        "irradiance on the rug {rug} against the floor beside it {floor}"
    );
}

/// A cave as a game level exports it: six faces looking in at a lamp,
/// every one two-sided as OBJ faces are read. Their backs look out into
/// the dark, so they get no back copies (`--info` says how many), and
/// under a sky, which lights the outside, they do.
const CAVE: &str = "o Cave
v 0 0 0
v 0 0 4
v 4 0 4
v 4 0 0
v 0 4 0
v 4 4 0
v 4 4 4
v 0 4 4
f 1 2 3 4
f 5 6 7 8
f 1 5 8 2
f 4 3 7 6
f 1 4 6 5
f 2 8 7 3
o Lamp
v 1.5 3.5 1.5
v 2.5 3.5 1.5
v 2.5 3.5 2.5
v 1.5 3.5 2.5
f 9 10 11 12
";

#[test]
fn a_lit_cave_gets_no_backs_facing_the_dark_unless_a_sky_lights_them() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "cave.obj", CAVE);
    let info = run_in(dir.path(), &["--info", "cave.obj", "--emit", "Lamp=10"]);
    assert!(info.status.success(), "{}", stderr(&info));
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        text.contains(
            "scene: cave.obj, 7 polygons (1 of them with a back side; \
             6 two-sided faces without one, as no light reaches their back)"
        ),
        "{text}"
    );
    for (sky, polygons) in [(false, 8), (true, 14)] {
        let mut args = vec!["cave.obj", "--emit", "Lamp=10", "--lenmax", "1", "-q"];
        args.extend(["-o", "cave.pfm", "--stats", "cave.json"]);
        if sky {
            args.extend(["--sky", "1"]);
        }
        let out = run_in(dir.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
        let stats = read_json(dir.path(), "cave.json");
        assert_eq!(
            stats["polygons"], polygons,
            "sky {sky}: the 7 faces, the lamp's back and the walls' only under a sky: {stats}"
        );
    }
}
