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
