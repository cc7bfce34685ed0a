//! The session against closed forms and against the solver run bare.

use super::*;
use crate::mesh::{self, refine::RefineOptions, MeshOptions};
use crate::testutil::{glowing_box, shadowed_box};

fn run_to_end(session: &mut Session) -> Vec<Event> {
    let cancel = AtomicBool::new(false);
    let mut events = Vec::new();
    loop {
        let event = session.advance(&cancel).unwrap();
        events.push(event);
        if event == Event::Finished {
            return events;
        }
        assert!(events.len() < 100_000, "the session never finished");
    }
}

fn build(s: &Scene, lenmax: f32) -> Mesh {
    mesh::build(
        s,
        &MeshOptions {
            lenmax,
            inset: mesh::DEFAULT_INSET,
        },
    )
    .unwrap()
}

fn options(refine: Option<RefineOptions>) -> SessionOptions {
    SessionOptions {
        solver: SolverOptions {
            threshold: 1e-4,
            ..Default::default()
        },
        refine,
        max_elements: mesh::MAX_ELEMENTS,
        ambient: false,
    }
}

/// Without refinement a session is the bare solver loop: the same steps
/// and the same radiosity bits, then `Stopped` and `Finished`.
#[test]
fn a_session_is_the_bare_solver_loop() {
    let s = glowing_box();
    let m = build(&s, 0.25);
    let vis = Visibility::new(&s);
    let o = options(None);
    let mut bare = crate::solver::build(&s, &m, &vis, o.solver);
    let mut bare_steps = 0;
    while !bare.is_done() && bare.step().is_some() {
        bare_steps += 1;
    }
    let mut session = Session::new(&s, &m, &vis, o);
    let events = run_to_end(&mut session);
    let steps = events
        .iter()
        .filter(|e| matches!(e, Event::Step(_)))
        .count();
    assert_eq!(steps, bare_steps);
    assert_eq!(
        &events[steps..],
        &[Event::Stopped(StopReason::Converged), Event::Finished]
    );
    let same = session
        .radiosity()
        .iter()
        .zip(bare.radiosity())
        .all(|(a, b)| a.r.to_bits() == b.r.to_bits() && a.b.to_bits() == b.b.to_bits());
    assert!(same);
    assert!(session.converged() && session.is_finished());
    assert_eq!(session.totals().steps, bare.steps());
    assert_eq!(session.totals().rays, bare.rays());
    assert_eq!(session.passes().len(), 1);
    // Finished stays finished.
    assert_eq!(
        session.advance(&AtomicBool::new(false)),
        Ok(Event::Finished)
    );
}

/// The uniform enclosure (every wall emitting `e`, reflecting `rho`) has
/// `B = e / (1 − rho)` everywhere; a session with refinement on reaches it
/// and refines nothing, since the solution has no edge.
#[test]
fn uniform_enclosure_through_a_session() {
    use crate::testutil::{closed_box, grey, scene};
    let (e, rho) = (1.0, 0.6);
    let s = scene(closed_box(1.0, [0; 6]), vec![grey("wall", e, rho)]);
    let m = build(&s, 0.1);
    let vis = Visibility::new(&s);
    let mut session = Session::new(&s, &m, &vis, options(Some(RefineOptions::default())));
    let events = run_to_end(&mut session);
    assert!(!events.iter().any(|e| matches!(e, Event::Refined(_))));
    let exact = e / (1.0 - rho);
    let worst = session
        .radiosity()
        .iter()
        .map(|b| (b.r - exact).abs() / exact)
        .fold(0.0, f64::max);
    assert!(worst < 0.01, "worst vertex error {worst}");
}

/// With refinement the session refines the shadow's edge up to the
/// allowed levels, each pass on a finer mesh, and its totals are the sums
/// over its passes; the continued solution is that of its final mesh.
#[test]
fn adaptive_passes_refine_and_add_up() {
    let s = shadowed_box();
    let m = build(&s, 0.2);
    let vis = Visibility::new(&s);
    let refine = RefineOptions::default();
    let mut session = Session::new(&s, &m, &vis, options(Some(refine)));
    let events = run_to_end(&mut session);
    let refinements = events
        .iter()
        .filter(|e| matches!(e, Event::Refined(_)))
        .count();
    assert_eq!(refinements as u32, refine.levels);
    let passes = session.passes();
    assert_eq!(passes.len(), refinements + 1);
    assert!(passes.windows(2).all(|w| w[1].vertices > w[0].vertices));
    assert!(passes[..refinements].iter().all(|p| p.split > 0));
    let totals = session.totals();
    assert_eq!(totals.steps, passes.iter().map(|p| p.steps).sum::<u64>());
    assert_eq!(totals.rays, passes.iter().map(|p| p.rays).sum::<u64>());
    // Continued passes keep counting from the last: the solver's own
    // count is the total.
    assert_eq!(totals.steps, session.solver().steps());
    assert_eq!(session.mesh().vertex_count(), passes[refinements].vertices);
    assert!(session.converged());
    // The continued solve is the solve of its final mesh: a fresh solve
    // of that mesh agrees within 0.5 % of the mean on every polygon.
    let mesh = session.mesh();
    let mut fresh = crate::solver::build(&s, mesh, &vis, options(None).solver);
    while !fresh.is_done() && fresh.step().is_some() {}
    let areas = mesh.vertex_areas();
    let mean = |radiosity: &[Rgb], j: usize| {
        let pm = &mesh.polygons[j];
        pm.vertices
            .clone()
            .map(|l| radiosity[l as usize].r * areas[l as usize])
            .sum::<f64>()
            / pm.area
    };
    let scene_mean = (0..mesh.polygons.len())
        .map(|j| mean(fresh.radiosity(), j) * mesh.polygons[j].area)
        .sum::<f64>()
        / mesh.polygons.iter().map(|pm| pm.area).sum::<f64>();
    for j in 0..mesh.polygons.len() {
        let error = (mean(session.radiosity(), j) - mean(fresh.radiosity(), j)).abs() / scene_mean;
        assert!(error < 0.005, "polygon {j}: {error}");
    }
}

/// An interrupt during the gather that carries a pass over to its refined
/// mesh stops that advance with the session still on its mesh; the next
/// advance carries it over on the same refined mesh, and the session ends
/// as an uninterrupted one does, bit for bit.
#[test]
fn a_cancelled_refinement_resumes_where_it_stopped() {
    let s = shadowed_box();
    let m = build(&s, 0.2);
    let vis = Visibility::new(&s);
    let refine = RefineOptions::default();
    let mut whole = Session::new(&s, &m, &vis, options(Some(refine)));
    run_to_end(&mut whole);
    let mut cut = Session::new(&s, &m, &vis, options(Some(refine)));
    let (go, stop) = (AtomicBool::new(false), AtomicBool::new(true));
    let mut cancelled = 0;
    loop {
        let event = cut.advance(&go).unwrap();
        if event == Event::Finished {
            break;
        }
        if matches!(event, Event::Stopped(StopReason::Converged)) {
            let (vertices, steps) = (cut.mesh().vertex_count(), cut.totals().steps);
            match cut.advance(&stop).unwrap() {
                Event::Cancelled => {
                    cancelled += 1;
                    assert_eq!(cut.mesh().vertex_count(), vertices);
                    assert_eq!(cut.totals().steps, steps);
                }
                // The last pass: nothing to refine, nothing to stop.
                Event::Finished => break,
                other => panic!("{other:?}"),
            }
        }
    }
    assert_eq!(cancelled, refine.levels);
    assert_eq!(cut.passes().len(), whole.passes().len());
    assert_eq!(cut.totals().steps, whole.totals().steps);
    assert_eq!(cut.totals().rays, whole.totals().rays);
    assert_eq!(cut.radiosity(), whole.radiosity());
}

/// The run's element limit clamps the refiner's: a refinement that would
/// pass it is refused, said once, and the session finishes on the mesh
/// it has.
#[test]
fn a_refinement_over_the_element_limit_is_refused() {
    let s = shadowed_box();
    let m = build(&s, 0.2);
    let vis = Visibility::new(&s);
    let mut o = options(Some(RefineOptions::default()));
    o.max_elements = m.elements.len() as u64 + 1;
    let mut session = Session::new(&s, &m, &vis, o);
    let events = run_to_end(&mut session);
    let tail = &events[events.len() - 3..];
    assert_eq!(tail[0], Event::Stopped(StopReason::Converged));
    assert!(
        matches!(tail[1], Event::Refused(r) if r.max == o.max_elements),
        "{tail:?}"
    );
    assert_eq!(tail[2], Event::Finished);
    assert_eq!(session.mesh().elements.len(), m.elements.len());
    assert_eq!(session.passes().len(), 1);
}

/// A pass stopped by the step limit is not refined: it would mark what is
/// merely unfinished.
#[test]
fn a_step_limited_pass_is_not_refined() {
    let s = shadowed_box();
    let m = build(&s, 0.2);
    let vis = Visibility::new(&s);
    let mut o = options(Some(RefineOptions::default()));
    o.solver.max_steps = Some(3);
    let mut session = Session::new(&s, &m, &vis, o);
    let events = run_to_end(&mut session);
    assert_eq!(events.len(), 5, "{events:?}");
    assert_eq!(events[3], Event::Stopped(StopReason::MaxSteps));
    assert!(!session.converged());
}

/// A cancelled step leaves the session as it was, and the next call
/// takes the step after all.
#[test]
fn a_cancelled_advance_changes_nothing() {
    let s = glowing_box();
    let m = build(&s, 0.25);
    let vis = Visibility::new(&s);
    let mut session = Session::new(&s, &m, &vis, options(None));
    let before: Vec<Rgb> = session.radiosity().to_vec();
    assert_eq!(
        session.advance(&AtomicBool::new(true)),
        Ok(Event::Cancelled)
    );
    assert_eq!(session.radiosity(), &before[..]);
    assert_eq!(session.totals().steps, 0);
    assert!(matches!(
        session.advance(&AtomicBool::new(false)),
        Ok(Event::Step(_))
    ));
}

/// What is shown: the solution itself, or with the ambient term on top
/// (never below it, and above it while light is unshot).
#[test]
fn shown_radiosity_with_and_without_the_ambient_term() {
    let s = glowing_box();
    let m = build(&s, 0.25);
    let vis = Visibility::new(&s);
    let mut plain = Session::new(&s, &m, &vis, options(None));
    let mut ambient = Session::new(
        &s,
        &m,
        &vis,
        SessionOptions {
            ambient: true,
            ..options(None)
        },
    );
    let cancel = AtomicBool::new(false);
    for _ in 0..3 {
        plain.advance(&cancel).unwrap();
        ambient.advance(&cancel).unwrap();
    }
    let (mut a, mut b) = (Vec::new(), Vec::new());
    plain.shown(&mut a);
    ambient.shown(&mut b);
    assert_eq!(a, plain.radiosity());
    assert!(a.iter().zip(&b).all(|(x, y)| y.r >= x.r));
    assert!(a.iter().zip(&b).any(|(x, y)| y.r > x.r));
}

/// Two-sided walls of a closed box (each wall and its back copy emitting
/// `e` and reflecting `rho`): the inside is the uniform enclosure,
/// `B = e / (1 − rho)`, and the outside sides see nothing, so they keep
/// `B = e` exactly. The back copies are coplanar with their fronts and
/// sit across every corner from the other walls' copies: neither blocks
/// the other, and no light crosses a wall.
#[test]
fn two_sided_box_is_the_enclosure_inside_and_bare_emission_outside() {
    use crate::scene::Sides;
    use crate::testutil::{closed_box, grey, scene};
    let (e, rho) = (1.0, 0.6);
    let s = scene(closed_box(1.0, [0; 6]), vec![grey("wall", e, rho)]).with_sides(Sides::Two);
    assert_eq!(s.polygons.len(), 12);
    let m = build(&s, 0.1);
    let vis = Visibility::new(&s);
    let mut session = Session::new(&s, &m, &vis, options(None));
    run_to_end(&mut session);
    let b = session.radiosity();
    let worst = |range: std::ops::Range<usize>, exact: f64| {
        m.polygons[range]
            .iter()
            .flat_map(|p| p.vertices.clone())
            .map(|v| (b[v as usize].r - exact).abs() / exact)
            .fold(0.0, f64::max)
    };
    let inside = worst(0..6, e / (1.0 - rho));
    assert!(inside < 0.01, "worst inside vertex error {inside}");
    let outside = worst(6..12, e);
    assert!(outside < 1e-12, "worst outside vertex error {outside}");
}

/// A single-plane wall lit from one side: its lit side is bright and its
/// back, which sees only the dark side of the world, stays black, with no
/// light through the wall; one-sided, the back is not there at all.
#[test]
fn a_thin_two_sided_wall_is_dark_on_its_unlit_side() {
    use crate::scene::Sides;
    use crate::testutil::{grey, polygon, scene};
    // A lamp at x = 0 facing +x, a wall at x = 1 facing it (−x).
    let lamp = polygon(1, &[[0., 0., 0.], [0., 1., 0.], [0., 1., 1.], [0., 0., 1.]]);
    let wall = polygon(0, &[[1., 0., 0.], [1., 0., 1.], [1., 1., 1.], [1., 1., 0.]]);
    let mut s = scene(
        vec![lamp, wall],
        vec![grey("wall", 0.0, 0.5), grey("lamp", 1.0, 0.0)],
    );
    s.polygons[1].surface.two_sided = true;
    let s = s.with_sides(Sides::AsLoaded);
    assert_eq!(s.polygons.len(), 3, "the wall and its back");
    let m = build(&s, 0.1);
    let vis = Visibility::new(&s);
    let mut session = Session::new(&s, &m, &vis, options(None));
    run_to_end(&mut session);
    let b = session.radiosity();
    let mean = |p: usize| {
        let r = m.polygons[p].vertices.clone();
        r.clone().map(|v| b[v as usize].r).sum::<f64>() / r.len() as f64
    };
    // Facing squares one unit apart: F ≈ 0.2, so the lit side ≈ 0.1.
    assert!(mean(1) > 0.05, "lit side {}", mean(1));
    assert_eq!(mean(2), 0.0, "the back of the wall gets no light");
}

/// The thin wall of the test above, tilted off the axes: the two sides of
/// a face lie in one plane only up to rounding, and a point of one side
/// then lies inside the other side's cells. Their exact near-field form
/// factor there is ±1 instead of 0, and the back copied the front's light
/// in blotches (McGuire's short box) or, inside sealed two-sided boxes,
/// the light grew without bound. Coplanar polygons exchange nothing.
#[test]
fn a_tilted_thin_wall_is_dark_on_its_unlit_side() {
    use crate::scene::Sides;
    use crate::testutil::{grey, polygon, scene};
    let turn = glam::Quat::from_axis_angle(glam::Vec3::new(0.3, 0.7, 0.2).normalize(), 0.9);
    let tilt = |v: [[f32; 3]; 4]| v.map(|p| (turn * glam::Vec3::from(p) + 0.37).to_array());
    let lamp = polygon(
        1,
        &tilt([[0., 0., 0.], [0., 1., 0.], [0., 1., 1.], [0., 0., 1.]]),
    );
    let wall = polygon(
        0,
        &tilt([[1., 0., 0.], [1., 0., 1.], [1., 1., 1.], [1., 1., 0.]]),
    );
    let mut s = scene(
        vec![lamp, wall],
        vec![grey("wall", 0.0, 0.9), grey("lamp", 1.0, 0.0)],
    );
    s.polygons[1].surface.two_sided = true;
    let s = s.with_sides(Sides::AsLoaded);
    let m = build(&s, 0.05);
    let vis = Visibility::new(&s);
    assert!(vis.coplanar(crate::scene::PolygonId(1), crate::scene::PolygonId(2)));
    let mut session = Session::new(&s, &m, &vis, options(None));
    run_to_end(&mut session);
    let b = session.radiosity();
    let lit = m.polygons[1].vertices.clone().map(|v| b[v as usize].r);
    assert!(lit.fold(0.0, f64::max) > 0.05);
    for v in m.polygons[2].vertices.clone() {
        assert_eq!(b[v as usize].r, 0.0, "back vertex {v} got light");
    }
}

/// The sun's light reaches a refined mesh's new vertices as it reached
/// the old ones: under the overhead sun a floor vertex out of the black
/// plate's shadow (and its penumbra) holds `ρ E_n` = 500 after every
/// refinement, one in the shadow 0; and the shadow's edge, where the
/// light changes, is what gets refined.
#[test]
fn refined_passes_keep_the_suns_light() {
    let s = crate::testutil::floor_under_a_plate();
    let m = build(&s, 0.5);
    let vis = Visibility::new(&s);
    let mut session = Session::new(&s, &m, &vis, options(Some(RefineOptions::default())));
    run_to_end(&mut session);
    assert!(session.passes().len() > 1, "{:?}", session.passes());
    let mesh = session.mesh();
    assert!(mesh.vertex_count() > m.vertex_count());
    let mut b = Vec::new();
    session.solution(&mut b);
    let (mut open, mut shaded) = (0, 0);
    for (l, p) in mesh.vertex_polygon.iter().enumerate() {
        let x = mesh.sample_positions[l];
        if p.0 != 0 {
            continue;
        }
        // The penumbra reaches tan(0.265°) ≈ 0.005 past the edges.
        let inside = |lo: f32, hi: f32, margin: f32| {
            (lo + margin..hi - margin).contains(&x.x) && (lo + margin..hi - margin).contains(&x.y)
        };
        if inside(1.0, 3.0, 0.01) {
            assert_eq!(b[l].r, 0.0, "{x}");
            shaded += 1;
        } else if !inside(1.0, 3.0, -0.01) {
            assert!((b[l].r - 500.0).abs() < 1e-9, "{x}: {}", b[l].r);
            open += 1;
        }
    }
    assert!(open > 0 && shaded > 0);
}
