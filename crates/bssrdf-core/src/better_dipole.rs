//! The "better dipole" of d'Eon (dE12: E. d'Eon, *A Better Dipole*, technical note, 2012).
//!
//! # Sources and status
//! The primary note was **not** available to us. The formulas below were pinned down from two
//! independent secondary sources that agree with each other and with docs/physics.md#better-dipole:
//! (i) appleseed's `betterdipolebssrdf.cpp` (profile) and `sss.cpp` `ComputeRdBetterDipole`,
//! which cite the note and Hery's *Texturing the Better Dipole* (Pixar) for the total; (ii) a
//! second open implementation of the profile (Frisvad group's GPU code). Both give the
//! profile as photon beam diffusion's depth integrand (HCJ13 / docs/physics.md#beam-diffusion) evaluated at the
//! single depth `z_r = 1/σt'`, without the near-source correction κ. We derived the total
//! below from the profile ourselves and it matches Hery's closed form, which cross-checks
//! the profile's normalisation (the `α'²` prefactor). One discrepancy between the sources:
//! appleseed evaluates the exponential decay with the classical `σtr = √(3σaσt')` while its
//! own total uses Grosjean's; we use Grosjean's `σtr = √(σa/D_G)` consistently (as the second
//! implementation and the total do). Treat as unverified (\[unchecked\] in docs/physics.md#better-dipole) until checked against the note.
//!
//! # Model (optical units `x = σt' r`, lengths in 1/σt')
//! Grosjean's diffusion coefficient `D = (2σa + σs')/(3σt'²)`, `σtr = √(σa/D)`; modified
//! boundary condition (dEI11) `A = (1 + 3C₂)/(1 − 2C₁)`, `c_φ = (1 − 2C₁)/4`,
//! `c_E = (1 − 3C₂)/2`; `z_r = 1/σt'`, image at `z_v = −(z_r + 4AD)` (above the surface):
//!
//! `R(r) = (α'²/4π)·[ (c_φ/D)(e^{−σtr d_r}/d_r − e^{−σtr d_v}/d_v)
//!                  + c_E(z_r(1+σtr d_r)e^{−σtr d_r}/d_r³ + |z_v|(1+σtr d_v)e^{−σtr d_v}/d_v³) ]`.
//!
//! Total (derived, equals Hery's formula): with `s = σtr` and `z_r`, `|z_v|` as above,
//! `R_tot = (α'²/2)·e^{−s z_r}·[c_E(1 + e^{−4ADs}) + (c_φ/(Ds))(1 − e^{−4ADs})]`, which in
//! optical units is `(α'²/2)e^{−√(3(1−α')/(2−α'))}[c_E(1+E) + c_φ/√((1−α')(2−α')/3)·(1−E)]`,
//! `E = e^{−4A√((1−α')(2−α')/3)}`; at `σa = 0` the second term tends to `4A c_φ = 1 + 3C₂`.
//!
//! # Units, validity, extremes
//! `R` in 1/length²; scaling `R(r) = σt'² R₁(σt' r)`. Diffusion model: good for `α'` near 1.
//! Finite at `r = 0`; `r⁻³` tail at `σa = 0`; zero profile for `σs' = 0`. Radius sampling
//! inverts the closed-form CDF, so `pdf_r = 2πr R / R_tot` exactly.

use crate::dipole_pair::{DipolePair, radial_profile_from_pair};
use crate::fresnel::FresnelMoments;

/// The better-dipole profile for one set of coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BetterDipole {
    pub(crate) pair: DipolePair,
    /// σt' (1/length).
    pub(crate) scale: f64,
}

impl BetterDipole {
    /// Better dipole for reduced albedo `alpha_p ∈ (0, 1]`, reduced extinction
    /// `sigma_t_p > 0` (1/length) and the material's Fresnel moments. No allocation.
    pub fn new(alpha_p: f64, sigma_t_p: f64, moments: &FresnelMoments) -> Self {
        Self {
            pair: Self::pair_at_depth(alpha_p, moments, 1.0),
            scale: sigma_t_p,
        }
    }

    /// The optical-unit pair for a real source at depth `z` (in 1/σt'); the better dipole
    /// uses `z = 1`, photon beam diffusion integrates over `z`.
    pub(crate) fn pair_at_depth(alpha_p: f64, m: &FresnelMoments, z: f64) -> DipolePair {
        let a2 = alpha_p * alpha_p;
        let d = (2.0 - alpha_p) / 3.0;
        DipolePair {
            z_r: z,
            z_v: z + 4.0 * m.a_pbd() * d,
            sigma: ((1.0 - alpha_p).max(0.0) / d).sqrt(),
            k_phi: a2 * m.c_phi() / d,
            k_e: a2 * m.c_e(),
        }
    }

    /// Effective transport coefficient `σtr = √(σa/D_G)` in 1/length.
    pub fn sigma_tr(&self) -> f64 {
        self.pair.sigma * self.scale
    }
}

radial_profile_from_pair!(BetterDipole);
