//! Splitting polygons along the lines where other polygons pass through
//! them, before meshing (Baum, Mann, Smith and Winget 1991, "Making
//! radiosity usable").
//!
//! A wall modelled as a box whose foot passes through the floor, or a
//! wall's single polygon continuing below the floor plane, has element
//! vertices in its buried part. They see nothing of the room and come out
//! dark, and Gouraud shading spreads that darkness into the visible part
//! above the floor: a dark band along the intersection. Cut along the
//! floor first, the wall becomes a visible piece and a buried piece, each
//! meshed on its own; the visible piece's vertices on the cut are evaluated
//! a little inside it (the mesher's inset), and no element straddles the
//! intersection.
//!
//! **Which intersections cut.** Polygon `P` is cut by the plane of a
//! polygon `Q` (not parallel to `P`) only where `P` has vertices on both
//! sides of that plane (farther than the tolerance), so that the cut
//! crosses `P`'s interior, and where `Q` meets `P` there:
//!
//! - **Through-cut**: the segments where `Q` and the polygons coplanar
//!   with it meet `P` together run across `P` from boundary to boundary
//!   (the floor meeting a sunk wall, however many tiles it is made of).
//!   `P` is cut along the whole line — unless `Q` is the side of a solid
//!   resting on `P` face to face (another polygon lies in `P`'s plane,
//!   facing the other way, and reaches the line: a block on a seat, flush
//!   with its edge). That is a contact, which is left alone as below.
//! - **Partial cut, interpenetrating**: the segment ends inside `P`, and
//!   `Q` itself has vertices on both sides of `P`'s plane: the two pass
//!   through each other, as the faces of a box sunk into the floor pass
//!   through it. The buried footprint must become pieces of its own, so
//!   `P` is cut along the line — but only the pieces (of the cuts made so
//!   far) that the segment itself touches. A box's four sides thus cut
//!   the floor into the footprint and four pieces around it, not into a
//!   grid across the whole floor, and a floor with many sunk legs grows
//!   by a few pieces per leg.
//! - **Partial cut, touching**: the segment ends inside `P`, and `Q` lies
//!   on one side of `P`'s plane, ending on it — a box standing on a table,
//!   a wall standing on a larger floor. Nothing is cut: the geometry does
//!   not pass through itself, and the scenes people build are made of
//!   such contacts.
//!
//! Polygons that merely touch along an edge (a wall standing on the floor
//! at its edge, two faces of a box) have no vertices on one side of the
//! other's plane and are never cut. A partition standing on a floor and
//! spanning it from wall to wall is the same geometry as a floor ending at
//! a sunk wall, and is cut like it: the light on the floor is
//! discontinuous there too.
//!
//! Cuts are made in the order of the cutting polygons in the scene, each
//! piece keeps the original's vertex order (so its front), material,
//! origin and [`Surface`], and the pieces of a polygon take its place in
//! [`Scene::polygons`] (so the order stays deterministic) and in every
//! [`Group`](crate::scene::Group) it belongs to. A piece that [`Polygon::new`]
//! would refuse (a sliver below its tolerances) is not made: its polygon
//! stays whole across that cut.
//!
//! The pass runs before `Scene::with_sides` adds the back copies of
//! two-sided polygons, so a back copy is a copy of a piece; a scene that
//! already has back copies is left as it is.
//!
//! **Cost.** Candidate pairs come from a BVH over the polygons' bounding
//! boxes (`obvhs`), and each polygon's cuts are found and made on its own,
//! in parallel: 118,300 polygons (a floor of tiles with a box on each,
//! half of them sunk) take under half a CPU-second, building the scene
//! included (the test `a_hundred_thousand_polygons_split_as_counted`).

use crate::budget::{fmt_count, least_run_bytes, MemoryBudget, OverBudget};
use crate::cancel::{Cancel, Cancelled};
use crate::scene::{Polygon, PolygonId, Scene};
use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::Bvh2;
use obvhs::BvhBuildParams;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Distance, as a fraction of the scene's extent (its bounding-box
/// diagonal), within which a vertex counts as lying on a plane, and within
/// which two segments on a cut line count as meeting or covering each
/// other.
///
/// Below the boundary inset of the default mesh (`DEFAULT_INSET` ×
/// `DEFAULT_LENMAX_FRACTION` ≈ 6e-4 of the extent): a polygon sunk less
/// deep than this is not cut, and its boundary vertices' evaluation points
/// are moved out of the buried sliver by the inset anyway. Far above the
/// `f32` rounding of coordinates (about 1e-7 of their magnitude), so
/// polygons that touch along an edge written with the same numbers never
/// count as crossing.
pub const SPLIT_TOLERANCE: f64 = 1e-4;

/// Two planes whose unit normals' cross product is shorter than this (the
/// sine of the angle between them) are parallel: they have no cut line.
pub const PARALLEL_SINE: f64 = 1e-4;

/// What [`Scene::split_intersections`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SplitStats {
    /// Polygons that were cut.
    pub polygons_cut: usize,
    /// The pieces those polygons became (so the scene grew by
    /// `pieces - polygons_cut` polygons).
    pub pieces: usize,
}

impl SplitStats {
    /// True when nothing was cut.
    pub fn is_empty(&self) -> bool {
        self.polygons_cut == 0
    }
}

/// A plane `n · x = d`, `n` a unit vector, in `f64`.
#[derive(Clone, Copy, Debug)]
struct Plane {
    n: DVec3,
    d: f64,
}

impl Plane {
    /// The plane of a polygon: its stored normal, through its vertices'
    /// mean (so a polygon a little off planar is split about its middle).
    fn of(vertices: &[DVec3], normal: DVec3) -> Plane {
        let centroid = vertices.iter().sum::<DVec3>() / vertices.len() as f64;
        Plane {
            n: normal,
            d: normal.dot(centroid),
        }
    }

    fn distance(&self, x: DVec3) -> f64 {
        self.n.dot(x) - self.d
    }

    /// The same plane with its normal's largest component positive, so
    /// that coplanar polygons facing either way give the same plane.
    fn canonical(self) -> Plane {
        let a = self.n.abs();
        let k = if a.x >= a.y && a.x >= a.z {
            self.n.x
        } else if a.y >= a.z {
            self.n.y
        } else {
            self.n.z
        };
        if k < 0.0 {
            Plane {
                n: -self.n,
                d: -self.d,
            }
        } else {
            self
        }
    }
}

/// Lowest and highest signed distance of `vertices` from `plane`.
fn side_range(vertices: &[DVec3], plane: &Plane) -> (f64, f64) {
    vertices
        .iter()
        .map(|&v| plane.distance(v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        })
}

/// True when `vertices` lie farther than `eps` on both sides of `plane`.
fn straddles(vertices: &[DVec3], plane: &Plane, eps: f64) -> bool {
    let (lo, hi) = side_range(vertices, plane);
    lo < -eps && hi > eps
}

/// Where the boundary of the convex polygon `vertices` meets `plane`, as
/// the interval of `dir · x` over those points (`dir` along the cut line):
/// the vertices within `eps` of the plane and the crossings of the edges
/// whose ends lie farther than `eps` on opposite sides. `None` when it does
/// not meet the plane.
fn chord(vertices: &[DVec3], plane: &Plane, dir: DVec3, eps: f64) -> Option<(f64, f64)> {
    let s: Vec<f64> = vertices.iter().map(|&v| plane.distance(v)).collect();
    let mut range: Option<(f64, f64)> = None;
    let mut add = |x: DVec3| {
        let t = dir.dot(x);
        range = Some(match range {
            None => (t, t),
            Some((lo, hi)) => (lo.min(t), hi.max(t)),
        });
    };
    let n = vertices.len();
    for i in 0..n {
        let j = (i + 1) % n;
        if s[i].abs() <= eps {
            add(vertices[i]);
        }
        if (s[i] > eps && s[j] < -eps) || (s[i] < -eps && s[j] > eps) {
            add(vertices[i] + (vertices[j] - vertices[i]) * (s[i] / (s[i] - s[j])));
        }
    }
    range
}

/// The convex polygon `vertices` cut by `plane` into its part in front
/// (distances `>= -eps`) and its part behind (`<= eps`), each in the
/// original cyclic order; vertices within `eps` of the plane go to both.
fn cut(vertices: &[DVec3], plane: &Plane, eps: f64) -> (Vec<DVec3>, Vec<DVec3>) {
    let s: Vec<f64> = vertices.iter().map(|&v| plane.distance(v)).collect();
    let (mut front, mut back) = (Vec::new(), Vec::new());
    let n = vertices.len();
    for i in 0..n {
        let j = (i + 1) % n;
        if s[i] >= -eps {
            front.push(vertices[i]);
        }
        if s[i] <= eps {
            back.push(vertices[i]);
        }
        if (s[i] > eps && s[j] < -eps) || (s[i] < -eps && s[j] > eps) {
            let x = vertices[i] + (vertices[j] - vertices[i]) * (s[i] / (s[i] - s[j]));
            front.push(x);
            back.push(x);
        }
    }
    (front, back)
}

/// One cut to make in a polygon: the plane, the direction of the cut line
/// in it, and the intervals of that line (in `dir · x`) along which pieces
/// are cut.
struct Cut {
    plane: Plane,
    dir: DVec3,
    intervals: Vec<(f64, f64)>,
}

/// What one other polygon contributes to the cuts of a polygon.
struct Meeting {
    /// The other polygon's plane, canonical.
    plane: Plane,
    /// Where the two meet, in `dir · x` along the cut line.
    interval: (f64, f64),
    /// The other polygon has vertices on both sides of this one's plane.
    through: bool,
}

/// Sorted intervals merged where they overlap or lie within `eps`.
fn merge(mut intervals: Vec<(f64, f64)>, eps: f64) -> Vec<(f64, f64)> {
    intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(intervals.len());
    for (lo, hi) in intervals {
        match out.last_mut() {
            Some(last) if lo <= last.1 + eps => last.1 = last.1.max(hi),
            _ => out.push((lo, hi)),
        }
    }
    out
}

/// The cut line's direction for polygon normal `n` and cutting plane `q`.
fn line_direction(n: DVec3, q: &Plane) -> DVec3 {
    n.cross(q.n).normalize()
}

/// The cuts polygon `p` gets from the polygons `others` (indices into
/// `planes` and `vertices`, ascending), in the order they are made.
fn cuts_of(
    p: usize,
    others: &[usize],
    vertices: &[Vec<DVec3>],
    planes: &[Plane],
    eps: f64,
) -> Vec<Cut> {
    let pv = &vertices[p];
    let pp = planes[p];
    let mut meetings: Vec<Meeting> = Vec::new();
    for &q in others {
        let qp = planes[q];
        if pp.n.cross(qp.n).length() < PARALLEL_SINE || !straddles(pv, &qp, eps) {
            continue;
        }
        let (lo, hi) = side_range(&vertices[q], &pp);
        if lo > eps || hi < -eps {
            continue;
        }
        let plane = qp.canonical();
        let dir = line_direction(pp.n, &plane);
        let (Some(a), Some(b)) = (
            chord(pv, &plane, dir, eps),
            chord(&vertices[q], &pp, dir, eps),
        ) else {
            continue;
        };
        let interval = (a.0.max(b.0), a.1.min(b.1));
        if interval.1 - interval.0 <= eps {
            continue;
        }
        meetings.push(Meeting {
            plane,
            interval,
            through: lo < -eps && hi > eps,
        });
    }

    // Group the meetings by plane (a floor of many tiles is one plane):
    // sorted by offset, a meeting joins a group within `eps` of it with
    // the same normal; then the groups go in the order of their first
    // polygon.
    let mut order: Vec<usize> = (0..meetings.len()).collect();
    order.sort_by(|&a, &b| meetings[a].plane.d.total_cmp(&meetings[b].plane.d));
    // (plane, meetings, first meeting index), ascending in offset.
    let mut groups: Vec<(Plane, Vec<&Meeting>, usize)> = Vec::new();
    for k in order {
        let m = &meetings[k];
        let same = groups
            .iter_mut()
            .rev()
            .take_while(|(g, _, _)| g.d >= m.plane.d - eps)
            .find(|(g, _, _)| g.n.cross(m.plane.n).length() < PARALLEL_SINE);
        match same {
            Some((_, list, first)) => {
                list.push(m);
                *first = (*first).min(k);
            }
            None => groups.push((m.plane, vec![m], k)),
        }
    }
    groups.sort_by_key(|g| g.2);

    let mut cuts = Vec::with_capacity(groups.len());
    for (plane, list, _) in groups {
        let dir = line_direction(pp.n, &plane);
        let Some((a0, a1)) = chord(pv, &plane, dir, eps) else {
            continue;
        };
        let all = merge(list.iter().map(|m| m.interval).collect(), eps);
        let across = all.len() == 1
            && all[0].0 <= a0 + eps
            && all[0].1 >= a1 - eps
            && (list.iter().any(|m| m.through)
                || !face_contact(pv, &pp, others, vertices, planes, &plane, dir, eps));
        let intervals = if across {
            vec![(a0, a1)]
        } else {
            merge(
                list.iter()
                    .filter(|m| m.through)
                    .map(|m| m.interval)
                    .collect(),
                eps,
            )
        };
        if !intervals.is_empty() {
            cuts.push(Cut {
                plane,
                dir,
                intervals,
            });
        }
    }
    cuts
}

/// True when one of the polygons `others` lies in the plane of polygon
/// `pv` (plane `pp`), facing the other way, and reaches the line where
/// `cutter` meets it: a solid resting on `pv` face to face (a block on a
/// seat, flush with its edge), whose side `cutter` stands on `pv` without
/// passing through it. A contact, not an intersection.
#[allow(clippy::too_many_arguments)]
fn face_contact(
    pv: &[DVec3],
    pp: &Plane,
    others: &[usize],
    vertices: &[Vec<DVec3>],
    planes: &[Plane],
    cutter: &Plane,
    dir: DVec3,
    eps: f64,
) -> bool {
    let Some((a0, a1)) = chord(pv, cutter, dir, eps) else {
        return false;
    };
    others.iter().any(|&r| {
        let rp = planes[r];
        let rv = &vertices[r];
        let (lo, hi) = side_range(rv, pp);
        rp.n.dot(pp.n) < 0.0
            && pp.n.cross(rp.n).length() < PARALLEL_SINE
            && lo >= -eps
            && hi <= eps
            && chord(rv, cutter, dir, eps).is_some_and(|(b0, b1)| a1.min(b1) - a0.max(b0) > eps)
    })
}

/// The count of pieces made so far by all polygons' cuts, against the
/// memory budget: each cut adds a polygon of at least three corners to
/// the scene, so the pass stops as soon as the scene it is making would
/// be over the budget ([`least_run_bytes`]), whichever thread gets there.
struct Growth<'a> {
    budget: &'a MemoryBudget,
    /// Polygons and corners before the pass.
    polygons: u64,
    corners: u64,
    /// Pieces added so far.
    added: AtomicU64,
}

impl Growth<'_> {
    /// The run's least memory with `added` more pieces.
    fn need(&self, added: u64) -> u64 {
        least_run_bytes(
            self.polygons.saturating_add(added),
            self.corners.saturating_add(added.saturating_mul(3)),
        )
    }

    /// Counts one more piece; false when the budget is now exceeded.
    fn add_piece(&self) -> bool {
        let added = self.added.fetch_add(1, Ordering::Relaxed) + 1;
        self.budget.fits(self.need(added))
    }

    /// True once some thread has gone over the budget.
    fn over(&self) -> bool {
        !self
            .budget
            .fits(self.need(self.added.load(Ordering::Relaxed)))
    }
}

/// The pieces polygon `p` is cut into by `cuts`, `Ok(None)` when no cut
/// was made, `Err(())` when `growth` went over its budget.
fn pieces_of(
    p: &Polygon,
    cuts: &[Cut],
    eps: f64,
    growth: &Growth<'_>,
) -> Result<Option<Vec<Polygon>>, ()> {
    let mut pieces = vec![p.clone()];
    let mut changed = false;
    for c in cuts {
        if growth.over() {
            return Err(());
        }
        let mut next = Vec::with_capacity(pieces.len() + 1);
        for piece in pieces {
            let v: Vec<DVec3> = piece.vertices.iter().map(|x| x.as_dvec3()).collect();
            let touched = straddles(&v, &c.plane, eps)
                && chord(&v, &c.plane, c.dir, eps).is_some_and(|(lo, hi)| {
                    c.intervals
                        .iter()
                        .any(|&(a, b)| hi.min(b) - lo.max(a) > eps)
                });
            let halves = touched.then(|| {
                let (front, back) = cut(&v, &c.plane, eps);
                let make = |vs: Vec<DVec3>| {
                    let vs = vs.into_iter().map(|x| x.as_vec3()).collect();
                    Polygon::new(p.material, vs, p.origin).ok().map(|mut q| {
                        q.surface = p.surface;
                        q
                    })
                };
                make(front).zip(make(back))
            });
            match halves.flatten() {
                Some((front, back)) => {
                    next.push(front);
                    next.push(back);
                    changed = true;
                    if !growth.add_piece() {
                        return Err(());
                    }
                }
                None => next.push(piece),
            }
        }
        pieces = next;
    }
    Ok(changed.then_some(pieces))
}

/// Why [`Scene::split_intersections_in`] stopped; the scene is unchanged.
#[derive(Debug, thiserror::Error)]
pub enum SplitStop {
    /// The pieces would need more memory than the budget.
    #[error("{0}")]
    Memory(#[from] OverBudget),
    /// The cancellation token was set.
    #[error("{0}")]
    Interrupted(#[from] Cancelled),
}

impl Scene {
    /// Splits every polygon along the lines where other polygons pass
    /// through it (see the module docs for which intersections cut), so
    /// that no element is later meshed across an intersection. The pieces
    /// of a polygon replace it in [`Scene::polygons`], in order, and in
    /// every group it belongs to; materials, origins and surfaces are kept.
    ///
    /// Meant to run once, after loading and before `with_sides` adds back
    /// copies; a scene that already has back copies is left unchanged.
    pub fn split_intersections(&mut self) -> SplitStats {
        // Nothing is over an unlimited budget, and a token nobody holds
        // is never set.
        self.split_intersections_in(&MemoryBudget::UNLIMITED, &Cancel::never())
            .unwrap_or_default()
    }

    /// [`Scene::split_intersections`] within the memory budget `budget`,
    /// stopping soon after `cancel` is set. The pieces are counted as they
    /// are made, and the pass stops with [`SplitStop::Memory`] as soon as
    /// the scene they make would need more than the budget (three crossing
    /// families of 40 quads make 201,720 pieces); each polygon checks
    /// `cancel` before it is cut. Either way the scene is left as it was.
    pub fn split_intersections_in(
        &mut self,
        budget: &MemoryBudget,
        cancel: &Cancel,
    ) -> Result<SplitStats, SplitStop> {
        let n = self.polygons.len();
        if n < 2 || self.polygons.iter().any(|p| p.surface.back_of.is_some()) {
            return Ok(SplitStats::default());
        }
        let growth = Growth {
            budget,
            polygons: n as u64,
            corners: self.polygons.iter().map(|p| p.vertices.len() as u64).sum(),
            added: AtomicU64::new(0),
        };
        let eps = SPLIT_TOLERANCE * f64::from(self.extent());
        let vertices: Vec<Vec<DVec3>> = self
            .polygons
            .iter()
            .map(|p| p.vertices.iter().map(|v| v.as_dvec3()).collect())
            .collect();
        let planes: Vec<Plane> = self
            .polygons
            .iter()
            .zip(&vertices)
            .map(|(p, v)| Plane::of(v, p.normal.as_dvec3()))
            .collect();
        let pad = Vec3A::splat(eps as f32);
        let boxes: Vec<Aabb> = self
            .polygons
            .iter()
            .map(|p| {
                let v: Vec<Vec3A> = p.vertices.iter().map(|&v| v.into()).collect();
                let b = Aabb::from_points(&v);
                Aabb::new(b.min - pad, b.max + pad)
            })
            .collect();
        let bvh = build_bvh2(
            &boxes,
            BvhBuildParams::fast_build(),
            &mut Duration::default(),
        );

        let replaced: Result<Vec<Option<Vec<Polygon>>>, ()> = (0..n)
            .into_par_iter()
            .map(|p| {
                if growth.over() {
                    return Err(());
                }
                if cancel.is_set() {
                    return Ok(None);
                }
                let others = overlapping(&bvh, &boxes, p);
                let cuts = cuts_of(p, &others, &vertices, &planes, eps);
                if cuts.is_empty() {
                    Ok(None)
                } else {
                    pieces_of(&self.polygons[p], &cuts, eps, &growth)
                }
            })
            .collect();
        cancel.check()?;
        let Ok(replaced) = replaced else {
            let added = growth.added.load(Ordering::Relaxed);
            return Err(SplitStop::Memory(OverBudget {
                need: growth.need(added),
                what: format!(
                    "{} polygons split along their intersections into more than {} pieces, \
                     at least",
                    fmt_count(n as u64),
                    fmt_count(n as u64 + added)
                ),
                budget: budget.bytes(),
            }));
        };

        let mut stats = SplitStats::default();
        if replaced.iter().all(Option::is_none) {
            return Ok(stats);
        }
        // first[i]..first[i + 1]: the new ids of old polygon i.
        let mut first = Vec::with_capacity(n + 1);
        let mut polygons = Vec::with_capacity(n);
        for (old, new) in std::mem::take(&mut self.polygons).into_iter().zip(replaced) {
            first.push(polygons.len() as u32);
            match new {
                Some(pieces) => {
                    stats.polygons_cut += 1;
                    stats.pieces += pieces.len();
                    polygons.extend(pieces);
                }
                None => polygons.push(old),
            }
        }
        first.push(polygons.len() as u32);
        self.polygons = polygons;
        for group in &mut self.groups {
            group.polygons = group
                .polygons
                .iter()
                .flat_map(|id| (first[id.index()]..first[id.index() + 1]).map(PolygonId))
                .collect();
        }
        Ok(stats)
    }
}

/// The polygons other than `p` whose boxes overlap `p`'s, ascending.
fn overlapping(bvh: &Bvh2, boxes: &[Aabb], p: usize) -> Vec<usize> {
    let mut out = Vec::new();
    bvh.aabb_traverse(boxes[p], |bvh, node| {
        let node = &bvh.nodes[node as usize];
        let start = node.first_index as usize;
        for &q in &bvh.primitive_indices[start..start + node.prim_count as usize] {
            let q = q as usize;
            if q != p && boxes[q].intersect_aabb(&boxes[p]) {
                out.push(q);
            }
        }
        true
    });
    out.sort_unstable();
    out.dedup();
    out
}

#[cfg(test)]
mod tests;
