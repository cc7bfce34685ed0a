//! The lines of the window's state panel (drawn by
//! [`crate::render::text::draw_panel`]) and of its title: how far the
//! solve is, the exposure, the mesh, the navigation and the keys, what a
//! key asked of the terminal, and what the last key did. Pure text, so it
//! is tested without a window.

use super::Navigation;
use crate::solver::StopReason;

/// How far the solve is, for the panel's first line and the title.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveState {
    /// Shooting steps taken.
    pub step: u64,
    /// Unshot power left, as a fraction of the emitted power.
    pub unshot: f64,
    /// Rays cast per second of solving, in millions.
    pub mrays_per_second: f64,
    /// Why the solve stopped, once it has.
    pub stopped: Option<StopReason>,
    /// True when something emits (else nothing is solved).
    pub emits: bool,
    /// The solver is paused (space).
    pub paused: bool,
    /// The adaptive pass running (1 for the first solve) and how many
    /// refinements may follow at most.
    pub pass: (u32, u32),
}

/// The first line: `step 12 · unshot 3.204% · 2.1 Mrays/s`, then how the
/// solve stopped or that it is paused; `starting` before the first step
/// (when the unshot power is not yet measured).
pub fn status(s: &SolveState) -> String {
    let state = match s.stopped {
        // Nothing was solved: the load warning said why.
        Some(_) if !s.emits => " · nothing emits".into(),
        Some(StopReason::Converged) if s.pass.0 > 1 => {
            format!(" · converged after {} refinements", s.pass.0 - 1)
        }
        Some(StopReason::Converged) => " · converged".into(),
        Some(StopReason::MaxSteps) => " · step limit".into(),
        None if s.paused => " · paused".into(),
        None => String::new(),
    };
    let refining = match s.pass {
        (1, _) | (_, 0) => String::new(),
        (k, levels) => format!("refinement {}/{levels} · ", k - 1),
    };
    if s.step == 0 && s.stopped.is_none() {
        return format!("{refining}starting{state}");
    }
    format!(
        "{refining}step {} · unshot {:.3}% · {:.1} Mrays/s{state}",
        s.step,
        s.unshot * 100.0,
        s.mrays_per_second
    )
}

/// `x` with four significant digits, without trailing zeros.
fn four_digits(x: f32) -> String {
    if !(x.is_finite() && x > 0.0) {
        return format!("{x}");
    }
    let decimals = (3.0 - f64::from(x).log10().floor()).clamp(0.0, 12.0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The exposure: the factor the picture is shown with, whether it is
/// automatic or `--exposure`'s, and how many stops `+`/`-` moved it.
pub fn exposure(factor: f32, automatic: bool, scale: f32) -> String {
    let source = if automatic { "auto" } else { "given" };
    let stops = scale.log2();
    let moved = if stops.abs() < 0.05 {
        String::new()
    } else {
        let unit = if (stops.abs() - 1.0).abs() < 0.05 {
            "stop"
        } else {
            "stops"
        };
        format!(" {stops:+.1} {unit}")
    };
    format!("exposure {} ({source}{moved})", four_digits(factor))
}

/// The mesh: its element count and whether its lines are drawn (`m`).
pub fn mesh(elements: usize, lines_shown: bool) -> String {
    let lines = if lines_shown { ", lines shown" } else { "" };
    format!(
        "{} elements{lines}",
        crate::budget::fmt_count(elements as u64)
    )
}

/// The keys line, after the left-drag mode.
pub fn keys(navigation: Navigation) -> String {
    format!(
        "{} · c: camera · f: full quality · h: help",
        navigation.name()
    )
}

/// The line shown while `w` waits for a file name typed in the terminal.
pub fn prompt(default: &std::path::Path) -> String {
    format!(
        "w: type a file name in the terminal (Enter: {})",
        default.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(step: u64) -> SolveState {
        SolveState {
            step,
            unshot: 0.03204,
            mrays_per_second: 2.14,
            stopped: None,
            emits: true,
            paused: false,
            pass: (1, 0),
        }
    }

    #[test]
    fn step_zero_is_starting_not_a_measured_unshot_power() {
        let s = SolveState {
            unshot: 0.0,
            mrays_per_second: 0.0,
            ..state(0)
        };
        assert_eq!(status(&s), "starting");
        assert_eq!(
            status(&SolveState { paused: true, ..s }),
            "starting · paused"
        );
        assert_eq!(status(&state(12)), "step 12 · unshot 3.204% · 2.1 Mrays/s");
        // A solve that stopped at step 0 says why.
        let dark = SolveState {
            stopped: Some(StopReason::Converged),
            emits: false,
            ..s
        };
        assert_eq!(
            status(&dark),
            "step 0 · unshot 0.000% · 0.0 Mrays/s · nothing emits"
        );
        let refined = SolveState {
            stopped: Some(StopReason::Converged),
            pass: (3, 2),
            ..state(40)
        };
        assert!(status(&refined).starts_with("refinement 2/2 · step 40"));
        assert!(status(&refined).ends_with("converged after 2 refinements"));
    }

    #[test]
    fn the_exposure_says_the_factor_its_source_and_the_stops() {
        assert_eq!(exposure(2.4171, true, 1.0), "exposure 2.417 (auto)");
        assert_eq!(
            exposure(3690.4, true, 1.26f32.powi(3)),
            "exposure 3690 (auto +1.0 stop)"
        );
        assert_eq!(
            exposure(0.5, false, 1.0 / 1.26f32.powi(2)),
            "exposure 0.5 (given -0.7 stops)"
        );
        assert_eq!(four_digits(0.000123456), "0.0001235");
    }

    #[test]
    fn the_mesh_and_keys() {
        assert_eq!(mesh(13_257, false), "13,257 elements");
        assert_eq!(mesh(1, true), "1 elements, lines shown");
        assert_eq!(
            keys(Navigation::Orbit),
            "orbit · c: camera · f: full quality · h: help"
        );
        assert_eq!(
            prompt(std::path::Path::new("rtable-001.tiff")),
            "w: type a file name in the terminal (Enter: rtable-001.tiff)"
        );
    }
}
