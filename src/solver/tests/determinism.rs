//! A step's guarantees: nothing to do without emitters, nothing changed
//! by a cancelled step. (The same bits on any thread count is checked for
//! every method by the conformance suite, `tests/conformance.rs`.)

use super::*;

#[test]
fn a_scene_without_emitters_is_converged_at_once() {
    let s = scene(closed_box(1.0, [0; 6]), vec![grey("wall", 0.0, 0.5)]);
    let mesh = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.5,
            inset: 0.0,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &mesh, &vis, SolverOptions::default());
    assert_eq!(solver.stop_reason(), Some(StopReason::Converged));
    assert!(solver.step().is_none());
    assert_eq!(solver.unshot_fraction(), 0.0);
}

#[test]
fn a_cancelled_step_changes_nothing() {
    let s = scene(closed_box(1.0, [0; 6]), vec![grey("wall", 1.0, 0.5)]);
    let mesh = mesh::build(
        &s,
        &MeshOptions {
            lenmax: 0.2,
            inset: 0.05,
        },
    )
    .unwrap();
    let vis = Visibility::new(&s);
    let mut solver = Progressive::new(&s, &mesh, &vis, SolverOptions::default());
    let before = (solver.radiosity().to_vec(), solver.unshot().to_vec());
    let cancel = std::sync::atomic::AtomicBool::new(true);
    assert!(solver.step_cancellable(&cancel).is_none());
    assert_eq!(
        (solver.radiosity().to_vec(), solver.unshot().to_vec()),
        before
    );
    assert_eq!((solver.steps(), solver.rays()), (0, 0));
    assert!(solver.step().is_some());
}
