//! A guided azimuthal density for the normal probe ([`crate::probe`], "Guided azimuths"):
//! where the caller knows which way from x_o the integrand leans (the tabulated profile's
//! oblique shape, whose forward shift makes the BSSRDF a product of clamped Fourier series in
//! the azimuth of x_i about x_o: docs/oblique-incidence.md), the normal probe draws its
//! azimuth from that shape, tabulated over [`AZIMUTH_BINS`] equal bins and mixed defensively
//! with the uniform azimuth (Hesterberg 1995, key `Hes95` in docs/references.md; Veach 1997
//! §9.2), and the probe density carries the mixture's exact density (1/radian), so the
//! estimate stays unbiased whatever the guide says.
//!
//! The shape is the caller's ([`AzimuthGuide`]): per colour channel and projected radius r
//! (length), up to two factors max(0, 1 + Σ_n a_n cos n(φ − φ_j)), n = 1, 2, 3, each about
//! its own direction in x_o's tangent plane. g, the guided part, is piecewise constant: its
//! value in a bin is the product at the bin's midpoint, divided by the sum over the bins.

use std::f64::consts::TAU;

use glam::DVec3;

/// Equal bins of the guided part's piecewise-constant density over [0, 2π).
pub const AZIMUTH_BINS: usize = 64;
/// The share β of the azimuths drawn from the guided part (the rest uniform): a defensive
/// mixture, so that the density is at least (1 − β)/(2π) everywhere. On the scenes of
/// docs/oblique-incidence.md ("Sampling") β = 0.9 was quieter than ½ where the guide was
/// good and noisier where it was a rough proxy; ½ is the safe choice.
pub const GUIDED_SHARE: f64 = 0.5;

/// What the caller knows at x_o: the preferred azimuthal shape of the points around it, a
/// product of up to two clamped Fourier series Π_j max(0, 1 + Σ_n a_jn cos n(φ − φ_j)),
/// n = 1, 2, 3, each about its own direction φ_j (the oblique shape's two sides, in the
/// renderer: docs/oblique-incidence.md).
pub trait AzimuthGuide {
    /// The directions of φ_j (any vectors; their projections on x_o's tangent plane are used,
    /// and a factor whose projection is 0 or not finite is left out).
    fn directions(&self) -> [DVec3; 2];
    /// The amplitudes a_jn (unitless) of the two factors for channel `channel` (0, 1, 2) at
    /// projected distance `r` (length) from x_o. A factor with a non-finite amplitude is left
    /// out.
    fn amplitudes(&self, channel: usize, r: f64) -> [[f64; 3]; 2];
}

/// The density p(φ) = (1 − β)/(2π) + β g(φ) (1/radian) of an azimuth φ measured in x_o's
/// frame, β = [`GUIDED_SHARE`], g piecewise constant over [`AZIMUTH_BINS`] equal bins, each
/// bin's value ∝ the guide's product of clamped series at its midpoint; uniform where that is
/// 0 everywhere or not finite. A defensive mixture (Hesterberg 1995, key `Hes95` in
/// docs/references.md): p ≥ (1 − β)/(2π) everywhere, so the estimate stays unbiased and its
/// weights bounded by 2π/(1 − β) times the uniform azimuth's whatever the guide says.
#[derive(Debug, Clone)]
pub struct AzimuthDensity {
    /// Cumulative bin values, `cum[k]` the sum of the first k (cum[0] = 0); `None`: uniform.
    cum: Option<[f64; AZIMUTH_BINS + 1]>,
}

fn midpoint_angles() -> &'static [(f64, f64); AZIMUTH_BINS] {
    static SC: std::sync::OnceLock<[(f64, f64); AZIMUTH_BINS]> = std::sync::OnceLock::new();
    SC.get_or_init(|| {
        std::array::from_fn(|k| (TAU * (k as f64 + 0.5) / AZIMUTH_BINS as f64).sin_cos())
    })
}

impl AzimuthDensity {
    /// The density of the factors `factors` (each its direction's angle φ_j in x_o's frame
    /// and its amplitudes a_jn; see the type); no factor, or only zero amplitudes, is the
    /// uniform density.
    pub fn new(factors: &[(f64, [f64; 3])]) -> Self {
        let used = |(phi0, a): &&(f64, [f64; 3])| {
            phi0.is_finite() && a.iter().all(|v| v.is_finite()) && *a != [0.0; 3]
        };
        if !factors.iter().any(|f| used(&f)) {
            return Self { cum: None };
        }
        let mid = midpoint_angles();
        let mut value = [1.0f64; AZIMUTH_BINS];
        for (phi0, a) in factors.iter().filter(used) {
            let (s0, c0) = phi0.sin_cos();
            for (v, &(s, c)) in value.iter_mut().zip(mid) {
                // cos(φ − φ0), and cos 2(φ − φ0), cos 3(φ − φ0) by Chebyshev.
                let u = c * c0 + s * s0;
                let series =
                    1.0 + a[0] * u + a[1] * (2.0 * u * u - 1.0) + a[2] * (4.0 * u * u - 3.0) * u;
                *v *= series.max(0.0);
            }
        }
        let mut cum = [0.0; AZIMUTH_BINS + 1];
        for k in 0..AZIMUTH_BINS {
            cum[k + 1] = cum[k] + value[k];
        }
        let total = cum[AZIMUTH_BINS];
        Self {
            cum: (total > 0.0 && total.is_finite()).then_some(cum),
        }
    }

    /// p(φ) (1/radian) at `phi` (any angle; taken modulo 2π).
    pub fn pdf(&self, phi: f64) -> f64 {
        let uniform = 1.0 / TAU;
        let Some(cum) = &self.cum else {
            return uniform;
        };
        let t = phi.rem_euclid(TAU) / TAU * AZIMUTH_BINS as f64;
        let k = (t as usize).min(AZIMUTH_BINS - 1);
        let g = (cum[k + 1] - cum[k]) / cum[AZIMUTH_BINS] * (AZIMUTH_BINS as f64 / TAU);
        (1.0 - GUIDED_SHARE) * uniform + GUIDED_SHARE * g
    }

    /// An azimuth in [0, 2π) from one uniform number `u` in [0, 1): below 1 − β uniform,
    /// else by inverting g's cumulative distribution.
    pub fn sample(&self, u: f64) -> f64 {
        let Some(cum) = &self.cum else {
            return TAU * u;
        };
        let beta = GUIDED_SHARE;
        if u < 1.0 - beta {
            return TAU * u / (1.0 - beta);
        }
        let v = ((u - (1.0 - beta)) / beta).clamp(0.0, 1.0);
        let target = v * cum[AZIMUTH_BINS];
        // The bin holding `target`: the last k with cum[k] ≤ target, moved down past empty
        // bins at the top.
        let mut k = cum
            .partition_point(|&c| c <= target)
            .saturating_sub(1)
            .min(AZIMUTH_BINS - 1);
        while k > 0 && cum[k + 1] - cum[k] <= 0.0 {
            k -= 1;
        }
        let w = cum[k + 1] - cum[k];
        let f = if w > 0.0 {
            ((target - cum[k]) / w).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let phi = TAU * (k as f64 + f) / AZIMUTH_BINS as f64;
        if phi < TAU { phi } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SplitMix64, UniformSource};
    use bssrdf_core::chi_square::ChiSquareTest;

    const CASES: [&[(f64, [f64; 3])]; 6] = [
        &[],
        &[(0.0, [0.4, 0.0, 0.0])],
        &[(1.0, [0.9, 0.3, -0.2])],
        // A series that goes negative: clamped at 0 over part of the circle.
        &[(-2.0, [2.5, 1.2, 0.6])],
        &[(0.3, [-1.8, 0.0, 0.9])],
        // Two factors about different directions.
        &[(0.3, [1.5, 0.5, 0.2]), (2.5, [0.8, -0.4, 0.3])],
    ];

    /// The density integrates to 1 over [0, 2π) and is at least (1 − β)/(2π) everywhere.
    #[test]
    fn azimuth_density_is_normalised_and_defensive() {
        for a in CASES {
            let d = AzimuthDensity::new(a);
            let n = 100 * AZIMUTH_BINS;
            let sum: f64 = (0..n)
                .map(|k| d.pdf(TAU * (k as f64 + 0.5) / n as f64) * TAU / n as f64)
                .sum();
            assert!((sum - 1.0).abs() < 1e-12, "{a:?}: {sum}");
            for k in 0..n {
                let p = d.pdf(TAU * k as f64 / n as f64 - 3.0 * TAU);
                assert!(p >= (1.0 - GUIDED_SHARE) / TAU - 1e-15, "{a:?}");
            }
        }
    }

    /// The sampled azimuths follow the density: a χ² test over its bins (fixed seed).
    #[test]
    fn azimuth_samples_follow_their_density() {
        let test = ChiSquareTest::family(1e-4, CASES.len() as u32);
        let mut rng = SplitMix64::new(43);
        let n = 200_000;
        for a in CASES {
            let d = AzimuthDensity::new(a);
            // Two test bins per bin of the density: within-bin uniformity is tested too.
            let bins = 2 * AZIMUTH_BINS;
            let mut observed = vec![0u64; bins];
            for _ in 0..n {
                let phi = d.sample(rng.next_f64());
                assert!((0.0..TAU).contains(&phi), "{a:?}: {phi}");
                observed[((phi / TAU * bins as f64) as usize).min(bins - 1)] += 1;
            }
            let expected: Vec<f64> = (0..bins)
                .map(|k| {
                    let phi = TAU * (k as f64 + 0.5) / bins as f64;
                    n as f64 * d.pdf(phi) * TAU / bins as f64
                })
                .collect();
            let chi = test.check(&observed, &expected).expect("a test");
            assert!(chi.passes(), "{a:?}: {chi}");
        }
    }
}
