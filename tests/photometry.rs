//! Photometry against closed forms: the final gather's illuminance at free
//! points (a uniform enclosure, Howell's parallel rectangle), an IES
//! luminaire over a floor (`E = I(θ) cos³θ / h²`), and the same room drawn
//! in millimetres and in metres.

use glam::Vec3;
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{parse_str, Photometry, Scene, Sides, Units};
use radiosity::solver::final_gather::{vertex_irradiance, FinalGather};
use radiosity::solver::{FormFactorMethod, Progressive, SolverOptions};
use radiosity::visibility::Visibility;
use std::f64::consts::PI;
use std::sync::Arc;

/// A closed box `0..s` on every axis, walls facing in, of material `m`.
fn closed_box(s: f64, m: &str) -> String {
    let q = |a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]| {
        let v = |p: [f64; 3]| format!("  vertex {} {} {}\n", p[0], p[1], p[2]);
        format!("polygon {m}\n{}{}{}{}end\n", v(a), v(b), v(c), v(d))
    };
    [
        q([0., 0., 0.], [0., 0., s], [s, 0., s], [s, 0., 0.]),
        q([0., s, 0.], [s, s, 0.], [s, s, s], [0., s, s]),
        q([0., 0., 0.], [0., s, 0.], [0., s, s], [0., 0., s]),
        q([s, 0., 0.], [s, 0., s], [s, s, s], [s, s, 0.]),
        q([0., 0., 0.], [s, 0., 0.], [s, s, 0.], [0., s, 0.]),
        q([0., 0., s], [0., s, s], [s, s, s], [s, 0., s]),
    ]
    .concat()
}

fn load(text: &str) -> Scene {
    parse_str(text, "test.sc").unwrap_or_else(|e| panic!("{e}"))
}

/// Howell's configuration factor from a differential area to a parallel
/// `a × b` rectangle at distance `c`, the area's normal through one of the
/// rectangle's corners.
fn corner_factor(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

#[test]
fn in_a_uniform_enclosure_the_illuminance_is_the_radiosity_everywhere() {
    let scene = load(&format!(
        "material w color 1 1 1 k_diffrefl 0.5 end\n{}",
        closed_box(2.0, "w")
    ));
    let mesh = mesh::build(&scene, &MeshOptions::for_scene(&scene)).unwrap();
    let visibility = Visibility::new(&scene);
    let b = vec![radiosity::color::Rgb::splat(3.0); mesh.vertex_count()];
    let gather = FinalGather::new(&scene, &mesh, &visibility, &b, true);
    // Points deep inside, near a wall, in a corner, facing every way.
    let points = [
        (Vec3::splat(1.0), Vec3::Y),
        (Vec3::new(1.0, 0.01, 1.0), Vec3::Y),
        (
            Vec3::new(0.02, 1.0, 0.5),
            Vec3::new(1.0, 1.0, 0.3).normalize(),
        ),
        (Vec3::new(1.9, 1.9, 1.95), -Vec3::ONE.normalize()),
        (
            Vec3::new(0.3, 1.2, 1.7),
            Vec3::new(-0.2, 0.1, 1.0).normalize(),
        ),
    ];
    for (x, e) in points.iter().zip(gather.irradiance_at(&points)) {
        assert!(
            (e.mean() / 3.0 - 1.0).abs() < 0.005,
            "{x:?}: E = {} for B = 3",
            e.mean()
        );
    }
}

#[test]
fn a_parallel_square_gives_howells_configuration_factor() {
    // A 1 × 1 emitter at y = 1 facing down over a black floor; only it
    // has radiosity.
    let scene = load(
        "material lamp color 1 1 1 k_emission 1 end\n\
         polygon lamp\n vertex 0 1 0\n vertex 1 1 0\n vertex 1 1 1\n vertex 0 1 1\nend\n",
    );
    let mesh = mesh::build(&scene, &MeshOptions::for_scene(&scene)).unwrap();
    let visibility = Visibility::new(&scene);
    let b = vec![radiosity::color::Rgb::splat(1.0); mesh.vertex_count()];
    let gather = FinalGather::new(&scene, &mesh, &visibility, &b, true);
    for (px, pz, h) in [
        (0.5, 0.5, 1.0),
        (0.2, 0.7, 0.5),
        (0.5, 0.5, 0.05),
        (1.5, 0.3, 0.8),
    ] {
        let c: f64 = h;
        // By superposition of the four rectangles cornered at the foot of
        // the point's normal (signed for a foot outside the square).
        let f = |a: f64, b: f64| a.signum() * b.signum() * corner_factor(a.abs(), b.abs(), c);
        let exact = f(1.0 - px, 1.0 - pz) + f(px, 1.0 - pz) + f(1.0 - px, pz) + f(px, pz);
        let x = Vec3::new(px as f32, (1.0 - h) as f32, pz as f32);
        let e = gather.irradiance(x, Vec3::Y).mean();
        assert!(
            (e / exact - 1.0).abs() < 0.003,
            "at ({px}, {pz}) {h} below: {e} vs Howell's {exact}"
        );
    }
}

/// `I(θ) = 1000 + 500 sin(2θ)` cd, the test tables' light below the
/// horizontal.
fn downward_candela(degrees: f64) -> f64 {
    1000.0 + 500.0 * (2.0 * degrees.to_radians()).sin()
}

/// A test table with vertical angles 0 to `top` degrees in 5° steps and
/// two horizontal planes so that the azimuth matters: C0 as
/// `candela(θ°)` gives, C90 × 0.5 (bilateral, quadrant-symmetric).
fn table_text(top: u32, candela: impl Fn(f64) -> f64) -> String {
    let vertical: Vec<f64> = (0..=top / 5).map(|k| k as f64 * 5.0).collect();
    let row = |scale: f64| -> String {
        vertical
            .iter()
            .map(|&d| format!("{:.3}", scale * candela(d)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    format!(
        "IESNA:LM-63-2002\n[TEST] closed-form test table\nTILT=NONE\n\
         1 -1 1 {} 2 1 2 0.1 0.1 0\n1 1 0\n{}\n0 90\n{}\n{}\n",
        vertical.len(),
        vertical
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(" "),
        row(1.0),
        row(0.5)
    )
}

/// A luminaire table: [`downward_candela`] over 0..90° (nothing upwards).
fn ies_text() -> String {
    table_text(90, downward_candela)
}

/// The floor illuminance of a 2 cm luminaire 2 m over a floor of
/// reflectance 0.5 (nothing else in the scene), drawn at `scale` scene
/// units a metre: by the final gather at `points` (metres), and from the
/// solver's floor vertices nearest them, `(b − e) / ρ`, with where they are
/// (metres).
#[allow(clippy::type_complexity)]
fn luminaire_floor(
    scale: f64,
    units: Units,
    points: &[(f64, f64)],
) -> (Vec<f64>, Vec<(f64, (f64, f64))>, Scene) {
    let (gathered, vertex, scene, _) =
        luminaire_floor_with(scale, units, points, SolverOptions::default());
    (gathered, vertex, scene)
}

/// [`luminaire_floor`] solved with `options`, and also the flux the floor
/// receives by the solver's vertices (`Σ (b − e) / ρ × vertex area`, in
/// lumens at `scale` 1).
#[allow(clippy::type_complexity)]
fn luminaire_floor_with(
    scale: f64,
    units: Units,
    points: &[(f64, f64)],
    solver_options: SolverOptions,
) -> (Vec<f64>, Vec<(f64, (f64, f64))>, Scene, f64) {
    let s = |v: f64| v * scale;
    let (l0, l1) = (s(2.49), s(2.51));
    let text = format!(
        "material lamp color 1 1 1 k_emission 1 end\n\
         material floor color 1 1 1 k_diffrefl 0.5 end\n\
         polygon floor\n vertex 0 0 0\n vertex 0 0 {w}\n vertex {w} 0 {w}\n vertex {w} 0 0\nend\n\
         polygon lamp\n vertex {l0} {h} {l0}\n vertex {l1} {h} {l0}\n vertex {l1} {h} {l1}\n vertex {l0} {h} {l1}\nend\n",
        w = s(5.0),
        h = s(2.0),
    );
    let mut scene = load(&text);
    let photometry = Arc::new(Photometry::parse(&ies_text(), "t.ies").unwrap());
    assert_eq!(scene.set_luminaire("lamp", photometry, units).unwrap(), 1);
    let mut options = MeshOptions::for_scene(&scene);
    options.lenmax = s(0.25) as f32;
    let mesh = mesh::build(&scene, &options).unwrap();
    let visibility = Visibility::new(&scene);
    let mut solver = radiosity::solver::build(&scene, &mesh, &visibility, solver_options);
    while solver.step().is_some() {}
    let gather = FinalGather::new(&scene, &mesh, &visibility, solver.radiosity(), true);
    let at: Vec<(Vec3, Vec3)> = points
        .iter()
        .map(|&(x, z)| (Vec3::new(s(x) as f32, 0.0, s(z) as f32), Vec3::Y))
        .collect();
    let gathered = gather.irradiance_at(&at).iter().map(|e| e.mean()).collect();
    let irradiance = vertex_irradiance(&scene, &mesh, solver.radiosity());
    // The floor vertices at the requested points.
    let vertex = points
        .iter()
        .map(|&(x, z)| {
            let p = Vec3::new(s(x) as f32, 0.0, s(z) as f32);
            let l = (0..mesh.vertex_count())
                .filter(|&l| mesh.vertex_polygon[l].0 == 0)
                .min_by(|&a, &b| {
                    mesh.positions[a]
                        .distance(p)
                        .total_cmp(&mesh.positions[b].distance(p))
                })
                .unwrap();
            let at = mesh.positions[l] / scale as f32;
            (irradiance[l].mean(), (f64::from(at.x), f64::from(at.z)))
        })
        .collect();
    let floor_flux = mesh
        .vertex_areas()
        .iter()
        .enumerate()
        .filter(|&(l, _)| mesh.vertex_polygon[l].0 == 0)
        .map(|(l, a)| irradiance[l].mean() * a)
        .sum();
    (gathered, vertex, scene, floor_flux)
}

#[test]
fn a_luminaire_over_a_floor_gives_i_cos3_over_h2() {
    let photometry = Photometry::parse(&ies_text(), "t.ies").unwrap();
    // Points along C0 (+x from the luminaire: its first edge) and C90.
    let points = [
        (2.5, 2.5),
        (3.0, 2.5),
        (4.0, 2.5),
        (4.75, 2.5),
        (2.5, 3.5),
        (2.5, 4.5),
        (3.5, 3.5),
    ];
    let (gathered, vertex, scene) = luminaire_floor(1.0, Units::M, &points);
    let h = 2.0;
    let c0 = scene.luminaires[0].c0;
    assert_eq!(c0, Vec3::X);
    let exact = |x: f64, z: f64| {
        let (dx, dz) = (x - 2.5, z - 2.5);
        let d2 = dx * dx + dz * dz + h * h;
        let cos = h / d2.sqrt();
        // The nadir is -y; C90 = nadir × C0 = -y × x = +z.
        let phi = dz.atan2(dx);
        photometry.intensity(cos.acos(), phi) * cos.powi(3) / (h * h)
    };
    for (k, &(x, z)) in points.iter().enumerate() {
        let (v, (vx, vz)) = vertex[k];
        for (what, got, exact) in [
            ("gathered", gathered[k], exact(x, z)),
            ("solver vertex", v, exact(vx, vz)),
        ] {
            assert!(
                (got / exact - 1.0).abs() < 0.01,
                "{what} near ({x}, {z}): {got} lx vs I cos³θ / h² = {exact} lx"
            );
        }
    }
}

/// `--form-factor hemicube` shoots a luminaire through its candela table
/// too: each hemicube pixel is weighted by `π (I / Φ) / cosθ`. The floor's
/// flux is the integral of `I cos³θ / h²` over it to 0.5 % (measured
/// 0.02 %; one sample per pixel), where a Lambertian shot of the same
/// flux puts 47 % more on this floor. Each vertex holds the mean of its
/// elements' light, 0.25 m across, so a point value is within 4 %
/// (measured: 3.4 % at the ridge of the table's C0 peak, 0.6 to 1.6 %
/// elsewhere).
#[test]
fn a_hemicube_shot_follows_the_luminaires_table() {
    let photometry = Photometry::parse(&ies_text(), "t.ies").unwrap();
    let h = 2.0;
    let exact = |x: f64, z: f64| {
        let (dx, dz) = (x - 2.5, z - 2.5);
        let d2 = dx * dx + dz * dz + h * h;
        let cos = h / d2.sqrt();
        photometry.intensity(cos.acos(), dz.atan2(dx)) * cos.powi(3) / (h * h)
    };
    // The flux onto the 5 × 5 m floor, by the midpoint rule on 1 cm cells.
    let cells = 500;
    let step = 5.0 / cells as f64;
    let mut flux = 0.0;
    for i in 0..cells {
        for k in 0..cells {
            flux += exact((i as f64 + 0.5) * step, (k as f64 + 0.5) * step) * step * step;
        }
    }
    let points = [
        (2.5, 2.5),
        (3.0, 2.5),
        (4.0, 2.5),
        (2.5, 3.5),
        (2.5, 4.5),
        (3.5, 3.5),
    ];
    let options = SolverOptions {
        form_factor: FormFactorMethod::Hemicube,
        ..SolverOptions::default()
    };
    let (_, vertex, _, floor) = luminaire_floor_with(1.0, Units::M, &points, options);
    assert!(
        (floor / flux - 1.0).abs() < 0.005,
        "floor flux {floor} lm, exact {flux} lm"
    );
    for (k, &(x, z)) in points.iter().enumerate() {
        let (v, (vx, vz)) = vertex[k];
        let e = exact(vx, vz);
        assert!(
            (v / e - 1.0).abs() < 0.04,
            "vertex near ({x}, {z}): {v} lx vs I cos³θ / h² = {e} lx"
        );
    }
}

#[test]
fn the_same_room_in_millimetres_and_in_metres_gives_the_same_lux() {
    let points = [(2.5, 2.5), (4.0, 3.0), (1.0, 0.5)];
    let (m, mv, _) = luminaire_floor(1.0, Units::M, &points);
    let (mm, mmv, _) = luminaire_floor(1000.0, Units::Mm, &points);
    for k in 0..points.len() {
        assert!((m[k] / mm[k] - 1.0).abs() < 1e-4, "{} vs {}", m[k], mm[k]);
        assert!(
            (mv[k].0 / mmv[k].0 - 1.0).abs() < 1e-4,
            "{:?} vs {:?}",
            mv[k],
            mmv[k]
        );
    }
    // And the luminaire emits its flux: exitance × area in m².
    let (_, _, scene) = luminaire_floor(1000.0, Units::Mm, &points);
    let l = &scene.luminaires[0];
    let lamp = scene
        .polygons
        .iter()
        .find(|p| p.material == l.material)
        .unwrap();
    let e = scene.materials[l.material.index()].emission().mean();
    assert!((e * Units::Mm.square_metres(lamp.area) / l.flux - 1.0).abs() < 1e-9);
}

#[test]
fn a_checkpoint_knows_the_luminaires_distribution() {
    let (_, _, scene) = luminaire_floor(1.0, Units::M, &[(2.5, 2.5)]);
    let mesh = mesh::build(&scene, &MeshOptions::for_scene(&scene)).unwrap();
    let options = SolverOptions::default();
    let print = |s: &Scene| radiosity::solver::checkpoint::fingerprint(s, &mesh, &options);
    // The same materials and flux, another shape: the C0 and C90 rows
    // swapped makes another shot.
    let mut swapped = scene.clone();
    let p = Arc::make_mut(&mut swapped.luminaires[0].photometry);
    let n = p.vertical.len();
    let (c0, c90) = p.candela.split_at_mut(n);
    c0.swap_with_slice(&mut c90[..n]);
    assert_eq!(print(&scene), print(&scene.clone()));
    assert_ne!(print(&scene), print(&swapped));
}

/// [`ies_text`] with light upwards too: 0 to 180° in 5° steps, the same
/// below the horizontal and `1000 − 600 sin(θ − 90°)` cd above it (1000
/// at the horizontal, 400 at the zenith), C90 × 0.5 throughout.
fn uplight_ies_text() -> String {
    table_text(180, |d| {
        if d <= 90.0 {
            downward_candela(d)
        } else {
            1000.0 - 600.0 * (d - 90.0).to_radians().sin()
        }
    })
}

/// A pendant's uplight leaves the luminaire's back with the table's upper
/// half: a 2 cm luminaire 2 m under a ceiling of reflectance 0.5 (nothing
/// else in the scene, so the ceiling gets direct light only) gives the
/// ceiling `E = I(θ) cos³ψ / h²` lux (θ from the nadir, past 90°; ψ from
/// the zenith) within 1 %, by the final gather and at the solver's
/// ceiling vertices; the floor-facing front still emits the lower half.
#[test]
fn a_luminaires_uplight_leaves_its_back_with_the_upper_half_of_the_table() {
    let text = "material lamp color 1 1 1 k_emission 1 end\n\
         material ceiling color 1 1 1 k_diffrefl 0.5 end\n\
         polygon ceiling\n vertex 0 4 0\n vertex 5 4 0\n vertex 5 4 5\n vertex 0 4 5\nend\n\
         polygon lamp\n vertex 2.49 2 2.49\n vertex 2.51 2 2.49\n vertex 2.51 2 2.51\n vertex 2.49 2 2.51\nend\n";
    let mut scene = load(text);
    let photometry = Arc::new(Photometry::parse(&uplight_ies_text(), "up.ies").unwrap());
    assert_eq!(
        scene
            .set_luminaire("lamp", photometry.clone(), Units::M)
            .unwrap(),
        1
    );
    let mut scene = scene.with_sides(Sides::AsLoaded);
    scene.light_luminaire_backs();
    // The front and its new back, each a luminaire of its half's flux.
    assert_eq!(scene.polygons.len(), 3);
    assert_eq!(scene.luminaires.len(), 2);
    let (down, up) = (&scene.luminaires[0], &scene.luminaires[1]);
    assert!(!down.upper && up.upper);
    let lower = photometry.flux(PI / 2.0);
    let upper = photometry.flux_between(PI / 2.0, PI);
    assert!((down.flux / lower - 1.0).abs() < 1e-9 && (up.flux / upper - 1.0).abs() < 1e-9);
    let back = &scene.polygons[2];
    assert_eq!(back.normal, Vec3::Y);
    let emitted = scene.materials[back.material.index()].emission().mean() * back.area;
    assert!(
        (emitted / upper - 1.0).abs() < 1e-9,
        "{emitted} lm vs {upper} lm"
    );

    let mut options = MeshOptions::for_scene(&scene);
    options.lenmax = 0.25;
    let mesh = mesh::build(&scene, &options).unwrap();
    let visibility = Visibility::new(&scene);
    let mut solver = Progressive::new(&scene, &mesh, &visibility, SolverOptions::default());
    while solver.step().is_some() {}
    let gather = FinalGather::new(&scene, &mesh, &visibility, solver.radiosity(), true);
    let irradiance = vertex_irradiance(&scene, &mesh, solver.radiosity());
    let h = 2.0;
    let exact = |x: f64, z: f64| {
        let (dx, dz) = (x - 2.5, z - 2.5);
        let d = (dx * dx + dz * dz + h * h).sqrt();
        let cos_psi = h / d;
        // From the nadir (down): past 90°. C90 = nadir × C0 = -y × x = +z.
        photometry.intensity(PI - cos_psi.acos(), dz.atan2(dx)) * cos_psi.powi(3) / (h * h)
    };
    for (x, z) in [
        (2.5, 2.5),
        (3.0, 2.5),
        (4.0, 2.5),
        (2.5, 3.5),
        (2.5, 4.5),
        (3.5, 3.5),
    ] {
        let p = Vec3::new(x as f32, 4.0, z as f32);
        let got = gather.irradiance_at(&[(p, -Vec3::Y)])[0].mean();
        let l = (0..mesh.vertex_count())
            .filter(|&l| mesh.vertex_polygon[l].0 == 0)
            .min_by(|&a, &b| {
                mesh.positions[a]
                    .distance(p)
                    .total_cmp(&mesh.positions[b].distance(p))
            })
            .unwrap();
        let at = mesh.positions[l];
        for (what, got, exact) in [
            ("gathered", got, exact(x, z)),
            (
                "solver vertex",
                irradiance[l].mean(),
                exact(f64::from(at.x), f64::from(at.z)),
            ),
        ] {
            assert!(
                (got / exact - 1.0).abs() < 0.01,
                "{what} near ({x}, {z}): {got} lx vs I cos³ψ / h² = {exact} lx"
            );
        }
    }
}
