//! The sky (`--sky`) against closed forms: inside a uniform enclosure the
//! radiance is the same from every direction, so a point receives the
//! sky's radiosity `S` times its form factor to whatever part of the sky it
//! sees, which Lambert's formula gives exactly for the polygonal openings
//! below ([`formfactor::point_to_polygon`]).

use super::formfactor::point_to_polygon;
use super::*;
use crate::color::Rgb;
use crate::mesh::{self, MeshOptions};
use crate::scene::Polygon;
use crate::testutil::{closed_box, grey, polygon, scene};
use glam::Vec3;

/// Solves `s` under `sky` on a mesh of `lenmax` with the default options;
/// returns the mesh, the radiosity and the steps taken.
fn solve_under_sky(s: Scene, sky: Rgb, lenmax: f32) -> (Scene, Mesh, Vec<Rgb>, u64) {
    solve_under_sky_with(s, sky, lenmax, Approximations::DEFAULT)
}

/// The two ways the default solve takes the sky: gathered at once
/// ([`crate::solver::accel::sky_dome`]) and shot facet by facet, its twin.
const BOTH_SKIES: [(&str, bool); 2] = [("at once", true), ("by facets", false)];

/// [`solve_under_sky`] with `approximations`.
fn solve_under_sky_with(
    mut s: Scene,
    sky: Rgb,
    lenmax: f32,
    approximations: Approximations,
) -> (Scene, Mesh, Vec<Rgb>, u64) {
    s.add_sky(sky).unwrap();
    let mesh = mesh::build(
        &s,
        &MeshOptions {
            lenmax,
            inset: mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    let options = SolverOptions {
        approximations,
        ..Default::default()
    };
    let mut solver = Progressive::new(&s, &mesh, &vis, options);
    while !solver.is_done() {
        if solver.step().is_none() {
            break;
        }
    }
    solver.validate().unwrap();
    let (radiosity, steps) = (solver.radiosity().to_vec(), solver.steps());
    (s, mesh, radiosity, steps)
}

/// A `w × w` floor at height 0 facing up (`+y`), material 0.
fn floor(w: f32) -> Polygon {
    polygon(0, &[[0., 0., 0.], [0., 0., w], [w, 0., w], [w, 0., 0.]])
}

/// The vertices of polygon `p`: (sample position, radiosity).
fn vertices_of<'a>(
    mesh: &'a Mesh,
    radiosity: &'a [Rgb],
    p: usize,
) -> impl Iterator<Item = (Vec3, Rgb)> + 'a {
    mesh.polygons[p]
        .vertices
        .clone()
        .map(move |l| (mesh.sample_positions[l as usize], radiosity[l as usize]))
}

/// The mean of `f` under vertex `l`'s hat on polygon `p`: integrated over
/// the elements around it, weighted by its barycentric (triangle) or
/// bilinear (quad) weight, on a 24 × 24 grid of each element's
/// parameters, between the corners' evaluation points.
fn hat_mean(mesh: &Mesh, p: usize, l: u32, f: impl Fn(Vec3) -> f64) -> f64 {
    let pm = &mesh.polygons[p];
    let elements = &mesh.elements[pm.elements.start as usize..pm.elements.end as usize];
    let (mut weighted, mut weight) = (0.0f64, 0.0f64);
    let n = 24;
    for e in elements {
        let c = e.corners();
        let Some(k) = c.iter().position(|v| v.0 == l) else {
            continue;
        };
        let at = |i: usize| mesh.sample_positions[c[(k + i) % c.len()].index()];
        let area = mesh.element_area(e);
        for i in 0..n {
            for j in 0..n {
                let (s, t) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (x, w) = if c.len() == 4 {
                    (
                        at(0) * ((1.0 - s) * (1.0 - t))
                            + at(1) * (s * (1.0 - t))
                            + at(2) * (s * t)
                            + at(3) * ((1.0 - s) * t),
                        (1.0 - s) * (1.0 - t),
                    )
                } else {
                    // The square folded onto the triangle: (s, t) above
                    // the diagonal reflected below it.
                    let (s, t) = if s + t > 1.0 {
                        (1.0 - s, 1.0 - t)
                    } else {
                        (s, t)
                    };
                    let lambda = 1.0 - s - t;
                    (at(0) * lambda + at(1) * s + at(2) * t, lambda)
                };
                weighted += area * f64::from(w) * f(x);
                weight += area * f64::from(w);
            }
        }
    }
    weighted / weight
}

#[test]
fn an_open_floor_under_a_sky_gets_its_reflectance_times_the_sky() {
    let sky = Rgb::new(1.0, 2.0, 4.0);
    let s = scene(
        vec![floor(4.0)],
        vec![crate::scene::Material {
            name: "stone".into(),
            color: Rgb::new(0.8, 0.5, 0.25),
            k_diffrefl: 1.0,
            k_emission: 0.0,
        }],
    );
    let (s, mesh, radiosity, _) = solve_under_sky(s, sky, 0.25);
    let expected = Rgb::new(0.8, 1.0, 1.0);
    let mut worst = 0.0f64;
    for (_, b) in vertices_of(&mesh, &radiosity, 0) {
        for (got, want) in b.to_array().into_iter().zip(expected.to_array()) {
            worst = worst.max((got / want - 1.0).abs());
        }
    }
    // The full hemisphere of sky, from 640 discrete directions.
    assert!(worst < 0.01, "worst relative error {worst}");
    // The sky's own vertices keep their emission; only the floor reflects.
    assert_eq!(s.sky(), Some(sky));
    for p in 1..s.polygons.len() {
        assert!(vertices_of(&mesh, &radiosity, p).all(|(_, b)| b == sky));
    }
}

#[test]
fn a_closed_box_under_a_sky_stays_black_inside() {
    // A grey box on a ground that the sky lights; the box's walls face
    // inward, so every ray to them from the sky crosses another wall.
    let mut polygons = closed_box(2.0, [0; 6]);
    polygons.push(polygon(
        1,
        &[
            [-4., -0.5, -4.],
            [-4., -0.5, 6.],
            [6., -0.5, 6.],
            [6., -0.5, -4.],
        ],
    ));
    let s = scene(
        polygons,
        vec![grey("wall", 0.0, 0.7), grey("ground", 0.0, 0.5)],
    );
    let (_, mesh, radiosity, _) = solve_under_sky(s, Rgb::splat(3.0), 0.1);
    for wall in 0..6 {
        for (x, b) in vertices_of(&mesh, &radiosity, wall) {
            assert_eq!(b, Rgb::BLACK, "wall {wall} at {x}");
        }
    }
    // The ground outside is lit (less under the box's shadow).
    let lit = vertices_of(&mesh, &radiosity, 6)
        .map(|(_, b)| b.r)
        .fold(0.0, f64::max);
    assert!(lit > 1.4 && lit < 1.515, "{lit}");
}

/// Black walls and a ceiling around a `6 × 6` floor of reflectance 0.5,
/// 2 units high, with a square hole of side `hole` in the middle of the
/// ceiling: only the floor reflects, so its radiosity is `0.5 · S · F(x →
/// hole)` exactly. Returns the scene and the hole's corners.
fn room_with_skylight(hole: f32) -> (Scene, [Vec3; 4]) {
    let (w, h) = (6.0f32, 2.0f32);
    let (a, b) = ((w - hole) / 2.0, (w + hole) / 2.0);
    // Ceiling pieces face down: listed counter-clockwise seen from below.
    let ceiling = |x0: f32, x1: f32, z0: f32, z1: f32| {
        polygon(1, &[[x0, h, z0], [x1, h, z0], [x1, h, z1], [x0, h, z1]])
    };
    let mut polygons = vec![
        floor(w),
        ceiling(0.0, w, 0.0, a),
        ceiling(0.0, w, b, w),
        ceiling(0.0, a, a, b),
        ceiling(b, w, a, b),
    ];
    // Four walls facing in.
    for wall in [
        [[0., 0., 0.], [w, 0., 0.], [w, h, 0.], [0., h, 0.]],
        [[w, 0., w], [0., 0., w], [0., h, w], [w, h, w]],
        [[0., 0., w], [0., 0., 0.], [0., h, 0.], [0., h, w]],
        [[w, 0., 0.], [w, 0., w], [w, h, w], [w, h, 0.]],
    ] {
        polygons.push(polygon(1, &wall));
    }
    let s = scene(
        polygons,
        vec![grey("floor", 0.0, 0.5), grey("black", 0.0, 0.0)],
    );
    for p in &s.polygons[1..] {
        let inward = Vec3::new(w / 2.0, h / 2.0, w / 2.0) - p.vertices[0];
        assert!(p.normal.dot(inward) > 0.0);
    }
    let corners = [
        Vec3::new(a, h, a),
        Vec3::new(b, h, a),
        Vec3::new(b, h, b),
        Vec3::new(a, h, b),
    ];
    (s, corners)
}

/// The `z` of the row of polygon `p`'s vertices nearest to `z`.
fn row_nearest(mesh: &Mesh, p: usize, z: f32) -> f32 {
    mesh.polygons[p]
        .vertices
        .clone()
        .map(|l| mesh.sample_positions[l as usize].z)
        .min_by(|a, b| (a - z).abs().total_cmp(&(b - z).abs()))
        .unwrap_or(z)
}

/// Per floor vertex on the row nearest to `z = 3` across the room, sorted by `x`:
/// (x, solved radiosity, exact radiosity).
/// `at_once`: the sky gathered at once, each vertex asking from its hat's
/// centroid ([`crate::solver::accel::hat`]), so the exact value is
/// Lambert's mean under the hat ([`hat_mean`]); else shot facet by facet,
/// and the exact value is Lambert's at the vertex.
fn skylight_profile(hole: f32, lenmax: f32, at_once: bool) -> Vec<(f32, f64, f64)> {
    let (s, corners) = room_with_skylight(hole);
    let approximations = Approximations::DEFAULT.with(Heuristic::SkyAtOnce, at_once);
    let (_, mesh, radiosity, _) = solve_under_sky_with(s, Rgb::splat(1.0), lenmax, approximations);
    let z = row_nearest(&mesh, 0, 3.0);
    let lambert = |x: Vec3| 0.5 * point_to_polygon(x, Vec3::Y, &corners);
    let mut line: Vec<(f32, f64, f64)> = mesh.polygons[0]
        .vertices
        .clone()
        .filter(|&l| mesh.sample_positions[l as usize].z == z)
        .map(|l| {
            let x = mesh.sample_positions[l as usize];
            let exact = if at_once {
                hat_mean(&mesh, 0, l, lambert)
            } else {
                lambert(x)
            };
            (x.x, radiosity[l as usize].r, exact)
        })
        .collect();
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    line
}

#[test]
fn sky_light_through_a_skylight_matches_lambert() {
    for (how, at_once) in BOTH_SKIES {
        skylight_matches_lambert(how, at_once);
    }
}

fn skylight_matches_lambert(how: &str, at_once: bool) {
    let line = skylight_profile(1.0, 0.1, at_once);
    assert!(line.len() > 50);
    let peak = line.iter().map(|v| v.2).fold(0.0, f64::max);
    let (mut worst, mut sum, mut exact_sum) = (0.0f64, 0.0, 0.0);
    for &(_, got, want) in &line {
        worst = worst.max((got - want).abs() / peak);
        sum += got;
        exact_sum += want;
    }
    eprintln!(
        "skylight {how}: worst {worst:.4} of the peak, sum {:.4}",
        sum / exact_sum
    );
    // The light the floor gets along the line, within 1 %; no point off
    // by more than a few percent of the peak.
    assert!(
        (sum / exact_sum - 1.0).abs() < 0.01,
        "{how}: {sum} vs {exact_sum}"
    );
    assert!(worst < 0.04, "{how}: worst error {worst} of the peak");
}

#[test]
fn sky_light_through_a_skylight_is_smooth() {
    // The floor under a skylight gets the sum of one sharp image of the
    // hole per sky direction seen through it; enough directions make the
    // sum smooth. Roughness: how far a vertex is from the mean of its two
    // neighbours, relative to the peak, against the exact profile's own.
    for (how, at_once) in BOTH_SKIES {
        let line = skylight_profile(1.0, 0.05, at_once);
        let peak = line.iter().map(|v| v.2).fold(0.0, f64::max);
        let rough = |value: fn(&(f32, f64, f64)) -> f64| {
            line.windows(3)
                .map(|w| (value(&w[1]) - 0.5 * (value(&w[0]) + value(&w[2]))).abs() / peak)
                .fold(0.0, f64::max)
        };
        let (solved, exact) = (rough(|v| v.1), rough(|v| v.2));
        eprintln!("roughness {how}: solved {solved:.4}, exact {exact:.4}");
        assert!(solved < 0.02, "{how}: roughness {solved} (exact {exact})");
    }
}

#[test]
fn an_overhang_shades_the_floor_as_lambert_says() {
    // A black roof 1 unit above the floor's half x < 2 (of a 4 × 4 floor):
    // the floor sees the sky except where the roof hides it.
    for (how, at_once) in BOTH_SKIES {
        overhang_shades_the_floor(how, at_once);
    }
}

fn overhang_shades_the_floor(how: &str, at_once: bool) {
    let roof = [[-1., 1., -1.], [2., 1., -1.], [2., 1., 5.], [-1., 1., 5.]];
    let s = scene(
        vec![floor(4.0), polygon(1, &roof)],
        vec![grey("floor", 0.0, 0.5), grey("black", 0.0, 0.0)],
    );
    let approximations = Approximations::DEFAULT.with(Heuristic::SkyAtOnce, at_once);
    let (_, mesh, radiosity, _) = solve_under_sky_with(s, Rgb::splat(2.0), 0.2, approximations);
    let corners = roof.map(Vec3::from_array);
    let mut worst = 0.0f64;
    let mut line: Vec<(f32, f64)> = Vec::new();
    let z = row_nearest(&mesh, 0, 2.0);
    for (x, b) in vertices_of(&mesh, &radiosity, 0) {
        let exact = 0.5 * 2.0 * (1.0 - point_to_polygon(x, Vec3::Y, &corners));
        worst = worst.max((b.r - exact).abs());
        if x.z == z {
            line.push((x.x, b.r));
        }
    }
    eprintln!("overhang {how}: worst error {worst:.4} of 1");
    assert!(worst < 0.03, "{how}: worst error {worst} of 1");
    // Brighter and brighter from deep under the roof out into the open
    // (nearer its far edge the floor sees the low sky beyond it again).
    line.sort_by(|a, b| a.0.total_cmp(&b.0));
    let outward: Vec<&(f32, f64)> = line.iter().filter(|v| v.0 >= 1.0).collect();
    assert!(outward.windows(2).all(|w| w[1].1 >= w[0].1), "{line:?}");
    assert!(
        line[0].1 < 0.25 && line[line.len() - 1].1 > 0.95,
        "{line:?}"
    );
}

#[test]
fn a_courtyard_under_a_sky_reflects_before_it_converges() {
    // Walls that reflect make the floor brighter than black walls do: the
    // threshold must not stop the solve once the sky has shot (its own
    // power is thousands of times the scene's).
    let courtyard = |rho: f64| {
        let (mut s, _) = room_with_skylight(1.0);
        s.polygons.drain(1..5);
        s.materials[1] = grey("walls", 0.0, rho);
        s
    };
    let mean_floor = |s: Scene| {
        let (_, mesh, radiosity, steps) = solve_under_sky(s, Rgb::splat(1.0), 0.25);
        let n = mesh.polygons[0].vertex_count() as f64;
        let sum: f64 = vertices_of(&mesh, &radiosity, 0).map(|(_, b)| b.r).sum();
        (sum / n, steps)
    };
    let (black, black_steps) = mean_floor(courtyard(0.0));
    let (grey_walls, grey_steps) = mean_floor(courtyard(0.6));
    // The sky (one step gathered at once), then the floor; with grey
    // walls, the walls too.
    assert!(black_steps >= 2 && grey_steps > black_steps + 3);
    assert!(
        black < 0.5 && grey_walls > black * 1.05,
        "{black} {grey_walls}"
    );
}

#[test]
fn the_sky_is_one_element_a_facet_and_is_left_out_of_the_drawn_mesh() {
    let mut s = scene(vec![floor(2.0)], vec![grey("floor", 0.0, 0.5)]);
    let bare = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.1,
            inset: 0.05,
        },
    )
    .unwrap();
    s.add_sky(Rgb::splat(1.0)).unwrap();
    let m = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.1,
            inset: 0.05,
        },
    )
    .unwrap();
    m.validate().unwrap();
    for pm in &m.polygons[1..] {
        assert!(pm.sky);
        assert_eq!((pm.elements.len(), pm.vertex_count()), (1, 3));
    }
    let radiosity: Vec<u32> = (0..m.vertex_count() as u32).collect();
    let (drawn, kept) = m.without_sky(&radiosity).unwrap();
    drawn.validate().unwrap();
    assert_eq!(drawn.positions, bare.positions);
    assert_eq!(drawn.elements, bare.elements);
    assert_eq!(drawn.polygons.len(), m.polygons.len());
    assert_eq!(kept, (0..bare.vertex_count() as u32).collect::<Vec<_>>());
    assert!(bare.without_sky(&radiosity).is_none());
}

#[test]
fn the_checkpoint_fingerprint_covers_the_sky() {
    let base = scene(vec![floor(2.0)], vec![grey("floor", 0.0, 0.5)]);
    let fingerprint = |sky: Option<Rgb>| {
        let mut s = base.clone();
        if let Some(sky) = sky {
            s.add_sky(sky).unwrap();
        }
        let options = MeshOptions {
            lenmax: 0.5,
            inset: mesh::DEFAULT_INSET,
        };
        let m = mesh::build(&s, &options).unwrap();
        checkpoint::fingerprint(&s, &m, &SolverOptions::default())
    };
    let (none, one, two) = (
        fingerprint(None),
        fingerprint(Some(Rgb::splat(1.0))),
        fingerprint(Some(Rgb::splat(2.0))),
    );
    assert!(none != one && one != two && none != two);
    assert_eq!(one, fingerprint(Some(Rgb::splat(1.0))));
}

/// Sky probes ([`super::probes`]) against asking every direction of
/// every facet, all else alike: a floor under an overhang, with a thin
/// post (0.1 × 0.1, 1.5 tall) out in the open, a small occluder the
/// probes might miss. The floor's vertices agree within 0.5 % relative
/// L1 and each within 2 % of the brightest, with fewer rays (measured:
/// 0.19 %, 0.74 % and 0.35 × the rays; much of this floor sees the sky's
/// edge past the roof, where probes disagree and their regions answer
/// away from the edge), and the same bits on 1 and 2 threads.
#[test]
fn sky_probes_match_asking_every_direction() {
    // Shot facet by facet, a facet's 16 probes: relL1 0.19 %, 0.35 × the
    // rays; gathered at once, a cell's one of 576, the cells near the
    // horizon asking all their directions: 0.01 %, 0.47 × the rays.
    sky_probes_match(false, 0.005, 0.4);
    sky_probes_match(true, 0.005, 0.5);
}

/// The probes against asking every direction, the sky gathered at once
/// or not: the floor's relative L1 difference below `l1`, the rays below
/// `share` of asking every direction.
fn sky_probes_match(at_once: bool, l1: f64, share: f64) {
    let roof = [[-1., 1., -1.], [2., 1., -1.], [2., 1., 5.], [-1., 1., 5.]];
    let mut polygons = vec![floor(4.0), polygon(1, &roof)];
    polygons.extend(crate::testutil::cuboid(
        [3.0, 0.0, 2.0],
        [3.1, 1.5, 2.1],
        false,
    ));
    let mut s = scene(
        polygons,
        vec![grey("floor", 0.0, 0.5), grey("black", 0.0, 0.0)],
    );
    s.add_sky(Rgb::splat(2.0)).unwrap();
    let mesh = crate::testutil::regular_mesh(&s, 0.1);
    let vis = Visibility::new(&s);
    let run = |probing: bool| {
        let options = SolverOptions {
            approximations: Approximations::DEFAULT
                .with(Heuristic::SkyProbes, probing)
                .with(Heuristic::SkyAtOnce, at_once),
            ..Default::default()
        };
        let mut solver = Progressive::new(&s, &mesh, &vis, options);
        while !solver.is_done() && solver.step().is_some() {}
        solver.validate().unwrap();
        (solver.radiosity().to_vec(), solver.rays())
    };
    let (probed, probed_rays) = run(true);
    let (every, every_rays) = run(false);
    let floor_vertices = mesh.polygons[0].vertices.clone();
    let peak = floor_vertices
        .clone()
        .map(|l| every[l as usize].mean())
        .fold(0.0f64, f64::max);
    let (mut diff, mut total, mut worst) = (0.0, 0.0, 0.0f64);
    for l in floor_vertices {
        let (a, b) = (probed[l as usize].mean(), every[l as usize].mean());
        diff += (a - b).abs();
        total += b;
        worst = worst.max((a - b).abs() / peak);
    }
    eprintln!(
        "sky probes (at once: {at_once}): floor relL1 {}, worst vertex {worst} of the peak, rays {probed_rays} vs {every_rays}",
        diff / total
    );
    assert!(diff / total < l1, "floor relL1 {}", diff / total);
    assert!(worst < 0.02, "worst vertex {worst} of the peak");
    assert!(
        (probed_rays as f64) < share * every_rays as f64,
        "probes saved too few rays: {probed_rays} vs {every_rays}"
    );
    let threads = |n| {
        super::on_threads(n, || {
            let options = SolverOptions {
                approximations: Approximations::DEFAULT.with(Heuristic::SkyAtOnce, at_once),
                ..Default::default()
            };
            let mut solver = Progressive::new(&s, &mesh, &vis, options);
            for _ in 0..20 {
                if solver.step().is_none() {
                    break;
                }
            }
            solver.radiosity().to_vec()
        })
    };
    assert!(super::same_bits(&threads(1), &threads(2)));
}

/// A `4 × 4` floor (reflectance 0.5) along a black wall at its edge
/// `x = 0`, `0.3` high and much longer than the floor, under a sky of 2,
/// meshed in `1 × 1` elements: the floor's vertices on the wall's foot
/// with `hat_centroids` and without, against the mean of Lambert's closed
/// form under each one's hat. Returns the worst difference on the foot's
/// row and over the whole floor, in units of the open floor's radiosity.
fn foot_of_a_wall_against_hat_means(hat_centroids: bool) -> (f64, f64) {
    let h = 0.3f32;
    let wall = [[0., 0., -40.], [0., h, -40.], [0., h, 44.], [0., 0., 44.]];
    let s = scene(
        vec![floor(4.0), polygon(1, &wall)],
        vec![grey("floor", 0.0, 0.5), grey("black", 0.0, 0.0)],
    );
    assert!(s.polygons[1].normal.x > 0.99, "the wall faces the floor");
    let approximations = Approximations::DEFAULT.with(Heuristic::HatCentroids, hat_centroids);
    let (_, mesh, radiosity, _) = solve_under_sky_with(s, Rgb::splat(2.0), 1.0, approximations);
    let corners = wall.map(Vec3::from_array);
    let open = |x: Vec3| 1.0 - point_to_polygon(x, Vec3::Y, &corners).abs();
    let (mut foot, mut all) = (0.0f64, 0.0f64);
    for l in mesh.polygons[0].vertices.clone() {
        let d = (radiosity[l as usize].r / (0.5 * 2.0) - hat_mean(&mesh, 0, l, open)).abs();
        all = all.max(d);
        if mesh.positions[l as usize].x == 0.0 {
            foot = foot.max(d);
        }
    }
    (foot, all)
}

#[test]
fn at_the_foot_of_a_wall_a_vertex_gets_its_elements_mean() {
    // Evaluated at its own point, 5 % of an element from the wall, a
    // vertex on the wall's foot sees 40 % of its sky blocked, where its
    // elements lose about 15 % on the whole (26 % of the open floor's
    // light apart); asked from its hat's centroid, a third of an element
    // in, it gets their mean to within the curvature of the light across
    // them (4 %).
    let (centroid_foot, centroid_all) = foot_of_a_wall_against_hat_means(true);
    let (point_foot, point_all) = foot_of_a_wall_against_hat_means(false);
    eprintln!(
        "against the hat means: centroids foot {centroid_foot:.4} all {centroid_all:.4}; \
         points foot {point_foot:.4} all {point_all:.4}"
    );
    assert!(centroid_all < 0.06, "centroids: worst {centroid_all}");
    assert!(
        point_foot > 4.0 * centroid_foot,
        "points: foot {point_foot} (centroids {centroid_foot})"
    );
}
