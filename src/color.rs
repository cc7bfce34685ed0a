//! Linear RGB triples for radiosity, emission and reflectance.
//!
//! Energy is summed in `f64` (see the design notes): a radiosity solve adds
//! millions of small contributions per vertex and `f32` would lose the tail
//! of the series.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub};

/// A linear RGB triple. What the channels mean (radiosity in the scene's
/// emission units, or a dimensionless reflectance) is said by whoever holds it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rgb {
    /// Red channel.
    pub r: f64,
    /// Green channel.
    pub g: f64,
    /// Blue channel.
    pub b: f64,
}

impl Rgb {
    /// Black: all channels zero.
    pub const BLACK: Rgb = Rgb::new(0.0, 0.0, 0.0);
    /// White: all channels one.
    pub const WHITE: Rgb = Rgb::new(1.0, 1.0, 1.0);

    /// A triple from its three channels.
    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Rgb { r, g, b }
    }

    /// The same value in all three channels.
    pub const fn splat(v: f64) -> Self {
        Rgb { r: v, g: v, b: v }
    }

    /// Relative luminance with the Rec. 709 / sRGB primaries (Y of CIE XYZ).
    pub fn luminance(self) -> f64 {
        0.2126 * self.r + 0.7152 * self.g + 0.0722 * self.b
    }

    /// Mean of the three channels: the scalar "amount" used to compare and
    /// add up powers without favouring any colour.
    pub fn mean(self) -> f64 {
        (self.r + self.g + self.b) / 3.0
    }

    /// Largest channel.
    pub fn max_channel(self) -> f64 {
        self.r.max(self.g).max(self.b)
    }

    /// Smallest channel.
    pub fn min_channel(self) -> f64 {
        self.r.min(self.g).min(self.b)
    }

    /// True when every channel is exactly zero.
    pub fn is_black(self) -> bool {
        self.r == 0.0 && self.g == 0.0 && self.b == 0.0
    }

    /// True when every channel is finite.
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    /// The channel-wise maximum of `self` and `o`.
    pub fn max(self, o: Rgb) -> Rgb {
        Rgb::new(self.r.max(o.r), self.g.max(o.g), self.b.max(o.b))
    }

    /// The channel-wise minimum of `self` and `o`.
    pub fn min(self, o: Rgb) -> Rgb {
        Rgb::new(self.r.min(o.r), self.g.min(o.g), self.b.min(o.b))
    }

    /// The channels as an array `[r, g, b]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.r, self.g, self.b]
    }

    /// The channels narrowed to `f32`, for pictures and exports.
    pub fn to_f32(self) -> [f32; 3] {
        [self.r as f32, self.g as f32, self.b as f32]
    }
}

impl Add for Rgb {
    type Output = Rgb;
    fn add(self, o: Rgb) -> Rgb {
        Rgb::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}

impl AddAssign for Rgb {
    fn add_assign(&mut self, o: Rgb) {
        self.r += o.r;
        self.g += o.g;
        self.b += o.b;
    }
}

impl Neg for Rgb {
    type Output = Rgb;
    fn neg(self) -> Rgb {
        Rgb::new(-self.r, -self.g, -self.b)
    }
}

impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}

/// Channel-wise product (reflectance times radiosity).
impl Mul for Rgb {
    type Output = Rgb;
    fn mul(self, o: Rgb) -> Rgb {
        Rgb::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}

impl Mul<f64> for Rgb {
    type Output = Rgb;
    fn mul(self, k: f64) -> Rgb {
        Rgb::new(self.r * k, self.g * k, self.b * k)
    }
}

impl MulAssign<f64> for Rgb {
    fn mul_assign(&mut self, k: f64) {
        self.r *= k;
        self.g *= k;
        self.b *= k;
    }
}

impl Div<f64> for Rgb {
    type Output = Rgb;
    fn div(self, k: f64) -> Rgb {
        Rgb::new(self.r / k, self.g / k, self.b / k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luminance_of_white_is_one() {
        assert!((Rgb::WHITE.luminance() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn arithmetic_is_channel_wise() {
        let a = Rgb::new(1.0, 2.0, 3.0);
        let b = Rgb::new(0.5, 0.25, 2.0);
        assert_eq!(a * b, Rgb::new(0.5, 0.5, 6.0));
        assert_eq!(a + b, Rgb::new(1.5, 2.25, 5.0));
        assert_eq!(a - b, Rgb::new(0.5, 1.75, 1.0));
        assert_eq!(a * 2.0, Rgb::new(2.0, 4.0, 6.0));
        assert_eq!(a / 2.0, Rgb::new(0.5, 1.0, 1.5));
        assert_eq!(a.mean(), 2.0);
        assert_eq!(a.max_channel(), 3.0);
        assert_eq!(a.min_channel(), 1.0);
    }
}
