//! What a run says of its daylight: the standard sky and the sun that lit
//! it, for `--stats` and the summary line ("under cie-clear, 10,000 lx,
//! and the sun at az 215.3, alt 52.1, 78,400 lx").

use crate::config::RunConfig;
use crate::scene::Scene;
use serde::Serialize;

/// A standard sky that lit the scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SkyStats {
    /// Its name as the command line gives it (`cie-clear`, `cie:7`).
    pub name: String,
    /// Its unobstructed horizontal illuminance, lux (the sun's not
    /// counted).
    pub horizontal_lux: f64,
    /// Its zenith luminance, cd/m².
    pub zenith_cd: f64,
}

/// The sun that lit the scene (`--sun`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SunStats {
    /// Degrees clockwise from true north (90 is east).
    pub azimuth: f64,
    /// Degrees above the horizon.
    pub altitude: f64,
    /// The direct normal illuminance `E_n`, lux.
    pub normal_lux: f64,
    /// The direct illuminance on an unobstructed horizontal plane,
    /// `E_n sin(altitude)`, lux.
    pub horizontal_lux: f64,
}

/// The standard sky of a run, `None` without one.
pub fn sky_stats(config: &RunConfig) -> Option<SkyStats> {
    let sky = config.daylight.resolve().ok().flatten()?;
    Some(SkyStats {
        name: sky.model.name(),
        horizontal_lux: sky.horizontal_illuminance(),
        zenith_cd: sky.zenith,
    })
}

/// The sun that lit `scene`, `None` without one.
pub fn sun_stats(scene: &Scene) -> Option<SunStats> {
    let sun = scene.sun?;
    Some(SunStats {
        azimuth: sun.position.azimuth.to_degrees(),
        altitude: sun.position.altitude.to_degrees(),
        normal_lux: sun.normal_illuminance,
        horizontal_lux: sun.horizontal_illuminance(),
    })
}

/// The summary line's words for the light from outside, starting with a
/// space: `" under cie-clear, 10,000 lx, and the sun at az 215.3, alt
/// 52.1, 78,400 lx"`; with a uniform sky of radiosity `uniform` (its
/// text) `" under a sky of 1"`; empty under none.
pub fn summary_words(
    sky: Option<&SkyStats>,
    uniform: Option<String>,
    sun: Option<&SunStats>,
) -> String {
    let sky = match (sky, uniform) {
        (Some(s), _) => Some(format!("{}, {} lx", s.name, thousands(s.horizontal_lux))),
        (None, Some(u)) => Some(format!("a sky of {u}")),
        (None, None) => None,
    };
    let sun = sun.map(|s| {
        format!(
            "the sun at az {:.1}, alt {:.1}, {} lx",
            s.azimuth,
            s.altitude,
            thousands(s.normal_lux)
        )
    });
    match (sky, sun) {
        (Some(sky), Some(sun)) => format!(" under {sky}, and {sun}"),
        (Some(sky), None) => format!(" under {sky}"),
        (None, Some(sun)) => format!(" under {sun}"),
        (None, None) => String::new(),
    }
}

/// `x` rounded to three significant digits, whole, with thousands
/// separated by commas (`10,000`, `78,400`, `0.5`).
pub fn thousands(x: f64) -> String {
    if !x.is_finite() || x.abs() < 1.0 {
        return super::short(x);
    }
    let magnitude = x.abs().log10().floor() as i32;
    let step = 10f64.powi((magnitude - 2).max(0));
    let rounded = ((x / step).round() * step) as i64;
    let digits = rounded.unsigned_abs().to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    if rounded < 0 {
        out.insert(0, '-');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_names_the_sky_and_the_sun() {
        let sky = SkyStats {
            name: "cie-clear".into(),
            horizontal_lux: 10_004.2,
            zenith_cd: 3000.0,
        };
        let sun = SunStats {
            azimuth: 215.34,
            altitude: 52.06,
            normal_lux: 78_412.0,
            horizontal_lux: 61_800.0,
        };
        assert_eq!(
            summary_words(Some(&sky), None, Some(&sun)),
            " under cie-clear, 10,000 lx, and the sun at az 215.3, alt 52.1, 78,400 lx"
        );
        assert_eq!(
            summary_words(Some(&sky), None, None),
            " under cie-clear, 10,000 lx"
        );
        assert_eq!(
            summary_words(None, None, Some(&sun)),
            " under the sun at az 215.3, alt 52.1, 78,400 lx"
        );
        assert_eq!(
            summary_words(None, Some("1".into()), None),
            " under a sky of 1"
        );
        assert_eq!(summary_words(None, None, None), "");
        assert_eq!(
            (thousands(999.4), thousands(1234.0), thousands(1_236_000.0)),
            ("999".into(), "1,230".into(), "1,240,000".into())
        );
    }
}
