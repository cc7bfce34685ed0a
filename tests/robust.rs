//! Whole-program robustness: Ctrl-C, checkpoints and resume, resource
//! limits, absurd inputs and output safety.

mod common;

use common::*;
use std::process::Child;
use std::time::{Duration, Instant};

fn child_stderr(child: &mut Child) -> String {
    use std::io::Read;
    let mut s = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut s);
    }
    s
}

#[cfg(unix)]
#[test]
fn ctrl_c_stops_promptly_writes_nothing_and_exits_130() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("rtable.sc");
    // Threshold 0: the solve would go on for minutes.
    let mut child = spawn_in(
        dir.path(),
        &[
            scene.to_str().unwrap(),
            "-o",
            "out.png",
            "--stats",
            "stats.json",
            "--threshold",
            "0",
        ],
    );
    std::thread::sleep(Duration::from_millis(1500));
    assert!(child.try_wait().unwrap().is_none(), "finished too early");
    let t = Instant::now();
    signal(&child, "INT");
    let status = wait_at_most(&mut child, Duration::from_secs(5));
    let err = child_stderr(&mut child);
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(
        t.elapsed() < Duration::from_secs(2),
        "took {:?}",
        t.elapsed()
    );
    assert!(err.contains("interrupted after"), "{err}");
    assert!(err.contains("nothing was written"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // No picture, no stats, no temporary file.
    assert_eq!(listing(dir.path()), Vec::<String>::new());
}

/// Options of the checkpoint runs: a coarse mesh, few samples and a fixed
/// number of steps, so the uninterrupted reference is quick.
const CKPT_RUN: &[&str] = &[
    "--lenmax",
    "0.12",
    "--shooter-samples",
    "16",
    "--threshold",
    "0",
    "--max-steps",
    "150",
    "-q",
];

#[cfg(unix)]
#[test]
fn interrupted_and_resumed_solve_gives_the_same_bits() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("rtable.sc");
    let scene = scene.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![scene];
        args.extend_from_slice(extra);
        args.extend_from_slice(CKPT_RUN);
        run_in(dir.path(), &args)
    };
    let full = run(&["-o", "full.pfm", "--stats", "full.json"]);
    assert!(full.status.success(), "{}", stderr(&full));

    // Interrupt at a step that differs from run to run: after the first
    // checkpoint exists, wait a random fraction of the reference solve.
    let solve_ms = {
        let stats: serde_json::Value = read_json(dir.path(), "full.json");
        (stats["seconds"]["solve"].as_f64().unwrap() * 1000.0) as u64
    };
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos() as u64;
    let mut interrupted = false;
    for attempt in 0..4u64 {
        let _ = std::fs::remove_file(dir.path().join("ck.bin"));
        let mut args = vec![
            scene,
            "-o",
            "part.pfm",
            "--checkpoint",
            "ck.bin",
            "--checkpoint-every",
            "0",
        ];
        args.extend_from_slice(CKPT_RUN);
        let mut child = spawn_in(dir.path(), &args);
        let start = Instant::now();
        while !dir.path().join("ck.bin").exists() && start.elapsed() < Duration::from_secs(30) {
            std::thread::sleep(Duration::from_millis(2));
        }
        let delay = (nanos >> attempt) % (solve_ms / 2 + 1);
        std::thread::sleep(Duration::from_millis(delay));
        signal(&child, "INT");
        let status = wait_at_most(&mut child, Duration::from_secs(10));
        let err = child_stderr(&mut child);
        if status.code() == Some(130) {
            assert!(err.contains("resume with --resume ck.bin"), "{err}");
            assert!(!dir.path().join("part.pfm").exists());
            interrupted = true;
            break;
        }
        // It finished before the signal arrived; try again sooner.
        assert!(status.success(), "{err}");
        std::fs::remove_file(dir.path().join("part.pfm")).unwrap();
    }
    assert!(interrupted, "never managed to interrupt the solve");

    let resumed = run(&[
        "-o",
        "resumed.pfm",
        "--resume",
        "ck.bin",
        "--stats",
        "resumed.json",
    ]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    let a = std::fs::read(dir.path().join("full.pfm")).unwrap();
    let b = std::fs::read(dir.path().join("resumed.pfm")).unwrap();
    assert!(
        a == b,
        "the resumed picture differs from the uninterrupted one"
    );
    let json = |name: &str| -> serde_json::Value { read_json(dir.path(), name) };
    let (f, r) = (json("full.json"), json("resumed.json"));
    for key in ["steps", "rays", "unshot_fraction", "vertices"] {
        assert_eq!(f[key], r[key], "{key}");
    }

    // The same checkpoint with another mesh is refused, clearly.
    let other = run_in(
        dir.path(),
        &[
            scene, "-o", "x.png", "--resume", "ck.bin", "--lenmax", "0.2", "-q",
        ],
    );
    assert_eq!(other.status.code(), Some(2));
    assert!(
        stderr(&other).contains("saved for a different scene"),
        "{}",
        stderr(&other)
    );
    // A damaged checkpoint too.
    let mut bytes = std::fs::read(dir.path().join("ck.bin")).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 1;
    std::fs::write(dir.path().join("bad.bin"), &bytes).unwrap();
    let mut args = vec![scene, "-o", "y.png", "--resume", "bad.bin"];
    args.extend_from_slice(CKPT_RUN);
    let bad = run_in(dir.path(), &args);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("damaged"), "{}", stderr(&bad));
    assert!(!dir.path().join("x.png").exists() && !dir.path().join("y.png").exists());
}

#[test]
fn too_many_elements_are_refused_with_a_lenmax_that_fits() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("rtable.sc");
    let scene = scene.to_str().unwrap();
    let out = run_in(
        dir.path(),
        &[scene, "-o", "out.png", "--max-elements", "2000", "-q"],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("--max-elements allows 2000"), "{err}");
    assert!(err.contains("of memory"), "{err}");
    // The suggested lenmax does fit, and is close to the smallest that does.
    let suggested = err
        .split("use --lenmax ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .unwrap_or_else(|| panic!("no suggestion in {err}"))
        .to_string();
    let l: f64 = suggested.parse().unwrap();
    let ok = run_in(
        dir.path(),
        &[
            scene,
            "-o",
            "out.png",
            "--max-elements",
            "2000",
            "--lenmax",
            &suggested,
            "--max-steps",
            "1",
            "--stats",
            "s.json",
            "-q",
        ],
    );
    assert!(ok.status.success(), "{}", stderr(&ok));
    let stats: serde_json::Value = read_json(dir.path(), "s.json");
    assert!(stats["elements"].as_u64().unwrap() <= 2000);
    let smaller = format!("{}", l * 0.98);
    let refused = run_in(
        dir.path(),
        &[
            scene,
            "-o",
            "out2.png",
            "--max-elements",
            "2000",
            "--lenmax",
            &smaller,
        ],
    );
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    // A lenmax absurdly small is refused before any allocation, quickly.
    let t = Instant::now();
    let tiny = run_in(dir.path(), &[scene, "-o", "out3.png", "--lenmax", "1e-30"]);
    assert_eq!(tiny.status.code(), Some(2), "{}", stderr(&tiny));
    assert!(t.elapsed() < Duration::from_secs(10));
    assert_eq!(listing(dir.path()), vec!["out.png", "s.json"]);
}

#[test]
fn absurd_inputs_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, &[&str], &str)] = &[
        (
            "coordinate-1e30.sc",
            &[],
            "fuzz.sc:5:10: error: number `1e30` is too large",
        ),
        ("scale-tiny-box.sc", &[], "polygon is too small"),
        ("scale-overflow.sc", &[], "overflow"),
        ("size-100000.sc", &[], "`size` 100000x100000 is too large"),
        (
            "sliver-triangle.sc",
            &["--size", "100000x100000"],
            "picture size 100000x100000 is too large",
        ),
    ];
    for (name, extra, expected) in cases {
        let path = root().join("tests").join("corpus").join("sc").join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let local = write(dir.path(), "fuzz.sc", &text);
        let mut args = vec![local.to_str().unwrap(), "-o", "out.png", "-q"];
        args.extend_from_slice(extra);
        let out = run_in(dir.path(), &args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        let expected = expected.replace("fuzz.sc", local.to_str().unwrap());
        assert!(
            err.contains(&expected),
            "{name}: expected `{expected}` in {err}"
        );
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert_eq!(listing(dir.path()), vec!["fuzz.sc"], "{name}");
    }
}

#[test]
fn outputs_never_clobber_the_input_or_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene("cornell.sc")).unwrap();
    let input = write(dir.path(), "in.sc", &text);
    let cases: &[(&[&str], &str)] = &[
        (
            &["-o", "missing/out.png"],
            "directory missing does not exist",
        ),
        (
            &["-o", "out.png", "--stats", "missing/s.json"],
            "does not exist",
        ),
        (
            &["-o", "out.png", "--checkpoint", "missing/ck"],
            "does not exist",
        ),
        (
            &["-o", "out.png", "--checkpoint", "in.sc"],
            "--checkpoint would overwrite the scene file",
        ),
        (
            &["-o", "out.png", "--stats", "./in.sc"],
            "--stats would overwrite the scene file",
        ),
        (
            &["-o", "same.png", "--stats", "same.png"],
            "must be different files",
        ),
        (
            &["-o", "out.png", "--checkpoint", "out.png"],
            "must be different files",
        ),
        (
            &["-o", "out.png", "--resume", "nothing.ckpt"],
            "nothing.ckpt: error: cannot read: ",
        ),
        (
            &["-o", "out.png", "--max-elements", "0"],
            "--max-elements must be",
        ),
        (
            &[
                "-o",
                "out.png",
                "--checkpoint",
                "c.ckpt",
                "--checkpoint-every=-1",
            ],
            "--checkpoint-every must be",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["in.sc"];
        args.extend_from_slice(extra);
        let out = run_in(dir.path(), &args);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(expected),
            "{extra:?}: {}",
            stderr(&out)
        );
        assert_eq!(listing(dir.path()), vec!["in.sc"], "{extra:?}");
    }
    // Another name for the same file is still the input.
    #[cfg(unix)]
    {
        std::fs::hard_link(&input, dir.path().join("alias.png")).unwrap();
        let out = run_in(dir.path(), &["in.sc", "-o", "alias.png"]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(
            stderr(&out).contains("-o would overwrite the scene file in.sc"),
            "{}",
            stderr(&out)
        );
    }
    assert_eq!(std::fs::read_to_string(&input).unwrap(), text);
}

/// A resumed run's `--log` continues the log of the run that saved the
/// checkpoint: the same steps, shooters, powers, unshot fractions and rays
/// as one uninterrupted run, from step 1, and its clock never goes back.
#[test]
fn a_resumed_log_continues_the_interrupted_one() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("rtable.sc");
    let scene = scene.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            scene,
            "--lenmax",
            "0.12",
            "--shooter-samples",
            "16",
            "--threshold",
            "0.01",
            "-q",
        ];
        args.extend_from_slice(extra);
        let out = run_in(dir.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
    };
    run(&["-o", "full.png", "--log", "full.csv"]);
    // Stopped by a step limit after 12 steps, then resumed to the end.
    run(&[
        "-o",
        "part.png",
        "--max-steps",
        "12",
        "--checkpoint",
        "ck.bin",
    ]);
    run(&["-o", "rest.png", "--resume", "ck.bin", "--log", "rest.csv"]);
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
    let (full, rest) = (read("full.csv"), read("rest.csv"));
    let columns = |log: &str| -> Vec<String> {
        log.lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    assert!(full.lines().count() > 13, "{full}");
    assert_eq!(columns(&full), columns(&rest));
    let seconds: Vec<f64> = rest
        .lines()
        .skip(1)
        .map(|l| l.rsplit_once(',').unwrap().1.parse().unwrap())
        .collect();
    assert!(seconds.windows(2).all(|w| w[1] >= w[0]), "{seconds:?}");
    let bytes = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert_eq!(bytes("full.png"), bytes("rest.png"));
}
