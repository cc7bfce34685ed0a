//! Measurement points: where `--illuminance-at` asks for the illuminance.
//!
//! A CSV file, one point a line: `x,y,z,nx,ny,nz`, the position in scene
//! units and the normal of the surface the light falls on (normalised
//! here; any finite length but zero, however large or small). Coordinates
//! are at most [`MAX_COORDINATE`] in magnitude, as the scene's are.
//!
//! The first line that is not blank or a comment is a header, and skipped,
//! when every field of it is a word (it starts with a letter or `_`, as
//! `x,y,z,nx,ny,nz` does); a line with any number or empty field in it is
//! data, so a typo in the first point (`1,2,x,0,1,0`) is an error at its
//! column rather than a header silently dropped. Blank lines and lines
//! starting with `#` are skipped, and so is a UTF-8 byte order mark.
//! Blanks around values are allowed.

use super::input::{read_file, InputKind};
use crate::budget::{fmt_count, MemoryBudget};
use crate::scene::error::fmt_num;
use crate::scene::MAX_COORDINATE;
use glam::{DVec3, Vec3};
use std::path::Path;

/// Why a points file could not be read: `FILE:LINE:COLUMN: error: ...`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}", crate::scene::error::positioned(file, *line, *column, "error", message))]
pub struct PointsError {
    /// The file as named by the user.
    pub file: String,
    /// 1-based line (0 when the file could not be read).
    pub line: usize,
    /// 1-based column in characters (0 when the file could not be read).
    pub column: usize,
    /// What is wrong and what was expected.
    pub message: String,
}

/// One measurement point: a position in scene units and a unit normal.
pub type MeasurementPoint = (Vec3, Vec3);

/// Bytes a measurement point takes from its reading to its result: the
/// point itself, its irradiance and the CSV row written for it.
pub const BYTES_PER_POINT: u64 = 128;

/// Reads the points file at `path` (see the module docs), under no memory
/// budget.
pub fn load_points(path: &Path) -> Result<Vec<MeasurementPoint>, PointsError> {
    load_points_within(path, &MemoryBudget::UNLIMITED)
}

/// Reads the points file at `path`, refusing it before parsing when its
/// text and a point per line would not fit `budget`.
pub fn load_points_within(
    path: &Path,
    budget: &MemoryBudget,
) -> Result<Vec<MeasurementPoint>, PointsError> {
    let name = path.display().to_string();
    let cannot = |message: String| PointsError {
        file: name.clone(),
        line: 0,
        column: 0,
        message,
    };
    let (bytes, _) = read_file(path, InputKind::Points)
        .map_err(|e| cannot(crate::scene::error::unreadable(&e)))?;
    let lines = bytes.iter().filter(|&&b| b == b'\n').count() as u64 + 1;
    let need = (bytes.len() as u64).saturating_add(lines.saturating_mul(BYTES_PER_POINT));
    budget
        .check(need, || {
            format!("{} lines of measurement points", fmt_count(lines))
        })
        .map_err(|over| cannot(over.to_string()))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| cannot("cannot read: stream did not contain valid UTF-8".to_string()))?;
    parse_points(&text, &name)
}

/// Parses the text of a points file named `file` in messages.
pub fn parse_points(text: &str, file: &str) -> Result<Vec<MeasurementPoint>, PointsError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut points = Vec::new();
    let mut seen_data = false;
    for (k, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let err = |column: usize, message: String| PointsError {
            file: file.to_string(),
            line: k + 1,
            column,
            message,
        };
        let mut fields = Vec::with_capacity(6);
        let mut start = 0;
        for field in line.split(',') {
            let lead = field.len() - field.trim_start().len();
            let column = line[..start + lead].chars().count() + 1;
            fields.push((field.trim(), column));
            start += field.len() + 1;
        }
        let is_header = !seen_data && fields.iter().all(|(f, _)| is_word(f));
        if is_header {
            seen_data = true;
            continue;
        }
        seen_data = true;
        if fields.len() != 6 {
            return Err(err(
                fields.get(6).map_or(line.chars().count() + 1, |f| f.1),
                format!(
                    "expected 6 values x,y,z,nx,ny,nz (position, then the normal), got {}",
                    fields.len()
                ),
            ));
        }
        let mut v = [0.0f64; 6];
        for (k, (slot, (field, column))) in v.iter_mut().zip(&fields).enumerate() {
            match field.parse::<f64>() {
                _ if field.is_empty() => {
                    return Err(err(*column, "expected a number, the field is empty".into()))
                }
                Ok(x) if k < 3 && x.is_finite() && x.abs() > MAX_COORDINATE => {
                    return Err(err(
                        *column,
                        format!(
                            "coordinate `{field}` is too far from the origin; coordinates must \
                             be at most {} in magnitude",
                            fmt_num(MAX_COORDINATE)
                        ),
                    ))
                }
                // A normal is only a direction: any finite f64 will do.
                Ok(x) if x.is_finite() => *slot = x,
                _ => {
                    return Err(err(
                        *column,
                        format!("expected a finite number, got `{field}`"),
                    ))
                }
            }
        }
        let Some(unit) = unit_normal(DVec3::new(v[3], v[4], v[5])) else {
            return Err(err(
                fields[3].1,
                "the normal nx,ny,nz must not be zero".into(),
            ));
        };
        let position = DVec3::new(v[0], v[1], v[2]).as_vec3();
        points.push((position, unit));
    }
    if points.is_empty() {
        return Err(PointsError {
            file: file.to_string(),
            line: text.lines().count().max(1),
            column: 1,
            message: "no points: expected lines of x,y,z,nx,ny,nz".into(),
        });
    }
    Ok(points)
}

/// True for a header field: a word starting with a letter or `_` (never
/// a number, which may start with a digit, a sign or a point, nor empty).
fn is_word(field: &str) -> bool {
    field
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
        && !matches!(
            field.to_ascii_lowercase().as_str(),
            "inf" | "infinity" | "nan"
        )
}

/// `n` as an `f32` unit vector, or `None` when it is zero. The components
/// are divided by the largest magnitude first, so the length neither
/// overflows (`1e300`) nor underflows (`1e-300`) when squared.
fn unit_normal(n: DVec3) -> Option<Vec3> {
    let largest = n.abs().max_element();
    if largest == 0.0 || !largest.is_finite() {
        return None;
    }
    let unit = (n / largest).normalize();
    unit.is_finite().then(|| unit.as_vec3())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_with_a_header_and_normalise_their_normals() {
        let p = parse_points(
            "x,y,z,nx,ny,nz\n1, 2,3,0,0,2\n\n# c\n4,5,6,0,1,0\n",
            "p.csv",
        )
        .unwrap();
        assert_eq!(
            p,
            vec![
                (Vec3::new(1.0, 2.0, 3.0), Vec3::Z),
                (Vec3::new(4.0, 5.0, 6.0), Vec3::Y)
            ]
        );
    }

    #[test]
    fn bad_points_say_where() {
        let e = parse_points("1,2,3,0,0,1\n1,2,x,0,0,1\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (2, 5));
        assert!(e
            .to_string()
            .starts_with("p.csv:2:5: error: expected a finite number"));
        let e = parse_points("1,2,3,0,0\n", "p.csv").unwrap_err();
        assert_eq!(e.line, 1);
        assert!(e.message.contains("expected 6 values"), "{e}");
        let e = parse_points("1,2,3,0,0,0\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (1, 7));
        assert!(parse_points("x,y\n", "p.csv")
            .unwrap_err()
            .message
            .contains("no points"));
        // A header only on the first line.
        let e = parse_points("1,2,3,0,0,1\nx,y,z,a,b,c\n", "p.csv").unwrap_err();
        assert_eq!(e.line, 2);
    }

    #[test]
    fn a_header_is_words_only_and_a_typo_in_the_first_point_is_an_error() {
        // A byte order mark before the header (Excel writes one).
        let p = parse_points("\u{feff}x,y,z,nx,ny,nz\n1,2,3,0,1,0\n", "p.csv").unwrap();
        assert_eq!(p, vec![(Vec3::new(1.0, 2.0, 3.0), Vec3::Y)]);
        // ... and before data.
        let p = parse_points("\u{feff}1,2,3,0,1,0\n", "p.csv").unwrap();
        assert_eq!(p.len(), 1);
        // A typo on the first line is not a header.
        let e = parse_points("1,2,x,0,1,0\n4,5,6,0,1,0\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (1, 5), "{e}");
        assert!(e.message.contains("`x`"), "{e}");
        // Nor is a first line with an empty field, or `inf`.
        let e = parse_points("1,,3,0,1,0\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (1, 3), "{e}");
        assert!(e.message.contains("empty"), "{e}");
        let e = parse_points("inf,2,3,0,1,0\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (1, 1), "{e}");
        // An empty field after the first line too.
        let e = parse_points("1,2,3,0,1,0\n1,2,3,0,, 1\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (2, 9), "{e}");
    }

    #[test]
    fn normals_of_any_finite_nonzero_length_are_normalised() {
        let p = parse_points(
            "0,0,0,0,1e30,0\n0,0,0,0,0,1e-30\n0,0,0,3e300,4e300,0\n0,0,0,1e-320,0,0\n",
            "p.csv",
        )
        .unwrap();
        let normals: Vec<Vec3> = p.iter().map(|q| q.1).collect();
        assert_eq!(normals[0], Vec3::Y);
        assert_eq!(normals[1], Vec3::Z);
        assert!((normals[2] - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6);
        assert_eq!(normals[3], Vec3::X);
        let e = parse_points("0,0,0,0,0,1e400\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (1, 11), "{e}");
    }

    #[test]
    fn coordinates_beyond_the_scene_limit_are_refused() {
        assert!(parse_points("1e12,0,0,0,1,0\n", "p.csv").is_ok());
        let e = parse_points("0,-1e13,0,0,1,0\n", "p.csv").unwrap_err();
        assert_eq!((e.line, e.column), (1, 3), "{e}");
        assert!(e.message.contains("at most 1e12"), "{e}");
    }
}
