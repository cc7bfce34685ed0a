//! The cancellation token every long phase of a run checks: loading,
//! splitting, meshing, solving, the photometric gathers, rendering and
//! writing. The command line sets it on the first SIGINT or SIGTERM; each
//! phase checks it often enough (per face, per polygon, per point, per
//! buffer written) that a run stops within a fraction of a second in any
//! of them.
//!
//! A phase that sees the token set stops with [`Cancelled`] and leaves
//! nothing half done behind: a file being written is abandoned and its
//! temporary removed (see [`crate::output`]), a file already renamed into
//! place stays and is reported as written.
//!
//! Work done inside a library that cannot be asked to stop (parsing a
//! model file, drawing a plot) and that writes nothing runs through
//! [`abandonable`]: on a thread of its own, which an interrupt abandons
//! (the program then exits, ending it).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How often [`abandonable`] looks at its token while it waits: well
/// within the half second an interrupt may take to act.
pub const POLL: Duration = Duration::from_millis(10);

/// A shared cancellation flag. Clones share one flag: setting it through
/// any clone is seen by all. Once set it stays set.
#[derive(Clone, Debug, Default)]
pub struct Cancel {
    flag: Arc<AtomicBool>,
}

/// The error of a phase that stopped because its [`Cancel`] was set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("interrupted")]
pub struct Cancelled;

impl Cancel {
    /// A token not yet set.
    pub fn new() -> Cancel {
        Cancel::default()
    }

    /// A token nobody else holds, so never set: for callers that cannot
    /// be interrupted (tests, examples, benchmarks).
    pub fn never() -> Cancel {
        Cancel::default()
    }

    /// Asks every phase holding this token to stop.
    pub fn set(&self) {
        self.flag.store(true, Ordering::SeqCst);
    }

    /// True once [`Cancel::set`] was called. One atomic load: cheap enough
    /// to call per item in a loop, including inside parallel loops.
    pub fn is_set(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once the token is set, for `?` in a loop.
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_set() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }

    /// The flag itself, for the solver's steps, which take an
    /// [`AtomicBool`].
    pub fn flag(&self) -> &AtomicBool {
        &self.flag
    }
}

/// The stack of an [`abandonable`] thread: that of a program's main thread
/// on Linux, which the work (a recursive parser, say) ran on before.
pub const ABANDONABLE_STACK: usize = 8 << 20;

/// Runs `work` on a thread of its own and returns its result, or
/// [`Cancelled`] as soon as `cancel` is set (checked every [`POLL`]),
/// leaving the thread to finish unobserved. Only for work that writes
/// nothing and whose caller stops once interrupted: an abandoned thread
/// runs on until it ends or the process exits. A panic in `work` is
/// resumed on the caller's thread. If no thread can be started, `work`
/// runs on the caller's, not abandonable.
pub fn abandonable<T: Send + 'static>(
    cancel: &Cancel,
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, Cancelled> {
    let (send, receive) = mpsc::channel();
    // Shared so that the caller can take the work back if the thread
    // cannot be started.
    let slot = Arc::new(Mutex::new(Some(work)));
    let taken = Arc::clone(&slot);
    let spawned = std::thread::Builder::new()
        .stack_size(ABANDONABLE_STACK)
        .spawn(move || {
            let work = taken.lock().ok().and_then(|mut w| w.take());
            if let Some(work) = work {
                // The receiver is gone only when the caller was interrupted.
                let _ = send.send(work());
            }
        });
    let thread = match spawned {
        Ok(thread) => thread,
        Err(_) => {
            let work = slot.lock().ok().and_then(|mut w| w.take());
            return match work {
                Some(work) => Ok(work()),
                None => Err(Cancelled),
            };
        }
    };
    loop {
        match receive.recv_timeout(POLL) {
            Ok(result) => return Ok(result),
            Err(RecvTimeoutError::Timeout) => cancel.check()?,
            Err(RecvTimeoutError::Disconnected) => match thread.join() {
                Err(panic) => std::panic::resume_unwind(panic),
                // It sends before it ends, so it cannot end quietly.
                Ok(()) => unreachable!("the worker ended without a result"),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_flag() {
        let a = Cancel::new();
        let b = a.clone();
        assert!(!b.is_set() && b.check().is_ok());
        a.set();
        assert!(b.is_set());
        assert_eq!(b.check(), Err(Cancelled));
        assert!(b.flag().load(Ordering::SeqCst));
        assert!(!Cancel::never().is_set());
    }

    #[test]
    fn abandonable_work_returns_its_result_or_is_left_on_cancel() {
        let cancel = Cancel::new();
        assert_eq!(abandonable(&cancel, || 6 * 7), Ok(42));
        let (release, wait) = mpsc::channel::<()>();
        let setter = cancel.clone();
        let start = std::time::Instant::now();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(50));
            setter.set();
        });
        // Would block until `release` is dropped, after the assertion.
        let result = abandonable(&cancel, move || wait.recv().is_ok());
        assert_eq!(result, Err(Cancelled));
        assert!(start.elapsed() < Duration::from_secs(2));
        drop(release);
    }

    #[test]
    #[should_panic(expected = "in the worker")]
    fn abandonable_work_panics_on_the_caller() {
        let _ = abandonable(&Cancel::new(), || panic!("in the worker"));
    }
}
