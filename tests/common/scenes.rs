//! Small scenes built in code through the crate's public API, and the
//! measurements the solver tests take of a solution: what the crate's own
//! unit tests build with their private helpers, for the integration tests
//! that check the solver against closed forms and its switches against
//! their twins.

use glam::Vec3;
use radiosity::color::Rgb;
use radiosity::mesh::{self, Mesh, MeshOptions};
use radiosity::scene::{Camera, CameraSource, Material, MaterialId, Polygon, Scene, SourcePos};
use radiosity::solver::SolverOptions;
use radiosity::visibility::Visibility;

/// A polygon of material `material` through `vertices` (scene units,
/// counter-clockwise seen from the front), with the normal, area and shape
/// the loader would give it.
pub fn polygon(material: u32, vertices: &[[f32; 3]]) -> Polygon {
    let v = vertices.iter().map(|a| Vec3::from_array(*a)).collect();
    Polygon::new(MaterialId(material), v, SourcePos::default()).expect("a valid polygon")
}

/// A grey material with emission `e` and reflectance `rho` (`< 1`) in
/// every channel.
pub fn grey(name: &str, e: f64, rho: f64) -> Material {
    Material {
        name: name.into(),
        color: Rgb::WHITE,
        k_diffrefl: rho,
        k_emission: e,
    }
}

/// A scene of these polygons and materials with a small camera at +z
/// (the camera plays no part in a solve).
pub fn scene(polygons: Vec<Polygon>, materials: Vec<Material>) -> Scene {
    Scene {
        polygons,
        materials,
        camera: Camera {
            eye: Vec3::new(0.5, 0.5, 5.0),
            lookat: Vec3::new(0.5, 0.5, 0.0),
            up: Vec3::Y,
            fov_y: 1.0,
            width: 32,
            height: 24,
        },
        camera_source: CameraSource::File,
        warnings: Vec::new(),
        groups: Vec::new(),
        luminaires: Vec::new(),
        sun: None,
        sky_pattern: None,
    }
}

/// The six inward-facing walls of the box `[0, s]³`, wall `k` of material
/// `materials[k]`, in the order -x, +x, -y, +y, -z, +z.
pub fn closed_box(s: f32, materials: [u32; 6]) -> Vec<Polygon> {
    // Listed counter-clockwise from outside; reversed to face inward.
    let walls: [[[f32; 3]; 4]; 6] = [
        [[0., 0., 0.], [0., 0., s], [0., s, s], [0., s, 0.]],
        [[s, 0., 0.], [s, s, 0.], [s, s, s], [s, 0., s]],
        [[0., 0., 0.], [s, 0., 0.], [s, 0., s], [0., 0., s]],
        [[0., s, 0.], [0., s, s], [s, s, s], [s, s, 0.]],
        [[0., 0., 0.], [0., s, 0.], [s, s, 0.], [s, 0., 0.]],
        [[0., 0., s], [s, 0., s], [s, s, s], [0., s, s]],
    ];
    walls
        .iter()
        .zip(materials)
        .map(|(v, m)| {
            let mut v = *v;
            v.reverse();
            polygon(m, &v)
        })
        .collect()
}

/// The lamp (emission 10, reflectance 0.3) and the two grey reflectors
/// (0.7 and 0.4) of [`glowing_box`], materials 0, 1 and 2.
pub fn lamp_materials() -> Vec<Material> {
    vec![
        grey("lamp", 10.0, 0.3),
        grey("a", 0.0, 0.7),
        grey("b", 0.0, 0.4),
    ]
}

/// A closed 2-unit box whose ceiling (+y) glows and reflects, with walls
/// of reflectances 0.7 and 0.4 ([`lamp_materials`]): every polygon
/// reflects, so its energy balance is a closed form.
pub fn glowing_box() -> Scene {
    scene(closed_box(2.0, [1, 2, 1, 0, 1, 2]), lamp_materials())
}

/// [`glowing_box`] with a square floating low over its floor, facing up,
/// casting a shadow.
pub fn shadowed_box() -> Scene {
    let mut polygons = closed_box(2.0, [1, 2, 1, 0, 1, 2]);
    polygons.push(polygon(
        1,
        &[
            [0.6, 0.3, 0.6],
            [0.6, 0.3, 1.4],
            [1.4, 0.3, 1.4],
            [1.4, 0.3, 0.6],
        ],
    ));
    scene(polygons, lamp_materials())
}

/// `p` (a quadrilateral) cut into `n × n` quadrilaterals of its material,
/// as an exporter that tiles a wall writes it.
pub fn tiled(p: &Polygon, n: usize) -> Vec<Polygon> {
    let v = &p.vertices;
    let at = |u: f32, w: f32| {
        (1.0 - u) * (1.0 - w) * v[0] + u * (1.0 - w) * v[1] + u * w * v[2] + (1.0 - u) * w * v[3]
    };
    let mut out = Vec::new();
    for b in 0..n {
        for a in 0..n {
            let (u0, u1) = (a as f32 / n as f32, (a + 1) as f32 / n as f32);
            let (w0, w1) = (b as f32 / n as f32, (b + 1) as f32 / n as f32);
            let corners = [at(u0, w0), at(u1, w0), at(u1, w1), at(u0, w1)].map(|c| c.to_array());
            out.push(polygon(p.material.0, &corners));
        }
    }
    out
}

/// [`shadowed_box`] with every polygon but the glowing ceiling cut into
/// `n × n` tiles, so that clusters form.
pub fn tiled_shadowed_box(n: usize) -> Scene {
    let s = shadowed_box();
    let polygons = s
        .polygons
        .iter()
        .flat_map(|p| {
            if p.material.0 == 0 {
                vec![p.clone()]
            } else {
                tiled(p, n)
            }
        })
        .collect();
    scene(polygons, s.materials)
}

/// The regular mesh of `s` with elements at most `lenmax` across and the
/// default inset.
pub fn regular_mesh(s: &Scene, lenmax: f32) -> Mesh {
    mesh::build(
        s,
        &MeshOptions {
            lenmax,
            inset: mesh::DEFAULT_INSET,
        },
    )
    .expect("the scene meshes")
}

/// What a solve left: its mesh, radiosity per mesh vertex, step count,
/// and the unshot power it started with and ended with.
pub struct Solved {
    /// The mesh solved on.
    pub mesh: Mesh,
    /// Radiosity per mesh vertex.
    pub radiosity: Vec<Rgb>,
    /// Shooting steps taken.
    pub steps: u64,
    /// Shadow rays cast.
    pub rays: u64,
    /// Unshot power before the first step (the emitted power).
    pub initial_power: f64,
    /// Net unshot power left at the end.
    pub unshot_power: f64,
}

/// Solves `s` on `mesh` with the method `options` choose
/// ([`radiosity::solver::build`]) until it is done (or a step finds
/// nothing to do), checking the method's invariants at the end.
pub fn solve_on(s: &Scene, mesh: Mesh, options: SolverOptions) -> Solved {
    let vis = Visibility::new(s);
    let mut solver = radiosity::solver::build(s, &mesh, &vis, options);
    while !solver.is_done() && solver.step().is_some() {}
    solver.validate().expect("the solver's invariants hold");
    let (radiosity, steps, rays) = (solver.radiosity().to_vec(), solver.steps(), solver.rays());
    let (initial_power, unshot_power) = (solver.initial_unshot_power(), solver.net_unshot_power());
    drop(solver);
    Solved {
        mesh,
        radiosity,
        steps,
        rays,
        initial_power,
        unshot_power,
    }
}

/// [`solve_on`] the [`regular_mesh`] of `s`.
pub fn solve(s: &Scene, lenmax: f32, options: SolverOptions) -> Solved {
    solve_on(s, regular_mesh(s, lenmax), options)
}

/// Runs `f` on a rayon pool of `threads` threads.
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

/// True when the two radiosity arrays are equal bit for bit.
pub fn same_bits(a: &[Rgb], b: &[Rgb]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.to_array().map(f64::to_bits) == y.to_array().map(f64::to_bits))
}

/// Area-weighted mean radiosity of polygon `p` of mesh `m`, from
/// `radiosity` per mesh vertex.
pub fn mean_radiosity(m: &Mesh, radiosity: &[Rgb], p: usize) -> Rgb {
    let areas = m.vertex_areas();
    let pm = &m.polygons[p];
    let mut sum = Rgb::BLACK;
    for l in pm.vertices.clone() {
        sum += radiosity[l as usize] * areas[l as usize];
    }
    sum / pm.area
}

/// The power the polygons of a closed scene `s` have absorbed, from their
/// mean radiosity on mesh `m` (red channel): each reflects `ρ` of what it
/// receives, so it absorbs `(1 − ρ) / ρ · (b − e) · A`. Every polygon must
/// reflect something.
pub fn absorbed_power(s: &Scene, m: &Mesh, radiosity: &[Rgb]) -> f64 {
    let mut absorbed = 0.0;
    for (p, polygon) in s.polygons.iter().enumerate() {
        let material = &s.materials[polygon.material.index()];
        let rho = material.reflectance().r;
        let b = mean_radiosity(m, radiosity, p).r;
        absorbed += polygon.area * (1.0 - rho) / rho * (b - material.emission().r);
    }
    absorbed
}

/// Relative L1 difference of `a` from `b`, radiosities per vertex of mesh
/// `m`: `Σ |a − b| A / Σ b A` over the vertices, of the channels' mean,
/// weighted by vertex area.
pub fn relative_l1(m: &Mesh, a: &[Rgb], b: &[Rgb]) -> f64 {
    let areas = m.vertex_areas();
    let (mut diff, mut total) = (0.0, 0.0);
    for (l, (x, y)) in a.iter().zip(b).enumerate() {
        diff += (x.mean() - y.mean()).abs() * areas[l];
        total += y.mean() * areas[l];
    }
    diff / total
}
