//! Progressive refinement radiosity with substructuring.
//!
//! Radiosity is kept at element vertices; unshot radiosity per vertex (by
//! default) or per polygon ([`UnshotScheme`]).
//! Each [`Progressive::step`] picks the polygon with the most unshot power
//! `‖Δb_i‖·A_i` (‖·‖ the channel mean) and shoots it to every element
//! vertex `l` of every other polygon `j`:
//!
//! ```text
//! Δrad_l = rho_j · Δb_i · F(l → i)        (F from `formfactor`)
//! b_l  += Δrad_l
//! Δb_j += Δrad_l / n_j                     (n_j: vertices of j; on a
//!                                           refined mesh, × area share)
//! Δb_i  = 0
//! ```
//!
//! **Overshooting** ([`SolverOptions::overshoot`], on by default; Feda and
//! Purgathofer 1992, the over-relaxation of Gortler, Cohen and Slusallek's
//! Southwell view of progressive refinement): each point of a shooter
//! also sends the light it expects to receive later (`Expectation`:
//! what it has received so far times the ratio of light still to come to
//! light shot, capped by its share of the ambient term), and is left at
//! `Δb = −` that, filled as the light arrives; a negative part the
//! shrinking expectation no longer covers is shot as negative light (a
//! step of the same gather, its `Δrad` subtracted). Unshot radiosity is
//! then signed, and the threshold reads its magnitude.
//!
//! **Settling** ([`SolverOptions::settle`], on by default): past the
//! threshold, the solve goes on while some point of a reflecting polygon
//! still has more than a fraction of its own radiosity to send, shooting
//! from the cluster that holds the most such light. The threshold weighs
//! power, and a pocket (the gap between a hung lamp and the ceiling, a
//! sphere's underside over the floor) holds little power while trading
//! most of its own light back and forth; settling converges it at the
//! cost of a few steps of weak light.
//!
//! A sky (`--sky`, [`crate::scene::Scene::add_sky`]) is an enclosure of
//! emitting facets that reflect nothing: each shoots like any emitter, from
//! its own grid of [`formfactor::SKY_FACET_SAMPLES`] points, and its unshot
//! power counts as the light it can bring to the scene, not its own (see
//! [`Progressive::unshot_power`]).
//!
//! **Clusters** ([`cluster`], on unless [`SolverOptions::clustering`] is
//! off): nearby small polygons form clusters, and a step shoots from the
//! *cluster* with the most unshot power, all its members at once, from
//! strata of their samples (a tessellated sphere's thousand triangles in
//! one step rather than a thousand). Emitters always shoot alone from
//! their own samples; any other polygon whose step carries less than
//! [`FULL_STRATA_SHARE`] of the initial power shoots through strata too,
//! fewer of them the weaker its light (see [`FULL_STRATA_SHARE`]).
//! Shadow-ray candidates are culled by the same groups in both modes, so
//! a tessellated object beside a thin shaft costs one box test.
//!
//! **Hierarchical receivers** ([`receivers`], with clusters, unless
//! [`SolverOptions::receiver_interpolation`] is off): a step of reflected
//! light evaluates large receiving grids at every fourth row and column
//! and at a check vertex per coarse cell, and interpolates the cell's
//! other vertices when the check shows the interpolation holds.
//!
//! **Shared facet rays** ([`facets`], with the same switch): a facet
//! under half an element across asks one shadow ray per shooter sample or
//! stratum, to its middle, for all its vertices, where no vertex is near
//! the sample's cell.
//!
//! **Sky probes** ([`probes`], with the same switch): a receiving
//! vertex asks a few of a sky facet's directions first and, when they
//! agree, takes their answer for all of them.
//!
//! **Far shooters** ([`far_shooters`], with the same switch): a vertex
//! many diameters from a polygon shooting alone (a lamp) probes a few of
//! its samples first and, when they agree, takes their answer for all.
//!
//! Emission and reflection are from the front only. Receivers are
//! processed in parallel; each vertex's sum is independent and the
//! per-polygon sums run in a fixed order, so the result is bit-identical
//! whatever the thread count.

pub mod accel;
pub mod checkpoint;
pub mod final_gather;
pub mod hemicube;
pub mod kernel;
pub mod parts;
mod unshot;

use accel::{cluster, facets, far_shooters, probes, receivers, subcells};
use kernel::{cell_integrals, distribution, formfactor};

use crate::color::Rgb;
use crate::mesh::refine::Refiner;
use crate::mesh::{Mesh, MeshRef};
use crate::scene::{PolygonId, Scene};
use crate::visibility::{LastBlocker, Visibility};
use cluster::{Cell, Clusters, Seen, Strata};
use facets::{Facets, Scratch};
use far_shooters::FarShooter;
use formfactor::{shooter_samples, weighted_point_to_samples, SampleSet, ShooterSample};
use rayon::prelude::*;
use receivers::CoarseGrid;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use subcells::SubCells;
use unshot::{Shot, UnshotField};

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

/// An emitter whose unshot power is at least this share of the power it
/// emits has not shot its light yet, and shoots before any reflector
/// (`Progressive::choose_pending_emitter`). Once shot, what it holds is
/// the light it reflects, far less in any ordinary scene.
pub const PENDING_EMISSION: f64 = 0.5;

/// A receiver whose shaft holds at most this many polygons tests its rays
/// against them one by one; more, and the BVH is faster.
pub const LINEAR_CANDIDATES: usize = 8;

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

/// A stratum a receiving vertex would descend into (nearer than
/// [`cluster::STRATUM_NEAR_RATIO`] diameters) is taken as one term when
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

/// The fewest strata a clustered step shoots from (unless its cells are
/// fewer).
pub const MIN_STRATA: usize = 8;

/// Shared-ray keys per stratum node ([`facets::Memo`]): one per normal
/// bin a far term may cast from, and one for the node's representative.
const RAY_SLOTS: u32 = 7;

/// Vertices of one polygon a worker takes at once in a gather pass
/// ([`par_runs`]): a small facet's three or four.
const PAR_RUN: usize = 4;

/// Vertices from which the check charges of a gather
/// ([`gather_passes`]) are made in parallel.
const PARALLEL_CHARGES: usize = 8_192;

/// The shared-ray key slot of a ray from the node's representative.
const REPRESENTATIVE_SLOT: u32 = RAY_SLOTS - 1;

/// Not a shared-ray slot: a ray the vertex asks alone, by the full
/// search (from a point of a near cell other than its sample).
const OWN_RAY_SLOT: u32 = u32::MAX;

/// The share of the ambient term ([`Progressive::ambient`]) times its
/// reflectance that a point may expect to receive later, and so send ahead
/// when it shoots ([`SolverOptions::overshoot`], [`Expectation`]). The
/// ambient term counts every bounce still to come as if spread evenly;
/// measured as the only expectation on the 15-, 30- and 60-table halls and
/// the 32-segment spheres (`docs/performance.md`), half of it took the
/// fewest rays (0.35 and 0.65 within a few per cent, 1 and 2 10 to 30 %
/// more, some steps sending light back).
const OVERSHOOT_SHARE: f64 = 0.5;

/// What a step expects each point to receive later (overshooting, [`Shot`]):
/// a point that has received `r` so far expects `min(gain · r, ρ ·
/// ambient)` per channel. The first is local: a point that received `r`
/// of the `S` shot so far should receive about `r · U / S` of the `U`
/// still to shoot, and `R = 1 / (1 − ρ̄)` times that with its bounces, so
/// `gain = R · U / S`; it keeps points in dark corners from sending ahead
/// light they will never get (with the ambient term alone, the facets
/// where a sphere rests on the floor came out 27 % too bright at 0.01 %
/// unshot). The second caps it where the light received so far is mostly
/// direct, which lamps spread far less evenly than its later bounces.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Expectation {
    /// `R · U / S` (see above), `>= 0`.
    gain: f64,
    /// [`OVERSHOOT_SHARE`] times the ambient term, clamped at 0 per
    /// channel, in the scene's emission units.
    ambient: Rgb,
}

impl Expectation {
    /// Nothing expected: no overshoot.
    const NONE: Expectation = Expectation {
        gain: 0.0,
        ambient: Rgb::BLACK,
    };
}

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

/// Default cap on shooter sample points (see [`ShooterSamples::AtMost`]).
/// With the near field the unoccluded form factors of unit squares (exact
/// 0.19982 parallel, 0.20004 perpendicular) are within 0.06 % at 16, 64 or
/// 256 points; what the count buys is visibility: each point casts one
/// shadow ray, so penumbrae are sampled by as many rays. 64 resolves a
/// room's shadows without visible banding and keeps a step on a
/// 14,000-vertex mesh under a million rays; 256 quadruples the rays.
pub const DEFAULT_SHOOTER_SAMPLES: u32 = 64;

/// How form factors are estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FormFactorMethod {
    /// Wallace's ray-traced sum over shooter sample points.
    #[value(name = "wallace")]
    Wallace,
    /// One ray from the shooter's centre with the point-to-disc form factor:
    /// cheap, with blocky shadows.
    #[value(name = "center")]
    Center,
    /// Cohen and Greenberg's hemicube: each shooter cell projects the
    /// scene's elements onto a hemicube of [`SolverOptions::hemicube_res`]
    /// pixels with a z-buffer and sums the pixels' delta form factors
    /// ([`hemicube`]). No shadow rays; aliases where elements are small
    /// seen from the shooter. Shoots every polygon alone (no clusters,
    /// every receiver exact); a sky facet still shoots by Wallace's rays.
    #[value(name = "hemicube")]
    Hemicube,
}

/// Which points of a shooter are used by [`FormFactorMethod::Wallace`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShooterSamples {
    /// Every element vertex of the shooter.
    All,
    /// A regular grid of cells over the polygon, at most this many
    /// (`>= 1`) and no more than its element vertices, each shooting from
    /// its centre with the near field of [`formfactor`].
    AtMost(u32),
}

/// Solver settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverOptions {
    /// Form factor estimate.
    pub form_factor: FormFactorMethod,
    /// Shooter samples for the Wallace estimate.
    pub shooter_samples: ShooterSamples,
    /// Stop when the unshot power falls to this fraction of the initial
    /// unshot power, in `[0, 1]` (and every point has settled:
    /// [`SolverOptions::settle`]).
    pub threshold: f64,
    /// Settling tolerance, in `[0, 1)`: once the unshot power is below the
    /// threshold, go on shooting while some point of a reflecting polygon
    /// still has more than this fraction of its radiosity to send (points
    /// darker than [`SETTLE_FLOOR`] of the mean count as that bright),
    /// from the cluster holding the most such light. A pocket (the gap
    /// under a lamp, a sphere's underside over the floor) holds little
    /// power but trades it back and forth; the threshold alone leaves it
    /// dark. 0 stops at the threshold alone.
    pub settle: f64,
    /// Stop after this many steps at most.
    pub max_steps: Option<u64>,
    /// Use the exact point-to-cell form factor for receivers close to a
    /// grid sample (see [`formfactor`]); off gives the plain disc sum.
    pub near_field: bool,
    /// Cull shadow rays with shafts between shooter and receiver (same
    /// result bits; off tests every ray against the whole scene's BVH).
    pub shaft_culling: bool,
    /// Where unshot radiosity is kept.
    pub unshot: UnshotScheme,
    /// Let nearby small polygons shoot together ([`cluster`]); off, every
    /// polygon shoots alone (the brute-force twin). Only the Wallace
    /// estimate on a grid ([`ShooterSamples::AtMost`]) clusters: the
    /// other settings exist to reproduce the original algorithm.
    pub clustering: bool,
    /// Let a clustered step interpolate receiving grids from their coarse
    /// vertices where [`receivers::accept`] allows, and take a near
    /// stratum whose light is weak at a vertex as one term
    /// ([`WEAK_STRATUM_SHARE`]); off, every receiving vertex is evaluated
    /// exactly, every near stratum descended into (the twin it is
    /// compared with).
    pub receiver_interpolation: bool,
    /// Pixels across a hemicube's top face, for
    /// [`FormFactorMethod::Hemicube`] (ignored by the other methods).
    pub hemicube_res: hemicube::HemicubeRes,
    /// Deliver a step in parts of about this much solver time each
    /// ([`parts`]): a window's picture then moves while a long step runs.
    /// The finished step is bit-identical to one in a piece; `None` (the
    /// default) runs every step in one piece.
    pub part_budget: Option<std::time::Duration>,
    /// Overshoot (Feda and Purgathofer 1992): a step also sends out the
    /// light each point of its shooters is expected to receive later
    /// (`Expectation`), leaving their unshot radiosity negative until
    /// that light arrives; what the shrinking expectation no longer covers
    /// is shot as negative light. Fewer steps to the same residual; off,
    /// unshot radiosity never goes below zero (the original algorithm).
    pub overshoot: bool,
}

/// Where unshot radiosity is kept between shooting steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum UnshotScheme {
    /// One value per polygon, the mean of what its vertices received: a
    /// polygon shoots as if lit evenly (the original algorithm).
    #[value(name = "polygon")]
    Polygon,
    /// One value per element vertex: each shooter sample carries the
    /// unshot radiosity interpolated at its position (linearly within the
    /// element triangle holding it, as the picture shades), and a polygon's
    /// unshot power is the sum over its vertices of unshot × vertex area.
    #[value(name = "vertex")]
    Vertex,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            form_factor: FormFactorMethod::Wallace,
            shooter_samples: ShooterSamples::AtMost(DEFAULT_SHOOTER_SAMPLES),
            threshold: DEFAULT_THRESHOLD,
            settle: DEFAULT_SETTLE,
            max_steps: None,
            near_field: true,
            shaft_culling: true,
            unshot: UnshotScheme::Vertex,
            clustering: true,
            receiver_interpolation: true,
            hemicube_res: hemicube::HemicubeRes::default(),
            overshoot: true,
            part_budget: None,
        }
    }
}

/// What one shooting step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Which step this was, from 1.
    pub step: u64,
    /// The polygon that shot (of a cluster, the member that held the most
    /// unshot power).
    pub shooter: PolygonId,
    /// How many polygons shot together: 1, or the members of a cluster
    /// ([`cluster`]).
    pub polygons: u32,
    /// The power it shot: `A_i · mean(Δb_i)` with the overshoot, in
    /// radiosity × area units (for a sky facet, weighted as
    /// [`Progressive::unshot_power`] says); negative for a step that shot
    /// negative light ([`SolverOptions::overshoot`]).
    pub shot_power: f64,
    /// Unshot power left after the step, as a fraction of the initial
    /// (for a part of a step not finished, what the last finished step
    /// left).
    pub unshot_fraction: f64,
    /// Shadow rays cast in this step.
    pub rays: u64,
    /// Sample–vertex pairs whose visibility mattered (both cosines
    /// positive); with shaft culling, those in clear shafts cast no ray.
    pub pairs: u64,
    /// Polygons that received in this step.
    pub receivers: u64,
    /// Of those, the ones whose shaft to the shooter held no polygon, so
    /// no ray was cast to them (0 without shaft culling).
    pub clear_receivers: u64,
    /// Which part of the step this report ends, from 1
    /// ([`SolverOptions::part_budget`]); the counts above are the step's
    /// so far.
    pub part: u32,
    /// Whether the step is finished (always, without a part budget).
    pub complete: bool,
}

/// A step begun: what it shoots, how, and how far it has got.
#[derive(Clone, Debug)]
struct Underway {
    /// The shooting cluster (without clustering, the polygon's own).
    cluster: usize,
    /// Its member holding the most unshot power.
    shooter: PolygonId,
    /// What [`Progressive::choose_shooter`] found it to send, signed.
    shot_power: f64,
    /// The expected light the shooters were read with.
    expected: Expectation,
    how: How,
    /// The receivers' chunks and how far they have been taken.
    plan: parts::Plan,
    /// Whether the shooters' unshot radiosity has been spent (with the
    /// first receivers applied).
    spent: bool,
    /// Counts so far.
    gathered: Gathered,
    receivers: u64,
    clear: u64,
    /// Parts reported so far, the one running included.
    part: u32,
    /// The unshot fraction the last finished step left.
    fraction_before: f64,
}

/// How a step shoots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum How {
    /// One polygon from its own samples.
    Alone,
    /// A cluster (or a polygon of weak light) from strata, descending from
    /// the strata tree's top when `from_top`.
    Cluster { from_top: bool },
}

/// What [`Progressive::begin_step`] did.
enum Begun {
    /// The whole step (a hemicube step).
    Done(StepReport),
    /// The shooter is read and its receivers marked.
    Underway(Underway),
}

/// What a gather writes, per mesh vertex ([`gather_passes`]).
struct Sums<'b> {
    /// The step's `Δrad`.
    delta: &'b mut [Rgb],
    /// The first pass's `Δrad`, which the second reads.
    first: &'b mut [Rgb],
    /// The interpolation error charged to check vertices
    /// ([`Progressive::charges`]).
    spent: &'b mut [Rgb],
}

/// The vertices a gather call takes and the passes it runs over them
/// ([`gather_passes`]).
#[derive(Clone, Debug, PartialEq, Eq)]
struct Work {
    /// Mesh vertices: whole polygons with [`Stage::All`], else some of
    /// one polygon's.
    vertices: Range<usize>,
    stage: Stage,
}

/// Which passes a gather call runs ([`gather_passes`]).
#[derive(Clone, Debug, PartialEq, Eq)]
enum Stage {
    /// Whole polygons: both passes and the check charges.
    All,
    /// The first pass over some of one polygon's vertices; with `copy`,
    /// the last such piece, then keeps the polygon's first-pass values
    /// for the second.
    Exact { copy: Option<Range<usize>> },
    /// The second pass over some of one polygon's vertices; with
    /// `charge`, the last such piece, then charges the polygon's checks.
    Interpolated { charge: Option<Range<usize>> },
}

/// What the gather phase of a step counted.
#[derive(Clone, Copy, Debug)]
struct Gathered {
    /// Sample–vertex pairs whose visibility mattered.
    pairs: u64,
    /// Shadow rays cast.
    rays: u64,
}

impl Gathered {
    fn add(&mut self, other: Gathered) {
        self.pairs += other.pairs;
        self.rays += other.rays;
    }
}

/// A solver state that breaks [`Progressive`]'s invariants: found by
/// [`Progressive::validate`] (a bug when it happens) or refused by
/// [`Progressive::restore`] (a state saved for another solve).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// The radiosity or unshot arrays do not have one entry per mesh
    /// vertex (radiosity) and per unit of the unshot scheme.
    #[error("array sizes do not match the mesh")]
    MeshMismatch,
    /// A vertex's radiosity is negative or not finite.
    #[error("vertex {vertex} has radiosity {value:?}")]
    BadRadiosity {
        /// The mesh vertex.
        vertex: usize,
        /// Its radiosity, in the scene's emission units.
        value: Rgb,
    },
    /// An unshot value is not finite.
    #[error("{unit} {index} has unshot radiosity {value:?}")]
    BadUnshot {
        /// What the value belongs to: "polygon" or "vertex" (by
        /// [`SolverOptions::unshot`]).
        unit: &'static str,
        /// The polygon or mesh vertex.
        index: usize,
        /// Its unshot radiosity, in the scene's emission units.
        value: Rgb,
    },
    /// A state to restore has other array sizes than this solve.
    #[error(
        "the saved state holds {radiosity} radiosity and {unshot} unshot values; \
         this solve has {expected_radiosity} and {expected_unshot}"
    )]
    StateMismatch {
        /// Radiosity entries in the state.
        radiosity: usize,
        /// Unshot entries in the state.
        unshot: usize,
        /// Radiosity entries this solve has (its mesh vertices).
        expected_radiosity: usize,
        /// Unshot entries this solve has.
        expected_unshot: usize,
    },
    /// A state to restore holds a non-finite value, or a negative
    /// radiosity or charge.
    #[error("the saved state holds a negative or non-finite value")]
    BadStateValue,
}

/// Why the solver stops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The unshot power fell below the threshold and every point settled
    /// ([`SolverOptions::settle`]), or there was none.
    Converged,
    /// The step limit was reached first.
    MaxSteps,
}

/// The state of a progressive solve: a value that is advanced one shooting
/// step at a time.
///
/// Invariants (checked by [`Progressive::validate`]): every radiosity is
/// finite and non-negative, every unshot value finite (negative only with
/// [`SolverOptions::overshoot`]); one radiosity per mesh vertex
/// and one unshot value per polygon or per mesh vertex, by
/// [`SolverOptions::unshot`].
pub struct Progressive<'a> {
    mesh: MeshRef<'a>,
    visibility: &'a Visibility,
    options: SolverOptions,
    /// Per polygon: front emission `e`.
    emission: Vec<Rgb>,
    /// Per polygon: front reflectance `rho`.
    reflectance: Vec<Rgb>,
    /// Per polygon: the factor its unshot power counts with (see
    /// [`sky_power_weights`]): 1, less for sky facets.
    power_weight: Vec<f64>,
    /// Per polygon: shooter samples.
    samples: Vec<Vec<ShooterSample>>,
    /// Per polygon: the parts of its shooter cells much larger than its
    /// elements ([`subcells`]).
    parts: Vec<SubCells>,
    /// Per polygon: its light distribution when it is a luminaire (its
    /// shot then weights directions by it, [`distribution`]).
    directional: Vec<Option<distribution::Directional>>,
    /// Per vertex: radiosity `b`.
    radiosity: Vec<Rgb>,
    /// Per vertex: the area it stands for ([`Mesh::vertex_areas`]), in
    /// square scene units, for the settling floor
    /// ([`Progressive::settle_floor`]).
    vertex_area: Vec<f64>,
    /// Unshot radiosity `Δb`: per polygon or per vertex, by
    /// [`SolverOptions::unshot`].
    unshot: UnshotField,
    /// Scratch: the unshot radiosity each sample of the shooter carries.
    shot: Vec<Rgb>,
    /// Scratch: what each part of the shooter's split cells sends
    /// ([`subcells`]), in the order of its [`SubCells::cells`]; empty in
    /// the per-polygon scheme, whose parts would all send the same.
    part_readings: Vec<Rgb>,
    /// Per vertex: scratch for the step's `Δrad`.
    delta: Vec<Rgb>,
    /// Per polygon: scratch, whether it receives in this step.
    receives: Vec<bool>,
    /// Per polygon: scratch, the polygons in its shaft to the shooter,
    /// ordered by their culling group.
    candidates: Vec<Vec<u32>>,
    /// Per polygon: fewer vertices than [`SHAFT_MIN_VERTICES`], so its
    /// rays always ask the BVH.
    small: Vec<bool>,
    /// The small facets whose vertices share their shadow rays.
    facets: Facets,
    /// Per polygon: a sky facet's probe samples ([`probes`]), empty for
    /// every other polygon and when probing is off.
    probes: Vec<Vec<u32>>,
    /// Per polygon: where it is far enough to be probed when it shoots
    /// alone, and its probes ([`far_shooters`]); `None` for sky facets,
    /// polygons of few samples and when the approximation is off.
    far_shooters: Vec<Option<FarShooter>>,
    /// Per polygon: scratch, its candidates in runs of one culling group
    /// with the group's bounds.
    candidate_runs: Vec<Vec<crate::visibility::CandidateRun>>,
    /// The groups shadow-ray candidates are culled by: the clusters of
    /// [`Clusters::build`] whether or not the solve shoots by clusters.
    culling_groups: Clusters,
    /// Groups of at most [`TILE_VERTICES`] consecutive vertices of one
    /// polygon, for thin shafts.
    tiles: Vec<std::ops::Range<u32>>,
    /// Per vertex: its tile.
    tile_of: Vec<u32>,
    /// Per tile and shooter sample group: scratch, the polygons in the
    /// shaft between them.
    tile_candidates: Vec<Vec<u32>>,
    /// Scratch: the shooter's sample positions (polygon shooter) or its
    /// strata's bounds, two corners a stratum (cluster shooter), in groups
    /// of [`SHOOTER_GROUP`] samples for tile shafts.
    group_points: Vec<glam::Vec3>,
    /// The clusters that shoot together (every polygon alone without
    /// clustering).
    clusters: Clusters,
    /// True when the solve shoots by clusters and strata
    /// ([`SolverOptions::clustering`] with a grid of samples).
    clustered: bool,
    /// Scratch for a cluster step: the shooting cells, their samples and
    /// strata.
    cells: Vec<Cell>,
    cell_samples: Vec<ShooterSample>,
    /// Scratch for a cluster step, per cell: where its parts' values start
    /// in `cell_part_values` when it is split, else [`subcells::NONE`].
    cell_parts: Vec<u32>,
    /// Scratch: what each part of a cluster step's split cells sends.
    cell_part_values: Vec<Rgb>,
    /// The leaves' values of the parts in `cell_part_values`,
    /// [`subcells::LEAVES`] per part, apart from the parts' so that those
    /// every receiver takes lie together in memory.
    cell_leaf_values: Vec<Rgb>,
    strata: Strata,
    /// Per polygon: its regular grid, whose vertices between coarse rows
    /// and columns a cluster step may interpolate ([`receivers`]).
    coarse: Vec<Option<CoarseGrid>>,
    /// Per mesh vertex, true where it is the first corner of a receiving
    /// grid's cell that another polygon crowds, which is never
    /// interpolated ([`receivers::crowded_cells`]); empty without
    /// receiver interpolation.
    crowded: Vec<bool>,
    /// Per vertex: scratch, a cluster step's `Δrad` at the vertices
    /// evaluated exactly, read while the others are interpolated.
    coarse_delta: Vec<Rgb>,
    /// Per vertex: the interpolation error charged to it as a check vertex
    /// ([`receivers::accept`]), in radiosity units per channel.
    spent: Vec<Rgb>,
    pairs: u64,
    receiver_pairs: u64,
    clear_receiver_pairs: u64,
    initial_unshot_power: f64,
    steps: u64,
    rays: u64,
    /// The step begun and not finished, when steps come in parts
    /// ([`SolverOptions::part_budget`]).
    underway: Option<Underway>,
    /// The unshot fraction after the last finished step (1 before the
    /// first), which a part of a step not finished reports.
    last_fraction: f64,
    /// The hemicube's tables and scratch, with
    /// [`FormFactorMethod::Hemicube`].
    hemicube: Option<hemicube::Shooting>,
}

impl<'a> Progressive<'a> {
    /// Starts a solve: every vertex at `b = e`, every polygon's unshot
    /// radiosity at `Δb = e`. `mesh` and `visibility` must be built from
    /// `scene`.
    pub fn new(
        scene: &Scene,
        mesh: impl Into<MeshRef<'a>>,
        visibility: &'a Visibility,
        options: SolverOptions,
    ) -> Self {
        let mesh_ref = mesh.into();
        let mesh: &Mesh = &mesh_ref;
        let set = match (options.form_factor, options.shooter_samples) {
            (FormFactorMethod::Center, _) => SampleSet::Centre,
            (FormFactorMethod::Wallace | FormFactorMethod::Hemicube, ShooterSamples::All) => {
                SampleSet::Vertices
            }
            (FormFactorMethod::Wallace | FormFactorMethod::Hemicube, ShooterSamples::AtMost(n)) => {
                SampleSet::AtMost(n)
            }
        };
        let emission: Vec<Rgb> = scene
            .polygons
            .iter()
            .map(|p| scene.materials[p.material.index()].emission())
            .collect();
        let reflectance = scene
            .polygons
            .iter()
            .map(|p| scene.materials[p.material.index()].reflectance())
            .collect();
        let sets: Vec<SampleSet> = scene
            .polygons
            .iter()
            .map(|p| SampleSet::for_polygon(set, p))
            .collect();
        let samples: Vec<Vec<ShooterSample>> = scene
            .polygons
            .iter()
            .zip(&mesh.polygons)
            .zip(&sets)
            .map(|((p, pm), &set)| shooter_samples(p, pm, mesh, set))
            .collect();
        let radiosity = mesh
            .vertex_polygon
            .iter()
            .map(|p| emission[p.index()])
            .collect();
        let covered = crate::mesh::covered::covered_vertices(scene, mesh);
        let parts = SubCells::build_all(scene, mesh, &samples, options.near_field);
        let unshot = UnshotField::new(
            options.unshot,
            mesh,
            &emission,
            &samples,
            &sets,
            &parts,
            covered,
        );
        let power_weight = sky_power_weights(mesh);
        let culling_groups = Clusters::build(scene, mesh, &emission);
        let clustered = matches!(
            (
                options.clustering,
                options.form_factor,
                options.shooter_samples
            ),
            (true, FormFactorMethod::Wallace, ShooterSamples::AtMost(_))
        );
        let clusters = if clustered {
            culling_groups.clone()
        } else {
            Clusters::singletons(scene)
        };
        let mut tiles = Vec::new();
        let mut tile_of = vec![0u32; mesh.vertex_count()];
        for pm in &mesh.polygons {
            let mut start = pm.vertices.start;
            while start < pm.vertices.end {
                let end = (start + TILE_VERTICES).min(pm.vertices.end);
                for l in start..end {
                    tile_of[l as usize] = tiles.len() as u32;
                }
                tiles.push(start..end);
                start = end;
            }
        }
        // Shared facet rays and sky probes go with the other receiver
        // approximations.
        let approximate = clustered && options.receiver_interpolation;
        let coarse: Vec<Option<CoarseGrid>> = mesh
            .polygons
            .iter()
            .map(|pm| CoarseGrid::detect(mesh, pm))
            .collect();
        let crowded = if approximate {
            receivers::crowded_cells(mesh, &coarse, |j, corners, normal, depth| {
                visibility.crowds(PolygonId(j as u32), &corners, normal, depth)
            })
        } else {
            Vec::new()
        };
        let sky_probes = mesh
            .polygons
            .iter()
            .zip(&samples)
            .map(|(pm, own)| {
                if pm.sky && approximate {
                    probes::spread(own, probes::SKY_PROBES)
                } else {
                    Vec::new()
                }
            })
            .collect();
        let far_shooters = mesh
            .polygons
            .iter()
            .zip(&samples)
            .map(|(pm, own)| {
                (approximate && !pm.sky)
                    .then(|| FarShooter::new(own))
                    .flatten()
            })
            .collect();
        let mut solver = Progressive {
            mesh: mesh_ref.clone(),
            visibility,
            options,
            emission,
            reflectance,
            power_weight,
            samples,
            parts,
            directional: distribution::Directional::for_scene(scene),
            radiosity,
            vertex_area: mesh.vertex_areas(),
            unshot,
            shot: Vec::new(),
            part_readings: Vec::new(),
            delta: vec![Rgb::BLACK; mesh.vertex_count()],
            receives: vec![false; mesh.polygons.len()],
            candidates: vec![Vec::new(); mesh.polygons.len()],
            candidate_runs: vec![Vec::new(); mesh.polygons.len()],
            small: mesh
                .polygons
                .iter()
                .map(|pm| pm.vertex_count() < SHAFT_MIN_VERTICES)
                .collect(),
            culling_groups,
            tile_candidates: Vec::new(),
            group_points: Vec::new(),
            clusters,
            clustered,
            cells: Vec::new(),
            cell_samples: Vec::new(),
            cell_parts: Vec::new(),
            cell_part_values: Vec::new(),
            cell_leaf_values: Vec::new(),
            strata: Strata::default(),
            coarse,
            crowded,
            coarse_delta: vec![Rgb::BLACK; mesh.vertex_count()],
            facets: Facets::new(mesh, approximate),
            probes: sky_probes,
            far_shooters,
            spent: vec![Rgb::BLACK; mesh.vertex_count()],
            tile_of,
            tiles,
            pairs: 0,
            receiver_pairs: 0,
            clear_receiver_pairs: 0,
            initial_unshot_power: 0.0,
            steps: 0,
            rays: 0,
            underway: None,
            last_fraction: 1.0,
            hemicube: (options.form_factor == FormFactorMethod::Hemicube)
                .then(|| hemicube::Shooting::new(scene, mesh, options.hemicube_res)),
        };
        solver.initial_unshot_power = solver.unshot_power();
        solver
    }

    /// Radiosity per mesh vertex, in the scene's emission units.
    pub fn radiosity(&self) -> &[Rgb] {
        &self.radiosity
    }

    /// Unshot radiosity `Δb`, in the scene's emission units: one value
    /// per polygon or one per mesh vertex, by [`SolverOptions::unshot`].
    pub fn unshot(&self) -> &[Rgb] {
        self.unshot.values()
    }

    /// Emission per polygon.
    pub fn emission(&self) -> &[Rgb] {
        &self.emission
    }

    /// Reflectance per polygon.
    pub fn reflectance(&self) -> &[Rgb] {
        &self.reflectance
    }

    /// The options it runs with.
    pub fn options(&self) -> &SolverOptions {
        &self.options
    }

    /// The mesh it solves on.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The mesh it solves on, as a handle that can outlive this solver.
    pub fn mesh_ref(&self) -> MeshRef<'a> {
        self.mesh.clone()
    }

    /// The ambient term of Cohen, Chen, Wallace and Greenberg (1988): the
    /// radiosity the unshot power would add everywhere if it were spread
    /// evenly over the scene and reflected on and on,
    /// `ambient = R · Σ Δb_i A_i / Σ A_i` with `R = 1 / (1 − ρ̄)` and
    /// `ρ̄ = Σ ρ_i A_i / Σ A_i`, per channel. It estimates what is still
    /// missing from an unconverged solution and tends to zero as the solve
    /// converges. With overshooting the unshot radiosity is signed, and so
    /// is this: what is left to shoot less what was sent ahead. It is for
    /// display only, and for the overshoot (`Expectation`).
    pub fn ambient(&self) -> Rgb {
        ambient_term(&self.mesh, &self.reflectance, &self.power_weight, |j| {
            self.unshot.mean(&self.mesh, j)
        })
    }

    /// The radiosity to show: per vertex `b + ρ · ambient` (see
    /// [`Progressive::ambient`]), at least 0 per channel, written into
    /// `out` (resized to the vertex count). The ambient term is negative
    /// while overshooting has sent more light ahead than is left to shoot
    /// ([`SolverOptions::overshoot`]). The solution itself is not changed.
    pub fn radiosity_with_ambient(&self, out: &mut Vec<Rgb>) {
        let ambient = self.ambient();
        out.clear();
        out.extend(
            self.radiosity
                .iter()
                .zip(&self.mesh.vertex_polygon)
                .map(|(b, p)| (*b + self.reflectance[p.index()] * ambient).max(Rgb::BLACK)),
        );
    }

    /// Total unshot power: `Σ A_i · mean(|Δb_i|)` (per-vertex scheme: the
    /// sum over vertices of `mean(|Δb_l|) · vertex area`, per channel), in
    /// radiosity × area units: how far the solution is from converged,
    /// counting light still to be sent and light sent ahead by overshooting
    /// ([`SolverOptions::overshoot`]) alike. A sky's facets count together
    /// as at most `S · A_scene` (its radiosity times the area of every
    /// other polygon), the most it can bring to the scene, not its own far
    /// larger power (see `sky_power_weights`).
    pub fn unshot_power(&self) -> f64 {
        self.unshot_sums().0
    }

    /// The signed unshot power `Σ A_i · mean(Δb_i)`: light still to be sent
    /// less light sent ahead, in radiosity × area units, weighted as
    /// [`Progressive::unshot_power`]. Energy balance reads it: emitted =
    /// absorbed + escaped + this. Equal to [`Progressive::unshot_power`]
    /// without overshooting.
    pub fn net_unshot_power(&self) -> f64 {
        self.unshot_sums().1
    }

    /// [`Progressive::unshot_power`] and [`Progressive::net_unshot_power`]
    /// in one pass: per polygon its positive part's power `p` and its
    /// negative part's magnitude `n` (weighted as
    /// [`Progressive::polygon_power`]), summed as `p + n` and `p − n`.
    fn unshot_sums(&self) -> (f64, f64) {
        (0..self.mesh.polygons.len()).fold((0.0, 0.0), |(magnitude, net), j| {
            let p = self.polygon_power(j, Shot::PLAIN);
            let n = self.polygon_power(j, Shot::NEGATIVE);
            (magnitude + (p + n), net + (p - n))
        })
    }

    /// The power polygon `j` sends out in a step that sends `shot`
    /// ([`UnshotField::sent_power`], the channel mean), in radiosity ×
    /// area units, as it counts for choosing the shooter and for the
    /// threshold: a sky facet's weighted by [`sky_power_weights`].
    fn polygon_power(&self, j: usize, shot: Shot) -> f64 {
        let sent = self.unshot.sent_power(&self.mesh, j, shot, &self.radiosity);
        sent.mean() * self.power_weight[j]
    }

    /// The unshot power of polygon `j` due to be shot in a step of sign
    /// `negative`, weighted as [`Progressive::polygon_power`]: the
    /// positive part as it is (what it expects to receive does not count:
    /// it would only be sent ahead), the negative part beyond what it still
    /// expects ([`Progressive::polygon_shot`]; what it sent ahead waits for
    /// the light to arrive, and is taken back once the expectation,
    /// shrinking as the solve converges, no longer covers it).
    fn polygon_due(&self, j: usize, negative: bool, expected: Expectation) -> f64 {
        if negative {
            self.polygon_power(j, self.polygon_shot(j, true, expected))
        } else {
            self.polygon_power(j, Shot::PLAIN)
        }
    }

    /// What the next step expects every point to receive later
    /// ([`Expectation`]); nothing without [`SolverOptions::overshoot`].
    fn expectation(&self) -> Expectation {
        if !self.options.overshoot {
            return Expectation::NONE;
        }
        let ambient = self.ambient().max(Rgb::BLACK) * OVERSHOOT_SHARE;
        let (mut shot, mut area, mut reflected) = (0.0, 0.0, 0.0);
        for (j, pm) in self.mesh.polygons.iter().enumerate() {
            shot += self
                .unshot
                .shot_so_far(&self.mesh, j, &self.radiosity)
                .mean()
                * self.power_weight[j];
            if !pm.sky {
                area += pm.area;
                reflected += self.reflectance[j].mean() * pm.area;
            }
        }
        let left = self.net_unshot_power();
        if shot <= 0.0 || left <= 0.0 || area <= 0.0 {
            return Expectation::NONE;
        }
        let r = 1.0 / (1.0 - reflected / area);
        Expectation {
            gain: r * left / shot,
            ambient,
        }
    }

    /// The shot of polygon `j` in a step of sign `negative` ([`Shot`]):
    /// each of its points expects `gain` times what it has received, at
    /// most `ρ_j ·` the step's share of the ambient term.
    fn polygon_shot(&self, j: usize, negative: bool, expected: Expectation) -> Shot {
        Shot {
            negative,
            gain: expected.gain,
            cap: self.reflectance[j] * expected.ambient,
            emission: self.emission[j],
        }
    }

    /// Unshot power at the start (the emitted power).
    pub fn initial_unshot_power(&self) -> f64 {
        self.initial_unshot_power
    }

    /// Unshot power as a fraction of the initial; 0 when nothing emits.
    pub fn unshot_fraction(&self) -> f64 {
        if self.initial_unshot_power > 0.0 {
            self.unshot_power() / self.initial_unshot_power
        } else {
            0.0
        }
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Shadow rays cast so far.
    pub fn rays(&self) -> u64 {
        self.rays
    }

    /// Sample–vertex pairs whose visibility mattered so far (rays cast
    /// plus rays saved by clear shafts).
    pub fn pairs(&self) -> u64 {
        self.pairs
    }

    /// Shooter–receiver polygon pairs processed so far, and how many of
    /// them had a clear shaft (no ray cast at all).
    pub fn receiver_pairs(&self) -> (u64, u64) {
        (self.receiver_pairs, self.clear_receiver_pairs)
    }

    /// Why the solve should stop now, or `None` to go on (always while a
    /// step is under way: [`Progressive::in_step`]).
    pub fn stop_reason(&self) -> Option<StopReason> {
        if self.underway.is_some() {
            None
        } else if (self.unshot_fraction() <= self.options.threshold && !self.unsettled())
            || self.unshot_power() <= 0.0
        {
            Some(StopReason::Converged)
        } else if self.options.max_steps.is_some_and(|m| self.steps >= m) {
            Some(StopReason::MaxSteps)
        } else {
            None
        }
    }

    /// True when [`Progressive::stop_reason`] says to stop.
    pub fn is_done(&self) -> bool {
        self.stop_reason().is_some()
    }

    /// The polygon that shoots next (the lowest index on ties): the one
    /// with the most unshot power, or of the cluster with the most, its
    /// member with the most (past the threshold, of the cluster holding
    /// the most light that has not settled: [`SolverOptions::settle`]);
    /// `None` when nothing is left to shoot.
    pub fn next_shooter(&self) -> Option<PolygonId> {
        if let Some(u) = &self.underway {
            return Some(u.shooter);
        }
        let expected = self.expectation();
        self.choose_shooter(expected)
            .map(|(cluster, _, negative)| self.strongest_member(cluster, negative, expected))
    }

    /// The small facets whose vertices share their shadow rays
    /// ([`facets`]).
    pub fn facets(&self) -> &Facets {
        &self.facets
    }

    /// This solver with every receiving vertex asking its own shadow rays
    /// (no [`facets`] sharing), all else alike: the twin the sharing is
    /// tested against.
    #[cfg(test)]
    pub(crate) fn without_shared_rays(mut self) -> Self {
        self.facets = Facets::default();
        self
    }

    /// This solver with every sky direction asked of every vertex (no
    /// [`probes`]), all else alike: the twin probing is tested against.
    #[cfg(test)]
    pub(crate) fn without_sky_probes(mut self) -> Self {
        self.probes.iter_mut().for_each(Vec::clear);
        self
    }

    /// This solver with every sample of a far shooter asked of every
    /// vertex (no [`far_shooters`] probes), all else alike: the twin
    /// probing is tested against.
    #[cfg(test)]
    pub(crate) fn without_far_probes(mut self) -> Self {
        self.far_shooters.iter_mut().for_each(|f| *f = None);
        self
    }

    /// The clusters the solve shoots from (each polygon alone without
    /// clustering).
    pub fn clusters(&self) -> &Clusters {
        &self.clusters
    }

    /// The member of `cluster` with the most unshot power due of sign
    /// `negative` ([`Progressive::polygon_due`]; the first on ties).
    fn strongest_member(&self, cluster: usize, negative: bool, expected: Expectation) -> PolygonId {
        let mut best = (0u32, f64::NEG_INFINITY);
        for &m in self.clusters.members(cluster) {
            let power = self.polygon_due(m as usize, negative, expected);
            if power > best.1 {
                best = (m, power);
            }
        }
        PolygonId(best.0)
    }

    /// One shooting step from the polygon with the most unshot power, or
    /// with a [`SolverOptions::part_budget`] one part of it (the report
    /// says whether the step is `complete`; the next call continues it).
    /// Returns `None` (and does nothing) when no polygon has unshot power.
    /// Does not look at the threshold or step limit: see
    /// [`Progressive::is_done`].
    pub fn step(&mut self) -> Option<StepReport> {
        self.step_cancellable(&AtomicBool::new(false))
    }

    /// [`Progressive::step`] that gives up as soon as `cancel` is set (from
    /// another thread) and returns `None`, leaving the state exactly as
    /// before the step, or, in a step delivered in parts, as after its
    /// last part (the next call continues it). A window uses it to quit
    /// promptly during a long step.
    pub fn step_cancellable(&mut self, cancel: &AtomicBool) -> Option<StepReport> {
        // A step's first part counts choosing the shooter and reading it
        // (building its strata) against its budget.
        let start = std::time::Instant::now();
        if self.underway.is_none() {
            match self.begin_step(cancel)? {
                Begun::Done(report) => return Some(report),
                Begun::Underway(u) => self.underway = Some(u),
            }
        }
        self.continue_step(start, cancel)
    }

    /// Whether a step delivered in parts ([`SolverOptions::part_budget`])
    /// has begun and not finished: the next [`Progressive::step`]
    /// continues it. The solution then holds the receivers done so far.
    pub fn in_step(&self) -> bool {
        self.underway.is_some()
    }

    /// Phases 1 and 2 of a step, and with hemicubes the whole step:
    /// chooses the shooter, reads what it sends and marks its receivers.
    /// `None` when nothing is due or, for a hemicube step, once `cancel`
    /// is set.
    fn begin_step(&mut self, cancel: &AtomicBool) -> Option<Begun> {
        let expected = self.expectation();
        let (cluster, shot_power, negative) = self.choose_shooter(expected)?;
        let shooter = self.strongest_member(cluster, negative, expected);
        let roots = self.step_roots(shot_power);
        // Emitters, every polygon without clustering and every polygon of
        // a scene where nothing clusters (a room of large walls, where
        // strata would only add work) keep their own samples; a polygon
        // whose light is weak shoots through strata, as a cluster of one.
        let alone = self.clusters.members(cluster).len() == 1
            && (!self.clustered
                || self.clusters.grouped() == 0
                || !self.emission[shooter.index()].is_black()
                || roots >= self.samples[shooter.index()].len());
        let by_hemicube = self.hemicube.is_some() && !self.mesh.polygons[shooter.index()].sky;
        let shot = self.polygon_shot(shooter.index(), negative, expected);
        let signed = if negative { -shot_power } else { shot_power };
        let mut underway = Underway {
            cluster,
            shooter,
            shot_power: signed,
            expected,
            how: How::Alone,
            plan: parts::Plan::new(1, false, false),
            spent: false,
            gathered: Gathered { pairs: 0, rays: 0 },
            receivers: 0,
            clear: 0,
            part: 0,
            fraction_before: self.last_fraction,
        };
        if by_hemicube {
            // A hemicube step renders all its receivers at once: one part.
            self.read_shooter(shooter, shot);
            self.mark_receivers(shooter.index());
            let hemicubes = if self.options.clustering {
                roots
            } else {
                usize::MAX
            };
            let gathered = self.gather_hemicube(shooter, shot, hemicubes, cancel)?;
            let polygons = 0..self.mesh.polygons.len();
            self.apply_chunk(&mut underway, polygons);
            underway.gathered = gathered;
            underway.part = 1;
            return Some(Begun::Done(self.finish_step(&underway)));
        }
        let in_parts = self.options.part_budget.is_some();
        if alone {
            self.read_shooter(shooter, shot);
            self.mark_receivers(shooter.index());
            self.group_points.clear();
            self.group_points
                .extend(self.samples[shooter.index()].iter().map(|s| s.position));
            // Reflected light may be interpolated across receiving grids;
            // an emitter's shot, which draws the sharpest shadows, never is.
            let interpolating = self.clustered
                && self.options.receiver_interpolation
                && self.emission[shooter.index()].is_black();
            let per_vertex = self.samples[shooter.index()].len();
            underway.plan = parts::Plan::new(per_vertex, interpolating, in_parts);
        } else {
            self.read_cluster(cluster, roots, negative, expected);
            self.mark_cluster_receivers();
            let from_top = roots < self.step_roots(f64::INFINITY);
            underway.how = How::Cluster { from_top };
            let per_vertex = self.strata.roots.len();
            let interpolating = self.options.receiver_interpolation;
            underway.plan = parts::Plan::new(per_vertex, interpolating, in_parts);
        }
        Some(Begun::Underway(underway))
    }

    /// Gathers and applies chunks of the step under way until every
    /// receiver is done (the step's report, `complete`) or, with a
    /// [`SolverOptions::part_budget`], until the next chunk would take the
    /// part past it, counted from `start` (a report of the part). `None`
    /// once `cancel` is set:
    /// the chunk in hand is dropped, and a step none of whose chunks was
    /// applied is forgotten, leaving the state exactly as before it.
    fn continue_step(
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
            let piece = matches!(chunk, parts::Chunk::Piece { .. });
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

    /// The next chunk of step `u` ([`parts::Plan::next`]).
    /// The shooting cluster's own members count as near ones: their sums
    /// descend to the cells around them.
    fn next_chunk(&self, u: &Underway) -> Option<(parts::Chunk, parts::Cursor, u64)> {
        let clustered = matches!(u.how, How::Cluster { .. });
        let member = |j: usize| clustered && self.clusters.of(PolygonId(j as u32)) == u.cluster;
        u.plan.next(&self.mesh.polygons, &self.receives, member)
    }

    /// Culls, gathers and (once its polygons are whole) applies one chunk
    /// of the step `u`; `None` once `cancel` is set, with nothing of the
    /// chunk applied.
    fn run_chunk(
        &mut self,
        u: &mut Underway,
        chunk: parts::Chunk,
        cancel: &AtomicBool,
    ) -> Option<()> {
        match chunk {
            parts::Chunk::Whole { polygons, vertices } => {
                self.cull_chunk(u, polygons.clone());
                let gathered = self.gather_chunk(u, vertices, Stage::All, cancel)?;
                u.gathered.add(gathered);
                self.apply_chunk(u, polygons);
            }
            parts::Chunk::Piece {
                polygon,
                vertices,
                all,
                pass,
                first,
                last,
            } => {
                let two_passes = u.plan.two_passes();
                let stage = match pass {
                    parts::Pass::Exact => {
                        if first {
                            self.cull_chunk(u, polygon..polygon + 1);
                        }
                        Stage::Exact {
                            copy: (last && two_passes).then(|| all.clone()),
                        }
                    }
                    parts::Pass::Interpolated => Stage::Interpolated {
                        charge: last.then(|| all.clone()),
                    },
                };
                let gathered = self.gather_chunk(u, vertices, stage, cancel)?;
                u.gathered.add(gathered);
                let done = last && (pass == parts::Pass::Interpolated || !two_passes);
                if done {
                    self.apply_chunk(u, polygon..polygon + 1);
                }
            }
        }
        Some(())
    }

    /// Phase 3 for the receiving polygons `polygons` of step `u`: with
    /// shaft culling, the polygons in each one's shaft to the shooter (or
    /// the cluster's bounds), then in each thin shaft between a receiver
    /// tile and a group of shooter samples (or strata).
    fn cull_chunk(&mut self, u: &Underway, polygons: Range<usize>) {
        if !self.options.shaft_culling {
            return;
        }
        match u.how {
            How::Alone => {
                self.cull_polygon_shafts(u.shooter, polygons.clone());
                let groups = self.shooter_groups(u.shooter.index());
                self.cull_tile_shafts_from(groups, 1, polygons);
            }
            How::Cluster { .. } => {
                self.cull_cluster_shafts(u.cluster, polygons.clone());
                let groups = self.strata.roots.len().div_ceil(SHOOTER_GROUP).max(1);
                self.cull_tile_shafts_from(groups, 2, polygons);
            }
        }
    }

    /// Phase 4 for `vertices` in `stage`, by the step's kind.
    fn gather_chunk(
        &mut self,
        u: &Underway,
        vertices: Range<usize>,
        stage: Stage,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        match u.how {
            How::Alone => self.gather(u.shooter, vertices, stage, cancel),
            How::Cluster { from_top } => {
                self.gather_cluster(u.cluster, from_top, vertices, stage, cancel)
            }
        }
    }

    /// How many strata a clustered step shoots from at most, for a step
    /// that shoots `power` (radiosity × area units): the shooter sample
    /// cap while the step carries at least [`FULL_STRATA_SHARE`] of the
    /// initial unshot power, fewer as it carries less (by the square root
    /// of the ratio, at least [`MIN_STRATA`]). A stratum's one ray decides
    /// the visibility of its whole power, so what a lumped stratum can get
    /// wrong is at most its power: the weaker the light, the coarser its
    /// strata may be (the power oracle of Hanrahan, Salzman and
    /// Aupperle's BF refinement).
    fn step_roots(&self, power: f64) -> usize {
        let cap = match self.options.shooter_samples {
            ShooterSamples::AtMost(n) => n as usize,
            ShooterSamples::All => usize::MAX,
        };
        if self.initial_unshot_power <= 0.0 {
            return cap;
        }
        let share = power / (FULL_STRATA_SHARE * self.initial_unshot_power);
        if share >= 1.0 {
            return cap;
        }
        ((cap as f64 * share.sqrt()).ceil() as usize).clamp(MIN_STRATA.min(cap), cap)
    }

    /// Phase 1, choose the shooter: the cluster (without clustering, the
    /// polygon) with the most unshot power due of one sign
    /// ([`Progressive::polygon_due`] with the step's `expected` light; the
    /// lowest index on ties, the positive part before the negative), that
    /// power in radiosity × area units and whether it is the negative part;
    /// `None` when nothing is due. Past the threshold, the settling step
    /// instead ([`Progressive::choose_unsettled`]) while there is one. A
    /// linear pass over the polygons: it costs far less than the gather,
    /// which visits every receiving vertex.
    fn choose_shooter(&self, expected: Expectation) -> Option<(usize, f64, bool)> {
        // Past the threshold, what is left to shoot is what has not settled.
        if self.options.settle > 0.0 && self.unshot_fraction() <= self.options.threshold {
            if let Some(chosen) = self.choose_unsettled(expected) {
                return Some(chosen);
            }
        }
        if let Some(chosen) = self.choose_pending_emitter() {
            return Some(chosen);
        }
        let mut positive = vec![0.0f64; self.clusters.len()];
        let mut negative = vec![0.0f64; self.clusters.len()];
        for i in 0..self.mesh.polygons.len() {
            let c = self.clusters.of(PolygonId(i as u32));
            positive[c] += self.polygon_due(i, false, expected);
            if self.options.overshoot {
                negative[c] += self.polygon_due(i, true, expected);
            }
        }
        let mut best: Option<(usize, f64, bool)> = None;
        for (c, (&p, &n)) in positive.iter().zip(&negative).enumerate() {
            for (power, sign) in [(p, false), (n, true)] {
                if power > 0.0 && best.is_none_or(|(_, b, _)| power > b) {
                    best = Some((c, power, sign));
                }
            }
        }
        best
    }

    /// The emitter that has not shot its own light yet holding the most
    /// unshot power, as [`Progressive::choose_shooter`] returns a step
    /// (emitters are clusters of their own): one whose unshot power is
    /// still at least [`PENDING_EMISSION`] of its emitted power, and more
    /// than the threshold's share of the initial power (less could be left
    /// unshot at the end). Every such light must be shot before the solve
    /// can stop, and a reflector that shoots before it does shoots again
    /// once it has, so emitters go first: on the 150-table hall the floor
    /// and ceiling had shot 17 times in between the 42 lamps. Sky facets
    /// are left to the power order, as their light is spread over many.
    fn choose_pending_emitter(&self) -> Option<(usize, f64, bool)> {
        let least = self.options.threshold * self.initial_unshot_power;
        let mut best: Option<(usize, f64, bool)> = None;
        for (j, (e, pm)) in self.emission.iter().zip(&self.mesh.polygons).enumerate() {
            if e.is_black() || pm.sky {
                continue;
            }
            let own = e.mean() * pm.area * self.power_weight[j];
            let due = self.polygon_power(j, Shot::PLAIN);
            if due >= PENDING_EMISSION * own && due > least && best.is_none_or(|(_, b, _)| due > b)
            {
                best = Some((self.clusters.of(PolygonId(j as u32)), due, false));
            }
        }
        best
    }

    /// Whether some point has not settled ([`SolverOptions::settle`]).
    fn unsettled(&self) -> bool {
        self.options.settle > 0.0 && self.choose_unsettled(self.expectation()).is_some()
    }

    /// The radiosity below which a point counts as that bright for
    /// settling: [`SETTLE_FLOOR`] of the mean radiosity (channel mean)
    /// over the reflecting polygons' area, sky facets left out.
    fn settle_floor(&self) -> f64 {
        let areas = &self.vertex_area;
        let (mut sum, mut area) = (0.0, 0.0);
        for (j, pm) in self.mesh.polygons.iter().enumerate() {
            if pm.sky || self.reflectance[j].is_black() {
                continue;
            }
            let range = pm.vertices.start as usize..pm.vertices.end as usize;
            for (b, a) in self.radiosity[range.clone()].iter().zip(&areas[range]) {
                sum += b.mean() * a;
                area += a;
            }
        }
        if area > 0.0 {
            SETTLE_FLOOR * sum / area
        } else {
            0.0
        }
    }

    /// The settling step due ([`SolverOptions::settle`]), as
    /// [`Progressive::choose_shooter`] returns a step: the cluster and
    /// sign holding the most power of points that have not settled, with
    /// all the power due of that sign (the whole cluster shoots, as in any
    /// step); `None` when every point has settled. Sky facets bring light
    /// only from outside and reflect nothing: they never hold it up.
    fn choose_unsettled(&self, expected: Expectation) -> Option<(usize, f64, bool)> {
        let floor = self.settle_floor();
        let tolerance = self.options.settle;
        // Per cluster, for each sign: (unsettled power, power due).
        let mut sums = vec![[(0.0f64, 0.0f64); 2]; self.clusters.len()];
        let signs: &[bool] = if self.options.overshoot {
            &[false, true]
        } else {
            &[false]
        };
        for i in 0..self.mesh.polygons.len() {
            if self.mesh.polygons[i].sky {
                continue;
            }
            let c = self.clusters.of(PolygonId(i as u32));
            for &negative in signs {
                let shot = if negative {
                    self.polygon_shot(i, true, expected)
                } else {
                    Shot::PLAIN
                };
                let unsettled = self.unshot.unsettled_power(
                    &self.mesh,
                    i,
                    shot,
                    &self.radiosity,
                    tolerance,
                    floor,
                );
                let sum = &mut sums[c][negative as usize];
                sum.0 += unsettled * self.power_weight[i];
                sum.1 += self.polygon_due(i, negative, expected);
            }
        }
        let mut best: Option<(usize, f64, bool, f64)> = None;
        for (c, pair) in sums.iter().enumerate() {
            for (negative, &(unsettled, due)) in pair.iter().enumerate() {
                if unsettled > 0.0 && due > 0.0 && best.is_none_or(|b| unsettled > b.3) {
                    best = Some((c, due, negative == 1, unsettled));
                }
            }
        }
        best.map(|(c, due, negative, _)| (c, due, negative))
    }

    /// Phase 2, read the shooter's samples: fills `self.shot` with the
    /// radiosity each sample of `shooter` sends in a step that sends
    /// `shot` ([`UnshotField::read_shooter`]).
    /// Its cells much larger than the elements carry their parts' mean,
    /// and their parts' own light is read into `self.part_readings`
    /// ([`subcells`]).
    fn read_shooter(&mut self, shooter: PolygonId, shot: Shot) {
        let i = shooter.index();
        let samples = self.samples[i].len();
        self.unshot.read_shooter(
            &self.mesh,
            i,
            samples,
            shot,
            &self.radiosity,
            &mut self.shot,
            &mut self.part_readings,
        );
        subcells::carry_means(&self.parts[i], &self.part_readings, &mut self.shot);
        // The samples read the field at their cells' centres; what they
        // send together must be what the step takes from the polygon.
        let sent = self.unshot.sent_power(&self.mesh, i, shot, &self.radiosity);
        unshot::send_what_is_spent(&mut self.shot, &self.samples[i], sent)
            .apply(&mut self.part_readings);
    }

    /// Shooter samples of polygon `i` are culled in groups of
    /// [`SHOOTER_GROUP`]: the number of groups, at least 1.
    fn shooter_groups(&self, i: usize) -> usize {
        self.samples[i].len().div_ceil(SHOOTER_GROUP).max(1)
    }

    /// Marks the polygons that can receive from shooter `i`: not `i`
    /// itself, with some reflectance, some vertex in front of `i`'s plane
    /// and some sample of `i` in front of their own plane. The others get
    /// nothing and need no per-vertex work.
    fn mark_receivers(&mut self, i: usize) {
        let mesh: &Mesh = &self.mesh;
        let shooter = &mesh.polygons[i];
        let origin = self.samples[i]
            .first()
            .map(|s| s.position)
            .unwrap_or_default();
        for (j, pm) in mesh.polygons.iter().enumerate() {
            let visible_side = || {
                let range = pm.vertices.start as usize..pm.vertices.end as usize;
                let in_front = mesh.sample_positions[range.clone()]
                    .iter()
                    .any(|&x| shooter.normal.dot(x - origin) > 0.0);
                let x0 = mesh.sample_positions[range.start];
                // A cell counts by its corners: the floor cell under a
                // table leg facing a wall has its sample behind the leg's
                // face and a part in front of it, which lights the face
                // ([`formfactor::front_point`]).
                in_front
                    && self.samples[i].iter().any(|s| {
                        pm.normal.dot(s.position - x0) > 0.0
                            || s.cell
                                .is_some_and(|c| c.iter().any(|&p| pm.normal.dot(p - x0) > 0.0))
                    })
            };
            self.receives[j] = j != i
                && !self.reflectance[j].is_black()
                && !self
                    .visibility
                    .coplanar(PolygonId(i as u32), PolygonId(j as u32))
                && pm.vertex_count() > 0
                && visible_side();
        }
    }

    /// Per receiver among `polygons`: the polygons in its shaft to
    /// `shooter` (`self.candidates`; empty for polygons that do not
    /// receive).
    fn cull_polygon_shafts(&mut self, shooter: PolygonId, polygons: Range<usize>) {
        let visibility = self.visibility;
        let receives = &self.receives;
        let small = &self.small;
        let groups = &self.culling_groups;
        let start = polygons.start;
        self.candidates[polygons.clone()]
            .par_iter_mut()
            .zip(self.candidate_runs[polygons].par_iter_mut())
            .enumerate()
            .for_each(|(k, (c, runs))| {
                let j = start + k;
                if receives[j] && !small[j] {
                    visibility.shaft_candidates(shooter, PolygonId(j as u32), REFINE_MAX, c);
                } else {
                    c.clear();
                }
                group_candidates(groups, c, runs);
            });
    }

    /// Thin shafts between small groups of shooter samples and of receiver
    /// vertices of `polygons`, searched among their polygons'
    /// candidates: per tile and sample group, the polygons in the shaft
    /// between them (`self.tile_candidates`). The shooter's points are in
    /// `self.group_points`: `per_sample` points for each sample (shooter
    /// sample or stratum), in `groups` groups of [`SHOOTER_GROUP`]
    /// samples.
    fn cull_tile_shafts_from(&mut self, groups: usize, per_sample: usize, polygons: Range<usize>) {
        let mesh: &Mesh = &self.mesh;
        let visibility = self.visibility;
        let group_len = SHOOTER_GROUP * per_sample;
        let receives = &self.receives;
        let group_points = &self.group_points;
        let polygon_candidates = &self.candidates;
        let candidate_runs = &self.candidate_runs;
        let tiles = &self.tiles;
        self.tile_candidates
            .resize_with(tiles.len() * groups, Vec::new);
        // The tiles of `polygons`: theirs are consecutive, as their
        // vertices are.
        let first = mesh.polygons[polygons.start].vertices.start as usize;
        let end = mesh.polygons[polygons.end - 1].vertices.end as usize;
        if first == end {
            return;
        }
        let tile_range = self.tile_of[first] as usize..self.tile_of[end - 1] as usize + 1;
        self.tile_candidates[tile_range.start * groups..tile_range.end * groups]
            .par_iter_mut()
            .enumerate()
            .for_each(|(k, c)| {
                let index = tile_range.start * groups + k;
                let (t, g) = (index / groups, index % groups);
                let Some(tile) = tiles.get(t) else {
                    c.clear();
                    return;
                };
                let j = mesh.vertex_polygon[tile.start as usize].index();
                let pc = &polygon_candidates[j];
                if receives[j] && !pc.is_empty() && pc.len() <= REFINE_MAX {
                    let to = &mesh.sample_positions[tile.start as usize..tile.end as usize];
                    let from = &group_points[(g * group_len).min(group_points.len())
                        ..((g + 1) * group_len).min(group_points.len())];
                    visibility.refine_candidates_in_runs(
                        from,
                        to,
                        &polygon_candidates[j],
                        &candidate_runs[j],
                        c,
                    );
                } else {
                    c.clear();
                }
            });
    }

    /// Phase 4, gather: every receiving vertex's `Δrad = ρ_j · Σ_k Δb_k ·
    /// F(l → sample k)` into `self.delta` (black for the others), in
    /// parallel; with clusters, a non-emitter's shot interpolates where
    /// [`gather_passes`] allows. Each vertex's value depends only on its
    /// own sum and the first pass, so the bits do not depend on the thread
    /// count. Returns `None` once `cancel` is set, with the solution
    /// untouched (only scratch written).
    fn gather(
        &mut self,
        shooter: PolygonId,
        vertices: Range<usize>,
        stage: Stage,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        let i = shooter.index();
        let mesh: &Mesh = &self.mesh;
        let visibility = self.visibility;
        let culling = self.options.shaft_culling;
        let groups = self.shooter_groups(i);
        let receives = &self.receives;
        let candidates = &self.candidates;
        let small = &self.small;
        let tile_candidates = &self.tile_candidates;
        let tile_of = &self.tile_of;
        let samples = &self.samples[i];
        let shooter_normal = mesh.polygons[i].normal;
        let reflectance = &self.reflectance;
        let near_field = self.options.near_field;
        let shot = &self.shot;
        let directional = self.directional[i].as_ref();
        let split = subcells::Split::of_polygon(&self.parts[i], &self.part_readings);
        // The exact `Δrad` at receiving vertex `l` of polygon `j`, with the
        // pairs and rays it took.
        let facets = &self.facets;
        let probes = &self.probes[i][..];
        let far_shooter = self.far_shooters[i].as_ref();
        let exact = |l: usize, j: PolygonId, scratch: &mut Scratch| -> (Rgb, u64, u64) {
            let x = mesh.sample_positions[l];
            let tile = tile_of[l] as usize * groups;
            let mut rays = 0u64;
            let memo = &mut scratch.memo;
            let nx = mesh.polygons[j.index()].normal;
            let mut last = LastBlocker::default();
            // Whether sample `k` at `s` is hidden from this vertex.
            let mut ray = |k: usize, s: glam::Vec3| -> bool {
                // A ray from elsewhere than the sample (the part of a near
                // cell in front of the vertex) is the vertex's own and
                // outside the shafts, which were built from the samples.
                if s != samples[k].position {
                    rays += 1;
                    return visibility.occluded_remembering(s, x, (shooter, j), &mut last);
                }
                // A small facet's vertices share one ray per sample.
                if let Some((hit, cast)) = facets.shared_ray(
                    memo,
                    visibility,
                    (shooter, j),
                    k as u32,
                    s,
                    samples[k].exact_r2,
                ) {
                    rays += cast;
                    return hit;
                }
                let blockers = tile_candidates
                    .get(tile + k / SHOOTER_GROUP)
                    .map_or(&[][..], |c| &c[..]);
                if !culling || small[j.index()] || candidates[j.index()].len() > REFINE_MAX {
                    rays += 1;
                    visibility.occluded_remembering(s, x, (shooter, j), &mut last)
                } else if blockers.is_empty() {
                    // Nothing in the shaft: visible, no ray needed.
                    false
                } else if blockers.len() <= LINEAR_CANDIDATES {
                    rays += 1;
                    visibility.occluded_among_remembering(s, x, blockers, &mut last)
                } else {
                    rays += 1;
                    visibility.occluded_remembering(s, x, (shooter, j), &mut last)
                }
            };
            // A sky facet's probes, when they agree, stand for all its
            // directions; so do a far shooter's for all its samples.
            let far_probes = far_shooter.and_then(|f| f.probes_from(x));
            let verdict = match (probes, far_probes) {
                ([], None) => None,
                ([], Some(far)) => probes::verdict(far, samples, x, nx, &mut ray),
                (sky, _) => probes::verdict(sky, samples, x, nx, &mut ray),
            };
            let (f, pairs) = distribution::shot_point_to_samples(
                directional,
                x,
                nx,
                shooter_normal,
                samples,
                |k| shot[k],
                split.as_ref(),
                near_field,
                |k, s| match verdict {
                    Some(blocked) => blocked,
                    None => ray(k, s),
                },
            );
            (reflectance[j.index()] * f, pairs, rays)
        };
        // Reflected light may be interpolated across receiving grids; an
        // emitter's shot, which draws the sharpest shadows, never is.
        let cells = Interpolating {
            on: self.clustered
                && self.options.receiver_interpolation
                && self.emission[i].is_black(),
            coarse: &self.coarse,
            crowded: &self.crowded,
            clusters: &self.clusters,
            receives,
            cluster: self.clusters.of(shooter),
            shooter: self.clusters.bounds(self.clusters.of(shooter)),
            positions: &mesh.positions,
            held: &self.radiosity,
        };
        gather_passes(
            Sums {
                delta: &mut self.delta,
                first: &mut self.coarse_delta,
                spent: &mut self.spent,
            },
            mesh,
            &cells,
            cancel,
            exact,
            Work { vertices, stage },
        )
    }

    /// Phase 4 by hemicubes ([`hemicube::Shooting::gather`]): `Δrad` of
    /// every receiving vertex into `self.delta`, from what `shot` sends
    /// (read into `self.shot`), from at most `hemicubes` hemicubes
    /// ([`Progressive::hemicube_points`]).
    fn gather_hemicube(
        &mut self,
        shooter: PolygonId,
        shot: Shot,
        hemicubes: usize,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        let i = shooter.index();
        let power = self.unshot.sent_power(&self.mesh, i, shot, &self.radiosity);
        let merged = self.hemicube_points(shooter, hemicubes);
        let (samples, shot) = match &merged {
            Some((samples, shot)) => (&samples[..], &shot[..]),
            None => (&self.samples[i][..], &self.shot[..]),
        };
        let hemicube = self.hemicube.as_mut()?;
        let pairs = hemicube.gather(
            &self.mesh,
            i,
            self.directional[i].as_ref(),
            samples,
            shot,
            power,
            &self.receives,
            &self.reflectance,
            &mut self.delta,
            cancel,
        )?;
        Some(Gathered { pairs, rays: 0 })
    }

    /// Where a hemicube step of `shooter` places its hemicubes when it may
    /// use at most `hemicubes` ([`Progressive::step_roots`]: fewer the
    /// weaker the step's light): `None` when the shooter's own samples
    /// are few enough (one hemicube each, carrying `self.shot`). Else its
    /// cells are merged into that many runs, the cut of their
    /// [`Strata`] as a cluster's weak step takes it, each a hemicube at
    /// the run's power-weighted centroid (on the polygon, which is
    /// convex) carrying the run's area and its mean unshot radiosity: the
    /// same power, from fewer points. A run is a coarser quadrature of
    /// the shooter, which only receivers within a few runs' widths notice,
    /// and a weak step carries too little light for that to show.
    fn hemicube_points(
        &self,
        shooter: PolygonId,
        hemicubes: usize,
    ) -> Option<(Vec<ShooterSample>, Vec<Rgb>)> {
        let i = shooter.index();
        let samples = &self.samples[i];
        if hemicubes >= samples.len() {
            return None;
        }
        let normal = self.mesh.polygons[i].normal;
        let cells: Vec<Cell> = samples
            .iter()
            .zip(&self.shot)
            .enumerate()
            .map(|(k, (sample, &unshot))| Cell {
                polygon: shooter,
                sample: k as u32,
                unshot,
                area: sample.area,
                normal,
                power: unshot.mean() * sample.area,
            })
            .filter(|c| c.power > 0.0)
            .collect();
        let strata = Strata::build(&cells, hemicubes, |c| {
            samples[cells[c].sample as usize].bounds()
        });
        let mut points = Vec::with_capacity(strata.roots.len());
        let mut shot = Vec::with_capacity(strata.roots.len());
        for &r in &strata.roots {
            let node = &strata.nodes[r as usize];
            let run = node.cells.start as usize..node.cells.end as usize;
            let area: f64 = cells[run].iter().map(|c| c.area).sum();
            if area <= 0.0 {
                continue;
            }
            points.push(ShooterSample::point(node.centroid, area));
            shot.push(node.power / area);
        }
        Some((points, shot))
    }

    /// Cluster step, phase 2: the cluster's cells (every member's shooter
    /// samples that carry unshot power, with what they carry) and their
    /// strata ([`Strata::build`]), a cut of at most `roots`
    /// ([`Progressive::step_roots`]).
    fn read_cluster(
        &mut self,
        cluster: usize,
        roots: usize,
        negative: bool,
        expected: Expectation,
    ) {
        self.cells.clear();
        self.cell_samples.clear();
        self.cell_parts.clear();
        self.cell_part_values.clear();
        self.cell_leaf_values.clear();
        for member in 0..self.clusters.members(cluster).len() {
            let m = self.clusters.members(cluster)[member];
            let i = m as usize;
            let shot = self.polygon_shot(i, negative, expected);
            // Each member's cells read as when it shoots alone.
            self.read_shooter(PolygonId(m), shot);
            let mesh: &Mesh = &self.mesh;
            let parts = &self.parts[i];

            for (k, (sample, &unshot)) in self.samples[i].iter().zip(&self.shot).enumerate() {
                let power = unshot.mean() * sample.area;
                if power > 0.0 {
                    self.cells.push(Cell {
                        polygon: PolygonId(m),
                        sample: k as u32,
                        unshot,
                        area: sample.area,
                        normal: mesh.polygons[i].normal,
                        power,
                    });
                    self.cell_samples.push(*sample);
                    let at = match parts.cell_values(k, &self.part_readings) {
                        Some((parts, leaves)) => {
                            let at = self.cell_part_values.len() as u32;
                            self.cell_part_values.extend_from_slice(parts);
                            self.cell_leaf_values.extend_from_slice(leaves);
                            at
                        }
                        None => subcells::NONE,
                    };
                    self.cell_parts.push(at);
                }
            }
        }
        let k = roots.min(self.cells.len());
        let samples = &self.cell_samples;
        self.strata = Strata::build(&self.cells, k, |c| samples[c].bounds());
    }

    /// Cluster step, marking: every polygon with some reflectance
    /// receives, the cluster's own members included (they see each
    /// other). Keeps the strata's bounds, two corners a stratum, for the
    /// thin shafts ([`Progressive::cull_chunk`]).
    fn mark_cluster_receivers(&mut self) {
        let mesh: &Mesh = &self.mesh;
        for (j, pm) in mesh.polygons.iter().enumerate() {
            self.receives[j] = !self.reflectance[j].is_black() && pm.vertex_count() > 0;
        }
        self.group_points.clear();
        for &r in &self.strata.roots {
            let s = &self.strata.nodes[r as usize];
            self.group_points.extend([s.bounds.0, s.bounds.1]);
        }
    }

    /// Cluster step, phase 3 for `polygons`: the polygons in each
    /// non-member's shaft to the cluster's bounds (members always test
    /// their rays against the whole scene).
    fn cull_cluster_shafts(&mut self, cluster: usize, polygons: Range<usize>) {
        let (lo, hi) = self.clusters.bounds(cluster);
        let bounds = (lo.as_dvec3(), hi.as_dvec3());
        let visibility = self.visibility;
        let receives = &self.receives;
        let clusters = &self.clusters;
        let small = &self.small;
        let groups = &self.culling_groups;
        let start = polygons.start;
        self.candidates[polygons.clone()]
            .par_iter_mut()
            .zip(self.candidate_runs[polygons].par_iter_mut())
            .enumerate()
            .for_each(|(k, (c, runs))| {
                let j = start + k;
                let member = clusters.of(PolygonId(j as u32)) == cluster;
                if receives[j] && !member && !small[j] {
                    visibility.box_shaft_candidates(bounds, PolygonId(j as u32), REFINE_MAX, c);
                } else {
                    c.clear();
                }
                group_candidates(groups, c, runs);
            });
    }

    /// Cluster step, phase 4: every receiving vertex's `Δrad`, summed over
    /// the strata: a far stratum ([`cluster::Seen::Far`]) gives one term
    /// and one ray; one wholly behind gives nothing; any other descends to
    /// its halves, down to single cells with the rules of a polygon's
    /// shot, unless its light is too weak there to matter
    /// ([`WEAK_STRATUM_SHARE`]), when it is one term too. Cells never shoot to their own polygon or one coplanar with
    /// it. Per vertex, in the two passes of [`gather_passes`], as
    /// [`Progressive::gather`].
    fn gather_cluster(
        &mut self,
        cluster: usize,
        from_top: bool,
        vertices: Range<usize>,
        stage: Stage,
        cancel: &AtomicBool,
    ) -> Option<Gathered> {
        let mesh: &Mesh = &self.mesh;
        let visibility = self.visibility;
        let culling = self.options.shaft_culling;
        let groups = self.strata.roots.len().div_ceil(SHOOTER_GROUP).max(1);
        let receives = &self.receives;
        let tile_candidates = &self.tile_candidates;
        let tile_of = &self.tile_of;
        let reflectance = &self.reflectance;
        let near_field = self.options.near_field;
        let clusters = &self.clusters;
        let candidates = &self.candidates;
        let small = &self.small;
        let cells = &self.cells;
        let cell_samples = &self.cell_samples;
        let cell_parts = &self.cell_parts;
        let cell_part_values = &self.cell_part_values;
        let cell_leaf_values = &self.cell_leaf_values;
        let parts = &self.parts;
        let strata = &self.strata;
        let held = &self.radiosity;
        let lump_share = if self.options.receiver_interpolation {
            WEAK_STRATUM_SHARE
        } else {
            0.0
        };
        // The exact `Δrad` at receiving vertex `l` of polygon `j`, with the
        // pairs and rays it took.
        let facets = &self.facets;
        let exact = |l: usize, j: PolygonId, scratch: &mut Scratch| -> (Rgb, u64, u64) {
            let Scratch { stack, memo } = scratch;
            let member = clusters.of(j) == cluster;
            let x = mesh.sample_positions[l];
            let nx = mesh.polygons[j.index()].normal;
            // What this step may leave to lumped strata at this vertex,
            // as a bound before reflection ([`WEAK_STRATUM_SHARE`]).
            let rho = reflectance[j.index()].mean();
            let mut allowance = if member || rho <= 0.0 {
                0.0
            } else {
                lump_share * held[l].mean() / rho
            };
            let tile = tile_of[l] as usize * groups;
            let (mut sum, mut pairs, mut rays) = (Rgb::BLACK, 0u64, 0u64);
            // (node, its cut index or NONE above the cut)
            const NONE: u32 = u32::MAX;
            stack.clear();
            // No cells (every reading zero): the step sends nothing.
            if from_top && !strata.nodes.is_empty() {
                stack.push((0, strata.root_index.first().copied().unwrap_or(NONE)));
            } else {
                stack.extend(strata.roots.iter().enumerate().map(|(i, &r)| (r, i as u32)));
                stack.reverse();
            }
            let whole = &candidates[j.index()];
            let mut last = LastBlocker::default();
            while let Some((n, si)) = stack.pop() {
                // Rays from a node in or below the cut are culled by
                // its group's thin shaft; from above, by the receiver's
                // shaft to the whole cluster.
                let blockers =
                    (culling && !member && !small[j.index()] && whole.len() <= REFINE_MAX).then(
                        || {
                            if si == NONE {
                                &whole[..]
                            } else {
                                tile_candidates
                                    .get(tile + si as usize / SHOOTER_GROUP)
                                    .map_or(&[][..], |c| &c[..])
                            }
                        },
                    );
                // A small facet's vertices share one ray per node.
                // Keyed by node and by the cell the ray leaves from (the
                // node's representative, or a normal bin's).
                let mut blocked = |from: glam::Vec3, own: PolygonId, exact_r2: f32, slot: u32| {
                    if slot == OWN_RAY_SLOT {
                        rays += 1;
                        return visibility.occluded_remembering(from, x, (own, j), &mut last);
                    }
                    let key = n * RAY_SLOTS + slot;
                    let (hit, cast) = facets
                        .shared_ray(memo, visibility, (own, j), key, from, exact_r2)
                        .unwrap_or_else(|| {
                            ray_blocked(visibility, blockers, from, x, (own, j), &mut last)
                        });
                    rays += cast;
                    hit
                };
                let node = &strata.nodes[n as usize];
                let rep = &cells[node.representative as usize];
                let rep_sample = &cell_samples[node.representative as usize];
                // Above a weak step's cut, nodes larger than any
                // stratum must lie deeper in front of the receiver.
                let depth_ratio = if si == NONE {
                    cluster::TOP_DEPTH_RATIO
                } else {
                    cluster::PLANE_DEPTH_RATIO
                };
                let seen = node.seen_from_at(x, nx, depth_ratio);
                if seen == Seen::Behind {
                    continue;
                }
                let binned = seen == Seen::FarBinned && from_top;
                let far = (seen == Seen::Far || binned) && !visibility.coplanar(rep.polygon, j);
                // A near stratum whose light is too weak here to matter
                // is taken as one term all the same, while the bounds of
                // what such terms bring stay within the allowance, unless
                // the vertex is inside its sphere ([`WEAK_STRATUM_SHARE`]).
                // `lumped` holds the bound of such a stratum.
                let lumped = if !far
                    && node.children.is_some()
                    && allowance > 0.0
                    && (x - node.centre).length_squared() > node.radius * node.radius
                {
                    let bound = node.bound_at(x, nx);
                    (bound <= allowance && rep.polygon != j && !visibility.coplanar(rep.polygon, j))
                        .then(|| {
                            allowance -= bound;
                            bound
                        })
                } else {
                    None
                };
                match node.children {
                    Some((a, b)) if !far && lumped.is_none() => {
                        let child = |c: u32| {
                            let at = strata.root_index[c as usize];
                            (c, if at != NONE { at } else { si })
                        };
                        stack.push(child(b));
                        stack.push(child(a));
                        continue;
                    }
                    None if !far => {
                        // A single cell close by: the exact rules of a
                        // polygon's shot.
                        if rep.polygon == j || visibility.coplanar(rep.polygon, j) {
                            continue;
                        }
                        // A split cell by its parts, as when its
                        // polygon shoots alone.
                        let at = cell_parts[node.representative as usize];
                        let split = (at != subcells::NONE)
                            .then(|| {
                                let at = at as usize;
                                subcells::Split::of_cell(
                                    &parts[rep.polygon.index()],
                                    rep.sample as usize,
                                    &cell_part_values[at..at + subcells::PARTS],
                                    &cell_leaf_values[at * subcells::LEAVES
                                        ..(at + subcells::PARTS) * subcells::LEAVES],
                                )
                            })
                            .flatten();
                        let (f, asked) = weighted_point_to_samples(
                            x,
                            nx,
                            mesh.polygons[rep.polygon.index()].normal,
                            std::slice::from_ref(rep_sample),
                            |_| rep.unshot,
                            split.as_ref(),
                            near_field,
                            |_, from| {
                                let exact_r2 = rep_sample.exact_r2;
                                // Not the sample: a near cell's part in
                                // front of the vertex, asked alone.
                                let slot = if from == rep_sample.position {
                                    REPRESENTATIVE_SLOT
                                } else {
                                    OWN_RAY_SLOT
                                };
                                blocked(from, rep.polygon, exact_r2, slot)
                            },
                        );
                        sum += f;
                        pairs += asked;
                        continue;
                    }
                    _ => {}
                }
                // Far: the node's power from its centroid, with its
                // mean normal and one ray from its representative; or,
                // binned (cells facing every way), each normal bin's
                // power with its own cosine and its own ray, from the
                // bin's representative (a cell facing the receiver: the
                // node's may lie on a table's underside, whose ray to
                // the ceiling the top blocks; one ray for all bins would
                // give the whole node the visibility of one face). A
                // lumped node, whose light is bounded within the
                // allowance, takes one ray, from the bin bringing most.
                let d = x - node.centroid;
                let r2 = d.length_squared();
                let cos_x = -nx.dot(d);
                if cos_x <= 0.0 || r2 <= 0.0 {
                    continue;
                }
                let geometry = {
                    let r2 = f64::from(r2);
                    f64::from(cos_x) / (std::f64::consts::PI * r2 * r2)
                };
                // (power it brings, whether a ray finds it visible)
                let (mut power, mut seen) = (Rgb::BLACK, Rgb::BLACK);
                if binned || lumped.is_some() {
                    let one_ray = lumped.is_some();
                    let (mut most, mut from) = (0.0, None);
                    for (b, (p, normal)) in node.bins.iter().enumerate() {
                        let cos_s = normal.dot(d);
                        let at = node.bin_representatives[b];
                        if cos_s <= 0.0 || at == u32::MAX {
                            continue;
                        }
                        let brings = *p * f64::from(cos_s);
                        power += brings;
                        if one_ray {
                            if brings.mean() > most {
                                most = brings.mean();
                                from = Some((at, b as u32));
                            }
                            continue;
                        }
                        let (origin, sample) = (&cells[at as usize], &cell_samples[at as usize]);
                        if !blocked(sample.position, origin.polygon, 0.0, b as u32) {
                            seen += brings;
                        }
                    }
                    if let Some((at, b)) = from {
                        let (origin, sample) = (&cells[at as usize], &cell_samples[at as usize]);
                        if !blocked(sample.position, origin.polygon, 0.0, b) {
                            seen = power;
                        }
                    }
                } else {
                    let cos_s = node.mean_normal.dot(d);
                    if cos_s <= 0.0 {
                        continue;
                    }
                    power = node.power * f64::from(cos_s);
                    // Far: no vertex near a cell.
                    if !blocked(rep_sample.position, rep.polygon, 0.0, REPRESENTATIVE_SLOT) {
                        seen = power;
                    }
                }
                if power.is_black() {
                    continue;
                }
                pairs += 1;
                let term = seen * geometry;
                // A lumped stratum may be close: its term is held to the
                // bound on what it can bring (in the share its visible
                // bins have of it).
                let whole = power.mean() * geometry;
                sum += match lumped {
                    Some(cap) if whole > cap => term * (cap / whole),
                    _ => term,
                };
            }
            (reflectance[j.index()] * sum, pairs, rays)
        };
        let cells = Interpolating {
            on: self.options.receiver_interpolation,
            coarse: &self.coarse,
            crowded: &self.crowded,
            clusters,
            receives,
            cluster,
            shooter: clusters.bounds(cluster),
            positions: &mesh.positions,
            held: &self.radiosity,
        };
        gather_passes(
            Sums {
                delta: &mut self.delta,
                first: &mut self.coarse_delta,
                spent: &mut self.spent,
            },
            mesh,
            &cells,
            cancel,
            exact,
            Work { vertices, stage },
        )
    }

    /// Phase 5, apply, for the receiving polygons `polygons` of step `u`:
    /// adds the gathered `Δrad` (subtracts it, for a step of negative
    /// light) to their radiosity and unshot radiosity (polygon by polygon
    /// in index order, so the sums are the same whatever the thread
    /// count). Before the step's first receivers, takes what the shooters
    /// sent from their unshot radiosity ([`UnshotField::spend`], with the
    /// `expected` light the step read them with): a cluster's members
    /// receive from each other in the step that empties them.
    fn apply_chunk(&mut self, u: &mut Underway, polygons: Range<usize>) {
        let negative = u.shot_power < 0.0;
        if !u.spent {
            for &m in self.clusters.members(u.cluster) {
                let shot = self.polygon_shot(m as usize, negative, u.expected);
                self.unshot
                    .spend(&self.mesh, m as usize, shot, &self.radiosity);
            }
            u.spent = true;
        }
        let culling = self.options.shaft_culling;
        let mesh: &Mesh = &self.mesh;
        for j in polygons {
            if !self.receives[j] {
                continue;
            }
            let pm = &mesh.polygons[j];
            u.receivers += 1;
            u.clear += (culling && !self.small[j] && self.candidates[j].is_empty()) as u64;
            for l in pm.vertices.clone() {
                let l = l as usize;
                if negative {
                    self.delta[l] = -self.delta[l];
                    // Negative light takes back what overshooting sent
                    // ahead; where the two reached a vertex by other
                    // sample points, rounding could take a little more
                    // than it holds.
                    self.radiosity[l] = (self.radiosity[l] + self.delta[l]).max(Rgb::BLACK);
                } else {
                    self.radiosity[l] += self.delta[l];
                }
            }
            self.unshot.accumulate(mesh, j, &self.delta);
        }
    }

    /// The report of a part of step `u` that leaves it unfinished.
    fn part_report(&self, u: &Underway, complete: bool) -> StepReport {
        StepReport {
            step: self.steps + u64::from(!complete),
            shooter: u.shooter,
            polygons: self.clusters.members(u.cluster).len() as u32,
            shot_power: u.shot_power,
            // Summing the unshot power visits every vertex: a part of a
            // step not finished says what the last finished step left.
            unshot_fraction: if complete {
                self.unshot_fraction()
            } else {
                u.fraction_before
            },
            rays: u.gathered.rays,
            pairs: u.gathered.pairs,
            receivers: u.receivers,
            clear_receivers: u.clear,
            part: u.part,
            complete,
        }
    }

    /// Counts the finished step `u` and reports it.
    fn finish_step(&mut self, u: &Underway) -> StepReport {
        self.pairs += u.gathered.pairs;
        self.receiver_pairs += u.receivers;
        self.clear_receiver_pairs += u.clear;
        self.steps += 1;
        self.rays += u.gathered.rays;
        let report = self.part_report(u, true);
        self.last_fraction = report.unshot_fraction;
        report
    }

    /// The state a solve on `refined`, a refinement of this solve's mesh,
    /// starts from to continue this one rather than start afresh (per-vertex
    /// scheme only; `None` for the per-polygon one):
    ///
    /// - a vertex both meshes have keeps its radiosity and unshot radiosity;
    /// - a new vertex gathers, from every polygon, the light that polygon
    ///   has shot so far (`b − Δb` read at its samples, as shooting reads
    ///   `Δb`): `b = e + ρ Σ_i F(x → i)(b − Δb)_i`, with the same form
    ///   factors and visibility as a step. Its unshot radiosity is the
    ///   coarse field carried over ([`Refiner::carry`]), so the polygon's
    ///   unshot power is unchanged.
    ///
    /// `refined` must be the mesh `refiner` returned last, refining this
    /// solve's mesh. The gather's rays are added to the ray count.
    pub fn refined_state(
        &self,
        refined: &Mesh,
        refiner: &Refiner,
    ) -> Option<checkpoint::SolverState> {
        let unshot = self.unshot.carried(refiner)?;
        let previous = refiner.previous_index();
        if previous.len() != refined.vertex_count() || unshot.len() != refined.vertex_count() {
            return None;
        }
        // Each polygon's cells as a step of it reads them: a split cell by
        // its parts.
        let shot: Vec<(Vec<Rgb>, Vec<Rgb>)> = self
            .unshot
            .shot_at_samples(&self.mesh, &self.radiosity)?
            .into_iter()
            .zip(&self.parts)
            .map(|((mut values, readings), parts)| {
                subcells::carry_means(parts, &readings, &mut values);
                (values, readings)
            })
            .collect();
        let visibility = self.visibility;
        let near_field = self.options.near_field;
        let gathered: Vec<(Rgb, u64)> = (0..refined.vertex_count())
            .into_par_iter()
            .with_min_len(64)
            .map(|l| {
                let j = refined.vertex_polygon[l];
                let b = match previous[l] {
                    Some(old) => return (self.radiosity[old as usize], 0),
                    None => self.emission[j.index()],
                };
                let rho = self.reflectance[j.index()];
                if rho.is_black() {
                    return (b, 0);
                }
                let x = refined.sample_positions[l];
                let normal = refined.polygons[j.index()].normal;
                let mut sum = Rgb::BLACK;
                let mut rays = 0;
                for (i, ((samples, (values, readings)), parts)) in
                    self.samples.iter().zip(&shot).zip(&self.parts).enumerate()
                {
                    // Coplanar polygons exchange no light (see
                    // `Visibility::coplanar`).
                    if i == j.index() || visibility.coplanar(PolygonId(i as u32), j) {
                        continue;
                    }
                    let shooter = PolygonId(i as u32);
                    let (f, asked) = distribution::shot_point_to_samples(
                        self.directional[i].as_ref(),
                        x,
                        normal,
                        self.mesh.polygons[i].normal,
                        samples,
                        |k| values[k],
                        subcells::Split::of_polygon(parts, readings).as_ref(),
                        near_field,
                        |_, s| visibility.occluded(s, x, (shooter, j)),
                    );
                    sum += f;
                    rays += asked;
                }
                (b + rho * sum, rays)
            })
            .collect();
        let rays = gathered.iter().map(|g| g.1).sum::<u64>();
        Some(checkpoint::SolverState {
            radiosity: gathered.into_iter().map(|g| g.0).collect(),
            unshot,
            steps: self.steps,
            rays: self.rays + rays,
            // Interpolation on the refined mesh starts with no charges.
            charges: Vec::new(),
        })
    }

    /// Checks the invariants; returns the first broken one.
    pub fn validate(&self) -> Result<(), SolverError> {
        if self.radiosity.len() != self.mesh.vertex_count() || !self.unshot.fits(&self.mesh) {
            return Err(SolverError::MeshMismatch);
        }
        let bad = |c: &Rgb| !c.is_finite() || c.min_channel() < 0.0;
        if let Some(l) = self.radiosity.iter().position(bad) {
            return Err(SolverError::BadRadiosity {
                vertex: l,
                value: self.radiosity[l],
            });
        }
        // Unshot radiosity is negative where overshooting sent light
        // ahead, so only its finiteness is checked.
        if let Some(j) = self.unshot().iter().position(|c| !c.is_finite()) {
            return Err(SolverError::BadUnshot {
                unit: self.unshot.unit(),
                index: j,
                value: self.unshot()[j],
            });
        }
        Ok(())
    }

    /// A copy of everything [`Progressive::restore`] needs to continue
    /// this solve bit for bit (see [`checkpoint`]). Taken between steps:
    /// in the middle of a step delivered in parts
    /// ([`Progressive::in_step`]) it would hold the receivers done so far
    /// and not the rest (checkpoints are saved by batch runs, which do not
    /// ask for parts).
    pub fn state(&self) -> checkpoint::SolverState {
        debug_assert!(
            self.underway.as_ref().is_none_or(|u| !u.spent),
            "a solver state taken in the middle of a step"
        );
        checkpoint::SolverState {
            radiosity: self.radiosity.clone(),
            unshot: self.unshot().to_vec(),
            steps: self.steps,
            rays: self.rays,
            charges: self.charges().to_vec(),
        }
    }

    /// Per mesh vertex, the interpolation error charged to it as a check
    /// vertex ([`receivers::accept`]), in the scene's emission units; empty
    /// while none has been (so a solve that never interpolates saves none).
    pub fn charges(&self) -> &[Rgb] {
        if self.spent.iter().all(|c| c.is_black()) {
            &[]
        } else {
            &self.spent
        }
    }

    /// Replaces the solve's state by a saved one from a solve of the same
    /// scene, mesh and options; refuses (and changes nothing) when the
    /// array sizes differ, a value is not finite, or a radiosity or charge
    /// is negative.
    pub fn restore(&mut self, state: checkpoint::SolverState) -> Result<(), SolverError> {
        if state.radiosity.len() != self.radiosity.len()
            || state.unshot.len() != self.unshot.values().len()
            || !(state.charges.is_empty() || state.charges.len() == self.radiosity.len())
        {
            return Err(SolverError::StateMismatch {
                radiosity: state.radiosity.len(),
                unshot: state.unshot.len(),
                expected_radiosity: self.radiosity.len(),
                expected_unshot: self.unshot.values().len(),
            });
        }
        let bad = |c: &Rgb| !c.is_finite() || c.min_channel() < 0.0;
        if state.radiosity.iter().chain(&state.charges).any(bad)
            || state.unshot.iter().any(|c| !c.is_finite())
        {
            return Err(SolverError::BadStateValue);
        }
        self.spent = if state.charges.is_empty() {
            vec![Rgb::BLACK; self.radiosity.len()]
        } else {
            state.charges
        };
        self.radiosity = state.radiosity;
        self.unshot.set_values(state.unshot);
        self.underway = None;
        self.last_fraction = self.unshot_fraction();
        self.steps = state.steps;
        self.rays = state.rays;
        Ok(())
    }
}

/// Which receiving vertices a step may interpolate
/// ([`receivers`]): those of a receiving grid, not a member of the
/// shooting cluster (those are near it), neither coarse nor a check.
struct Interpolating<'s> {
    /// False when the step evaluates every vertex exactly.
    on: bool,
    coarse: &'s [Option<CoarseGrid>],
    /// Per mesh vertex, whether the cell it is the first corner of is
    /// crowded (empty: none is).
    crowded: &'s [bool],
    clusters: &'s Clusters,
    receives: &'s [bool],
    /// The shooting cluster.
    cluster: usize,
    /// The shooting cluster's bounds.
    shooter: (glam::Vec3, glam::Vec3),
    /// Element vertex positions.
    positions: &'s [glam::Vec3],
    /// Per vertex, the radiosity before the step.
    held: &'s [Rgb],
}

impl Interpolating<'_> {
    /// The coarse cell vertex `l` of polygon `j` may be interpolated from.
    fn cell(&self, l: usize, j: PolygonId) -> Option<receivers::Interpolation> {
        if !self.on || !self.receives[j.index()] || self.clusters.of(j) == self.cluster {
            return None;
        }
        match self.coarse[j.index()]?.role(l as u32) {
            receivers::Role::Fine(cell) => self.usable(cell),
            receivers::Role::Exact | receivers::Role::Check(_) => None,
        }
    }

    /// The coarse cell vertex `l` of polygon `j` is the check vertex of,
    /// when the step may interpolate that cell.
    fn checked_cell(&self, l: usize, j: PolygonId) -> Option<receivers::Interpolation> {
        if !self.on || !self.receives[j.index()] || self.clusters.of(j) == self.cluster {
            return None;
        }
        match self.coarse[j.index()]?.role(l as u32) {
            receivers::Role::Check(cell) => self.usable(cell),
            receivers::Role::Exact | receivers::Role::Fine(_) => None,
        }
    }

    /// `cell`, unless it is too near the shooter ([`receivers::far_from`]).
    fn usable(&self, cell: receivers::Interpolation) -> Option<receivers::Interpolation> {
        if self.crowded.get(cell.corners[0] as usize) == Some(&true) {
            return None;
        }
        let corners = cell.corners.map(|c| self.positions[c as usize]);
        receivers::far_from(corners, self.shooter).then_some(cell)
    }
}

/// A step's gather, phase 4, in two passes over the vertices: first every
/// receiving vertex `cells` does not offer (by `exact`, which returns a
/// vertex's `Δrad`, pairs and rays), then the others, each interpolated
/// from its coarse cell when [`receivers::accept`] allows and exact
/// otherwise; last, each check vertex of a cell accepted by the weak rule
/// is charged its error in `spent`. Writes `delta` (black for
/// non-receivers). Each vertex depends only on itself and the
/// first pass, so the bits do not depend on the thread count, nor on how
/// `work` cuts a step ([`parts`]): over whole polygons it runs all three,
/// over a piece of one polygon the pass its [`Stage`] names (the first
/// pass's values kept, in `coarse_delta`, and the charges made, once the
/// polygon's last piece of that pass is done). `None` once `cancel` is
/// set, with only scratch written.
fn gather_passes<E>(
    sums: Sums,
    mesh: &Mesh,
    cells: &Interpolating,
    cancel: &AtomicBool,
    exact: E,
    work: Work,
) -> Option<Gathered>
where
    E: Fn(usize, PolygonId, &mut Scratch) -> (Rgb, u64, u64) + Sync,
{
    let (receives, held) = (cells.receives, cells.held);
    let Work { vertices, stage } = work;
    let Sums {
        delta,
        first: coarse_delta,
        spent,
    } = sums;
    let start = vertices.start;
    let mut gathered = Gathered { pairs: 0, rays: 0 };
    if let Stage::All | Stage::Exact { .. } = stage {
        let (pairs, rays) = par_runs(
            mesh,
            &mut delta[vertices.clone()],
            start,
            |scratch, l, delta| {
                let j = mesh.vertex_polygon[l];
                if !receives[j.index()]
                    || cancel.load(Ordering::Relaxed)
                    || cells.cell(l, j).is_some()
                {
                    *delta = Rgb::BLACK;
                    return (0, 0);
                }
                let (d, pairs, rays) = exact(l, j, scratch);
                *delta = d;
                (pairs, rays)
            },
        );
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        gathered.add(Gathered { pairs, rays });
        if !cells.on {
            return Some(gathered);
        }
        // The first pass's values, which the second reads (over the whole
        // polygon, once its last piece is done).
        let keep = match &stage {
            Stage::All => Some(vertices.clone()),
            Stage::Exact { copy } => copy.clone(),
            Stage::Interpolated { .. } => None,
        };
        if let Some(r) = keep {
            coarse_delta[r.clone()].copy_from_slice(&delta[r]);
        }
        if let Stage::Exact { .. } = stage {
            return Some(gathered);
        }
    }
    if !cells.on {
        return Some(gathered);
    }
    let first = &*coarse_delta;
    let spent_now = &*spent;
    let (pairs2, rays2) = par_runs(
        mesh,
        &mut delta[vertices.clone()],
        start,
        |scratch, l, delta| {
            let j = mesh.vertex_polygon[l];
            let Some(cell) = cells.cell(l, j) else {
                return (0, 0);
            };
            if cancel.load(Ordering::Relaxed) {
                return (0, 0);
            }
            let corners = cell.corners.map(|c| first[c as usize]);
            let c = cell.check as usize;
            if receivers::accept(corners, first[c], cell.check_weights, held[c], spent_now[c])
                .is_some()
            {
                *delta =
                    receivers::interpolate(corners, cell.weights, first[c], cell.check_weights);
                return (0, 0);
            }
            let (d, pairs, rays) = exact(l, j, scratch);
            *delta = d;
            (pairs, rays)
        },
    );
    if cancel.load(Ordering::Relaxed) {
        return None;
    }
    gathered.add(Gathered {
        pairs: pairs2,
        rays: rays2,
    });
    // The check charges, once the second pass read them all.
    let charge = match stage {
        Stage::All => Some(vertices),
        Stage::Interpolated { charge } => charge,
        Stage::Exact { .. } => None,
    };
    if let Some(r) = charge {
        let first_l = r.start;
        let charge_one = |(k, s): (usize, &mut Rgb)| {
            let l = first_l + k;
            let j = mesh.vertex_polygon[l];
            if let Some(cell) = cells.checked_cell(l, j) {
                let corners = cell.corners.map(|c| first[c as usize]);
                if let Some(cost) =
                    receivers::accept(corners, first[l], cell.check_weights, held[l], *s)
                {
                    *s += cost;
                }
            }
        };
        // A chunk's few thousand vertices cost less than waking the
        // workers.
        if r.len() < PARALLEL_CHARGES {
            spent[r].iter_mut().enumerate().for_each(charge_one);
        } else {
            spent[r]
                .par_iter_mut()
                .enumerate()
                .with_min_len(256)
                .for_each(charge_one);
        }
    }
    Some(gathered)
}

/// Orders one receiver's shaft candidates `c` by culling group (of
/// `groups`) and records their runs with the group's bounds, for
/// [`Visibility::refine_candidates_in_runs`].
fn group_candidates(
    groups: &Clusters,
    c: &mut [u32],
    runs: &mut Vec<crate::visibility::CandidateRun>,
) {
    runs.clear();
    c.sort_unstable_by_key(|&p| (groups.of(PolygonId(p)), p));
    let mut start = 0;
    while start < c.len() {
        let g = groups.of(PolygonId(c[start]));
        let mut end = start + 1;
        while end < c.len() && groups.of(PolygonId(c[end])) == g {
            end += 1;
        }
        let (lo, hi) = groups.bounds(g);
        runs.push((start as u32..end as u32, (lo.as_dvec3(), hi.as_dvec3())));
        start = end;
    }
}

/// Runs `f` (scratch, vertex, its `Δrad`; returns pairs and rays) on
/// every vertex of `delta`, which holds the vertices from `start`, in
/// parallel, in runs of at most [`PAR_RUN`] vertices of one polygon: a
/// small facet's vertices stay with one worker, which shares their rays
/// ([`facets`]), and the threads finish a chunk of a few hundred vertices
/// ([`parts`]) within a few vertices' time of each other. Returns the
/// summed pairs and rays.
fn par_runs<F>(mesh: &Mesh, delta: &mut [Rgb], start: usize, f: F) -> (u64, u64)
where
    F: Fn(&mut Scratch, usize, &mut Rgb) -> (u64, u64) + Sync,
{
    let mut runs = Vec::with_capacity(delta.len() / PAR_RUN + 1);
    let (mut rest, mut l) = (delta, start);
    while !rest.is_empty() {
        let polygon_end = mesh.polygons[mesh.vertex_polygon[l].index()].vertices.end as usize;
        let n = (polygon_end - l).min(PAR_RUN).min(rest.len());
        let (run, tail) = std::mem::take(&mut rest).split_at_mut(n);
        runs.push((l, run));
        rest = tail;
        l += n;
    }
    runs.into_par_iter()
        // One scratch per worker, reused from run to run.
        .map_init(Scratch::default, |scratch: &mut Scratch, (first, run)| {
            let mut sum = (0, 0);
            for (k, d) in run.iter_mut().enumerate() {
                let (pairs, rays) = f(scratch, first + k, d);
                sum.0 += pairs;
                sum.1 += rays;
            }
            sum
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// Whether the segment from `from` to `x` is blocked, and the rays cast
/// to tell (0 or 1): `blockers` are the polygons in its thin shaft
/// (`None`: test the whole scene; empty: nothing can block), `ends` the
/// polygons it joins, which never block.
#[inline]
fn ray_blocked(
    visibility: &Visibility,
    blockers: Option<&[u32]>,
    from: glam::Vec3,
    x: glam::Vec3,
    ends: (PolygonId, PolygonId),
    last: &mut LastBlocker,
) -> (bool, u64) {
    match blockers {
        Some([]) => (false, 0),
        Some(b) if b.len() <= LINEAR_CANDIDATES => (
            visibility.occluded_among_ends_remembering(from, x, b, ends, last),
            1,
        ),
        _ => (visibility.occluded_remembering(from, x, ends, last), 1),
    }
}

/// The ambient term ([`Progressive::ambient`]) of a scene whose polygon
/// `j` (of `mesh`) has reflectance `reflectance[j]`, sky power weight
/// `power_weight[j]` ([`sky_power_weights`]) and mean unshot radiosity
/// `unshot_mean(j)`.
fn ambient_term(
    mesh: &Mesh,
    reflectance: &[Rgb],
    power_weight: &[f64],
    unshot_mean: impl Fn(usize) -> Rgb,
) -> Rgb {
    let (mut area, mut unshot, mut reflected) = (0.0, Rgb::BLACK, Rgb::BLACK);
    for (j, (rho, pm)) in reflectance.iter().zip(&mesh.polygons).enumerate() {
        // The sky is no part of the scene its light is spread over;
        // what it has not shot yet is the light's source, counted as
        // the power it would bring (see `sky_power_weights`).
        if pm.sky {
            unshot += unshot_mean(j) * pm.area * power_weight[j];
            continue;
        }
        area += pm.area;
        unshot += unshot_mean(j) * pm.area;
        reflected += *rho * pm.area;
    }
    if area <= 0.0 {
        return Rgb::BLACK;
    }
    let rho = reflected / area;
    // Every reflectance channel is below 1, so their mean is too.
    let r = Rgb::new(
        1.0 / (1.0 - rho.r),
        1.0 / (1.0 - rho.g),
        1.0 / (1.0 - rho.b),
    );
    r * (unshot / area)
}

/// What a solve of `scene` on `mesh` shows before its first step, per mesh
/// vertex in the scene's radiosity units: each vertex's emission plus its
/// reflectance times the ambient term of the unshot emission (the value of
/// [`Progressive::radiosity_with_ambient`] for a new solver), computed
/// without building a solver (no samples, clusters or visibility), so a
/// window can show a lit scene at once on a model whose solver takes a
/// while to set up.
pub fn first_look(scene: &Scene, mesh: &Mesh) -> Vec<Rgb> {
    let material = |p: &crate::scene::Polygon| &scene.materials[p.material.index()];
    let emission: Vec<Rgb> = scene
        .polygons
        .iter()
        .map(|p| material(p).emission())
        .collect();
    let reflectance: Vec<Rgb> = scene
        .polygons
        .iter()
        .map(|p| material(p).reflectance())
        .collect();
    if emission.len() != mesh.polygons.len() {
        return vec![Rgb::BLACK; mesh.vertex_count()];
    }
    let ambient = ambient_term(mesh, &reflectance, &sky_power_weights(mesh), |j| {
        emission[j]
    });
    mesh.vertex_polygon
        .iter()
        .map(|p| emission[p.index()] + reflectance[p.index()] * ambient)
        .collect()
}

/// Per polygon of `mesh`, the factor its unshot power counts with: 1 for
/// the scene's polygons; for the facets of a sky, the scene's area (every
/// non-sky polygon's) over the sky's, so that the whole sky counts as
/// `S · A_scene`.
///
/// A sky's own power, `S` times the area of an enclosure far outside the
/// scene, is mostly light that never reaches it, and it depends on the
/// enclosure's arbitrary radius. Counted whole it would make the first
/// bounce in the scene look negligible against the initial power, and the
/// threshold would stop the solve before any light was reflected. What a
/// sky can bring to the scene is at most `S · A_scene` (each polygon's form
/// factor to the sky is at most 1), which is also what an emitter of the
/// scene's size would hold: the threshold then means what it means for
/// any scene.
fn sky_power_weights(mesh: &Mesh) -> Vec<f64> {
    let (mut scene_area, mut sky_area) = (0.0, 0.0);
    for pm in &mesh.polygons {
        if pm.sky {
            sky_area += pm.area;
        } else {
            scene_area += pm.area;
        }
    }
    let sky_weight = if sky_area > 0.0 {
        scene_area / sky_area
    } else {
        1.0
    };
    mesh.polygons
        .iter()
        .map(|pm| if pm.sky { sky_weight } else { 1.0 })
        .collect()
}

#[cfg(test)]
mod crowded_tests;
#[cfg(test)]
mod emitter_order_tests;
#[cfg(test)]
mod far_shooter_tests;
#[cfg(test)]
mod overshoot_tests;
#[cfg(test)]
mod parts_tests;
#[cfg(test)]
mod resting_tests;
#[cfg(test)]
mod settle_tests;
#[cfg(test)]
mod sky_tests;
#[cfg(test)]
mod tests;
