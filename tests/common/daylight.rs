//! The open floor the daylight tests solve under a sky: a surface nothing
//! shades, so its illuminance is the sky's own horizontal illuminance.

use super::{run_in, write};
use std::path::Path;
use std::process::Output;

/// An open floor 10 × 10 m of reflectance 0.5 at y = 0, facing up.
pub const FLOOR: &str = "material floor\n  color 0.5 0.5 0.5\n  k_diffrefl 1\nend\n\
polygon floor\n  vertex 0 0 0\n  vertex 10 0 0\n  vertex 10 0 -10\n  vertex 0 0 -10\nend\n";

/// Writes [`FLOOR`] into `dir` and solves it in metres with a work plane
/// 1 m apart at the floor (`--workplane 0,1`), under the sky options
/// `sky` (`["--sky", "cie-overcast"]` and so on).
pub fn run_floor(dir: &Path, sky: &[&str]) -> Output {
    write(dir, "floor.sc", FLOOR);
    let args = [
        &[
            "floor.sc",
            "--units",
            "m",
            "--workplane",
            "0,1",
            "-o",
            "f.png",
        ][..],
        sky,
    ]
    .concat();
    run_in(dir, &args)
}

/// Runs `floor.sc` (already written into `dir`) with each case's options
/// and checks the run is refused as bad usage: exit 2, the error saying
/// the case's text, and no picture written.
pub fn assert_refused(dir: &Path, cases: &[(&[&str], &str)]) {
    for (args, says) in cases {
        let out = run_in(dir, &[&["floor.sc", "-o", "f.png"][..], args].concat());
        let err = super::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!dir.join("f.png").exists(), "{args:?}");
    }
}

/// The number after `key` (e.g. `"Eavg "`) on the first line of the run's
/// standard output that starts with `line` (e.g. `"work plane at"`);
/// panics, with the output, when either is missing.
pub fn printed_figure(out: &Output, line: &str, key: &str) -> f64 {
    let text = String::from_utf8_lossy(&out.stdout);
    let found = text
        .lines()
        .find(|l| l.starts_with(line))
        .unwrap_or_else(|| panic!("no {line:?} line in {text:?} ({})", super::stderr(out)));
    let at = found
        .find(key)
        .unwrap_or_else(|| panic!("no {key:?} in {found}"))
        + key.len();
    found[at..]
        .split_whitespace()
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no number after {key:?} in {found}"))
}
