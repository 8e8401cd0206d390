//! Procedural two-valued and linear patterns over a plane, shared by the analytic test plane of
//! this crate and the tracer's procedural textures ("same definitions, same code").
//!
//! Coordinates `(x, y)` are in scene units in the pattern's own plane. Definitions:
//! * stripe: `u = x cos θ + y sin θ`, `k = floor(u / w + 1/2)`, value = `values[k mod 2]`
//!   (with `k mod 2 ∈ {0, 1}` for negative `k` too), so the band containing the origin
//!   (`|u| < w/2`) has `values[0]`;
//! * check: `k = floor(x / w + 1/2) + floor(y / w + 1/2)`, value = `values[k mod 2]`, so the
//!   cell containing the origin has `values[0]`;
//! * ramp: `v0 + gx·x + gy·y`, clamped below at 0 by users that need non-negative
//!   coefficients.

/// A pattern that selects one of two values at each point of its plane.
pub trait BinaryPattern {
    /// 0 or 1: which of the two values applies at `(x, y)`.
    fn select(&self, x: f64, y: f64) -> usize;
}

/// ⌊v⌋ as an `i64` for |v| < 2⁵², `None` beyond (where every `f64` is already an integer)
/// and for NaN.
///
/// Through `i64` rather than `floor` and `rem_euclid`, which are library calls on the baseline
/// x86-64 target and cost as much as the rest of a pattern lookup.
#[inline]
fn floor_i64(v: f64) -> Option<i64> {
    const EXACT: f64 = 4_503_599_627_370_496.0; // 2^52
    (v.abs() < EXACT).then(|| {
        let i = v as i64;
        if (i as f64) > v { i - 1 } else { i }
    })
}

/// ⌊v⌋, equal to `v.floor()` for every `v`, without the library call below 2⁵²
/// ([`floor_i64`]).
#[inline]
pub(crate) fn fast_floor(v: f64) -> f64 {
    floor_i64(v).map_or_else(|| v.floor(), |i| i as f64)
}

/// Whether the integer-valued `k` is odd, without `rem_euclid` (a library call): `k − 2⌊k/2⌋`.
#[inline]
pub(crate) fn is_odd(k: f64) -> bool {
    k - 2.0 * fast_floor(0.5 * k) == 1.0
}

/// The first odd integer at or after the integer-valued `k`.
#[inline]
pub(crate) fn first_odd(k: f64) -> f64 {
    if is_odd(k) { k } else { k + 1.0 }
}

/// Parity (0 or 1) of ⌊x⌋ + ⌊y⌋, for the values of a pattern's cell coordinates: through
/// [`floor_i64`]; coordinates beyond 2⁵² (integers, and beyond 2⁵³ even ones) and NaN take the
/// slow exact path.
#[inline]
fn parity_of_floors(x: f64, y: f64) -> usize {
    match (floor_i64(x), floor_i64(y)) {
        (Some(i), Some(j)) => ((i + j) & 1) as usize,
        _ => ((x.floor() + y.floor()).rem_euclid(2.0) as usize) & 1,
    }
}

/// Parallel bands of width `width`, running along the direction `angle + 90°`.
///
/// Built by [`Stripe::new`], which keeps the direction (cos θ, sin θ) beside the angle, so
/// that a lookup costs two multiplications rather than a `sin_cos`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stripe {
    width: f64,
    angle: f64,
    cos: f64,
    sin: f64,
}

impl Stripe {
    /// Bands of width `width` (scene units, > 0) varying along the direction at `angle`
    /// radians, (cos θ, sin θ).
    pub fn new(width: f64, angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self {
            width,
            angle,
            cos,
            sin,
        }
    }

    /// Band width w (scene units).
    #[inline]
    pub fn width(&self) -> f64 {
        self.width
    }

    /// θ in radians: bands vary along the direction (cos θ, sin θ).
    #[inline]
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// The unit direction (cos θ, sin θ) along which the bands vary.
    #[inline]
    pub fn direction(&self) -> (f64, f64) {
        (self.cos, self.sin)
    }

    /// The stripe coordinate `u = x cos θ + y sin θ`.
    #[inline]
    pub fn u(&self, x: f64, y: f64) -> f64 {
        x * self.cos + y * self.sin
    }
}

impl BinaryPattern for Stripe {
    #[inline]
    fn select(&self, x: f64, y: f64) -> usize {
        parity_of_floors(self.u(x, y) / self.width + 0.5, 0.0)
    }
}

/// A checkerboard of square cells of side `width`, aligned with the axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Check {
    /// Cell side w (scene units, > 0).
    pub width: f64,
}

impl BinaryPattern for Check {
    #[inline]
    fn select(&self, x: f64, y: f64) -> usize {
        parity_of_floors(x / self.width + 0.5, y / self.width + 0.5)
    }
}

/// A linear function `v0 + gx·x + gy·y`: its average over any centrally symmetric region equals
/// its value at the region's centre, which makes exact tests of averaging estimators possible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ramp {
    /// Value at the origin.
    pub v0: f64,
    /// Gradient (∂v/∂x, ∂v/∂y).
    pub gradient: [f64; 2],
}

impl Ramp {
    /// The ramp's value at `(x, y)` (may be negative away from the origin).
    #[inline]
    pub fn value(&self, x: f64, y: f64) -> f64 {
        self.v0 + self.gradient[0] * x + self.gradient[1] * y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_floor_and_parity_are_the_library_ones() {
        for v in [
            -3.5,
            -3.0,
            -2.999_999,
            -0.5,
            -0.0,
            0.0,
            1e-300,
            0.5,
            1.0,
            2.5,
            7.0,
            1e15 + 0.5,
            4_503_599_627_370_495.5,
            4.6e15,
            1e300,
            -1e300,
            f64::INFINITY,
        ] {
            assert_eq!(fast_floor(v), v.floor(), "{v}");
        }
        assert!(fast_floor(f64::NAN).is_nan());
        for k in -9i64..=9 {
            assert_eq!(is_odd(k as f64), k.rem_euclid(2) == 1, "{k}");
            let f = first_odd(k as f64);
            assert!(is_odd(f) && f - k as f64 <= 1.0 && f >= k as f64, "{k}");
        }
    }

    #[test]
    fn origin_cell_has_value_zero_and_parity_alternates() {
        let s = Stripe::new(4.0, std::f64::consts::FRAC_PI_4);
        assert_eq!(s.select(0.0, 0.0), 0);
        assert_eq!(s.select(3.0, 0.0), 1); // u = 2.12 > 2
        assert_eq!(s.select(-3.0, 0.0), 1); // negative k: k = -1 -> parity 1
        assert_eq!(s.select(-6.0, 0.0), 1); // u = -4.24: k = floor(-0.56) = -1
        assert_eq!(s.select(-9.0, 0.0), 0); // u = -6.36: k = floor(-1.09) = -2
        // Bands vary along (cos θ, sin θ) and are constant across it.
        let (w, theta) = (4.0, 0.3f64);
        let s = Stripe::new(w, theta);
        let (along, across) = ((theta.cos(), theta.sin()), (-theta.sin(), theta.cos()));
        assert_eq!(s.direction(), along);
        assert_eq!((s.width(), s.angle()), (w, theta));
        assert_eq!(s.select(3.0 * along.0, 3.0 * along.1), 1); // u = 3
        assert_eq!(s.select(100.0 * across.0, 100.0 * across.1), 0); // u = 0
        assert!((s.u(2.0, -5.0) - (2.0 * theta.cos() - 5.0 * theta.sin())).abs() < 1e-15);
        let c = Check { width: 4.0 };
        assert_eq!(c.select(0.0, 0.0), 0);
        assert_eq!(c.select(2.5, 0.0), 1);
        assert_eq!(c.select(2.5, 2.5), 0);
        assert_eq!(c.select(-2.5, 0.0), 1);
        assert_eq!(c.select(-2.5, -2.5), 0);
    }

    #[test]
    fn fast_parity_equals_floor_parity() {
        // Against the definition through `floor` and `rem_euclid`: exact integers, values a
        // hair either side of them, negatives, large magnitudes, the 2^52 boundary and NaN.
        let reference = |x: f64, y: f64| ((x.floor() + y.floor()).rem_euclid(2.0) as usize) & 1;
        let mut values = vec![0.0, -0.0, 0.5, -0.5, 1e300, -1e300, f64::NAN];
        for k in [
            -3i64,
            -2,
            -1,
            1,
            2,
            3,
            1 << 40,
            -(1 << 40),
            (1 << 52) - 1,
            1 << 52,
        ] {
            let v = k as f64;
            values.extend([v, v.next_up(), v.next_down(), v + 0.25, v - 0.75]);
        }
        for &x in &values {
            for &y in &values {
                if x.is_nan() || y.is_nan() {
                    assert!(parity_of_floors(x, y) <= 1);
                    continue;
                }
                assert_eq!(parity_of_floors(x, y), reference(x, y), "x {x}, y {y}");
            }
        }
    }
}
