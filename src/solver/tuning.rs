//! Every tuning constant of the solver, one index.
//!
//! Each number below was chosen by a measurement or a stated judgement;
//! its doc comment says which (the figures are in `docs/performance.md`
//! and `docs/accuracy.md`, their history in `docs/changelog.md`). They
//! are grouped by the phase of a step that reads them; the modules that
//! use them import them from here, so a change to any is a change to this
//! one file. [`INDEX`] lists them all with their values, and a
//! checkpoint's fingerprint hashes it ([`super::checkpoint::fingerprint`]):
//! a state saved by a build tuned otherwise is never resumed into a
//! different answer.
//!
//! | phase | read in | constants |
//! |---|---|---|
//! | choosing the shooter | `step::choose` | [`DEFAULT_THRESHOLD`], [`DEFAULT_SETTLE`], [`SETTLE_FLOOR`], [`PENDING_EMISSION`], [`OVERSHOOT_SHARE`], [`MAX_SPEND_SCALE`] |
//! | reading the shooter, and the set-up | `step::read`, `accel::cluster`, `accel::subcells` | [`DEFAULT_SHOOTER_SAMPLES`], [`SKY_FACET_SAMPLES`], [`FULL_STRATA_SHARE`], [`MIN_STRATA`], [`CLUSTER_EXTENT`], [`SUBCELL_ELEMENTS_PER_CELL`], [`SUBCELL_LEAF_RATIO`], [`SUBCELL_FAR_SCALE`], [`SUBCELL_CLOSE`], [`SUBCELL_REACH`], [`SUBCELL_EDGE_MARGIN`] |
//! | culling | `step::cull` | [`TILE_VERTICES`], [`SHOOTER_GROUP`], [`SHAFT_MIN_VERTICES`], [`REFINE_MAX`], [`LINEAR_CANDIDATES`] |
//! | gathering | `step::gather`, `accel` | [`EXACT_RATIO`], [`NEAR_FIELD_RATIO`], [`RECEIVER_STRIDE`], [`CHECK_TOLERANCE`], [`RECEIVER_WEAK_SHARE`], [`RECEIVER_ERROR_BUDGET`], [`CROWD_RATIO`], [`RECEIVER_NEAR_RATIO`], [`FACET_NEAR_RATIO`], [`FACET_SCALE_RATIO`], [`SKY_PROBES`], [`SKY_CELLS`], [`SKY_CELL_STRATA`], [`SKY_GRAZING_Z`], [`SKY_CHUNK_VERTICES`], [`MIN_PROBES`], [`SHARE_CREASE_DEG`], [`FAR_SHOOTER_RATIO`], [`FAR_PROBES`], [`PAR_RUN`], [`PARALLEL_CHARGES`] |
//! | gathering from a cluster | `step::gather_cluster`, `accel::cluster` | [`WEAK_STRATUM_SHARE`], [`STRATUM_NEAR_RATIO`], [`PLANE_DEPTH_RATIO`], [`TOP_DEPTH_RATIO`], [`RESTING_NEAR_FACTOR`], [`RESTING_TOLERANCE`] |
//! | delivering a step in parts | `step::parts` | [`CHUNK_WORK`], [`PIECE_WORK`], [`CHUNK_GROWTH`], [`PIECE_GROWTH`], [`CHUNK_TARGET`], [`NEAR_WEIGHT`], [`WINDOW_PART_BUDGET`] |
//! | the hemicube | `hemicube` | [`DEFAULT_HEMICUBE_RES`], [`HEMICUBE_EDGE_SLACK`], [`HEMICUBE_NEAR_FRACTION`] |
//! | the particle tail | `step::tail`, `step::tail_gather` | [`TAIL_AUTO_FROM`], [`TAIL_AUTO_VERTICES`], [`TAIL_COSTLY_RATIO`], [`TAIL_EARLY_FROM`], [`TAIL_PARTICLES_PER_VERTEX`], [`TAIL_GATHER_RAYS`], [`TAIL_GATHER_BATCH`], [`TAIL_GATHER_PART_BATCH`], [`TAIL_STEPS`], [`TAIL_CHUNK`], [`TAIL_BATCH`], [`TAIL_PART_BATCH`], [`TAIL_MAX_BOUNCES`], [`TAIL_SURVIVAL_MAX`] |
//! | carrying a solve to a refined mesh | `carry` | [`CARRY_GATHER_RAYS`], [`CARRY_EXACT_SAMPLES`], [`CARRY_CHUNK_VERTICES`] |
//!
//! Structural constants (how many ray slots a cluster step keeps, the
//! sub-cell grid's side, file-format fields) stay with the code whose
//! layout they are; the approximation switches are
//! [`super::Approximations`].

use std::time::Duration;

#[cfg(doc)]
use super::{
    accel::{cluster, facets, far_shooters, probes, receivers, subcells},
    hemicube,
    kernel::formfactor,
    step, Approximations, Progressive, ShooterSamples, SolverOptions,
};

// ---- Choosing the shooter: step::choose: the order of shooting, overshooting, settling, the stopping rule ----

/// Default fraction of the initial unshot power at which solving stops.
pub const DEFAULT_THRESHOLD: f64 = 1e-3;

/// Default settling tolerance ([`SolverOptions::settle`]): past the
/// threshold, a point still holding more than 2 % of its radiosity to
/// send is shot. The error this leaves in a pocket is about half of it:
/// on the spheres of 32 segments, against the clustered solve at 10⁻⁶,
/// worst polygon 1.05 %, against 0.60 % at 1 % and 2.2 % at 4 %; against
/// the brute-force solve at 10⁻⁶, seven facets 2.0 to 2.4 % off
/// (`docs/accuracy.md`, "Settling").
pub const DEFAULT_SETTLE: f64 = 0.02;

/// Points darker than this fraction of the mean radiosity over the
/// reflecting area count as this bright for settling
/// ([`SolverOptions::settle`]): a point in a contact shadow holding
/// light of no consequence does not keep the solve going.
pub const SETTLE_FLOOR: f64 = 0.01;

/// An emitter whose unshot power is at least this share of the power it
/// emits has not shot its light yet, and shoots before any reflector
/// (`Progressive::choose_pending_emitter`). Once shot, what it holds is
/// the light it reflects, far less in any ordinary scene.
pub const PENDING_EMISSION: f64 = 0.5;

/// The share of the ambient term ([`Progressive::ambient`]) times its
/// reflectance that a point may expect to receive later, and so send ahead
/// when it shoots ([`Approximations::overshoot`], `Expectation`). The
/// ambient term counts every bounce still to come as if spread evenly;
/// measured as the only expectation on the 15-, 30- and 60-table halls and
/// the 32-segment spheres (`docs/performance.md`), half of it took the
/// fewest rays (0.35 and 0.65 within a few per cent, 1 and 2 10 to 30 %
/// more, some steps sending light back).
pub const OVERSHOOT_SHARE: f64 = 0.5;

/// The largest factor by which `send_what_is_spent` scales a channel
/// of a shooter's samples (or its inverse, the smallest). Beyond it the
/// samples' reading is no estimate of the polygon's power (a field of
/// both signs summing to nearly nothing, under overshooting), and is
/// left as it is.
pub const MAX_SPEND_SCALE: f64 = 4.0;

// ---- Reading the shooter: step::read and the set-up of samples: shooter cells, sky facets, strata, clusters, sub-cells ----

/// Default cap on shooter sample points (see [`ShooterSamples::AtMost`]).
/// With the near field the unoccluded form factors of unit squares (exact
/// 0.19982 parallel, 0.20004 perpendicular) are within 0.06 % at 16, 64 or
/// 256 points; what the count buys is visibility: each point casts one
/// shadow ray, so penumbrae are sampled by as many rays. 64 resolves a
/// room's shadows without visible banding and keeps a step on a
/// 14,000-vertex mesh under a million rays; 256 quadruples the rays.
pub const DEFAULT_SHOOTER_SAMPLES: u32 = 64;

/// Points a sky facet ([`crate::scene::Surface::sky`]) shoots from,
/// whatever `--shooter-samples` and `--form-factor` say: a facet is one
/// element, yet it subtends a large solid angle, and its points are the
/// directions sky light comes from. With the 80 facets of
/// [`crate::scene::SKY_SUBDIVISIONS`] this makes 20,480 directions.
///
/// Measured on the floor under a 1 × 1 skylight 2 units up (the solver's
/// `sky_light_through_a_skylight_*` tests, lenmax 0.05), as the largest
/// departure of a vertex from the mean of its neighbours (roughness) and
/// from Lambert's exact value, both relative to the peak: a regular grid
/// of 16 a facet gave 12 % and 9 % (rows of directions enter through the
/// window's edge at once); jittered, 16 gave 8.4 % and 11 %, 64 gave 3.8 %
/// and 5.7 %, 144 gave 2.4 % and under 4 %, 256 gives 1.5 % and 2.6 %
/// (exact profile: 0.1 %). Rays grow with the count: an open courtyard of
/// 7,353 vertices solves in 0.5 s at 16, 2.2 s at 64, 3.5 s at 144 and
/// 4.3 s at 256 on two cores.
pub const SKY_FACET_SAMPLES: u32 = 256;

/// A clustered step that shoots at least this fraction of the initial
/// unshot power shoots from as many strata as the shooter sample cap; a
/// weaker one from fewer, by the square root of its share of this, at
/// least [`MIN_STRATA`]: a stratum's one ray decides the visibility of its
/// whole power, so the weaker the light the coarser its strata may be (the
/// power oracle of Hanrahan, Salzman and Aupperle's BF refinement). At
/// 1 % the two spheres of 32 segments in the Cornell box solve in 18 s
/// rather than 29 s, with the picture 0.05 % from the unclustered solve;
/// at 5 %, 17 s and 0.1 %.
pub const FULL_STRATA_SHARE: f64 = 0.01;

/// The fewest strata a clustered step shoots from (unless its cells are
/// fewer).
pub const MIN_STRATA: usize = 8;

/// A cluster is at most this fraction of the scene's extent (the diagonal
/// of its bounds) across. Larger clusters mean fewer steps but more
/// receivers in their near field and fewer strata per object. Measured
/// (solve seconds, two cores): the hall of 1,000 polygons took 25.6 s at a
/// quarter and 30.9 s at a half; two spheres of 16 segments in the Cornell
/// box 7.1 s at both, 10.9 s at an eighth; the picture within 0.07 % of
/// the unclustered solve in every case.
pub const CLUSTER_EXTENT: f32 = 0.25;

/// A cell is split when it stands for more than this many of its
/// polygon's elements (by area): finer than that, its centre's reading is
/// already what its elements hold.
pub const SUBCELL_ELEMENTS_PER_CELL: f64 = 4.0;

/// A receiver within this many of a sub-cell's diameters takes the sub-cell as
/// its leaves (the distance within which a sub-cell takes Lambert's exact
/// form factor).
pub const SUBCELL_LEAF_RATIO: f32 = EXACT_RATIO;

/// A receiver farther than this factor of the cell's exact radius
/// ([`formfactor::ShooterSample::exact_r2`], itself 1.5 cell diameters), 2 cell
/// diameters, is more than 6 of a sub-cell's diameters from every sub-cell, and
/// takes their point terms, four at a time; nearer, each sub-cell is taken by
/// the rules of a cell (Lambert's exact form factor within 1.5 of its
/// diameters, its quadrature within 6, its point term beyond).
pub const SUBCELL_FAR_SCALE: f32 = 2.0 / 1.5;

/// How close over a shooter's plane, in cell diameters, a point must
/// stand to count (`Over`).
pub const SUBCELL_CLOSE: f32 = 0.5;

/// How near a cell's centre, in cell diameters, a point must stand to
/// count (`Over`).
pub const SUBCELL_REACH: f32 = 1.0;

/// How far inside a shooter's edges, in cell diameters, a point must
/// stand over it to count as over its inside (`Over`).
pub const SUBCELL_EDGE_MARGIN: f32 = 0.01;

// ---- Culling: step::cull: shafts between shooter and receivers, and which rays ask the BVH ----

/// Receiver vertices are grouped in runs of this many consecutive vertices
/// of one polygon (a stretch of a grid row) for shaft culling: a shaft to
/// a whole wall holds most of a room, one to a short run is thin and often
/// clear. Sixteen keeps the shaft work per step well below the ray work it
/// saves.
pub const TILE_VERTICES: u32 = 16;

/// Shooter samples are grouped in runs of this many (a stretch of their
/// grid) for shaft culling, for the same reason as [`TILE_VERTICES`].
pub const SHOOTER_GROUP: usize = 8;

/// A receiver polygon with fewer element vertices than this tests its rays
/// against the BVH rather than building a shaft to the shooter: a shaft
/// query walks the BVH much as a ray does, and a small facet (a triangle
/// of a tessellated sphere) casts too few rays to pay for it. Same result
/// bits either way.
pub const SHAFT_MIN_VERTICES: u32 = 8;

/// A receiver whose shaft to the shooter holds more polygons than this
/// skips the thin shafts and tests its rays against the BVH: narrowing a
/// long list costs a box test per polygon per tile and sample group, and
/// what remains of it is still too long to test one by one. Same result
/// bits either way.
pub const REFINE_MAX: usize = 256;

/// A receiver whose shaft holds at most this many polygons tests its rays
/// against them one by one; more, and the BVH is faster.
pub const LINEAR_CANDIDATES: usize = 8;

// ---- Gathering: step::gather: form factors near a cell, receiver interpolation, shared facet rays, probes; the parallel runs ----

/// A receiver within this many cell diameters of a grid sample gets the
/// exact point-to-cell form factor: close enough that a quadrature's points
/// are no longer far compared with their spacing (1 and 2 diameters gave
/// the same errors as 1.5).
pub const EXACT_RATIO: f32 = 1.5;

/// A receiver within this many cell diameters of a grid sample gets the
/// cell's quadrature (or, closer, the exact) form factor instead of the
/// point term. Measured on a unit square of 8 × 8 cells (worst error over
/// 2,000 random receivers / over a perpendicular wall): 3 diameters give
/// 0.8 % / 0.8 %, 4 give 0.6 % / 0.6 %, 6 give 0.27 % / 0.33 %. The extra
/// terms cost arithmetic only, never a ray.
pub const NEAR_FIELD_RATIO: f32 = 6.0;

/// Every this-many rows and columns of a receiving grid (and its last row
/// and column) are evaluated exactly; the vertices between are
/// interpolated where [`receivers::accept`] allows. With 4, a large wall evaluates
/// about one vertex in eight (16 coarse vertices and a check per 25).
pub const RECEIVER_STRIDE: u32 = 4;

/// A cell is interpolated when its corners predict its check vertex to
/// this fraction of the exact value ... Chosen with [`RECEIVER_WEAK_SHARE`] on the
/// 30-table hall and the 32-segment spheres against `--exact-receivers`:
/// 2 % and 0.05 % gave pictures within 0.21 % and 0.09 %, 5 % and 0.2 %
/// within 0.60 % and 0.20 % for little more speed.
pub const CHECK_TOLERANCE: f64 = 0.02;

/// ... or to this fraction of the radiosity the check vertex already holds,
/// within [`RECEIVER_ERROR_BUDGET`].
pub const RECEIVER_WEAK_SHARE: f64 = 0.001;

/// The most interpolation error the weak rule of [`receivers::accept`] may leave at a
/// check vertex over a whole solve, as a fraction of its radiosity.
pub const RECEIVER_ERROR_BUDGET: f64 = 0.005;

/// A coarse cell is evaluated exactly at every vertex, in every step,
/// when another polygon reaches into the space in front of it up to this
/// many of its diagonals away ([`receivers::crowded_cells`]): a chair's legs on a
/// floor cell, a lamp hung just under a ceiling. Such a polygon casts a
/// shadow or closes a pocket smaller than the cell, which its five
/// exact points may all miss: interpolated, the floor around a chair leg
/// was bright where the leg hides it, the leg's foot 2.5 % too bright
/// on the 30-table hall, and the ceiling above McGuire's lamp lit by
/// light that cannot reach it, the lamp's back 2.8 % too bright.
pub const CROWD_RATIO: f32 = 0.25;

/// A coarse cell nearer the shooter's bounds than this many of its
/// diagonals is evaluated exactly (`far_from`).
pub const RECEIVER_NEAR_RATIO: f32 = 1.0;

/// A shooter sample nearer a facet's middle than this many of the facet's
/// diameters is asked per vertex rather than shared.
pub const FACET_NEAR_RATIO: f32 = 4.0;

/// A facet shares its rays when it is at most this fraction of the mesh's
/// element size across (its longest element edge).
pub const FACET_SCALE_RATIO: f32 = 0.5;

/// How many of a sky facet's directions a receiving vertex asks first.
pub const SKY_PROBES: usize = 16;

/// Cells per side of the square a vertex's hemisphere of sky directions
/// is cut into when the sky is gathered at once
/// ([`crate::solver::accel::sky_dome`]): each cell has one probe, so 576
/// probes, about as dense as the 16 of each facet facing the vertex when
/// the sky shoots facet by facet. Measured on the skylight and overhang
/// tests (`src/solver/tests/sky.rs`): 12 cells (144 probes) missed openings
/// between probes (the skylight's floor off by 14 % of its peak) and
/// made `tests/models/godot/room.glb` 3.6 % off the path tracer, 3.5 %
/// darker; 16 cells of 4 × 4 strata left the overhang's floor 4.5 % off.
pub const SKY_CELLS: usize = 24;

/// Strata per side of a cell of [`SKY_CELLS`]: 3 makes 5,184 directions a
/// vertex, about 0.0012 sr each (a facet of 80 held 256 directions of
/// 0.0006 sr). With 1,296 (12 cells of 3) the skylight's floor was 3 %
/// rough and 6 % off its peak even asking every direction.
pub const SKY_CELL_STRATA: usize = 3;

/// A cell that reaches this close to the horizon (the `z`, the cosine
/// to the normal, of its lowest stratum centre) is probed by five of its
/// strata, the column from the horizon up and the row along it
/// (`accel::sky_dome`): the concentric map's cells are equal in projected
/// solid angle, so near the horizon one spans some 24° of elevation, and
/// a window's head or sill seen at a grazing angle crosses it between
/// one probe and the next ring's. Measured on the daylight office under
/// `--sky 10000` against Mitsuba (`docs/accuracy.md`): one probe for
/// every cell made the work plane 1.46 % too bright on average, every
/// direction of these cells asked 0.23 %, the column alone 0.45 %, the
/// five 0.23 %; `room.glb`'s sky step casts 183 M rays asking every
/// direction of these cells, 152 M with the five.
pub const SKY_GRAZING_Z: f32 = 0.25;

/// Element vertices a sky step gathers in one parallel chunk (a part of
/// the step ends only between chunks): 15 to 100 ms on two cores at the
/// 700 to 1,200 rays a vertex of a real export, so a window's parts keep
/// near their budget.
pub const SKY_CHUNK_VERTICES: usize = 384;

/// A verdict needs at least this many probes in front of the receiver: a
/// facet near its horizon is seen through too few to judge.
pub const MIN_PROBES: usize = 4;

/// Vertices of two polygons at one point share their `Δrad`
/// ([`crate::solver::accel::shared`]) when the polygons' normals are at
/// most this many degrees apart (and they have one material and one
/// smoothing). A judgement, not a sweep: 15° lets the facets of a UV
/// sphere of 24 segments or more share (a game prop's, McGuire's balls),
/// and keeps the value a follower takes within the cosine error of a
/// normal 15° off (at most 3.4 % of light arriving along the normal);
/// flat triangulated walls share at any angle. On the switch test scenes
/// the share changes the radiosity by at most 0.14 % (relative L1) and
/// saves 1.3 to 1.8 times the rays; on Godot's `room.glb` under `--sky 1`,
/// 30 steps cast 76 M rays instead of 108 M (`docs/performance.md`).
pub const SHARE_CREASE_DEG: f32 = 15.0;

/// A receiving vertex at least this many shooter diameters from the
/// shooter's middle probes it first ([`far_shooters::FarShooter`]). At 12, the probes'
/// rays are at most a twelfth of the height of a table top (0.75 units)
/// apart where they pass its edge: about 0.06 units, a quarter of an
/// element of the halls' 0.25 units.
///
/// At 6 the probes missed parts of chairs: against the unclustered solve,
/// both converged to 10⁻⁵, eight chair-leg faces of the 60-table hall were
/// 2.0 to 2.5 % too bright (0.69 % with no probes at all); at 12 none is
/// over 2 % (worst 1.12 % at the default threshold), for 4 % more rays
/// there and 1.5 % more time on the 150-table hall
/// (`docs/accuracy.md`, "Far lamps probed from twelve diameters").
pub const FAR_SHOOTER_RATIO: f32 = 12.0;

/// How many of a far shooter's samples a vertex asks first; all of them
/// must face the vertex ([`probes::verdict`] with its
/// [`MIN_PROBES`]) and agree.
pub const FAR_PROBES: usize = MIN_PROBES;

/// Vertices of one polygon a worker takes at once in a gather pass
/// (`par_runs`): a small facet's three or four.
pub const PAR_RUN: usize = 4;

/// Vertices from which the check charges of a gather
/// (`gather_passes`) are made in parallel.
pub const PARALLEL_CHARGES: usize = 8_192;

// ---- Gathering from a cluster: step::gather_cluster: the far test of strata and weak strata ----

/// A stratum a receiving vertex would descend into (nearer than
/// [`STRATUM_NEAR_RATIO`] diameters) is taken as one term when
/// the bound on what it brings ([`cluster::Stratum::bound_at`], times the
/// receiver's reflectance) fits in this share of what the vertex holds,
/// the bounds of all strata so taken in a step summed (after Hanrahan,
/// Salzman and Aupperle's BF refinement: a link is refined only when what
/// it carries matters). The term is the far term, held to the bound.
/// Measured (`docs/performance.md`, Weak strata): 0.3 % takes 15 to 19 %
/// fewer rays on the halls and spheres and moves their pictures' distance
/// from the original algorithm by 0.01 %; the closed-box energy balance
/// moves from −0.43 % to −0.48 % (a lumped term misses what its stratum
/// sends from behind the centroid's side of the receiver's plane), and at
/// 1 % to −0.59 %. A receiver inside the stratum's bounding sphere never
/// takes it as one term: there the far term is furthest off (a facet
/// touching the floor), always the same way, and a solve of many weak
/// steps (overshooting makes them) added it up to 3.2 % at a sphere's
/// contact, converged, against `--no-clustering` (1.1 % since).
pub const WEAK_STRATUM_SHARE: f64 = 3e-3;

/// A receiver within this many stratum diameters of a stratum's bounding
/// box descends to the stratum's halves rather than taking one far term.
/// One cluster's shot from a tiled unit square to a parallel and a
/// perpendicular square (test `a_cluster_shot_matches_lambert`): worst
/// vertex error 0.64 % of the peak at 1.5, 0.43 % at 2, 0.24 % at 3; the
/// nearer, the fewer rays.
pub const STRATUM_NEAR_RATIO: f32 = 2.0;

/// A stratum is in front of a receiver's plane, for one far term, when
/// its bounding box's centre lies at least this many of the box's half
/// depths along the receiver's normal in front of it: the box lies in
/// front, and the receiver's cosine varies over it by at most 1/this of
/// its value at the centre either way, however wide the box is across the
/// normal (a run of floor cells seen from the ceiling).
///
/// At 1.5 (the cosine within ±67 %) the floor under a sphere resting on
/// it came out dark: there the receiver's cosine is small and varies
/// much over a stratum of the sphere's lower rings, which the far term
/// misses, and light goes back and forth between the two surfaces, each
/// bounce bringing the error back. On the 32-segment spheres the facets
/// at the contact were 2.15 % off the unclustered solve (2.40 %
/// converged to 10⁻⁶); at 3 the worst polygon anywhere is 1.25 % (1.14 %
/// converged), for 4 % more rays there and 1.3 % more on the 150-table
/// hall. 2 and 2.5 left the contact as it was; 4 gave 0.73 % converged
/// for 6 % more rays (`docs/accuracy.md`, "The plane test near a sphere's
/// contact").
pub const PLANE_DEPTH_RATIO: f32 = 3.0;

/// [`PLANE_DEPTH_RATIO`] for a node above a weak step's cut of strata.
/// A weak step (less power than a full one) starts at the strata tree's
/// root and takes any node that passes the far test as one term, so its
/// terms may be larger than any stratum a full step takes: half a ball
/// resting on the floor rather than a patch of it. Overshooting makes
/// most late steps weak, and their errors come back at every bounce in
/// the gap under a ball.
///
/// Measured on the Cornell box with two spheres of 64 segments
/// (`docs/accuracy.md`, "Nodes above a weak step's cut"). At 3, against
/// the unclustered solve converged to 10⁻⁵, 8 facets of a ball's lowest
/// rings were over 2 % too bright (worst 2.84 %); at 6, none (worst
/// 1.63 %, and 1.06 % converged), for 0.6 to 1.0 % more rays on every
/// hall and the spheres. Against the unclustered solve at the default
/// threshold: 42 facets over 2 % at 3; at 4, 5, 6 and 8 the worst
/// polygon 1.21, 1.08, 0.91 and 0.86 %. Asking 6 of every node of a
/// weak step left 1.25 % for 7 % more rays, and of every node of every
/// step 1.26 % for 9 % more: the nodes above the cut are the ones that
/// need it. 8 costs twice the rays of 6 on the larger halls.
pub const TOP_DEPTH_RATIO: f32 = 6.0;

/// A stratum whose box rests on a receiver's plane (no part behind it,
/// but too deep for [`PLANE_DEPTH_RATIO`]: a chair seen from the floor
/// it stands on) is in front of it from this many times the near
/// distance ([`STRATUM_NEAR_RATIO`] diameters). No cell is behind, so the
/// far term's cosine at the power-weighted centroid is the cells' mean
/// height over the plane, exactly; what the extra distance buys is the
/// spread of their distances, which here weighs with heights from zero.
/// Measured on the 30-table hall: 5.7 % fewer rays, the picture as far
/// from the unclustered solve as without it (0.355 %).
pub const RESTING_NEAR_FACTOR: f32 = 2.0;

/// How far below the receiver's plane a resting box's bottom may reach,
/// as a fraction of its half depth (rounding of a floor's height).
pub const RESTING_TOLERANCE: f32 = 1e-3;

// ---- Delivering a step in parts: step::parts: how much work a chunk or a part takes (no result changes) ----

/// Receiving vertices × shooter points (samples or strata) in one chunk of
/// whole polygons at most: about 5 ms of gathering on two cores where a
/// pair costs what it costs on average, 40 ms where it costs most (0.3 to
/// 2.3 µs on the 100,000-triangle sphere box, more where receivers take
/// a part's leaves). Chunks shrink from the time the earlier ones took
/// (`Plan::observe`), down to [`CHUNK_WORK`] / 64; they never grow past
/// it, as the next polygons may cost several times the last. Twice this
/// let a part that met the dearest polygons late run to 0.12 s.
pub const CHUNK_WORK: u64 = 1 << 14;

/// Work in one piece of a large polygon at most: its vertices cost less
/// than others, most being interpolated, but the ones near the shooter
/// are evaluated exactly (a hall's floor under the shooting table cost
/// 0.47 µs a pair, so a piece stays under about 30 ms). Pieces grow
/// while the floor's far rows are cheap; four times this let the first
/// part of a step that then reached the rows under the shooting tables
/// run to 0.13 s on the 150-table hall's finest mesh, and twice this,
/// once the floor's cells round chair legs were exact in every step
/// ([`CROWD_RATIO`]), let a piece of the 150-table
/// hall's floor that reached them run to 0.12 s.
pub const PIECE_WORK: u64 = 2 * CHUNK_WORK;

/// How much a chunk may grow on the last one's size: slowly, as the next
/// polygons may cost several times the last (a tessellated sphere's
/// facets beside the shooting patch).
pub const CHUNK_GROWTH: f64 = 1.25;

/// How much a piece of a large polygon may grow on the last one's size.
pub const PIECE_GROWTH: f64 = 1.5;

/// The solver time a chunk aims at: a part ends within about this of its
/// budget.
pub const CHUNK_TARGET: Duration = Duration::from_millis(20);

/// How much more a receiving vertex of the shooting cluster is counted
/// than another: it lies among the cells it receives from, so its sum
/// descends the strata to single cells.
pub const NEAR_WEIGHT: u64 = 8;

/// The solver time a window asks a part of a step to stay near: under
/// the 100 ms that keeps a picture moving, with a chunk's margin.
pub const WINDOW_PART_BUDGET: Duration = Duration::from_millis(50);

// ---- The hemicube: the hemicube method ----

/// Default [`hemicube::HemicubeRes`]: pixels across the top face. Measured
/// (`docs/accuracy.md`, "Hemicube"): the unit squares' form factors from
/// 64 hemicubes are within 0.03 % of the exact midpoint rule at 64
/// pixels and 0.016 % at 128; the pictures of `rtable` and `cornell` are
/// 3.0 % from the reference at 64, 2.4 to 2.8 % at 128 and 2.3 to 2.8 %
/// at 256, while a solve at 128 takes 1.2 to 1.4 times as long as at 64
/// and one at 256 1.6 to 1.7 times as long again. 128 buys most of what
/// more pixels give; past it the error is mostly the shooter's
/// quadrature (more cells, `--shooter-samples`, reduce it).
pub const DEFAULT_HEMICUBE_RES: u32 = 128;

/// A pixel's centre counts as inside a triangle when none of its
/// barycentric weights is below minus this: a slack so that pixel
/// centres on an edge shared by two triangles are never missed by both
/// to rounding (a crack would let a farther element show through).
pub const HEMICUBE_EDGE_SLACK: f32 = 1e-6;

/// Near clipping distance of a hemicube, as a fraction of the square root
/// of the area its shooter sample stands for: small enough that only an
/// element passing within a hair of the eye is cut, large enough that
/// `1/w` stays finite in `f32`.
pub const HEMICUBE_NEAR_FRACTION: f32 = 1e-5;

/// The unshot fraction at which an automatic tail ([`super::TailOption::Auto`])
/// takes over from the shooting steps ([`super::step::tail`]). The light
/// left then is spread over the whole model, where shooting steps each
/// carry a sliver of it; particles carry it all, with noise in the
/// share of each vertex's light it makes up. Measured on the exported
/// room and game level under `--sky 1` against a path tracer
/// (`docs/accuracy.md`, The particle tail): from 30 % with 64 particles
/// a vertex, `room.glb` 1.95 % off in 61 CPU seconds (from 3 %: 1.44 %
/// in 79 s; shooting to the end: 2.77 % in 190 s), `zdm2.obj` 5.9 % in
/// 137 s (from 3 %: 8.1 % in 611 s).
pub const TAIL_AUTO_FROM: f64 = 0.3;

/// Element vertices from which an automatic tail is on: below it a
/// shooting solve's tail takes seconds, and the bundled and generated
/// scenes keep their noise-free answers.
pub const TAIL_AUTO_VERTICES: u64 = 100_000;

/// An automatic tail also takes over before [`TAIL_AUTO_FROM`], at an
/// unshot fraction of at most [`TAIL_EARLY_FROM`], right after a shooting
/// step that cast more than this many shadow rays per unit of power it
/// shot for each particle per unit of power the tail would trace for the
/// light then left ([`TAIL_PARTICLES_PER_VERTEX`] a vertex over the unshot
/// power). A particle costs about six such rays (`fortitude.obj`: 4.6 µs
/// of CPU a particle, 0.7 µs a shooting step's ray), so past 5 shooting
/// is no cheaper than particles for the light it carries. Measured
/// (`docs/accuracy.md`, The particle tail): the shooting steps of
/// `room.glb` and `zdm2.glb` under `--sky 1` cast 0 to 3 times the
/// tail's rays per unit of power and are unchanged; `fortitude.obj`'s 5
/// to 8 times, two steps of a quarter of the level in one cluster 69 and
/// 76 times. At 5 it hands over after its first step (33.5 % left):
/// 3.76 % off the path tracer in 344 s of CPU, against 4.03 % in 536 s;
/// at 25, after the 69-times step, 4.28 % in 459 s. `room.glb` lit by a
/// lamp hands over at 50 %.
pub const TAIL_COSTLY_RATIO: f64 = 5.0;

/// The highest unshot fraction at which a costly shooting step hands the
/// light left to an automatic tail ([`TAIL_COSTLY_RATIO`]): above it the
/// particles would carry much of the light, and their noise with it.
pub const TAIL_EARLY_FROM: f64 = 0.5;

/// Particles per element vertex the tail traces over four steps, a
/// quarter each, by default (`--tail-particles`). Without the final
/// gather, from 30 %, 16 left `room.glb`'s picture 3.35 % off the path
/// tracer, 64 1.95 %, 128 1.66 %; a particle costs about 1.4 µs of CPU
/// there. The gather ([`TAIL_GATHER_RAYS`]) averages the particles'
/// noise away: after it, 16 a vertex left `fortitude.obj` 2.25 % off in
/// 126 s wall, 64 2.21 % in 171 s, and 8 2.36 % (64 without it: 2.91 %
/// in 155 s).
pub const TAIL_PARTICLES_PER_VERTEX: f64 = 16.0;

/// Directions each receiving vertex gathers the tail's field over in the
/// final gather (`step::tail_gather`): an 8 × 8 stratified grid of the
/// cosine-weighted hemisphere. Measured on `fortitude.obj` after 16
/// particles a vertex: 36 left it 2.98 % off the path tracer, 64 2.25 %;
/// the 64 cost about 15 s of its 126 s wall.
pub const TAIL_GATHER_RAYS: usize = 64;

/// Gathering vertices run together between checks for an interrupt in
/// the final gather (about 0.15 s on two cores at 64 directions each).
pub const TAIL_GATHER_BATCH: usize = 4096;

/// Gathering vertices run together in a final gather delivered in parts
/// (the window's part budget): about 20 ms on two cores.
pub const TAIL_GATHER_PART_BATCH: usize = 512;

/// Steps over which the tail shoots the light left: each an equal share
/// of it, so the picture moves between them.
pub const TAIL_STEPS: u32 = 4;

/// Particles traced by one task: their deposits are summed in task
/// order, so the bits do not depend on the thread count.
pub const TAIL_CHUNK: u64 = 1024;

/// Tasks run together between checks for an interrupt; their deposits
/// are held until summed (about 100 kB a task).
pub const TAIL_BATCH: u64 = 64;

/// Tasks run together in a tail step delivered in parts (the window's
/// part budget): a part ends after a batch, and a batch of
/// [`TAIL_BATCH`] took about 0.1 s on `room.glb`, over the window's
/// 50 ms. The deposits are summed in task order whatever the batch, so
/// the step's bits are the same.
pub const TAIL_PART_BATCH: u64 = 16;

/// Bounces a particle takes at most: Russian roulette ends nearly every
/// path long before (a path survives 200 bounces of the most reflective
/// surface allowed with odds of 1 in 30,000), this only bounds a path
/// that cannot end.
pub const TAIL_MAX_BOUNCES: u32 = 200;

/// The most a particle's survival odds at a bounce can be: a surface that
/// reflects nearly all light would otherwise keep paths going for
/// thousands of bounces.
pub const TAIL_SURVIVAL_MAX: f64 = 0.95;

// ---- Carrying a solve to a refined mesh: carry ----

/// Directions a new vertex of a refined mesh gathers the light reflected
/// so far over (`carry`, with clusters): a 16 × 16 stratified grid of
/// the cosine-weighted hemisphere. Four times the tail's final gather
/// ([`TAIL_GATHER_RAYS`]): a new vertex sits between vertices that were
/// shot exactly, where a gather's noise would show as a blotch, and the
/// sky's and lamps' light, the sharp part, is gathered apart from it.
pub const CARRY_GATHER_RAYS: usize = 256;

/// The most samples of all polygons together for which a new vertex of a
/// refined mesh still gathers from every polygon's samples, exactly as a
/// step would (`carry`): that costs a ray per sample, so 20,000 is about
/// ten times the hemisphere's rays, and a scene of a few hundred polygons
/// (the bundled ones) keeps the exact gather.
pub const CARRY_EXACT_SAMPLES: usize = 20_000;

/// Vertices of a refined mesh gathered in one parallel chunk (`carry`),
/// after which the step gauge says how many new vertices have gathered:
/// about half a second on two cores at the 0.2 ms a new vertex of a real
/// level takes.
pub const CARRY_CHUNK_VERTICES: usize = 2048;

/// Which phase of a step reads a constant of [`INDEX`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Choosing the shooter ([`step`]'s `choose`).
    Choose,
    /// Reading the shooter's samples, and the solve's set-up.
    Read,
    /// Shaft culling.
    Cull,
    /// Gathering at the receivers.
    Gather,
    /// Gathering from a cluster's strata.
    GatherCluster,
    /// Delivering a step in parts (never changes a result).
    Parts,
    /// The hemicube method.
    Hemicube,
    /// The particle tail.
    Tail,
    /// Carrying a solve to a refined mesh.
    Carry,
}

/// One constant of the index: its name, the phase that reads it, and its
/// value as an `f64` (exact for every constant here: integers below 2⁵³,
/// `f32`s, durations in seconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tuned {
    /// The constant's name in this module.
    pub name: &'static str,
    /// The phase that reads it.
    pub phase: Phase,
    /// Its value.
    pub value: f64,
}

/// Every constant of this module, in the order above.
pub const INDEX: &[Tuned] = &[
    Tuned {
        name: "DEFAULT_THRESHOLD",
        phase: Phase::Choose,
        value: DEFAULT_THRESHOLD,
    },
    Tuned {
        name: "DEFAULT_SETTLE",
        phase: Phase::Choose,
        value: DEFAULT_SETTLE,
    },
    Tuned {
        name: "SETTLE_FLOOR",
        phase: Phase::Choose,
        value: SETTLE_FLOOR,
    },
    Tuned {
        name: "PENDING_EMISSION",
        phase: Phase::Choose,
        value: PENDING_EMISSION,
    },
    Tuned {
        name: "OVERSHOOT_SHARE",
        phase: Phase::Choose,
        value: OVERSHOOT_SHARE,
    },
    Tuned {
        name: "MAX_SPEND_SCALE",
        phase: Phase::Choose,
        value: MAX_SPEND_SCALE,
    },
    Tuned {
        name: "DEFAULT_SHOOTER_SAMPLES",
        phase: Phase::Read,
        value: DEFAULT_SHOOTER_SAMPLES as f64,
    },
    Tuned {
        name: "SKY_FACET_SAMPLES",
        phase: Phase::Read,
        value: SKY_FACET_SAMPLES as f64,
    },
    Tuned {
        name: "FULL_STRATA_SHARE",
        phase: Phase::Read,
        value: FULL_STRATA_SHARE,
    },
    Tuned {
        name: "MIN_STRATA",
        phase: Phase::Read,
        value: MIN_STRATA as f64,
    },
    Tuned {
        name: "CLUSTER_EXTENT",
        phase: Phase::Read,
        value: CLUSTER_EXTENT as f64,
    },
    Tuned {
        name: "SUBCELL_ELEMENTS_PER_CELL",
        phase: Phase::Read,
        value: SUBCELL_ELEMENTS_PER_CELL,
    },
    Tuned {
        name: "SUBCELL_LEAF_RATIO",
        phase: Phase::Read,
        value: SUBCELL_LEAF_RATIO as f64,
    },
    Tuned {
        name: "SUBCELL_FAR_SCALE",
        phase: Phase::Read,
        value: SUBCELL_FAR_SCALE as f64,
    },
    Tuned {
        name: "SUBCELL_CLOSE",
        phase: Phase::Read,
        value: SUBCELL_CLOSE as f64,
    },
    Tuned {
        name: "SUBCELL_REACH",
        phase: Phase::Read,
        value: SUBCELL_REACH as f64,
    },
    Tuned {
        name: "SUBCELL_EDGE_MARGIN",
        phase: Phase::Read,
        value: SUBCELL_EDGE_MARGIN as f64,
    },
    Tuned {
        name: "TILE_VERTICES",
        phase: Phase::Cull,
        value: TILE_VERTICES as f64,
    },
    Tuned {
        name: "SHOOTER_GROUP",
        phase: Phase::Cull,
        value: SHOOTER_GROUP as f64,
    },
    Tuned {
        name: "SHAFT_MIN_VERTICES",
        phase: Phase::Cull,
        value: SHAFT_MIN_VERTICES as f64,
    },
    Tuned {
        name: "REFINE_MAX",
        phase: Phase::Cull,
        value: REFINE_MAX as f64,
    },
    Tuned {
        name: "LINEAR_CANDIDATES",
        phase: Phase::Cull,
        value: LINEAR_CANDIDATES as f64,
    },
    Tuned {
        name: "EXACT_RATIO",
        phase: Phase::Gather,
        value: EXACT_RATIO as f64,
    },
    Tuned {
        name: "NEAR_FIELD_RATIO",
        phase: Phase::Gather,
        value: NEAR_FIELD_RATIO as f64,
    },
    Tuned {
        name: "RECEIVER_STRIDE",
        phase: Phase::Gather,
        value: RECEIVER_STRIDE as f64,
    },
    Tuned {
        name: "CHECK_TOLERANCE",
        phase: Phase::Gather,
        value: CHECK_TOLERANCE,
    },
    Tuned {
        name: "RECEIVER_WEAK_SHARE",
        phase: Phase::Gather,
        value: RECEIVER_WEAK_SHARE,
    },
    Tuned {
        name: "RECEIVER_ERROR_BUDGET",
        phase: Phase::Gather,
        value: RECEIVER_ERROR_BUDGET,
    },
    Tuned {
        name: "CROWD_RATIO",
        phase: Phase::Gather,
        value: CROWD_RATIO as f64,
    },
    Tuned {
        name: "RECEIVER_NEAR_RATIO",
        phase: Phase::Gather,
        value: RECEIVER_NEAR_RATIO as f64,
    },
    Tuned {
        name: "FACET_NEAR_RATIO",
        phase: Phase::Gather,
        value: FACET_NEAR_RATIO as f64,
    },
    Tuned {
        name: "FACET_SCALE_RATIO",
        phase: Phase::Gather,
        value: FACET_SCALE_RATIO as f64,
    },
    Tuned {
        name: "SKY_PROBES",
        phase: Phase::Gather,
        value: SKY_PROBES as f64,
    },
    Tuned {
        name: "SKY_CELLS",
        phase: Phase::Gather,
        value: SKY_CELLS as f64,
    },
    Tuned {
        name: "SKY_CELL_STRATA",
        phase: Phase::Gather,
        value: SKY_CELL_STRATA as f64,
    },
    Tuned {
        name: "SKY_GRAZING_Z",
        phase: Phase::Gather,
        value: SKY_GRAZING_Z as f64,
    },
    Tuned {
        name: "SKY_CHUNK_VERTICES",
        phase: Phase::Gather,
        value: SKY_CHUNK_VERTICES as f64,
    },
    Tuned {
        name: "MIN_PROBES",
        phase: Phase::Gather,
        value: MIN_PROBES as f64,
    },
    Tuned {
        name: "SHARE_CREASE_DEG",
        phase: Phase::Gather,
        value: SHARE_CREASE_DEG as f64,
    },
    Tuned {
        name: "FAR_SHOOTER_RATIO",
        phase: Phase::Gather,
        value: FAR_SHOOTER_RATIO as f64,
    },
    Tuned {
        name: "FAR_PROBES",
        phase: Phase::Gather,
        value: FAR_PROBES as f64,
    },
    Tuned {
        name: "PAR_RUN",
        phase: Phase::Gather,
        value: PAR_RUN as f64,
    },
    Tuned {
        name: "PARALLEL_CHARGES",
        phase: Phase::Gather,
        value: PARALLEL_CHARGES as f64,
    },
    Tuned {
        name: "WEAK_STRATUM_SHARE",
        phase: Phase::GatherCluster,
        value: WEAK_STRATUM_SHARE,
    },
    Tuned {
        name: "STRATUM_NEAR_RATIO",
        phase: Phase::GatherCluster,
        value: STRATUM_NEAR_RATIO as f64,
    },
    Tuned {
        name: "PLANE_DEPTH_RATIO",
        phase: Phase::GatherCluster,
        value: PLANE_DEPTH_RATIO as f64,
    },
    Tuned {
        name: "TOP_DEPTH_RATIO",
        phase: Phase::GatherCluster,
        value: TOP_DEPTH_RATIO as f64,
    },
    Tuned {
        name: "RESTING_NEAR_FACTOR",
        phase: Phase::GatherCluster,
        value: RESTING_NEAR_FACTOR as f64,
    },
    Tuned {
        name: "RESTING_TOLERANCE",
        phase: Phase::GatherCluster,
        value: RESTING_TOLERANCE as f64,
    },
    Tuned {
        name: "CHUNK_WORK",
        phase: Phase::Parts,
        value: CHUNK_WORK as f64,
    },
    Tuned {
        name: "PIECE_WORK",
        phase: Phase::Parts,
        value: PIECE_WORK as f64,
    },
    Tuned {
        name: "CHUNK_GROWTH",
        phase: Phase::Parts,
        value: CHUNK_GROWTH,
    },
    Tuned {
        name: "PIECE_GROWTH",
        phase: Phase::Parts,
        value: PIECE_GROWTH,
    },
    Tuned {
        name: "CHUNK_TARGET",
        phase: Phase::Parts,
        value: CHUNK_TARGET.as_secs_f64(),
    },
    Tuned {
        name: "NEAR_WEIGHT",
        phase: Phase::Parts,
        value: NEAR_WEIGHT as f64,
    },
    Tuned {
        name: "WINDOW_PART_BUDGET",
        phase: Phase::Parts,
        value: WINDOW_PART_BUDGET.as_secs_f64(),
    },
    Tuned {
        name: "DEFAULT_HEMICUBE_RES",
        phase: Phase::Hemicube,
        value: DEFAULT_HEMICUBE_RES as f64,
    },
    Tuned {
        name: "HEMICUBE_EDGE_SLACK",
        phase: Phase::Hemicube,
        value: HEMICUBE_EDGE_SLACK as f64,
    },
    Tuned {
        name: "HEMICUBE_NEAR_FRACTION",
        phase: Phase::Hemicube,
        value: HEMICUBE_NEAR_FRACTION as f64,
    },
    Tuned {
        name: "TAIL_AUTO_FROM",
        phase: Phase::Tail,
        value: TAIL_AUTO_FROM,
    },
    Tuned {
        name: "TAIL_AUTO_VERTICES",
        phase: Phase::Tail,
        value: TAIL_AUTO_VERTICES as f64,
    },
    Tuned {
        name: "TAIL_COSTLY_RATIO",
        phase: Phase::Tail,
        value: TAIL_COSTLY_RATIO,
    },
    Tuned {
        name: "TAIL_EARLY_FROM",
        phase: Phase::Tail,
        value: TAIL_EARLY_FROM,
    },
    Tuned {
        name: "TAIL_PARTICLES_PER_VERTEX",
        phase: Phase::Tail,
        value: TAIL_PARTICLES_PER_VERTEX,
    },
    Tuned {
        name: "TAIL_GATHER_RAYS",
        phase: Phase::Tail,
        value: TAIL_GATHER_RAYS as f64,
    },
    Tuned {
        name: "TAIL_GATHER_BATCH",
        phase: Phase::Tail,
        value: TAIL_GATHER_BATCH as f64,
    },
    Tuned {
        name: "TAIL_GATHER_PART_BATCH",
        phase: Phase::Tail,
        value: TAIL_GATHER_PART_BATCH as f64,
    },
    Tuned {
        name: "TAIL_STEPS",
        phase: Phase::Tail,
        value: TAIL_STEPS as f64,
    },
    Tuned {
        name: "TAIL_CHUNK",
        phase: Phase::Tail,
        value: TAIL_CHUNK as f64,
    },
    Tuned {
        name: "TAIL_BATCH",
        phase: Phase::Tail,
        value: TAIL_BATCH as f64,
    },
    Tuned {
        name: "TAIL_PART_BATCH",
        phase: Phase::Tail,
        value: TAIL_PART_BATCH as f64,
    },
    Tuned {
        name: "TAIL_MAX_BOUNCES",
        phase: Phase::Tail,
        value: TAIL_MAX_BOUNCES as f64,
    },
    Tuned {
        name: "TAIL_SURVIVAL_MAX",
        phase: Phase::Tail,
        value: TAIL_SURVIVAL_MAX,
    },
    Tuned {
        name: "CARRY_GATHER_RAYS",
        phase: Phase::Carry,
        value: CARRY_GATHER_RAYS as f64,
    },
    Tuned {
        name: "CARRY_EXACT_SAMPLES",
        phase: Phase::Carry,
        value: CARRY_EXACT_SAMPLES as f64,
    },
    Tuned {
        name: "CARRY_CHUNK_VERTICES",
        phase: Phase::Carry,
        value: CARRY_CHUNK_VERTICES as f64,
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Every `pub const` of this file is in [`INDEX`], in order, so the
    /// checkpoint fingerprint covers every constant.
    #[test]
    fn the_index_lists_every_constant() {
        let declared: Vec<&str> = include_str!("tuning.rs")
            .lines()
            .filter_map(|l| l.strip_prefix("pub const "))
            .filter_map(|l| l.split(':').next())
            .filter(|name| *name != "INDEX")
            .collect();
        let indexed: Vec<&str> = INDEX.iter().map(|t| t.name).collect();
        assert_eq!(declared, indexed);
    }

    /// Each value in the index is the constant's own, exactly.
    #[test]
    fn the_index_holds_the_values() {
        let at = |name: &str| INDEX.iter().find(|t| t.name == name).unwrap().value;
        assert_eq!(at("CLUSTER_EXTENT"), f64::from(CLUSTER_EXTENT));
        assert_eq!(at("WEAK_STRATUM_SHARE"), WEAK_STRATUM_SHARE);
        assert_eq!(at("CHUNK_TARGET"), CHUNK_TARGET.as_secs_f64());
        assert_eq!(at("SKY_FACET_SAMPLES"), f64::from(SKY_FACET_SAMPLES));
    }
}
