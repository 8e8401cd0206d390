//! Fixed Gauss rules (Gauss–Legendre on [-1, 1], Gauss–Laguerre for `∫₀^∞ e^{-y} f(y) dy`),
//! computed once at first use by Newton iteration on the three-term recurrences
//! (Abramowitz & Stegun 25.4.29–30 and 25.4.45), so no tabulated constants are needed.
//!
//! Internal helper for the profile models; exactness on polynomials is unit-tested.

use std::sync::OnceLock;

/// An `N`-point rule: nodes and weights.
#[derive(Debug)]
pub(crate) struct Rule<const N: usize> {
    pub x: [f64; N],
    pub w: [f64; N],
}

fn legendre<const N: usize>() -> Rule<N> {
    let mut x = [0.0; N];
    let mut w = [0.0; N];
    let n = N as f64;
    for i in 0..N {
        // Initial guess (Tricomi), then Newton on P_N.
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=N {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            let pn = if N == 1 { z } else { p1 };
            let pm = if N == 1 { 1.0 } else { p0 };
            dp = n * (z * pn - pm) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    Rule { x, w }
}

fn laguerre<const N: usize>() -> Rule<N> {
    let mut x = [0.0; N];
    let mut w = [0.0; N];
    let n = N as f64;
    let mut z = 0.0;
    for i in 0..N {
        // Standard initial guesses for the zeros of L_N (Stroud & Secrest), then Newton.
        z = match i {
            0 => 3.0 / (1.0 + 2.4 * n),
            1 => z + 15.0 / (1.0 + 2.5 * n),
            _ => {
                let a = (i - 1) as f64;
                z + (1.0 + 2.55 * a) / (1.9 * a) * (z - x[i - 2])
            }
        };
        let mut dp = 1.0;
        let mut pm = 0.0;
        for _ in 0..200 {
            let (mut p0, mut p1) = (0.0, 1.0);
            for k in 1..=N {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0 - z) * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            pm = p0;
            dp = n * (p1 - p0) / z;
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() <= 1e-15 * z.abs().max(1.0) {
                break;
            }
        }
        x[i] = z;
        w[i] = -1.0 / (dp * n * pm);
    }
    Rule { x, w }
}

/// 8-point Gauss–Legendre on [-1, 1].
pub(crate) fn gl8() -> &'static Rule<8> {
    static R: OnceLock<Rule<8>> = OnceLock::new();
    R.get_or_init(legendre::<8>)
}

/// 12-point Gauss–Legendre on [-1, 1].
pub(crate) fn gl12() -> &'static Rule<12> {
    static R: OnceLock<Rule<12>> = OnceLock::new();
    R.get_or_init(legendre::<12>)
}

/// 32-point Gauss–Legendre on [-1, 1].
pub(crate) fn gl32() -> &'static Rule<32> {
    static R: OnceLock<Rule<32>> = OnceLock::new();
    R.get_or_init(legendre::<32>)
}

/// 16-point Gauss–Laguerre: `∫₀^∞ e^{-y} f(y) dy ≈ Σ w_k f(x_k)`.
pub(crate) fn laguerre16() -> &'static Rule<16> {
    static R: OnceLock<Rule<16>> = OnceLock::new();
    R.get_or_init(laguerre::<16>)
}

/// `∫_a^b f` with an `N`-point Gauss–Legendre rule.
pub(crate) fn integrate<const N: usize>(
    rule: &Rule<N>,
    a: f64,
    b: f64,
    f: impl Fn(f64) -> f64,
) -> f64 {
    let h = 0.5 * (b - a);
    let m = 0.5 * (a + b);
    let mut s = 0.0;
    for k in 0..N {
        s += rule.w[k] * f(m + h * rule.x[k]);
    }
    s * h
}

/// The nodes and weights of a Gauss–Legendre `rule` mapped to `[a, b]`.
pub(crate) fn integrate_nodes<const N: usize>(
    rule: &Rule<N>,
    a: f64,
    b: f64,
) -> impl Iterator<Item = (f64, f64)> + '_ {
    let h = 0.5 * (b - a);
    let m = 0.5 * (a + b);
    (0..N).map(move |k| (m + h * rule.x[k], h * rule.w[k]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legendre_is_exact_on_polynomials() {
        fn check<const N: usize>(r: &Rule<N>) {
            for k in 0..(2 * N) {
                let got: f64 = (0..N).map(|i| r.w[i] * r.x[i].powi(k as i32)).sum();
                let want = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k as f64 + 1.0)
                };
                assert!((got - want).abs() < 1e-13, "N={N} k={k}: {got} vs {want}");
            }
        }
        check(gl8());
        check(&legendre::<16>());
        check(gl32());
    }

    #[test]
    fn laguerre_is_exact_on_polynomials() {
        let r = laguerre16();
        let mut fact = 1.0;
        for k in 0..20 {
            if k > 0 {
                fact *= k as f64;
            }
            let got: f64 = (0..16).map(|i| r.w[i] * r.x[i].powi(k)).sum();
            assert!((got - fact).abs() < 1e-11 * fact, "k={k}: {got} vs {fact}");
        }
        assert!(r.x.windows(2).all(|p| p[0] < p[1]) && r.x[0] > 0.0);
    }
}
