//! The directional transmittance of the rough dielectric boundary, for the BSSRDF's Fresnel
//! terms (`integrator/bssrdf.rs`).
//!
//! The separable BSSRDF weighs light crossing a smooth boundary by the Fresnel transmittance
//! `1 − F_r(cos θ)` at each end. Through a rough boundary the fraction of the light arriving
//! from outside at cosine μ that enters the medium is
//!
//! `T(μ; α, η) = ∫ f_t(ω_o, ω_i) |cos θ_i| dω_i = E[(1 − F(ω_o·ω_m)) · G(ω_o, ω_t) / G1(ω_o)]`
//!
//! over the normals ω_m visible from ω_o (`cos θ_o = μ`), ω_t the direction refracted through
//! ω_m ([`super::RoughDielectric`], whose sampler realises it: the path tracer's weight of a
//! transmitted sample is `G / G1`). By reciprocity of the boundary's flux transfer it is also
//! the fraction of diffuse light inside that leaves toward a direction of cosine μ, up to the
//! η² the BSSRDF's normalisation absorbs; the BSSRDF uses it at both ends, with the
//! normalisation `c(α) = 2 ∫₀¹ T(μ; α) μ dμ` in place of `1 − 2 C1(1/η)` (the smooth value,
//! which `T` and `c` tend to as α → 0).
//!
//! The table holds T on a grid of μ (and of α over the material's range of roughness),
//! each value a deterministic quadrature over the visible-normal sampler's unit square
//! (`QUADRATURE²` midpoints); lookups interpolate linearly.

use glam::DVec3;

use super::{Lobe, RoughDielectric};

/// Nodes in μ ∈ [0, 1].
const MU_NODES: usize = 33;
/// Nodes in α over a range of roughness (one node for a single α).
const ALPHA_NODES: usize = 9;
/// Midpoints per side of the quadrature of each value.
const QUADRATURE: usize = 40;

/// T(μ; α) and c(α) of one η on a grid (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TransmittanceTable {
    /// The α of each row (increasing; one row when α is constant).
    alphas: Vec<f64>,
    /// `values[row * MU_NODES + k]` = T(k / (MU_NODES − 1); alphas[row]).
    values: Vec<f64>,
    /// c(α) per row.
    norms: Vec<f64>,
}

/// T(μ; α, η) by quadrature over the visible normals (module docs). At μ = 0 (grazing) the
/// limit is taken as the value just above.
pub fn directional_transmittance(eta: f64, alpha: f64, mu: f64) -> f64 {
    let mu = mu.clamp(1e-4, 1.0);
    let b = RoughDielectric::new(eta, alpha);
    let wo = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let n = QUADRATURE;
    let mut sum = 0.0;
    for a in 0..n {
        for c in 0..n {
            let u = [(a as f64 + 0.5) / n as f64, (c as f64 + 0.5) / n as f64];
            // The transmission lobe alone: its weight times the probability of choosing it
            // (uc = 1 − ε never reflects unless F = 1).
            let m = b.distribution.sample_visible(wo, u);
            let f = bssrdf_core::fresnel::dielectric(wo.dot(m), eta);
            if f >= 1.0 {
                continue;
            }
            if let Some(s) = b.sample(wo, 1.0 - f64::EPSILON, u)
                && s.lobe == Lobe::Transmission
            {
                sum += (1.0 - f) * s.weight;
            }
        }
    }
    sum / (n * n) as f64
}

impl TransmittanceTable {
    /// The table of relative index `eta` (> 1) for roughness α in `[alpha_lo, alpha_hi]`
    /// (both ≥ [`super::SMOOTH_ALPHA`]; equal for a constant roughness).
    pub fn new(eta: f64, alpha_lo: f64, alpha_hi: f64) -> Self {
        let rows = if alpha_hi > alpha_lo { ALPHA_NODES } else { 1 };
        let alphas: Vec<f64> = (0..rows)
            .map(|r| {
                if rows == 1 {
                    alpha_lo
                } else {
                    alpha_lo + (alpha_hi - alpha_lo) * r as f64 / (rows - 1) as f64
                }
            })
            .collect();
        let mut values = Vec::with_capacity(rows * MU_NODES);
        let mut norms = Vec::with_capacity(rows);
        for &alpha in &alphas {
            let row: Vec<f64> = (0..MU_NODES)
                .map(|k| directional_transmittance(eta, alpha, k as f64 / (MU_NODES - 1) as f64))
                .collect();
            // c = 2 ∫ T μ dμ by the trapezoid rule over the nodes.
            let h = 1.0 / (MU_NODES - 1) as f64;
            let integral: f64 = (0..MU_NODES)
                .map(|k| {
                    let w = if k == 0 || k == MU_NODES - 1 {
                        0.5
                    } else {
                        1.0
                    };
                    w * row[k] * k as f64 * h
                })
                .sum::<f64>()
                * h;
            norms.push(2.0 * integral);
            values.extend(row);
        }
        Self {
            alphas,
            values,
            norms,
        }
    }

    /// The row below `alpha` and the weight of the row above (0 for one row).
    #[inline]
    fn rows(&self, alpha: f64) -> (usize, f64) {
        let n = self.alphas.len();
        if n == 1 {
            return (0, 0.0);
        }
        let (lo, hi) = (self.alphas[0], self.alphas[n - 1]);
        let x = ((alpha - lo) / (hi - lo)).clamp(0.0, 1.0) * (n - 1) as f64;
        let r = (x as usize).min(n - 2);
        (r, x - r as f64)
    }

    /// T(μ; α) (linear interpolation; α clamped to the table's range).
    #[inline]
    pub fn transmittance(&self, mu: f64, alpha: f64) -> f64 {
        let x = mu.clamp(0.0, 1.0) * (MU_NODES - 1) as f64;
        let k = (x as usize).min(MU_NODES - 2);
        let f = x - k as f64;
        let row = |r: usize| {
            let v = &self.values[r * MU_NODES..];
            v[k] + f * (v[k + 1] - v[k])
        };
        let (r, w) = self.rows(alpha);
        if w == 0.0 {
            row(r)
        } else {
            row(r) + w * (row(r + 1) - row(r))
        }
    }

    /// c(α) = 2 ∫₀¹ T(μ; α) μ dμ (linear interpolation in α).
    #[inline]
    pub fn norm(&self, alpha: f64) -> f64 {
        let (r, w) = self.rows(alpha);
        if w == 0.0 {
            self.norms[r]
        } else {
            self.norms[r] + w * (self.norms[r + 1] - self.norms[r])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The table against the path tracer's own estimate of the same fraction: sampled
    /// crossings from outside, transmitted with their weight (3 SE + the quadrature's 2e-3);
    /// and toward the smooth boundary's 1 − F and 1 − 2 C1(1/η) as α → 0.
    #[test]
    fn transmittance_matches_sampled_crossings_and_the_smooth_limit() {
        let eta = 1.4;
        let table = TransmittanceTable::new(eta, 0.05, 0.8);
        let mut rng = Rng::from_keys(4, &[]);
        for alpha in [0.05, 0.3, 0.8] {
            let b = RoughDielectric::new(eta, alpha);
            for mu in [0.9f64, 0.5, 0.15] {
                let wo = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let n = 200_000;
                let (mut s, mut s2) = (0.0, 0.0);
                for _ in 0..n {
                    let w = match b.sample(wo, rng.uniform(), rng.uniform2()) {
                        Some(x) if x.lobe == Lobe::Transmission => x.weight,
                        _ => 0.0,
                    };
                    s += w;
                    s2 += w * w;
                }
                let m = s / n as f64;
                let se = ((s2 / n as f64 - m * m) / n as f64).sqrt();
                let t = table.transmittance(mu, alpha);
                assert!(
                    (t - m).abs() < 3.0 * se + 2e-3,
                    "α {alpha}, μ {mu}: table {t}, sampled {m} ± {se}"
                );
            }
        }
        let smooth = TransmittanceTable::new(eta, 2e-3, 2e-3);
        for mu in [1.0, 0.7, 0.4, 0.2] {
            let want = 1.0 - bssrdf_core::fresnel::dielectric(mu, eta);
            let got = smooth.transmittance(mu, 2e-3);
            assert!((got - want).abs() < 5e-3, "μ {mu}: {got} vs 1 − F = {want}");
        }
        let c = 1.0 - 2.0 * bssrdf_core::fresnel::fresnel_moment(1, 1.0 / eta);
        assert!(
            (smooth.norm(2e-3) - c).abs() < 5e-3,
            "{} vs {c}",
            smooth.norm(2e-3)
        );
        // Rougher boundaries let less light through at normal incidence (more is dropped)
        // and more at grazing incidence (the microfacets face it).
        assert!(table.transmittance(1.0, 0.8) < table.transmittance(1.0, 0.05));
        assert!(table.transmittance(0.1, 0.8) > table.transmittance(0.1, 0.05));
    }
}
