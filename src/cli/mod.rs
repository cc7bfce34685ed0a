//! The command line: clap's definitions ([`Args`]), the parsers for
//! structured values ([`parse_size`], [`parse_shooter_samples`],
//! [`parse_emit`], [`parse_sky`]) and the
//! conversion of the raw arguments into the one validated [`Invocation`]
//! the rest of the program sees (never `argv`).
//!
//! The layout follows ripgrep's `flags/`: `args` holds the raw options,
//! `values` the value parsers, `invocation` the validation and the decisions
//! taken once (window or batch), `needs` the options that mean something
//! only with another, `help` what `-h` and `--help` say beyond each
//! option's doc comment. Bad values are [`ValueError`]s reported by clap,
//! an option without the one it needs a clap error from [`parse_from`],
//! or [`UsageError`]s from the conversion; all mean exit code 2.
//!
//! ```
//! use clap::Parser;
//! use radiosity::cli::{Args, Invocation, Mode};
//!
//! let args = Args::try_parse_from(["radiosity", "scene.sc", "-o", "out.png"]).unwrap();
//! let invocation = Invocation::try_from(args).unwrap();
//! assert_eq!(invocation.mode, Mode::Batch);
//! ```

mod args;
mod help;
mod invocation;
mod needs;
mod values;

pub use args::{Args, EXIT_CODES};
pub use help::{command, parse, parse_from};
pub use invocation::{Invocation, Mode, UsageError};
pub use values::{parse_emit, parse_shooter_samples, parse_size, parse_sky, ValueError};
