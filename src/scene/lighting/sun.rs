//! The sun as a light (`--sun`): where it stands, from an azimuth and an
//! altitude or from a date, a time and a place, and how bright its direct
//! light is. The solver shoots its light once, before the first step
//! ([`crate::solver::sun`]).
//!
//! **Position.** From a date and time the sun's position follows NOAA's
//! solar calculator (the spreadsheet `NOAA_Solar_Calculations_day.xls`
//! of the Global Monitoring Laboratory, after Meeus, *Astronomical
//! Algorithms*, 1991, the low-precision solar coordinates of chapter 24
//! and the equation of time of chapter 27): the sun's apparent longitude,
//! declination and the equation of time from the Julian century, then the
//! hour angle at the place, then altitude and azimuth, the altitude
//! raised by the spreadsheet's standard atmospheric refraction. NOAA
//! states it good to a minute of arc or so for dates between 1800 and
//! 2100 and latitudes within ±72°. The clock time is local standard time
//! at `zone` hours from UTC (no daylight saving time is applied).
//!
//! **Brightness.** The direct normal illuminance `E_n` (lux, on a plane
//! facing the sun) is given, or taken from the IES clear-sky formula
//! (IES Lighting Handbook, Reference volume, 1984; the CIE's 1994
//! guide): `E_n = E_xn exp(−c m)` with `E_xn` the extraterrestrial
//! illuminance [`EXTRATERRESTRIAL_LUX`], times `1 + 0.034 cos(2π (J − 2)
//! / 365)` on day of the year `J` when the date is known, the extinction
//! `c` = [`CLEAR_EXTINCTION`] for a clear sky, and the optical air mass
//! `m = 1 / sin α` at altitude `α`.
//!
//! **Disc.** The sun is a disc [`SUN_DISC_DEGREES`] across, of even
//! luminance; the visibility of a point is the share of
//! [`SUN_DISC_SAMPLES`] stratified directions over the disc that reach
//! past the scene ([`Sun::disc_directions`]).

use super::daylight::{HorizonFrame, SunPosition};
use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// The sun's angular diameter, degrees (its mean as seen from the earth).
pub const SUN_DISC_DEGREES: f64 = 0.53;

/// Cells along each side of the square mapped onto the sun's disc: the
/// visibility of a point asks `SUN_DISC_GRID²` directions, one per cell of
/// equal area (Shirley and Chiu's concentric map).
pub const SUN_DISC_GRID: usize = 8;

/// Directions over the sun's disc each point asks, `SUN_DISC_GRID²`.
pub const SUN_DISC_SAMPLES: usize = SUN_DISC_GRID * SUN_DISC_GRID;

/// The extraterrestrial direct normal illuminance at the mean earth–sun
/// distance, lux (the IES figure).
pub const EXTRATERRESTRIAL_LUX: f64 = 127_500.0;

/// The atmospheric extinction coefficient of a clear sky in the IES
/// formula.
pub const CLEAR_EXTINCTION: f64 = 0.21;

/// The most `E_n` the program takes, lux: well above the
/// extraterrestrial figure, so any real sun fits.
pub const MAX_SUN_LUX: f64 = 1e6;

/// A local date and clock time, and the zone it is told in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunTime {
    /// The year (Gregorian calendar).
    pub year: i32,
    /// The month, 1 to 12.
    pub month: u32,
    /// The day of the month, 1 to its length.
    pub day: u32,
    /// The local standard time, hours after midnight, `0..24`.
    pub hours: f64,
    /// The zone: local standard time less UTC, hours (`+1` for central
    /// Europe, `−5` for New York).
    pub zone: f64,
}

impl SunTime {
    /// The day of the year, 1 to 366.
    pub fn day_of_year(&self) -> u32 {
        const BEFORE: [u32; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];
        let leap = is_leap(self.year) && self.month > 2;
        BEFORE[(self.month.clamp(1, 12) - 1) as usize] + self.day + u32::from(leap)
    }

    /// The Julian day of the moment (UTC), by Meeus's chapter 7.
    pub fn julian_day(&self) -> f64 {
        let (mut y, mut m) = (f64::from(self.year), f64::from(self.month));
        if m <= 2.0 {
            y -= 1.0;
            m += 12.0;
        }
        let a = (y / 100.0).floor();
        let b = 2.0 - a + (a / 4.0).floor();
        let day = f64::from(self.day) + (self.hours - self.zone) / 24.0;
        (365.25 * (y + 4716.0)).floor() + (30.6001 * (m + 1.0)).floor() + day + b - 1524.5
    }
}

/// Whether `year` is a leap year of the Gregorian calendar.
pub fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

/// The days of `month` (1 to 12) in `year`; 0 for another month.
pub fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if is_leap(year) => 29,
        2 => 28,
        _ => 0,
    }
}

/// The sun's apparent position at `time` seen from `latitude` and
/// `longitude` (degrees, north and east positive), by NOAA's solar
/// calculator (see the module docs). The altitude is refracted and may
/// be negative (below the horizon).
pub fn solar_position(time: &SunTime, latitude: f64, longitude: f64) -> SunPosition {
    let century = (time.julian_day() - 2_451_545.0) / 36_525.0;
    let t = century;
    let mean_longitude = (280.46646 + t * (36000.76983 + t * 0.0003032)).rem_euclid(360.0);
    let mean_anomaly = 357.52911 + t * (35999.05029 - 0.0001537 * t);
    let eccentricity = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);
    let m = mean_anomaly.to_radians();
    let centre = m.sin() * (1.914602 - t * (0.004817 + 0.000014 * t))
        + (2.0 * m).sin() * (0.019993 - 0.000101 * t)
        + (3.0 * m).sin() * 0.000289;
    let true_longitude = mean_longitude + centre;
    let omega = (125.04 - 1934.136 * t).to_radians();
    let apparent_longitude = (true_longitude - 0.00569 - 0.00478 * omega.sin()).to_radians();
    let mean_obliquity =
        23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
    let obliquity = (mean_obliquity + 0.00256 * omega.cos()).to_radians();
    let declination = (obliquity.sin() * apparent_longitude.sin()).asin();
    let y = (obliquity / 2.0).tan().powi(2);
    let l0 = mean_longitude.to_radians();
    let e = eccentricity;
    // Minutes of time.
    let equation_of_time = 4.0
        * (y * (2.0 * l0).sin() - 2.0 * e * m.sin() + 4.0 * e * y * m.sin() * (2.0 * l0).cos()
            - 0.5 * y * y * (4.0 * l0).sin()
            - 1.25 * e * e * (2.0 * m).sin())
        .to_degrees();
    let true_solar_minutes = (time.hours * 60.0 + equation_of_time + 4.0 * longitude
        - 60.0 * time.zone)
        .rem_euclid(1440.0);
    let hour_angle = (true_solar_minutes / 4.0 - 180.0).to_radians();
    let phi = latitude.to_radians();
    let sin_altitude =
        phi.sin() * declination.sin() + phi.cos() * declination.cos() * hour_angle.cos();
    let altitude = sin_altitude.clamp(-1.0, 1.0).asin();
    // Meeus's azimuth from the south, turned to run from the north.
    let from_south = hour_angle
        .sin()
        .atan2(hour_angle.cos() * phi.sin() - declination.tan() * phi.cos());
    let azimuth = (from_south + PI).rem_euclid(2.0 * PI);
    let refracted = altitude + refraction(altitude.to_degrees()).to_radians();
    SunPosition {
        azimuth,
        altitude: refracted.min(FRAC_PI_2),
    }
}

/// NOAA's standard atmospheric refraction at true altitude `h` degrees,
/// degrees to add.
fn refraction(h: f64) -> f64 {
    let arcseconds = if h > 85.0 {
        0.0
    } else if h > 5.0 {
        let t = h.to_radians().tan();
        58.1 / t - 0.07 / t.powi(3) + 0.000086 / t.powi(5)
    } else if h > -0.575 {
        1735.0 + h * (-518.2 + h * (103.4 + h * (-12.79 + h * 0.711)))
    } else {
        -20.772 / h.to_radians().tan()
    };
    arcseconds / 3600.0
}

/// The IES clear-sky direct normal illuminance for the sun at `altitude`
/// radians, lux (see the module docs); on `day` of the year when known.
/// 0 at or below the horizon.
pub fn clear_sky_normal_illuminance(altitude: f64, day: Option<u32>) -> f64 {
    if altitude <= 0.0 {
        return 0.0;
    }
    let distance = day.map_or(1.0, |j| {
        1.0 + 0.034 * (2.0 * PI * (f64::from(j) - 2.0) / 365.0).cos()
    });
    let air_mass = 1.0 / altitude.sin();
    EXTRATERRESTRIAL_LUX * distance * (-CLEAR_EXTINCTION * air_mass).exp()
}

/// The sun as the scene holds it: where it is and how bright.
///
/// Invariants: `direction` is a unit vector in scene coordinates, above
/// the model's horizon; `normal_illuminance` is finite and `> 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Where the sun is in the model's sky (altitude `>= 0`).
    pub position: SunPosition,
    /// Towards the sun's centre, scene coordinates, unit.
    pub direction: Vec3,
    /// The direct normal illuminance `E_n`, in the scene's radiosity
    /// units (lux under `--units`).
    pub normal_illuminance: f64,
}

impl Sun {
    /// The sun at `position` in the frame `frame`, `normal_illuminance`
    /// lux on a plane facing it; `None` when it is below the horizon or
    /// gives no light.
    pub fn new(
        position: SunPosition,
        normal_illuminance: f64,
        frame: &HorizonFrame,
    ) -> Option<Sun> {
        if !(position.altitude >= 0.0 && normal_illuminance > 0.0 && normal_illuminance.is_finite())
        {
            return None;
        }
        let direction = frame.to_scene(position.direction()).normalize().as_vec3();
        Some(Sun {
            position,
            direction,
            normal_illuminance,
        })
    }

    /// The direct illuminance on an unobstructed horizontal plane,
    /// `E_n sin α`.
    pub fn horizontal_illuminance(&self) -> f64 {
        self.normal_illuminance * self.position.altitude.sin()
    }

    /// [`SUN_DISC_SAMPLES`] unit directions over the sun's disc, one in
    /// each cell of equal solid angle (an `SUN_DISC_GRID`-square grid's
    /// cell centres carried onto the disc by Shirley and Chiu's concentric
    /// map), in a fixed order.
    pub fn disc_directions(&self) -> Vec<Vec3> {
        let s = DVec3::from(self.direction);
        let (u, v) = s.any_orthonormal_pair();
        let radius = (SUN_DISC_DEGREES / 2.0).to_radians().tan();
        let n = SUN_DISC_GRID as f64;
        let mut out = Vec::with_capacity(SUN_DISC_SAMPLES);
        for i in 0..SUN_DISC_GRID {
            for j in 0..SUN_DISC_GRID {
                let a = 2.0 * (i as f64 + 0.5) / n - 1.0;
                let b = 2.0 * (j as f64 + 0.5) / n - 1.0;
                let (r, phi) = if a.abs() > b.abs() {
                    (a, PI / 4.0 * (b / a))
                } else {
                    (b, FRAC_PI_2 - PI / 4.0 * (a / b))
                };
                let (sp, cp) = phi.sin_cos();
                let d = s + (u * cp + v * sp) * (r * radius);
                out.push(d.normalize().as_vec3());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(year, month, day, hours, zone, latitude, longitude, altitude,
    /// azimuth)`, degrees.
    type Case = (i32, u32, u32, f64, f64, f64, f64, f64, f64);

    /// Published positions of the sun, each azimuth and altitude within
    /// 0.1°:
    ///
    /// - NOAA's Solar Calculator (gml.noaa.gov/grad/solcalc) at noon UTC
    ///   on 22 December 2012, longitude 0, latitudes 41° S, 3° S, 3° N and
    ///   41° N: elevations 72.44, 69.57, 63.57, 25.6, azimuths 359.09,
    ///   180.79, 180.62, 180.3.
    /// - NREL's Solar Position Algorithm report (Reda and Andreas, NREL
    ///   TP-560-34302, 2003, table A5.1): Golden, Colorado (39.742476° N,
    ///   105.1786° W), 17 October 2003, 12:30:30 at UTC−7: topocentric
    ///   zenith angle 50.11162°, azimuth 194.34024°.
    ///   The next day at the same time, by NREL's SPA (as pvlib's tests,
    ///   `test_solarposition.py`, print it): apparent zenith angle
    ///   50.478260°, azimuth 194.311132°.
    const PUBLISHED: [Case; 6] = [
        (2012, 12, 22, 12.0, 0.0, -41.0, 0.0, 72.44, 359.09),
        (2012, 12, 22, 12.0, 0.0, -3.0, 0.0, 69.57, 180.79),
        (2012, 12, 22, 12.0, 0.0, 3.0, 0.0, 63.57, 180.62),
        (2012, 12, 22, 12.0, 0.0, 41.0, 0.0, 25.6, 180.3),
        (
            2003,
            10,
            17,
            12.0 + 30.5 / 60.0,
            -7.0,
            39.742476,
            -105.1786,
            90.0 - 50.11162,
            194.34024,
        ),
        (
            2003,
            10,
            18,
            12.0 + 30.5 / 60.0,
            -7.0,
            39.742476,
            -105.1786,
            90.0 - 50.478260,
            194.311132,
        ),
    ];

    #[test]
    fn the_position_matches_published_tables_within_a_tenth_of_a_degree() {
        for (year, month, day, hours, zone, lat, lon, alt, az) in PUBLISHED {
            let time = SunTime {
                year,
                month,
                day,
                hours,
                zone,
            };
            let p = solar_position(&time, lat, lon);
            let (got_alt, got_az) = (p.altitude.to_degrees(), p.azimuth.to_degrees());
            let d_az = (got_az - az + 180.0).rem_euclid(360.0) - 180.0;
            println!(
                "{year}-{month}-{day} {lat},{lon}: alt {got_alt:.3} ({alt}), az {got_az:.3} ({az})"
            );
            assert!((got_alt - alt).abs() < 0.1, "altitude {got_alt} vs {alt}");
            assert!(d_az.abs() < 0.1, "azimuth {got_az} vs {az}");
        }
    }

    #[test]
    fn julian_days_and_days_of_the_year_are_meeus_s() {
        // Meeus, example 7.a: 1957 October 4.81 is JD 2436116.31.
        let t = SunTime {
            year: 1957,
            month: 10,
            day: 4,
            hours: 0.81 * 24.0,
            zone: 0.0,
        };
        assert!((t.julian_day() - 2_436_116.31).abs() < 1e-6);
        // J2000.0: 2000 January 1.5 is JD 2451545.0.
        let t = SunTime {
            year: 2000,
            month: 1,
            day: 1,
            hours: 13.0,
            zone: 1.0,
        };
        assert!((t.julian_day() - 2_451_545.0).abs() < 1e-9);
        let on = |year, month, day| {
            SunTime {
                year,
                month,
                day,
                hours: 0.0,
                zone: 0.0,
            }
            .day_of_year()
        };
        assert_eq!(
            (on(2026, 1, 1), on(2026, 6, 21), on(2024, 12, 31)),
            (1, 172, 366)
        );
        assert_eq!((days_in_month(2024, 2), days_in_month(1900, 2)), (29, 28));
    }

    #[test]
    fn the_clear_sky_formula_is_the_ies_one() {
        // Overhead: one air mass.
        let e = clear_sky_normal_illuminance(FRAC_PI_2, None);
        assert!((e - 127_500.0 * (-0.21f64).exp()).abs() < 1e-6, "{e}");
        // 30° high: two air masses; early January, 3.4 % closer.
        let e = clear_sky_normal_illuminance(30f64.to_radians(), Some(2));
        assert!(
            (e - 127_500.0 * 1.034 * (-0.42f64).exp()).abs() < 1e-6,
            "{e}"
        );
        assert_eq!(clear_sky_normal_illuminance(-0.1, None), 0.0);
    }

    #[test]
    fn the_disc_directions_fill_the_disc_evenly() {
        let frame = HorizonFrame::new(Vec3::Y, 0.0);
        let sun = Sun::new(SunPosition::from_degrees(200.0, 35.0), 1e5, &frame).unwrap();
        let dirs = sun.disc_directions();
        assert_eq!(dirs.len(), SUN_DISC_SAMPLES);
        let radius = (SUN_DISC_DEGREES / 2.0).to_radians();
        let mut mean = Vec3::ZERO;
        let mut inner = 0;
        for d in &dirs {
            let angle = f64::from(d.dot(sun.direction).min(1.0)).acos();
            assert!(angle < radius * 1.0001, "{angle} vs {radius}");
            inner += usize::from(angle < radius * 0.75);
            mean += *d;
        }
        // (3/4)² = 9/16 of the disc's area lies within 3/4 of its radius.
        assert_eq!(inner, SUN_DISC_SAMPLES * 9 / 16);
        let off = f64::from((mean / dirs.len() as f32).normalize().dot(sun.direction)).acos();
        assert!(off < radius * 0.01, "{off}");
        // Below the horizon there is no sun.
        assert!(Sun::new(SunPosition::from_degrees(200.0, -1.0), 1e5, &frame).is_none());
        assert!((sun.horizontal_illuminance() - 1e5 * 35f64.to_radians().sin()).abs() < 1e-6);
    }
}
