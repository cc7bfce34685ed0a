//! The whole sky gathered at once: every receiving vertex asks its own
//! hemisphere of directions which reach the sky, in one step.
//!
//! Shot facet by facet, a sky of 80 facets takes 80 steps, and each
//! visits every vertex that faces the facet: on a real export those steps
//! were most of the solve (on `tests/models/godot/room.glb`, 21 s of
//! 33 s, 610 rays a vertex). Yet what a vertex receives from a sky that
//! reflects nothing is a plain integral over its hemisphere,
//! `Δrad = ρ · (1/π) ∫ Δb_sky(ω) · V(x, ω) · cos θ dω`, which a
//! cosine-weighted set of `N` directions estimates as
//! `ρ · (1/N) Σ_k Δb_sky(ω_k) · V(x, ω_k)`: each open direction brings
//! the unshot radiosity of the facet it reaches, times `1/N`. An
//! unoccluded plane under a uniform sky `S` gets exactly `S`, as from
//! the facets, and whatever the enclosure's shape.
//!
//! **The directions** ([`Hemisphere`]): the unit square cut into
//! `(C·K)²` equal strata, `C²` cells of `K²`, mapped onto the disc by
//! Shirley and Chiu's concentric map and lifted onto the hemisphere
//! (Malley's method: area on the disc is cosine-weighted solid angle, so
//! every stratum carries the same weight `1/N`). The direction asked in
//! each stratum is jittered within it by a hash of the stratum's index,
//! the same for every vertex: a window's edge then lets directions in one
//! at a time rather than in rows (a regular pattern's banding), and
//! neighbouring vertices share the pattern, so the penumbra is smooth
//! (jittered per vertex, the skylight test's floor was 9 % rough).
//!
//! **Probes**, as the facets had them ([`super::probes`]): a vertex first
//! asks one direction per cell. A cell whose probe and every probe of the
//! cells touching it see the sky takes that answer for all its
//! directions; one whose probes two rings deep are all blocked takes
//! that (an opening poking into a cell past its nearest probes), and so
//! does one whose own ring is blocked and whose four corner strata are
//! too; the others, along a shadow's edge, ask every direction. A cell near the
//! horizon ([`SKY_GRAZING_Z`](crate::solver::tuning::SKY_GRAZING_Z)) spans
//! some 24° of elevation, across which a window's head or sill or a
//! parapet runs: its probe is the column of strata from the horizon up
//! and the row along the horizon (five of nine), and it settles only
//! when they agree. Off with
//! [`crate::solver::Approximations::sky_probes`].
//!
//! **The sky's light by direction** ([`Dome`]): a uniform sky's facets
//! all hold the same unshot radiosity, and an open direction brings it.
//! Otherwise (a daylight sky, or one some facets of which have shot) a
//! direction brings the facet its ray reaches: where it meets the sphere
//! inscribed in the facets, looked up in a cube map of the facets' cones
//! from the centre.
//!
//! The brute-force twin is shooting facet by facet
//! ([`crate::solver::Approximations::sky_at_once`] off);
//! `src/solver/tests/sky.rs` checks both against the closed forms.

use crate::color::Rgb;
use crate::mesh::Mesh;
use glam::Vec3;

/// The hemisphere's strata and cells, in the receiver's frame (`z` along
/// its normal).
#[derive(Clone, Debug)]
pub struct Hemisphere {
    /// Cells per side of the unit square, `1..=32`.
    cells: usize,
    /// Strata per side of a cell, `>= 1`.
    per_cell: usize,
    /// Per cell, the cells within one ring of it (itself left out).
    ring1: Vec<Vec<u16>>,
    /// Per cell, the cells within two rings of it (itself left out).
    ring2: Vec<Vec<u16>>,
    /// Per cell, the strata its probe asks (indices within the cell, the
    /// middle one first): the middle alone, or for a cell near the
    /// horizon ([`SKY_GRAZING_Z`](crate::solver::tuning::SKY_GRAZING_Z))
    /// the column through the middle from the horizon up and the row
    /// along the horizon ([`horizon_probe`]).
    probes: Vec<Vec<u16>>,
    /// The corner strata of a cell (indices within it, no repeats): a
    /// dark cell whose own ring of probes is dark but whose next ring is
    /// not asks these next, and settles dark when they all are.
    corners: Vec<u16>,
    /// Per stratum (cell by cell, `per_cell²` each), the direction of its
    /// centre, unit, `z >= 0`: where a settled cell's directions reach
    /// the sky.
    centres: Vec<Vec3>,
    /// Per stratum, the direction asked: jittered within the stratum by a
    /// hash of its index, the same for every vertex.
    asked: Vec<Vec3>,
}

/// The most cells per side of [`Hemisphere`]: a vertex keeps one bit per
/// cell.
const MAX_CELLS: usize = 32;

/// A cell's probe: the stratum nearest its middle, as an index within
/// the cell.
fn probe_of(per_cell: usize) -> usize {
    let m = per_cell / 2;
    m * per_cell + m
}

/// The strata of a cell near the horizon that its probe asks: the middle
/// one, then the rest of the column through it along the radius of the
/// concentric map (`u` when the cell's middle `(a, b)` has `|a| >= |b|`,
/// else `v`), which runs from the horizon up, and the rest of the row
/// nearest the horizon, which spans the most elevation (13.6° of the
/// cell's 23.6° at 24 cells of 3 × 3).
fn horizon_probe(per_cell: usize, (a, b): (f32, f32)) -> Vec<u16> {
    let m = per_cell / 2;
    let along_u = a.abs() >= b.abs();
    let outer = if (if along_u { a } else { b }) > 0.0 {
        per_cell - 1
    } else {
        0
    };
    // Stratum `along` radially, `across` round the horizon.
    let at = |along: usize, across: usize| {
        (if along_u {
            across * per_cell + along
        } else {
            along * per_cell + across
        }) as u16
    };
    let mut strata = vec![probe_of(per_cell) as u16];
    for i in (0..per_cell).filter(|&i| i != m) {
        strata.push(at(i, m));
    }
    for i in (0..per_cell).filter(|&i| i != m) {
        strata.push(at(outer, i));
    }
    strata
}

/// Shirley and Chiu's concentric map of `(a, b)` in `[-1, 1]²` onto the
/// unit disc, lifted onto the upper hemisphere: area-preserving up to a
/// constant, so uniform points of the square become cosine-weighted
/// directions.
fn concentric(a: f32, b: f32) -> Vec3 {
    use std::f32::consts::FRAC_PI_4;
    let (r, phi) = if a == 0.0 && b == 0.0 {
        (0.0, 0.0)
    } else if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a / b))
    };
    let (x, y) = (r * phi.cos(), r * phi.sin());
    Vec3::new(x, y, (1.0 - x * x - y * y).max(0.0).sqrt())
}

/// Two uniform numbers in `[0, 1)` from a hash of `stratum` (SplitMix64's
/// finaliser).
fn jitter(stratum: u32) -> (f32, f32) {
    let mut z = (u64::from(stratum) + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let unit = |bits: u64| (bits & 0xFF_FFFF) as f32 / (1u32 << 24) as f32;
    (unit(z), unit(z >> 32))
}

impl Hemisphere {
    /// `cells²` cells of `per_cell²` strata each (`cells` clamped to
    /// `1..=32`, `per_cell` to at least 1).
    pub fn new(cells: usize, per_cell: usize) -> Hemisphere {
        let cells = cells.clamp(1, MAX_CELLS);
        let per_cell = per_cell.max(1);
        let ring = |c: usize, r: i64| -> Vec<u16> {
            let (cx, cy) = ((c % cells) as i64, (c / cells) as i64);
            let mut out = Vec::new();
            for dy in -r..=r {
                for dx in -r..=r {
                    let (x, y) = (cx + dx, cy + dy);
                    if (dx, dy) != (0, 0)
                        && (0..cells as i64).contains(&x)
                        && (0..cells as i64).contains(&y)
                    {
                        out.push((y * cells as i64 + x) as u16);
                    }
                }
            }
            out
        };
        let n = cells * cells;
        let mut h = Hemisphere {
            cells,
            per_cell,
            ring1: (0..n).map(|c| ring(c, 1)).collect(),
            ring2: (0..n).map(|c| ring(c, 2)).collect(),
            probes: Vec::with_capacity(n),
            corners: {
                let p = per_cell as u16;
                let mut corners = vec![0, p - 1, p * (p - 1), p * p - 1];
                corners.dedup();
                corners
            },
            centres: Vec::with_capacity(n * per_cell * per_cell),
            asked: Vec::with_capacity(n * per_cell * per_cell),
        };
        for c in 0..n {
            let mut lowest = 1.0f32;
            for s in 0..per_cell * per_cell {
                let (a, b) = h.square(c, s, (0.5, 0.5));
                h.centres.push(concentric(a, b));
                lowest = lowest.min(concentric(a, b).z);
                let stratum = (c * per_cell * per_cell + s) as u32;
                let (a, b) = h.square(c, s, jitter(stratum));
                h.asked.push(concentric(a, b));
            }
            let grazing = lowest < crate::solver::tuning::SKY_GRAZING_Z;
            h.probes.push(if grazing {
                horizon_probe(per_cell, h.cell_middle(c))
            } else {
                vec![probe_of(per_cell) as u16]
            });
        }
        h
    }

    /// Directions in all, `N`.
    pub fn directions(&self) -> usize {
        self.centres.len()
    }

    /// The point of the square `[-1, 1]²` at offset `(ju, jv)` (each in
    /// `[0, 1)`) within stratum `s` of cell `c`.
    fn square(&self, c: usize, s: usize, (ju, jv): (f32, f32)) -> (f32, f32) {
        let n = (self.cells * self.per_cell) as f32;
        let u = (c % self.cells) * self.per_cell + s % self.per_cell;
        let v = (c / self.cells) * self.per_cell + s / self.per_cell;
        (
            2.0 * (u as f32 + ju) / n - 1.0,
            2.0 * (v as f32 + jv) / n - 1.0,
        )
    }

    /// The middle of cell `c` on the square `[-1, 1]²`.
    fn cell_middle(&self, c: usize) -> (f32, f32) {
        let n = self.cells as f32;
        let (u, v) = ((c % self.cells) as f32 + 0.5, (c / self.cells) as f32 + 0.5);
        (2.0 * u / n - 1.0, 2.0 * v / n - 1.0)
    }

    /// The direction asked for stratum `s` of cell `c`, in the receiver's
    /// frame.
    #[inline]
    fn jittered(&self, c: usize, s: usize) -> Vec3 {
        self.asked[c * self.per_cell * self.per_cell + s]
    }

    /// What a vertex at `x` (scene units) with unit normal `n` receives from the sky before its reflectance: `(1/N) Σ_k
    /// light(ω_k)` over its open directions (in the scene's emission
    /// units), and the rays it cast. `blocked(end)` says whether the
    /// segment from `x` to `end` is blocked; `probing` lets a cell's probes
    /// answer for it (module docs).
    pub fn gather(
        &self,
        dome: &Dome,
        light: &SkyLight,
        x: Vec3,
        n: Vec3,
        probing: bool,
        mut blocked: impl FnMut(Vec3) -> bool,
    ) -> (Rgb, u64) {
        let (t, b) = n.any_orthonormal_pair();
        let world = |d: Vec3| t * d.x + b * d.y + n * d.z;
        let mut rays = 0u64;
        let mut open = |d: Vec3| -> (bool, Vec3) {
            let end = dome.end(x, world(d));
            rays += 1;
            (!blocked(end), end)
        };
        let cells = self.cells * self.cells;
        let k = self.per_cell * self.per_cell;
        let probe = probe_of(self.per_cell);
        let mut sum = Rgb::BLACK;
        if !probing {
            for c in 0..cells {
                for s in 0..k {
                    let (seen, end) = open(self.jittered(c, s));
                    if seen {
                        sum += light.at(dome, || end);
                    }
                }
            }
            return (sum * (1.0 / self.directions() as f64), rays);
        }
        // Each stratum asked so far, and whether it was open: two bits.
        let words = (cells * k).div_ceil(64);
        let mut asked = vec![0u64; words];
        let mut opened = vec![0u64; words];
        let bit = |bits: &[u64], i: usize| bits[i / 64] >> (i % 64) & 1 == 1;
        let mut ask = |c: usize, s: usize| -> bool {
            let i = c * k + s;
            if !bit(&asked, i) {
                asked[i / 64] |= 1 << (i % 64);
                if open(self.jittered(c, s)).0 {
                    opened[i / 64] |= 1 << (i % 64);
                }
            }
            bit(&opened, i)
        };
        // The probes: a cell is open when its middle stratum is, and
        // agrees with itself when its whole probe does.
        let mut seen = [0u64; MAX_CELLS * MAX_CELLS / 64];
        let mut uniform = [0u64; MAX_CELLS * MAX_CELLS / 64];
        for c in 0..cells {
            let here = ask(c, probe);
            let agree = self.probes[c][1..]
                .iter()
                .all(|&s| ask(c, usize::from(s)) == here);
            seen[c / 64] |= u64::from(here) << (c % 64);
            uniform[c / 64] |= u64::from(agree) << (c % 64);
        }
        let is_open = |c: usize| seen[c / 64] >> (c % 64) & 1 == 1;
        for c in 0..cells {
            let here = is_open(c);
            // A dark cell whose own ring is dark but the next ring is not
            // asks its corners before every stratum: an opening poking
            // into it from two cells away reaches a corner. One next to
            // an open cell asks every stratum, as the edge may cross it
            // anywhere.
            let dark = |ring: &[u16]| ring.iter().all(|&o| !is_open(usize::from(o)));
            let settled = uniform[c / 64] >> (c % 64) & 1 == 1
                && if here {
                    self.ring1[c].iter().all(|&o| is_open(usize::from(o)))
                } else {
                    dark(&self.ring2[c])
                        || dark(&self.ring1[c])
                            && self.corners.iter().all(|&s| !ask(c, usize::from(s)))
                };
            if settled {
                if here {
                    sum += light.cell(self, dome, x, world, c);
                }
                continue;
            }
            for s in 0..k {
                if ask(c, s) {
                    sum += light.at(dome, || dome.end(x, world(self.jittered(c, s))));
                }
            }
        }
        (sum * (1.0 / self.directions() as f64), rays)
    }
}

/// The sky's geometry: its centre and the sphere inscribed in its facets,
/// and which facet each direction from the centre meets.
#[derive(Clone, Debug)]
pub struct Dome {
    /// The facets' centre, scene units.
    centre: Vec3,
    /// A radius just inside every facet's plane, scene units: rays end on
    /// this sphere, short of the sky.
    reach: f32,
    /// The sky facets' polygon indices.
    facets: Vec<usize>,
    /// Per cube-map texel ([`CUBE_SIZE`]² a face, six faces), the index
    /// into `facets` of the facet whose cone from the centre holds the
    /// texel's direction.
    cube: Vec<u16>,
}

/// Texels per side of a face of [`Dome`]'s cube map: at 64, a texel is
/// under 1.5° across, against about 25° for a facet of 80.
const CUBE_SIZE: usize = 64;

/// The cube-map texel of direction `d` (not zero).
fn texel(d: Vec3) -> usize {
    let a = d.abs();
    let (face, u, v, m) = if a.x >= a.y && a.x >= a.z {
        (usize::from(d.x < 0.0), d.y, d.z, a.x)
    } else if a.y >= a.z {
        (2 + usize::from(d.y < 0.0), d.z, d.x, a.y)
    } else {
        (4 + usize::from(d.z < 0.0), d.x, d.y, a.z)
    };
    let cell = |w: f32| ((((w / m) + 1.0) * 0.5 * CUBE_SIZE as f32) as usize).min(CUBE_SIZE - 1);
    (face * CUBE_SIZE + cell(v)) * CUBE_SIZE + cell(u)
}

/// The direction through the middle of texel `i`.
fn texel_direction(i: usize) -> Vec3 {
    let face = i / (CUBE_SIZE * CUBE_SIZE);
    let (row, col) = ((i / CUBE_SIZE) % CUBE_SIZE, i % CUBE_SIZE);
    let w = |k: usize| (k as f32 + 0.5) / CUBE_SIZE as f32 * 2.0 - 1.0;
    let (u, v) = (w(col), w(row));
    let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    match face / 2 {
        0 => Vec3::new(s, u, v),
        1 => Vec3::new(v, s, u),
        _ => Vec3::new(u, v, s),
    }
    .normalize()
}

impl Dome {
    /// The sky of `mesh` (its polygons marked [`crate::mesh::PolygonMesh::sky`]),
    /// `None` when it has none or its facets are too many to index
    /// (more than 65,535) or enclose no room.
    pub fn new(mesh: &Mesh) -> Option<Dome> {
        let facets: Vec<usize> = (0..mesh.polygons.len())
            .filter(|&j| mesh.polygons[j].sky && mesh.polygons[j].vertex_count() > 0)
            .collect();
        if facets.is_empty() || facets.len() > usize::from(u16::MAX) {
            return None;
        }
        let corners = |j: usize| {
            let pm = &mesh.polygons[j];
            &mesh.positions[pm.vertices.start as usize..pm.vertices.end as usize]
        };
        let (sum, count) = facets
            .iter()
            .flat_map(|&j| corners(j))
            .fold((glam::DVec3::ZERO, 0usize), |(s, n), p| {
                (s + p.as_dvec3(), n + 1)
            });
        let centre = (sum / count as f64).as_vec3();
        // The nearest facet plane: the corners of an element are the
        // facet's own (a sky facet is meshed as one element).
        let reach = facets
            .iter()
            .map(|&j| {
                let normal = mesh.polygons[j].normal.normalize_or_zero();
                normal.dot(corners(j)[0] - centre).abs()
            })
            .fold(f32::INFINITY, f32::min)
            * 0.999;
        if !(reach.is_finite() && reach > 0.0) {
            return None;
        }
        // Each facet's cone from the centre, as its edges' planes.
        let middles: Vec<Vec3> = facets
            .iter()
            .map(|&j| {
                let c = corners(j);
                (c.iter().copied().sum::<Vec3>() / c.len() as f32 - centre).normalize_or_zero()
            })
            .collect();
        // Each edge's plane through the centre, facing the facet's middle
        // (a plane pair alone bounds the cone and its mirror image).
        let cones: Vec<Vec<Vec3>> = facets
            .iter()
            .zip(&middles)
            .map(|(&j, &m)| {
                let c = corners(j);
                (0..c.len())
                    .map(|k| {
                        let p = (c[k] - centre).cross(c[(k + 1) % c.len()] - centre);
                        if p.dot(m) < 0.0 {
                            -p
                        } else {
                            p
                        }
                    })
                    .collect()
            })
            .collect();
        let cube = (0..6 * CUBE_SIZE * CUBE_SIZE)
            .map(|i| {
                let d = texel_direction(i);
                let inside = |planes: &Vec<Vec3>| planes.iter().all(|p| p.dot(d) >= 0.0);
                cones.iter().position(inside).unwrap_or_else(|| {
                    // Rounding at a seam: the facet whose middle is nearest.
                    middles
                        .iter()
                        .enumerate()
                        .fold((0, f32::NEG_INFINITY), |best, (k, m)| {
                            let c = m.dot(d);
                            if c > best.1 {
                                (k, c)
                            } else {
                                best
                            }
                        })
                        .0
                }) as u16
            })
            .collect();
        Some(Dome {
            centre,
            reach,
            facets,
            cube,
        })
    }

    /// The sky facets' polygon indices.
    pub fn facets(&self) -> &[usize] {
        &self.facets
    }

    /// Where the ray from `x` (inside the sphere the rays end on) along
    /// the unit `d` ends: on that sphere, short of every facet.
    pub fn end(&self, x: Vec3, d: Vec3) -> Vec3 {
        let o = x - self.centre;
        let od = o.dot(d);
        let c = o.length_squared() - self.reach * self.reach;
        let t = -od + (od * od - c).max(0.0).sqrt();
        x + d * t.max(0.0)
    }

    /// The index into [`Dome::facets`] of the facet a ray ending at `end`
    /// (a point of [`Dome::end`]) reaches.
    pub fn facet_at(&self, end: Vec3) -> usize {
        let d = end - self.centre;
        if d == Vec3::ZERO || !d.is_finite() {
            return 0;
        }
        usize::from(self.cube[texel(d)])
    }
}

/// The unshot radiosity the sky sends, by direction: one value when
/// every facet holds the same, else per facet.
#[derive(Clone, Debug)]
pub enum SkyLight {
    /// Every facet holds this.
    Uniform(Rgb),
    /// Per facet of [`Dome::facets`], in its order.
    PerFacet(Vec<Rgb>),
}

impl SkyLight {
    /// What `dome`'s facets hold now, by `unshot(j)` of facet polygon `j`
    /// (negative parts count as nothing: a sky facet receives no light to
    /// owe).
    pub fn of(dome: &Dome, unshot: impl Fn(usize) -> Rgb) -> SkyLight {
        let values: Vec<Rgb> = dome
            .facets
            .iter()
            .map(|&j| unshot(j).max(Rgb::BLACK))
            .collect();
        match values.first() {
            Some(&first) if values.iter().all(|&v| v == first) => SkyLight::Uniform(first),
            _ => SkyLight::PerFacet(values),
        }
    }

    /// Whether no facet holds any light.
    pub fn is_black(&self) -> bool {
        match self {
            SkyLight::Uniform(v) => v.is_black(),
            SkyLight::PerFacet(v) => v.iter().all(|c| c.is_black()),
        }
    }

    /// What an open direction brings; `end()` gives where its ray ends,
    /// asked only when the facets differ (a uniform sky's direction
    /// brings the same wherever it ends).
    #[inline]
    fn at(&self, dome: &Dome, end: impl FnOnce() -> Vec3) -> Rgb {
        match self {
            SkyLight::Uniform(v) => *v,
            SkyLight::PerFacet(v) => v[dome.facet_at(end())],
        }
    }

    /// What every direction of cell `c` brings, all open, summed: by the
    /// strata's centres (`world` takes them to the scene's frame).
    fn cell(
        &self,
        h: &Hemisphere,
        dome: &Dome,
        x: Vec3,
        world: impl Fn(Vec3) -> Vec3,
        c: usize,
    ) -> Rgb {
        let k = h.per_cell * h.per_cell;
        match self {
            SkyLight::Uniform(v) => *v * k as f64,
            SkyLight::PerFacet(v) => h.centres[c * k..(c + 1) * k]
                .iter()
                .fold(Rgb::BLACK, |acc, &d| {
                    acc + v[dome.facet_at(dome.end(x, world(d)))]
                }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The floor under a plate with a uniform sky: its mesh and dome.
    fn plate_under_a_sky() -> (Mesh, Dome) {
        let mut scene = crate::testutil::floor_under_a_plate();
        scene.add_sky(Rgb::splat(1.0)).unwrap();
        let mesh = crate::testutil::regular_mesh(&scene, 10.0);
        let dome = Dome::new(&mesh).unwrap();
        (mesh, dome)
    }

    #[test]
    fn the_directions_are_cosine_weighted() {
        // Over the hemisphere, E[cos θ] = 2/3 and E[cos² θ] = 1/2 for the
        // density cos θ / π.
        let h = Hemisphere::new(12, 3);
        assert_eq!(h.directions(), 36 * 36);
        let n = h.directions() as f64;
        let mean_cos: f64 = h.centres.iter().map(|d| f64::from(d.z)).sum::<f64>() / n;
        let mean_cos2: f64 = h
            .centres
            .iter()
            .map(|d| f64::from(d.z).powi(2))
            .sum::<f64>()
            / n;
        // The strata's centres, by the midpoint rule: off a little at the rim.
        assert!((mean_cos - 2.0 / 3.0).abs() < 5e-3, "{mean_cos}");
        assert!((mean_cos2 - 0.5).abs() < 5e-3, "{mean_cos2}");
        // Jittered, the set is a stratified estimate, unbiased over jitters.
        let (mut sum, mut sum2, mut count) = (0.0, 0.0, 0.0);
        for c in 0..144 {
            for s in 0..9 {
                let z = f64::from(h.jittered(c, s).z);
                sum += z;
                sum2 += z * z;
                count += 1.0;
            }
        }
        assert!((sum / count - 2.0 / 3.0).abs() < 2e-3, "{}", sum / count);
        assert!((sum2 / count - 0.5).abs() < 2e-3, "{}", sum2 / count);
        for d in &h.centres {
            assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0);
        }
        // The jittered directions stay in their stratum's patch.
        for c in 0..144 {
            for s in 0..9 {
                let (a, b) = h.square(c, s, jitter((c * 9 + s) as u32));
                let (a0, b0) = h.square(c, s, (0.0, 0.0));
                let (a1, b1) = h.square(c, s, (1.0, 1.0));
                assert!(a >= a0 && a <= a1 && b >= b0 && b <= b1);
            }
        }
    }

    #[test]
    fn the_rings_hold_the_touching_cells() {
        let h = Hemisphere::new(4, 1);
        // A corner cell touches three, two rings deep eight.
        assert_eq!(h.ring1[0], vec![1, 4, 5]);
        assert_eq!(h.ring2[0], vec![1, 2, 4, 5, 6, 8, 9, 10]);
        // A middle cell touches eight.
        assert_eq!(h.ring1[5].len(), 8);
    }

    #[test]
    fn every_texel_finds_the_facet_its_direction_crosses() {
        let (mesh, dome) = plate_under_a_sky();
        assert_eq!(dome.facets().len(), 80);
        // A ray from the centre along a facet's middle direction meets
        // that facet.
        for (k, &j) in dome.facets().iter().enumerate() {
            let pm = &mesh.polygons[j];
            let c = &mesh.positions[pm.vertices.start as usize..pm.vertices.end as usize];
            let middle = c.iter().copied().sum::<Vec3>() / c.len() as f32;
            let end = dome.end(dome.centre, (middle - dome.centre).normalize());
            assert_eq!(dome.facet_at(end), k);
            assert!((end - dome.centre).length() < (middle - dome.centre).length());
        }
        // Every facet owns texels, in proportion to its solid angle
        // (the 80 facets differ by at most about a third).
        // A texel's solid angle is 1/(1 + u² + v²)^{3/2} of a middle
        // one's, `u` and `v` its face coordinates.
        let mut owned = vec![0f64; 80];
        for (i, &f) in dome.cube.iter().enumerate() {
            let d = texel_direction(i);
            let m = d.abs().max_element();
            owned[usize::from(f)] += f64::from(m).powi(3);
        }
        let mean = owned.iter().sum::<f64>() / 80.0;
        assert!(
            owned.iter().all(|&o| o > 0.7 * mean && o < 1.3 * mean),
            "{owned:?}"
        );
    }

    #[test]
    fn an_open_plane_under_a_uniform_sky_receives_it_all() {
        let (_, dome) = plate_under_a_sky();
        let h = Hemisphere::new(12, 3);
        let light = SkyLight::of(&dome, |_| Rgb::splat(2.0));
        assert!(matches!(light, SkyLight::Uniform(_)));
        // A probe a cell, five strata for the cells near the horizon:
        // the outer ring.
        let grazing = h.probes.iter().filter(|p| p.len() == 5).count() as u64;
        assert_eq!(grazing, 4 * 12 - 4);
        for probing in [true, false] {
            let (e, rays) = h.gather(&dome, &light, Vec3::ZERO, Vec3::Y, probing, |_| false);
            assert!((e.r - 2.0).abs() < 1e-9, "{e:?}");
            assert_eq!(rays, if probing { 144 + 4 * grazing } else { 1296 });
        }
        // Per facet, the same light gives the same answer.
        let per = SkyLight::PerFacet(vec![Rgb::splat(2.0); 80]);
        let (e, _) = h.gather(&dome, &per, Vec3::ZERO, Vec3::Y, true, |_| false);
        assert!((e.r - 2.0).abs() < 1e-9);
    }

    /// A parapet all round up to 10° of elevation hides `sin² 10°` of
    /// the cosine-weighted hemisphere. A cell near the horizon spans
    /// its lowest 23.6°, so one probe at its middle sees over the
    /// parapet, and so do its neighbours': the horizon cells' probes find
    /// the edge.
    #[test]
    fn a_parapet_at_the_horizon_is_found_by_the_horizon_cells_probes() {
        let (_, dome) = plate_under_a_sky();
        let h = Hemisphere::new(24, 3);
        let light = SkyLight::Uniform(Rgb::splat(1.0));
        let sin_e = 10f64.to_radians().sin();
        let exact = 1.0 - sin_e * sin_e;
        let parapet = |end: Vec3| f64::from(end.normalize().y) < sin_e;
        let (all, _) = h.gather(&dome, &light, Vec3::ZERO, Vec3::Y, false, parapet);
        let (probed, rays) = h.gather(&dome, &light, Vec3::ZERO, Vec3::Y, true, parapet);
        assert!((all.r - exact).abs() < 0.002, "{} against {exact}", all.r);
        assert!(
            (probed.r - all.r).abs() < 0.003,
            "{} against {}",
            probed.r,
            all.r
        );
        // Every cell probed, the outer ring's five strata each.
        assert!(rays >= 576 + 4 * 92, "{rays}");
    }

    /// A skylight: the sky seen through a round opening of half-angle
    /// `radius` about `axis` (unit), everything else blocked.
    fn skylight(axis: Vec3, radius_deg: f32) -> impl Fn(Vec3) -> bool {
        let cos = radius_deg.to_radians().cos();
        move |end: Vec3| end.normalize().dot(axis) < cos
    }

    /// Openings of 3° to 20° radius, overhead and tilted towards the
    /// horizon: the probes, the rings and the dark cells' corners find
    /// each as asking every direction does (to the last digit when
    /// written), with under a third of its rays. Corners asked by every
    /// dark cell next to an opening, not only by those a ring further
    /// out, lost 0.6 % of the 10° and 20° openings overhead and 25 % of
    /// the 3° one at 75°.
    #[test]
    fn small_openings_are_found_by_probes_rings_and_corners() {
        let (_, dome) = plate_under_a_sky();
        let h = Hemisphere::new(24, 3);
        let light = SkyLight::Uniform(Rgb::splat(1.0));
        for tilt in [0.0f32, 30.0, 60.0, 75.0] {
            let t = tilt.to_radians();
            let axis = Vec3::new(t.sin() * 0.6, t.cos(), t.sin() * 0.8).normalize();
            for radius in [3.0f32, 6.0, 10.0, 20.0] {
                let open = skylight(axis, radius);
                let (all, all_rays) = h.gather(&dome, &light, Vec3::ZERO, Vec3::Y, false, &open);
                let (probed, rays) = h.gather(&dome, &light, Vec3::ZERO, Vec3::Y, true, &open);
                assert!(
                    (probed.r - all.r).abs() <= 1e-3 * all.r,
                    "{tilt}° {radius}°: {} against {}",
                    probed.r,
                    all.r
                );
                assert!(
                    3 * rays <= all_rays,
                    "{tilt}° {radius}°: {rays} of {all_rays}"
                );
            }
        }
    }

    #[test]
    fn a_half_blocked_hemisphere_receives_half_and_probes_agree_with_every_direction() {
        let (_, dome) = plate_under_a_sky();
        let h = Hemisphere::new(24, 3);
        let light = SkyLight::Uniform(Rgb::splat(1.0));
        // Everything with x > 0 blocked: half the cosine-weighted
        // hemisphere about +y.
        let half = |end: Vec3| end.x > 0.0;
        let (all, all_rays) = h.gather(&dome, &light, Vec3::ZERO, Vec3::Y, false, half);
        let (probed, probed_rays) = h.gather(&dome, &light, Vec3::ZERO, Vec3::Y, true, half);
        assert!((all.r - 0.5).abs() < 0.01, "{all:?}");
        assert!((probed.r - all.r).abs() < 1e-12, "{probed:?} {all:?}");
        assert!(probed_rays < all_rays / 2, "{probed_rays} {all_rays}");
    }
}
