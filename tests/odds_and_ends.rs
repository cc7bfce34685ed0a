//! What a user hits in a first hour beyond help and errors: `.hdr`
//! pictures, `--threshold 0`, `--exposure` in stops, the warning when
//! `--sky` cannot reach a closed room.

mod common;

use common::*;

/// A `.pfm`'s pixels, top row first, three floats each.
fn read_pfm(path: &std::path::Path) -> (u32, u32, Vec<[f32; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    let text_end = bytes
        .iter()
        .enumerate()
        .filter(|(_, &b)| b == b'\n')
        .nth(2)
        .unwrap()
        .0;
    let header = String::from_utf8_lossy(&bytes[..text_end]).into_owned();
    let mut words = header.split_whitespace().skip(1);
    let w: u32 = words.next().unwrap().parse().unwrap();
    let h: u32 = words.next().unwrap().parse().unwrap();
    let floats: Vec<f32> = bytes[text_end + 1..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let rows: Vec<&[f32]> = floats.chunks_exact(3 * w as usize).collect();
    let pixels = rows
        .iter()
        .rev()
        .flat_map(|r| r.chunks_exact(3).map(|p| [p[0], p[1], p[2]]))
        .collect();
    (w, h, pixels)
}

/// `-o X.hdr` writes a Radiance RGBE picture of the same linear values
/// as `-o X.pfm`, to RGBE's precision (within a 128th of each pixel's
/// largest channel).
#[test]
fn hdr_pictures_hold_the_pfm_values_to_rgbe_precision() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell.sc");
    for out in ["a.hdr", "a.pfm"] {
        let run = run_in(
            dir.path(),
            &[
                cornell.to_str().unwrap(),
                "-o",
                out,
                "--lenmax",
                "60",
                "--max-steps",
                "10",
                "--size",
                "40x30",
                "-q",
            ],
        );
        assert!(run.status.success(), "{out}: {}", stderr(&run));
    }
    let hdr = image::open(dir.path().join("a.hdr")).unwrap().into_rgb32f();
    let (w, h, pfm) = read_pfm(&dir.path().join("a.pfm"));
    assert_eq!(hdr.dimensions(), (w, h));
    let mut lit = 0;
    for (got, want) in hdr.pixels().zip(&pfm) {
        let largest = want.iter().copied().fold(0.0f32, f32::max);
        lit += usize::from(largest > 0.0);
        for (g, v) in got.0.iter().zip(want) {
            assert!((g - v).abs() <= largest / 128.0, "{:?} for {want:?}", got.0);
        }
    }
    assert!(lit > pfm.len() / 2, "only {lit} lit pixels");
}

/// `--exposure` counts stops from the automatic exposure: 0 is the
/// automatic picture bit for bit, +2 four times the factor (a brighter
/// picture), -1 half of it; the summary and `--stats` give the automatic
/// value and the stops.
#[test]
fn exposure_is_in_stops_from_the_automatic_one() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell.sc");
    let run = |name: &str, stops: Option<&str>| {
        let png = format!("{name}.png");
        let json = format!("{name}.json");
        let mut args = vec![
            cornell.to_str().unwrap(),
            "-o",
            &png,
            "--stats",
            &json,
            "--lenmax",
            "60",
            "--max-steps",
            "20",
            "--size",
            "48x48",
        ];
        if let Some(stops) = stops {
            args.extend(["--exposure", stops]);
        }
        let out = run_in(dir.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
        let stats = read_json(dir.path(), &json);
        let picture = image::open(dir.path().join(&png)).unwrap().to_rgb8();
        let mean = picture.pixels().map(|p| f64::from(p.0[1])).sum::<f64>()
            / f64::from(picture.width() * picture.height());
        (stderr(&out), stats, picture, mean)
    };
    let (said, auto, picture, mean) = run("auto", None);
    let factor = auto["exposure"].as_f64().unwrap();
    assert_eq!(auto["auto_exposure"].as_f64(), Some(factor));
    assert_eq!(auto["exposure_stops"].as_f64(), Some(0.0));
    assert!(said.contains(", exposure "), "{said}");
    assert!(said.contains(" (automatic) → auto.png"), "{said}");

    let (_, zero, same, _) = run("zero", Some("0"));
    assert_eq!(zero["exposure"].as_f64(), Some(factor));
    assert!(same == picture, "--exposure 0 is the automatic picture");

    let (said, up, _, brighter) = run("up", Some("2"));
    assert_eq!(up["auto_exposure"].as_f64(), Some(factor));
    let four = up["exposure"].as_f64().unwrap() / factor;
    assert!((four - 4.0).abs() < 1e-6, "{four}");
    assert!(said.contains("+2 stops) → up.png"), "{said}");
    assert!(brighter > mean * 1.3, "{brighter} against {mean}");

    let (_, down, _, darker) = run("down", Some("-1"));
    let half = down["exposure"].as_f64().unwrap() / factor;
    assert!((half - 0.5).abs() < 1e-6, "{half}");
    assert!(darker < mean, "{darker} against {mean}");
}

/// `--sky` on a closed room (rtable: its camera sees no opening, and the
/// sky's light lights nothing inside) gets one warning saying so, even
/// with `-q`, also in `--stats`; the open Cornell box (no front wall)
/// gets none, nor does the room without a sky.
#[test]
fn a_sky_that_cannot_reach_a_closed_room_is_said_once() {
    let warning = "warning: --sky: no sky light reaches the scene (it is closed)";
    let dir = tempfile::tempdir().unwrap();
    let run = |scene_name: &str, lenmax: &str, sky: bool| {
        let scene = scene(scene_name);
        let mut args = vec![
            scene.to_str().unwrap().to_string(),
            "-o".into(),
            "out.png".into(),
            "--stats".into(),
            "stats.json".into(),
            "--lenmax".into(),
            lenmax.into(),
            "--size".into(),
            "32x24".into(),
            "-q".into(),
        ];
        if sky {
            args.extend(["--sky".into(), "1".into()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_in(dir.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
        let stats = read_json(dir.path(), "stats.json");
        let in_stats = stats["warnings"]
            .as_array()
            .is_some_and(|w| w.iter().any(|w| w.as_str().unwrap().starts_with(warning)));
        (stderr(&out).matches(warning).count(), in_stats)
    };
    assert_eq!(run("rtable.sc", "1", true), (1, true));
    assert_eq!(run("rtable.sc", "1", false), (0, false));
    assert_eq!(run("cornell.sc", "60", true), (0, false));
}

/// Whether `name` (a file in the repository's top folder) matches the
/// `.gitignore` pattern `pattern` (`*` wildcards, an optional leading `/`).
fn glob(pattern: &str, name: &str) -> bool {
    let pattern = pattern.trim_start_matches('/');
    if pattern.contains('/') {
        return false;
    }
    let parts: Vec<&str> = pattern.split('*').collect();
    let (first, last) = (parts[0], parts[parts.len() - 1]);
    if parts.len() == 1 {
        return name == pattern;
    }
    if !name.starts_with(first) || !name[first.len()..].ends_with(last) {
        return false;
    }
    let mut rest = &name[first.len()..name.len() - last.len()];
    for middle in &parts[1..parts.len() - 1] {
        match rest.find(middle) {
            Some(at) => rest = &rest[at + middle.len()..],
            None => return false,
        }
    }
    true
}

/// Whether the repository's `.gitignore` ignores `name` in its top folder.
fn ignored(name: &str) -> bool {
    let text = std::fs::read_to_string(root().join(".gitignore")).unwrap();
    let mut ignored = false;
    for line in text.lines().map(str::trim) {
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match line.strip_prefix('!') {
            Some(p) if glob(p, name) => ignored = false,
            None if glob(line, name) => ignored = true,
            _ => {}
        }
    }
    ignored
}

/// Every file a run writes under its default name, and the outputs the
/// guide's commands name, are ignored by git: running the program in the
/// repository leaves `git status` clean.
#[test]
fn the_gitignore_covers_what_the_program_writes() {
    let dir = tempfile::tempdir().unwrap();
    let office = scene("office.sc");
    // Without -o or --workplane-out: the picture and the work plane under
    // their default names.
    let out = run_in(
        dir.path(),
        &[
            office.to_str().unwrap(),
            "--no-window",
            "--units",
            "m",
            "--workplane",
            "0.8",
            "--lenmax",
            "1",
            "--max-steps",
            "2",
            "--size",
            "32x24",
            "-q",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let mut written = listing(dir.path());
    assert_eq!(
        written,
        ["office-workplane.csv", "office-workplane.png", "office.png"]
    );
    // The window's w and p pictures (viewer::next_auto_name), a killed
    // run's temporary (output::Temporary), and what the guide's commands
    // write under names of their own.
    written.extend(
        [
            "office-001.tiff",
            "office.tiff",
            ".radiosity-1234-a1b2c3",
            "room.exr",
            "room.pfm",
            "room.hdr",
            "room.tif",
            "big.ckpt",
            "room.glb",
            "room.ply",
            "stats.json",
            "steps.csv",
            "lux.csv",
        ]
        .map(String::from),
    );
    for name in &written {
        assert!(ignored(name), "{name} is not ignored");
    }
    for kept in ["Cargo.toml", "README.md", "room.sc", "room.obj", "room.mtl"] {
        assert!(!ignored(kept), "{kept} is ignored");
    }
}
