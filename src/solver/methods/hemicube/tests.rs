//! The hemicube against closed forms: its delta form factors, and the
//! form factors it measures from a point and between unit squares.

use super::*;
use crate::mesh::{self, MeshOptions};
use crate::solver::formfactor::point_to_polygon;
use crate::testutil::{grey, polygon, scene};

/// Exact form factor between two coaxial parallel unit squares one unit
/// apart (Howell's catalogue, C-11).
const F_PARALLEL_UNIT_SQUARES: f64 = 0.19982;
/// Exact form factor between two unit squares meeting at a right angle
/// along a full edge (Howell's catalogue, C-14).
const F_PERPENDICULAR_UNIT_SQUARES: f64 = 0.20004;

/// The delta form factors are exact per pixel (Lambert's integral in
/// `f64`), so the whole hemicube sums to 1 up to the rounding of some
/// hundred thousand additions.
const DELTA_SUM_TOLERANCE: f64 = 1e-9;

const BOTTOM: [[f32; 3]; 4] = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]];
const TOP: [[f32; 3]; 4] = [[0., 0., 1.], [0., 1., 1.], [1., 1., 1.], [1., 0., 1.]];
const SIDE: [[f32; 3]; 4] = [[0., 0., 0.], [0., 1., 0.], [0., 1., 1.], [0., 0., 1.]];

#[test]
fn delta_form_factors_sum_to_one() {
    for n in [8, 64, 128, 256] {
        let d = DeltaFormFactors::new(HemicubeRes::new(n).unwrap());
        let total = d.total();
        assert!(
            (total - 1.0).abs() < DELTA_SUM_TOLERANCE,
            "N = {n}: {total}"
        );
        if n < 64 {
            continue;
        }
        // The pixel next to the top face's centre: within 1 % of the
        // cosine-law value ΔA / π of a small pixel straight overhead (its
        // cos⁴ falloff over a pixel of 2/64 is below 0.1 %).
        let n = n as usize;
        let centre = d.top[(n / 2) * n + n / 2];
        let expected = (2.0 / n as f64).powi(2) / PI;
        assert!(
            (centre - expected).abs() < 0.01 * expected,
            "{centre} vs {expected}"
        );
    }
}

#[test]
fn resolution_is_even_and_in_range() {
    for bad in [0, 1, 7, 9, 127, 8192, u64::MAX] {
        assert_eq!(
            HemicubeRes::new(bad),
            Err(HemicubeError::BadResolution(bad))
        );
    }
    for good in [8, 64, 128, 4096] {
        assert_eq!(
            HemicubeRes::new(good).map(HemicubeRes::get),
            Ok(good as u32)
        );
    }
    let message = HemicubeError::BadResolution(0).to_string();
    assert!(
        message.contains("even number") && message.contains("got 0"),
        "{message}"
    );
}

#[test]
fn frames_are_orthonormal_and_turned() {
    let n = Vec3::new(0.3, -0.5, 0.8).normalize();
    let a = frame(n, 1);
    let b = frame(n, 2);
    for f in [a, b] {
        assert!((f.u.length() - 1.0).abs() < 1e-5 && f.u.dot(f.n).abs() < 1e-5);
        assert!((f.v - f.n.cross(f.u)).length() < 1e-6);
    }
    assert!(a.u.dot(b.u) < 0.99999, "seeds turn the frame");
    assert_eq!(frame(n, 1), a, "the same seed gives the same frame");
}

/// A scene of an emitter (polygon 0) and other polygons, meshed.
fn meshed(polygons: Vec<crate::scene::Polygon>, lenmax: f32) -> (crate::scene::Scene, Mesh) {
    let s = scene(polygons, vec![grey("a", 1.0, 0.5), grey("b", 0.0, 0.5)]);
    let m = mesh::build(&s, &MeshOptions { lenmax, inset: 0.0 }).unwrap();
    (s, m)
}

/// Sum over polygon `p`'s elements of the form factors from one hemicube
/// at `eye` on polygon 0, with every other polygon receiving.
fn point_form_factor(
    s: &crate::scene::Scene,
    m: &Mesh,
    eye: Vec3,
    seed: u64,
    res: u64,
) -> Vec<f64> {
    let deltas = DeltaFormFactors::new(HemicubeRes::new(res).unwrap());
    let corners: Vec<Vec<Vec3>> = s.polygons.iter().map(|p| p.vertices.clone()).collect();
    let mut roles = vec![Role::Receiver; s.polygons.len()];
    roles[0] = Role::Skip;
    let mut out = Vec::new();
    Hemicube::new().form_factors(
        &deltas,
        m,
        &corners,
        &roles,
        eye,
        frame(s.polygons[0].normal, seed),
        1e-6,
        None,
        &mut out,
    );
    let mut per_polygon = vec![0.0; s.polygons.len()];
    for (e, f) in out {
        per_polygon[m.element_polygon[e as usize].index()] += f;
    }
    per_polygon
}

/// From a point, the hemicube's form factor to a square must match
/// Lambert's exact value. The error is the pixels the square's outline
/// crosses: at N = 128 its image on the top face is about 64 pixels
/// across, so about 4 · 64 pixels of the outline are each half right,
/// on average: a relative error of order 1/64 at worst and much less
/// with cancellations; measured under 0.3 %. Bound 1 %.
#[test]
fn point_to_square_matches_lambert() {
    let (s, m) = meshed(
        vec![polygon(0, &BOTTOM), polygon(1, &TOP), polygon(1, &SIDE)],
        0.1,
    );
    for (eye, seed) in [
        (Vec3::new(0.5, 0.5, 0.0), 3),
        (Vec3::new(0.2, 0.7, 0.0), 4),
        (Vec3::new(0.9, 0.1, 0.0), 5),
    ] {
        let f = point_form_factor(&s, &m, eye, seed, 128);
        for p in [1, 2] {
            let exact = point_to_polygon(eye, Vec3::Z, &s.polygons[p].vertices);
            let err = (f[p] - exact).abs() / exact;
            eprintln!("eye {eye}, polygon {p}: {} vs {exact}, error {err}", f[p]);
            assert!(err < 0.01, "eye {eye}, polygon {p}: {} vs {exact}", f[p]);
        }
    }
}

/// A nearer occluder hides what it covers: an opaque square halfway up
/// between the eye and the top square takes the top's place in the item
/// buffer, and gets (about) the form factor the top had there.
#[test]
fn a_nearer_square_hides_a_farther_one() {
    let mid: Vec<[f32; 3]> = TOP.iter().map(|v| [v[0], v[1], 0.5]).collect();
    let (s, m) = meshed(
        vec![polygon(0, &BOTTOM), polygon(1, &TOP), polygon(1, &mid)],
        0.1,
    );
    let eye = Vec3::new(0.5, 0.5, 0.0);
    let f = point_form_factor(&s, &m, eye, 7, 128);
    assert_eq!(f[1], 0.0, "the top square is hidden");
    let exact = point_to_polygon(eye, Vec3::Z, &s.polygons[2].vertices);
    assert!((f[2] - exact).abs() < 0.01 * exact, "{} vs {exact}", f[2]);
}

/// Polygon-to-polygon form factor from one hemicube at each cell centre
/// of a `k × k` grid on the bottom square, weighted by cell area; and
/// the same midpoint rule with Lambert's exact point form factor.
fn square_form_factor(receiver: [[f32; 3]; 4], k: usize, res: u64) -> (f64, f64) {
    let (s, m) = meshed(vec![polygon(0, &BOTTOM), polygon(1, &receiver)], 0.05);
    let (mut sum, mut exact) = (0.0, 0.0);
    for a in 0..k {
        for b in 0..k {
            let eye = Vec3::new(
                (a as f32 + 0.5) / k as f32,
                (b as f32 + 0.5) / k as f32,
                0.0,
            );
            sum += point_form_factor(&s, &m, eye, (a * k + b) as u64, res)[1];
            exact += point_to_polygon(eye, Vec3::Z, &s.polygons[1].vertices);
        }
    }
    let cells = (k * k) as f64;
    (sum / cells, exact / cells)
}

/// Parallel and perpendicular unit squares from 8 × 8 hemicubes, one per
/// cell as the solver places them. Two errors add up: the midpoint rule
/// over 64 cells (with exact point form factors: 0.24 % high for the
/// parallel pair, whose point form factor is curved, 0.06 % low for the
/// perpendicular one) and each hemicube's pixel outline error (see
/// `point_to_square_matches_lambert`), which partly averages out over 64
/// turned hemicubes. Bounds: the hemicube within 0.5 % of the exact
/// midpoint rule at N = 64 and 0.25 % at N = 128 (measured 0.003–0.03 %),
/// and within that plus 0.5 % (the quadrature) of the closed form.
#[test]
fn unit_squares_from_a_grid_of_hemicubes() {
    for (res, bound) in [(64, 0.005), (128, 0.0025)] {
        for (receiver, exact) in [
            (TOP, F_PARALLEL_UNIT_SQUARES),
            (SIDE, F_PERPENDICULAR_UNIT_SQUARES),
        ] {
            let (f, midpoint) = square_form_factor(receiver, 8, res);
            let err = (f - midpoint).abs() / midpoint;
            let closed = (f - exact).abs() / exact;
            eprintln!(
                "N = {res}: F = {f}, midpoint rule {midpoint} (error {err}), \
                 closed form {exact} (error {closed})"
            );
            assert!(err < bound, "N = {res}: F = {f}, midpoint rule {midpoint}");
            assert!(closed < bound + 0.005, "N = {res}: F = {f}, exact {exact}");
        }
    }
}

/// An element far smaller than a pixel's footprint is point sampled: it
/// is either missed or given a whole pixel's delta form factor (the
/// aliasing of Wallace, Elmquist and Haines 1989, §2). Its exact form
/// factor is about 1/10 of a pixel's delta here; the hemicube gives 0 or
/// at least a pixel's worth, never the right value.
#[test]
fn a_tiny_element_is_missed_or_overweighted() {
    let d = 0.002;
    let tiny = [
        [0.5, 0.5, 1.0],
        [0.5, 0.5 + d, 1.0],
        [0.5 + d, 0.5 + d, 1.0],
        [0.5 + d, 0.5, 1.0],
    ];
    let (s, m) = meshed(vec![polygon(0, &BOTTOM), polygon(1, &tiny)], 1.0);
    let eye = Vec3::new(0.5, 0.5, 0.0);
    let exact = point_to_polygon(eye, Vec3::Z, &s.polygons[1].vertices);
    let pixel = (2.0f64 / 64.0).powi(2) / PI;
    assert!(exact < 0.2 * pixel);
    for seed in 0..8 {
        let f = point_form_factor(&s, &m, eye, seed, 64)[1];
        assert!(
            f == 0.0 || f > 0.9 * pixel,
            "seed {seed}: {f} vs pixel {pixel}"
        );
    }
}

/// Spreading keeps power: `Σ vertex area × Δ` equals the power the
/// elements received.
#[test]
fn spreading_to_vertices_keeps_the_power() {
    let (_, m) = meshed(vec![polygon(0, &BOTTOM), polygon(1, &TOP)], 0.15);
    let areas = m.vertex_areas();
    let mut received = vec![crate::color::Rgb::BLACK; m.elements.len()];
    let mut total = 0.0;
    for (e, r) in received.iter_mut().enumerate() {
        let v = 0.1 + (e % 7) as f64;
        *r = crate::color::Rgb::new(v, 2.0 * v, 0.0);
        if m.element_polygon[e].index() == 1 {
            total += v;
        }
    }
    let mut delta = vec![crate::color::Rgb::BLACK; m.vertex_count()];
    spread_to_vertices(&m, 1, &received, &areas, &mut delta);
    let pm = &m.polygons[1];
    let kept: f64 = pm
        .vertices
        .clone()
        .map(|l| delta[l as usize].r * areas[l as usize])
        .sum();
    assert!((kept - total).abs() < 1e-9 * total, "{kept} vs {total}");
    assert!(m.polygons[0]
        .vertices
        .clone()
        .all(|l| delta[l as usize].is_black()));
}

// The solver shooting by hemicubes.

use crate::color::Rgb;
use crate::solver::{FormFactorMethod, Method, SolverOptions};
use crate::testutil::glowing_box;
use crate::visibility::Visibility;

/// Hemicube solver options at the default resolution.
fn hemicube_options() -> SolverOptions {
    SolverOptions {
        form_factor: FormFactorMethod::Hemicube,
        ..SolverOptions::default()
    }
}

/// A checkpoint of a hemicube solve is refused by a solve with another
/// method or resolution: the fingerprint holds both.
#[test]
fn checkpoint_fingerprint_holds_method_and_resolution() {
    let s = glowing_box();
    let m = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.5,
            inset: 0.0,
        },
    )
    .unwrap();
    let print = |o: SolverOptions| crate::solver::checkpoint::fingerprint(&s, &m, &o);
    let hemi = hemicube_options();
    let coarse = SolverOptions {
        hemicube_res: HemicubeRes::new(64).unwrap(),
        ..hemi
    };
    assert_ne!(print(hemi), print(SolverOptions::default()));
    assert_ne!(print(hemi), print(coarse));
    assert_eq!(print(hemi), print(hemicube_options()));
}

/// A weak step merges its shooter's cells into fewer hemicubes
/// ([`Progressive::hemicube_points`]): at most the number asked, on the
/// shooter, together standing for its whole area and carrying exactly
/// the power its cells carry, per channel. A strong step, or one under
/// `--no-clustering`, keeps one hemicube per cell.
#[test]
fn weak_steps_merge_cells_into_fewer_hemicubes_with_the_same_power() {
    let s = glowing_box();
    let m = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.1,
            inset: mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    let mut method = HemicubeMethod::new(&s, &m, &vis, hemicube_options());
    // After the ceiling's shot every wall holds unshot light.
    method.step().unwrap();
    let solver = &mut method.progressive;
    let shooter = solver.next_shooter().unwrap();
    let i = shooter.index();
    solver.read_shooter(shooter, crate::solver::unshot::Shot::PLAIN);
    let cells = solver.samples[i].len();
    assert_eq!(
        cells,
        crate::solver::tuning::DEFAULT_SHOOTER_SAMPLES as usize
    );
    assert!(solver.hemicube_points(shooter, cells).is_none());
    let polygon = &s.polygons[i];
    let (lo, hi) = polygon.vertices.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &v| (lo.min(v), hi.max(v)),
    );
    let carried = |samples: &[crate::solver::formfactor::ShooterSample], shot: &[Rgb]| {
        samples
            .iter()
            .zip(shot)
            .fold(Rgb::BLACK, |sum, (sample, &u)| sum + u * sample.area)
    };
    let all = carried(&solver.samples[i], &solver.shot);
    for k in [1, 8, 20] {
        let (points, shot) = solver.hemicube_points(shooter, k).unwrap();
        assert!(
            !points.is_empty() && points.len() <= k,
            "{k}: {}",
            points.len()
        );
        let area: f64 = points.iter().map(|p| p.area).sum();
        assert!((area / polygon.area - 1.0).abs() < 1e-9, "{k}: area {area}");
        let power = carried(&points, &shot);
        for (got, want) in [(power.r, all.r), (power.g, all.g), (power.b, all.b)] {
            assert!((got / want - 1.0).abs() < 1e-9, "{k}: {got} vs {want}");
        }
        for p in &points {
            let on_plane = (p.position - polygon.vertices[0]).dot(polygon.normal);
            assert!(on_plane.abs() < 1e-5, "{k}: {on_plane} off the plane");
            let inside = p.position.cmpge(lo - 1e-5).all() && p.position.cmple(hi + 1e-5).all();
            assert!(inside, "{k}: {} outside the shooter", p.position);
        }
    }
}
