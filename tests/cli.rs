//! Whole-program behaviour: bundled scenes render, bad input is refused
//! with a positioned message and leaves nothing behind.

mod common;

use common::*;

/// Options that keep the bundled scenes quick in tests: a coarse mesh and
/// a loose threshold (the pictures are checked for size and light, not
/// quality).
const QUICK: &[&str] = &["--threshold", "0.05", "--shooter-samples", "16", "-q"];

fn render_scene(name: &str, lenmax: &str) {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene(name);
    let mut args = vec![
        scene.to_str().unwrap(),
        "-o",
        "out.png",
        "--lenmax",
        lenmax,
        "--stats",
        "stats.json",
    ];
    args.extend_from_slice(QUICK);
    let out = run_in(dir.path(), &args);
    assert!(out.status.success(), "{name}: {}", stderr(&out));
    let img = image::open(dir.path().join("out.png")).unwrap().to_rgb8();
    let text = std::fs::read_to_string(scene).unwrap();
    // The camera's size line, e.g. `size 640 480`.
    let size_line = text
        .lines()
        .find(|l| l.trim_start().starts_with("size"))
        .unwrap();
    let nums: Vec<u32> = size_line
        .split_whitespace()
        .skip(1)
        .take(2)
        .map(|n| n.parse().unwrap())
        .collect();
    assert_eq!((img.width(), img.height()), (nums[0], nums[1]), "{name}");
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 20)).count();
    assert!(
        lit > (img.width() * img.height()) as usize / 4,
        "{name}: only {lit} lit pixels"
    );
    let stats: serde_json::Value = read_json(dir.path(), "stats.json");
    assert!(stats["steps"].as_u64().unwrap() > 0);
    assert!(stats["rays"].as_u64().unwrap() > 0);
    assert!(stats["vertices"].as_u64().unwrap() > stats["polygons"].as_u64().unwrap());
    for phase in ["load", "mesh", "bvh", "solve", "render", "write"] {
        assert!(stats["seconds"][phase].as_f64().unwrap() >= 0.0);
    }
}

#[test]
fn rtable_renders() {
    render_scene("rtable.sc", "0.3");
}

#[test]
fn cornell_renders() {
    render_scene("cornell.sc", "60");
}

#[test]
fn table_chair_renders() {
    render_scene("table_chair.sc", "0.4");
}

#[test]
fn default_run_writes_scene_named_png_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &["--lenmax", "0.5", "--threshold", "0.2", "--size", "64x48"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("rtable.png"), "{}", stderr(&out));
    let img = image::open(dir.path().join("rtable.png")).unwrap();
    assert_eq!((img.width(), img.height()), (64, 48));
}

#[test]
fn every_picture_format_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    for name in ["a.png", "a.tiff", "a.tif", "a.exr", "a.pfm"] {
        let out = run_in(
            dir.path(),
            &[
                scene.to_str().unwrap(),
                "-o",
                name,
                "--lenmax",
                "120",
                "--size",
                "32x32",
                "--max-steps",
                "3",
                "-q",
            ],
        );
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert!(dir.path().join(name).metadata().unwrap().len() > 0);
    }
    let exr = image::open(dir.path().join("a.exr")).unwrap().to_rgb32f();
    assert_eq!((exr.width(), exr.height()), (32, 32));
    // Linear radiosity: the light is far brighter than 1.
    assert!(exr.pixels().any(|p| p.0[0] > 1.0));
    assert_eq!(
        listing(dir.path()),
        vec!["a.exr", "a.pfm", "a.png", "a.tif", "a.tiff"]
    );
}

/// Each bad file: exit status 2, the positioned message on stderr, and no
/// output file.
#[test]
fn bad_scenes_are_refused_with_positions() {
    let cases: &[(&str, &str, &str)] = &[
        ("unknown.sc", "material m\n  color 1 1 1\nend\nsphere m 1 2 3\n", "unknown.sc:4:1: error:"),
        (
            "nonplanar.sc",
            "material m\n  k_diffrefl 0.5\nend\npolygon m\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 1 1 1\n  vertex 0 1 0\nend\n",
            "nonplanar.sc:4:1: error:",
        ),
        ("undefined.sc", "polygon nope\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\nend\n", "undefined.sc:1:9: error:"),
        ("unterminated.sc", "material m\n  color 1 1 1\n", "unterminated.sc:1:1: error:"),
        ("badnumber.sc", "material m\n  color 1 nan 1\nend\n", "badnumber.sc:2:11: error:"),
    ];
    for (name, text, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        let path = write(dir.path(), name, text);
        let out = run_in(
            dir.path(),
            &[
                path.file_name().unwrap().to_str().unwrap(),
                "-o",
                "out.png",
                "--stats",
                "s.json",
            ],
        );
        assert_eq!(out.status.code(), Some(2), "{name}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(expected),
            "{name}: expected `{expected}` in:\n{}",
            stderr(&out)
        );
        assert!(!stderr(&out).contains("panicked"));
        assert_eq!(
            listing(dir.path()),
            vec![name.to_string()],
            "{name}: something was written"
        );
    }
}

#[test]
fn missing_scene_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["nowhere.sc", "-o", "out.png"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).starts_with("nowhere.sc: error: cannot read: "),
        "{}",
        stderr(&out)
    );
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn bad_options_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["-o", "out.bmp"][..],
        &["-o", "missing-dir/out.png"],
        &["--lenmax", "0"],
        &["--lenmax", "-1"],
        &["--shooter-samples", "zero"],
        &["--size", "10by10"],
        &["--threshold", "2"],
        &["--form-factor", "magic"],
        &["--adaptive-levels", "2"],
        &["--adaptive", "--adaptive-levels", "0"],
        &["--adaptive", "--adaptive-levels", "7"],
        &["--adaptive", "--adaptive-threshold", "1.5"],
        &["--adaptive", "--adaptive-threshold", "0"],
        &["--adaptive", "--checkpoint", "state.ckpt"],
        &["--adaptive", "--resume", "state.ckpt"],
        &["--mesh-lines", "-o", "out.exr"],
    ] {
        let out = run_in(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains("error"), "{args:?}: {}", stderr(&out));
    }
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn refuses_to_overwrite_the_input_scene() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene("cornell.sc")).unwrap();
    write(dir.path(), "scene.png", &text);
    let out = run_in(dir.path(), &["scene.png", "-o", "scene.png"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("scene.png")).unwrap(),
        text
    );
}

#[test]
fn help_documents_every_option() {
    let out = run_in(&root(), &["--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for option in [
        "--output",
        "--lenmax",
        "--inset",
        "--threshold",
        "--max-steps",
        "--form-factor",
        "--shooter-samples",
        "--hemicube-res",
        "--size",
        "--exposure",
        "--stats",
        "--threads",
        "--max-elements",
        "--checkpoint",
        "--checkpoint-every",
        "--resume",
        "--adaptive",
        "--adaptive-threshold",
        "--adaptive-levels",
        "--mesh-lines",
        "130 interrupted",
    ] {
        assert!(help.contains(option), "--help lacks {option}");
    }
}

/// `-h` gives one line per option; `--help` adds each option's long text.
#[test]
fn short_help_is_one_line_per_option_and_long_help_more() {
    let short = run_in(&root(), &["-h"]);
    let long = run_in(&root(), &["--help"]);
    assert!(short.status.success() && long.status.success());
    let short = String::from_utf8_lossy(&short.stdout).into_owned();
    let long = String::from_utf8_lossy(&long.stdout).into_owned();
    // Every line that names an option carries its summary on the same line.
    let option_lines: Vec<&str> = short
        .lines()
        .filter(|l| l.trim_start().starts_with('-'))
        .collect();
    assert!(option_lines.len() > 30, "{short}");
    for line in &option_lines {
        let words = line.split_whitespace().count();
        assert!(words > 2, "no summary on the option's line: `{line}`");
    }
    // Nothing but the option lines, a heading and a blank line for each
    // of the nine groups, a pointer to --help and the exit codes.
    assert!(
        short.lines().count() < option_lines.len() + 2 * 9 + 15,
        "-h is not short:\n{short}"
    );
    assert!(short.contains("130 interrupted"), "{short}");
    // The long text is in --help only.
    for detail in [
        "a quadrature of the cell to 6",
        "95th-percentile luminance",
        "Possible values:",
    ] {
        assert!(long.contains(detail), "--help lacks `{detail}`");
        assert!(!short.contains(detail), "-h has `{detail}`");
    }
    assert!(long.lines().count() > 2 * short.lines().count());
}

#[test]
fn a_bad_choice_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    for args in [&["--unshot", "element"][..], &["--form-factor", "Wallace"]] {
        let out = run_in(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("possible values"),
            "{args:?}: {}",
            stderr(&out)
        );
    }
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn without_a_display_it_says_why_and_writes_the_picture() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    let out = run_in(
        dir.path(),
        &[
            scene.to_str().unwrap(),
            "--lenmax",
            "120",
            "--size",
            "32x32",
            "--max-steps",
            "2",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("no display"), "{}", stderr(&out));
    assert!(dir.path().join("cornell.png").exists());
}

#[test]
fn no_window_flag_runs_in_batch_even_with_a_display() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    let out = run_with_display(
        dir.path(),
        ":12345",
        &[
            scene.to_str().unwrap(),
            "--no-window",
            "--lenmax",
            "120",
            "--size",
            "32x32",
            "--max-steps",
            "2",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("cornell.png").exists());
}

#[test]
fn an_unreachable_display_falls_back_to_batch() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    let out = run_with_display(
        dir.path(),
        ":12345",
        &[
            scene.to_str().unwrap(),
            "--lenmax",
            "120",
            "--size",
            "32x32",
            "--max-steps",
            "2",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("cannot open a window"),
        "{}",
        stderr(&out)
    );
    assert!(dir.path().join("cornell.png").exists());
}

/// Reads a colour PFM: the header, then little-endian `f32` RGB.
fn read_pfm(path: &std::path::Path) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    // Three header lines: "PF", "W H", "-1.0".
    let mut newlines = 0;
    let start = bytes
        .iter()
        .position(|&b| {
            newlines += (b == b'\n') as u32;
            newlines == 3
        })
        .unwrap()
        + 1;
    bytes[start..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// `--ambient` brightens an early picture (never darkens a pixel), and
/// without it a file shows the solution alone.
#[test]
fn ambient_term_brightens_early_pictures_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    let common = [
        scene.to_str().unwrap(),
        "--lenmax",
        "80",
        "--size",
        "48x48",
        "--max-steps",
        "1",
        "-q",
    ];
    let mut plain = common.to_vec();
    plain.extend_from_slice(&["-o", "plain.pfm"]);
    let mut with = common.to_vec();
    with.extend_from_slice(&["-o", "ambient.pfm", "--ambient"]);
    for args in [&plain, &with] {
        let out = run_in(dir.path(), args);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let (a, b) = (
        read_pfm(&dir.path().join("plain.pfm")),
        read_pfm(&dir.path().join("ambient.pfm")),
    );
    assert_eq!(a.len(), b.len());
    assert!(a.iter().zip(&b).all(|(x, y)| y >= x));
    let (sa, sb): (f32, f32) = (a.iter().sum(), b.iter().sum());
    assert!(sb > sa * 1.2, "ambient {sb} vs plain {sa}");
}

#[test]
fn adaptive_runs_refine_and_report_each_pass() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    let out = run_in(
        dir.path(),
        &[
            scene.to_str().unwrap(),
            "-o",
            "out.png",
            "--lenmax",
            "60",
            "--adaptive",
            "--mesh-lines",
            "--stats",
            "stats.json",
            "--export",
            "mesh.ply",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("adaptive pass 3"), "{}", stderr(&out));
    let stats: serde_json::Value = read_json(dir.path(), "stats.json");
    let passes = stats["adaptive"].as_array().unwrap();
    assert_eq!(passes.len(), 3, "{passes:?}");
    let vertices: Vec<u64> = passes
        .iter()
        .map(|p| p["vertices"].as_u64().unwrap())
        .collect();
    assert!(vertices.windows(2).all(|w| w[1] > w[0]), "{vertices:?}");
    assert!(passes[0]["split"].as_u64().unwrap() > 0);
    // Refined passes continue the converged solve: far fewer steps.
    let steps: Vec<u64> = passes
        .iter()
        .map(|p| p["steps"].as_u64().unwrap())
        .collect();
    assert!(
        steps[1] * 4 < steps[0] && steps[2] * 4 < steps[0],
        "{steps:?}"
    );
    assert_eq!(stats["steps"].as_u64(), Some(steps.iter().sum()));
    assert_eq!(passes[2]["split"].as_u64(), Some(0));
    // The totals describe the last, finest solve, and the export holds it.
    assert_eq!(stats["vertices"].as_u64(), Some(vertices[2]));
    let ply = std::fs::read(dir.path().join("mesh.ply")).unwrap();
    let header = String::from_utf8_lossy(&ply[..ply.len().min(400)]).to_string();
    assert!(
        header.contains(&format!("element vertex {}", vertices[2])),
        "{header}"
    );
    // Mesh lines are drawn: the cyan of the window's `m`.
    let img = image::open(dir.path().join("out.png")).unwrap().to_rgb8();
    let cyan = img.pixels().filter(|p| p.0 == [40, 220, 255]).count();
    assert!(cyan > 1000, "{cyan} mesh-line pixels");

    // Without --adaptive the stats have no passes.
    let out = run_in(
        dir.path(),
        &[
            scene.to_str().unwrap(),
            "-o",
            "plain.png",
            "--lenmax",
            "60",
            "--stats",
            "plain.json",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let plain: serde_json::Value = read_json(dir.path(), "plain.json");
    assert!(plain.get("adaptive").is_none());
    assert_eq!(plain["vertices"].as_u64(), Some(vertices[0]));
}

#[test]
fn adaptive_refinement_respects_max_elements() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    // 60 gives 632 elements; a first refinement would go past 1,100.
    let out = run_in(
        dir.path(),
        &[
            scene.to_str().unwrap(),
            "-o",
            "out.png",
            "--lenmax",
            "60",
            "--adaptive",
            "--max-elements",
            "1100",
            "--stats",
            "stats.json",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("refining no further")
            && stderr(&out).contains("over the limit of 1100 (--max-elements"),
        "{}",
        stderr(&out)
    );
    let stats: serde_json::Value = read_json(dir.path(), "stats.json");
    assert!(stats["elements"].as_u64().unwrap() <= 1100);
    assert_eq!(stats["adaptive"].as_array().unwrap().len(), 1);
}

#[test]
fn adaptive_runs_with_every_scheme_and_form_factor() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    for (extra, passes) in [
        (&["--unshot", "polygon"][..], 3),
        (&["--form-factor", "center"], 3),
        (&["--form-factor", "center", "--unshot", "polygon"], 3),
        (&["--shooter-samples", "all"], 3),
        (&["--form-factor", "hemicube", "--hemicube-res", "32"], 3),
        // A solve cut short is not refined.
        (&["--max-steps", "3"], 1),
    ] {
        let mut args = vec![
            scene.to_str().unwrap(),
            "-o",
            "out.png",
            "--lenmax",
            "60",
            "--adaptive",
            "--stats",
            "stats.json",
            "-q",
        ];
        args.extend_from_slice(extra);
        let out = run_in(dir.path(), &args);
        assert!(out.status.success(), "{extra:?}: {}", stderr(&out));
        let stats: serde_json::Value = read_json(dir.path(), "stats.json");
        assert_eq!(
            stats["adaptive"].as_array().unwrap().len(),
            passes,
            "{extra:?}"
        );
    }
}

/// `--form-factor hemicube` solves and renders a bundled scene with no
/// shadow ray; a hemicube resolution it cannot use is a usage error that
/// names the option and the accepted range, and writes nothing.
#[test]
fn hemicube_runs_end_to_end_and_refuses_a_bad_resolution() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("cornell.sc");
    let mut args = vec![
        scene.to_str().unwrap(),
        "-o",
        "out.png",
        "--lenmax",
        "60",
        "--form-factor",
        "hemicube",
        "--hemicube-res",
        "32",
        "--stats",
        "stats.json",
    ];
    args.extend_from_slice(QUICK);
    let out = run_in(dir.path(), &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(dir.path().join("out.png")).unwrap().to_rgb8();
    let lit = img.pixels().filter(|p| p.0.iter().any(|&c| c > 20)).count();
    assert!(
        lit > (img.width() * img.height()) as usize / 4,
        "only {lit} lit pixels"
    );
    let stats: serde_json::Value = read_json(dir.path(), "stats.json");
    assert!(stats["steps"].as_u64().unwrap() > 0);
    assert_eq!(stats["rays"].as_u64(), Some(0), "hemicubes cast no ray");

    let empty = tempfile::tempdir().unwrap();
    for bad in ["0", "7", "100000", "many"] {
        let out = run_in(
            empty.path(),
            &[
                scene.to_str().unwrap(),
                "-o",
                "out.png",
                "--form-factor",
                "hemicube",
                "--hemicube-res",
                bad,
            ],
        );
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        let message = stderr(&out);
        assert!(
            message
                .contains("--hemicube-res must be an even whole number of pixels from 8 to 4096"),
            "{bad}: {message}"
        );
        assert!(
            message.contains(&format!("got `{bad}`")),
            "{bad}: {message}"
        );
    }
    assert!(listing(empty.path()).is_empty());
}

/// Without `--lenmax`, a scene whose default mesh is over the vertex
/// budget is cut coarser, and one line before the solve says so (under
/// `-q` too, as the load warnings) and that the mesh will be refined once;
/// with `--no-adaptive` the line says nothing of a refinement, and with
/// `--lenmax` the line is not there.
/// The scene: 150 unit squares stacked 0.001 apart, 504,600 vertices at
/// the default lenmax 0.017776, 453,750 at the budget's 0.0186.
#[test]
fn a_default_mesh_over_the_vertex_budget_is_coarsened_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("material wall color 1 1 1 k_diffrefl 0.5 end\n");
    for k in 0..150 {
        let z = k as f64 * 0.001;
        text += &format!(
            "polygon wall vertex 0 0 {z} vertex 1 0 {z} vertex 1 1 {z} vertex 0 1 {z} end\n"
        );
    }
    let scene = write(dir.path(), "stack.sc", &text);
    let scene = scene.to_str().unwrap();
    let quick = ["-q", "--size", "32x24", "-o", "out.png"];
    let out = run_in(
        dir.path(),
        &[&[scene, "--stats", "a.json"], &quick[..]].concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let said = stderr(&out);
    let line = format!(
        "{scene}: warning: mesh coarsened to lenmax 0.0186 (an estimated 454,000 vertices, \
         within the budget of 470,000; the default 0.01778 would give 505,000): \
         give --lenmax for a finer one"
    );
    let refined = "; once solved, up to 5,000 of its elements where the light changes most \
                   are split and solved again (--no-adaptive keeps it)\n";
    assert!(said.contains(&format!("{line}{refined}")), "{said}");
    let stats = read_json(dir.path(), "a.json");
    assert_eq!(stats["lenmax"].as_f64().unwrap() as f32, 0.0186);
    assert_eq!(stats["vertices"], 453_750);

    let kept = [scene, "--no-adaptive", "--stats", "k.json"];
    let out = run_in(dir.path(), &[&kept[..], &quick[..]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(&format!("{line}\n")),
        "{}",
        stderr(&out)
    );

    let given = [scene, "--lenmax", "0.02", "--stats", "b.json"];
    let out = run_in(dir.path(), &[&given[..], &quick[..]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("coarsened"), "{}", stderr(&out));
    let stats = read_json(dir.path(), "b.json");
    assert_eq!(stats["lenmax"].as_f64().unwrap() as f32, 0.02);
    assert_eq!(stats["vertices"], 150 * 52 * 52);
}

/// `--tail` hands the light left to the particle tail, which carries all
/// of it: the run ends converged with nothing unshot, the summary says
/// how many particles it traced, and `--stats` has the same count: a
/// quarter of `--tail-particles` per element vertex in each of at most
/// four tail steps.
#[test]
fn the_particle_tail_carries_the_rest_and_the_summary_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell.sc");
    let out = run_in(
        dir.path(),
        &[
            cornell.to_str().unwrap(),
            "--lenmax",
            "50",
            "--tail",
            "0.5",
            "--tail-particles",
            "40",
            "-o",
            "c.png",
            "--stats",
            "s.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let stats = read_json(dir.path(), "s.json");
    let (vertices, particles) = (
        stats["vertices"].as_u64().unwrap(),
        stats["particles"].as_u64().unwrap(),
    );
    let steps = particles / (10 * vertices);
    assert_eq!(particles, steps * 10 * vertices, "{particles} {vertices}");
    assert!((1..=4).contains(&steps), "{steps} tail steps");
    assert_eq!(stats["unshot_fraction"].as_f64(), Some(0.0));
    assert_eq!(stats["converged"].as_bool(), Some(true));
    let said = stderr(&out);
    let millions = format!("(the tail by {:.1} M particles)", particles as f64 / 1e6);
    assert!(said.contains(&millions), "{said}");
}
