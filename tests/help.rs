//! Help that teaches and usage errors that say what to do: `-h` grouped
//! under headings, the comparison switches and the examples in `--help`
//! only, every example run as printed, every option that needs another
//! refused alike without it, negative values reaching the range checks.

mod common;

use common::*;

/// Standard output of a run, as text.
fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The example commands `--help` ends with, one argument list each
/// (without the program's name), lines continued with ` \` joined.
fn help_examples() -> Vec<Vec<String>> {
    let out = run_in(&root(), &["--help"]);
    assert!(out.status.success());
    let help = stdout(&out);
    let examples = help.split_once("Examples").expect("--help has examples").1;
    let mut commands = Vec::new();
    let mut lines = examples.lines();
    while let Some(line) = lines.next() {
        let Some(command) = line.trim_start().strip_prefix("radiosity ") else {
            continue;
        };
        let mut command = command.to_string();
        while command.ends_with('\\') {
            command.pop();
            command.push(' ');
            command.push_str(lines.next().expect("a continued line").trim());
        }
        commands.push(command.split_whitespace().map(String::from).collect());
    }
    commands
}

/// Every command `--help` shows runs as shown, in a fresh folder with the
/// bundled scenes named from the project's, limited to a few steps.
#[test]
fn every_example_in_the_help_runs() {
    let examples = help_examples();
    assert!(
        (4..=6).contains(&examples.len()),
        "{} examples",
        examples.len()
    );
    let root = root();
    for example in examples {
        let dir = tempfile::tempdir().unwrap();
        // Bundled files are named from the project's folder.
        let mut args: Vec<String> = example
            .iter()
            .map(|a| {
                if a.starts_with("scenes/") {
                    root.join(a).display().to_string()
                } else if let Some((name, file)) = a.split_once("=scenes/") {
                    format!("{name}={}", root.join("scenes").join(file).display())
                } else {
                    a.clone()
                }
            })
            .collect();
        args.extend(["--max-steps", "3", "-q"].map(String::from));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_in(dir.path(), &args);
        assert!(
            out.status.success(),
            "radiosity {}: {}",
            example.join(" "),
            stderr(&out)
        );
        let written = listing(dir.path());
        for (k, a) in example.iter().enumerate() {
            if ["-o", "--export", "--falsecolor", "--checkpoint"].contains(&a.as_str()) {
                let file = &example[k + 1];
                assert!(written.contains(file), "{example:?} wrote {written:?}");
            }
        }
        assert!(!written.is_empty(), "{example:?} wrote nothing");
    }
}

/// True when `help` has a line for `option`.
fn lists(help: &str, option: &str) -> bool {
    help.lines().any(|l| {
        l.trim_start().starts_with('-')
            && l.split_whitespace()
                .any(|w| w.trim_end_matches(',') == option)
    })
}

/// `-h` groups the options under headings and leaves out the switches
/// that compare the solver with its brute-force twins; `--help` has them,
/// and ends with the examples and the exit codes.
#[test]
fn short_help_is_grouped_and_comparison_switches_are_in_long_help() {
    let short = stdout(&run_in(&root(), &["-h"]));
    let long = stdout(&run_in(&root(), &["--help"]));
    for heading in [
        "Input:",
        "Output:",
        "Mesh and solver:",
        "Camera and picture:",
        "Light:",
        "Window:",
        "Long solves:",
        "Photometry:",
    ] {
        assert!(
            short.lines().any(|l| l == heading),
            "-h lacks {heading}\n{short}"
        );
        assert!(long.lines().any(|l| l == heading), "--help lacks {heading}");
    }
    for switch in [
        "--no-near-field",
        "--no-shaft-culling",
        "--no-clustering",
        "--exact-receivers",
        "--no-overshoot",
        "--without",
        "--exact",
        "--unshot",
        "--hemicube-res",
    ] {
        assert!(!lists(&short, switch), "-h shows {switch}");
        assert!(lists(&long, switch), "--help lacks {switch}");
    }
    for everyday in ["--emit", "--sky", "--lenmax", "--exposure", "--export"] {
        assert!(lists(&short, everyday), "-h lacks {everyday}");
    }
    assert!(!short.contains("Examples"), "{short}");
    let examples = long.find("Examples").expect("--help ends with examples");
    let codes = long.rfind("Exit codes:").expect("and the exit codes");
    assert!(examples < codes);
}

/// The help is written for the command line, not rustdoc: no doc-link
/// brackets or private item paths leak from the code's doc comments into
/// what `-h` and `--help` print (the values' lists included).
#[test]
fn help_shows_no_rustdoc_links() {
    for flag in ["-h", "--help"] {
        let help = stdout(&run_in(&root(), &[flag]));
        for (n, line) in help.lines().enumerate() {
            assert!(
                !line.contains("[`") && !line.contains("::"),
                "{flag} line {}: {line}",
                n + 1
            );
        }
    }
}

/// Each option that means something only with another is refused
/// without it, with one message of one form naming what it needs, exit
/// code 2, and nothing written.
#[test]
fn an_option_without_the_one_it_needs_is_one_error_naming_it() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["--falsecolor-max", "100"],
            "--falsecolor-max needs --falsecolor or --workplane",
        ),
        (
            &["--falsecolor-scale", "linear"],
            "--falsecolor-scale needs --falsecolor or --workplane",
        ),
        (
            &["--falsecolor-of", "illuminance"],
            "--falsecolor-of needs --falsecolor",
        ),
        (
            &["--workplane", "0.8", "--falsecolor-of", "illuminance"],
            "--falsecolor-of needs --falsecolor",
        ),
        (
            &["--hemicube-res", "64"],
            "--hemicube-res needs --form-factor hemicube",
        ),
        (
            &["--form-factor", "center", "--hemicube-res", "64"],
            "--hemicube-res needs --form-factor hemicube",
        ),
        (
            &["--checkpoint-every", "5"],
            "--checkpoint-every needs --checkpoint",
        ),
        (
            &["--resume", "x.ckpt", "--checkpoint-every", "5"],
            "--checkpoint-every needs --checkpoint",
        ),
        (
            &["--adaptive-threshold", "0.1"],
            "--adaptive-threshold needs --adaptive",
        ),
        (
            &["--adaptive-levels", "3"],
            "--adaptive-levels needs --adaptive",
        ),
        (
            &["--adaptive-max-splits", "300"],
            "--adaptive-max-splits needs --adaptive",
        ),
        (
            &["--illuminance-out", "e.csv"],
            "--illuminance-out needs --illuminance-at",
        ),
        (
            &["--illuminance-at", "p.csv"],
            "--illuminance-at needs --illuminance-out",
        ),
        (
            &["--workplane-out", "plan"],
            "--workplane-out needs --workplane",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (args, message) in cases {
        let out = run_in(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        let first = stderr(&out).lines().next().unwrap_or_default().to_string();
        assert_eq!(first, format!("error: {message}"), "{args:?}");
    }
    assert!(listing(dir.path()).is_empty());
    // With what they need they are accepted (and checked for range).
    let out = run_in(
        dir.path(),
        &[
            "--workplane",
            "0.8",
            "--falsecolor-max",
            "-1",
            "--no-window",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).starts_with("error: --falsecolor-max must be a positive number, got -1"),
        "{}",
        stderr(&out)
    );
}

/// A negative number after an option is its value: it reaches the
/// option's range check and gets that message, not clap's "unexpected
/// argument".
#[test]
fn negative_values_get_the_range_message() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["--lenmax", "-1"],
            "error: --lenmax must be a positive number of scene units, got -1",
        ),
        (
            &["--threshold", "-0.5"],
            "error: --threshold must be between 0 and 1, got -0.5",
        ),
        (
            &["--settle", "-1"],
            "error: --settle must be at least 0 and below 1, got -1",
        ),
        (
            &["--inset", "-0.1"],
            "error: --inset must be at least 0 and below 0.5",
        ),
        (
            &["--sky", "-1,2,3"],
            "--sky must look like 1 or 0.8,0.9,1.2",
        ),
        (
            &["--workplane", "-1"],
            "--workplane must look like 0.8 or 0.8,0.25",
        ),
        (&["--size", "-1x5"], "--size must look like 640x480"),
        (&["--aa", "-1"], "-1 is not in 1..=8"),
        (
            &["--max-steps", "-1"],
            "'--max-steps <N>': expected a whole number like 0, 200 or 2e5, got `-1`",
        ),
        (
            &["--threads", "-2"],
            "'--threads <N>': expected a whole number like 0, 200 or 2e5",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (args, message) in cases {
        let out = run_in(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = stderr(&out);
        assert!(err.contains(message), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
    }
}

/// A value that is not a number of the option's kind says what a good
/// one looks like, not the parser's "invalid digit found in string"; a
/// whole count may be written with an exponent.
#[test]
fn values_that_are_not_numbers_say_what_is_expected() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["--lenmax", "abc"],
            "'--lenmax <L>': expected a number like 0.5, 2 or 1e-3, got `abc`",
        ),
        (
            &["--exposure", "bright"],
            "'--exposure <STOPS>': expected a number like 0.5, 2 or 1e-3",
        ),
        (
            &["--max-steps", "1.5"],
            "'--max-steps <N>': expected a whole number like 0, 200 or 2e5, got `1.5`",
        ),
        (
            &["--adaptive-levels", "5000000000"],
            "expected a whole number like 0, 200 or 2e5 (at most 4294967295)",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell.sc");
    for (args, message) in cases {
        let mut all = vec![cornell.to_str().unwrap()];
        all.extend_from_slice(args);
        let out = run_in(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = stderr(&out);
        assert!(err.contains(message), "{args:?}: {err}");
        assert!(!err.contains("invalid digit"), "{args:?}: {err}");
    }
    let out = run_in(
        dir.path(),
        &[
            cornell.to_str().unwrap(),
            "--max-steps",
            "2e0",
            "-q",
            "-o",
            "x.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

/// A file that cannot be read is `FILE: error: cannot read: REASON`,
/// with no line and column (there is no text to point into), whichever
/// option names it; exit code 2 and nothing written.
#[test]
fn a_missing_file_is_reported_without_a_position() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell.sc");
    let cornell = cornell.to_str().unwrap();
    let office = scene("office.sc");
    let office = office.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["nosuch.sc"], "nosuch.sc"),
        (&["nosuch.obj"], "nosuch.obj"),
        (&["nosuch.glb"], "nosuch.glb"),
        (&[cornell, "--camera", "nocam.sc"], "nocam.sc"),
        (
            &[office, "--units", "m", "--ies", "luminaire=nosuch.ies"],
            "nosuch.ies",
        ),
        (
            &[
                cornell,
                "--illuminance-at",
                "nop.csv",
                "--illuminance-out",
                "e.csv",
            ],
            "nop.csv",
        ),
        (&[cornell, "--resume", "no.ckpt"], "no.ckpt"),
    ];
    for (args, file) in cases {
        let mut all = args.to_vec();
        all.extend(["-o", "out.png", "-q", "--max-steps", "1"]);
        let out = run_in(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).trim_end(),
            format!("{file}: error: cannot read: No such file or directory (os error 2)"),
            "{args:?}"
        );
        assert!(listing(dir.path()).is_empty(), "{args:?}");
    }
}

/// Without a display the run says it writes a file instead of opening a
/// window only once the scene has loaded: a scene with errors gets its
/// errors alone, not a promise of a picture that is never written.
#[test]
fn no_promise_of_a_picture_before_the_scene_has_loaded() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "broken.sc", "camera\n  eye 0 0\nend\nbogus\n");
    let out = run_in(dir.path(), &["broken.sc"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(!err.contains("instead"), "{err}");
    assert!(err.starts_with("broken.sc:"), "{err}");
    assert_eq!(listing(dir.path()), ["broken.sc"]);
    // A scene that loads still says it, and writes the picture.
    let cornell = scene("cornell.sc");
    let out = run_in(
        dir.path(),
        &[
            cornell.to_str().unwrap(),
            "--max-steps",
            "1",
            "--lenmax",
            "100",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("writing cornell.png in the current directory instead"),
        "{}",
        stderr(&out)
    );
    assert!(dir.path().join("cornell.png").exists());
}

/// Each output's format message lists the formats that output accepts,
/// and only those.
#[test]
fn a_format_message_lists_only_what_the_option_accepts() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene("cornell.sc");
    let cornell = cornell.to_str().unwrap();
    let eight_bit = ".png, .tif or .tiff";
    let cases: &[(&[&str], &str, String)] = &[
        (
            &["-o", "x.jpg"],
            "x.jpg",
            "unknown extension .jpg; supported picture formats are .png, .tif, .tiff, .exr, \
             .pfm, .hdr"
                .into(),
        ),
        (
            &["--falsecolor", "fc.exr"],
            "fc.exr",
            format!("--falsecolor writes an 8-bit picture: use {eight_bit}"),
        ),
        (
            &["--falsecolor", "fc.jpg"],
            "fc.jpg",
            format!(
                "unknown extension .jpg; --falsecolor writes an 8-bit picture: use {eight_bit}"
            ),
        ),
        (
            &["--plot", "p.hdr"],
            "p.hdr",
            format!("a plot is an 8-bit picture: use {eight_bit}"),
        ),
        (
            &["--mesh-lines", "-o", "m.pfm"],
            "m.pfm",
            format!("--mesh-lines draws on 8-bit pictures: use {eight_bit}"),
        ),
        (
            &["--export", "m.obj"],
            "m.obj",
            "unknown extension .obj; supported mesh formats are .glb, .ply".into(),
        ),
    ];
    for (args, file, reason) in cases {
        let mut all = vec![cornell, "-q"];
        all.extend_from_slice(args);
        if !args.contains(&"-o") {
            all.extend(["-o", "x.png"]);
        }
        let out = run_in(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert_eq!(
            stderr(&out).trim_end(),
            format!("error: cannot write {file}: {reason}"),
            "{args:?}"
        );
    }
    assert!(listing(dir.path()).is_empty());
}

/// `--tail`'s help states the automatic tail's start, mesh size and early
/// hand-over as the solver's tuning has them, and its refusals name what it takes.
#[test]
fn the_tail_help_quotes_the_tuning() {
    use radiosity::solver::tuning::{
        TAIL_AUTO_FROM, TAIL_AUTO_VERTICES, TAIL_COSTLY_RATIO, TAIL_EARLY_FROM,
    };
    let out = run_in(&root(), &["--help"]);
    let help = stdout(&out)
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let thousands = TAIL_AUTO_VERTICES / 1000;
    let (high, low) = (thousands / 1000, thousands % 1000);
    let vertices = if high > 0 {
        format!("{high},{low:03},000")
    } else {
        format!("{low},000")
    };
    let said =
        format!("turns it on from {TAIL_AUTO_FROM} on meshes of {vertices} element vertices");
    assert!(help.contains(&said), "--help lacks {said:?}");
    let early = format!(
        "or from up to {TAIL_EARLY_FROM} right after a shooting step that cost {TAIL_COSTLY_RATIO} times"
    );
    assert!(help.contains(&early), "--help lacks {early:?}");
    for bad in ["1.5", "-0.1", "sometimes"] {
        let out = run_in(&root(), &["--tail", bad, "--no-window"]);
        assert_eq!(out.status.code(), Some(2), "--tail {bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--tail must be `auto`, `off` or a fraction"),
            "{err}"
        );
    }
}

/// `--inset`'s help states how much farther in a one-element polygon's
/// corners are evaluated, as the mesher has it.
#[test]
fn the_inset_help_quotes_the_one_element_factor() {
    use radiosity::mesh::ONE_ELEMENT_INSET;
    let out = run_in(&root(), &["--help"]);
    let help = stdout(&out)
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let said = format!("has its corners evaluated {ONE_ELEMENT_INSET} times as far in");
    assert!(help.contains(&said), "--help lacks {said:?}");
}
