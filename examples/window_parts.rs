//! How often the window's picture moves: solves a scene as the window does,
//! with steps delivered in parts of about
//! [`WINDOW_PART_BUDGET`](radiosity::solver::tuning::WINDOW_PART_BUDGET)
//! (`docs/performance.md`), and prints the solver time between pictures
//! (each part) against the time of whole steps:
//!
//! ```sh
//! cargo run --release --example hall -- 150 > hall150.sc
//! cargo run --release --example window_parts -- hall150.sc
//! ```
//!
//! Arguments: the scene and, optionally, `lenmax` in scene units (`-` or
//! absent for the program's default) and the part budget in milliseconds
//! (default the window's; `0` ends a part after every chunk, `none` runs
//! every step in one piece, as a batch run does). `WP_SKY=V` puts the
//! scene under a uniform sky of radiosity `V`, as `--sky V` does (a real
//! export has no lamps of its own):
//!
//! ```sh
//! WP_SKY=1 cargo run --release --example window_parts -- tests/models/godot/room.glb
//! ```
//! Prints the steps, the
//! parts, the median and longest part and step, how many of each took more
//! than 100 ms, and the whole solve's seconds.
//! `WP_LIST=1` also lists each part over 100 ms: its step, which part of
//! the step it was, the shooter and how many polygons shot with it.

use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare;
use radiosity::session::{Event, Session, SessionOptions};
use radiosity::solver::tuning::WINDOW_PART_BUDGET;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Median and largest of `v` (seconds), and how many exceed 0.1 s.
fn summary(v: &mut [f64]) -> (f64, f64, usize) {
    v.sort_by(f64::total_cmp);
    let median = v.get(v.len() / 2).copied().unwrap_or(0.0);
    let max = v.last().copied().unwrap_or(0.0);
    (median, max, v.iter().filter(|&&t| t > 0.1).count())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(scene) = args.first() else {
        eprintln!("usage: window_parts SCENE [LENMAX|-] [BUDGET_MS|none]");
        std::process::exit(2);
    };
    let mut config = RunConfig::new(SceneSource::File(PathBuf::from(scene)));
    config.lenmax = args.get(1).and_then(|l| l.parse().ok());
    if let Some(v) = std::env::var_os("WP_SKY") {
        match v.to_str().and_then(|v| v.parse::<f64>().ok()) {
            Some(v) if v.is_finite() && v >= 0.0 => {
                config.sky = Some(radiosity::color::Rgb::new(v, v, v));
            }
            _ => {
                eprintln!("WP_SKY: a radiosity of 0 or more, not {v:?}");
                std::process::exit(2);
            }
        }
    }
    let budget = match args.get(2).map(String::as_str) {
        None => Some(WINDOW_PART_BUDGET),
        Some("none") => None,
        Some(ms) => match ms.parse::<u64>() {
            Ok(ms) => Some(Duration::from_millis(ms)),
            Err(_) => {
                eprintln!("budget: milliseconds or `none`, not {ms:?}");
                std::process::exit(2);
            }
        },
    };
    let prepared = match prepare::prepare(&config) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut options = SessionOptions::for_run(&config, &prepared, true);
    options.solver.part_budget = budget;
    let mut session = Session::from_prepared(&prepared, options);
    let cancel = AtomicBool::new(false);
    let (mut parts, mut steps) = (Vec::new(), Vec::new());
    // The particle tail's parts and steps, apart.
    let (mut tail_parts, mut tail_steps) = (Vec::new(), Vec::new());
    let mut step_so_far = 0.0;
    let list_long = std::env::var_os("WP_LIST").is_some();
    let start = Instant::now();
    loop {
        let t = Instant::now();
        let event = session.advance(&cancel).expect("a solve without errors");
        let took = t.elapsed().as_secs_f64();
        match event {
            Event::Step(report) => {
                if list_long && took > 0.1 {
                    println!(
                        "long part: step {} part {} ({}) {took:.3} s, shooter {} of {} polygons, rays {}, receivers {}",
                        report.step,
                        report.part,
                        if report.complete { "last" } else { "not last" },
                        report.shooter.0,
                        report.polygons,
                        report.rays,
                        report.receivers
                    );
                }
                parts.push(took);
                if report.particles > 0 {
                    tail_parts.push(took);
                }
                step_so_far += took;
                if report.complete {
                    steps.push(step_so_far);
                    if report.particles > 0 {
                        tail_steps.push(step_so_far);
                    }
                    step_so_far = 0.0;
                }
            }
            Event::Finished => break,
            _ => {}
        }
    }
    let total = start.elapsed().as_secs_f64();
    let (n_parts, n_steps) = (parts.len(), steps.len());
    let (pm, px, po) = summary(&mut parts);
    let (sm, sx, so) = summary(&mut steps);
    println!(
        "# {scene}: {} polygons, {} vertices, budget {}",
        prepared.scene.polygons.len(),
        prepared.mesh.vertex_count(),
        budget.map_or("none".into(), |b| format!("{} ms", b.as_millis()))
    );
    println!("| | count | median s | longest s | over 100 ms |");
    println!("|---|---|---|---|---|");
    println!("| parts (pictures) | {n_parts} | {pm:.3} | {px:.3} | {po} |");
    println!("| steps | {n_steps} | {sm:.3} | {sx:.3} | {so} |");
    if !tail_steps.is_empty() {
        let (n_tp, n_ts) = (tail_parts.len(), tail_steps.len());
        let (tpm, tpx, tpo) = summary(&mut tail_parts);
        let (tsm, tsx, tso) = summary(&mut tail_steps);
        println!("| of them the tail's parts | {n_tp} | {tpm:.3} | {tpx:.3} | {tpo} |");
        println!("| of them the tail's steps | {n_ts} | {tsm:.3} | {tsx:.3} | {tso} |");
    }
    println!(
        "solve {total:.2} s, {} rays, unshot {:.3} %",
        session.totals().rays,
        session.unshot_fraction() * 100.0
    );
}
