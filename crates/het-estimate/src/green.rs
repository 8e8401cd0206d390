//! The diffusion Green's function of a half-space with an extrapolated boundary, in the
//! transport units the averaging kernel is tabulated in (docs/kernel.md#greens-function).
//!
//! Units: lengths in transport mean free paths ℓ = 1/σt' (σt' = σa + (1 − g)σs), so the
//! diffusion constant is D = 1/3 and the source sits at depth 1. The remaining parameters are
//! κ = σtr/σt' = √(3σa/σt') ∈ [0, √3] and the extrapolation height z_b = 2AD = 2A/3, with A the
//! classical dipole's boundary coefficient (1 + F_dr)/(1 − F_dr) (Jensen et al. 2001, the
//! dipole section; F_dr = 2C₁(η) by quadrature, `bssrdf_core::fresnel`).

use bssrdf_core::ParamError;
use bssrdf_core::fresnel::{DiffuseFresnel, FresnelMoments};

/// The classical dipole's boundary coefficient A = (1 + F_dr)/(1 − F_dr) for the relative
/// index `eta`, with the exact F_dr = 2C₁(η) (the dipole profile's default,
/// `DiffuseFresnel::Exact`). A = 1 at η = 1, about 23.9 at η = 3. Errors: η not finite or
/// outside [1, 3].
pub fn boundary_coefficient(eta: f64) -> Result<f64, ParamError> {
    if !eta.is_finite() {
        return Err(ParamError::NotFinite {
            name: "eta",
            value: eta,
        });
    }
    if !(1.0..=3.0).contains(&eta) {
        return Err(ParamError::OutOfRange {
            name: "eta",
            range: "[1, 3]",
            value: eta,
        });
    }
    let f_dr = DiffuseFresnel::Exact.f_dr(&FresnelMoments::new(eta)?);
    Ok((1.0 + f_dr) / (1.0 - f_dr))
}

/// `e^{κρ} · 4πD · G(s, x)` for a unit source s at depth 1 and a medium point x at depth
/// `zeta` ≥ 0 and horizontal distance `rho` ≥ 0 from it (transport units):
///
/// `G̃ = e^{−κ(r₁ − ρ)}/r₁ − e^{−κ(r₂ − ρ)}/r₂`, r₁ = |x − s|, r₂ = |x − s'|,
///
/// s' the image of s mirrored about the extrapolated boundary at height `zb` above the surface
/// (depth −(1 + 2z_b)). The factor e^{κρ} keeps the value representable far from the source
/// (the kernel multiplies it back in closed form); r − ρ is computed as Δz²/(r + ρ), without
/// cancellation. Positive for ζ ≥ 0 (r₂ > r₁); finite for κ = 0 (the power-law limit) and for
/// every (ρ, ζ) except the source itself (ρ = 0, ζ = 1).
#[inline]
pub fn scaled_green(rho: f64, zeta: f64, kappa: f64, zb: f64) -> f64 {
    let dz1 = zeta - 1.0;
    let dz2 = zeta + 1.0 + 2.0 * zb;
    let r1 = (rho * rho + dz1 * dz1).sqrt();
    let r2 = (rho * rho + dz2 * dz2).sqrt();
    let e1 = (-kappa * (dz1 * dz1 / (r1 + rho))).exp();
    let e2 = (-kappa * (dz2 * dz2 / (r2 + rho))).exp();
    e1 / r1 - e2 / r2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_coefficient_matches_the_fresnel_table() {
        // docs/physics.md#fresnel: A_J at η = 1, 1.3, 3.
        assert_eq!(boundary_coefficient(1.0).unwrap(), 1.0);
        assert!((boundary_coefficient(1.3).unwrap() - 2.600079).abs() < 1e-4);
        assert!((boundary_coefficient(3.0).unwrap() - 23.86887).abs() < 1e-3);
        assert!(boundary_coefficient(0.9).is_err());
        assert!(boundary_coefficient(f64::NAN).is_err());
    }

    #[test]
    fn scaled_green_is_the_image_pair() {
        // Against the unscaled formula where e^{κρ} is harmless.
        let (rho, zeta, kappa, zb) = (1.7, 0.4, 0.3, 0.9);
        let r1 = (rho * rho + (zeta - 1.0f64).powi(2)).sqrt();
        let r2 = (rho * rho + (zeta + 1.0 + 2.0 * zb).powi(2)).sqrt();
        let g = (-kappa * r1).exp() / r1 - (-kappa * r2).exp() / r2;
        let scaled = scaled_green(rho, zeta, kappa, zb);
        assert!((scaled * (-kappa * rho).exp() - g).abs() < 1e-14);
        // Positive and finite far away, at κ = 0 and at large κ.
        for (rho, zeta, kappa) in [
            (1e6, 0.0, 0.0),
            (1e6, 3.0, 1.7),
            (0.0, 0.0, 1.7),
            (0.1, 1e5, 0.0),
        ] {
            let v = scaled_green(rho, zeta, kappa, zb);
            assert!(v.is_finite() && v > 0.0, "{rho} {zeta} {kappa}: {v}");
        }
    }
}
