//! Fuzzing the scene loaders inside `cargo test`.
//!
//! A deterministic mutator (seeded PRNG, no external engine) turns a seed
//! corpus — the bundled scenes, the regression cases in `tests/corpus/` and
//! small hand-written scenes — into a fixed number of hostile inputs: byte
//! flips, deleted, duplicated and spliced spans, swapped lines, truncations,
//! inserted keywords and absurd numbers (`1e30`, `nan`, `size 100000
//! 100000`, `scale 0.000001`, …), plus scenes generated from the grammar with
//! random (often extreme) values. Every input must:
//!
//! - never panic (a panic is caught and reported with the input);
//! - never hang: each parse runs under a watchdog and must finish in under
//!   [`PER_INPUT_LIMIT`] (a parse still running after that aborts the test
//!   binary, printing the input);
//! - if rejected, carry at least one diagnostic, each with the file name, a
//!   one-line message and a position inside the input;
//! - if accepted, satisfy every invariant the later stages rely on (valid
//!   polygons within the coordinate limits, materials with reflectance
//!   below one, a camera that makes a view, a mesh size that can be
//!   estimated).
//!
//! Each loader is a [`Target`]; the OBJ importer becomes one more entry in
//! [`targets`] when it lands. `RADIOSITY_FUZZ_CASES` overrides the number of
//! cases per target and `RADIOSITY_FUZZ_SEED` the seed (to explore beyond
//! the fixed CI run); a failure prints the seed, the case number and the
//! input, and saves the input in the system's temporary directory so it can
//! be added to `tests/corpus/`.

mod common;

use radiosity::mesh::{self, MeshOptions};
use radiosity::render::View;
use radiosity::scene::{self, Diagnostic, Scene, MAX_COORDINATE};
use std::panic::{self, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Cases per target in the CI run. About 12 s for the `.sc` target on two
/// cores in the test profile (see `docs/reliability.md`).
const DEFAULT_CASES: u64 = 300_000;

/// The fixed seed of the CI run.
const DEFAULT_SEED: u64 = 0x005e_ed0f_5c3e_u64;

/// Longest a single input may take to load.
const PER_INPUT_LIMIT: Duration = Duration::from_secs(1);

/// The file name loaders see, which every diagnostic must carry.
const FILE: &str = "fuzz.sc";

/// A loader under test.
struct Target {
    /// Short name for messages.
    name: &'static str,
    /// File extension of its inputs (for saved failures and the corpus).
    extension: &'static str,
    /// Loads bytes.
    load: fn(&[u8]) -> Result<Scene, Vec<Diagnostic>>,
    /// Seed inputs besides the corpus directory.
    seeds: fn() -> Vec<Vec<u8>>,
    /// Generates a random input from the grammar.
    generate: fn(&mut Rng) -> Vec<u8>,
    /// Tokens worth inserting.
    dictionary: Vec<&'static str>,
}

fn targets() -> Vec<Target> {
    vec![Target {
        name: "sc",
        extension: "sc",
        load: |b| scene::parse_bytes(b, FILE).map_err(|e| e.diagnostics),
        seeds: sc_seeds,
        generate: generate_sc,
        // The parser's keywords, then malformed and extreme fragments.
        dictionary: scene::KEYWORDS
            .iter()
            .chain(SC_FRAGMENTS)
            .copied()
            .collect(),
    }]
}

// ------------------------------------------------------------------ rng --

/// SplitMix64: tiny, fast, and the same sequence on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// Mostly a number in `lo..hi`, sometimes anything ([`Rng::number`]).
    fn sane(&mut self, lo: f64, hi: f64) -> String {
        if self.chance(85) {
            let x = lo + (hi - lo) * (self.next() as f64 / u64::MAX as f64);
            format!("{x:.3}")
        } else {
            self.number()
        }
    }

    /// A number as a scene file would write it: mostly ordinary, sometimes
    /// absurd.
    fn number(&mut self) -> String {
        if self.chance(15) {
            return self.pick(INTERESTING_NUMBERS).to_string();
        }
        let magnitude = match self.below(4) {
            0 => 1.0,
            1 => 10.0,
            2 => 0.01,
            _ => 1000.0,
        };
        let x = (self.next() as f64 / u64::MAX as f64 * 2.0 - 1.0) * magnitude;
        if self.chance(30) {
            format!("{}", x.round())
        } else {
            format!("{x:.3}")
        }
    }
}

// ------------------------------------------------------------- the .sc --

const INTERESTING_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    ".5",
    "5.",
    "1e30",
    "-1e30",
    "1e12",
    "1.0000001e12",
    "1e-9",
    "1e-12",
    "1e-30",
    "1e-320",
    "3.4e38",
    "3.5e38",
    "1e308",
    "1e999",
    "0.000001",
    "1000000",
    "100000",
    "65536",
    "65537",
    "8192",
    "8193",
    "4294967295",
    "4294967296",
    "179.9999999",
    "180",
    "1e-45",
    "0.9999999",
    "nan",
    "-inf",
    "0x10",
    "1e",
    "--1",
    "99999999999999999999999999999999999999999",
];

const SC_FRAGMENTS: &[&str] = &[
    "scale 0.000001",
    "scale 1e300",
    "scale 1 0.000001 1",
    "rotate 0 0 0 90",
    "rotate 1 1 1 1e300",
    "size 100000 100000",
    "size 65536 65536",
    "size 0 1",
    "vertex 1e30 0 0",
    "vertex 0 0 0",
    "translate 1e12 1e12 1e12",
    "box m 0 0 0 1 1 1",
    "box m 0 0 0 1e-10 1e-10 1e-10",
    "material m color 1 1 1 k_diffrefl 0.5 end",
    "material l k_emission 1e308 end",
    "polygon m vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end",
    "polygon m vertex 0 0 0 vertex 1 0 0 vertex 1 0 0 end",
    "polygon m vertex 0 0 0 vertex 1e-12 0 0 vertex 0 1e-12 0 end",
    "transform",
    "transform transform transform",
    "#",
    "# comment\n",
    "\n",
    "\r\n",
    "\t",
    " ",
    "\u{feff}",
    "é",
    "\u{2028}",
    "\0",
    "m",
    "nan",
    "inf",
    "_",
];

/// Small scenes that reach the deep checks quickly.
fn sc_seeds() -> Vec<Vec<u8>> {
    let mut seeds: Vec<Vec<u8>> = ["rtable.sc", "cornell.sc", "table_chair.sc"]
        .iter()
        .map(|n| std::fs::read(common::scene(n)).expect("bundled scene"))
        .collect();
    seeds.extend(
        [
            "material m color 1 1 1 k_diffrefl 0.5 end\n\
             material l color 1 1 1 k_emission 1 end\n\
             polygon l vertex 0 1 0 vertex 1 1 0 vertex 1 1 1 vertex 0 1 1 end\n\
             box m -1 -1 -1 2 0 2\n",
            "camera eye 0 0 -5 lookat 0 0 0 up 0 1 0 fov 60 size 64 48 end\n\
             material m k_diffrefl 0.5 k_emission 0.1 end\n\
             transform translate 1 2 3 rotate 0 1 0 30 scale 2 \n\
               polygon m vertex 0 0 0 vertex 1 0 0 vertex 1.5 1 0 vertex 0.5 1.5 0 vertex -0.5 1 0 end\n\
             end\n",
            "material m k_diffrefl 0.3 end\n\
             transform scale 0.000001\n  transform scale 0.000001\n    box m 0 0 0 1 1 1\n  end\nend\n",
            "material m k_diffrefl 0.3 end\nbox m 0 0 0 1e11 1e11 1e11\n",
        ]
        .iter()
        .map(|s| s.as_bytes().to_vec()),
    );
    seeds
}

/// A scene from the grammar with random values: mostly well-formed, so the
/// geometric and numeric checks behind the syntax get exercised.
fn generate_sc(rng: &mut Rng) -> Vec<u8> {
    let mut s = String::new();
    let mut materials = Vec::new();
    if rng.chance(50) {
        s += "camera\n";
        for field in ["eye", "lookat", "up"] {
            if rng.chance(85) {
                s += &format!(
                    "  {field} {} {} {}\n",
                    rng.number(),
                    rng.number(),
                    rng.number()
                );
            }
        }
        if rng.chance(50) {
            s += &format!("  fov {}\n", rng.sane(1.0, 179.0));
        }
        if rng.chance(50) {
            s += &format!(
                "  size {} {}\n",
                rng.pick(INTERESTING_NUMBERS),
                rng.pick(&["1", "480", "8192", "100000", "65536"])
            );
        }
        s += "end\n";
    }
    for k in 0..1 + rng.below(3) {
        let name = format!("m{k}");
        s += &format!("material {name}\n");
        if rng.chance(70) {
            s += &format!(
                "  color {} {} {}\n",
                rng.sane(0.0, 1.0),
                rng.sane(0.0, 1.0),
                rng.sane(0.0, 1.0)
            );
        }
        s += &format!("  k_diffrefl {}\n", rng.sane(0.0, 0.99));
        if rng.chance(40) {
            s += &format!("  k_emission {}\n", rng.sane(0.0, 10.0));
        }
        s += "end\n";
        materials.push(name);
    }
    let mut depth = 0;
    for _ in 0..1 + rng.below(6) {
        match rng.below(6) {
            0 => {
                s += "transform\n";
                depth += 1;
                for _ in 0..1 + rng.below(3) {
                    s += &match rng.below(3) {
                        0 => format!(
                            "  translate {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number()
                        ),
                        1 => format!(
                            "  rotate {} {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number(),
                            rng.number()
                        ),
                        _ if rng.chance(50) => format!("  scale {}\n", rng.number()),
                        _ => format!(
                            "  scale {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number()
                        ),
                    };
                }
            }
            1 if depth > 0 => {
                s += "end\n";
                depth -= 1;
            }
            2 => {
                s += &format!("box {}", rng.pick(&materials));
                for _ in 0..6 {
                    s += &format!(" {}", rng.number());
                }
                s += "\n";
            }
            _ => {
                // A regular polygon (convex, planar) in a random plane, or
                // random vertices.
                s += &format!("polygon {}\n", rng.pick(&materials));
                let n = 3 + rng.below(6);
                let regular = rng.chance(70);
                let radius: f64 = rng.number().parse().unwrap_or(1.0);
                for i in 0..n {
                    if regular {
                        let a = i as f64 / n as f64 * std::f64::consts::TAU;
                        s += &format!("  vertex {} {} 0\n", radius * a.cos(), radius * a.sin());
                    } else {
                        s += &format!(
                            "  vertex {} {} {}\n",
                            rng.number(),
                            rng.number(),
                            rng.number()
                        );
                    }
                }
                s += "end\n";
            }
        }
    }
    for _ in 0..depth {
        if rng.chance(90) {
            s += "end\n";
        }
    }
    s.into_bytes()
}

// -------------------------------------------------------------- mutator --

fn mutate(rng: &mut Rng, input: &mut Vec<u8>, other: &[u8], dictionary: &[&str]) {
    let span = |rng: &mut Rng, len: usize| {
        let a = rng.below(len + 1);
        let b = (a + rng.below(64)).min(len);
        (a, b)
    };
    match rng.below(10) {
        0 if !input.is_empty() => {
            let i = rng.below(input.len());
            input[i] ^= 1 << rng.below(8);
        }
        1 if !input.is_empty() => {
            let i = rng.below(input.len());
            input[i] = *rng.pick(b" \n\t#.-+eE019azAZ_\x00\x7f\xc3\xa9\xff\xfe");
        }
        2 => {
            let (a, b) = span(rng, input.len());
            input.drain(a..b);
        }
        3 => {
            let (a, b) = span(rng, input.len());
            let copy = input[a..b].to_vec();
            let at = rng.below(input.len() + 1);
            input.splice(at..at, copy);
        }
        4 => {
            // Splice: our head with the other input's tail.
            let cut = rng.below(input.len() + 1);
            let from = rng.below(other.len() + 1);
            input.truncate(cut);
            input.extend_from_slice(&other[from..]);
        }
        5 => {
            let text = String::from_utf8_lossy(input).into_owned();
            let mut lines: Vec<&str> = text.lines().collect();
            if lines.len() > 1 {
                let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
                lines.swap(a, b);
            }
            *input = lines.join("\n").into_bytes();
        }
        6 => input.truncate(rng.below(input.len() + 1)),
        7 => {
            // Replace a whitespace-separated token by an interesting number.
            let text = String::from_utf8_lossy(input).into_owned();
            let tokens: Vec<&str> = text.split(' ').collect();
            let k = rng.below(tokens.len());
            let mut out: Vec<&str> = tokens.clone();
            out[k] = *rng.pick(INTERESTING_NUMBERS);
            *input = out.join(" ").into_bytes();
        }
        _ => {
            let at = rng.below(input.len() + 1);
            let token = format!(" {} ", rng.pick(dictionary));
            input.splice(at..at, token.into_bytes());
        }
    }
}

// --------------------------------------------------------------- checks --

/// Why an outcome is wrong, or `None`.
fn check(input: &[u8], outcome: &Result<Scene, Vec<Diagnostic>>) -> Option<String> {
    match outcome {
        Err(diags) => {
            if diags.is_empty() {
                return Some("rejected without a diagnostic".into());
            }
            let lines: Vec<&[u8]> = input.split(|&b| b == b'\n').collect();
            for d in diags {
                if d.file != FILE {
                    return Some(format!("diagnostic names file `{}`: {d}", d.file));
                }
                if d.message.is_empty() || d.message.contains('\n') {
                    return Some(format!("message is empty or several lines: {d:?}"));
                }
                let line = d.line as usize;
                // Columns count characters, which are never more than bytes;
                // one past the end is where "end of file" problems point.
                let ok = line >= 1
                    && line <= lines.len()
                    && d.col >= 1
                    && d.col as usize <= lines[line - 1].len() + 1;
                if !ok {
                    return Some(format!("position outside the input: {d}"));
                }
            }
            None
        }
        Ok(scene) => {
            if scene.polygons.is_empty() {
                return Some("accepted a scene without polygons".into());
            }
            for (i, p) in scene.polygons.iter().enumerate() {
                if let Err(e) = p.validate() {
                    return Some(format!("accepted polygon {i} is invalid: {e}"));
                }
                if p.vertices
                    .iter()
                    .any(|v| v.abs().max_element() as f64 > MAX_COORDINATE)
                {
                    return Some(format!("polygon {i} is outside the coordinate limit"));
                }
                if p.material.index() >= scene.materials.len() {
                    return Some(format!("polygon {i} names a missing material"));
                }
            }
            for m in &scene.materials {
                let (e, rho) = (m.emission(), m.reflectance());
                let valid = e.is_finite()
                    && e.min_channel() >= 0.0
                    && rho.is_finite()
                    && rho.min_channel() >= 0.0
                    && rho.max_channel() < 1.0;
                if !valid {
                    return Some(format!("accepted material breaks its invariants: {m:?}"));
                }
            }
            if let Err(e) = View::new(&scene.camera) {
                return Some(format!("accepted camera makes no view: {e}"));
            }
            if let Err(e) = mesh::estimate(scene, &MeshOptions::for_scene(scene)) {
                return Some(format!("default mesh options refused: {e}"));
            }
            None
        }
    }
}

// --------------------------------------------------------------- driver --

/// Watches the case in progress and aborts the process when one runs past
/// the limit: a hang would otherwise stall the test run forever.
struct Watchdog {
    started_ms: Arc<AtomicU64>,
    input: Arc<Mutex<Vec<u8>>>,
    stop: Arc<AtomicBool>,
    epoch: Instant,
}

impl Watchdog {
    fn start(target: &'static str) -> Watchdog {
        let dog = Watchdog {
            started_ms: Arc::new(AtomicU64::new(0)),
            input: Arc::new(Mutex::new(Vec::new())),
            stop: Arc::new(AtomicBool::new(false)),
            epoch: Instant::now(),
        };
        let (started, input, stop, epoch) = (
            dog.started_ms.clone(),
            dog.input.clone(),
            dog.stop.clone(),
            dog.epoch,
        );
        std::thread::spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(50));
                let s = started.load(Ordering::Relaxed);
                let now = epoch.elapsed().as_millis() as u64 + 1;
                if s != 0 && now.saturating_sub(s) > 2 * PER_INPUT_LIMIT.as_millis() as u64 {
                    let bytes = input.lock().map(|b| b.clone()).unwrap_or_default();
                    let saved = save_failure(target, "hang", &bytes);
                    eprintln!(
                        "fuzz {target}: input still loading after {:?}; saved to {}:\n{}",
                        2 * PER_INPUT_LIMIT,
                        saved.display(),
                        String::from_utf8_lossy(&bytes)
                    );
                    std::process::abort();
                }
            }
        });
        dog
    }

    fn begin(&self, input: &[u8]) {
        if let Ok(mut slot) = self.input.lock() {
            slot.clear();
            slot.extend_from_slice(input);
        }
        let now = self.epoch.elapsed().as_millis() as u64 + 1;
        self.started_ms.store(now, Ordering::Relaxed);
    }

    fn end(&self) {
        self.started_ms.store(0, Ordering::Relaxed);
    }
}

impl Drop for Watchdog {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

fn save_failure(target: &str, why: &str, input: &[u8]) -> PathBuf {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in input {
        hash = (hash ^ b as u64).wrapping_mul(0x100_0000_01b3);
    }
    let path = std::env::temp_dir().join(format!("radiosity-fuzz-{target}-{why}-{hash:016x}"));
    let _ = std::fs::write(&path, input);
    path
}

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// What a fuzz run saw.
#[derive(Debug, Default)]
struct Summary {
    cases: u64,
    accepted: u64,
    slowest: Duration,
    failures: Vec<String>,
}

fn corpus(target: &Target) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = common::root()
        .join("tests")
        .join("corpus")
        .join(target.name);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|p| p.extension().is_some_and(|e| e == target.extension));
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).expect("corpus file readable");
            (p, bytes)
        })
        .collect()
}

fn fuzz(target: &Target, cases: u64, seed: u64) -> Summary {
    let mut seeds = (target.seeds)();
    seeds.extend(corpus(target).into_iter().map(|(_, b)| b));
    let mut rng = Rng(seed);
    let dog = Watchdog::start(target.name);
    let mut summary = Summary::default();
    for case in 0..cases {
        // A fifth generated as is (mostly valid: the checks on accepted
        // scenes need them), a fifth generated and lightly mutated, the
        // rest mutated seeds.
        let (mut input, mutations) = match rng.below(5) {
            0 => ((target.generate)(&mut rng), 0),
            1 => ((target.generate)(&mut rng), 1 + rng.below(2)),
            _ => (rng.pick(&seeds).clone(), 1 + rng.below(8)),
        };
        let other = rng.pick(&seeds).clone();
        for _ in 0..mutations {
            mutate(&mut rng, &mut input, &other, &target.dictionary);
        }
        dog.begin(&input);
        let t = Instant::now();
        let outcome = panic::catch_unwind(AssertUnwindSafe(|| (target.load)(&input)));
        let elapsed = t.elapsed();
        dog.end();
        summary.cases += 1;
        summary.slowest = summary.slowest.max(elapsed);
        let problem = match &outcome {
            Err(p) => Some(format!(
                "panicked: {}",
                p.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default()
            )),
            Ok(_) if elapsed > PER_INPUT_LIMIT => Some(format!("took {elapsed:?}")),
            Ok(o) => {
                summary.accepted += o.is_ok() as u64;
                check(&input, o)
            }
        };
        if let Some(problem) = problem {
            let saved = save_failure(target.name, "fail", &input);
            summary.failures.push(format!(
                "case {case} (seed {seed:#x}): {problem}; input saved to {}:\n{}",
                saved.display(),
                String::from_utf8_lossy(&input[..input.len().min(2000)])
            ));
            if summary.failures.len() >= 5 {
                break;
            }
        }
    }
    summary
}

#[test]
fn loaders_survive_fuzzing() {
    let cases = env_u64("RADIOSITY_FUZZ_CASES", DEFAULT_CASES);
    let seed = env_u64("RADIOSITY_FUZZ_SEED", DEFAULT_SEED);
    for target in targets() {
        let t = Instant::now();
        let s = fuzz(&target, cases, seed);
        eprintln!(
            "fuzz {}: {} cases ({} accepted) in {:.1} s, slowest input {:.1} ms",
            target.name,
            s.cases,
            s.accepted,
            t.elapsed().as_secs_f64(),
            s.slowest.as_secs_f64() * 1e3
        );
        assert!(s.failures.is_empty(), "{}", s.failures.join("\n\n"));
        assert_eq!(s.cases, cases);
        // A mutator that only ever produced garbage would test little of
        // the validation behind the syntax.
        assert!(
            s.accepted > cases / 100,
            "only {} of {} inputs were valid scenes",
            s.accepted,
            cases
        );
    }
}

/// Every file kept in `tests/corpus/<target>/` loads to exactly the
/// outcome recorded next to it in `NAME.expected` (`ok`, or the
/// diagnostics as printed), and passes the same checks as a fuzz case.
#[test]
fn corpus_cases_keep_their_outcome() {
    for target in targets() {
        let files = corpus(&target);
        assert!(!files.is_empty(), "no corpus for {}", target.name);
        for (path, bytes) in files {
            let outcome = (target.load)(&bytes);
            if let Some(problem) = check(&bytes, &outcome) {
                panic!("{}: {problem}", path.display());
            }
            let got = match &outcome {
                Ok(_) => "ok".to_string(),
                Err(diags) => diags
                    .iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join("\n"),
            };
            let expected_path = path.with_extension("expected");
            if std::env::var_os("RADIOSITY_BLESS").is_some() {
                std::fs::write(&expected_path, format!("{got}\n")).expect("bless");
                continue;
            }
            let expected = std::fs::read_to_string(&expected_path).unwrap_or_else(|_| {
                panic!(
                    "{} has no {} (run with RADIOSITY_BLESS=1 to record it)",
                    path.display(),
                    expected_path.display()
                )
            });
            assert_eq!(got, expected.trim_end(), "{}", path.display());
        }
    }
}
