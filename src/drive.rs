//! One run of the program from a validated [`Invocation`]: the batch run,
//! or the window with its fallback to the batch run when no window can
//! open. Both drivers are the [`batch`] and [`viewer`] entry points; this
//! module only chooses between them, so the front end has one call to make.

use crate::batch::{self, RunError, RunStats};
use crate::cancel::Cancel;
use crate::cli::{Invocation, Mode};
use crate::config::RunConfig;
use crate::prepare::{self, Prepared};
use crate::viewer::{self, ViewerError};

/// Runs `invocation`: `Ok(Some(stats))` when a batch run wrote its
/// results, `Ok(None)` when the window ran and the user closed it.
///
/// A batch run stops with [`RunError::Interrupted`] once `cancel` is set.
/// `arm_cancel` is called at most once, just before a batch run starts, and
/// never when the window runs, so that a Ctrl-C handler setting `cancel` is
/// installed only where `cancel` is polled: the window quits with its own
/// keys, and a Ctrl-C in its terminal ends it the ordinary way.
pub fn run(
    invocation: &Invocation,
    cancel: &Cancel,
    arm_cancel: impl FnOnce(),
) -> Result<Option<RunStats>, RunError> {
    let config = &invocation.config;
    match invocation.mode {
        Mode::Batch => batch(config, None, cancel, arm_cancel, || {}),
        Mode::Info => {
            print!("{}", crate::info::describe(config)?);
            Ok(None)
        }
        Mode::Window => {
            // Says why the picture goes to a file instead of a window.
            let fallback = |why: &str| {
                if !invocation.quiet() {
                    eprintln!(
                        "{why}: writing {} in the current directory instead",
                        config.output_path().display()
                    );
                }
            };
            if let Err(why) = viewer::display_available() {
                // Said once the scene has loaded: bad outputs and a scene
                // that does not load are refused before it, as the notice
                // would promise a file that is never written.
                return batch(config, None, cancel, arm_cancel, || {
                    fallback(&why.to_string())
                });
            }
            // The window's first frame needs no BVH: the solver's thread
            // builds it.
            let prepared = prepare::prepare_deferred(config)?;
            match viewer::run(&prepared, config) {
                Ok(()) => Ok(None),
                Err(ViewerError::CannotOpen(why)) => {
                    batch(config, Some(&prepared), cancel, arm_cancel, || {
                        fallback(&why)
                    })
                }
                Err(ViewerError::View(e)) => Err(RunError::View(e)),
                Err(ViewerError::Render(e)) => Err(RunError::Render(e)),
            }
        }
    }
}

/// The batch run, from the scene or from a scene already `prepared` for a
/// window that could not open: the one place a run is made cancellable.
/// `loaded` is called once the scene is prepared, before the solve.
fn batch(
    config: &RunConfig,
    prepared: Option<&Prepared>,
    cancel: &Cancel,
    arm_cancel: impl FnOnce(),
    loaded: impl FnOnce(),
) -> Result<Option<RunStats>, RunError> {
    arm_cancel();
    let owned;
    let prepared = match prepared {
        Some(prepared) => prepared,
        None => {
            owned = batch::prepare(config, cancel)?;
            &owned
        }
    };
    loaded();
    batch::run_prepared(config, prepared, cancel).map(Some)
}
