//! Every `radiosity …` command shown in `README.md` and `docs/guide.md`
//! runs here as written, so the docs cannot drift from the program: in
//! `sh` code blocks (continued across trailing `\`) and in inline code.
//! Each runs in a fresh folder holding the files the docs name (the
//! tutorial's `room.sc` taken from the guide itself, real exported models
//! from `tests/models/` for `room.glb`, `house.glb` and `cornell.obj`),
//! must exit 0 and write every file it names; where the docs show what a
//! command prints (a plain code block right after it), the block must be
//! an excerpt of what it printed (standard output, then standard error),
//! and where a table row gives a command's mesh (`| 14,206 vertices |`),
//! `--stats` must count as many.
//!
//! Finding the commands and their shown output is this file's own work (in
//! `sh` blocks, inline code and table rows, which `trycmd` cannot read);
//! running them and matching the output is `snapbox`'s: a shown block may
//! use its wildcards, `...` on a line of its own for lines left out and
//! `[..]` for the part of a line that varies with the machine (seconds).
//!
//! Real models are solved for a few steps only (`--max-steps` is added);
//! the bundled `.sc` scenes run to convergence, as the docs say.

mod common;

use common::*;
use std::path::{Path, PathBuf};

/// A command found in the docs, and the lines the docs show it printing.
#[derive(Debug)]
struct Documented {
    file: &'static str,
    line: usize,
    command: String,
    prints: Vec<String>,
    /// The element vertices a table row gives beside the command
    /// (`| 14,206 vertices |`), checked against `--stats`.
    vertices: Option<u64>,
}

const DOCS: [&str; 2] = ["README.md", "docs/guide.md"];

/// The commands of one document (see the module docs).
fn commands_of(file: &'static str) -> Vec<Documented> {
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        let line = lines[k];
        if line.trim_start().starts_with("```sh") {
            k += 1;
            let mut found = Vec::new();
            let mut current = String::new();
            let mut at = 0;
            while k < lines.len() && !lines[k].trim_start().starts_with("```") {
                let l = strip_comment(lines[k]);
                if current.is_empty() && l.trim_start().starts_with("radiosity ") {
                    at = k + 1;
                }
                if !current.is_empty() || l.trim_start().starts_with("radiosity ") {
                    let (body, more) = match l.trim_end().strip_suffix('\\') {
                        Some(b) => (b, true),
                        None => (l, false),
                    };
                    current.push_str(body.trim());
                    current.push(' ');
                    if !more {
                        found.push((at, current.trim().to_string()));
                        current.clear();
                    }
                }
                k += 1;
            }
            k += 1;
            // A plain block right after (blank lines between) is what a
            // lone command prints.
            let mut n = k;
            while n < lines.len() && lines[n].trim().is_empty() {
                n += 1;
            }
            let mut prints = Vec::new();
            if found.len() == 1 && n < lines.len() && lines[n].trim() == "```" {
                n += 1;
                while n < lines.len() && lines[n].trim() != "```" {
                    prints.push(lines[n].to_string());
                    n += 1;
                }
            }
            let single = found.len() == 1;
            for (line, command) in found {
                out.push(Documented {
                    file,
                    line,
                    command,
                    prints: if single { prints.clone() } else { Vec::new() },
                    vertices: None,
                });
            }
            continue;
        }
        // Inline code spans that are whole commands.
        for (i, span) in line.split('`').enumerate() {
            if i % 2 == 1 && is_inline_command(span) {
                out.push(Documented {
                    file,
                    line: k + 1,
                    command: span.to_string(),
                    prints: Vec::new(),
                    vertices: vertices_in_row(line),
                });
            }
        }
        k += 1;
    }
    out
}

/// `radiosity` followed by an option or a file name (not a window
/// title's `radiosity — …`).
fn is_inline_command(span: &str) -> bool {
    let mut words = span.split_whitespace();
    words.next() == Some("radiosity")
        && words
            .next()
            .is_some_and(|w| w.starts_with('-') || w.contains('.'))
}

/// `N` of a table row's `| N vertices |` cell.
fn vertices_in_row(line: &str) -> Option<u64> {
    line.split('|')
        .map(str::trim)
        .find_map(|cell| cell.strip_suffix(" vertices"))
        .and_then(|n| n.replace(',', "").parse().ok())
}

/// The line without a trailing shell comment.
fn strip_comment(line: &str) -> &str {
    match line.find(" #") {
        Some(k) => &line[..k],
        None => line,
    }
}

/// Options whose value is a file the command writes.
const OUTPUT_OPTIONS: [&str; 10] = [
    "-o",
    "--export",
    "--lightmap",
    "--lightmap-texture",
    "--log",
    "--plot",
    "--stats",
    "--falsecolor",
    "--checkpoint",
    "--illuminance-out",
];

/// Files the docs name as inputs, and where the test takes them from.
fn fixture(dir: &Path, name: &str) -> Option<()> {
    let models = root().join("tests/models");
    let copy = |from: PathBuf, to: &str| {
        std::fs::copy(&from, dir.join(to)).unwrap_or_else(|e| panic!("{}: {e}", from.display()));
    };
    match name {
        "room.sc" => {
            write(dir, "room.sc", &tutorial_room());
        }
        "big.sc" => copy(scene("cornell.sc"), "big.sc"),
        "room.obj" | "model.obj" => {
            write(dir, name, BLENDER_ROOM);
        }
        "house.glb" => copy(models.join("raylib/greenman.glb"), "house.glb"),
        "room.glb" => copy(models.join("godot/room.glb"), "room.glb"),
        "cornell.obj" => {
            copy(
                models.join("mcguire/CornellBox-Original.obj"),
                "cornell.obj",
            );
            copy(
                models.join("mcguire/CornellBox-Original.mtl"),
                "CornellBox-Original.mtl",
            );
        }
        "camera.sc" => copy(models.join("mcguire/camera.sc"), "camera.sc"),
        "floor.sc" => {
            write(dir, "floor.sc", OPEN_FLOOR);
        }
        _ => return None,
    }
    Some(())
}

/// The tutorial's `room.sc`: the guide's code block after "Save this as
/// `room.sc`".
fn tutorial_room() -> String {
    let guide = std::fs::read_to_string(root().join("docs/guide.md")).unwrap();
    let at = guide
        .find("Save this as `room.sc`")
        .expect("the guide's tutorial saves room.sc");
    let rest = &guide[at..];
    let open = rest.find("```\n").expect("a code block follows") + 4;
    let close = rest[open..].find("```").unwrap();
    rest[open..open + close].to_string()
}

/// The daylight section's open floor: 10 × 10 m of reflectance 0.5,
/// facing up, nothing above it, and a camera looking down at it.
const OPEN_FLOOR: &str = "camera\n  eye 5 6 4\n  lookat 5 0 -5\nend\nmaterial floor\n  color 0.5 0.5 0.5\n  k_diffrefl 1\nend\n\
polygon floor\n  vertex 0 0 0\n  vertex 10 0 0\n  vertex 10 0 -10\n  vertex 0 0 -10\nend\n";

/// A room as Blender exports a scaled cube: faces pointing out, a `Lamp`
/// plane under the ceiling and a box on the floor, no materials.
const BLENDER_ROOM: &str = "\
o Room
v -2 0 -2
v 2 0 -2
v 2 0 2
v -2 0 2
v -2 3 -2
v 2 3 -2
v 2 3 2
v -2 3 2
f 1 2 3 4
f 5 8 7 6
f 1 5 6 2
f 2 6 7 3
f 3 7 8 4
f 4 8 5 1
o Lamp
v -0.5 2.95 -0.5
v 0.5 2.95 -0.5
v 0.5 2.95 0.5
v -0.5 2.95 0.5
f 9 10 11 12
o Box
v 0.3 0 0.3
v 1.1 0 0.3
v 1.1 0 1.1
v 0.3 0 1.1
v 0.3 0.8 0.3
v 1.1 0.8 0.3
v 1.1 0.8 1.1
v 0.3 0.8 1.1
f 13 14 15 16
f 17 20 19 18
f 13 17 18 14
f 14 18 19 15
f 15 19 20 16
f 16 20 17 13
";

/// The files a command's arguments name: `(inputs, outputs)`.
fn files_of(args: &[String]) -> (Vec<String>, Vec<String>) {
    let (mut inputs, mut outputs) = (Vec::new(), Vec::new());
    let mut k = 0;
    while k < args.len() {
        let a = &args[k];
        if OUTPUT_OPTIONS.contains(&a.as_str()) && k + 1 < args.len() {
            outputs.push(args[k + 1].clone());
            k += 2;
            continue;
        }
        if a == "--workplane-out" && k + 1 < args.len() {
            outputs.push(format!("{}.csv", args[k + 1]));
            outputs.push(format!("{}.png", args[k + 1]));
            k += 2;
            continue;
        }
        // `NAME=FILE` (`--ies`) names a file after the `=`; a file name
        // ends in an extension of letters (`0.75,0.1` is no file).
        let name = a.rsplit('=').next().unwrap_or(a);
        let extension = name.rsplit_once('.').map(|(_, e)| e);
        if !a.starts_with('-')
            && extension
                .is_some_and(|e| !e.is_empty() && e.chars().all(|c| c.is_ascii_alphabetic()))
        {
            inputs.push(name.to_string());
        }
        k += 1;
    }
    (inputs, outputs)
}

/// The program with `args` in `dir`, with no display (a documented
/// command writes its files; it opens no window).
fn radiosity(dir: &Path, args: &[String]) -> snapbox::cmd::Command {
    snapbox::cmd::Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .current_dir(dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
}

fn run_documented(doc: &Documented) {
    let at = format!("{}:{}: `{}`", doc.file, doc.line, doc.command);
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(root().join("scenes"), dir.path().join("scenes")).unwrap();
    let mut args: Vec<String> = doc
        .command
        .split_whitespace()
        .skip(1)
        .map(String::from)
        .collect();
    let (inputs, outputs) = files_of(&args);
    for input in &inputs {
        // `--resume big.ckpt` reads what the command before it wrote.
        if input.starts_with("scenes/") || input.ends_with(".ckpt") || outputs.contains(input) {
            continue;
        }
        if fixture(dir.path(), input).is_none() {
            panic!("{at}: the docs name `{input}`; give it a fixture in tests/doc_commands.rs");
        }
    }
    let resumes = args.iter().any(|a| a == "--resume");
    if resumes {
        // The run it resumes, as the docs show it just before.
        let mut first = args.clone();
        let k = first.iter().position(|a| a == "--resume").unwrap();
        first.drain(k..k + 2);
        first.extend(["--max-steps".to_string(), "5".to_string()]);
        println!("running {at} (the run it resumes)");
        radiosity(dir.path(), &first).assert().success();
    }
    let real_model = inputs
        .iter()
        .any(|i| i.ends_with(".obj") || i.ends_with(".glb") || i.ends_with(".gltf"));
    let solves = !args.iter().any(|a| a == "--info" || a == "--help");
    if real_model && solves && !args.iter().any(|a| a == "--max-steps") {
        args.extend(["--max-steps".to_string(), "5".to_string()]);
    }
    // A row's mesh size is read back from `--stats` (added when the
    // command has none of its own).
    let stats = match args.iter().position(|a| a == "--stats") {
        Some(k) => args[k + 1].clone(),
        None if doc.vertices.is_some() => {
            args.extend(["--stats".to_string(), "doc-stats.json".to_string()]);
            "doc-stats.json".to_string()
        }
        None => String::new(),
    };
    // Said first, so that a failure below (whose message is snapbox's:
    // the exit code, standard output and error) names the documented line.
    println!("running {at}");
    let run = radiosity(dir.path(), &args).assert().success();
    let o = run.get_output();
    let err = stderr(o);
    assert!(!err.contains("panicked"), "{at}: {err}");
    // A documented command makes a picture worth looking at.
    assert!(!err.contains("nearly black"), "{at}: {err}");
    for output in &outputs {
        assert!(
            dir.path().join(output).is_file(),
            "{at}: wrote no {output}: {err}"
        );
    }
    if let Some(vertices) = doc.vertices {
        let text = std::fs::read_to_string(dir.path().join(&stats)).unwrap();
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(
            json["vertices"].as_u64(),
            Some(vertices),
            "{at}: the docs give {vertices} vertices"
        );
    }
    if !doc.prints.is_empty() {
        let printed = format!("{}{err}", String::from_utf8_lossy(&o.stdout));
        snapbox::Assert::new()
            .try_eq(Some(&at), printed.into(), shown(&doc.prints).into())
            .unwrap_or_else(|e| panic!("{at}: the docs show other output:\n{e}"));
    }
}

/// The snapbox pattern the docs' shown lines make: an excerpt, so any
/// lines before and after it.
fn shown(prints: &[String]) -> String {
    format!("...\n{}\n...\n", prints.join("\n"))
}

#[test]
fn the_docs_show_commands_to_run() {
    // So that a change to the extraction cannot make the test vacuous.
    let all: Vec<Documented> = DOCS.iter().flat_map(|f| commands_of(f)).collect();
    assert!(all.len() >= 15, "{all:#?}");
    assert!(all.iter().any(|d| !d.prints.is_empty()), "{all:#?}");
    assert!(all.iter().any(|d| d.vertices.is_some()), "{all:#?}");
}

/// The README a newcomer reads first stays short (about ten minutes), and
/// gets to their own model early: the formats in its opening paragraph,
/// then the two commands, then a model of theirs lit (`--emit`) and taken
/// elsewhere (`--export`) within its first 60 lines, all of it run by the
/// tests above.
#[test]
fn the_readme_is_short_and_lights_your_own_model_early() {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.len() <= 200, "README.md has {} lines", lines.len());
    let first = |what: &str| lines.iter().position(|l| l.contains(what));
    assert!(first("OBJ").is_some_and(|k| k < 10), "OBJ late");
    assert!(first("glTF").is_some_and(|k| k < 10), "glTF late");
    let commands = first("## The two commands").expect("the two commands");
    let own = first("## Your own model").expect("your own model");
    assert!(commands < own && own < 60, "{commands} {own}");
    let own_commands: Vec<Documented> = commands_of("README.md")
        .into_iter()
        .filter(|d| d.line > own && d.line < 60)
        .collect();
    for option in ["--emit", "--export"] {
        assert!(
            own_commands.iter().any(|d| d.command.contains(option)),
            "no `radiosity … {option}` under \"Your own model\": {own_commands:#?}"
        );
    }
}

/// What a shown block accepts, without running the program: the lines in
/// order anywhere in the output, `[..]` for what varies; a changed figure
/// anywhere else fails.
#[test]
fn a_shown_block_is_an_excerpt_with_wildcards() {
    let printed = "warning: something\nroom.sc: 33 steps, 0.59 s solving, 2.9 M rays\nwrote x\n";
    let matches = |lines: &[&str]| {
        let lines: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        snapbox::Assert::new()
            .try_eq(None, printed.into(), shown(&lines).into())
            .is_ok()
    };
    assert!(matches(&["room.sc: 33 steps, [..] s solving, 2.9 M rays"]));
    assert!(matches(&[
        "room.sc: 33 steps, 0.59 s solving, 2.9 M rays",
        "wrote x"
    ]));
    assert!(matches(&["warning: something", "...", "wrote x"]));
    assert!(!matches(&["room.sc: 34 steps, [..] s solving, 2.9 M rays"]));
    assert!(!matches(&["room.sc: 33 steps, [..] s solving, 3.0 M rays"]));
    assert!(!matches(&["wrote x", "warning: something"]));
    assert!(!matches(&["room.sc: 33 steps, 0.60 s solving, 2.9 M rays"]));
}

#[test]
fn every_command_in_the_readme_runs_as_written() {
    for doc in commands_of("README.md") {
        run_documented(&doc);
    }
}

#[test]
fn every_command_in_the_guide_runs_as_written() {
    for doc in commands_of("docs/guide.md") {
        run_documented(&doc);
    }
}
