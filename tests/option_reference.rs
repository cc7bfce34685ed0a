//! The guide's option reference ("Every option" in `docs/guide.md`)
//! against the command line's own definitions: every option the program
//! takes has a row there, and every row names an option the program
//! takes, so the reference can neither leave one out nor keep a stale one.

mod common;

use std::collections::BTreeSet;

/// The options named at the start of the rows of the guide's table.
fn documented() -> BTreeSet<String> {
    let guide = std::fs::read_to_string(common::root().join("docs/guide.md")).unwrap();
    let start = guide
        .find("\n## Every option")
        .expect("the guide has its option reference");
    let section = &guide[start + 1..];
    let end = section[3..].find("\n## ").map_or(section.len(), |k| k + 3);
    let mut names = BTreeSet::new();
    for line in section[..end].lines() {
        // The first cell: `-o, --output FILE`, `--ambient`, `--no-ambient`.
        let Some(cell) = line.strip_prefix("| ").and_then(|l| l.split(" | ").next()) else {
            continue;
        };
        for span in cell.split('`').skip(1).step_by(2) {
            for word in span.split([',', ' ']) {
                if word.starts_with("--") {
                    names.insert(word.to_string());
                }
            }
        }
    }
    names
}

/// The long options of the command line, `--help` and `--version` aside.
fn defined() -> BTreeSet<String> {
    radiosity::cli::command()
        .get_arguments()
        .filter_map(|a| a.get_long())
        .filter(|l| !matches!(*l, "help" | "version"))
        .map(|l| format!("--{l}"))
        .collect()
}

#[test]
fn the_guide_documents_every_option_and_only_those() {
    let (documented, defined) = (documented(), defined());
    assert!(defined.len() > 40, "{defined:?}");
    let missing: Vec<_> = defined.difference(&documented).collect();
    let stale: Vec<_> = documented.difference(&defined).collect();
    assert!(
        missing.is_empty(),
        "options without a row in docs/guide.md's \"Every option\": {missing:?}"
    );
    assert!(
        stale.is_empty(),
        "rows in docs/guide.md's \"Every option\" for no option: {stale:?}"
    );
}
