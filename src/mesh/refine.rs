//! Adaptive refinement: split the elements across which a scalar field
//! (the solver's luminance) changes sharply, keeping the mesh conforming.
//!
//! A [`Refiner`] remembers the *leaf* elements of every refinement so far:
//! the triangles and quadrilaterals the regular mesh started with, and
//! their children. Each [`Refiner::refine`] pass
//!
//! 1. **marks** every leaf whose field values (at its corners and at any
//!    vertex lying on its edges) differ by more than the threshold relative
//!    to the largest of them, `(max − min) / max(max, floor) > threshold`,
//!    unless it has already been split [`RefineOptions::levels`] times. The
//!    `floor` is [`DARK_FLOOR`] times the area-weighted mean of the field,
//!    so that noise in the near-black parts of a scene does not split them;
//!    When more leaves are marked than [`RefineOptions::max_splits`],
//!    only that many are kept: those with the most light to gain, their
//!    values' spread times their area (`(max − min) · area`, the light
//!    a linear drawing across them can miss). On a real level a pass
//!    marks tens of thousands of leaves, most of them small; the few
//!    thousand largest take almost all of the error
//!    ([`DEFAULT_MAX_SPLITS`]);
//! 2. **splits** each marked leaf into four: a quadrilateral at its edge
//!    midpoints and its centre, a triangle at its edge midpoints;
//! 3. **closes** the split: a leaf whose edge carries more than one new
//!    vertex (its neighbour is two levels finer), or whose new vertices lie
//!    on edges that no single corner can see past (opposite edges of a
//!    quadrilateral, two edges of a triangle), is split too, until none is
//!    left;
//! 4. **emits** a conforming mesh: a leaf with a vertex on an edge (a
//!    *hanging* vertex, where the neighbour was split) is drawn as a fan of
//!    triangles through that vertex, so the picture has no crack and no
//!    T-vertex seam: every vertex's radiosity is computed, and every triangle
//!    that touches the vertex interpolates it.
//!
//! Each emitted mesh is then stitched ([`super::stitch`]): a refined
//! boundary edge gets its neighbours' vertices, and the neighbours get its
//! new midpoints, so the refined mesh stays watertight.
//!
//! New vertices are the midpoints of their straight edges (and the centre of
//! a quadrilateral is the mean of its corners, which is the bilinear patch's
//! centre), so they lie exactly on the polygon. A new vertex on the polygon's
//! boundary gets the same inset as the polygon's other boundary vertices
//! ([`PolygonMesh::inset`]; the corners of a polygon left one element keep
//! their farther one, [`super::sample_inset`]).

use super::stitch::Origin;
use super::{inset_positions, Element, Mesh, PolygonMesh, VertexId};
use crate::scene::{PolygonId, Scene};
use glam::Vec3;
use std::collections::HashMap;

/// Default [`RefineOptions::threshold`]: a leaf is split when its vertex
/// luminances differ by more than a quarter of the largest. A smooth
/// gradient across an element of the default mesh stays well under it
/// (a few percent); the edge of a shadow is far over it.
pub const DEFAULT_THRESHOLD: f64 = 0.25;

/// Default [`RefineOptions::levels`]: elements are split at most twice, to a
/// quarter of the initial edge length.
pub const DEFAULT_LEVELS: u32 = 2;

/// Default [`RefineOptions::max_splits`]: at most 5,000 leaves split for
/// their values per pass, those with the most light to gain.
///
/// Chosen 2026-12-07 on the Sauerbraten level `pandora.obj` under
/// `--sky 1` (`--adaptive-levels 1`; 230,066 elements, 46,056 over the
/// default threshold), against a path tracer's picture of one view
/// (`docs/performance.md`), one run each on two cores:
///
/// | leaves split | new vertices | gather | error | wall |
/// |---|---|---|---|---|
/// | none (no refinement) | 0 | | 3.44 % | 67 s |
/// | 2,303 largest | 21,000 | 6 s | 2.96 % | 73 s |
/// | 4,606 largest | 42,000 | 12 s | 2.78 % | 85 s |
/// | **5,000 largest (this default)** | 45,000 | 11 s | 2.75 % | 77 s |
/// | 9,212 largest | 80,000 | 20 s | 2.79 % | 92 s |
/// | 18,423 largest | 147,000 | 36 s | 2.75 % | 106 s |
/// | all 46,056 | 305,000 | 60 s | 2.69 % | 138 s |
/// | the 27,250 over a threshold of 0.4 | 202,000 | 38 s | 2.88 % | 102 s |
///
/// A scene of a few thousand elements marks fewer than this and is
/// refined where its threshold says.
pub const DEFAULT_MAX_SPLITS: u64 = 5_000;

/// Most [`RefineOptions::levels`] accepted: each level can quadruple the
/// elements where it splits, and six already cut an element's edges into
/// 64, more than any shadow boundary of a sensible initial mesh needs.
pub const MAX_LEVELS: u32 = 6;

/// Values below this fraction of the field's area-weighted mean count as
/// black when comparing a leaf's values (see the module docs).
pub const DARK_FLOOR: f64 = 0.02;

/// How to refine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineOptions {
    /// Split a leaf whose values differ by more than this fraction of the
    /// largest of them; in `(0, 1)`.
    pub threshold: f64,
    /// Split an initial element at most this many times (each halves the
    /// edge length); in `1..=`[`MAX_LEVELS`].
    pub levels: u32,
    /// Split at most this many leaves for their values in one pass, those
    /// with the most light to gain (module docs); at least 1.
    pub max_splits: u64,
    /// Refuse a pass whose mesh would have more elements than this (then
    /// [`Refiner::refine`] changes nothing and [`Refiner::refused`] says
    /// how many it would have had).
    pub max_elements: u64,
}

/// A [`RefineOptions`] field out of its range. The messages name the
/// field, so a front end can prefix its own spelling of the option.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum OptionsError {
    /// [`RefineOptions::threshold`] is not in `(0, 1)`: at 0 every leaf
    /// with any variation splits, at 1 none ever does.
    #[error("threshold must be above 0 and below 1, got {0}")]
    Threshold(f64),
    /// [`RefineOptions::levels`] is not in `1..=`[`MAX_LEVELS`].
    #[error("levels must be between 1 and {MAX_LEVELS}, got {0}")]
    Levels(u32),
    /// [`RefineOptions::max_splits`] is 0: no pass could split anything.
    #[error("max-splits must be at least 1, got {0}")]
    MaxSplits(u64),
}

impl RefineOptions {
    /// Checks the documented ranges of [`RefineOptions::threshold`] and
    /// [`RefineOptions::levels`] (every `max_elements` is usable: it only
    /// refuses passes). The one test of these options, used by the command
    /// line before anything is loaded.
    pub fn validate(&self) -> Result<(), OptionsError> {
        if !(self.threshold.is_finite() && self.threshold > 0.0 && self.threshold < 1.0) {
            return Err(OptionsError::Threshold(self.threshold));
        }
        if !(1..=MAX_LEVELS).contains(&self.levels) {
            return Err(OptionsError::Levels(self.levels));
        }
        if self.max_splits == 0 {
            return Err(OptionsError::MaxSplits(self.max_splits));
        }
        Ok(())
    }
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            threshold: DEFAULT_THRESHOLD,
            levels: DEFAULT_LEVELS,
            max_splits: DEFAULT_MAX_SPLITS,
            max_elements: super::MAX_ELEMENTS,
        }
    }
}

/// What one refinement pass did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RefineReport {
    /// Leaves split because their values differ by more than the
    /// threshold: all of them, or the [`RefineOptions::max_splits`] with
    /// the most light to gain.
    pub marked: usize,
    /// Leaves whose values differ by more than the threshold, split or
    /// not.
    pub over_threshold: usize,
    /// Leaves split to keep the mesh conforming (closure).
    pub closure: usize,
    /// Leaves after the pass.
    pub leaves: usize,
    /// Leaves drawn as fans around hanging vertices.
    pub fans: usize,
}

/// A refinement pass refused because its mesh would be too large; its
/// `Display` is a one-line warning for the user.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "refining no further: the next refinement would make about {elements} elements, \
     over the limit of {max} (--max-elements, or what --max-memory holds)"
)]
pub struct Refused {
    /// Elements the refused mesh could have had (an upper bound).
    pub elements: u64,
    /// The limit it would have passed.
    pub max: u64,
}

/// One leaf element: 3 or 4 corners in pool vertex ids, counter-clockwise.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    corners: [u32; 4],
    len: u8,
    level: u8,
    polygon: PolygonId,
}

impl Leaf {
    fn corners(&self) -> &[u32] {
        &self.corners[..self.len as usize]
    }

    /// Its edges as `(from, to)`, counter-clockwise.
    fn edges(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        let c = self.corners();
        (0..c.len()).map(move |k| (c[k], c[(k + 1) % c.len()]))
    }
}

/// The refinement state of one mesh: leaves, vertices and the midpoint of
/// every split edge. Built from a mesh of [`super::build`]; each
/// [`Refiner::refine`] returns the next mesh.
pub struct Refiner {
    /// Every vertex so far, in pool ids; the meshes renumber them.
    positions: Vec<Vec3>,
    vertex_polygon: Vec<PolygonId>,
    leaves: Vec<Leaf>,
    /// The midpoint of each split edge, keyed by its end points in
    /// ascending order.
    midpoints: HashMap<(u32, u32), u32>,
    /// The initial per-polygon data (normal, area, inset, grid counts).
    polygons: Vec<PolygonMesh>,
    /// Pool id of each vertex of the last mesh returned (or of the mesh
    /// the refiner was built from).
    mesh_to_pool: Vec<u32>,
    /// Pool id of each vertex of the mesh before the last one returned.
    previous_mesh_to_pool: Vec<u32>,
    /// The two pool vertices each pool vertex was made between (its edge's
    /// ends, or a quadrilateral's `0–2` diagonal for its centre), `None`
    /// for the initial mesh's vertices.
    parents: Vec<Option<[u32; 2]>>,
    passes: u32,
    /// The last pass, if it was refused for [`RefineOptions::max_elements`].
    refused: Option<Refused>,
    /// True for the pool vertices stitching added to an emitted mesh
    /// ([`super::stitch`]): they are no leaf's corner, and each emitted
    /// mesh is stitched afresh, so [`Refiner::emit`] leaves them out.
    stitch_only: Vec<bool>,
    /// The pool id of each stitched vertex by polygon and exact position,
    /// so that a vertex stitched again in a later pass keeps its id (and
    /// its solved radiosity).
    stitch_ids: HashMap<(u32, [u32; 3]), u32>,
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl Refiner {
    /// Starts from an unrefined mesh (every polygon at level 0, as
    /// [`super::build`] makes them).
    pub fn new(mesh: &Mesh) -> Refiner {
        let leaves = mesh
            .elements
            .iter()
            .zip(&mesh.element_polygon)
            .map(|(e, &polygon)| {
                let mut corners = [0u32; 4];
                for (slot, c) in corners.iter_mut().zip(e.corners()) {
                    *slot = c.0;
                }
                Leaf {
                    corners,
                    len: e.corners().len() as u8,
                    level: 0,
                    polygon,
                }
            })
            .collect();
        Refiner {
            positions: mesh.positions.clone(),
            vertex_polygon: mesh.vertex_polygon.clone(),
            leaves,
            midpoints: HashMap::new(),
            polygons: mesh.polygons.clone(),
            mesh_to_pool: (0..mesh.vertex_count() as u32).collect(),
            previous_mesh_to_pool: Vec::new(),
            parents: vec![None; mesh.vertex_count()],
            passes: 0,
            refused: None,
            stitch_only: vec![false; mesh.vertex_count()],
            stitch_ids: HashMap::new(),
        }
    }

    /// When the last [`Refiner::refine`] returned `None` because its mesh
    /// would have exceeded [`RefineOptions::max_elements`]: why.
    pub fn refused(&self) -> Option<Refused> {
        self.refused
    }

    /// Refinement passes that split something so far.
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// For each vertex of the last mesh returned, its index in the mesh
    /// before it, or `None` for a vertex the last pass made. Empty before
    /// the first pass.
    pub fn previous_index(&self) -> Vec<Option<u32>> {
        let mut index = vec![None; self.positions.len()];
        for (k, &pool) in self.previous_mesh_to_pool.iter().enumerate() {
            index[pool as usize] = Some(k as u32);
        }
        self.mesh_to_pool
            .iter()
            .map(|&pool| index[pool as usize])
            .collect()
    }

    /// Carries a per-vertex field of the mesh before the last one returned
    /// over to the last one: kept at the vertices both have, and at each
    /// new vertex the mean of the two it was made between (the value the
    /// coarser mesh's Gouraud interpolation had there, but where that mesh
    /// drew the split element as a fan). `previous` holds one value per
    /// vertex of the mesh before.
    pub fn carry<T>(&self, previous: &[T]) -> Vec<T>
    where
        T: Copy + Default + std::ops::Add<Output = T> + std::ops::Mul<f64, Output = T>,
    {
        assert_eq!(previous.len(), self.previous_mesh_to_pool.len());
        let mut pool = vec![T::default(); self.positions.len()];
        let mut known = vec![false; self.positions.len()];
        for (&p, &v) in self.previous_mesh_to_pool.iter().zip(previous) {
            pool[p as usize] = v;
            known[p as usize] = true;
        }
        // Parents are always made before their children.
        for v in 0..pool.len() {
            if let (false, Some([a, b])) = (known[v], self.parents[v]) {
                pool[v] = (pool[a as usize] + pool[b as usize]) * 0.5;
            }
        }
        self.mesh_to_pool
            .iter()
            .map(|&p| pool[p as usize])
            .collect()
    }

    /// One pass: marks and splits the leaves over the threshold, closes the
    /// split and returns the new conforming mesh, or `None` when no leaf
    /// needs splitting (then nothing changes).
    ///
    /// `values` holds the field per vertex of the last mesh (the one this
    /// refiner was built from, or the last one returned), finite and
    /// non-negative; `scene` is the scene the mesh was built from.
    pub fn refine(
        &mut self,
        scene: &Scene,
        values: &[f64],
        options: &RefineOptions,
    ) -> Option<(Mesh, RefineReport)> {
        assert_eq!(
            values.len(),
            self.mesh_to_pool.len(),
            "one value per vertex of the last mesh"
        );
        let mut pool_values = vec![0.0; self.positions.len()];
        for (&pool, &v) in self.mesh_to_pool.iter().zip(values) {
            pool_values[pool as usize] = if v.is_finite() { v.max(0.0) } else { 0.0 };
        }
        let floor = DARK_FLOOR * self.mean(&pool_values);
        let max_level = options.levels.min(u8::MAX as u32) as u8;

        let mut ring = Vec::new();
        // Each leaf over the threshold, with the light it has to gain.
        let mut over: Vec<(f64, usize)> = (0..self.leaves.len())
            .filter_map(|k| {
                let leaf = self.leaves[k];
                if leaf.level >= max_level || self.is_sky(&leaf) {
                    return None;
                }
                self.ring(&leaf, &mut ring);
                let (lo, hi) = ring.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
                    let x = pool_values[v as usize];
                    (lo.min(x), hi.max(x))
                });
                (hi > 0.0 && (hi - lo) / hi.max(floor) > options.threshold)
                    .then(|| ((hi - lo) * self.leaf_area(&leaf), k))
            })
            .collect();
        let over_threshold = over.len();
        let keep = usize::try_from(options.max_splits).unwrap_or(usize::MAX);
        if over.len() > keep {
            // The most light to gain first; ties in leaf order, so the
            // choice does not depend on the sort.
            over.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            over.truncate(keep);
            over.sort_unstable_by_key(|&(_, k)| k);
        }
        let marked: Vec<usize> = over.into_iter().map(|(_, k)| k).collect();
        self.refused = None;
        if marked.is_empty() {
            return None;
        }
        // Each split adds three leaves, and a fan up to three triangles
        // more than its leaf: at most six more elements per split before
        // the closure, which adds a few percent.
        let elements = self.leaves.len() as u64 + 6 * marked.len() as u64;
        if elements > options.max_elements {
            self.refused = Some(Refused {
                elements,
                max: options.max_elements,
            });
            return None;
        }
        let mut report = RefineReport {
            marked: marked.len(),
            over_threshold,
            ..RefineReport::default()
        };
        // Split from the back so that the indices still to split stay valid
        // (children are appended at the end, the first child in place).
        for &k in marked.iter().rev() {
            self.split(k);
        }
        report.closure = self.close();
        self.passes += 1;
        for leaf in &self.leaves {
            let p = &mut self.polygons[leaf.polygon.index()];
            p.levels = p.levels.max(leaf.level as u32);
        }
        let (mesh, fans) = self.emit(scene);
        let mesh = self.stitch(scene, mesh);
        report.leaves = self.leaves.len();
        report.fans = fans;
        Some((mesh, report))
    }

    /// Area-weighted mean of a per-pool-vertex field over the leaves, sky
    /// facets left out.
    fn mean(&self, values: &[f64]) -> f64 {
        let (mut sum, mut area) = (0.0, 0.0);
        // The sky's huge bright facets would raise the floor above the
        // scene's own dark parts.
        for leaf in self.leaves.iter().filter(|leaf| !self.is_sky(leaf)) {
            let a = self.leaf_area(leaf);
            let mean = leaf
                .corners()
                .iter()
                .map(|&c| values[c as usize])
                .sum::<f64>()
                / leaf.len as f64;
            sum += a * mean;
            area += a;
        }
        if area > 0.0 {
            sum / area
        } else {
            0.0
        }
    }

    /// True for a leaf of a sky facet, which is never split.
    fn is_sky(&self, leaf: &Leaf) -> bool {
        self.polygons
            .get(leaf.polygon.index())
            .is_some_and(|pm| pm.sky)
    }

    fn leaf_area(&self, leaf: &Leaf) -> f64 {
        let p = |k: usize| self.positions[leaf.corners[k] as usize].as_dvec3();
        let tri = |a: usize, b: usize, c: usize| (p(b) - p(a)).cross(p(c) - p(a)).length() * 0.5;
        tri(0, 1, 2) + if leaf.len == 4 { tri(0, 2, 3) } else { 0.0 }
    }

    /// The vertices along edge `a → b` strictly between its ends, in order
    /// from `a`: the midpoints of every split of it and of its halves.
    fn hanging(&self, a: u32, b: u32, out: &mut Vec<u32>) {
        if let Some(&m) = self.midpoints.get(&edge_key(a, b)) {
            self.hanging(a, m, out);
            out.push(m);
            self.hanging(m, b, out);
        }
    }

    /// The leaf's boundary: its corners with the hanging vertices between
    /// them, counter-clockwise from its first corner.
    fn ring(&self, leaf: &Leaf, out: &mut Vec<u32>) {
        out.clear();
        for (a, b) in leaf.edges() {
            out.push(a);
            self.hanging(a, b, out);
        }
    }

    fn midpoint(&mut self, a: u32, b: u32) -> u32 {
        let key = edge_key(a, b);
        if let Some(&m) = self.midpoints.get(&key) {
            return m;
        }
        let p = (self.positions[a as usize] + self.positions[b as usize]) * 0.5;
        let m = self.vertex(p, self.vertex_polygon[a as usize], [a, b]);
        self.midpoints.insert(key, m);
        m
    }

    fn vertex(&mut self, p: Vec3, polygon: PolygonId, parents: [u32; 2]) -> u32 {
        self.positions.push(p);
        self.vertex_polygon.push(polygon);
        self.parents.push(Some(parents));
        self.stitch_only.push(false);
        (self.positions.len() - 1) as u32
    }

    /// Stitches an emitted mesh ([`super::stitch`]) so that refined edges
    /// meet their neighbours' vertices, and numbers the stitched vertices
    /// in the pool: the same polygon and position keep their pool id from
    /// pass to pass.
    fn stitch(&mut self, scene: &Scene, mesh: Mesh) -> Mesh {
        let (stitched, origins) = super::stitch::stitch_with_origins(scene, mesh);
        let Some(origins) = origins else {
            return stitched;
        };
        let emitted = std::mem::take(&mut self.mesh_to_pool);
        self.mesh_to_pool = Vec::with_capacity(origins.len());
        for (v, origin) in origins.iter().enumerate() {
            let pool = match *origin {
                Origin::Kept(i) => emitted[i as usize],
                Origin::New([a, b]) => {
                    let polygon = stitched.vertex_polygon[v];
                    let key = (
                        polygon.0,
                        stitched.positions[v].to_array().map(f32::to_bits),
                    );
                    match self.stitch_ids.get(&key) {
                        Some(&id) => id,
                        None => {
                            let id = self.vertex(
                                stitched.positions[v],
                                polygon,
                                [emitted[a as usize], emitted[b as usize]],
                            );
                            self.stitch_only[id as usize] = true;
                            self.stitch_ids.insert(key, id);
                            id
                        }
                    }
                }
            };
            self.mesh_to_pool.push(pool);
        }
        stitched
    }

    /// Splits leaf `k` into four; the first child takes its place.
    fn split(&mut self, k: usize) {
        let leaf = self.leaves[k];
        let level = leaf.level + 1;
        let child = |corners: &[u32]| {
            let mut c = [corners[0]; 4];
            c[..corners.len()].copy_from_slice(corners);
            Leaf {
                corners: c,
                len: corners.len() as u8,
                level,
                polygon: leaf.polygon,
            }
        };
        let c = leaf.corners;
        let children: Vec<Leaf> = if leaf.len == 4 {
            let m01 = self.midpoint(c[0], c[1]);
            let m12 = self.midpoint(c[1], c[2]);
            let m23 = self.midpoint(c[2], c[3]);
            let m30 = self.midpoint(c[3], c[0]);
            let centre = c.iter().map(|&v| self.positions[v as usize]).sum::<Vec3>() * 0.25;
            // The centre lies on the 0–2 diagonal the quadrilateral is
            // drawn with: its value there is the mean of those corners.
            let o = self.vertex(centre, leaf.polygon, [c[0], c[2]]);
            vec![
                child(&[c[0], m01, o, m30]),
                child(&[m01, c[1], m12, o]),
                child(&[o, m12, c[2], m23]),
                child(&[m30, o, m23, c[3]]),
            ]
        } else {
            let m01 = self.midpoint(c[0], c[1]);
            let m12 = self.midpoint(c[1], c[2]);
            let m20 = self.midpoint(c[2], c[0]);
            vec![
                child(&[c[0], m01, m20]),
                child(&[m01, c[1], m12]),
                child(&[m20, m12, c[2]]),
                child(&[m01, m12, m20]),
            ]
        };
        self.leaves[k] = children[0];
        self.leaves.extend_from_slice(&children[1..]);
    }

    /// Which edges of a leaf carry hanging vertices, as a bit mask, or
    /// `None` when the leaf must be split: an edge carries more than one,
    /// or no fan can take them all.
    fn hanging_edges(&self, leaf: &Leaf) -> Option<u8> {
        let mut mask = 0u8;
        for (k, (a, b)) in leaf.edges().enumerate() {
            if let Some(&m) = self.midpoints.get(&edge_key(a, b)) {
                if self.midpoints.contains_key(&edge_key(a, m))
                    || self.midpoints.contains_key(&edge_key(m, b))
                {
                    return None;
                }
                mask |= 1 << k;
            }
        }
        match (leaf.len, mask.count_ones()) {
            (_, 0 | 1) => Some(mask),
            // Two adjacent edges of a quadrilateral: the corner opposite
            // their common corner sees past both.
            (4, 2) if mask != 0b0101 && mask != 0b1010 => Some(mask),
            _ => None,
        }
    }

    /// Splits leaves until every leaf can be drawn conforming; returns how
    /// many were split.
    fn close(&mut self) -> usize {
        let mut split = 0;
        loop {
            let before = split;
            let mut k = 0;
            while k < self.leaves.len() {
                if self.hanging_edges(&self.leaves[k]).is_none() {
                    self.split(k);
                    split += 1;
                    // The first child now sits at `k`: check it again.
                    continue;
                }
                k += 1;
            }
            if split == before {
                return split;
            }
        }
    }

    /// The conforming mesh of the current leaves; returns it and how many
    /// leaves were drawn as fans.
    fn emit(&mut self, scene: &Scene) -> (Mesh, usize) {
        let polygon_count = self.polygons.len();
        let mut vertices_of: Vec<Vec<u32>> = vec![Vec::new(); polygon_count];
        for (v, p) in self.vertex_polygon.iter().enumerate() {
            if !self.stitch_only[v] {
                vertices_of[p.index()].push(v as u32);
            }
        }
        let mut leaves_of: Vec<Vec<usize>> = vec![Vec::new(); polygon_count];
        for (k, leaf) in self.leaves.iter().enumerate() {
            leaves_of[leaf.polygon.index()].push(k);
        }
        let mut mesh = Mesh {
            positions: Vec::with_capacity(self.positions.len()),
            sample_positions: Vec::with_capacity(self.positions.len()),
            vertex_polygon: Vec::with_capacity(self.positions.len()),
            elements: Vec::with_capacity(self.leaves.len()),
            element_polygon: Vec::with_capacity(self.leaves.len()),
            polygons: Vec::with_capacity(polygon_count),
        };
        let mut pool_to_mesh = vec![0u32; self.positions.len()];
        self.previous_mesh_to_pool = std::mem::take(&mut self.mesh_to_pool);
        let mut fans = 0;
        let mut ring = Vec::new();
        for (p, (polygon, initial)) in scene.polygons.iter().zip(&self.polygons).enumerate() {
            let id = PolygonId(p as u32);
            let v_start = mesh.positions.len() as u32;
            if initial.levels > 0 {
                // New vertices were numbered as they were made, scattered
                // over the polygon; the solver groups runs of consecutive
                // vertices into shafts, which must stay thin. A Z-order
                // curve keeps neighbours together.
                sort_along_z_curve(&mut vertices_of[p], &self.positions);
            }
            for &v in &vertices_of[p] {
                pool_to_mesh[v as usize] = mesh.positions.len() as u32;
                self.mesh_to_pool.push(v);
                mesh.positions.push(self.positions[v as usize]);
                mesh.vertex_polygon.push(id);
            }
            let e_start = mesh.elements.len() as u32;
            let at = |v: u32| VertexId(pool_to_mesh[v as usize]);
            for &k in &leaves_of[p] {
                let leaf = self.leaves[k];
                let mask = self.hanging_edges(&leaf).unwrap_or(0);
                if mask == 0 {
                    let c = leaf.corners;
                    mesh.elements.push(if leaf.len == 4 {
                        Element::quad(at(c[0]), at(c[1]), at(c[2]), at(c[3]))
                    } else {
                        Element::triangle(at(c[0]), at(c[1]), at(c[2]))
                    });
                    mesh.element_polygon.push(id);
                    continue;
                }
                fans += 1;
                self.ring(&leaf, &mut ring);
                // The fan's apex: the hanging vertex when there is one edge
                // with one (the most even triangles), else the corner not
                // on either hanging edge (see `hanging_edges`).
                let apex = if mask.count_ones() == 1 {
                    let edge = mask.trailing_zeros() as usize;
                    ring.iter()
                        .position(|&v| v == self.hanging_vertex(&leaf, edge))
                        .unwrap_or(0)
                } else {
                    let n = leaf.len as u32;
                    let hanging = |e: u32| mask & (1 << (e % n)) != 0;
                    // Corner `c` lies on edges `c` and `c - 1`.
                    let corner = (0..n)
                        .find(|&c| !hanging(c) && !hanging(c + n - 1))
                        .unwrap_or(0);
                    ring.iter()
                        .position(|&v| v == leaf.corners[corner as usize])
                        .unwrap_or(0)
                };
                let n = ring.len();
                for s in 1..n - 1 {
                    let (b, c) = (ring[(apex + s) % n], ring[(apex + s + 1) % n]);
                    mesh.elements
                        .push(Element::triangle(at(ring[apex]), at(b), at(c)));
                    mesh.element_polygon.push(id);
                }
            }
            let mut pm = initial.clone();
            pm.vertices = v_start..mesh.positions.len() as u32;
            pm.elements = e_start..mesh.elements.len() as u32;
            pm.min_edge = min_edge(&mesh, &pm).unwrap_or(initial.min_edge);
            mesh.sample_positions.extend(inset_positions(
                polygon,
                &mesh.positions[v_start as usize..],
                initial.inset,
            ));
            // A polygon still one element (one leaf, never split) keeps its
            // corners' farther inset (`super::sample_inset`); vertices
            // stitched into its edges keep the polygon's own.
            if let [k] = leaves_of[p][..] {
                let leaf = self.leaves[k];
                let far = super::sample_inset(initial.inset, 1);
                for &c in &leaf.corners[..leaf.len as usize] {
                    let l = pool_to_mesh[c as usize] as usize;
                    let at = mesh.positions[l];
                    mesh.sample_positions[l] =
                        inset_positions(polygon, &[at], far).next().unwrap_or(at);
                }
            }
            mesh.polygons.push(pm);
        }
        (mesh, fans)
    }

    /// The hanging vertex on edge `edge` of a leaf (which has one).
    fn hanging_vertex(&self, leaf: &Leaf, edge: usize) -> u32 {
        let n = leaf.len as usize;
        let (a, b) = (leaf.corners[edge], leaf.corners[(edge + 1) % n]);
        self.midpoints[&edge_key(a, b)]
    }
}

/// Sorts vertex ids by the Z-order (Morton) code of their positions
/// within the bounding box of them all, 10 bits per axis; ties by id.
fn sort_along_z_curve(ids: &mut [u32], positions: &[Vec3]) {
    let (lo, hi) = ids.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &v| (lo.min(positions[v as usize]), hi.max(positions[v as usize])),
    );
    let scale = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
    let spread = |mut x: u32| {
        // Insert two zero bits between each of the low 10 bits.
        x &= 0x3ff;
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    let code = |v: u32| {
        let q =
            ((positions[v as usize] - lo) / scale * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
        spread(q.x as u32) | (spread(q.y as u32) << 1) | (spread(q.z as u32) << 2)
    };
    ids.sort_by_key(|&v| (code(v), v));
}

/// The shortest element edge of a polygon's mesh, in scene units.
fn min_edge(mesh: &Mesh, pm: &PolygonMesh) -> Option<f32> {
    mesh.elements[pm.elements.start as usize..pm.elements.end as usize]
        .iter()
        .flat_map(|e| {
            let c = e.corners();
            (0..c.len()).map(move |k| (c[k], c[(k + 1) % c.len()]))
        })
        .map(|(a, b)| mesh.positions[a.index()].distance(mesh.positions[b.index()]))
        .reduce(f32::min)
}

#[cfg(test)]
mod tests;
