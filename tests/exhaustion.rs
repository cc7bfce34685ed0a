//! Solves run to exhaustion stay finite: `--threshold 0` with a step
//! limit, on the bundled scenes, on generated scenes with reflectance up
//! to 0.95 and with emission down to powers that no `f32` holds, and on a
//! real model under a sky, checking every value after every step.
//!
//! The last steps of a solve run to exhaustion shoot ever less light,
//! down to powers that flush to zero in `f32`: a weighted mean over such
//! powers divided 0 by 0 and the NaN spread through every later step
//! (issue 47). Scaling a scene's emission down reaches that regime in the
//! first steps, which keeps these tests short. Also: `--threshold 0` ends
//! a run cleanly, converged, when the unshot power is exactly zero.

mod common;

use common::scenes::{grey, polygon, regular_mesh, scene, tiled_shadowed_box};
use common::{read_json, root, run_in, scene as bundled, stderr};
use radiosity::config::{RunConfig, SceneSource};
use radiosity::prepare::prepare;
use radiosity::scene::Scene;
use radiosity::session::{Event, Session, SessionOptions};
use radiosity::solver::{Approximations, Heuristic, Progressive, SolverOptions, StopReason};
use radiosity::visibility::Visibility;
use std::sync::atomic::AtomicBool;

/// Solver options that run to exhaustion, or to `limit` steps.
fn exhausting(limit: u64) -> SolverOptions {
    SolverOptions {
        threshold: 0.0,
        max_steps: Some(limit),
        ..SolverOptions::default()
    }
}

/// Steps `solver` until it stops, checking after every step that every
/// value is finite and the step's figures too; returns why it stopped
/// (`None`: a step found nothing to shoot).
fn exhaust(solver: &mut Progressive, name: &str) -> Option<StopReason> {
    loop {
        if let Some(reason) = solver.stop_reason() {
            return Some(reason);
        }
        let Some(report) = solver.step() else {
            assert_eq!(solver.fault(), None, "{name}");
            return None;
        };
        assert!(
            report.shot_power.is_finite() && report.unshot_fraction.is_finite(),
            "{name}: step {} reported {report:?}",
            report.step
        );
        if let Err(e) = solver.validate() {
            panic!("{name}: after step {}: {e}", report.step);
        }
    }
}

/// Runs the scene `config` names through a session to its end, checking
/// every value after every step; returns the steps taken.
fn exhaust_run(config: &RunConfig) -> u64 {
    let name = config.scene.display_name();
    let prepared = prepare(config).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut session =
        Session::from_prepared(&prepared, SessionOptions::for_run(config, &prepared, false));
    let cancel = AtomicBool::new(false);
    loop {
        match session.advance(&cancel) {
            Ok(Event::Finished) => break,
            Ok(Event::Step(report)) => {
                if let Err(e) = session.solver().validate() {
                    panic!("{name}: after step {}: {e}", report.step);
                }
            }
            Ok(_) => {}
            Err(e) => panic!("{name}: {e}"),
        }
    }
    session.validate().unwrap();
    session.totals().steps
}

/// The bundled scenes, each run to its step limit with threshold 0 on a
/// coarse mesh.
#[test]
fn bundled_scenes_stay_finite_to_exhaustion() {
    for (file, lenmax, limit) in [
        ("cornell.sc", 60.0, 600),
        ("office.sc", 40.0, 300),
        ("rtable.sc", 0.5, 600),
        ("table_chair.sc", 0.5, 300),
    ] {
        let mut config = RunConfig::new(SceneSource::File(bundled(file)));
        config.lenmax = Some(lenmax);
        config.solver = exhausting(limit);
        let steps = exhaust_run(&config);
        assert!(steps > 0, "{file}");
    }
}

/// A tiled box (so clusters form and shoot through strata) of
/// reflectances up to 0.95, its lamp's emission scaled from ordinary to
/// far below what an `f32` holds, run until nothing is left or the step
/// limit, with clustering and overshooting on and off.
#[test]
fn generated_scenes_stay_finite_to_exhaustion() {
    for rho in [0.5, 0.95] {
        for emission in [10.0, 1e-30, 1e-300] {
            let mut s: Scene = tiled_shadowed_box(4);
            s.materials = vec![
                grey("lamp", emission, rho),
                grey("a", 0.0, rho),
                grey("b", 0.0, rho.min(0.9)),
            ];
            let mesh = regular_mesh(&s, 0.5);
            let vis = Visibility::new(&s);
            for (clustering, overshoot) in [(true, true), (true, false), (false, true)] {
                let options = SolverOptions {
                    approximations: Approximations::DEFAULT
                        .with(Heuristic::Clusters, clustering)
                        .with(Heuristic::Overshoot, overshoot),
                    ..exhausting(400)
                };
                let name = format!(
                    "rho {rho}, emission {emission:e}, clustering {clustering}, \
                     overshoot {overshoot}"
                );
                let mut solver = Progressive::new(&s, &mesh, &vis, options);
                exhaust(&mut solver, &name);
                assert!(solver.steps() > 0, "{name}");
            }
        }
    }
}

/// A real model under `--sky`: McGuire's Cornell box with two spheres
/// (2,200 faces, 8,000 vertices at this mesh), lit by its lamp and by
/// the sky through its open side. The sky's facets shoot by rays, the
/// spheres' many small faces through strata. (The 6,700-face airplane of
/// `raylib/plane.obj` takes a second a step under a sky.)
#[test]
fn a_model_under_a_sky_stays_finite_to_exhaustion() {
    let model = root().join("tests/models/mcguire/CornellBox-Sphere.obj");
    let mut config = RunConfig::new(SceneSource::File(model));
    config.lenmax = Some(0.3);
    config.sky = Some(radiosity::color::Rgb::splat(1.0));
    config.solver = exhausting(250);
    assert!(exhaust_run(&config) > 0);
}

/// `--threshold 0` ends cleanly (exit 0, converged) once nothing is left
/// to shoot: a lamp over a floor that reflects nothing leaves exactly
/// zero after its one step.
#[test]
fn threshold_0_stops_converged_at_exactly_zero() {
    let s = scene(
        vec![
            polygon(0, &[[0., 1., 0.], [1., 1., 0.], [1., 1., 1.], [0., 1., 1.]]),
            polygon(1, &[[0., 0., 0.], [0., 0., 1.], [1., 0., 1.], [1., 0., 0.]]),
        ],
        vec![grey("lamp", 1.0, 0.0), grey("black", 0.0, 0.0)],
    );
    let mesh = regular_mesh(&s, 0.25);
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &mesh, &vis, exhausting(100));
    let reason = exhaust(&mut solver, "lamp over black");
    assert!(
        matches!(reason, Some(StopReason::Converged) | None),
        "{reason:?}"
    );
    assert_eq!(solver.unshot_power(), 0.0);
    assert_eq!(solver.steps(), 1);
}

/// The command line: `--threshold 0` with `--max-steps` stops at the
/// step limit with exit 0; a scene that empties stops converged, its
/// unshot fraction exactly 0.
#[test]
fn threshold_0_runs_to_the_step_limit_or_to_zero() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = bundled("cornell.sc");
    let out = run_in(
        dir.path(),
        &[
            cornell.to_str().unwrap(),
            "--threshold",
            "0",
            "--max-steps",
            "40",
            "--lenmax",
            "60",
            "--size",
            "32x24",
            "-o",
            "a.png",
            "--stats",
            "a.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let stats = read_json(dir.path(), "a.json");
    assert_eq!(stats["steps"], 40, "{stats}");
    assert_eq!(stats["converged"], false, "{stats}");

    let lamp = common::write(
        dir.path(),
        "lamp.sc",
        "camera\n eye 0.5 0.5 3\n lookat 0.5 0.5 0\n up 0 1 0\n fov 60\nend\n\
         material lamp\n color 1 1 1\n k_emission 1\nend\n\
         material black\n color 1 1 1\n k_diffrefl 0\nend\n\
         polygon lamp\n vertex 0 1 0\n vertex 1 1 0\n vertex 1 1 1\n vertex 0 1 1\nend\n\
         polygon black\n vertex 0 0 0\n vertex 0 0 1\n vertex 1 0 1\n vertex 1 0 0\nend\n",
    );
    let out = run_in(
        dir.path(),
        &[
            lamp.to_str().unwrap(),
            "--threshold",
            "0",
            "--size",
            "32x24",
            "-o",
            "b.png",
            "--stats",
            "b.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let stats = read_json(dir.path(), "b.json");
    assert_eq!(stats["unshot_fraction"], 0.0, "{stats}");
    assert_eq!(stats["converged"], true, "{stats}");
}
