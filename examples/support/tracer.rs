//! Brute-force ray casting against a scene's polygons and the radiosity
//! lookup of a solution, with nothing of the solver's visibility code:
//! the independent side of the examples that check the solver
//! (`illuminance_reference`, `consistency`).

// Each example uses part of it.
#![allow(dead_code)]

use glam::DVec3;
use radiosity::color::Rgb;
use radiosity::mesh::Mesh;
use radiosity::scene::Scene;

/// A small, seedable generator (SplitMix64), so each run is the same.
pub struct Rng(pub u64);

impl Rng {
    /// The next value, uniform in `[0, 1)`.
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The scene's polygons for brute-force ray casting, and a solution for
/// the radiosity lookup.
pub struct Tracer<'a> {
    pub scene: &'a Scene,
    pub mesh: &'a Mesh,
    pub radiosity: &'a [Rgb],
    /// Hits nearer than this along a ray (in units of its direction's
    /// length) are ignored: the surface it leaves from.
    pub t_min: f64,
}

impl Tracer<'_> {
    /// The nearest polygon hit by the ray `o + t d` (`t > t_min`): its
    /// index and `t`. Of polygons hit at the same place (a two-sided
    /// face and its back copy) the one facing the ray's origin.
    pub fn hit(&self, o: DVec3, d: DVec3) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        let facing = |i: usize| self.scene.polygons[i].normal.as_dvec3().dot(d) < 0.0;
        for (i, p) in self.scene.polygons.iter().enumerate() {
            let n = p.normal.as_dvec3();
            let denom = n.dot(d);
            if denom.abs() < 1e-12 {
                continue;
            }
            let v0 = p.vertices[0].as_dvec3();
            let t = n.dot(v0 - o) / denom;
            if t <= self.t_min {
                continue;
            }
            if let Some((b, tb)) = best {
                let tie = (t - tb).abs() <= 1e-9 * tb.max(1.0);
                if t > tb && !tie || tie && (facing(b) || denom > 0.0) {
                    continue;
                }
            }
            let x = o + d * t;
            let k = p.vertices.len();
            let inside = (0..k).all(|j| {
                let a = p.vertices[j].as_dvec3();
                let b = p.vertices[(j + 1) % k].as_dvec3();
                n.dot((b - a).cross(x - a)) >= -1e-9
            });
            if inside {
                best = Some((i, t));
            }
        }
        best
    }

    /// True when something lies strictly between `a` and `b`.
    pub fn blocked(&self, a: DVec3, b: DVec3) -> bool {
        let d = b - a;
        self.hit(a, d).is_some_and(|(_, t)| t < 1.0 - 1e-6)
    }

    /// The radiosity at `x` on polygon `p`, interpolated over the
    /// element's triangles as the picture draws it.
    pub fn radiosity_at(&self, p: usize, x: DVec3) -> Rgb {
        let pm = &self.mesh.polygons[p];
        let n = pm.normal.as_dvec3();
        let mut nearest = (f64::INFINITY, Rgb::BLACK);
        for e in &self.mesh.elements[pm.elements.start as usize..pm.elements.end as usize] {
            for [a, b, c] in e.triangles() {
                let (pa, pb, pc) = (
                    self.mesh.positions[a.index()].as_dvec3(),
                    self.mesh.positions[b.index()].as_dvec3(),
                    self.mesh.positions[c.index()].as_dvec3(),
                );
                let area = n.dot((pb - pa).cross(pc - pa));
                if area <= 0.0 {
                    continue;
                }
                let wa = n.dot((pb - x).cross(pc - x)) / area;
                let wb = n.dot((pc - x).cross(pa - x)) / area;
                let wc = 1.0 - wa - wb;
                let outside = (-wa).max(-wb).max(-wc);
                let value = self.radiosity[a.index()] * wa.max(0.0)
                    + self.radiosity[b.index()] * wb.max(0.0)
                    + self.radiosity[c.index()] * wc.max(0.0);
                if outside <= 0.0 {
                    return value;
                }
                if outside < nearest.0 {
                    nearest = (outside, value);
                }
            }
        }
        nearest.1
    }

    /// A uniformly random point of polygon `p` (a fan of triangles from
    /// its first vertex, chosen by area), kept a millionth of the way in
    /// from its edges.
    pub fn point_on(&self, p: usize, rng: &mut Rng) -> DVec3 {
        let v: Vec<DVec3> = self.scene.polygons[p]
            .vertices
            .iter()
            .map(|v| v.as_dvec3())
            .collect();
        let areas: Vec<f64> = (1..v.len() - 1)
            .map(|k| (v[k] - v[0]).cross(v[k + 1] - v[0]).length())
            .collect();
        let mut pick = rng.next() * areas.iter().sum::<f64>();
        let mut k = 0;
        while k + 1 < areas.len() && pick > areas[k] {
            pick -= areas[k];
            k += 1;
        }
        let (mut s, mut t) = (rng.next(), rng.next());
        if s + t > 1.0 {
            (s, t) = (1.0 - s, 1.0 - t);
        }
        let (s, t) = (s.clamp(1e-6, 1.0), t.clamp(1e-6, 1.0));
        let w0 = (1.0 - s - t).max(1e-6);
        (v[0] * w0 + v[k + 1] * s + v[k + 2] * t) / (w0 + s + t)
    }
}
