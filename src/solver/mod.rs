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
//! **Overshooting** ([`Approximations::overshoot`], on by default; Feda and
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
//! its own grid of [`crate::solver::tuning::SKY_FACET_SAMPLES`] points (a
//! standard sky's weighted by its luminance in each direction,
//! [`formfactor::polygon_samples`]), and its unshot
//! power counts as the light it can bring to the scene, not its own (see
//! [`Progressive::unshot_power`]).
//!
//! **Clusters** ([`cluster`], on unless [`Approximations::clusters`] is
//! off): nearby small polygons form clusters, and a step shoots from the
//! *cluster* with the most unshot power, all its members at once, from
//! strata of their samples (a tessellated sphere's thousand triangles in
//! one step rather than a thousand). Emitters always shoot alone from
//! their own samples; any other polygon whose step carries less than
//! [`FULL_STRATA_SHARE`](crate::solver::tuning::FULL_STRATA_SHARE) of the initial power shoots through strata too,
//! fewer of them the weaker its light (see [`FULL_STRATA_SHARE`](crate::solver::tuning::FULL_STRATA_SHARE)).
//! Shadow-ray candidates are culled by the same groups in both modes, so
//! a tessellated object beside a thin shaft costs one box test.
//!
//! **Hierarchical receivers** ([`receivers`], with clusters, unless
//! [`Approximations::receiver_interpolation`] is off): a step of reflected
//! light evaluates large receiving grids at every fourth row and column
//! and at a check vertex per coarse cell, and interpolates the cell's
//! other vertices when the check shows the interpolation holds.
//!
//! **Shared facet rays** ([`facets`], with the same switch): a facet
//! under half an element across asks one shadow ray per shooter sample or
//! stratum, to its middle, for all its vertices, where no vertex is near
//! the sample's cell.
//!
//! **Sky probes** ([`accel::probes`], with the same switch): a receiving
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
//!
//! Drivers see a solve through [`Method`], built by [`build`] from the
//! options: progressive shooting is one method, the hemicube another
//! ([`methods`]).

pub mod accel;
mod ambient;
mod approximations;
pub mod carry;
pub mod checkpoint;
pub mod final_gather;
pub mod gauge;
pub mod kernel;
pub mod method;
pub mod methods;
mod setup;
pub mod step;
pub mod sun;
pub mod tuning;
mod unshot;

pub use method::{build, Method};
pub use methods::hemicube;

use crate::solver::tuning::{
    DEFAULT_SETTLE, DEFAULT_SHOOTER_SAMPLES, DEFAULT_THRESHOLD, SHAFT_MIN_VERTICES, TILE_VERTICES,
};
use accel::{cluster, facets, far_shooters, receivers, shared, subcells};
pub use ambient::first_look;
use ambient::{ambient_term, sky_power_weights};
pub use approximations::{Approximations, Heuristic};
pub use gauge::StepGauge;
use kernel::{cell_integrals, distribution, formfactor};
pub use step::StepPhase;
use step::Underway;

use crate::color::Rgb;
use crate::mesh::{Mesh, MeshRef};
use crate::scene::{PolygonId, Scene};
use crate::visibility::Visibility;
use cluster::{Cell, Clusters, Strata};
use facets::Facets;
use far_shooters::FarShooter;
use formfactor::{polygon_samples, SampleSet, ShooterSample};
use rayon::prelude::*;
use receivers::CoarseGrid;

use subcells::SubCells;
use unshot::{Shot, UnshotField};

/// Shared-ray keys per stratum node ([`facets::Memo`]): one per normal
/// bin a far term may cast from, and one for the node's representative.
const RAY_SLOTS: u32 = 7;

/// The shared-ray key slot of a ray from the node's representative.
const REPRESENTATIVE_SLOT: u32 = RAY_SLOTS - 1;

/// Not a shared-ray slot: a ray the vertex asks alone, by the full
/// search (from a point of a near cell other than its sample).
const OWN_RAY_SLOT: u32 = u32::MAX;

/// Polygons per parallel run of [`Progressive::per_polygon`]: enough that
/// a run outweighs handing it to a thread (a polygon of a real export has
/// a handful of vertices).
const POLYGON_RUN: usize = 512;

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
    /// [`OVERSHOOT_SHARE`](crate::solver::tuning::OVERSHOOT_SHARE) times the ambient term, clamped at 0 per
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
    #[value(
        name = "hemicube",
        help = "Cohen and Greenberg's hemicube: each shooter cell projects the scene's elements \
                onto a hemicube of --hemicube-res pixels with a z-buffer. No shadow rays; aliases \
                where elements are small seen from the shooter. Shoots every polygon alone; a sky \
                facet still shoots by Wallace's rays"
    )]
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
    /// darker than [`SETTLE_FLOOR`](crate::solver::tuning::SETTLE_FLOOR) of the mean count as that bright),
    /// from the cluster holding the most such light. A pocket (the gap
    /// under a lamp, a sphere's underside over the floor) holds little
    /// power but trades it back and forth; the threshold alone leaves it
    /// dark. 0 stops at the threshold alone.
    pub settle: f64,
    /// Stop after this many steps at most.
    pub max_steps: Option<u64>,
    /// Which heuristics the solve uses ([`Approximations`]: all by
    /// default; [`Approximations::EXACT`] is the brute-force twin).
    pub approximations: Approximations,
    /// Where unshot radiosity is kept.
    pub unshot: UnshotScheme,
    /// Pixels across a hemicube's top face, for
    /// [`FormFactorMethod::Hemicube`] (ignored by the other methods).
    pub hemicube_res: hemicube::HemicubeRes,
    /// Deliver a step in parts of about this much solver time each
    /// ([`step::parts`]): a window's picture then moves while a long step runs.
    /// The finished step is bit-identical to one in a piece; `None` (the
    /// default) runs every step in one piece.
    pub part_budget: Option<std::time::Duration>,
    /// When the light left unshot is carried by particles instead of
    /// shooting steps ([`step::tail`]).
    pub tail: TailOption,
    /// Particles per element vertex the tail traces over four steps, a
    /// quarter each (a tail that begins well below its fraction takes
    /// fewer steps), `> 0` ([`tuning::TAIL_PARTICLES_PER_VERTEX`] by
    /// default).
    pub tail_particles: f64,
}

/// When a solve hands the light left unshot to the particle tail
/// ([`step::tail`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TailOption {
    /// Never: shooting steps to the end (the brute-force twin).
    Off,
    /// From [`tuning::TAIL_AUTO_FROM`] of the emitted power on meshes of
    /// at least [`tuning::TAIL_AUTO_VERTICES`] element vertices, where
    /// the last light spread thin costs a shooting solve most of its
    /// steps; never on smaller ones, whose shooting tails are short.
    Auto,
    /// Once the unshot power is at most this fraction of the emitted, in
    /// `[0, 1]`.
    From(f64),
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
            approximations: Approximations::DEFAULT,
            unshot: UnshotScheme::Vertex,
            hemicube_res: hemicube::HemicubeRes::default(),
            part_budget: None,
            tail: TailOption::Auto,
            tail_particles: tuning::TAIL_PARTICLES_PER_VERTEX,
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
    /// negative light ([`Approximations::overshoot`]).
    pub shot_power: f64,
    /// Unshot power left after the step, as a fraction of the initial
    /// (for a part of a step not finished, what the last finished step
    /// left).
    pub unshot_fraction: f64,
    /// Shadow rays cast in this step.
    pub rays: u64,
    /// Sample–vertex pairs whose visibility mattered (both cosines
    /// positive); with shaft culling, those in clear shafts cast no ray.
    /// A shooter whose probes found it wholly hidden from a vertex
    /// ([`accel::probes`]) counts no pair there.
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
    /// Particles traced: 0 for a shooting step, the count of a tail step
    /// ([`step::tail`]), which shoots every polygon's share at once
    /// (`shooter` is then the polygon that held the most of it, `rays`
    /// the particles' rays).
    pub particles: u64,
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
    /// A step made a value that is not finite (a bug when it happens).
    /// Found before anything was applied (phases [`StepPhase::Read`] and
    /// [`StepPhase::Gather`]), the step is dropped and the solution is
    /// that of the step before; found after ([`StepPhase::Apply`]), the
    /// solution holds it. The solver takes no further step
    /// ([`Progressive::fault`]).
    #[error("step {step} (shooter polygon {}) made a non-finite value while {phase}", shooter.0)]
    NotFinite {
        /// The step, from 1.
        step: u64,
        /// Its shooter (a cluster step's member holding the most light).
        shooter: PolygonId,
        /// The phase that made the value.
        phase: StepPhase,
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
    /// A state to restore holds a non-finite value, a negative radiosity
    /// or charge, or a value beyond [`checkpoint::MAX_STATE_VALUE`].
    #[error(
        "the saved state holds a negative, non-finite or impossibly large value \
         (above {:e})",
        checkpoint::MAX_STATE_VALUE
    )]
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
/// [`Approximations::overshoot`]); one radiosity per mesh vertex
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
    /// Per polygon: the sub-cells of its shooter cells much larger than
    /// its elements ([`subcells`]).
    subcells: Vec<SubCells>,
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
    /// Scratch: what each sub-cell of the shooter's split cells sends
    /// ([`subcells`]), in the order of its [`SubCells::cells`]; empty in
    /// the per-polygon scheme, whose sub-cells would all send the same.
    subcell_readings: Vec<Rgb>,
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
    /// Per vertex: the vertex whose `Δrad` it takes, or
    /// [`shared::ALONE`] ([`shared`]); empty when receivers are not
    /// shared.
    leaders: Vec<u32>,
    /// Per polygon: a sky facet's probes and their regions
    /// ([`accel::probes::SkyProbes`]), `None` for every other polygon and
    /// when probing is off.
    probes: Vec<Option<accel::probes::SkyProbes>>,
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
    /// of [`SHOOTER_GROUP`](crate::solver::tuning::SHOOTER_GROUP) samples for tile shafts.
    group_points: Vec<glam::Vec3>,
    /// The clusters that shoot together (every polygon alone without
    /// clustering).
    clusters: Clusters,
    /// True when the solve shoots by clusters and strata
    /// ([`Approximations::clusters`] with a grid of samples).
    clustered: bool,
    /// Scratch for a cluster step: the shooting cells, their samples and
    /// strata.
    cells: Vec<Cell>,
    cell_samples: Vec<ShooterSample>,
    /// Scratch for a cluster step, per cell: where its sub-cells' values
    /// start in `cell_subcell_values` when it is split, else
    /// [`subcells::NONE`].
    cell_subcells: Vec<u32>,
    /// Scratch: what each sub-cell of a cluster step's split cells sends.
    cell_subcell_values: Vec<Rgb>,
    /// The leaves' values of the sub-cells in `cell_subcell_values`,
    /// [`subcells::LEAVES`] per sub-cell, apart from the sub-cells' so that
    /// those every receiver takes lie together in memory.
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
    /// The failed step, once one made a non-finite value
    /// ([`SolverError::NotFinite`]); no step is taken after it.
    fault: Option<SolverError>,
    /// The unshot fraction after the last finished step (1 before the
    /// first), which a part of a step not finished reports.
    last_fraction: f64,
    /// Counts the changes to the radiosity and unshot values: bumped
    /// wherever they change ([`Progressive::apply_chunk`],
    /// [`Progressive::restore`]), so the scans kept in `scans` know
    /// whether they still hold.
    state: u64,
    /// The scans a step asks for several times over one state.
    scans: std::sync::Mutex<Scans>,
    /// The scene's sun, whose direct light the solve starts from
    /// ([`sun`]); `None` without one.
    sun: Option<sun::SunShot>,
    /// The particle tail's settings and tables ([`step::tail`]).
    tail: step::tail::Tail,
    /// The sky gathered at once, and its step under way.
    sky: step::sky::SkyGather,
    /// How far the step under way has got ([`gauge`]): the sky's and the
    /// particle tail's steps fill it.
    gauge: std::sync::Arc<StepGauge>,
}

/// The scans over every vertex that choosing a step, checking for
/// convergence and reporting each ask for (the unshot power summed; what
/// points expect to receive), kept for the state they were taken of. A
/// step asked for the unshot power five times and the expectation twice,
/// each a pass over every vertex; on a 262,000-vertex export they were a
/// tenth of the solve.
#[derive(Clone, Copy, Debug, Default)]
struct Scans {
    /// The [`Progressive::state`] they were taken of.
    state: u64,
    /// [`Progressive::unshot_sums`], when taken.
    sums: Option<(f64, f64)>,
    /// [`Progressive::expectation`], when taken.
    expectation: Option<Expectation>,
}

impl<'a> Progressive<'a> {
    /// Starts a solve: every vertex at `b = e`, every polygon's unshot
    /// radiosity at `Δb = e`. `mesh` and `visibility` must be built from
    /// `scene`. It shoots by rays (Wallace's or the centre estimate);
    /// with [`FormFactorMethod::Hemicube`] its sample set is the
    /// hemicube's but it still shoots by rays: [`build`] makes the
    /// hemicube method ([`hemicube::HemicubeMethod`]), which steps it.
    pub fn new(
        scene: &Scene,
        mesh: impl Into<MeshRef<'a>>,
        visibility: &'a Visibility,
        options: SolverOptions,
    ) -> Self {
        let mesh_ref = mesh.into();
        let mesh: &Mesh = &mesh_ref;
        let set = setup::sample_set(&options);
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
        let samples: Vec<Vec<ShooterSample>> = mesh
            .polygons
            .iter()
            .zip(&sets)
            .enumerate()
            .map(|(i, (pm, &set))| polygon_samples(scene, i, pm, mesh, set))
            .collect();
        let radiosity = mesh
            .vertex_polygon
            .iter()
            .map(|p| emission[p.index()])
            .collect();
        let covered = crate::mesh::covered::covered_vertices(scene, mesh);
        let subcells =
            SubCells::build_all(scene, mesh, &samples, options.approximations.near_field);
        let unshot = UnshotField::new(
            options.unshot,
            mesh,
            &emission,
            &samples,
            &sets,
            &subcells,
            covered,
        );
        let power_weight = sky_power_weights(mesh);
        let culling_groups = Clusters::build(scene, mesh, &emission);
        let clustered = matches!(
            (
                options.approximations.clusters,
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
        let (tiles, tile_of) = setup::tiles(mesh);
        // The receiver heuristics act only in a solve that clusters; the
        // crowded-cell guard only where receivers are interpolated.
        let approx = &options.approximations;
        let coarse: Vec<Option<CoarseGrid>> = mesh
            .polygons
            .iter()
            .map(|pm| CoarseGrid::detect(mesh, pm))
            .collect();
        let guarded = clustered && approx.receiver_interpolation && approx.crowded_cells;
        let crowded = setup::crowded(mesh, visibility, &coarse, guarded);
        let sky_probes = setup::sky_probes(mesh, &samples, clustered && approx.sky_probes);
        let far_shooters = setup::far_shooters(mesh, &samples, clustered && approx.far_shooters);
        let mut solver = Progressive {
            mesh: mesh_ref.clone(),
            visibility,
            options,
            emission,
            reflectance,
            power_weight,
            samples,
            subcells,
            directional: distribution::Directional::for_scene(scene),
            radiosity,
            vertex_area: mesh.vertex_areas(),
            unshot,
            shot: Vec::new(),
            subcell_readings: Vec::new(),
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
            cell_subcells: Vec::new(),
            cell_subcell_values: Vec::new(),
            cell_leaf_values: Vec::new(),
            strata: Strata::default(),
            coarse,
            crowded,
            coarse_delta: vec![Rgb::BLACK; mesh.vertex_count()],
            facets: Facets::new(mesh, clustered && approx.facet_rays),
            probes: sky_probes,
            leaders: shared::leaders(
                scene,
                mesh,
                visibility,
                clustered && approx.shared_receivers,
            ),
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
            fault: None,
            last_fraction: 1.0,
            state: 0,
            scans: std::sync::Mutex::new(Scans::default()),
            sun: sun::SunShot::for_scene(scene),
            tail: step::tail::Tail::new(
                options.tail,
                options.tail_particles,
                options.approximations.tail_gather,
                scene,
                mesh,
            ),
            // A daylight sky's luminance varies within a facet (its
            // samples are weighted by it), which the dome's per-facet
            // light does not hold: such a sky shoots facet by facet.
            sky: step::sky::SkyGather::new(
                mesh,
                clustered && approx.sky_at_once && scene.sky_pattern.is_none(),
                clustered && approx.sky_probes,
                approx.hat_centroids,
            ),
            gauge: std::sync::Arc::default(),
        };
        solver.receive_sun();
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
        let means = self.per_polygon(|j| self.unshot.mean(&self.mesh, j));
        ambient_term(&self.mesh, &self.reflectance, &self.power_weight, |j| {
            means[j]
        })
    }

    /// `f` of every polygon, in polygon order, computed in parallel runs of
    /// [`POLYGON_RUN`]. The scans a step makes between gathers (choosing
    /// the shooter, the unshot power, the expectation, settling) each
    /// visit every vertex; run on one core they were a fifth of a step's
    /// wall time on a 262,000-vertex export. Callers sum the results in
    /// polygon order, so the bits do not depend on the thread count.
    pub(in crate::solver) fn per_polygon<T: Send>(
        &self,
        f: impl Fn(usize) -> T + Sync + Send,
    ) -> Vec<T> {
        (0..self.mesh.polygons.len())
            .into_par_iter()
            .with_min_len(POLYGON_RUN)
            .map(f)
            .collect()
    }

    /// The radiosity to show: per vertex `b + ρ · ambient` (see
    /// [`Progressive::ambient`]), at least 0 per channel, written into
    /// `out` (resized to the vertex count). The ambient term is negative
    /// while overshooting has sent more light ahead than is left to shoot
    /// ([`Approximations::overshoot`]). The solution itself is not changed.
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
    /// ([`Approximations::overshoot`]) alike. A sky's facets count together
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
        if let Some(sums) = self.kept(|s| s.sums) {
            return sums;
        }
        let sums = self
            .per_polygon(|j| {
                (
                    self.polygon_power(j, Shot::PLAIN),
                    self.polygon_power(j, Shot::NEGATIVE),
                )
            })
            .into_iter()
            .fold((0.0, 0.0), |(magnitude, net), (p, n)| {
                (magnitude + (p + n), net + (p - n))
            });
        self.keep(|s| s.sums = Some(sums));
        sums
    }

    /// A scan kept for the current state ([`Scans`]), if `get` finds it.
    fn kept<T>(&self, get: impl Fn(&Scans) -> Option<T>) -> Option<T> {
        let scans = self.scans.lock().unwrap_or_else(|e| e.into_inner());
        (scans.state == self.state).then(|| get(&scans)).flatten()
    }

    /// Keeps a scan taken of the current state, forgetting those of an
    /// earlier one. Not held while scanning: a scan may ask for another.
    fn keep(&self, set: impl Fn(&mut Scans)) {
        let mut scans = self.scans.lock().unwrap_or_else(|e| e.into_inner());
        if scans.state != self.state {
            *scans = Scans {
                state: self.state,
                ..Scans::default()
            };
        }
        set(&mut scans);
    }

    /// Marks the radiosity or unshot values changed: every kept scan is
    /// stale.
    fn changed(&mut self) {
        self.state = self.state.wrapping_add(1);
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

    /// Particles the tail has traced in this solve ([`step::tail`]; not
    /// kept in a checkpoint).
    pub fn particles(&self) -> u64 {
        self.tail.particles
    }

    /// The unshot fraction at or below which the particle tail takes
    /// over, as [`SolverOptions::tail`] resolved on this mesh; `None`
    /// when it is off.
    pub fn tail_from(&self) -> Option<f64> {
        self.tail.from()
    }

    /// Why the solve should stop now, or `None` to go on (always while a
    /// step is under way: [`Progressive::in_step`]).
    pub fn stop_reason(&self) -> Option<StopReason> {
        if self.in_step() {
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

    /// The clusters the solve shoots from (each polygon alone without
    /// clustering).
    pub fn clusters(&self) -> &Clusters {
        &self.clusters
    }

    /// Checks the invariants; returns the first broken one.
    pub fn validate(&self) -> Result<(), SolverError> {
        if let Some(fault) = &self.fault {
            return Err(fault.clone());
        }
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
            self.underway.as_ref().is_none_or(|u| !u.spent)
                && self.tail.underway.is_none()
                && self.sky.underway.is_none(),
            "a solver state taken in the middle of a step"
        );
        checkpoint::SolverState {
            radiosity: self.radiosity.clone(),
            unshot: self.unshot().to_vec(),
            steps: self.steps,
            rays: self.rays,
            charges: self.charges().to_vec(),
            tail_from: self.tail.from(),
            tail_began: self.tail.began_values(),
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
    /// array sizes differ, a value is not finite, a radiosity or charge
    /// is negative, or the tail fraction is outside `[0, 1]`. The saved
    /// tail fraction is taken only when this solve's tail is on.
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
        let limit = checkpoint::MAX_STATE_VALUE;
        let bad = |c: &Rgb| !c.is_finite() || c.min_channel() < 0.0 || c.max_channel() > limit;
        let bad_unshot =
            |c: &Rgb| !c.is_finite() || c.max_channel() > limit || c.min_channel() < -limit;
        if state.radiosity.iter().chain(&state.charges).any(bad)
            || state.unshot.iter().any(bad_unshot)
            || state.tail_from.is_some_and(|f| !(0.0..=1.0).contains(&f))
            || !(state.tail_began.is_empty() || state.tail_began.len() == 3 * self.radiosity.len())
            || state.tail_began.iter().any(bad_unshot)
        {
            return Err(SolverError::BadStateValue);
        }
        self.tail.set_began(state.tail_began);
        if let (Some(from), Some(_)) = (state.tail_from, self.tail.from) {
            self.tail.from = Some(from);
        }
        self.spent = if state.charges.is_empty() {
            vec![Rgb::BLACK; self.radiosity.len()]
        } else {
            state.charges
        };
        self.radiosity = state.radiosity;
        self.unshot.set_values(state.unshot);
        self.changed();
        self.underway = None;
        self.tail.underway = None;
        self.sky.underway = None;
        self.fault = None;
        self.last_fraction = self.unshot_fraction();
        self.steps = state.steps;
        self.rays = state.rays;
        Ok(())
    }
}

#[cfg(test)]
mod tests;
