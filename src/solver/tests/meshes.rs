//! Solves on refined meshes: continued from a coarser solve as adaptive
//! subdivision continues them, against a fresh solve, and grid
//! independence.

use super::*;

/// Solves `s` adaptively as `--adaptive` does, through the solve session:
/// on its regular mesh, then refined by the solution's luminance and
/// continued twice ([`Progressive::refined_state`]).
fn solve_adaptively(s: &Scene, lenmax: f32, options: SolverOptions) -> Solved {
    use crate::session::{Session, SessionOptions};
    use std::sync::atomic::AtomicBool;
    let mesh = mesh::build(
        s,
        &MeshOptions {
            lenmax,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(s);
    let mut session = Session::new(
        s,
        &mesh,
        &vis,
        SessionOptions {
            solver: options,
            refine: Some(Default::default()),
            max_elements: crate::mesh::MAX_ELEMENTS,
            ambient: false,
        },
    );
    assert!(session.run_to_end(&AtomicBool::new(false)).unwrap());
    assert_eq!(session.passes().len(), 3);
    session.validate().unwrap();
    let solver = session.solver();
    Solved {
        radiosity: solver.radiosity().to_vec(),
        steps: solver.steps(),
        initial_power: solver.initial_unshot_power(),
        unshot_power: solver.net_unshot_power(),
        mesh: session.mesh().clone(),
    }
}

/// [`solve_adaptively`] with the elements marked by a step of the field
/// across the plane `x = cut` instead of the luminance, so that a uniform
/// solution gets refined too. (A session refines by luminance only, so this
/// drives the refiner itself.)
fn solve_continued(s: &Scene, lenmax: f32, cut: f32, options: SolverOptions) -> Solved {
    use crate::mesh::refine::{RefineOptions, Refiner};
    let mut mesh = mesh::build(
        s,
        &MeshOptions {
            lenmax,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(s);
    let mut refiner = Refiner::new(&mesh);
    let mut start = None;
    loop {
        let mut solver = Progressive::new(s, &mesh, &vis, options);
        if let Some(state) = start.take() {
            solver.restore(state).unwrap();
        }
        while !solver.is_done() && solver.step().is_some() {}
        solver.validate().unwrap();
        let field: Vec<f64> = mesh
            .positions
            .iter()
            .map(|p| if p.x < cut { 0.2 } else { 1.0 })
            .collect();
        let options = RefineOptions::default();
        let next = if refiner.passes() < options.levels {
            refiner.refine(s, &field, &options)
        } else {
            None
        };
        match next {
            Some((refined, _)) => {
                start = solver
                    .refined_state(&refined, &refiner, &AtomicBool::new(false))
                    .expect("not cancelled");
                assert!(start.is_some());
                drop(solver);
                mesh = refined;
            }
            None => {
                assert_eq!(refiner.passes(), 2);
                return Solved {
                    radiosity: solver.radiosity().to_vec(),
                    steps: solver.steps(),
                    initial_power: solver.initial_unshot_power(),
                    unshot_power: solver.net_unshot_power(),
                    mesh,
                };
            }
        }
    }
}

/// A solve continued on refined meshes keeps the closed forms: the
/// uniform enclosure exact at every vertex (new vertices gather exactly
/// `e/(1 − rho)`), and the closed box's energy balanced within 0.5 %.
#[test]
fn continued_refinement_keeps_closed_forms() {
    let (e, rho) = (1.0, 0.6);
    let uniform = scene(closed_box(1.0, [0; 6]), vec![grey("wall", e, rho)]);
    let options = SolverOptions {
        threshold: 1e-4,
        ..Default::default()
    };
    let solved = solve_continued(&uniform, 0.1, 0.37, options);
    let exact = e / (1.0 - rho);
    let worst = solved
        .radiosity
        .iter()
        .map(|b| (b.r - exact).abs() / exact)
        .fold(0.0, f64::max);
    eprintln!("continued, uniform box: worst vertex error {worst}");
    assert!(worst < 0.01, "{worst}");

    let glowing = glowing_box();
    let solved = solve_continued(
        &glowing,
        0.1,
        0.77,
        SolverOptions {
            threshold: 1e-5,
            ..Default::default()
        },
    );
    let error = energy_error(&glowing, &solved);
    eprintln!("continued, glowing box: energy error {error}");
    assert!(error < 0.005, "energy error {error}");
}

/// Continuing on the refined mesh gives what solving it afresh gives: in
/// a box lit from its ceiling with a floating square casting a shadow on
/// the floor, every polygon's mean within 0.5 % and every vertex within
/// 0.5 % of the scene's mean radiosity (measured: 0.08 %). Where the
/// shooters' unshot fields are unchanged by the refinement, the gather is
/// the sum of the steps' contributions exactly, up to rounding.
#[test]
fn continued_refinement_matches_a_fresh_solve() {
    let s = shadowed_box();
    assert!(s.polygons[6].normal.y > 0.0);
    // Every vertex exact: interpolated receivers would make the two differ
    // by what interpolation changes on the coarse mesh's vertices (1.1 %
    // of the scene mean at worst), which is not what this checks.
    let options = SolverOptions {
        threshold: 1e-4,
        approximations: Approximations::DEFAULT.without(&Heuristic::RECEIVERS),
        ..Default::default()
    };
    let continued = solve_adaptively(&s, 0.1, options);
    let fresh = solve_on(&s, continued.mesh.clone(), options);
    let areas = continued.mesh.vertex_areas();
    let total_area: f64 = areas.iter().sum();
    let scene_mean = continued
        .radiosity
        .iter()
        .zip(&areas)
        .map(|(b, a)| b.luminance() * a)
        .sum::<f64>()
        / total_area;
    for p in 0..s.polygons.len() {
        let (a, b) = (
            mean_radiosity(&continued.mesh, &continued.radiosity, p).luminance(),
            mean_radiosity(&fresh.mesh, &fresh.radiosity, p).luminance(),
        );
        assert!(
            (a - b).abs() < 0.005 * b.max(0.01 * scene_mean),
            "polygon {p}: {a} continued, {b} fresh"
        );
    }
    let worst = continued
        .radiosity
        .iter()
        .zip(&fresh.radiosity)
        .map(|(a, b)| (a.luminance() - b.luminance()).abs() / scene_mean)
        .fold(0.0, f64::max);
    eprintln!("continued against fresh: worst vertex difference {worst} of the scene mean");
    assert!(worst < 0.005, "{worst}");
    assert!(fresh.steps > 0 && continued.mesh.vertex_count() > 0);
}

/// Grid independence: halving lenmax changes the mean radiosity of each
/// wall of the Cornell box by less than 1 %.
#[test]
fn cornell_walls_are_grid_independent() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.sc");
    let s = crate::scene::load(&path).unwrap();
    let coarse_lenmax = MeshOptions::for_scene(&s).lenmax;
    let options = SolverOptions::default();
    let coarse = solve(&s, coarse_lenmax, crate::mesh::DEFAULT_INSET, options);
    let fine = solve(&s, coarse_lenmax / 2.0, crate::mesh::DEFAULT_INSET, options);
    // The five walls: floor, ceiling, back, right, left (the first polygons
    // after the light in the file are the room's; check by reflectance).
    let mut checked = 0;
    for (p, polygon) in s.polygons.iter().enumerate() {
        if polygon.area < 200_000.0 {
            continue; // blocks and the light
        }
        let (a, b) = (
            mean_radiosity(&coarse.mesh, &coarse.radiosity, p),
            mean_radiosity(&fine.mesh, &fine.radiosity, p),
        );
        for (x, y) in a.to_array().into_iter().zip(b.to_array()) {
            assert!((x - y).abs() < 0.01 * y, "polygon {p}: {a:?} vs {b:?}");
        }
        checked += 1;
    }
    assert_eq!(checked, 5);
}
