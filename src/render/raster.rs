//! A software z-buffer rasterizer that draws the element mesh with Gouraud
//! shading of the per-vertex radiosity.
//!
//! Each element is split into its triangles
//! ([`Element::triangles`](crate::mesh::Element::triangles)). A triangle is
//! taken to camera space, clipped (Sutherland–Hodgman) against
//! the near plane and a guard band around the picture, projected, snapped to
//! a grid of `1 / 2^SUBPIXEL_BITS` pixel, and filled with exact integer edge
//! functions at pixel centres under the top-left rule, so triangles that
//! share an edge cover each pixel along it exactly once. Radiosity and depth
//! are interpolated perspective-correctly (linear in `1 / z`), and the
//! nearest surface wins the depth test.
//!
//! Only the front of a polygon reflects or emits light: triangles seen from
//! the back hold no light (`0` in the linear frame, flagged in
//! [`Frame::back`]) but still hide what is behind them, unless another
//! polygon is that back side (a two-sided face's back copy), which then
//! draws it. Tone mapping paints back faces in dim blue-grey diagonal
//! stripes ([`super::back_face_color`]), never black, so an eye that
//! walked through a wall sees where it is. Overlapping coplanar polygons are stacked by their draw
//! layer ([`LAYER_DEPTH_BIAS`]).
//!
//! Work is parallel in two stages. Setup transforms and classifies every
//! mesh vertex once (camera space, which side of each clip plane, its
//! projection), then runs of consecutive elements are turned into screen
//! triangles, each run sorted by a counting sort into screen tiles of
//! `TILE_WIDTH × TILE_HEIGHT` pixels by bounding box. Drawing then fills
//! one row of tiles per work item, each tile walking only its own
//! triangles, runs in mesh order and each run's bin in mesh order. No
//! pixel belongs to two tiles and every pixel sees its triangles in mesh
//! order, so the result is the same bits whatever the number of threads,
//! and the same bits as drawing every triangle over the whole picture (a
//! test holds the two together).

use super::view::View;
use crate::cancel::{Cancel, Cancelled};
use crate::color::Rgb;
use crate::mesh::{Mesh, VertexId};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::ops::Range;
use thiserror::Error;

/// Relative depth by which each draw layer is pulled towards the eye:
/// far above the rounding of depths interpolated from `f32` vertices
/// (1e-7 relative), far below any gap a model means (a stack of
/// [`crate::scene::MAX_DRAW_LAYER`] layers moves 0.014 % of the depth).
pub const LAYER_DEPTH_BIAS: f64 = 2e-5;

/// Bits of sub-pixel precision of the snapped screen coordinates.
///
/// Vertices are snapped to `1 / 256` pixel so the edge tests can be done in
/// exact integer arithmetic: a shared edge then gives exactly opposite edge
/// values in its two triangles, which is what makes the fill rule watertight.
pub const SUBPIXEL_BITS: u32 = 8;

/// How far beyond the picture triangles are kept before they are clipped
/// at the sides, in half picture sizes measured from the picture centre.
///
/// With `2.0` the clip planes lie one picture width (height) beyond each
/// edge, so the extra vertices clipping makes are never inside the picture,
/// while screen coordinates stay small enough for exact `i64` edge tests.
pub const GUARD_BAND: f64 = 2.0;

/// Width of the screen tiles triangles are binned into, in pixels.
///
/// Each tile only walks the triangles whose bounding box overlaps it.
/// 32×32, 64×64, 64×8 and 128×8 were measured on the render bench too
/// (`docs/performance.md`): none was clearly faster.
const TILE_WIDTH: usize = 64;

/// Height of the screen tiles, in pixels. A row of tiles (a band of this
/// many pixel rows) is one parallel work item, so the buffers it writes are
/// one contiguous slice each.
const TILE_HEIGHT: usize = 16;

/// Fewest elements per parallel work item of triangle setup: below this,
/// handing out the work costs more than it saves.
const MIN_SETUP_CHUNK: usize = 256;

/// Setup work items per thread, so that a slow chunk (many clipped
/// triangles) does not leave the other threads idle.
const SETUP_CHUNKS_PER_THREAD: usize = 4;

/// Row spans of at least this many pixels are cut to the triangle
/// arithmetically; shorter ones test every pixel (three integer divisions
/// cost more than a few edge tests).
const SPAN_MIN_WIDTH: i64 = 8;

/// Clip planes: the near plane and four guard-band planes.
const CLIP_PLANES: usize = 5;

/// Most vertices a triangle can have after clipping against the
/// [`CLIP_PLANES`] (each plane adds at most one).
const MAX_CLIPPED: usize = 8;

/// Sub-pixel grid steps per pixel.
const SUBPIXEL: i64 = 1 << SUBPIXEL_BITS;

/// A rendered picture of linear radiosity.
///
/// Invariants: `pixels.len() == covered.len() == back.len() == width *
/// height`, all row-major with row 0 at the top of the picture.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB radiosity seen at each pixel centre, in the scene's
    /// radiosity units (exitance). Background and back faces are `0`: only
    /// light is stored here (EXR and PFM pictures write it as it is).
    pub pixels: Vec<[f32; 3]>,
    /// Whether any surface (front or back) covers the pixel centre.
    pub covered: Vec<bool>,
    /// Fraction of the pixel that shows the back of a polygon, in `[0, 1]`:
    /// `0` or `1` as drawn, the fraction of its samples once antialiased
    /// ([`super::antialias::downsample`]). Linear pixels hold no light
    /// there (`0`); 8-bit pictures paint it ([`super::to_srgb8`]).
    pub back: Vec<f32>,
}

impl Frame {
    /// An empty (all background) frame of the given size.
    pub fn new(width: u32, height: u32) -> Frame {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            pixels: vec![[0.0; 3]; n],
            covered: vec![false; n],
            back: vec![0.0; n],
        }
    }

    /// Number of pixels, `width * height`.
    pub fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// True when the frame has no pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True when the buffers have the length the size promises.
    pub fn is_consistent(&self) -> bool {
        self.pixels.len() == self.len()
            && self.covered.len() == self.len()
            && self.back.len() == self.len()
    }

    /// The pixel at column `x`, row `y` (row 0 at the top); `None` outside
    /// the frame.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[f32; 3]> {
        self.index(x, y).and_then(|i| self.pixels.get(i).copied())
    }

    /// Whether the pixel at column `x`, row `y` is covered; `false` outside
    /// the frame.
    pub fn is_covered(&self, x: u32, y: u32) -> bool {
        self.index(x, y)
            .and_then(|i| self.covered.get(i).copied())
            .unwrap_or(false)
    }

    fn index(&self, x: u32, y: u32) -> Option<usize> {
        (x < self.width && y < self.height).then(|| y as usize * self.width as usize + x as usize)
    }

    /// Sets the size, keeping the buffers' contents where the length is
    /// unchanged (the rasterizer clears them in parallel); returns the
    /// number of pixels. Stops with [`Cancelled`] once `cancel` is set,
    /// the frame then to be drawn again before use.
    fn resize(&mut self, width: u32, height: u32, cancel: &Cancel) -> Result<usize, Cancelled> {
        let n = width as usize * height as usize;
        self.width = width;
        self.height = height;
        resize_cancellable(&mut self.pixels, n, [0.0; 3], cancel)?;
        resize_cancellable(&mut self.covered, n, false, cancel)?;
        resize_cancellable(&mut self.back, n, 0.0, cancel)?;
        Ok(n)
    }
}

/// Elements a buffer grows by between two looks at the token in
/// [`resize_cancellable`]: a few megabytes, milliseconds to fill.
const RESIZE_CHUNK: usize = 1 << 20;

/// `v.resize(n, value)`, growing [`RESIZE_CHUNK`] elements at a time and
/// stopping with [`Cancelled`] once `cancel` is set: filling the buffers
/// of the largest picture takes seconds on a busy machine.
fn resize_cancellable<T: Clone>(
    v: &mut Vec<T>,
    n: usize,
    value: T,
    cancel: &Cancel,
) -> Result<(), Cancelled> {
    if n <= v.len() {
        v.truncate(n);
        return Ok(());
    }
    v.reserve_exact(n - v.len());
    while v.len() < n {
        cancel.check()?;
        let len = (v.len() + RESIZE_CHUNK).min(n);
        v.resize(len, value.clone());
    }
    Ok(())
}

/// Why a mesh and its radiosities cannot be drawn.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum RenderError {
    /// There must be one radiosity per mesh vertex.
    #[error("{found} radiosity values for a mesh of {expected} vertices")]
    RadiosityCount {
        /// Number of mesh vertices.
        expected: usize,
        /// Number of radiosity values given.
        found: usize,
    },
    /// The mesh's arrays disagree (a bug in whoever built it).
    #[error("inconsistent mesh: {0}")]
    BadMesh(String),
    /// The run's cancellation token was set while drawing
    /// ([`Rasterizer::render_cancellable`]); the picture is incomplete.
    #[error("{0}")]
    Cancelled(#[from] crate::cancel::Cancelled),
}

/// The z-buffer rasterizer. It owns the colour, coverage and depth buffers
/// and the screen triangles with their tile bins, and reuses them from one
/// picture to the next (the viewer redraws after every solver step).
#[derive(Clone, Debug)]
pub struct Rasterizer {
    frame: Frame,
    /// Per pixel, `1 / z` of the nearest surface so far (`0` = nothing).
    inv_depth: Vec<f64>,
    /// Per pixel, whether the nearest surface so far is a front face.
    front: Vec<bool>,
    /// Per mesh vertex, its projection in the current view.
    vertices: Vec<ProjectedVertex>,
    /// The screen triangles of consecutive runs of elements, in mesh order,
    /// each run with its own tile bins.
    batches: Vec<Batch>,
}

impl Default for Rasterizer {
    fn default() -> Self {
        Rasterizer::new()
    }
}

impl Rasterizer {
    /// A rasterizer with empty buffers; they are sized by the first view.
    pub fn new() -> Rasterizer {
        Rasterizer {
            frame: Frame::new(0, 0),
            inv_depth: Vec::new(),
            front: Vec::new(),
            vertices: Vec::new(),
            batches: Vec::new(),
        }
    }

    /// The last picture drawn (empty before the first).
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Per pixel of the last picture, row-major from the top, `1 / z` of
    /// the nearest surface (`z` the camera-space depth in scene units; 0
    /// where nothing was drawn). Overlays use it for their depth test.
    pub fn inv_depth(&self) -> &[f64] {
        &self.inv_depth
    }

    /// Per pixel of the last picture, row-major from the top, whether the
    /// nearest surface is a front face: `false` for back faces and for
    /// background. With [`Frame::covered`] it tells the three apart (see
    /// [`super::PictureCoverage`]).
    pub fn front_faces(&self) -> &[bool] {
        &self.front
    }

    /// Draws `mesh` seen through `view`, shading every element vertex with
    /// its linear `radiosity` (one per mesh vertex, in the scene's radiosity
    /// units), and returns the picture, sized as the view.
    ///
    /// Front faces show the Gouraud-interpolated radiosity; back faces are
    /// `0` with [`Frame::back`] set to 1; uncovered pixels are `0` and not
    /// `covered`. Sky facets
    /// ([`crate::mesh::PolygonMesh::sky`]) are not drawn: where the sky is
    /// seen, the picture shows background.
    pub fn render(
        &mut self,
        mesh: &Mesh,
        radiosity: &[Rgb],
        view: &View,
    ) -> Result<&Frame, RenderError> {
        self.render_cancellable(mesh, radiosity, view, &Cancel::never())
    }

    /// [`Rasterizer::render`], stopping with [`RenderError::Cancelled`]
    /// soon after `cancel` is set: it is checked per run of elements set
    /// up and per band of tiles drawn, each far below a tenth of a second.
    pub fn render_cancellable(
        &mut self,
        mesh: &Mesh,
        radiosity: &[Rgb],
        view: &View,
        cancel: &Cancel,
    ) -> Result<&Frame, RenderError> {
        check_mesh(mesh, radiosity)?;
        let (width, height) = (view.width(), view.height());
        let n = self.frame.resize(width, height, cancel)?;
        // Cleared band by band below, in parallel.
        resize_cancellable(&mut self.inv_depth, n, 0.0, cancel)?;
        resize_cancellable(&mut self.front, n, false, cancel)?;

        let w = width as usize;
        let tiles_x = w.div_ceil(TILE_WIDTH);
        let tiles = tiles_x * (height as usize).div_ceil(TILE_HEIGHT);
        self.setup(mesh, radiosity, view, tiles_x, tiles, cancel);
        cancel.check()?;

        let batches = &self.batches;
        let vertices = &self.vertices;
        self.frame
            .pixels
            .par_chunks_mut(TILE_HEIGHT * w)
            .zip(self.frame.covered.par_chunks_mut(TILE_HEIGHT * w))
            .zip(self.inv_depth.par_chunks_mut(TILE_HEIGHT * w))
            .zip(self.front.par_chunks_mut(TILE_HEIGHT * w))
            .zip(self.frame.back.par_chunks_mut(TILE_HEIGHT * w))
            .enumerate()
            .for_each(|(ty, ((((pixels, covered), depth), front), back))| {
                pixels.fill([0.0; 3]);
                covered.fill(false);
                depth.fill(0.0);
                front.fill(false);
                back.fill(0.0);
                let mut target = Band {
                    width: w,
                    first_row: ty * TILE_HEIGHT,
                    rows: pixels.len() / w,
                    pixels,
                    covered,
                    depth,
                    front,
                    back,
                };
                for tx in 0..tiles_x {
                    if cancel.is_set() {
                        return;
                    }
                    let tile = ty * tiles_x + tx;
                    let columns = tx * TILE_WIDTH..((tx + 1) * TILE_WIDTH).min(w);
                    // Batches in mesh order, each bin in mesh order: every
                    // pixel sees the triangles in mesh order, whatever the
                    // tiles and threads.
                    for batch in batches {
                        for &i in batch.tile(tile) {
                            let t = &batch.triangles[i as usize];
                            target.draw(t, batch.vertices(t, vertices), columns.clone());
                        }
                    }
                }
            });
        cancel.check()?;
        Ok(&self.frame)
    }

    /// Transforms, clips, projects and bins every element's triangles, in
    /// parallel: first every mesh vertex (camera space, which side of each
    /// clip plane, projection), then runs of elements, which keep mesh
    /// order.
    fn setup(
        &mut self,
        mesh: &Mesh,
        radiosity: &[Rgb],
        view: &View,
        tiles_x: usize,
        tiles: usize,
        cancel: &Cancel,
    ) {
        let setup = Setup::new(view);
        self.vertices
            .resize(mesh.positions.len(), ProjectedVertex::default());
        self.vertices
            .par_iter_mut()
            .zip(mesh.positions.par_iter().zip(radiosity.par_iter()))
            .with_min_len(4096)
            .for_each(|(out, (&p, c))| {
                *out = setup.vertex(view.to_camera(p).as_dvec3(), c.to_array())
            });

        let elements = mesh.elements.len();
        let chunk = elements
            .div_ceil(SETUP_CHUNKS_PER_THREAD * rayon::current_num_threads())
            .max(MIN_SETUP_CHUNK);
        self.batches
            .resize_with(elements.div_ceil(chunk), Batch::default);
        let vertices = &self.vertices;
        self.batches
            .par_iter_mut()
            .enumerate()
            .for_each(|(k, batch)| {
                batch.triangles.clear();
                batch.local.clear();
                if cancel.is_set() {
                    return;
                }
                for e in k * chunk..((k + 1) * chunk).min(elements) {
                    // Checked by `check_mesh`: every index below is in range.
                    let polygon = &mesh.polygons[mesh.element_polygon[e].index()];
                    // The sky lights the scene; it is not part of the picture.
                    if polygon.sky {
                        continue;
                    }
                    for tri in mesh.elements[e].triangles() {
                        // Which side the eye is on decides lit or black: the
                        // polygon's plane is the same for all its triangles,
                        // so a polygon is never half lit.
                        let front = polygon
                            .normal
                            .dot(view.eye() - mesh.positions[tri[0].index()])
                            > 0.0;
                        // Its back side is another polygon, drawn on its own.
                        if !front && polygon.has_back {
                            continue;
                        }
                        let p = tri.map(|v| &vertices[v.index()]);
                        // Clipping plane by plane, in order, while the triangle
                        // is still whole: a plane with every corner inside
                        // leaves it as it is, one with every corner outside
                        // removes it, the first other one cuts it.
                        let not_inside = p[0].not_inside | p[1].not_inside | p[2].not_inside;
                        if not_inside == 0 {
                            if p.iter().all(|p| p.valid) {
                                let screen = [&p[0].screen, &p[1].screen, &p[2].screen];
                                if let Some(t) =
                                    setup.triangle(tri.map(|v| v.0), screen, front, polygon.layer)
                                {
                                    batch.triangles.push(t);
                                }
                            }
                            continue;
                        }
                        let first = not_inside.trailing_zeros() as usize;
                        if (p[0].outside & p[1].outside & p[2].outside) & (1 << first) != 0 {
                            continue;
                        }
                        let corner = |v: VertexId| ClipVertex {
                            p: view.to_camera(mesh.positions[v.index()]).as_dvec3(),
                            c: radiosity[v.index()].to_array(),
                        };
                        setup.push_clipped(
                            [corner(tri[0]), corner(tri[1]), corner(tri[2])],
                            front,
                            polygon.layer,
                            first,
                            &mut batch.local,
                            &mut batch.triangles,
                        );
                    }
                }
                batch.sort_into_tiles(tiles_x, tiles);
            });
    }
}

/// Marks a [`ScreenTriangle`] vertex index as one of its batch's own
/// vertices (made by clipping) rather than a mesh vertex.
const LOCAL_VERTEX: u32 = 1 << 31;

/// A mesh vertex in the current view.
#[derive(Clone, Copy, Debug, Default)]
struct ProjectedVertex {
    /// Its projection with its radiosity; meaningful when `valid`.
    screen: ScreenVertex,
    /// Whether the projection is finite (the vertex is in front of the eye).
    valid: bool,
    /// Bit `k` set when the vertex is not inside clip plane `k`
    /// (`!(distance >= 0)`, so NaN counts).
    not_inside: u8,
    /// Bit `k` set when the vertex is outside clip plane `k`
    /// (`distance < 0`).
    outside: u8,
}

/// The screen triangles of a run of consecutive elements, in mesh order,
/// and which of them overlap each screen tile.
#[derive(Clone, Debug, Default)]
struct Batch {
    triangles: Vec<ScreenTriangle>,
    /// The vertices clipping made, which the triangles name with
    /// [`LOCAL_VERTEX`] set.
    local: Vec<ScreenVertex>,
    /// Tile `t`'s triangles are `entries[start[t]..start[t + 1]]`,
    /// ascending indices into `triangles`; `start` has one entry per tile
    /// and one more.
    start: Vec<u32>,
    entries: Vec<u32>,
    /// Where the next entry of each tile goes while binning.
    cursor: Vec<u32>,
}

impl Batch {
    /// Sorts the triangles into the tiles their pixel bounding boxes
    /// overlap (a counting sort, so each bin keeps mesh order).
    fn sort_into_tiles(&mut self, tiles_x: usize, tiles: usize) {
        let tiles_of = |t: &ScreenTriangle| {
            let (x0, x1) = (t.x0 as usize / TILE_WIDTH, t.x1 as usize / TILE_WIDTH);
            (t.y0 as usize / TILE_HEIGHT..=t.y1 as usize / TILE_HEIGHT)
                .flat_map(move |ty| (x0..=x1).map(move |tx| ty * tiles_x + tx))
        };
        self.start.clear();
        self.start.resize(tiles + 1, 0);
        for t in &self.triangles {
            for tile in tiles_of(t) {
                self.start[tile + 1] += 1;
            }
        }
        for i in 1..=tiles {
            self.start[i] += self.start[i - 1];
        }
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.start[..tiles]);
        self.entries.clear();
        self.entries.resize(self.start[tiles] as usize, 0);
        for (i, t) in self.triangles.iter().enumerate() {
            for tile in tiles_of(t) {
                self.entries[self.cursor[tile] as usize] = i as u32;
                self.cursor[tile] += 1;
            }
        }
    }

    /// The three vertices of a triangle of this batch.
    fn vertices<'a>(
        &'a self,
        t: &ScreenTriangle,
        mesh: &'a [ProjectedVertex],
    ) -> [&'a ScreenVertex; 3] {
        t.v.map(|i| {
            if i & LOCAL_VERTEX != 0 {
                &self.local[(i & !LOCAL_VERTEX) as usize]
            } else {
                &mesh[i as usize].screen
            }
        })
    }

    /// Indices of the triangles overlapping `tile`, ascending.
    fn tile(&self, tile: usize) -> &[u32] {
        &self.entries[self.start[tile] as usize..self.start[tile + 1] as usize]
    }
}

/// Checks that every index the rasterizer follows is in range, so that
/// drawing cannot panic on a malformed mesh.
fn check_mesh(mesh: &Mesh, radiosity: &[Rgb]) -> Result<(), RenderError> {
    let n = mesh.positions.len();
    if radiosity.len() != n {
        return Err(RenderError::RadiosityCount {
            expected: n,
            found: radiosity.len(),
        });
    }
    if mesh.element_polygon.len() != mesh.elements.len() {
        return Err(RenderError::BadMesh(format!(
            "{} elements but {} element polygons",
            mesh.elements.len(),
            mesh.element_polygon.len()
        )));
    }
    for (e, (element, polygon)) in mesh.elements.iter().zip(&mesh.element_polygon).enumerate() {
        if polygon.index() >= mesh.polygons.len() {
            return Err(RenderError::BadMesh(format!(
                "element {e} belongs to polygon {} of {}",
                polygon.index(),
                mesh.polygons.len()
            )));
        }
        if let Some(v) = element.corners().iter().find(|v| v.index() >= n) {
            return Err(RenderError::BadMesh(format!(
                "element {e} uses vertex {} of {n}",
                v.index()
            )));
        }
    }
    Ok(())
}

/// A vertex during clipping: camera-space position and linear radiosity.
#[derive(Clone, Copy, Debug, Default)]
struct ClipVertex {
    p: DVec3,
    c: [f64; 3],
}

/// A convex polygon of at most [`MAX_CLIPPED`] vertices, on the stack.
#[derive(Clone, Copy)]
struct ClipPolygon {
    v: [ClipVertex; MAX_CLIPPED],
    len: usize,
}

impl ClipPolygon {
    fn push(&mut self, v: ClipVertex) {
        // Each plane adds at most one vertex to a convex polygon, so a
        // triangle never exceeds the capacity; the guard keeps a numerically
        // odd case from panicking.
        if self.len < MAX_CLIPPED {
            self.v[self.len] = v;
            self.len += 1;
        }
    }
}

/// The edge from `inside` to `outside` cut where the plane distance is zero.
///
/// Always computed from the inside vertex, whichever way the polygon walks
/// the edge, so two triangles sharing an edge get bit-identical cut points.
fn cut(inside: &ClipVertex, d_in: f64, outside: &ClipVertex, d_out: f64) -> ClipVertex {
    let t = d_in / (d_in - d_out);
    let lerp = |a: f64, b: f64| a + (b - a) * t;
    ClipVertex {
        p: inside.p + (outside.p - inside.p) * t,
        c: [
            lerp(inside.c[0], outside.c[0]),
            lerp(inside.c[1], outside.c[1]),
            lerp(inside.c[2], outside.c[2]),
        ],
    }
}

/// One Sutherland–Hodgman pass: keeps the part where `distance >= 0`.
fn clip(poly: &ClipPolygon, distance: impl Fn(DVec3) -> f64) -> ClipPolygon {
    let mut out = ClipPolygon {
        v: [ClipVertex::default(); MAX_CLIPPED],
        len: 0,
    };
    if poly.len == 0 {
        return out;
    }
    let mut prev = poly.v[poly.len - 1];
    let mut d_prev = distance(prev.p);
    for &cur in &poly.v[..poly.len] {
        let d_cur = distance(cur.p);
        // NaN distances fail both tests: such a vertex is dropped.
        if d_cur >= 0.0 {
            if d_prev < 0.0 {
                out.push(cut(&cur, d_cur, &prev, d_prev));
            }
            out.push(cur);
        } else if d_prev >= 0.0 {
            out.push(cut(&prev, d_prev, &cur, d_cur));
        }
        prev = cur;
        d_prev = d_cur;
    }
    out
}

/// A projected vertex: snapped pixel position and the values interpolated
/// linearly in screen space.
#[derive(Clone, Copy, Debug, Default)]
struct ScreenVertex {
    /// Position in `1 / SUBPIXEL` pixels.
    x: i64,
    y: i64,
    /// `1 / z`, z the camera-space depth.
    inv_z: f64,
    /// Radiosity divided by z.
    c_over_z: [f64; 3],
}

/// A triangle ready to fill: positive area (clockwise on screen, y down),
/// per-edge fill-rule bias and a pixel bounding box inside the picture.
#[derive(Clone, Copy, Debug)]
struct ScreenTriangle {
    /// Its vertices, clockwise on screen: mesh vertex indices, or with
    /// [`LOCAL_VERTEX`] set indices into its batch's clipped vertices.
    v: [u32; 3],
    /// Twice the area in squared sub-pixel units, `> 0`.
    area: i64,
    /// Per edge opposite vertex `i`: `0` for top-left edges (pixel centres
    /// exactly on them are inside), `1` otherwise.
    bias: [u8; 3],
    /// Whether the eye sees the front of the triangle's polygon.
    front: bool,
    /// Its polygon's draw layer ([`crate::mesh::PolygonMesh::layer`]).
    layer: u8,
    /// Inclusive pixel bounds: columns `x0..=x1`, rows `y0..=y1` (a picture
    /// side is at most [`crate::camera::MAX_PICTURE_SIDE`]).
    x0: u32,
    x1: u32,
    y0: u32,
    y1: u32,
}

/// Edge function of the edge `a → b` at `(px, py)`: twice the signed area of
/// `a, b, p`, exact in `i64` for coordinates within the guard band.
fn edge(a: &ScreenVertex, b: &ScreenVertex, px: i64, py: i64) -> i64 {
    (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x)
}

/// Top-left rule for triangles with positive edge functions inside
/// (clockwise on a y-down screen): a top edge runs exactly horizontally to
/// the right, a left edge runs upwards.
fn is_top_left(a: &ScreenVertex, b: &ScreenVertex) -> bool {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    dy < 0 || (dy == 0 && dx > 0)
}

/// Per-view constants of triangle setup.
struct Setup {
    near: f64,
    /// Guard-band half sizes in pixels times `z / focal` (see `push`).
    guard_x: f64,
    guard_y: f64,
    focal: f64,
    width: f64,
    height: f64,
}

impl Setup {
    fn new(view: &View) -> Self {
        let width = f64::from(view.width());
        let height = f64::from(view.height());
        Setup {
            near: f64::from(view.near()),
            guard_x: GUARD_BAND * width / 2.0,
            guard_y: GUARD_BAND * height / 2.0,
            focal: view.focal_px(),
            width,
            height,
        }
    }

    /// Signed distance of camera-space `p` to clip plane `k`, scaled,
    /// positive inside: the near plane, then the four guard-band planes
    /// through the eye, `|f x / z| <= gx` and `|f y / z| <= gy` multiplied
    /// by `z > 0`.
    fn distance(&self, k: usize, p: DVec3) -> f64 {
        let (f, gx, gy) = (self.focal, self.guard_x, self.guard_y);
        match k {
            0 => p.z - self.near,
            1 => gx * p.z - f * p.x,
            2 => gx * p.z + f * p.x,
            3 => gy * p.z - f * p.y,
            _ => gy * p.z + f * p.y,
        }
    }

    /// A mesh vertex at camera-space `p` with radiosity `c`: which side of
    /// each clip plane it lies, and its projection.
    fn vertex(&self, p: DVec3, c: [f64; 3]) -> ProjectedVertex {
        let (mut not_inside, mut outside) = (0, 0);
        for k in 0..CLIP_PLANES {
            let d = self.distance(k, p);
            if d.is_nan() || d < 0.0 {
                not_inside |= 1 << k;
            }
            if d < 0.0 {
                outside |= 1 << k;
            }
        }
        let screen = self.project(&ClipVertex { p, c }, true);
        ProjectedVertex {
            screen: screen.unwrap_or_default(),
            valid: screen.is_some(),
            not_inside,
            outside,
        }
    }

    /// Clips one camera-space triangle against the planes from `first` on
    /// (the earlier ones keep it whole), projects and snaps the result, and
    /// appends its screen triangles (none if it is invisible), their new
    /// vertices to `local`.
    fn push_clipped(
        &self,
        tri: [ClipVertex; 3],
        front: bool,
        layer: u8,
        first: usize,
        local: &mut Vec<ScreenVertex>,
        out: &mut Vec<ScreenTriangle>,
    ) {
        let mut poly = ClipPolygon {
            v: [ClipVertex::default(); MAX_CLIPPED],
            len: 3,
        };
        poly.v[..3].copy_from_slice(&tri);
        for k in first..CLIP_PLANES {
            poly = clip(&poly, |p| self.distance(k, p));
        }
        if poly.len < 3 {
            return;
        }
        let mut screen = [None; MAX_CLIPPED];
        for (s, v) in screen.iter_mut().zip(&poly.v[..poly.len]) {
            if let Some(p) = self.project(v, front) {
                *s = Some((local.len() as u32 | LOCAL_VERTEX, p));
                local.push(p);
            }
        }
        // A fan from the first vertex: its inner edges are shared by
        // neighbouring fan triangles with identical endpoints, so the fill
        // rule covers them once as well.
        for i in 1..poly.len - 1 {
            if let (Some(a), Some(b), Some(c)) = (screen[0], screen[i], screen[i + 1]) {
                if let Some(t) = self.triangle([a.0, b.0, c.0], [&a.1, &b.1, &c.1], front, layer) {
                    out.push(t);
                }
            }
        }
    }

    fn project(&self, v: &ClipVertex, front: bool) -> Option<ScreenVertex> {
        // `View::camera_to_pixel` with the focal length computed once.
        if v.p.z.is_nan() || v.p.z <= 0.0 {
            return None;
        }
        let pixel = DVec2::new(
            self.width / 2.0 + self.focal * v.p.x / v.p.z,
            self.height / 2.0 - self.focal * v.p.y / v.p.z,
        );
        let snap = |x: f64| (x * SUBPIXEL as f64).round();
        let (x, y) = (snap(pixel.x), snap(pixel.y));
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        let inv_z = 1.0 / v.p.z;
        // Back faces are black: their radiosity is that of the other side.
        let c = if front { v.c } else { [0.0; 3] };
        Some(ScreenVertex {
            // Within the guard band the values are far below 2^40, so the
            // conversion is exact.
            x: x as i64,
            y: y as i64,
            inv_z,
            c_over_z: [c[0] * inv_z, c[1] * inv_z, c[2] * inv_z],
        })
    }

    /// The screen triangle of vertices `v` named `index`, wound clockwise;
    /// `None` when it is degenerate or covers no pixel centre.
    fn triangle(
        &self,
        index: [u32; 3],
        v: [&ScreenVertex; 3],
        front: bool,
        layer: u8,
    ) -> Option<ScreenTriangle> {
        let area = edge(v[0], v[1], v[2].x, v[2].y);
        let (v, index) = match area.signum() {
            1 => (v, index),
            -1 => ([v[0], v[2], v[1]], [index[0], index[2], index[1]]),
            // Degenerate (edge-on or collapsed by snapping): covers nothing.
            _ => return None,
        };
        // Pixel centres are at (i + 1/2) pixels: the first column whose
        // centre is at or right of min_x, the last at or left of max_x.
        let lo = |m: i64| (m - SUBPIXEL / 2 + SUBPIXEL - 1).div_euclid(SUBPIXEL);
        let hi = |m: i64| (m - SUBPIXEL / 2).div_euclid(SUBPIXEL);
        let (min_x, max_x) = (v.iter().map(|p| p.x).min()?, v.iter().map(|p| p.x).max()?);
        let (min_y, max_y) = (v.iter().map(|p| p.y).min()?, v.iter().map(|p| p.y).max()?);
        let x0 = lo(min_x).max(0);
        let x1 = hi(max_x).min(self.width as i64 - 1);
        let y0 = lo(min_y).max(0);
        let y1 = hi(max_y).min(self.height as i64 - 1);
        if x0 > x1 || y0 > y1 {
            return None;
        }
        Some(ScreenTriangle {
            v: index,
            area: area.abs(),
            bias: [
                u8::from(!is_top_left(v[1], v[2])),
                u8::from(!is_top_left(v[2], v[0])),
                u8::from(!is_top_left(v[0], v[1])),
            ],
            front,
            layer,
            // Non-negative and inside the picture after the clamps above.
            x0: x0 as u32,
            x1: x1 as u32,
            y0: y0 as u32,
            y1: y1 as u32,
        })
    }
}

/// The rows of the picture one parallel task fills.
struct Band<'a> {
    width: usize,
    first_row: usize,
    rows: usize,
    pixels: &'a mut [[f32; 3]],
    covered: &'a mut [bool],
    depth: &'a mut [f64],
    front: &'a mut [bool],
    back: &'a mut [f32],
}

impl Band<'_> {
    /// Draws the part of `t` (with vertices `v`) in this band's rows and in
    /// `columns`.
    ///
    /// Rows wider than [`SPAN_MIN_WIDTH`] are cut to the run of pixels
    /// whose centres pass all three edge tests, solved exactly in integers
    /// from the edge functions' per-pixel steps; narrower ones test each
    /// pixel. Either way the pixels drawn are exactly those the edge tests
    /// accept.
    fn draw(&mut self, t: &ScreenTriangle, v: [&ScreenVertex; 3], columns: Range<usize>) {
        let y0 = (t.y0 as usize).max(self.first_row);
        let y1 = (t.y1 as usize).min(self.first_row + self.rows - 1);
        let x0 = (t.x0 as usize).max(columns.start);
        let x1 = (t.x1 as usize).min(columns.end.saturating_sub(1));
        if y0 > y1 || x0 > x1 {
            return;
        }
        let [a, b, c] = v;
        let bias = t.bias.map(i64::from);
        // How each edge function changes from one pixel to the next right.
        let step = [
            (b.y - c.y) * SUBPIXEL,
            (c.y - a.y) * SUBPIXEL,
            (a.y - b.y) * SUBPIXEL,
        ];
        let last = (x1 - x0) as i64;
        let px0 = x0 as i64 * SUBPIXEL + SUBPIXEL / 2;
        for y in y0..=y1 {
            let py = y as i64 * SUBPIXEL + SUBPIXEL / 2;
            let start = [
                edge(b, c, px0, py),
                edge(c, a, px0, py),
                edge(a, b, px0, py),
            ];
            let row = (y - self.first_row) * self.width;
            if last < SPAN_MIN_WIDTH {
                let mut w = start;
                for x in x0..=x1 {
                    if w[0] >= bias[0] && w[1] >= bias[1] && w[2] >= bias[2] {
                        self.shade(t, v, w, row + x);
                    }
                    w = [w[0] + step[0], w[1] + step[1], w[2] + step[2]];
                }
                continue;
            }
            // The pixels `x0 + k` with `start[i] + k * step[i] >= bias[i]`
            // for every edge `i`.
            let (mut lo, mut hi) = (0, last);
            for i in 0..3 {
                let need = bias[i] - start[i];
                match step[i].signum() {
                    1 => lo = lo.max((need + step[i] - 1).div_euclid(step[i])),
                    -1 => hi = hi.min((-need).div_euclid(-step[i])),
                    _ if need > 0 => hi = -1,
                    _ => {}
                }
            }
            if lo > hi {
                continue;
            }
            let mut w = [0; 3];
            for i in 0..3 {
                w[i] = start[i] + lo * step[i];
            }
            for x in x0 + lo as usize..=x0 + hi as usize {
                self.shade(t, v, w, row + x);
                w = [w[0] + step[0], w[1] + step[1], w[2] + step[2]];
            }
        }
    }

    /// Depth-tests and shades pixel `i` of the band, inside `t` with edge
    /// functions `w` at its centre.
    #[inline(always)]
    fn shade(&mut self, t: &ScreenTriangle, v: [&ScreenVertex; 3], w: [i64; 3], i: usize) {
        let [a, b, c] = v;
        let area = t.area as f64;
        let (l0, l1, l2) = (w[0] as f64 / area, w[1] as f64 / area, w[2] as f64 / area);
        let inv_z = l0 * a.inv_z + l1 * b.inv_z + l2 * c.inv_z;
        // A higher layer is pulled nearer by a hair, so of two overlapping
        // coplanar polygons it wins wherever rounding would have split them.
        let key = inv_z * (1.0 + f64::from(t.layer) * LAYER_DEPTH_BIAS);
        // Strictly nearer: on equal depth the first triangle drawn (in mesh
        // order, in every tile) keeps the pixel.
        if key.is_nan() || key <= self.depth[i] {
            return;
        }
        self.depth[i] = key;
        self.covered[i] = true;
        self.front[i] = t.front;
        self.back[i] = if t.front { 0.0 } else { 1.0 };
        // Back faces hold no light: their radiosity is that of the other
        // side. The 8-bit picture paints them (`to_srgb8`).
        self.pixels[i] = if t.front {
            let channel = |k: usize| {
                ((l0 * a.c_over_z[k] + l1 * b.c_over_z[k] + l2 * c.c_over_z[k]) / inv_z) as f32
            };
            [channel(0), channel(1), channel(2)]
        } else {
            [0.0; 3]
        };
    }

    /// The brute-force twin of [`Band::draw`]: every pixel of the
    /// triangle's bounding box, each tested against the three edges.
    #[cfg(test)]
    fn draw_every_pixel(&mut self, t: &ScreenTriangle, v: [&ScreenVertex; 3]) {
        let y0 = (t.y0 as usize).max(self.first_row);
        let y1 = (t.y1 as usize).min(self.first_row + self.rows - 1);
        let [a, b, c] = v;
        for y in y0..=y1 {
            let py = y as i64 * SUBPIXEL + SUBPIXEL / 2;
            let row = (y - self.first_row) * self.width;
            for x in t.x0 as usize..=t.x1 as usize {
                let px = x as i64 * SUBPIXEL + SUBPIXEL / 2;
                let w = [edge(b, c, px, py), edge(c, a, px, py), edge(a, b, px, py)];
                if (0..3).all(|k| w[k] >= i64::from(t.bias[k])) {
                    self.shade(t, v, w, row + x);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
