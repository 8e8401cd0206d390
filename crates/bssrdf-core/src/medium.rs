//! Validated single-channel optical parameters of a homogeneous medium and the quantities
//! derived from them.

use crate::error::check_g;
use crate::error::{ParamError, check_non_negative};

/// Optical parameters of one colour channel of a homogeneous medium.
///
/// Invariants (checked by [`MediumParams::new`]): `sigma_a`, `sigma_s` finite and `>= 0`;
/// `g` finite with `|g| < 1` ([`crate::error::check_g`]); `eta` finite with `eta >= 1` (models that support `eta < 1`
/// may relax this through their own constructors).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MediumParams {
    sigma_a: f64,
    sigma_s: f64,
    g: f64,
    eta: f64,
}

impl MediumParams {
    /// Validates and builds the parameters. `sigma_a`, `sigma_s` in 1/length.
    pub fn new(sigma_a: f64, sigma_s: f64, g: f64, eta: f64) -> Result<Self, ParamError> {
        check_non_negative("sigma_a", sigma_a)?;
        check_non_negative("sigma_s", sigma_s)?;
        check_g(g)?;
        if !eta.is_finite() {
            return Err(ParamError::NotFinite {
                name: "eta",
                value: eta,
            });
        }
        if eta < 1.0 {
            return Err(ParamError::OutOfRange {
                name: "eta",
                range: "[1, inf)",
                value: eta,
            });
        }
        Ok(Self {
            sigma_a,
            sigma_s,
            g,
            eta,
        })
    }

    /// Absorption coefficient σa (1/length).
    pub fn sigma_a(&self) -> f64 {
        self.sigma_a
    }
    /// Scattering coefficient σs (1/length).
    pub fn sigma_s(&self) -> f64 {
        self.sigma_s
    }
    /// Henyey–Greenstein mean cosine g.
    pub fn g(&self) -> f64 {
        self.g
    }
    /// Relative index of refraction η = n_medium / n_outside.
    pub fn eta(&self) -> f64 {
        self.eta
    }
    /// Extinction σt = σa + σs.
    pub fn sigma_t(&self) -> f64 {
        self.sigma_a + self.sigma_s
    }
    /// Reduced scattering σs' = (1 − g) σs.
    pub fn sigma_s_reduced(&self) -> f64 {
        (1.0 - self.g) * self.sigma_s
    }
    /// Reduced extinction σt' = σa + σs'.
    pub fn sigma_t_reduced(&self) -> f64 {
        self.sigma_a + self.sigma_s_reduced()
    }
    /// Single-scattering albedo ϖ = σs/σt; 0 for vacuum (σt = 0).
    pub fn albedo(&self) -> f64 {
        let st = self.sigma_t();
        if st > 0.0 { self.sigma_s / st } else { 0.0 }
    }
    /// Reduced albedo α' = σs'/σt'; 0 for vacuum.
    pub fn albedo_reduced(&self) -> f64 {
        let st = self.sigma_t_reduced();
        if st > 0.0 {
            self.sigma_s_reduced() / st
        } else {
            0.0
        }
    }
    /// Classical effective transport coefficient σtr = √(3 σa σt') (JMLH01).
    pub fn sigma_tr(&self) -> f64 {
        (3.0 * self.sigma_a * self.sigma_t_reduced()).sqrt()
    }
    /// Mean free path 1/σt (infinite for vacuum).
    pub fn mean_free_path(&self) -> f64 {
        1.0 / self.sigma_t()
    }
    /// The same medium with other coefficients (g and η kept), validated.
    pub fn with_coefficients(&self, sigma_a: f64, sigma_s: f64) -> Result<Self, ParamError> {
        Self::new(sigma_a, sigma_s, self.g, self.eta)
    }
}
