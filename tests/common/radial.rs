//! `∫₀^∞ 2πr R(r) dr` of a radial profile by quadrature on the tabulated profiles' own radial
//! bins (the pieces between which their interpolation changes form), independently of the
//! profiles' closed-form totals.

use bssrdf_core::tabulated::grid::{N_BINS, edge};

/// `∫ 2πr eval(r) dr` for a profile whose optical unit is `sigma_t` (1/length): the first bin,
/// [0, 10⁻³) mean free paths, by the midpoint rule in r (2,000 nodes); every later bin by the
/// midpoint rule in ln r (64 nodes); nothing beyond the last bin (10³ mean free paths).
pub fn radial_integral(eval: impl Fn(f64) -> f64, sigma_t: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let n0 = 2000;
    let first: f64 = (0..n0)
        .map(|k| {
            let r = (k as f64 + 0.5) / n0 as f64 * edge(1) / sigma_t;
            tau * r * eval(r) * edge(1) / sigma_t / n0 as f64
        })
        .sum();
    let rest: f64 = (1..N_BINS)
        .map(|j| {
            let (a, b) = (edge(j).ln(), edge(j + 1).ln());
            let m = 64;
            (0..m)
                .map(|k| {
                    let r = (a + (k as f64 + 0.5) / m as f64 * (b - a)).exp() / sigma_t;
                    tau * r * r * eval(r) * (b - a) / m as f64
                })
                .sum::<f64>()
        })
        .sum();
    first + rest
}
