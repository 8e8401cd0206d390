//! Photon beam diffusion, multiple-scattering term (HCJ13, as implemented in pbrt-v3/v4
//! `BeamDiffusionMS`; docs/physics.md#beam-diffusion).
//!
//! # Model
//! A pencil beam at normal incidence is replaced by a line of isotropic first-scatter sources
//! with density `σs' e^{−σt' z}` along depth `z`; each is a dipole with Grosjean's diffusion
//! coefficient and the modified (dEI11) boundary condition. With `D = (2σa + σs')/(3σt'²)`,
//! `σtr = √(σa/D)`, `A = (1 + 3C₂)/(1 − 2C₁)`, `c_φ = (1 − 2C₁)/4`, `c_E = (1 − 3C₂)/2`,
//! image at `z_v = −(z + 4AD)`:
//!
//! `MS(r) = α'² ∫₀^∞ σt' e^{−σt' z} κ(z, r) [c_φ φ_D(z, r) + c_E E_n(z, r)] dz`,
//! `φ_D = (e^{−σtr d_r}/d_r − e^{−σtr d_v}/d_v)/(4πD)`,
//! `E_n = (z(1+σtr d_r)e^{−σtr d_r}/d_r³ + |z_v|(1+σtr d_v)e^{−σtr d_v}/d_v³)/(4π)`,
//! `κ = 1 − e^{−2σt'(d_r + z)}` (near-source correction).
//!
//! # Quadrature (deviation from pbrt, on purpose)
//! pbrt sums 100 stratified midpoints of the exponential depth distribution; that rule is
//! 5 % off at `r = 0.001` (docs/physics.md#beam-diffusion). Here, in optical units `x = σt' r`, `ζ = σt' z`, the
//! integral `∫₀^∞ e^{−ζ} H(ζ) dζ` is split into
//! * `ζ ∈ [0, 2]`: the integrand has a feature of width `x` and, for `x ≪ 1`, a `1/ζ`
//!   shoulder for `x ≪ ζ ≪ 1` (the source of the logarithmic divergence at `r → 0`), so it is
//!   integrated in `w = ln(1 + ζ/c)`, `c = min(x, 1)`, which makes it smooth, with 8-point
//!   Gauss–Legendre panels of width ≤ 2 in `w` (`⌈ln(1 + 2/c)/2⌉` panels);
//! * `ζ ∈ [2, ∞)`: 16-point Gauss–Laguerre, the integrand being smooth on the unit scale.
//!
//! This reproduces the adaptive-quadrature ("exact") values of docs/physics.md#beam-diffusion to < 5e-7 relative at
//! `rσt ≥ 0.1` and a brute-force depth integral to < 1e-5 at `rσt = 0.01` (unit tests), with
//! 24 (`x ≥ 1`) to 40 (`x = 0.01`) integrand evaluations per `eval` (≈ 1.3–3.3 µs). The totals agree with
//! the totals listed there for pbrt's 100-sample rule (0.05124, 0.33613, 0.68920, 0.85238 for
//! ϖ = 0.5 … 0.999) to the 5 digits given: that rule's error sits at `rσt < 0.1`, where little
//! energy is.
//!
//! # Units, validity, extremes
//! `r` in length, `MS` in 1/length²; `MS(r) = σt'² MS₁(σt' r)`. The model overshoots the exact
//! half-space albedo by 12–33 % (docs/physics.md#beam-diffusion), so do not expect `total ≤ 1` near `α' = 1`.
//! At `r → 0` it diverges like `ln(1/r)` (docs/physics.md#hazards); `eval` evaluates at
//! `max(r, 1e-6/σt')`, i.e. returns the finite value at one millionth of a reduced mean free
//! path for smaller radii (`2πr·MS → 0` there, so no energy is affected). `σa = 0` gives an
//! algebraic tail. `total` and `radius_for_fraction` are numerical (≈ 0.4 ms); the renderer
//! should use [`crate::table::ProfileTable`] for sampling, totals and radii.
//! Radius sampling uses a closed-form proposal: 85 % the better dipole's exact radial
//! distribution (same `D`, `A`, `σtr`, real source at `z = 1/σt'`) and 15 % an exponential of
//! rate `σt'`, whose density is returned by `pdf_r` exactly.

use crate::better_dipole::BetterDipole;
use crate::dipole_pair::DipolePair;
use crate::fresnel::FresnelMoments;
use crate::profile::{
    Exponential, RadialProfile, TWO_PI, clean_f, clean_u, numeric_radius_for_fraction,
    numeric_total, optical,
};
use crate::quadrature::{gl8, laguerre16};
use std::f64::consts::PI;

/// Largest panel width in `w = ln(1 + y/c)` (the integrands are smooth on the unit scale in
/// `w`; 8-point Gauss–Legendre on width 2 is accurate to ~1e-7 for them, unit-tested).
const PANEL_W: f64 = 2.0;

/// Smallest optical radius at which the divergent PBD terms are evaluated.
pub(crate) const X_FLOOR: f64 = 1e-6;

/// `∫₀^∞ e^{−y} f(y) dy` for an integrand with a feature of width `c` near `y = 0`:
/// `[0, a]` in `w = ln(1 + y/c)` with 8-point Gauss–Legendre panels of width ≤ 2 (the first
/// panel in `w = w₁s²` when `sqrt_edge`, for integrands that start like `√y`), `[a, ∞)` by
/// 16-point Gauss–Laguerre.
pub(crate) fn depth_integral(c: f64, a: f64, sqrt_edge: bool, f: impl Fn(f64) -> f64) -> f64 {
    let mut sum = 0.0;
    if a > 0.0 {
        let wmax = (a / c).ln_1p();
        let n = ((wmax / PANEL_W).ceil() as usize).max(1);
        let h = wmax / n as f64;
        let g = gl8();
        for k in 0..n {
            let w0 = k as f64 * h;
            let mut part = 0.0;
            for i in 0..8 {
                let t = 0.5 * (g.x[i] + 1.0); // in [0, 1]
                let (w, jac) = if k == 0 && sqrt_edge {
                    (h * t * t, 2.0 * h * t)
                } else {
                    (w0 + h * t, h)
                };
                let y = c * w.exp_m1();
                part += g.w[i] * 0.5 * jac * (-y).exp() * f(y) * (y + c);
            }
            sum += part;
        }
    }
    let l = laguerre16();
    let ea = (-a).exp();
    let mut tail = 0.0;
    for i in 0..16 {
        tail += l.w[i] * f(a + l.x[i]);
    }
    sum + ea * tail
}

/// The photon-beam-diffusion multiple-scattering profile for one set of coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamDiffusionMs {
    alpha_p: f64,
    /// 4AD in optical units.
    four_ad: f64,
    sigma_tr: f64,
    /// α'² c_φ / D.
    k_phi: f64,
    /// α'² c_E.
    k_e: f64,
    /// The better dipole with the same constants: sampling proposal.
    proposal: DipolePair,
    /// σt' (1/length).
    scale: f64,
}

impl BeamDiffusionMs {
    /// PBD-MS for reduced albedo `alpha_p ∈ (0, 1]`, reduced extinction `sigma_t_p > 0`
    /// (1/length) and the material's Fresnel moments. No allocation, no quadrature.
    pub fn new(alpha_p: f64, sigma_t_p: f64, moments: &FresnelMoments) -> Self {
        let pair = BetterDipole::pair_at_depth(alpha_p, moments, 1.0);
        Self {
            alpha_p,
            four_ad: pair.z_v - 1.0,
            sigma_tr: pair.sigma,
            k_phi: pair.k_phi,
            k_e: pair.k_e,
            proposal: pair,
            scale: sigma_t_p,
        }
    }

    /// Reduced albedo α'.
    pub fn alpha_p(&self) -> f64 {
        self.alpha_p
    }

    /// Effective transport coefficient `σtr = √(σa/D_G)` in 1/length.
    pub fn sigma_tr(&self) -> f64 {
        self.sigma_tr * self.scale
    }

    /// Depth integrand `κ(c_φφ_D + c_E E_n)·α'²` at optical depth `z`, squared radius `x2`.
    #[inline]
    fn integrand(&self, x2: f64, z: f64) -> f64 {
        let s = self.sigma_tr;
        let zv = z + self.four_ad;
        let dr = (x2 + z * z).sqrt();
        let dv = (x2 + zv * zv).sqrt();
        let delta = self.four_ad * (z + zv) / (dv + dr);
        let er = (-s * dr).exp();
        let em1 = (-s * delta).exp_m1(); // e^{−σΔ} − 1
        let ev = er * (1.0 + em1); // e^{−σ d_v}
        let phi = self.k_phi * er * (delta / (dr * dv) - em1 / dv);
        let e_n = self.k_e
            * (z * (1.0 + s * dr) * er / (dr * dr * dr)
                + zv * (1.0 + s * dv) * ev / (dv * dv * dv));
        let kappa = -(-2.0 * (dr + z)).exp_m1();
        kappa * (phi + e_n) * (1.0 / (4.0 * PI))
    }

    /// `MS₁(x)` in optical units (σt' = 1).
    pub(crate) fn eval_optical(&self, x: f64) -> f64 {
        let x = x.max(X_FLOOR);
        let x2 = x * x;
        depth_integral(x.min(1.0), 2.0, false, |z| self.integrand(x2, z))
    }

    /// Total of the better dipole with the same constants (within tens of % of PBD's): a
    /// cheap mixture weight.
    pub(crate) fn proposal_total(&self) -> f64 {
        self.proposal.total()
    }

    fn proposal_pdf(&self, x: f64) -> f64 {
        0.85 * self.proposal.pdf(x) + 0.15 * Exponential { rate: 1.0 }.pdf(x)
    }
}

impl RadialProfile for BeamDiffusionMs {
    fn eval(&self, r: f64) -> f64 {
        self.scale * self.scale * self.eval_optical(optical(r, self.scale))
    }
    fn total(&self) -> f64 {
        numeric_total(|x| TWO_PI * x * self.eval_optical(x))
    }
    fn sample_r(&self, u: f64) -> Option<f64> {
        let u = clean_u(u)?;
        let x = if u < 0.85 {
            self.proposal.quantile(u / 0.85)
        } else {
            Exponential { rate: 1.0 }.sample((u - 0.85) / 0.15)
        };
        Some(x / self.scale)
    }
    fn pdf_r(&self, r: f64) -> f64 {
        self.scale * self.proposal_pdf(optical(r, self.scale))
    }
    fn radius_for_fraction(&self, f: f64) -> f64 {
        let f = clean_f(f);
        numeric_radius_for_fraction(|x| TWO_PI * x * self.eval_optical(x), f) / self.scale
    }
}
