#![allow(dead_code)]
//! Test helpers: a tiny deterministic RNG, an independent brute-force radial integrator and a
//! chi-square goodness-of-fit test for radius samplers.

use crate::chi_square::{ChiSquare, ChiSquareTest};
use crate::profile::RadialProfile;

/// SplitMix64 (Steele, Lea & Flood 2014): deterministic, good enough for tests.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// `∫_a^b f` by composite Simpson with `n` (even) intervals in `ln(x)` when `a > 0`.
/// Written independently of the crate's Gauss rules.
pub fn simpson_log(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let (la, lb) = (a.ln(), b.ln());
    let h = (lb - la) / n as f64;
    let mut s = 0.0;
    for k in 0..=n {
        let x = (la + k as f64 * h).exp();
        let w = if k == 0 || k == n {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        s += w * f(x) * x;
    }
    s * h / 3.0
}

/// Brute-force `∫₀^∞ 2πr R(r) dr` over `[lo, hi]` on a fine logarithmic Simpson grid.
pub fn brute_total(p: &impl RadialProfile, lo: f64, hi: f64) -> f64 {
    simpson_log(
        |r| 2.0 * std::f64::consts::PI * r * p.eval(r),
        lo,
        hi,
        20_000,
    )
}

/// Chi-square test of `sampler.sample_r` against the density `pdf` over radius bins
/// geometric between `lo` and `hi` (plus the two open ends), bins pooled until the expected
/// count is ≥ 5 ([`crate::chi_square`]). Expected bin probabilities come from integrating
/// `pdf` (Simpson, not the sampler's CDF).
pub fn chi_square(
    test: ChiSquareTest,
    sampler: &impl RadialProfile,
    pdf: impl Fn(f64) -> f64,
    lo: f64,
    hi: f64,
    n_samples: usize,
    seed: u64,
) -> ChiSquare {
    let nb = 60;
    let mut edges = vec![0.0];
    for k in 0..=nb {
        edges.push(lo * (hi / lo).powf(k as f64 / nb as f64));
    }
    let mut expected = Vec::new();
    // [0, lo]: linear Simpson.
    let first = {
        let n = 2000;
        let h = lo / n as f64;
        let mut s = 0.0;
        for k in 0..=n {
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            s += w * pdf(k as f64 * h);
        }
        s * h / 3.0
    };
    expected.push(first);
    for k in 1..edges.len() - 1 {
        expected.push(simpson_log(&pdf, edges[k], edges[k + 1], 200));
    }
    let inner: f64 = expected.iter().sum();
    expected.push((1.0 - inner).max(0.0));
    edges.push(f64::INFINITY);
    let mut counts = vec![0u64; expected.len()];
    let mut rng = Rng::new(seed);
    for _ in 0..n_samples {
        let r = sampler.sample_r(rng.uniform()).expect("non-zero profile");
        assert!(r.is_finite() && r >= 0.0);
        let k = edges
            .partition_point(|&e| e <= r)
            .saturating_sub(1)
            .min(counts.len() - 1);
        counts[k] += 1;
    }
    let n = n_samples as f64;
    let expected: Vec<f64> = expected.iter().map(|p| p * n).collect();
    test.check(&counts, &expected).expect("enough bins")
}
