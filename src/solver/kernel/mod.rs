//! The maths of one transfer: the form factor from a shooter's samples to
//! a receiving point, the light a shooter cell holds, and the form factor
//! of a luminaire's shot.
//!
//! - [`formfactor`]: shooter samples and the form factor from them to a
//!   point;
//! - `cell_integrals`: the light a shooter cell holds, as weights on its
//!   polygon's vertices;
//! - [`distribution`]: emission weighted by a luminaire's distribution.

pub(crate) mod cell_integrals;
pub mod distribution;
pub mod formfactor;
