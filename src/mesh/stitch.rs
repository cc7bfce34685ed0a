//! Watertight meshing: polygons that share an edge, or meet in a
//! T-junction, get matching element vertices along it.
//!
//! Each polygon is meshed on its own ([`super::build`]), so two polygons
//! sharing an edge cut it differently (a triangle of 3 subdivisions next to
//! one of 5), and even the same cut, computed from the two ends of the edge,
//! differs in the last bits. The rasteriser then leaves single background
//! pixels along the edge, and an exported mesh has cracks. [`stitch`] closes
//! them after every polygon is meshed (and again after each adaptive
//! refinement, see [`super::refine`]):
//!
//! 1. the **boundary edges** of each polygon's mesh are the element edges
//!    used by one element of it (found from the polygon's edges, or, for
//!    a polygon thinner than the tolerances, by counting);
//! 2. **snap**: boundary vertices of different polygons closer than the
//!    tolerance `ε` ([`STITCH_TOLERANCE`] × the scene's bounding-box
//!    diagonal) get one position, bit for bit: that of the lowest-numbered
//!    of them (a cluster holding two vertices of one polygon is left
//!    alone, so no element collapses);
//! 3. **insert**: a boundary vertex of another polygon lying on a boundary
//!    edge of this one (within `ε` of the segment, farther than `ε` from
//!    both ends) becomes a new vertex of this polygon at the same position,
//!    bit for bit. It is evaluated by the solver like any boundary vertex,
//!    at a point moved inward by the polygon's inset;
//! 4. **split**: an element whose edges received vertices is replaced by a
//!    fan of triangles from a corner not on those edges, or, when every
//!    corner touches one (a triangle with vertices on two edges), from a
//!    new vertex at its centre.
//!
//! One pass is enough: every boundary position of every polygon is then a
//! vertex of every polygon whose boundary passes through it.
//!
//! Both searches use uniform grids of sorted cell keys (no per-cell
//! allocation): the snap grid has cells of 64 `ε`, so a vertex nearly
//! always looks in one cell; the edge grid has cells of the mean boundary
//! edge length, each edge registered in every cell within `ε` of it, so a
//! vertex looks in its own cell only. The cost is `O(n log n)` in the
//! boundary vertices.

use super::{Element, Inset, Mesh, VertexId};
use crate::scene::{PolygonId, Scene};
use glam::Vec3;
use rayon::prelude::*;

/// Stitching tolerance `ε` as a fraction of the scene's bounding-box
/// diagonal (scene units after multiplying). It must cover the rounding of
/// element vertices computed in `f32` from different corners (a few units
/// in the last place, about 1e-7 of the coordinates) and the six decimals
/// most exporters print (5e-7 absolute, for models a metre or more
/// across); at 1e-5 of a 10 m scene it is 0.1 mm, far below any element.
pub const STITCH_TOLERANCE: f32 = 1e-5;

/// Cell size of the snap grid in multiples of `ε`: large enough that a
/// vertex's `ε`-ball nearly always lies in one cell.
const SNAP_CELL: f32 = 64.0;

/// Where a vertex of a stitched mesh comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Origin {
    /// The input mesh's vertex of this index.
    Kept(u32),
    /// Made by stitching, on the segment between these two input vertices
    /// (the ends of the element edge it was inserted on, or two opposite
    /// corners of the element whose centre it is).
    New([u32; 2]),
}

/// The mesh made watertight along shared edges and T-junctions (see the
/// module docs). Each polygon keeps its vertices, in order, followed by
/// the vertices stitching added; an element that received vertices on its
/// edges becomes a fan of triangles in its place. Positions of boundary
/// vertices may move by at most the tolerance (snapped), their evaluation
/// points with them.
pub fn stitch(scene: &Scene, mesh: Mesh) -> Mesh {
    stitch_with_origins(scene, mesh).0
}

/// A boundary element edge: element `element`'s edge `edge` (from corner
/// `edge` to the next), from vertex `a` to vertex `b`.
#[derive(Clone, Copy, Debug)]
struct BoundaryEdge {
    element: u32,
    edge: u8,
    a: u32,
    b: u32,
}

/// [`stitch`], and the origin of every vertex of the result: `None` when
/// every vertex is [`Origin::Kept`] in place (nothing was inserted).
pub(crate) fn stitch_with_origins(scene: &Scene, mut mesh: Mesh) -> (Mesh, Option<Vec<Origin>>) {
    let extent = scene.extent();
    if mesh.polygons.len() < 2 || extent.is_nan() || extent <= 0.0 {
        return (mesh, None);
    }
    let eps = STITCH_TOLERANCE * extent;
    let edges = boundary_edges(scene, &mesh, eps);
    let mut boundary: Vec<u32> = edges.iter().flat_map(|e| [e.a, e.b]).collect();
    boundary.par_sort_unstable();
    boundary.dedup();
    snap(&mut mesh, &boundary, eps, extent);
    let hits = t_junctions(&mesh, &edges, &boundary, eps, extent);
    if hits.is_empty() {
        return (mesh, None);
    }
    let (out, origins) = rebuild(scene, &mesh, &edges, &hits);
    (out, Some(origins))
}

/// Every polygon's boundary element edges, polygon by polygon, in element
/// order: the element edges whose two ends lie on one edge of the polygon
/// (the polygons are convex, so such an edge runs along it). Found from
/// the geometry rather than by counting the elements of each edge, so
/// the cost is linear; a polygon too thin for that ([`is_thin`]) by
/// counting.
fn boundary_edges(scene: &Scene, mesh: &Mesh, eps: f32) -> Vec<BoundaryEdge> {
    let mut out = Vec::new();
    let mut mask: Vec<u64> = Vec::new();
    let mut candidates = Vec::new();
    for (polygon, pm) in scene.polygons.iter().zip(&mesh.polygons) {
        let (lines, near) = edge_lines(polygon);
        if is_thin(polygon, &lines, eps) {
            thin_boundary(mesh, pm, &mut out);
            continue;
        }
        let first = pm.vertices.start;
        mask.clear();
        mask.extend(pm.vertices.clone().map(|v| {
            let p = mesh.positions[v as usize];
            let on = |k: usize| {
                lines[k].is_some_and(|(a, dir, tolerance)| {
                    let rel = p - a;
                    (rel - rel.dot(dir) * dir).length() <= tolerance
                })
            };
            // Edges past the 64th share the last bit: a false
            // candidate is only tested, never inserted wrongly.
            let bit = |m: u64, k: usize| m | 1 << k.min(63);
            match &near {
                None => (0..lines.len()).filter(|&k| on(k)).fold(0u64, bit),
                Some(grid) => {
                    grid.near(p, &mut candidates);
                    candidates
                        .iter()
                        .map(|&k| k as usize)
                        .filter(|&k| on(k))
                        .fold(0u64, bit)
                }
            }
        }));
        for e in pm.elements.clone() {
            let c = mesh.elements[e as usize].corners();
            for k in 0..c.len() {
                let (a, b) = (c[k].0, c[(k + 1) % c.len()].0);
                if mask[(a - first) as usize] & mask[(b - first) as usize] != 0 {
                    out.push(BoundaryEdge {
                        element: e,
                        edge: k as u8,
                        a,
                        b,
                    });
                }
            }
        }
    }
    out
}

/// Whether `polygon` is so thin that a point can lie within the on-edge
/// tolerance, or the stitching tolerance `eps`, of two of its edges at
/// once: its mean width across its longest edge (`2 · area / longest`, a
/// triangle's height) is at most twice the larger of them. A needle of a
/// real export (80 m long, 0.6 mm high) is one: found from the geometry,
/// every edge of its element grid was a boundary edge, each took every
/// neighbour's vertex beside it, and a refinement of the model's
/// neighbours grew its 3,200 vertices to 84,000.
fn is_thin(polygon: &crate::scene::Polygon, lines: &[Option<EdgeLine>], eps: f32) -> bool {
    let v = &polygon.vertices;
    let longest = (0..v.len())
        .map(|k| v[k].distance(v[(k + 1) % v.len()]))
        .fold(0.0f32, f32::max);
    let tolerance = lines.iter().flatten().map(|l| l.2).fold(eps, f32::max);
    longest > 0.0 && 2.0 * polygon.area as f32 / longest <= 2.0 * tolerance
}

/// A thin polygon's boundary element edges (see [`is_thin`]), found by
/// counting: the element edges that only one of its elements uses.
fn thin_boundary(mesh: &Mesh, pm: &super::PolygonMesh, out: &mut Vec<BoundaryEdge>) {
    let mut uses: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    let edges = |e: u32| {
        let c = mesh.elements[e as usize].corners();
        (0..c.len()).map(move |k| (k, c[k].0, c[(k + 1) % c.len()].0))
    };
    for e in pm.elements.clone() {
        for (_, a, b) in edges(e) {
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    for e in pm.elements.clone() {
        for (k, a, b) in edges(e) {
            if uses[&(a.min(b), a.max(b))] == 1 {
                out.push(BoundaryEdge {
                    element: e,
                    edge: k as u8,
                    a,
                    b,
                });
            }
        }
    }
}

/// A polygon edge's start, unit direction and on-edge tolerance.
type EdgeLine = (Vec3, Vec3, f32);

/// Each edge of a polygon, by its first vertex, as `(start, unit
/// direction, tolerance)` (none where two vertices meet), the tolerance
/// that of the inset rule (a fraction of the polygon's extent); and for a
/// polygon of many edges, the grid that finds the edges near a point.
fn edge_lines(polygon: &crate::scene::Polygon) -> (Vec<Option<EdgeLine>>, Option<super::EdgeGrid>) {
    let v = &polygon.vertices;
    let extent = crate::scene::polygon_extent_f32(v);
    let tolerance = super::ON_EDGE_TOLERANCE * extent;
    let lines = (0..v.len())
        .map(|k| {
            let (a, b) = (v[k], v[(k + 1) % v.len()]);
            let dir = (b - a).normalize_or_zero();
            (dir != Vec3::ZERO).then_some((a, dir, tolerance))
        })
        .collect();
    let near = (v.len() > super::EDGE_GRID_MIN).then(|| super::EdgeGrid::new(v, extent, tolerance));
    (lines, near)
}

/// A uniform grid: cell coordinates packed in a `u64`, 21 bits per axis.
#[derive(Clone, Copy)]
struct Grid {
    origin: Vec3,
    cell: f32,
}

impl Grid {
    fn new(origin: Vec3, cell: f32, extent: f32) -> Grid {
        // At most 2^20 cells across the scene, so the keys never wrap.
        Grid {
            origin,
            cell: cell.max(extent / (1 << 20) as f32),
        }
    }

    fn coords(&self, p: Vec3) -> [u64; 3] {
        let q = ((p - self.origin) / self.cell).floor();
        [q.x, q.y, q.z].map(|c| c.clamp(0.0, ((1 << 21) - 1) as f32) as u64)
    }

    fn key(c: [u64; 3]) -> u64 {
        (c[0] << 42) | (c[1] << 21) | c[2]
    }

    /// Every cell key of the box `[lo, hi]`.
    fn keys(&self, lo: Vec3, hi: Vec3, out: &mut Vec<u64>) {
        let (l, h) = (self.coords(lo), self.coords(hi));
        for x in l[0]..=h[0] {
            for y in l[1]..=h[1] {
                for z in l[2]..=h[2] {
                    out.push(Grid::key([x, y, z]));
                }
            }
        }
    }
}

/// The items of cell `key` in `entries` sorted by key.
fn cell(entries: &[(u64, u32)], key: u64) -> &[(u64, u32)] {
    let start = entries.partition_point(|e| e.0 < key);
    let end = start + entries[start..].partition_point(|e| e.0 == key);
    &entries[start..end]
}

/// Union-find root with path halving.
fn root(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        parent[i as usize] = parent[parent[i as usize] as usize];
        i = parent[i as usize];
    }
    i
}

/// Gives boundary vertices of different polygons within `eps` of each
/// other one position (step 2 of the module docs); moves their evaluation
/// points by the same amount.
fn snap(mesh: &mut Mesh, boundary: &[u32], eps: f32, extent: f32) {
    let lo = boundary
        .iter()
        .map(|&v| mesh.positions[v as usize])
        .fold(Vec3::splat(f32::INFINITY), Vec3::min)
        - Vec3::splat(eps);
    let grid = Grid::new(lo, SNAP_CELL * eps, extent);
    let mut entries: Vec<(u64, u32)> = boundary
        .iter()
        .enumerate()
        .map(|(i, &v)| (Grid::key(grid.coords(mesh.positions[v as usize])), i as u32))
        .collect();
    entries.par_sort_unstable();
    let mut parent: Vec<u32> = (0..boundary.len() as u32).collect();
    let mut keys = Vec::new();
    let mut joined = false;
    let mut join = |parent: &mut [u32], i: u32, j: u32| {
        let (u, v) = (boundary[i as usize] as usize, boundary[j as usize] as usize);
        if mesh.vertex_polygon[u] != mesh.vertex_polygon[v]
            && mesh.positions[u].distance(mesh.positions[v]) <= eps
        {
            let (a, b) = (root(parent, i), root(parent, j));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
                joined = true;
            }
        }
    };
    // Pairs within one cell, run by run of the sorted keys; then, for the
    // few vertices whose ε-ball crosses into other cells, those cells.
    let mut s = 0;
    while s < entries.len() {
        let mut e = s + 1;
        while e < entries.len() && entries[e].0 == entries[s].0 {
            e += 1;
        }
        for x in s..e {
            for y in x + 1..e {
                join(&mut parent, entries[x].1, entries[y].1);
            }
        }
        for x in s..e {
            let (own, i) = entries[x];
            let p = mesh.positions[boundary[i as usize] as usize];
            keys.clear();
            grid.keys(p - Vec3::splat(eps), p + Vec3::splat(eps), &mut keys);
            for &key in keys.iter().filter(|&&k| k != own) {
                for &(_, j) in cell(&entries, key) {
                    join(&mut parent, i, j);
                }
            }
        }
        s = e;
    }
    if !joined {
        return;
    }
    // Clusters by root; the root is the lowest index, hence the lowest
    // vertex id (`boundary` is sorted). A cluster with two vertices of one
    // polygon is left as it is.
    let mut members: Vec<(u32, u32, u32)> = (0..boundary.len() as u32)
        .map(|i| {
            let r = root(&mut parent, i);
            let v = boundary[i as usize];
            (r, mesh.vertex_polygon[v as usize].0, v)
        })
        .collect();
    members.par_sort_unstable();
    let mut s = 0;
    while s < members.len() {
        let mut e = s + 1;
        while e < members.len() && members[e].0 == members[s].0 {
            e += 1;
        }
        let group = &members[s..e];
        let repeated = group.windows(2).any(|w| w[0].1 == w[1].1);
        if group.len() > 1 && !repeated {
            let target = mesh.positions[boundary[group[0].0 as usize] as usize];
            for &(_, _, v) in group {
                let delta = target - mesh.positions[v as usize];
                mesh.positions[v as usize] = target;
                mesh.sample_positions[v as usize] += delta;
            }
        }
        s = e;
    }
}

/// A boundary vertex found on another polygon's boundary edge.
#[derive(Clone, Copy, Debug)]
struct Hit {
    /// Index into the boundary edges.
    edge: u32,
    /// Where along the edge, in `(0, 1)` from its `a`.
    t: f32,
    /// The vertex (input id) whose position is copied.
    vertex: u32,
}

/// Every boundary vertex lying inside another polygon's boundary edge
/// (step 3 of the module docs), sorted by edge and position along it, one
/// per position.
fn t_junctions(
    mesh: &Mesh,
    edges: &[BoundaryEdge],
    boundary: &[u32],
    eps: f32,
    extent: f32,
) -> Vec<Hit> {
    let positions = &mesh.positions;
    let total: f64 = edges
        .iter()
        .map(|e| positions[e.a as usize].distance(positions[e.b as usize]) as f64)
        .sum();
    let mean = (total / edges.len().max(1) as f64) as f32;
    let lo = boundary
        .iter()
        .map(|&v| positions[v as usize])
        .fold(Vec3::splat(f32::INFINITY), Vec3::min)
        - Vec3::splat(2.0 * eps);
    let grid = Grid::new(lo, mean.max(4.0 * eps), extent);
    let pad = Vec3::splat(eps);
    let mut entries: Vec<(u64, u32)> = Vec::with_capacity(edges.len() * 4);
    let mut keys = Vec::new();
    for (i, e) in edges.iter().enumerate() {
        let (a, b) = (positions[e.a as usize], positions[e.b as usize]);
        let steps = (a.distance(b) / grid.cell).ceil().clamp(1.0, 1e6) as u32;
        keys.clear();
        for s in 0..steps {
            let p = a.lerp(b, s as f32 / steps as f32);
            let q = a.lerp(b, (s + 1) as f32 / steps as f32);
            grid.keys(p.min(q) - pad, p.max(q) + pad, &mut keys);
        }
        keys.sort_unstable();
        keys.dedup();
        entries.extend(keys.iter().map(|&k| (k, i as u32)));
    }
    entries.par_sort_unstable();

    // Each vertex looks in its own cell only (edges are registered with
    // an ε margin): a merge of the two key-sorted lists.
    let mut vertices: Vec<(u64, u32)> = boundary
        .iter()
        .map(|&v| (Grid::key(grid.coords(positions[v as usize])), v))
        .collect();
    vertices.par_sort_unstable();
    let ends: Vec<(Vec3, Vec3, PolygonId)> = edges
        .iter()
        .map(|e| {
            (
                positions[e.a as usize],
                positions[e.b as usize],
                mesh.vertex_polygon[e.a as usize],
            )
        })
        .collect();
    // In parallel over runs of vertices, each merging from its first key.
    let chunk = vertices
        .len()
        .div_ceil(rayon::current_num_threads() * 8)
        .max(1024);
    let mut hits: Vec<Hit> = vertices
        .par_chunks(chunk)
        .flat_map_iter(|run| {
            let mut at = entries.partition_point(|e| e.0 < run[0].0);
            let mut hits = Vec::new();
            for &(key, v) in run {
                while at < entries.len() && entries[at].0 < key {
                    at += 1;
                }
                let p = positions[v as usize];
                let polygon = mesh.vertex_polygon[v as usize];
                for &(_, i) in entries[at..].iter().take_while(|e| e.0 == key) {
                    let (a, b, owner) = ends[i as usize];
                    if owner == polygon {
                        continue;
                    }
                    let d = b - a;
                    let t = (p - a).dot(d) / d.length_squared();
                    if !(t > 0.0 && t < 1.0)
                        || (a + t * d).distance(p) > eps
                        || p.distance(a) <= eps
                        || p.distance(b) <= eps
                    {
                        continue;
                    }
                    hits.push(Hit {
                        edge: i,
                        t,
                        vertex: v,
                    });
                }
            }
            hits
        })
        .collect();
    hits.sort_unstable_by(|x, y| {
        (x.edge, x.t, x.vertex)
            .partial_cmp(&(y.edge, y.t, y.vertex))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    // One vertex per position along an edge: coincident vertices of
    // several neighbours (snapped to one point) are inserted once.
    hits.dedup_by(|later, kept| {
        later.edge == kept.edge
            && positions[later.vertex as usize].distance(positions[kept.vertex as usize]) <= eps
    });
    hits
}

/// The stitched mesh: every polygon's vertices, then its inserted ones;
/// its elements, those with inserted vertices on their edges replaced by
/// fans (step 4 of the module docs).
fn rebuild(
    scene: &Scene,
    mesh: &Mesh,
    edges: &[BoundaryEdge],
    hits: &[Hit],
) -> (Mesh, Vec<Origin>) {
    let positions = &mesh.positions;
    let samples = &mesh.sample_positions;
    let extra = hits.len();
    let mut out = Mesh {
        positions: Vec::with_capacity(positions.len() + extra),
        sample_positions: Vec::with_capacity(positions.len() + extra),
        vertex_polygon: Vec::with_capacity(positions.len() + extra),
        elements: Vec::with_capacity(mesh.elements.len() + 3 * extra),
        element_polygon: Vec::with_capacity(mesh.elements.len() + 3 * extra),
        polygons: Vec::with_capacity(mesh.polygons.len()),
    };
    let mut origin = Vec::with_capacity(positions.len() + extra);
    // Hits grouped by element: boundary edges are sorted by element, and
    // hits by edge.
    let mut next_hit = 0usize;
    // Per element being rebuilt: the inserted vertices (output ids) on
    // each of its edges, in order from the edge's first corner.
    let mut on_edge: [Vec<u32>; 4] = Default::default();
    let mut ring: Vec<u32> = Vec::new();
    for (index, (polygon, pm)) in scene.polygons.iter().zip(&mesh.polygons).enumerate() {
        let id = PolygonId(index as u32);
        let v_start = out.positions.len() as u32;
        let shift = |v: u32| v - pm.vertices.start + v_start;
        for v in pm.vertices.clone() {
            out.positions.push(positions[v as usize]);
            out.sample_positions.push(samples[v as usize]);
            out.vertex_polygon.push(id);
            origin.push(Origin::Kept(v));
        }
        let e_start = out.elements.len() as u32;
        let mut added = 0u32;
        // Built at the polygon's first inserted vertex, if any.
        let mut inset = None;
        for e in pm.elements.clone() {
            let element = mesh.elements[e as usize];
            let mut touched = false;
            on_edge.iter_mut().for_each(Vec::clear);
            while next_hit < hits.len() && edges[hits[next_hit].edge as usize].element == e {
                let hit = hits[next_hit];
                next_hit += 1;
                let edge = edges[hit.edge as usize];
                let p = positions[hit.vertex as usize];
                // The point on the segment itself gets the inset rule,
                // then the (at most ε) offset back to the copied position.
                let (a, b) = (positions[edge.a as usize], positions[edge.b as usize]);
                let on_line = a.lerp(b, hit.t);
                let inset = inset.get_or_insert_with(|| Inset::new(polygon, pm.inset));
                let sample = inset.at(on_line) + (p - on_line);
                on_edge[edge.edge as usize].push(out.positions.len() as u32);
                out.positions.push(p);
                out.sample_positions.push(sample);
                out.vertex_polygon.push(id);
                origin.push(Origin::New([edge.a, edge.b]));
                added += 1;
                touched = true;
            }
            let corners = element.corners();
            if !touched {
                let c: Vec<VertexId> = corners.iter().map(|c| VertexId(shift(c.0))).collect();
                out.elements.push(if c.len() == 4 {
                    Element::quad(c[0], c[1], c[2], c[3])
                } else {
                    Element::triangle(c[0], c[1], c[2])
                });
                out.element_polygon.push(id);
                continue;
            }
            let n = corners.len();
            ring.clear();
            for k in 0..n {
                ring.push(shift(corners[k].0));
                ring.extend_from_slice(&on_edge[k]);
            }
            // A corner on no edge that received vertices sees every
            // inserted vertex across the element.
            let free =
                (0..n).find(|&k| on_edge[k].is_empty() && on_edge[(k + n - 1) % n].is_empty());
            match free {
                Some(k) => {
                    let apex = ring
                        .iter()
                        .position(|&v| v == shift(corners[k].0))
                        .unwrap_or(0);
                    let m = ring.len();
                    for s in 1..m - 1 {
                        out.elements.push(Element::triangle(
                            VertexId(ring[apex]),
                            VertexId(ring[(apex + s) % m]),
                            VertexId(ring[(apex + s + 1) % m]),
                        ));
                        out.element_polygon.push(id);
                    }
                }
                None => {
                    let centre =
                        corners.iter().map(|c| positions[c.index()]).sum::<Vec3>() / n as f32;
                    let apex = out.positions.len() as u32;
                    out.positions.push(centre);
                    out.sample_positions.push(centre);
                    out.vertex_polygon.push(id);
                    origin.push(Origin::New([corners[0].0, corners[2 % n].0]));
                    added += 1;
                    let m = ring.len();
                    for s in 0..m {
                        out.elements.push(Element::triangle(
                            VertexId(apex),
                            VertexId(ring[s]),
                            VertexId(ring[(s + 1) % m]),
                        ));
                        out.element_polygon.push(id);
                    }
                }
            }
        }
        let mut stitched = pm.clone();
        stitched.vertices = v_start..out.positions.len() as u32;
        stitched.elements = e_start..out.elements.len() as u32;
        stitched.stitched |= added > 0;
        out.polygons.push(stitched);
    }
    (out, origin)
}

#[cfg(test)]
mod tests;
