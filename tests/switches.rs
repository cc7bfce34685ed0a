//! Each heuristic of the solver ([`Approximations`]) against its twin: a
//! solve with every switch on (or, for a twin that leaves another switch
//! without effect, every switch but that one), and the same solve with one
//! switch turned off, must give the same radiosity bits (for a switch that changes no
//! result) or stay within a relative L1 difference of the picture's
//! radiosity; so must the groups `--exact-receivers` turns off and the
//! brute-force twin [`Approximations::EXACT`]. Every switch must also act
//! on one of the scenes (change bits or rays), so no row passes by
//! testing nothing. A switch is a row of [`switches`]; a new one is one
//! more line.

mod common;

use common::scenes::{
    grey, polygon, regular_mesh, relative_l1, same_bits, scene, solve_on, tiled, tiled_shadowed_box,
};
use radiosity::color::Rgb;
use radiosity::mesh::{self, Mesh, MeshOptions};
use radiosity::scene::Scene;
use radiosity::solver::{Approximations, Heuristic, SolverOptions};

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

/// One switch or group of switches: its name, the heuristics it turns off
/// (the twin), and how close the twin must come to the default on every
/// scene.
struct Switch {
    /// The switch's name, for messages.
    name: &'static str,
    /// The approximations of the twin.
    twin: Approximations,
    /// What the twin is compared with: the default, or for a switch whose
    /// twin leaves another switch without effect, the default without
    /// that one too.
    base: Approximations,
    /// How close the default must be to the twin.
    tolerance: Tolerance,
    /// Scenes this row leaves out, for time: the brute-force twin on the
    /// spheres' 2,188 facets takes 2,500 steps (33 s); the unclustered
    /// row checks them there.
    skip: &'static [&'static str],
}

/// A row turning off one heuristic.
fn off(h: Heuristic, tolerance: Tolerance) -> Switch {
    Switch {
        name: format!("{h:?}").leak(),
        twin: Approximations::DEFAULT.with(h, false),
        base: Approximations::DEFAULT,
        tolerance,
        skip: &[],
    }
}

/// Every switch, then the groups. A relative L1 bound is the largest the
/// switch gives today on the four scenes (in the row's comment, in the
/// order Cornell box, tiled box, spheres, sky, wide floor), with a margin of two or
/// more; the solves are deterministic, so the margin is for changes to
/// come, not for noise.
// A table: one row per line.
#[rustfmt::skip]
fn switches() -> Vec<Switch> {
    use Heuristic::*;
    vec![
        // 0, 9.5e-5, 0, 0, 0: only the tiled box's weak lamp waits.
        off(EmittersFirst, RelativeL1(3e-4)),
        // 4.6e-4, 9.5e-4, 4.2e-4, 1.4e-6, 3e-8: both stop at the same
        // threshold, by different paths.
        off(Overshoot, RelativeL1(2e-3)),
        // 8.4e-6, 0, 2.1e-4, 2.6e-7, 2.9e-5: the pockets under the balls.
        off(Settling, RelativeL1(1e-3)),
        // 2.7 %, 6.3 %, 1.7 %, 3.6e-5, 1.5e-4: the plain disc sum is what the
        // near field corrects, receivers close to a shooter's samples
        // (the walls along their shared edges, the tiles side by side).
        off(NearField, RelativeL1(0.1)),
        // Shaft culling changes which rays are cast, never what they find.
        off(ShaftCulling, SameBits),
        // 2.7e-4, 2.3e-3, 5.8e-4, 2.6e-6, 5e-7 (the Cornell box has no
        // clusters: what changes there is the receiver heuristics, which
        // act only in a solve that clusters; the tiled box's is mostly
        // shared receivers).
        off(Clusters, RelativeL1(5e-3)),
        // 0, 4.9e-4, 3.0e-4, 4.9e-7, 4e-7.
        off(Strata, RelativeL1(2e-3)),
        // 2.7e-4, 1.4e-4, 0, 5.2e-7, 7e-8.
        off(ReceiverInterpolation, RelativeL1(1e-3)),
        // 0, 4.0e-4, 2.9e-4, 3.2e-7, 1.9e-7.
        off(WeakStrata, RelativeL1(1e-3)),
        // 9.7e-5, 4.5e-4, 0, 2.1e-7, 0.
        off(CrowdedCells, RelativeL1(1.5e-3)),
        // 3e-7 on the spheres, 0 elsewhere.
        off(FacetRays, RelativeL1(1e-5)),
        // 8.4e-8 under the sky (its hemisphere's probes), 0 elsewhere.
        off(SkyProbes, RelativeL1(1e-5)),
        // 0 everywhere: the far lamp's probes agree; it casts fewer rays.
        off(FarShooters, RelativeL1(1e-5)),
        // 0, 2.2e-3, 3.2e-4, 1.3e-6, 0: a tile's or a facet's vertex
        // takes its neighbour's value at the same point, a tenth of
        // lenmax from its own inset point.
        off(SharedReceivers, RelativeL1(5e-3)),
        // 2.0e-6 on the courtyard, the only scene with a sky: 191 steps
        // by facets, 110 with the sky at once (the skylight and overhang
        // tests of `src/solver/tests/sky.rs` check both against Lambert).
        // Shot by facets, vertices ask from their own points, so against
        // the sky at once without hat centroids.
        Switch { base: Approximations::DEFAULT.with(HatCentroids, false), ..off(SkyAtOnce, RelativeL1(1e-5)) },
        // 7.2e-6 on the courtyard, 0 elsewhere: its floor's and walls'
        // edge vertices ask a third of an element in (the wall's-foot
        // test of `src/solver/tests/sky.rs` checks it against Lambert;
        // the sky's facets, far larger than the courtyard, weigh in
        // every sky row's L1).
        off(HatCentroids, RelativeL1(2e-5)),
        // 2.7e-4, 2.3e-3, 5.7e-4, 1.4e-6, 2.5e-7.
        Switch { name: "--exact-receivers", twin: Approximations::DEFAULT.without(&Heuristic::RECEIVERS), base: Approximations::DEFAULT, tolerance: RelativeL1(5e-3), skip: &[] },
        // 5.7e-4, 2.3e-3, (skipped), 3.1e-6, 5e-7. The brute-force twin, but
        // for shaft culling, which changes no bit (its own row) and
        // would only multiply the rays; against the default without hat
        // centroids, as its vertices ask from their own points.
        Switch { name: "Approximations::EXACT", twin: Approximations::EXACT.with(ShaftCulling, true), base: Approximations::DEFAULT.with(HatCentroids, false), tolerance: RelativeL1(5e-3), skip: &["spheres"] },
    ]
}

/// Solves `s` on `mesh` with the default options and with each switch
/// turned off; returns, per row of [`switches`], whether the twin acted
/// (other bits or other rays), and the failures: every row whose twin is
/// not within its tolerance, naming the scene, the switch, the tolerance
/// and what was measured.
fn check_switches(name: &str, s: &Scene, mesh: &Mesh) -> (Vec<bool>, Vec<String>) {
    let defaults = SolverOptions::default();
    let reference = solve_on(s, mesh.clone(), defaults);
    let mut failures = Vec::new();
    let mut acted = Vec::new();
    for switch in switches() {
        if switch.skip.contains(&name) {
            acted.push(false);
            continue;
        }
        let other_base;
        let base = if switch.base == defaults.approximations {
            &reference
        } else {
            other_base = solve_on(
                s,
                mesh.clone(),
                SolverOptions {
                    approximations: switch.base,
                    ..defaults
                },
            );
            &other_base
        };
        let options = SolverOptions {
            approximations: switch.twin,
            ..defaults
        };
        let clock = std::time::Instant::now();
        let twin = solve_on(s, mesh.clone(), options);
        let seconds = clock.elapsed().as_secs_f64();
        let same = same_bits(&base.radiosity, &twin.radiosity);
        acted.push(!same || twin.rays != base.rays);
        let (passed, measured) = match switch.tolerance {
            SameBits => (same, format!("same bits: {same}")),
            RelativeL1(bound) => {
                let l1 = relative_l1(mesh, &base.radiosity, &twin.radiosity);
                (l1 <= bound, format!("relative L1 {l1:e}"))
            }
        };
        eprintln!(
            "{name}, {} off: {measured} ({} steps, {} rays against {}, {}; {seconds:.2} s)",
            switch.name, twin.steps, twin.rays, base.steps, base.rays
        );
        if !passed {
            failures.push(format!(
                "{name}, {} off: {measured}, expected {:?}",
                switch.name, switch.tolerance
            ));
        }
    }
    (acted, failures)
}

/// The five scenes: what each heuristic acts on is in one of them.
fn scenes() -> Vec<(&'static str, Scene, Mesh)> {
    let cornell = radiosity::scene::load(&common::scene("cornell.sc")).expect("cornell.sc loads");
    let cornell_mesh = mesh::build(&cornell, &MeshOptions::for_scene(&cornell)).expect("meshes");
    let tiled = tiled_box_with_a_weak_lamp();
    let tiled_mesh = regular_mesh(&tiled, 0.15);
    // McGuire's Cornell box with two spheres (a real export, 2,188
    // faces): clusters of small facets, facets smaller than half an
    // element that share their rays, pockets under the balls.
    let path = common::root().join("tests/models/mcguire/CornellBox-Sphere.obj");
    let spheres = radiosity::scene::load(&path).expect("CornellBox-Sphere.obj loads");
    let spheres_mesh = regular_mesh(&spheres, 0.25);
    let sky = courtyard();
    let sky_mesh = regular_mesh(&sky, 0.25);
    let far = lamp_over_a_wide_floor();
    let far_mesh = regular_mesh(&far, 0.25);
    vec![
        ("cornell.sc", cornell, cornell_mesh),
        ("tiled box", tiled, tiled_mesh),
        ("spheres", spheres, spheres_mesh),
        ("courtyard under a sky", sky, sky_mesh),
        ("lamp over a wide floor", far, far_mesh),
    ]
}

/// A 2-unit room lit by its glowing ceiling, with a square floating over
/// the floor casting a shadow, every wall cut into 4 × 4 tiles so that
/// clusters form, and a weak lamp on the floor: the walls the ceiling
/// lights hold more power than it emits, so the order of shooting depends
/// on whether emitters go first.
fn tiled_box_with_a_weak_lamp() -> Scene {
    let mut s = tiled_shadowed_box(4);
    s.materials.push(grey("weak lamp", 0.5, 0.3));
    let weak = (s.materials.len() - 1) as u32;
    s.polygons.push(polygon(
        weak,
        &[
            [0.2, 0.01, 0.2],
            [0.2, 0.01, 0.5],
            [0.5, 0.01, 0.5],
            [0.5, 0.01, 0.2],
        ],
    ));
    s
}

/// A 20 × 20 floor under a lamp 0.8 across, 3 over one corner, with a
/// table top over the floor: most of the floor lies more than twelve lamp
/// diameters away (far shooters).
fn lamp_over_a_wide_floor() -> Scene {
    let w = 20.0;
    let polygons = vec![
        polygon(0, &[[0., 0., 0.], [0., 0., w], [w, 0., w], [w, 0., 0.]]),
        polygon(
            1,
            &[[1., 3., 1.], [1.8, 3., 1.], [1.8, 3., 1.8], [1., 3., 1.8]],
        ),
        // The table top's upper and lower faces.
        polygon(
            0,
            &[
                [8., 0.75, 8.],
                [8., 0.75, 9.],
                [9., 0.75, 9.],
                [9., 0.75, 8.],
            ],
        ),
        polygon(
            0,
            &[[8., 0.7, 8.], [9., 0.7, 8.], [9., 0.7, 9.], [8., 0.7, 9.]],
        ),
    ];
    scene(
        polygons,
        vec![grey("grey", 0.0, 0.5), grey("lamp", 10.0, 0.0)],
    )
}

/// A 4 × 4 courtyard of tiled walls 1.5 high, open to a uniform sky, with
/// a small lamp in one corner.
fn courtyard() -> Scene {
    let floor = polygon(
        1,
        &[
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 4.0],
            [4.0, 0.0, 4.0],
            [4.0, 0.0, 0.0],
        ],
    );
    let walls = [
        [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 1.5, 0.0],
            [0.0, 1.5, 0.0],
        ],
        [
            [4.0, 0.0, 4.0],
            [0.0, 0.0, 4.0],
            [0.0, 1.5, 4.0],
            [4.0, 1.5, 4.0],
        ],
        [
            [0.0, 0.0, 4.0],
            [0.0, 0.0, 0.0],
            [0.0, 1.5, 0.0],
            [0.0, 1.5, 4.0],
        ],
    ];
    // Facing down, 1 over the floor.
    let lamp = polygon(
        0,
        &[
            [3.5, 1.0, 3.5],
            [3.7, 1.0, 3.5],
            [3.7, 1.0, 3.7],
            [3.5, 1.0, 3.7],
        ],
    );
    let mut polygons = tiled(&floor, 4);
    for w in walls {
        polygons.extend(tiled(&polygon(1, &w), 4));
    }
    polygons.push(lamp);
    let mut s = scene(
        polygons,
        vec![grey("lamp", 20.0, 0.0), grey("stone", 0.0, 0.6)],
    );
    s.add_sky(Rgb::splat(1.0))
        .expect("a sky fits around the courtyard");
    s
}

/// Every switch within its tolerance on every scene, and every switch
/// acting on at least one of them.
#[test]
fn each_switch_against_its_twin() {
    let mut acted = vec![false; switches().len()];
    let mut failures = Vec::new();
    for (name, s, mesh) in scenes() {
        let (a, f) = check_switches(name, &s, &mesh);
        acted.iter_mut().zip(a).for_each(|(x, a)| *x |= a);
        failures.extend(f);
    }
    for (switch, acted) in switches().iter().zip(acted) {
        if !acted {
            failures.push(format!(
                "{} changed nothing on any scene: untested",
                switch.name
            ));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
