//! The photometric options end to end: what they write, what they print,
//! and how they refuse bad input (file:line:column, exit code 2, nothing
//! written).

mod common;

use common::{listing, run_in, scene, stderr, write};

/// A small lit box: fast to solve.
const ROOM: &str = "\
material lamp color 1 1 1 k_emission 1000 end
material wall color 1 1 1 k_diffrefl 0.5 end
polygon wall vertex 0 0 0 vertex 0 0 2 vertex 2 0 2 vertex 2 0 0 end
polygon wall vertex 0 2 0 vertex 2 2 0 vertex 2 2 2 vertex 0 2 2 end
polygon wall vertex 0 0 0 vertex 0 2 0 vertex 0 2 2 vertex 0 0 2 end
polygon wall vertex 2 0 0 vertex 2 0 2 vertex 2 2 2 vertex 2 2 0 end
polygon wall vertex 0 0 0 vertex 2 0 0 vertex 2 2 0 vertex 0 2 0 end
polygon wall vertex 0 0 2 vertex 0 2 2 vertex 2 2 2 vertex 2 0 2 end
polygon lamp vertex 0.8 1.99 0.8 vertex 1.2 1.99 0.8 vertex 1.2 1.99 1.2 vertex 0.8 1.99 1.2 end
camera eye 1 1 0.1 lookat 1 1 2 up 0 1 0 size 48 36 end
";

const LENMAX: &str = "0.25";

#[test]
fn illuminance_points_and_a_work_plane_are_written_in_lux_with_units() {
    let dir = tempfile::tempdir().unwrap();
    let room = write(dir.path(), "room.sc", ROOM);
    write(
        dir.path(),
        "points.csv",
        "x,y,z,nx,ny,nz\n1,0,1,0,1,0\n1,1,1,0,-1,0\n",
    );
    let out = run_in(
        dir.path(),
        &[
            room.to_str().unwrap(),
            "-q",
            "--lenmax",
            LENMAX,
            "--units",
            "m",
            "--illuminance-at",
            "points.csv",
            "--illuminance-out",
            "e.csv",
            "--workplane",
            "0.5,0.5",
            "--falsecolor",
            "fc.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.path().join("e.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("x,y,z,nx,ny,nz,e_r,e_g,e_b,e"));
    let e: Vec<f64> = lines
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(e.len(), 2);
    // The floor's centre, under the lamp, gets more than the floor gives
    // the ceiling's centre (the lamp is behind a downward-facing meter).
    assert!(e[0] > 0.0 && e[1] > 0.0 && e[0] > e[1], "{e:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("work plane at 0.5: Eavg") && stdout.contains(" lx, Emin/Eavg "),
        "{stdout}"
    );
    let plane = std::fs::read_to_string(dir.path().join("room-workplane.csv")).unwrap();
    // A 2 × 2 floor at 0.5 spacing: 16 points and the header.
    assert_eq!(plane.lines().count(), 17);
    for png in ["room-workplane.png", "fc.png", "room.png"] {
        assert!(dir.path().join(png).exists(), "{png} missing");
    }
    // Without units, a warning says the values are not lux.
    let out = run_in(
        dir.path(),
        &[
            room.to_str().unwrap(),
            "-q",
            "--lenmax",
            LENMAX,
            "--workplane",
            "0.5",
            "--workplane-out",
            "plan",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("no --units"), "{}", stderr(&out));
    assert!(dir.path().join("plan.csv").exists() && dir.path().join("plan.png").exists());
}

/// A work plane through a crate on the floor: the points inside it are
/// counted, read 0, and leave the figures alone.
#[test]
fn work_plane_points_inside_a_solid_are_left_out_of_the_figures() {
    let dir = tempfile::tempdir().unwrap();
    // A crate over the four grid points nearest the corner (0, 0).
    let room = write(
        dir.path(),
        "room.sc",
        &format!("{ROOM}box wall 0.1 0 0.1  0.9 0.9 0.9\n"),
    );
    let out = run_in(
        dir.path(),
        &[
            room.to_str().unwrap(),
            "-q",
            "--lenmax",
            LENMAX,
            "--units",
            "m",
            "--workplane",
            "0.5,0.5",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("(4 of 16 points inside solid objects or outside the walls left out"),
        "{stdout}"
    );
    let emin: f64 = stdout
        .split("Emin ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no Emin in {stdout}"));
    assert!(emin > 1.0, "{stdout}");
    let plane = std::fs::read_to_string(dir.path().join("room-workplane.csv")).unwrap();
    let zeros: Vec<&str> = plane
        .lines()
        .skip(1)
        .filter(|l| l.rsplit(',').next().unwrap().parse::<f64>().unwrap() == 0.0)
        .collect();
    assert_eq!(zeros.len(), 4, "{plane}");
    // Cell centres 0.25 and 0.75 on both floor axes.
    for l in &zeros {
        let xz: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
        assert!(xz[0] < 0.9 && xz[2] < 0.9, "{l}");
    }
}

#[test]
fn bad_points_files_are_refused_with_their_position_before_solving() {
    let dir = tempfile::tempdir().unwrap();
    let room = write(dir.path(), "room.sc", ROOM);
    write(dir.path(), "points.csv", "1,0,1,0,1,0\n1,0,oops,0,1,0\n");
    let before = listing(dir.path());
    let out = run_in(
        dir.path(),
        &[
            room.to_str().unwrap(),
            "--illuminance-at",
            "points.csv",
            "--illuminance-out",
            "e.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("points.csv:2:5: error: expected a finite number, got `oops`"),
        "{err}"
    );
    assert_eq!(listing(dir.path()), before, "something was written");
}

#[test]
fn ies_luminaires_need_units_and_a_good_file() {
    let dir = tempfile::tempdir().unwrap();
    let room = write(dir.path(), "room.sc", ROOM);
    let panel = scene("luminaires/panel.ies");
    let ies = format!("lamp={}", panel.display());
    let out = run_in(dir.path(), &[room.to_str().unwrap(), "--ies", &ies]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("--ies needs --units"),
        "{}",
        stderr(&out)
    );

    write(
        dir.path(),
        "bad.ies",
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 3 2 0 0 0\n",
    );
    let out = run_in(
        dir.path(),
        &[
            room.to_str().unwrap(),
            "--units",
            "m",
            "--ies",
            "lamp=bad.ies",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("bad.ies:3:12: error: photometric type 3 (A) is not supported"),
        "{}",
        stderr(&out)
    );
    let out = run_in(
        dir.path(),
        &[
            room.to_str().unwrap(),
            "--units",
            "m",
            "--ies",
            &format!("nothing={}", panel.display()),
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--ies nothing:"), "{}", stderr(&out));

    let out = run_in(
        dir.path(),
        &[
            room.to_str().unwrap(),
            "-q",
            "--lenmax",
            LENMAX,
            "--units",
            "m",
            "--ies",
            &ies,
            "--workplane",
            "0",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("Eavg"));
}
