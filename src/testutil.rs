//! Small scenes built in code for unit tests, independent of the parser.

use crate::color::Rgb;
use crate::scene::{
    Camera, CameraSource, Material, MaterialId, Polygon, Scene, Shape, SourcePos, Surface,
};
use glam::{DVec3, Vec3};

/// The generated hall of tables and chairs, shared with the examples and
/// the benches.
#[path = "../examples/support/hall.rs"]
pub mod hall;
/// The generated Cornell box with two UV spheres, shared with the examples.
#[path = "../examples/support/sphere_box.rs"]
pub mod sphere_box;

/// Marsaglia's xorshift64: a tiny deterministic pseudo-random stream, so
/// that randomized tests draw the same cases on every run.
pub struct Xorshift(pub u64);

impl Xorshift {
    /// The next 64 random bits (the seed must not be 0).
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in `[0, 1)` with 53 random bits.
    pub fn unit_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[0, 1)` with 24 random bits (exact in `f32`).
    pub fn unit_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// A polygon with its Newell normal and area; the shape is inferred.
pub fn polygon(material: u32, vertices: &[[f32; 3]]) -> Polygon {
    let v: Vec<Vec3> = vertices.iter().map(|a| Vec3::from_array(*a)).collect();
    let mut n = DVec3::ZERO;
    for k in 0..v.len() {
        n += v[k].as_dvec3().cross(v[(k + 1) % v.len()].as_dvec3());
    }
    let shape = match v.len() {
        3 => Shape::Triangle,
        4 if (v[0] + v[2] - v[1] - v[3]).length() < 1e-6 => Shape::Parallelogram,
        4 => Shape::Quad,
        _ => Shape::Convex,
    };
    Polygon {
        material: MaterialId(material),
        vertices: v,
        normal: n.normalize().as_vec3(),
        area: n.length() * 0.5,
        shape,
        origin: SourcePos::default(),
        surface: Surface::default(),
    }
}

/// A grey material with emission `e` and reflectance `rho` in every channel.
pub fn grey(name: &str, e: f64, rho: f64) -> Material {
    Material {
        name: name.into(),
        color: Rgb::WHITE,
        k_diffrefl: rho,
        k_emission: e,
    }
}

/// A scene of these polygons and materials with a camera at +z.
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

/// The box `lo..hi` as six quads of material 0 ([`closed_box`]'s order),
/// facing inwards (`inward`) or outwards.
pub fn cuboid(lo: [f32; 3], hi: [f32; 3], inward: bool) -> Vec<Polygon> {
    let s = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    closed_box(1.0, [0; 6])
        .into_iter()
        .map(|p| {
            let mut v: Vec<[f32; 3]> = p
                .vertices
                .iter()
                .map(|q| [lo[0] + q.x * s[0], lo[1] + q.y * s[1], lo[2] + q.z * s[2]])
                .collect();
            if !inward {
                v.reverse();
            }
            polygon(0, &v)
        })
        .collect()
}

/// The six inward-facing walls of the box `[0, s]³`, wall `k` with
/// material `materials[k]`, in the order -x, +x, -y, +y, -z, +z.
pub fn closed_box(s: f32, materials: [u32; 6]) -> Vec<Polygon> {
    let walls: [(u32, [[f32; 3]; 4]); 6] = [
        (
            materials[0],
            [[0., 0., 0.], [0., 0., s], [0., s, s], [0., s, 0.]],
        ),
        (
            materials[1],
            [[s, 0., 0.], [s, s, 0.], [s, s, s], [s, 0., s]],
        ),
        (
            materials[2],
            [[0., 0., 0.], [s, 0., 0.], [s, 0., s], [0., 0., s]],
        ),
        (
            materials[3],
            [[0., s, 0.], [0., s, s], [s, s, s], [s, s, 0.]],
        ),
        (
            materials[4],
            [[0., 0., 0.], [0., s, 0.], [s, s, 0.], [s, 0., 0.]],
        ),
        (
            materials[5],
            [[0., 0., s], [s, 0., s], [s, s, s], [0., s, s]],
        ),
    ];
    // Listed counter-clockwise from outside; reversed to face inward.
    walls
        .iter()
        .map(|(m, v)| {
            let mut v = *v;
            v.reverse();
            polygon(*m, &v)
        })
        .collect()
}

#[test]
fn closed_box_faces_inward() {
    let walls = closed_box(2.0, [0; 6]);
    let centre = Vec3::splat(1.0);
    for w in &walls {
        assert!(w.normal.dot(centre - w.vertices[0]) > 0.0);
        assert!((w.area - 4.0).abs() < 1e-9);
        assert_eq!(w.shape, Shape::Parallelogram);
    }
}

/// A closed 2-unit box whose ceiling glows (emission 10) and reflects
/// (0.3), with walls of reflectances 0.7 and 0.4: every polygon reflects,
/// so its energy balance is a closed form. (A lamp hanging inside would
/// absorb light on its black back, which no wall's balance sees.)
pub fn glowing_box() -> Scene {
    scene(
        closed_box(2.0, [1, 2, 1, 0, 1, 2]),
        vec![
            grey("lamp", 10.0, 0.3),
            grey("a", 0.0, 0.7),
            grey("b", 0.0, 0.4),
        ],
    )
}

/// [`glowing_box`] with a square floating low over its floor, facing up:
/// it casts a sharp shadow that adaptive subdivision refines.
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
    scene(polygons, glowing_box().materials)
}

/// The regular mesh of `s` with elements at most `lenmax` across and the
/// default inset.
pub fn regular_mesh(s: &Scene, lenmax: f32) -> crate::mesh::Mesh {
    crate::mesh::build(
        s,
        &crate::mesh::MeshOptions {
            lenmax,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap()
}

/// Area-weighted mean radiosity of polygon `p` of mesh `m`, from
/// `radiosity` per mesh vertex.
pub fn mean_radiosity(m: &crate::mesh::Mesh, radiosity: &[Rgb], p: usize) -> Rgb {
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
pub fn absorbed_power(s: &Scene, m: &crate::mesh::Mesh, radiosity: &[Rgb]) -> f64 {
    let mut absorbed = 0.0;
    for (p, polygon) in s.polygons.iter().enumerate() {
        let material = &s.materials[polygon.material.index()];
        let rho = material.reflectance().r;
        let b = mean_radiosity(m, radiosity, p).r;
        absorbed += polygon.area * (1.0 - rho) / rho * (b - material.emission().r);
    }
    absorbed
}

/// `p` (a quadrilateral) cut into `n × n` quadrilaterals of its material,
/// as an exporter that triangulates or tiles a wall writes it.
pub fn tiled(p: &crate::scene::Polygon, n: usize) -> Vec<crate::scene::Polygon> {
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

/// [`glowing_box`] and [`shadowed_box`] with every wall but the glowing
/// ceiling cut into `n × n` tiles, so that clusters form.
pub fn tiled_box(shadowed: bool, n: usize) -> Scene {
    let s = if shadowed {
        shadowed_box()
    } else {
        glowing_box()
    };
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

/// A floor 0..4 × 0..4 (z = 0, facing +z) under a black square plate
/// 1..3 × 1..3 at height 1, facing down, the sun overhead.
pub fn floor_under_a_plate() -> Scene {
    let mut s = scene(
        vec![
            polygon(
                0,
                &[
                    [0.0, 0.0, 0.0],
                    [4.0, 0.0, 0.0],
                    [4.0, 4.0, 0.0],
                    [0.0, 4.0, 0.0],
                ],
            ),
            polygon(
                1,
                &[
                    [1.0, 1.0, 1.0],
                    [1.0, 3.0, 1.0],
                    [3.0, 3.0, 1.0],
                    [3.0, 1.0, 1.0],
                ],
            ),
        ],
        vec![grey("floor", 0.0, 0.5), grey("plate", 0.0, 0.0)],
    );
    s.camera.up = Vec3::Z;
    let frame = crate::scene::HorizonFrame::new(Vec3::Z, 0.0);
    s.sun = crate::scene::Sun::new(
        crate::scene::SunPosition::from_degrees(0.0, 90.0),
        1000.0,
        &frame,
    );
    s
}
