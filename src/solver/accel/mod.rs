//! The acceleration structures and heuristics of a shooting step: what
//! lets a step cast fewer shadow rays or sum fewer terms than one per
//! shooter sample and receiving vertex, each with a switch that turns it
//! off ([`super::SolverOptions`]).
//!
//! - [`cluster`]: clusters of polygons that shoot together, and the
//!   strata a cluster shoots from;
//! - [`receivers`]: hierarchical receivers, interpolated between coarse
//!   vertices where a check shows the interpolation holds;
//! - [`facets`]: small receiving facets sharing their shadow rays;
//! - [`hat`]: the elements around a vertex, and their centroid, where
//!   the sky step asks from;
//! - [`probes`]: a sky facet's directions probed first;
//! - [`far_shooters`]: a far shooter's samples probed first;
//! - [`subcells`]: shooter cells much larger than their elements, shot as
//!   their sub-cells;
//! - [`shared`]: vertices of one surface at one point receiving as one;
//! - [`sky_dome`]: the whole sky gathered at once over each vertex's
//!   hemisphere of directions.

pub mod cluster;
pub mod facets;
pub mod far_shooters;
pub mod hat;
pub mod probes;
pub mod receivers;
pub mod shared;
pub mod sky_dome;
pub mod subcells;
