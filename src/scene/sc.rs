//! The `.sc` parser: scene text in, validated [`Scene`] out.
//!
//! The format is described in `docs/scene-format.md`. In short: a file is a
//! sequence of statements (`camera … end`, `material NAME … end`,
//! `polygon MATERIAL … end`, `box MATERIAL X0 Y0 Z0 X1 Y1 Z1`,
//! `transform … end`), tokens are separated by whitespace, line breaks carry
//! no meaning and `#` starts a comment anywhere.
//!
//! The parser reads the whole file before giving up: after an error it skips
//! to the next keyword and goes on, so one run reports every independent
//! mistake (up to [`MAX_DIAGNOSTICS`]). Each diagnostic points at the token
//! at fault; problems of a whole block (a missing field, an invalid polygon,
//! no `end`) point at the keyword that opened it.

use super::error::fmt_num;
use super::{
    CameraSource, Diagnostic, LoadError, Material, MaterialId, Polygon, PolygonError, Scene,
    SourcePos, MAX_COORDINATE,
};
use crate::camera::{
    picture_size_ok, Camera, CameraError, DEFAULT_FOV_DEG, DEFAULT_SIZE, MAX_PICTURE_PIXELS,
    MAX_PICTURE_SIDE,
};
use crate::color::Rgb;
use glam::{DAffine3, DMat3, DVec3, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// The parser stops after this many diagnostics: past that point a file is
/// usually not a scene at all and more messages help nobody.
pub const MAX_DIAGNOSTICS: usize = 100;

/// Largest emitted radiosity per channel (`k_emission` × `color`), in the
/// scene's radiosity units. Far above any physical scene, low enough that
/// emission × area × polygon count stays finite in `f64` and radiosities
/// stay finite in the `f32` pictures.
pub const MAX_EMISSION: f64 = 1e20;

/// Every keyword of the format. None of them may be used as a name.
pub const KEYWORDS: &[&str] = &[
    "camera",
    "material",
    "polygon",
    "box",
    "transform",
    "end",
    "eye",
    "lookat",
    "up",
    "fov",
    "size",
    "color",
    "k_diffrefl",
    "k_emission",
    "vertex",
    "translate",
    "rotate",
    "scale",
];

/// Keywords that start a statement; meeting one inside a field block means
/// the block's `end` is missing.
const STATEMENTS: &[&str] = &["camera", "material", "polygon", "box", "transform"];

const CAMERA_FIELDS: &[&str] = &["eye", "lookat", "up", "fov", "size"];
const MATERIAL_FIELDS: &[&str] = &["color", "k_diffrefl", "k_emission"];
const POLYGON_FIELDS: &[&str] = &["vertex"];

/// Where the start of a file is, for problems of the file as a whole.
const FILE_START: SourcePos = SourcePos { line: 1, col: 1 };

/// Parses `.sc` source text; `file` names it in diagnostics.
///
/// A byte-order mark at the very start is skipped. On success every
/// polygon is valid (see [`Polygon::new`]), every material obeys the
/// invariants of [`Material`], and the camera those of [`Camera`]. A file
/// with no camera gets [`Camera::frame`] of the scene's bounds; a file with
/// no polygon is an error.
pub fn parse_str(source: &str, file: &str) -> Result<Scene, LoadError> {
    let source = source.strip_prefix('\u{feff}').unwrap_or(source);
    let mut parser = Parser::new(file, lex(source));
    parser.run();
    parser.finish()
}

/// Parses `.sc` source text for its camera only, as a sidecar camera for
/// a scene from another format (`--camera`). The file is checked exactly
/// as [`parse_str`] checks it, except that it may have no polygons; it
/// must have a `camera` block.
pub fn parse_camera_str(source: &str, file: &str) -> Result<Camera, LoadError> {
    let source = source.strip_prefix('\u{feff}').unwrap_or(source);
    let mut parser = Parser::new(file, lex(source));
    parser.run();
    parser.report_pending(false)?;
    parser.camera.ok_or_else(|| {
        Diagnostic::new(file, FILE_START, "camera file has no `camera` block").into()
    })
}

/// Reads `path` and parses its camera (see [`parse_camera_str`]); the
/// path as given names the file in diagnostics.
pub fn load_camera(path: &Path) -> Result<Camera, LoadError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path)
        .map_err(|e| Diagnostic::new(&file, FILE_START, format!("cannot read file: {e}")))?;
    let text = decode(&bytes, &file)?;
    parse_camera_str(text, &file)
}

/// Reads `path` and parses it; the path as given names the file in
/// diagnostics. A file that cannot be read is reported at `1:1`, a file
/// that is not UTF-8 at its first bad byte.
pub(crate) fn load_file(path: &Path) -> Result<Scene, LoadError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path)
        .map_err(|e| Diagnostic::new(&file, FILE_START, format!("cannot read file: {e}")))?;
    parse_bytes(&bytes, &file)
}

/// Parses the raw bytes of a `.sc` file; `file` names it in diagnostics.
/// Bytes that are not UTF-8 are reported at the first bad one; otherwise
/// as [`parse_str`].
pub fn parse_bytes(bytes: &[u8], file: &str) -> Result<Scene, LoadError> {
    let text = decode(bytes, file)?;
    parse_str(text, file)
}

/// The bytes as UTF-8 text without a leading byte-order mark.
fn decode<'b>(bytes: &'b [u8], file: &str) -> Result<&'b str, LoadError> {
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    match std::str::from_utf8(body) {
        Ok(text) => Ok(text),
        Err(e) => {
            // Everything before the bad byte is valid, so its end position
            // is where the problem is.
            let valid = std::str::from_utf8(&body[..e.valid_up_to()]).unwrap_or_default();
            let pos = valid.chars().fold(FILE_START, advance);
            Err(Diagnostic::new(file, pos, "file is not valid UTF-8").into())
        }
    }
}

/// The position after `c`, given the position of `c`. Only LF ends a line
/// (a CR before it is whitespace on the line), and every character,
/// tab included, is one column.
fn advance(pos: SourcePos, c: char) -> SourcePos {
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

// ---------------------------------------------------------------- lexer --

/// What a token is. Malformed tokens are kept (as [`Kind::Bad`]) rather
/// than reported by the lexer so that diagnostics come out in file order
/// and the parser can tell "bad number where a number belongs" apart from
/// "stray garbage".
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// A decimal number in the format's grammar, finite.
    Number(f64),
    /// Name-shaped: a keyword, a name, or `nan`/`inf` (refused later).
    Word,
    /// Neither: see [`bad_message`].
    Bad,
    /// End of input; always the last token.
    Eof,
}

#[derive(Clone, Copy, Debug)]
struct Token<'a> {
    kind: Kind,
    text: &'a str,
    pos: SourcePos,
}

/// Splits the source into tokens: maximal runs of characters that are
/// neither whitespace nor `#`. A `#` ends the token it is in and starts a
/// comment up to the end of the line.
fn lex(source: &str) -> Vec<Token<'_>> {
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
fn is_number(text: &str) -> bool {
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
fn is_non_finite_word(text: &str) -> bool {
    let t = text.trim_start_matches(['+', '-']).to_ascii_lowercase();
    matches!(t.as_str(), "nan" | "inf" | "infinity")
}

/// The message for a token the lexer classified as [`Kind::Bad`], or a
/// `nan`/`inf` word where a number belongs.
fn bad_message(text: &str) -> String {
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
fn quote(text: &str) -> String {
    const MAX_CHARS: usize = 40;
    if text.chars().count() > MAX_CHARS {
        let head: String = text.chars().take(MAX_CHARS).collect();
        format!("`{head}…`")
    } else {
        format!("`{text}`")
    }
}

fn at(pos: SourcePos) -> String {
    format!("{}:{}", pos.line, pos.col)
}

/// What each statement or field expects after its keyword, for "missing"
/// and "extra" messages.
fn arity(keyword: &str) -> &'static str {
    match keyword {
        "eye" | "lookat" | "up" | "color" | "vertex" | "translate" => "takes 3 numbers",
        "rotate" => "takes 4 numbers",
        "scale" => "takes 1 or 3 numbers",
        "fov" | "k_diffrefl" | "k_emission" => "takes 1 number",
        "size" => "takes 2 numbers",
        "box" => "takes a material name and 6 numbers",
        "material" => "takes a name and no numbers",
        "polygon" => "takes a material name and no numbers (vertices go on `vertex` lines)",
        _ => "takes no numbers",
    }
}

// --------------------------------------------------------------- parser --

/// A number as read, with where it was written (for range errors).
#[derive(Clone, Copy, Debug)]
struct Num<'a> {
    value: f64,
    text: &'a str,
    pos: SourcePos,
}

/// One open `transform` block: where it started and the matrix that maps
/// the coordinates written inside it (at this point) to world space.
struct Frame {
    pos: SourcePos,
    matrix: DAffine3,
}

/// A name that was used before any material of that name existed.
struct PendingUse {
    name: String,
    pos: SourcePos,
}

struct Parser<'a> {
    file: &'a str,
    tokens: Vec<Token<'a>>,
    next: usize,
    diags: Vec<Diagnostic>,
    materials: Vec<Material>,
    material_ids: HashMap<&'a str, (MaterialId, SourcePos)>,
    undefined_uses: Vec<PendingUse>,
    polygons: Vec<Polygon>,
    camera: Option<Camera>,
    camera_pos: Option<SourcePos>,
    frames: Vec<Frame>,
    /// The keyword read last, to explain a stray number after it.
    last_keyword: Option<&'a str>,
}

impl<'a> Parser<'a> {
    fn new(file: &'a str, tokens: Vec<Token<'a>>) -> Self {
        Parser {
            file,
            tokens,
            next: 0,
            diags: Vec::new(),
            materials: Vec::new(),
            material_ids: HashMap::new(),
            undefined_uses: Vec::new(),
            polygons: Vec::new(),
            camera: None,
            camera_pos: None,
            frames: Vec::new(),
            last_keyword: None,
        }
    }

    fn peek(&self) -> Token<'a> {
        // `lex` always ends the list with Eof and `bump` never passes it.
        self.tokens[self.next.min(self.tokens.len() - 1)]
    }

    fn bump(&mut self) -> Token<'a> {
        let t = self.peek();
        if t.kind != Kind::Eof {
            self.next += 1;
        }
        t
    }

    fn error(&mut self, pos: SourcePos, message: impl Into<String>) {
        self.diags.push(Diagnostic::new(self.file, pos, message));
    }

    fn gave_up(&self) -> bool {
        self.diags.len() >= MAX_DIAGNOSTICS
    }

    /// Reports a number or malformed token where a keyword belongs, then
    /// skips the rest of the run so that one mistake gives one message.
    fn stray(&mut self) {
        let t = self.bump();
        let message = match (t.kind, self.last_keyword) {
            (Kind::Number(_), Some(kw)) => {
                format!("extra number {}: `{kw}` {}", quote(t.text), arity(kw))
            }
            (Kind::Number(_), None) => {
                format!("unexpected number {}; expected a keyword", quote(t.text))
            }
            _ => bad_message(t.text),
        };
        self.error(t.pos, message);
        while matches!(self.peek().kind, Kind::Number(_) | Kind::Bad) {
            self.bump();
        }
    }

    /// Skips the arguments of an unknown or misplaced keyword `kw`: every
    /// number up to the next word, and names too while on `kw`'s line. Line
    /// breaks mean nothing to the grammar, but they are the best guess of
    /// where a statement nobody understands ends.
    fn skip_arguments(&mut self, kw: Token<'a>) {
        loop {
            let t = self.peek();
            let skip = match t.kind {
                Kind::Number(_) | Kind::Bad => true,
                Kind::Word => t.pos.line == kw.pos.line && !KEYWORDS.contains(&t.text),
                Kind::Eof => false,
            };
            if !skip {
                return;
            }
            self.bump();
        }
    }

    // ------------------------------------------------------- statements --

    fn run(&mut self) {
        while !self.gave_up() {
            let t = self.peek();
            match t.kind {
                Kind::Eof => {
                    for f in std::mem::take(&mut self.frames).iter().rev() {
                        self.error(
                            f.pos,
                            "unterminated `transform` block: end of file before its `end`",
                        );
                    }
                    return;
                }
                Kind::Number(_) | Kind::Bad => self.stray(),
                Kind::Word => {
                    self.bump();
                    self.last_keyword = Some(t.text);
                    self.statement(t);
                }
            }
        }
    }

    fn statement(&mut self, kw: Token<'a>) {
        let in_transform = !self.frames.is_empty();
        match kw.text {
            "camera" | "material" if in_transform => {
                self.error(
                    kw.pos,
                    format!("`{}` is not allowed inside a transform block", kw.text),
                );
                // Still read it, so its contents are checked and skipped.
                if kw.text == "camera" {
                    self.camera_block(kw);
                } else {
                    self.material_block(kw);
                }
            }
            "camera" => self.camera_block(kw),
            "material" => self.material_block(kw),
            "polygon" => self.polygon_block(kw),
            "box" => self.box_statement(kw),
            "transform" => {
                let matrix = self.current_matrix();
                self.frames.push(Frame {
                    pos: kw.pos,
                    matrix,
                });
            }
            "end" => {
                if self.frames.pop().is_none() {
                    self.error(kw.pos, "`end` without an open block");
                }
            }
            "translate" | "rotate" | "scale" => {
                let t = self.transform_line(kw);
                match (self.frames.last_mut(), t) {
                    // Post-multiplying makes the latest line act first on
                    // what follows, as a matrix stack does.
                    (Some(frame), Some(t)) => {
                        let product = frame.matrix * t;
                        if product.is_finite() {
                            frame.matrix = product;
                        } else {
                            self.error(
                                kw.pos,
                                format!(
                                    "this `{}` makes the enclosing transforms overflow: \
                                     the combined matrix is no longer finite",
                                    kw.text
                                ),
                            );
                        }
                    }
                    (None, _) => self.error(
                        kw.pos,
                        format!("`{}` is only allowed inside a transform block", kw.text),
                    ),
                    (Some(_), None) => {}
                }
            }
            s if KEYWORDS.contains(&s) => {
                let block = if CAMERA_FIELDS.contains(&s) {
                    "camera"
                } else if MATERIAL_FIELDS.contains(&s) {
                    "material"
                } else {
                    "polygon"
                };
                self.error(
                    kw.pos,
                    format!("`{s}` is only allowed inside a {block} block"),
                );
                self.skip_arguments(kw);
            }
            s => {
                self.error(kw.pos, format!("unknown keyword {}", quote(s)));
                self.skip_arguments(kw);
            }
        }
    }

    fn current_matrix(&self) -> DAffine3 {
        self.frames.last().map_or(DAffine3::IDENTITY, |f| f.matrix)
    }

    /// Reads the fields of a block up to its `end`, calling `field` for each
    /// field keyword in `fields` (after the keyword). Fields not in
    /// `repeatable` may be given once. Returns whether the block was closed
    /// by `end`; if not, the problem has been reported at `open`.
    fn block(
        &mut self,
        open: Token<'a>,
        fields: &[&str],
        repeatable: &[&str],
        field: &mut dyn FnMut(&mut Self, Token<'a>),
    ) -> bool {
        let what = open.text;
        let mut seen: Vec<Token<'a>> = Vec::new();
        loop {
            if self.gave_up() {
                return false;
            }
            let t = self.peek();
            match t.kind {
                Kind::Eof => {
                    self.error(
                        open.pos,
                        format!("unterminated `{what}` block: end of file before its `end`"),
                    );
                    return false;
                }
                Kind::Number(_) | Kind::Bad => self.stray(),
                Kind::Word => match t.text {
                    "end" => {
                        self.bump();
                        self.last_keyword = Some("end");
                        return true;
                    }
                    s if fields.contains(&s) => {
                        self.bump();
                        self.last_keyword = Some(t.text);
                        if !repeatable.contains(&s) {
                            if let Some(first) = seen.iter().find(|f| f.text == s) {
                                let message = format!(
                                    "duplicate `{s}` in {what} block (first at {})",
                                    at(first.pos)
                                );
                                self.error(t.pos, message);
                            } else {
                                seen.push(t);
                            }
                        }
                        field(self, t);
                    }
                    s if STATEMENTS.contains(&s) => {
                        // Leave the keyword for the statement loop: the block
                        // most likely just lacks its `end`.
                        self.error(
                            open.pos,
                            format!(
                                "unterminated `{what}` block: `{s}` at {} comes before its `end`",
                                at(t.pos)
                            ),
                        );
                        return false;
                    }
                    s => {
                        self.bump();
                        let expected = fields
                            .iter()
                            .map(|f| format!("`{f}`"))
                            .collect::<Vec<_>>()
                            .join(", ");
                        let message = if KEYWORDS.contains(&s) {
                            format!("`{s}` is not allowed in a {what} block (expected {expected} or `end`)")
                        } else {
                            format!(
                                "unknown keyword {} in {what} block (expected {expected} or `end`)",
                                quote(s)
                            )
                        };
                        self.error(t.pos, message);
                        self.skip_arguments(t);
                    }
                },
            }
        }
    }

    /// Reads `n` numbers after `kw`. Malformed numbers are reported where
    /// they are and still count, so the rest of the line lines up; a missing
    /// number is reported at `kw`. `None` when anything was wrong.
    fn numbers(&mut self, kw: Token<'a>, n: usize) -> Option<Vec<Num<'a>>> {
        self.more_numbers(kw, n, 0)
    }

    /// [`Parser::numbers`] when `have` numbers of the same keyword were
    /// read already (for the count in the message).
    fn more_numbers(&mut self, kw: Token<'a>, n: usize, have: usize) -> Option<Vec<Num<'a>>> {
        let mut out = Vec::with_capacity(n);
        let mut ok = true;
        while out.len() < n {
            let t = self.peek();
            match t.kind {
                Kind::Number(value) => out.push(Num {
                    value,
                    text: t.text,
                    pos: t.pos,
                }),
                Kind::Bad => {
                    self.error(t.pos, bad_message(t.text));
                    ok = false;
                    out.push(Num {
                        value: 0.0,
                        text: t.text,
                        pos: t.pos,
                    });
                }
                Kind::Word if is_non_finite_word(t.text) => {
                    self.error(t.pos, bad_message(t.text));
                    ok = false;
                    out.push(Num {
                        value: 0.0,
                        text: t.text,
                        pos: t.pos,
                    });
                }
                Kind::Word | Kind::Eof => {
                    self.error(
                        kw.pos,
                        format!(
                            "missing number: `{}` {}, found {}",
                            kw.text,
                            arity(kw.text),
                            have + out.len()
                        ),
                    );
                    return None;
                }
            }
            self.bump();
        }
        ok.then_some(out)
    }

    /// Three numbers that must fit a coordinate.
    fn point(&mut self, kw: Token<'a>) -> Option<DVec3> {
        let nums = self.numbers(kw, 3)?;
        self.check_coordinates(&nums)
            .then(|| DVec3::new(nums[0].value, nums[1].value, nums[2].value))
    }

    /// Whether every number fits a coordinate (reporting those that do not).
    fn check_coordinates(&mut self, nums: &[Num<'a>]) -> bool {
        let mut ok = true;
        for n in nums {
            if n.value.abs() > MAX_COORDINATE {
                self.error(
                    n.pos,
                    format!(
                        "number {} is too large for a coordinate (at most {} in magnitude)",
                        quote(n.text),
                        fmt_num(MAX_COORDINATE)
                    ),
                );
                ok = false;
            }
        }
        ok
    }

    /// One number that must be `>= 0`.
    fn non_negative(&mut self, kw: Token<'a>) -> Option<f64> {
        let n = self.numbers(kw, 1)?[0];
        if n.value < 0.0 {
            self.error(
                n.pos,
                format!("`{}` {} is negative; it must be >= 0", kw.text, n.text),
            );
            return None;
        }
        Some(n.value)
    }

    /// A name after `kw` (material name). `fields` are the keywords that
    /// may follow directly when the name is missing; those are left alone.
    fn name(&mut self, kw: Token<'a>, fields: &[&str]) -> Option<(&'a str, SourcePos)> {
        let t = self.peek();
        let what = if kw.text == "material" {
            "a name"
        } else {
            "a material name"
        };
        match t.kind {
            Kind::Word if t.text == "end" || fields.contains(&t.text) => {
                self.error(
                    t.pos,
                    format!(
                        "missing name: `{}` needs {what} before `{}`",
                        kw.text, t.text
                    ),
                );
                None
            }
            Kind::Word if KEYWORDS.contains(&t.text) => {
                self.bump();
                self.error(
                    t.pos,
                    format!("`{}` is a keyword and cannot be used as a name", t.text),
                );
                None
            }
            Kind::Word if t.text == "nan" || t.text == "inf" => {
                self.bump();
                self.error(t.pos, format!("`{}` cannot be used as a name", t.text));
                None
            }
            Kind::Word => {
                self.bump();
                Some((t.text, t.pos))
            }
            Kind::Eof => {
                self.error(kw.pos, format!("missing name: `{}` needs {what}", kw.text));
                None
            }
            Kind::Number(_) | Kind::Bad => {
                // A box's numbers follow its name: leave them to be read
                // as such rather than reporting each one again.
                if kw.text != "box" {
                    self.bump();
                }
                self.error(
                    t.pos,
                    format!(
                        "`{}` needs {what}, found {}; names start with a letter or `_`",
                        kw.text,
                        quote(t.text)
                    ),
                );
                None
            }
        }
    }

    /// The material a shape names, or `None` (reported, or noted as used
    /// before definition, to be reported at the end).
    fn material_ref(&mut self, kw: Token<'a>, fields: &[&str]) -> Option<MaterialId> {
        let (name, pos) = self.name(kw, fields)?;
        match self.material_ids.get(name) {
            Some(&(id, _)) => Some(id),
            None => {
                self.undefined_uses.push(PendingUse {
                    name: name.to_owned(),
                    pos,
                });
                None
            }
        }
    }

    // ----------------------------------------------------------- camera --

    fn camera_block(&mut self, open: Token<'a>) {
        let second = self.camera_pos.is_some();
        if let Some(first) = self.camera_pos {
            self.error(
                open.pos,
                format!("second `camera` block; the first is at {}", at(first)),
            );
        }
        let mut eye = None;
        let mut lookat = None;
        let mut up = None;
        let mut fov = None;
        let mut size = None;
        // A field that was given but wrong: its error is reported already,
        // and the block must not be checked further or used.
        let mut bad = false;
        let closed = self.block(open, CAMERA_FIELDS, &[], &mut |p, kw| {
            let ok = match kw.text {
                "eye" => p.point(kw).map(|v| eye = Some((v, kw.pos))),
                "lookat" => p.point(kw).map(|v| lookat = Some((v, kw.pos))),
                "up" => p.point(kw).map(|v| up = Some((v, kw.pos))),
                "fov" => p.fov(kw).map(|v| fov = Some(v)),
                _ => p.size(kw).map(|v| size = Some(v)),
            };
            bad |= ok.is_none();
        });
        if !second {
            self.camera_pos = Some(open.pos);
        }
        if !closed || bad {
            return;
        }
        let (Some((eye, _)), Some((lookat, lookat_pos))) = (eye, lookat) else {
            for (missing, field) in [(eye.is_none(), "eye"), (lookat.is_none(), "lookat")] {
                if missing {
                    self.error(open.pos, format!("camera block has no `{field}`"));
                }
            }
            return;
        };
        let (up, up_pos) = up.unwrap_or((DVec3::Y, open.pos));
        let (width, height) = size.unwrap_or(DEFAULT_SIZE);
        let camera = Camera {
            eye: eye.as_vec3(),
            lookat: lookat.as_vec3(),
            up: up.as_vec3(),
            fov_y: fov.unwrap_or(DEFAULT_FOV_DEG).to_radians(),
            width,
            height,
        };
        // The one validation every camera goes through; its errors are
        // placed at the field at fault. The fields were checked one by one
        // already, so only their combination can fail here, but a case
        // nobody foresaw still gets the block's position rather than a
        // failure after solving.
        if let Err(e) = camera.check() {
            match e {
                CameraError::NoViewDirection => self.error(
                    lookat_pos,
                    "`lookat` equals `eye`; the camera has no view direction",
                ),
                CameraError::UpZero => {
                    self.error(up_pos, "`up` is zero; it must give a direction")
                }
                CameraError::UpParallel => self.error(
                    up_pos,
                    format!(
                        "`up` ({} {} {}) is parallel to the view direction; the picture's up would be undefined",
                        fmt_num(up.x),
                        fmt_num(up.y),
                        fmt_num(up.z)
                    ),
                ),
                e => self.error(open.pos, format!("unusable camera: {e}")),
            }
            return;
        }
        if !second {
            self.camera = Some(camera);
        }
    }

    /// `fov DEG`, strictly between 0 and 180 degrees.
    fn fov(&mut self, kw: Token<'a>) -> Option<f32> {
        let n = self.numbers(kw, 1)?[0];
        // Checked on the f32 value the camera keeps, so a value rounding to
        // 180 cannot slip through.
        let deg = n.value as f32;
        // The radians too: a subnormal angle in degrees is zero in radians.
        let rad = deg.to_radians();
        if deg <= 0.0 || deg >= 180.0 || rad <= 0.0 || rad >= std::f32::consts::PI {
            self.error(
                n.pos,
                format!(
                    "`fov` {} is out of range; it must be more than 0 and less than 180 degrees",
                    n.text
                ),
            );
            return None;
        }
        Some(deg)
    }

    /// `size W H`, whole numbers of pixels, each at least 1, within the
    /// renderer's limits ([`MAX_PICTURE_SIDE`], [`MAX_PICTURE_PIXELS`]).
    fn size(&mut self, kw: Token<'a>) -> Option<(u32, u32)> {
        let nums = self.numbers(kw, 2)?;
        let mut out = [0u32; 2];
        let mut ok = true;
        for (slot, n) in out.iter_mut().zip(&nums) {
            let message = if !n.text.bytes().all(|b| b.is_ascii_digit()) {
                format!(
                    "`size` needs whole numbers of pixels (digits only), found {}",
                    quote(n.text)
                )
            } else {
                match n.text.parse::<u32>() {
                    Ok(0) => "`size` must be at least 1 pixel, found `0`".to_owned(),
                    Ok(v) => {
                        *slot = v;
                        continue;
                    }
                    Err(_) => format!(
                        "`size` {} is too large (at most {})",
                        quote(n.text),
                        u32::MAX
                    ),
                }
            };
            self.error(n.pos, message);
            ok = false;
        }
        if ok && !picture_size_ok(out[0], out[1]) {
            self.error(
                nums[0].pos,
                format!(
                    "`size` {}x{} is too large: each side may be at most {MAX_PICTURE_SIDE} pixels \
                     and the picture at most {MAX_PICTURE_PIXELS} pixels (8192x8192)",
                    out[0], out[1]
                ),
            );
            return None;
        }
        ok.then_some((out[0], out[1]))
    }

    // --------------------------------------------------------- material --

    fn material_block(&mut self, open: Token<'a>) {
        let name = self.name(open, MATERIAL_FIELDS);
        let mut registered = None;
        if let Some((name, pos)) = name {
            if let Some(&(_, first)) = self.material_ids.get(name) {
                self.error(
                    pos,
                    format!("material `{name}` is already defined at {}", at(first)),
                );
            } else {
                match u32::try_from(self.materials.len()) {
                    Ok(index) => {
                        // Registered before its body is read, valid or not,
                        // so a mistake in the body does not also make every
                        // use of the name an "undefined material".
                        self.material_ids
                            .insert(name, (MaterialId(index), open.pos));
                        self.materials.push(Material {
                            name: name.to_owned(),
                            color: Rgb::WHITE,
                            k_diffrefl: 0.0,
                            k_emission: 0.0,
                        });
                        registered = Some(index as usize);
                    }
                    Err(_) => self.error(pos, "too many materials"),
                }
            }
        }

        let mut color = Rgb::WHITE;
        let mut k_diffrefl = None;
        let mut k_emission = 0.0;
        let mut emission_pos = open.pos;
        let mut bad = false;
        let closed = self.block(open, MATERIAL_FIELDS, &[], &mut |p, kw| {
            let ok = match kw.text {
                "color" => p.color(kw).map(|c| color = c),
                "k_diffrefl" => p.non_negative(kw).map(|k| k_diffrefl = Some((k, kw.pos))),
                _ => p.non_negative(kw).map(|k| {
                    k_emission = k;
                    emission_pos = kw.pos;
                }),
            };
            bad |= ok.is_none();
        });
        if !closed || bad {
            return;
        }
        let e = color * k_emission;
        if !e.is_finite() || e.max_channel() > MAX_EMISSION {
            self.error(
                emission_pos,
                format!(
                    "emission `k_emission` × `color` is {} in its largest channel; it must be at most {}",
                    fmt_num(e.max_channel()),
                    fmt_num(MAX_EMISSION)
                ),
            );
            return;
        }
        if let Some((k, pos)) = k_diffrefl {
            let rho = color * k;
            if rho.max_channel() >= 1.0 {
                let channel = ["red", "green", "blue"]
                    .into_iter()
                    .zip(rho.to_array())
                    .fold(("red", f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
                self.error(
                    pos,
                    format!(
                        "reflectance `k_diffrefl` × `color` is {} in the {} channel; every channel must be below 1",
                        fmt_num(channel.1),
                        channel.0
                    ),
                );
                return;
            }
        }
        if let Some(m) = registered.and_then(|i| self.materials.get_mut(i)) {
            m.color = color;
            m.k_diffrefl = k_diffrefl.map_or(0.0, |k| k.0);
            m.k_emission = k_emission;
        }
    }

    /// `color R G B`, each channel `>= 0`.
    fn color(&mut self, kw: Token<'a>) -> Option<Rgb> {
        let nums = self.numbers(kw, 3)?;
        let mut ok = true;
        for n in &nums {
            if n.value < 0.0 {
                self.error(
                    n.pos,
                    format!(
                        "`color` channel {} is negative; channels must be >= 0",
                        n.text
                    ),
                );
                ok = false;
            }
        }
        ok.then(|| Rgb::new(nums[0].value, nums[1].value, nums[2].value))
    }

    // ----------------------------------------------------------- shapes --

    fn polygon_block(&mut self, open: Token<'a>) {
        let material = self.material_ref(open, POLYGON_FIELDS);
        let mut vertices = Vec::new();
        let mut bad = false;
        let closed = self.block(
            open,
            POLYGON_FIELDS,
            POLYGON_FIELDS,
            &mut |p, kw| match p.point(kw) {
                Some(v) => vertices.push(v),
                None => bad = true,
            },
        );
        if !closed || bad {
            return;
        }
        self.add_polygon(open, material, &vertices);
    }

    fn box_statement(&mut self, open: Token<'a>) {
        let material = self.material_ref(open, &[]);
        let Some(n) = self.numbers(open, 6) else {
            return;
        };
        if !self.check_coordinates(&n) {
            return;
        }
        let a = DVec3::new(n[0].value, n[1].value, n[2].value);
        let b = DVec3::new(n[3].value, n[4].value, n[5].value);
        let (lo, hi) = (a.min(b), a.max(b));
        for (axis, extent) in ["x", "y", "z"].into_iter().zip((hi - lo).to_array()) {
            if extent == 0.0 {
                self.error(
                    open.pos,
                    format!("box has zero extent along {axis}; it would be flat"),
                );
                return;
            }
        }
        for face in box_faces(lo, hi) {
            if !self.add_polygon(open, material, &face) {
                // One message per box: the faces share whatever went wrong.
                return;
            }
        }
    }

    /// Transforms the vertices by the open transform blocks and adds the
    /// polygon, or reports why it is invalid at `open`. The polygon is only
    /// kept when its material is known. Returns whether the geometry was
    /// valid.
    fn add_polygon(
        &mut self,
        open: Token<'a>,
        material: Option<MaterialId>,
        local: &[DVec3],
    ) -> bool {
        let m = self.current_matrix();
        let world64: Vec<DVec3> = local.iter().map(|&v| m.transform_point3(v)).collect();
        // Checked in f64, before rounding to f32 could turn a far vertex
        // into an infinite one with a less helpful message.
        if let Some(i) = world64
            .iter()
            .position(|v| !v.is_finite() || v.abs().max_element() > MAX_COORDINATE)
        {
            let e = if world64[i].is_finite() {
                PolygonError::TooFar {
                    vertex: i + 1,
                    magnitude: world64[i].abs().max_element(),
                }
            } else {
                PolygonError::NotFinite { vertex: i + 1 }
            };
            self.error(open.pos, format!("{e} (after the enclosing transforms)"));
            return false;
        }
        let mut world: Vec<Vec3> = world64.iter().map(|v| v.as_vec3()).collect();
        if m.matrix3.determinant() < 0.0 && world.len() > 1 {
            // A mirror turns counter-clockwise into clockwise; reversing the
            // order (keeping the first vertex first) puts the front back on
            // the physical side it was written on.
            world[1..].reverse();
        }
        match Polygon::new(material.unwrap_or(MaterialId(0)), world, open.pos) {
            Ok(p) => {
                if material.is_some() {
                    self.polygons.push(p);
                }
                true
            }
            Err(e) => {
                let message = if self.frames.is_empty() {
                    e.to_string()
                } else {
                    format!("{e} (after the enclosing transforms)")
                };
                self.error(open.pos, message);
                false
            }
        }
    }

    /// A rotation, translation or scaling from one line inside a transform
    /// block, or `None` if the line is wrong (reported).
    fn transform_line(&mut self, kw: Token<'a>) -> Option<DAffine3> {
        match kw.text {
            "translate" => self.point(kw).map(DAffine3::from_translation),
            "rotate" => {
                let n = self.numbers(kw, 4)?;
                let axis = DVec3::new(n[0].value, n[1].value, n[2].value);
                // Scale down first so squaring cannot overflow or underflow.
                let largest = axis.abs().max_element();
                let axis = (axis / largest).normalize_or_zero();
                if largest == 0.0 || axis == DVec3::ZERO {
                    self.error(n[0].pos, "rotation axis is zero; it must give a direction");
                    return None;
                }
                let angle = n[3].value.to_radians();
                Some(DAffine3::from_mat3(DMat3::from_axis_angle(axis, angle)))
            }
            _ => {
                let mut n = self.numbers(kw, 1)?;
                if matches!(self.peek().kind, Kind::Number(_) | Kind::Bad) {
                    n.extend(self.more_numbers(kw, 2, 1)?);
                }
                let mut ok = true;
                for f in &n {
                    if f.value == 0.0 {
                        self.error(
                            f.pos,
                            format!(
                                "scale factor {} is zero; factors must be non-zero",
                                quote(f.text)
                            ),
                        );
                        ok = false;
                    }
                }
                let factors = match n.as_slice() {
                    [s] => DVec3::splat(s.value),
                    [x, y, z] => DVec3::new(x.value, y.value, z.value),
                    _ => return None,
                };
                ok.then(|| DAffine3::from_scale(factors))
            }
        }
    }

    // ----------------------------------------------------------- finish --

    fn finish(mut self) -> Result<Scene, LoadError> {
        self.report_pending(true)?;
        let (camera, camera_source) = match self.camera {
            Some(c) => (c, CameraSource::File),
            None => {
                let (lo, hi) = super::polygon_bounds(&self.polygons);
                (Camera::frame(lo, hi), CameraSource::AutoFramed)
            }
        };
        Ok(Scene {
            polygons: self.polygons,
            materials: self.materials,
            camera,
            camera_source,
        })
    }

    /// Reports the uses of undefined materials and, when
    /// `require_polygons`, an empty scene; then every diagnostic found, in
    /// file order, if there is any.
    fn report_pending(&mut self, require_polygons: bool) -> Result<(), LoadError> {
        for u in std::mem::take(&mut self.undefined_uses) {
            let message = match self.material_ids.get(u.name.as_str()) {
                Some(&(_, def)) => format!(
                    "material `{}` is used before its definition at {}",
                    u.name,
                    at(def)
                ),
                None => format!("undefined material `{}`", u.name),
            };
            self.error(u.pos, message);
        }
        if require_polygons && self.diags.is_empty() && self.polygons.is_empty() {
            self.error(FILE_START, "scene has no polygons");
        }
        if !self.diags.is_empty() {
            return Err(LoadError::from_diagnostics(std::mem::take(&mut self.diags)));
        }
        Ok(())
    }
}

/// The six faces of the box `lo..hi`, each counter-clockwise seen from
/// outside, in the order -x, +x, -y, +y, -z, +z.
fn box_faces(lo: DVec3, hi: DVec3) -> [[DVec3; 4]; 6] {
    let c = |x: bool, y: bool, z: bool| {
        DVec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let (f, t) = (false, true);
    [
        [c(f, f, f), c(f, f, t), c(f, t, t), c(f, t, f)],
        [c(t, f, f), c(t, t, f), c(t, t, t), c(t, f, t)],
        [c(f, f, f), c(t, f, f), c(t, f, t), c(f, f, t)],
        [c(f, t, f), c(f, t, t), c(t, t, t), c(t, t, f)],
        [c(f, f, f), c(f, t, f), c(t, t, f), c(t, f, f)],
        [c(f, f, t), c(t, f, t), c(t, t, t), c(f, t, t)],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Shape;

    /// The example at the end of the format's contract.
    const EXAMPLE: &str = "\
# a white room lit by one square lamp, with a red box on the floor
camera
  eye 2.5 1.5 -4
  lookat 2.5 1.5 2.5
  up 0 1 0
  fov 50
  size 640 480
end

material white
  color 1 1 1
  k_diffrefl 0.75
end
material red
  color 0.9 0.1 0.1
  k_diffrefl 0.8
end
material lamp
  color 1 0.9 0.8
  k_emission 20
end

# floor, seen from above: counter-clockwise from +y
polygon white
  vertex 0 0 0
  vertex 0 0 5
  vertex 5 0 5
  vertex 5 0 0
end
# lamp under the ceiling, facing down
polygon lamp
  vertex 2 2.99 2
  vertex 3 2.99 2
  vertex 3 2.99 3
  vertex 2 2.99 3
end
transform
  translate 1 0 1
  rotate 0 1 0 30
  box red 0 0 0 1 1 1
end
";

    /// A material and nothing else, to put in front of shapes.
    const WHITE: &str = "material white k_diffrefl 0.5 end\n";
    /// A valid triangle, for files that need some polygon.
    const TRIANGLE: &str = "polygon white vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end\n";

    fn parse(src: &str) -> Scene {
        match parse_str(src, "t.sc") {
            Ok(s) => {
                for p in &s.polygons {
                    assert_eq!(p.validate(), Ok(()));
                }
                s
            }
            Err(e) => panic!("expected the scene to load, got:\n{e}"),
        }
    }

    /// Every diagnostic as `LINE:COL: MESSAGE`.
    fn errors(src: &str) -> Vec<String> {
        match parse_str(src, "t.sc") {
            Ok(_) => panic!("expected an error for:\n{src}"),
            Err(e) => {
                assert!(!e.diagnostics.is_empty());
                e.diagnostics
                    .iter()
                    .map(|d| format!("{}:{}: {}", d.line, d.col, d.message))
                    .collect()
            }
        }
    }

    fn first_error(src: &str) -> String {
        errors(src).swap_remove(0)
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    fn has_vertex(p: &Polygon, v: Vec3) -> bool {
        p.vertices.iter().any(|&w| close(w, v))
    }

    // ------------------------------------------------------------ valid --

    #[test]
    fn the_contract_example_loads() {
        let s = parse(EXAMPLE);
        assert_eq!(s.polygons.len(), 8, "1 floor + 1 lamp + 6 box faces");
        let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["white", "red", "lamp"]);
        assert_eq!(s.camera_source, CameraSource::File);
        assert_eq!(s.camera.eye, Vec3::new(2.5, 1.5, -4.0));
        assert_eq!(s.camera.lookat, Vec3::new(2.5, 1.5, 2.5));
        assert!((s.camera.fov_y - 50f32.to_radians()).abs() < 1e-7);
        assert_eq!((s.camera.width, s.camera.height), (640, 480));

        let floor = &s.polygons[0];
        assert_eq!(floor.normal, Vec3::Y);
        assert_eq!(floor.shape, Shape::Parallelogram);
        assert_eq!(floor.origin, SourcePos { line: 24, col: 1 });
        let lamp = &s.polygons[1];
        assert!(close(lamp.normal, -Vec3::Y), "the lamp faces down");
        assert_eq!(s.material_of(crate::scene::PolygonId(1)).name, "lamp");
        let lamp_m = &s.materials[lamp.material.index()];
        assert_eq!(lamp_m.emission(), Rgb::new(20.0, 18.0, 16.0));

        // The box is rotated 30° about +y first, then moved by (1, 0, 1).
        let (sin, cos) = 30f32.to_radians().sin_cos();
        let rotate = |v: Vec3| Vec3::new(cos * v.x + sin * v.z, v.y, -sin * v.x + cos * v.z);
        let place = |v: Vec3| rotate(v) + Vec3::new(1.0, 0.0, 1.0);
        let faces = &s.polygons[2..];
        for corner in [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Z,
            Vec3::ONE,
            Vec3::new(1.0, 0.0, 1.0),
        ] {
            assert!(
                faces.iter().any(|p| has_vertex(p, place(corner))),
                "box corner {corner} should be at {}",
                place(corner)
            );
        }
        // The -x face's normal is the rotated -x axis.
        assert!(close(faces[0].normal, rotate(-Vec3::X)));
        for f in faces {
            assert_eq!(f.material, MaterialId(1));
            assert_eq!(f.shape, Shape::Parallelogram);
            assert!((f.area - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn camera_defaults() {
        let s = parse(&format!(
            "camera eye 0 0 -5 lookat 0 0 0 end\n{WHITE}{TRIANGLE}"
        ));
        assert_eq!(s.camera_source, CameraSource::File);
        assert_eq!(s.camera.up, Vec3::Y);
        assert_eq!(s.camera.fov_y, DEFAULT_FOV_DEG.to_radians());
        assert_eq!((s.camera.width, s.camera.height), DEFAULT_SIZE);
    }

    #[test]
    fn camera_every_field() {
        let s = parse(&format!(
            "camera\n size 320 200\n fov 90\n up 0 0 1\n lookat 1 2 3\n eye 4 5 6\nend\n{WHITE}{TRIANGLE}"
        ));
        let c = s.camera;
        assert_eq!(c.eye, Vec3::new(4.0, 5.0, 6.0));
        assert_eq!(c.lookat, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(c.up, Vec3::Z);
        assert!((c.fov_y - std::f32::consts::FRAC_PI_2).abs() < 1e-7);
        assert_eq!((c.width, c.height), (320, 200));
    }

    #[test]
    fn no_camera_frames_the_scene() {
        let s = parse(&format!("{WHITE}box white -1 0 2 3 4 7\n"));
        assert_eq!(s.camera_source, CameraSource::AutoFramed);
        let c = s.camera;
        assert_eq!(c.lookat, Vec3::new(1.0, 2.0, 4.5));
        assert_eq!(c.up, Vec3::Y);
        assert_eq!((c.width, c.height), DEFAULT_SIZE);
        assert!(c.eye.z < -0.5, "eye on the -z side of the scene");
        // Every vertex is inside the vertical field of view.
        let forward = (c.lookat - c.eye).normalize();
        for p in &s.polygons {
            for &v in &p.vertices {
                let angle = (v - c.eye).normalize().dot(forward).acos();
                assert!(angle <= 0.5 * c.fov_y + 1e-5, "{v} is outside the view");
            }
        }
    }

    #[test]
    fn materials_defaults_and_fields() {
        let s = parse(
            &format!(
                "material plain end\n\
             material glow color 1 0.5 0.25 k_emission 4 k_diffrefl 0.5 end\n\
             {TRIANGLE}"
            )
            .replace("polygon white", "polygon glow"),
        );
        let plain = &s.materials[0];
        assert_eq!(plain.name, "plain");
        assert_eq!(plain.color, Rgb::WHITE);
        assert_eq!((plain.k_diffrefl, plain.k_emission), (0.0, 0.0));
        let glow = &s.materials[1];
        assert_eq!(glow.emission(), Rgb::new(4.0, 2.0, 1.0));
        assert_eq!(glow.reflectance(), Rgb::new(0.5, 0.25, 0.125));
        assert_eq!(s.polygons[0].material, MaterialId(1));
    }

    #[test]
    fn polygon_shapes_are_classified() {
        let s = parse(&format!(
            "{WHITE}{TRIANGLE}\
             polygon white vertex 0 0 0 vertex 2 0 0 vertex 3 1 0 vertex 1 1 0 end\n\
             polygon white vertex 0 0 0 vertex 3 0 0 vertex 2 1 0 vertex 1 1 0 end\n\
             polygon white vertex 0 0 0 vertex 2 0 0 vertex 3 1 0 vertex 1 2 0 vertex -1 1 0 end\n"
        ));
        let shapes: Vec<Shape> = s.polygons.iter().map(|p| p.shape).collect();
        assert_eq!(
            shapes,
            [
                Shape::Triangle,
                Shape::Parallelogram,
                Shape::Quad,
                Shape::Convex
            ]
        );
        assert!(s.polygons.iter().all(|p| p.normal == Vec3::Z));
    }

    #[test]
    fn box_faces_point_outward_with_the_right_areas() {
        // Corners given max-first: the order does not matter.
        for src in [
            "box white 1 2 3 4 6 8",
            "box white 4 6 8 1 2 3",
            "box white 4 2 8 1 6 3",
        ] {
            let s = parse(&format!("{WHITE}{src}\n"));
            assert_eq!(s.polygons.len(), 6);
            let centre = Vec3::new(2.5, 4.0, 5.5);
            let expected_normals = [-Vec3::X, Vec3::X, -Vec3::Y, Vec3::Y, -Vec3::Z, Vec3::Z];
            // Extents 3 × 4 × 5.
            let expected_areas = [20.0, 20.0, 15.0, 15.0, 12.0, 12.0];
            for ((p, n), area) in s.polygons.iter().zip(expected_normals).zip(expected_areas) {
                assert_eq!(p.normal, n);
                let face_centre = p.vertices.iter().sum::<Vec3>() / 4.0;
                assert!((face_centre - centre).dot(p.normal) > 0.0);
                assert!((p.area - area).abs() < 1e-9);
                assert_eq!(p.shape, Shape::Parallelogram);
                assert_eq!(p.origin, SourcePos { line: 2, col: 1 });
            }
        }
    }

    #[test]
    fn transform_lines_act_last_first() {
        // Rotate first, then translate: the corner (1,0,0) turns to -z
        // under a 90° turn about +y and then moves by (10, 0, 0).
        let s = parse(&format!(
            "{WHITE}transform translate 10 0 0 rotate 0 1 0 90 {TRIANGLE} end\n"
        ));
        let p = &s.polygons[0];
        assert!(close(p.vertices[0], Vec3::new(10.0, 0.0, 0.0)));
        assert!(close(p.vertices[1], Vec3::new(10.0, 0.0, -1.0)));
        assert!(close(p.vertices[2], Vec3::new(10.0, 1.0, 0.0)));
        assert!(close(p.normal, Vec3::X));

        // The other order: translate first, then rotate the result.
        let s = parse(&format!(
            "{WHITE}transform rotate 0 1 0 90 translate 10 0 0 {TRIANGLE} end\n"
        ));
        assert!(close(s.polygons[0].vertices[0], Vec3::new(0.0, 0.0, -10.0)));
    }

    #[test]
    fn scale_uniform_and_per_axis() {
        let s = parse(&format!(
            "{WHITE}transform scale 2 {TRIANGLE} scale 1 3 1 {TRIANGLE} end\n"
        ));
        assert!(close(s.polygons[0].vertices[1], Vec3::new(2.0, 0.0, 0.0)));
        assert!((s.polygons[0].area - 2.0).abs() < 1e-9);
        // Both lines act on the second triangle: (0,1,0) → (0,3,0) → (0,6,0).
        assert!(close(s.polygons[1].vertices[2], Vec3::new(0.0, 6.0, 0.0)));
    }

    #[test]
    fn a_line_acts_only_on_what_follows_it() {
        let s = parse(&format!(
            "{WHITE}transform {TRIANGLE} translate 0 0 7 {TRIANGLE} end {TRIANGLE}"
        ));
        assert_eq!(s.polygons[0].vertices[0], Vec3::ZERO);
        assert_eq!(s.polygons[1].vertices[0], Vec3::new(0.0, 0.0, 7.0));
        assert_eq!(s.polygons[2].vertices[0], Vec3::ZERO);
    }

    #[test]
    fn nested_blocks_act_inner_first() {
        let s = parse(&format!(
            "{WHITE}transform\n translate 10 0 0\n transform\n  rotate 0 0 1 90\n  {TRIANGLE} end\n {TRIANGLE}end\n"
        ));
        // Inner: (1,0,0) rotates to (0,1,0), then the outer moves it.
        assert!(close(s.polygons[0].vertices[1], Vec3::new(10.0, 1.0, 0.0)));
        // After the inner block only the outer line applies.
        assert!(close(s.polygons[1].vertices[1], Vec3::new(11.0, 0.0, 0.0)));
    }

    #[test]
    fn mirroring_keeps_fronts_on_the_physical_side() {
        let floor = "polygon white vertex 0 0 0 vertex 0 0 5 vertex 5 0 5 vertex 5 0 0 end";
        // Mirrored left-right, a floor still faces up.
        let s = parse(&format!("{WHITE}transform scale -1 1 1 {floor} end\n"));
        let p = &s.polygons[0];
        assert_eq!(p.normal, Vec3::Y);
        assert_eq!(p.vertices[0], Vec3::ZERO, "the first vertex stays first");
        assert!(has_vertex(p, Vec3::new(-5.0, 0.0, 5.0)));
        // Mirrored upside down, it faces down, as its mirror image does.
        let s = parse(&format!("{WHITE}transform scale 1 -1 1 {floor} end\n"));
        assert_eq!(s.polygons[0].normal, -Vec3::Y);
        // A mirrored box stays closed with outward fronts.
        let s = parse(&format!(
            "{WHITE}transform scale -2 1 1 box white 0 0 0 1 1 1 end\n"
        ));
        let centre = Vec3::new(-1.0, 0.5, 0.5);
        for p in &s.polygons {
            let face_centre = p.vertices.iter().sum::<Vec3>() / 4.0;
            assert!((face_centre - centre).dot(p.normal) > 0.0);
        }
    }

    #[test]
    fn comments_end_tokens_anywhere() {
        let s = parse(
            "material wh#comment right in the name\n k_diffrefl 0.5#and here\n end#\n\
             polygon wh vertex 0 0 0 vertex 1# 2 3\n 0 0 vertex 0 1 0 end # done",
        );
        assert_eq!(s.materials[0].name, "wh");
        assert_eq!(s.materials[0].k_diffrefl, 0.5);
        assert_eq!(s.polygons[0].vertices[1], Vec3::X);
    }

    #[test]
    fn byte_order_mark_is_skipped() {
        let s = parse(&format!("\u{feff}{WHITE}{TRIANGLE}"));
        assert_eq!(s.polygons.len(), 1);
        // Columns on line 1 do not count the mark.
        assert_eq!(first_error("\u{feff}bogus"), "1:1: unknown keyword `bogus`");
    }

    #[test]
    fn every_number_form() {
        let s = parse(&format!(
            "camera eye 1 -0.5 .5 lookat 5. +2 2.5E-3 up 0 1e0 0 fov 4.5e+1 end\n{WHITE}{TRIANGLE}"
        ));
        assert_eq!(s.camera.eye, Vec3::new(1.0, -0.5, 0.5));
        assert_eq!(s.camera.lookat, Vec3::new(5.0, 2.0, 0.0025));
        assert_eq!(s.camera.fov_y, 45f32.to_radians());
    }

    #[test]
    fn number_grammar() {
        for ok in [
            "1", "-0.5", ".5", "5.", "+2", "2.5E-3", "1e5", "0", "-.5e+2",
        ] {
            assert!(is_number(ok), "{ok}");
        }
        for bad in [
            "", ".", "+", "-.", "1e", "1e+", "e5", "1.2.3", "0x10", "1_000", "5.e", "1f",
        ] {
            assert!(!is_number(bad), "{bad}");
        }
    }

    #[test]
    fn name_charset() {
        let s = parse(&format!(
            "material A_b.c-1 end material _ end material Inf2 end {WHITE}{TRIANGLE}"
        ));
        let names: Vec<&str> = s.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["A_b.c-1", "_", "Inf2", "white"]);
        assert_eq!(
            first_error("material 2x end"),
            "1:10: `material` needs a name, found `2x`; names start with a letter or `_`"
        );
        assert_eq!(
            first_error("material nan end"),
            "1:10: `nan` cannot be used as a name"
        );
    }

    #[test]
    fn columns_count_characters_and_tabs_are_one() {
        // `ééé` is 6 bytes but 3 columns; a tab is one column.
        assert_eq!(
            errors("ééé foo\n\tbar"),
            [
                "1:1: unexpected `ééé`: not a keyword, a name or a number",
                "1:5: unknown keyword `foo`",
                "2:2: unknown keyword `bar`",
            ]
        );
    }

    #[test]
    fn crlf_line_ends() {
        let s = parse(&format!("{WHITE}{TRIANGLE}").replace('\n', "\r\n"));
        assert_eq!(s.polygons.len(), 1);
        assert_eq!(
            first_error("\r\n\r\n  bogus\r\n"),
            "3:3: unknown keyword `bogus`"
        );
    }

    #[test]
    fn unused_materials_are_kept() {
        let s = parse(&format!("material spare end {WHITE}{TRIANGLE}"));
        assert_eq!(s.materials.len(), 2);
        assert_eq!(s.polygons[0].material, MaterialId(1));
    }

    // ----------------------------------------------------------- errors --

    #[test]
    fn diagnostics_name_the_file() {
        match parse_str("bogus", "scenes/room.sc") {
            Err(e) => assert_eq!(
                e.to_string(),
                "scenes/room.sc:1:1: error: unknown keyword `bogus`"
            ),
            Ok(_) => panic!("should fail"),
        }
    }

    #[test]
    fn unknown_keyword() {
        assert_eq!(
            first_error(&format!("{WHITE}\n  lights 1 2 3\n{TRIANGLE}")),
            "3:3: unknown keyword `lights`"
        );
        assert_eq!(
            first_error("camera\n  eye 0 0 0 lookat 0 0 1\n  colour 1 1 1\nend"),
            "3:3: unknown keyword `colour` in camera block \
             (expected `eye`, `lookat`, `up`, `fov`, `size` or `end`)"
        );
        assert_eq!(
            first_error("material m\n  vertex 1 1 1\nend"),
            "2:3: `vertex` is not allowed in a material block \
             (expected `color`, `k_diffrefl`, `k_emission` or `end`)"
        );
        assert_eq!(
            first_error("vertex 0 0 0"),
            "1:1: `vertex` is only allowed inside a polygon block"
        );
        assert_eq!(
            first_error("Camera eye 0 0 0 end"),
            "1:1: unknown keyword `Camera`"
        );
    }

    #[test]
    fn missing_number() {
        assert_eq!(
            first_error("camera\n  eye 1 2\n  lookat 0 0 0\nend"),
            "2:3: missing number: `eye` takes 3 numbers, found 2"
        );
        assert_eq!(
            first_error(&format!("{WHITE}polygon white vertex 0 0 0 vertex 1 0 end")),
            "2:28: missing number: `vertex` takes 3 numbers, found 2"
        );
        assert_eq!(
            first_error(&format!("{WHITE}box white 0 0 0 1 1 end")),
            "2:1: missing number: `box` takes a material name and 6 numbers, found 5"
        );
        assert_eq!(
            first_error(&format!("{WHITE}transform scale 1 2 {TRIANGLE} end")),
            "2:11: missing number: `scale` takes 1 or 3 numbers, found 2"
        );
    }

    #[test]
    fn extra_number() {
        assert_eq!(
            first_error("camera\n  eye 1 2 3 4\n  lookat 0 0 0\nend"),
            "2:13: extra number `4`: `eye` takes 3 numbers"
        );
        assert_eq!(
            first_error(&format!("{WHITE}box white 0 0 0 1 1 1 1")),
            "2:23: extra number `1`: `box` takes a material name and 6 numbers"
        );
        assert_eq!(
            first_error("5 camera"),
            "1:1: unexpected number `5`; expected a keyword"
        );
        assert_eq!(
            first_error(&format!(
                "{WHITE}polygon white 1 vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end"
            )),
            "2:15: extra number `1`: `polygon` takes a material name and no numbers \
             (vertices go on `vertex` lines)"
        );
    }

    #[test]
    fn bad_number_forms() {
        let at_fov = |v: &str| first_error(&format!("camera fov {v} end"));
        assert_eq!(
            at_fov("nan"),
            "1:12: `nan` is not allowed: numbers must be finite decimals"
        );
        assert_eq!(
            at_fov("inf"),
            "1:12: `inf` is not allowed: numbers must be finite decimals"
        );
        assert_eq!(
            at_fov("-Infinity"),
            "1:12: `-Infinity` is not allowed: numbers must be finite decimals"
        );
        assert_eq!(
            at_fov("0x10"),
            "1:12: invalid number `0x10`: numbers are decimal, like 1, -0.5, .5 or 2.5e-3"
        );
        assert_eq!(
            at_fov("1e999"),
            "1:12: number `1e999` is out of range (it overflows to infinity)"
        );
        assert_eq!(
            first_error(&format!(
                "{WHITE}polygon white vertex 1e39 0 0 vertex 1 0 0 vertex 0 1 0 end"
            )),
            "2:22: number `1e39` is too large for a coordinate (at most 1e12 in magnitude)"
        );
    }

    #[test]
    fn size_must_be_whole_positive_pixels() {
        let at_size = |v: &str| first_error(&format!("camera\n  size {v}\nend"));
        assert_eq!(
            at_size("640.0 480"),
            "2:8: `size` needs whole numbers of pixels (digits only), found `640.0`"
        );
        assert_eq!(
            at_size("640 +480"),
            "2:12: `size` needs whole numbers of pixels (digits only), found `+480`"
        );
        assert_eq!(
            at_size("640 0"),
            "2:12: `size` must be at least 1 pixel, found `0`"
        );
        assert_eq!(
            at_size("99999999999 1"),
            "2:8: `size` `99999999999` is too large (at most 4294967295)"
        );
        assert_eq!(
            at_size("100000 100000"),
            "2:8: `size` 100000x100000 is too large: each side may be at most 65536 pixels \
             and the picture at most 67108864 pixels (8192x8192)"
        );
        assert!(at_size("65536 1025").contains("too large"));
        assert!(
            parse_str("camera eye 0 0 -1 lookat 0 0 0 size 8192 8192 end", "a.sc")
                .unwrap_err()
                .to_string()
                .contains("no polygons")
        );
    }

    #[test]
    fn fov_out_of_range() {
        for (v, col) in [("0", 12), ("180", 12), ("-5", 12), ("1000", 12)] {
            assert_eq!(
                first_error(&format!("camera fov {v} end")),
                format!(
                    "1:{col}: `fov` {v} is out of range; it must be more than 0 and less than 180 degrees"
                )
            );
        }
    }

    #[test]
    fn negative_color_and_coefficients() {
        assert_eq!(
            first_error("material m\n  color 1 -0.5 1\nend"),
            "2:11: `color` channel -0.5 is negative; channels must be >= 0"
        );
        assert_eq!(
            first_error("material m k_emission -1 end"),
            "1:23: `k_emission` -1 is negative; it must be >= 0"
        );
        assert_eq!(
            first_error("material m k_diffrefl -0.1 end"),
            "1:23: `k_diffrefl` -0.1 is negative; it must be >= 0"
        );
    }

    #[test]
    fn reflectance_must_stay_below_one() {
        assert_eq!(
            first_error("material m\n  color 0.5 1.25 1\n  k_diffrefl 0.8\nend"),
            "3:3: reflectance `k_diffrefl` × `color` is 1 in the green channel; \
             every channel must be below 1"
        );
        // Emission may be as large as it likes.
        parse(&format!(
            "material m color 2 2 2 k_emission 100 k_diffrefl 0.49 end {}",
            TRIANGLE.replace("white", "m")
        ));
    }

    #[test]
    fn duplicate_field() {
        assert_eq!(
            first_error("camera\n  eye 0 0 0\n  lookat 0 0 1\n  eye 1 1 1\nend"),
            "4:3: duplicate `eye` in camera block (first at 2:3)"
        );
        assert_eq!(
            first_error("material m color 1 1 1 color 0 0 0 end"),
            "1:24: duplicate `color` in material block (first at 1:12)"
        );
    }

    #[test]
    fn duplicate_material() {
        assert_eq!(
            first_error(&format!("{WHITE}\nmaterial white end {TRIANGLE}")),
            "3:10: material `white` is already defined at 1:1"
        );
    }

    #[test]
    fn undefined_material() {
        assert_eq!(
            first_error(&format!(
                "{WHITE}polygon black vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end"
            )),
            "2:9: undefined material `black`"
        );
        assert_eq!(
            first_error("box black 0 0 0 1 1 1"),
            "1:5: undefined material `black`"
        );
    }

    #[test]
    fn material_used_before_its_definition() {
        assert_eq!(
            errors(&format!("{TRIANGLE}{WHITE}")),
            ["1:9: material `white` is used before its definition at 2:1"]
        );
    }

    #[test]
    fn keyword_as_name() {
        assert_eq!(
            first_error("material box end"),
            "1:10: `box` is a keyword and cannot be used as a name"
        );
        assert_eq!(
            first_error("material color 1 1 1 end"),
            "1:10: missing name: `material` needs a name before `color`"
        );
        assert_eq!(
            first_error("polygon vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 end"),
            "1:9: missing name: `polygon` needs a material name before `vertex`"
        );
    }

    #[test]
    fn fewer_than_three_vertices() {
        assert_eq!(
            first_error(&format!(
                "{WHITE}\npolygon white\n  vertex 0 0 0\n  vertex 1 0 0\nend"
            )),
            "3:1: polygon has 2 vertices; at least 3 are needed"
        );
        assert_eq!(
            first_error(&format!("{WHITE}polygon white end")),
            "2:1: polygon has 0 vertices; at least 3 are needed"
        );
    }

    #[test]
    fn equal_consecutive_vertices() {
        assert_eq!(
            first_error(&format!(
                "{WHITE}polygon white vertex 0 0 0 vertex 1 0 0 vertex 1 0 0 vertex 0 1 0 end"
            )),
            "2:1: vertices 2 and 3 are equal"
        );
    }

    #[test]
    fn non_planar_polygon() {
        assert_eq!(
            first_error(&format!(
                "{WHITE}polygon white vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 vertex 0 1 0.5 end"
            )),
            "2:1: polygon is not planar: vertex 1 is 0.118 units from the plane (tolerance 0.0015)"
        );
    }

    #[test]
    fn non_convex_polygon() {
        assert_eq!(
            first_error(&format!(
                "{WHITE}polygon white vertex 0 0 0 vertex 2 0 0 vertex 1 0.5 0 \
                 vertex 2 2 0 vertex 0 2 0 end"
            )),
            "2:1: polygon is not convex at vertex 3"
        );
    }

    #[test]
    fn zero_area_polygon() {
        assert_eq!(
            first_error(&format!(
                "{WHITE}polygon white vertex 0 0 0 vertex 1 1 1 vertex 2 2 2 end"
            )),
            "2:1: polygon has zero area"
        );
    }

    #[test]
    fn zero_extent_box() {
        assert_eq!(
            first_error(&format!("{WHITE}\n  box white 0 1 0 1 1 1")),
            "3:3: box has zero extent along y; it would be flat"
        );
    }

    #[test]
    fn zero_scale_and_zero_axis() {
        assert_eq!(
            first_error(&format!("{WHITE}transform scale 1 0 1 {TRIANGLE} end")),
            "2:19: scale factor `0` is zero; factors must be non-zero"
        );
        assert_eq!(
            first_error(&format!("{WHITE}transform scale -0.0 {TRIANGLE} end")),
            "2:17: scale factor `-0.0` is zero; factors must be non-zero"
        );
        assert_eq!(
            first_error(&format!("{WHITE}transform rotate 0 0 0 45 {TRIANGLE} end")),
            "2:18: rotation axis is zero; it must give a direction"
        );
    }

    #[test]
    fn transform_lines_outside_a_transform() {
        assert_eq!(
            first_error("translate 1 2 3"),
            "1:1: `translate` is only allowed inside a transform block"
        );
    }

    #[test]
    fn unterminated_blocks() {
        assert_eq!(
            errors(&format!("{WHITE}\n  polygon white\n  vertex 0 0 0\n")),
            ["3:3: unterminated `polygon` block: end of file before its `end`"]
        );
        assert_eq!(
            errors(&format!("{WHITE}transform\n transform\n{TRIANGLE}end\n")),
            ["2:1: unterminated `transform` block: end of file before its `end`"]
        );
        // A statement keyword inside a block means its `end` is missing;
        // the statement itself is still read.
        assert_eq!(
            errors(&format!(
                "camera eye 0 0 -1 lookat 0 0 0\n{WHITE}{TRIANGLE}"
            )),
            ["1:1: unterminated `camera` block: `material` at 2:1 comes before its `end`"]
        );
    }

    #[test]
    fn end_without_a_block() {
        assert_eq!(
            first_error(&format!("{WHITE}{TRIANGLE}end")),
            "3:1: `end` without an open block"
        );
    }

    #[test]
    fn second_camera() {
        let cam = "camera eye 0 0 -1 lookat 0 0 0 end\n";
        assert_eq!(
            errors(&format!("{cam}{cam}{WHITE}{TRIANGLE}")),
            ["2:1: second `camera` block; the first is at 1:1"]
        );
    }

    #[test]
    fn camera_and_material_inside_transform() {
        assert_eq!(
            errors(&format!(
                "transform\n  camera eye 0 0 -1 lookat 0 0 0 end\nend\n{WHITE}{TRIANGLE}"
            )),
            ["2:3: `camera` is not allowed inside a transform block"]
        );
        assert_eq!(
            errors(&format!("transform\n  {WHITE}end\n{TRIANGLE}")),
            ["2:3: `material` is not allowed inside a transform block"]
        );
    }

    #[test]
    fn camera_geometry_errors() {
        assert_eq!(
            first_error("camera\n  lookat 0 0 0\nend"),
            "1:1: camera block has no `eye`"
        );
        assert_eq!(
            errors("camera end"),
            [
                "1:1: camera block has no `eye`",
                "1:1: camera block has no `lookat`"
            ]
        );
        assert_eq!(
            first_error("camera\n  eye 1 2 3\n  lookat 1 2 3\nend"),
            "3:3: `lookat` equals `eye`; the camera has no view direction"
        );
        assert_eq!(
            first_error("camera eye 0 0 0 lookat 0 5 0 end"),
            "1:1: `up` (0 1 0) is parallel to the view direction; \
             the picture's up would be undefined"
        );
        assert_eq!(
            first_error("camera eye 0 0 0 lookat 0 0 1 up 0 0 -2 end"),
            "1:31: `up` (0 0 -2) is parallel to the view direction; \
             the picture's up would be undefined"
        );
        assert_eq!(
            first_error("camera eye 0 0 0 lookat 0 0 1 up 0 0 0 end"),
            "1:31: `up` is zero; it must give a direction"
        );
    }

    #[test]
    fn empty_scene() {
        assert_eq!(errors(""), ["1:1: scene has no polygons"]);
        assert_eq!(
            errors(&format!("# just a material\n{WHITE}")),
            ["1:1: scene has no polygons"]
        );
    }

    #[test]
    fn independent_errors_are_all_reported_in_file_order() {
        let src = format!(
            "{TRIANGLE}\
             material m color 1 1 -1 end\n\
             bogus 1 2\n\
             camera fov 200 end\n\
             {WHITE}"
        );
        assert_eq!(
            errors(&src),
            [
                "1:9: material `white` is used before its definition at 5:1",
                "2:22: `color` channel -1 is negative; channels must be >= 0",
                "3:1: unknown keyword `bogus`",
                "4:12: `fov` 200 is out of range; it must be more than 0 and less than 180 degrees",
            ]
        );
    }

    #[test]
    fn diagnostics_are_capped() {
        let src = "bogus\n".repeat(3 * MAX_DIAGNOSTICS);
        assert_eq!(errors(&src).len(), MAX_DIAGNOSTICS);
    }

    #[test]
    fn never_panics_on_damaged_input() {
        // Every prefix of the example, and the example with bytes replaced
        // by a fixed pseudo-random sequence: each must load or fail cleanly.
        let chars: Vec<char> = EXAMPLE.chars().collect();
        for n in 0..chars.len() {
            let prefix: String = chars[..n].iter().collect();
            let _ = parse_str(&prefix, "t.sc");
        }
        let alphabet: Vec<char> = " \n#-+.e0159abxyz_\u{e9}endvertexboxtransform"
            .chars()
            .collect();
        let mut state: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..2000 {
            let mut damaged = chars.clone();
            for _ in 0..(next() % 6 + 1) {
                let i = (next() % damaged.len() as u64) as usize;
                damaged[i] = alphabet[(next() % alphabet.len() as u64) as usize];
            }
            let text: String = damaged.into_iter().collect();
            let _ = parse_str(&text, "t.sc");
        }
    }

    #[test]
    fn deep_nesting_does_not_overflow_the_stack() {
        let src = format!(
            "{WHITE}{}{TRIANGLE}{}",
            "transform translate 0 0 1\n".repeat(100_000),
            "end\n".repeat(100_000)
        );
        let s = parse(&src);
        assert_eq!(s.polygons[0].vertices[0], Vec3::new(0.0, 0.0, 100_000.0));
    }

    // ------------------------------------------------------------ files --

    /// A file in the system's temporary directory, removed when dropped.
    struct TempFile(std::path::PathBuf);

    impl TempFile {
        fn new(name: &str, bytes: &[u8]) -> Self {
            let path = std::env::temp_dir()
                .join(format!("radiosity-sc-test-{}-{name}", std::process::id()));
            std::fs::write(&path, bytes).expect("write a temporary file");
            TempFile(path)
        }
    }

    impl Drop for TempFile {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    #[test]
    fn load_file_reads_and_parses() {
        let f = TempFile::new("ok.sc", format!("\u{feff}{WHITE}{TRIANGLE}").as_bytes());
        match load_file(&f.0) {
            Ok(s) => assert_eq!(s.polygons.len(), 1),
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn load_file_reports_the_first_bad_utf8_byte() {
        let f = TempFile::new("bad.sc", b"\xEF\xBB\xBFmaterial m\n  color \xff 1 1\nend\n");
        match load_file(&f.0) {
            Ok(_) => panic!("should fail"),
            Err(e) => {
                let d = &e.diagnostics[0];
                assert_eq!(e.diagnostics.len(), 1);
                assert_eq!((d.line, d.col), (2, 9));
                assert_eq!(d.message, "file is not valid UTF-8");
                assert_eq!(d.file, f.0.display().to_string());
            }
        }
        // A truncated multi-byte character at the very end.
        match decode(
            "é\nab\u{e9}"
                .as_bytes()
                .split_last()
                .map_or(&[][..], |x| x.1),
            "t.sc",
        ) {
            Ok(_) => panic!("should fail"),
            Err(e) => assert_eq!(e.to_string(), "t.sc:2:3: error: file is not valid UTF-8"),
        }
    }

    #[test]
    fn load_file_reports_unreadable_files() {
        let path = std::env::temp_dir().join("radiosity-sc-test-does-not-exist.sc");
        match load_file(&path) {
            Ok(_) => panic!("should fail"),
            Err(e) => {
                let d = &e.diagnostics[0];
                assert_eq!((d.line, d.col), (1, 1));
                assert!(d.message.starts_with("cannot read file: "), "{}", d.message);
            }
        }
    }

    #[test]
    fn camera_files_need_a_camera_but_no_polygons() {
        let cam = "camera\n  eye 1 2 3\n  lookat 1 2 4\n  fov 30\n  size 64 48\nend\n";
        let c = parse_camera_str(cam, "cam.sc").unwrap();
        assert_eq!(c.eye, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(c.lookat, Vec3::new(1.0, 2.0, 4.0));
        assert_eq!((c.width, c.height), (64, 48));
        assert!((c.fov_y - 30f32.to_radians()).abs() < 1e-6);
        // A whole scene is accepted too; its camera is taken.
        let with_scene =
            format!("{cam}material m color 0.5 0.5 0.5 k_diffrefl 1 end box m 0 0 0 1 1 1\n");
        assert_eq!(parse_camera_str(&with_scene, "s.sc").unwrap(), c);
        // No camera block: an error at the start of the file.
        let e = parse_camera_str("# nothing\n", "empty.sc").unwrap_err();
        assert_eq!(
            e.to_string(),
            "empty.sc:1:1: error: camera file has no `camera` block"
        );
        // Mistakes are reported as in any scene file.
        let e =
            parse_camera_str("camera\n  eye 0 0 0\n  lookat 0 0 0\nend\n", "bad.sc").unwrap_err();
        assert_eq!(e.first().map(|d| (d.line, d.col)), Some((3, 3)), "{e}");
    }
}
