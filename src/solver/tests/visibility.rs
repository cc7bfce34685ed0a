//! Shadows: shaft culling changes which rays are cast, never what they
//! find. (That an occluder casts a shadow is checked for every method by
//! the conformance suite, `tests/conformance.rs`.)

use super::*;

/// Shaft culling changes which rays are cast, never what they find: the
/// radiosities are bit for bit those of testing every ray against the BVH,
/// and fewer rays are cast.
#[test]
fn shaft_culling_changes_no_result_bit() {
    let mut polygons = room_with_lamp(4.0);
    // A table-like slab, a block on the floor and a thin wall piece.
    polygons.push(polygon(
        1,
        &[
            [1.0, 1.5, 1.0],
            [3.0, 1.5, 1.0],
            [3.0, 1.5, 3.0],
            [1.0, 1.5, 3.0],
        ],
    ));
    polygons.push(polygon(
        2,
        &[
            [0.5, 0.0, 0.5],
            [0.5, 1.0, 0.5],
            [0.5, 1.0, 1.2],
            [0.5, 0.0, 1.2],
        ],
    ));
    polygons.push(polygon(
        1,
        &[
            [3.2, 0.0, 0.2],
            [3.2, 0.0, 1.0],
            [3.2, 2.5, 1.0],
            [3.2, 2.5, 0.2],
        ],
    ));
    let s = scene(polygons, lamp_materials());
    let mesh = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.3,
            inset: crate::mesh::DEFAULT_INSET,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    let run = |shaft_culling: bool| {
        let mut solver = Progressive::new(
            &s,
            &mesh,
            &vis,
            SolverOptions {
                approximations: Approximations::DEFAULT
                    .with(Heuristic::ShaftCulling, shaft_culling),
                max_steps: Some(25),
                ..Default::default()
            },
        );
        while !solver.is_done() && solver.step().is_some() {}
        (
            solver.radiosity().to_vec(),
            solver.rays(),
            solver.pairs(),
            solver.receiver_pairs(),
        )
    };
    let (culled, culled_rays, culled_pairs, (receivers, clear)) = run(true);
    let (exact, exact_rays, exact_pairs, _) = run(false);
    assert!(same_bits(&culled, &exact));
    assert_eq!(culled_pairs, exact_pairs);
    assert_eq!(exact_rays, exact_pairs);
    assert!(culled_rays < exact_rays, "{culled_rays} vs {exact_rays}");
    assert!(clear > 0 && clear < receivers, "{clear} of {receivers}");
}
