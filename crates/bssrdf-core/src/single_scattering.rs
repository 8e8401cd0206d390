//! Single-scattering radial profile of photon beam diffusion (HCJ13 as in pbrt-v3/v4
//! `BeamDiffusionSS`; docs/physics.md#beam-diffusion). Usable with every model through
//! [`crate::Scattering`].
//!
//! # Model
//! Normal incidence; the beam scatters once at depth `t` and leaves towards the exit point at
//! distance `d = √(r² + t²)` with cosine `μ = t/d` to the normal:
//!
//! `SS(r) = σs ∫_{t_c}^∞ e^{−σt(t + d)}/d² · p_HG(−μ; g) · (1 − F_r(μ; η)) · μ dt`,
//! `t_c = r√(η² − 1)` (below it the exit ray is totally internally reflected).
//!
//! `p_HG(−μ)` is Henyey–Greenstein at the physical scattering cosine (backscatter towards the
//! exit point; pbrt writes it as `HenyeyGreenstein(t/d, g)` in its opposite sign convention),
//! `F_r(μ; η)` the exact dielectric reflectance for light inside hitting the boundary. For
//! `η = 1` this is the exact single-scattering exitance of a half-space (docs/physics.md#half-space); for
//! `η > 1` it neglects the refraction of the incident beam, like pbrt.
//!
//! Total (derived here by integrating over the exit plane in polar coordinates around the
//! scattering point): `SS_tot = 2πϖ ∫_{μ_c}^1 p_HG(−μ)(1 − F_r(μ))·μ/(1+μ) dμ`, which is
//! `(ϖ/2)(1 − ln 2)` for `η = 1`, `g = 0` (docs/physics.md#half-space). It is evaluated in the HG CDF variable
//! (so that strongly peaked phase functions are integrated exactly) with a square-root
//! substitution at the TIR edge, 64 Gauss–Legendre nodes.
//!
//! # Quadrature of the profile
//! Optical units `x = σt r`, depth `τ = τ_c + y`: `∫₀^∞ e^{−y}(…)dy` with the same split as
//! the multiple-scattering term ([`crate::beam_diffusion`]): `y ∈ [0, 1]` in
//! `w = ln(1 + y/min(x, 1))` (first panel square-root substituted for the TIR edge), then
//! Gauss–Laguerre. The factor `e^{−x}` is taken out (`d − x = τ²/(d + x)`), so large `r`
//! underflows cleanly. Reproduces the "exact" values of docs/physics.md#beam-diffusion to < 1e-5 relative for `rσt ≥ 0.01`.
//!
//! # Units and extremes
//! `SS` in 1/length²; `SS(r) = σt² SS₁(σt r)` with `ϖ = σs/σt`. Diverges like `σs/(4πr)` as
//! `r → 0` (`2πr·SS → σs/2` for η = 1, g = 0); `eval` evaluates at `max(r, 1e-6/σt)`.
//! Radius sampling uses the exponential proposal `σt e^{−σt r}` (the weight
//! `2πr SS/pdf` is bounded), returned exactly by `pdf_r`.

use crate::beam_diffusion::{X_FLOOR, depth_integral};
use crate::fresnel::dielectric;
use crate::hg;
use crate::profile::{
    Exponential, RadialProfile, TWO_PI, clean_f, clean_u, numeric_radius_for_fraction, optical,
};
use crate::quadrature::{gl32, integrate};

/// The single-scattering profile for one set of coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingleScattering {
    omega: f64,
    g: f64,
    inv_eta: f64,
    /// √(η² − 1).
    tan_c: f64,
    /// σt (1/length).
    scale: f64,
}

/// Inverse CDF of HG over `cos θ ∈ [−1, 1]` (propagation convention), exact for every
/// `|g| < 1` (isotropic only for `|g| < 1e-8`, where the closed form cancels).
fn hg_inverse_cdf(g: f64, u: f64) -> f64 {
    if g.abs() < 1e-8 {
        return (2.0 * u - 1.0).clamp(-1.0, 1.0);
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// HG CDF `∫_{-1}^{c} 2π p dc'`.
fn hg_cdf(g: f64, c: f64) -> f64 {
    if g.abs() < 1e-8 {
        return 0.5 * (1.0 + c);
    }
    (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 + g * g - 2.0 * g * c).sqrt() - 1.0 / (1.0 + g))
}

impl SingleScattering {
    /// Single scattering for albedo `omega = σs/σt ∈ (0, 1]`, extinction `sigma_t > 0`
    /// (1/length), HG `g` (|g| < 1) and relative index `eta ≥ 1`. No allocation.
    pub fn new(omega: f64, sigma_t: f64, g: f64, eta: f64) -> Self {
        Self {
            omega,
            g,
            inv_eta: 1.0 / eta,
            tan_c: (eta * eta - 1.0).max(0.0).sqrt(),
            scale: sigma_t,
        }
    }

    /// `SS₁(x)` in optical units (σt = 1).
    pub(crate) fn eval_optical(&self, x: f64) -> f64 {
        let x = x.max(X_FLOOR);
        let x2 = x * x;
        let tc = x * self.tan_c;
        let pre = self.omega * (-(x + tc)).exp();
        if pre == 0.0 {
            return 0.0;
        }
        let f = |y: f64| {
            let t = tc + y;
            let d = (x2 + t * t).sqrt();
            let mu = t / d;
            let trans = 1.0 - dielectric(mu, self.inv_eta);
            if trans <= 0.0 {
                return 0.0;
            }
            (-(t * t) / (d + x)).exp() / (d * d) * hg::phase(-mu, self.g) * trans * mu
        };
        let sqrt_edge = self.tan_c > 0.0;
        pre * depth_integral(x.min(1.0), 1.0, sqrt_edge, f)
    }

    fn proposal(&self) -> Exponential {
        Exponential { rate: 1.0 }
    }

    /// Optical-unit scale σt (1/length).
    pub fn sigma_t(&self) -> f64 {
        self.scale
    }

    /// Single-scattering albedo ϖ = σs/σt.
    pub fn omega_value(&self) -> f64 {
        self.omega
    }
}

impl RadialProfile for SingleScattering {
    fn eval(&self, r: f64) -> f64 {
        self.scale * self.scale * self.eval_optical(optical(r, self.scale))
    }
    fn total(&self) -> f64 {
        let mu_c = self.tan_c * self.inv_eta; // √(η²−1)/η = √(1 − 1/η²)
        let u_c = hg_cdf(self.g, -mu_c);
        let h = |s: f64| {
            let u = u_c * (1.0 - s * s);
            let mu = -hg_inverse_cdf(self.g, u);
            let trans = 1.0 - dielectric(mu, self.inv_eta);
            2.0 * u_c * s * mu * trans.max(0.0) / (1.0 + mu)
        };
        self.omega * (integrate(gl32(), 0.0, 0.5, h) + integrate(gl32(), 0.5, 1.0, h))
    }
    fn sample_r(&self, u: f64) -> Option<f64> {
        let u = clean_u(u)?;
        Some(self.proposal().sample(u) / self.scale)
    }
    fn pdf_r(&self, r: f64) -> f64 {
        self.scale * self.proposal().pdf(optical(r, self.scale))
    }
    fn radius_for_fraction(&self, f: f64) -> f64 {
        let f = clean_f(f);
        numeric_radius_for_fraction(|x| TWO_PI * x * self.eval_optical(x), f) / self.scale
    }
}
