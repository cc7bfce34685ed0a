//! IESNA LM-63 photometric files: a luminaire's luminous intensity
//! distribution, what `--ies NAME=FILE.ies` gives the polygons of `NAME`.
//!
//! Read: the 1995 and 2002 formats (and the 1991 and 1986 ones, whose
//! layout is the same): an optional `IESNA:LM-63-…` first line, keyword
//! lines (`[TEST] …`, kept as text and otherwise ignored), `TILT=NONE`,
//! then the numbers, separated by blanks, commas or line breaks:
//!
//! ```text
//! lamps  lumens-per-lamp  candela-multiplier  n-vertical  n-horizontal
//! photometric-type  units-type  width  length  height
//! ballast-factor  future-use  input-watts
//! vertical angles (n-vertical)      horizontal angles (n-horizontal)
//! candela values: n-vertical for each horizontal angle in turn
//! ```
//!
//! Only type C photometry (type 1; the vertical angle from the nadir, the
//! horizontal angle around it) is read: types A and B are refused with a
//! message, as is a tilt table (`TILT=INCLUDE` or a file: the lamp's
//! output depending on its tilt; a luminaire here is never tilted, so only
//! `TILT=NONE` makes sense). The vertical angles must start at 0° or 90°
//! and end at 90° or 180°; the horizontal angles start at 0° and end at 0°
//! (one plane: the same all around), 90° (symmetric in each quadrant),
//! 180° (symmetric about the 0–180° plane) or 360° (no symmetry).
//!
//! **Intensity.** `I = candela × multiplier × ballast factor`, in candela:
//! with absolute photometry (lumens per lamp −1) that is the luminaire's;
//! with relative photometry the table is for the rated lamp lumens
//! (`lamps × lumens per lamp`), which is what it gives as written. Between
//! the listed angles the intensity is interpolated bilinearly in the two
//! angles (as Radiance's `ies2rad` data do); beyond the listed vertical
//! angles it is 0.
//!
//! Errors give the file, the line and the column of the offending value
//! and what was expected there ([`IesError`]).

use super::input::{InputKind, InputSet};
use std::f64::consts::PI;
use std::fmt;
use std::path::Path;

/// The most angles of either kind a file may list: more than any real
/// photometry (a 0.5° grid over 360° is 721), few enough that a hostile
/// file cannot make a table of billions of values.
pub const MAX_ANGLES: usize = 10_000;

/// The most candela values a file may list (vertical × horizontal).
pub const MAX_VALUES: usize = 1_000_000;

/// The largest intensity a file may give, candela, after the multiplier
/// and ballast factor: a million times the brightest searchlight (about
/// 1e9 cd), so no real file comes near it, while the flux and the
/// luminaire's exitance computed from it stay far from overflow.
pub const MAX_CANDELA: f64 = 1e15;

/// How far (degrees) the first and last angles may be from the values the
/// format allows (0, 90, 180, 360), for files written with rounding.
pub const ANGLE_TOLERANCE_DEG: f64 = 1e-3;

/// Polar × azimuthal cells of the midpoint rule [`Photometry::flux`]
/// integrates with: against the closed form of a cosine distribution its
/// error is below 1e-5.
pub const FLUX_CELLS: (usize, usize) = (360, 720);

/// An error in an IES file: where and what.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}", crate::scene::error::positioned(file, *line, *column, "error", message))]
pub struct IesError {
    /// The file as named by the user.
    pub file: String,
    /// 1-based line (0 when the file could not be read at all).
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong and what was expected.
    pub message: String,
}

/// How the horizontal angles cover the circle around the nadir.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// One horizontal angle (0°): the same intensity all around.
    Full,
    /// 0° to 90°: each quadrant is a mirror of the first.
    Quadrant,
    /// 0° to 180°: the 180–360° half mirrors the first.
    Bilateral,
    /// 0° to 360°: no symmetry.
    None,
}

/// A type C luminous intensity distribution, ready to be evaluated.
///
/// Invariants: `vertical` and `horizontal` strictly increase, in radians;
/// `vertical` within `[0, π]`, `horizontal` within `[0, 2π]` and starting
/// at 0; `candela` holds `horizontal.len() × vertical.len()` finite
/// values `>= 0` in candela (multiplier and ballast factor applied), one
/// run of vertical values per horizontal angle.
#[derive(Clone, Debug, PartialEq)]
pub struct Photometry {
    /// Vertical angles from the nadir, radians.
    pub vertical: Vec<f64>,
    /// Horizontal angles around the nadir, radians.
    pub horizontal: Vec<f64>,
    /// Intensities in candela, `candela[h * vertical.len() + v]`.
    pub candela: Vec<f64>,
    /// What the horizontal angles cover.
    pub symmetry: Symmetry,
    /// Rated lamp lumens (lamps × lumens per lamp), `None` with absolute
    /// photometry.
    pub lamp_lumens: Option<f64>,
    /// The keyword lines (`[KEYWORD] text`), for messages.
    pub keywords: Vec<(String, String)>,
}

impl Photometry {
    /// Reads and parses the IES file at `path`; `name` is how messages name
    /// it.
    pub fn load(path: &Path) -> Result<Photometry, IesError> {
        Photometry::load_into(path, &InputSet::default())
    }

    /// [`Photometry::load`], recording the file in `inputs`.
    pub fn load_into(path: &Path, inputs: &InputSet) -> Result<Photometry, IesError> {
        let name = path.display().to_string();
        let bytes = inputs.read(path, InputKind::Ies).map_err(|e| IesError {
            file: name.clone(),
            line: 0,
            column: 0,
            message: crate::scene::error::unreadable(&e),
        })?;
        // IES files are ASCII; Latin-1 keywords are not rare, and read as
        // such rather than refused.
        let text: String = bytes.iter().map(|&b| b as char).collect();
        Photometry::parse(&text, &name)
    }

    /// Parses the text of an IES file named `file` in messages.
    pub fn parse(text: &str, file: &str) -> Result<Photometry, IesError> {
        let lines: Vec<&str> = text.lines().collect();
        let (keywords, tilt) = keywords_and_tilt(&lines, file)?;
        let mut numbers = Numbers {
            tokens: Tokens::new(&lines, tilt + 1),
            file,
        };
        let header = read_header(&mut numbers, tilt)?;
        let Header {
            nv,
            nh,
            lamp_lumens,
            ..
        } = header;
        let (vertical, horizontal, symmetry) = read_angles(&mut numbers, nv, nh)?;
        let candela = read_candela(&mut numbers, &header)?;
        Ok(Photometry {
            vertical: vertical
                .iter()
                .map(|v| v.0.clamp(0.0, 180.0).to_radians())
                .collect(),
            horizontal: horizontal
                .iter()
                .map(|h| h.0.clamp(0.0, 360.0).to_radians())
                .collect(),
            candela,
            symmetry,
            lamp_lumens,
            keywords,
        })
    }

    /// Luminous intensity in candela at `theta` radians from the nadir
    /// (`0..=π`) and `phi` radians around it (any value; the C0 plane at 0,
    /// counter-clockwise seen from below the luminaire, looking up).
    pub fn intensity(&self, theta: f64, phi: f64) -> f64 {
        let nv = self.vertical.len();
        let Some(v) = bracket(&self.vertical, theta) else {
            return 0.0;
        };
        let phi = phi.rem_euclid(2.0 * PI);
        let phi = match self.symmetry {
            Symmetry::Full => 0.0,
            Symmetry::Quadrant => {
                let p = if phi > PI { 2.0 * PI - phi } else { phi };
                if p > PI / 2.0 {
                    PI - p
                } else {
                    p
                }
            }
            Symmetry::Bilateral => {
                if phi > PI {
                    2.0 * PI - phi
                } else {
                    phi
                }
            }
            Symmetry::None => phi,
        };
        let at = |h: usize| {
            let row = &self.candela[h * nv..(h + 1) * nv];
            row[v.0] * (1.0 - v.1) + row[(v.0 + 1).min(nv - 1)] * v.1
        };
        match bracket(&self.horizontal, phi) {
            Some((h, t)) => at(h) * (1.0 - t) + at((h + 1).min(self.horizontal.len() - 1)) * t,
            // Only with a single horizontal angle.
            None => at(0),
        }
    }

    /// Luminous flux in lumens into the cone `theta <= max_theta` around
    /// the nadir: [`Photometry::flux_between`] from 0.
    pub fn flux(&self, max_theta: f64) -> f64 {
        self.flux_between(0.0, max_theta)
    }

    /// Luminous flux in lumens between the vertical angles `from` and `to`
    /// (radians from the nadir): `∫∫ I sinθ dθ dφ` by the midpoint rule
    /// on [`FLUX_CELLS`] cells over that band.
    pub fn flux_between(&self, from: f64, to: f64) -> f64 {
        let (nt, np) = FLUX_CELLS;
        let dt = (to - from) / nt as f64;
        let dp = 2.0 * PI / np as f64;
        let mut sum = 0.0;
        for i in 0..nt {
            let t = from + (i as f64 + 0.5) * dt;
            // The exact integral of sinθ over the cell, not the midpoint's.
            let weight = (t - dt / 2.0).cos() - (t + dt / 2.0).cos();
            let ring: f64 = (0..np)
                .map(|j| self.intensity(t, (j as f64 + 0.5) * dp))
                .sum();
            sum += ring * weight * dp;
        }
        sum
    }
}

/// The cell of strictly increasing `grid` that holds `x` and the
/// fraction of the way through it: `(k, t)` with `x = grid[k] + t
/// (grid[k+1] − grid[k])`; `None` outside the grid or for a one-point
/// grid other than at its point (then `(0, 0)`).
fn bracket(grid: &[f64], x: f64) -> Option<(usize, f64)> {
    let n = grid.len();
    // A hair of tolerance so that the end angles are inside.
    let eps = 1e-9;
    if n == 0 || x < grid[0] - eps || x > grid[n - 1] + eps {
        return None;
    }
    if n == 1 {
        return Some((0, 0.0));
    }
    let k = grid.partition_point(|&g| g <= x).clamp(1, n - 1) - 1;
    let t = ((x - grid[k]) / (grid[k + 1] - grid[k])).clamp(0.0, 1.0);
    Some((k, t))
}

/// The keyword lines before `TILT=`, and the index of the `TILT=NONE`
/// line; an error when there is none or it asks for a tilt table.
fn keywords_and_tilt(
    lines: &[&str],
    file: &str,
) -> Result<(Vec<(String, String)>, usize), IesError> {
    let err = |line, column, message| error_at(file, line, column, message);
    let mut keywords = Vec::new();
    let mut tilt_line = None;
    for (k, raw) in lines.iter().enumerate() {
        let line = raw.trim();
        if let Some(rest) = line.strip_prefix("TILT=").or(line.strip_prefix("TILT =")) {
            let rest = rest.trim();
            if rest != "NONE" {
                return Err(err(
                    k + 1,
                    raw.find("TILT").unwrap_or(0) + 1,
                    format!(
                        "TILT={rest}: only TILT=NONE is supported (a luminaire here \
                         is never tilted, so a tilt table has no use)"
                    ),
                ));
            }
            tilt_line = Some(k);
            break;
        }
        if let Some(rest) = line.strip_prefix('[') {
            let (key, value) = rest.split_once(']').unwrap_or((rest, ""));
            keywords.push((key.trim().to_string(), value.trim().to_string()));
        }
        // Anything else before TILT (the format line, free text of
        // the 1986 format) is a header.
    }
    let Some(tilt) = tilt_line else {
        return Err(err(
            lines.len().max(1),
            1,
            "no TILT= line: an IES file lists its keywords, then TILT=NONE, \
             then the photometric data"
                .into(),
        ));
    };
    Ok((keywords, tilt))
}

/// An error at `line` and `column` (both 1-based) of `file`.
fn error_at(file: &str, line: usize, column: usize, message: String) -> IesError {
    IesError {
        file: file.to_string(),
        line,
        column,
        message,
    }
}

/// A number after the TILT line: its value, line and column.
type Value = (f64, usize, usize);

/// The numbers after the TILT line, read one at a time, with the errors
/// that place them in `file`.
struct Numbers<'a> {
    tokens: Tokens<'a>,
    file: &'a str,
}

impl Numbers<'_> {
    /// The next number, which should be `what`.
    fn next(&mut self, what: &str) -> Result<Value, IesError> {
        let file = self.file;
        let err = |line, column, message| error_at(file, line, column, message);
        match self.tokens.next() {
            None => Err(err(
                self.tokens.end_line(),
                1,
                format!("the file ends where {what} was expected"),
            )),
            Some((text, line, column)) => match text.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok((v, line, column)),
                _ => Err(err(
                    line,
                    column,
                    format!("expected {what} (a number), got `{text}`"),
                )),
            },
        }
    }
}

/// The header numbers after the TILT line, as the distribution needs them.
#[derive(Clone, Copy)]
struct Header {
    /// The number of vertical angles.
    nv: usize,
    /// The number of horizontal angles.
    nh: usize,
    multiplier: Value,
    ballast: Value,
    lamp_lumens: Option<f64>,
}

/// Reads and checks the thirteen numbers of the header (lamps to input
/// watts), in file order; `tilt` is the index of the TILT line.
fn read_header(numbers: &mut Numbers<'_>, tilt: usize) -> Result<Header, IesError> {
    let file = numbers.file;
    let err = |line, column, message| error_at(file, line, column, message);
    let count = |v: (f64, usize, usize), what: &str, max: usize| {
        if v.0.fract() == 0.0 && v.0 >= 1.0 && v.0 <= max as f64 {
            Ok(v.0 as usize)
        } else {
            Err(err(
                v.1,
                v.2,
                format!("{what} must be a whole number from 1 to {max}, got {}", v.0),
            ))
        }
    };
    let lamps = numbers.next("the number of lamps")?;
    let lumens = numbers.next("the lumens per lamp")?;
    let multiplier = numbers.next("the candela multiplier")?;
    let nv = count(
        numbers.next("the number of vertical angles")?,
        "the number of vertical angles",
        MAX_ANGLES,
    )?;
    let nh = count(
        numbers.next("the number of horizontal angles")?,
        "the number of horizontal angles",
        MAX_ANGLES,
    )?;
    if nv * nh > MAX_VALUES {
        return Err(err(
            tilt + 2,
            1,
            format!("{nv} × {nh} candela values are more than the {MAX_VALUES} this reader takes"),
        ));
    }
    let kind = numbers.next("the photometric type")?;
    match kind.0 as i64 {
        1 if kind.0.fract() == 0.0 => {}
        2 | 3 if kind.0.fract() == 0.0 => {
            return Err(err(
                kind.1,
                kind.2,
                format!(
                    "photometric type {} ({}) is not supported: only type C (1), \
                     the type of architectural luminaires",
                    kind.0,
                    if kind.0 == 2.0 { "B" } else { "A" }
                ),
            ))
        }
        _ => {
            return Err(err(
                kind.1,
                kind.2,
                format!(
                    "the photometric type must be 1 (C), 2 (B) or 3 (A), got {}",
                    kind.0
                ),
            ))
        }
    }
    let units = numbers.next("the units type")?;
    if units.0 != 1.0 && units.0 != 2.0 {
        return Err(err(
            units.1,
            units.2,
            format!(
                "the units type must be 1 (feet) or 2 (metres), got {}",
                units.0
            ),
        ));
    }
    for what in ["the width", "the length", "the height"] {
        numbers.next(what)?;
    }
    let ballast = numbers.next("the ballast factor")?;
    numbers.next("the ballast-lamp factor (future use)")?;
    numbers.next("the input watts")?;
    if lamps.0 < 1.0 || lamps.0.fract() != 0.0 {
        return Err(err(
            lamps.1,
            lamps.2,
            format!(
                "the number of lamps must be a whole number >= 1, got {}",
                lamps.0
            ),
        ));
    }
    let lamp_lumens = if lumens.0 == -1.0 {
        None
    } else if lumens.0 > 0.0 {
        Some(lamps.0 * lumens.0)
    } else {
        return Err(err(
            lumens.1,
            lumens.2,
            format!(
                "the lumens per lamp must be positive, or -1 for absolute photometry, got {}",
                lumens.0
            ),
        ));
    };
    for (v, what) in [
        (multiplier, "candela multiplier"),
        (ballast, "ballast factor"),
    ] {
        if v.0 <= 0.0 {
            return Err(err(
                v.1,
                v.2,
                format!("the {what} must be positive, got {}", v.0),
            ));
        }
    }
    Ok(Header {
        nv,
        nh,
        multiplier,
        ballast,
        lamp_lumens,
    })
}

/// Reads the `nv` vertical and `nh` horizontal angles, checks that they
/// increase and start and end where type C angles do, and gives the
/// horizontal symmetry they imply.
fn read_angles(
    numbers: &mut Numbers<'_>,
    nv: usize,
    nh: usize,
) -> Result<(Vec<Value>, Vec<Value>, Symmetry), IesError> {
    let file = numbers.file;
    let err = |line, column, message| error_at(file, line, column, message);
    let mut angles = |n: usize, what: &str| -> Result<Vec<(f64, usize, usize)>, IesError> {
        (0..n).map(|_| numbers.next(what)).collect()
    };
    let vertical = angles(nv, "a vertical angle")?;
    let horizontal = angles(nh, "a horizontal angle")?;
    let increasing = |a: &[(f64, usize, usize)], what: &str| {
        for w in a.windows(2) {
            if w[1].0 <= w[0].0 {
                return Err(err(
                    w[1].1,
                    w[1].2,
                    format!(
                        "the {what} angles must increase, but {} follows {}",
                        w[1].0, w[0].0
                    ),
                ));
            }
        }
        Ok(())
    };
    increasing(&vertical, "vertical")?;
    increasing(&horizontal, "horizontal")?;
    let near = |a: f64, b: f64| (a - b).abs() <= ANGLE_TOLERANCE_DEG;
    let (v0, v1) = (vertical[0], vertical[nv - 1]);
    if !(near(v0.0, 0.0) || near(v0.0, 90.0)) {
        return Err(err(
            v0.1,
            v0.2,
            format!(
                "type C vertical angles start at 0 or 90 degrees, got {}",
                v0.0
            ),
        ));
    }
    if !(near(v1.0, 90.0) || near(v1.0, 180.0)) && nv > 1 {
        return Err(err(
            v1.1,
            v1.2,
            format!(
                "type C vertical angles end at 90 or 180 degrees, got {}",
                v1.0
            ),
        ));
    }
    let (h0, h1) = (horizontal[0], horizontal[nh - 1]);
    if !near(h0.0, 0.0) {
        return Err(err(
            h0.1,
            h0.2,
            format!("type C horizontal angles start at 0 degrees, got {}", h0.0),
        ));
    }
    let symmetry = if nh == 1 {
        Symmetry::Full
    } else if near(h1.0, 90.0) {
        Symmetry::Quadrant
    } else if near(h1.0, 180.0) {
        Symmetry::Bilateral
    } else if near(h1.0, 360.0) {
        Symmetry::None
    } else {
        return Err(err(
            h1.1,
            h1.2,
            format!(
                "type C horizontal angles end at 0, 90, 180 or 360 degrees, got {}",
                h1.0
            ),
        ));
    };
    Ok((vertical, horizontal, symmetry))
}

/// Reads the candela values (times the multiplier and the ballast factor,
/// each at most [`MAX_CANDELA`]) and checks that nothing follows them.
fn read_candela(numbers: &mut Numbers<'_>, header: &Header) -> Result<Vec<f64>, IesError> {
    let file = numbers.file;
    let Header {
        nv,
        nh,
        multiplier,
        ballast,
        ..
    } = *header;
    let err = |line, column, message| error_at(file, line, column, message);
    let mut candela = Vec::with_capacity(nv * nh);
    for _ in 0..nv * nh {
        let c = numbers.next("a candela value")?;
        if c.0 < 0.0 {
            return Err(err(
                c.1,
                c.2,
                format!("candela values must be >= 0, got {}", c.0),
            ));
        }
        let intensity = c.0 * multiplier.0 * ballast.0;
        if !intensity.is_finite() || intensity > MAX_CANDELA {
            return Err(err(
                c.1,
                c.2,
                format!(
                    "candela value {} times the multiplier and ballast factor is {intensity:e} cd, \
                     above the largest allowed, {MAX_CANDELA:e} cd",
                    c.0
                ),
            ));
        }
        candela.push(intensity);
    }
    if let Some((text, line, column)) = numbers.tokens.next() {
        return Err(err(
            line,
            column,
            format!(
                "unexpected `{text}` after the {} candela values the header announces",
                nv * nh
            ),
        ));
    }
    Ok(candela)
}

/// The numbers after the TILT line, with their 1-based lines and columns.
struct Tokens<'a> {
    lines: &'a [&'a str],
    line: usize,
    column: usize,
}

impl<'a> Tokens<'a> {
    fn new(lines: &'a [&'a str], first: usize) -> Self {
        Tokens {
            lines,
            line: first,
            column: 0,
        }
    }

    /// The next blank- or comma-separated word, its line and column.
    fn next(&mut self) -> Option<(&'a str, usize, usize)> {
        while self.line < self.lines.len() {
            let text = self.lines[self.line];
            let rest = &text[self.column..];
            let skip = rest
                .find(|c: char| !(c.is_whitespace() || c == ','))
                .unwrap_or(rest.len());
            let start = self.column + skip;
            if start >= text.len() {
                self.line += 1;
                self.column = 0;
                continue;
            }
            let len = text[start..]
                .find(|c: char| c.is_whitespace() || c == ',')
                .unwrap_or(text.len() - start);
            self.column = start + len;
            let column = text[..start].chars().count() + 1;
            return Some((&text[start..start + len], self.line + 1, column));
        }
        None
    }

    /// The last line, for an error at the end of the file.
    fn end_line(&self) -> usize {
        self.lines.len().max(1)
    }
}

impl fmt::Display for Symmetry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Symmetry::Full => "rotationally symmetric",
            Symmetry::Quadrant => "quadrant-symmetric",
            Symmetry::Bilateral => "bilaterally symmetric",
            Symmetry::None => "asymmetric",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const COSINE: &str = "IESNA:LM-63-2002\n[TEST] cosine\n[MANUFAC] none\nTILT=NONE\n\
        1 -1 1 7 1 1 2 0.1 0.1 0\n1 1 0\n0 15 30 45 60 75 90\n0\n\
        1000 965.93 866.03 707.11 500 258.82 0\n";

    #[test]
    fn a_cosine_table_gives_its_flux_and_interpolates_between_angles() {
        let p = Photometry::parse(COSINE, "cos.ies").unwrap();
        assert_eq!(p.symmetry, Symmetry::Full);
        assert_eq!(p.lamp_lumens, None);
        assert_eq!(p.keywords[0], ("TEST".into(), "cosine".into()));
        // Linear interpolation of a cosine between 15° steps: within 1 %.
        for deg in [0.0f64, 7.0, 22.5, 50.0, 80.0] {
            let exact = 1000.0 * deg.to_radians().cos();
            let got = p.intensity(deg.to_radians(), 1.234);
            assert!(
                (got - exact).abs() <= 0.01 * 1000.0,
                "{deg}: {got} vs {exact}"
            );
        }
        assert_eq!(p.intensity(100f64.to_radians(), 0.0), 0.0);
        // π I0 lumens for a cosine distribution (within the interpolation).
        let flux = p.flux(PI / 2.0);
        assert!((flux / (PI * 1000.0) - 1.0).abs() < 0.01, "{flux}");
    }

    /// Finite but absurd intensities (1e300 cd, or a multiplier that makes
    /// them so) are refused where they stand: they made non-finite pixels.
    #[test]
    fn intensities_above_the_limit_are_refused_at_their_value() {
        for (text, line, column) in [
            (
                "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n1e300 0\n",
                6,
                1,
            ),
            (
                "TILT=NONE\n1 -1 1e10 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 1e6\n",
                6,
                4,
            ),
        ] {
            let e = Photometry::parse(text, "hot.ies").unwrap_err();
            assert_eq!((e.line, e.column), (line, column), "{e}");
            assert!(e.message.contains("above the largest allowed"), "{e}");
        }
        let at_limit =
            format!("TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n{MAX_CANDELA:e} 0\n");
        assert!(Photometry::parse(&at_limit, "ok.ies").is_ok());
    }

    #[test]
    fn symmetries_mirror_the_horizontal_angles() {
        // Intensity = 100 + horizontal angle in degrees, over 0..90.
        let text = "IESNA:LM-63-1995\nTILT=NONE\n2 500 2 2 3 1 1 0 0 0\n1 1 100\n\
            0 90\n0 45 90\n100 100\n145 145\n190 190\n";
        let p = Photometry::parse(text, "q.ies").unwrap();
        assert_eq!(p.symmetry, Symmetry::Quadrant);
        assert_eq!(p.lamp_lumens, Some(1000.0));
        let i = |deg: f64| p.intensity(0.3, deg.to_radians());
        assert!((i(30.0) - 2.0 * 130.0).abs() < 1e-9);
        assert!((i(150.0) - i(30.0)).abs() < 1e-9);
        assert!((i(210.0) - i(30.0)).abs() < 1e-9);
        assert!((i(330.0) - i(30.0)).abs() < 1e-9);
        assert!((i(-30.0) - i(30.0)).abs() < 1e-9);
    }

    #[test]
    fn errors_name_the_line_and_column_and_what_was_expected() {
        let cases = [
            ("TILT=INCLUDE\n", 1, "only TILT=NONE"),
            ("[A] b\n", 1, "no TILT"),
            ("TILT=NONE\n1 -1 1 2 1 2 2 0 0 0\n", 2, "type 2 (B)"),
            (
                "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 x\n",
                4,
                "expected a vertical angle",
            ),
            (
                "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n5\n",
                6,
                "file ends",
            ),
            (
                "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n90 0\n0\n5 5\n",
                4,
                "must increase",
            ),
            (
                "TILT=NONE\n1 -1 1 2 2 1 2 0 0 0\n1 1 0\n0 90\n0 45\n5 5 5 5\n",
                5,
                "end at 0, 90",
            ),
            (
                "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n5 -5\n",
                6,
                ">= 0",
            ),
            (
                "TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n5 5 5\n",
                6,
                "unexpected",
            ),
            (
                "TILT=NONE\n1 0 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n5 5\n",
                2,
                "lumens per lamp",
            ),
        ];
        for (text, line, words) in cases {
            let e = Photometry::parse(text, "bad.ies").unwrap_err();
            assert_eq!(e.line, line, "{text:?}: {e}");
            assert!(e.to_string().starts_with("bad.ies:"), "{e}");
            assert!(e.message.contains(words), "{text:?}: {e}");
        }
        let e = Photometry::parse("TILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 x\n", "b.ies");
        assert_eq!(e.unwrap_err().column, 3);
    }
}
