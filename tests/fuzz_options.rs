//! Fuzzing what the loaders in `tests/fuzz.rs` and `tests/fuzz_ies.rs` do
//! not cover: the command line, the measurement-points CSV and the
//! checkpoint reader, in the same style (a deterministic mutator on a seed
//! corpus, every case caught if it panics, every case under the address
//! space limit of [`common::limit_address_space`]).
//!
//! - `options`: random command lines built from the program's own option
//!   table (every long option, with hostile values: `nan`, `-1`, `1e308`,
//!   empty, control characters, huge sizes) go through the parser and the
//!   validation into an [`Invocation`]. A refusal must carry a one-line
//!   message (clap's own may be longer: it must name the offending
//!   argument); an accepted invocation must hold the ranges the run relies
//!   on (finite, positive sizes, thresholds within their ranges).
//! - `points`: mutated CSV files go through [`parse_points`]; a refusal is
//!   located at a line and column inside the input; accepted points are
//!   finite with unit normals.
//! - `checkpoint`: a real checkpoint of a small solve, mutated and (in most
//!   cases) resealed with a valid checksum so that the mutation reaches the
//!   checks behind it, is decoded and restored into a fresh session of the
//!   same solve; a restored state must pass the solver's invariants, and
//!   one more step must leave every value finite.
//!
//! `RADIOSITY_FUZZ_CASES` overrides the number of cases per target and
//! `RADIOSITY_FUZZ_SEED` the seed.

mod common;

use common::Rng;
use radiosity::cli::{self, Invocation};
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::import::points::parse_points;
use radiosity::scene::{self, Scene};
use radiosity::session::{Session, SessionOptions};
use radiosity::solver::checkpoint;
use radiosity::solver::SolverOptions;
use radiosity::visibility::Visibility;
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// Cases of the option target in the CI run.
const OPTION_CASES: u64 = 40_000;

/// Cases of the points target in the CI run.
const POINTS_CASES: u64 = 60_000;

/// Cases of the checkpoint target in the CI run (each restores a session).
const CHECKPOINT_CASES: u64 = 20_000;

/// The fixed seed of the CI run.
const DEFAULT_SEED: u64 = 0x0971_0435;

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Runs `cases` cases of `one` (which returns why a case is wrong, if it
/// is), catching panics, and fails with the first few problems.
fn fuzz(name: &str, default_cases: u64, mut one: impl FnMut(&mut Rng) -> (String, Option<String>)) {
    common::limit_address_space();
    let cases = env_u64("RADIOSITY_FUZZ_CASES", default_cases);
    let seed = env_u64("RADIOSITY_FUZZ_SEED", DEFAULT_SEED);
    let mut rng = Rng(seed);
    let started = Instant::now();
    let mut failures = Vec::new();
    for case in 0..cases {
        let mut shown = String::new();
        let outcome = panic::catch_unwind(AssertUnwindSafe(|| {
            let (input, problem) = one(&mut rng);
            shown = input;
            problem
        }));
        let problem = match outcome {
            Ok(problem) => problem,
            Err(p) => Some(format!("panicked: {}", common::panic_message(p.as_ref()))),
        };
        if let Some(problem) = problem {
            failures.push(format!("case {case} (seed {seed:#x}): {problem}\n{shown}"));
            if failures.len() >= 5 {
                break;
            }
        }
    }
    eprintln!(
        "fuzz {name}: {cases} cases in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

// -------------------------------------------------------------- options --

/// Values worth giving an option: legal, extreme, malformed and hostile.
const VALUES: &[&str] = &[
    "0",
    "1",
    "-1",
    "0.5",
    "2",
    "1e-307",
    "5e-324",
    "1e308",
    "1e309",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "",
    " ",
    "100000",
    "4294967296",
    "18446744073709551616",
    "10000",
    "1,2",
    "1,2,3",
    "0,0,0",
    "-1,-1,-1",
    "1e30,0,0",
    "800x600",
    "0x0",
    "100000x100000",
    "Lamp=10",
    "Lamp=1,2,3",
    "=",
    "Lamp=nan",
    "Lamp=-1",
    "luminaire=panel.ies",
    "m",
    "mm",
    "ft",
    "out.png",
    "out.exr",
    "out.pfm",
    "out.tif",
    "out.glb",
    "out.ply",
    "out.json",
    "out.csv",
    "out.txt",
    "scene.sc",
    "/dev/null",
    "dir/",
    "\u{1b}[31mred",
    "a\nb",
    "é",
    "center",
    "area",
    "hemicube",
    "progressive",
    "both",
    "front",
    "auto",
    "0.8",
    "0.8,0.1",
    "64",
    "1x1",
];

/// A random command line: options from the program's own table, each with
/// a value when it takes one, and sometimes a scene name or stray token.
fn command_line(rng: &mut Rng, options: &[(String, bool)]) -> Vec<String> {
    let mut argv = vec!["radiosity".to_string()];
    if rng.chance(80) {
        argv.push(
            rng.pick(&["scene.sc", "model.obj", "room.glb", "-", "x.gltf"])
                .to_string(),
        );
    }
    for _ in 0..rng.below(7) {
        let (long, takes) = rng.pick(options);
        let value = if rng.chance(10) {
            // A value of random bytes, kept valid UTF-8.
            let n = rng.below(12);
            (0..n)
                .map(|_| char::from_u32(rng.below(0x80) as u32).unwrap_or('?'))
                .collect()
        } else {
            rng.pick(VALUES).to_string()
        };
        match (takes, rng.below(10)) {
            (true, 0) => argv.push(format!("--{long}={value}")),
            (true, 1) => argv.push(format!("--{long}")), // value missing
            (true, _) => {
                argv.push(format!("--{long}"));
                argv.push(value);
            }
            (false, 0) => argv.push(format!("--{long}={value}")),
            (false, _) => argv.push(format!("--{long}")),
        }
    }
    if rng.chance(5) {
        argv.push(rng.pick(VALUES).to_string());
    }
    argv
}

/// Why an accepted invocation breaks what the run relies on, if it does.
fn invocation_problem(inv: &Invocation) -> Option<String> {
    let c = &inv.config;
    let s = &c.solver;
    if !(0.0..=1.0).contains(&s.threshold) {
        return Some(format!("threshold {} outside [0, 1]", s.threshold));
    }
    if let Some(lenmax) = c.lenmax {
        if !(lenmax.is_finite() && lenmax > 0.0) {
            return Some(format!("lenmax {lenmax} is not a positive number"));
        }
    }
    if !(c.inset.is_finite() && c.inset >= 0.0) {
        return Some(format!("inset {} is not a number >= 0", c.inset));
    }
    if let Some((w, h)) = c.size {
        if w == 0 || h == 0 {
            return Some(format!("picture size {w}x{h}"));
        }
    }
    if c.max_elements == 0 || c.max_elements > mesh::MAX_ADDRESSABLE_ELEMENTS {
        return Some(format!("max elements {}", c.max_elements));
    }
    if c.aa == 0 {
        return Some("antialiasing factor 0".into());
    }
    for (name, rgb) in &c.emit {
        if !(rgb.is_finite() && rgb.min_channel() >= 0.0) {
            return Some(format!("--emit {name} = {rgb:?}"));
        }
    }
    if let Some(sky) = c.sky {
        if !(sky.is_finite() && sky.min_channel() >= 0.0) {
            return Some(format!("--sky {sky:?}"));
        }
    }
    None
}

#[test]
fn option_parser_survives_fuzzing() {
    let command = cli::command();
    let options: Vec<(String, bool)> = command
        .get_arguments()
        .filter_map(|a| {
            let long = a.get_long()?.to_string();
            Some((long, a.get_action().takes_values()))
        })
        .collect();
    assert!(options.len() > 40, "the option table has {}", options.len());
    let mut accepted = 0u64;
    fuzz("options", OPTION_CASES, |rng| {
        let argv = command_line(rng, &options);
        let shown = format!("{argv:?}");
        let problem = match cli::parse_from(&argv) {
            // clap's messages name the argument; --help and --version are
            // errors of their own kind.
            Err(e) => e
                .to_string()
                .trim()
                .is_empty()
                .then(|| "clap refused without a message".to_string()),
            Ok(args) => match Invocation::try_from(args) {
                Err(e) => {
                    let m = e.to_string();
                    (m.trim().is_empty() || m.contains('\n'))
                        .then(|| format!("usage error is empty or several lines: {m:?}"))
                }
                Ok(inv) => {
                    accepted += 1;
                    invocation_problem(&inv)
                }
            },
        };
        (shown, problem)
    });
    assert!(
        accepted > 100,
        "only {accepted} command lines were accepted"
    );
}

// --------------------------------------------------------------- points --

const POINTS_SEEDS: &[&str] = &[
    "x,y,z,nx,ny,nz\n0,0,0,0,0,1\n1,2,3,0,1,0\n",
    "# desk\n0.5, 0.8, 0.5, 0, 1, 0\n\n1.5,0.8,0.5,0,1,0\r\n",
    "1e-3,2e3,-4,1,1,1\n-1,-2,-3,-0.5,0.5,0\n",
    "0,0,0,0,0,1",
];

const POINTS_TOKENS: &[&str] = &[
    ",", "\n", "\r\n", "#", " ", "nan", "inf", "-inf", "1e308", "1e-320", "1e30", "1e-30", "0",
    "-0", "x", "\u{feff}", "\"", "1,,3", ";", "\t", "0,0,0",
];

/// One byte-level or token-level mutation of `input`.
fn mutate(rng: &mut Rng, input: &mut Vec<u8>, tokens: &[&str]) {
    let at = rng.below(input.len() + 1);
    match rng.below(6) {
        0 if !input.is_empty() => {
            let i = rng.below(input.len());
            input[i] ^= 1 << rng.below(8);
        }
        1 if !input.is_empty() => {
            let end = (at + 1 + rng.below(8)).min(input.len());
            input.drain(at.min(end)..end);
        }
        2 if !input.is_empty() => {
            let from = rng.below(input.len());
            let end = (from + 1 + rng.below(16)).min(input.len());
            let span = input[from..end].to_vec();
            input.splice(at..at, span);
        }
        3 => {
            input.truncate(at);
        }
        _ if tokens.is_empty() => input.insert(at, rng.next() as u8),
        _ => {
            let t = rng.pick(tokens).as_bytes().to_vec();
            input.splice(at..at, t);
        }
    }
}

#[test]
fn points_reader_survives_fuzzing() {
    let file = "fuzz.csv";
    fuzz("points", POINTS_CASES, |rng| {
        let mut input = rng.pick(POINTS_SEEDS).as_bytes().to_vec();
        for _ in 0..1 + rng.below(6) {
            mutate(rng, &mut input, POINTS_TOKENS);
        }
        let text = String::from_utf8_lossy(&input).into_owned();
        let problem = match parse_points(&text, file) {
            Err(e) => {
                let lines: Vec<&str> = text.split('\n').collect();
                let located = e.file == file
                    && e.line >= 1
                    && e.line <= lines.len()
                    && e.column >= 1
                    && e.column <= lines[e.line - 1].chars().count() + 1;
                if !located {
                    Some(format!("refusal not located inside the input: {e}"))
                } else if e.message.is_empty() || e.message.contains('\n') {
                    Some(format!("message empty or several lines: {e}"))
                } else {
                    None
                }
            }
            Ok(points) => points.iter().find_map(|(p, n)| {
                let unit = (n.length() - 1.0).abs() < 1e-4;
                (!(p.is_finite() && n.is_finite() && unit))
                    .then(|| format!("accepted point {p} with normal {n}"))
            }),
        };
        (text, problem)
    });
}

// ----------------------------------------------------------- checkpoint --

/// Bytes of the trailing checksum (FNV-1a of everything before it).
const CHECKSUM_LEN: usize = 8;

/// Replaces the trailing checksum with the right one for the bytes before
/// it, as `radiosity::solver::checkpoint` computes it.
fn reseal(bytes: &mut [u8]) {
    if bytes.len() < CHECKSUM_LEN {
        return;
    }
    let body = bytes.len() - CHECKSUM_LEN;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in &bytes[..body] {
        h = (h ^ b as u64).wrapping_mul(0x100_0000_01b3);
    }
    bytes[body..].copy_from_slice(&h.to_le_bytes());
}

/// Hostile 8-byte words for the header's counts and the stored values.
fn hostile_word(rng: &mut Rng) -> u64 {
    *rng.pick(&[
        0,
        1,
        u64::MAX,
        u64::MAX / 24,
        1 << 40,
        f64::NAN.to_bits(),
        f64::INFINITY.to_bits(),
        (-1.0f64).to_bits(),
        f64::MAX.to_bits(),
        5e-324f64.to_bits(),
        (-0.0f64).to_bits(),
        1e30f64.to_bits(),
        (-1e30f64).to_bits(),
        1.1e30f64.to_bits(),
        4,
    ])
}

#[test]
fn checkpoint_reader_survives_fuzzing() {
    let scene: Scene =
        scene::parse_str(include_str!("../scenes/cornell.sc"), "cornell.sc").expect("scene");
    let mesh = mesh::build(
        &scene,
        &MeshOptions {
            lenmax: scene.extent() / 4.0,
            inset: mesh::DEFAULT_INSET,
        },
    )
    .expect("mesh");
    let visibility = Visibility::new(&scene);
    let options = || SessionOptions {
        solver: SolverOptions::default(),
        refine: None,
        max_elements: mesh::MAX_ELEMENTS,
        ambient: false,
    };
    let never = AtomicBool::new(false);
    // Seeds: the state before any step and after a few.
    let seeds: Vec<Vec<u8>> = [0, 3]
        .into_iter()
        .map(|steps| {
            let mut s = Session::new(&scene, &mesh, &visibility, options());
            for _ in 0..steps {
                s.advance(&never).expect("step");
            }
            checkpoint::encode(7, &s.solver().state(), &[0u8; 56])
        })
        .collect();
    let mut restored = 0u64;
    fuzz("checkpoint", CHECKPOINT_CASES, |rng| {
        let mut bytes = rng.pick(&seeds).clone();
        for _ in 0..1 + rng.below(4) {
            if rng.chance(50) && bytes.len() >= 8 {
                // An aligned word: a count, a step total or a stored value.
                let at = 8 * rng.below(bytes.len() / 8);
                let w = hostile_word(rng).to_le_bytes();
                let end = (at + 8).min(bytes.len());
                bytes[at..end].copy_from_slice(&w[..end - at]);
            } else {
                mutate(rng, &mut bytes, &[]);
            }
        }
        if rng.chance(85) {
            reseal(&mut bytes);
        }
        let shown = format!("{} bytes", bytes.len());
        let problem = match checkpoint::decode(&bytes) {
            Err(e) => e
                .to_string()
                .is_empty()
                .then(|| "refused without a reason".to_string()),
            Ok(decoded) => {
                let mut s = Session::new(&scene, &mesh, &visibility, options());
                match s.restore(decoded.state) {
                    Err(_) => None,
                    Ok(()) => {
                        restored += 1;
                        if let Err(e) = s.validate() {
                            Some(format!("restored state breaks an invariant: {e}"))
                        } else {
                            match s.advance(&never) {
                                Err(e) => Some(format!("a step after restoring failed: {e}")),
                                Ok(_) => s.radiosity().iter().any(|b| !b.is_finite()).then(|| {
                                    "a step after restoring made a non-finite value".into()
                                }),
                            }
                        }
                    }
                }
            }
        };
        (shown, problem)
    });
    assert!(
        restored > CHECKPOINT_CASES.min(env_u64("RADIOSITY_FUZZ_CASES", CHECKPOINT_CASES)) / 100,
        "only {restored} mutated checkpoints were restored"
    );
}
