//! The baked light in a glTF export, and in a lightmapped model, looks in a
//! web browser as it does in the program's own picture:
//! `scripts/browser/render.mjs` loads the file with three.js's
//! `GLTFLoader` in headless Chromium and renders the same camera, and the
//! two pictures are compared over 4 × 4-pixel blocks.
//!
//! Needs `node`, Debian's `chromium` and the script's `npm` packages
//! (`.ci/run` installs all three and sets `RADIOSITY_REQUIRE_BROWSER`, so
//! in CI a missing piece fails the test). Elsewhere, without them, the test
//! says loudly that it skipped.

mod common;

use common::pictures::*;
use common::*;
use std::path::PathBuf;
use std::process::Command;

/// Why the browser check cannot run here, if it cannot.
fn missing() -> Option<String> {
    let chromium = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    if which("node").is_none() {
        Some("node is not installed".into())
    } else if !chromium.is_file() {
        Some(format!("no Chromium at {}", chromium.display()))
    } else if !root()
        .join("scripts/browser/node_modules/three/package.json")
        .is_file()
    {
        Some("scripts/browser has no node_modules (npm ci there)".into())
    } else {
        None
    }
}

/// `scene` solved with `output` (the option and file that makes the
/// `.glb`) and written as `-o c.png`, then `c.glb`'s browser picture with
/// `render.mjs --show show`, both at `view`: the program's picture and the
/// browser's. `None` (after saying so) when the browser check cannot run
/// here and need not.
fn program_and_browser(
    scene_file: &str,
    view: [&str; 10],
    output: &str,
    show: &str,
) -> Option<(image::RgbImage, image::RgbImage)> {
    if let Some(why) = missing() {
        assert!(
            std::env::var_os("RADIOSITY_REQUIRE_BROWSER").is_none(),
            "the browser check must run here: {why}"
        );
        eprintln!("\n**************** SKIPPED: browser test: {why} ****************\n");
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = root().join(scene_file);
    let mut args = vec![path.to_str().unwrap(), output, "c.glb", "-o", "c.png"];
    args.extend(["--aa", "1", "-q", "--no-window"]);
    args.extend(view);
    let out = run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = Command::new("node")
        .arg(root().join("scripts/browser/render.mjs"))
        .args(["c.glb", "three.png", "--show", show])
        .args(view)
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let program = image::open(dir.path().join("c.png")).unwrap().to_rgb8();
    let three = image::open(dir.path().join("three.png")).unwrap().to_rgb8();
    Some((program, three))
}

#[test]
fn the_exported_cornell_box_looks_in_three_js_as_in_the_program() {
    let Some((program, three)) =
        program_and_browser("scenes/cornell.sc", CORNELL_VIEW, "--export", "colours")
    else {
        return;
    };
    let error = block_error(&program, &three);
    eprintln!(
        "three.js against the program: {:.2} % relative block error",
        error * 100.0
    );
    assert!(error < MAX_BLOCK_ERROR, "{:.2} %", error * 100.0);
    // The measure tells a wrong picture apart: the same picture upside
    // down, or shifted by two pixels, is far off.
    let flipped = image::imageops::flip_vertical(&three);
    let mut shifted = three.clone();
    for (x, y, p) in shifted.enumerate_pixels_mut() {
        *p = *three.get_pixel(x.saturating_sub(2), y);
    }
    let (flipped, shifted) = (
        block_error(&program, &flipped),
        block_error(&program, &shifted),
    );
    eprintln!(
        "upside down: {:.2} %, two pixels to the right: {:.2} %",
        flipped * 100.0,
        shifted * 100.0
    );
    assert!(flipped > 5.0 * MAX_BLOCK_ERROR && shifted > MAX_BLOCK_ERROR);
}

/// `--lightmap`'s model shows in three.js, loaded as it is (its own
/// materials, no light added, the lightmap read as the emissive texture on
/// the second UV set), as the program's picture of the same view: a
/// texture upside down or on the wrong UV set would be far off. Three
/// scenes: the Cornell box (16 charts), the room with the table (43
/// charts, many of them small: the table's legs and the box on it), and
/// McGuire's Cornell box with spheres, an OBJ read back with its own
/// smooth normals, every face with a back copy.
#[test]
fn the_lightmapped_scenes_look_in_three_js_as_in_the_program() {
    for (scene_file, view) in [
        ("scenes/cornell.sc", CORNELL_VIEW),
        ("scenes/rtable.sc", RTABLE_VIEW),
        ("tests/models/mcguire/CornellBox-Sphere.obj", MCGUIRE_VIEW),
    ] {
        let Some((program, three)) = program_and_browser(scene_file, view, "--lightmap", "file")
        else {
            return;
        };
        let error = block_error(&program, &three);
        eprintln!(
            "{scene_file}: three.js's lightmapped model against the program: \
             {:.2} % relative block error",
            error * 100.0
        );
        assert!(
            error < MAX_BLOCK_ERROR,
            "{scene_file}: {:.2} %",
            error * 100.0
        );
    }
}

/// The camera of `tests/models/mcguire/camera.sc` at 320 × 240.
const MCGUIRE_VIEW: [&str; 10] = [
    "--eye",
    "0,1,3.9",
    "--look-at",
    "0,1,0",
    "--up",
    "0,1,0",
    "--fov",
    "39",
    "--size",
    "320x240",
];

/// An OBJ's `map_Kd` texture lies the right way up on its `--lightmap`
/// model in three.js: a 2 × 1 floor whose `vt` puts OBJ's `v = 1` (the
/// top of the image, in OBJ's convention) at its far end, textured red
/// over blue, seen from above with the far end at the top of the picture
/// and drawn in its base colour (`render.mjs --show base`): red above,
/// blue below, on both of the floor's quads.
#[test]
fn an_obj_texture_shows_the_right_way_up_in_three_js() {
    if let Some(why) = missing() {
        assert!(
            std::env::var_os("RADIOSITY_REQUIRE_BROWSER").is_none(),
            "the browser check must run here: {why}"
        );
        eprintln!("\n**************** SKIPPED: browser test: {why} ****************\n");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "floor.obj",
        "mtllib floor.mtl\nv 0 0 0\nv 2 0 0\nv 2 0 -1\nv 0 0 -1\n\
         v 0.8 1 -0.3\nv 1.2 1 -0.3\nv 1.2 1 -0.7\nv 0.8 1 -0.7\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         usemtl Tex\nf 1/1 2/2 3/3 4/4\nusemtl Lamp\nf 8 7 6 5\n",
    );
    write(
        dir.path(),
        "floor.mtl",
        "newmtl Tex\nKd 1 1 1\nmap_Kd tex.png\nnewmtl Lamp\nKd 0 0 0\nKe 1 1 1\n",
    );
    image::RgbImage::from_fn(8, 8, |_, y| {
        image::Rgb(if y < 4 { [200, 40, 40] } else { [40, 40, 200] })
    })
    .save(dir.path().join("tex.png"))
    .unwrap();
    let out = run_in(
        dir.path(),
        &[
            "floor.obj",
            "--emit",
            "Lamp=10",
            "-o",
            "floor.png",
            "--lightmap",
            "floor.glb",
            "--lightmap-density",
            "32",
            "-q",
            "--no-window",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // From 3 units above the floor's middle, -z (the far end) up.
    let out = Command::new("node")
        .arg(root().join("scripts/browser/render.mjs"))
        .args(["floor.glb", "three.png", "--show", "base"])
        .args([
            "--eye",
            "1,3,-0.5",
            "--look-at",
            "1,0,-0.5",
            "--up",
            "0,0,-1",
        ])
        .args(["--fov", "60", "--size", "160x120"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let three = image::open(dir.path().join("three.png")).unwrap().to_rgb8();
    // The floor spans rows 43 to 77 and columns 45 to 115; the lamp
    // hides the middle columns. Rows 48 and 72 are 0.85 and 0.15 units
    // from the near edge, columns 56 and 104 are 0.3 units in from the
    // floor's sides.
    for x in [56, 104] {
        let (top, bottom) = (three.get_pixel(x, 48).0, three.get_pixel(x, 72).0);
        eprintln!("column {x}: far end {top:?}, near end {bottom:?}");
        let red = |p: [u8; 3]| u32::from(p[0]) > 2 * u32::from(p[2]);
        let blue = |p: [u8; 3]| u32::from(p[2]) > 2 * u32::from(p[0]);
        assert!(
            red(top) && blue(bottom),
            "column {x}: {top:?} over {bottom:?}"
        );
    }
}
