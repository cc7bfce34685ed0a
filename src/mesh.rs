//! Meshing: each polygon becomes a grid of small elements whose corners
//! (element vertices) carry the radiosity.
//!
//! MESH TYPES ONLY: the builder is being written.

use crate::scene::PolygonId;
use glam::Vec3;
use std::ops::Range;

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
        Element { corners: [a, b, c, c], len: 3 }
    }

    /// A quadrilateral element.
    pub fn quad(a: VertexId, b: VertexId, c: VertexId, d: VertexId) -> Self {
        Element { corners: [a, b, c, d], len: 4 }
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
    /// quads; the subdivision count of every edge for triangles).
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
}

/// The element mesh of a whole scene, as flat arrays.
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

impl Mesh {
    /// Number of element vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
}
