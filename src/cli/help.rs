//! What `-h` and `--help` say beyond the options' own doc comments: the
//! long help of the options whose text quotes a tuning constant, written
//! from the constants themselves ([`crate::solver::tuning`]) so `--help`
//! never says one number while the solver uses another; the examples
//! `--help` ends with ([`EXAMPLES`], each run by a test); and the footers.

use super::args::{Args, EXIT_CODES};
use crate::solver::tuning::{
    CHECK_TOLERANCE, CLUSTER_EXTENT, EXACT_RATIO, FACET_SCALE_RATIO, FAR_PROBES, FAR_SHOOTER_RATIO,
    NEAR_FIELD_RATIO, OVERSHOOT_SHARE, RECEIVER_STRIDE, RECEIVER_WEAK_SHARE, SHARE_CREASE_DEG,
    SKY_CELL_STRATA, SKY_FACET_SAMPLES, SKY_PROBES, WEAK_STRATUM_SHARE,
};
use clap::CommandFactory;

/// The examples `--help` ends with: a command (run in the project's
/// folder, on a bundled scene) and what it does. A test runs each as
/// `--help` prints it, so none can drift from what the program accepts.
pub const EXAMPLES: &[(&str, &str)] = &[
    (
        "radiosity scenes/cornell.sc",
        "The Cornell box in a window (without a display: written to cornell.png).",
    ),
    (
        "radiosity scenes/cornell.sc -o cornell.png --exposure 1",
        "A picture one stop brighter than the automatic exposure.",
    ),
    (
        "radiosity scenes/rtable.sc --adaptive -o rtable.exr --export rtable.glb",
        "Sharper shadows; linear radiosity (.exr) and the solved mesh for Blender.",
    ),
    (
        "radiosity scenes/cornell.sc --camera scenes/cameras/cornell-base.sc -o base.png",
        "The same box seen from another camera.",
    ),
    (
        "radiosity scenes/office.sc --units m --ies luminaire=scenes/luminaires/panel.ies \\
         --workplane 0.8 --falsecolor office-lux.png --falsecolor-of illuminance",
        "Lux on a desk-high work plane under IES panels, and the view in false colour.",
    ),
    (
        "radiosity scenes/table_chair.sc -o table.png --checkpoint table.ckpt",
        "Saves the solve as it goes; after a Ctrl-C, add --resume table.ckpt to go on.",
    ),
];

/// The text after the options in `--help`: [`EXAMPLES`], then the exit
/// codes.
fn after_long_help() -> String {
    let mut text = String::from("Examples (in the project's folder):\n");
    for (command, what) in EXAMPLES {
        text.push_str(&format!("  {command}\n      {what}\n"));
    }
    text.push('\n');
    text.push_str(EXIT_CODES);
    text
}

/// The text after the options in `-h`: where the rest is, then the exit
/// codes.
fn after_short_help() -> String {
    format!(
        "--help shows each option in full, the switches that compare the solver \
         with its brute-force twins, and examples.\n\n{EXIT_CODES}"
    )
}

/// The command's definition as the program parses it: the long help of
/// every option that quotes a tuning constant filled in from it, and the
/// footers of `-h` and `--help`.
pub fn command() -> clap::Command {
    Args::command()
        .after_help(after_short_help())
        .after_long_help(after_long_help())
        .mut_arg("no_near_field", |a| a.long_help(near_field()))
        .mut_arg("no_clustering", |a| a.long_help(clustering()))
        .mut_arg("exact_receivers", |a| a.long_help(exact_receivers()))
        .mut_arg("no_overshoot", |a| a.long_help(overshoot()))
}

/// Parses the process's arguments with [`command`]'s help.
pub fn parse() -> Result<Args, clap::Error> {
    parse_from(std::env::args_os())
}

/// Parses `args` (the program's name first) with [`command`]'s help,
/// refusing an option given without the one it needs
/// (the table in `cli/needs.rs`).
pub fn parse_from<I, T>(args: I) -> Result<Args, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let mut command = command();
    let matches = command.try_get_matches_from_mut(args)?;
    let args = <Args as clap::FromArgMatches>::from_arg_matches(&matches)?;
    match super::needs::unmet(&matches, &args) {
        Some(message) => {
            Err(command.error(clap::error::ErrorKind::MissingRequiredArgument, message))
        }
        None => Ok(args),
    }
}

/// A fraction as a percentage with as few digits as it needs (`0.02` →
/// `2 %`, `0.003` → `0.3 %`).
fn percent(f: f64) -> String {
    format!("{} %", (f * 1000.0).round() / 10.0)
}

fn near_field() -> String {
    format!(
        "Use the disc approximation however near the receiver.\n\n\
         Every shooter sample then uses the plain disc approximation \
         a/(πr² + a); by default the exact point-to-cell form factor is used \
         within {EXACT_RATIO} cell diameters, a quadrature of the cell to \
         {NEAR_FIELD_RATIO}."
    )
}

fn clustering() -> String {
    format!(
        "Shoot every polygon alone (the solver without clusters).\n\n\
         By default nearby small polygons (a tessellated sphere, a chair) \
         shoot their unshot power together in one step, from strata of their \
         cells; no cluster is more than {CLUSTER_EXTENT} of the scene's \
         diagonal across, and emitters always shoot alone. This is the \
         brute-force twin, for comparison."
    )
}

fn exact_receivers() -> String {
    format!(
        "Evaluate every receiving vertex exactly, in every step.\n\n\
         By default, with clusters, a step of reflected light evaluates large \
         receiving grids at every {stride}th row and column and at a check \
         vertex in each cell between, and interpolates the cell's other \
         vertices where the corners predict the check vertex within {check} \
         (or {weak} of what it already holds), and a vertex takes a nearby \
         part of the shooting cluster as one term when its light there is too \
         weak to matter (within {stratum} of what the vertex holds). A facet \
         under {facet} of an element across asks one shadow ray per shooter \
         sample for all its vertices, in every step, and a vertex asks \
         {SKY_PROBES} of a sky facet's {SKY_FACET_SAMPLES} directions first, \
         the others only when those disagree (a sky gathered at once: one of \
         each {SKY_CELL_STRATA} × {SKY_CELL_STRATA} of its hemisphere's \
         directions, five near the horizon, then the rest of those along an \
         edge, a dark patch one further off from an opening its four corners \
         first); a vertex {FAR_SHOOTER_RATIO} or \
         more diameters from a lamp asks {FAR_PROBES} of its samples first, the \
         others only when those disagree. Vertices of polygons of one surface \
         at one point (coplanar, or smooth within {SHARE_CREASE_DEG}°) take \
         the value of the first of them. Emitters' shots are otherwise always \
         exact. This is the exact twin, for comparison (`--without` turns off \
         one of these at a time).",
        stride = RECEIVER_STRIDE,
        check = percent(CHECK_TOLERANCE),
        weak = percent(RECEIVER_WEAK_SHARE),
        stratum = percent(WEAK_STRATUM_SHARE),
        facet = FACET_SCALE_RATIO,
    )
}

fn overshoot() -> String {
    format!(
        "Shoot exactly the unshot light, never more.\n\n\
         By default each point of a shooter also sends out the light it can \
         expect to receive later (what it has received so far times the ratio \
         of light still to come to light shot, at most {OVERSHOOT_SHARE} of its \
         reflectance times the ambient term), which converges in fewer steps; \
         what it sent ahead and never received is taken back by steps of \
         negative light. This is the original algorithm, for comparison."
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `--help` prints for `id`.
    fn long_help(id: &str) -> String {
        let command = command();
        let arg = command
            .get_arguments()
            .find(|a| a.get_id() == id)
            .unwrap_or_else(|| panic!("no option {id}"));
        arg.get_long_help().expect("a long help").to_string()
    }

    #[test]
    fn the_help_quotes_the_constants_the_solver_uses() {
        let receivers = long_help("exact_receivers");
        for quoted in [
            format!("every {RECEIVER_STRIDE}th row"),
            format!("{SKY_PROBES} of a sky facet's {SKY_FACET_SAMPLES} directions"),
            format!("one of each {SKY_CELL_STRATA} × {SKY_CELL_STRATA}"),
            format!("{FAR_SHOOTER_RATIO} or more diameters"),
            format!("asks {FAR_PROBES} of its samples"),
            format!("smooth within {SHARE_CREASE_DEG}°"),
            format!("within {}", percent(CHECK_TOLERANCE)),
        ] {
            assert!(receivers.contains(&quoted), "{quoted:?} not in {receivers}");
        }
        assert!(long_help("no_near_field").contains(&format!("within {EXACT_RATIO} cell")));
        assert!(long_help("no_clustering").contains(&format!("{CLUSTER_EXTENT} of the scene")));
        assert!(long_help("no_overshoot").contains(&format!("at most {OVERSHOOT_SHARE} of")));
    }

    #[test]
    fn percentages_keep_their_digits() {
        assert_eq!(percent(0.02), "2 %");
        assert_eq!(percent(0.003), "0.3 %");
        assert_eq!(percent(0.001), "0.1 %");
    }

    /// Every option sits under a heading, and `-h` leaves out exactly the
    /// switches that compare the solver with its brute-force twins.
    #[test]
    fn options_are_grouped_and_comparison_switches_are_long_help_only() {
        let command = command();
        let mut hidden = Vec::new();
        for arg in command.get_arguments() {
            assert!(
                arg.get_help_heading().is_some(),
                "{} has no heading",
                arg.get_id()
            );
            if arg.is_hide_short_help_set() {
                hidden.push(arg.get_id().as_str());
            }
        }
        hidden.sort_unstable();
        assert_eq!(
            hidden,
            [
                "exact",
                "exact_receivers",
                "hemicube_res",
                "no_clustering",
                "no_near_field",
                "no_overshoot",
                "no_shaft_culling",
                "unshot",
                "without",
            ]
        );
    }

    #[test]
    fn the_long_help_parses_as_the_derived_command_does() {
        let args = parse_from(["radiosity", "scene.sc", "--exact-receivers"]).unwrap();
        assert!(args.exact_receivers);
        command().debug_assert();
    }
}
