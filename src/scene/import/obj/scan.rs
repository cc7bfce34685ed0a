//! The OBJ pre-scan: `tobj` reports no positions, so every `v`, `vt`,
//! `vn`, `f` and `l` line is checked here first, giving `FILE:LINE:COL`
//! for each mistake, and the faces, `usemtl`, `mtllib`, object, group and
//! smoothing statements are noted where they are. Also the line
//! bookkeeping that places what `tobj` reports: the reader that counts
//! the bytes it gave out, and the text with dangling references removed.

use super::Tally;
use crate::scene::error::MAX_DIAGNOSTICS;
use crate::scene::lighting::emit::GroupScan;
use crate::scene::{Diagnostic, SourcePos};
use std::cell::Cell;
use std::collections::HashMap;
use std::io::{self, BufRead, Read};
use std::rc::Rc;

/// What the OBJ pre-scan finds.
pub(super) struct Scan {
    pub(super) diags: Vec<Diagnostic>,
    /// Every `f` line, and every `l` line with three or more vertices, in
    /// file order.
    pub(super) faces: Vec<FaceLine>,
    pub(super) usemtls: Vec<Named>,
    pub(super) mtllibs: Vec<MtlLib>,
    /// The `o` and `g` statements.
    pub(super) names: GroupScan,
    /// Face and line statements rewritten without the texture coordinate
    /// or normal references that point at nothing: `(line number, the
    /// line as tobj must read it)`.
    pub(super) repairs: Vec<(u32, String)>,
    /// Corners whose texture coordinate `[0]` or normal `[1]` index is out
    /// of range (both are dropped, see [`check_reference`]).
    pub(super) dropped: [Tally; 2],
}

pub(super) struct FaceLine {
    pub(super) pos: SourcePos,
    pub(super) is_line: bool,
    /// Its objects and groups, for [`GroupScan::assign`].
    pub(super) names: u32,
    /// The smoothing group it is in, `(object, s number)`: the object
    /// counts `o` statements, so two objects never share one.
    pub(super) smoothing: Option<(u32, u64)>,
    /// Its corners that name a normal: `(position, normal)`, both
    /// 1-based file indices (negative ones resolved).
    pub(super) normals: Vec<(u64, u64)>,
    /// Its smooth surface, from [`smooth_surfaces`].
    pub(super) smooth: Option<u32>,
}

pub(super) struct Named {
    pub(super) name: String,
    pub(super) pos: SourcePos,
}

pub(super) struct MtlLib {
    pub(super) line: u32,
    pub(super) pos: SourcePos,
}

/// The words of a line (split on whitespace, as `tobj` splits them) with
/// their 1-based columns in characters.
pub(super) fn words(line: &str) -> Vec<(&str, u32)> {
    let mut out = Vec::new();
    let mut start: Option<(usize, u32)> = None;
    let mut col = 0u32;
    for (i, c) in line.char_indices() {
        col += 1;
        if c.is_whitespace() {
            if let Some((s, sc)) = start.take() {
                out.push((&line[s..i], sc));
            }
        } else if start.is_none() {
            start = Some((i, col));
        }
    }
    if let Some((s, sc)) = start {
        out.push((&line[s..], sc));
    }
    out
}

/// Lines as `tobj` reads them (split at LF, a CR before it dropped), with
/// their 1-based numbers.
pub(super) fn lines(text: &str) -> impl Iterator<Item = (u32, &str)> {
    text.split('\n')
        .enumerate()
        .map(|(i, l)| (i as u32 + 1, l.strip_suffix('\r').unwrap_or(l)))
}

/// Checks every `v`, `vt`, `vn`, `f` and `l` line, and notes where the
/// faces, `usemtl` and `mtllib` lines are.
pub(super) fn scan_obj(text: &str, file: &str) -> Scan {
    let mut scan = Scan {
        diags: Vec::new(),
        faces: Vec::new(),
        usemtls: Vec::new(),
        mtllibs: Vec::new(),
        names: GroupScan::default(),
        repairs: Vec::new(),
        dropped: [Tally::default(), Tally::default()],
    };
    // Positive indices may refer to any vertex of the file (tobj resolves
    // them at the end), negative ones count back from the current line.
    let mut totals = [0usize; 3];
    for (_, line) in lines(text) {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    let mut seen = [0usize; 3];
    let mut object = 0u32;
    let mut smoothing: Option<u64> = None;
    for (number, line) in lines(text) {
        if scan.diags.len() >= MAX_DIAGNOSTICS {
            break;
        }
        let w = words(line);
        let Some(&(keyword, col)) = w.first() else {
            continue;
        };
        let at = |col: u32| SourcePos { line: number, col };
        let mut error = |col: u32, message: String| {
            scan.diags.push(Diagnostic::new(file, at(col), message));
        };
        match keyword {
            "v" | "vt" | "vn" => {
                let (kind, need) = match keyword {
                    "v" => (0, 3),
                    "vt" => (1, 1),
                    _ => (2, 3),
                };
                seen[kind] += 1;
                check_vertex_line(&w, need, file, number, &mut scan.diags);
            }
            "f" | "l" => {
                let cursor = Cursor {
                    totals,
                    seen,
                    object,
                    smoothing,
                };
                scan_face_line(&mut scan, &w, file, number, &cursor);
            }
            "usemtl" => {
                // tobj takes everything after the first space, trimmed.
                let name = line.split_once(' ').map_or("", |x| x.1.trim());
                if name.is_empty() {
                    error(col, "`usemtl` needs a material name".into());
                } else {
                    scan.usemtls.push(Named {
                        name: name.to_string(),
                        pos: at(col),
                    });
                }
            }
            "o" | "g" => {
                if keyword == "o" {
                    object += 1;
                }
                scan.names
                    .statement(keyword, &line.trim_start()[keyword.len()..])
            }
            // `s off` and `s 0` end smoothing; any other number (or
            // name) starts or continues that group.
            "s" => {
                smoothing = match w.get(1).map(|x| x.0) {
                    None | Some("off") | Some("0") => None,
                    Some(word) => Some(word.parse::<u64>().unwrap_or_else(|_| {
                        // A non-numeric group name: a stable number for it.
                        use std::hash::{Hash, Hasher};
                        let mut h = std::collections::hash_map::DefaultHasher::new();
                        word.hash(&mut h);
                        h.finish()
                    })),
                }
            }
            "mtllib" => {
                if line.split_once(' ').map_or("", |x| x.1.trim()).is_empty() {
                    error(col, "`mtllib` needs a file name".into());
                } else {
                    scan.mtllibs.push(MtlLib {
                        line: number,
                        pos: at(col),
                    });
                }
            }
            _ => {}
        }
    }
    scan
}

/// Where the scan has got to, as a face line needs it.
struct Cursor {
    /// The `v`, `vt` and `vn` lines of the whole file (positive indices
    /// may refer to any of them).
    totals: [usize; 3],
    /// Those before this line (negative indices count back from here).
    seen: [usize; 3],
    /// The `o` statements so far.
    object: u32,
    /// The smoothing group in force (`s N`), if any.
    smoothing: Option<u64>,
}

/// Checks a `v`, `vt` or `vn` line (its words `w`, on line `number`): at
/// least `need` numbers, each finite.
fn check_vertex_line(
    w: &[(&str, u32)],
    need: usize,
    file: &str,
    number: u32,
    diags: &mut Vec<Diagnostic>,
) {
    let (keyword, col) = w[0];
    let at = |col: u32| SourcePos { line: number, col };
    let mut error = |col: u32, message: String| {
        diags.push(Diagnostic::new(file, at(col), message));
    };
    if w.len() - 1 < need {
        error(
            col,
            format!(
                "`{keyword}` needs at least {need} numbers, found {}",
                w.len() - 1
            ),
        );
        return;
    }
    for &(word, c) in &w[1..] {
        match word.parse::<f32>() {
            Ok(x) if x.is_finite() => {}
            Ok(_) => error(
                c,
                format!("`{word}` is not allowed: numbers must be finite"),
            ),
            Err(_) => error(c, format!("invalid number `{word}`")),
        }
    }
}

/// Checks an `f` or `l` line (its words `w`, on line `number`): enough
/// vertices, every corner's references; notes the corners to rewrite
/// without dangling references, and the face with its objects, groups,
/// smoothing group and normals.
fn scan_face_line(scan: &mut Scan, w: &[(&str, u32)], file: &str, number: u32, cursor: &Cursor) {
    let (keyword, col) = w[0];
    let at = |col: u32| SourcePos { line: number, col };
    let mut error = |col: u32, message: String| {
        scan.diags.push(Diagnostic::new(file, at(col), message));
    };
    let is_line = keyword == "l";
    let count = w.len() - 1;
    if !is_line && count < 3 {
        error(
            col,
            format!("face has {count} vertices; at least 3 are needed"),
        );
        return;
    }
    let mut ok = true;
    // The corners as tobj gets them: out-of-range texture
    // coordinate and normal references dropped.
    let mut corners: Vec<String> = Vec::with_capacity(count);
    for &(word, c) in &w[1..] {
        match check_reference(word, &cursor.seen, &cursor.totals) {
            Ok(bad) => {
                for (k, tally) in scan.dropped.iter_mut().enumerate() {
                    if bad[k] {
                        tally.add(at(c), || word.to_string());
                    }
                }
                corners.push(without_references(word, bad));
            }
            Err(message) => {
                error(c, message);
                ok = false;
            }
        }
    }
    if ok && corners.iter().zip(&w[1..]).any(|(a, b)| a != b.0) {
        scan.repairs
            .push((number, format!("{keyword} {}", corners.join(" "))));
    }
    if ok && count >= 3 {
        let normals = if is_line {
            Vec::new()
        } else {
            corners
                .iter()
                .filter_map(|word| corner_normal(word, &cursor.seen))
                .collect()
        };
        scan.faces.push(FaceLine {
            pos: at(col),
            is_line,
            names: scan.names.current(),
            smoothing: cursor.smoothing.map(|s| (cursor.object, s)),
            normals,
            smooth: None,
        });
    }
}

/// The `(position, normal)` file indices (1-based, negative ones resolved
/// against `seen`) of a checked face corner `v//vn` or `v/vt/vn`; `None`
/// for a corner without a normal.
pub(super) fn corner_normal(word: &str, seen: &[usize; 3]) -> Option<(u64, u64)> {
    let mut parts = word.split('/');
    let v = parts.next()?;
    let n = parts.nth(1)?;
    let resolve = |part: &str, kind: usize| -> Option<u64> {
        let i = part.parse::<i64>().ok()?;
        if i > 0 {
            Some(i as u64)
        } else {
            (seen[kind] as u64 + 1).checked_sub(i.unsigned_abs())
        }
    };
    Some((resolve(v, 0)?, resolve(n, 2)?))
}

/// Gives each face its smooth surface (union-find over faces): faces of
/// one smoothing group (`s N` within one `o` object) are one surface, and
/// so are faces with a corner of the same position and the same normal
/// (`f a//n`; Blender writes one shared `vn` per vertex of a face shaded
/// smooth, and its own `vn` per flat face). A face with neither stays
/// faceted (`None`). Surfaces are numbered from 0 in order of their first
/// face.
pub(super) fn smooth_surfaces(faces: &mut [FaceLine]) {
    let n = faces.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut joined = vec![false; n];
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut union = |parent: &mut Vec<usize>, a: usize, b: usize| {
        joined[a] = true;
        joined[b] = true;
        let (ra, rb) = (find(parent, a), find(parent, b));
        parent[ra.max(rb)] = ra.min(rb);
    };
    let mut first_in_group: HashMap<(u32, u64), usize> = HashMap::new();
    let mut first_with_corner: HashMap<(u64, u64), usize> = HashMap::new();
    for (i, face) in faces.iter().enumerate() {
        if face.is_line {
            continue;
        }
        if let Some(g) = face.smoothing {
            let first = *first_in_group.entry(g).or_insert(i);
            union(&mut parent, first, i);
        }
        for &corner in &face.normals {
            let first = *first_with_corner.entry(corner).or_insert(i);
            if first != i {
                union(&mut parent, first, i);
            }
        }
    }
    let mut ids: HashMap<usize, u32> = HashMap::new();
    for i in 0..n {
        if joined[i] {
            let r = find(&mut parent, i);
            let next = ids.len() as u32;
            faces[i].smooth = Some(*ids.entry(r).or_insert(next));
        }
    }
}

/// Checks one face corner `v`, `v/vt`, `v//vn` or `v/vt/vn` against the
/// counts of vertices, texture coordinates and normals (`seen` so far for
/// negative indices, `totals` in the file for positive ones).
///
/// A malformed corner or a vertex index out of range is an error. A
/// texture coordinate or normal index out of range is not: texture
/// coordinates are never used and normals only join smooth surfaces, so
/// the corner has one sensible reading without them (exporters and hand
/// edits leave such indices behind). The result says which of the two
/// (`[texture coordinate, normal]`) must be dropped.
pub(super) fn check_reference(
    word: &str,
    seen: &[usize; 3],
    totals: &[usize; 3],
) -> Result<[bool; 2], String> {
    let mut dropped = [false; 2];
    const WHAT: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    const PLURAL: [&str; 3] = ["vertices", "texture coordinates", "normals"];
    let parts: Vec<&str> = word.split('/').collect();
    if parts.len() > 3 || parts[0].is_empty() {
        return Err(format!(
            "invalid face vertex `{word}`: expected v, v/vt, v//vn or v/vt/vn"
        ));
    }
    for (k, part) in parts.iter().enumerate() {
        if part.is_empty() {
            continue;
        }
        let Ok(i) = part.parse::<i64>() else {
            return Err(format!(
                "invalid face vertex `{word}`: `{part}` is not a whole number"
            ));
        };
        let ok = match i {
            0 => false,
            i if i > 0 => i as u64 <= totals[k] as u64,
            i => i.unsigned_abs() <= seen[k] as u64,
        };
        if !ok && k > 0 {
            dropped[k - 1] = true;
        } else if !ok {
            return Err(format!(
                "{} index {i} in `{word}` is out of range: {} {} {}",
                WHAT[k],
                if i < 0 { seen[k] } else { totals[k] },
                PLURAL[k],
                if i < 0 {
                    "are defined above this line"
                } else {
                    "are defined in the file (indices count from 1)"
                }
            ));
        }
    }
    Ok(dropped)
}

/// The corner `word` (checked by [`check_reference`]) without its texture
/// coordinate (`drop[0]`) or normal (`drop[1]`) reference: `7/9/2` becomes
/// `7//2`, `7/2` or `7`.
pub(super) fn without_references(word: &str, drop: [bool; 2]) -> String {
    if drop == [false, false] {
        return word.to_string();
    }
    let mut parts = word.split('/');
    let v = parts.next().unwrap_or_default();
    let vt = parts.next().filter(|p| !p.is_empty() && !drop[0]);
    let vn = parts.next().filter(|p| !p.is_empty() && !drop[1]);
    match (vt, vn) {
        (None, None) => v.to_string(),
        (Some(t), None) => format!("{v}/{t}"),
        (None, Some(n)) => format!("{v}//{n}"),
        (Some(t), Some(n)) => format!("{v}/{t}/{n}"),
    }
}

/// `text` with the lines the scan rewrote ([`Scan::repairs`], in line
/// order) put in place; every line keeps its number.
pub(super) fn repaired_text(text: &str, repairs: &[(u32, String)]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut next = repairs.iter().peekable();
    for (i, line) in text.split('\n').enumerate() {
        if i > 0 {
            out.push('\n');
        }
        match next.peek() {
            Some((number, repaired)) if *number as usize == i + 1 => {
                out.push_str(repaired);
                if line.ends_with('\r') {
                    out.push('\r');
                }
                next.next();
            }
            _ => out.push_str(line),
        }
    }
    out
}

/// The 1-based number of the line that ends at byte `pos` (the last line
/// read when a reader has consumed `pos` bytes).
pub(super) fn line_at(text: &str, pos: usize) -> u32 {
    let end = pos.min(text.len()).saturating_sub(1);
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count() as u32
        + 1
}

/// The column of the first word of line `line`, or 1.
pub(super) fn first_word_col(text: &str, line: u32) -> u32 {
    lines(text)
        .find(|(n, _)| *n == line)
        .and_then(|(_, l)| words(l).first().map(|w| w.1))
        .unwrap_or(1)
}

/// A `BufRead` over the text that records how many bytes were consumed.
pub(super) struct CountingReader<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) pos: Rc<Cell<usize>>,
}

impl Read for CountingReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let rest = self.fill_buf()?;
        let n = rest.len().min(buf.len());
        buf[..n].copy_from_slice(&rest[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for CountingReader<'_> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        Ok(&self.bytes[self.pos.get().min(self.bytes.len())..])
    }

    fn consume(&mut self, amt: usize) {
        self.pos.set((self.pos.get() + amt).min(self.bytes.len()));
    }
}
