//! Measurement points: where `--illuminance-at` asks for the illuminance.
//!
//! A CSV file, one point a line: `x,y,z,nx,ny,nz`, the position in scene
//! units and the normal of the surface the light falls on (normalised
//! here; any length but zero). A first line that is not numbers is a
//! header and skipped; blank lines and lines starting with `#` are
//! skipped too. Blanks around values are allowed.

use super::input::{read_file, InputError, InputKind};
use glam::Vec3;
use std::path::Path;

/// Why a points file could not be read: `FILE:LINE:COLUMN: error: ...`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: error: {message}")]
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

/// Reads the points file at `path` (see the module docs).
pub fn load_points(path: &Path) -> Result<Vec<MeasurementPoint>, PointsError> {
    let name = path.display().to_string();
    let cannot = |message: String| PointsError {
        file: name.clone(),
        line: 0,
        column: 0,
        message,
    };
    let (bytes, _) = read_file(path, InputKind::Points).map_err(|e| {
        cannot(match e {
            InputError::Io { error, .. } => format!("cannot read the points file: {error}"),
            refused => refused.to_string(),
        })
    })?;
    let text = String::from_utf8(bytes).map_err(|_| {
        cannot("cannot read the points file: stream did not contain valid UTF-8".to_string())
    })?;
    parse_points(&text, &name)
}

/// Parses the text of a points file named `file` in messages.
pub fn parse_points(text: &str, file: &str) -> Result<Vec<MeasurementPoint>, PointsError> {
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
        let is_header = !seen_data
            && points.is_empty()
            && fields.iter().any(|(f, _)| f.parse::<f32>().is_err());
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
        let mut v = [0.0f32; 6];
        for (slot, (field, column)) in v.iter_mut().zip(&fields) {
            match field.parse::<f32>() {
                Ok(x) if x.is_finite() => *slot = x,
                _ => {
                    return Err(err(
                        *column,
                        format!("expected a finite number, got `{field}`"),
                    ))
                }
            }
        }
        let normal = Vec3::new(v[3], v[4], v[5]);
        let unit = normal.normalize_or_zero();
        if unit == Vec3::ZERO || !unit.is_finite() {
            return Err(err(
                fields[3].1,
                "the normal nx,ny,nz must not be zero".into(),
            ));
        }
        points.push((Vec3::new(v[0], v[1], v[2]), unit));
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
}
