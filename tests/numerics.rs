//! Numerical safety: degenerate and extreme geometry the loader accepts
//! gives finite, non-negative radiosities and pictures.

use radiosity::mesh::{self, MeshOptions};
use radiosity::render::render;
use radiosity::render::View;
use radiosity::scene::{parse_str, Scene};
use radiosity::solver::{Approximations, Heuristic, Progressive, SolverOptions};
use radiosity::visibility::Visibility;

const MATERIALS: &str = "\
material lamp color 1 1 1 k_emission 10 end
material grey color 1 1 1 k_diffrefl 0.7 end
";

/// Solves `steps` steps of the scene (inset `inset`, lenmax `lenmax` or the
/// default) and checks every radiosity and every pixel.
fn solve_checked(text: &str, lenmax: Option<f32>, inset: f32, steps: u32) -> Vec<f64> {
    let scene: Scene = parse_str(text, "test.sc").unwrap_or_else(|e| panic!("{e}"));
    let mut options = MeshOptions::for_scene(&scene);
    options.inset = inset;
    if let Some(l) = lenmax {
        options.lenmax = l;
    }
    let mesh = mesh::build(&scene, &options).unwrap();
    mesh.validate().unwrap();
    let visibility = Visibility::new(&scene);
    for near_field in [true, false] {
        let options = SolverOptions {
            approximations: Approximations::DEFAULT.with(Heuristic::NearField, near_field),
            ..SolverOptions::default()
        };
        let mut solver = Progressive::new(&scene, &mesh, &visibility, options);
        for _ in 0..steps {
            if solver.step().is_none() {
                break;
            }
            solver.validate().unwrap();
        }
        let frame = render(
            &mesh,
            solver.radiosity(),
            &View::new(&scene.camera).unwrap(),
        )
        .unwrap();
        assert!(
            frame
                .pixels
                .iter()
                .flatten()
                .all(|c| c.is_finite() && *c >= 0.0),
            "a pixel is negative or not finite"
        );
        if near_field {
            return solver.radiosity().iter().map(|c| c.mean()).collect();
        }
    }
    unreachable!()
}

#[test]
fn sliver_triangles_stay_finite() {
    // A triangle 1000 long and 1e-3 wide (aspect 10^6), lit, and a sliver
    // light shining on a floor.
    let text = format!(
        "{MATERIALS}
polygon grey vertex 0 0 0 vertex 1000 0 0 vertex 1000 0.001 0 end
polygon lamp vertex 0 0 5 vertex 0 0.01 5 vertex 1000 0 5 end
polygon grey vertex -10 -10 -1 vertex 1010 -10 -1 vertex 1010 10 -1 vertex -10 10 -1 end
polygon lamp vertex 0 0 10 vertex 0 1 10 vertex 1000 0 10 end
"
    );
    let b = solve_checked(&text, None, 0.05, 8);
    assert!(b.iter().any(|&x| x > 0.0));
}

#[test]
fn coincident_polygons_stay_finite() {
    // Two identical squares facing the same way, one facing the other in
    // the same plane, and a lamp coincident with a wall.
    let text = format!(
        "{MATERIALS}
polygon grey vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0 end
polygon grey vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0 end
polygon grey vertex 0 0 0 vertex 0 1 0 vertex 1 1 0 vertex 1 0 0 end
polygon lamp vertex 0 0 1 vertex 0 1 1 vertex 1 1 1 vertex 1 0 1 end
polygon grey vertex 0 0 1 vertex 0 1 1 vertex 1 1 1 vertex 1 0 1 end
"
    );
    for inset in [0.0, 0.05] {
        let b = solve_checked(&text, Some(0.1), inset, 10);
        assert!(b.iter().any(|&x| x > 0.0));
    }
}

#[test]
fn receiver_vertex_on_an_occluders_edge_stays_finite() {
    // A wall standing on the floor along x = 1: with no inset, the floor's
    // vertices at x = 1 lie exactly on the wall's bottom edge, and rays
    // from them graze it; the lamp is straight above that line.
    let text = format!(
        "{MATERIALS}
polygon grey vertex 0 0 0 vertex 0 2 0 vertex 2 2 0 vertex 2 0 0 end
polygon grey vertex 1 0 0 vertex 1 2 0 vertex 1 2 1 vertex 1 0 1 end
polygon lamp vertex 0.5 0 3 vertex 1.5 0 3 vertex 1.5 2 3 vertex 0.5 2 3 end
"
    );
    let b = solve_checked(&text, Some(0.25), 0.0, 6);
    assert!(b.iter().all(|&x| x.is_finite() && x >= 0.0));
    assert!(b.iter().any(|&x| x > 0.0));
}

#[test]
fn extreme_scales_within_the_limits_stay_finite() {
    // The same lit box at the largest and smallest sizes the loader takes.
    for (lo, hi) in [("-1e12", "1e12"), ("0", "1e-9"), ("1e11", "1.0001e11")] {
        let text = format!(
            "material lamp color 1 1 1 k_emission 1e20 k_diffrefl 0.5 end
             box lamp {lo} {lo} {lo} {hi} {hi} {hi}
             material grey color 1 1 1 k_diffrefl 0.99 end
             polygon grey vertex {lo} {lo} {lo} vertex {hi} {lo} {lo} vertex {hi} {hi} {lo} end"
        );
        solve_checked(&text, None, 0.05, 4);
    }
}

#[test]
fn estimate_matches_the_built_mesh() {
    let text = format!(
        "{MATERIALS}
polygon grey vertex 0 0 0 vertex 3 0 0 vertex 0 2 0 end
polygon grey vertex 0 0 1 vertex 3 0 1 vertex 3 2 1 vertex 0 2 1 end
polygon grey vertex 0 0 2 vertex 3 0 2 vertex 2.5 2 2 vertex 0.2 1.5 2 end
polygon grey vertex 0 0 3 vertex 2 0 3 vertex 3 1 3 vertex 2 2 3 vertex 0 2 3 vertex -1 1 3 end
box lamp 5 5 5 6 7 8
"
    );
    let scene = parse_str(&text, "t.sc").unwrap();
    for lenmax in [10.0, 1.0, 0.3, 0.07] {
        let options = MeshOptions {
            lenmax,
            ..MeshOptions::for_scene(&scene)
        };
        let m = mesh::build(&scene, &options).unwrap();
        let e = mesh::estimate(&scene, &options).unwrap();
        assert_eq!(e.elements, m.elements.len() as u64, "lenmax {lenmax}");
        assert_eq!(e.vertices, m.vertex_count() as u64, "lenmax {lenmax}");
    }
}
