//! The lightmap's texels filled from the solution.
//!
//! Every texel bilinear filtering may read for a point of a triangle of
//! the model (its centre within [`REACH`] of the triangle in UV space) is
//! given a point of that triangle: its centre's when the centre lies
//! inside (a point of the surface), else the triangle's point nearest to
//! the centre. Bilinear filtering anywhere inside a chart thus reads only
//! texels that hold the light of points of that chart, at most a texel's
//! diagonal from where it samples. The light at each point is the solution's there
//! ([`super::locate`]): a function of the 3D point alone, so the two sides
//! of a seam between charts hold the light of the same edge.
//!
//! Texels no triangle covers are then filled from their filled neighbours,
//! [`DILATE_PASSES`] rings deep (into the padding between charts, so that
//! mipmaps and texture compression do not darken chart edges); the rest
//! stay black.

use super::locate::{barycentric, Locator};
use crate::cancel::{Cancel, Cancelled};
use crate::color::Rgb;
use crate::render::Frame;
use crate::scene::import::gltf::source::SourceModel;
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Rings of empty texels around the charts filled from their neighbours.
pub const DILATE_PASSES: u32 = 4;

/// How far from a triangle in UV space, in texels, a texel centre may be
/// and still be given a point of it: a texel's width diagonally, so that
/// every texel bilinear filtering reads for a point of the triangle (the
/// four whose centres are less than a texel away along each axis) holds a
/// point of the triangle's chart. Charts are `2 × PADDING` texels apart,
/// more than twice this, so no texel is within reach of two charts.
pub const REACH: f32 = std::f32::consts::SQRT_2;

/// How far a point clamped to a triangle's edge is moved towards its
/// centroid, as a fraction of the way.
const EDGE_NUDGE: f32 = 1e-3;

/// The filled lightmap.
#[derive(Clone, Debug)]
pub struct Texture {
    /// The radiosity the picture draws, per texel (scene radiosity units),
    /// row 0 at the top (glTF's `v = 0`).
    pub shown: Frame,
    /// The irradiance, per texel: the light arriving, `(radiosity −
    /// emission) / reflectance` of the polygon the texel's point lies on
    /// (scene radiosity units; 0 where the surface reflects nothing).
    pub irradiance: Frame,
    /// Per texel, the triangle whose point it holds: `1 + ` the index of
    /// the triangle among all the model's triangles, primitive after
    /// primitive; 0 for a texel that holds no point (dilated or empty).
    pub owner: Vec<u32>,
    /// Texels holding a point of the model whose point no scene polygon
    /// lies on (filled by dilation instead).
    pub unmatched: usize,
}

/// What one texel holds before it is evaluated.
#[derive(Clone, Copy)]
struct Assigned {
    /// Global triangle index + 1 (0: none).
    owner: u32,
    /// The point and the triangle's front normal.
    point: Vec3,
    normal: Vec3,
    /// Distance in texels from the texel centre to the triangle (0 inside).
    distance: f32,
}

/// Fills a `width × height` lightmap of `model` (whose primitives all have
/// `uv1`) from the solution `locator` reads. `scene` gives the polygons'
/// emission and reflectance for the irradiance. Stops within a texel's
/// work per thread once `cancel` is set ([`Cancelled`]).
pub fn fill(
    model: &SourceModel,
    width: u32,
    height: u32,
    locator: &Locator<'_>,
    scene: &Scene,
    cancel: &Cancel,
) -> Result<Texture, Cancelled> {
    let (w, h) = (width as usize, height as usize);
    let mut assigned: Vec<Option<Assigned>> = vec![None; w * h];
    let size = Vec2::new(width as f32, height as f32);
    let mut owner = 0u32;
    for p in &model.primitives {
        let Some(uv1) = &p.uv1 else {
            owner += (p.indices.len() / 3) as u32;
            continue;
        };
        for t in p.indices.chunks_exact(3) {
            owner += 1;
            let ids = [t[0], t[1], t[2]].map(|i| i as usize);
            let pos = ids.map(|i| Vec3::from_array(p.positions[i]));
            let uv = ids.map(|i| Vec2::from_array(uv1[i]) * size);
            let normal = (pos[1] - pos[0]).cross(pos[2] - pos[0]).normalize_or_zero();
            if normal == Vec3::ZERO || barycentric(uv[0], &uv).is_none() {
                continue;
            }
            let lo = uv[0].min(uv[1]).min(uv[2]) - Vec2::splat(1.0);
            let hi = uv[0].max(uv[1]).max(uv[2]) + Vec2::splat(1.0);
            let x0 = lo.x.floor().max(0.0) as usize;
            let y0 = lo.y.floor().max(0.0) as usize;
            let x1 = (hi.x.ceil().max(0.0) as usize).min(w);
            let y1 = (hi.y.ceil().max(0.0) as usize).min(h);
            for y in y0..y1 {
                for x in x0..x1 {
                    let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let (weights, distance) = nearest_on_triangle(centre, &uv);
                    if distance > REACH {
                        continue;
                    }
                    let slot = &mut assigned[y * w + x];
                    // A centre inside wins over an edge's overlap; among
                    // overlaps, the nearest; ties keep the first.
                    if slot.is_some_and(|s| s.distance <= distance) {
                        continue;
                    }
                    // A point clamped to an edge is moved a hair inside,
                    // so its probe meets this triangle's polygon, not the
                    // neighbour's across a crease.
                    let weights = if distance > 0.0 {
                        weights.map(|x| x * (1.0 - EDGE_NUDGE) + EDGE_NUDGE / 3.0)
                    } else {
                        weights
                    };
                    let point = pos[0] * weights[0] + pos[1] * weights[1] + pos[2] * weights[2];
                    *slot = Some(Assigned {
                        owner,
                        point,
                        normal,
                        distance,
                    });
                }
            }
        }
    }
    let reflectance: Vec<(Rgb, Rgb)> = scene
        .polygons
        .iter()
        .map(|p| {
            let m = &scene.materials[p.material.index()];
            (m.reflectance(), m.emission())
        })
        .collect();
    let values: Vec<Option<([f32; 3], [f32; 3])>> = assigned
        .par_iter()
        .map(|a| {
            let a = (*a)?;
            if cancel.is_set() {
                return None;
            }
            let s = locator.sample(a.point, a.normal)?;
            let (rho, emission) = reflectance[s.polygon.index()];
            let arriving = s.radiosity - emission;
            let channel = |b: f64, r: f64| if r > 0.0 { (b / r).max(0.0) } else { 0.0 };
            let irradiance = Rgb::new(
                channel(arriving.r, rho.r),
                channel(arriving.g, rho.g),
                channel(arriving.b, rho.b),
            );
            Some((s.shown.to_f32(), irradiance.to_f32()))
        })
        .collect();
    cancel.check()?;
    let unmatched = assigned
        .iter()
        .zip(&values)
        .filter(|(a, v)| a.is_some() && v.is_none())
        .count();
    let owner: Vec<u32> = assigned
        .iter()
        .zip(&values)
        .map(|(a, v)| match (a, v) {
            (Some(a), Some(_)) => a.owner,
            _ => 0,
        })
        .collect();
    let mut shown: Vec<Option<[f32; 3]>> = values.iter().map(|v| v.map(|v| v.0)).collect();
    let mut irradiance: Vec<Option<[f32; 3]>> = values.iter().map(|v| v.map(|v| v.1)).collect();
    for _ in 0..DILATE_PASSES {
        dilate(&mut shown, w, h);
        dilate(&mut irradiance, w, h);
    }
    let frame = |values: Vec<Option<[f32; 3]>>| {
        let mut f = Frame::new(width, height);
        for (k, v) in values.into_iter().enumerate() {
            if let Some(v) = v {
                f.pixels[k] = v;
                f.covered[k] = true;
            }
        }
        f
    };
    Ok(Texture {
        shown: frame(shown),
        irradiance: frame(irradiance),
        owner,
        unmatched,
    })
}

/// One ring of dilation: every empty texel with filled neighbours (of the
/// eight around it) takes their mean.
fn dilate(texels: &mut [Option<[f32; 3]>], w: usize, h: usize) {
    let before = texels.to_vec();
    texels.par_iter_mut().enumerate().for_each(|(k, t)| {
        if t.is_some() {
            return;
        }
        let (x, y) = ((k % w) as i64, (k / w) as i64);
        let mut sum = [0.0f32; 3];
        let mut n = 0.0f32;
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (nx, ny) = (x + dx, y + dy);
                if (dx, dy) == (0, 0) || nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                if let Some(v) = before[ny as usize * w + nx as usize] {
                    for c in 0..3 {
                        sum[c] += v[c];
                    }
                    n += 1.0;
                }
            }
        }
        if n > 0.0 {
            *t = Some(sum.map(|s| s / n));
        }
    });
}

/// The barycentric weights of the point of triangle `t` nearest to `p`
/// and its distance from `p` (0 when `p` is inside).
pub fn nearest_on_triangle(p: Vec2, t: &[Vec2; 3]) -> ([f32; 3], f32) {
    let Some(w) = barycentric(p, t) else {
        return ([1.0, 0.0, 0.0], f32::INFINITY);
    };
    if w.iter().all(|&x| x >= 0.0) {
        return (w, 0.0);
    }
    let mut best = ([1.0, 0.0, 0.0], f32::INFINITY);
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let ab = b - a;
        let s = ((p - a).dot(ab) / ab.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
        let q = a + ab * s;
        let d = (p - q).length();
        if d < best.1 {
            let mut w = [0.0; 3];
            w[k] = 1.0 - s;
            w[(k + 1) % 3] = s;
            best = (w, d);
        }
    }
    best
}
