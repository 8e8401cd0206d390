//! Chandrasekhar's H-function for isotropic scattering (Cha50, Ch. V), computed here
//! independently of the renderer: Nyström iteration of
//! `1/H(μ) = √(1−ϖ) + (ϖ/2) ∫₀¹ μ' H(μ') / (μ + μ') dμ'` on Gauss–Legendre nodes, whose nodes
//! and weights are themselves computed by Newton's method on the Legendre polynomials.
//!
//! Exact results built on it (docs/physics.md#half-space): the plane albedo of a half-space at normal
//! incidence `A = 1 − H(1)·√(1−ϖ)`, the single-scattering part `(ϖ/2)(1 − ln 2)`, and the
//! multiple-scattering part `A − R_ss`.

/// Gauss–Legendre nodes and weights on [0, 1].
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-15 {
                break;
            }
        }
        x[i] = 0.5 * (1.0 - z);
        w[i] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// H(μ; ϖ) for 0 ≤ ϖ < 1.
pub fn h(omega: f64, mu: f64) -> f64 {
    h_function(omega)(mu)
}

/// H(·; ϖ) for 0 ≤ ϖ < 1, solved once: evaluating the returned function at any μ costs one
/// quadrature sum.
pub fn h_function(omega: f64) -> impl Fn(f64) -> f64 {
    let (x, w) = gauss_legendre(200);
    let nodes = x.clone();
    let s = (1.0 - omega).sqrt();
    // The right-hand side 1/(√(1−ϖ) + (ϖ/2) ∫ μ' H(μ') / (μ + μ') dμ') for the nodal values `hk`.
    let rhs = move |mu: f64, hk: &[f64]| -> f64 {
        let integral: f64 = x
            .iter()
            .zip(&w)
            .zip(hk)
            .map(|((&mj, &wj), &hj)| wj * mj * hj / (mu + mj))
            .sum();
        1.0 / (s + 0.5 * omega * integral)
    };
    let mut hk = vec![1.0; nodes.len()];
    for _ in 0..10_000 {
        let next: Vec<f64> = nodes.iter().map(|&m| rhs(m, &hk)).collect();
        let diff = next
            .iter()
            .zip(&hk)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        hk = next;
        if diff < 1e-14 {
            break;
        }
    }
    move |mu: f64| rhs(mu, &hk)
}

/// Plane albedo of an isotropic, index-matched half-space at normal incidence.
pub fn half_space_albedo(omega: f64) -> f64 {
    1.0 - h(omega, 1.0) * (1.0 - omega).sqrt()
}

/// Radiance leaving an isotropic, index-matched half-space along the direction with cosine
/// `mu` (to the normal), lit by a collimated beam at cosine `mu0` whose irradiance on a surface
/// perpendicular to it is 1: `I = ϖ μ0 H(μ) H(μ0) / (4π (μ + μ0))` (Cha50, the diffuse
/// reflection law for isotropic scattering, with πF = 1). Returns (all orders, single only).
pub fn emergent_radiance(omega: f64, mu: f64, mu0: f64) -> (f64, f64) {
    let single = omega * mu0 / (4.0 * std::f64::consts::PI * (mu + mu0));
    (single * h(omega, mu) * h(omega, mu0), single)
}

/// Single-scattering reflectance at normal incidence, isotropic phase, index-matched.
pub fn single_scattering_albedo(omega: f64) -> f64 {
    0.5 * omega * (1.0 - std::f64::consts::LN_2)
}

#[test]
fn h_function_satisfies_its_zeroth_moment_identity() {
    // ∫₀¹ H dμ = (2/ϖ)(1 − √(1 − ϖ)), a consequence of the integral equation (Cha50).
    for omega in [0.5, 0.9, 0.99] {
        let (x, w) = gauss_legendre(64);
        let m0: f64 = x.iter().zip(&w).map(|(&m, &wi)| wi * h(omega, m)).sum();
        let want = 2.0 / omega * (1.0 - (1.0 - omega).sqrt());
        // H behaves like μ ln μ near 0, which limits the quadrature to ~1e-8.
        assert!((m0 - want).abs() < 1e-7, "ϖ={omega}: {m0} vs {want}");
    }
}

#[test]
fn h_function_matches_the_notes_independent_values() {
    // H(1) computed outside this repository (docs/physics.md#half-space, two independent methods).
    for (omega, h1) in [(0.5, 1.25125956), (0.9, 1.85009852), (0.99, 2.47279283)] {
        assert!(
            (h(omega, 1.0) - h1).abs() < 2e-8,
            "ϖ={omega}: {}",
            h(omega, 1.0)
        );
    }
}
