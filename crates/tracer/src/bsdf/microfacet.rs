//! The Trowbridge–Reitz (GGX) microfacet distribution with Smith's height-correlated
//! masking–shadowing, and the sampling of its visible normals (pbrt-v4 §9.6; Heitz 2018).
//!
//! Conventions: directions are unit vectors in the local frame of the macro-surface, whose
//! normal is `+z`; `θ` is the angle from `+z`. The roughness `α` is the slope parameter of
//! pbrt-v4's `TrowbridgeReitzDistribution` (isotropic here): the RMS slope of the microsurface
//! is `α/√2` per axis. Scene files give a perceptual roughness `r ∈ [0, 1]` with `α = r²`
//! (glTF, OpenPBR and Cycles' convention), see [`alpha_from_roughness`].
//!
//! * `D(ω_m) = 1 / (π α² cos⁴θ_m (1 + tan²θ_m / α²)²)`, normalised so that
//!   `∫ D(ω_m) cos θ_m dω_m = 1` (pbrt-v4 `TrowbridgeReitzDistribution::D`);
//! * `Λ(ω) = (√(1 + α² tan²θ) − 1) / 2`, `G1(ω) = 1 / (1 + Λ(ω))` (Smith's masking, `Lambda`
//!   and `G1`);
//! * `G(ω_o, ω_i) = 1 / (1 + Λ(ω_o) + Λ(ω_i))`, the height-correlated masking–shadowing
//!   (`G`; Hei14);
//! * the visible normals seen from `ω`: `D_ω(ω_m) = G1(ω) / |cos θ| · D(ω_m) · |ω·ω_m|`
//!   (`D(w, wm)`), sampled by [`TrowbridgeReitz::sample_visible`] (Hei18).

use std::f64::consts::PI;

use glam::DVec3;

/// The roughness α below which a boundary is treated as perfectly smooth (a delta
/// distribution), as pbrt-v4's `EffectivelySmooth`: the microfacet formulas lose precision
/// there, and the specular limit is what they tend to.
pub const SMOOTH_ALPHA: f64 = 1e-3;

/// α = r² for a perceptual roughness `r` (the scene's `roughness` key, in [0, 1]).
#[inline]
pub fn alpha_from_roughness(r: f64) -> f64 {
    r * r
}

/// The isotropic Trowbridge–Reitz (GGX) distribution of roughness α (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrowbridgeReitz {
    /// α (> 0).
    pub alpha: f64,
}

impl TrowbridgeReitz {
    /// The distribution of roughness `alpha` (clamped up to [`SMOOTH_ALPHA`]).
    pub fn new(alpha: f64) -> Self {
        Self {
            alpha: alpha.max(SMOOTH_ALPHA),
        }
    }

    /// `tan²θ` of `w` (∞ at grazing).
    #[inline]
    fn tan2(w: DVec3) -> f64 {
        let cos2 = w.z * w.z;
        let sin2 = (1.0 - cos2).max(0.0);
        sin2 / cos2
    }

    /// The microfacet density `D(ω_m)` (1/sr, per unit projected area).
    #[inline]
    pub fn d(&self, wm: DVec3) -> f64 {
        let tan2 = Self::tan2(wm);
        if !tan2.is_finite() {
            return 0.0;
        }
        let cos4 = (wm.z * wm.z) * (wm.z * wm.z);
        let a2 = self.alpha * self.alpha;
        let e = 1.0 + tan2 / a2;
        1.0 / (PI * a2 * cos4 * e * e)
    }

    /// Smith's `Λ(ω)`.
    #[inline]
    pub fn lambda(&self, w: DVec3) -> f64 {
        let tan2 = Self::tan2(w);
        if !tan2.is_finite() {
            return f64::INFINITY;
        }
        ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0) / 2.0
    }

    /// The masking function `G1(ω) = 1 / (1 + Λ(ω))`.
    #[inline]
    pub fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// The height-correlated masking–shadowing `G(ω_o, ω_i)`.
    #[inline]
    pub fn g(&self, wo: DVec3, wi: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of the normals visible from `w`, `D_ω(ω_m)` (1/sr): what
    /// [`TrowbridgeReitz::sample_visible`] draws.
    #[inline]
    pub fn visible(&self, w: DVec3, wm: DVec3) -> f64 {
        let cos = w.z.abs();
        if cos == 0.0 {
            return 0.0;
        }
        self.g1(w) / cos * self.d(wm) * w.dot(wm).abs()
    }

    /// A microfacet normal (in the upper hemisphere) drawn from the normals visible from `w`
    /// (from `−w` when `w` is below the surface) with `u ∈ [0, 1)²`
    /// (Hei18, as pbrt-v4's `TrowbridgeReitzDistribution::Sample_wm`): stretch `w` to the
    /// unit-roughness configuration, sample the projected hemisphere there, and unstretch.
    #[inline]
    pub fn sample_visible(&self, w: DVec3, u: [f64; 2]) -> DVec3 {
        let a = self.alpha;
        let mut wh = DVec3::new(a * w.x, a * w.y, w.z).normalize();
        if wh.z < 0.0 {
            wh = -wh;
        }
        let t1 = if wh.z < 0.99999 {
            DVec3::Z.cross(wh).normalize()
        } else {
            DVec3::X
        };
        let t2 = wh.cross(t1);
        // A uniform point on the disk (polar map), its second coordinate squeezed toward the
        // part of the disk the projected hemisphere covers.
        let r = u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let (px, py) = (r * phi.cos(), r * phi.sin());
        let h = (1.0 - px * px).max(0.0).sqrt();
        let s = 0.5 * (1.0 + wh.z);
        let py = (1.0 - s) * h + s * py;
        let pz = (1.0 - px * px - py * py).max(0.0).sqrt();
        let nh = px * t1 + py * t2 + pz * wh;
        DVec3::new(a * nh.x, a * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use bssrdf_core::chi_square::ChiSquareTest;

    /// `∫ f(ω) dω` over the sphere by the midpoint rule in (cos θ, φ) on `n × 2n` cells.
    fn sphere_integral(n: usize, f: impl Fn(DVec3) -> f64) -> f64 {
        let mut s = 0.0;
        for a in 0..n {
            let cos = 1.0 - 2.0 * (a as f64 + 0.5) / n as f64;
            let sin = (1.0 - cos * cos).sqrt();
            for b in 0..2 * n {
                let phi = PI * (b as f64 + 0.5) / n as f64;
                s += f(DVec3::new(sin * phi.cos(), sin * phi.sin(), cos));
            }
        }
        s * 4.0 * PI / (2 * n * n) as f64
    }

    fn direction(cos: f64, phi: f64) -> DVec3 {
        let sin = (1.0 - cos * cos).sqrt();
        DVec3::new(sin * phi.cos(), sin * phi.sin(), cos)
    }

    /// The normalisation of D, and the "weak white furnace" of Hei14: the
    /// projected area of the visible microfacets equals the macro-surface's,
    /// `∫ G1(ω_o) D(ω_m) max(0, ω_o·ω_m) dω_m = cos θ_o`, for every ω_o and α.
    #[test]
    fn normalisation_and_weak_white_furnace() {
        for alpha in [0.2, 0.3, 0.6, 1.0] {
            let d = TrowbridgeReitz::new(alpha);
            // Fine grid for the peaked small-α densities.
            let n = if alpha < 0.25 { 2000 } else { 800 };
            let norm = sphere_integral(n, |m| if m.z > 0.0 { d.d(m) * m.z } else { 0.0 });
            assert!((norm - 1.0).abs() < 2e-3, "α {alpha}: ∫D cos = {norm}");
            for cos_o in [0.95, 0.6, 0.2] {
                let wo = direction(cos_o, 0.7);
                let proj = sphere_integral(n, |m| {
                    if m.z > 0.0 {
                        d.g1(wo) * d.d(m) * wo.dot(m).max(0.0)
                    } else {
                        0.0
                    }
                });
                assert!(
                    (proj - cos_o).abs() < 3e-3 * cos_o.max(0.3),
                    "α {alpha}, cos {cos_o}: {proj}"
                );
                // And the visible-normal density integrates to 1.
                let vis = sphere_integral(n, |m| {
                    if m.z > 0.0 && wo.dot(m) > 0.0 {
                        d.visible(wo, m)
                    } else {
                        0.0
                    }
                });
                assert!((vis - 1.0).abs() < 3e-3, "α {alpha}, cos {cos_o}: {vis}");
            }
        }
    }

    /// χ² test of the visible-normal sampler against `D_ω`, integrated over (cos θ_m, φ_m)
    /// bins of the upper hemisphere.
    #[test]
    fn visible_normals_follow_their_density() {
        let cases = [(0.2, 0.9), (0.5, 0.3), (1.0, 0.7), (0.35, -0.5)];
        let test = ChiSquareTest::family(1e-4, cases.len() as u32);
        for (k, (alpha, cos_o)) in cases.into_iter().enumerate() {
            let d = TrowbridgeReitz::new(alpha);
            let wo = direction(cos_o, 1.1);
            // Below the surface, the normals are those visible from −w.
            let seen = if wo.z < 0.0 { -wo } else { wo };
            let (nt, np, sub) = (30, 24, 16);
            // Bins uniform in cos θ_m over the upper hemisphere.
            let mut expected = vec![0.0; nt * np];
            for a in 0..nt {
                for b in 0..np {
                    let mut s = 0.0;
                    for c in 0..sub {
                        for e in 0..sub {
                            let cos = 1.0 - (a as f64 + (c as f64 + 0.5) / sub as f64) / nt as f64;
                            let phi =
                                2.0 * PI * (b as f64 + (e as f64 + 0.5) / sub as f64) / np as f64;
                            let m = direction(cos, phi);
                            if seen.dot(m) > 0.0 {
                                s += d.visible(seen, m);
                            }
                        }
                    }
                    expected[a * np + b] =
                        s * (1.0 / nt as f64) * (2.0 * PI / np as f64) / (sub * sub) as f64;
                }
            }
            let n = 300_000;
            let mut counts = vec![0u64; nt * np];
            let mut rng = Rng::from_keys(21, &[k as u64]);
            for _ in 0..n {
                let m = d.sample_visible(wo, rng.uniform2());
                assert!(m.z > 0.0 && (m.length() - 1.0).abs() < 1e-9);
                let a = (((1.0 - m.z) * nt as f64) as usize).min(nt - 1);
                let phi = m.y.atan2(m.x).rem_euclid(2.0 * PI);
                let b = ((phi / (2.0 * PI) * np as f64) as usize).min(np - 1);
                counts[a * np + b] += 1;
            }
            let expected: Vec<f64> = expected.iter().map(|p| p * n as f64).collect();
            let r = test.check(&counts, &expected).unwrap();
            assert!(r.passes(), "α {alpha}, cos {cos_o}: {r}");
        }
    }
}
