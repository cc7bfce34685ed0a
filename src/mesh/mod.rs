//! Meshing: each polygon becomes a grid of small elements whose corners
//! (element vertices) carry the radiosity.
//!
//! How each polygon is cut, with `lenmax` the longest allowed element edge:
//!
//! - a **parallelogram** becomes `nu × nv` congruent parallelograms,
//!   `nu = ⌊|v1 − v0| / lenmax⌋ + 1` and `nv = ⌊|v3 − v0| / lenmax⌋ + 1`;
//! - any other convex **quadrilateral** becomes a bilinear `nu × nv` grid,
//!   `nu` from the longer of its two `u` edges and `nv` from the longer `v`
//!   edge, so every interior grid line (a blend of the two) is short enough;
//! - a **triangle** becomes `n²` triangles by a regular subdivision of each
//!   edge into `n` parts, `n` from its longest edge;
//! - a **convex polygon** of five or six vertices (collinear vertices
//!   dropped) is first split into a fan of triangles around its centroid,
//!   and every fan triangle is subdivided with the same `n`, so the fan's
//!   shared edges carry the same vertices;
//! - a convex polygon of more vertices (a disc, a cylinder's cap) becomes
//!   the Delaunay triangulation of its rim cut every `lenmax` and a
//!   triangular lattice inside (`lattice`), whose size follows its area
//!   and perimeter rather than its vertex count.
//!
//! Element vertices are shared between neighbouring elements of the same
//! polygon, never between polygons: each polygon's radiosity is
//! discontinuous at its boundary, as a diffuse polygon's is across a crease.
//! But polygons that share an edge or meet in a T-junction get vertices at
//! the same positions along it ([`stitch`], run by [`build`] after every
//! polygon is meshed), so the picture and the exports are watertight; and
//! the vertices of a smooth surface's facets there show one radiosity
//! ([`weld`]).
//!
//! **Inset.** Vertices on a polygon's boundary are evaluated (not drawn) at a
//! point moved inward by `inset × s` along the in-plane inward normal of each
//! boundary edge they lie on, where `s` is `lenmax`, or the polygon's
//! diameter when that is smaller. A vertex exactly on a room's corner line
//! lies in the plane of the neighbouring wall, where its shadow rays graze
//! that wall and its form factors to it vanish; moved a little inward it
//! sees what the surface near the corner sees, so corners do not come out
//! dark. Two rules keep this true on a real export's slivers: at an acute
//! apex, where the two edges' normals nearly cancel, the point moves at
//! least `inset × s` along the bisector; and it moves at most half the way
//! across the polygon ([`INSET_CLAMP`]). (A sliver's own size would not
//! do: its shortest edge is a hair, and its vertices at a wall's foot
//! would be evaluated in the corner itself.)
//!
//! A polygon that is one element moves its corners [`ONE_ELEMENT_INSET`]
//! times as far ([`sample_inset`]). Its corners are its only samples, and the picture spreads each one's
//! value linearly over the whole polygon: evaluated near a corner where
//! the polygon meets a wall or a floor (a game level's block, the step
//! of a ledge), the dark of that corner became a wedge across the
//! polygon. Farther in, a corner's value stands more for the part of the
//! polygon it is spread over (its hat, whose centroid lies halfway along
//! the median from that corner). Vertices that stitching then puts on
//! its edges, where a neighbour's finer mesh meets it, keep the polygon's
//! own inset ([`PolygonMesh::inset`]), as do all its vertices once
//! refinement splits it.

use crate::budget::fmt_bytes;
use crate::cancel::Cancel;
use crate::scene::{Polygon, PolygonId, Scene, Shape};
use glam::{DVec3, Vec3};
use std::collections::HashMap;
use std::ops::Range;

pub mod budget;
pub mod covered;
mod handle;
mod lattice;
pub mod refine;
pub mod stitch;
pub mod weld;

pub use handle::MeshRef;

/// Default inset of boundary vertices, as a fraction of `lenmax` (or of
/// the polygon's diameter when smaller; see the module docs). Five
/// percent moves the sample far above `f32` rounding yet leaves it inside
/// its elements.
pub const DEFAULT_INSET: f32 = 0.05;

/// How many times as far inside a polygon that is a single element its
/// boundary vertices are evaluated as those of a polygon of many
/// elements (see the module docs): the inset `inset × min(lenmax,
/// diameter)` times this, still at most half the way across. Measured
/// against the path-traced references of `docs/performance.md` (its
/// cameras, `--sky 1`, default options): 1 (the same inset for all)
/// left `pandora.obj` 5.21 % off, `fortitude.obj` 3.76 %, `zdm2.glb`
/// 3.24 %, `zdm2.obj` 2.81 %; 3 gives 4.47 %, 3.42 %, 3.13 %, 2.71 %
/// (`room.glb` and the vianney house within 0.01 % of before); 5 gave
/// `pandora.obj` 4.75 % and `zdm2.obj` 2.89 %. Tripling the inset of
/// every polygon instead made `zdm2.obj` worse (3.12 %): on a wall of
/// many elements a boundary vertex stands for a strip one element wide,
/// and its neighbours are near.
pub const ONE_ELEMENT_INSET: f32 = 3.0;

/// Default `lenmax` as a fraction of the scene's bounding-box diagonal,
/// when its mesh is within the vertex budget ([`budget`]). For `rtable`
/// (diagonal 7.7 units) this gives elements under 0.1 units, about 14,000
/// vertices, converged to 0.1 % unshot in a few seconds on two cores, with
/// smooth shadows.
pub const DEFAULT_LENMAX_FRACTION: f32 = 1.0 / 80.0;

/// Most elements a mesh may have. A mesh this large needs gigabytes for the
/// solver's arrays; asking for more is almost always a `lenmax` typo.
pub const MAX_ELEMENTS: u64 = 20_000_000;

/// The most elements any limit allows: vertex and element indices are
/// `u32`, and a mesh has at most about twice as many vertices as elements
/// (a strip of `n` elements has `2n + 2`).
pub const MAX_ADDRESSABLE_ELEMENTS: u64 = u32::MAX as u64 / 4;

/// A vertex counts as lying on a polygon edge when it is closer to the
/// edge's line than this fraction of the polygon's extent.
pub(crate) const ON_EDGE_TOLERANCE: f32 = 1e-5;

/// Relative tolerance for dropping a vertex of a 5+-gon as collinear with
/// its neighbours (cross product against the product of edge lengths).
const COLLINEAR_TOLERANCE: f64 = 1e-9;

/// Index of an element vertex in the [`Mesh`] arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VertexId(pub u32);

impl VertexId {
    /// The index as a `usize`, for slice access.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One element: a triangle or a quadrilateral of element vertices, listed
/// counter-clockwise seen from the polygon's front.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Element {
    corners: [VertexId; 4],
    len: u8,
}

impl Element {
    /// A triangular element.
    pub fn triangle(a: VertexId, b: VertexId, c: VertexId) -> Self {
        Element {
            corners: [a, b, c, c],
            len: 3,
        }
    }

    /// A quadrilateral element.
    pub fn quad(a: VertexId, b: VertexId, c: VertexId, d: VertexId) -> Self {
        Element {
            corners: [a, b, c, d],
            len: 4,
        }
    }

    /// Its corners, 3 or 4 of them, counter-clockwise from the front.
    pub fn corners(&self) -> &[VertexId] {
        &self.corners[..self.len as usize]
    }

    /// The element as one or two triangles (a quad is split along its
    /// `0–2` diagonal), counter-clockwise from the front.
    pub fn triangles(&self) -> impl Iterator<Item = [VertexId; 3]> + '_ {
        let c = self.corners;
        let second = (self.len == 4).then_some([c[0], c[2], c[3]]);
        std::iter::once([c[0], c[1], c[2]]).chain(second)
    }
}

/// The mesh of one polygon.
#[derive(Clone, Debug, PartialEq)]
pub struct PolygonMesh {
    /// Elements along the first parametric direction (edge `v0→v1` for
    /// quads; the subdivision count of every edge for triangles and fans).
    pub nu: u32,
    /// Elements along the second direction (edge `v0→v3` for quads; equal
    /// to `nu` for triangles and polygons of five or more vertices).
    pub nv: u32,
    /// Its element vertices: a contiguous range of [`Mesh`] vertex indices.
    pub vertices: Range<u32>,
    /// Its elements: a contiguous range of [`Mesh::elements`].
    pub elements: Range<u32>,
    /// Unit front normal (copied from the scene polygon).
    pub normal: Vec3,
    /// Area of the polygon in square scene units.
    pub area: f64,
    /// Length of its shortest element edge, in scene units.
    pub min_edge: f32,
    /// Distance its boundary vertices' evaluation points are moved inward
    /// ([`Mesh::sample_positions`]), in scene units: `inset × min(lenmax,
    /// diameter)`; stitching and refinement move new boundary vertices by
    /// the same distance. The corners of a polygon meshed as one element
    /// move [`ONE_ELEMENT_INSET`] times as far ([`sample_inset`]).
    pub inset: f32,
    /// Adaptive refinement passes that split some of its elements (see
    /// [`refine`]); 0 for the regular subdivision of [`build`], whose
    /// vertices are evenly spaced.
    pub levels: u32,
    /// Its draw layer among overlapping coplanar polygons that face its
    /// way ([`crate::scene::draw_layers`]): where they overlap, the
    /// picture shows the highest layer. 0 for most polygons.
    pub layer: u8,
    /// True when another polygon draws its back side (its back copy, the
    /// front it is the back copy of, or a face of the file that is its
    /// reverse, [`crate::scene::Surface::back`]):
    /// the picture then draws this one from the front only.
    pub has_back: bool,
    /// A sky facet ([`crate::scene::Surface::sky`]): one element whatever
    /// the lenmax, never refined, drawn or exported (see
    /// [`Mesh::without_sky`]).
    pub sky: bool,
    /// True when [`stitch`] added vertices to its mesh (or to the mesh it
    /// was refined from): its vertices are then unevenly spaced along the
    /// boundary.
    pub stitched: bool,
}

impl PolygonMesh {
    /// Number of element vertices of this polygon.
    pub fn vertex_count(&self) -> u32 {
        self.vertices.end - self.vertices.start
    }
}

/// The distance the corners of a polygon meshed as `elements` elements
/// are evaluated inside it, given its `inset` distance
/// ([`PolygonMesh::inset`]), in scene units (see the module docs).
pub fn sample_inset(inset: f32, elements: usize) -> f32 {
    if elements == 1 {
        inset * ONE_ELEMENT_INSET
    } else {
        inset
    }
}

/// The element mesh of a whole scene, as flat arrays.
///
/// Invariants (checked by [`Mesh::validate`]): the per-vertex arrays have one
/// entry per vertex; each polygon's vertices and elements are contiguous and
/// in scene order; every element's corners belong to its own polygon.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Element vertex positions on the polygon, in scene units: where the
    /// picture draws them.
    pub positions: Vec<Vec3>,
    /// Where each vertex's radiosity is evaluated: [`Mesh::positions`]
    /// moved inward from the polygon's boundary by the inset.
    pub sample_positions: Vec<Vec3>,
    /// The polygon each vertex belongs to.
    pub vertex_polygon: Vec<PolygonId>,
    /// Every element of every polygon.
    pub elements: Vec<Element>,
    /// The polygon each element belongs to.
    pub element_polygon: Vec<PolygonId>,
    /// Per scene polygon, in scene order.
    pub polygons: Vec<PolygonMesh>,
}

/// How to mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshOptions {
    /// Every element edge is shorter than this, in scene units; `> 0`.
    pub lenmax: f32,
    /// Inset of boundary vertices as a fraction of the polygon's shortest
    /// element edge, in `[0, 0.5)`; 0 disables it.
    pub inset: f32,
}

impl MeshOptions {
    /// The finest default options for a scene: `lenmax` a fixed fraction
    /// ([`DEFAULT_LENMAX_FRACTION`]) of its bounding-box diagonal. A run
    /// without `--lenmax` takes [`MeshOptions::within_budget`], which is
    /// these unless their mesh is over the vertex budget.
    pub fn for_scene(scene: &Scene) -> Self {
        let extent = scene.extent();
        MeshOptions {
            lenmax: if extent > 0.0 {
                extent * DEFAULT_LENMAX_FRACTION
            } else {
                1.0
            },
            inset: DEFAULT_INSET,
        }
    }
}

/// Why a mesh could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// The run's cancellation token was set while meshing
    /// ([`build_cancellable`]).
    #[error("{0}")]
    Interrupted(#[from] crate::cancel::Cancelled),
    /// `lenmax` is not a positive finite number.
    #[error("lenmax must be a positive number of scene units, got {0}")]
    BadLenmax(f32),
    /// The inset is outside `[0, 0.5)`.
    #[error("inset must be at least 0 and below 0.5 (a fraction of lenmax), got {0}")]
    BadInset(f32),
    /// The mesh would have more elements than allowed: what it would
    /// take, and the smallest lenmax that fits.
    #[error(
        "lenmax {lenmax} would make {} elements and {} vertices, about {} of memory; \
         --max-elements allows {max}: {}",
        size.elements,
        size.vertices,
        fmt_bytes(memory_estimate(*size)),
        match suggested {
            Some(l) => format!("use --lenmax {l} or larger (or raise --max-elements)"),
            None => "the scene has more polygons than that even unsubdivided".to_string(),
        }
    )]
    TooManyElements {
        /// The lenmax asked for, in scene units.
        lenmax: f32,
        /// The mesh it would make.
        size: MeshSize,
        /// The element limit.
        max: u64,
        /// The smallest lenmax (to three significant digits) that fits,
        /// if any does ([`lenmax_to_fit`]).
        suggested: Option<f32>,
    },
}

/// Element and vertex counts of a mesh, known before it is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshSize {
    /// Elements the mesh will have.
    pub elements: u64,
    /// Element vertices the mesh will have.
    pub vertices: u64,
}

/// The exact element and vertex counts of the polygons meshed each on its
/// own ([`build_unstitched_with_limit`]), computed from the subdivision
/// counts alone (no allocation per element), so that a driver can refuse a
/// mesh too large for memory before building it. [`build`]'s stitching
/// then adds the vertices polygons take from their neighbours' edges and
/// the elements split to hold them: under half a percent more vertices on
/// the bundled scenes, up to a fifth more on game levels.
pub fn estimate(scene: &Scene, options: &MeshOptions) -> Result<MeshSize, MeshError> {
    check_options(options)?;
    Ok(Sizes::of(scene).at(options.lenmax))
}

/// A scene's mesh size at any lenmax ([`estimate`]'s counts) without
/// looking at its polygons again: what each polygon's subdivision counts
/// come from, found once. The size only falls (or stays) as lenmax grows.
#[derive(Clone, Debug)]
pub struct Sizes {
    spans: Vec<Span>,
}

impl Sizes {
    /// The spans of every polygon of `scene`.
    pub fn of(scene: &Scene) -> Sizes {
        Sizes {
            spans: scene.polygons.iter().map(|p| Plan::new(p).span).collect(),
        }
    }

    /// The mesh size at `lenmax` (positive, scene units), as [`estimate`]
    /// gives it.
    pub fn at(&self, lenmax: f32) -> MeshSize {
        self.spans.iter().fold(
            MeshSize {
                elements: 0,
                vertices: 0,
            },
            |sum, span| {
                let size = span.size_at(lenmax);
                MeshSize {
                    elements: sum.elements.saturating_add(size.elements),
                    vertices: sum.vertices.saturating_add(size.vertices),
                }
            },
        )
    }

    /// The least size any lenmax gives: one element per triangle or quad,
    /// a fan of one element per rim edge for a larger polygon. Its vertex
    /// count is the polygons' corners (and a fan's apex).
    pub fn least(&self) -> MeshSize {
        self.at(f32::INFINITY)
    }

    /// The smallest lenmax, rounded up to three significant digits, that
    /// gives the [`Sizes::least`] mesh: a longer one changes nothing.
    /// In scene units; [`f32::MIN_POSITIVE`] for a scene with nothing to
    /// cut.
    pub fn coarsest(&self) -> f32 {
        let longest = self
            .spans
            .iter()
            .map(|s| s.u.max(s.v))
            .fold(0.0f32, f32::max);
        if longest <= 0.0 {
            return f32::MIN_POSITIVE;
        }
        // One element wherever lenmax exceeds every span (`divisions`).
        let above = round_up(longest.next_up());
        let least = self.least();
        if self.at(above) == least {
            above
        } else {
            longest.next_up()
        }
    }

    /// The smallest lenmax not below `from` whose mesh passes `fits`,
    /// rounded up to three significant digits unless it is `from` itself;
    /// `None` when even [`Sizes::coarsest`] does not. `fits` must hold at
    /// every lenmax above one where it holds, as a limit on the size does.
    pub fn smallest_fitting(&self, from: f32, fits: impl Fn(MeshSize) -> bool) -> Option<f32> {
        let fits = |lenmax: f32| fits(self.at(lenmax));
        if fits(from) {
            return Some(from);
        }
        let mut hi = self.coarsest().max(from);
        if !fits(hi) {
            return None;
        }
        let mut lo = from;
        // Bisection in log scale; the count only falls as lenmax grows.
        for _ in 0..60 {
            let mid = (lo * hi).sqrt();
            if !(mid > lo && mid < hi) {
                break;
            }
            if fits(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        // Rounded for the messages that show it, still fitting.
        let rounded = round_up(hi);
        Some(if fits(rounded) { rounded } else { hi })
    }
}

/// `x` rounded up to three significant digits (`13.8523` to `13.9`), a
/// lenmax a message can show and a user can type.
fn round_up(x: f32) -> f32 {
    let digits = 10f64.powf((x as f64).log10().floor() - 2.0);
    let rounded = ((x as f64 / digits).ceil() * digits) as f32;
    // Casting back may round down below `x`.
    if rounded >= x {
        rounded
    } else {
        rounded.next_up()
    }
}

/// Refuses, before anything is allocated, a mesh with more than
/// `max_elements` elements (at most [`MAX_ADDRESSABLE_ELEMENTS`]), saying
/// how much memory it would take and which lenmax would fit.
pub fn check_size(
    scene: &Scene,
    options: &MeshOptions,
    max_elements: u64,
) -> Result<MeshSize, MeshError> {
    let max = max_elements.min(MAX_ADDRESSABLE_ELEMENTS);
    let size = estimate(scene, options)?;
    if size.elements <= max {
        Ok(size)
    } else {
        Err(too_many_elements(scene, options, max))
    }
}

/// The error for a mesh over `max_elements`, with its size and the
/// lenmax that fits.
fn too_many_elements(scene: &Scene, options: &MeshOptions, max_elements: u64) -> MeshError {
    let size = estimate(scene, options).unwrap_or(MeshSize {
        elements: u64::MAX,
        vertices: u64::MAX,
    });
    MeshError::TooManyElements {
        lenmax: options.lenmax,
        size,
        max: max_elements,
        suggested: lenmax_to_fit(scene, options, max_elements),
    }
}

/// The smallest lenmax, rounded up to three significant digits, whose mesh
/// has at most `max_elements` elements; `None` when even one element per
/// polygon is too many.
pub fn lenmax_to_fit(scene: &Scene, options: &MeshOptions, max_elements: u64) -> Option<f32> {
    check_options(options).ok()?;
    Sizes::of(scene).smallest_fitting(options.lenmax, |s| s.elements <= max_elements)
}

/// Bytes held per mesh vertex and per element during a run: the memory
/// model of [`crate::budget`], which [`memory_estimate`] applies.
pub use crate::budget::{BYTES_PER_ELEMENT, BYTES_PER_VERTEX};

/// Estimated peak memory of a run with a mesh of this size, in bytes:
/// [`BYTES_PER_VERTEX`] per vertex and [`BYTES_PER_ELEMENT`] per element.
pub fn memory_estimate(size: MeshSize) -> u64 {
    size.vertices
        .saturating_mul(BYTES_PER_VERTEX)
        .saturating_add(size.elements.saturating_mul(BYTES_PER_ELEMENT))
}

/// Builds the element mesh of every polygon of `scene`, refusing more than
/// [`MAX_ELEMENTS`] elements.
pub fn build(scene: &Scene, options: &MeshOptions) -> Result<Mesh, MeshError> {
    build_with_limit(scene, options, MAX_ELEMENTS)
}

/// `lenmax` itself when it is a usable longest element edge (a positive,
/// finite number of scene units), else [`MeshError::BadLenmax`]. The one
/// test of a lenmax: the command line checks its `--lenmax` with it before
/// anything is loaded, and [`build`] and [`estimate`] check theirs.
pub fn check_lenmax(lenmax: f32) -> Result<f32, MeshError> {
    if lenmax.is_finite() && lenmax > 0.0 {
        Ok(lenmax)
    } else {
        Err(MeshError::BadLenmax(lenmax))
    }
}

/// `inset` itself when it is a usable boundary inset (a fraction of an
/// element edge in `[0, 0.5)`, so an evaluation point stays well inside
/// the boundary elements of its vertex), else [`MeshError::BadInset`]. The
/// one test of an inset, as [`check_lenmax`] is of a lenmax.
pub fn check_inset(inset: f32) -> Result<f32, MeshError> {
    if inset.is_finite() && (0.0..0.5).contains(&inset) {
        Ok(inset)
    } else {
        Err(MeshError::BadInset(inset))
    }
}

fn check_options(options: &MeshOptions) -> Result<(), MeshError> {
    check_lenmax(options.lenmax)?;
    check_inset(options.inset)?;
    Ok(())
}

/// [`build`] with another element limit, itself capped at
/// [`MAX_ADDRESSABLE_ELEMENTS`].
pub fn build_with_limit(
    scene: &Scene,
    options: &MeshOptions,
    max_elements: u64,
) -> Result<Mesh, MeshError> {
    build_cancellable(scene, options, max_elements, &Cancel::never())
}

/// [`build_with_limit`], stopping with [`MeshError::Interrupted`] soon
/// after `cancel` is set: it is checked per polygon meshed and before the
/// mesh is stitched.
pub fn build_cancellable(
    scene: &Scene,
    options: &MeshOptions,
    max_elements: u64,
    cancel: &Cancel,
) -> Result<Mesh, MeshError> {
    let mesh = build_unstitched(scene, options, max_elements, cancel)?;
    cancel.check()?;
    Ok(stitch::stitch(scene, mesh))
}

/// Each polygon meshed on its own, not [`stitch`]ed: the mesh before its
/// shared edges are made watertight (what a comparison of the two, or a
/// tool that wants the bare grids, starts from).
pub fn build_unstitched_with_limit(
    scene: &Scene,
    options: &MeshOptions,
    max_elements: u64,
) -> Result<Mesh, MeshError> {
    build_unstitched(scene, options, max_elements, &Cancel::never())
}

/// [`build_unstitched_with_limit`], checking `cancel` per polygon.
fn build_unstitched(
    scene: &Scene,
    options: &MeshOptions,
    max_elements: u64,
    cancel: &Cancel,
) -> Result<Mesh, MeshError> {
    let max_elements = max_elements.min(MAX_ADDRESSABLE_ELEMENTS);
    check_options(options)?;
    let plans: Vec<Plan> = scene.polygons.iter().map(Plan::new).collect();
    // Saturating: absurd subdivision counts must reach the limit check,
    // not overflow on the way.
    let elements = plans.iter().fold(0u64, |sum, p| {
        sum.saturating_add(p.span.size_at(options.lenmax).elements)
    });
    if elements > max_elements {
        return Err(too_many_elements(scene, options, max_elements));
    }

    let mut mesh = Mesh {
        positions: Vec::new(),
        sample_positions: Vec::new(),
        vertex_polygon: Vec::new(),
        elements: Vec::with_capacity(elements as usize),
        element_polygon: Vec::with_capacity(elements as usize),
        polygons: Vec::with_capacity(scene.polygons.len()),
    };
    let layers = crate::scene::draw_layers(scene, &crate::scene::plane_classes(scene));
    for (index, (polygon, plan)) in scene.polygons.iter().zip(&plans).enumerate() {
        cancel.check()?;
        let id = PolygonId(index as u32);
        let v_start = mesh.positions.len() as u32;
        let e_start = mesh.elements.len() as u32;
        let mut builder = PolygonBuilder {
            mesh: &mut mesh,
            polygon: id,
            first_vertex: v_start,
        };
        let (nu, nv, min_edge) = plan.emit(&mut builder, options.lenmax);
        let v_end = mesh.positions.len() as u32;
        // The scale the vertex's value is interpolated over: the element
        // size, or the polygon's when it is smaller (not a sliver's width,
        // nor the shortest edge of its needles).
        let scale = options
            .lenmax
            .min(crate::scene::polygon_extent_f32(&polygon.vertices));
        let elements = mesh.elements.len() - e_start as usize;
        mesh.sample_positions.extend(inset_positions(
            polygon,
            &mesh.positions[v_start as usize..],
            sample_inset(options.inset * scale, elements),
        ));
        mesh.polygons.push(PolygonMesh {
            nu,
            nv,
            vertices: v_start..v_end,
            elements: e_start..mesh.elements.len() as u32,
            normal: polygon.normal,
            area: polygon.area,
            min_edge,
            inset: options.inset * scale,
            levels: 0,
            layer: layers[index],
            // A back copy is the other side of its front: neither draws
            // the side the other draws, or the two would z-fight.
            has_back: polygon.surface.back.is_some() || polygon.surface.back_of.is_some(),
            sky: polygon.surface.sky,
            stitched: false,
        });
    }
    Ok(mesh)
}

/// How one polygon will be cut: its shape after simplification, and what
/// sets its subdivision counts at any lenmax.
struct Plan {
    cut: Cut,
    span: Span,
}

/// The shape a polygon is cut as.
enum Cut {
    /// Parallelogram `v0 + u (v1 − v0) + v (v3 − v0)`.
    Parallelogram([Vec3; 4]),
    /// Bilinear quad.
    Bilinear([Vec3; 4]),
    /// A single triangle subdivided `n` times per edge.
    Triangle([Vec3; 3]),
    /// A fan of triangles `(apex, rim[k], rim[k+1])` around a closed rim.
    Fan { apex: Vec3, rim: Vec<Vec3> },
    /// A convex polygon of more than [`FAN_MAX_RIM`] vertices, meshed by
    /// [`lattice::mesh`].
    Lattice { rim: Vec<Vec3>, normal: Vec3 },
}

/// The most rim vertices a convex polygon is cut as a fan with: past
/// this, a fan's `m · n²` elements outgrow the lattice's, and its
/// triangles grow thin.
const FAN_MAX_RIM: usize = 6;

/// What sets one polygon's mesh size at any lenmax: the lengths its
/// subdivision counts come from, and how the counts become elements and
/// vertices. Computed once per polygon ([`Sizes`]), so that the size at
/// many lenmax values (a search for the lenmax that fits) needs no
/// geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Span {
    /// The length cut into `nu` parts, in scene units: the longer `u` edge
    /// of a quad, the longest edge of a triangle or of a fan's triangles;
    /// 0 for a sky facet, which is one element whatever the lenmax.
    u: f32,
    /// The length cut into `nv` parts: the longer `v` edge of a quad;
    /// equal to `u` for triangles and fans.
    v: f32,
    /// How the counts become elements and vertices.
    form: Form,
}

/// How subdivision counts become elements and vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Form {
    /// An `nu × nv` grid of quads.
    Grid,
    /// A triangle cut `nu` times per edge.
    Triangle,
    /// A fan of this many triangles, each cut `nu` times per edge.
    Fan(u32),
    /// A rim and lattice ([`lattice`]) over this area and perimeter (scene
    /// units) with this many rim vertices.
    Lattice { area: f32, perimeter: f32, rim: u32 },
}

/// Subdivisions so that `length / n < lenmax`.
fn divisions(length: f32, lenmax: f32) -> u32 {
    let n = (length / lenmax).floor() + 1.0;
    // Saturate absurd counts; `MAX_ELEMENTS` then refuses the mesh.
    if n >= u32::MAX as f32 / 4.0 {
        u32::MAX / 4
    } else {
        n as u32
    }
}

impl Span {
    /// The subdivision counts `(nu, nv)` at `lenmax`.
    fn divisions(&self, lenmax: f32) -> (u32, u32) {
        (divisions(self.u, lenmax), divisions(self.v, lenmax))
    }

    /// Elements and vertices of the polygon's own mesh at `lenmax`
    /// (before [`stitch`]).
    fn size_at(&self, lenmax: f32) -> MeshSize {
        let (nu, nv) = self.divisions(lenmax);
        let (nu, nv) = (nu as u64, nv as u64);
        match self.form {
            Form::Grid => MeshSize {
                elements: nu * nv,
                vertices: (nu + 1) * (nv + 1),
            },
            Form::Triangle => MeshSize {
                elements: nu * nu,
                vertices: (nu + 1) * (nu + 2) / 2,
            },
            // The apex, each spoke's points past the apex, and each fan
            // triangle's points off both of its spokes.
            Form::Fan(m) => {
                let m = m as u64;
                let inner = nu * nu.saturating_sub(1) / 2;
                MeshSize {
                    elements: m.saturating_mul(nu * nu),
                    vertices: (m.saturating_mul(nu + inner)).saturating_add(1),
                }
            }
            Form::Lattice {
                area,
                perimeter,
                rim,
            } => {
                let (elements, vertices) = lattice::size_at(area, perimeter, rim, lenmax);
                MeshSize { elements, vertices }
            }
        }
    }
}

impl Plan {
    fn new(polygon: &Polygon) -> Plan {
        let v = &polygon.vertices;
        let (cut, u, w, form) = match polygon.shape {
            Shape::Parallelogram | Shape::Quad => {
                let q = [v[0], v[1], v[2], v[3]];
                if polygon.shape == Shape::Parallelogram {
                    let (u, w) = (q[0].distance(q[1]), q[0].distance(q[3]));
                    (Cut::Parallelogram(q), u, w, Form::Grid)
                } else {
                    let u = q[0].distance(q[1]).max(q[3].distance(q[2]));
                    let w = q[0].distance(q[3]).max(q[1].distance(q[2]));
                    (Cut::Bilinear(q), u, w, Form::Grid)
                }
            }
            Shape::Triangle => {
                let t = [v[0], v[1], v[2]];
                let longest = t[0]
                    .distance(t[1])
                    .max(t[1].distance(t[2]))
                    .max(t[2].distance(t[0]));
                (Cut::Triangle(t), longest, longest, Form::Triangle)
            }
            Shape::Convex => {
                let rim = drop_collinear(v);
                if rim.len() == 3 {
                    return Plan::new(&Polygon {
                        vertices: rim,
                        shape: Shape::Triangle,
                        ..polygon.clone()
                    });
                }
                if rim.len() > FAN_MAX_RIM && !polygon.surface.sky {
                    let diameter = crate::scene::polygon_extent_f32(&rim);
                    let rim = lattice::simplify(&rim, ON_EDGE_TOLERANCE * diameter);
                    let perimeter = (0..rim.len())
                        .map(|k| rim[k].distance(rim[(k + 1) % rim.len()]))
                        .sum::<f32>();
                    let form = Form::Lattice {
                        area: polygon.area as f32,
                        perimeter,
                        rim: rim.len() as u32,
                    };
                    // The lattice's size comes from `form`; `u` and `v`
                    // only say how large the polygon is.
                    let cut = Cut::Lattice {
                        rim,
                        normal: polygon.normal,
                    };
                    (cut, diameter, diameter, form)
                } else {
                    let apex = area_centroid(&rim);
                    let mut longest = 0.0f32;
                    for k in 0..rim.len() {
                        let (a, b) = (rim[k], rim[(k + 1) % rim.len()]);
                        longest = longest.max(a.distance(b)).max(apex.distance(a));
                    }
                    let form = Form::Fan(rim.len() as u32);
                    (Cut::Fan { apex, rim }, longest, longest, form)
                }
            }
        };
        // A sky facet's radiosity is its emission, the same everywhere:
        // one element carries it, whatever the scene's lenmax.
        let (u, v) = if polygon.surface.sky {
            (0.0, 0.0)
        } else {
            (u, w)
        };
        Plan {
            cut,
            span: Span { u, v, form },
        }
    }

    /// Emits the vertices and elements cut at `lenmax`; returns
    /// `(nu, nv, min_edge)`.
    fn emit(&self, b: &mut PolygonBuilder, lenmax: f32) -> (u32, u32, f32) {
        let (nu, nv) = self.span.divisions(lenmax);
        match &self.cut {
            Cut::Parallelogram(v) => {
                let (eu, ev) = (v[1] - v[0], v[3] - v[0]);
                b.grid(nu, nv, |u, w| v[0] + u * eu + w * ev);
                let min_edge = (eu.length() / nu as f32).min(ev.length() / nv as f32);
                (nu, nv, min_edge)
            }
            Cut::Bilinear(v) => {
                let bilinear = |u: f32, w: f32| {
                    (1.0 - u) * (1.0 - w) * v[0]
                        + u * (1.0 - w) * v[1]
                        + u * w * v[2]
                        + (1.0 - u) * w * v[3]
                };
                b.grid(nu, nv, bilinear);
                let shortest_u = v[0].distance(v[1]).min(v[3].distance(v[2])) / nu as f32;
                let shortest_v = v[0].distance(v[3]).min(v[1].distance(v[2])) / nv as f32;
                (nu, nv, shortest_u.min(shortest_v))
            }
            Cut::Triangle(v) => {
                b.triangle(nu, v[0], v[1], v[2]);
                let shortest = v[0]
                    .distance(v[1])
                    .min(v[1].distance(v[2]))
                    .min(v[2].distance(v[0]));
                (nu, nu, shortest / nu as f32)
            }
            Cut::Fan { apex, rim } => {
                b.fan(nu, *apex, rim);
                let mut shortest = f32::INFINITY;
                for k in 0..rim.len() {
                    let (a, c) = (rim[k], rim[(k + 1) % rim.len()]);
                    shortest = shortest.min(a.distance(c)).min(apex.distance(a));
                }
                (nu, nu, shortest / nu as f32)
            }
            Cut::Lattice { rim, normal } => {
                let mesh = lattice::mesh(rim, *normal, lenmax);
                let first = b.mesh.positions.len() as u32;
                for &p in &mesh.positions {
                    b.vertex(p);
                }
                for t in &mesh.triangles {
                    let [a, c, d] = t.map(|i| VertexId(first + i));
                    b.element(Element::triangle(a, c, d));
                }
                // Not a grid: one "division" each way, so nothing takes
                // it for one.
                (1, 1, mesh.min_edge)
            }
        }
    }
}

/// Appends one polygon's vertices and elements to the mesh.
struct PolygonBuilder<'a> {
    mesh: &'a mut Mesh,
    polygon: PolygonId,
    first_vertex: u32,
}

impl PolygonBuilder<'_> {
    fn vertex(&mut self, p: Vec3) -> VertexId {
        let id = VertexId(self.mesh.positions.len() as u32);
        self.mesh.positions.push(p);
        self.mesh.vertex_polygon.push(self.polygon);
        id
    }

    fn element(&mut self, e: Element) {
        self.mesh.elements.push(e);
        self.mesh.element_polygon.push(self.polygon);
    }

    /// A `(nu + 1) × (nv + 1)` grid of vertices at `at(a / nu, b / nv)`,
    /// with the `u` index running fastest, and its `nu × nv` quads.
    fn grid(&mut self, nu: u32, nv: u32, at: impl Fn(f32, f32) -> Vec3) {
        for b in 0..=nv {
            for a in 0..=nu {
                self.vertex(at(a as f32 / nu as f32, b as f32 / nv as f32));
            }
        }
        let first = self.first_vertex;
        let id = |a: u32, b: u32| VertexId(first + b * (nu + 1) + a);
        for b in 0..nv {
            for a in 0..nu {
                let e = Element::quad(id(a, b), id(a + 1, b), id(a + 1, b + 1), id(a, b + 1));
                self.element(e);
            }
        }
    }

    /// The regular subdivision of one triangle: vertices at
    /// `v0 + (i/n)(v1 − v0) + (j/n)(v2 − v0)` for `i + j <= n`.
    fn triangle(&mut self, n: u32, v0: Vec3, v1: Vec3, v2: Vec3) {
        let (e1, e2) = (v1 - v0, v2 - v0);
        let mut ids = HashMap::new();
        for j in 0..=n {
            for i in 0..=(n - j) {
                let p = v0 + (i as f32 / n as f32) * e1 + (j as f32 / n as f32) * e2;
                ids.insert((i, j), self.vertex(p));
            }
        }
        self.subdivide(n, |i, j| ids[&(i, j)]);
    }

    /// Emits the `n²` elements of a subdivided triangle whose lattice
    /// point `(i, j)` is the vertex `id(i, j)`.
    fn subdivide(&mut self, n: u32, id: impl Fn(u32, u32) -> VertexId) {
        for j in 0..n {
            for i in 0..(n - j) {
                self.element(Element::triangle(id(i, j), id(i + 1, j), id(i, j + 1)));
                if i + j + 1 < n {
                    self.element(Element::triangle(
                        id(i + 1, j),
                        id(i + 1, j + 1),
                        id(i, j + 1),
                    ));
                }
            }
        }
    }

    /// A fan of subdivided triangles `(apex, rim[k], rim[k+1])`. Points on
    /// the spokes `apex → rim[k]` are shared by the two triangles that
    /// meet there, and computed once from the spoke so they are identical.
    fn fan(&mut self, n: u32, apex: Vec3, rim: &[Vec3]) {
        #[derive(Hash, PartialEq, Eq, Clone, Copy)]
        enum Key {
            Apex,
            Spoke(usize, u32),
            Inner(usize, u32, u32),
        }
        let m = rim.len();
        let mut ids: HashMap<Key, VertexId> = HashMap::new();
        let key = |k: usize, i: u32, j: u32| match (i, j) {
            (0, 0) => Key::Apex,
            (_, 0) => Key::Spoke(k, i),
            (0, _) => Key::Spoke((k + 1) % m, j),
            _ => Key::Inner(k, i, j),
        };
        for k in 0..m {
            let (a, c) = (rim[k], rim[(k + 1) % m]);
            for j in 0..=n {
                for i in 0..=(n - j) {
                    let kk = key(k, i, j);
                    if ids.contains_key(&kk) {
                        continue;
                    }
                    let p = match kk {
                        Key::Apex => apex,
                        Key::Spoke(s, t) => apex + (t as f32 / n as f32) * (rim[s] - apex),
                        Key::Inner(..) => {
                            apex + (i as f32 / n as f32) * (a - apex)
                                + (j as f32 / n as f32) * (c - apex)
                        }
                    };
                    let id = self.vertex(p);
                    ids.insert(kk, id);
                }
            }
            self.subdivide(n, |i, j| ids[&key(k, i, j)]);
        }
    }
}

/// The vertices of a convex polygon without those collinear with their
/// neighbours (which would make zero-area fan triangles).
pub(crate) fn drop_collinear(v: &[Vec3]) -> Vec<Vec3> {
    let n = v.len();
    let kept: Vec<Vec3> = (0..n)
        .filter(|&k| {
            let prev = v[(k + n - 1) % n].as_dvec3();
            let here = v[k].as_dvec3();
            let next = v[(k + 1) % n].as_dvec3();
            let (a, b) = (here - prev, next - here);
            a.cross(b).length() > COLLINEAR_TOLERANCE * a.length() * b.length()
        })
        .map(|k| v[k])
        .collect();
    if kept.len() >= 3 {
        kept
    } else {
        v.to_vec()
    }
}

/// Area centroid of a planar convex polygon (inside it, unlike the vertex
/// mean's failure cases it is robust to uneven vertex spacing).
pub(crate) fn area_centroid(v: &[Vec3]) -> Vec3 {
    let origin = v[0].as_dvec3();
    let mut weighted = DVec3::ZERO;
    let mut total = 0.0;
    let normal = {
        let mut n = DVec3::ZERO;
        for k in 0..v.len() {
            n += v[k].as_dvec3().cross(v[(k + 1) % v.len()].as_dvec3());
        }
        n.normalize_or_zero()
    };
    for k in 1..v.len() - 1 {
        let (a, b) = (v[k].as_dvec3(), v[k + 1].as_dvec3());
        let area = (a - origin).cross(b - origin).dot(normal) * 0.5;
        weighted += (origin + a + b) / 3.0 * area;
        total += area;
    }
    if total > 0.0 {
        (weighted / total).as_vec3()
    } else {
        v.iter().copied().sum::<Vec3>() / v.len() as f32
    }
}

/// Evaluation points of one polygon's vertices: each vertex that lies on a
/// polygon edge moves `distance` along that edge's inward normal (a corner
/// vertex moves along both).
fn inset_positions<'a>(
    polygon: &'a Polygon,
    positions: &'a [Vec3],
    distance: f32,
) -> impl Iterator<Item = Vec3> + 'a {
    let mut inset = Inset::new(polygon, distance);
    positions.iter().map(move |&p| inset.at(p))
}

/// The inset rule of one polygon, built once and asked point by point
/// (stitching asks it once per inserted vertex).
struct Inset {
    /// Per vertex `k`, the edge from it to the next as `(start, unit
    /// direction, inward normal)` (none where the two vertices meet).
    edges: Vec<Option<(Vec3, Vec3, Vec3)>>,
    /// Distance from an edge's line within which a point is on the edge.
    tolerance: f32,
    /// How far a point on an edge moves inward, in scene units.
    distance: f32,
    /// For a polygon of many edges, the grid that finds those near a point.
    near: Option<EdgeGrid>,
    candidates: Vec<u32>,
}

impl Inset {
    fn new(polygon: &Polygon, distance: f32) -> Inset {
        let v = &polygon.vertices;
        let extent = crate::scene::polygon_extent_f32(v);
        let tolerance = ON_EDGE_TOLERANCE * extent;
        let edges = (0..v.len())
            .map(|k| {
                let (a, b) = (v[k], v[(k + 1) % v.len()]);
                let dir = (b - a).normalize_or_zero();
                // For a counter-clockwise polygon, normal × edge points inside.
                let inward = polygon.normal.cross(dir).normalize_or_zero();
                (dir != Vec3::ZERO).then_some((a, dir, inward))
            })
            .collect::<Vec<_>>();
        // A polygon of many edges (a disc of thousands of vertices) finds
        // the edges near a vertex through a grid rather than testing them
        // all.
        let near = (edges.len() > EDGE_GRID_MIN && distance != 0.0)
            .then(|| EdgeGrid::new(v, extent, tolerance));
        Inset {
            edges,
            tolerance,
            distance,
            near,
            candidates: Vec::new(),
        }
    }

    /// The evaluation point of a vertex at `p`.
    fn at(&mut self, p: Vec3) -> Vec3 {
        if self.distance == 0.0 {
            return p;
        }
        let tolerance = self.tolerance;
        let mut inward_sum = Vec3::ZERO;
        let mut test = |&(a, dir, inward): &(Vec3, Vec3, Vec3)| {
            let rel = p - a;
            let off_line = rel - rel.dot(dir) * dir;
            if off_line.length() <= tolerance {
                inward_sum += inward;
            }
        };
        match &self.near {
            None => self.edges.iter().flatten().for_each(&mut test),
            Some(grid) => {
                // In edge order, as the loop over every edge adds them.
                grid.near(p, &mut self.candidates);
                self.candidates
                    .iter()
                    .filter_map(|&k| self.edges[k as usize].as_ref())
                    .for_each(&mut test);
            }
        }
        let length = inward_sum.length();
        if length == 0.0 {
            return p;
        }
        let toward = inward_sum / length;
        // At a corner the moves along both edges' normals add up (a right
        // angle's sample is `distance` from both edges); at an acute
        // apex they nearly cancel, so the move is at least `distance`,
        // along the bisector.
        let mut reach = self.distance * length.max(1.0);
        if self.near.is_none() {
            // Inside the polygon: at most a share of the way across it.
            reach = reach.min(INSET_CLAMP * self.across(p, toward));
        }
        p + toward * reach
    }

    /// How far from `p` (on or inside the polygon) along the unit in-plane
    /// direction `toward` the polygon's boundary lies, scene units.
    fn across(&self, p: Vec3, toward: Vec3) -> f32 {
        self.edges
            .iter()
            .flatten()
            .filter_map(|&(a, _, inward)| {
                let closing = -inward.dot(toward);
                let gap = inward.dot(p - a);
                (closing > 1e-6 && gap > self.tolerance).then(|| gap / closing)
            })
            .fold(f32::INFINITY, f32::min)
    }
}

/// Edges above which [`inset_positions`] looks edges up in an
/// [`EdgeGrid`].
const EDGE_GRID_MIN: usize = 32;

/// The share of the way across the polygon a vertex's sample moves at
/// most (see the module docs), for polygons of at most 32 edges: a
/// sliver's width, not the element size, bounds it there. Measured on
/// Godot's `zdm2.glb` (its camera, a 1,024-sample path-traced
/// reference): 3.69 % at a quarter of the way, 3.15 % at half, 3.34 %
/// unclamped, where samples left their polygon.
pub const INSET_CLAMP: f32 = 0.5;

/// A polygon's boundary edges binned in cubic cells by their bounds grown
/// by the on-edge tolerance: the edges a point may lie on are those of
/// its cell.
struct EdgeGrid {
    cell: f32,
    bins: HashMap<[i32; 3], Vec<u32>>,
}

impl EdgeGrid {
    fn new(v: &[Vec3], extent: f32, tolerance: f32) -> EdgeGrid {
        let n = v.len();
        // About one edge's length a cell, so each edge meets a few; at
        // least an eighth of the longest edge, so none meets more than
        // 9 × 9 × 9.
        let longest = (0..n)
            .map(|k| v[k].distance(v[(k + 1) % n]))
            .fold(0.0f32, f32::max);
        let cell = (extent / (n as f32).sqrt())
            .max(longest / 8.0)
            .max(4.0 * tolerance)
            .max(f32::MIN_POSITIVE);
        let mut grid = EdgeGrid {
            cell,
            bins: HashMap::new(),
        };
        for k in 0..n {
            let (a, b) = (v[k], v[(k + 1) % n]);
            let (lo, hi) = (
                grid.key(a.min(b) - Vec3::splat(tolerance)),
                grid.key(a.max(b) + Vec3::splat(tolerance)),
            );
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        grid.bins.entry([x, y, z]).or_default().push(k as u32);
                    }
                }
            }
        }
        grid
    }

    fn key(&self, p: Vec3) -> [i32; 3] {
        (p / self.cell).floor().to_array().map(|x| x as i32)
    }

    /// The edges (their first vertex's index) whose grown bounds may hold
    /// `p`, ascending, into `out`.
    fn near(&self, p: Vec3, out: &mut Vec<u32>) {
        out.clear();
        if let Some(edges) = self.bins.get(&self.key(p)) {
            out.extend_from_slice(edges);
        }
    }
}

impl Mesh {
    /// Number of element vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Area of an element in square scene units (exact for planar
    /// triangles and quads).
    pub fn element_area(&self, e: &Element) -> f64 {
        e.triangles()
            .map(|[a, b, c]| {
                let (a, b, c) = (
                    self.positions[a.index()].as_dvec3(),
                    self.positions[b.index()].as_dvec3(),
                    self.positions[c.index()].as_dvec3(),
                );
                (b - a).cross(c - a).length() * 0.5
            })
            .sum()
    }

    /// The area each vertex stands for: every element gives an equal share
    /// of its area to each of its corners. Sums to the polygon's area over
    /// the polygon's vertices, so `Σ area × radiosity` is a polygon's power.
    pub fn vertex_areas(&self) -> Vec<f64> {
        let mut areas = vec![0.0; self.vertex_count()];
        for e in &self.elements {
            let share = self.element_area(e) / e.corners().len() as f64;
            for c in e.corners() {
                areas[c.index()] += share;
            }
        }
        areas
    }

    /// Each of polygon `pm`'s vertices' weight in the polygon's mean
    /// (summing to 1, in vertex order): `1/n` on a regular mesh
    /// (`levels == 0`, not stitched), where every vertex stands for the same area as in
    /// the original algorithm; its share of the polygon's area
    /// ([`Mesh::vertex_areas`]) on a refined one, where vertices crowd
    /// the refined parts and an even weight would over-count them.
    pub fn polygon_vertex_weights(&self, pm: &PolygonMesh) -> Vec<f64> {
        let n = pm.vertex_count() as usize;
        if (pm.levels == 0 && !pm.stitched) || n == 0 {
            return vec![1.0 / n.max(1) as f64; n];
        }
        let mut areas = vec![0.0; n];
        for e in &self.elements[pm.elements.start as usize..pm.elements.end as usize] {
            let share = self.element_area(e) / e.corners().len() as f64;
            for c in e.corners() {
                areas[(c.0 - pm.vertices.start) as usize] += share;
            }
        }
        let total: f64 = areas.iter().sum();
        if total > 0.0 {
            areas.iter_mut().for_each(|a| *a /= total);
        }
        areas
    }

    /// The mesh as drawn and exported: without the vertices and elements of
    /// sky facets ([`PolygonMesh::sky`]), with `values` (one per vertex of
    /// this mesh: a radiosity, say) kept for the vertices that stay. Every
    /// polygon keeps its index, so [`Mesh::vertex_polygon`] and
    /// [`Mesh::element_polygon`] still name scene polygons; a sky facet's
    /// ranges are empty. `None` when there is no sky (use this mesh).
    pub fn without_sky<T: Clone>(&self, values: &[T]) -> Option<(Mesh, Vec<T>)> {
        if !self.polygons.iter().any(|pm| pm.sky) {
            return None;
        }
        let mut new_index = vec![u32::MAX; self.vertex_count()];
        let mut out = Mesh {
            positions: Vec::new(),
            sample_positions: Vec::new(),
            vertex_polygon: Vec::new(),
            elements: Vec::new(),
            element_polygon: Vec::new(),
            polygons: Vec::with_capacity(self.polygons.len()),
        };
        let mut kept = Vec::new();
        for pm in &self.polygons {
            let (v_start, e_start) = (out.positions.len() as u32, out.elements.len() as u32);
            if !pm.sky {
                for l in pm.vertices.clone() {
                    let l = l as usize;
                    new_index[l] = out.positions.len() as u32;
                    out.positions.push(self.positions[l]);
                    out.sample_positions.push(self.sample_positions[l]);
                    out.vertex_polygon.push(self.vertex_polygon[l]);
                    kept.extend(values.get(l).cloned());
                }
                for e in pm.elements.clone() {
                    let mut element = self.elements[e as usize];
                    // A triangle's repeated fourth corner is renumbered too.
                    for c in &mut element.corners {
                        *c = VertexId(new_index[c.index()]);
                    }
                    out.elements.push(element);
                    out.element_polygon.push(self.element_polygon[e as usize]);
                }
            }
            let mut polygon = pm.clone();
            polygon.vertices = v_start..out.positions.len() as u32;
            polygon.elements = e_start..out.elements.len() as u32;
            out.polygons.push(polygon);
        }
        Some((out, kept))
    }

    /// Checks the structural invariants; returns the first broken one.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.vertex_count();
        if self.sample_positions.len() != n || self.vertex_polygon.len() != n {
            return Err("per-vertex arrays differ in length".into());
        }
        if self.element_polygon.len() != self.elements.len() {
            return Err("per-element arrays differ in length".into());
        }
        let (mut next_v, mut next_e) = (0u32, 0u32);
        for (index, pm) in self.polygons.iter().enumerate() {
            let id = PolygonId(index as u32);
            if pm.vertices.start != next_v || pm.elements.start != next_e {
                return Err(format!("polygon {index}: ranges are not contiguous"));
            }
            next_v = pm.vertices.end;
            next_e = pm.elements.end;
            for v in pm.vertices.clone() {
                if self.vertex_polygon[v as usize] != id {
                    return Err(format!("vertex {v} is not marked as polygon {index}'s"));
                }
            }
            for e in pm.elements.clone() {
                if self.element_polygon[e as usize] != id {
                    return Err(format!("element {e} is not marked as polygon {index}'s"));
                }
                for c in self.elements[e as usize].corners() {
                    if !pm.vertices.contains(&c.0) {
                        return Err(format!(
                            "element {e} uses vertex {} of another polygon",
                            c.0
                        ));
                    }
                }
            }
        }
        if next_v as usize != n || next_e as usize != self.elements.len() {
            return Err("polygon ranges do not cover the arrays".into());
        }
        if self
            .positions
            .iter()
            .chain(&self.sample_positions)
            .any(|p| !p.is_finite())
        {
            return Err("a vertex position is not finite".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
