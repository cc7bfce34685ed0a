//! The solver's heuristics, one switch each, and the exact twin.
//!
//! Every acceleration and every rule of thumb the progressive solver uses
//! is one field of [`Approximations`]. All are on by default
//! ([`Approximations::DEFAULT`]); [`Approximations::EXACT`] is the
//! brute-force twin that each is measured against: every polygon shoots
//! alone from all its cells, in plain power order, exactly the light it
//! holds, to every receiving vertex with its own shadow rays, each ray
//! tested against the whole scene. Turning one switch off leaves the
//! others as they are, so each heuristic can be checked against its twin
//! alone (`tests/switches.rs`), and `radiosity --without NAME` does the
//! same from the command line.
//!
//! Some switches act only inside another: the receiver heuristics
//! (interpolation, weak strata, crowded cells, facet rays, sky probes, far
//! shooters, shared receivers) only in a solve that clusters, and strata only with clusters.
//! Clusters need Wallace's estimate on a grid of shooter cells
//! ([`super::ShooterSamples::AtMost`]).

/// One named switch per heuristic of the solver (`true`: in use). See the
/// module documentation for the exact twin.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Approximations {
    /// Emitters that have not shot their own light go before any
    /// reflector ([`super::tuning::PENDING_EMISSION`]). Off: plain power
    /// order, the original algorithm.
    pub emitters_first: bool,
    /// Overshooting (Feda and Purgathofer 1992): a step also sends out the
    /// light each point of its shooters is expected to receive later,
    /// leaving their unshot radiosity negative until it arrives; what the
    /// shrinking expectation no longer covers is shot as negative light
    /// ([`super::tuning::OVERSHOOT_SHARE`]). Fewer steps to the same
    /// residual. Off: unshot radiosity never goes below zero.
    pub overshoot: bool,
    /// Settling: past the threshold, go on shooting while some point still
    /// holds more than [`super::SolverOptions::settle`] of its radiosity
    /// unshot. Off: stop at the threshold alone.
    pub settling: bool,
    /// The exact point-to-cell form factor for receivers near a shooter
    /// cell ([`super::tuning::EXACT_RATIO`],
    /// [`super::tuning::NEAR_FIELD_RATIO`]). Off: the plain disc sum
    /// however near (wrong near a cell: the original point-sample
    /// estimate). The exact twin keeps it on.
    pub near_field: bool,
    /// Shadow rays tested only against the polygons in the shaft between
    /// shooter and receiver. The same result bits either way; off tests
    /// every ray against the whole scene's BVH.
    pub shaft_culling: bool,
    /// Nearby small polygons (a tessellated sphere, a chair) shoot their
    /// unshot power together, from strata of their cells
    /// ([`super::tuning::CLUSTER_EXTENT`]). Off: every polygon shoots
    /// alone.
    pub clusters: bool,
    /// A step whose light is weak shoots from fewer, coarser strata
    /// ([`super::tuning::FULL_STRATA_SHARE`], [`super::tuning::MIN_STRATA`]),
    /// and a weak polygon shoots through strata as a cluster of one. Off:
    /// every step shoots from as many cells as a full one.
    pub strata: bool,
    /// A step of reflected light evaluates large receiving grids at their
    /// coarse vertices and a check vertex per cell, and interpolates the
    /// rest where the check holds ([`super::accel::receivers`]). Off: every
    /// receiving vertex is evaluated.
    pub receiver_interpolation: bool,
    /// A near stratum whose light is weak at a vertex is taken as one term
    /// ([`super::tuning::WEAK_STRATUM_SHARE`]). Off: every near stratum is
    /// descended into.
    pub weak_strata: bool,
    /// A receiving cell that another polygon reaches close in front of is
    /// never interpolated ([`super::tuning::CROWD_RATIO`]). A guard of
    /// receiver interpolation: off, crowded cells are interpolated like
    /// any other (only to measure what the guard buys).
    pub crowded_cells: bool,
    /// A facet under half an element across asks one shadow ray per
    /// shooter sample for all its vertices ([`super::accel::facets`]).
    /// Off: each vertex asks its own.
    pub facet_rays: bool,
    /// A receiving vertex asks a few of a sky facet's directions first,
    /// the rest only when they disagree ([`super::accel::probes`]). Off:
    /// every direction.
    pub sky_probes: bool,
    /// A vertex far from a lamp shooting alone asks a few of its samples
    /// first, the rest only when they disagree
    /// ([`super::accel::far_shooters`]). Off: every sample.
    pub far_shooters: bool,
    /// Vertices of one surface at one point (a triangulated wall's, a
    /// smooth sphere's facets') receive as one, the lowest-numbered
    /// evaluated and the others taking its `Δrad`
    /// ([`super::accel::shared`]). Off: each is evaluated alone.
    pub shared_receivers: bool,
    /// A sky that reflects nothing is shot in one step, every receiving
    /// vertex gathering it over its own hemisphere of directions
    /// ([`super::accel::sky_dome`]). Acts only in a solve that clusters,
    /// and not on a daylight sky (its luminance varies within a facet).
    /// Off: one step per sky facet, from its own directions.
    pub sky_at_once: bool,
    /// In the sky step ([`Approximations::sky_at_once`]), a vertex asks
    /// its hemisphere from the centroid of the elements around it (its
    /// hat, [`super::accel::hat`]), so that its value is close to their
    /// mean rather than the light at its own point: at a surface's edge, a
    /// third of an element in. Off: from the vertex's evaluation point.
    pub hat_centroids: bool,
    /// The particle tail's last step ends with a final gather: every
    /// receiving vertex gathers one bounce of the tail's whole field over
    /// its hemisphere, which replaces the particles' deposits on it
    /// ([`super::step::tail_gather`]). Off: the particles' deposits stand.
    pub tail_gather: bool,
}

/// The name of one switch of [`Approximations`], as the command line
/// spells it (`--without clusters,overshoot`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Heuristic {
    /// [`Approximations::emitters_first`].
    #[value(help = "lamps shoot their own light before any reflector")]
    EmittersFirst,
    /// [`Approximations::overshoot`].
    #[value(
        help = "a step also sends the light its shooter will receive later (Feda and Purgathofer)"
    )]
    Overshoot,
    /// [`Approximations::settling`].
    #[value(help = "past the threshold, shoot on until every point has sent most of its light")]
    Settling,
    /// [`Approximations::near_field`].
    #[value(help = "the exact point-to-cell form factor for receivers near a shooter cell")]
    NearField,
    /// [`Approximations::shaft_culling`].
    #[value(
        help = "shadow rays test only the polygons between shooter and receiver (same result)"
    )]
    ShaftCulling,
    /// [`Approximations::clusters`].
    #[value(help = "nearby small polygons shoot their light together")]
    Clusters,
    /// [`Approximations::strata`].
    #[value(help = "a weak step shoots from fewer, coarser cells")]
    Strata,
    /// [`Approximations::receiver_interpolation`].
    #[value(
        help = "large receiving grids are evaluated at coarse vertices and interpolated where a check holds"
    )]
    ReceiverInterpolation,
    /// [`Approximations::weak_strata`].
    #[value(help = "a near stratum whose light is weak at a vertex is taken as one term")]
    WeakStrata,
    /// [`Approximations::crowded_cells`].
    #[value(help = "a receiving cell with another polygon close in front is never interpolated")]
    CrowdedCells,
    /// [`Approximations::facet_rays`].
    #[value(
        help = "a facet under half an element across asks one shadow ray per sample for all its vertices"
    )]
    FacetRays,
    /// [`Approximations::sky_probes`].
    #[value(
        help = "a vertex asks a few of a sky facet's directions first, the rest only when they disagree"
    )]
    SkyProbes,
    /// [`Approximations::far_shooters`].
    #[value(
        help = "a vertex far from a lamp asks a few of its samples first, the rest only when they disagree"
    )]
    FarShooters,
    /// [`Approximations::shared_receivers`].
    #[value(help = "vertices of one surface at one point receive as one")]
    SharedReceivers,
    /// [`Approximations::sky_at_once`].
    #[value(
        help = "the sky is shot in one step, each vertex asking its own hemisphere of directions"
    )]
    SkyAtOnce,
    /// [`Approximations::hat_centroids`].
    #[value(help = "under the sky a vertex asks from the centroid of the elements around it")]
    HatCentroids,
    /// [`Approximations::tail_gather`].
    #[value(
        help = "the particle tail ends with each vertex gathering one bounce of its light, not the particles' deposits"
    )]
    TailGather,
}

impl Heuristic {
    /// Every switch, in the order of [`Approximations`]' fields.
    pub const ALL: [Heuristic; 17] = [
        Heuristic::EmittersFirst,
        Heuristic::Overshoot,
        Heuristic::Settling,
        Heuristic::NearField,
        Heuristic::ShaftCulling,
        Heuristic::Clusters,
        Heuristic::Strata,
        Heuristic::ReceiverInterpolation,
        Heuristic::WeakStrata,
        Heuristic::CrowdedCells,
        Heuristic::FacetRays,
        Heuristic::SkyProbes,
        Heuristic::FarShooters,
        Heuristic::SharedReceivers,
        Heuristic::SkyAtOnce,
        Heuristic::HatCentroids,
        Heuristic::TailGather,
    ];

    /// The switches `--exact-receivers` turns off: every receiving vertex
    /// evaluated with its own rays, in every step.
    pub const RECEIVERS: [Heuristic; 7] = [
        Heuristic::ReceiverInterpolation,
        Heuristic::WeakStrata,
        Heuristic::CrowdedCells,
        Heuristic::FacetRays,
        Heuristic::SkyProbes,
        Heuristic::FarShooters,
        Heuristic::SharedReceivers,
    ];
}

impl Approximations {
    /// Every heuristic in use: what a solve runs with unless told otherwise.
    pub const DEFAULT: Approximations = Approximations {
        emitters_first: true,
        overshoot: true,
        settling: true,
        near_field: true,
        shaft_culling: true,
        clusters: true,
        strata: true,
        receiver_interpolation: true,
        weak_strata: true,
        crowded_cells: true,
        facet_rays: true,
        sky_probes: true,
        far_shooters: true,
        shared_receivers: true,
        sky_at_once: true,
        hat_centroids: true,
        tail_gather: true,
    };

    /// The brute-force twin: no heuristic that trades accuracy or a
    /// different order of shooting for speed. The near field stays (it is
    /// the exact form factor near a cell, which the plain disc sum only
    /// approximates) and so does settling (it only goes on where light is
    /// left). Shaft culling is off: the same bits, every ray tested against
    /// the whole scene.
    pub const EXACT: Approximations = Approximations {
        emitters_first: false,
        overshoot: false,
        settling: true,
        near_field: true,
        shaft_culling: false,
        clusters: false,
        strata: false,
        receiver_interpolation: false,
        weak_strata: false,
        crowded_cells: false,
        facet_rays: false,
        sky_probes: false,
        far_shooters: false,
        shared_receivers: false,
        sky_at_once: false,
        hat_centroids: false,
        tail_gather: false,
    };

    /// Whether switch `h` is on.
    pub fn get(&self, h: Heuristic) -> bool {
        // One table of fields serves both ways: read through a copy.
        let mut copy = *self;
        *copy.field_mut(h)
    }

    /// This value with switch `h` set to `on`, the others as they are.
    pub fn with(mut self, h: Heuristic, on: bool) -> Approximations {
        *self.field_mut(h) = on;
        self
    }

    /// This value with every switch of `group` off.
    pub fn without(self, group: &[Heuristic]) -> Approximations {
        group.iter().fold(self, |a, &h| a.with(h, false))
    }

    /// The switches as bits, in the order of [`Heuristic::ALL`] (bit 0
    /// first): what a checkpoint's fingerprint hashes.
    pub fn bits(&self) -> u64 {
        Heuristic::ALL
            .iter()
            .enumerate()
            .fold(0, |b, (i, &h)| b | (u64::from(self.get(h)) << i))
    }

    fn field_mut(&mut self, h: Heuristic) -> &mut bool {
        match h {
            Heuristic::EmittersFirst => &mut self.emitters_first,
            Heuristic::Overshoot => &mut self.overshoot,
            Heuristic::Settling => &mut self.settling,
            Heuristic::NearField => &mut self.near_field,
            Heuristic::ShaftCulling => &mut self.shaft_culling,
            Heuristic::Clusters => &mut self.clusters,
            Heuristic::Strata => &mut self.strata,
            Heuristic::ReceiverInterpolation => &mut self.receiver_interpolation,
            Heuristic::WeakStrata => &mut self.weak_strata,
            Heuristic::CrowdedCells => &mut self.crowded_cells,
            Heuristic::FacetRays => &mut self.facet_rays,
            Heuristic::SkyProbes => &mut self.sky_probes,
            Heuristic::FarShooters => &mut self.far_shooters,
            Heuristic::SharedReceivers => &mut self.shared_receivers,
            Heuristic::SkyAtOnce => &mut self.sky_at_once,
            Heuristic::HatCentroids => &mut self.hat_centroids,
            Heuristic::TailGather => &mut self.tail_gather,
        }
    }
}

impl Default for Approximations {
    fn default() -> Self {
        Approximations::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_switch_is_its_own_field() {
        for (i, &h) in Heuristic::ALL.iter().enumerate() {
            let off = Approximations::DEFAULT.with(h, false);
            assert!(!off.get(h));
            assert_eq!(
                off.bits(),
                Approximations::DEFAULT.bits() & !(1 << i),
                "{h:?}"
            );
        }
        assert_eq!(
            Approximations::DEFAULT.bits(),
            (1 << Heuristic::ALL.len()) - 1
        );
    }

    #[test]
    fn the_exact_twin_keeps_only_what_is_exact() {
        let on: Vec<Heuristic> = Heuristic::ALL
            .into_iter()
            .filter(|&h| Approximations::EXACT.get(h))
            .collect();
        assert_eq!(on, [Heuristic::Settling, Heuristic::NearField]);
    }
}
