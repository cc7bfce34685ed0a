//! Polygon validation and classification. (placeholder; being written)

/// How a polygon is meshed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Three vertices.
    Triangle,
    /// Four vertices with `v0 + v2 == v1 + v3` (within tolerance).
    Parallelogram,
    /// Any other convex quadrilateral.
    Quad,
    /// Five or more vertices.
    Convex,
}

/// Why a list of vertices is not a valid polygon.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PolygonError {
    /// Placeholder.
    #[error("invalid polygon")]
    Invalid,
}
