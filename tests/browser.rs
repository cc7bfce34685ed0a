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
    let path = scene(scene_file);
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
        program_and_browser("cornell.sc", CORNELL_VIEW, "--export", "colours")
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
/// texture upside down or on the wrong UV set would be far off. Two
/// scenes: the Cornell box (16 charts) and the room with the table (43
/// charts, many of them small: the table's legs and the box on it).
#[test]
fn the_lightmapped_scenes_look_in_three_js_as_in_the_program() {
    for (scene_file, view) in [("cornell.sc", CORNELL_VIEW), ("rtable.sc", RTABLE_VIEW)] {
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
