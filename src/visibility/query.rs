//! The one choice of how to test a shadow ray: no test, a short list of
//! candidate polygons, or the whole BVH.
//!
//! Shaft culling ([`Visibility::shaft_candidates`],
//! [`Visibility::box_shaft_candidates`],
//! [`Visibility::refine_candidates_in_runs`]) lists the polygons that may
//! block a segment. An empty list means nothing can: the segment is
//! visible and no ray is cast. A short one is tested polygon by polygon;
//! past a few polygons the BVH's traversal is faster than the list, and
//! without a list (culling off, a receiver too small to pay for a shaft,
//! a shaft too crowded to list) the BVH is the only test. Every gather
//! (a step's, a cluster's, the final gather) makes this choice through
//! [`ShadowQuery::choose`], so they count rays alike and give the same
//! answers whichever test runs.

use super::{LastBlocker, Visibility};
use crate::scene::PolygonId;
use glam::Vec3;

/// How a shadow ray is tested ([`Visibility::shadow`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowQuery<'c> {
    /// Nothing can block the segment: visible, no ray cast.
    Clear,
    /// Only these polygons (indices) can block it, few enough to test one
    /// by one; never empty.
    Among(&'c [u32]),
    /// Any polygon may block it: the BVH's traversal.
    Everything,
}

impl<'c> ShadowQuery<'c> {
    /// The test for a segment whose possible blockers are `candidates`:
    /// `None` when there is no complete list (the whole scene is tested),
    /// `Some` of a complete one; a list longer than `linear_max` polygons
    /// is tested through the BVH too.
    #[inline]
    pub fn choose(candidates: Option<&'c [u32]>, linear_max: usize) -> Self {
        match candidates {
            Some([]) => ShadowQuery::Clear,
            Some(c) if c.len() <= linear_max => ShadowQuery::Among(c),
            _ => ShadowQuery::Everything,
        }
    }

    /// The shadow rays the test casts, as a step counts them: 0 for
    /// [`ShadowQuery::Clear`], else 1.
    #[inline]
    pub fn rays(self) -> u64 {
        match self {
            ShadowQuery::Clear => 0,
            ShadowQuery::Among(_) | ShadowQuery::Everything => 1,
        }
    }
}

impl Visibility {
    /// Whether the open segment from `a` to `b` is blocked, by the test
    /// `query`, leaving out `ends` and the polygons in their planes as
    /// [`Visibility::occluded`] does. The answer is that of
    /// [`Visibility::occluded`] whenever `query` comes from a complete list
    /// of the segment's possible blockers.
    #[inline]
    pub fn shadow(
        &self,
        query: ShadowQuery,
        a: Vec3,
        b: Vec3,
        ends: (PolygonId, PolygonId),
    ) -> bool {
        self.shadow_remembering(query, a, b, ends, &mut LastBlocker::default())
    }

    /// [`Visibility::shadow`], trying `last` first and keeping in it the
    /// blocker found ([`LastBlocker`]: the same answer, found sooner).
    #[inline]
    pub fn shadow_remembering(
        &self,
        query: ShadowQuery,
        a: Vec3,
        b: Vec3,
        ends: (PolygonId, PolygonId),
        last: &mut LastBlocker,
    ) -> bool {
        match query {
            ShadowQuery::Clear => false,
            ShadowQuery::Among(candidates) => {
                self.occluded_among_ends_remembering(a, b, candidates, ends, last)
            }
            ShadowQuery::Everything => self.occluded_remembering(a, b, ends, last),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No list tests the whole scene, an empty one nothing (no ray), a
    /// short one its polygons, a long one the whole scene.
    #[test]
    fn the_choice_follows_the_candidate_list() {
        let short = [3, 5];
        let long = [1, 2, 3, 4];
        assert_eq!(ShadowQuery::choose(None, 3), ShadowQuery::Everything);
        assert_eq!(ShadowQuery::choose(Some(&[]), 3), ShadowQuery::Clear);
        assert_eq!(
            ShadowQuery::choose(Some(&short), 3),
            ShadowQuery::Among(&short)
        );
        assert_eq!(ShadowQuery::choose(Some(&long), 3), ShadowQuery::Everything);
        assert_eq!(ShadowQuery::Clear.rays(), 0);
        assert_eq!(ShadowQuery::Among(&short).rays(), 1);
        assert_eq!(ShadowQuery::Everything.rays(), 1);
    }
}
