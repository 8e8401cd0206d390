//! Classical dipole diffusion profile (JMLH01, the dipole-diffusion section: the `R_d(r)` and
//! `S_d` equations; docs/physics.md#dipole).
//!
//! # Model
//! With reduced coefficients `σs' = (1 − g)σs`, `σt' = σa + σs'`, `α' = σs'/σt'`:
//! `D = 1/(3σt')`, `σtr = √(3σaσt')`, real source depth `z_r = 1/σt'`, image height
//! `z_v = z_r + 4AD` above the surface (extrapolated boundary `z_b = 2AD`),
//! `A = (1 + F_dr)/(1 − F_dr)` with the internal diffuse Fresnel reflectance `F_dr`
//! (exact `2C₁(η)` by default, or the Egan–Hilgeman fit, see [`crate::fresnel::DiffuseFresnel`]):
//!
//! `R_d(r) = (α'/4π)·[z_r(1+σtr d_r)e^{−σtr d_r}/d_r³ + z_v(1+σtr d_v)e^{−σtr d_v}/d_v³]`,
//! `d_{r,v} = √(r² + z_{r,v}²)`.
//!
//! Total diffuse reflectance (closed form, docs/physics.md#dipole \[derived\], also Jensen & Buhler 2002):
//! `R_d,tot = (α'/2)·e^{−√(3(1−α'))}·(1 + e^{−(4/3)A√(3(1−α'))})`.
//!
//! # Units and scaling
//! `r` in scene length, `R_d` in 1/length². Internally the profile is evaluated in optical
//! units `x = σt' r` and scaled: `R_d(r) = σt'² R₁(σt' r)` (docs/physics.md#conventions).
//!
//! # Validity and extremes
//! Diffusion theory: accurate for `α'` near 1 and `r` beyond a few mean free paths; it
//! ignores single scattering (combine with [`crate::single_scattering`] through
//! [`crate::Scattering`]). `R_d(0)` is finite (`d_r ≥ z_r`). `σa = 0` gives `σtr = 0` and an
//! `r⁻³` tail (sampling and `radius_for_fraction` still exact). `σs' = 0` or vacuum gives the
//! zero profile (handled by [`crate::family::ProfileFamily::profile`]).
//! Radius sampling inverts the closed-form CDF, so `pdf_r = 2πr R_d / R_d,tot` exactly.

use crate::dipole_pair::{DipolePair, radial_profile_from_pair};

/// The classical dipole profile for one set of coefficients (construct through
/// [`crate::family::ProfileFamily::profile`], or [`Dipole::new`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dipole {
    pair: DipolePair,
    /// σt' (1/length): optical-unit scale.
    scale: f64,
}

impl Dipole {
    /// Dipole for reduced albedo `alpha_p ∈ (0, 1]`, reduced extinction `sigma_t_p > 0`
    /// (1/length) and boundary coefficient `a ≥ 1`. Callers guarantee the ranges (the family
    /// validates user input); no allocation, no quadrature.
    pub fn new(alpha_p: f64, sigma_t_p: f64, a: f64) -> Self {
        // Optical units: σt' = 1, D = 1/3.
        let d = 1.0 / 3.0;
        let sigma_tr = (3.0 * (1.0 - alpha_p).max(0.0)).sqrt();
        Self {
            pair: DipolePair {
                z_r: 1.0,
                z_v: 1.0 + 4.0 * a * d,
                sigma: sigma_tr,
                k_phi: 0.0,
                k_e: alpha_p,
            },
            scale: sigma_t_p,
        }
    }

    /// The closed-form total `(α'/2)e^{−√(3(1−α'))}(1 + e^{−(4/3)A√(3(1−α'))})`.
    pub fn total_closed_form(alpha_p: f64, a: f64) -> f64 {
        let s = (3.0 * (1.0 - alpha_p).max(0.0)).sqrt();
        0.5 * alpha_p * (-s).exp() * (1.0 + (-(4.0 / 3.0) * a * s).exp())
    }

    /// Effective transport coefficient `σtr = √(3σaσt')` in 1/length.
    pub fn sigma_tr(&self) -> f64 {
        self.pair.sigma * self.scale
    }
}

radial_profile_from_pair!(Dipole);
