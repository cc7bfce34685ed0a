//! The solver methods behind [`super::Method`], one module each:
//!
//! - [`progressive`]: progressive shooting ([`super::Progressive`],
//!   whose state and phases live in [`super`] and [`super::step`]), with
//!   Wallace's ray-traced form factors or the centre estimate;
//! - [`hemicube`]: the hemicube, which takes progressive shooting's
//!   choice of shooter and its application of the step and reads and
//!   gathers by rendering.
//!
//! A new method is a module here implementing [`super::Method`] and a
//! case of [`super::build`]; the conformance suite (`tests/conformance.rs`)
//! checks it with one more row.

pub mod hemicube;
pub mod progressive;
