//! `--daylight-factor` through the binary: daylight factors on a work
//! plane under the CIE overcast sky, checked against closed forms and an
//! independent integral of a window's sky component.

mod common;

use common::daylight::*;
use common::*;

/// The `DF mean … %, DF min … %` figures a run printed.
fn daylight_factors(out: &std::process::Output) -> (f64, f64) {
    let figure = |key| printed_figure(out, "daylight factor at", key);
    (figure("DF mean "), figure("DF min "))
}

/// Under an open roof every point sees the whole sky: a daylight factor
/// of 100 %.
#[test]
fn the_daylight_factor_under_an_open_roof_is_a_hundred_percent() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_floor(dir.path(), &["--sky", "cie-overcast", "--daylight-factor"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (mean, min) = daylight_factors(&out);
    assert!(
        (mean - 100.0).abs() < 1.0 && (min - 100.0).abs() < 1.0,
        "{mean} {min}"
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("DF >= 2 % over 100.0 % of the plane (needs 50 %): met"),
        "{text}"
    );
    assert!(dir.path().join("floor-workplane-df.png").exists());
}

/// A black room 4 × 4 × 3 m with an opening 2 × 1 m in its wall at z = 0
/// (x 1 to 3, y 1 to 2): nothing inside reflects, so a point's daylight
/// factor is the window's sky component alone.
const BLACK_ROOM: &str = "material black\n  color 0 0 0\nend\n\
polygon black\n  vertex 0 0 0\n  vertex 4 0 0\n  vertex 4 0 -4\n  vertex 0 0 -4\nend\n\
polygon black\n  vertex 0 3 0\n  vertex 0 3 -4\n  vertex 4 3 -4\n  vertex 4 3 0\nend\n\
polygon black\n  vertex 0 0 -4\n  vertex 4 0 -4\n  vertex 4 3 -4\n  vertex 0 3 -4\nend\n\
polygon black\n  vertex 0 0 0\n  vertex 0 0 -4\n  vertex 0 3 -4\n  vertex 0 3 0\nend\n\
polygon black\n  vertex 4 0 0\n  vertex 4 3 0\n  vertex 4 3 -4\n  vertex 4 0 -4\nend\n\
polygon black\n  vertex 0 0 0\n  vertex 0 1 0\n  vertex 4 1 0\n  vertex 4 0 0\nend\n\
polygon black\n  vertex 0 2 0\n  vertex 0 3 0\n  vertex 4 3 0\n  vertex 4 2 0\nend\n\
polygon black\n  vertex 0 1 0\n  vertex 0 2 0\n  vertex 1 2 0\n  vertex 1 1 0\nend\n\
polygon black\n  vertex 3 1 0\n  vertex 3 2 0\n  vertex 4 2 0\n  vertex 4 1 0\nend\n";

/// The sky component at `p` (facing up) of the opening x 1..3, y 1..2 in
/// the plane z = 0, under the CIE overcast sky: `∫ L cos θ dω` over the
/// opening, by the midpoint rule on a 400 × 200 grid of it, over the
/// unobstructed `7π Lz / 9`; written apart from the program's sky.
fn sky_component(p: [f64; 3]) -> f64 {
    let (nx, ny) = (400, 200);
    let (dx, dy) = (2.0 / nx as f64, 1.0 / ny as f64);
    let mut e = 0.0;
    for i in 0..nx {
        for j in 0..ny {
            let w = [
                1.0 + (i as f64 + 0.5) * dx,
                1.0 + (j as f64 + 0.5) * dy,
                0.0,
            ];
            let v = [w[0] - p[0], w[1] - p[1], w[2] - p[2]];
            let r2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            let r = r2.sqrt();
            let (up, out) = (v[1] / r, v[2] / r);
            let luminance = (1.0 + 2.0 * up) / 3.0;
            e += luminance * up * out / r2 * dx * dy;
        }
    }
    e / (7.0 * std::f64::consts::PI / 9.0)
}

/// Each point's daylight factor in a black room is the opening's sky
/// component, integrated here apart from the program (within 4 % of it,
/// the sky facets' sampling: measured at most 3.3 %), near the window and
/// at the back of the room, where the window shows only the dark band of
/// the overcast sky near the horizon (read at the facets' mean
/// luminance, the deepest point would be 13 % high).
#[test]
fn a_windows_sky_component_matches_an_independent_integral() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "room.sc", BLACK_ROOM);
    let points = [
        [2.0, 0.5, -1.0],
        [2.0, 0.5, -2.5],
        [1.0, 0.5, -1.5],
        [3.5, 0.5, -3.0],
        [2.0, 0.5, -3.9],
    ];
    let csv: String = points
        .iter()
        .map(|p| format!("{},{},{},0,1,0\n", p[0], p[1], p[2]))
        .collect();
    write(dir.path(), "points.csv", &csv);
    let out = run_in(
        dir.path(),
        &[
            "room.sc",
            "--units",
            "m",
            "--sky",
            "cie-overcast,10000lx",
            "--illuminance-at",
            "points.csv",
            "--illuminance-out",
            "e.csv",
            "-o",
            "room.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let values = std::fs::read_to_string(dir.path().join("e.csv")).unwrap();
    for (p, line) in points.iter().zip(values.lines().skip(1)) {
        let e: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
        let (got, want) = (e / 10_000.0, sky_component(*p));
        assert!(want > 0.005, "{p:?}: {want}");
        assert!(
            (got - want).abs() < 0.04 * want,
            "{p:?}: DF {got} vs SC {want}"
        );
    }
}

/// The daylight factor is that of the overcast sky on a work plane.
#[test]
fn the_daylight_factor_needs_a_work_plane_and_the_overcast_sky() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "floor.sc", FLOOR);
    let cases: [(&[&str], &str); 2] = [
        (
            &["--units", "m", "--sky", "cie-overcast", "--daylight-factor"],
            "--daylight-factor needs --workplane",
        ),
        (
            &[
                "--units",
                "m",
                "--sky",
                "cie-clear",
                "--sun",
                "180,30",
                "--daylight-factor",
                "--workplane",
                "0",
            ],
            "--daylight-factor needs --sky cie-overcast",
        ),
    ];
    assert_refused(dir.path(), &cases);
}

/// The bundled side-lit office, as the guide runs it: the daylight factor
/// falls from the window to the back wall.
#[test]
fn the_bundled_office_prints_its_daylight_factors_and_writes_the_plan() {
    let dir = tempfile::tempdir().unwrap();
    let office = scene("daylight-office.sc");
    let out = run_in(
        dir.path(),
        &[
            office.to_str().unwrap(),
            "--units",
            "m",
            "--sky",
            "cie-overcast",
            "--daylight-factor",
            "--workplane",
            "0.8",
            "--no-window",
            "-o",
            "x.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let (mean, min) = daylight_factors(&out);
    assert!(min > 0.0 && mean > 2.0 * min, "{mean} {min}");
    assert!(dir.path().join("daylight-office-workplane-df.png").exists());
    // Row by row from the window (z = 0) to the back: the first row is
    // brighter than the last.
    let csv = std::fs::read_to_string(dir.path().join("daylight-office-workplane.csv")).unwrap();
    let rows: Vec<(f64, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (f[2], f[9])
        })
        .collect();
    let near: f64 = rows.iter().filter(|r| r.0 > -1.0).map(|r| r.1).sum();
    let far: f64 = rows.iter().filter(|r| r.0 < -5.0).map(|r| r.1).sum();
    assert!(near > 5.0 * far, "{near} vs {far}");
}
