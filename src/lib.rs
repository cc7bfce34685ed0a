//! A progressive-refinement radiosity renderer with ray-traced form factors.
#![warn(missing_docs)]

pub mod batch;
pub mod budget;
pub mod camera;
pub mod cancel;
pub mod cli;
pub mod color;
pub mod config;
pub mod drive;
pub mod info;
pub mod mesh;
pub mod output;
pub mod prepare;
pub mod render;
pub mod scene;
pub mod session;
pub mod solver;
pub mod viewer;
pub mod visibility;

#[cfg(test)]
mod testutil;
