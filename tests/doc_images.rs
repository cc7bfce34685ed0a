//! Every picture README.md and the docs show (the dated changelog aside)
//! is made by a script or a documented command, so a picture can be
//! regenerated when the program changes instead of going stale:
//! `scripts/doc_images.sh` for the bundled scenes' pictures,
//! `docs/images/render_models.sh` for the exported models,
//! `scripts/window_shots.sh` for the window's screenshots (the real window
//! under Xvfb, driven by xdotool), and the `cargo run --example …` lines
//! the docs give for the plots.

mod common;

use common::*;

/// The scripts that make pictures: each lists them as `"NAME|…"` entries
/// (the picture is `NAME.png`), in the folder of `docs/images/` given.
const SCRIPTS: [(&str, &str); 3] = [
    ("scripts/doc_images.sh", ""),
    ("docs/images/render_models.sh", "models/"),
    ("scripts/window_shots.sh", ""),
];

/// The documents whose pictures must be reproducible.
const DOCS: [&str; 6] = [
    "README.md",
    "docs/guide.md",
    "docs/accuracy.md",
    "docs/performance.md",
    "docs/reliability.md",
    "docs/architecture.md",
];

/// The file names of the `images/…` pictures a Markdown text shows
/// (`![alt](images/NAME.png)` or `docs/images/...`).
fn pictures_in(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    for piece in text.split("](").skip(1) {
        let target = piece.split(')').next().unwrap_or("");
        if let Some(at) = target.find("images/") {
            found.push(target[at + "images/".len()..].to_string());
        }
    }
    found
}

/// Names a script or a documented command makes: `NAME|` entries of the
/// [`SCRIPTS`] (their output is `NAME.png`), and `docs/images/FILE`
/// arguments of `cargo run` lines in the docs.
fn made_pictures() -> Vec<String> {
    let root = root();
    let mut made = Vec::new();
    for (script, folder) in SCRIPTS {
        let text = std::fs::read_to_string(root.join(script)).unwrap();
        for line in text.lines() {
            let line = line.trim();
            if let Some(entry) = line.strip_prefix('"') {
                if let Some((name, _)) = entry.split_once('|') {
                    made.push(format!("{folder}{name}.png"));
                }
            }
        }
    }
    // The office's plan is written beside its false-colour view.
    made.push("office-workplane.png".to_string());
    for doc in DOCS {
        let text = std::fs::read_to_string(root.join(doc)).unwrap();
        for line in text.lines().filter(|l| l.starts_with("cargo run")) {
            for word in line.split_whitespace() {
                if let Some(name) = word.strip_prefix("docs/images/") {
                    made.push(name.to_string());
                }
            }
        }
    }
    made
}

#[test]
fn every_picture_the_docs_show_is_made_by_a_script_or_a_documented_command() {
    let made = made_pictures();
    assert!(made.len() >= 15, "{made:?}");
    let mut shown = 0;
    for doc in DOCS {
        let text = std::fs::read_to_string(root().join(doc)).unwrap();
        for picture in pictures_in(&text) {
            shown += 1;
            assert!(
                root().join("docs/images").join(&picture).is_file(),
                "{doc} shows images/{picture}, which does not exist"
            );
            assert!(
                made.contains(&picture),
                "{doc} shows images/{picture}, which no script makes \
                 (add it to scripts/doc_images.sh)"
            );
        }
    }
    assert!(shown >= 20, "{shown} pictures found");
}

/// The picture scripts are valid shell: a syntax error would only show
/// when someone next needs the pictures.
#[test]
fn the_picture_scripts_parse() {
    for (script, _) in SCRIPTS {
        let status = std::process::Command::new("bash")
            .arg("-n")
            .arg(root().join(script))
            .status()
            .unwrap();
        assert!(status.success(), "{script}");
    }
}
