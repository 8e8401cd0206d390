//! What a field's bounds tell an estimator before it looks anything up, and the sanitising
//! of looked-up values.

use bssrdf_core::Rgb;

use crate::field::{Coefficients, FieldBounds};

/// Values above this are clamped when looked up and when finished: the profiles' limit
/// ([`bssrdf_core::SIGMA_MAX`], 1e12 per unit length), so that a field and the profile that
/// reads its estimate share one valid range (a field returning 1e15 gives an estimate of 1e12,
/// which every profile accepts). Sums of up to 2³² such samples cannot overflow.
pub(crate) const MAX_COEFFICIENT: f64 = bssrdf_core::SIGMA_MAX;

/// Clamps to `[0, MAX_COEFFICIENT]`, mapping NaN to 0 (unlike `f64::clamp`).
#[inline]
pub(crate) fn clamp_coefficient(v: f64) -> f64 {
    if v > 0.0 { v.min(MAX_COEFFICIENT) } else { 0.0 }
}

/// A field value made safe to average: NaN and negative values become 0, huge values are
/// clamped. Invalid values are a caller bug, caught by a debug assertion.
#[inline]
pub(crate) fn sanitise(c: Coefficients) -> Coefficients {
    debug_assert!(
        c.is_valid(),
        "CoefficientField returned invalid coefficients {c:?} (must be finite and >= 0)"
    );
    Coefficients {
        sigma_a: c.sigma_a.map(clamp_coefficient),
        sigma_s: c.sigma_s.map(clamp_coefficient),
    }
}

/// 1 where the (coefficient, channel) value is known to be constant, 0 elsewhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Mask {
    pub sigma_a: Rgb,
    pub sigma_s: Rgb,
}

impl Mask {
    pub const NONE: Mask = Mask {
        sigma_a: Rgb::ZERO,
        sigma_s: Rgb::ZERO,
    };

    #[inline]
    fn count(&self) -> u8 {
        (self.sigma_a.0.iter().sum::<f64>() + self.sigma_s.0.iter().sum::<f64>()) as u8
    }
}

/// The field's bounds, digested once per estimate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Known {
    bounds: Option<FieldBounds>,
    constant: Mask,
}

impl Known {
    #[inline]
    pub fn new(bounds: Option<FieldBounds>) -> Self {
        let constant = match bounds {
            None => Mask::NONE,
            Some(b) => {
                let eq = |lo: Rgb, hi: Rgb| lo.zip_map(hi, |l, h| if l == h { 1.0 } else { 0.0 });
                Mask {
                    sigma_a: eq(b.min.sigma_a, b.max.sigma_a),
                    sigma_s: eq(b.min.sigma_s, b.max.sigma_s),
                }
            }
        };
        Self { bounds, constant }
    }

    /// The whole field is constant: its value, if so.
    #[inline]
    pub fn constant_field(&self) -> Option<Coefficients> {
        let b = self.bounds?;
        b.is_constant().then(|| sanitise_bound(b.min))
    }

    /// How many (coefficient, channel) values are constant.
    #[inline]
    pub fn constant_components(&self) -> u8 {
        self.constant.count()
    }

    /// 1 where a (coefficient, channel) value must be averaged (it is not known constant):
    /// `(σa channels, σs channels)`.
    #[inline]
    pub fn varying(&self) -> (Rgb, Rgb) {
        (
            Rgb::ONE - self.constant.sigma_a,
            Rgb::ONE - self.constant.sigma_s,
        )
    }

    /// Channel `c` needs no averaging at all (both its σa and σs are constant).
    #[inline]
    pub fn channel_constant(&self, c: usize) -> bool {
        self.constant.sigma_a[c] == 1.0 && self.constant.sigma_s[c] == 1.0
    }

    /// Replaces constant components by their value, clamps to the bounds and sanitises: the
    /// final step of every estimator. The result is finite and ≥ 0.
    #[inline]
    pub fn finish(&self, c: Coefficients) -> Coefficients {
        let mut c = Coefficients {
            sigma_a: c.sigma_a.map(clamp_coefficient),
            sigma_s: c.sigma_s.map(clamp_coefficient),
        };
        if let Some(b) = self.bounds {
            // An average of values within the bounds lies within them; clamping only removes
            // rounding, and replaces constant components exactly. A bound that is NaN or
            // infinite (unbounded field) leaves the value alone.
            let clamp = |v: f64, lo: f64, hi: f64| {
                let v = if lo.is_finite() && v < lo { lo } else { v };
                if hi.is_finite() && v > hi { hi } else { v }
            };
            for k in 0..3 {
                c.sigma_a[k] = clamp(c.sigma_a[k], b.min.sigma_a[k], b.max.sigma_a[k]);
                c.sigma_s[k] = clamp(c.sigma_s[k], b.min.sigma_s[k], b.max.sigma_s[k]);
            }
            c = Coefficients {
                sigma_a: c.sigma_a.map(clamp_coefficient),
                sigma_s: c.sigma_s.map(clamp_coefficient),
            };
        }
        c
    }
}

/// Sanitises a bound used as a value (bounds come from the caller too).
#[inline]
fn sanitise_bound(c: Coefficients) -> Coefficients {
    let fix = |v: f64| {
        if v.is_finite() {
            v.clamp(0.0, MAX_COEFFICIENT)
        } else if v == f64::INFINITY {
            MAX_COEFFICIENT
        } else {
            0.0
        }
    };
    Coefficients {
        sigma_a: c.sigma_a.map(fix),
        sigma_s: c.sigma_s.map(fix),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finish_replaces_constants_and_clamps() {
        let lo = Coefficients {
            sigma_a: Rgb::new(0.1, 0.2, 0.3),
            sigma_s: Rgb::splat(1.0),
        };
        let hi = Coefficients {
            sigma_a: Rgb::new(0.1, 0.5, f64::INFINITY),
            sigma_s: Rgb::splat(1.0),
        };
        let k = Known::new(Some(FieldBounds { min: lo, max: hi }));
        assert_eq!(k.constant_components(), 4);
        assert!(k.channel_constant(0) && !k.channel_constant(1));
        assert!(k.constant_field().is_none());
        let c = k.finish(Coefficients {
            sigma_a: Rgb::new(0.1000001, 0.6, 7.0),
            sigma_s: Rgb::splat(0.999999),
        });
        assert_eq!(c.sigma_a, Rgb::new(0.1, 0.5, 7.0));
        assert_eq!(c.sigma_s, Rgb::splat(1.0));
        let nan = k.finish(Coefficients {
            sigma_a: Rgb::splat(f64::NAN),
            sigma_s: Rgb::splat(-1.0),
        });
        assert!(nan.is_valid());
    }
}
