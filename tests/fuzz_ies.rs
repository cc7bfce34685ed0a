//! Fuzzing the IES (LM-63) reader inside `cargo test`, in the style of
//! `tests/fuzz.rs`: a deterministic mutator (seeded PRNG, no external
//! engine) turns a seed corpus (the bundled `panel.ies` and small
//! hand-written files of every symmetry) into hostile inputs: byte flips,
//! deleted, duplicated and spliced spans, swapped lines, truncations and
//! inserted tokens (`nan`, `1e308`, `-1`, `TILT=INCLUDE`, huge counts).
//! Every input must:
//!
//! - never panic (a panic is caught and reported with the input);
//! - if rejected, name the file at a line inside the input (or one past
//!   its end, for a file that ends too soon) and a column on that line;
//! - if accepted, hold the invariants of [`Photometry`]: increasing
//!   angles within range, finite intensities `>= 0` at every direction
//!   asked.
//!
//! `RADIOSITY_FUZZ_CASES` overrides the number of cases and
//! `RADIOSITY_FUZZ_SEED` the seed.

mod common;

use common::Rng;
use radiosity::scene::Photometry;
use std::panic::{self, AssertUnwindSafe};

/// Cases of the CI run: about 4 s on two cores in the release profile.
const CASES: u64 = 200_000;

/// The fixed seed of the CI run.
const DEFAULT_SEED: u64 = 0x1e5_f022;

const FILE: &str = "fuzz.ies";

fn seeds() -> Vec<String> {
    vec![
        include_str!("../scenes/luminaires/panel.ies").to_string(),
        "IESNA:LM-63-1995\n[TEST] one plane\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 10\n\
         0 45 90\n0\n300 200 0\n"
            .to_string(),
        "IESNA91\nTILT=NONE\n2 500 0.5 3 3 1 1 1 1 0\n0.9 1 50\n0,90,180\n0,90,180\n\
         10,20,30\n11,21,31\n12,22,32\n"
            .to_string(),
        "TILT=NONE\n1 -1 1 2 5 1 2 0 0 0\n1 1 0\n90 180\n0 90 180 270 360\n\
         1 2\n3 4\n5 6\n7 8\n1 2\n"
            .to_string(),
    ]
}

const TOKENS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-1",
    "0",
    "1e-320",
    "999999999",
    "TILT=INCLUDE",
    "TILT=NONE",
    ",",
    "\n",
    "[KEY]",
    "90",
    "180",
    "360",
    "2",
    "3",
    " ",
    "\r\n",
    "é",
];

fn mutate(rng: &mut Rng, input: &mut Vec<u8>, other: &[u8]) {
    for _ in 0..1 + rng.below(4) {
        let len = input.len();
        match rng.below(7) {
            0 if len > 0 => {
                let k = rng.below(len);
                input[k] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let a = rng.below(len);
                let b = (a + rng.below(16)).min(len);
                input.drain(a..b);
            }
            2 if len > 0 => {
                let a = rng.below(len);
                let b = (a + rng.below(32)).min(len);
                let span = input[a..b].to_vec();
                let at = rng.below(len);
                input.splice(at..at, span);
            }
            3 if !other.is_empty() => {
                let a = rng.below(other.len());
                let b = (a + rng.below(64)).min(other.len());
                let at = rng.below(len + 1);
                input.splice(at..at, other[a..b].iter().copied());
            }
            4 => input.truncate(rng.below(len + 1)),
            5 => {
                let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
                let at = rng.below(len + 1);
                input.splice(at..at, token.iter().copied());
            }
            _ => {
                let text = String::from_utf8_lossy(input).into_owned();
                let mut lines: Vec<&str> = text.lines().collect();
                if lines.len() > 1 {
                    let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
                    lines.swap(a, b);
                }
                *input = lines.join("\n").into_bytes();
            }
        }
    }
}

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn check(text: &str) -> Result<(), String> {
    match Photometry::parse(text, FILE) {
        Err(e) => {
            let lines = text.lines().count();
            let located = e.file == FILE
                && e.line >= 1
                && e.line <= lines.max(1) + 1
                && e.column >= 1
                && e.column
                    <= text
                        .lines()
                        .nth(e.line - 1)
                        .map_or(1, |l| l.chars().count() + 1);
            if !located || !e.to_string().starts_with("fuzz.ies:") {
                return Err(format!("rejection not located: {e}"));
            }
            Ok(())
        }
        Ok(p) => {
            let increasing = |a: &[f64]| a.windows(2).all(|w| w[1] > w[0]);
            if !increasing(&p.vertical) || !increasing(&p.horizontal) {
                return Err("angles do not increase".into());
            }
            if p.vertical
                .iter()
                .any(|v| !(0.0..=std::f64::consts::PI).contains(v))
            {
                return Err("a vertical angle out of range".into());
            }
            if p.candela.len() != p.vertical.len() * p.horizontal.len() {
                return Err("the table has the wrong size".into());
            }
            for k in 0..64 {
                let theta = k as f64 / 63.0 * std::f64::consts::PI;
                let phi = k as f64 * 0.7 - 3.0;
                let i = p.intensity(theta, phi);
                if !(i.is_finite() && i >= 0.0) {
                    return Err(format!("intensity {i} at ({theta}, {phi})"));
                }
            }
            Ok(())
        }
    }
}

#[test]
fn fuzz_ies() {
    common::limit_address_space();
    let cases = env_u64("RADIOSITY_FUZZ_CASES", CASES);
    let seed = env_u64("RADIOSITY_FUZZ_SEED", DEFAULT_SEED);
    let seeds = seeds();
    let mut rng = Rng(seed);
    let (mut accepted, mut rejected) = (0u64, 0u64);
    panic::set_hook(Box::new(|_| {}));
    for case in 0..cases {
        let base = &seeds[rng.below(seeds.len())];
        let other = &seeds[rng.below(seeds.len())];
        let mut input = base.clone().into_bytes();
        mutate(&mut rng, &mut input, other.as_bytes());
        // The reader takes text: files are read as Latin-1.
        let text: String = input.iter().map(|&b| b as char).collect();
        let outcome = panic::catch_unwind(AssertUnwindSafe(|| check(&text)));
        match outcome {
            Ok(Ok(())) => {
                if Photometry::parse(&text, FILE).is_ok() {
                    accepted += 1;
                } else {
                    rejected += 1;
                }
            }
            Ok(Err(why)) => {
                let _ = panic::take_hook();
                panic!("seed {seed:#x}, case {case}: {why}\ninput:\n{text}");
            }
            Err(_) => {
                let _ = panic::take_hook();
                panic!("seed {seed:#x}, case {case}: the reader panicked\ninput:\n{text}");
            }
        }
    }
    let _ = panic::take_hook();
    // The corpus must reach both outcomes, or the mutator tests nothing.
    assert!(accepted > cases / 50, "only {accepted} of {cases} accepted");
    assert!(rejected > cases / 50, "only {rejected} of {cases} rejected");
}
