//! `--lightmap`'s model in Blender, imported as a user imports it
//! (*File → Import → glTF 2.0*, its defaults): every material's Emission
//! is the lightmap image, read as sRGB at strength 1, through the second
//! UV map, and a render with the guide's settings (the world black, *View
//! Transform* Standard) from the program's camera is the program's
//! picture. `scripts/blender/render_lightmap.py` does the Blender side;
//! Cycles renders on the CPU.
//!
//! Blender is large and optional: without it on the `PATH` (or at
//! `BLENDER`), or with an importer that cannot run (no numpy), the test
//! says loudly that it skipped. CI does not install it.

mod common;

use common::pictures::*;
use common::*;
use std::path::PathBuf;
use std::process::Command;

/// The Blender to run (`BLENDER`, else `blender` on the `PATH`), if
/// there is one.
fn blender() -> Option<PathBuf> {
    match std::env::var_os("BLENDER") {
        Some(path) => Some(PathBuf::from(path)).filter(|p| p.is_file()),
        None => which("blender"),
    }
}

/// Says loudly that the Blender check did not run, and why.
fn skipped(why: &str) {
    eprintln!("\n**************** SKIPPED: Blender test: {why} ****************\n");
}

/// `scene_file` baked with `--lightmap` and drawn with `-o` at `view`,
/// then the `.glb` rendered in Blender at the same view: the program's
/// picture, Blender's, and the Blender script's report. `None` (after
/// saying so) when Blender cannot run the check here.
fn program_and_blender(
    scene_file: &str,
    view: [&str; 10],
) -> Option<(image::RgbImage, image::RgbImage, String)> {
    let Some(blender) = blender() else {
        skipped("blender is not installed (Debian: apt-get install blender python3-numpy)");
        return None;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = scene(scene_file);
    let mut args = vec![path.to_str().unwrap(), "--lightmap", "c.glb", "-o", "c.png"];
    args.extend(["-q", "--no-window"]);
    args.extend(view);
    let out = run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = Command::new(blender)
        .args(["-b", "--factory-startup", "--python"])
        .arg(root().join("scripts/blender/render_lightmap.py"))
        .args([
            "--",
            "c.glb",
            "blender.png",
            "--engine",
            "cycles",
            "--samples",
            "16",
        ])
        .args(view)
        .current_dir(dir.path())
        .output()
        .unwrap();
    let report = String::from_utf8_lossy(&out.stdout).into_owned();
    if report.contains("No module named 'numpy'") {
        skipped("Blender's glTF importer needs numpy (Debian: apt-get install python3-numpy)");
        return None;
    }
    assert!(out.status.success(), "{report}{}", stderr(&out));
    let program = image::open(dir.path().join("c.png")).unwrap().to_rgb8();
    let rendered = image::open(dir.path().join("blender.png"))
        .unwrap()
        .to_rgb8();
    Some((program, rendered, report))
}

/// The lightmapped Cornell box and room with the table, in Blender, are
/// the program's pictures within the browser test's bound; and each
/// material shows the lightmap as the guide says (the script exits 1
/// otherwise: a lightmap on the first UV map, read as Non-Color or at
/// another strength, or a material without it).
#[test]
fn the_lightmapped_scenes_look_in_blender_as_in_the_program() {
    for (scene_file, view) in [("cornell.sc", CORNELL_VIEW), ("rtable.sc", RTABLE_VIEW)] {
        let Some((program, rendered, report)) = program_and_blender(scene_file, view) else {
            return;
        };
        let materials: Vec<&str> = report
            .lines()
            .filter(|l| l.starts_with("material "))
            .collect();
        assert!(!materials.is_empty(), "{report}");
        for line in &materials {
            assert!(
                line.contains("Emission <- image lightmap (sRGB) <- UV map ")
                    && line.ends_with(", strength 1"),
                "{scene_file}: {line}"
            );
        }
        let error = block_error(&program, &rendered);
        eprintln!(
            "{scene_file}: Blender's lightmapped model against the program: \
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
