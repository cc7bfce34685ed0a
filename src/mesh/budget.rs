//! The default mesh's vertex budget. Without `--lenmax`, a scene is cut at
//! [`DEFAULT_LENMAX_FRACTION`] of its bounding-box diagonal, unless that
//! mesh would have more than [`VERTEX_BUDGET`] element vertices: a solve
//! step costs about the same per vertex whatever the scene, so a game
//! level of 70,000 triangles cut that fine (three quarters of a million
//! vertices) takes hours where a few minutes were wanted. Such a scene is
//! cut at the finest lenmax whose mesh stays within the budget, found from
//! the size estimate ([`Sizes`]) without building a mesh, and a line says
//! what was chosen and how to get a finer mesh. A run on such a mesh then
//! refines it once where the light changes most
//! ([`crate::config::RunConfig::refinement`]). An explicit lenmax is never
//! changed; nor is the default of a scene within the budget (every bundled
//! scene, by a factor of 23 or more).
//!
//! A polygon never has fewer vertices than its corners, so the budget has
//! a floor: when even one element per polygon ([`Sizes::least`]) is over
//! the budget, the scene is cut at the coarsest lenmax that still changes
//! the mesh ([`Sizes::coarsest`]), and the line says so.

#[cfg(doc)]
use super::DEFAULT_LENMAX_FRACTION;
use super::{MeshOptions, Sizes};
use crate::scene::Scene;
use std::fmt;

/// Most element vertices a default mesh may have, by [`Sizes::at`]'s
/// estimate: the budget above.
///
/// Chosen 2026-12-06 from whole solves of the Sauerbraten level
/// `zdm2.obj` under `--sky 1` on two cores (`docs/performance.md`), timed
/// and compared with a path tracer's 4,096-sample picture of one view by
/// `scripts/pathtrace/timing.py` (relative L1 on 4 × 4 blocks):
///
/// | lenmax | vertices built | error | CPU |
/// |---|---|---|---|
/// | 182 (one element per polygon) | 429,068 | 5.85 % | 125 s |
/// | 27 | 506,660 | 2.84 % | 181 s |
/// | **25.3 (this budget)** | 512,769 | 2.73 % | 190 s, 105 s wall |
/// | 20 | 574,595 | 2.66 % | 240 s |
/// | 13.85 (the diagonal's 1/80) | 765,478 | 2.55 % | 317 s, 189 s wall |
///
/// The level's 70,000 triangles have 210,000 corners, twice that with the
/// back copies of two-sided faces, so one element per polygon is already
/// about 410,000 vertices; the first 100,000 vertices past that split its
/// large walls and floors, where the sky's shadows fall, and take the
/// error from 5.9 % to 2.7 %; the next 250,000 buy a tenth of a percent
/// more for half as much time again. Most of a solve's time is the sky's
/// 80 steps (about 4 µs of one core per vertex each, 6.6 µs once the
/// arrays outgrow the caches) and the particle tail's three or four
/// steps; the reflected light's shooting steps before the tail are few.
/// The largest default mesh that `docs/performance.md` times, two spheres
/// of 224 segments in the Cornell box (312,235 vertices), keeps its
/// default.
///
/// The estimate counts each polygon's own grid: the vertices that
/// stitching adds where polygons meet ([`super::stitch`]) are under half a
/// percent more on the bundled scenes, but 3 to 18 % more on the game
/// levels measured (`zdm2.glb` with the facets of `--sky 1`: 339,941
/// estimated, 401,255 built; `zdm2.obj` at lenmax 25.3: 468,191
/// estimated, 512,769 built).
pub const VERTEX_BUDGET: u64 = 470_000;

/// The lenmax a scene is meshed at when none is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DefaultLenmax {
    /// The lenmax, in scene units: [`DEFAULT_LENMAX_FRACTION`] of the
    /// scene's diagonal, or coarser when that is over the budget.
    pub lenmax: f32,
    /// What the budget changed, when it changed anything.
    pub coarsened: Option<Coarsened>,
}

/// A default mesh the vertex budget made coarser than the diagonal's
/// fraction: what its [`fmt::Display`] line tells the user.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coarsened {
    /// The lenmax chosen, in scene units (three significant digits).
    pub lenmax: f32,
    /// Estimated element vertices at that lenmax (before stitching,
    /// which adds a few percent).
    pub vertices: u64,
    /// The lenmax the diagonal's fraction gives, in scene units.
    pub fine_lenmax: f32,
    /// Estimated element vertices at `fine_lenmax`.
    pub fine_vertices: u64,
    /// The budget, in vertices.
    pub budget: u64,
    /// True when even one element per polygon is over the budget:
    /// `lenmax` is then the coarsest that changes the mesh.
    pub over_budget: bool,
}

impl MeshOptions {
    /// The default options for a scene within a vertex budget: those of
    /// [`MeshOptions::for_scene`], with a coarser lenmax when their mesh
    /// would have more than `budget` element vertices
    /// ([`default_lenmax`]).
    pub fn within_budget(scene: &Scene, budget: u64) -> (MeshOptions, Option<Coarsened>) {
        let options = MeshOptions::for_scene(scene);
        let chosen = default_lenmax(scene, options.lenmax, budget);
        (
            MeshOptions {
                lenmax: chosen.lenmax,
                ..options
            },
            chosen.coarsened,
        )
    }
}

/// The finest lenmax not below `fine` (scene units, positive) whose mesh
/// has at most `budget` element vertices by [`Sizes::at`]'s estimate,
/// rounded up to three significant digits; `fine` itself when its mesh is
/// within the budget; [`Sizes::coarsest`] when no lenmax is.
pub fn default_lenmax(scene: &Scene, fine: f32, budget: u64) -> DefaultLenmax {
    let sizes = Sizes::of(scene);
    let fine_vertices = sizes.at(fine).vertices;
    if fine_vertices <= budget {
        return DefaultLenmax {
            lenmax: fine,
            coarsened: None,
        };
    }
    let (lenmax, over_budget) = match sizes.smallest_fitting(fine, |s| s.vertices <= budget) {
        Some(lenmax) => (lenmax, false),
        None => (sizes.coarsest(), true),
    };
    if lenmax <= fine {
        // Already one element per polygon: nothing coarser helps.
        return DefaultLenmax {
            lenmax: fine,
            coarsened: None,
        };
    }
    DefaultLenmax {
        lenmax,
        coarsened: Some(Coarsened {
            lenmax,
            vertices: sizes.at(lenmax).vertices,
            fine_lenmax: fine,
            fine_vertices,
            budget,
            over_budget,
        }),
    }
}

impl fmt::Display for Coarsened {
    /// One line, no trailing period: `mesh coarsened to lenmax 41.2 (an
    /// estimated 300,000 vertices, within the budget of 300,000; the
    /// default 13.85 would give 766,000): give --lenmax for a finer one`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "mesh coarsened to lenmax {}", self.lenmax)?;
        if self.over_budget {
            write!(f, ", one element per polygon")?;
        }
        write!(
            f,
            " (an estimated {} vertices, {} the budget of {}; the default {} would give {}): \
             give --lenmax for a finer one",
            about(self.vertices),
            if self.over_budget { "over" } else { "within" },
            about(self.budget),
            significant(self.fine_lenmax, 4),
            about(self.fine_vertices)
        )
    }
}

/// `x` to `digits` significant digits, printed as briefly as it reads:
/// `13.852257` to `13.85`.
fn significant(x: f32, digits: i32) -> f64 {
    let x = x as f64;
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    // Scaled by an exact power of ten either way, so 13.85 prints so.
    let shift = digits - 1 - x.abs().log10().floor() as i32;
    if shift >= 0 {
        let scale = 10f64.powi(shift);
        (x * scale).round() / scale
    } else {
        let scale = 10f64.powi(-shift);
        (x / scale).round() * scale
    }
}

/// A count as the message shows it: to the nearest thousand from 10,000
/// up (the estimate is a few percent short of the stitched mesh anyway),
/// with thousands separators.
fn about(n: u64) -> String {
    crate::budget::fmt_count(if n >= 10_000 {
        (n + 500) / 1000 * 1000
    } else {
        n
    })
}

#[cfg(test)]
mod tests;
