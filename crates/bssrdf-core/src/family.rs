//! Per-material preparation: a [`ProfileFamily`] fixes the model, the scattering orders, `g`
//! and `η` (and computes the Fresnel moments once); [`ProfileFamily::profile`] then builds the
//! [`Profile`] for any `(σa, σs)` in a few nanoseconds (no quadrature, no allocation), which is
//! what the renderer does for every `(x_i, x_o)` pair.
//!
//! Costs (release build, see `benches/profiles.rs`): `ProfileFamily::new` ≈ 3 µs (three
//! Fresnel moments by quadrature); `profile()` a few ns.

use crate::beam_diffusion::BeamDiffusionMs;
use crate::better_dipole::BetterDipole;
use crate::dipole::Dipole;
use crate::directional_dipole::DirectionalDipole;
use crate::error::ParamError;
use crate::error::{check_eta, check_g};
use crate::fresnel::{DiffuseFresnel, FresnelMoments};
use crate::half_space_albedo::AnisotropicTotals;
use crate::model::{ProfileModel, Scattering};
use crate::profile::{RadialProfile, TWO_PI, clean_f, clean_u, numeric_radius_for_fraction};
use crate::single_scattering::SingleScattering;
use crate::tabulated::TabulatedTerm;

pub use crate::error::{ETA_RANGE, G_MAX, SIGMA_EPSILON, SIGMA_MAX, validate_sigmas};

/// Options of a family beyond the model, `g` and `η`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct FamilyOptions {
    /// How the classical dipole gets `F_dr` (ignored by the other models, which always use
    /// the exact moments).
    pub diffuse_fresnel: DiffuseFresnel,
}

impl FamilyOptions {
    /// The defaults (the exact diffuse Fresnel reflectance).
    pub const fn new() -> Self {
        Self {
            diffuse_fresnel: DiffuseFresnel::Exact,
        }
    }

    /// The same options with the diffuse Fresnel choice `diffuse_fresnel`
    /// (`FamilyOptions::new().with_diffuse_fresnel(DiffuseFresnel::JensenFit)`).
    pub const fn with_diffuse_fresnel(mut self, diffuse_fresnel: DiffuseFresnel) -> Self {
        self.diffuse_fresnel = diffuse_fresnel;
        self
    }
}

/// A prepared material: model, scattering orders, `g`, `η` and everything that depends only on
/// them (Fresnel moments, boundary coefficients). Cheap to copy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileFamily {
    model: ProfileModel,
    scattering: Scattering,
    g: f64,
    eta: f64,
    options: FamilyOptions,
    moments: FresnelMoments,
    /// JMLH01's `A = (1 + F_dr)/(1 − F_dr)` for the dipole.
    a_dipole: f64,
    /// External first moment `C₁(1/η)` (directional dipole normalisation).
    c1_external: f64,
    /// The tabulated model's totals for g ≠ 0 (the real anisotropic medium's half-space;
    /// [`AnisotropicTotals`]); `None` for g = 0 and the other models.
    anisotropic: Option<&'static AnisotropicTotals>,
}

impl ProfileFamily {
    /// Prepares a family with default options. `g ∈ (−1, 1)` (clamped to `±G_MAX`),
    /// `η ∈ [1, 3]`; otherwise a typed error naming the parameter. Cost ≈ 2 µs (two Fresnel
    /// moments by quadrature); for the tabulated model with g ≠ 0 the first family of each
    /// (g, η) also computes that medium's half-space totals ([`AnisotropicTotals`], about
    /// 40 ms).
    pub fn new(
        model: ProfileModel,
        scattering: Scattering,
        g: f64,
        eta: f64,
    ) -> Result<Self, ParamError> {
        Self::with_options(model, scattering, g, eta, FamilyOptions::default())
    }

    /// Prepares a family with explicit options.
    pub fn with_options(
        model: ProfileModel,
        scattering: Scattering,
        g: f64,
        eta: f64,
        options: FamilyOptions,
    ) -> Result<Self, ParamError> {
        check_g(g)?;
        check_eta(eta)?;
        if model == ProfileModel::Tabulated && eta > crate::tabulated::half_space::ETA_MAX {
            return Err(ParamError::OutOfRange {
                name: "eta",
                range: "[1, 1.6] (the tabulated profile's table)",
                value: eta,
            });
        }
        // HG and the reduced coefficients degenerate at |g| = 1 (docs/physics.md#hazards): clamp.
        let g = g.clamp(-G_MAX, G_MAX);
        let moments = FresnelMoments::new(eta)?;
        let f_dr = options.diffuse_fresnel.f_dr(&moments);
        Ok(Self {
            model,
            scattering,
            g,
            eta,
            options,
            moments,
            a_dipole: (1.0 + f_dr) / (1.0 - f_dr),
            c1_external: FresnelMoments::new(1.0 / eta)?.c1,
            anisotropic: (model == ProfileModel::Tabulated && g != 0.0)
                .then(|| AnisotropicTotals::get(g, eta)),
        })
    }

    /// The model.
    pub fn model(&self) -> ProfileModel {
        self.model
    }
    /// The scattering orders included.
    pub fn scattering(&self) -> Scattering {
        self.scattering
    }
    /// HG mean cosine (after clamping to `±G_MAX`).
    pub fn g(&self) -> f64 {
        self.g
    }
    /// Relative index of refraction.
    pub fn eta(&self) -> f64 {
        self.eta
    }
    /// Options.
    pub fn options(&self) -> FamilyOptions {
        self.options
    }
    /// The exact Fresnel moments of `η`.
    pub fn moments(&self) -> FresnelMoments {
        self.moments
    }
    /// The classical dipole's boundary coefficient `A` under the chosen `F_dr`.
    pub fn a_dipole(&self) -> f64 {
        self.a_dipole
    }

    /// The directional dipole (FHK14) for `(σa, σs)` with this family's `g` and `η` (the
    /// family's model choice does not apply: FHK14 is not radially symmetric). No quadrature.
    pub fn directional_dipole(
        &self,
        sigma_a: f64,
        sigma_s: f64,
    ) -> Result<DirectionalDipole, ParamError> {
        DirectionalDipole::with_moments(sigma_a, sigma_s, self.g, &self.moments, self.c1_external)
    }

    /// The profile for absorption `sigma_a` and scattering `sigma_s` (1/length, finite,
    /// `0 ≤ σ ≤ 1e12`; values below 1e-12 count as 0). Pure absorbers and vacuum give the zero
    /// profile. Cost: a few ns, no allocation.
    pub fn profile(&self, sigma_a: f64, sigma_s: f64) -> Result<Profile, ParamError> {
        let (sigma_a, sigma_s) = validate_sigmas(sigma_a, sigma_s)?;
        let Reduced {
            sigma_tp,
            albedo: reduced_albedo,
        } = self.reduced(sigma_a, sigma_s);
        if self.model == ProfileModel::Tabulated {
            return Ok(self.tabulated(sigma_a, sigma_s, reduced_albedo, sigma_tp));
        }
        let multiple = reduced_albedo
            .filter(|_| self.scattering.includes_multiple())
            .map(|alpha_p| match self.model {
                ProfileModel::Dipole => {
                    MultipleTerm::Dipole(Dipole::new(alpha_p, sigma_tp, self.a_dipole))
                }
                ProfileModel::BetterDipole => {
                    MultipleTerm::BetterDipole(BetterDipole::new(alpha_p, sigma_tp, &self.moments))
                }
                // Pbd (the tabulated model returned above).
                _ => MultipleTerm::Pbd(BeamDiffusionMs::new(alpha_p, sigma_tp, &self.moments)),
            });
        let single = self.single(sigma_a, sigma_s);
        Ok(Profile { multiple, single })
    }
}

/// The reduced extinction of a medium under similarity theory, σt' = σa + σs' with σs' =
/// (1 − g) σs (1/length), and its reduced albedo α' = σs'/σt', `None` unless both σs' and σt'
/// reach [`SIGMA_EPSILON`] (the profiles treat such a medium as not scattering).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Reduced {
    pub(crate) sigma_tp: f64,
    pub(crate) albedo: Option<f64>,
}

impl ProfileFamily {
    /// The reduced coefficients of validated `sigma_a`, `sigma_s` with this family's g: what
    /// every radial and slab profile of the family is evaluated at.
    pub(crate) fn reduced(&self, sigma_a: f64, sigma_s: f64) -> Reduced {
        let sigma_sp = (1.0 - self.g) * sigma_s;
        let sigma_tp = sigma_a + sigma_sp;
        let albedo =
            (sigma_sp >= SIGMA_EPSILON && sigma_tp >= SIGMA_EPSILON).then(|| sigma_sp / sigma_tp);
        Reduced { sigma_tp, albedo }
    }

    /// The reduced albedo α' = σs'/σt' (similarity theory with this family's g) at which the
    /// family's profiles read their tables, for absorption `sigma_a` and scattering `sigma_s`
    /// (validated as [`ProfileFamily::profile`]); `Ok(None)` for a medium that does not scatter.
    pub fn reduced_albedo(&self, sigma_a: f64, sigma_s: f64) -> Result<Option<f64>, ParamError> {
        let (sigma_a, sigma_s) = validate_sigmas(sigma_a, sigma_s)?;
        Ok(self.reduced(sigma_a, sigma_s).albedo)
    }

    /// The exact single scattering of the real medium (HG g, unreduced σs and σt) when the
    /// family counts it and the medium scatters.
    fn single(&self, sigma_a: f64, sigma_s: f64) -> Option<SingleScattering> {
        let sigma_t = sigma_a + sigma_s;
        (self.scattering.includes_single() && sigma_s >= SIGMA_EPSILON && sigma_t >= SIGMA_EPSILON)
            .then(|| SingleScattering::new(sigma_s / sigma_t, sigma_t, self.g, self.eta))
    }

    /// The tabulated profile for validated `sigma_a`, `sigma_s`, with reduced albedo
    /// `reduced_albedo` and reduced extinction `sigma_tp`, counting the orders the family
    /// selects (docs/tabulated-profile.md, "Anisotropic scattering").
    ///
    /// * g = 0: both orders from the table, at the medium's own albedo and σt.
    /// * g ≠ 0: the table holds isotropic media only. Multiple scattering (two or more
    ///   events, as the path tracer counts them) is the shape of the similar isotropic
    ///   medium's multiple scattering (similarity theory: σs' = (1 − g)σs) scaled to the real
    ///   medium's total, [`AnisotropicTotals::multiple`]: its half-space plane albedo, solved
    ///   for HG scattering, minus its exact single scattering. Single scattering is that exact
    ///   term ([`SingleScattering`], the real g, σs and σt), as for the other models. All
    ///   orders are their sum. Against the HG medium's own totals (adding–doubling, and an
    ///   independent photon simulation; docs/physics.md#half-space), the similar medium's
    ///   multiple scattering, used before, was 11–28 % low at g 0.3–0.6 and ϖ 0.9–0.99, and
    ///   its total 4–13 % high at ϖ 0.9 (so its total minus the exact single scattering would
    ///   be 5–14 % high there).
    fn tabulated(
        &self,
        sigma_a: f64,
        sigma_s: f64,
        reduced_albedo: Option<f64>,
        sigma_tp: f64,
    ) -> Profile {
        let Some(alpha_p) = reduced_albedo else {
            // No multiple scattering (σs' vanishes); single scattering may remain at g → 1.
            return Profile {
                multiple: None,
                single: self
                    .single(sigma_a, sigma_s)
                    .filter(|_| self.anisotropic.is_some()),
            };
        };
        let (single, multiple) = (
            self.scattering.includes_single(),
            self.scattering.includes_multiple(),
        );
        let Some(totals) = self.anisotropic else {
            let term = TabulatedTerm::new(sigma_tp, alpha_p, self.eta, single, multiple);
            return Profile {
                multiple: Some(MultipleTerm::Tabulated(term)),
                single: None,
            };
        };
        let omega = sigma_s / (sigma_a + sigma_s);
        Profile {
            multiple: multiple.then(|| {
                MultipleTerm::Tabulated(
                    TabulatedTerm::new(sigma_tp, alpha_p, self.eta, false, true)
                        .scaled_to(totals.multiple(omega)),
                )
            }),
            single: self.single(sigma_a, sigma_s),
        }
    }

    /// The real medium's multiple-scattering total over the similar isotropic medium's (the
    /// factor [`ProfileFamily::profile`] scales the table's multiple scattering by at g ≠ 0;
    /// 1 at g = 0, for other models and for media that do not scatter), for validated
    /// coefficients. The slab profile scales both its faces by it.
    pub(crate) fn multiple_scale(&self, sigma_a: f64, sigma_s: f64) -> f64 {
        let (
            Some(totals),
            Reduced {
                sigma_tp,
                albedo: Some(alpha_p),
            },
        ) = (self.anisotropic, self.reduced(sigma_a, sigma_s))
        else {
            return 1.0;
        };
        let similar = TabulatedTerm::new(sigma_tp, alpha_p, self.eta, false, true).total();
        let omega = sigma_s / (sigma_a + sigma_s);
        if similar > 0.0 {
            totals.multiple(omega) / similar
        } else {
            1.0
        }
    }

    /// The single-scattering term of a tabulated family for validated coefficients, as
    /// [`ProfileFamily::profile`] makes it (the table's at g = 0, the exact one at g ≠ 0;
    /// `None` unless the family counts single scattering and the medium scatters).
    pub(crate) fn tabulated_single(&self, sigma_a: f64, sigma_s: f64) -> Option<Profile> {
        if !self.scattering.includes_single() {
            return None;
        }
        let reduced = self.reduced(sigma_a, sigma_s);
        let alpha_p = reduced.albedo?;
        Some(if self.anisotropic.is_some() {
            Profile {
                multiple: None,
                single: self.single(sigma_a, sigma_s),
            }
        } else {
            Profile {
                multiple: Some(MultipleTerm::Tabulated(TabulatedTerm::new(
                    reduced.sigma_tp,
                    alpha_p,
                    self.eta,
                    true,
                    false,
                ))),
                single: None,
            }
        })
    }
}

/// The multiple-scattering (diffusion) part of a [`Profile`]. A future profile tabulated from
/// the reference path tracer is one more variant.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum MultipleTerm {
    /// Classical dipole (JMLH01).
    Dipole(Dipole),
    /// Better dipole (dE12).
    BetterDipole(BetterDipole),
    /// Photon beam diffusion, multiple scattering (HCJ13).
    Pbd(BeamDiffusionMs),
    /// The tabulated half-space profile ([`crate::tabulated`]). At g = 0 it carries *every*
    /// order the family selects (single scattering included), and the [`Profile`] has no
    /// separate single-scattering term; at g ≠ 0 it is the multiple scattering alone, and
    /// single scattering is the exact term ([`ProfileFamily::profile`]).
    Tabulated(TabulatedTerm),
}

impl MultipleTerm {
    fn as_dyn(&self) -> &dyn RadialProfile {
        match self {
            MultipleTerm::Dipole(m) => m,
            MultipleTerm::BetterDipole(m) => m,
            MultipleTerm::Pbd(m) => m,
            MultipleTerm::Tabulated(m) => m,
        }
    }
    /// True when `pdf_r` is exactly `2πrR/total` (closed-form CDF).
    fn exact_sampling(&self) -> bool {
        matches!(
            self,
            MultipleTerm::Dipole(_) | MultipleTerm::BetterDipole(_) | MultipleTerm::Tabulated(_)
        )
    }
    /// A cheap estimate of the total, used only as a mixture weight for sampling.
    fn weight(&self) -> f64 {
        match self {
            MultipleTerm::Dipole(m) => m.total(),
            MultipleTerm::BetterDipole(m) => m.total(),
            // The better dipole with the same constants is within tens of % of PBD.
            MultipleTerm::Pbd(m) => m.proposal_total(),
            MultipleTerm::Tabulated(m) => m.total(),
        }
    }
}

/// A homogeneous radial profile: the chosen model's multiple-scattering term and/or single
/// scattering, per the family's [`Scattering`]. `Copy`, a few dozen bytes.
///
/// Sampling: the profile's `pdf_r` is a mixture of each term's density (see the models),
/// weighted by (cheap estimates of) their totals; with a dipole or better dipole alone it is
/// exactly `2πrR/total`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    multiple: Option<MultipleTerm>,
    single: Option<SingleScattering>,
}

impl Profile {
    /// The zero profile (vacuum, pure absorber).
    pub const ZERO: Profile = Profile {
        multiple: None,
        single: None,
    };

    /// The multiple-scattering term, if any.
    pub fn multiple(&self) -> Option<&MultipleTerm> {
        self.multiple.as_ref()
    }
    /// The single-scattering term, if any.
    pub fn single(&self) -> Option<&SingleScattering> {
        self.single.as_ref()
    }
    /// True for the zero profile.
    pub fn is_zero(&self) -> bool {
        self.multiple.is_none() && self.single.is_none()
    }

    /// Mixture weights (multiple, single), summing to 1 when not zero.
    fn weights(&self) -> (f64, f64) {
        let wm = self.multiple.as_ref().map_or(0.0, |m| m.weight());
        let ws = self.single.as_ref().map_or(0.0, |s| {
            // (ϖ/2)(1 − ln 2): the η = 1, g = 0 total, a fine mixture weight.
            s.omega_value() * 0.153_426_409_720_027_3
        });
        let t = wm + ws;
        if t > 0.0 {
            (wm / t, ws / t)
        } else if self.multiple.is_some() {
            (1.0, 0.0)
        } else {
            (0.0, 1.0)
        }
    }
}

impl RadialProfile for Profile {
    fn eval(&self, r: f64) -> f64 {
        self.multiple.as_ref().map_or(0.0, |m| m.as_dyn().eval(r))
            + self.single.as_ref().map_or(0.0, |s| s.eval(r))
    }
    fn total(&self) -> f64 {
        self.multiple.as_ref().map_or(0.0, |m| m.as_dyn().total())
            + self.single.as_ref().map_or(0.0, |s| s.total())
    }
    fn sample_r(&self, u: f64) -> Option<f64> {
        let u = clean_u(u)?;
        let (wm, _) = self.weights();
        match (&self.multiple, &self.single) {
            (None, None) => None,
            (Some(m), None) => m.as_dyn().sample_r(u),
            (None, Some(s)) => s.sample_r(u),
            (Some(m), Some(s)) => {
                if u < wm {
                    m.as_dyn().sample_r(u / wm)
                } else {
                    s.sample_r(((u - wm) / (1.0 - wm)).min(1.0))
                }
            }
        }
    }
    fn pdf_r(&self, r: f64) -> f64 {
        let (wm, ws) = self.weights();
        self.multiple
            .as_ref()
            .map_or(0.0, |m| wm * m.as_dyn().pdf_r(r))
            + self.single.as_ref().map_or(0.0, |s| ws * s.pdf_r(r))
    }
    fn radius_for_fraction(&self, f: f64) -> f64 {
        let f = clean_f(f);
        match (&self.multiple, &self.single) {
            (None, None) => 0.0,
            (Some(m), None) if m.exact_sampling() => m.as_dyn().radius_for_fraction(f),
            (Some(m), None) => m.as_dyn().radius_for_fraction(f),
            (None, Some(s)) => s.radius_for_fraction(f),
            (Some(_), Some(s)) => {
                // Numerical CDF of the sum, in units of the single-scattering scale σt.
                let k = s.sigma_t();
                numeric_radius_for_fraction(
                    |x| {
                        let r = x / k;
                        TWO_PI * r * self.eval(r) / k
                    },
                    f,
                ) / k
            }
        }
    }
}
