//! Shafts (Haines and Wallace, "Shaft Culling for Efficient Ray-Traced
//! Radiosity", 1991): the convex region between two axis-aligned boxes.
//!
//! Every segment from a point of box `A` to a point of box `B` lies in the
//! convex hull of the two boxes. The shaft is that hull, or a conservative
//! superset of it: the box around both, cut by at most eight planes, each
//! through an edge of `A` and the matching edge of `B` where one box sticks
//! out past the other on one axis and the other box on a second axis. An
//! object entirely outside the shaft can block no such segment.

use glam::DVec3;

/// The region between two boxes: inside the combined box and on the inner
/// side of every plane.
#[derive(Clone, Debug, PartialEq)]
pub struct Shaft {
    /// Combined box minimum corner, in scene units.
    pub min: DVec3,
    /// Combined box maximum corner, in scene units.
    pub max: DVec3,
    /// Planes `(n, d)`: inside is `n · x <= d`. `n` is a unit vector.
    planes: [(DVec3, f64); 8],
    plane_count: usize,
    /// How far outside a plane or the box something may be and still count
    /// as inside, in scene units.
    tolerance: f64,
}

/// Which box makes one face of the combined box.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Maker {
    A,
    B,
    Both,
}

impl Shaft {
    /// The shaft between boxes `a` and `b` (`(min, max)` each), counting
    /// points up to `tolerance` outside as inside.
    pub fn between(a: (DVec3, DVec3), b: (DVec3, DVec3), tolerance: f64) -> Shaft {
        let min = a.0.min(b.0);
        let max = a.1.max(b.1);
        let maker = |axis: usize, high: bool| -> Maker {
            let (av, bv) = if high {
                (a.1[axis], b.1[axis])
            } else {
                (a.0[axis], b.0[axis])
            };
            if av == bv {
                Maker::Both
            } else if (av > bv) == high {
                Maker::A
            } else {
                Maker::B
            }
        };
        let mut shaft = Shaft {
            min,
            max,
            planes: [(DVec3::ZERO, 0.0); 8],
            plane_count: 0,
            tolerance,
        };
        let centres = (a.0 + a.1 + b.0 + b.1) * 0.5;
        for i in 0..3 {
            for j in (i + 1)..3 {
                for hi_i in [false, true] {
                    for hi_j in [false, true] {
                        let (mi, mj) = (maker(i, hi_i), maker(j, hi_j));
                        let (first, second) = match (mi, mj) {
                            (Maker::A, Maker::B) => (a, b),
                            (Maker::B, Maker::A) => (b, a),
                            _ => continue,
                        };
                        // The edge of `first` on face (i, hi_i) ∩ (j, hi_j)
                        // and the same edge of `second`, seen in the (i, j)
                        // plane: two points.
                        let pick = |bx: (DVec3, DVec3), axis: usize, high: bool| {
                            if high {
                                bx.1[axis]
                            } else {
                                bx.0[axis]
                            }
                        };
                        let p = (pick(first, i, hi_i), pick(first, j, hi_j));
                        let q = (pick(second, i, hi_i), pick(second, j, hi_j));
                        let (du, dv) = (q.0 - p.0, q.1 - p.1);
                        let mut n = DVec3::ZERO;
                        n[i] = dv;
                        n[j] = -du;
                        let n = n.normalize_or_zero();
                        if n == DVec3::ZERO {
                            continue;
                        }
                        let mut point = DVec3::ZERO;
                        point[i] = p.0;
                        point[j] = p.1;
                        let (mut n, mut d) = (n, n.dot(point));
                        // Orient outward: the boxes' centres are inside
                        // (their sum is twice their midpoint).
                        if n.dot(centres) > 2.0 * d {
                            n = -n;
                            d = -d;
                        }
                        if shaft.plane_count < shaft.planes.len() {
                            shaft.planes[shaft.plane_count] = (n, d);
                            shaft.plane_count += 1;
                        }
                    }
                }
            }
        }
        shaft
    }

    /// The planes bounding the shaft besides its box.
    pub fn planes(&self) -> &[(DVec3, f64)] {
        &self.planes[..self.plane_count]
    }

    /// True when the box `(min, max)` may overlap the shaft; false only
    /// when it is certainly outside (beyond the tolerance).
    pub fn may_overlap_box(&self, min: DVec3, max: DVec3) -> bool {
        let t = self.tolerance;
        if (min.cmpgt(self.max + t) | max.cmplt(self.min - t)).any() {
            return false;
        }
        self.planes().iter().all(|&(n, d)| {
            // The box corner furthest inside along -n.
            let corner = DVec3::new(
                if n.x >= 0.0 { min.x } else { max.x },
                if n.y >= 0.0 { min.y } else { max.y },
                if n.z >= 0.0 { min.z } else { max.z },
            );
            n.dot(corner) <= d + t
        })
    }

    /// True when the convex polygon with these vertices may overlap the
    /// shaft; false only when all its vertices are outside one plane or
    /// one face of the box.
    pub fn may_overlap_points(&self, points: impl Iterator<Item = DVec3> + Clone) -> bool {
        let t = self.tolerance;
        for axis in 0..3 {
            if points.clone().all(|p| p[axis] > self.max[axis] + t)
                || points.clone().all(|p| p[axis] < self.min[axis] - t)
            {
                return false;
            }
        }
        self.planes()
            .iter()
            .all(|&(n, d)| points.clone().any(|p| n.dot(p) <= d + t))
    }

    /// True when the point is inside (within the tolerance).
    pub fn contains(&self, p: DVec3) -> bool {
        let t = self.tolerance;
        (p.cmpge(self.min - t) & p.cmple(self.max + t)).all()
            && self.planes().iter().all(|&(n, d)| n.dot(p) <= d + t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rand_stream(seed: u64) -> impl FnMut() -> f64 {
        let mut stream = crate::testutil::Xorshift(seed);
        move || stream.unit_f64()
    }

    fn random_box(r: &mut impl FnMut() -> f64) -> (DVec3, DVec3) {
        let a = DVec3::new(r() * 10.0, r() * 10.0, r() * 10.0);
        // Some boxes flat on one axis, as walls are.
        let flat = (r() * 4.0) as usize;
        let mut size = DVec3::new(r() * 3.0, r() * 3.0, r() * 3.0);
        if flat < 3 {
            size[flat] = 0.0;
        }
        (a, a + size)
    }

    /// Every point on a segment between the two boxes is in the shaft.
    #[test]
    fn shaft_contains_every_segment_between_its_boxes() {
        let mut r = rand_stream(0x9e37_79b9_7f4a_7c15);
        for _ in 0..2000 {
            let (a, b) = (random_box(&mut r), random_box(&mut r));
            let shaft = Shaft::between(a, b, 1e-9);
            for _ in 0..20 {
                let pa = a.0 + (a.1 - a.0) * DVec3::new(r(), r(), r());
                let pb = b.0 + (b.1 - b.0) * DVec3::new(r(), r(), r());
                let t = r();
                let p = pa + (pb - pa) * t;
                assert!(
                    shaft.contains(p),
                    "{p} not in shaft between {a:?} and {b:?}"
                );
            }
        }
    }

    /// The shaft is tight: points on the far side of a cut corner are out.
    #[test]
    fn shaft_cuts_the_corners_of_the_combined_box() {
        // Two unit boxes on a diagonal: the combined box's other two
        // corners are far outside the hull.
        let a = (DVec3::ZERO, DVec3::ONE);
        let b = (DVec3::new(4.0, 4.0, 0.0), DVec3::new(5.0, 5.0, 1.0));
        let shaft = Shaft::between(a, b, 1e-9);
        assert!(shaft.contains(DVec3::new(2.5, 2.5, 0.5)));
        assert!(!shaft.contains(DVec3::new(4.5, 0.5, 0.5)));
        assert!(!shaft.contains(DVec3::new(0.5, 4.5, 0.5)));
        assert!(!shaft.may_overlap_box(DVec3::new(4.0, 0.0, 0.0), DVec3::new(5.0, 1.0, 1.0)));
        assert!(shaft.may_overlap_box(DVec3::new(2.0, 2.0, 0.0), DVec3::new(3.0, 3.0, 1.0)));
        assert!(!shaft.may_overlap_points(
            [
                DVec3::new(4.0, 0.0, 0.5),
                DVec3::new(5.0, 0.0, 0.5),
                DVec3::new(5.0, 1.0, 0.5)
            ]
            .into_iter()
        ));
    }
}
