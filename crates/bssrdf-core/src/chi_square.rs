//! Pearson's χ² goodness-of-fit test for Monte Carlo samplers, shared by every sampler test of
//! the workspace (`docs/physics.md#statistics`).
//!
//! * **Pooling.** Bins whose expected count is below [`MIN_EXPECTED`] are merged with their
//!   neighbours, in the order given, until every pooled bin expects at least that many
//!   samples; a remainder at the end joins the last pooled bin. The statistic then has
//!   (pooled bins − 1) degrees of freedom.
//! * **Multiple tests.** A test that runs `m` checks at family-wise level α uses the Šidák
//!   per-check level `1 − (1 − α)^{1/m}`, so that the whole family fails with probability α
//!   when every sampler is right.
//! * **Critical values** are quantiles of the χ² distribution computed from the regularised
//!   incomplete gamma function (series and Lentz continued fraction, Lanczos ln Γ), not
//!   tabulated and not the Wilson–Hilferty approximation.

/// The smallest expected count of a pooled bin.
pub const MIN_EXPECTED: f64 = 5.0;

/// A family of `tests` χ² checks at family-wise significance `alpha`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChiSquareTest {
    /// Probability that the family rejects correct samplers.
    pub alpha: f64,
    /// Number of checks in the family.
    pub tests: u32,
}

/// The outcome of one check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChiSquare {
    /// Pearson's statistic Σ (O − E)²/E over the pooled bins.
    pub statistic: f64,
    /// Degrees of freedom (pooled bins − 1).
    pub dof: usize,
    /// The per-check significance level (Šidák-corrected).
    pub level: f64,
    /// The upper `level` quantile of χ²(`dof`).
    pub critical: f64,
}

impl ChiSquare {
    /// True when the statistic stays below the critical value.
    pub fn passes(&self) -> bool {
        self.statistic < self.critical
    }
}

impl std::fmt::Display for ChiSquare {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "χ² = {:.2} over {} dof (critical {:.2} at level {:.2e})",
            self.statistic, self.dof, self.critical, self.level
        )
    }
}

impl ChiSquareTest {
    /// One check at significance 1e-4.
    pub const SINGLE: ChiSquareTest = ChiSquareTest::family(1e-4, 1);

    /// `tests` checks at family-wise significance `alpha` ∈ (0, 1).
    pub const fn family(alpha: f64, tests: u32) -> Self {
        Self { alpha, tests }
    }

    /// The Šidák per-check level 1 − (1 − α)^{1/m}.
    pub fn level(&self) -> f64 {
        let m = self.tests.max(1) as f64;
        -(((1.0 - self.alpha).ln()) / m).exp_m1()
    }

    /// Pearson's test of `observed` counts against `expected` counts (same length, in an order
    /// where neighbours may be pooled). `None` when fewer than two pooled bins remain (the
    /// test could not fail) or the input is not a valid set of counts.
    pub fn check(&self, observed: &[u64], expected: &[f64]) -> Option<ChiSquare> {
        if observed.len() != expected.len()
            || expected.iter().any(|e| !(e.is_finite() && *e >= 0.0))
            || !(self.alpha > 0.0 && self.alpha < 1.0)
        {
            return None;
        }
        let mut pooled: Vec<(f64, f64)> = Vec::new();
        let (mut e_acc, mut o_acc) = (0.0, 0.0);
        for (&o, &e) in observed.iter().zip(expected) {
            e_acc += e;
            o_acc += o as f64;
            if e_acc >= MIN_EXPECTED {
                pooled.push((e_acc, o_acc));
                e_acc = 0.0;
                o_acc = 0.0;
            }
        }
        match pooled.last_mut() {
            Some(last) => {
                last.0 += e_acc;
                last.1 += o_acc;
            }
            None => return None,
        }
        if pooled.len() < 2 {
            return None;
        }
        let statistic = pooled.iter().map(|(e, o)| (o - e) * (o - e) / e).sum();
        let dof = pooled.len() - 1;
        let level = self.level();
        Some(ChiSquare {
            statistic,
            dof,
            level,
            critical: critical(dof, level),
        })
    }

    /// [`Self::check`] with equal expected counts (bins of equal probability).
    pub fn check_uniform(&self, observed: &[u64]) -> Option<ChiSquare> {
        let n: u64 = observed.iter().sum();
        let e = n as f64 / observed.len() as f64;
        self.check(observed, &vec![e; observed.len()])
    }
}

/// P(X > x) for X ~ χ²(`dof`): the regularised upper incomplete gamma Q(dof/2, x/2).
pub fn upper_tail(dof: usize, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    gamma_q(0.5 * dof as f64, 0.5 * x)
}

/// The upper `level` quantile of χ²(`dof`): x with P(X > x) = level (bisection on
/// [`upper_tail`], relative accuracy 1e-12).
pub fn critical(dof: usize, level: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, dof.max(1) as f64);
    while upper_tail(dof, hi) > level {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if upper_tail(dof, mid) > level {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms; ~1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x)Γ(1 − x) = π / sin(πx).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (k, c) in C.iter().enumerate().skip(1) {
        a += c / (x + k as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma Q(a, x), a > 0, x ≥ 0: the power series of P for
/// x < a + 1, Lentz's continued fraction for Q otherwise.
fn gamma_q(a: f64, x: f64) -> f64 {
    let prefactor = (a * x.ln() - x - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * prefactor).max(0.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (prefactor * h).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn critical_values_match_published_tables() {
        // Upper quantiles of χ² (NIST/SEMATECH e-Handbook, Table 1.3.6.7.4; 0.05 and 0.001).
        for (dof, level, want) in [
            (1, 0.05, 3.841),
            (10, 0.05, 18.307),
            (19, 0.001, 43.820),
            (20, 0.001, 45.315),
            (39, 0.001, 72.055),
            (100, 0.001, 149.449),
        ] {
            let got = critical(dof, level);
            assert!((got - want).abs() < 1.5e-3, "χ²({dof}) at {level}: {got}");
        }
        // χ²(2) has the closed-form tail e^{−x/2}.
        for x in [0.1, 1.0, 7.0, 30.0] {
            assert!((upper_tail(2, x) - (-0.5 * x).exp()).abs() < 1e-13);
        }
    }

    #[test]
    fn sidak_level_makes_the_family_level_alpha() {
        let t = ChiSquareTest::family(1e-3, 6);
        assert!(((1.0 - t.level()).powi(6) - (1.0 - 1e-3)).abs() < 1e-15);
        assert!((ChiSquareTest::family(0.01, 1).level() - 0.01).abs() < 1e-15);
    }

    #[test]
    fn bins_are_pooled_to_five_expected_and_degenerate_input_is_refused() {
        // Expected 2, 2, 2, 10, 1: pooled into (6), (10 + 1): one degree of freedom.
        let r = ChiSquareTest::SINGLE
            .check(&[6, 0, 0, 11, 0], &[2.0, 2.0, 2.0, 10.0, 1.0])
            .unwrap();
        assert_eq!(r.dof, 1);
        assert!(r.statistic.abs() < 1e-12);
        assert!(ChiSquareTest::SINGLE.check(&[3], &[3.0]).is_none());
        assert!(ChiSquareTest::SINGLE.check(&[3, 4], &[3.0]).is_none());
        // A grossly wrong histogram fails.
        let r = ChiSquareTest::SINGLE
            .check_uniform(&[850, 1150, 1000, 1000])
            .unwrap();
        assert!(!r.passes(), "{r}");
    }
}
