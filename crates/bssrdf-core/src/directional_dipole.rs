//! Directional dipole (FHK14: Frisvad, Hachisuka & Kjeldsen, *Directional Dipole Model for
//! Subsurface Scattering*, ACM TOG 34(1), 2014), and its modified tangent-plane normal, which
//! the estimators reuse to orient their averaging ellipse.
//!
//! # Source and status
//! Implemented from the authors' sample code as carried by `RoaldFre/mitsuba`
//! `src/subsurface/dirpole.cpp` (docs/physics.md#directional-dipole); the paper's own notation was not checked
//! (\[U\]). Differences from the sample code: the Fresnel moments are exact (quadrature) instead
//! of the polynomial fits, and the degenerate modified normal falls back to `n_i`.
//!
//! # Model (all lengths in scene units)
//! `D = 1/(3σt')` (classical, not Grosjean), `σtr = √(σa/D)`, `d_e = 2.131 D/√α'`,
//! `C_φ(η) = (1 − 2C₁(η))/4`, `C_E(η) = (1 − 3C₂(η))/2`, `A = (1 − C_E)/(2C_φ)`.
//! `ω₁₂` is `ω_i` (pointing towards the light) refracted into the medium; the virtual source is
//! at `x_v = x_i + 2A d_e n_i*` with direction `ω_v = ω₁₂ − 2(ω₁₂·n_i*)n_i*`, `n_i*` the
//! [`modified_normal`]. With `x = x_o − x_i`, `r = |x|`, `μ₀ = −n_o·ω₁₂`,
//! `cos β = −√((r² − (x·ω₁₂)²)/(r² + d_e²))`, real-source distance
//! `d_r² = r² + Dμ₀(Dμ₀ − 2d_e cos β)` if `μ₀ > 0`, else `r² + (1/(3σt))²`, and
//! `d_v = |x_o − x_v|`:
//!
//! `S'(x, ω, R) = [1/(4C_φ(1/η))]·[1/(4π²)]·(e^{−σtr R}/R³)·{C_φ(η)[R²/D + 3(1+σtr R)(x·ω)]
//!   − C_E(η)[3D(1+σtr R)(ω·n_o) − ((1+σtr R) + 3D(3(1+σtr R) + (σtr R)²)(x·ω)/R²)(x·n_o)]}`,
//!
//! `S_d = max(0, S'(x_o − x_i, ω₁₂, d_r) − S'(x_o − x_v, ω_v, d_v))` (1/(length²·sr)). The full
//! BSSRDF multiplies by the Fresnel transmittances `T₁₂(ω_i)` and `T₂₁(ω_o)`, which the caller
//! applies. For flat geometry at normal incidence the exitance is `M = π(1 − 2C₁(1/η))·S_d`.
//!
//! # Validity and extremes
//! Not energy-conserving in the near field (∫2πrM = 1.088 at σs = 1, σa = 0.01 against the
//! exact 0.754; docs/physics.md#directional-dipole); within ~10 % of the classical dipole beyond ~5 mean free paths.
//! `σs' = 0` (where `d_e → ∞`) and vacuum give 0; `σa = 0` gives `σtr = 0` (algebraic decay);
//! `x_o = x_i` is finite (`d_r ≥ Dμ₀ > 0` or `1/(3σt)`, `d_v = 2A d_e`); the difference can go
//! negative and is clamped at 0 like the sample code. Light arriving from below the surface
//! (`ω_i·n_i < 0`) is treated as grazing.

use crate::error::ParamError;
use crate::error::{check_eta, validate_sigmas};
use crate::fresnel::FresnelMoments;
use glam::DVec3;
use std::f64::consts::PI;

/// FHK14's modified normal `n_i* = x̂ × (n_i × x̂) / |n_i × x̂|`, with `x̂ = (x_o − x_i)/|x_o − x_i|`;
/// equivalently `normalize(n_i − (n_i·x̂) x̂)`: `n_i` projected onto the plane perpendicular to
/// the chord, so the plane through `x_i` with this normal also contains `x_o` (docs/physics.md#directional-dipole).
///
/// Undefined when `x_o = x_i` or `n_i ∥ x̂`; in those cases (chord shorter than 1e-12 of the
/// coordinates' scale, or `|n_i × x̂| < 1e-9`) it returns `n_i` normalised, as docs/physics.md#directional-dipole advises.
/// `n_i` must be non-zero; the result is always a finite unit vector when it is.
pub fn modified_normal(n_i: DVec3, x_i: DVec3, x_o: DVec3) -> DVec3 {
    let n = n_i.normalize_or(DVec3::Z);
    let chord = x_o - x_i;
    let len = chord.length();
    let scale = x_i
        .abs()
        .max_element()
        .max(x_o.abs().max_element())
        .max(1.0);
    if len.is_nan() || len <= 1e-12 * scale {
        return n;
    }
    let xh = chord / len;
    let proj = n - n.dot(xh) * xh;
    let plen = proj.length();
    if plen < 1e-9 {
        return n;
    }
    proj / plen
}

/// The directional dipole for one set of coefficients (construct per pair; cheap with
/// [`DirectionalDipole::with_moments`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalDipole {
    sigma_tr: f64,
    d: f64,
    d_e: f64,
    /// 1/(3σt), the μ₀ ≤ 0 real-source offset.
    inv_3_sigma_t: f64,
    c_phi: f64,
    c_e: f64,
    a: f64,
    /// 1/(4 C_φ(1/η)) / (4π²).
    norm: f64,
    inv_eta: f64,
    zero: bool,
}

impl DirectionalDipole {
    /// Builds the model for `σa`, `σs` (1/length), HG `g` and relative index `eta ∈ [1, 3]`,
    /// computing the Fresnel moments by quadrature (≈ 3 µs; use
    /// [`DirectionalDipole::with_moments`] per pair).
    pub fn new(sigma_a: f64, sigma_s: f64, g: f64, eta: f64) -> Result<Self, ParamError> {
        crate::MediumParams::new(0.0, 0.0, g, eta)?;
        check_eta(eta)?;
        let internal = FresnelMoments::new(eta)?;
        let external = FresnelMoments::new(1.0 / eta)?;
        Self::with_moments(sigma_a, sigma_s, g, &internal, external.c1)
    }

    /// Builds the model from precomputed moments: `internal` = moments of `η`,
    /// `c1_external = C₁(1/η)`. No quadrature.
    pub fn with_moments(
        sigma_a: f64,
        sigma_s: f64,
        g: f64,
        internal: &FresnelMoments,
        c1_external: f64,
    ) -> Result<Self, ParamError> {
        let (sigma_a, sigma_s) = validate_sigmas(sigma_a, sigma_s)?;
        let sigma_sp = (1.0 - g) * sigma_s;
        let sigma_tp = sigma_a + sigma_sp;
        let sigma_t = sigma_a + sigma_s;
        let zero = sigma_sp <= 0.0 || sigma_tp <= 0.0;
        let alpha_p = if zero { 1.0 } else { sigma_sp / sigma_tp };
        let d = if zero { 1.0 } else { 1.0 / (3.0 * sigma_tp) };
        let c_phi = internal.c_phi();
        let c_e = internal.c_e();
        Ok(Self {
            sigma_tr: (sigma_a / d).sqrt(),
            d,
            d_e: 2.131 * d / alpha_p.sqrt(),
            inv_3_sigma_t: if sigma_t > 0.0 {
                1.0 / (3.0 * sigma_t)
            } else {
                1.0
            },
            c_phi,
            c_e,
            a: (1.0 - c_e) / (2.0 * c_phi),
            norm: 1.0 / (1.0 - 2.0 * c1_external) / (4.0 * PI * PI),
            inv_eta: 1.0 / internal.eta,
            zero,
        })
    }

    /// `1/(4C_φ(1/η)) = 1/(1 − 2C₁(1/η))`: the exitance of flat normal incidence is
    /// `M = π S_d / this`.
    pub fn normalisation(&self) -> f64 {
        self.norm * 4.0 * PI * PI
    }

    fn s_prime(&self, x: DVec3, w: DVec3, r: f64, n_o: DVec3) -> f64 {
        let s_tr_r = self.sigma_tr * r;
        let one = 1.0 + s_tr_r;
        let x_w = x.dot(w);
        let r2 = r * r;
        let t0 = self.norm * (-s_tr_r).exp() / (r * r2);
        let t1 = r2 / self.d + 3.0 * one * x_w;
        let t2 = 3.0 * self.d * one * w.dot(n_o);
        let t3 = (one + 3.0 * self.d * (3.0 * one + s_tr_r * s_tr_r) / r2 * x_w) * x.dot(n_o);
        t0 * (self.c_phi * t1 - self.c_e * (t2 - t3))
    }

    /// Diffuse BSSRDF `S_d(x_i, ω_i, n_i; x_o, n_o)` in 1/(length²·sr), without the Fresnel
    /// transmittances. `w_i` points from `x_i` towards the light; normals point out of the
    /// medium; all directions unit length. Finite and ≥ 0 for every input (NaN geometry → 0).
    pub fn s_d(&self, x_i: DVec3, w_i: DVec3, n_i: DVec3, x_o: DVec3, n_o: DVec3) -> f64 {
        if self.zero {
            return 0.0;
        }
        // Refract ω_i into the medium (relative index 1/η from outside to inside).
        let n = n_i.normalize_or(DVec3::Z);
        let cos_i = w_i.dot(n).clamp(0.0, 1.0);
        let nnt = self.inv_eta;
        let cos_t = (1.0 - nnt * nnt * (1.0 - cos_i * cos_i)).max(0.0).sqrt();
        let w12 = (-nnt * w_i + (nnt * cos_i - cos_t) * n).normalize_or(-n);
        let x = x_o - x_i;
        let r2 = x.length_squared();
        let ni_s = modified_normal(n, x_i, x_o);
        let wv = w12 - 2.0 * w12.dot(ni_s) * ni_s;
        let x_w = x.dot(w12);
        let cos_beta = -((r2 - x_w * x_w).max(0.0) / (r2 + self.d_e * self.d_e)).sqrt();
        let mu0 = -n_o.dot(w12);
        let dr2 = if mu0 > 0.0 {
            r2 + self.d * mu0 * (self.d * mu0 - 2.0 * self.d_e * cos_beta)
        } else {
            r2 + self.inv_3_sigma_t * self.inv_3_sigma_t
        };
        let x_v = x_i + 2.0 * self.a * self.d_e * ni_s;
        let xv = x_o - x_v;
        let dv = xv.length();
        let v = self.s_prime(x, w12, dr2.sqrt(), n_o) - self.s_prime(xv, wv, dv, n_o);
        if v.is_finite() && v > 0.0 { v } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spot_values_match_notes() {
        // docs/physics.md#directional-dipole [computed]: flat geometry, normal incidence, σs = 1, σa = 0.01, η = 1;
        // M = π(1 − 2C₁(1/η)) S_d.
        let m = DirectionalDipole::new(0.01, 1.0, 0.0, 1.0).unwrap();
        let fam = crate::ProfileFamily::new(
            crate::ProfileModel::Dipole,
            crate::Scattering::Multiple,
            0.0,
            1.0,
        )
        .unwrap();
        assert_eq!(fam.directional_dipole(0.01, 1.0).unwrap(), m);
        let n = DVec3::Z;
        let exitance =
            |r: f64| PI / m.normalisation() * m.s_d(DVec3::ZERO, n, n, DVec3::new(r, 0.0, 0.0), n);
        for (r, want) in [
            (0.1, 6.14461e-1),
            (0.5, 1.34737e-1),
            (1.0, 5.38500e-2),
            (2.0, 1.60786e-2),
            (5.0, 1.41939e-3),
            (10.0, 1.20430e-4),
        ] {
            let got = exitance(r);
            assert!((got - want).abs() < 2e-5 * want, "r={r}: {got} vs {want}");
        }
        // ∫2πr M dr ≈ 1.088 (σa = 0.01) and 0.730 (σa = 0.1): brute-force Simpson in ln r.
        for (sa, want) in [(0.01, 1.088), (0.1, 0.730)] {
            let m = DirectionalDipole::new(sa, 1.0, 0.0, 1.0).unwrap();
            let f =
                |r: f64| 2.0 * PI * r * PI * m.s_d(DVec3::ZERO, n, n, DVec3::new(r, 0.0, 0.0), n);
            let tot = crate::test_util::simpson_log(f, 1e-8, 1e4, 20_000);
            assert!((tot - want).abs() < 1e-3, "σa={sa}: {tot} vs {want}");
        }
    }

    #[test]
    fn extremes_are_finite() {
        let n = DVec3::Z;
        for (sa, ss, g, eta) in [
            (0.0, 1.0, 0.0, 1.0),
            (1.0, 0.0, 0.0, 1.5),
            (0.0, 0.0, 0.0, 1.0),
            (1e6, 1e6, 0.9, 3.0),
            (1e-6, 1e-6, -0.9, 1.3),
            (0.0, 1e6, 0.99, 2.0),
        ] {
            let m = DirectionalDipole::new(sa, ss, g, eta).unwrap();
            for r in [0.0, 1e-9, 1.0, 1e9] {
                for w in [
                    n,
                    DVec3::new(1.0, 0.0, 0.0),
                    DVec3::new(0.6, 0.0, -0.8),
                    DVec3::new(0.0, 0.6, 0.8),
                ] {
                    for no in [n, -n, DVec3::X] {
                        let v = m.s_d(DVec3::ZERO, w, n, DVec3::new(r, 0.0, 0.0), no);
                        assert!(
                            v.is_finite() && v >= 0.0,
                            "({sa},{ss},{g},{eta}) r={r}: {v}"
                        );
                    }
                }
            }
        }
        assert!(DirectionalDipole::new(-1.0, 1.0, 0.0, 1.0).is_err());
        assert!(DirectionalDipole::new(1.0, 1.0, 0.0, 0.5).is_err());
        assert!(DirectionalDipole::new(1.0, 1.0, 1.0, 1.5).is_err());
    }

    #[test]
    fn modified_normal_is_perpendicular_to_chord_and_matches_cross_form() {
        let n_i = DVec3::new(0.2, -0.1, 1.0).normalize();
        let x_i = DVec3::new(0.3, 0.1, 0.0);
        let x_o = DVec3::new(-1.0, 2.0, 0.5);
        let m = modified_normal(n_i, x_i, x_o);
        let xh = (x_o - x_i).normalize();
        assert!(m.dot(xh).abs() < 1e-12);
        assert!((m.length() - 1.0).abs() < 1e-12);
        let c = n_i.cross(xh);
        let cross_form = xh.cross(c) / c.length();
        assert!((m - cross_form).length() < 1e-12);
    }

    #[test]
    fn degenerate_cases_fall_back_to_n_i() {
        let n = DVec3::Z;
        assert_eq!(modified_normal(n, DVec3::ONE, DVec3::ONE), n);
        assert_eq!(
            modified_normal(n, DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0)),
            n
        );
        assert_eq!(
            modified_normal(n, DVec3::ZERO, DVec3::new(0.0, 0.0, -2.0)),
            n
        );
    }
}
