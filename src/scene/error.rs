//! Load errors with positions.
//!
//! Every problem the loader finds becomes a [`Diagnostic`] that names the
//! file, the line and the column (counted in Unicode characters, from 1) of
//! the token at fault, in the form compilers use:
//!
//! ```text
//! scene.sc:12:3: error: duplicate `eye` in camera block (first at 4:3)
//! ```
//!
//! A failed load is a [`LoadError`] holding one or more diagnostics in file
//! order, so a user can fix several mistakes per run.
//!
//! What the `.sc` and `.obj` loaders share lives here too, so that the two
//! formats word the same problem the same way: the cap on diagnostics, the
//! position of whole-file problems, and the messages for unreadable files,
//! negative colour channels and reflectance at or above one.

use super::import::input::InputError;
use super::SourcePos;
use crate::color::Rgb;
use std::fmt;

/// A loader stops after this many diagnostics: past that point a file is
/// usually not a scene at all and more messages help nobody.
pub const MAX_DIAGNOSTICS: usize = 100;

/// Where the start of a file is, for problems of the text as a whole (it
/// is empty, it lacks a required block); a file that cannot be read at
/// all has no position ([`cannot_read`]).
pub(crate) const FILE_START: SourcePos = SourcePos { line: 1, col: 1 };

/// The diagnostic for a file that cannot be read: of the file as a
/// whole, with no line and column (there is no text to point into),
/// printed `FILE: error: cannot read: REASON`, or the refusal
/// ([`InputError::is_refusal`]) as it words itself.
pub(crate) fn cannot_read(file: &str, error: &InputError) -> Diagnostic {
    Diagnostic::whole(file, unreadable(error))
}

/// What [`cannot_read`] says after `FILE: error: `; also the wording of
/// the loaders with errors of their own (IES, points files).
pub(crate) fn unreadable(error: &InputError) -> String {
    match error {
        InputError::Io { error, .. } => format!("cannot read: {error}"),
        refused => refused.to_string(),
    }
}

/// The message for a colour channel written negative: `keyword` is the
/// field (`color`, `Kd`, `Ke`) and `text` the number as written.
pub(crate) fn negative_channel(keyword: &str, text: &str) -> String {
    format!("`{keyword}` channel {text} is negative; channels must be >= 0")
}

/// The message for a reflectance `rho` with a channel at or above one,
/// naming its largest channel (the first of equal ones); `what` says how
/// the file wrote it (`` `Kd` ``, `` `k_diffrefl` × `color` ``).
pub(crate) fn reflectance_too_high(what: &str, rho: Rgb) -> String {
    let (channel, value) = ["red", "green", "blue"]
        .into_iter()
        .zip(rho.to_array())
        .fold(("red", f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
    format!(
        "reflectance {what} is {} in the {channel} channel; every channel must be below 1",
        fmt_num(value)
    )
}

/// `text` as printed on a terminal: every control character (ESC, CR,
/// LF, tab, DEL, the C1 range...) written as its Rust escape (`\u{1b}`,
/// `\r`, `\n`), so a name read from a model can never move the cursor,
/// recolour the terminal or start a line that looks like another message.
/// Everything else, non-ASCII letters included, is kept. Used for every
/// name and message a loader prints ([`Diagnostic`], [`Warning`], the
/// `--emit` suggestions).
pub fn escape_controls(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// One problem found while loading, with its position.
///
/// A text format (`.sc`, `.obj`, `.mtl`, a `.gltf` file's JSON syntax)
/// places it by line and column. A problem in a binary file, or one a glTF
/// loader places by its JSON path (`meshes[3].primitives[0]`) or byte
/// offset in the message itself, has line and column 0 (see
/// [`Diagnostic::whole`]) and is printed `FILE: error: MESSAGE`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// The file as the user named it.
    pub file: String,
    /// Line, from 1; 0 when the message says where (see above).
    pub line: u32,
    /// Column in characters, from 1; 0 when `line` is 0.
    pub col: u32,
    /// What is wrong: one line, no trailing period, no position.
    pub message: String,
}

impl Diagnostic {
    /// A diagnostic for `file` at `pos`.
    pub fn new(file: &str, pos: SourcePos, message: impl Into<String>) -> Self {
        Diagnostic {
            file: file.to_owned(),
            line: pos.line,
            col: pos.col,
            message: message.into(),
        }
    }

    /// A diagnostic with no line and column: `message` says where (a JSON
    /// path, a byte offset) or concerns the whole file.
    pub fn whole(file: &str, message: impl Into<String>) -> Self {
        Diagnostic {
            file: file.to_owned(),
            line: 0,
            col: 0,
            message: message.into(),
        }
    }

    /// Where it points, as a [`SourcePos`].
    pub fn pos(&self) -> SourcePos {
        SourcePos {
            line: self.line,
            col: self.col,
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (file, message) = (escape_controls(&self.file), escape_controls(&self.message));
        if self.line == 0 {
            return write!(f, "{file}: error: {message}");
        }
        write!(f, "{file}:{}:{}: error: {message}", self.line, self.col)
    }
}

/// Something a loader accepted but changed or ignored, for the user to
/// know: a quirk of an exporter with one sensible reading. Printed as one
/// line, `FILE:LINE:COL: warning: MESSAGE` (or `FILE: warning: MESSAGE`
/// when it concerns the whole file), on stderr, even with `--quiet`.
/// Loaders summarise a kind of quirk found many times in one warning (a
/// count and the first position), so a file with thousands of faults gets
/// a few lines.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Warning {
    /// The file as the user named it.
    pub file: String,
    /// Where in it, if the warning points at one place.
    pub pos: Option<SourcePos>,
    /// What was changed or ignored: one line, no trailing period.
    pub message: String,
}

impl Warning {
    /// A warning at `pos` in `file`.
    pub fn at(file: &str, pos: SourcePos, message: impl Into<String>) -> Self {
        Warning {
            file: file.to_owned(),
            pos: Some(pos),
            message: message.into(),
        }
    }

    /// A warning about the whole of `file`.
    pub fn file(file: &str, message: impl Into<String>) -> Self {
        Warning {
            file: file.to_owned(),
            pos: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (file, message) = (escape_controls(&self.file), escape_controls(&self.message));
        match self.pos {
            Some(pos) => write!(f, "{file}:{}:{}: warning: {message}", pos.line, pos.col),
            None => write!(f, "{file}: warning: {message}"),
        }
    }
}

/// A failed load: at least one diagnostic, printed one per line.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct LoadError {
    /// Every problem found, in file order; never empty.
    pub diagnostics: Vec<Diagnostic>,
}

impl LoadError {
    /// The diagnostics as an error: sorted by file, then position (stable,
    /// so several messages at one place keep their order), at most
    /// [`MAX_DIAGNOSTICS`].
    pub fn from_diagnostics(mut diagnostics: Vec<Diagnostic>) -> LoadError {
        diagnostics.sort_by(|a, b| {
            (a.file.as_str(), a.line, a.col).cmp(&(b.file.as_str(), b.line, b.col))
        });
        diagnostics.truncate(MAX_DIAGNOSTICS);
        LoadError { diagnostics }
    }

    /// The first problem, the one a user should fix first.
    pub fn first(&self) -> Option<&Diagnostic> {
        self.diagnostics.first()
    }
}

impl From<Diagnostic> for LoadError {
    fn from(d: Diagnostic) -> Self {
        LoadError {
            diagnostics: vec![d],
        }
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.diagnostics.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

/// `FILE:LINE:COL: KIND: MESSAGE`, or `FILE: KIND: MESSAGE` when `line`
/// is 0 (the message concerns the whole file, one that cannot be read,
/// say), for the loaders whose errors are not [`Diagnostic`]s (IES and
/// points files); control characters escaped as [`Diagnostic`]'s are.
pub(crate) fn positioned(
    file: &str,
    line: usize,
    column: usize,
    kind: &str,
    message: &str,
) -> String {
    let (file, message) = (escape_controls(file), escape_controls(message));
    if line == 0 {
        format!("{file}: {kind}: {message}")
    } else {
        format!("{file}:{line}:{column}: {kind}: {message}")
    }
}

/// Formats a quantity for a message with about three significant digits and
/// no trailing zeros (`0.31`, `0.005`, `120`), so messages stay short
/// whatever the scale of the scene.
pub(crate) fn fmt_num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor();
    if !(-4.0..7.0).contains(&magnitude) {
        // Scientific beyond a million or below a ten-thousandth, so limits
        // like 1e12 and 1e-9 stay readable.
        let s = format!("{x:.2e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exponent}");
    }
    // Three significant digits; clamp so huge or tiny values stay readable.
    let decimals = (2.0 - magnitude).clamp(0.0, 12.0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diag(line: u32, col: u32, message: &str) -> Diagnostic {
        Diagnostic::new("a.sc", SourcePos { line, col }, message)
    }

    #[test]
    fn diagnostic_displays_like_a_compiler() {
        assert_eq!(
            diag(3, 7, "unknown keyword `foo`").to_string(),
            "a.sc:3:7: error: unknown keyword `foo`"
        );
    }

    #[test]
    fn a_diagnostic_without_a_line_prints_the_file_alone() {
        let d = Diagnostic::whole("m.glb", "meshes[3].primitives[0]: no POSITION");
        assert_eq!(
            d.to_string(),
            "m.glb: error: meshes[3].primitives[0]: no POSITION"
        );
    }

    #[test]
    fn load_error_prints_one_line_per_diagnostic() {
        let e = LoadError {
            diagnostics: vec![diag(1, 1, "first"), diag(2, 5, "second")],
        };
        assert_eq!(
            e.to_string(),
            "a.sc:1:1: error: first\na.sc:2:5: error: second"
        );
        assert_eq!(
            e.first().map(|d| d.pos()),
            Some(SourcePos { line: 1, col: 1 })
        );
    }

    #[test]
    fn numbers_in_messages_have_three_significant_digits() {
        assert_eq!(fmt_num(0.31), "0.31");
        assert_eq!(fmt_num(0.005), "0.005");
        assert_eq!(fmt_num(0.0123456), "0.0123");
        assert_eq!(fmt_num(120.0), "120");
        assert_eq!(fmt_num(1.5), "1.5");
        assert_eq!(fmt_num(-2.25), "-2.25");
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(1e12), "1e12");
        assert_eq!(fmt_num(1.8e12), "1.8e12");
        assert_eq!(fmt_num(1e-9), "1e-9");
        assert_eq!(fmt_num(-2.5e-12), "-2.5e-12");
        assert_eq!(fmt_num(123456.0), "123456");
    }
}

#[cfg(test)]
mod warning_tests {
    use super::*;

    #[test]
    fn warnings_read_as_one_line_with_their_place() {
        let at = Warning::at("room.obj", SourcePos { line: 12, col: 3 }, "`Kd` 1 clamped");
        assert_eq!(at.to_string(), "room.obj:12:3: warning: `Kd` 1 clamped");
        // Control characters of a name are shown escaped, never sent
        // to the terminal.
        let hostile = Warning::file("r\u{1b}[2J.obj", "material `a\r\nb\u{7f}` x");
        assert_eq!(
            hostile.to_string(),
            "r\\u{1b}[2J.obj: warning: material `a\\r\\nb\\u{7f}` x"
        );
        let d = Diagnostic::new("m.mtl", SourcePos { line: 2, col: 1 }, "`\u{9b}31m`");
        assert_eq!(d.to_string(), "m.mtl:2:1: error: `\\u{9b}31m`");
        assert_eq!(escape_controls("é plain"), "é plain");
        let whole = Warning::file("room.obj", "nothing emits light");
        assert_eq!(whole.to_string(), "room.obj: warning: nothing emits light");
    }
}
