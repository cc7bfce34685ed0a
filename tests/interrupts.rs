//! Interrupts in every phase of a batch run: SIGINT and SIGTERM end the
//! run with exit code 130 within a bound far below what the phase would
//! otherwise take (loading and splitting, the illuminance gather, drawing
//! and writing a large picture), the message names exactly the files
//! written, and no temporary file is left behind. The next run removes the
//! temporaries a killed run left.

#![cfg(unix)]

mod common;

use common::*;
use std::path::Path;
use std::process::{Child, Command, ExitStatus};
use std::time::{Duration, Instant};

/// How long an interrupted run may take to exit: generous for a loaded
/// two-core machine, while each phase interrupted below would otherwise
/// take far longer.
const BOUND: Duration = Duration::from_secs(3);

/// Sends `sig` and returns the exit status, the seconds it took and the
/// child's stderr.
fn interrupt(child: &mut Child, sig: &str) -> (ExitStatus, Duration, String) {
    let t = Instant::now();
    signal(child, sig);
    let status = wait_at_most(child, Duration::from_secs(60));
    let took = t.elapsed();
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut err);
    }
    (status, took, err)
}

/// The temporaries (`.radiosity-*`) in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    listing(dir)
        .into_iter()
        .filter(|n| n.starts_with(".radiosity-"))
        .collect()
}

/// An OBJ of `3k` squares in three families of `k` parallel planes, each
/// square cut by the `2k` squares of the other families: `3k (k + 1)²`
/// pieces to split, mesh, stitch and put in a BVH.
fn crossing_planes(dir: &Path, k: usize) -> std::path::PathBuf {
    let mut obj = String::new();
    let mut v = 1;
    for axis in 0..3 {
        for i in 0..k {
            let t = -1.0 + 2.0 * (i as f64 + 0.5) / k as f64;
            for (a, b) in [(-1.01, -1.01), (1.01, -1.01), (1.01, 1.01), (-1.01, 1.01)] {
                let mut p = [0.0; 3];
                p[axis] = t;
                p[(axis + 1) % 3] = a;
                p[(axis + 2) % 3] = b;
                obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
            }
            obj.push_str(&format!("f {} {} {} {}\n", v, v + 1, v + 2, v + 3));
            v += 4;
        }
    }
    write(dir, "planes.obj", &obj)
}

#[test]
fn an_interrupt_while_loading_and_splitting_acts_at_once() {
    for sig in ["INT", "TERM"] {
        let dir = tempfile::tempdir().unwrap();
        let obj = crossing_planes(dir.path(), 40);
        // Splitting into 201,720 pieces, meshing and stitching them take
        // many seconds.
        let mut child = spawn_in(
            dir.path(),
            &[obj.to_str().unwrap(), "-o", "out.png", "--stats", "s.json"],
        );
        std::thread::sleep(Duration::from_millis(700));
        assert!(child.try_wait().unwrap().is_none(), "finished too early");
        let (status, took, err) = interrupt(&mut child, sig);
        assert_eq!(status.code(), Some(130), "{sig}: {err}");
        assert!(took < BOUND, "{sig}: took {took:?}: {err}");
        assert!(
            err.contains("interrupted after 0 steps; nothing was written"),
            "{sig}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(listing(dir.path()), vec!["planes.obj".to_string()]);
    }
}

#[test]
fn an_interrupt_during_the_illuminance_gather_names_what_was_written() {
    let dir = tempfile::tempdir().unwrap();
    // 200,000 points: a gather of a minute or more on two cores.
    let mut points = String::new();
    let mut rng = Rng(7);
    for _ in 0..200_000 {
        let mut at = || 50.0 + 450.0 * (rng.next() % 10_000) as f64 / 10_000.0;
        points.push_str(&format!("{},{},{},0,1,0\n", at(), at(), at()));
    }
    write(dir.path(), "points.csv", &points);
    let cornell = scene("cornell.sc");
    let mut child = spawn_in(
        dir.path(),
        &[
            cornell.to_str().unwrap(),
            "--max-steps",
            "5",
            "--size",
            "64x64",
            "-o",
            "a.png",
            "--export",
            "a.ply",
            "--stats",
            "a.json",
            "--illuminance-at",
            "points.csv",
            "--illuminance-out",
            "e.csv",
        ],
    );
    // The picture and the export are written before the gather starts.
    let start = Instant::now();
    while !dir.path().join("a.ply").exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "ended before the gather"
        );
        assert!(start.elapsed() < Duration::from_secs(120), "no export");
        std::thread::sleep(Duration::from_millis(5));
    }
    std::thread::sleep(Duration::from_millis(300));
    assert!(child.try_wait().unwrap().is_none(), "the gather ended");
    let (status, took, err) = interrupt(&mut child, "TERM");
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(took < BOUND, "took {took:?}: {err}");
    assert!(
        err.contains("interrupted after 5 steps; wrote a.png, a.ply; not written: a.json, e.csv"),
        "{err}"
    );
    assert!(!err.contains("nothing was written"), "{err}");
    assert_eq!(
        listing(dir.path()),
        vec!["a.ply", "a.png", "points.csv"],
        "{err}"
    );
}

#[test]
fn an_interrupt_while_drawing_or_writing_a_large_picture_tells_the_truth() {
    // Interrupted at times that fall in drawing, tone mapping, encoding
    // and writing a 4096 × 4096 picture over an older one, or after: in
    // every case the run ends within the bound, no temporary is left, and
    // the message says the picture was written exactly when it was.
    let cornell = scene("cornell.sc");
    for delay_ms in [300, 900, 1500, 2200, 3000] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("big.png"), b"old").unwrap();
        let mut child = spawn_in(
            dir.path(),
            &[
                cornell.to_str().unwrap(),
                "--max-steps",
                "1",
                "--size",
                "4096x4096",
                "-o",
                "big.png",
                "--stats",
                "s.json",
            ],
        );
        std::thread::sleep(Duration::from_millis(delay_ms));
        if child.try_wait().unwrap().is_some() {
            // The run finished before this delay: later ones would too.
            break;
        }
        let (status, took, err) = interrupt(&mut child, "INT");
        let replaced = std::fs::read(dir.path().join("big.png")).unwrap() != b"old";
        assert!(temporaries(dir.path()).is_empty(), "{err}");
        if status.code() == Some(0) {
            // The signal came as the run ended.
            assert!(replaced);
            continue;
        }
        assert_eq!(status.code(), Some(130), "{delay_ms} ms: {err}");
        assert!(took < BOUND, "{delay_ms} ms: took {took:?}: {err}");
        if replaced {
            assert!(
                err.contains("wrote big.png; not written: s.json"),
                "{delay_ms} ms: {err}"
            );
        } else {
            assert!(err.contains("nothing was written"), "{delay_ms} ms: {err}");
        }
        assert!(!dir.path().join("s.json").exists(), "{err}");
    }
}

#[test]
fn the_next_run_removes_the_temporaries_of_a_killed_one() {
    let dir = tempfile::tempdir().unwrap();
    // A writer that has ended, as a run killed by SIGKILL has.
    let mut gone = Command::new("true").spawn().unwrap();
    let pid = gone.id();
    gone.wait().unwrap();
    let left = format!(".radiosity-{pid}-Ab12Cd");
    std::fs::write(dir.path().join(&left), vec![0u8; 2_000_000]).unwrap();
    std::fs::write(dir.path().join("keep.txt"), b"x").unwrap();
    let cornell = scene("cornell.sc");
    let out = run_in(
        dir.path(),
        &[
            cornell.to_str().unwrap(),
            "--max-steps",
            "1",
            "--size",
            "32x32",
            "-o",
            "a.png",
            "-q",
        ],
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("note: removed 1 temporary file (2.0 MB) that a killed run left in ."),
        "{err}"
    );
    assert_eq!(listing(dir.path()), vec!["a.png", "keep.txt"], "{err}");
}
