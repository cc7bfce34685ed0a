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
    Camera, CameraSource, Diagnostic, LoadError, Material, MaterialId, Polygon, Scene, SourcePos,
    DEFAULT_FOV_DEG, DEFAULT_SIZE,
};
use crate::color::Rgb;
use glam::{DAffine3, DMat3, DVec3, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// The parser stops after this many diagnostics: past that point a file is
/// usually not a scene at all and more messages help nobody.
pub const MAX_DIAGNOSTICS: usize = 100;

/// `up` counts as parallel to the view direction when the sine of the angle
/// between them is below this. Small enough to accept any up a person would
/// write, large enough that `normalize(forward x up)` is still accurate in
/// `f32`.
pub const UP_PARALLEL_TOLERANCE: f64 = 1e-4;

/// Largest magnitude accepted for a coordinate: geometry is stored in `f32`,
/// so anything larger would become infinite.
pub const MAX_COORDINATE: f64 = f32::MAX as f64;

/// Every keyword of the format. None of them may be used as a name.
const KEYWORDS: &[&str] = &[
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

/// Reads `path` and parses it; the path as given names the file in
/// diagnostics. A file that cannot be read is reported at `1:1`, a file
/// that is not UTF-8 at its first bad byte.
pub(crate) fn load_file(path: &Path) -> Result<Scene, LoadError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path)
        .map_err(|e| Diagnostic::new(&file, FILE_START, format!("cannot read file: {e}")))?;
    let text = decode(&bytes, &file)?;
    parse_str(text, &file)
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

    /// Skips the arguments of an unknown or misplaced keyword.
    fn skip_arguments(&mut self) {
        while matches!(self.peek().kind, Kind::Number(_) | Kind::Bad)
            || (self.peek().kind == Kind::Word && !KEYWORDS.contains(&self.peek().text))
        {
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
                    (Some(frame), Some(t)) => frame.matrix *= t,
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
                self.skip_arguments();
            }
            s => {
                self.error(kw.pos, format!("unknown keyword {}", quote(s)));
                self.skip_arguments();
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
                        self.skip_arguments();
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
                        "number {} is too large for a coordinate (at most {MAX_COORDINATE:e} in magnitude)",
                        quote(n.text)
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
        let forward = lookat.as_vec3().as_dvec3() - eye.as_vec3().as_dvec3();
        if forward == DVec3::ZERO {
            self.error(
                lookat_pos,
                "`lookat` equals `eye`; the camera has no view direction",
            );
            return;
        }
        if up == DVec3::ZERO {
            self.error(up_pos, "`up` is zero; it must give a direction");
            return;
        }
        let sine = forward
            .normalize_or_zero()
            .cross(up.normalize_or_zero())
            .length();
        if sine < UP_PARALLEL_TOLERANCE {
            self.error(
                up_pos,
                format!(
                    "`up` ({} {} {}) is parallel to the view direction; the picture's up would be undefined",
                    fmt_num(up.x),
                    fmt_num(up.y),
                    fmt_num(up.z)
                ),
            );
            return;
        }
        let (width, height) = size.unwrap_or(DEFAULT_SIZE);
        let camera = Camera {
            eye: eye.as_vec3(),
            lookat: lookat.as_vec3(),
            up: up.as_vec3(),
            fov_y: fov.unwrap_or(DEFAULT_FOV_DEG).to_radians(),
            width,
            height,
        };
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
        if deg <= 0.0 || deg >= 180.0 {
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

    /// `size W H`, whole numbers of pixels, each at least 1.
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
        let mut bad = false;
        let closed = self.block(open, MATERIAL_FIELDS, &[], &mut |p, kw| {
            let ok = match kw.text {
                "color" => p.color(kw).map(|c| color = c),
                "k_diffrefl" => p.non_negative(kw).map(|k| k_diffrefl = Some((k, kw.pos))),
                _ => p.non_negative(kw).map(|k| k_emission = k),
            };
            bad |= ok.is_none();
        });
        if !closed || bad {
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
        let mut world: Vec<Vec3> = local
            .iter()
            .map(|&v| m.transform_point3(v).as_vec3())
            .collect();
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
                self.error(open.pos, e.to_string());
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
        if self.diags.is_empty() && self.polygons.is_empty() {
            self.error(FILE_START, "scene has no polygons");
        }
        if !self.diags.is_empty() {
            // Stable, so messages at one position keep the order they were
            // found in.
            self.diags.sort_by_key(|d| (d.line, d.col));
            self.diags.truncate(MAX_DIAGNOSTICS);
            return Err(LoadError {
                diagnostics: self.diags,
            });
        }
        let (camera, camera_source) = match self.camera {
            Some(c) => (c, CameraSource::File),
            None => {
                let (lo, hi) = bounds(&self.polygons);
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
}

fn bounds(polygons: &[Polygon]) -> (Vec3, Vec3) {
    polygons
        .iter()
        .flat_map(|p| p.vertices.iter().copied())
        .fold(None, |acc: Option<(Vec3, Vec3)>, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
        .unwrap_or((Vec3::ZERO, Vec3::ZERO))
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
