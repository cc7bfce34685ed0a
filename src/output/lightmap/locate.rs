//! The solved light at a point of the user's model: which scene polygon
//! the point lies on (a short ray through the visibility structure), and
//! the radiosity the picture draws there (the element vertices'
//! radiosity interpolated across the element triangle holding the point,
//! as the rasteriser's Gouraud shading does).

use crate::color::Rgb;
use crate::mesh::Mesh;
use crate::scene::{PolygonId, Scene};
use crate::visibility::Visibility;
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

/// How far in front of the model's surface a probe ray starts, as a
/// fraction of the scene's bounding-box diagonal: well above the padding
/// of the visibility structure's boxes
/// ([`crate::visibility::BOX_PADDING`] of the extent), within which a ray
/// may miss a polygon it starts on; a surface nearer than this in front
/// (a rug on a floor) is stepped past (see [`Locator::sample`]).
pub const PROBE_OFFSET: f32 = 1e-3;

/// How far from the model's point a probe may find its polygon, as a
/// fraction of the scene's bounding-box diagonal: a point of the model
/// lies on a scene polygon (the importer made the polygons from the same
/// triangles, rounded to `f32`), so a hit farther off is another surface.
pub const PROBE_TOLERANCE: f32 = 1e-4;

/// Surfaces in front of a point, nearer than [`PROBE_OFFSET`], that a
/// probe steps past before it gives up on the point.
pub const PROBE_STEPS: usize = 3;

/// Barycentric slack for a point on an element triangle's edge, which
/// rounding may put a hair outside.
const EDGE_SLACK: f32 = 1e-4;

/// The light the solution gives at one point of a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// The scene polygon the point lies on.
    pub polygon: PolygonId,
    /// The radiosity the picture draws there (scene radiosity units).
    pub shown: Rgb,
    /// The solved radiosity there (scene radiosity units).
    pub radiosity: Rgb,
}

/// Finds the solved light at points of the model's surface. Built once;
/// each polygon's element lookup grid is built the first time a point
/// lands on it.
pub struct Locator<'a> {
    scene: &'a Scene,
    mesh: &'a Mesh,
    visibility: &'a Visibility,
    shown: &'a [Rgb],
    radiosity: &'a [Rgb],
    /// Probe start distance in scene units.
    offset: f32,
    /// How far from its point a probe may hit, in scene units.
    tolerance: f32,
    grids: Vec<OnceLock<Grid>>,
}

impl<'a> Locator<'a> {
    /// A locator over the solved `mesh` of `scene` (`shown` and
    /// `radiosity` one value per mesh vertex).
    pub fn new(
        scene: &'a Scene,
        mesh: &'a Mesh,
        visibility: &'a Visibility,
        shown: &'a [Rgb],
        radiosity: &'a [Rgb],
    ) -> Self {
        // The model's size, not the sky's: the sky's facets enclose the
        // scene far off, and would make the probes start centimetres out.
        let model = scene.polygons.iter().filter(|p| !p.surface.sky);
        let (lo, hi) = model.flat_map(|p| &p.vertices).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &v| (lo.min(v), hi.max(v)),
        );
        let diagonal = (hi - lo).length();
        let diagonal = if diagonal.is_finite() && diagonal > 0.0 {
            diagonal
        } else {
            1.0
        };
        Locator {
            scene,
            mesh,
            visibility,
            shown,
            radiosity,
            offset: diagonal * PROBE_OFFSET,
            tolerance: diagonal * PROBE_TOLERANCE,
            grids: (0..mesh.polygons.len()).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The light at `point` (scene units) of a surface whose front faces
    /// along the unit `normal`; `None` when no polygon of the scene lies
    /// there (within [`PROBE_TOLERANCE`]).
    ///
    /// The probe is a ray from [`PROBE_OFFSET`] in front of the point
    /// back along the normal; a surface it meets before the point (nearer
    /// than the tolerance) is stepped past, [`PROBE_STEPS`] times at most,
    /// by starting again just behind it.
    pub fn sample(&self, point: Vec3, normal: Vec3) -> Option<Sample> {
        let (polygon, on) = self.polygon_at(point, normal)?;
        let (shown, radiosity) = self.interpolate(polygon, on)?;
        Some(Sample {
            polygon,
            shown,
            radiosity,
        })
    }

    /// Whether the solver lit the side of the surface at `point` that
    /// faces along the unit `normal`: a scene polygon lies there (as
    /// [`Locator::sample`] finds it) with its front that way. False where
    /// no polygon lies, and on the back of a one-sided face.
    pub fn lit_side(&self, point: Vec3, normal: Vec3) -> bool {
        self.polygon_at(point, normal)
            .is_some_and(|(p, _)| self.scene.polygons[p.index()].normal.dot(normal) > 0.0)
    }

    /// The polygon [`Locator::sample`] reads at `point` for a surface
    /// facing along `normal`, and the point where its probe met it.
    fn polygon_at(&self, point: Vec3, normal: Vec3) -> Option<(PolygonId, Vec3)> {
        let mut origin = point + normal * self.offset;
        let mut ahead = self.offset;
        let mut found = None;
        for _ in 0..=PROBE_STEPS {
            let (hit, t) = self.visibility.first_hit(origin, -normal)?;
            if (t - ahead).abs() <= self.tolerance {
                found = Some((hit, origin - normal * t));
                break;
            }
            // Something in front, or past the point: a probe that starts
            // behind the surface it is to find would miss it.
            let step = t + self.tolerance / 2.0;
            if t > ahead || ahead - step < self.tolerance * 2.0 {
                return None;
            }
            origin -= normal * step;
            ahead -= step;
        }
        let (hit, on) = found?;
        // The two sides of a two-sided face are two coplanar polygons:
        // take the one facing the model's front.
        Some((self.facing(hit, normal), on))
    }

    /// `hit`, or its back side when that faces along `normal` and `hit`
    /// does not.
    fn facing(&self, hit: PolygonId, normal: Vec3) -> PolygonId {
        let p = &self.scene.polygons[hit.index()];
        if p.normal.dot(normal) >= 0.0 {
            return hit;
        }
        match p.surface.back.or(p.surface.back_of) {
            Some(b) if self.scene.polygons[b.index()].normal.dot(normal) > 0.0 => b,
            _ => hit,
        }
    }

    /// The shown and solved radiosity at `point` on `polygon`,
    /// interpolated over the element triangle holding it (the nearest one
    /// when rounding puts the point just outside them all).
    fn interpolate(&self, polygon: PolygonId, point: Vec3) -> Option<(Rgb, Rgb)> {
        let pm = self.mesh.polygons.get(polygon.index())?;
        let grid = self.grids[polygon.index()].get_or_init(|| Grid::new(self.mesh, polygon));
        let (tri, w) = grid.find(grid.project(point))?;
        let mix = |values: &[Rgb]| {
            tri.iter().zip(w).fold(Rgb::BLACK, |acc, (v, w)| {
                acc + values[*v as usize] * f64::from(w)
            })
        };
        debug_assert!(pm.vertices.contains(&tri[0]));
        Some((mix(self.shown), mix(self.radiosity)))
    }
}

/// Cells per side of a polygon's lookup grid at most.
const MAX_GRID_SIDE: usize = 64;

/// One polygon's element triangles in its plane, bucketed in a uniform
/// grid for point lookup.
struct Grid {
    /// Plane basis: the first vertex and two unit directions in the plane.
    origin: Vec3,
    axes: (Vec3, Vec3),
    /// Each element triangle: its mesh vertex ids and 2D corners.
    triangles: Vec<([u32; 3], [Vec2; 3])>,
    lo: Vec2,
    cell: Vec2,
    side: usize,
    /// Triangles overlapping each cell's box, row by row.
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(mesh: &Mesh, polygon: PolygonId) -> Grid {
        let pm = &mesh.polygons[polygon.index()];
        let normal = pm.normal;
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let origin = mesh
            .positions
            .get(pm.vertices.start as usize)
            .copied()
            .unwrap_or(Vec3::ZERO);
        let flat = |p: Vec3| Vec2::new((p - origin).dot(u), (p - origin).dot(v));
        let triangles: Vec<([u32; 3], [Vec2; 3])> = mesh.elements
            [pm.elements.start as usize..pm.elements.end as usize]
            .iter()
            .flat_map(|e| e.triangles().collect::<Vec<_>>())
            .map(|t| {
                let ids = t.map(|v| v.0);
                (ids, ids.map(|i| flat(mesh.positions[i as usize])))
            })
            .collect();
        let (lo, hi) = triangles.iter().flat_map(|(_, c)| c).fold(
            (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
            |(lo, hi), &c| (lo.min(c), hi.max(c)),
        );
        let side = ((triangles.len() as f64).sqrt().ceil() as usize).clamp(1, MAX_GRID_SIDE);
        let cell = ((hi - lo) / side as f32).max(Vec2::splat(f32::MIN_POSITIVE));
        let mut cells = vec![Vec::new(); side * side];
        let index = |p: Vec2| {
            let c = ((p - lo) / cell).floor();
            (
                (c.x.max(0.0) as usize).min(side - 1),
                (c.y.max(0.0) as usize).min(side - 1),
            )
        };
        for (k, (_, c)) in triangles.iter().enumerate() {
            let a = index(c[0].min(c[1]).min(c[2]));
            let b = index(c[0].max(c[1]).max(c[2]));
            for y in a.1..=b.1 {
                for x in a.0..=b.0 {
                    cells[y * side + x].push(k as u32);
                }
            }
        }
        Grid {
            origin,
            axes: (u, v),
            triangles,
            lo,
            cell,
            side,
            cells,
        }
    }

    fn project(&self, p: Vec3) -> Vec2 {
        let d = p - self.origin;
        Vec2::new(d.dot(self.axes.0), d.dot(self.axes.1))
    }

    /// The element triangle holding `p` and `p`'s barycentric weights in
    /// it (clamped to the triangle, summing to one); the triangle nearest
    /// to holding it when none does.
    fn find(&self, p: Vec2) -> Option<([u32; 3], [f32; 3])> {
        let c = ((p - self.lo) / self.cell).floor();
        let inside_grid =
            c.x >= 0.0 && c.y >= 0.0 && c.x < self.side as f32 && c.y < self.side as f32;
        let best_of = |candidates: &mut dyn Iterator<Item = usize>| {
            let mut best: Option<(usize, [f32; 3], f32)> = None;
            for k in candidates {
                let Some(w) = barycentric(p, &self.triangles[k].1) else {
                    continue;
                };
                let worst = w[0].min(w[1]).min(w[2]);
                if best.is_none_or(|b| worst > b.2) {
                    best = Some((k, w, worst));
                }
            }
            best
        };
        let mut best = None;
        if inside_grid {
            let cell = &self.cells[c.y as usize * self.side + c.x as usize];
            best = best_of(&mut cell.iter().map(|&k| k as usize));
        }
        if best.is_none_or(|b| b.2 < -EDGE_SLACK) {
            best = best_of(&mut (0..self.triangles.len()));
        }
        let (k, w, _) = best?;
        let clamped = w.map(|x| x.max(0.0));
        let sum: f32 = clamped.iter().sum();
        if sum <= 0.0 {
            return None;
        }
        Some((self.triangles[k].0, clamped.map(|x| x / sum)))
    }
}

/// Barycentric weights of `p` in triangle `t` (negative outside); `None`
/// for a triangle of no area.
pub fn barycentric(p: Vec2, t: &[Vec2; 3]) -> Option<[f32; 3]> {
    let (a, b, c) = (t[0], t[1], t[2]);
    let area = (b - a).perp_dot(c - a);
    if area == 0.0 || !area.is_finite() {
        return None;
    }
    let wa = (b - p).perp_dot(c - p) / area;
    let wb = (c - p).perp_dot(a - p) / area;
    Some([wa, wb, 1.0 - wa - wb])
}
