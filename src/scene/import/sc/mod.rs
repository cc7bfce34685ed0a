//! The `.sc` loader: scene text in, validated [`Scene`] out.
//!
//! The format is described in `docs/scene-format.md`. In short: a file is a
//! sequence of statements (`camera … end`, `material NAME … end`,
//! `polygon MATERIAL … end`, `box MATERIAL X0 Y0 Z0 X1 Y1 Z1`,
//! `transform … end`), tokens are separated by whitespace, line breaks carry
//! no meaning and `#` starts a comment anywhere.
//!
//! The parser reads the whole file before giving up: after an error it skips
//! to the next keyword and goes on, so one run reports every independent
//! mistake (up to [`MAX_DIAGNOSTICS`](crate::scene::MAX_DIAGNOSTICS)). Each
//! diagnostic points at the token at fault; problems of a whole block (a
//! missing field, an invalid polygon, no `end`) point at the keyword that
//! opened it.
//!
//! One concept a file: `lexer` splits the text into tokens with positions,
//! `parser` reads blocks and keywords and builds the [`Scene`], and this
//! file holds the entry points (text, bytes, files, camera files) and the
//! format's public constants.

mod lexer;
mod parser;
#[cfg(test)]
mod tests;

use crate::camera::Camera;
use crate::scene::error::{cannot_read, FILE_START};
use crate::scene::import::input::{InputKind, InputSet};
use crate::scene::{Diagnostic, LoadError, Scene};
use lexer::{advance, lex};
use parser::Parser;
use std::path::Path;

/// Largest emitted radiosity per channel (`k_emission` × `color`), in the
/// scene's radiosity units. Far above any physical scene, low enough that
/// emission × area × polygon count stays finite in `f64` and radiosities
/// stay finite in the `f32` pictures.
pub const MAX_EMISSION: f64 = 1e20;

/// Every keyword of the format, in the order the format introduces them.
/// None of them may be used as a name. The fuzz tests use this list as
/// their dictionary, so it must stay complete.
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

/// Parses `.sc` source text; `file` names it in diagnostics.
///
/// A byte-order mark at the very start is skipped. On success every
/// polygon is valid (see [`Polygon::new`](crate::scene::Polygon::new)),
/// every material obeys the invariants of
/// [`Material`](crate::scene::Material), and the camera has passed
/// [`Camera::check`]. A file with no camera gets
/// [`frame_camera`](crate::scene::frame_camera) of its polygons (from
/// inside a room, from outside an object); a file with no polygon is an
/// error.
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
    load_camera_into(path, &InputSet::default())
}

/// [`load_camera`], recording the file in `inputs`.
pub fn load_camera_into(path: &Path, inputs: &InputSet) -> Result<Camera, LoadError> {
    let file = path.display().to_string();
    let bytes = inputs
        .read(path, InputKind::Camera)
        .map_err(|e| cannot_read(&file, &e))?;
    let text = decode(&bytes, &file)?;
    parse_camera_str(text, &file)
}

/// Reads `path` and parses it; the path as given names the file in
/// diagnostics. A file that cannot be read is reported without a
/// position, a file that is not UTF-8 at its first bad byte.
pub(crate) fn load_file(path: &Path, inputs: &InputSet) -> Result<Scene, LoadError> {
    let file = path.display().to_string();
    let bytes = inputs
        .read(path, InputKind::Scene)
        .map_err(|e| cannot_read(&file, &e))?;
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
