//! What one scene unit is in metres, for photometric results.
//!
//! Radiosity is a ratio of power to area, and form factors are
//! dimensionless: drawing the same room in millimetres or in metres gives
//! the same radiosity everywhere, so a diffuse emission `e` needs no
//! conversion. With a unit given, emission and radiosity are read as
//! luminous exitance in lm/m² (whatever the scene unit), luminance is
//! `radiosity / π` in cd/m² and irradiance is illuminance in lux. What does
//! depend on the unit is everything that mixes a length with light: a
//! luminous intensity in candela gives `E = I cosθ / d²` lux only with `d`
//! in metres, and a luminaire's lumens spread over its area in m². Those
//! conversions go through [`Units::metres`] and [`Units::square_metres`].

use std::fmt;

/// The length of one scene unit. glTF is in metres by its specification;
/// OBJ and `.sc` files have no unit, so photometric output needs one given.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Units {
    /// Metres.
    M,
    /// Centimetres (0.01 m).
    Cm,
    /// Millimetres (0.001 m).
    Mm,
    /// Inches (0.0254 m exactly).
    In,
    /// Feet (0.3048 m exactly).
    Ft,
}

impl Units {
    /// Metres per scene unit (exact by definition for every unit).
    pub fn metres_per_unit(self) -> f64 {
        match self {
            Units::M => 1.0,
            Units::Cm => 0.01,
            Units::Mm => 0.001,
            Units::In => 0.0254,
            Units::Ft => 0.3048,
        }
    }

    /// A length of `scene_units` scene units in metres.
    pub fn metres(self, scene_units: f64) -> f64 {
        scene_units * self.metres_per_unit()
    }

    /// An area of `square_units` square scene units in square metres.
    pub fn square_metres(self, square_units: f64) -> f64 {
        let m = self.metres_per_unit();
        square_units * m * m
    }

    /// The unit's name as the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            Units::M => "m",
            Units::Cm => "cm",
            Units::Mm => "mm",
            Units::In => "in",
            Units::Ft => "ft",
        }
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The photometric names of the quantities a result is given in: with a
/// unit, lux and cd/m²; without, the scene's own radiosity units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Photometric {
    /// The scene's unit, when known.
    pub units: Option<Units>,
}

impl Photometric {
    /// The unit of an illuminance (irradiance): `lx`, or the scene's
    /// radiosity units.
    pub fn illuminance_unit(self) -> &'static str {
        if self.units.is_some() {
            "lx"
        } else {
            "radiosity units"
        }
    }

    /// The unit of a luminance (`radiosity / π`): `cd/m²`, or the scene's
    /// radiance units.
    pub fn luminance_unit(self) -> &'static str {
        if self.units.is_some() {
            "cd/m²"
        } else {
            "radiance units"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_convert_lengths_and_areas_by_their_definitions() {
        assert_eq!(Units::Mm.metres(1500.0), 1.5);
        assert!((Units::Ft.metres(10.0) - 3.048).abs() < 1e-12);
        assert!((Units::In.square_metres(144.0) - 0.092_903_04).abs() < 1e-12);
        assert!((Units::Cm.square_metres(10_000.0) - 1.0).abs() < 1e-12);
        for u in [Units::M, Units::Cm, Units::Mm, Units::In, Units::Ft] {
            let m = u.metres_per_unit();
            assert!((u.square_metres(1.0) - m * m).abs() < 1e-15);
            assert_eq!(u.to_string(), u.name());
        }
    }
}
