//! Small receiving facets share their shadow rays: every element vertex of
//! a facet asks one ray per shooter sample, from that sample to the
//! facet's middle.
//!
//! A tessellated surface (a sphere of a thousand triangles, a real
//! export's furniture) is meshed as one element per facet, and every
//! facet keeps its own vertices, so each point of the surface is a vertex
//! of about six facets: a step cast about six nearly identical rays from
//! each shooter sample to each point (three per triangle), and on the
//! 100,000-triangle sphere box those rays were most of the time. A facet
//! at most [`FACET_SCALE_RATIO`] of the mesh's element size across (the longest
//! element edge of the mesh, at most `lenmax`) is finer than the mesh
//! was asked to resolve: one ray from each shooter sample to the facet's
//! middle ([`Facets::point`]: the mean of its vertices' inset sample
//! positions, inside the convex facet) decides that sample's visibility
//! for all its vertices. A shadow edge then falls on facet edges rather
//! than across a facet, moved by less than half an element. The form
//! factor itself (distance and both cosines) stays each vertex's own.
//!
//! Larger facets ask per vertex: a chair leg's face, two elements tall,
//! is lit at its foot and shadowed by the seat at its top, and sharing
//! the middle's rays made such faces of the 15-table hall up to 28 %
//! brighter than the reference.
//!
//! A sample nearer the facet than [`FACET_NEAR_RATIO`] of its diameter is
//! asked per vertex, as before: there the rays to the vertices part too
//! widely for one to stand for the others (a chair leg where it meets the
//! floor that shoots). So is a sample whose cell some vertex of the facet
//! takes the exact point-to-cell form factor of
//! ([`crate::solver::tuning::EXACT_RATIO`]): such a vertex is close to a cell
//! large beside it and takes much of its light from it, by one ray that
//! must end at the vertex itself. Measured on the 64-segment spheres: the
//! tiny facets around a sphere's pole, where it touches the floor, lie
//! within 3° of the floor, and the pole's vertex sees a floor cell 36
//! units away along it while the facet's middle, 0.4 units up, grazes its
//! neighbours; shared, that vertex lost all its light (0.0088 to 2e-8).
//!
//! The shared answer is a pure function of the facet and the sample (or
//! stratum) it was asked for, so memoising it ([`Memo`]) cannot change a
//! bit, whatever vertex asks first and however the vertices are split
//! between threads. The count of rays cast does vary a little: a facet
//! whose vertices fall in two workers' runs asks some rays twice, and
//! the runs depend on work stealing (on the 100,000-triangle box, 4
//! steps cast 12,319,995 to 12,320,055 rays over runs with the same
//! picture bytes). On with clusters and hierarchical receivers
//! ([`crate::solver::Approximations::receiver_interpolation`]); `--exact-receivers`
//! and `--no-clustering` ask every ray per vertex.

use crate::mesh::Mesh;
use crate::scene::PolygonId;
use crate::solver::tuning::{FACET_NEAR_RATIO, FACET_SCALE_RATIO, SHAFT_MIN_VERTICES};
use crate::visibility::Visibility;
use glam::Vec3;

/// Per polygon, the point its shared rays end at, when it is small enough
/// to share them.
#[derive(Clone, Debug, Default)]
pub struct Facets {
    /// Per polygon: its middle and its diameter (scene units), or `None`
    /// when its vertices ask their own rays.
    points: Vec<Option<(Vec3, f32)>>,
}

impl Facets {
    /// The facets of `mesh` that share rays: polygons with fewer than
    /// [`SHAFT_MIN_VERTICES`] element vertices and at most
    /// [`FACET_SCALE_RATIO`] of the longest element edge across, none of them a
    /// sky facet (it receives nothing). Empty (every polygon per vertex)
    /// when `on` is false.
    pub fn new(mesh: &Mesh, on: bool) -> Self {
        let element_size = mesh
            .elements
            .iter()
            .flat_map(|e| {
                let c = e.corners();
                (0..c.len()).map(move |k| {
                    let (a, b) = (c[k].index(), c[(k + 1) % c.len()].index());
                    mesh.positions[a].distance(mesh.positions[b])
                })
            })
            .fold(0.0f32, f32::max);
        let largest = FACET_SCALE_RATIO * element_size;
        let points = mesh
            .polygons
            .iter()
            .map(|pm| {
                let n = pm.vertex_count();
                if !on || pm.sky || n == 0 || n >= SHAFT_MIN_VERTICES {
                    return None;
                }
                let at =
                    &mesh.sample_positions[pm.vertices.start as usize..pm.vertices.end as usize];
                let middle = at.iter().copied().sum::<Vec3>() / n as f32;
                let corners = &mesh.positions[pm.vertices.start as usize..pm.vertices.end as usize];
                let diameter = corners
                    .iter()
                    .flat_map(|a| corners.iter().map(move |b| a.distance(*b)))
                    .fold(0.0f32, f32::max);
                (middle.is_finite() && diameter <= largest).then_some((middle, diameter))
            })
            .collect();
        Facets { points }
    }

    /// How many polygons share their rays.
    pub fn sharing(&self) -> usize {
        self.points.iter().filter(|p| p.is_some()).count()
    }

    /// Where the shared ray from a shooter point `from` to polygon `j`
    /// ends: `Some(middle)` when `j` shares its rays and `from` is far
    /// enough from it, `None` when each vertex asks its own. `exact_r2`
    /// is the square of the distance (scene units) within which a
    /// receiver takes the exact form factor of `from`'s cell
    /// ([`crate::solver::kernel::formfactor::ShooterSample::exact_r2`]; 0 for a far
    /// stratum): no vertex of a sharing facet may lie within it.
    #[inline]
    pub fn point(&self, j: usize, from: Vec3, exact_r2: f32) -> Option<Vec3> {
        let (middle, diameter) = self.points.get(j).copied().flatten()?;
        let reach = (FACET_NEAR_RATIO * diameter).max(exact_r2.sqrt() + diameter);
        (from.distance_squared(middle) > reach * reach).then_some(middle)
    }

    /// The shared answer for the segment from shooter point `from` (of
    /// polygon `ends.0`, sample or stratum `key`) to receiving facet
    /// `ends.1`: `Some((blocked, rays cast))` from `memo`, or from one ray
    /// to the facet's middle, when the facet shares ([`Facets::point`]);
    /// `None` when the vertex must ask its own ray.
    #[inline]
    pub fn shared_ray(
        &self,
        memo: &mut Memo,
        visibility: &Visibility,
        ends: (PolygonId, PolygonId),
        key: u32,
        from: Vec3,
        exact_r2: f32,
    ) -> Option<(bool, u64)> {
        let facet = ends.1;
        let middle = self.point(facet.index(), from, exact_r2)?;
        Some(memo.answer(facet.0, key, || {
            (visibility.occluded(from, middle, ends), 1)
        }))
    }
}

/// A worker's scratch for one step's gather: the traversal stack of a
/// cluster's strata and the memo of shared rays.
#[derive(Debug, Default)]
pub struct Scratch {
    /// Nodes still to visit (node, its cut index).
    pub stack: Vec<(u32, u32)>,
    /// Shared answers of the facet being gathered.
    pub memo: Memo,
}

/// The shared visibility answers of one facet, by key (a shooter sample's
/// or a stratum's index): cleared when another facet asks. Each answer is
/// a pure function of its facet and key, so a cleared or split memo only
/// costs rays, never changes a bit.
#[derive(Debug, Default)]
pub struct Memo {
    facet: Option<u32>,
    generation: u32,
    /// Per key: the generation it was written in and whether the ray was
    /// blocked.
    entries: Vec<(u32, bool)>,
}

impl Memo {
    /// The answer for `key` on facet `facet`: the memoised one, or
    /// `ask()`'s (whether blocked, rays cast), kept. Returns whether
    /// blocked and the rays this call cast.
    #[inline]
    pub fn answer(
        &mut self,
        facet: u32,
        key: u32,
        ask: impl FnOnce() -> (bool, u64),
    ) -> (bool, u64) {
        if self.facet != Some(facet) {
            self.facet = Some(facet);
            self.generation = self.generation.wrapping_add(1);
            if self.generation == 0 {
                // Wrapped: forget every stamp rather than trust an old one.
                self.entries.iter_mut().for_each(|e| e.0 = 0);
                self.generation = 1;
            }
        }
        let k = key as usize;
        if k >= self.entries.len() {
            self.entries.resize(k + 1, (0, false));
        }
        let (stamp, blocked) = self.entries[k];
        if stamp == self.generation {
            return (blocked, 0);
        }
        let (blocked, rays) = ask();
        self.entries[k] = (self.generation, blocked);
        (blocked, rays)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{grey, polygon, regular_mesh, scene};

    /// A 4 × 4 floor (cut into elements of 1) and two facets above it: a
    /// small triangle (0.3 across) and a large one (2 across).
    fn floor_and_facets() -> (crate::scene::Scene, Mesh) {
        let s = scene(
            vec![
                polygon(0, &[[0., 0., 0.], [4., 0., 0.], [4., 0., 4.], [0., 0., 4.]]),
                polygon(0, &[[1., 1., 1.], [1.3, 1., 1.], [1., 1., 1.1]]),
                polygon(0, &[[2., 1., 2.], [4., 1., 2.], [2., 1., 2.5]]),
            ],
            vec![grey("g", 0.0, 0.5)],
        );
        let mesh = regular_mesh(&s, 1.0);
        (s, mesh)
    }

    #[test]
    fn only_facets_under_half_an_element_share_and_only_from_afar() {
        let (_, mesh) = floor_and_facets();
        let facets = Facets::new(&mesh, true);
        // The floor has many vertices, the large triangle is two elements
        // across: only the small triangle shares.
        assert_eq!(facets.sharing(), 1);
        let far = Vec3::new(3.5, 0.0, 3.5);
        let middle = facets.point(1, far, 0.0).expect("a far sample shares");
        let corners = &mesh.positions[mesh.polygons[1].vertices.start as usize..];
        assert!(
            middle.distance(corners[0]) < 0.3,
            "the middle is on the facet"
        );
        assert!(facets.point(0, far, 0.0).is_none());
        assert!(facets.point(2, far, 0.0).is_none());
        // Within FACET_NEAR_RATIO diameters: per vertex.
        assert!(facets.point(1, Vec3::new(1.1, 0.5, 1.0), 0.0).is_none());
        // A cell large enough that the facet lies within its exact zone:
        // per vertex, though the cell's sample is far.
        assert!(facets.point(1, far, 16.0).is_none());
        assert!(facets.point(1, far, 0.25).is_some());
        // Off: nothing shares.
        assert_eq!(Facets::new(&mesh, false).sharing(), 0);
    }

    #[test]
    fn a_memo_asks_once_per_facet_and_key() {
        let mut memo = Memo::default();
        let mut asked = 0;
        let mut ask = |answer: bool| {
            asked += 1;
            (answer, 1)
        };
        assert_eq!(memo.answer(3, 5, || ask(true)), (true, 1));
        assert_eq!(memo.answer(3, 5, || ask(false)), (true, 0));
        assert_eq!(memo.answer(3, 2, || ask(false)), (false, 1));
        // Another facet: its own answers.
        assert_eq!(memo.answer(4, 5, || ask(false)), (false, 1));
        // Back to the first: asked again, never a stale answer.
        assert_eq!(memo.answer(3, 5, || ask(false)), (false, 1));
        assert_eq!(asked, 4);
    }

    #[test]
    fn a_memo_survives_its_generation_wrapping() {
        let mut memo = Memo::default();
        memo.answer(0, 0, || (true, 1));
        memo.generation = u32::MAX;
        memo.facet = Some(0);
        // Facet 1 wraps the generation: the entry stamped long ago must
        // not be read as current.
        memo.entries[0] = (1, true);
        assert_eq!(memo.answer(1, 0, || (false, 1)), (false, 1));
    }
}
