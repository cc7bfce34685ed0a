//! Parsers for option values that are more than a number: each turns the
//! text into the type the library uses, or says what the text should look
//! like. clap calls them while parsing, so a bad value is a usage error
//! (exit code 2) naming the option.

use crate::color::Rgb;
use crate::scene::{
    days_in_month, solar_position, SkyLevel, SkyModel, SunPosition, SunTime, MAX_COORDINATE,
    MAX_EMISSION, MAX_SUN_LUX,
};
use crate::solver::hemicube::HemicubeRes;
use crate::solver::{ShooterSamples, TailOption};

/// An option value that does not parse. clap prints the message after its
/// own `invalid value 'TEXT' for '--OPTION <NAME>': `; it is still a whole
/// sentence naming the option, so it reads the same wherever it is shown.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ValueError {
    /// `--size` is not `WxH` with whole numbers of pixels, both at least 1.
    #[error("--size must look like 640x480 (whole numbers >= 1), got `{0}`")]
    Size(String),
    /// `--shooter-samples` is neither `all` nor a whole number at least 1.
    #[error("--shooter-samples must be `all` or a whole number >= 1, got `{0}`")]
    ShooterSamples(String),
    /// `--tail` is neither `auto`, `off` nor a fraction in `[0, 1]`.
    #[error("--tail must be `auto`, `off` or a fraction from 0 to 1 (like 0.03), got `{0}`")]
    Tail(String),
    /// `--tail-particles` is not a number above 0 and at most 10⁶.
    #[error("--tail-particles must be a number above 0 and at most 1e6 (like 16), got `{0}`")]
    TailParticles(String),
    /// `--emit` is not `NAME=VALUE` with a non-empty name and a radiosity
    /// `V` or `R,G,B`, each channel a number from 0 to
    /// [`MAX_EMISSION`].
    #[error(
        "--emit must look like NAME=10 or NAME=10,8,6 (a radiosity per channel, \
         from 0 to {max:e}), got `{0}`",
        max = MAX_EMISSION
    )]
    Emit(String),
    /// `--sky` is not a radiosity `V` or `R,G,B`, each channel a number
    /// from 0 to [`MAX_EMISSION`].
    #[error(
        "--sky must look like 1 or 0.8,0.9,1.2 (a radiosity per channel, \
         from 0 to {max:e}), got `{0}`",
        max = MAX_EMISSION
    )]
    Sky(String),
    /// `--sky cie-...` is not a standard sky `cie-overcast`, `cie-clear`
    /// or `cie:N` (N from 1 to 15), optionally followed by `,VALUELX` (an
    /// unobstructed horizontal illuminance) or `,VALUECD` (a zenith
    /// luminance in cd/m²), the value finite and `> 0`.
    #[error(
        "--sky must name a standard sky like cie-overcast, cie-clear or cie:7 (types 1 to 15), \
         optionally with its brightness as `,10000lx` (unobstructed horizontal illuminance) \
         or `,3000cd` (zenith luminance in cd/m²), got `{0}`"
    )]
    StandardSky(String),
    /// `--sun` is not `AZIMUTH,ALTITUDE[,Nlx]`: degrees clockwise from
    /// north, degrees above the horizon from 0 to 90, and optionally the
    /// direct normal illuminance in lux (`> 0`, at most [`MAX_SUN_LUX`]).
    #[error(
        "--sun must look like 135,40 or 135,40,80000lx (azimuth in degrees clockwise from \
         north, altitude in degrees from 0 to 90, optionally the direct normal illuminance \
         in lux, more than 0 and at most {max:e}), or give a date, got `{0}`",
        max = MAX_SUN_LUX
    )]
    Sun(String),
    /// `--sun` starts with a date but is not
    /// `DATE,TIME,LATITUDE,LONGITUDE[,ZONE][,Nlx]`.
    #[error(
        "--sun with a date must look like 2026-06-21,15:00,51.48,-0.0 or \
         2026-06-21,15:00,51.48,-0.0,1,80000lx: a date YYYY-MM-DD from {min} to {max_year}, \
         a local standard time HH:MM or HH:MM:SS, the latitude (-90 to 90) and longitude \
         (-180 to 180, east positive) in degrees, optionally the zone in hours from UTC \
         (-12 to 14; default the longitude's nominal zone, longitude/15 rounded) and the \
         direct normal illuminance in lux; got `{0}`",
        min = MIN_SUN_YEAR,
        max_year = MAX_SUN_YEAR
    )]
    SunDate(String),
    /// `--north` is not a finite number of degrees.
    #[error("--north must be a number of degrees (true north clockwise from the model's north), got `{0}`")]
    North(String),
    /// `--hemicube-res` is not a whole number, or not one a hemicube can
    /// have ([`HemicubeRes::new`]).
    #[error("--hemicube-res must be an even whole number of pixels from {min} to {max}, got `{0}`",
        min = crate::solver::hemicube::MIN_HEMICUBE_RES,
        max = crate::solver::hemicube::MAX_HEMICUBE_RES)]
    HemicubeRes(String),
    /// `--ies` is not `NAME=FILE` with both parts non-empty.
    #[error("--ies must look like NAME=FILE.ies, got `{0}`")]
    Ies(String),
    /// `--workplane` is not `HEIGHT` or `HEIGHT,SPACING`, a height `>= 0`
    /// and a spacing `> 0`, both finite.
    #[error("--workplane must look like 0.8 or 0.8,0.25 (a height >= 0, a spacing > 0, in scene units), got `{0}`")]
    Workplane(String),
    /// `--eye` or `--look-at` is not a point `X,Y,Z`: three finite
    /// numbers, each at most [`MAX_COORDINATE`] in magnitude.
    #[error(
        "{option} must be a point X,Y,Z like 1.5,1.6,-2 (three numbers, each at most \
         {max:e} in magnitude), got `{text}`",
        max = MAX_COORDINATE
    )]
    Point {
        /// The option, as spelled on the command line.
        option: &'static str,
        /// The value given.
        text: String,
    },
    /// `--up` is not a direction `X,Y,Z`: a point (as `--eye`) that is
    /// not all zero.
    #[error("--up must be a direction X,Y,Z like 0,1,0 (three numbers, not all zero), got `{0}`")]
    Up(String),
    /// A number option's value is not a number.
    #[error("expected a number like 0.5, 2 or 1e-3, got `{0}`")]
    Number(String),
    /// A count option's value is not a whole number from 0 up (written
    /// `200` or `2e5`) that fits the count.
    #[error("expected a whole number like 0, 200 or 2e5{}, got `{text}`", at_most(*.max))]
    Whole {
        /// The value given.
        text: String,
        /// The largest count the option takes.
        max: u64,
    },
    /// `--fov` is not a number of degrees strictly between 0 and 180.
    #[error("--fov must be a vertical field of view in degrees, more than 0 and less than 180, got `{0}`")]
    Fov(String),
}

/// Parses a number option (`f32` or `f64`): any float Rust reads
/// (`0.5`, `-2`, `1e-3`, `inf`); whether it is in range is the option's own
/// check, made later with its meaning in the message.
pub fn parse_number<T: std::str::FromStr>(text: &str) -> Result<T, ValueError> {
    text.trim()
        .parse()
        .map_err(|_| ValueError::Number(text.to_string()))
}

/// Parses a count option (steps, threads, elements): a whole number from
/// 0 up, also in exponent form when it is whole (`2e5`), at most `T`'s
/// largest value.
pub fn parse_whole<T>(text: &str) -> Result<T, ValueError>
where
    T: TryFrom<u64> + Bounded,
{
    let refuse = || ValueError::Whole {
        text: text.to_string(),
        max: T::MAX_COUNT,
    };
    let trimmed = text.trim();
    let whole: u64 = match trimmed.parse::<u64>() {
        Ok(n) => n,
        Err(_) => {
            let x: f64 = trimmed.parse().map_err(|_| refuse())?;
            // 2^64 is the first f64 past u64's range.
            if !(x >= 0.0 && x.fract() == 0.0 && x < 18_446_744_073_709_551_616.0) {
                return Err(refuse());
            }
            x as u64
        }
    };
    T::try_from(whole).map_err(|_| refuse())
}

/// ` (at most N)` for a count type smaller than `u64`, whose largest
/// value a user can reach; nothing for `u64`.
fn at_most(max: u64) -> String {
    if max < u64::MAX {
        format!(" (at most {max})")
    } else {
        String::new()
    }
}

/// The largest value of a count type, for [`parse_whole`]'s message.
pub trait Bounded {
    /// The type's largest value.
    const MAX_COUNT: u64;
}

impl Bounded for u32 {
    const MAX_COUNT: u64 = u32::MAX as u64;
}

impl Bounded for u64 {
    const MAX_COUNT: u64 = u64::MAX;
}

impl Bounded for usize {
    const MAX_COUNT: u64 = usize::MAX as u64;
}

/// Parses `--hemicube-res`: pixels across a hemicube's top face, an even
/// whole number in the range [`HemicubeRes::new`] accepts.
pub fn parse_hemicube_res(text: &str) -> Result<HemicubeRes, ValueError> {
    text.parse::<u64>()
        .ok()
        .and_then(|n| HemicubeRes::new(n).ok())
        .ok_or_else(|| ValueError::HemicubeRes(text.to_string()))
}

/// Parses `--ies`: `NAME=FILE`, split at the last `=`, neither empty.
/// Whether the scene has such a name and the file is an IES file is for
/// the run to say.
pub fn parse_ies(text: &str) -> Result<(String, std::path::PathBuf), ValueError> {
    match text.rsplit_once('=') {
        Some((name, file)) if !name.is_empty() && !file.is_empty() => {
            Ok((name.to_string(), file.into()))
        }
        _ => Err(ValueError::Ies(text.to_string())),
    }
}

/// Parses `--workplane`: `HEIGHT` or `HEIGHT,SPACING`, in scene units,
/// the height finite and `>= 0`, the spacing finite and `> 0`.
pub fn parse_workplane(text: &str) -> Result<(f32, Option<f32>), ValueError> {
    let bad = || ValueError::Workplane(text.to_string());
    let number = |s: &str| s.trim().parse::<f32>().ok().filter(|v| v.is_finite());
    let (height, spacing) = match text.split_once(',') {
        Some((h, s)) => (number(h).ok_or_else(bad)?, Some(number(s).ok_or_else(bad)?)),
        None => (number(text).ok_or_else(bad)?, None),
    };
    if height < 0.0 || spacing.is_some_and(|s| s <= 0.0) {
        return Err(bad());
    }
    Ok((height, spacing))
}

/// Three numbers `X,Y,Z` (spaces around them allowed), each finite and at
/// most [`MAX_COORDINATE`] in magnitude, read as `f64` and rounded to
/// `f32` as a `.sc` file's are, so that the same text gives the same
/// camera either way; `None` otherwise.
fn parse_triple(text: &str) -> Option<glam::Vec3> {
    let values = text
        .split(',')
        .map(|c| match c.trim().parse::<f64>() {
            Ok(x) if x.is_finite() && x.abs() <= MAX_COORDINATE => Some(x),
            _ => None,
        })
        .collect::<Option<Vec<f64>>>()?;
    match values[..] {
        [x, y, z] => Some(glam::DVec3::new(x, y, z).as_vec3()),
        _ => None,
    }
}

/// Parses `--eye`: a point `X,Y,Z` in scene units (see [`parse_triple`]).
pub fn parse_eye(text: &str) -> Result<glam::Vec3, ValueError> {
    parse_triple(text).ok_or_else(|| ValueError::Point {
        option: "--eye",
        text: text.to_string(),
    })
}

/// Parses `--look-at`: a point `X,Y,Z` in scene units (see
/// [`parse_eye`]).
pub fn parse_look_at(text: &str) -> Result<glam::Vec3, ValueError> {
    parse_triple(text).ok_or_else(|| ValueError::Point {
        option: "--look-at",
        text: text.to_string(),
    })
}

/// Parses `--up`: a direction `X,Y,Z`, as [`parse_eye`] but not zero
/// (in `f32`).
pub fn parse_up(text: &str) -> Result<glam::Vec3, ValueError> {
    parse_triple(text)
        .filter(|v| *v != glam::Vec3::ZERO)
        .ok_or_else(|| ValueError::Up(text.to_string()))
}

/// Parses `--fov`: degrees, read as a `.sc` file's `fov` is (an `f32`),
/// strictly between 0 and 180, and so that their radians are too.
pub fn parse_fov(text: &str) -> Result<f32, ValueError> {
    let deg = text.trim().parse::<f64>().ok().map(|d| d as f32);
    match deg {
        Some(d) if d > 0.0 && d < 180.0 && d.to_radians() > 0.0 => Ok(d),
        _ => Err(ValueError::Fov(text.to_string())),
    }
}

/// Parses `--size`: `WxH` (or `WXH`), width and height in pixels, both
/// whole numbers at least 1. How large a picture may be is the renderer's
/// to say, once it knows the camera.
pub fn parse_size(text: &str) -> Result<(u32, u32), ValueError> {
    let parsed = text
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if w >= 1 && h >= 1 => Ok((w, h)),
        _ => Err(ValueError::Size(text.to_string())),
    }
}

/// Parses `--shooter-samples`: `all` ([`ShooterSamples::All`]) or a whole
/// number `N >= 1` ([`ShooterSamples::AtMost`]`(N)`).
pub fn parse_shooter_samples(text: &str) -> Result<ShooterSamples, ValueError> {
    if text == "all" {
        return Ok(ShooterSamples::All);
    }
    match text.parse::<u32>() {
        Ok(n) if n >= 1 => Ok(ShooterSamples::AtMost(n)),
        _ => Err(ValueError::ShooterSamples(text.to_string())),
    }
}

/// Parses `--tail`: `auto`, `off`, or the unshot fraction from which the
/// particle tail carries the light left, in `[0, 1]`.
pub fn parse_tail(text: &str) -> Result<TailOption, ValueError> {
    match text {
        "auto" => Ok(TailOption::Auto),
        "off" => Ok(TailOption::Off),
        _ => match text.parse::<f64>() {
            Ok(f) if (0.0..=1.0).contains(&f) => Ok(TailOption::From(f)),
            _ => Err(ValueError::Tail(text.to_string())),
        },
    }
}

/// Parses `--tail-particles`: particles per element vertex, above 0 and
/// at most 10⁶ (beyond, one tail of a large model would trace more
/// particles than a day allows).
pub fn parse_tail_particles(text: &str) -> Result<f64, ValueError> {
    match text.parse::<f64>() {
        Ok(n) if n > 0.0 && n <= 1e6 => Ok(n),
        _ => Err(ValueError::TailParticles(text.to_string())),
    }
}

/// Parses `--emit`: `NAME=VALUE`, split at the last `=` (so a name may
/// hold one), with `NAME` not empty and `VALUE` a radiosity in the
/// scene's units, `V` (grey) or `R,G,B`, every channel finite, `>= 0` and
/// at most [`MAX_EMISSION`]. Whether the scene has such a name is the
/// scene's to say, once it is loaded.
pub fn parse_emit(text: &str) -> Result<(String, Rgb), ValueError> {
    let bad = || ValueError::Emit(text.to_string());
    let (name, value) = text.rsplit_once('=').ok_or_else(bad)?;
    if name.is_empty() {
        return Err(bad());
    }
    let rgb = parse_radiosity(value).ok_or_else(bad)?;
    Ok((name.to_string(), rgb))
}

/// What `--sky` asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SkyArg {
    /// A uniform sky of this radiosity (scene units).
    Uniform(Rgb),
    /// A standard sky, at this level or the model's default.
    Standard(SkyModel, Option<SkyLevel>),
}

/// Parses `--sky`: a radiosity in the scene's units, `V` (grey) or
/// `R,G,B`, every channel finite, `>= 0` and at most [`MAX_EMISSION`],
/// as the value of `--emit`; or a standard sky (text starting `cie`):
/// `cie-overcast`, `cie-clear` or `cie:N`, then optionally `,Elx` or
/// `,Lcd` (case ignored).
pub fn parse_sky(text: &str) -> Result<SkyArg, ValueError> {
    if !text.trim_start().to_ascii_lowercase().starts_with("cie") {
        return parse_radiosity(text)
            .map(SkyArg::Uniform)
            .ok_or_else(|| ValueError::Sky(text.to_string()));
    }
    let bad = || ValueError::StandardSky(text.to_string());
    let lower = text.trim().to_ascii_lowercase();
    let (name, value) = match lower.split_once(',') {
        Some((n, v)) => (n.trim(), Some(v.trim())),
        None => (lower.as_str(), None),
    };
    let model = match name {
        "cie-overcast" => SkyModel::CieOvercast,
        "cie-clear" => SkyModel::CLEAR,
        _ => {
            let n = name.strip_prefix("cie:").ok_or_else(bad)?;
            SkyModel::Cie(n.trim().parse::<u8>().map_err(|_| bad())?)
        }
    };
    if !model.is_valid() {
        return Err(bad());
    }
    let level = match value {
        None => None,
        Some(v) => {
            let (number, level): (&str, fn(f64) -> SkyLevel) = if let Some(n) = v.strip_suffix("lx")
            {
                (n, SkyLevel::Horizontal)
            } else if let Some(n) = v.strip_suffix("cd") {
                (n, SkyLevel::Zenith)
            } else {
                return Err(bad());
            };
            match number.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && x > 0.0 && x <= MAX_EMISSION => Some(level(x)),
                _ => return Err(bad()),
            }
        }
    };
    Ok(SkyArg::Standard(model, level))
}

/// The first year `--sun` takes a date in: NOAA's algorithm is stated
/// good from 1800 to 2100, and a little beyond.
pub const MIN_SUN_YEAR: i32 = 1800;

/// The last year `--sun` takes a date in.
pub const MAX_SUN_YEAR: i32 = 2200;

/// What `--sun` gives: where the sun is and, if given, how bright.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunArg {
    /// Where the sun is. The altitude is `0..=π/2` when given as an angle;
    /// from a date it may be negative (the sun below the horizon).
    pub position: SunPosition,
    /// The day of the year, when a date was given.
    pub day: Option<u32>,
    /// The direct normal illuminance given (`,Nlx`), lux, finite, `> 0`
    /// and at most [`MAX_SUN_LUX`].
    pub normal_lux: Option<f64>,
}

/// Parses `--sun`: `AZIMUTH,ALTITUDE[,Nlx]`, the azimuth in degrees
/// clockwise from north (any finite number), the altitude in degrees from
/// 0 to 90; or `DATE,TIME,LATITUDE,LONGITUDE[,ZONE][,Nlx]`, the date
/// `YYYY-MM-DD` ([`MIN_SUN_YEAR`] to [`MAX_SUN_YEAR`]), the local standard
/// time `HH:MM[:SS]`, degrees of latitude (north positive) and longitude
/// (east positive), the zone in hours from UTC (`-12..=14`; default the
/// longitude's nominal zone, `round(longitude / 15)`), the position then
/// by [`solar_position`]. `Nlx` is the direct normal illuminance in lux
/// (case ignored).
pub fn parse_sun(text: &str) -> Result<SunArg, ValueError> {
    let mut fields: Vec<String> = text
        .split(',')
        .map(|f| f.trim().to_ascii_lowercase())
        .collect();
    // A year of four digits and a dash: a date, right or wrong.
    let dated = fields.first().is_some_and(|f| {
        let b = f.as_bytes();
        b.len() > 5 && b[..4].iter().all(u8::is_ascii_digit) && b[4] == b'-'
    });
    let bad = || {
        if dated {
            ValueError::SunDate(text.to_string())
        } else {
            ValueError::Sun(text.to_string())
        }
    };
    let normal_lux = match fields.last().and_then(|f| f.strip_suffix("lx")) {
        Some(n) => {
            let lux = finite(n).filter(|&x| x > 0.0 && x <= MAX_SUN_LUX);
            fields.pop();
            Some(lux.ok_or_else(bad)?)
        }
        None => None,
    };
    if dated {
        let (year, month, day) = fields.first().and_then(|f| parse_date(f)).ok_or_else(bad)?;
        let (date_and_place, zone) = match fields.len() {
            4 => (&fields[..], None),
            5 => (&fields[..4], Some(finite(&fields[4]).ok_or_else(bad)?)),
            _ => return Err(bad()),
        };
        let hours = parse_clock(&date_and_place[1]).ok_or_else(bad)?;
        let latitude = finite(&date_and_place[2]).ok_or_else(bad)?;
        let longitude = finite(&date_and_place[3]).ok_or_else(bad)?;
        if latitude.abs() > 90.0 || longitude.abs() > 180.0 {
            return Err(bad());
        }
        let zone = zone.unwrap_or_else(|| (longitude / 15.0).round());
        if !(-12.0..=14.0).contains(&zone) {
            return Err(bad());
        }
        let time = SunTime {
            year,
            month,
            day,
            hours,
            zone,
        };
        return Ok(SunArg {
            position: solar_position(&time, latitude, longitude),
            day: Some(time.day_of_year()),
            normal_lux,
        });
    }
    let numbers = fields
        .iter()
        .map(|f| finite(f))
        .collect::<Option<Vec<f64>>>()
        .ok_or_else(bad)?;
    let [azimuth, altitude] = numbers[..] else {
        return Err(bad());
    };
    if !(0.0..=90.0).contains(&altitude) || azimuth.abs() > 360.0 * 1e6 {
        return Err(bad());
    }
    Ok(SunArg {
        position: SunPosition::from_degrees(azimuth.rem_euclid(360.0), altitude),
        day: None,
        normal_lux,
    })
}

/// A finite number, or `None`.
fn finite(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|x| x.is_finite())
}

/// `YYYY-MM-DD`, a real day from [`MIN_SUN_YEAR`] to [`MAX_SUN_YEAR`].
fn parse_date(text: &str) -> Option<(i32, u32, u32)> {
    let mut parts = text.split('-');
    let (y, m, d) = (parts.next()?, parts.next()?, parts.next()?);
    if parts.next().is_some() || y.len() != 4 || !(1..=2).contains(&m.len()) {
        return None;
    }
    let all_digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !(all_digits(y) && all_digits(m) && all_digits(d)) {
        return None;
    }
    let (year, month, day) = (y.parse().ok()?, m.parse().ok()?, d.parse().ok()?);
    let real = (MIN_SUN_YEAR..=MAX_SUN_YEAR).contains(&year)
        && (1..=days_in_month(year, month)).contains(&day);
    real.then_some((year, month, day))
}

/// `HH:MM` or `HH:MM:SS`, before 24:00, as hours.
fn parse_clock(text: &str) -> Option<f64> {
    let parts: Vec<&str> = text.split(':').collect();
    if !(2..=3).contains(&parts.len()) || parts.iter().any(|p| p.is_empty() || p.len() > 2) {
        return None;
    }
    let numbers: Vec<u32> = parts
        .iter()
        .map(|p| p.parse().ok())
        .collect::<Option<_>>()?;
    let (h, m, s) = (numbers[0], numbers[1], numbers.get(2).copied().unwrap_or(0));
    (h < 24 && m < 60 && s < 60).then(|| f64::from(h) + f64::from(m) / 60.0 + f64::from(s) / 3600.0)
}

/// Parses `--north`: degrees, finite (any sign, read modulo 360).
pub fn parse_north(text: &str) -> Result<f64, ValueError> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x.abs() <= 360.0 * 1e6 => Ok(x.rem_euclid(360.0)),
        _ => Err(ValueError::North(text.to_string())),
    }
}

/// A radiosity `V` or `R,G,B` (spaces around channels allowed), every
/// channel finite, `>= 0` and at most [`MAX_EMISSION`]; `None` otherwise.
fn parse_radiosity(value: &str) -> Option<Rgb> {
    let channels = value
        .split(',')
        .map(|c| match c.trim().parse::<f64>() {
            Ok(x) if x.is_finite() && (0.0..=MAX_EMISSION).contains(&x) => Some(x),
            _ => None,
        })
        .collect::<Option<Vec<f64>>>()?;
    match channels[..] {
        [v] => Some(Rgb::splat(v)),
        [r, g, b] => Some(Rgb::new(r, g, b)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_whole_numbers_that_fit() {
        assert_eq!(parse_whole::<u64>("200"), Ok(200));
        assert_eq!(parse_whole::<u64>(" 2e5 "), Ok(200_000));
        assert_eq!(parse_whole::<u32>("4294967295"), Ok(u32::MAX));
        for bad in ["-1", "1.5", "abc", "", "nan", "inf", "-0.5", "1e30"] {
            assert!(
                matches!(parse_whole::<u64>(bad), Err(ValueError::Whole { .. })),
                "{bad}"
            );
        }
        assert_eq!(
            parse_whole::<u32>("4294967296"),
            Err(ValueError::Whole {
                text: "4294967296".into(),
                max: u64::from(u32::MAX)
            })
        );
        assert_eq!(parse_number::<f32>("1e-3"), Ok(1e-3));
        assert_eq!(
            parse_number::<f64>("x"),
            Err(ValueError::Number("x".into()))
        );
    }

    #[test]
    fn sizes_are_width_by_height_in_whole_pixels() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert_eq!(parse_size("1X1"), Ok((1, 1)));
        for bad in [
            "10by10", "0x10", "10x0", "10x", "x10", "-1x5", "1.5x2", "", "10x10x10",
        ] {
            assert_eq!(parse_size(bad), Err(ValueError::Size(bad.into())), "{bad}");
        }
    }

    #[test]
    fn shooter_samples_are_all_or_at_least_one() {
        assert_eq!(parse_shooter_samples("all"), Ok(ShooterSamples::All));
        assert_eq!(parse_shooter_samples("1"), Ok(ShooterSamples::AtMost(1)));
        assert_eq!(
            parse_shooter_samples("256"),
            Ok(ShooterSamples::AtMost(256))
        );
        for bad in ["zero", "0", "-4", "ALL", "", "1e3"] {
            assert_eq!(
                parse_shooter_samples(bad),
                Err(ValueError::ShooterSamples(bad.into())),
                "{bad}"
            );
        }
    }

    #[test]
    fn emit_is_a_name_and_a_grey_or_coloured_radiosity() {
        assert_eq!(
            parse_emit("Lamp=10"),
            Ok(("Lamp".to_string(), Rgb::splat(10.0)))
        );
        assert_eq!(
            parse_emit("Ceiling Light=10,8, 6"),
            Ok(("Ceiling Light".to_string(), Rgb::new(10.0, 8.0, 6.0)))
        );
        assert_eq!(parse_emit("a=b=0"), Ok(("a=b".to_string(), Rgb::BLACK)));
        for bad in [
            "Lamp",
            "=10",
            "Lamp=",
            "Lamp=-1",
            "Lamp=a,b",
            "Lamp=1,2",
            "Lamp=1,2,3,4",
            "Lamp=nan",
            "Lamp=inf",
            "Lamp=1e21",
            "Lamp=1,,2",
        ] {
            assert_eq!(parse_emit(bad), Err(ValueError::Emit(bad.into())), "{bad}");
        }
        assert_eq!(
            parse_emit("Lamp=-1").unwrap_err().to_string(),
            "--emit must look like NAME=10 or NAME=10,8,6 (a radiosity per channel, \
             from 0 to 1e20), got `Lamp=-1`"
        );
    }

    #[test]
    fn sky_is_a_grey_or_coloured_radiosity() {
        let uniform = |rgb| Ok(SkyArg::Uniform(rgb));
        assert_eq!(parse_sky("1"), uniform(Rgb::splat(1.0)));
        assert_eq!(parse_sky("0.8, 0.9,1.2"), uniform(Rgb::new(0.8, 0.9, 1.2)));
        assert_eq!(parse_sky("0"), uniform(Rgb::BLACK));
        for bad in ["", "-1", "a", "1,2", "1,2,3,4", "nan", "inf", "1e21", "x=1"] {
            assert_eq!(parse_sky(bad), Err(ValueError::Sky(bad.into())), "{bad}");
        }
        assert_eq!(
            parse_sky("-1").unwrap_err().to_string(),
            "--sky must look like 1 or 0.8,0.9,1.2 (a radiosity per channel, \
             from 0 to 1e20), got `-1`"
        );
    }

    #[test]
    fn standard_skies_name_a_model_and_maybe_a_level() {
        use SkyLevel::{Horizontal, Zenith};
        let ok = |m, l| Ok(SkyArg::Standard(m, l));
        assert_eq!(parse_sky("cie-overcast"), ok(SkyModel::CieOvercast, None));
        assert_eq!(
            parse_sky("CIE-Overcast, 10000lx"),
            ok(SkyModel::CieOvercast, Some(Horizontal(10_000.0)))
        );
        assert_eq!(
            parse_sky("cie-clear,8000cd"),
            ok(SkyModel::CLEAR, Some(Zenith(8000.0)))
        );
        assert_eq!(parse_sky("cie:7"), ok(SkyModel::Cie(7), None));
        assert_eq!(
            parse_sky("cie:15,2e4lx"),
            ok(SkyModel::Cie(15), Some(Horizontal(2e4)))
        );
        for bad in [
            "cie",
            "cie-sunny",
            "cie:0",
            "cie:16",
            "cie:x",
            "cie-overcast,10000",
            "cie-clear,0lx",
            "cie-clear,-5cd",
            "cie-clear,nanlx",
            "cie:3,1e21lx",
            "cie-overcast,",
        ] {
            assert_eq!(
                parse_sky(bad),
                Err(ValueError::StandardSky(bad.into())),
                "{bad}"
            );
        }
    }

    #[test]
    fn the_sun_is_an_azimuth_and_an_altitude() {
        let sun = parse_sun("135, 40").unwrap();
        assert_eq!(sun.position, SunPosition::from_degrees(135.0, 40.0));
        let sun = parse_sun("-90,90").unwrap();
        assert_eq!(sun.position, SunPosition::from_degrees(270.0, 90.0));
        assert_eq!((sun.day, sun.normal_lux), (None, None));
        let sun = parse_sun("180,45,80000LX").unwrap();
        assert_eq!(sun.normal_lux, Some(80_000.0));
        for bad in [
            "",
            "135",
            "135,-1",
            "135,91",
            "135,40,80000",
            "135,40,0lx",
            "135,40,-5lx",
            "135,40,2e6lx",
            "135,40,1,2",
            "a,b",
            "inf,3",
        ] {
            assert_eq!(parse_sun(bad), Err(ValueError::Sun(bad.into())), "{bad}");
        }
    }

    #[test]
    fn the_sun_from_a_date_time_and_place() {
        // Greenwich at 15:00 UTC on the June solstice: high in the
        // west-south-west.
        let sun = parse_sun("2026-06-21,15:00,51.48,-0.0").unwrap();
        let (az, alt) = (
            sun.position.azimuth.to_degrees(),
            sun.position.altitude.to_degrees(),
        );
        assert!(
            az > 235.0 && az < 250.0 && alt > 40.0 && alt < 55.0,
            "{az} {alt}"
        );
        assert_eq!((sun.day, sun.normal_lux), (Some(172), None));
        // The zone defaults to the longitude's nominal one: 15:00 at 30° E
        // is 15:00 at UTC+2.
        assert_eq!(
            parse_sun("2026-06-21,15:00,10,30").unwrap(),
            parse_sun("2026-06-21,15:00,10,30,2").unwrap()
        );
        let given = parse_sun("2026-06-21,15:00:30,51.48,-0.0,1,90000lx").unwrap();
        assert_eq!(given.normal_lux, Some(90_000.0));
        // At midnight the sun is below the horizon: parsed all the same.
        let night = parse_sun("2026-06-21,00:00,51.48,-0.0").unwrap();
        assert!(night.position.altitude < 0.0);
        for bad in [
            "2026-02-30,12:00,50,0",
            "2026-06-21,24:00,50,0",
            "2026-06-21,12:60,50,0",
            "2026-06-21,12,50,0",
            "2026-06-21,12:00,91,0",
            "2026-06-21,12:00,50,181",
            "2026-06-21,12:00,50",
            "2026-06-21,12:00,50,0,15",
            "2026-06-21,12:00,50,0,1,2",
            "2026-06-21,12:00,50,0,0lx",
            "1700-06-21,12:00,50,0",
        ] {
            assert_eq!(
                parse_sun(bad),
                Err(ValueError::SunDate(bad.into())),
                "{bad}"
            );
        }
        assert_eq!(parse_north("-30"), Ok(330.0));
        assert_eq!(parse_north("x"), Err(ValueError::North("x".into())));
    }

    #[test]
    fn camera_points_are_three_finite_numbers() {
        assert_eq!(parse_eye("1.5,1.6,-2"), Ok(glam::Vec3::new(1.5, 1.6, -2.0)));
        assert_eq!(
            parse_look_at(" 0, 1e3 ,0"),
            Ok(glam::Vec3::new(0.0, 1000.0, 0.0))
        );
        assert_eq!(parse_up("0,0,-1"), Ok(glam::Vec3::NEG_Z));
        for bad in [
            "", "1,2", "1,2,3,4", "a,b,c", "nan,0,0", "inf,0,0", "1e13,0,0", "1;2;3",
        ] {
            assert!(parse_eye(bad).is_err(), "{bad}");
            assert!(parse_up(bad).is_err(), "{bad}");
        }
        assert_eq!(
            parse_eye("1,2").unwrap_err().to_string(),
            "--eye must be a point X,Y,Z like 1.5,1.6,-2 (three numbers, each at most 1e12 \
             in magnitude), got `1,2`"
        );
        assert_eq!(
            parse_up("0,0,0").unwrap_err().to_string(),
            "--up must be a direction X,Y,Z like 0,1,0 (three numbers, not all zero), got `0,0,0`"
        );
        // A component below f32's range rounds to zero: no direction.
        assert!(parse_up("1e-50,0,0").is_err());
    }

    #[test]
    fn the_field_of_view_is_strictly_between_0_and_180_degrees() {
        assert_eq!(parse_fov("45"), Ok(45.0));
        assert_eq!(parse_fov("179.9"), Ok(179.9));
        for bad in ["0", "180", "-10", "200", "nan", "inf", "1e-50", "wide", ""] {
            assert_eq!(parse_fov(bad), Err(ValueError::Fov(bad.into())), "{bad}");
        }
        // A value that rounds to 180 in f32 is 180.
        assert!(parse_fov("179.999999999").is_err());
    }

    #[test]
    fn messages_keep_their_wording() {
        assert_eq!(
            parse_size("10by10").unwrap_err().to_string(),
            "--size must look like 640x480 (whole numbers >= 1), got `10by10`"
        );
        assert_eq!(
            parse_shooter_samples("zero").unwrap_err().to_string(),
            "--shooter-samples must be `all` or a whole number >= 1, got `zero`"
        );
    }
}
