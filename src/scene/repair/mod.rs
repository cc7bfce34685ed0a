//! The passes that make real exports solvable, and the one order they run
//! in ([`run`]): closed solids keep their outside
//! ([`Scene::orient_solids`], `solids.rs`), polygons are cut where others
//! pass through them ([`Scene::split_intersections`], `split.rs`),
//! two-sided faces get their back copies ([`Scene::with_sides`],
//! `sides.rs`), and an emitting side trapped under a ceiling falls silent
//! ([`Scene::silence_covered_sides`], `trapped.rs`). Beside them,
//! `coplanar.rs` is the rule for polygons in one plane that the visibility
//! tests and the picture follow (they never block each other, overlaps are
//! drawn in a fixed order: [`plane_classes`](crate::scene::plane_classes),
//! [`draw_layers`](crate::scene::draw_layers)); it needs no pass.

pub(super) mod coplanar;
pub(super) mod sides;
pub(super) mod solids;
pub(super) mod split;
pub(super) mod trapped;
pub(super) mod unreached;

use crate::budget::{MemoryBudget, OverBudget};
use crate::cancel::{Cancel, Cancelled};
use crate::scene::{PolygonError, PolygonId, Scene, Sides, SkyLight, SplitStats, SplitStop};
use glam::Vec3;

/// What the repair passes are told: the choices of the command line that
/// change geometry.
#[derive(Clone, Copy, Debug)]
pub struct RepairOptions<'a> {
    /// Which faces are two-sided (`--sides`).
    pub sides: Sides,
    /// The `--sky` enclosure, when one is asked for (see
    /// [`Scene::add_sky_light`]).
    pub sky: Option<SkyLight>,
    /// The scene's name as the warnings give it.
    pub file: &'a str,
    /// The memory the repaired scene may take: the splitting along
    /// intersections stops when its pieces would need more
    /// ([`Scene::split_intersections_in`]).
    pub budget: MemoryBudget,
}

/// Why the repair passes could not finish.
#[derive(Debug, thiserror::Error)]
pub enum RepairError {
    /// The `--sky` enclosure would lie beyond
    /// [`MAX_COORDINATE`](crate::scene::MAX_COORDINATE).
    #[error("{0}")]
    Sky(#[from] PolygonError),
    /// Splitting along intersections would make more pieces than the
    /// memory budget allows.
    #[error("{0}")]
    Memory(#[from] OverBudget),
    /// The cancellation token was set during the passes
    /// ([`run_cancellable`]).
    #[error("{0}")]
    Interrupted(#[from] Cancelled),
}

/// Rays cast into the finished scene, which the trapped-sides pass needs:
/// the scene stays below the visibility code, so whoever runs the passes
/// supplies them (the BVH, or brute force in a test).
pub trait FirstHit {
    /// The nearest polygon along the ray from `origin` in the unit
    /// `direction`, and the distance to it in scene units, or `None` when
    /// the ray leaves the scene.
    fn first_hit_polygon(&self, origin: Vec3, direction: Vec3) -> Option<(PolygonId, f32)>;

    /// The distance of [`FirstHit::first_hit_polygon`] alone.
    fn first_hit_distance(&self, origin: Vec3, direction: Vec3) -> Option<f32> {
        self.first_hit_polygon(origin, direction).map(|hit| hit.1)
    }
}

/// What [`run`] did besides changing the scene.
#[derive(Debug)]
pub struct RepairReport<R> {
    /// What splitting along intersections did.
    pub split: SplitStats,
    /// The rays built on the finished scene to look for trapped sides,
    /// when some face emits from both sides (else none were built).
    pub rays: Option<R>,
    /// Back copies left out because no light can reach them
    /// (`unreached.rs`).
    pub unreached_backs: usize,
}

/// Runs the repair passes on a loaded scene whose emission (`--emit`,
/// `--ies`) is set, pushing their warnings onto [`Scene::warnings`] in
/// the order the passes run, and returns the repaired scene. `build_rays`
/// is called on the scene before its back copies are made, when some
/// polygon would get one, to find the backs no light reaches
/// (`unreached.rs`), and on the finished scene, when some face emits from
/// both sides ([`Scene::emits_from_both_sides`]).
///
/// Fails when the `--sky` enclosure would lie beyond
/// [`MAX_COORDINATE`](crate::scene::MAX_COORDINATE), or when splitting
/// would go over [`RepairOptions::budget`].
pub fn run<R: FirstHit + Sync>(
    scene: Scene,
    options: &RepairOptions<'_>,
    build_rays: impl FnMut(&Scene) -> R,
) -> Result<(Scene, RepairReport<R>), RepairError> {
    run_cancellable(scene, options, build_rays, &Cancel::never())
}

/// [`run`], stopping with [`RepairError::Interrupted`] soon after `cancel`
/// is set: it is checked between the passes and per polygon while
/// splitting, the pass that can take long.
pub fn run_cancellable<R: FirstHit + Sync>(
    mut scene: Scene,
    options: &RepairOptions<'_>,
    mut build_rays: impl FnMut(&Scene) -> R,
    cancel: &Cancel,
) -> Result<(Scene, RepairReport<R>), RepairError> {
    cancel.check()?;
    // Solids keep their outside only. Found before the cuts, which leave
    // T-junctions on a box sunk into a floor; the pieces keep the mark.
    if let Some(warning) = scene.orient_solids(options.sides, options.file) {
        scene.warnings.push(warning);
    }
    // Not a quirk of the file, so no warning: geometry passing through
    // geometry is how models are built. Before the back copies, so that
    // each piece gets its own.
    let split = scene
        .split_intersections_in(&options.budget, cancel)
        .map_err(|stop| match stop {
            SplitStop::Memory(e) => RepairError::Memory(e),
            SplitStop::Interrupted(c) => RepairError::Interrupted(c),
        })?;
    // Backs only where light can reach them: on the scene as it is, so
    // that the rays meet each face once.
    cancel.check()?;
    let two_sided = scene.would_get_backs(options.sides);
    let mut unreached_backs = 0;
    let keep = if options.sides != Sides::Two && two_sided.iter().any(|&t| t) {
        let rays = build_rays(&scene);
        let reached =
            unreached::reached_backs(&scene, &two_sided, options.sky.is_some(), &rays, cancel)?;
        unreached_backs = two_sided
            .iter()
            .zip(&reached)
            .filter(|&(&t, &r)| t && !r)
            .count();
        reached
    } else {
        vec![true; scene.polygons.len()]
    };
    cancel.check()?;
    let mut scene = scene.with_sides_where(options.sides, &keep);
    // A luminaire's back is a back copy, or made here as one: after the
    // back copies, so that it finds those of a two-sided scene.
    scene.light_luminaire_backs();
    // Last, after everything that adds or changes polygons, so that the
    // enclosure is built around the finished scene.
    if let Some(sky) = &options.sky {
        scene.add_sky_light(sky)?;
    }
    // An emitting face with two sides, one just under a ceiling, emits
    // from the other only. Rays find the gap, so they are cast on the
    // finished geometry, sky included (silencing a side changes only a
    // material, so they stay valid and are handed back).
    let mut rays = None;
    cancel.check()?;
    if scene.emits_from_both_sides() {
        let built = build_rays(&scene);
        let first_hit = |origin, direction| built.first_hit_distance(origin, direction);
        if let Some(warning) = scene.silence_covered_sides(first_hit, options.file) {
            scene.warnings.push(warning);
        }
        rays = Some(built);
    }
    Ok((
        scene,
        RepairReport {
            split,
            rays,
            unreached_backs,
        },
    ))
}
