//! The per-channel coefficient pair a homogeneous profile is evaluated at, and the one valid
//! range shared by fields, estimators and profiles.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub};

use crate::error::{ParamError, SIGMA_MAX, check_sigma};
use crate::rgb::Rgb;

/// Absorption and scattering coefficients per colour channel, in 1/length.
///
/// The valid range is `[0, SIGMA_MAX]` (finite, `SIGMA_MAX = 1e12`) for every value: what a
/// [`crate::ProfileFamily`] accepts, and where `het-estimate`'s estimates are clamped
/// ([`Coefficients::clamp_to_range`]). Arithmetic is channel-wise, for blending and scaling
/// coefficients (`a.lerp(b, t)`, `0.5 * (a + b)`, `c * 2.0`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Coefficients {
    /// σa per channel.
    pub sigma_a: Rgb,
    /// σs per channel.
    pub sigma_s: Rgb,
}

impl Coefficients {
    /// All zero (vacuum).
    pub const ZERO: Coefficients = Coefficients::grey(0.0, 0.0);

    /// From σa and σs per channel.
    pub const fn new(sigma_a: Rgb, sigma_s: Rgb) -> Self {
        Self { sigma_a, sigma_s }
    }
    /// The same σa and σs in every channel.
    pub const fn grey(sigma_a: f64, sigma_s: f64) -> Self {
        Self {
            sigma_a: Rgb::splat(sigma_a),
            sigma_s: Rgb::splat(sigma_s),
        }
    }
    /// Extinction σt = σa + σs per channel.
    #[inline]
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }
    /// Channel-wise minimum.
    #[inline]
    pub fn min(self, o: Self) -> Self {
        Self {
            sigma_a: self.sigma_a.zip_map(o.sigma_a, f64::min),
            sigma_s: self.sigma_s.zip_map(o.sigma_s, f64::min),
        }
    }
    /// Channel-wise maximum.
    #[inline]
    pub fn max(self, o: Self) -> Self {
        Self {
            sigma_a: self.sigma_a.zip_map(o.sigma_a, f64::max),
            sigma_s: self.sigma_s.zip_map(o.sigma_s, f64::max),
        }
    }
    /// Linear interpolation `(1 − t)·self + t·o`, channel by channel.
    #[inline]
    pub fn lerp(self, o: Self, t: f64) -> Self {
        Self {
            sigma_a: self.sigma_a.lerp(o.sigma_a, t),
            sigma_s: self.sigma_s.lerp(o.sigma_s, t),
        }
    }
    /// Applies `f` to every value (both coefficients, every channel).
    #[inline]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Self {
            sigma_a: self.sigma_a.map(&f),
            sigma_s: self.sigma_s.map(&f),
        }
    }
    /// True when every value is finite and non-negative.
    #[inline]
    pub fn is_valid(&self) -> bool {
        self.sigma_a.is_finite()
            && self.sigma_s.is_finite()
            && self.sigma_a.min_component() >= 0.0
            && self.sigma_s.min_component() >= 0.0
    }
    /// The values clamped to the valid range `[0, SIGMA_MAX]`: NaN and negative values become
    /// 0, values above [`SIGMA_MAX`] (+∞ included) become `SIGMA_MAX`. This is what
    /// `het-estimate` applies to every estimate, so that an estimate is always a valid
    /// profile argument.
    #[inline]
    pub fn clamp_to_range(self) -> Self {
        self.map(|v| if v > 0.0 { v.min(SIGMA_MAX) } else { 0.0 })
    }
    /// `Ok(self)` when every value lies in `[0, SIGMA_MAX]`, else the error of the first that
    /// does not (named `sigma_a` or `sigma_s`).
    pub fn validate(self) -> Result<Self, ParamError> {
        for ch in 0..3 {
            check_sigma("sigma_a", self.sigma_a[ch])?;
            check_sigma("sigma_s", self.sigma_s[ch])?;
        }
        Ok(self)
    }
}

impl Add for Coefficients {
    type Output = Coefficients;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.sigma_a + o.sigma_a, self.sigma_s + o.sigma_s)
    }
}
impl AddAssign for Coefficients {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl Sub for Coefficients {
    type Output = Coefficients;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.sigma_a - o.sigma_a, self.sigma_s - o.sigma_s)
    }
}
impl Mul<f64> for Coefficients {
    type Output = Coefficients;
    #[inline]
    fn mul(self, s: f64) -> Self {
        Self::new(self.sigma_a * s, self.sigma_s * s)
    }
}
impl Mul<Coefficients> for f64 {
    type Output = Coefficients;
    #[inline]
    fn mul(self, c: Coefficients) -> Coefficients {
        c * self
    }
}
impl MulAssign<f64> for Coefficients {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}
impl Div<f64> for Coefficients {
    type Output = Coefficients;
    #[inline]
    fn div(self, s: f64) -> Self {
        Self::new(self.sigma_a / s, self.sigma_s / s)
    }
}
impl std::iter::Sum for Coefficients {
    fn sum<I: Iterator<Item = Coefficients>>(iter: I) -> Coefficients {
        iter.fold(Coefficients::ZERO, |a, b| a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_and_range() {
        let a = Coefficients::new(Rgb::new(0.1, 0.2, 0.3), Rgb::splat(1.0));
        let b = Coefficients::grey(0.3, 3.0);
        assert_eq!(0.5 * (a + b), (a + b) / 2.0);
        assert_eq!(a.lerp(b, 0.0), a);
        assert_eq!(a.lerp(b, 1.0), b);
        assert_eq!(a.lerp(b, 0.5).sigma_s, Rgb::splat(2.0));
        assert_eq!(b - b, Coefficients::ZERO);
        assert_eq!([a, b].into_iter().sum::<Coefficients>(), a + b);
        assert_eq!(a.sigma_t(), Rgb::new(1.1, 1.2, 1.3));
        let wild = Coefficients::new(
            Rgb::new(f64::INFINITY, f64::NAN, -1.0),
            Rgb::new(2e12, 5.0, 0.0),
        );
        let c = wild.clamp_to_range();
        assert_eq!(c.sigma_a, Rgb::new(SIGMA_MAX, 0.0, 0.0));
        assert_eq!(c.sigma_s, Rgb::new(SIGMA_MAX, 5.0, 0.0));
        assert_eq!(c.validate(), Ok(c));
        assert!(wild.validate().is_err());
        assert!(Coefficients::grey(0.0, 1e13).validate().is_err());
    }
}
