//! Steps delivered in parts, so a window's picture keeps moving while one
//! long step runs.
//!
//! A step of a large scene (a hall of 150 tables, 56,000 vertices) can take
//! more than half a second: every receiving vertex sums over the shooter's
//! samples or strata. With [`SolverOptions::part_budget`] set, the step's
//! receivers are taken in chunks, in polygon order, and the step returns
//! after the chunk that brings its solver time near the budget, with the
//! receivers done so far applied; the next call continues it. The shooter
//! chosen, what it sends and every receiver's sum are those of the step in
//! one piece, so the finished step is bit-identical to it: only the
//! pictures between parts are new.
//!
//! A chunk is a run of whole polygons holding at most so many vertex–sample
//! pairs ([`CHUNK_WORK`] at first, then what the chunks before took about
//! [`CHUNK_TARGET`] to gather), or, for one polygon larger than that (a
//! hall's floor), a piece of its vertices in one of the two passes of a
//! hierarchical gather (`Pass`); the polygon is applied once its last
//! piece is done, as a receiving grid's interpolation and its check charges
//! need all of its first pass. Without a budget a step is one chunk of
//! every polygon: the solver as it was. `Plan` cuts the receivers into
//! chunks; `Progressive::continue_step` runs them, each through phases 3
//! to 5.
//!
//! [`SolverOptions::part_budget`]: crate::solver::SolverOptions::part_budget

use super::gather::Stage;
use super::{How, StepPhase, Underway};
use crate::scene::PolygonId;
use crate::solver::tuning::{
    CHUNK_GROWTH, CHUNK_TARGET, CHUNK_WORK, NEAR_WEIGHT, PIECE_GROWTH, PIECE_WORK,
};
use crate::solver::{Progressive, StepReport};
use std::sync::atomic::AtomicBool;

use crate::mesh::PolygonMesh;
use std::ops::Range;
use std::time::Duration;

/// Which pass of a receiving polygon's gather a piece runs
/// ([`super::gather::gather_passes`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Pass {
    /// The vertices evaluated exactly (every vertex when the step does
    /// not interpolate).
    Exact,
    /// The vertices a coarse cell may interpolate, from the first pass.
    Interpolated,
}

/// What one chunk of a step's receivers is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Chunk {
    /// Whole polygons: culled, gathered in both passes and applied.
    Whole {
        /// Polygon indices.
        polygons: Range<usize>,
        /// Their mesh vertices (contiguous, as polygons' ranges are).
        vertices: Range<usize>,
    },
    /// Some vertices of one large polygon in one pass.
    Piece {
        /// The polygon.
        polygon: usize,
        /// The vertices of this piece.
        vertices: Range<usize>,
        /// Every vertex of the polygon.
        all: Range<usize>,
        /// The pass the piece runs.
        pass: Pass,
        /// The first piece of its pass (the polygon is culled before the
        /// first piece of its first pass).
        first: bool,
        /// The last piece of its pass.
        last: bool,
    },
}

/// Where a step's receivers have been taken to: the next chunk starts
/// here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Cursor {
    /// The next polygon not yet begun.
    polygon: usize,
    /// Within a large polygon: its pass and the next vertex.
    piece: Option<(usize, Pass, usize)>,
}

/// How a step's receivers are cut into chunks.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plan {
    /// Work per receiving vertex: the shooter's samples or strata (≥ 1).
    per_vertex: u64,
    /// Work in one chunk of whole polygons at most (see [`CHUNK_WORK`]).
    limit: u64,
    /// Work in one piece of a large polygon at most.
    piece_limit: u64,
    /// Whether the step's gather has a second, interpolating pass.
    two_passes: bool,
    /// False: one chunk of every polygon.
    in_parts: bool,
    cursor: Cursor,
}

impl Plan {
    /// A plan from the first polygon. `per_vertex` is what one receiving
    /// vertex costs in [`CHUNK_WORK`] units.
    pub(crate) fn new(per_vertex: usize, two_passes: bool, in_parts: bool) -> Plan {
        Plan {
            per_vertex: per_vertex.max(1) as u64,
            limit: CHUNK_WORK,
            piece_limit: CHUNK_WORK,
            two_passes,
            in_parts,
            cursor: Cursor {
                polygon: 0,
                piece: None,
            },
        }
    }

    /// The next chunk, where the step stands once it is done and the
    /// chunk's work; `None` when every polygon has been taken. Polygons
    /// that do not receive cost nothing and ride along in whole chunks;
    /// those `near(j)` says are near the shooter (of its cluster) count
    /// [`NEAR_WEIGHT`] times.
    pub(crate) fn next(
        &self,
        polygons: &[PolygonMesh],
        receives: &[bool],
        near: impl Fn(usize) -> bool,
    ) -> Option<(Chunk, Cursor, u64)> {
        let range = |p: &PolygonMesh| p.vertices.start as usize..p.vertices.end as usize;
        let per_vertex = |j: usize| {
            if near(j) {
                self.per_vertex * NEAR_WEIGHT
            } else {
                self.per_vertex
            }
        };
        let work = |j: usize| {
            if receives[j] {
                u64::from(polygons[j].vertex_count()) * per_vertex(j)
            } else {
                0
            }
        };
        let Cursor { polygon, piece } = self.cursor;
        if let Some((j, pass, at)) = piece {
            let all = range(&polygons[j]);
            let step = (self.piece_limit / per_vertex(j)).max(1) as usize;
            let end = (at + step).min(all.end);
            let last = end == all.end;
            let after = match (last, pass) {
                (false, _) => Cursor {
                    polygon,
                    piece: Some((j, pass, end)),
                },
                (true, Pass::Exact) if self.two_passes => Cursor {
                    polygon,
                    piece: Some((j, Pass::Interpolated, all.start)),
                },
                (true, _) => Cursor {
                    polygon: j + 1,
                    piece: None,
                },
            };
            let chunk = Chunk::Piece {
                polygon: j,
                vertices: at..end,
                first: at == all.start,
                all,
                pass,
                last,
            };
            return Some((chunk, after, (end - at) as u64 * per_vertex(j)));
        }
        if polygon >= polygons.len() {
            return None;
        }
        if !self.in_parts {
            let end = polygons.len();
            let chunk = Chunk::Whole {
                polygons: polygon..end,
                vertices: range(&polygons[polygon]).start..range(&polygons[end - 1]).end,
            };
            let after = Cursor {
                polygon: end,
                piece: None,
            };
            return Some((chunk, after, (polygon..end).map(work).sum()));
        }
        if work(polygon) > self.limit {
            // A large polygon: begin its pieces.
            let piece = Plan {
                cursor: Cursor {
                    polygon,
                    piece: Some((polygon, Pass::Exact, range(&polygons[polygon]).start)),
                },
                ..*self
            };
            return piece.next(polygons, receives, near);
        }
        let (mut end, mut sum) = (polygon, 0u64);
        while end < polygons.len() {
            let w = work(end);
            if w > self.limit || (sum + w > self.limit && end > polygon) {
                break;
            }
            sum += w;
            end += 1;
        }
        let chunk = Chunk::Whole {
            polygons: polygon..end,
            vertices: range(&polygons[polygon]).start..range(&polygons[end - 1]).end,
        };
        Some((
            chunk,
            Cursor {
                polygon: end,
                piece: None,
            },
            sum,
        ))
    }

    /// Sizes the next chunks from one of `work` that took `took` (a
    /// `piece` of a large polygon, or whole polygons): at once down to
    /// what fits [`CHUNK_TARGET`], and up towards it halfway
    /// (geometrically), by a quarter at most for whole polygons, within
    /// [`CHUNK_WORK`] / 64 and [`CHUNK_WORK`]; pieces may grow by half, up
    /// to [`PIECE_WORK`], as the rest of one polygon costs about what its
    /// last piece did (a receiving grid's interpolated vertices cost next
    /// to nothing). A chunk's size changes which receivers share a part,
    /// never a result bit.
    pub(crate) fn observe(&mut self, piece: bool, work: u64, took: Duration) {
        if work == 0 {
            return;
        }
        let fits = work as f64 * CHUNK_TARGET.as_secs_f64() / took.as_secs_f64().max(1e-6);
        let (limit, growth, cap) = if piece {
            (&mut self.piece_limit, PIECE_GROWTH, PIECE_WORK)
        } else {
            (&mut self.limit, CHUNK_GROWTH, CHUNK_WORK)
        };
        let now = *limit as f64;
        let next = if fits < now {
            fits
        } else {
            (now * fits).sqrt().min(now * growth)
        };
        *limit = (next as u64).clamp(CHUNK_WORK / 64, cap);
    }

    /// Moves on to `cursor` (from [`Plan::next`]) once its chunk is done.
    pub(crate) fn advance(&mut self, cursor: Cursor) {
        self.cursor = cursor;
    }

    /// Whether every one of `polygons` polygons has been taken (when
    /// [`Plan::next`] has nothing left).
    pub(crate) fn finished(&self, polygons: usize) -> bool {
        self.cursor.piece.is_none() && self.cursor.polygon >= polygons
    }

    /// Whether a large polygon's gather has a second, interpolating pass.
    pub(crate) fn two_passes(&self) -> bool {
        self.two_passes
    }
}

impl<'a> Progressive<'a> {
    /// Gathers and applies chunks of the step under way until every
    /// receiver is done (the step's report, `complete`) or, with a
    /// [`SolverOptions::part_budget`], until the next chunk would take the
    /// part past it, counted from `start` (a report of the part). `None`
    /// once `cancel` is set:
    /// the chunk in hand is dropped, and a step none of whose chunks was
    /// applied is forgotten, leaving the state exactly as before it.
    pub(in crate::solver) fn continue_step(
        &mut self,
        start: std::time::Instant,
        cancel: &AtomicBool,
    ) -> Option<StepReport> {
        // On a worker of the thread pool: a part runs many short parallel
        // loops, and each one called from outside the pool would wait for
        // sleeping workers to wake and for the caller to be woken back.
        if rayon::current_thread_index().is_none() {
            return rayon::scope(|_| self.continue_step(start, cancel));
        }
        let mut u = self.underway.take()?;
        let mut longest = std::time::Duration::ZERO;
        u.part += 1;
        loop {
            let chunk_start = std::time::Instant::now();
            let Some((chunk, after, work)) = self.next_chunk(&u) else {
                break;
            };
            let piece = matches!(chunk, Chunk::Piece { .. });
            if self.run_chunk(&mut u, chunk, cancel).is_none() {
                u.part -= 1;
                if u.spent {
                    self.underway = Some(u);
                }
                return None;
            }
            let took = chunk_start.elapsed();
            u.plan.advance(after);
            u.plan.observe(piece, work, took);
            longest = longest.max(took);
            if u.plan.finished(self.mesh.polygons.len()) {
                break;
            }
            if let Some(budget) = self.options.part_budget {
                if start.elapsed() + longest >= budget {
                    let report = self.part_report(&u, false);
                    self.underway = Some(u);
                    return Some(report);
                }
            }
        }
        Some(self.finish_step(&u))
    }

    /// The next chunk of step `u` ([`Plan::next`]).
    /// The shooting cluster's own members count as near ones: their sums
    /// descend to the cells around them.
    pub(in crate::solver) fn next_chunk(&self, u: &Underway) -> Option<(Chunk, Cursor, u64)> {
        let clustered = matches!(u.how, How::Cluster { .. });
        let member = |j: usize| clustered && self.clusters.of(PolygonId(j as u32)) == u.cluster;
        u.plan.next(&self.mesh.polygons, &self.receives, member)
    }

    /// Culls, gathers and (once its polygons are whole) applies one chunk
    /// of the step `u`; `None` once `cancel` is set or what it gathered is
    /// not finite ([`Progressive::fault`]), with nothing of the chunk
    /// applied.
    pub(in crate::solver) fn run_chunk(
        &mut self,
        u: &mut Underway,
        chunk: Chunk,
        cancel: &AtomicBool,
    ) -> Option<()> {
        match chunk {
            Chunk::Whole { polygons, vertices } => {
                self.cull_chunk(u, polygons.clone());
                let gathered = self.gather_chunk(u, vertices, Stage::All, cancel)?;
                u.gathered.add(gathered);
                if !self.gathered_is_finite(polygons.clone()) {
                    self.fail(self.steps + 1, u, StepPhase::Gather);
                    return None;
                }
                self.apply_chunk(u, polygons);
            }
            Chunk::Piece {
                polygon,
                vertices,
                all,
                pass,
                first,
                last,
            } => {
                let two_passes = u.plan.two_passes();
                let stage = match pass {
                    Pass::Exact => {
                        if first {
                            self.cull_chunk(u, polygon..polygon + 1);
                        }
                        Stage::Exact {
                            copy: (last && two_passes).then(|| all.clone()),
                        }
                    }
                    Pass::Interpolated => Stage::Interpolated {
                        charge: last.then(|| all.clone()),
                    },
                };
                let gathered = self.gather_chunk(u, vertices, stage, cancel)?;
                u.gathered.add(gathered);
                let done = last && (pass == Pass::Interpolated || !two_passes);
                if done {
                    if !self.gathered_is_finite(polygon..polygon + 1) {
                        self.fail(self.steps + 1, u, StepPhase::Gather);
                        return None;
                    }
                    self.apply_chunk(u, polygon..polygon + 1);
                }
            }
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Polygons of these vertex counts, contiguous.
    fn polygons(counts: &[u32]) -> Vec<PolygonMesh> {
        let mut start = 0;
        counts
            .iter()
            .map(|&n| {
                let p = PolygonMesh {
                    nu: 1,
                    nv: 1,
                    vertices: start..start + n,
                    elements: 0..0,
                    normal: glam::Vec3::Y,
                    area: 1.0,
                    min_edge: 1.0,
                    inset: 0.0,
                    levels: 0,
                    layer: 0,
                    has_back: false,
                    sky: false,
                    stitched: false,
                };
                start += n;
                p
            })
            .collect()
    }

    /// Every chunk of a plan, in order.
    fn chunks(plan: Plan, polygons: &[PolygonMesh], receives: &[bool]) -> Vec<Chunk> {
        let mut plan = plan;
        let mut out = Vec::new();
        while let Some((chunk, after, _)) = plan.next(polygons, receives, |_| false) {
            assert!(!plan.finished(polygons.len()));
            out.push(chunk);
            plan.advance(after);
        }
        assert!(plan.finished(polygons.len()));
        out
    }

    /// Work a vertex in the tests: 1,024 vertices a full chunk.
    const PER_VERTEX: usize = (CHUNK_WORK / 1_024) as usize;

    #[test]
    fn without_parts_a_step_is_one_chunk_of_everything() {
        let p = polygons(&[10, 0, 50_000, 3]);
        let got = chunks(Plan::new(PER_VERTEX, true, false), &p, &[true; 4]);
        assert_eq!(
            got,
            vec![Chunk::Whole {
                polygons: 0..4,
                vertices: 0..50_013
            }]
        );
    }

    #[test]
    fn every_receiving_vertex_is_taken_once_in_each_pass() {
        // 1,024 vertices a chunk.
        let counts = [600, 600, 0, 5_000, 100, 2_100, 7];
        let p = polygons(&counts);
        let receives = [true, true, false, true, true, false, true];
        for two_passes in [false, true] {
            let got = chunks(Plan::new(PER_VERTEX, two_passes, true), &p, &receives);
            let total: u32 = counts.iter().sum();
            // Whole chunks cover polygons once; pieces cover each pass.
            let mut exact = vec![0u8; total as usize];
            let mut second = vec![0u8; total as usize];
            let mut next_polygon = 0;
            for c in &got {
                match c {
                    Chunk::Whole { polygons, vertices } => {
                        assert_eq!(polygons.start, next_polygon);
                        next_polygon = polygons.end;
                        let work: u64 = polygons
                            .clone()
                            .filter(|&j| receives[j])
                            .map(|j| u64::from(counts[j]) * PER_VERTEX as u64)
                            .sum();
                        assert!(work <= CHUNK_WORK || polygons.len() == 1);
                        for l in vertices.clone() {
                            exact[l] += 1;
                            second[l] += 1;
                        }
                    }
                    Chunk::Piece {
                        polygon,
                        vertices,
                        pass,
                        ..
                    } => {
                        assert_eq!(*polygon, 3, "only the 5,000-vertex polygon is cut");
                        assert!(vertices.len() <= 1_024);
                        next_polygon = polygon + 1;
                        let into = match pass {
                            Pass::Exact => &mut exact,
                            Pass::Interpolated => &mut second,
                        };
                        for l in vertices.clone() {
                            into[l] += 1;
                        }
                    }
                }
            }
            assert_eq!(next_polygon, counts.len());
            assert!(exact.iter().all(|&n| n == 1));
            let second_expected = if two_passes { 1 } else { 0 };
            for (l, &n) in second.iter().enumerate().take(6_200).skip(1_200) {
                assert_eq!(n, second_expected, "vertex {l}");
            }
            // The large polygon's pieces: 5 per pass, first and last marked.
            let pieces: Vec<_> = got
                .iter()
                .filter_map(|c| match c {
                    Chunk::Piece {
                        pass, first, last, ..
                    } => Some((*pass, *first, *last)),
                    _ => None,
                })
                .collect();
            assert_eq!(pieces.len(), if two_passes { 10 } else { 5 });
            assert_eq!(pieces[0], (Pass::Exact, true, false));
            assert_eq!(pieces[4], (Pass::Exact, false, true));
            if two_passes {
                assert_eq!(pieces[5], (Pass::Interpolated, true, false));
                assert_eq!(pieces[9], (Pass::Interpolated, false, true));
            }
        }
    }

    #[test]
    fn chunks_shrink_at_once_to_their_target_time_and_grow_slowly() {
        let mut plan = Plan::new(PER_VERTEX, false, true);
        plan.observe(false, CHUNK_WORK, CHUNK_TARGET * 4);
        assert_eq!(plan.limit, CHUNK_WORK / 4);
        plan.observe(false, CHUNK_WORK / 4, CHUNK_TARGET / 4);
        assert_eq!(plan.limit, CHUNK_WORK * 5 / 16);
        plan.observe(false, CHUNK_WORK, Duration::from_nanos(1));
        assert_eq!(plan.limit, CHUNK_WORK * 25 / 64);
        for _ in 0..10 {
            plan.observe(false, CHUNK_WORK, Duration::from_nanos(1));
        }
        assert_eq!(plan.limit, CHUNK_WORK);
        plan.observe(false, CHUNK_WORK, Duration::from_secs(100));
        assert_eq!(plan.limit, CHUNK_WORK / 64);
        // Pieces grow faster and past the cap, to theirs.
        plan.observe(true, CHUNK_WORK, CHUNK_TARGET / 16);
        assert_eq!(plan.piece_limit, CHUNK_WORK * 3 / 2);
        for _ in 0..10 {
            plan.observe(true, CHUNK_WORK, Duration::from_nanos(1));
        }
        assert_eq!(plan.piece_limit, PIECE_WORK);
        plan.observe(true, CHUNK_WORK, CHUNK_TARGET * 2);
        assert_eq!(plan.piece_limit, CHUNK_WORK / 2);
        // Chunks follow the limit.
        let p = polygons(&[16; 40]);
        let got = chunks(plan, &p, &[true; 40]);
        assert_eq!(got.len(), 40, "one 1,024-pair polygon a chunk");
    }

    #[test]
    fn polygons_near_the_shooter_count_more() {
        let p = polygons(&[128; 32]);
        let plan = Plan::new(PER_VERTEX, false, true);
        let (chunk, _, work) = plan.next(&p, &[true; 32], |_| false).unwrap();
        assert_eq!(
            (chunk, work),
            (
                Chunk::Whole {
                    polygons: 0..8,
                    vertices: 0..1_024
                },
                CHUNK_WORK
            )
        );
        let (chunk, _, work) = plan.next(&p, &[true; 32], |_| true).unwrap();
        assert_eq!(
            (chunk, work),
            (
                Chunk::Whole {
                    polygons: 0..1,
                    vertices: 0..128
                },
                CHUNK_WORK
            )
        );
    }

    #[test]
    fn a_large_polygon_that_does_not_receive_is_not_cut() {
        let p = polygons(&[100_000, 10]);
        let got = chunks(Plan::new(PER_VERTEX, true, true), &p, &[false, true]);
        assert_eq!(
            got,
            vec![Chunk::Whole {
                polygons: 0..2,
                vertices: 0..100_010
            }]
        );
    }
}
