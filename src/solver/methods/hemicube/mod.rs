//! Hemicube form factors (Cohen and Greenberg 1985), as used for
//! progressive shooting by Cohen, Chen, Wallace and Greenberg (1988):
//! `--form-factor hemicube`.
//!
//! A hemicube is half a cube of half-width 1 centred on a point `x` of the
//! shooter, its top face 1 above `x` along the shooter's normal and its
//! four half-height side faces standing on the shooter's plane. The top
//! face has `N × N` pixels, each side face `N × N/2`
//! ([`HemicubeRes`]). Every element of the scene is projected through `x`
//! onto the five faces and drawn by a small z-buffer of its own, which
//! keeps per pixel the index of the nearest element (an *item buffer*).
//! Each pixel carries its *delta form factor*, the exact form factor from
//! `x` to the pixel's square (Lambert's contour integral, in `f64`), so
//! the deltas of the whole hemicube sum to 1 to rounding. An element's
//! form factor from `x` is the sum of the deltas of the pixels it holds:
//!
//! ```text
//! F(x → e) = Σ_{pixels p showing e} ΔF_p
//! ```
//!
//! Occlusion comes with the projection: a pixel shows only the nearest
//! element, so nothing is ray traced. What it costs is aliasing (Wallace,
//! Elmquist and Haines 1989, §2): a pixel is one point sample of its
//! direction, so an element smaller than a pixel's footprint is hit or
//! missed whole, shadows of small occluders come out as plaid patterns of
//! pixel rows, and a regular pixel grid seen from regularly spaced
//! shooter points bands. Each hemicube is turned about the normal by its
//! own pseudo-random angle ([`frame`]) so the errors of neighbouring
//! hemicubes do not line up (Cohen et al. 1988 rotate for the same
//! reason).
//!
//! The solver method ([`HemicubeMethod`], in `method.rs`) places one
//! hemicube at each of the shooter's grid samples (its
//! `--shooter-samples` cells), each carrying its cell's area and unshot
//! radiosity (a weak step merges its cells into fewer runs, one hemicube
//! each: `Progressive::hemicube_points`), and spreads what the elements
//! receive to their vertices ([`spread_to_vertices`]).

use crate::mesh::Mesh;
use crate::solver::kernel::distribution::Directional;
use crate::solver::tuning::{DEFAULT_HEMICUBE_RES, HEMICUBE_EDGE_SLACK, HEMICUBE_NEAR_FRACTION};
use glam::{DVec3, Vec3};
use std::f64::consts::PI;

mod method;
pub use method::HemicubeMethod;

/// Smallest resolution accepted: with fewer pixels a side face has under
/// four rows and whole walls vanish between pixel centres.
pub const MIN_HEMICUBE_RES: u32 = 8;

/// Largest resolution accepted: at 4096 the delta form factor tables
/// take 200 MB and each thread's item and depth buffers 134 MB, beyond
/// any use (the error stops falling well before: `docs/accuracy.md`).
pub const MAX_HEMICUBE_RES: u32 = 4096;

/// Pixels across the top face of a hemicube: an even number in
/// [`MIN_HEMICUBE_RES`]`..=`[`MAX_HEMICUBE_RES`] (the side faces have
/// `N/2` rows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HemicubeRes(u32);

/// A hemicube resolution that cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HemicubeError {
    /// Outside the accepted range, or odd.
    #[error(
        "the hemicube resolution must be an even number of pixels from {MIN_HEMICUBE_RES} \
         to {MAX_HEMICUBE_RES}, got {0}"
    )]
    BadResolution(u64),
}

impl HemicubeRes {
    /// `n` pixels across the top face, if it is even and in range.
    pub fn new(n: u64) -> Result<Self, HemicubeError> {
        if n.is_multiple_of(2) && (MIN_HEMICUBE_RES as u64..=MAX_HEMICUBE_RES as u64).contains(&n) {
            Ok(HemicubeRes(n as u32))
        } else {
            Err(HemicubeError::BadResolution(n))
        }
    }

    /// Pixels across the top face.
    pub fn get(self) -> u32 {
        self.0
    }
}

impl Default for HemicubeRes {
    fn default() -> Self {
        HemicubeRes(DEFAULT_HEMICUBE_RES)
    }
}

/// The form factor from the origin, facing `+z`, to the planar polygon
/// `corners` lying wholly at `z >= 0` (Lambert's contour integral, in
/// `f64`: a pixel of 1/4096 is still resolved to about `1e-12`).
fn lambert(corners: &[DVec3]) -> f64 {
    let mut sum = 0.0;
    for k in 0..corners.len() {
        let (a, b) = (
            corners[k].normalize(),
            corners[(k + 1) % corners.len()].normalize(),
        );
        let c = a.cross(b);
        let s = c.length();
        if s > 0.0 {
            let angle = s.atan2(a.dot(b));
            sum += angle * c.z / s;
        }
    }
    (sum / (2.0 * PI)).abs()
}

/// The delta form factors of a resolution: per pixel of the top face and
/// of a side face (all four are alike), the exact form factor from the
/// hemicube's centre to the pixel, summing over the whole hemicube to 1
/// (to rounding).
#[derive(Clone, Debug, PartialEq)]
pub struct DeltaFormFactors {
    res: u32,
    /// `N × N`, row-major, row `r` at `y ∈ [-1 + 2r/N, -1 + 2(r+1)/N]`.
    top: Vec<f64>,
    /// `N × N/2`, row-major, row `r` at height `z ∈ [2r/N, 2(r+1)/N]`.
    side: Vec<f64>,
}

impl DeltaFormFactors {
    /// The table for `res`.
    pub fn new(res: HemicubeRes) -> Self {
        let n = res.get() as usize;
        let at = |i: usize| -1.0 + 2.0 * i as f64 / n as f64;
        let mut top = Vec::with_capacity(n * n);
        for r in 0..n {
            for c in 0..n {
                let (x0, x1, y0, y1) = (at(c), at(c + 1), at(r), at(r + 1));
                top.push(lambert(&[
                    DVec3::new(x0, y0, 1.0),
                    DVec3::new(x1, y0, 1.0),
                    DVec3::new(x1, y1, 1.0),
                    DVec3::new(x0, y1, 1.0),
                ]));
            }
        }
        let mut side = Vec::with_capacity(n * n / 2);
        for r in 0..n / 2 {
            for c in 0..n {
                // The face at y = 1: columns along x, rows up z.
                let (x0, x1, z0, z1) = (at(c), at(c + 1), at(r + n / 2), at(r + n / 2 + 1));
                side.push(lambert(&[
                    DVec3::new(x0, 1.0, z0),
                    DVec3::new(x1, 1.0, z0),
                    DVec3::new(x1, 1.0, z1),
                    DVec3::new(x0, 1.0, z1),
                ]));
            }
        }
        DeltaFormFactors {
            res: res.get(),
            top,
            side,
        }
    }

    /// Sum over the whole hemicube (top face and four side faces): 1 to
    /// rounding.
    pub fn total(&self) -> f64 {
        self.top.iter().sum::<f64>() + 4.0 * self.side.iter().sum::<f64>()
    }

    /// Pixels across the top face.
    pub fn res(&self) -> u32 {
        self.res
    }
}

/// What a polygon is to one hemicube.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Not drawn at all (the shooter itself, a sky facet, the back of a
    /// two-sided surface whose front is drawn).
    Skip,
    /// Drawn, so it hides what is behind it, but receives nothing (its
    /// back faces the hemicube, or it reflects nothing).
    Occluder,
    /// Drawn, and credited with the form factors of its pixels.
    Receiver,
}

/// An orthonormal frame of a hemicube: `u`, `v` across, `n` the normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent, unit length.
    pub u: Vec3,
    /// Second tangent, `n × u`.
    pub v: Vec3,
    /// The shooter's unit front normal.
    pub n: Vec3,
}

/// The frame of a hemicube on a shooter with unit normal `n`, turned about
/// `n` by an angle in `[0, π/2)` drawn from `seed` (a hash, the same on
/// every run): the faces of neighbouring hemicubes do not line up, so
/// their pixel grids alias differently and the errors average out rather
/// than band. A quarter turn is a symmetry of the cube, so that range is
/// every distinct orientation.
pub fn frame(n: Vec3, seed: u64) -> Frame {
    let n = n.normalize();
    let helper = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let u0 = helper.cross(n).normalize();
    let v0 = n.cross(u0);
    let angle = (splitmix64(seed) >> 11) as f64 / (1u64 << 53) as f64 * (PI / 2.0);
    let (s, c) = (angle.sin() as f32, angle.cos() as f32);
    let u = (u0 * c + v0 * s).normalize();
    Frame {
        u,
        v: n.cross(u),
        n,
    }
}

/// Steele, Lea and Flood's SplitMix64 finaliser: a seed to 64 well-mixed
/// bits.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_eb9c_e849_a4f3);
    z ^ (z >> 31)
}

/// No element in this pixel.
const EMPTY: u32 = u32::MAX;

/// A point in face camera space: `a` across, `b` up the face, `w` along
/// the face's view direction.
#[derive(Clone, Copy, Debug)]
struct Cam {
    a: f32,
    b: f32,
    w: f32,
}

/// The five faces: which local axis (with sign) is across, up and along
/// the view, and whether the face is a half-height side face.
const FACES: [([(usize, f32); 3], bool); 5] = [
    ([(0, 1.0), (1, 1.0), (2, 1.0)], false),
    ([(1, 1.0), (2, 1.0), (0, 1.0)], true),
    ([(1, 1.0), (2, 1.0), (0, -1.0)], true),
    ([(0, 1.0), (2, 1.0), (1, 1.0)], true),
    ([(0, 1.0), (2, 1.0), (1, -1.0)], true),
];

/// The scratch of one hemicube renderer: an item buffer and a depth
/// buffer big enough for the top face, and a per-element accumulator.
/// One per worker thread; reused from hemicube to hemicube.
#[derive(Debug, Default)]
pub struct Hemicube {
    /// Per pixel of the face being drawn: the nearest element, or `EMPTY`.
    ids: Vec<u32>,
    /// Per pixel: `1/w` of the nearest element (larger is nearer), 0 when
    /// empty.
    depth: Vec<f32>,
    /// Per mesh element: the form factor summed so far for the current
    /// hemicube.
    sum: Vec<f64>,
    /// The elements with a non-zero `sum`, in the order first seen.
    touched: Vec<u32>,
    /// Per mesh vertex: its position in the hemicube's frame (written
    /// for the vertices of drawn polygons only).
    local: Vec<[f32; 3]>,
}

impl Hemicube {
    /// An empty renderer; buffers grow on first use.
    pub fn new() -> Self {
        Hemicube::default()
    }

    /// Form factors from the point `eye` (on a shooter, oriented by
    /// `frame`) to every element of the polygons `roles` makes
    /// [`Role::Receiver`], with those it makes [`Role::Occluder`] hiding
    /// what lies behind them. `corners` holds each polygon's corners (the
    /// scene polygon: every element lies within its convex hull), used to
    /// skip a polygon wholly outside a face. Writes `(element, F)` pairs
    /// into `out` (cleared first), sorted by element, each `F > 0`; their
    /// sum is at most 1. `near` is the near clipping distance in scene
    /// units (see [`HEMICUBE_NEAR_FRACTION`]).
    ///
    /// `weight`, when given, multiplies each pixel's delta form factor by
    /// its value at the pixel centre's direction (in the hemicube's
    /// frame: `u`, `v`, `n` components, any length): a luminaire's shot
    /// ([`luminaire_weight`]) then counts each direction by its candela
    /// table instead of Lambert's cosine.
    #[allow(clippy::too_many_arguments)]
    pub fn form_factors(
        &mut self,
        deltas: &DeltaFormFactors,
        mesh: &Mesh,
        corners: &[Vec<Vec3>],
        roles: &[Role],
        eye: Vec3,
        frame: Frame,
        near: f32,
        weight: Option<&dyn Fn(DVec3) -> f64>,
        out: &mut Vec<(u32, f64)>,
    ) {
        let n = deltas.res as usize;
        self.ids.resize(n * n, EMPTY);
        self.depth.resize(n * n, 0.0);
        if self.sum.len() != mesh.elements.len() {
            self.sum = vec![0.0; mesh.elements.len()];
        }
        self.touched.clear();
        let local = |p: Vec3| {
            let d = p - eye;
            [d.dot(frame.u), d.dot(frame.v), d.dot(frame.n)]
        };
        self.local.resize(mesh.vertex_count(), [0.0; 3]);
        for (pm, role) in mesh.polygons.iter().zip(roles) {
            if *role != Role::Skip {
                let range = pm.vertices.start as usize..pm.vertices.end as usize;
                for (l, p) in self.local[range.clone()]
                    .iter_mut()
                    .zip(&mesh.positions[range])
                {
                    *l = local(*p);
                }
            }
        }
        let positions = &self.local;
        for &(axes, side) in &FACES {
            let rows = if side { n / 2 } else { n };
            let to_cam = |l: [f32; 3]| Cam {
                a: l[axes[0].0] * axes[0].1,
                b: l[axes[1].0] * axes[1].1,
                w: l[axes[2].0] * axes[2].1,
            };
            let pixels = n * rows;
            self.ids[..pixels].fill(EMPTY);
            self.depth[..pixels].fill(0.0);
            let mut face = Face {
                n,
                rows,
                side,
                near,
                ids: &mut self.ids[..pixels],
                depth: &mut self.depth[..pixels],
            };
            for (j, pm) in mesh.polygons.iter().enumerate() {
                if roles[j] == Role::Skip {
                    continue;
                }
                // Every element lies in the convex hull of the polygon's
                // corners: all of them outside one clip plane puts the
                // whole polygon out of this face.
                let outside = corners[j]
                    .iter()
                    .fold(u8::MAX, |acc, &c| acc & face.outcode(to_cam(local(c))));
                if outside != 0 {
                    continue;
                }
                for e in pm.elements.clone() {
                    let element = &mesh.elements[e as usize];
                    let mut cam = [Cam {
                        a: 0.0,
                        b: 0.0,
                        w: 0.0,
                    }; 4];
                    let mut outside = u8::MAX;
                    for (c, v) in cam.iter_mut().zip(element.corners()) {
                        *c = to_cam(positions[v.index()]);
                        outside &= face.outcode(*c);
                    }
                    if outside != 0 {
                        continue;
                    }
                    face.draw([cam[0], cam[1], cam[2]], e);
                    if element.corners().len() == 4 {
                        // The second triangle of `Element::triangles`.
                        face.draw([cam[0], cam[2], cam[3]], e);
                    }
                }
            }
            let table = if side { &deltas.side } else { &deltas.top };
            for (pixel, (&id, &df)) in self.ids[..pixels].iter().zip(table).enumerate() {
                if id == EMPTY || roles[mesh.element_polygon[id as usize].index()] != Role::Receiver
                {
                    continue;
                }
                let df = match weight {
                    Some(weight) => {
                        // The pixel centre on its face (`w = 1`), back to
                        // the frame's axes (each axis's sign is its own
                        // inverse).
                        let (c, r) = (pixel % n, pixel / n);
                        let a = -1.0 + 2.0 * (c as f64 + 0.5) / n as f64;
                        let b = if side {
                            2.0 * (r as f64 + 0.5) / n as f64
                        } else {
                            -1.0 + 2.0 * (r as f64 + 0.5) / n as f64
                        };
                        let mut local = DVec3::ZERO;
                        for (&(axis, sign), value) in axes.iter().zip([a, b, 1.0]) {
                            local[axis] = value * sign as f64;
                        }
                        df * weight(local)
                    }
                    None => df,
                };
                if df <= 0.0 {
                    continue;
                }
                let s = &mut self.sum[id as usize];
                if *s == 0.0 {
                    self.touched.push(id);
                }
                *s += df;
            }
        }
        self.touched.sort_unstable();
        out.clear();
        for &e in &self.touched {
            out.push((e, self.sum[e as usize]));
            self.sum[e as usize] = 0.0;
        }
    }
}

/// One face being drawn.
struct Face<'b> {
    /// Pixels across.
    n: usize,
    /// Pixel rows: `n` for the top face, `n/2` for a side face.
    rows: usize,
    /// A side face covers `b/w ∈ [0, 1]`; the top face `[-1, 1]`.
    side: bool,
    near: f32,
    ids: &'b mut [u32],
    depth: &'b mut [f32],
}

impl Face<'_> {
    /// Bit `k` set when `p` is outside clip plane `k`: near, the four
    /// sides of the face's pyramid.
    fn outcode(&self, p: Cam) -> u8 {
        let bottom = if self.side { 0.0 } else { -p.w };
        (p.w < self.near) as u8
            | ((p.a > p.w) as u8) << 1
            | ((p.a < -p.w) as u8) << 2
            | ((p.b > p.w) as u8) << 3
            | ((p.b < bottom) as u8) << 4
    }

    /// Signed distance of `p` inside clip plane `k` (>= 0 inside).
    fn plane(&self, k: usize, p: Cam) -> f32 {
        match k {
            0 => p.w - self.near,
            1 => p.w - p.a,
            2 => p.w + p.a,
            3 => p.w - p.b,
            _ => {
                if self.side {
                    p.b
                } else {
                    p.w + p.b
                }
            }
        }
    }

    /// Clips triangle `t` to the face's pyramid and draws what is left
    /// with item `id`.
    fn draw(&mut self, t: [Cam; 3], id: u32) {
        let codes = t.map(|p| self.outcode(p));
        if codes[0] & codes[1] & codes[2] != 0 {
            return;
        }
        // Sutherland–Hodgman against the planes some corner is outside;
        // a triangle clipped by five planes has at most eight corners.
        const MOST: usize = 8;
        let zero = Cam {
            a: 0.0,
            b: 0.0,
            w: 0.0,
        };
        let mut poly = [zero; MOST];
        poly[..3].copy_from_slice(&t);
        let mut len = 3;
        let any = codes[0] | codes[1] | codes[2];
        for k in 0..5 {
            if any & (1 << k) == 0 {
                continue;
            }
            let mut next = [zero; MOST];
            let mut next_len = 0;
            for i in 0..len {
                let (p, q) = (poly[i], poly[(i + 1) % len]);
                let (dp, dq) = (self.plane(k, p), self.plane(k, q));
                if dp >= 0.0 && next_len < MOST {
                    next[next_len] = p;
                    next_len += 1;
                }
                if (dp >= 0.0) != (dq >= 0.0) && next_len < MOST {
                    let s = dp / (dp - dq);
                    next[next_len] = Cam {
                        a: p.a + (q.a - p.a) * s,
                        b: p.b + (q.b - p.b) * s,
                        w: p.w + (q.w - p.w) * s,
                    };
                    next_len += 1;
                }
            }
            (poly, len) = (next, next_len);
            if len < 3 {
                return;
            }
        }
        // Project to pixel coordinates; `1/w` is affine on the screen.
        let half = self.n as f32 * 0.5;
        let b0 = if self.side { 0.0 } else { 1.0 };
        let near = self.near;
        let project = |p: Cam| {
            let inv = 1.0 / p.w.max(near);
            [(p.a * inv + 1.0) * half, (p.b * inv + b0) * half, inv]
        };
        let first = project(poly[0]);
        let mut previous = project(poly[1]);
        for &p in &poly[2..len] {
            let next = project(p);
            self.triangle(first, previous, next, id);
            previous = next;
        }
    }

    /// Draws a screen triangle (pixel coordinates and `1/w`) with item
    /// `id`, keeping per pixel the largest `1/w` (first drawn on ties).
    /// Pixel centres on an edge count as inside, so no pixel falls
    /// between two triangles that share the edge.
    fn triangle(&mut self, p0: [f32; 3], p1: [f32; 3], p2: [f32; 3], id: u32) {
        let area = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let inv_area = 1.0 / area;
        let slack = -HEMICUBE_EDGE_SLACK;
        let x_min = p0[0].min(p1[0]).min(p2[0]);
        let x_max = p0[0].max(p1[0]).max(p2[0]);
        let y_min = p0[1].min(p1[1]).min(p2[1]);
        let y_max = p0[1].max(p1[1]).max(p2[1]);
        // Pixel (c, r) has its centre at (c + 0.5, r + 0.5).
        let c0 = ((x_min - 0.5).ceil().max(0.0)) as usize;
        let c1 = ((x_max - 0.5).floor().min(self.n as f32 - 1.0)) as isize;
        let r0 = ((y_min - 0.5).ceil().max(0.0)) as usize;
        let r1 = ((y_max - 0.5).floor().min(self.rows as f32 - 1.0)) as isize;
        if c1 < c0 as isize || r1 < r0 as isize {
            return;
        }
        // Barycentric weights of the pixel centre, normalised by the
        // signed area so either winding works.
        let edge = |a: [f32; 3], b: [f32; 3], x: f32, y: f32| {
            ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) * inv_area
        };
        for r in r0..=r1 as usize {
            let y = r as f32 + 0.5;
            let row = r * self.n;
            for c in c0..=c1 as usize {
                let x = c as f32 + 0.5;
                let w0 = edge(p1, p2, x, y);
                let w1 = edge(p2, p0, x, y);
                let w2 = edge(p0, p1, x, y);
                if w0 < slack || w1 < slack || w2 < slack {
                    continue;
                }
                let z = w0 * p0[2] + w1 * p1[2] + w2 * p2[2];
                let at = row + c;
                if z > self.depth[at] {
                    self.depth[at] = z;
                    self.ids[at] = id;
                }
            }
        }
    }
}

/// Spreads the light elements received in a step to their vertices: per
/// vertex, the area-weighted mean of its elements' radiosity increase,
/// each element weighted by the share of its area its corners stand for
/// (`A_e / corners`, the weights of [`Mesh::vertex_areas`]), so that
/// `Σ_vertices vertex area × Δ = Σ_elements A_e ΔB_e`: the power received
/// is kept exactly under the per-vertex unshot scheme.
///
/// `received[e]` is what element `e` received as power, `ΔB_e · A_e`
/// (radiosity × area units); `vertex_area` is [`Mesh::vertex_areas`];
/// writes per vertex `Δ` into `delta`, only at the vertices of `polygon`.
pub fn spread_to_vertices(
    mesh: &Mesh,
    polygon: usize,
    received: &[crate::color::Rgb],
    vertex_area: &[f64],
    delta: &mut [crate::color::Rgb],
) {
    let pm = &mesh.polygons[polygon];
    for l in pm.vertices.clone() {
        delta[l as usize] = crate::color::Rgb::BLACK;
    }
    for e in pm.elements.clone() {
        let element = &mesh.elements[e as usize];
        let share = received[e as usize] / element.corners().len() as f64;
        for c in element.corners() {
            delta[c.index()] += share;
        }
    }
    for l in pm.vertices.clone() {
        let a = vertex_area[l as usize];
        delta[l as usize] = if a > 0.0 {
            delta[l as usize] / a
        } else {
            crate::color::Rgb::BLACK
        };
    }
}

/// The weight that turns a hemicube's Lambertian delta form factors into
/// a luminaire's share of flux per pixel: a pixel of delta `ΔF ≈ cosθ dω
/// / π` in the direction `d` (in `frame`'s axes) receives `I(d) dω / Φ`
/// of the luminaire's flux, so its weight is `π (I(d) / Φ) / cosθ`
/// ([`Directional::relative_intensity`]). With a cosine distribution
/// (`I / Φ = cosθ / π`) the weight is 1; the weighted deltas of a whole
/// hemicube sum to the table's flux below the plane over `Φ`, 1 to the
/// accuracy of one sample per pixel.
pub fn luminaire_weight(directional: &Directional, frame: Frame) -> impl Fn(DVec3) -> f64 + '_ {
    let (u, v, n) = (frame.u.as_dvec3(), frame.v.as_dvec3(), frame.n.as_dvec3());
    move |local: DVec3| {
        let len = local.length();
        if local.z <= 0.0 || len <= 0.0 {
            return 0.0;
        }
        let world = u * local.x + v * local.y + n * local.z;
        PI * directional.relative_intensity(world) * len / local.z
    }
}

/// What a hemicube step needs beyond the solver's own state: the delta
/// form factors, every polygon's corners, and scratch. Built once per
/// solve ([`HemicubeMethod::new`]).
#[derive(Debug)]
pub(crate) struct Shooting {
    deltas: DeltaFormFactors,
    /// Per polygon: its scene corners (see [`Hemicube::form_factors`]).
    corners: Vec<Vec<Vec3>>,
    /// Per mesh vertex: [`Mesh::vertex_areas`].
    vertex_area: Vec<f64>,
    /// Per polygon: a sky facet (never drawn: it is behind everything and
    /// reflects nothing).
    sky: Vec<bool>,
    /// Per polygon: has a back twin drawn in its place when it faces away.
    has_back: Vec<bool>,
    /// Per mesh element: scratch, the power it receives in the step.
    received: Vec<crate::color::Rgb>,
}

impl Shooting {
    /// The hemicube state for a solve of `scene` on `mesh` at `res`.
    pub(crate) fn new(scene: &crate::scene::Scene, mesh: &Mesh, res: HemicubeRes) -> Self {
        Shooting {
            deltas: DeltaFormFactors::new(res),
            corners: scene.polygons.iter().map(|p| p.vertices.clone()).collect(),
            vertex_area: mesh.vertex_areas(),
            sky: mesh.polygons.iter().map(|pm| pm.sky).collect(),
            has_back: mesh.polygons.iter().map(|pm| pm.has_back).collect(),
            received: vec![crate::color::Rgb::BLACK; mesh.elements.len()],
        }
    }

    /// Shoots polygon `shooter` by hemicubes: one at each of its
    /// `samples`, carrying `shot[k]` (its unshot radiosity read there)
    /// over the sample's area, scaled per channel so that the samples
    /// together carry exactly `power`, the power (radiosity × area) the
    /// step takes from the polygon's unshot radiosity: the field read at cell
    /// centres integrates a polygon's vertex field only to second order,
    /// and the difference would be light made or lost. Polygons marked in `receives` get
    /// `ΔB_e = ρ_j Σ_k shot_k F_k(e) A_k / A_e` per element, spread to
    /// their vertices in `delta` ([`spread_to_vertices`]). The hemicubes
    /// are rendered in parallel and summed in sample order, so the bits
    /// do not depend on the thread count. Returns the sample–element
    /// pairs with a non-zero form factor, or `None` (with only scratch
    /// written) once `cancel` is set. A shooter with a light distribution
    /// (`directional`, an `--ies` luminaire) weights each pixel by it
    /// ([`luminaire_weight`]).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn gather(
        &mut self,
        mesh: &Mesh,
        shooter: usize,
        directional: Option<&Directional>,
        samples: &[crate::solver::kernel::formfactor::ShooterSample],
        shot: &[crate::color::Rgb],
        power: crate::color::Rgb,
        receives: &[bool],
        reflectance: &[crate::color::Rgb],
        delta: &mut [crate::color::Rgb],
        cancel: &std::sync::atomic::AtomicBool,
    ) -> Option<u64> {
        use rayon::prelude::*;
        use std::sync::atomic::Ordering;
        let normal = mesh.polygons[shooter].normal;
        let (deltas, corners, sky, has_back) =
            (&self.deltas, &self.corners, &self.sky, &self.has_back);
        let per_sample: Vec<Vec<(u32, f64)>> = samples
            .par_iter()
            .enumerate()
            .map_init(
                || (Hemicube::new(), Vec::new()),
                |(cube, roles), (k, sample)| {
                    let mut out = Vec::new();
                    if cancel.load(Ordering::Relaxed) || shot[k].is_black() {
                        return out;
                    }
                    let eye = sample.position;
                    roles.clear();
                    roles.extend(mesh.polygons.iter().enumerate().map(|(j, pm)| {
                        let facing = corners[j]
                            .first()
                            .is_some_and(|&c| pm.normal.dot(eye - c) > 0.0);
                        if j == shooter || sky[j] || (has_back[j] && !facing) {
                            Role::Skip
                        } else if receives[j] && facing {
                            Role::Receiver
                        } else {
                            Role::Occluder
                        }
                    }));
                    let seed = ((shooter as u64) << 32) ^ k as u64;
                    let near = HEMICUBE_NEAR_FRACTION * (sample.area as f32).sqrt();
                    let frame = frame(normal, seed);
                    let weight = directional.map(|d| luminaire_weight(d, frame));
                    cube.form_factors(
                        deltas,
                        mesh,
                        corners,
                        roles,
                        eye,
                        frame,
                        near,
                        weight.as_ref().map(|w| w as &dyn Fn(DVec3) -> f64),
                        &mut out,
                    );
                    out
                },
            )
            .collect();
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        self.received.fill(crate::color::Rgb::BLACK);
        let carried = samples
            .iter()
            .zip(shot)
            .fold(crate::color::Rgb::BLACK, |sum, (sample, &unshot)| {
                sum + unshot * sample.area
            });
        let ratio = |p: f64, c: f64| if c > 0.0 { p / c } else { 0.0 };
        let scale = crate::color::Rgb::new(
            ratio(power.r, carried.r),
            ratio(power.g, carried.g),
            ratio(power.b, carried.b),
        );
        let mut pairs = 0u64;
        for ((sample, &unshot), list) in samples.iter().zip(shot).zip(&per_sample) {
            let power = scale * unshot * sample.area;
            pairs += list.len() as u64;
            for &(e, f) in list {
                self.received[e as usize] += power * f;
            }
        }
        for (j, pm) in mesh.polygons.iter().enumerate() {
            if !receives[j] {
                continue;
            }
            for e in pm.elements.clone() {
                self.received[e as usize] = reflectance[j] * self.received[e as usize];
            }
            spread_to_vertices(mesh, j, &self.received, &self.vertex_area, delta);
        }
        Some(pairs)
    }
}

#[cfg(test)]
mod tests;
