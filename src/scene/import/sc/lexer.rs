//! The `.sc` lexer: source text in, tokens with their positions out.
//!
//! A token is a maximal run of characters that are neither whitespace nor
//! `#`; `#` starts a comment that runs to the end of its line, also in the
//! middle of a token. Each token is classified here (number, name-shaped
//! word, malformed) but malformed tokens are not reported: the parser does
//! that, so diagnostics come out in file order and can say what was
//! expected. Positions count lines from 1 and columns from 1 in Unicode
//! characters (a tab is one column); only LF ends a line.

use crate::scene::error::FILE_START;
use crate::scene::SourcePos;

/// The position after `c`, given the position of `c`. Only LF ends a line
/// (a CR before it is whitespace on the line), and every character,
/// tab included, is one column.
pub(super) fn advance(pos: SourcePos, c: char) -> SourcePos {
    if c == '\n' {
        SourcePos {
            line: pos.line.saturating_add(1),
            col: 1,
        }
    } else {
        SourcePos {
            line: pos.line,
            col: pos.col.saturating_add(1),
        }
    }
}

/// What a token is. Malformed tokens are kept (as [`Kind::Bad`]) rather
/// than reported by the lexer so that diagnostics come out in file order
/// and the parser can tell "bad number where a number belongs" apart from
/// "stray garbage".
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Kind {
    /// A decimal number in the format's grammar, finite.
    Number(f64),
    /// Name-shaped: a keyword, a name, or `nan`/`inf` (refused later).
    Word,
    /// Neither: see [`bad_message`].
    Bad,
    /// End of input; always the last token.
    Eof,
}

/// One token: a slice of the source with its kind and position.
#[derive(Clone, Copy, Debug)]
pub(super) struct Token<'a> {
    /// What it is.
    pub(super) kind: Kind,
    /// Its text as written (empty for [`Kind::Eof`]).
    pub(super) text: &'a str,
    /// Where its first character is.
    pub(super) pos: SourcePos,
}

/// Splits the source into tokens: maximal runs of characters that are
/// neither whitespace nor `#`. A `#` ends the token it is in and starts a
/// comment up to the end of the line.
pub(super) fn lex(source: &str) -> Vec<Token<'_>> {
    let mut tokens = Vec::new();
    let mut pos = FILE_START;
    let mut start: Option<(usize, SourcePos)> = None;
    let mut in_comment = false;
    for (i, c) in source.char_indices() {
        if in_comment {
            in_comment = c != '\n';
        } else if c == '#' || c.is_whitespace() {
            if let Some((s, p)) = start.take() {
                tokens.push(classify(&source[s..i], p));
            }
            in_comment = c == '#';
        } else if start.is_none() {
            start = Some((i, pos));
        }
        pos = advance(pos, c);
    }
    if let Some((s, p)) = start {
        tokens.push(classify(&source[s..], p));
    }
    tokens.push(Token {
        kind: Kind::Eof,
        text: "",
        pos,
    });
    tokens
}

fn classify(text: &str, pos: SourcePos) -> Token<'_> {
    let kind = if is_number(text) {
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Kind::Number(x),
            _ => Kind::Bad,
        }
    } else if is_name_shaped(text) {
        Kind::Word
    } else {
        Kind::Bad
    };
    Token { kind, text, pos }
}

/// `[+-]?(D+(.D*)?|.D+)([eE][+-]?D+)?`, exactly.
pub(super) fn is_number(text: &str) -> bool {
    let b = text.as_bytes();
    let mut i = 0;
    let digits = |i: &mut usize| {
        let from = *i;
        while *i < b.len() && b[*i].is_ascii_digit() {
            *i += 1;
        }
        *i - from
    };
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let int = digits(&mut i);
    let mut frac = 0;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        frac = digits(&mut i);
    }
    if int == 0 && frac == 0 {
        return false;
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        if digits(&mut i) == 0 {
            return false;
        }
    }
    i == b.len()
}

/// `[A-Za-z_][A-Za-z0-9_.-]*`.
fn is_name_shaped(text: &str) -> bool {
    let mut chars = text.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '-'))
}

/// `nan`, `inf`, `infinity` in any case and with any sign: what someone
/// writes who expects them to be numbers.
pub(super) fn is_non_finite_word(text: &str) -> bool {
    let t = text.trim_start_matches(['+', '-']).to_ascii_lowercase();
    matches!(t.as_str(), "nan" | "inf" | "infinity")
}

/// The message for a token the lexer classified as [`Kind::Bad`], or a
/// `nan`/`inf` word where a number belongs.
pub(super) fn bad_message(text: &str) -> String {
    let q = quote(text);
    if is_non_finite_word(text) {
        format!("{q} is not allowed: numbers must be finite decimals")
    } else if is_number(text) {
        format!("number {q} is out of range (it overflows to infinity)")
    } else if text.starts_with(|c: char| c.is_ascii_digit() || matches!(c, '+' | '-' | '.')) {
        format!("invalid number {q}: numbers are decimal, like 1, -0.5, .5 or 2.5e-3")
    } else {
        format!("unexpected {q}: not a keyword, a name or a number")
    }
}

/// A token's text in backquotes for a message, shortened if huge.
pub(super) fn quote(text: &str) -> String {
    const MAX_CHARS: usize = 40;
    if text.chars().count() > MAX_CHARS {
        let head: String = text.chars().take(MAX_CHARS).collect();
        format!("`{head}…`")
    } else {
        format!("`{text}`")
    }
}
