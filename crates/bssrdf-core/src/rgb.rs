//! A tiny RGB triple of `f64` used for per-channel coefficients and radiance.

use std::ops::{
    Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign,
};

/// Three `f64` values, one per colour channel (linear RGB).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rgb(pub [f64; 3]);

impl Rgb {
    /// All zero.
    pub const ZERO: Rgb = Rgb([0.0; 3]);
    /// All one.
    pub const ONE: Rgb = Rgb([1.0; 3]);

    /// The same value in every channel.
    #[inline]
    pub const fn splat(v: f64) -> Self {
        Rgb([v, v, v])
    }
    /// From three channels.
    #[inline]
    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Rgb([r, g, b])
    }
    /// Applies `f` to every channel.
    #[inline]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Rgb([f(self.0[0]), f(self.0[1]), f(self.0[2])])
    }
    /// Combines two triples channel by channel.
    #[inline]
    pub fn zip_map(self, o: Rgb, f: impl Fn(f64, f64) -> f64) -> Self {
        Rgb([
            f(self.0[0], o.0[0]),
            f(self.0[1], o.0[1]),
            f(self.0[2], o.0[2]),
        ])
    }
    /// Arithmetic mean of the channels.
    #[inline]
    pub fn mean(self) -> f64 {
        (self.0[0] + self.0[1] + self.0[2]) / 3.0
    }
    /// Largest channel.
    #[inline]
    pub fn max_component(self) -> f64 {
        self.0[0].max(self.0[1]).max(self.0[2])
    }
    /// Smallest channel.
    #[inline]
    pub fn min_component(self) -> f64 {
        self.0[0].min(self.0[1]).min(self.0[2])
    }
    /// True when every channel is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }
    /// True when every channel is exactly zero.
    #[inline]
    pub fn is_zero(self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }
    /// Linear interpolation `(1 − t)·self + t·o`, channel by channel (`t = 0` gives `self`,
    /// `t = 1` gives `o` exactly).
    #[inline]
    pub fn lerp(self, o: Rgb, t: f64) -> Self {
        self.zip_map(o, |a, b| (1.0 - t) * a + t * b)
    }
    /// Rec. 709 luminance of a linear RGB value.
    #[inline]
    pub fn luminance(self) -> f64 {
        0.2126 * self.0[0] + 0.7152 * self.0[1] + 0.0722 * self.0[2]
    }
}

impl Index<usize> for Rgb {
    type Output = f64;
    #[inline]
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}
impl IndexMut<usize> for Rgb {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.0[i]
    }
}
impl Add for Rgb {
    type Output = Rgb;
    #[inline]
    fn add(self, o: Rgb) -> Rgb {
        self.zip_map(o, |a, b| a + b)
    }
}
impl AddAssign for Rgb {
    #[inline]
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}
impl Sub for Rgb {
    type Output = Rgb;
    #[inline]
    fn sub(self, o: Rgb) -> Rgb {
        self.zip_map(o, |a, b| a - b)
    }
}
impl Mul for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, o: Rgb) -> Rgb {
        self.zip_map(o, |a, b| a * b)
    }
}
impl Mul<f64> for Rgb {
    type Output = Rgb;
    #[inline]
    fn mul(self, s: f64) -> Rgb {
        self.map(|a| a * s)
    }
}
impl MulAssign<f64> for Rgb {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}
impl MulAssign for Rgb {
    #[inline]
    fn mul_assign(&mut self, o: Rgb) {
        *self = *self * o;
    }
}
impl Div<f64> for Rgb {
    type Output = Rgb;
    #[inline]
    fn div(self, s: f64) -> Rgb {
        self.map(|a| a / s)
    }
}
impl DivAssign<f64> for Rgb {
    #[inline]
    fn div_assign(&mut self, s: f64) {
        *self = *self / s;
    }
}
impl Div for Rgb {
    type Output = Rgb;
    #[inline]
    fn div(self, o: Rgb) -> Rgb {
        self.zip_map(o, |a, b| a / b)
    }
}
impl SubAssign for Rgb {
    #[inline]
    fn sub_assign(&mut self, o: Rgb) {
        *self = *self - o;
    }
}
impl Neg for Rgb {
    type Output = Rgb;
    #[inline]
    fn neg(self) -> Rgb {
        self.map(|a| -a)
    }
}
impl Mul<Rgb> for f64 {
    type Output = Rgb;
    #[inline]
    fn mul(self, o: Rgb) -> Rgb {
        o.map(|a| self * a)
    }
}
impl From<[f64; 3]> for Rgb {
    #[inline]
    fn from(v: [f64; 3]) -> Rgb {
        Rgb(v)
    }
}
impl From<Rgb> for [f64; 3] {
    #[inline]
    fn from(v: Rgb) -> [f64; 3] {
        v.0
    }
}
impl std::iter::Sum for Rgb {
    fn sum<I: Iterator<Item = Rgb>>(iter: I) -> Rgb {
        iter.fold(Rgb::ZERO, |a, b| a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_is_channel_wise() {
        let (a, b) = (Rgb::new(1.0, 2.0, 4.0), Rgb::new(0.5, 0.25, 2.0));
        assert_eq!(2.0 * a, a * 2.0);
        assert_eq!(2.0 * a, Rgb::new(2.0, 4.0, 8.0));
        assert_eq!(a / b, Rgb::new(2.0, 8.0, 2.0));
        assert_eq!(-a + a, Rgb::ZERO);
        assert_eq!(a.lerp(b, 0.0), a);
        assert_eq!(a.lerp(b, 1.0), b);
        assert_eq!(a.lerp(b, 0.5), Rgb::new(0.75, 1.125, 3.0));
        let mut c = a;
        c -= b;
        c /= 0.5;
        assert_eq!(c, Rgb::new(1.0, 3.5, 4.0));
        assert_eq!([a, b].into_iter().sum::<Rgb>(), a + b);
        assert_eq!(
            <[f64; 3]>::from(Rgb::from([1.0, 2.0, 3.0])),
            [1.0, 2.0, 3.0]
        );
    }
}
