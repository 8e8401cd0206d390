//! The rough diffuse reflector of opaque materials: the Oren–Nayar model in Fujii's form
//! ("A tiny improvement of Oren–Nayar reflectance model", 2012; OpenPBR's
//! `base_diffuse_roughness`, whose energy-preserving EON extension is not included here):
//!
//! `f(ω_o, ω_i) = ρ/π · (1 + σ s/t) / (1 + (1/2 − 2/(3π)) σ)`,
//! `s = ω_i·ω_o − cos θ_i cos θ_o`, `t = max(cos θ_i, cos θ_o)` where `s > 0`, else 1,
//!
//! with ρ the albedo and the roughness σ ∈ [0, 1] (the scene's `roughness` of a diffuse
//! material): Lambert's `ρ/π` at σ = 0; rougher surfaces scatter more back toward the light
//! and look flatter. The model is reciprocal, and its directional albedo stays at or below ρ
//! (it loses some energy at high σ, which EON adds back).

use std::f64::consts::PI;

use glam::DVec3;

/// `π f / ρ` of the model above for the unit directions `wo`, `wi` about the unit normal `n`
/// (both in front of it; 0 otherwise). Equal to 1 at `sigma = 0` (Lambert).
#[inline]
pub fn oren_nayar(sigma: f64, n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
    let (cos_o, cos_i) = (wo.dot(n), wi.dot(n));
    if cos_o <= 0.0 || cos_i <= 0.0 {
        return 0.0;
    }
    if sigma <= 0.0 {
        return 1.0;
    }
    let s = wi.dot(wo) - cos_i * cos_o;
    let t = if s > 0.0 { cos_i.max(cos_o) } else { 1.0 };
    (1.0 + sigma * s / t) / (1.0 + (0.5 - 2.0 / (3.0 * PI)) * sigma)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direction(cos: f64, phi: f64) -> DVec3 {
        let sin = (1.0 - cos * cos).sqrt();
        DVec3::new(sin * phi.cos(), sin * phi.sin(), cos)
    }

    /// The directional albedo `∫ f cos θ_i dω_i / ρ` by a fine midpoint rule.
    fn albedo(sigma: f64, cos_o: f64) -> f64 {
        let wo = direction(cos_o, 0.0);
        let n = 400;
        let mut s = 0.0;
        for a in 0..n {
            let cos = (a as f64 + 0.5) / n as f64;
            for b in 0..2 * n {
                let wi = direction(cos, PI * (b as f64 + 0.5) / n as f64);
                s += oren_nayar(sigma, DVec3::Z, wo, wi) / PI * cos;
            }
        }
        s * 2.0 * PI / (2 * n * n) as f64
    }

    /// Lambert at σ = 0; reciprocal; an albedo at most 1 that falls with σ, by at most the
    /// normalisation's 1 / (1 + (1/2 − 2/(3π))σ) at normal incidence (where s ≤ 0 and t = 1, the
    /// average of s over the hemisphere weighted by cos being −2/3 of cos... see below).
    #[test]
    fn lambert_limit_reciprocity_and_albedo() {
        for cos_o in [1.0, 0.7, 0.3, 0.05] {
            assert!((albedo(0.0, cos_o) - 1.0).abs() < 1e-4);
            let mut last = 1.0 + 1e-9;
            for sigma in [0.25, 0.5, 0.75, 1.0] {
                let a = albedo(sigma, cos_o);
                assert!(a <= 1.0 + 1e-4 && a > 0.5, "σ {sigma}, cos {cos_o}: {a}");
                assert!(a <= last + 1e-4, "albedo grows with σ at cos {cos_o}");
                last = a;
            }
        }
        // At normal incidence s = −cos θ_i cos θ_o + ω_i·ω_o = 0 exactly (ω_o = n), so the
        // albedo is the normalisation alone.
        let c = 0.5 - 2.0 / (3.0 * PI);
        assert!((albedo(1.0, 1.0) - 1.0 / (1.0 + c)).abs() < 1e-4);
        let (a, b) = (direction(0.6, 0.3), direction(0.2, 2.5));
        assert_eq!(
            oren_nayar(0.8, DVec3::Z, a, b),
            oren_nayar(0.8, DVec3::Z, b, a)
        );
        assert_eq!(oren_nayar(0.5, DVec3::Z, a, -b), 0.0);
    }
}
