//! The particle tail ([`crate::solver::step::tail`]) against closed
//! forms, energy balance and its brute-force twin (shooting steps to the
//! end), and its bits on any thread count.

use super::*;
use crate::testutil::regular_mesh;

/// Tail options: from `from` of the emitted power, `particles` per
/// element vertex.
fn tail(from: f64, particles: f64) -> SolverOptions {
    SolverOptions {
        tail: TailOption::From(from),
        tail_particles: particles,
        threshold: 1e-4,
        ..Default::default()
    }
}

/// In a closed box whose walls all emit 1 and reflect 0.6, every point's
/// radiosity is `e / (1 − ρ) = 2.5`. The tail takes over once every wall
/// has shot its own light (0.6 of the power is then left, 40 % of each
/// point's final radiosity): the mean over the vertices within 0.5 %,
/// every vertex within 4 % (its noise: about 2,000 particles land on each
/// vertex's hat).
#[test]
fn the_tail_fills_the_uniform_enclosure() {
    let (e, rho) = (1.0, 0.6);
    let s = scene(closed_box(1.0, [0; 6]), vec![grey("wall", e, rho)]);
    let exact = e / (1.0 - rho);
    for unshot in [UnshotScheme::Polygon, UnshotScheme::Vertex] {
        let options = SolverOptions {
            unshot,
            ..tail(1.0, 1000.0)
        };
        let solved = solve(&s, 0.125, crate::mesh::DEFAULT_INSET, options);
        let errors: Vec<f64> = solved
            .radiosity
            .iter()
            .map(|b| (b.r - exact) / exact)
            .collect();
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        let worst = errors.iter().fold(0.0f64, |w, x| w.max(x.abs()));
        eprintln!("{unshot:?}: mean error {mean:+.5}, worst vertex {worst:.5}");
        assert!(mean.abs() < 0.005, "{unshot:?}: mean {mean}");
        assert!(worst < 0.04, "{unshot:?}: worst {worst}");
        assert_eq!(solved.unshot_power, 0.0);
    }
}

/// The uniform enclosure with its floor written as a real exporter writes
/// an n-gon: a fan of 48 long thin triangles from one point of an edge
/// (apex angles of 2° to 6°), whose elements near the apex are needles.
/// Each particle must land on the element holding it
/// ([`crate::solver::unshot`]'s locator): every floor vertex within 10 % of the closed form at 200
/// particles a vertex (7.7 % measured), the floor's mean within 1 %.
#[test]
fn a_fan_of_thin_triangles_fills_the_uniform_enclosure() {
    let (e, rho) = (1.0, 0.6);
    let exact = e / (1.0 - rho);
    let mut polygons = closed_box(1.0, [0; 6]);
    polygons.remove(2); // the floor, y = 0
    let walls = polygons.len();
    let apex = [0.5f32, 0.0, 0.0];
    let mut rim: Vec<[f32; 3]> = Vec::new();
    for k in 0..=16 {
        rim.push([1.0, 0.0, k as f32 / 16.0]);
    }
    for k in 1..=16 {
        rim.push([1.0 - k as f32 / 16.0, 0.0, 1.0]);
    }
    for k in 1..=16 {
        rim.push([0.0, 0.0, 1.0 - k as f32 / 16.0]);
    }
    for w in rim.windows(2) {
        let mut p = polygon(0, &[apex, w[0], w[1]]);
        if p.normal.y < 0.0 {
            p = polygon(0, &[apex, w[1], w[0]]);
        }
        polygons.push(p);
    }
    let fan = polygons.len() - walls;
    assert_eq!(fan, 48);
    let s = scene(polygons, vec![grey("wall", e, rho)]);
    let solved = solve(&s, 0.125, crate::mesh::DEFAULT_INSET, tail(1.0, 200.0));
    let floor: Vec<f64> = (0..solved.mesh.vertex_count())
        .filter(|&l| solved.mesh.vertex_polygon[l].index() >= walls)
        .map(|l| (solved.radiosity[l].r - exact) / exact)
        .collect();
    let mean = floor.iter().sum::<f64>() / floor.len() as f64;
    let worst = floor.iter().fold(0.0f64, |w, x| w.max(x.abs()));
    eprintln!(
        "{} floor vertices: mean error {mean:+.4}, worst {worst:.4}",
        floor.len()
    );
    assert!(mean.abs() < 0.01, "mean {mean}");
    assert!(worst < 0.1, "worst {worst}");
    assert_eq!(solved.unshot_power, 0.0);
}

/// In a closed box the power emitted is the power absorbed: the tail
/// carries the light left to its end, so nothing is left unshot and the
/// balance holds within the tail's noise (1 %; shooting to 10⁻⁵ holds it
/// within 0.5 %, `energy_balance_in_a_closed_box`).
#[test]
fn the_tail_balances_energy_in_a_closed_box() {
    let s = glowing_box();
    let solved = solve_on(&s, refined_across(&s, 0.1, 0.77), tail(0.2, 400.0));
    let error = energy_error(&s, &solved);
    eprintln!("tail from 20 %: energy error {error}");
    assert_eq!(solved.unshot_power, 0.0);
    assert!(error < 0.01, "{error}");
}

/// The brute-force twin: a lit room with a plate casting a shadow on its
/// floor, solved by shooting steps to 10⁻⁴ of the power and by shooting
/// to 5 % and the tail. Mean relative difference per vertex under 1 %,
/// the mean radiosity within 0.3 %.
#[test]
fn the_tail_matches_shooting_to_the_end() {
    let s = shadowed_box();
    let exact = shot_to_the_end(&s);
    let tailed = solve(&s, 0.1, crate::mesh::DEFAULT_INSET, tail(0.05, 400.0));
    assert!(
        tailed.steps < exact.steps,
        "{} {}",
        tailed.steps,
        exact.steps
    );
    let (l1, bias) = l1_and_bias(&tailed.radiosity, &exact.radiosity);
    eprintln!(
        "steps {} vs {}: relative L1 {l1:.5}, bias {bias:+.5}",
        tailed.steps, exact.steps
    );
    assert!(l1 < 0.01, "{l1}");
    assert!(bias.abs() < 0.003, "{bias}");
}

/// `s` solved by shooting steps to 10⁻⁴ of the power, without the tail.
fn shot_to_the_end(s: &Scene) -> Solved {
    solve(
        s,
        0.1,
        crate::mesh::DEFAULT_INSET,
        SolverOptions {
            tail: TailOption::Off,
            threshold: 1e-4,
            ..Default::default()
        },
    )
}

/// The mean relative difference per vertex of `radiosity` from `exact`
/// (by the mean of the channels), and the relative difference of their
/// means.
fn l1_and_bias(radiosity: &[Rgb], exact: &[Rgb]) -> (f64, f64) {
    let n = exact.len() as f64;
    let l1 = exact
        .iter()
        .zip(radiosity)
        .map(|(a, b)| (a.mean() - b.mean()).abs() / a.mean())
        .sum::<f64>()
        / n;
    let mean = |r: &[Rgb]| r.iter().map(|b| b.mean()).sum::<f64>() / n;
    (l1, mean(radiosity) / mean(exact) - 1.0)
}

/// The final gather ([`crate::solver::step::tail_gather`]) against its
/// twin, the particles' own deposits: the shadowed room's tail from 30 %
/// with 4 particles a vertex, both against shooting to 10⁻⁴. The gather
/// must at least halve the particles' mean error per vertex (measured:
/// 3.7 % → 0.8 %) and keep the mean radiosity within 0.5 % (the gather
/// reads the particles' field, so a gather that lost or doubled a bounce
/// would move it by several percent).
#[test]
fn the_final_gather_takes_the_noise_out_of_few_particles() {
    let s = shadowed_box();
    let exact = shot_to_the_end(&s);
    let off_by = |gather: bool| {
        let options = SolverOptions {
            approximations: Approximations::DEFAULT.with(Heuristic::TailGather, gather),
            ..tail(0.3, 4.0)
        };
        let tailed = solve(&s, 0.1, crate::mesh::DEFAULT_INSET, options);
        let (l1, bias) = l1_and_bias(&tailed.radiosity, &exact.radiosity);
        eprintln!("gather {gather}: relative L1 {l1:.5}, bias {bias:+.5}");
        (l1, bias)
    };
    let (particles, _) = off_by(false);
    let (gathered, bias) = off_by(true);
    assert!(gathered < 0.5 * particles, "{gathered} vs {particles}");
    assert!(bias.abs() < 0.005, "{bias}");
}

/// A tail step's particles draw their numbers from their own index and
/// are summed in their order: the same bits on one thread and on three.
#[test]
fn the_tail_gives_the_same_bits_on_any_thread_count() {
    let s = shadowed_box();
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| solve(&s, 0.1, crate::mesh::DEFAULT_INSET, tail(0.1, 50.0)).radiosity)
    };
    assert_eq!(on(1), on(3));
}

/// A cancelled tail step changes nothing, and the next one runs.
#[test]
fn a_cancelled_tail_step_changes_nothing() {
    let s = glowing_box();
    let mesh = regular_mesh(&s, 0.2);
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &mesh, &vis, tail(1.0, 50.0));
    while solver.step().is_some_and(|r| r.particles == 0) {}
    let before = (solver.radiosity().to_vec(), solver.unshot().to_vec());
    let steps = solver.steps();
    let cancel = std::sync::atomic::AtomicBool::new(true);
    assert!(solver.step_cancellable(&cancel).is_none());
    assert_eq!(
        (solver.radiosity().to_vec(), solver.unshot().to_vec()),
        before
    );
    assert_eq!(solver.steps(), steps);
    assert!(solver.step().is_some_and(|r| r.particles > 0));
}

/// A solve saved during its tail and resumed goes on to the same bits as
/// the solve that was never stopped: a tail step's share is a function of
/// the unshot fraction alone.
#[test]
fn a_tail_resumed_from_its_state_ends_as_the_uninterrupted_one() {
    let s = shadowed_box();
    let mesh = regular_mesh(&s, 0.1);
    let vis = Visibility::new(&s);
    let options = tail(0.1, 50.0);
    let run = |solver: &mut Progressive| while !solver.is_done() && solver.step().is_some() {};
    let mut whole = Progressive::new(&s, &mesh, &vis, options);
    run(&mut whole);
    let mut first = Progressive::new(&s, &mesh, &vis, options);
    while first.step().is_some_and(|r| r.particles == 0) {}
    let mut resumed = Progressive::new(&s, &mesh, &vis, options);
    resumed.restore(first.state()).unwrap();
    run(&mut resumed);
    assert_eq!(resumed.steps(), whole.steps());
    assert_eq!(resumed.radiosity(), whole.radiosity());
}

/// A step is costly when it cast more than `TAIL_COSTLY_RATIO` times
/// the tail's particles per unit of power, counting either sign of power
/// shot; a step that shot nothing, or a solve with nothing left, is not.
#[test]
fn a_step_is_costly_past_the_ratio_of_the_tails_particles() {
    use crate::solver::step::tail::costly;
    use crate::solver::tuning::TAIL_COSTLY_RATIO;
    // 1,000 particles for 100 of power left: 10 a unit; a step of 2 of
    // power is costly past 2 · 10 · ratio rays.
    let at = (2.0 * 10.0 * TAIL_COSTLY_RATIO) as u64;
    assert!(!costly(at, 2.0, 100.0, 1000.0));
    assert!(costly(at + 1, 2.0, 100.0, 1000.0));
    assert!(costly(at + 1, -2.0, 100.0, 1000.0));
    assert!(!costly(u64::MAX, 0.0, 100.0, 1000.0));
    assert!(!costly(u64::MAX, 2.0, 0.0, 1000.0));
}

/// An automatic tail takes over early after a step that cost far more
/// rays for its light than the tail's particles would
/// (`TAIL_COSTLY_RATIO`). In the shadowed room with a tail of few
/// particles every shooting step is costly: the tail takes over right
/// after the first step that leaves at most `TAIL_EARLY_FROM`, at that
/// step's fraction, not at its own 1 %. A solve saved right then and
/// resumed ends as the uninterrupted one (the state keeps the fraction;
/// without it the resumed solve would shoot on). A tail whose fraction is
/// given waits for it.
#[test]
fn a_costly_step_hands_the_rest_to_an_automatic_tail() {
    use crate::solver::tuning::TAIL_EARLY_FROM;
    let s = shadowed_box();
    let mesh = regular_mesh(&s, 0.1);
    let vis = Visibility::new(&s);
    let options = tail(0.01, 0.05);
    let automatic = || {
        let mut solver = Progressive::new(&s, &mesh, &vis, options);
        solver.tail.automatic_from(0.01);
        solver
    };
    let run = |solver: &mut Progressive| while !solver.is_done() && solver.step().is_some() {};
    // Up to the step after which the tail takes over.
    let mut first = automatic();
    let mut last = None;
    while first.tail_from() == Some(0.01) {
        let report = first.step().expect("a step");
        assert_eq!(report.particles, 0, "a tail step before the hand-over");
        last = Some(report);
    }
    let last = last.unwrap();
    let from = first.tail_from().unwrap();
    eprintln!("handed over after step {} at {from}", last.step);
    assert_eq!(from, last.unshot_fraction);
    assert!(from > 0.01 && from <= TAIL_EARLY_FROM, "{from}");
    assert!(first.step().is_some_and(|r| r.particles > 0));
    // Saved at the hand-over and resumed.
    let mut whole = automatic();
    run(&mut whole);
    let mut saved = automatic();
    while saved.steps() < last.step {
        saved.step();
    }
    assert_eq!(saved.state().tail_from, Some(from));
    let mut resumed = automatic();
    resumed.restore(saved.state()).unwrap();
    run(&mut resumed);
    assert_eq!(resumed.steps(), whole.steps());
    assert_eq!(resumed.radiosity(), whole.radiosity());
    // Given its fraction, the tail waits for it.
    let mut given = Progressive::new(&s, &mesh, &vis, options);
    let mut fraction = 1.0;
    while let Some(r) = given.step().filter(|r| r.particles == 0) {
        fraction = r.unshot_fraction;
    }
    assert_eq!(given.tail_from(), Some(0.01));
    assert!(fraction <= 0.01, "{fraction}");
}

/// A tail step delivered in parts (the window's part budget) ends bit for
/// bit as the step in one piece; between its parts the solution shows the
/// light landed so far, rising part by part, and a cancel between parts
/// loses nothing: the next call goes on from the last part.
#[test]
fn a_tail_step_in_parts_ends_as_the_step_in_one_piece() {
    let s = glowing_box();
    let mesh = regular_mesh(&s, 0.1);
    let vis = Visibility::new(&s);
    // About 360,000 particles a tail step: six batches.
    let options = tail(1.0, 2000.0);
    let parted_options = SolverOptions {
        part_budget: Some(std::time::Duration::ZERO),
        ..options
    };
    let mut whole = Progressive::new(&s, &mesh, &vis, options);
    while whole.step().is_some_and(|r| r.particles == 0) {}
    let mut parted = Progressive::new(&s, &mesh, &vis, parted_options);
    let mean = |p: &Progressive| p.radiosity().iter().map(|b| b.g).sum::<f64>();
    // The shooting steps before the tail, each in parts too.
    loop {
        let r = parted.step().expect("a step");
        if r.particles > 0 {
            assert!(!r.complete, "the tail step comes in parts");
            break;
        }
    }
    let mut parts = 1;
    let mut last = mean(&parted);
    let cancel = std::sync::atomic::AtomicBool::new(true);
    loop {
        if parts == 3 {
            let held = parted.radiosity().to_vec();
            assert!(parted.step_cancellable(&cancel).is_none());
            assert!(parted.in_step(), "a cancel keeps the step under way");
            assert_eq!(parted.radiosity(), &held[..]);
        }
        let r = parted.step().expect("the tail step goes on");
        assert!(r.particles > 0);
        parts += 1;
        let now = mean(&parted);
        assert!(
            now >= last - 1e-9 * last.abs(),
            "part {parts}: {now} < {last}"
        );
        last = now;
        if r.complete {
            assert_eq!(r.part, parts);
            break;
        }
        assert!(!parted.is_done() && parted.in_step());
    }
    assert!(parts > 3, "{parts} parts");
    assert_eq!(parted.steps(), whole.steps());
    assert_eq!(parted.radiosity(), whole.radiosity());
    assert_eq!(parted.unshot(), whole.unshot());
    assert!(!parted.in_step());
}
