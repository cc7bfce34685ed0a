//! Cameras from the command line (`--eye`, `--look-at`, `--up`, `--fov`),
//! `--info`, and the automatic camera of a room modelled with its faces
//! pointing out (as a scaled cube in Blender is): it stands inside, and a
//! picture from outside says why it is dark.

mod common;

use common::{run_in, stderr, write};
use std::path::Path;

/// A Blender-style room: a 4 × 3 × 5 box whose faces point out, a `Lamp`
/// square 0.1 below the ceiling and a box on the floor, nothing emitting.
const ROOM_OBJ: &str = "\
mtllib room.mtl
o Room
v -2 0 -2.5
v 2 0 -2.5
v 2 0 2.5
v -2 0 2.5
v -2 3 -2.5
v 2 3 -2.5
v 2 3 2.5
v -2 3 2.5
usemtl Wall
f 1 2 3 4
f 5 8 7 6
f 1 5 6 2
f 4 3 7 8
f 1 4 8 5
f 2 6 7 3
o Lamp
v -0.5 2.9 -0.5
v 0.5 2.9 -0.5
v 0.5 2.9 0.5
v -0.5 2.9 0.5
usemtl LampShade
f 9 10 11 12
o Box
v 0.5 0 0.5
v 1.3 0 0.5
v 1.3 0 1.3
v 0.5 0 1.3
v 0.5 0.8 0.5
v 1.3 0.8 0.5
v 1.3 0.8 1.3
v 0.5 0.8 1.3
usemtl Box
f 13 14 15 16
f 17 20 19 18
f 13 17 18 14
f 16 15 19 20
f 13 16 20 17
f 14 18 19 15
";

const ROOM_MTL: &str = "\
newmtl Wall
Kd 0.8 0.5 0.4
newmtl LampShade
Kd 0.8 0.8 0.8
newmtl Box
Kd 0.5 0.5 0.7
";

fn write_room(dir: &Path) {
    write(dir, "room.obj", ROOM_OBJ);
    write(dir, "room.mtl", ROOM_MTL);
}

/// The mean of the 8-bit channels of a picture, 0 to 255.
fn mean_8bit(path: &Path) -> f64 {
    let img = image::open(path).unwrap().to_rgb8();
    let sum: u64 = img.as_raw().iter().map(|&c| u64::from(c)).sum();
    sum as f64 / img.as_raw().len() as f64
}

/// The `camera (...)` line of `--info`, parsed into its options.
fn info_camera(dir: &Path, args: &[&str]) -> Vec<(String, String)> {
    let mut all = vec!["--info"];
    all.extend_from_slice(args);
    let out = run_in(dir, &all);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text
        .lines()
        .find(|l| l.starts_with("camera ("))
        .unwrap_or_else(|| panic!("no camera line in {text}"));
    let options = line.split_once("): ").unwrap().1;
    let words: Vec<&str> = options.split_whitespace().collect();
    words
        .chunks(2)
        .map(|p| (p[0].to_string(), p[1].to_string()))
        .collect()
}

fn option<'a>(options: &'a [(String, String)], name: &str) -> &'a str {
    &options.iter().find(|(n, _)| n == name).unwrap().1
}

fn point(text: &str) -> [f32; 3] {
    let v: Vec<f32> = text.split(',').map(|c| c.parse().unwrap()).collect();
    [v[0], v[1], v[2]]
}

#[test]
fn camera_options_render_the_same_pixels_as_a_camera_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::scene("rtable.sc");
    let scene = scene.to_str().unwrap();
    write(
        dir.path(),
        "view.sc",
        "camera\n  eye 0.4 2.2 4.6\n  lookat 3.1 0.8 1.2\n  up 0.1 1 0\n  fov 62.5\nend\n",
    );
    let common_args = [
        scene,
        "--size",
        "48x36",
        "--max-steps",
        "3",
        "--aa",
        "2",
        "-q",
    ];
    let run = |extra: &[&str], out: &str| {
        let mut args = common_args.to_vec();
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", out]);
        let o = run_in(dir.path(), &args);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(dir.path().join(out)).unwrap()
    };
    let by_options = run(
        &[
            "--eye",
            "0.4,2.2,4.6",
            "--look-at",
            "3.1,0.8,1.2",
            "--up",
            "0.1,1,0",
            "--fov",
            "62.5",
        ],
        "options.pfm",
    );
    let by_file = run(&["--camera", "view.sc"], "file.pfm");
    let scene_own = run(&[], "own.pfm");
    assert_eq!(by_options, by_file, "the linear pictures differ");
    assert_ne!(by_options, scene_own, "the options changed nothing");
}

#[test]
fn each_camera_option_replaces_its_part_only() {
    let dir = tempfile::tempdir().unwrap();
    write_room(dir.path());
    let auto = info_camera(dir.path(), &["room.obj", "--emit", "Lamp=10"]);
    let moved = info_camera(
        dir.path(),
        &["room.obj", "--emit", "Lamp=10", "--eye", "-1.5,1,-2"],
    );
    assert_eq!(option(&moved, "--eye"), "-1.5,1,-2");
    for kept in ["--look-at", "--up", "--fov", "--size"] {
        assert_eq!(option(&moved, kept), option(&auto, kept), "{kept}");
    }
    let wide = info_camera(dir.path(), &["room.obj", "--fov", "80", "--up", "0,1,0.5"]);
    assert_eq!(option(&wide, "--fov"), "80");
    assert_eq!(option(&wide, "--up"), "0,1,0.5");
    // A .sc scene's own camera is changed in the same way.
    let scene = common::scene("rtable.sc");
    let rtable = info_camera(dir.path(), &[scene.to_str().unwrap(), "--look-at", "1,1,1"]);
    assert_eq!(option(&rtable, "--eye"), "2.5,1.7,0.35");
    assert_eq!(option(&rtable, "--look-at"), "1,1,1");
}

#[test]
fn unusable_camera_options_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    write_room(dir.path());
    let scene = common::scene("rtable.sc");
    let scene = scene.to_str().unwrap();
    for (args, said) in [
        (
            &[scene, "--eye", "1,2,3", "--look-at", "1,2,3"][..],
            "error: --eye 1,2,3 and --look-at 1,2,3 are the same point",
        ),
        (
            &[
                scene,
                "--eye",
                "0,0,0",
                "--look-at",
                "0,0,1",
                "--up",
                "0,0,-3",
            ],
            "error: --up 0,0,-3 is parallel to the view direction",
        ),
        // rtable's camera looks at 2.5,0.75,3: an eye there has no view.
        (
            &[scene, "--eye", "2.5,0.75,3"],
            "error: --eye 2.5,0.75,3 is the scene camera's look-at point",
        ),
        // Straight down, with the scene camera's up +y.
        (
            &[scene, "--eye", "2.5,3,3", "--look-at", "2.5,0,3"],
            "is parallel to the camera's up direction 0,1,0: give --up across the view",
        ),
        (
            &[scene, "--fov", "0"],
            "--fov must be a vertical field of view",
        ),
        (
            &[scene, "--fov", "180"],
            "--fov must be a vertical field of view",
        ),
        (&[scene, "--eye", "1,2"], "--eye must be a point X,Y,Z"),
        (
            &[scene, "--look-at", "inf,0,0"],
            "--look-at must be a point X,Y,Z",
        ),
        (&[scene, "--up", "0,0,0"], "--up must be a direction X,Y,Z"),
    ] {
        let mut all = args.to_vec();
        all.extend_from_slice(&["-o", "x.png", "--size", "8x6", "--max-steps", "1"]);
        let out = run_in(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(said), "{args:?}: {}", stderr(&out));
        assert!(
            !dir.path().join("x.png").exists(),
            "{args:?} wrote a picture"
        );
    }
    // Negative numbers are values, not options.
    let out = run_in(
        dir.path(),
        &[
            scene,
            "--eye",
            "-1,2,-3",
            "--look-at",
            "-2.5,-0.5,4",
            "--info",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_room_with_outward_faces_is_seen_from_inside_and_lit() {
    let dir = tempfile::tempdir().unwrap();
    write_room(dir.path());
    let out = run_in(
        dir.path(),
        &[
            "room.obj", "--emit", "Lamp=10", "--size", "64x48", "-q", "-o", "x.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("nearly black"), "{}", stderr(&out));
    // Framed from outside, the picture was black (mean 0); from inside the
    // lit walls fill it.
    let mean = mean_8bit(&dir.path().join("x.png"));
    assert!(mean > 60.0, "mean pixel value {mean} of 255");
    // The eye stands inside the room's bounds, off the box.
    let camera = info_camera(dir.path(), &["room.obj", "--emit", "Lamp=10"]);
    let eye = point(option(&camera, "--eye"));
    let (lo, hi) = ([-2.0, 0.0, -2.5], [2.0, 3.0, 2.5]);
    assert!((0..3).all(|k| eye[k] > lo[k] && eye[k] < hi[k]), "{eye:?}");
    // Without a light in it, the closed box is seen from outside as before.
    let unlit = info_camera(dir.path(), &["room.obj"]);
    let eye = point(option(&unlit, "--eye"));
    assert!(eye[2] < lo[2], "{eye:?}");
}

#[test]
fn a_dark_picture_from_outside_the_lit_room_says_so() {
    let dir = tempfile::tempdir().unwrap();
    write_room(dir.path());
    let out = run_in(
        dir.path(),
        &[
            "room.obj",
            "--emit",
            "Lamp=10",
            "--eye",
            "0,10,-20",
            "--look-at",
            "0,1,0",
            "--size",
            "64x48",
            "-q",
            "-o",
            "x.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains(
            "warning: the picture is nearly black (99% of its pixels): the camera stands \
             outside the closed surface that holds the lights"
        ),
        "{err}"
    );
    // Looking away from a lit room from inside it is no such case.
    let out = run_in(
        dir.path(),
        &[
            "room.obj",
            "--emit",
            "Lamp=10",
            "--eye",
            "0,1.5,0",
            "--look-at",
            "0,1.5,-100",
            "--size",
            "64x48",
            "-q",
            "-o",
            "y.png",
        ],
    );
    assert!(
        !stderr(&out).contains("outside the closed surface"),
        "{}",
        stderr(&out)
    );
}

/// The number after `label` on the line that starts with it.
fn number_after(text: &str, label: &str) -> f64 {
    let line = text.lines().find(|l| l.starts_with(label)).unwrap();
    line[label.len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .replace(',', "")
        .parse()
        .unwrap()
}

#[test]
fn info_describes_a_model_without_solving() {
    let dir = tempfile::tempdir().unwrap();
    write_room(dir.path());
    let out = run_in(dir.path(), &["room.obj", "--emit", "Lamp=10", "--info"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stderr.is_empty(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    for line in [
        "scene: room.obj, 13 polygons (7 of them with a back side)\n",
        "materials (3):\n  Wall: reflectance 0.8 0.5 0.4, 6 polygons\n",
        "objects (3): Room (6 polygons), Lamp (1 polygon), Box (6 polygons)\n",
        "emitters (1):\n  LampShade: emits 10 10 10, 1 polygon, area 1\n",
        "bounds: -2 0 -2.5 to 2 3 2.5 (size 4 x 3 x 5, diagonal 7.071068)\n",
        "warnings: none\n",
    ] {
        assert!(text.contains(line), "{line:?} not in\n{text}");
    }
    // The default lenmax is 1/80 of the diagonal, √50.
    let lenmax = number_after(&text, "lenmax:");
    assert!((lenmax - 50f64.sqrt() / 80.0).abs() < 1e-6, "{lenmax}");
    // Nothing was written, and the estimate is the mesh a run builds.
    assert_eq!(common::listing(dir.path()), ["room.mtl", "room.obj"]);
    let run = run_in(
        dir.path(),
        &[
            "room.obj",
            "--emit",
            "Lamp=10",
            "--max-steps",
            "1",
            "--size",
            "8x6",
            "-q",
            "-o",
            "x.png",
            "--stats",
            "s.json",
        ],
    );
    assert!(run.status.success(), "{}", stderr(&run));
    let stats = common::read_json(dir.path(), "s.json");
    let estimated = number_after(&text, "estimated mesh:");
    assert_eq!(Some(estimated as u64), stats["elements"].as_u64());
    // Without --emit, the warning that nothing emits is listed.
    let out = run_in(dir.path(), &["room.obj", "--info"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("emitters: none"), "{text}");
    assert!(
        text.contains("warnings (1):\n  room.obj: warning: nothing emits light"),
        "{text}"
    );
}

#[test]
fn info_reads_every_bundled_scene_and_a_downloaded_model() {
    let dir = tempfile::tempdir().unwrap();
    let mut scenes: Vec<std::path::PathBuf> = std::fs::read_dir(common::root().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "sc"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 4);
    scenes.push(common::root().join("tests/models/mcguire/CornellBox-Original.obj"));
    for scene in &scenes {
        let out = run_in(dir.path(), &[scene.to_str().unwrap(), "--info"]);
        assert!(out.status.success(), "{scene:?}: {}", stderr(&out));
        let text = String::from_utf8(out.stdout).unwrap();
        for label in [
            "scene: ",
            "materials (",
            // "emitters (N)", or for a scene lit by a sky alone (the
            // daylight office) "emitters: none (…give --sky)".
            "emitters",
            "bounds: ",
            "camera (",
            "lenmax: ",
            "estimated mesh: ",
            "warnings",
        ] {
            assert!(text.contains(label), "{scene:?}: no {label:?} in\n{text}");
        }
    }
    let office = run_in(
        dir.path(),
        &[common::scene("office.sc").to_str().unwrap(), "--info"],
    );
    assert!(String::from_utf8(office.stdout)
        .unwrap()
        .contains("emitters ("));
    let out = run_in(
        dir.path(),
        &[scenes.last().unwrap().to_str().unwrap(), "--info"],
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("  light: emits 17 12 4, 1 polygon"), "{text}");
    assert!(text.contains("groups (7): floor (1 polygon)"), "{text}");
    assert_eq!(common::listing(dir.path()), Vec::<String>::new());
}

#[test]
fn the_ambient_term_does_not_light_up_a_view_of_unlit_walls() {
    let dir = tempfile::tempdir().unwrap();
    write_room(dir.path());
    // Outside the lit room, looking at its walls, with the ambient term
    // shown as the window shows it: exposed for the ambient term alone,
    // the walls came out a bright, flat salmon (mean 174 of 255 on them).
    write(
        dir.path(),
        "outside.sc",
        "camera\n  eye 0 10 -20\n  lookat 0 1 0\nend\n",
    );
    let out = run_in(
        dir.path(),
        &[
            "room.obj",
            "--emit",
            "Lamp=10",
            "--camera",
            "outside.sc",
            "--ambient",
            "--max-steps",
            "5",
            "--size",
            "64x48",
            "-q",
            "-o",
            "x.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.path().join("x.png")).unwrap().to_rgb8();
    let walls: Vec<f64> = img
        .pixels()
        .filter(|p| p.0.iter().any(|&c| c > 0))
        .map(|p| p.0.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0)
        .collect();
    assert!(walls.len() > 100, "{} pixels of wall", walls.len());
    let mean = walls.iter().sum::<f64>() / walls.len() as f64;
    assert!(
        mean < 90.0,
        "the unlit walls are bright: mean {mean} of 255"
    );
}
