//! Clusters, strata, interpolated receivers and shared facet rays
//! against the brute-force twin, closed forms and thread counts.

use super::*;

/// The closed-box energy balance holds when tiles shoot together as
/// clusters, within the same 0.5 % as without them, in under half the
/// steps.
#[test]
fn energy_balance_with_clusters() {
    let s = tiled_box(false, 6);
    let options = SolverOptions {
        threshold: 1e-5,
        ..Default::default()
    };
    let clustered = solve(&s, 0.1, crate::mesh::DEFAULT_INSET, options);
    let error = energy_error(&s, &clustered);
    let alone = solve(
        &s,
        0.1,
        crate::mesh::DEFAULT_INSET,
        SolverOptions {
            approximations: options.approximations.with(Heuristic::Clusters, false),
            ..options
        },
    );
    eprintln!(
        "energy error {error}; {} steps clustered, {} alone",
        clustered.steps, alone.steps
    );
    assert!(error < 0.005, "energy error {error}");
    assert!(
        clustered.steps * 2 < alone.steps,
        "{} steps clustered, {} alone",
        clustered.steps,
        alone.steps
    );
}

/// On a tiled room with a shadow, clusters give what every polygon
/// shooting alone gives: with every receiving vertex exact, every
/// polygon's mean within 2 % and the vertices within 1 % (relative L1).
/// With receivers interpolated as well (the default), the vertices stay
/// within 1 % and the polygon means within 2.5 %: measured 2.02 %, the
/// walls' tiles darker than alone by 1.5 to 2 % in both (see
/// `docs/accuracy.md`).
#[test]
fn clusters_match_the_brute_force_twin() {
    let s = tiled_box(true, 5);
    let options = SolverOptions {
        threshold: 1e-4,
        ..Default::default()
    };
    let mesh = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.1,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    let grouped = Progressive::new(&s, &mesh, &vis, options)
        .clusters()
        .grouped();
    assert!(grouped >= 6, "{grouped} clusters of several tiles");
    let alone = solve_on(
        &s,
        mesh.clone(),
        SolverOptions {
            approximations: options.approximations.with(Heuristic::Clusters, false),
            ..options
        },
    );
    for (interpolate, bound) in [(false, 0.02), (true, 0.025)] {
        let clustered = solve_on(
            &s,
            mesh.clone(),
            SolverOptions {
                approximations: if interpolate {
                    options.approximations
                } else {
                    options.approximations.without(&Heuristic::RECEIVERS)
                },
                ..options
            },
        );
        let m = &clustered.mesh;
        let mut worst = 0.0f64;
        for p in 0..s.polygons.len() {
            let a = mean_radiosity(m, &clustered.radiosity, p).mean();
            let b = mean_radiosity(m, &alone.radiosity, p).mean();
            worst = worst.max((a - b).abs() / b);
        }
        let areas = m.vertex_areas();
        let (mut diff, mut total) = (0.0, 0.0);
        for (l, (a, b)) in clustered.radiosity.iter().zip(&alone.radiosity).enumerate() {
            diff += (a.mean() - b.mean()).abs() * areas[l];
            total += b.mean() * areas[l];
        }
        eprintln!(
            "interpolated receivers {interpolate}: worst polygon mean {worst}, vertex relL1 {}; \
             {} steps clustered, {} alone",
            diff / total,
            clustered.steps,
            alone.steps
        );
        assert!(worst < bound, "worst polygon mean differs by {worst}");
        assert!(diff / total < 0.01, "vertex relL1 {}", diff / total);
    }
}

/// One cluster shot, checked against Lambert: a unit square cut into
/// 8 × 8 tiles, each vertex holding unshot radiosity 1, shoots once
/// (as one cluster) to a parallel square one unit above and a
/// perpendicular one along its edge; every receiver vertex must get
/// `ρ Σ F(x → tile)` over the tiles of the cluster, within 1 % of the
/// largest value.
#[test]
fn a_cluster_shot_matches_lambert() {
    use super::formfactor::point_to_polygon;
    let source = polygon(
        0,
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
    );
    let mut polygons = tiled(&source, 8);
    let tiles = polygons.len();
    // Facing down onto the square, and standing on its edge y = 1 facing -y.
    polygons.push(polygon(
        1,
        &[
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
        ],
    ));
    polygons.push(polygon(
        1,
        &[
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ],
    ));
    // A speck far away makes the scene large, so the square is one cluster.
    polygons.push(polygon(
        1,
        &[
            [6.0, 0.0, 0.0],
            [6.1, 0.0, 0.0],
            [6.1, 0.1, 0.0],
            [6.0, 0.1, 0.0],
        ],
    ));
    let rho = 0.5;
    let s = scene(
        polygons,
        vec![grey("tile", 0.0, 0.8), grey("wall", 0.0, rho)],
    );
    let mesh = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.04,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    // Without overshoot the step sends exactly the unshot light set here.
    let options = SolverOptions {
        approximations: Approximations::DEFAULT.with(Heuristic::Overshoot, false),
        ..Default::default()
    };
    let mut solver = Progressive::new(&s, &mesh, &vis, options);
    let unshot: Vec<Rgb> = mesh
        .vertex_polygon
        .iter()
        .map(|p| {
            if p.index() < tiles {
                Rgb::new(1.0, 1.0, 1.0)
            } else {
                Rgb::BLACK
            }
        })
        .collect();
    solver
        .restore(checkpoint::SolverState {
            radiosity: vec![Rgb::BLACK; mesh.vertex_count()],
            unshot,
            steps: 0,
            rays: 0,
            charges: Vec::new(),
            tail_from: None,
            tail_began: Vec::new(),
        })
        .unwrap();
    let report = solver.step().unwrap();
    assert_eq!(report.polygons as usize, tiles, "the square shot as one");
    let (mut worst, mut peak) = (0.0f64, 0.0f64);
    for receiver in [tiles, tiles + 1] {
        let pm = &mesh.polygons[receiver];
        for l in pm.vertices.clone() {
            let x = mesh.sample_positions[l as usize];
            let exact: f64 = s.polygons[..tiles]
                .iter()
                .map(|t| point_to_polygon(x, pm.normal, &t.vertices))
                .sum::<f64>()
                * rho;
            let got = solver.radiosity()[l as usize].r;
            worst = worst.max((got - exact).abs());
            peak = peak.max(exact);
        }
    }
    eprintln!("worst error {worst} of peak {peak}");
    assert!(worst < 0.01 * peak, "worst error {worst} of peak {peak}");
}

/// Hierarchical receivers: interpolating reflected light across coarse
/// cells of the walls gives what evaluating every vertex gives (vertices
/// within 0.5 % relative L1, every polygon's mean within 1 %, the darkest
/// floor vertex under the blocker within 2 %) with fewer rays; and the
/// same bits on 1 and 2 threads.
#[test]
fn interpolated_receivers_match_exact_ones() {
    let s = shadowed_box();
    let mesh = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.1,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    let run = |interpolate: bool| {
        let options = SolverOptions {
            threshold: 1e-4,
            approximations: if interpolate {
                Approximations::DEFAULT
            } else {
                Approximations::DEFAULT.without(&Heuristic::RECEIVERS)
            },
            ..Default::default()
        };
        let mut solver = Progressive::new(&s, &mesh, &vis, options);
        while !solver.is_done() && solver.step().is_some() {}
        solver.validate().unwrap();
        (solver.radiosity().to_vec(), solver.rays())
    };
    let (coarse, coarse_rays) = run(true);
    let (exact, exact_rays) = run(false);
    let areas = mesh.vertex_areas();
    let (mut diff, mut total) = (0.0, 0.0);
    for (l, (a, b)) in coarse.iter().zip(&exact).enumerate() {
        diff += (a.mean() - b.mean()).abs() * areas[l];
        total += b.mean() * areas[l];
    }
    let mut worst = 0.0f64;
    for p in 0..s.polygons.len() {
        let a = mean_radiosity(&mesh, &coarse, p).mean();
        let b = mean_radiosity(&mesh, &exact, p).mean();
        worst = worst.max((a - b).abs() / b);
    }
    // The floor is polygon 3 of `closed_box`'s order... found by its
    // normal, pointing up.
    let floor = (0..s.polygons.len())
        .find(|&p| s.polygons[p].normal.y > 0.9 && s.polygons[p].vertices[0].y < 0.01)
        .expect("a floor");
    let darkest = |r: &[Rgb]| {
        mesh.polygons[floor]
            .vertices
            .clone()
            .map(|l| r[l as usize].mean())
            .fold(f64::INFINITY, f64::min)
    };
    let (dc, de) = (darkest(&coarse), darkest(&exact));
    eprintln!(
        "vertex relL1 {}, worst polygon {worst}, darkest floor {dc} vs {de}, rays {coarse_rays} vs {exact_rays}",
        diff / total
    );
    assert!(diff / total < 0.005, "vertex relL1 {}", diff / total);
    assert!(worst < 0.01, "worst polygon mean differs by {worst}");
    assert!((dc - de).abs() < 0.02 * de, "shadow {dc} vs {de}");
    assert!(
        (coarse_rays as f64) < 0.8 * exact_rays as f64,
        "interpolation saved no rays: {coarse_rays} vs {exact_rays}"
    );
    let threads = |n| {
        on_threads(n, || {
            let options = SolverOptions {
                max_steps: Some(12),
                ..Default::default()
            };
            solve_on(&s, mesh.clone(), options).radiosity
        })
    };
    assert!(same_bits(&threads(1), &threads(2)));
}

/// Small facets share their shadow rays ([`super::facets`]): on the
/// Cornell box with two tessellated spheres, meshed so that most of the
/// spheres' facets are under half an element across, the solve with
/// shared rays casts far fewer rays and gives what every vertex asking
/// its own gives (vertices within 0.2 % relative L1, every polygon's mean
/// within 2 %), with the same bits on 1 and 2 threads.
#[test]
fn shared_facet_rays_match_per_vertex_rays() {
    let s = crate::scene::parse_str(&crate::testutil::sphere_box::sphere_box_sc(24), "t.sc")
        .expect("the generated scene parses");
    let mesh = crate::testutil::regular_mesh(&s, 80.0);
    let vis = Visibility::new(&s);
    let options = SolverOptions {
        threshold: 1e-3,
        ..Default::default()
    };
    let sharing = Progressive::new(&s, &mesh, &vis, options)
        .facets()
        .sharing();
    assert!(
        sharing * 2 > s.polygons.len(),
        "{sharing} of {} polygons share their rays",
        s.polygons.len()
    );
    let run = |shared: bool| {
        let options = SolverOptions {
            // Shared receivers would take most facet vertices out of
            // the comparison: facet rays alone.
            approximations: options
                .approximations
                .with(Heuristic::FacetRays, shared)
                .with(Heuristic::SharedReceivers, false),
            ..options
        };
        let mut solver = Progressive::new(&s, &mesh, &vis, options);
        while !solver.is_done() && solver.step().is_some() {}
        solver.validate().unwrap();
        (solver.radiosity().to_vec(), solver.rays())
    };
    let (shared, shared_rays) = run(true);
    let (own, own_rays) = run(false);
    let areas = mesh.vertex_areas();
    let (mut diff, mut total) = (0.0, 0.0);
    for (l, (a, b)) in shared.iter().zip(&own).enumerate() {
        diff += (a.mean() - b.mean()).abs() * areas[l];
        total += b.mean() * areas[l];
    }
    let brightest = (0..s.polygons.len())
        .map(|p| mean_radiosity(&mesh, &own, p).mean())
        .fold(0.0f64, f64::max);
    let mut worst = 0.0f64;
    for p in 0..s.polygons.len() {
        let (a, b) = (
            mean_radiosity(&mesh, &shared, p).mean(),
            mean_radiosity(&mesh, &own, p).mean(),
        );
        // As `cluster_compare` does: polygons at least a thousandth of
        // the brightest (the lamp aside, it is not lit).
        if b >= 1e-3 * brightest {
            worst = worst.max((a - b).abs() / b);
        }
    }
    eprintln!(
        "{sharing} facets share; vertex relL1 {}, worst polygon {worst}, rays {shared_rays} vs {own_rays}",
        diff / total
    );
    assert!(diff / total < 0.002, "vertex relL1 {}", diff / total);
    assert!(worst < 0.02, "worst polygon mean differs by {worst}");
    assert!(
        (shared_rays as f64) < 0.7 * own_rays as f64,
        "sharing saved too few rays: {shared_rays} vs {own_rays}"
    );
    let threads = |n| {
        on_threads(n, || {
            let options = SolverOptions {
                max_steps: Some(10),
                ..options
            };
            solve_on(&s, mesh.clone(), options).radiosity
        })
    };
    assert!(same_bits(&threads(1), &threads(2)));
}

/// Blocks of cells facing every way (36 small boxes standing on a
/// room's floor, as a game level's steps and pillars stand), whose
/// strata far receivers take by normal bins in every step, strong or
/// weak: the solve gives what every polygon shooting alone gives, the
/// vertices within 1 % (relative L1; measured 0.13 %).
#[test]
fn blocks_facing_every_way_match_the_twin() {
    let mut s = tiled_box(false, 4);
    for i in 0..6 {
        for k in 0..6 {
            let (x, y) = (0.3 + 0.07 * i as f32, 0.3 + 0.07 * k as f32);
            let top = 0.04 + 0.01 * ((i + k) % 3) as f32;
            for mut p in crate::testutil::cuboid([x, y, 0.0], [x + 0.04, y + 0.04, top], false) {
                p.material = crate::scene::MaterialId(1);
                s.polygons.push(p);
            }
        }
    }
    let options = SolverOptions {
        threshold: 1e-3,
        ..Default::default()
    };
    let mesh = crate::testutil::regular_mesh(&s, 0.1);
    let clustered = solve_on(&s, mesh.clone(), options).radiosity;
    let alone = solve_on(
        &s,
        mesh.clone(),
        SolverOptions {
            approximations: options.approximations.with(Heuristic::Clusters, false),
            ..options
        },
    );
    let areas = mesh.vertex_areas();
    let (mut diff, mut total) = (0.0, 0.0);
    for (l, (a, b)) in clustered.iter().zip(&alone.radiosity).enumerate() {
        diff += (a.mean() - b.mean()).abs() * areas[l];
        total += b.mean() * areas[l];
    }
    assert!(diff / total < 0.01, "vertex relL1 {}", diff / total);
}
