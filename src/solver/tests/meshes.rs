//! Solves on refined meshes: continued from a coarser solve as adaptive
//! subdivision continues them, against a fresh solve, and grid
//! independence.

use super::*;
use std::sync::atomic::AtomicBool;

/// Solves `s` adaptively as `--adaptive` does, through the solve session:
/// on its regular mesh, then refined by the solution's luminance and
/// continued twice ([`Progressive::refined_state`]).
fn solve_adaptively(s: &Scene, lenmax: f32, options: SolverOptions) -> Solved {
    use crate::session::{Session, SessionOptions};
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
                    .refined_state(s, &refined, &refiner, &AtomicBool::new(false))
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

/// The scene of the carry's tests: an open-topped box under a sky of
/// radiosity 2, with a lamp hanging under the open top and a square
/// casting shadows on the floor.
fn courtyard_with_lamp() -> Scene {
    let mut polygons = closed_box(2.0, [1, 2, 1, 0, 1, 2]);
    polygons.remove(3);
    polygons.push(polygon(
        1,
        &[
            [0.6, 0.3, 0.6],
            [0.6, 0.3, 1.4],
            [1.4, 0.3, 1.4],
            [1.4, 0.3, 0.6],
        ],
    ));
    polygons.push(polygon(
        0,
        &[
            [1.3, 1.9, 0.3],
            [1.3, 1.9, 0.8],
            [0.8, 1.9, 0.8],
            [0.8, 1.9, 0.3],
        ],
    ));
    let mut s = scene(polygons, shadowed_box().materials);
    assert!(s.polygons.last().unwrap().normal.y < 0.0);
    s.add_sky(Rgb::splat(2.0)).unwrap();
    s
}

/// A new vertex's carry over its hemisphere (lamps by polygon, the sky
/// by the sky step's directions, reflected light by rays;
/// [`crate::solver::carry`]) against its twin, every polygon's samples,
/// both asking from the vertex's own point: in [`courtyard_with_lamp`]
/// solved to 0.1 % and refined once by its luminance, the new vertices
/// differ from the twin's by 1.2 % of their mean on average, 0.4 %
/// brighter on the whole, and 4.6 % at worst (measured), with a fifth of
/// the twin's rays.
#[test]
fn new_vertices_gather_over_the_hemisphere_as_from_every_polygon() {
    use crate::mesh::refine::{RefineOptions, Refiner};
    use crate::solver::carry::Carry;
    let s = courtyard_with_lamp();
    let mesh = crate::testutil::regular_mesh(&s, 0.2);
    let vis = Visibility::new(&s);
    let options = SolverOptions {
        approximations: Approximations::DEFAULT.without(&[Heuristic::HatCentroids]),
        ..Default::default()
    };
    let mut solver = Progressive::new(&s, &mesh, &vis, options);
    while !solver.is_done() && solver.step().is_some() {}
    solver.validate().unwrap();
    let luminance: Vec<f64> = solver.radiosity().iter().map(|b| b.luminance()).collect();
    let mut refiner = Refiner::new(&mesh);
    let (refined, _) = refiner
        .refine(&s, &luminance, &RefineOptions::default())
        .expect("the shadows refine");
    let cancel = AtomicBool::new(false);
    let state = |how| {
        solver
            .refined_state_by(&s, &refined, &refiner, &cancel, how)
            .unwrap()
            .unwrap()
    };
    let (fast, twin) = (state(Carry::Hemisphere), state(Carry::EveryPolygon));
    let previous = refiner.previous_index();
    let sky = |l: usize| refined.polygons[refined.vertex_polygon[l].index()].sky;
    let new: Vec<usize> = (0..refined.vertex_count())
        .filter(|&l| previous[l].is_none() && !sky(l))
        .collect();
    assert!(new.len() > 100, "{} new vertices", new.len());
    let n = new.len() as f64;
    let lum = |state: &checkpoint::SolverState, l: usize| state.radiosity[l].luminance();
    let mean = new.iter().map(|&l| lum(&twin, l)).sum::<f64>() / n;
    let differences: Vec<f64> = new
        .iter()
        .map(|&l| (lum(&fast, l) - lum(&twin, l)) / mean)
        .collect();
    let signed = differences.iter().sum::<f64>() / n;
    let average = differences.iter().map(|d| d.abs()).sum::<f64>() / n;
    let worst = differences.iter().map(|d| d.abs()).fold(0.0, f64::max);
    let (fast_rays, twin_rays) = (fast.rays - solver.rays(), twin.rays - solver.rays());
    eprintln!(
        "{n} new vertices, against the twin: {average} on average, {signed} signed, \
         {worst} at worst, of their mean; rays {fast_rays} against {twin_rays}"
    );
    assert!(
        average < 0.02 && signed.abs() < 0.01 && worst < 0.08,
        "{average} {signed} {worst}"
    );
    assert!(fast_rays * 5 <= twin_rays, "{fast_rays} {twin_rays}");
    // Old vertices keep their values, in both.
    for l in (0..refined.vertex_count()).filter(|&l| previous[l].is_some()) {
        assert_eq!(fast.radiosity[l], twin.radiosity[l]);
    }
}

/// Refines `mesh` once where `field` (of a vertex's position) changes,
/// and carries `solver`'s solution over by the hemisphere
/// ([`crate::solver::carry`]): the refined mesh, the new vertices, and
/// the carried state.
fn carried_across(
    s: &Scene,
    mesh: &Mesh,
    solver: &Progressive,
    field: impl Fn(glam::Vec3) -> f64,
) -> (Mesh, Vec<usize>, checkpoint::SolverState) {
    use crate::mesh::refine::{RefineOptions, Refiner};
    use crate::solver::carry::Carry;
    let field: Vec<f64> = mesh.positions.iter().map(|&p| field(p)).collect();
    let mut refiner = Refiner::new(mesh);
    let (refined, _) = refiner
        .refine(s, &field, &RefineOptions::default())
        .expect("the field refines");
    let state = solver
        .refined_state_by(
            s,
            &refined,
            &refiner,
            &AtomicBool::new(false),
            Carry::Hemisphere,
        )
        .unwrap()
        .unwrap();
    let new = (0..refined.vertex_count())
        .filter(|&l| refiner.previous_index()[l].is_none())
        .collect();
    (refined, new, state)
}

/// The hemisphere's rays read the reflected light exactly where it is
/// even: in a closed grey box (reflectance 0.7 and 0.4, no lamp) whose
/// every vertex has sent radiosity 3 and holds none unshot, every new
/// vertex of a refinement gathers `ρ · 3`, whichever element each ray
/// lands in.
#[test]
fn new_vertices_gather_an_even_field_exactly() {
    let s = scene(
        closed_box(2.0, [1, 2, 1, 1, 1, 2]),
        shadowed_box().materials,
    );
    let mesh = crate::testutil::regular_mesh(&s, 0.25);
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &mesh, &vis, SolverOptions::default());
    let mut state = solver.state();
    state.radiosity = vec![Rgb::splat(3.0); mesh.vertex_count()];
    state.unshot = vec![Rgb::BLACK; state.unshot.len()];
    solver.restore(state).unwrap();
    let (refined, new, carried) =
        carried_across(&s, &mesh, &solver, |p| if p.x < 0.9 { 0.2 } else { 1.0 });
    let mut checked = 0;
    for l in new {
        let rho = [0.3, 0.7, 0.4][s.polygons[refined.vertex_polygon[l].index()]
            .material
            .index()];
        let b = carried.radiosity[l].r;
        assert!(
            (b - 3.0 * rho).abs() < 1e-5,
            "vertex {l}: {b}, not {}",
            3.0 * rho
        );
        checked += 1;
    }
    assert!(checked > 50, "{checked}");
}

/// New vertices of one surface at one point gather as one: a floor of
/// two coplanar quads under a sky, with a wall standing on it, refined
/// across the edge between them. Every midpoint of that edge is a vertex
/// of both quads; the two take one value, the carry casts fewer rays
/// than with every vertex alone, and the floor's new vertices stay within
/// 1 % of those values on average.
#[test]
fn new_vertices_of_one_surface_at_one_point_gather_as_one() {
    let quad =
        |x0: f32, x1: f32| polygon(1, &[[x0, 0., 0.], [x0, 0., 2.], [x1, 0., 2.], [x1, 0., 0.]]);
    let wall = {
        let w = polygon(
            2,
            &[[0., 0., 1.5], [0., 1., 1.5], [2., 1., 1.5], [2., 0., 1.5]],
        );
        if w.normal.z < 0.0 {
            w
        } else {
            polygon(
                2,
                &[[2., 0., 1.5], [2., 1., 1.5], [0., 1., 1.5], [0., 0., 1.5]],
            )
        }
    };
    let mut s = scene(
        vec![quad(0.0, 1.0), quad(1.0, 2.0), wall],
        shadowed_box().materials,
    );
    assert!(s.polygons[0].normal.y > 0.0 && s.polygons[2].normal.z < 0.0);
    s.add_sky(Rgb::splat(1.0)).unwrap();
    let mesh = crate::testutil::regular_mesh(&s, 0.25);
    let vis = Visibility::new(&s);
    let carry = |approximations: Approximations| {
        let options = SolverOptions {
            approximations,
            ..Default::default()
        };
        let mut solver = Progressive::new(&s, &mesh, &vis, options);
        while !solver.is_done() && solver.step().is_some() {}
        let (refined, new, state) = carried_across(&s, &mesh, &solver, |p| {
            if (p.x - 1.0).abs() < 0.1 {
                1.0
            } else {
                0.2
            }
        });
        (refined, new, state.radiosity, state.rays - solver.rays())
    };
    let (refined, new, shared, shared_rays) = carry(Approximations::DEFAULT);
    let (_, _, alone, alone_rays) =
        carry(Approximations::DEFAULT.without(&[Heuristic::SharedReceivers]));
    let floor = |l: usize| refined.vertex_polygon[l].index() < 2;
    let mut pairs = 0;
    for &a in new
        .iter()
        .filter(|&&l| refined.vertex_polygon[l].index() == 0)
    {
        for &b in new
            .iter()
            .filter(|&&l| refined.vertex_polygon[l].index() == 1)
        {
            if refined.positions[a] == refined.positions[b] {
                assert_eq!(shared[a], shared[b], "vertices {a} and {b}");
                pairs += 1;
            }
        }
    }
    assert!(pairs >= 4, "{pairs} midpoints on the shared edge");
    let on_floor: Vec<usize> = new.iter().copied().filter(|&l| floor(l)).collect();
    let mean = on_floor.iter().map(|&l| alone[l].r).sum::<f64>() / on_floor.len() as f64;
    let off = on_floor
        .iter()
        .map(|&l| (shared[l].r - alone[l].r).abs() / mean)
        .sum::<f64>()
        / on_floor.len() as f64;
    eprintln!(
        "{pairs} shared midpoints; {off} apart on average; rays {shared_rays} against {alone_rays}"
    );
    assert!(off < 0.01, "{off}");
    assert!(shared_rays < alone_rays, "{shared_rays} {alone_rays}");
}
