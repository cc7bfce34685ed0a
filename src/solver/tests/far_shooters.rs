//! Far shooters probed ([`super::far_shooters`]) against asking every
//! sample: a lamp over a large floor with a table top and thin legs
//! between them.

use super::*;
use crate::testutil::{cuboid, grey, polygon, regular_mesh, scene};

/// A 20 × 20 floor (material 0, grey), a 0.8 × 0.8 lamp facing down 3
/// units above one corner (material 1), a 1 × 1 table top at 0.75 and
/// three legs 0.05 across, all grey.
fn lamp_over_floor() -> Scene {
    let w = 20.0;
    let mut polygons = vec![
        polygon(0, &[[0., 0., 0.], [0., 0., w], [w, 0., w], [w, 0., 0.]]),
        polygon(
            1,
            &[[1., 3., 1.], [1.8, 3., 1.], [1.8, 3., 1.8], [1., 3., 1.8]],
        ),
    ];
    polygons.extend(cuboid([8.0, 0.70, 8.0], [9.0, 0.75, 9.0], false));
    for (x, z) in [(12.0, 12.0), (15.0, 6.0), (6.0, 15.0)] {
        polygons.extend(cuboid([x, 0.0, z], [x + 0.05, 0.75, z + 0.05], false));
    }
    scene(
        polygons,
        vec![grey("grey", 0.0, 0.5), grey("lamp", 10.0, 0.0)],
    )
}

/// The lamp's shot alone (the first step) with far shooters probed and
/// with every sample asked: the floor's vertices within 0.5 % relative
/// L1, the table top's shadow dark in both, the probed twin at most 0.6 ×
/// the rays (measured: 0.0004 %, 0.23 × the rays), and the same bits on 1
/// and 2 threads.
#[test]
fn far_shooters_probed_match_asking_every_sample() {
    let s = lamp_over_floor();
    let mesh = regular_mesh(&s, 0.25);
    let vis = Visibility::new(&s);
    let lamp_shot = |probing: bool| {
        let options = SolverOptions {
            approximations: Approximations::DEFAULT.with(Heuristic::FarShooters, probing),
            ..Default::default()
        };
        let mut solver = Progressive::new(&s, &mesh, &vis, options);
        assert_eq!(solver.next_shooter(), Some(PolygonId(1)), "the lamp first");
        solver.step().expect("the lamp shoots");
        solver.validate().unwrap();
        (solver.radiosity().to_vec(), solver.rays())
    };
    let (probed, probed_rays) = lamp_shot(true);
    let (every, every_rays) = lamp_shot(false);
    let floor = mesh.polygons[0].vertices.clone();
    let (mut diff, mut total) = (0.0, 0.0);
    for l in floor.clone() {
        let (a, b) = (probed[l as usize].mean(), every[l as usize].mean());
        diff += (a - b).abs();
        total += b;
    }
    eprintln!(
        "far probes: floor relL1 {}, rays {probed_rays} vs {every_rays}",
        diff / total
    );
    assert!(diff / total < 0.005, "floor relL1 {}", diff / total);
    assert!(
        (probed_rays as f64) < 0.6 * every_rays as f64,
        "probes saved too few rays: {probed_rays} vs {every_rays}"
    );
    // The vertex nearest the middle of the table top's shadow (the top's
    // middle seen from the lamp's, 13.2 units across the floor from it:
    // probed), against one in the open as far away.
    let nearest = |p: glam::Vec3| {
        floor
            .clone()
            .min_by(|&a, &b| {
                let d = |l: u32| mesh.sample_positions[l as usize].distance_squared(p);
                d(a).total_cmp(&d(b))
            })
            .unwrap() as usize
    };
    let (under, open) = (
        nearest(glam::Vec3::new(10.76, 0.0, 10.76)),
        nearest(glam::Vec3::new(14.6, 0.0, 1.4)),
    );
    for r in [&probed, &every] {
        assert!(
            r[under].mean() < 0.01 * r[open].mean(),
            "shadowed {:?} against open {:?}",
            r[under],
            r[open]
        );
    }
    let threads = |n| {
        super::on_threads(n, || {
            let mut solver = Progressive::new(&s, &mesh, &vis, SolverOptions::default());
            for _ in 0..5 {
                if solver.step().is_none() {
                    break;
                }
            }
            solver.radiosity().to_vec()
        })
    };
    assert!(super::same_bits(&threads(1), &threads(2)));
}
