//! Options that mean something only with another: `--falsecolor-max`
//! without `--falsecolor` or `--workplane` would be silently ignored, so
//! the command line is refused instead, with one message of one form,
//! `--OPTION needs --PARENT`, whatever the option (exit code 2).
//!
//! Whether an option was given is read from clap's matches (an option
//! with a default always has a value), whether its parent was from the
//! parsed [`Args`]; hence the check runs in [`super::parse_from`], the
//! parser the program uses.

use super::args::Args;
use crate::solver::FormFactorMethod;
use clap::parser::ValueSource;
use clap::ArgMatches;

/// One option that needs another.
pub struct Need {
    /// The option's id (its field in [`Args`]).
    pub id: &'static str,
    /// How the message names the option.
    pub flag: &'static str,
    /// How the message names what it needs.
    pub parent: &'static str,
    /// Whether the parsed arguments hold what it needs.
    pub met: fn(&Args) -> bool,
}

/// Every option that needs another, in the order they are checked (a
/// command line with several is refused for the first).
pub const NEEDS: &[Need] = &[
    Need {
        id: "hemicube_res",
        flag: "--hemicube-res",
        parent: "--form-factor hemicube",
        met: |a| a.form_factor == FormFactorMethod::Hemicube,
    },
    Need {
        id: "adaptive_threshold",
        flag: "--adaptive-threshold",
        parent: "--adaptive",
        met: |a| a.adaptive,
    },
    Need {
        id: "adaptive_levels",
        flag: "--adaptive-levels",
        parent: "--adaptive",
        met: |a| a.adaptive,
    },
    Need {
        id: "adaptive_max_splits",
        flag: "--adaptive-max-splits",
        parent: "--adaptive",
        met: |a| a.adaptive,
    },
    Need {
        id: "checkpoint_every",
        flag: "--checkpoint-every",
        parent: "--checkpoint",
        met: |a| a.checkpoint.is_some(),
    },
    Need {
        id: "illuminance_at",
        flag: "--illuminance-at",
        parent: "--illuminance-out",
        met: |a| a.illuminance_out.is_some(),
    },
    Need {
        id: "illuminance_out",
        flag: "--illuminance-out",
        parent: "--illuminance-at",
        met: |a| a.illuminance_at.is_some(),
    },
    Need {
        id: "workplane_out",
        flag: "--workplane-out",
        parent: "--workplane",
        met: |a| a.workplane.is_some(),
    },
    Need {
        id: "falsecolor_of",
        flag: "--falsecolor-of",
        parent: "--falsecolor",
        met: |a| a.falsecolor.is_some(),
    },
    Need {
        id: "falsecolor_scale",
        flag: "--falsecolor-scale",
        parent: "--falsecolor or --workplane",
        met: |a| a.falsecolor.is_some() || a.workplane.is_some(),
    },
    Need {
        id: "falsecolor_max",
        flag: "--falsecolor-max",
        parent: "--falsecolor or --workplane",
        met: |a| a.falsecolor.is_some() || a.workplane.is_some(),
    },
    Need {
        id: "daylight_factor",
        flag: "--daylight-factor",
        parent: "--workplane",
        met: |a| a.workplane.is_some(),
    },
    Need {
        id: "north",
        flag: "--north",
        parent: "--sun",
        met: |a| a.sun.is_some(),
    },
];

/// The message for the first option of [`NEEDS`] given on the command
/// line (per `matches`) without what it needs (per `args`), or `None`.
pub fn unmet(matches: &ArgMatches, args: &Args) -> Option<String> {
    NEEDS
        .iter()
        .find(|n| matches.value_source(n.id) == Some(ValueSource::CommandLine) && !(n.met)(args))
        .map(|n| format!("{} needs {}", n.flag, n.parent))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn every_entry_names_an_option_as_it_is_spelled() {
        let command = Args::command();
        for need in NEEDS {
            let arg = command
                .get_arguments()
                .find(|a| a.get_id() == need.id)
                .unwrap_or_else(|| panic!("no option {}", need.id));
            assert_eq!(
                Some(need.flag.trim_start_matches("--")),
                arg.get_long(),
                "{}",
                need.id
            );
            assert!(need.parent.starts_with("--"), "{}", need.parent);
        }
    }
}
