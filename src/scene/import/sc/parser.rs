//! The `.sc` parser proper: tokens in, [`Scene`] out.
//!
//! A single pass over the token list: the statement loop
//! ([`Parser::run`]) hands each keyword to the reader of its block, the
//! readers check every field as it is read and report problems at the token
//! at fault, and [`Parser::finish`] builds the scene once the whole file has
//! been read. After an error the parser skips to the next keyword and goes
//! on, so one run reports every independent mistake (up to
//! [`MAX_DIAGNOSTICS`]). Problems of a whole block (a missing field, an
//! invalid polygon, no `end`) point at the keyword that opened it.
//!
//! `transform` blocks keep a stack of matrices (in `f64`) instead of
//! recursing, so nesting depth costs no stack.

use super::lexer::{bad_message, is_non_finite_word, quote, Kind, Token};
use super::{KEYWORDS, MAX_EMISSION};
use crate::camera::{
    picture_size_ok, Camera, CameraError, DEFAULT_FOV_DEG, DEFAULT_SIZE, MAX_PICTURE_PIXELS,
    MAX_PICTURE_SIDE,
};
use crate::color::Rgb;
use crate::scene::error::{
    fmt_num, negative_channel, reflectance_too_high, FILE_START, MAX_DIAGNOSTICS,
};
use crate::scene::{
    CameraSource, Diagnostic, LoadError, Material, MaterialId, Polygon, PolygonError, Scene,
    SourcePos, MAX_COORDINATE,
};
use glam::{DAffine3, DMat3, DVec3, Vec3};
use std::collections::HashMap;

/// Keywords that start a statement; meeting one inside a field block means
/// the block's `end` is missing.
const STATEMENTS: &[&str] = &["camera", "material", "polygon", "box", "transform"];

/// The fields of each block, in the order messages list them.
const CAMERA_FIELDS: &[&str] = &["eye", "lookat", "up", "fov", "size"];
/// See [`CAMERA_FIELDS`].
const MATERIAL_FIELDS: &[&str] = &["color", "k_diffrefl", "k_emission"];
/// See [`CAMERA_FIELDS`].
const POLYGON_FIELDS: &[&str] = &["vertex"];

/// A position as `LINE:COL`, for messages that point at a second place.
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

/// The parser's state while it reads one file.
pub(super) struct Parser<'a> {
    file: &'a str,
    tokens: Vec<Token<'a>>,
    next: usize,
    diags: Vec<Diagnostic>,
    materials: Vec<Material>,
    material_ids: HashMap<&'a str, (MaterialId, SourcePos)>,
    undefined_uses: Vec<PendingUse>,
    polygons: Vec<Polygon>,
    /// The file's camera, once a valid `camera` block was read.
    pub(super) camera: Option<Camera>,
    camera_pos: Option<SourcePos>,
    frames: Vec<Frame>,
    /// The keyword read last, to explain a stray number after it.
    last_keyword: Option<&'a str>,
}

impl<'a> Parser<'a> {
    /// A parser of `tokens`, from the file named `file` in diagnostics.
    pub(super) fn new(file: &'a str, tokens: Vec<Token<'a>>) -> Self {
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

    /// Reads every statement up to the end of the file (or until
    /// [`MAX_DIAGNOSTICS`] problems were found).
    pub(super) fn run(&mut self) {
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
                self.error(pos, reflectance_too_high("`k_diffrefl` × `color`", rho));
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
                self.error(n.pos, negative_channel("color", n.text));
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

    /// The scene read, or every problem found.
    pub(super) fn finish(mut self) -> Result<Scene, LoadError> {
        self.report_pending(true)?;
        let (camera, camera_source) = match self.camera {
            Some(c) => (c, CameraSource::File),
            None => (
                crate::scene::frame_camera(&self.polygons),
                CameraSource::AutoFramed,
            ),
        };
        Ok(Scene {
            polygons: self.polygons,
            materials: self.materials,
            camera,
            camera_source,
            warnings: Vec::new(),
            groups: Vec::new(),
            luminaires: Vec::new(),
            sun: None,
            sky_pattern: None,
        })
    }

    /// Reports the uses of undefined materials and, when
    /// `require_polygons`, an empty scene; then every diagnostic found, in
    /// file order, if there is any.
    pub(super) fn report_pending(&mut self, require_polygons: bool) -> Result<(), LoadError> {
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
