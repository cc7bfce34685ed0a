//! One conformance suite for every way the solver can shoot: each
//! closed-form check runs over every configuration (form factor method ×
//! unshot scheme × clustering where it applies) that claims it, with the
//! tolerance that configuration states for it.
//!
//! The checks: the form factor between two parallel and between two
//! perpendicular unit squares, measured through one shooting step; the
//! uniform enclosure `B = e / (1 − ρ)`; energy balance in a closed and in
//! an open box; a shadow; and the same bits on one thread and on two.
//! The closed forms and scenes are those of the solver's unit tests, which
//! checked one configuration at a time; here a configuration is a row of
//! [`configurations`] listing its tolerance per check with the reason,
//! and every solve is built through the solver's seam
//! (`radiosity::solver::build`, in `common::scenes::solve_on`), so a new
//! method is one more row. A
//! bound the unit tests stated is kept; where none was stated (the
//! estimates with known losses), the bound is what the configuration
//! measures today with a margin, and a check a configuration cannot pass
//! is left out of its row with the reason.
//!
//! Clusters form of small polygons only: in the scenes of whole walls the
//! clustered and unclustered rows differ by the receivers' interpolation
//! alone, which goes with clustering; the determinism check's tiled box
//! has clusters.

mod common;

use common::scenes::{
    absorbed_power, closed_box, grey, lamp_materials, mean_radiosity, on_threads, polygon,
    same_bits, scene, solve, tiled_shadowed_box,
};
use glam::Vec3;
use radiosity::color::Rgb;
use radiosity::scene::Scene;
use radiosity::solver::kernel::formfactor::point_to_polygon;
use radiosity::solver::{
    Approximations, FormFactorMethod, Heuristic, ShooterSamples, SolverOptions, TailOption,
    UnshotScheme,
};

/// Exact form factor between two coaxial parallel unit squares one unit
/// apart (Howell's catalogue, C-11).
const F_PARALLEL_UNIT_SQUARES: f64 = 0.19982;
/// Exact form factor between two unit squares meeting at a right angle
/// along a full edge (Howell's catalogue, C-14).
const F_PERPENDICULAR_UNIT_SQUARES: f64 = 0.20004;

/// The unit square in the plane z = 0, facing +z: the emitter.
const BOTTOM: [[f32; 3]; 4] = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
/// The unit square one unit above [`BOTTOM`], facing it.
const TOP: [[f32; 3]; 4] = [[0., 0., 1.], [0., 1., 1.], [1., 1., 1.], [1., 0., 1.]];
/// The unit square in the plane x = 0 sharing [`BOTTOM`]'s edge along y,
/// facing +x.
const SIDE: [[f32; 3]; 4] = [[0., 0., 0.], [0., 1., 0.], [0., 1., 1.], [0., 0., 1.]];

/// The closed-form checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Check {
    /// `|F − 0.19982| / 0.19982` for parallel unit squares.
    ParallelSquares,
    /// `|F − 0.20004| / 0.20004` for perpendicular unit squares.
    PerpendicularSquares,
    /// The worst vertex's `|B − e/(1 − ρ)| / (e/(1 − ρ))` in the uniform
    /// enclosure.
    EnclosureVertices,
    /// The worst wall mean's relative error in the uniform enclosure.
    EnclosureWalls,
    /// `|absorbed + unshot − emitted| / emitted` in a closed box.
    ClosedBalance,
    /// `|absorbed + escaped + unshot − emitted| / emitted` in an open box.
    OpenBalance,
    /// The radiosity of a floor point in an occluder's umbra as a fraction
    /// of an unoccluded one's: at most the tolerance.
    Shadow,
    /// One thread and two give the same radiosity bits (tolerance 0).
    ThreadDeterminism,
}

use Check::*;

/// A solver configuration and the checks it claims, each with its
/// tolerance.
struct Config {
    /// How failures name it.
    name: String,
    /// The solver's settings (threshold and step limit are the checks').
    options: SolverOptions,
    /// The checks it must pass, with their tolerances.
    claims: Vec<(Check, f64)>,
}

impl Config {
    /// This configuration's tolerance for `check`, if it claims it.
    fn tolerance(&self, check: Check) -> Option<f64> {
        self.claims
            .iter()
            .find(|(c, _)| *c == check)
            .map(|&(_, t)| t)
    }
}

/// A row of [`configurations`]: default options but for this method,
/// shooter samples, unshot scheme and clustering.
fn row(
    name: &str,
    form_factor: FormFactorMethod,
    shooter_samples: ShooterSamples,
    unshot: UnshotScheme,
    clustering: bool,
    claims: Vec<(Check, f64)>,
) -> Config {
    Config {
        name: name.to_owned(),
        options: SolverOptions {
            form_factor,
            shooter_samples,
            unshot,
            approximations: Approximations::DEFAULT.with(Heuristic::Clusters, clustering),
            ..SolverOptions::default()
        },
        claims,
    }
}

/// Every configuration: each form factor method (Wallace on the default
/// grid of shooter samples, Wallace from every element vertex, the centre
/// estimate, the hemicube) with each unshot scheme, and with clustering
/// on and off where it applies. Only Wallace on a grid clusters; the
/// other rows keep the default (on), which they ignore, as a command line
/// choosing them does.
// A table: one row per line.
#[rustfmt::skip]
fn configurations() -> Vec<Config> {
    use FormFactorMethod::{Center, Hemicube, Wallace};
    use UnshotScheme::{Polygon, Vertex};
    let grid = ShooterSamples::AtMost(radiosity::solver::tuning::DEFAULT_SHOOTER_SAMPLES);
    let all = ShooterSamples::All;
    vec![
        row("wallace grid, polygon, clustered", Wallace, grid, Polygon, true, wallace_grid(Polygon)),
        row("wallace grid, polygon, alone", Wallace, grid, Polygon, false, wallace_grid(Polygon)),
        row("wallace grid, vertex, clustered", Wallace, grid, Vertex, true, wallace_grid(Vertex)),
        row("wallace grid, vertex, alone", Wallace, grid, Vertex, false, wallace_grid(Vertex)),
        row("wallace all, polygon", Wallace, all, Polygon, true, wallace_all(Polygon)),
        row("wallace all, vertex", Wallace, all, Vertex, true, wallace_all(Vertex)),
        row("centre, polygon", Center, grid, Polygon, true, centre()),
        row("centre, vertex", Center, grid, Vertex, true, centre()),
        row("hemicube, polygon", Hemicube, grid, Polygon, true, hemicube(Polygon)),
        row("hemicube, vertex", Hemicube, grid, Vertex, true, hemicube(Vertex)),
        tail_row("wallace grid, polygon, clustered, particle tail", Polygon),
        tail_row("wallace grid, vertex, clustered, particle tail", Vertex),
    ]
}

/// The default solve with the particle tail
/// (`radiosity::solver::step::tail`) taking over once a third of the
/// power is left, at 1,000 particles a vertex: the checks of a solve to
/// its end (the form factors and the shadow are single shooting steps,
/// which no tail touches).
fn tail_row(name: &str, unshot: UnshotScheme) -> Config {
    let grid = ShooterSamples::AtMost(radiosity::solver::tuning::DEFAULT_SHOOTER_SAMPLES);
    let mut config = row(
        name,
        FormFactorMethod::Wallace,
        grid,
        unshot,
        true,
        tail(unshot),
    );
    config.options.tail = TailOption::From(0.3);
    config.options.tail_particles = 1000.0;
    config
}

/// The particle tail's bounds: the shooting steps' where a check sees no
/// tail, and its noise where it does.
fn tail(unshot: UnshotScheme) -> Vec<(Check, f64)> {
    vec![
        (ParallelSquares, 0.005),
        (PerpendicularSquares, 0.005),
        // Each vertex's light from the tail is the particles' that land
        // on it: measured 1.9 % (polygon) and 1.6 % (vertex) at the worst
        // vertex; a wall averages over a hundred vertices (0.39 % and
        // 0.07 %).
        (EnclosureVertices, 0.04),
        (EnclosureWalls, 0.01),
        // Nothing is left unshot: the balance holds to the particles'
        // noise (measured 0.02 % and 0.03 %).
        (ClosedBalance, 0.01),
        (
            OpenBalance,
            match unshot {
                // Measured 0.02 %.
                UnshotScheme::Vertex => 0.01,
                // Measured 0.76 %, the shooting row's loss: the scheme
                // re-emits each wall's light evenly before the tail.
                UnshotScheme::Polygon => 0.015,
            },
        ),
        (Shadow, 0.0),
        (ThreadDeterminism, 0.0),
    ]
}

/// Wallace's estimate on the default grid of 64 shooter samples, with
/// the near field.
fn wallace_grid(unshot: UnshotScheme) -> Vec<(Check, f64)> {
    vec![
        // The receiver is integrated on a 51 × 51 vertex grid; integrating
        // the exact point form factor there is within 0.005 %, so the
        // bound is on the estimate: 0.5 %.
        (ParallelSquares, 0.005),
        (PerpendicularSquares, 0.005),
        // Every vertex within 1 % with either scheme, and so every wall
        // (measured 0.04 % and 0.05 %).
        (EnclosureVertices, 0.01),
        (EnclosureWalls, 0.01),
        // Within 0.5 % with either scheme, clustered or not (measured
        // 0.02 % to 0.04 %).
        (ClosedBalance, 0.005),
        (
            OpenBalance,
            match unshot {
                UnshotScheme::Vertex => 0.005,
                // Measured 0.8 %: the scheme re-emits each wall's light
                // evenly, while the walls are darker near the opening, so
                // more light leaves through it than the solution's own
                // radiosities say.
                UnshotScheme::Polygon => 0.012,
            },
        ),
        // Each of the lamp's samples has its own shadow ray: the umbra is
        // black.
        (Shadow, 0.0),
        (ThreadDeterminism, 0.0),
    ]
}

/// Wallace's estimate from every element vertex of the shooter (the
/// original algorithm's samples), each vertex standing for its share of
/// the area with the plain disc term: no near field, so a receiver close
/// to a sample (a wall meeting the shooter at an edge) gets too little,
/// and light that should reach the walls next to a shooter is lost. The
/// bounds are what that loss measures today with a margin: they guard
/// against it growing, and the grid's rows check the physics.
fn wallace_all(unshot: UnshotScheme) -> Vec<(Check, f64)> {
    vec![
        // Measured 0.68 %: the vertices along the emitter's edges.
        (ParallelSquares, 0.01),
        // Measured 2.8 % low: the shared edge's samples touch the
        // receiver.
        (PerpendicularSquares, 0.04),
        (
            EnclosureVertices,
            match unshot {
                // Measured 13 % low at the worst (corner) vertex.
                UnshotScheme::Polygon => 0.2,
                // Measured 25 %: the corner vertices' unshot light is
                // shot from the corners themselves.
                UnshotScheme::Vertex => 0.3,
            },
        ),
        // Measured 10 % (polygon) and 12 % (vertex) low.
        (EnclosureWalls, 0.15),
        // Measured 10 % (polygon) and 11 % (vertex) of the power lost.
        (ClosedBalance, 0.15),
        // Measured 7.7 % and 7.8 %.
        (OpenBalance, 0.1),
        // Every vertex of the lamp has its own shadow ray: the umbra is
        // black.
        (Shadow, 0.0),
        (ThreadDeterminism, 0.0),
    ]
}

/// The one-sample centre estimate: one ray and the point-to-disc form
/// factor from the shooter's centre, far too coarse for walls that meet
/// at an edge. Its bounds are its known losses, measured today (alike
/// with either unshot scheme) with a margin; the shadow and determinism
/// are exact.
fn centre() -> Vec<(Check, f64)> {
    vec![
        // One disc a unit away stands for the square: measured 6.3 % low.
        (ParallelSquares, 0.08),
        // Left out: the one sample is half a unit from the shared edge,
        // so the estimate is no measurement of this form factor (41 %
        // low).
        // In the uniform enclosure the estimate only has to stay
        // physical: every vertex above its own emission `e` (an error
        // under 0.6; measured 0.51), ...
        (EnclosureVertices, 0.6),
        // ... and the walls' means measured 35 % and 34 % low.
        (EnclosureWalls, 0.4),
        // The known energy loss of the centre estimate: the light a
        // wall sends its neighbours across their shared edges is
        // underestimated as the perpendicular pair's is. Measured 55 %
        // and 54 % of the power lost in the closed box, 40 % and 39 % in
        // the open one.
        (ClosedBalance, 0.6),
        (OpenBalance, 0.45),
        // The one ray from the lamp's centre is blocked.
        (Shadow, 0.0),
        (ThreadDeterminism, 0.0),
    ]
}

/// Cohen and Greenberg's hemicube at the default resolution (N = 128),
/// one per shooter cell.
fn hemicube(unshot: UnshotScheme) -> Vec<(Check, f64)> {
    vec![
        // 64 cells and N = 128: the pixel outline error (0.25 % against
        // the exact midpoint rule) plus 0.5 % of quadrature. Measured
        // 0.23 % and 0.03 %.
        (ParallelSquares, 0.0075),
        (PerpendicularSquares, 0.0075),
        // A corner vertex holds the light of one element, which the
        // hemicubes of the neighbouring walls see edge-on across a few
        // pixel rows: measured 3.7 % and 3.8 % at the worst vertex.
        (EnclosureVertices, 0.05),
        (
            EnclosureWalls,
            match unshot {
                // Every pixel shows a wall and the pixels sum to 1: the
                // walls' means are exact to the threshold (measured
                // 0.008 %).
                UnshotScheme::Vertex => 0.005,
                // Even vertex weights overweight the boundary vertices:
                // measured 0.6 %.
                UnshotScheme::Polygon => 0.01,
            },
        ),
        (
            ClosedBalance,
            match unshot {
                // Each step hands on exactly the power it clears (times
                // ρ): exact to rounding (measured 0).
                UnshotScheme::Vertex => 1e-9,
                // Even vertex weights, with the boundary vertices holding
                // the boundary elements' light alone: measured 1.6 %.
                UnshotScheme::Polygon => 0.02,
            },
        ),
        (
            OpenBalance,
            match unshot {
                // Lambert's escape evaluated at the vertices rather than
                // over the elements the hemicube integrated: measured
                // 0.01 %.
                UnshotScheme::Vertex => 0.005,
                // The closed box's even vertex weights again: measured
                // 1.6 %.
                UnshotScheme::Polygon => 0.025,
            },
        ),
        // No pixel of any hemicube sees a point an element deep in the
        // umbra.
        (Shadow, 0.0),
        (ThreadDeterminism, 0.0),
    ]
}

/// Runs `measure` for every configuration claiming `check` and returns
/// a line for each whose error exceeds its tolerance, naming it with the
/// expected and measured values. `measure` returns the error (compared
/// with the tolerance) and a description of what it measured.
fn run(check: Check, mut measure: impl FnMut(&Config) -> (f64, String)) -> Vec<String> {
    let mut failures = Vec::new();
    let mut claimed = 0;
    for config in configurations() {
        let Some(tolerance) = config.tolerance(check) else {
            continue;
        };
        claimed += 1;
        let (error, what) = measure(&config);
        eprintln!("{check:?}, {}: {what}; error {error:e}", config.name);
        if error.is_nan() || error > tolerance {
            failures.push(format!(
                "{check:?}, {}: {what}; error {error:e}, tolerance {tolerance:e}",
                config.name
            ));
        }
    }
    assert!(claimed > 0, "{check:?}: no configuration claims it");
    failures
}

/// Fails with every line of `failures`, if any.
fn assert_passed(failures: Vec<String>) {
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// Form factor from polygon 1 to emitter 0 measured through one shooting
/// step: with `e = 1` and `ρ = 0.5` every receiver vertex gets `0.5 ·
/// F(vertex → emitter)`; the area mean over the receiver is `0.5 · F_10`,
/// which for equal areas is the emitter's form factor to it.
fn measured_form_factor(receiver: [[f32; 3]; 4], options: SolverOptions) -> f64 {
    let s = scene(
        vec![polygon(0, &BOTTOM), polygon(1, &receiver)],
        vec![grey("lamp", 1.0, 0.0), grey("wall", 0.0, 0.5)],
    );
    let options = SolverOptions {
        max_steps: Some(1),
        ..options
    };
    let solved = solve(&s, 0.02, options);
    mean_radiosity(&solved.mesh, &solved.radiosity, 1).r / 0.5
}

/// The relative error of a measured form factor and what was measured.
fn form_factor_error(receiver: [[f32; 3]; 4], exact: f64, options: SolverOptions) -> (f64, String) {
    let f = measured_form_factor(receiver, options);
    ((f - exact).abs() / exact, format!("F = {f}, exact {exact}"))
}

#[test]
fn parallel_unit_squares() {
    assert_passed(run(ParallelSquares, |c| {
        form_factor_error(TOP, F_PARALLEL_UNIT_SQUARES, c.options)
    }));
}

#[test]
fn perpendicular_unit_squares() {
    assert_passed(run(PerpendicularSquares, |c| {
        form_factor_error(SIDE, F_PERPENDICULAR_UNIT_SQUARES, c.options)
    }));
}

/// The uniform enclosure: a closed unit box whose walls all have `e = 1`
/// and `ρ = 0.6`, solved to a threshold of 1e-4 on elements 0.1 across.
/// Returns the worst vertex's and the worst wall mean's relative errors
/// from the exact `B = e / (1 − ρ)`, and the step count.
fn uniform_enclosure_errors(options: SolverOptions) -> (f64, f64, u64) {
    let (e, rho) = (1.0, 0.6);
    let s = scene(closed_box(1.0, [0; 6]), vec![grey("wall", e, rho)]);
    let exact = e / (1.0 - rho);
    let solved = solve(
        &s,
        0.1,
        SolverOptions {
            threshold: 1e-4,
            ..options
        },
    );
    let worst_vertex = solved
        .radiosity
        .iter()
        .map(|b| (b.r - exact).abs() / exact)
        .fold(0.0, f64::max);
    let worst_wall = (0..6)
        .map(|p| (mean_radiosity(&solved.mesh, &solved.radiosity, p).r - exact).abs() / exact)
        .fold(0.0, f64::max);
    (worst_vertex, worst_wall, solved.steps)
}

/// Both enclosure checks from one solve per configuration.
#[test]
fn uniform_enclosure() {
    let mut solved = std::collections::HashMap::new();
    let mut measure = |c: &Config| {
        *solved.entry(c.name.clone()).or_insert_with(|| {
            let (vertex, wall, steps) = uniform_enclosure_errors(c.options);
            assert!(steps > 6, "{}: {steps} steps", c.name);
            (vertex, wall)
        })
    };
    let mut failures = run(EnclosureVertices, |c| {
        let (vertex, _) = measure(c);
        (vertex, format!("worst vertex off B = 2.5 by {vertex}"))
    });
    failures.extend(run(EnclosureWalls, |c| {
        let (_, wall) = measure(c);
        (wall, format!("worst wall mean off B = 2.5 by {wall}"))
    }));
    assert_passed(failures);
}

/// In a closed room the power emitted equals the power absorbed, where a
/// polygon absorbs `A (1 − ρ)/ρ · (B − e)`; the unshot power left at the
/// end counts as not yet absorbed. The glowing box, solved to 1e-5 on
/// elements 0.1 across.
#[test]
fn energy_balance_in_a_closed_box() {
    assert_passed(run(ClosedBalance, |c| {
        let s = common::scenes::glowing_box();
        let options = SolverOptions {
            threshold: 1e-5,
            ..c.options
        };
        let solved = solve(&s, 0.1, options);
        let absorbed = absorbed_power(&s, &solved.mesh, &solved.radiosity);
        let emitted = solved.initial_power;
        let error = (absorbed + solved.unshot_power - emitted).abs() / emitted;
        (
            error,
            format!(
                "emitted {emitted}, absorbed {absorbed} + unshot {}",
                solved.unshot_power
            ),
        )
    }));
}

/// The glowing box without its top: emitted = absorbed + escaped +
/// unshot, where the power escaping from a point `x` of a wall is `B(x) ·
/// F(x → opening)` with Lambert's exact `F` to the missing square
/// (nothing inside the convex box blocks it), summed over the vertices'
/// areas where the solver evaluates `B`.
#[test]
fn energy_balance_in_an_open_box() {
    let mut walls = closed_box(2.0, [1, 2, 1, 0, 1, 2]);
    // Lambert's integral is unsigned: the opening's orientation is moot.
    let opening = walls.pop().expect("six walls");
    let s = scene(walls, lamp_materials());
    assert_passed(run(OpenBalance, |c| {
        let options = SolverOptions {
            threshold: 1e-5,
            ..c.options
        };
        let solved = solve(&s, 0.1, options);
        let areas = solved.mesh.vertex_areas();
        let (mut absorbed, mut escaped) = (0.0, 0.0);
        for (p, polygon) in s.polygons.iter().enumerate() {
            let material = &s.materials[polygon.material.index()];
            let (rho, e) = (material.reflectance().r, material.emission().r);
            let pm = &solved.mesh.polygons[p];
            for l in pm.vertices.clone() {
                let (b, a) = (solved.radiosity[l as usize].r, areas[l as usize]);
                absorbed += a * (1.0 - rho) / rho * (b - e);
                let x = solved.mesh.sample_positions[l as usize];
                escaped += a * b * point_to_polygon(x, pm.normal, &opening.vertices);
            }
        }
        let emitted = solved.initial_power;
        assert!(
            escaped > 0.2 * emitted,
            "{}: the opening lets light out: {escaped} of {emitted}",
            c.name
        );
        let error = (absorbed + escaped + solved.unshot_power - emitted).abs() / emitted;
        (
            error,
            format!(
                "emitted {emitted}, absorbed {absorbed} + escaped {escaped} + unshot {}",
                solved.unshot_power
            ),
        )
    }));
}

/// A lamp 2 units over a floor, facing down, and an opaque black square
/// halfway between: a floor point under the blocker's centre is an
/// element or more inside the umbra. One step; the measured value is its
/// radiosity as a fraction of a floor point's outside the shadow (which
/// must be lit).
#[test]
fn occluder_casts_a_shadow() {
    let s = scene(
        vec![
            // The lamp, facing -z.
            polygon(
                0,
                &[[-0.5, 0., 2.], [-0.5, 1., 2.], [0.5, 1., 2.], [0.5, 0., 2.]],
            ),
            // The floor, facing +z.
            polygon(
                1,
                &[[-3., -2., 0.], [3., -2., 0.], [3., 3., 0.], [-3., 3., 0.]],
            ),
            // The blocker.
            polygon(
                2,
                &[
                    [-1., -0.5, 1.],
                    [1., -0.5, 1.],
                    [1., 1.5, 1.],
                    [-1., 1.5, 1.],
                ],
            ),
        ],
        vec![
            grey("lamp", 1.0, 0.0),
            grey("floor", 0.0, 0.5),
            grey("black", 0.0, 0.0),
        ],
    );
    assert_passed(run(Shadow, |c| {
        let options = SolverOptions {
            max_steps: Some(1),
            ..c.options
        };
        let solved = solve(&s, 0.25, options);
        let m = &solved.mesh;
        let vertex_at = |x: f32, y: f32| {
            m.polygons[1]
                .vertices
                .clone()
                .min_by(|&p, &q| {
                    let d = |v: u32| m.positions[v as usize].distance(Vec3::new(x, y, 0.0));
                    d(p).total_cmp(&d(q))
                })
                .expect("a floor vertex") as usize
        };
        let under = solved.radiosity[vertex_at(0.0, 0.5)].max_channel();
        let outside = solved.radiosity[vertex_at(2.5, 0.5)].r;
        assert!(outside > 0.0, "{}: the floor outside is lit", c.name);
        (
            under / outside,
            format!("B = {under} in the umbra, {outside} outside"),
        )
    }));
}

/// A scene for determinism: [`tiled_shadowed_box`] has clusters of tiles
/// and a blocker whose shadow the rays must find.
fn determinism_scene() -> Scene {
    tiled_shadowed_box(4)
}

/// One thread or two, the same bits: 25 steps of the tiled, shadowed box
/// on elements 0.15 across.
#[test]
fn thread_count_does_not_change_the_result() {
    let s = determinism_scene();
    assert_passed(run(ThreadDeterminism, |c| {
        let options = SolverOptions {
            max_steps: Some(25),
            ..c.options
        };
        let runs: Vec<Vec<Rgb>> = [1, 2]
            .into_iter()
            .map(|threads| on_threads(threads, || solve(&s, 0.15, options).radiosity))
            .collect();
        let differ = runs[0]
            .iter()
            .zip(&runs[1])
            .filter(|(a, b)| !same_bits(&[**a], &[**b]))
            .count();
        (
            differ as f64,
            format!("{differ} of {} vertices differ", runs[0].len()),
        )
    }));
}
