//! `radiosity`: the command-line front end. Parses the arguments, turns
//! them into one validated [`Invocation`], runs it and maps the outcome to
//! an exit code: 0 success, 1 a failure writing results, 2 bad input or
//! usage, 130 interrupted (Ctrl-C).

use radiosity::batch::{self, RunError};
use radiosity::cancel::Cancel;
use radiosity::cli::{Invocation, UsageError};
use radiosity::drive;
use std::process::ExitCode;
use std::sync::LazyLock;

/// Set by the Ctrl-C handler; every phase of a batch run checks it.
static INTERRUPTED: LazyLock<Cancel> = LazyLock::new(Cancel::new);

/// Why the program ends other than by a finished run; [`exit_code`] turns
/// each into its message and code.
enum Stop {
    /// clap's own: `--help` and `--version` (0) or a command line it cannot
    /// parse (2).
    Clap(clap::Error),
    /// Options that parsed but cannot be used.
    Usage(UsageError),
    /// The `--threads` pool could not be started.
    Threads(usize, rayon::ThreadPoolBuildError),
    /// The run failed or was interrupted.
    Run(RunError),
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(stop) => ExitCode::from(exit_code(stop)),
    }
}

/// Parse, configure, run.
fn run() -> Result<(), Stop> {
    let args = radiosity::cli::parse().map_err(Stop::Clap)?;
    let invocation = Invocation::try_from(args).map_err(Stop::Usage)?;
    if let Some(threads) = invocation.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads.get())
            .build_global()
            .map_err(|e| Stop::Threads(threads.get(), e))?;
    }
    let stats = drive::run(&invocation, &INTERRUPTED, catch_ctrl_c).map_err(Stop::Run)?;
    if let Some(stats) = stats.filter(|_| !invocation.quiet()) {
        eprintln!("{}", batch::summary(&stats));
    }
    Ok(())
}

/// Reports `stop` on the terminal and returns its exit code: the one place
/// codes are chosen (besides a second Ctrl-C, which exits at once with 130).
fn exit_code(stop: Stop) -> u8 {
    match stop {
        Stop::Clap(e) => {
            // Help goes to stdout and errors to stderr, as clap decides.
            let _ = e.print();
            // clap's codes are 0 (help, version) and 2 (usage).
            u8::try_from(e.exit_code()).unwrap_or(2)
        }
        Stop::Usage(e) => {
            eprintln!("error: {e}");
            2
        }
        Stop::Threads(threads, e) => {
            // Exit 1 means a result could not be written; a pool the
            // system refuses is a problem of the options given.
            eprintln!("error: cannot start {threads} threads: {e}; give fewer with --threads");
            2
        }
        Stop::Run(e) => {
            // Load errors already read `FILE:LINE:COL: error: ...`.
            if e.is_self_describing() {
                eprintln!("{e}");
            } else {
                eprintln!("error: {e}");
            }
            e.exit_code()
        }
    }
}

/// Makes Ctrl-C (SIGINT, and SIGTERM) stop a batch run cleanly: the first
/// sets [`INTERRUPTED`], which every phase of the run checks (load, split,
/// mesh, solve, gather, render, write); a second removes the temporaries
/// of the files being written and exits at once with 130. [`drive::run`]
/// installs it for batch runs only.
fn catch_ctrl_c() {
    let installed = ctrlc::set_handler(|| {
        if INTERRUPTED.is_set() {
            radiosity::output::remove_temporaries();
            eprintln!("interrupted again: exiting now");
            std::process::exit(130);
        }
        INTERRUPTED.set();
        eprintln!("interrupted: stopping (Ctrl-C again to exit at once)");
    });
    if let Err(e) = installed {
        eprintln!("warning: cannot catch Ctrl-C ({e}); an interrupt will end the run abruptly");
    }
}
