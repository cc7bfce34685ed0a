//! Real exported models, as users bring them: each file under
//! `tests/models/` (where it comes from, its licence and the tool that
//! wrote it are in `tests/models/README.md`) is loaded and solved at a
//! coarse mesh and a small picture, and the test asserts what a user
//! sees: the exit code, the warnings (their number and what they name),
//! and whether the picture is lit, measured as the fraction of pixels that
//! are not black.
//!
//! Pictures are small and meshes coarse, so each model solves in seconds.

mod common;

use common::{read_json, root, run_in, stderr};
use std::path::{Path, PathBuf};
use std::process::Output;

/// A pixel whose brightest 8-bit channel reaches this is "lit": well above
/// the black of the background and of unlit faces (0), well below any
/// surface the light reaches in these models.
const LIT_LEVEL: u8 = 8;

/// The path of a collected model, `tests/models/<rel>`.
fn model(rel: &str) -> PathBuf {
    root().join("tests").join("models").join(rel)
}

/// The camera that looks into McGuire's Cornell boxes from their open side.
fn mcguire_camera() -> PathBuf {
    model("mcguire/camera.sc")
}

/// Runs the program in `dir` on `scene` with `args`, writing `out.png` and
/// `stats.json` there.
fn solve(dir: &Path, scene: &Path, args: &[&str]) -> Output {
    let scene = scene.to_str().expect("a UTF-8 path");
    let mut all = vec![scene, "-o", "out.png", "--stats", "stats.json"];
    all.extend_from_slice(args);
    run_in(dir, &all)
}

/// The `warning:` lines of a run's standard error.
fn warnings(out: &Output) -> Vec<String> {
    stderr(out)
        .lines()
        .filter(|l| l.contains("warning:"))
        .map(str::to_owned)
        .collect()
}

/// The fraction of the pixels of `dir/name` with a channel at or above
/// [`LIT_LEVEL`], from 0 to 1.
fn lit_fraction(dir: &Path, name: &str) -> f64 {
    let img = image::open(dir.join(name)).unwrap().to_rgb8();
    let lit = img
        .pixels()
        .filter(|p| p.0.iter().any(|&c| c >= LIT_LEVEL))
        .count();
    lit as f64 / (img.width() * img.height()) as f64
}

/// Mean 8-bit red, green and blue of the pixels of `dir/name` in the
/// rectangle `x0..x1` × `y0..y1`, given as fractions of the width and the
/// height (y down).
fn mean_rgb(dir: &Path, name: &str, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> [f64; 3] {
    let img = image::open(dir.join(name)).unwrap().to_rgb8();
    let (w, h) = (img.width() as f64, img.height() as f64);
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for y in (y0 * h) as u32..(y1 * h) as u32 {
        for x in (x0 * w) as u32..(x1 * w) as u32 {
            let p = img.get_pixel(x, y).0;
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// The one warning for McGuire's `CornellBox-Original.obj`: each box's
/// "Bottom Face" repeats another face's vertices.
fn repeated_faces_warning() -> String {
    format!(
        "{}:107:1: warning: 2 faces repeat an earlier face exactly (first: line 107 repeats \
         line 93); one of each was kept, as repeated faces would shadow each other",
        model("mcguire/CornellBox-Original.obj").display()
    )
}

/// Runs McGuire's `CornellBox-Original.obj` in `dir` as [`solve`] does,
/// from its camera, at `--lenmax 0.25` and 160 × 120, with `extra`.
fn solve_mcguire_box(dir: &Path, extra: &[&str]) -> Output {
    let cam = mcguire_camera();
    let mut args = vec![
        "--camera",
        cam.to_str().expect("a UTF-8 path"),
        "--lenmax",
        "0.25",
        "--size",
        "160x120",
    ];
    args.extend_from_slice(extra);
    solve(dir, &model("mcguire/CornellBox-Original.obj"), &args)
}

/// The mean linear RGB of the `.pfm` `dir/name` over the fractions
/// `x0..x1` of its width and `y0..y1` of its height (from the top).
fn mean_linear(dir: &Path, name: &str, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> [f64; 3] {
    let bytes = std::fs::read(dir.join(name)).unwrap();
    let ends: Vec<usize> = (0..bytes.len())
        .filter(|&i| bytes[i] == b'\n')
        .take(3)
        .collect();
    let size = String::from_utf8_lossy(&bytes[ends[0] + 1..ends[1]]).into_owned();
    let mut wh = size.split_whitespace().map(|n| n.parse::<usize>().unwrap());
    let (w, h) = (wh.next().unwrap(), wh.next().unwrap());
    let value = |x: usize, y: usize, c: usize| {
        // Rows are stored bottom first.
        let at = ends[2] + 1 + (((h - 1 - y) * w + x) * 3 + c) * 4;
        f64::from(f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()))
    };
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for y in (y0 * h as f64) as usize..(y1 * h as f64) as usize {
        for x in (x0 * w as f64) as usize..(x1 * w as f64) as usize {
            for (c, s) in sum.iter_mut().enumerate() {
                *s += value(x, y, c);
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// The warning that McGuire's Cornell boxes get for their lamp, one face
/// (`CornellBox-Original.obj`, line 168) or two triangles
/// (`CornellBox-Sphere.obj`, from line 5766) a centimetre under the
/// ceiling: the side facing it emits nothing.
fn covered_lamp_warning(file: &str) -> String {
    let path = model(file).display().to_string();
    if file.ends_with("Sphere.obj") {
        format!(
            "{path}:5766:1: warning: 2 emitting faces have a surface behind one side, closer \
             than 5 % of the face's width (first: this face's back, 0.010 units): those sides \
             now emit nothing, as light sent into so narrow a gap would only seep out at its edge"
        )
    } else {
        format!(
            "{path}:168:1: warning: this emitting face's back has a surface 0.010 units behind \
             it, closer than 5 % of the face's width: that side now emits nothing, as light sent \
             into so narrow a gap would only seep out at its edge"
        )
    }
}

/// Rec. 709 luminance of an RGB triple.
fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

// ---------------------------------------------------------------------------
// McGuire's Cornell boxes (public domain, hand-made OBJ + MTL with `Ke`)

#[test]
fn mcguire_cornell_box_lights_itself_through_ke() {
    let dir = tempfile::tempdir().unwrap();
    let out = solve_mcguire_box(dir.path(), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    // The lamp's `Ke 17 12 4` emits; the MTL's `Ka`, `Ns`, `Ni`, `illum
    // 2` with black `Ks` are plain diffuse. Two warnings: the two faces
    // the file repeats, and the lamp's back against the ceiling.
    assert_eq!(
        warnings(&out),
        [
            repeated_faces_warning(),
            covered_lamp_warning("mcguire/CornellBox-Original.obj")
        ]
    );
    let stats = read_json(dir.path(), "stats.json");
    assert_eq!(stats["converged"], true);
    assert!(stats["steps"].as_u64().unwrap() > 10, "{stats}");
    // The box fills most of the picture (measured 0.71; the rest is the
    // background beside the walls).
    let lit = lit_fraction(dir.path(), "out.png");
    assert!(lit > 0.6, "lit fraction {lit}");
    // Red wall on the left, green on the right, as in every picture of it.
    let left = mean_rgb(dir.path(), "out.png", (0.12, 0.22), (0.3, 0.7));
    let right = mean_rgb(dir.path(), "out.png", (0.78, 0.88), (0.3, 0.7));
    assert!(left[0] > 2.0 * left[1], "left wall {left:?}");
    assert!(right[1] > 1.2 * right[0], "right wall {right:?}");
}

#[test]
fn mcguire_lamp_under_the_ceiling_lights_the_room_alike_at_any_sample_count() {
    // The lamp hangs 1 cm under the ceiling. When its back emitted too,
    // the light in the gap reached the room only through the ceiling's
    // cells straddling the lamp's edge, as their samples fell: the
    // middle of this picture came out 37 % brighter at 16 shooter samples
    // than at 64. With the back silenced, the two agree.
    // Compared in linear radiosity (.pfm), as the automatic exposure of
    // each picture would hide a difference of the whole.
    let dir = tempfile::tempdir().unwrap();
    let middle = |samples: &str| {
        let cam = mcguire_camera();
        let scene = model("mcguire/CornellBox-Original.obj");
        let args = [
            scene.to_str().unwrap(),
            "--camera",
            cam.to_str().unwrap(),
            "--lenmax",
            "0.25",
            "--size",
            "160x120",
            "--shooter-samples",
            samples,
            "-o",
            "out.pfm",
        ];
        let out = run_in(dir.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
        let warned =
            warnings(&out).contains(&covered_lamp_warning("mcguire/CornellBox-Original.obj"));
        // The back wall and the boxes (measured a luminance of 0.11).
        let middle = mean_linear(dir.path(), "out.pfm", (0.3, 0.7), (0.3, 0.7));
        (luminance(middle), warned)
    };
    let ((few, warned), (many, _)) = (middle("16"), middle("64"));
    assert!(few > 0.02, "the middle is lit: {few}");
    assert!(
        (few / many - 1.0).abs() < 0.02,
        "16 samples {few}, 64 samples {many}"
    );
    assert!(warned, "the warning names the lamp");
}

#[test]
fn mcguire_cornell_box_framed_automatically_shows_its_inside() {
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("mcguire/CornellBox-Original.obj"),
        &["--lenmax", "0.25", "--size", "160x120"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(warnings(&out)[0], repeated_faces_warning());
    let lit = lit_fraction(dir.path(), "out.png");
    assert!(lit > 0.3, "lit fraction {lit}");
}

#[test]
fn mcguire_cornell_box_repeated_faces_change_nothing() {
    // Each box's "Bottom Face" repeats the vertices of another face
    // (`f -12 -11 -10 -9`, `f -8 -7 -6 -5`). Dropped, with one warning,
    // the picture must be the one of the file without those two lines.
    // Today the tall block's front is 4 % brighter, in bright blocks.
    let original = model("mcguire/CornellBox-Original.obj");
    let text = std::fs::read_to_string(&original).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let cleaned: String = text
        .split_inclusive('\n')
        .filter(|l| !l.starts_with("f -12 -11 -10 -9") && !l.starts_with("f -8 -7 -6 -5"))
        .collect();
    assert_eq!(cleaned.lines().count() + 2, text.lines().count());
    std::fs::write(dir.path().join("cleaned.obj"), cleaned).unwrap();
    std::fs::copy(
        model("mcguire/CornellBox-Original.mtl"),
        dir.path().join("CornellBox-Original.mtl"),
    )
    .unwrap();
    let cam = mcguire_camera();
    let args = [
        "--camera",
        cam.to_str().unwrap(),
        "--lenmax",
        "0.08",
        "--size",
        "160x120",
    ];
    let out = solve(dir.path(), &original, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(warnings(&out)[0], repeated_faces_warning());
    std::fs::rename(dir.path().join("out.png"), dir.path().join("a.png")).unwrap();
    let clean = solve(dir.path(), &dir.path().join("cleaned.obj"), &args);
    assert!(clean.status.success(), "{}", stderr(&clean));
    let tall = ((0.36, 0.46), (0.45, 0.75));
    let a = luminance(mean_rgb(dir.path(), "a.png", tall.0, tall.1));
    let b = luminance(mean_rgb(dir.path(), "out.png", tall.0, tall.1));
    assert!((a / b - 1.0).abs() < 0.01, "tall block front {a} vs {b}");
}

#[test]
fn mcguire_spheres_are_read_as_diffuse_and_their_lamp_faces_down() {
    // CRLF lines, two smooth spheres (`s 1`, `vn`) of mirror and glass
    // materials, and an MTL with stray `v 0.2 0 0` lines.
    let dir = tempfile::tempdir().unwrap();
    let cam = mcguire_camera();
    let out = solve(
        dir.path(),
        &model("mcguire/CornellBox-Sphere.obj"),
        &[
            "--camera",
            cam.to_str().unwrap(),
            "--lenmax",
            "0.3",
            "--size",
            "160x120",
            "--max-steps",
            "12",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let w = warnings(&out);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].contains("CornellBox-Sphere.mtl: warning:"), "{w:?}");
    assert_eq!(w[1], covered_lamp_warning("mcguire/CornellBox-Sphere.obj"));
    assert!(
        w[0].contains("leftSphere") && w[0].contains("rightSphere"),
        "{w:?}"
    );
    let stats = read_json(dir.path(), "stats.json");
    // Every face loads: 2188, and the walls' back copies (the spheres
    // are closed solids: one-sided).
    assert!(stats["polygons"].as_u64().unwrap() >= 2188, "{stats}");
    // Walls, floor and ceiling lit (measured 0.54: the spheres, `Kd
    // 0.01`, and the background beside the walls stay dark).
    let lit = lit_fraction(dir.path(), "out.png");
    assert!(lit > 0.45, "lit fraction {lit}");
}

// ---------------------------------------------------------------------------
// tinyobjloader's Cornell box (hand-written; its lamp has `Ka 20`, no `Ke`)

#[test]
fn tinyobjloader_cornell_box_without_ke_names_its_lamp() {
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("tinyobjloader/cornell_box.obj"),
        &["--lenmax", "40", "--size", "160x120"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let w = warnings(&out);
    // `Kd 1` in each of its five materials: one warning each, then the
    // one saying nothing emits.
    assert_eq!(w.len(), 6, "{w:?}");
    for (line, name) in [
        (3, "white"),
        (8, "red"),
        (13, "green"),
        (18, "blue"),
        (23, "light"),
    ] {
        let at = format!("cornell_box.mtl:{line}:1: warning: material `{name}`");
        assert!(w.iter().any(|l| l.contains(&at)), "{at} in {w:?}");
    }
    let nothing = &w[5];
    assert!(
        nothing.contains("cornell_box.obj: warning: nothing emits light"),
        "{w:?}"
    );
    assert!(
        nothing.contains("object `light`") && nothing.contains("material `light`"),
        "{nothing}"
    );
    assert!(nothing.contains("--emit"), "{nothing}");
    let stats = read_json(dir.path(), "stats.json");
    assert_eq!(stats["nothing_emits"], true);
    assert_eq!(stats["converged"], false);
    assert!(lit_fraction(dir.path(), "out.png") < 0.001);
}

#[test]
fn tinyobjloader_cornell_box_lit_with_emit() {
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("tinyobjloader/cornell_box.obj"),
        &["--emit", "light=10", "--lenmax", "40", "--size", "160x120"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let w = warnings(&out);
    assert_eq!(w.len(), 6, "the five `Kd 1` warnings and the lamp's: {w:?}");
    assert!(!w.iter().any(|l| l.contains("nothing emits")), "{w:?}");
    // Its lamp is 0.8 units under a ceiling 550 wide.
    assert!(
        w[5].contains(
            "cornell_box.obj:37:1: warning: this emitting face's back has a surface 0.800"
        ),
        "{w:?}"
    );
    let stats = read_json(dir.path(), "stats.json");
    assert_eq!(stats["converged"], true);
    // The box, seen through its open front, is lit (measured 0.35).
    let lit = lit_fraction(dir.path(), "out.png");
    assert!(lit > 0.25, "lit fraction {lit}");

    let bad = solve(
        dir.path(),
        &model("tinyobjloader/cornell_box.obj"),
        &["--emit", "lamp=10", "--lenmax", "40", "--size", "160x120"],
    );
    assert_eq!(bad.status.code(), Some(2));
    let err = stderr(&bad);
    assert!(err.contains("`lamp`") && err.contains("`light`"), "{err}");
}

// ---------------------------------------------------------------------------
// raylib's biplane (Blender 2.90 OBJ, no MTL, no lamp)

#[test]
fn raylib_plane_without_lamp_says_nothing_emits_and_names_none() {
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("raylib/plane.obj"),
        &["--lenmax", "5", "--size", "160x120"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let w = warnings(&out);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("plane.obj: warning: nothing emits light"),
        "{w:?}"
    );
    assert!(!w[0].contains("looks like a lamp"), "{w:?}");
    let stats = read_json(dir.path(), "stats.json");
    // Every face loads: 2564, with back copies and cut pieces more.
    assert!(stats["polygons"].as_u64().unwrap() > 2564, "{stats}");
    assert_eq!(stats["nothing_emits"], true);
}

#[test]
fn raylib_plane_under_a_sky_is_lit() {
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("raylib/plane.obj"),
        // Six steps: the sky's facets shoot first, and each sends 256
        // directions to every vertex; the whole solve takes minutes.
        &[
            "--sky",
            "1",
            "--one-sided",
            "--lenmax",
            "50",
            "--max-steps",
            "6",
            "--size",
            "160x120",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // Framed from -z the biplane covers 4 % of the picture; the sky is not
    // drawn, so that is what is lit (measured 0.043), and the picture is
    // said to be mostly background.
    let w = warnings(&out);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("is background"), "{w:?}");
    let lit = lit_fraction(dir.path(), "out.png");
    assert!(lit > 0.03, "lit fraction {lit}");
}

// ---------------------------------------------------------------------------
// three.js's OBJ loader verification file (hand-written)

#[test]
fn threejs_verify_loads_with_a_few_warnings() {
    // Texture indices 7 to 10 with four `vt` defined, `p` and `l` lines,
    // negative indices, a `map_Kd` that is not there and `Kd 1`.
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("threejs/verify.obj"),
        &["--lenmax", "4", "--size", "160x120"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(!err.contains("error:"), "{err}");
    let w = warnings(&out);
    assert!(w.len() <= 8, "a few lines, not one per fault: {w:?}");
    assert!(
        w.iter()
            .any(|l| l.contains("verify.obj:136:") && l.contains("texture coordinate")),
        "one warning at the first bad index: {w:?}"
    );
    assert!(
        w.iter().any(|l| l.contains("map_Kd")),
        "the missing texture: {w:?}"
    );
    assert!(
        w.iter().any(|l| l.contains("nothing emits")),
        "no lamp: {w:?}"
    );
}

// ---------------------------------------------------------------------------
// glTF models.

#[test]
fn gltf_box_loads_and_lights_with_emit() {
    // Khronos's Box: one mesh named `Mesh`, one unnamed red material,
    // a node matrix turning +z up into +y up.
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("khronos/Box.gltf"),
        &["--lenmax", "0.1", "--size", "160x120"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let w = warnings(&out);
    // Its material is metallic (read as diffuse), and nothing emits.
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("Box.gltf: warning: treated as diffuse: materials[0] (metallic 1)"),
        "{w:?}"
    );
    assert!(
        w[1].contains("Box.gltf: warning: nothing emits light"),
        "{w:?}"
    );
    let stats = read_json(dir.path(), "stats.json");
    assert_eq!(stats["polygons"].as_u64().map(|n| n >= 6), Some(true));

    let lit = solve(
        dir.path(),
        &model("khronos/Box.gltf"),
        &["--emit", "Mesh=1", "--lenmax", "0.1", "--size", "160x120"],
    );
    assert!(lit.status.success(), "{}", stderr(&lit));
    let fraction = lit_fraction(dir.path(), "out.png");
    assert!(fraction > 0.05, "lit fraction {fraction}");
}

#[test]
fn gltf_cameras_takes_the_files_perspective_camera() {
    // A unit square tilted 45° and a perspective camera (yfov 0.7 rad,
    // aspect 1) in front of it, then an orthographic one (not taken).
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("khronos/Cameras.gltf"),
        &["--lenmax", "0.05"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.path().join("out.png")).unwrap();
    assert_eq!(img.width(), img.height(), "aspect ratio 1 from the file");
    let w = warnings(&out);
    assert!(w.iter().any(|l| l.contains("nothing emits")), "{w:?}");
}

#[test]
fn glb_blender_character_loads_and_lights_under_a_sky() {
    // A skinned character from Blender's glTF exporter (3.6), as `.glb`.
    let dir = tempfile::tempdir().unwrap();
    let out = solve(
        dir.path(),
        &model("raylib/greenman.glb"),
        &["--lenmax", "0.1", "--size", "160x120"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let w = warnings(&out);
    assert!(
        w.iter()
            .any(|l| l.contains("greenman.glb: warning: nothing emits")),
        "{w:?}"
    );
    let lit = solve(
        dir.path(),
        &model("raylib/greenman.glb"),
        &["--sky", "1", "--lenmax", "1", "--size", "160x120"],
    );
    assert!(lit.status.success(), "{}", stderr(&lit));
    let fraction = lit_fraction(dir.path(), "out.png");
    assert!(fraction > 0.02, "lit fraction {fraction}");
}
