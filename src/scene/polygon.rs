//! Polygon validation and classification.
//!
//! [`Polygon::new`] is the one door through which vertices become a
//! [`Polygon`]: it refuses anything the later stages cannot mesh or light
//! (too few vertices, repeated vertices, zero area, non-planar, non-convex),
//! computes the normal and area by Newell's method in `f64`, and decides the
//! [`Shape`], which picks the meshing scheme.
//!
//! All tolerances are relative to the polygon's *extent*, the largest
//! distance between two of its vertices (the convexity and planarity
//! tolerances add the rounding of its `f32` coordinates,
//! [`COORDINATE_ROUNDING`]), so a polygon means the same thing whatever
//! its unit of length and whatever else is in the scene.

use super::error::fmt_num;
use super::{MaterialId, Polygon, SourcePos, Surface};
use glam::{DVec3, Vec3};

/// How far a vertex may lie from the polygon's plane, as a fraction of the
/// polygon's extent (the format's "within 1e-3 of the largest extent"),
/// plus [`COORDINATE_ROUNDING`].
pub const PLANARITY_TOLERANCE: f64 = 1e-3;

/// Two consecutive vertices closer than this fraction of the extent count as
/// equal. Non-zero so that vertices equal up to `f32` rounding (after a
/// transform, say) are caught as what they are rather than as a fold.
pub const COINCIDENT_TOLERANCE: f64 = 1e-6;

/// A polygon whose area is below this fraction of its extent squared has
/// zero area. Coordinates are `f32`, so exactly collinear points written in
/// decimal still produce a tiny rounding area of order `1e-8 × extent²`.
pub const ZERO_AREA_TOLERANCE: f64 = 1e-7;

/// A vertex turns the wrong way (is concave) when the nearer of its two
/// neighbours lies more than this fraction of the extent (plus
/// [`COORDINATE_ROUNDING`]) on the wrong side of the line of the other
/// edge. A little on the wrong side is `f32` rounding of collinear
/// vertices, which the format allows. At a turn past a right angle, where
/// the boundary doubles back, the test is on the turn's sine instead: a
/// sine below this (the wrong way, or nearly straight back) is a fold.
pub const CONVEXITY_TOLERANCE: f64 = 1e-6;

/// How far `f32` rounding may move a vertex off the line or plane it
/// belongs to, as a fraction of the polygon's largest coordinate magnitude:
/// four units in the last place (each vertex of a corner is rounded by up
/// to half of one in each coordinate). Added to the convexity and
/// planarity tolerances, so that a polygon small against its distance from
/// the origin, whose coordinates cannot be more precise than that, is not
/// refused for their rounding. Relative to the polygon's own coordinates,
/// so scaling a polygon scales its tolerances.
pub const COORDINATE_ROUNDING: f64 = 4.0 * f32::EPSILON as f64;

/// How far, in radians, the edges' total turning may differ from one full
/// turn (`2π`) before the polygon is taken to wind around more than once.
pub const TURNING_TOLERANCE: f64 = 1e-3;

/// A quadrilateral is a parallelogram when `|v0 + v2 - v1 - v3|` is at most
/// this fraction of its extent. Loose enough for `f32` rounding after a
/// rotation, tight enough that meshing it as an exact parallelogram moves no
/// vertex visibly.
pub const PARALLELOGRAM_TOLERANCE: f64 = 1e-5;

/// Largest magnitude of a world-space coordinate, in scene units.
///
/// Geometry is `f32` and the later stages multiply up to three lengths
/// together (ray–plane tests, form factor denominators): with lengths below
/// `1e12` those products stay far below `f32::MAX` (`3.4e38`), so nothing
/// overflows to infinity or turns into NaN. A scene this large is a scene
/// in the wrong unit.
pub const MAX_COORDINATE: f64 = 1e12;

/// Smallest extent (largest distance between two vertices) of a polygon,
/// in scene units. Products of three lengths below `1e-9` come near the
/// bottom of `f32`'s normal range (`1.2e-38`), where form factors and ray
/// tests underflow to zero; such a polygon is an error (for instance a
/// `scale 0.000001` applied once too often), not a silent black speck.
pub const MIN_EXTENT: f64 = 1e-9;

/// How a polygon is meshed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Three vertices.
    Triangle,
    /// Four vertices with `v0 + v2 == v1 + v3` (within
    /// [`PARALLELOGRAM_TOLERANCE`] of the extent): meshed into congruent
    /// parallelogram elements.
    Parallelogram,
    /// Any other convex quadrilateral: meshed into a bilinear grid.
    Quad,
    /// Five or more vertices.
    Convex,
}

/// Why a list of vertices is not a valid polygon. Vertex numbers in the
/// variants and messages count from 1, in the order the vertices were given.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than three vertices.
    #[error("polygon has {count} vertices; at least 3 are needed")]
    TooFewVertices {
        /// How many there are.
        count: usize,
    },
    /// A coordinate is NaN or infinite (for instance after a huge scale).
    #[error("vertex {vertex} is not finite")]
    NotFinite {
        /// Which vertex, from 1.
        vertex: usize,
    },
    /// A coordinate's magnitude is above [`MAX_COORDINATE`].
    #[error(
        "vertex {vertex} is {} units from the origin; coordinates must be at most {} in magnitude",
        fmt_num(*.magnitude),
        fmt_num(MAX_COORDINATE)
    )]
    TooFar {
        /// Which vertex, from 1.
        vertex: usize,
        /// Its largest coordinate magnitude, in scene units.
        magnitude: f64,
    },
    /// The polygon is smaller than [`MIN_EXTENT`].
    #[error(
        "polygon is too small: its vertices are at most {} units apart, below the smallest \
         allowed size {}",
        fmt_num(*.extent),
        fmt_num(MIN_EXTENT)
    )]
    TooSmall {
        /// Its extent, in scene units.
        extent: f64,
    },
    /// Two consecutive vertices (also the last and the first) coincide.
    #[error("vertices {first} and {second} are equal")]
    EqualVertices {
        /// The earlier of the two, from 1.
        first: usize,
        /// The later of the two, from 1 (1 when `first` is the last vertex).
        second: usize,
    },
    /// The area is zero (for instance all vertices on one line).
    #[error("polygon has zero area")]
    ZeroArea,
    /// A vertex lies too far from the polygon's plane.
    #[error(
        "polygon is not planar: vertex {vertex} is {} units from the plane (tolerance {})",
        fmt_num(*.distance),
        fmt_num(*.tolerance)
    )]
    NotPlanar {
        /// The vertex farthest from the plane, from 1.
        vertex: usize,
        /// Its distance from the plane, in scene units.
        distance: f64,
        /// The largest distance allowed, in scene units.
        tolerance: f64,
    },
    /// A triangle whose angle at a vertex is so small that its boundary
    /// doubles back there: three nearly collinear vertices that still
    /// enclose more than [`ZERO_AREA_TOLERANCE`] of area (a sliver, as
    /// exporters write by the thousand). A triangle is never concave.
    #[error("triangle is a sliver: its angle at vertex {vertex} is almost zero")]
    Sliver {
        /// The vertex of the vanishing angle, from 1.
        vertex: usize,
    },
    /// The polygon turns the wrong way (or folds back) at a vertex.
    #[error("polygon is not convex at vertex {vertex}")]
    NotConvex {
        /// Where, from 1.
        vertex: usize,
    },
    /// Every turn goes the same way but the boundary winds around more than
    /// once, like a pentagram.
    #[error(
        "polygon is not convex: its edges turn through {} degrees, not 360 (it overlaps itself)",
        fmt_num(*.turning_deg)
    )]
    SelfOverlapping {
        /// Total turning of the edges, in degrees.
        turning_deg: f64,
    },
    /// The stored normal, area or shape disagree with the vertices (only
    /// from [`Polygon::validate`] on a polygon built by hand).
    #[error("polygon's {what} does not match its vertices")]
    Inconsistent {
        /// Which derived field is wrong.
        what: &'static str,
    },
}

/// What [`analyze`] learns from valid vertices.
struct Analysis {
    normal: DVec3,
    area: f64,
    shape: Shape,
}

impl Polygon {
    /// Validates the vertices and builds the polygon, with its unit normal
    /// (the direction of Newell's area vector), its area in square scene
    /// units, and its [`Shape`].
    ///
    /// `vertices` are in scene units, in order around the polygon,
    /// counter-clockwise seen from the front. `origin` is where the statement
    /// that made it starts, for later messages.
    pub fn new(
        material: MaterialId,
        vertices: Vec<Vec3>,
        origin: SourcePos,
    ) -> Result<Polygon, PolygonError> {
        let a = analyze(&vertices)?;
        Ok(Polygon {
            material,
            vertices,
            normal: a.normal.as_vec3(),
            area: a.area,
            shape: a.shape,
            origin,
            surface: Surface::default(),
        })
    }

    /// Re-checks every invariant of the type: the vertices are valid and the
    /// stored normal, area and shape are the ones [`Polygon::new`] computes.
    /// For tests and for polygons assembled field by field.
    pub fn validate(&self) -> Result<(), PolygonError> {
        let a = analyze(&self.vertices)?;
        // The stored values went through f32; allow for that rounding only.
        const STORED_TOLERANCE: f64 = 1e-5;
        if (self.normal.as_dvec3() - a.normal).length() > STORED_TOLERANCE {
            return Err(PolygonError::Inconsistent { what: "normal" });
        }
        if (self.area - a.area).abs() > STORED_TOLERANCE * a.area {
            return Err(PolygonError::Inconsistent { what: "area" });
        }
        if self.shape != a.shape {
            return Err(PolygonError::Inconsistent { what: "shape" });
        }
        Ok(())
    }
}

/// Checks the vertices in the order of the error variants (so the simplest
/// explanation wins) and computes the derived fields.
fn analyze(vertices: &[Vec3]) -> Result<Analysis, PolygonError> {
    let n = vertices.len();
    if n < 3 {
        return Err(PolygonError::TooFewVertices { count: n });
    }
    if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
        return Err(PolygonError::NotFinite { vertex: i + 1 });
    }
    let v: Vec<DVec3> = vertices.iter().map(|p| p.as_dvec3()).collect();
    if let Some(i) = v
        .iter()
        .position(|p| p.abs().max_element() > MAX_COORDINATE)
    {
        return Err(PolygonError::TooFar {
            vertex: i + 1,
            magnitude: v[i].abs().max_element(),
        });
    }
    let extent = diameter(&v);
    if !extent.is_finite() {
        // Finite f32 coordinates cannot overflow in f64; kept so a future
        // change of precision cannot slip a NaN past the checks below.
        return Err(PolygonError::NotFinite { vertex: 1 });
    }
    if extent < MIN_EXTENT {
        return Err(PolygonError::TooSmall { extent });
    }

    for i in 0..n {
        let j = (i + 1) % n;
        if v[i].distance(v[j]) <= COINCIDENT_TOLERANCE * extent {
            return Err(PolygonError::EqualVertices {
                first: i + 1,
                second: j + 1,
            });
        }
    }

    // Newell's method about the centroid: twice the area vector, and exact
    // for planar polygons whatever the winding of the coordinate axes.
    let centroid = v.iter().sum::<DVec3>() / n as f64;
    let mut twice_area = DVec3::ZERO;
    for i in 0..n {
        let a = v[i] - centroid;
        let b = v[(i + 1) % n] - centroid;
        twice_area += a.cross(b);
    }
    let area = 0.5 * twice_area.length();
    if area <= ZERO_AREA_TOLERANCE * extent * extent {
        return Err(PolygonError::ZeroArea);
    }
    let normal = twice_area / (2.0 * area);

    // What f32 coordinates this far from the origin can resolve.
    let rounding =
        COORDINATE_ROUNDING * v.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
    let tolerance = PLANARITY_TOLERANCE * extent + rounding;
    let (worst, distance) = v
        .iter()
        .map(|p| (p - centroid).dot(normal).abs())
        .enumerate()
        .fold(
            (0, 0.0),
            |best, (i, d)| if d > best.1 { (i, d) } else { best },
        );
    if distance > tolerance {
        return Err(PolygonError::NotPlanar {
            vertex: worst + 1,
            distance,
            tolerance,
        });
    }

    let convexity_tolerance = CONVEXITY_TOLERANCE * extent + rounding;
    let mut turning = 0.0;
    for i in 0..n {
        let prev = v[(i + n - 1) % n];
        let next = v[(i + 1) % n];
        let (e1, e2) = (v[i] - prev, next - v[i]);
        let shorter = e1.length().min(e2.length());
        let (e1, e2) = (e1.normalize(), e2.normalize());
        let sin = e1.cross(e2).dot(normal);
        let cos = e1.dot(e2);
        // A straight-through vertex (cos ≈ 1) is allowed; one where the
        // boundary doubles back (cos ≈ -1) is a fold, not a convex corner.
        // Past a right angle, only a turn the right way is a corner; short
        // of one, a turn the wrong way by less than the tolerance is a
        // straight vertex moved by rounding: the nearer neighbour lies
        // `-sin × shorter` on the wrong side of the other edge's line.
        let wrong = if cos < 0.0 {
            sin <= CONVEXITY_TOLERANCE
        } else {
            -sin * shorter > convexity_tolerance
        };
        if wrong {
            // A triangle of positive area turns the same way at every
            // vertex: a fold can only be a vanishing angle, not a concave
            // corner.
            if n == 3 {
                return Err(PolygonError::Sliver { vertex: i + 1 });
            }
            return Err(PolygonError::NotConvex { vertex: i + 1 });
        }
        turning += sin.atan2(cos);
    }
    if (turning - std::f64::consts::TAU).abs() > TURNING_TOLERANCE {
        return Err(PolygonError::SelfOverlapping {
            turning_deg: turning.to_degrees(),
        });
    }

    let shape = match n {
        3 => Shape::Triangle,
        4 if (v[0] + v[2] - v[1] - v[3]).length() <= PARALLELOGRAM_TOLERANCE * extent => {
            Shape::Parallelogram
        }
        4 => Shape::Quad,
        _ => Shape::Convex,
    };
    Ok(Analysis {
        normal,
        area,
        shape,
    })
}

/// Vertices up to which a polygon's size is its diameter, found pair by
/// pair; beyond, the diagonal of its bounding box (between one and √3
/// times the diameter), so a face of 100,000 vertices is measured in
/// linear time, not in five billion distances.
pub const EXACT_DIAMETER_MAX_VERTICES: usize = 256;

/// The polygon's size for its tolerances: the largest distance between two
/// vertices, or for more than [`EXACT_DIAMETER_MAX_VERTICES`] the diagonal
/// of their bounding box.
fn diameter(v: &[DVec3]) -> f64 {
    if v.len() > EXACT_DIAMETER_MAX_VERTICES {
        let (lo, hi) = v
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        return lo.distance(hi);
    }
    let mut d2: f64 = 0.0;
    for (i, a) in v.iter().enumerate() {
        for b in &v[i + 1..] {
            d2 = d2.max(a.distance_squared(*b));
        }
    }
    d2.sqrt()
}

/// [`diameter`] of `f32` vertices, in `f32` (the mesher's measure of a
/// polygon's size).
pub(crate) fn polygon_extent_f32(v: &[Vec3]) -> f32 {
    if v.len() > EXACT_DIAMETER_MAX_VERTICES {
        let (lo, hi) = v
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        return lo.distance(hi);
    }
    v.iter()
        .flat_map(|a| v.iter().map(move |b| a.distance(*b)))
        .fold(0.0f32, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn poly(vs: &[[f32; 3]]) -> Result<Polygon, PolygonError> {
        let vertices = vs.iter().map(|&a| Vec3::from_array(a)).collect();
        Polygon::new(MaterialId(0), vertices, SourcePos { line: 1, col: 1 })
    }

    fn ok(vs: &[[f32; 3]]) -> Polygon {
        match poly(vs) {
            Ok(p) => {
                assert_eq!(p.validate(), Ok(()));
                p
            }
            Err(e) => panic!("expected a valid polygon, got: {e}"),
        }
    }

    fn err(vs: &[[f32; 3]]) -> String {
        match poly(vs) {
            Ok(p) => panic!("expected an error, got {p:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn triangle_normal_area_and_shape() {
        let p = ok(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
        assert_eq!(p.shape, Shape::Triangle);
        assert_eq!(p.normal, Vec3::Z);
        assert!((p.area - 2.0).abs() < 1e-12);
    }

    #[test]
    fn square_is_parallelogram_and_normal_follows_winding() {
        // Counter-clockwise seen from +y, as the format's floor example.
        let p = ok(&[
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 5.0],
            [5.0, 0.0, 5.0],
            [5.0, 0.0, 0.0],
        ]);
        assert_eq!(p.shape, Shape::Parallelogram);
        assert_eq!(p.normal, Vec3::Y);
        assert!((p.area - 25.0).abs() < 1e-9);
    }

    #[test]
    fn skewed_parallelogram_and_trapezoid() {
        let para = ok(&[
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ]);
        assert_eq!(para.shape, Shape::Parallelogram);
        let trapezoid = ok(&[
            [0.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ]);
        assert_eq!(trapezoid.shape, Shape::Quad);
        assert!((trapezoid.area - 2.0).abs() < 1e-9);
    }

    #[test]
    fn pentagon_is_convex_shape() {
        let p = ok(&[
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
            [-1.0, 1.0, 0.0],
        ]);
        assert_eq!(p.shape, Shape::Convex);
        assert_eq!(p.normal, Vec3::Z);
    }

    #[test]
    fn collinear_consecutive_vertices_are_allowed() {
        // A square with an extra vertex in the middle of its first edge.
        let p = ok(&[
            [0.0, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ]);
        assert_eq!(p.shape, Shape::Convex);
        assert!((p.area - 1.0).abs() < 1e-9);
        // Decimal coordinates that are only collinear up to f32 rounding.
        ok(&[
            [0.1, 0.1, 0.1],
            [0.2, 0.2, 0.2],
            [0.3, 0.3, 0.3],
            [0.3, 0.7, 0.3],
        ]);
    }

    #[test]
    fn clockwise_vertices_give_the_opposite_normal() {
        let p = ok(&[[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]]);
        assert_eq!(p.normal, -Vec3::Z);
    }

    #[test]
    fn too_few_vertices() {
        assert_eq!(
            err(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]),
            "polygon has 2 vertices; at least 3 are needed"
        );
    }

    #[test]
    fn non_finite_vertex() {
        assert_eq!(
            err(&[[0.0, 0.0, 0.0], [f32::INFINITY, 0.0, 0.0], [0.0, 1.0, 0.0]]),
            "vertex 2 is not finite"
        );
        assert_eq!(
            err(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, f32::NAN, 0.0]]),
            "vertex 3 is not finite"
        );
    }

    #[test]
    fn equal_consecutive_vertices() {
        assert_eq!(
            err(&[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
            ]),
            "vertices 2 and 3 are equal"
        );
        assert_eq!(
            err(&[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0],
            ]),
            "vertices 4 and 1 are equal"
        );
    }

    #[test]
    fn zero_area() {
        assert_eq!(
            err(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]),
            "polygon has zero area"
        );
    }

    #[test]
    fn non_planar() {
        let e = err(&[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.5],
        ]);
        // Extent 1.5 (vertex 2 to vertex 4), so the tolerance is 0.0015.
        assert_eq!(
            e,
            "polygon is not planar: vertex 1 is 0.118 units from the plane (tolerance 0.0015)"
        );
        // Within 1e-3 of the extent is planar enough.
        ok(&[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.001],
        ]);
    }

    #[test]
    fn non_convex() {
        // An arrowhead: vertex 3 points inward.
        assert_eq!(
            err(&[
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [1.0, 0.5, 0.0],
                [2.0, 2.0, 0.0],
                [0.0, 2.0, 0.0],
            ]),
            "polygon is not convex at vertex 3"
        );
        // A boundary that runs back along itself.
        assert_eq!(
            err(&[
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
            ]),
            "polygon is not convex at vertex 2"
        );
    }

    /// A triangle whose tip angle vanishes (4.5e-7 radians) but whose area
    /// is above the zero-area bound is a sliver, never "not convex".
    #[test]
    fn a_sliver_triangle_is_named_so() {
        assert_eq!(
            err(&[[0.0, 0.0, 0.0], [1000.0, 0.0, 0.0], [2000.0, 0.0009, 0.0]]),
            "triangle is a sliver: its angle at vertex 1 is almost zero"
        );
        // A thin triangle with a real angle is a triangle.
        ok(&[[0.0, 0.0, 0.0], [1000.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    }

    #[test]
    fn pentagram_winds_twice() {
        let pts: Vec<[f32; 3]> = (0..5)
            .map(|k| {
                let a = (k as f32) * 2.0 * std::f32::consts::TAU / 5.0;
                [a.cos(), a.sin(), 0.0]
            })
            .collect();
        assert_eq!(
            err(&pts),
            "polygon is not convex: its edges turn through 720 degrees, not 360 (it overlaps itself)"
        );
    }

    /// `shape` scaled by `scale`, turned by the `k`-th of a set of
    /// rotations, moved `offset` extents from the origin and rounded to
    /// `f32`: the same polygon at another size, orientation and place, with
    /// the float noise of an export.
    fn placed(shape: &[[f64; 3]], scale: f64, k: usize, offset: f64) -> Vec<Vec3> {
        let rotation = glam::DMat3::from_rotation_z(k as f64 * 0.371)
            * glam::DMat3::from_rotation_x(k as f64 * 0.173 + 0.1);
        shape
            .iter()
            .map(|p| {
                ((rotation * DVec3::from_array(*p) + DVec3::new(0.3, -0.6, 1.0) * offset) * scale)
                    .as_vec3()
            })
            .collect()
    }

    /// The verdict without its numbers: the shape, or the error (without
    /// the vertex of a quad whose four vertices are equally far from its
    /// plane).
    fn verdict(vertices: Vec<Vec3>) -> String {
        match analyze(&vertices) {
            Ok(a) => format!("{:?}", a.shape),
            Err(PolygonError::NotPlanar { .. }) => "not planar".to_string(),
            Err(e) => e.to_string(),
        }
    }

    /// A unit square, a pentagon with a straight vertex, an arrowhead
    /// (concave at vertex 3, by a tenth of its size), a folded quad (vertex
    /// 4 a fifth of its size off the plane), a square with a fifth vertex
    /// a ten-thousandth of its size inside its left edge, and a pentagram.
    fn test_shapes() -> Vec<(Vec<[f64; 3]>, &'static str)> {
        let star: Vec<[f64; 3]> = (0..5)
            .map(|k| {
                let a = k as f64 * 2.0 * std::f64::consts::TAU / 5.0;
                [a.cos(), a.sin(), 0.0]
            })
            .collect();
        vec![
            (
                vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
                "Parallelogram",
            ),
            (
                vec![[0., 0., 0.], [0.5, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
                "Convex",
            ),
            (
                vec![[0., 0., 0.], [1., 0., 0.], [0.9, 0.5, 0.], [1., 1., 0.], [0., 1., 0.]],
                "polygon is not convex at vertex 3",
            ),
            (
                vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.2]],
                "not planar",
            ),
            (
                vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [1e-4, 0.5, 0.]],
                "polygon is not convex at vertex 5",
            ),
            (
                star,
                "polygon is not convex: its edges turn through 720 degrees, not 360 (it overlaps itself)",
            ),
        ]
    }

    /// The convexity and planarity tolerances follow the polygon's size:
    /// the same polygon a ten-thousandth of a unit and a hundred thousand
    /// units across gets the same verdict, turned any way, at the origin
    /// or a hundred times its size away from it.
    #[test]
    fn verdicts_do_not_depend_on_the_polygons_size_or_place() {
        for (shape, expected) in test_shapes() {
            for scale in [1e-4, 1.0, 1e5] {
                for offset in [0.0, 1.0, 10.0, 100.0] {
                    for k in 0..50 {
                        assert_eq!(
                            verdict(placed(&shape, scale, k, offset)),
                            expected,
                            "{shape:?} × {scale:e}, {offset} away, turn {k}"
                        );
                    }
                }
            }
        }
    }

    /// A tolerance on the sine of each turn alone refused a pentagon whose
    /// straight vertex `f32` rounding had moved off its line, once the
    /// pentagon was some way from the origin (4 to 8 of these 200
    /// placements at ten sizes away, 64 to 80 at a thousand): that sine is
    /// the rounding over the edge, and the rounding grows with the
    /// distance from the origin, not with the polygon.
    #[test]
    fn a_straight_vertex_moved_by_rounding_is_convex_far_from_the_origin() {
        let pentagon = [
            [0., 0., 0.],
            [0.5, 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
        ];
        for scale in [1e-4, 1e-2, 1.0, 1e3] {
            for offset in [10.0, 1000.0] {
                for k in 0..200 {
                    let vertices = placed(&pentagon, scale, k, offset);
                    assert!(
                        analyze(&vertices).is_ok_and(|a| a.shape == Shape::Convex),
                        "× {scale:e}, {offset} away, turn {k}: {:?}",
                        analyze(&vertices).err()
                    );
                }
            }
        }
    }

    #[test]
    fn validate_catches_tampered_fields() {
        let mut p = ok(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
        p.normal = -p.normal;
        assert_eq!(
            p.validate(),
            Err(PolygonError::Inconsistent { what: "normal" })
        );
    }
}
