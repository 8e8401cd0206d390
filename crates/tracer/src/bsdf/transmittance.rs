//! What light arriving from outside at a rough dielectric boundary does, by direction: the
//! single-scattering albedo E(μ; α) that the energy-conserving lobe divides by, and the
//! fraction T(μ; α) that enters the medium, for the BSSRDF's Fresnel terms
//! (`integrator/bssrdf.rs`).
//!
//! For light arriving from outside at cosine μ (ω_o, `cos θ_o = μ`), with ω_m a normal visible
//! from ω_o and ω_r, ω_t the directions reflected and refracted through it
//! ([`super::RoughDielectric`]):
//!
//! * `E(μ; α) = E[F(ω_o·ω_m) · G(ω_o, ω_r)/G1(ω_o) + (1 − F) · G(ω_o, ω_t)/G1(ω_o)]`, the
//!   single-scattering albedo (each term 0 when its direction leaves to the wrong side);
//! * `T(μ; α) = E[(1 − F) · G(ω_o, ω_t)/G1(ω_o)] / E(μ; α)`, the fraction of the light the
//!   energy-conserving boundary ([`super::RoughDielectric::sample_conserving`]) lets in: the
//!   probability that its sample is a refraction, which is how the camera path realises it.
//!
//! The separable BSSRDF weighs light crossing a smooth boundary by the Fresnel transmittance
//! `1 − F_r(cos θ)` at each end, normalised by `c = 1 − 2 C1(1/η) = 2 ∫₀¹ (1 − F_r(μ)) μ dμ`.
//! Through a rough boundary it takes T at each end (reciprocity of the boundary's flux transfer
//! makes the fraction leaving toward cosine μ of diffuse light inside the same function, up to
//! the η² the normalisation absorbs) and `c(α) = 2 ∫₀¹ T(μ; α) μ dμ`. As α → 0, T → 1 − F_r
//! and c → 1 − 2 C1(1/η).
//!
//! The table holds T and E on a grid of μ (and of α over the material's range of roughness),
//! each value a deterministic quadrature over the visible-normal sampler's unit square
//! (`QUADRATURE²` midpoints); lookups interpolate linearly. Tables are shared by every object
//! and render of one process with the same η and range of α ([`TransmittanceTable::shared`]).

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use glam::DVec3;

use super::RoughDielectric;
use super::dielectric::refract;

/// Nodes in μ ∈ [0, 1].
const MU_NODES: usize = 33;
/// Nodes in α over a range of roughness (one node for a single α).
const ALPHA_NODES: usize = 9;
/// Midpoints per side of the quadrature of each value.
const QUADRATURE: usize = 40;

/// T(μ; α), E(μ; α) and c(α) of one η on a grid (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TransmittanceTable {
    /// The α of each row (increasing; one row when α is constant).
    alphas: Vec<f64>,
    /// `transmitted[row * MU_NODES + k]` = T(k / (MU_NODES − 1); alphas[row]).
    transmitted: Vec<f64>,
    /// The single-scattering albedo E, laid out as `transmitted`.
    albedo: Vec<f64>,
    /// c(α) per row.
    norms: Vec<f64>,
}

/// The single-scattering albedo E and the single-scattering transmitted fraction (before the
/// division by E) of light arriving from outside at cosine `mu` (module docs), by quadrature
/// over the visible normals. At μ = 0 (grazing) the values just above are taken.
pub fn single_scattering(eta: f64, alpha: f64, mu: f64) -> (f64, f64) {
    let mu = mu.clamp(1e-4, 1.0);
    let b = RoughDielectric::new(eta, alpha);
    let d = &b.distribution;
    let wo = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let g1 = d.g1(wo);
    let n = QUADRATURE;
    let (mut albedo, mut transmitted) = (0.0, 0.0);
    for a in 0..n {
        for c in 0..n {
            let u = [(a as f64 + 0.5) / n as f64, (c as f64 + 0.5) / n as f64];
            let m = d.sample_visible(wo, u);
            let cos = wo.dot(m);
            if cos <= 0.0 {
                continue;
            }
            let f = bssrdf_core::fresnel::dielectric(cos, eta);
            let r = -wo + 2.0 * cos * m;
            if r.z > 0.0 {
                albedo += f * d.g(wo, r) / g1;
            }
            if f < 1.0
                && let Some(t) = refract(wo, m, eta)
                && t.z < 0.0
            {
                let w = (1.0 - f) * d.g(wo, t) / g1;
                albedo += w;
                transmitted += w;
            }
        }
    }
    let k = (n * n) as f64;
    (albedo / k, transmitted / k)
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
        let mut transmitted = Vec::with_capacity(rows * MU_NODES);
        let mut albedo = Vec::with_capacity(rows * MU_NODES);
        let mut norms = Vec::with_capacity(rows);
        let h = 1.0 / (MU_NODES - 1) as f64;
        for &alpha in &alphas {
            let mut integral = 0.0;
            for k in 0..MU_NODES {
                let (e, t) = single_scattering(eta, alpha, k as f64 * h);
                let t = if e > 0.0 { t / e } else { 0.0 };
                // c = 2 ∫ T μ dμ by the trapezoid rule over the nodes.
                let w = if k == 0 || k == MU_NODES - 1 {
                    0.5
                } else {
                    1.0
                };
                integral += w * t * k as f64 * h * h;
                transmitted.push(t);
                albedo.push(e);
            }
            norms.push(2.0 * integral);
        }
        Self {
            alphas,
            transmitted,
            albedo,
            norms,
        }
    }

    /// [`TransmittanceTable::new`], built once per process for each `(eta, alpha_lo, alpha_hi)`
    /// and shared (a material's objects, its renders, the camera and light tracers).
    pub fn shared(eta: f64, alpha_lo: f64, alpha_hi: f64) -> Arc<Self> {
        static TABLES: OnceLock<Mutex<HashMap<[u64; 3], Arc<TransmittanceTable>>>> =
            OnceLock::new();
        let key = [eta.to_bits(), alpha_lo.to_bits(), alpha_hi.to_bits()];
        let tables = TABLES.get_or_init(Default::default);
        if let Some(t) = tables.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
            return t.clone();
        }
        // Built outside the lock (tens of milliseconds); a concurrent build of the same key
        // gives the same table.
        let table = Arc::new(Self::new(eta, alpha_lo, alpha_hi));
        tables
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry(key)
            .or_insert(table)
            .clone()
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

    /// Linear interpolation of `values` at (μ, α).
    #[inline]
    fn lookup(&self, values: &[f64], mu: f64, alpha: f64) -> f64 {
        let x = mu.clamp(0.0, 1.0) * (MU_NODES - 1) as f64;
        let k = (x as usize).min(MU_NODES - 2);
        let f = x - k as f64;
        let row = |r: usize| {
            let v = &values[r * MU_NODES..];
            v[k] + f * (v[k + 1] - v[k])
        };
        let (r, w) = self.rows(alpha);
        if w == 0.0 {
            row(r)
        } else {
            row(r) + w * (row(r + 1) - row(r))
        }
    }

    /// T(μ; α): the fraction of the light arriving from outside at cosine μ that the
    /// energy-conserving boundary lets in (α clamped to the table's range).
    #[inline]
    pub fn transmittance(&self, mu: f64, alpha: f64) -> f64 {
        self.lookup(&self.transmitted, mu, alpha)
    }

    /// E(μ; α): the single-scattering albedo of light arriving from outside at cosine μ.
    #[inline]
    pub fn albedo(&self, mu: f64, alpha: f64) -> f64 {
        self.lookup(&self.albedo, mu, alpha)
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
    use crate::bsdf::Lobe;
    use crate::rng::Rng;

    /// The table against the path tracer's own crossings: the fraction of the energy-conserving
    /// sampler's crossings from outside that refract (3 SE + the quadrature's 2e-3), and the
    /// single-scattering albedo against the single-scattering sampler's mean weight; both
    /// toward the smooth boundary's 1 − F, 1 and 1 − 2 C1(1/η) as α → 0.
    #[test]
    fn the_table_matches_sampled_crossings_and_the_smooth_limit() {
        let eta = 1.4;
        let table = TransmittanceTable::new(eta, 0.05, 0.8);
        let mut rng = Rng::from_keys(4, &[]);
        for alpha in [0.05, 0.3, 0.8] {
            let b = RoughDielectric::new(eta, alpha);
            for mu in [0.9f64, 0.5, 0.15] {
                let wo = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let n = 100_000;
                let mut entered = 0;
                let (mut s, mut s2) = (0.0, 0.0);
                for _ in 0..n {
                    let c = b.sample_conserving(wo, &mut rng).unwrap();
                    entered += usize::from(c.lobe == Lobe::Transmission);
                    let w = b
                        .sample(wo, rng.uniform(), rng.uniform2())
                        .map_or(0.0, |x| x.weight);
                    s += w;
                    s2 += w * w;
                }
                let p = entered as f64 / n as f64;
                let t = table.transmittance(mu, alpha);
                let se = (t * (1.0 - t) / n as f64).sqrt();
                assert!(
                    (t - p).abs() < 3.0 * se + 2e-3,
                    "α {alpha}, μ {mu}: table {t}, sampled {p} ± {se}"
                );
                let m = s / n as f64;
                let se = ((s2 / n as f64 - m * m) / n as f64).sqrt();
                let e = table.albedo(mu, alpha);
                assert!(
                    (e - m).abs() < 3.0 * se + 2e-3,
                    "α {alpha}, μ {mu}: albedo {e}, sampled {m} ± {se}"
                );
            }
        }
        let smooth = TransmittanceTable::new(eta, 2e-3, 2e-3);
        for mu in [1.0, 0.7, 0.4, 0.2] {
            let want = 1.0 - bssrdf_core::fresnel::dielectric(mu, eta);
            let got = smooth.transmittance(mu, 2e-3);
            assert!((got - want).abs() < 5e-3, "μ {mu}: {got} vs 1 − F = {want}");
            assert!((smooth.albedo(mu, 2e-3) - 1.0).abs() < 5e-3);
        }
        let c = 1.0 - 2.0 * bssrdf_core::fresnel::fresnel_moment(1, 1.0 / eta);
        assert!(
            (smooth.norm(2e-3) - c).abs() < 5e-3,
            "{} vs {c}",
            smooth.norm(2e-3)
        );
        // The shared table is the table.
        assert_eq!(*TransmittanceTable::shared(eta, 0.05, 0.8), table);
    }
}
