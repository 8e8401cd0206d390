//! Henyey–Greenstein phase function (Henyey & Greenstein 1941; pbrt-v4 §11.3.1).
//!
//! Convention: `cos_theta = ω_in · ω_out` with both vectors pointing along the direction of
//! light propagation, so `g > 0` is forward scattering. The phase function is normalised over
//! the sphere: `∫ p dω = 1` (units 1/sr).

use std::f64::consts::PI;

/// Below this |g| the isotropic formulas are used (the HG sampler's inversion cancels).
const ISOTROPIC_EPS: f64 = 1e-3;

/// HG phase function value `p(cos θ; g)` in 1/sr. Requires `|g| < 1`.
pub fn phase(cos_theta: f64, g: f64) -> f64 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denom * denom.max(f64::MIN_POSITIVE).sqrt())
}

/// Samples `cos θ` (propagation convention) from HG with `u ∈ [0, 1)`; exact inversion of the
/// CDF, with the isotropic branch for |g| < 1e-3.
pub fn sample_cos_theta(g: f64, u: f64) -> f64 {
    let c = if g.abs() < ISOTROPIC_EPS {
        1.0 - 2.0 * u
    } else {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
        (1.0 + g * g - s * s) / (2.0 * g)
    };
    c.clamp(-1.0, 1.0)
}
