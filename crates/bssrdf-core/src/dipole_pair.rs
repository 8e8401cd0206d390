//! The closed-form source pair shared by the classical dipole (JMLH01) and the better dipole
//! (dE12): a real point source at depth `z_r` and a negative image at height `z_v` above the
//! surface, observed on the surface at distance `x` (all in optical units, see below).
//!
//! Profile (docs/physics.md#dipole, #beam-diffusion with a single depth):
//! `R₁(x) = (1/4π)·[ k_φ (e^{−σ d_r}/d_r − e^{−σ d_v}/d_v)
//!                 + k_E (z_r(1+σd_r)e^{−σd_r}/d_r³ + z_v(1+σd_v)e^{−σd_v}/d_v³) ]`,
//! with `d_{r,v} = √(x² + z_{r,v}²)`. The first bracket is the fluence term, the second the
//! normal flux of the pair (both image terms add because the image sits above the surface).
//!
//! Closed-form radial survival function, from `∫_x^∞ 2πr e^{−σd}/d dr = 2π e^{−σd(x)}/σ` and
//! `∫_x^∞ 2πr z(1+σd)e^{−σd}/d³ dr = 2π z e^{−σd(x)}/d(x)` [derived, docs/physics.md#dipole]:
//! `S(x) = ½[ k_φ (e^{−σd_r} − e^{−σd_v})/σ + k_E (z_r e^{−σd_r}/d_r + z_v e^{−σd_v}/d_v) ]`,
//! so the total is `S(0)` and radius sampling by inverting `S` is exact.
//!
//! Numerics: the fluence difference is written as `e^{−σd_r}[Δ/(d_r d_v) − expm1(−σΔ)/d_v]`
//! with `Δ = d_v − d_r = (z_v² − z_r²)/(d_v + d_r)`, both terms non-negative, so there is no
//! far-field cancellation (docs/physics.md#hazards); `(1 − e^{−σΔ})/σ` has the finite limit `Δ` at `σ = 0`.

use crate::profile::{TWO_PI, invert_survival, one_minus_exp_over};

/// Implements [`crate::RadialProfile`] for a model that is a [`DipolePair`] in optical units
/// (field `pair`) scaled to scene units by `scale` (σ of the optical unit): the scaling law
/// `R(r) = scale² R₁(scale·r)` of docs/physics.md#conventions, with exact sampling by inverting the survival
/// function.
macro_rules! radial_profile_from_pair {
    ($model:ty) => {
        impl $crate::profile::RadialProfile for $model {
            fn eval(&self, r: f64) -> f64 {
                let x = $crate::profile::optical(r, self.scale);
                self.scale * self.scale * self.pair.eval(x)
            }
            fn total(&self) -> f64 {
                self.pair.total()
            }
            fn sample_r(&self, u: f64) -> Option<f64> {
                let u = $crate::profile::clean_u(u)?;
                (self.pair.total() > 0.0).then(|| self.pair.quantile(u) / self.scale)
            }
            fn pdf_r(&self, r: f64) -> f64 {
                self.scale * self.pair.pdf($crate::profile::optical(r, self.scale))
            }
            fn radius_for_fraction(&self, f: f64) -> f64 {
                self.pair.quantile($crate::profile::clean_f(f)) / self.scale
            }
        }
    };
}
pub(crate) use radial_profile_from_pair;
use std::f64::consts::PI;

/// A real/image source pair in optical units (lengths in units of a model-chosen mean free
/// path). Invariants: `0 < z_r < z_v`, `σ ≥ 0`, `k_φ, k_E ≥ 0`, all finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DipolePair {
    pub z_r: f64,
    pub z_v: f64,
    pub sigma: f64,
    pub k_phi: f64,
    pub k_e: f64,
}

impl DipolePair {
    #[inline]
    fn parts(&self, x: f64) -> (f64, f64, f64) {
        let x2 = x * x;
        let dr = (x2 + self.z_r * self.z_r).sqrt();
        let dv = (x2 + self.z_v * self.z_v).sqrt();
        let delta = (self.z_v * self.z_v - self.z_r * self.z_r) / (dv + dr);
        (dr, dv, delta)
    }

    /// `R₁(x)` (optical units).
    #[inline]
    pub fn eval(&self, x: f64) -> f64 {
        let (dr, dv, delta) = self.parts(x);
        let s = self.sigma;
        let er = (-s * dr).exp();
        let ev = (-s * dv).exp();
        let mut v = 0.0;
        if self.k_phi > 0.0 {
            v += self.k_phi * er * (delta / (dr * dv) - (-s * delta).exp_m1() / dv);
        }
        v += self.k_e
            * (self.z_r * (1.0 + s * dr) * er / (dr * dr * dr)
                + self.z_v * (1.0 + s * dv) * ev / (dv * dv * dv));
        v / (4.0 * PI)
    }

    /// `S(x) = ∫_x^∞ 2πr R₁ dr`.
    #[inline]
    pub fn survival(&self, x: f64) -> f64 {
        let (dr, dv, delta) = self.parts(x);
        let s = self.sigma;
        let er = (-s * dr).exp();
        let ev = (-s * dv).exp();
        let phi = if self.k_phi > 0.0 {
            self.k_phi * er * delta * one_minus_exp_over(s * delta)
        } else {
            0.0
        };
        0.5 * (phi + self.k_e * (self.z_r * er / dr + self.z_v * ev / dv))
    }

    /// Total `S(0)`.
    pub fn total(&self) -> f64 {
        self.survival(0.0)
    }

    /// Density of `x` proportional to `2πx R₁(x)`.
    pub fn pdf(&self, x: f64) -> f64 {
        let t = self.total();
        if t > 0.0 {
            TWO_PI * x * self.eval(x) / t
        } else {
            0.0
        }
    }

    /// Radius holding the fraction `f` of the energy: solves `S(x) = (1 − f) S(0)`.
    pub fn quantile(&self, f: f64) -> f64 {
        let t = self.total();
        if t <= 0.0 {
            return 0.0;
        }
        let scale = if self.sigma > 0.0 {
            1.0 / self.sigma
        } else {
            self.z_v
        };
        invert_survival(
            |x| (self.survival(x), -TWO_PI * x * self.eval(x)),
            (1.0 - f) * t,
            scale.max(self.z_r),
        )
    }
}
