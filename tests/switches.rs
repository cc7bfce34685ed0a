//! Each approximation switch of [`SolverOptions`] against its twin: a
//! solve with every switch at its default, and the same solve with one
//! switch turned off, must give the same radiosity bits (for a switch
//! that changes no result) or stay within a relative L1 difference of
//! the picture's radiosity. A switch is a row of [`switches`]; a new one
//! is one more line.

mod common;

use common::scenes::{regular_mesh, relative_l1, same_bits, solve_on, tiled_shadowed_box};
use radiosity::mesh::{self, Mesh, MeshOptions};
use radiosity::scene::Scene;
use radiosity::solver::SolverOptions;

/// How close a switch's twin must come.
#[derive(Clone, Copy, Debug)]
enum Tolerance {
    /// The same radiosity bits at every vertex.
    SameBits,
    /// Area-weighted relative L1 difference of the vertices' radiosity
    /// (the channels' mean) at most this.
    RelativeL1(f64),
}

use Tolerance::*;

/// One approximation switch: its name, how to turn it off (the twin), and
/// how close the twin must come to the default on every scene.
struct Switch {
    /// The option's name, for messages.
    name: &'static str,
    /// Turns the switch off in the default options.
    off: fn(&mut SolverOptions),
    /// How close the default must be to the twin.
    tolerance: Tolerance,
}

/// Every switch. A relative L1 bound is what the switch gives today on
/// both scenes (measured on the Cornell box, then on the tiled box, in
/// the row's comment), with a margin of two or more; the solves are
/// deterministic, so the margin is for changes to come, not for noise.
// A table: one row per line.
#[rustfmt::skip]
fn switches() -> Vec<Switch> {
    vec![
        // Shaft culling changes which rays are cast, never what they find.
        Switch { name: "shaft_culling", off: |o| o.shaft_culling = false, tolerance: SameBits },
        // 0.027 %, 0.063 % (the Cornell box has no clusters: what
        // changes is the receivers' interpolation, which goes with it).
        Switch { name: "clustering", off: |o| o.clustering = false, tolerance: RelativeL1(0.002) },
        // 0.027 %, 0.043 %.
        Switch { name: "receiver_interpolation", off: |o| o.receiver_interpolation = false, tolerance: RelativeL1(0.002) },
        // 2.7 %, 6.3 %: the plain disc sum is what the near field
        // corrects, receivers close to a shooter's samples (the walls
        // along their shared edges, the tiles next to each other).
        Switch { name: "near_field", off: |o| o.near_field = false, tolerance: RelativeL1(0.1) },
        // 0.046 %, 0.093 %: both stop at the same threshold, by different
        // paths.
        Switch { name: "overshoot", off: |o| o.overshoot = false, tolerance: RelativeL1(0.002) },
        // 0.0008 %, 0: neither scene has a pocket for settling to fill
        // (the solver's settle tests build one).
        Switch { name: "settle", off: |o| o.settle = 0.0, tolerance: RelativeL1(1e-4) },
    ]
}

/// Solves `s` on `mesh` with the default options and with each switch
/// turned off, and fails with every switch whose twin is not within its
/// tolerance, naming the scene, the switch, the tolerance and what was
/// measured.
fn check_switches(name: &str, s: &Scene, mesh: &Mesh) {
    let defaults = SolverOptions::default();
    let reference = solve_on(s, mesh.clone(), defaults);
    let mut failures = Vec::new();
    for switch in switches() {
        let mut options = defaults;
        (switch.off)(&mut options);
        let twin = solve_on(s, mesh.clone(), options);
        let (passed, measured) = match switch.tolerance {
            SameBits => {
                let same = same_bits(&reference.radiosity, &twin.radiosity);
                (same, format!("same bits: {same}"))
            }
            RelativeL1(bound) => {
                let l1 = relative_l1(mesh, &reference.radiosity, &twin.radiosity);
                (l1 <= bound, format!("relative L1 {l1:e}"))
            }
        };
        eprintln!(
            "{name}, {} off: {measured} ({} steps against {})",
            switch.name, twin.steps, reference.steps
        );
        if !passed {
            failures.push(format!(
                "{name}, {} off: {measured}, expected {:?}",
                switch.name, switch.tolerance
            ));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// The bundled Cornell box on its default mesh.
#[test]
fn switches_on_the_cornell_box() {
    let s = radiosity::scene::load(&common::scene("cornell.sc")).expect("cornell.sc loads");
    let mesh = mesh::build(&s, &MeshOptions::for_scene(&s)).expect("the scene meshes");
    check_switches("cornell.sc", &s, &mesh);
}

/// A 2-unit room lit by its glowing ceiling, with a square floating over
/// the floor casting a shadow, every wall cut into 4 × 4 tiles so that
/// clusters form; elements 0.15 across.
#[test]
fn switches_on_a_tiled_box() {
    let s = tiled_shadowed_box(4);
    let mesh = regular_mesh(&s, 0.15);
    check_switches("tiled box", &s, &mesh);
}
