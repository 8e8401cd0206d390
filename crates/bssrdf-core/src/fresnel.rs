//! Fresnel reflectance of a smooth dielectric boundary (pbrt-v4 §9.3).

/// Unpolarised Fresnel reflectance for light arriving at the boundary with cosine `cos_i`
/// (measured from the normal on the incident side, `cos_i ∈ [0, 1]`) and relative index
/// `eta = n_transmitted / n_incident`. Returns 1 under total internal reflection, and exactly
/// 0 at `eta = 1` (an index-matched boundary is no boundary: the formula would round to
/// about 1e-32, and to 1 at grazing incidence, where `sin²θ_t` reaches 1).
pub fn dielectric(cos_i: f64, eta: f64) -> f64 {
    if eta == 1.0 {
        return 0.0;
    }
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

use crate::error::ParamError;
use crate::quadrature::{gl32, integrate};

/// Fresnel moment `C_i(η) = ∫₀¹ F_r(μ; η) μ^i dμ` of the *exact* unpolarised dielectric
/// reflectance, for light inside a medium of relative index `η = n_medium / n_outside` that hits
/// the boundary with cosine `μ` (pbrt-v3 book §11.4.1; docs/physics.md#fresnel). For `η > 1` this
/// includes total internal reflection below `μ_c = √(1 − 1/η²)`; the *external* moment (light
/// arriving from outside) is `C_i(1/η)`. `2 C_1(η)` is the internal diffuse reflectance `F_dr`.
///
/// Computed by quadrature (not pbrt's degree-5 fits, which break down above η ≈ 2.5, docs/physics.md#fresnel):
/// the TIR part `μ_c^{i+1}/(i+1)` is exact; the rest is integrated over the cosine `t` of the
/// transmitted direction, `μ = √(1 − (1 − t²)/η²)`, which removes the square-root edge at
/// `μ_c`, with two 32-point Gauss–Legendre panels (error < 1e-12). For `η < 1` there is no TIR
/// and the integral is taken over `μ` directly. Exactly 0 at `η = 1`. Cost ≈ 1 µs.
///
/// `eta` must be finite and > 0 (not checked here; see [`FresnelMoments::new`]).
pub fn fresnel_moment(i: i32, eta: f64) -> f64 {
    if eta == 1.0 {
        return 0.0;
    }
    let inv = 1.0 / eta;
    if eta > 1.0 {
        let mu_c = (1.0 - inv * inv).max(0.0).sqrt();
        let tir = mu_c.powi(i + 1) / (i as f64 + 1.0);
        let f = |t: f64| {
            let mu = (1.0 - (1.0 - t * t) * inv * inv).max(0.0).sqrt();
            if mu <= 0.0 {
                return 0.0;
            }
            dielectric(mu, inv) * mu.powi(i) * t * inv * inv / mu
        };
        tir + integrate(gl32(), 0.0, 0.5, f) + integrate(gl32(), 0.5, 1.0, f)
    } else {
        let f = |mu: f64| dielectric(mu, inv) * mu.powi(i);
        integrate(gl32(), 0.0, 0.5, f) + integrate(gl32(), 0.5, 1.0, f)
    }
}

/// The first two Fresnel moments of one relative index, computed once per material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FresnelMoments {
    /// Relative index η the moments belong to.
    pub eta: f64,
    /// `C_1(η)`; `2 C_1` is the internal diffuse reflectance `F_dr`.
    pub c1: f64,
    /// `C_2(η)`.
    pub c2: f64,
}

impl FresnelMoments {
    /// Largest relative index accepted (also used for `1/η` of the external moments).
    pub const ETA_MAX: f64 = 10.0;

    /// Computes `C_1(η)` and `C_2(η)` by quadrature ([`fresnel_moment`]). `eta` must be finite
    /// and in `[1/10, 10]` (external moments use `1/η`); the project validates `η ∈ [1, 3]`.
    pub fn new(eta: f64) -> Result<Self, ParamError> {
        if !eta.is_finite() {
            return Err(ParamError::NotFinite {
                name: "eta",
                value: eta,
            });
        }
        if !(1.0 / Self::ETA_MAX..=Self::ETA_MAX).contains(&eta) {
            return Err(ParamError::OutOfRange {
                name: "eta",
                range: "[0.1, 10]",
                value: eta,
            });
        }
        Ok(Self {
            eta,
            c1: fresnel_moment(1, eta),
            c2: fresnel_moment(2, eta),
        })
    }

    /// Internal diffuse reflectance `F_dr = 2 C_1`.
    pub fn f_dr(&self) -> f64 {
        2.0 * self.c1
    }
    /// Fluence exitance weight `c_φ = (1 − 2C_1)/4` (dEI11 / HCJ13 boundary condition).
    pub fn c_phi(&self) -> f64 {
        0.25 * (1.0 - 2.0 * self.c1)
    }
    /// Flux exitance weight `c_E = (1 − 3C_2)/2`.
    pub fn c_e(&self) -> f64 {
        0.5 * (1.0 - 3.0 * self.c2)
    }
    /// Boundary coefficient of the modified (dEI11) boundary condition,
    /// `A = (1 + 3C_2)/(1 − 2C_1)`, used by photon beam diffusion and the better dipole.
    pub fn a_pbd(&self) -> f64 {
        (1.0 + 3.0 * self.c2) / (1.0 - 2.0 * self.c1)
    }
}

/// Egan & Hilgeman's rational fit of the internal diffuse Fresnel reflectance, as used by JMLH01
/// (`F_dr = −1.440/η² + 0.710/η + 0.668 + 0.0636 η`). Within 0.0016 of the exact `2C_1` for
/// η ≤ 2.2, but 0.016 off at η = 3 and 0.0016 (not 0) at η = 1 (docs/physics.md#fresnel).
pub fn f_dr_egan_hilgeman(eta: f64) -> f64 {
    -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
}

/// How the classical dipole obtains its diffuse Fresnel reflectance `F_dr` (and so its boundary
/// coefficient `A = (1 + F_dr)/(1 − F_dr)`).
///
/// Trade-off (docs/physics.md#fresnel): the fit reproduces JMLH01 exactly as published and is
/// within 0.0016 of the exact value for η ≤ 2.2, but it gives `A = 1.0032` instead of 1 at η = 1
/// and `A = 29.99` instead of 23.87 at η = 3. `Exact` is correct over the whole η range and
/// costs one quadrature per material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum DiffuseFresnel {
    /// `F_dr = 2 C_1(η)` by quadrature of the exact Fresnel formula (default).
    #[default]
    Exact,
    /// Egan–Hilgeman rational fit, as in JMLH01 ([`f_dr_egan_hilgeman`]).
    JensenFit,
}

impl DiffuseFresnel {
    /// `F_dr` for the given moments under this choice.
    pub fn f_dr(self, moments: &FresnelMoments) -> f64 {
        match self {
            DiffuseFresnel::Exact => moments.f_dr(),
            DiffuseFresnel::JensenFit => f_dr_egan_hilgeman(moments.eta),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An index-matched boundary reflects nothing at any angle, grazing included; just off
    /// η = 1 the reflectance is small but not zero.
    #[test]
    fn index_matched_boundary_reflects_nothing() {
        for k in 0..=100 {
            let cos = k as f64 / 100.0;
            assert_eq!(dielectric(cos, 1.0), 0.0, "cos {cos}");
        }
        let near = dielectric(0.5, 1.01);
        assert!(near > 0.0 && near < 1e-3, "{near}");
    }

    #[test]
    fn moments_match_independent_table() {
        // docs/physics.md#fresnel [computed]: η, C1, C2, C1(1/η), A_J, A_PBD.
        let table = [
            (1.30, 0.222230, 0.100090, 0.030565, 2.600079, 2.34053),
            (1.33, 0.235975, 0.109413, 0.032965, 2.787514, 2.51536),
            (1.50, 0.298173, 0.154810, 0.045889, 3.95474, 3.62793),
            (2.00, 0.395075, 0.234957, 0.080298, 8.53058, 8.12420),
            (3.00, 0.459789, 0.294228, 0.138102, 23.86887, 23.41012),
        ];
        for (eta, c1, c2, c1e, aj, apbd) in table {
            let m = FresnelMoments::new(eta).unwrap();
            // The table's C1/C2 are rounded to ~2e-6 (its A columns, 7 digits, are tighter).
            assert!((m.c1 - c1).abs() < 3e-6, "eta={eta}: C1 {} vs {c1}", m.c1);
            assert!((m.c2 - c2).abs() < 3e-6, "eta={eta}: C2 {} vs {c2}", m.c2);
            let ext = FresnelMoments::new(1.0 / eta).unwrap();
            assert!(
                (ext.c1 - c1e).abs() < 1e-6,
                "eta={eta}: C1ext {} vs {c1e}",
                ext.c1
            );
            let a_j = (1.0 + m.f_dr()) / (1.0 - m.f_dr());
            assert!((a_j - aj).abs() < 1e-5 * aj, "eta={eta}: A_J {a_j} vs {aj}");
            assert!((m.a_pbd() - apbd).abs() < 1e-5 * apbd, "eta={eta}: A_PBD");
        }
        let one = FresnelMoments::new(1.0).unwrap();
        assert_eq!((one.c1, one.c2), (0.0, 0.0));
        assert_eq!(one.a_pbd(), 1.0);
        // Continuity across η = 1 (internal vs external branch).
        assert!(fresnel_moment(1, 1.0 + 1e-9).abs() < 1e-6);
        assert!(fresnel_moment(1, 1.0 - 1e-9).abs() < 1e-6);
    }

    #[test]
    fn moments_agree_with_brute_force_midpoint() {
        // Independent check: plain midpoint rule in μ on the reflectance itself.
        for eta in [1.1, 1.7, 2.5] {
            let n = 400_000;
            let (mut s1, mut s2) = (0.0, 0.0);
            for k in 0..n {
                let mu = (k as f64 + 0.5) / n as f64;
                let f = dielectric(mu, 1.0 / eta);
                s1 += f * mu;
                s2 += f * mu * mu;
            }
            let m = FresnelMoments::new(eta).unwrap();
            assert!((s1 / n as f64 - m.c1).abs() < 1e-7, "eta={eta}");
            assert!((s2 / n as f64 - m.c2).abs() < 1e-7, "eta={eta}");
        }
    }

    #[test]
    fn fit_matches_notes() {
        // docs/physics.md#fresnel: fit gives A = 1.0032 at η = 1 and ≈ 29.99 at η = 3.
        let a = |f: f64| (1.0 + f) / (1.0 - f);
        assert!((a(f_dr_egan_hilgeman(1.0)) - 1.003205).abs() < 1e-5);
        assert!((a(f_dr_egan_hilgeman(3.0)) - 29.99).abs() < 0.01);
        assert!(FresnelMoments::new(f64::NAN).is_err());
        assert!(FresnelMoments::new(0.0).is_err());
    }
}
