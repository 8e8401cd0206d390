//! The closed set of estimators, resolved once per material ([`Estimator::prepare`]) and then
//! run per (x_i, x_o) pair ([`PreparedEstimator::estimate`]).

use std::sync::Arc;

use bssrdf_core::ParamError;

use crate::budget::SampleBudget;
use crate::estimator_output::{Estimate, Region};
use crate::field::CoefficientField;
use crate::kernel::{self, KernelParams};
use crate::kernel_table::KernelTable;
use crate::known::Known;
use crate::names::Named;
use crate::path_integral::SemiMinorAxis;
use crate::point_lookup;
use crate::prefilter::Averaging;
use crate::random::UniformSource;
use crate::region_average::Probe;
use crate::segment::{self, SegmentParams};
use crate::sone::{self, SoneParams};
use crate::surface::SurfaceQuery;

/// How the homogeneous parameters for a pair (x_i, x_o) are estimated.
///
/// Names (`Display`/`FromStr`, used by the CLI and scene files): those of [`Estimator::ALL`].
/// Parsing a name gives the variant with default parameters.
///
/// New methods are one more variant each, with their parameters in their own module; the
/// variant says which options it takes ([`Estimator::options`]), and the renderer and the
/// command line read that (docs/architecture.md, "Adding an estimator").
/// Prefiltered constant-time averaging is an option of `sone` ([`SoneParams::averaging`], on
/// by default), not a separate estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Estimator {
    /// Jensen et al. (JMLH01): the coefficients at the incident point x_i.
    JensenIn,
    /// Jensen et al. evaluated at the exitant point x_o, as in the paper's Figure 4.
    JensenOut,
    /// d'Eon & Irving (dEI11) as the paper describes it, in its literal reading:
    /// ½(σ(x_i) + σ(x_o)). The paper's baseline.
    Endpoints,
    /// Mean along the chord x_i–x_o projected onto the surface (the other reading of the
    /// paper's description of dEI11; not attributed to dEI11).
    Segment(SegmentParams),
    /// Sone, Hachisuka & Koike (paper §3): averages over the path-integral ellipse.
    Sone(SoneParams),
    /// The diffusion-derived averaging kernel: σa and σs averaged with the depth-integrated
    /// photon measurement density of the half-space diffusion approximation (docs/kernel.md).
    Kernel(KernelParams),
}

impl Named for Estimator {
    const WHAT: &'static str = "estimator";
    const ALL: &'static [Self] = &[
        Estimator::JensenIn,
        Estimator::JensenOut,
        Estimator::Endpoints,
        Estimator::Segment(SegmentParams::new()),
        Estimator::Sone(SoneParams::new()),
        Estimator::Kernel(KernelParams::new()),
    ];
    fn name(self) -> &'static str {
        match self {
            Estimator::JensenIn => "jensen-in",
            Estimator::JensenOut => "jensen-out",
            Estimator::Endpoints => "endpoints",
            Estimator::Segment(_) => "segment",
            Estimator::Sone(_) => "sone",
            Estimator::Kernel(_) => "kernel",
        }
    }
}

named_display_fromstr!(Estimator);

impl Estimator {
    /// The name used on the command line and in scene files.
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// True when the estimator asks fields for constant-time region averages
    /// ([`CoefficientField::ellipse_average`]): `sone` with [`crate::Averaging::Prefiltered`].
    /// A renderer builds what those averages read (summed-area tables) when it prepares a
    /// material, and for such estimators only.
    pub fn reads_region_averages(&self) -> bool {
        matches!(self, Estimator::Sone(p) if p.averaging == crate::Averaging::Prefiltered)
    }

    /// Validates the parameters and resolves the per-material constants (⟨θ²⟩ for Sone:
    /// the exact value costs ~1 µs; the kernel's table: a few ms unless another live
    /// prepared estimator already holds the table of the same η, which is then shared), so do
    /// this once per material, outside the pixel loop. The prepared estimator owns what it
    /// computed: dropping it frees the kernel's table (512 KiB) unless another holds it.
    ///
    /// `g` is the Henyey–Greenstein mean cosine of the material (|g| < 1) and `eta` its
    /// relative index of refraction n_medium/n_outside (in [1, 3]; the kernel's extrapolated
    /// boundary depends on it). Errors: `g` or `eta` not finite or out of range; a
    /// `SampleBudget::TargetRelError` with a non-positive or non-finite target; kernel
    /// parameters out of range ([`KernelParams::validate`]).
    pub fn prepare(self, g: f64, eta: f64) -> Result<PreparedEstimator, ParamError> {
        let a = crate::green::boundary_coefficient(eta)?;
        // Validate g for every estimator, so that a bad material fails early whatever is chosen.
        let theta2_of = |m: crate::path_integral::MeanSquareAngle| m.evaluate(g);
        let theta2 = match self {
            Estimator::JensenIn | Estimator::JensenOut | Estimator::Endpoints => {
                theta2_of(Default::default())?;
                0.0
            }
            Estimator::Segment(p) => {
                theta2_of(Default::default())?;
                p.samples.validate()?;
                0.0
            }
            Estimator::Sone(p) => {
                p.disk.validate()?;
                p.ellipse.validate()?;
                theta2_of(Default::default())?;
                let (g_theta, _) = p.width_scattering.resolve(g);
                p.mean_square_angle.evaluate(g_theta)?
            }
            Estimator::Kernel(p) => {
                theta2_of(Default::default())?;
                p.validate()?;
                0.0
            }
        };
        let kernel = match self {
            Estimator::Kernel(_) => Some(KernelTable::shared(a)),
            _ => None,
        };
        let sigma_s_scale = match self {
            Estimator::Sone(p) => p.width_scattering.resolve(g).1,
            _ => 1.0,
        };
        Ok(PreparedEstimator {
            estimator: self,
            theta2,
            sigma_s_scale,
            g,
            kernel,
        })
    }
}

/// The options an estimator takes beyond its name (what a command line or scene file may set
/// on it): each flag says whether [`Estimator::with_samples`], [`Estimator::with_averaging`]
/// and [`Estimator::with_semi_minor`] change it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct EstimatorOptions {
    /// Averaging samples per region (a [`SampleBudget`]).
    pub samples: bool,
    /// Prefiltered or Monte Carlo averaging ([`Averaging`]).
    pub averaging: bool,
    /// The semi-minor axis reading of the path-integral ellipse ([`SemiMinorAxis`]).
    pub semi_minor: bool,
}

impl EstimatorOptions {
    /// The names of the estimators of [`Estimator::ALL`] for which `takes` holds, e.g.
    /// `"segment, sone and kernel"`, for help texts and error messages.
    pub fn names_of(takes: impl Fn(EstimatorOptions) -> bool) -> String {
        let names: Vec<&str> = Estimator::ALL
            .iter()
            .filter(|e| takes(e.options()))
            .map(|e| e.name())
            .collect();
        match names.split_last() {
            None => String::new(),
            Some((last, [])) => (*last).to_string(),
            Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
        }
    }
}

impl Estimator {
    /// Which options this estimator takes.
    pub const fn options(self) -> EstimatorOptions {
        match self {
            Estimator::JensenIn | Estimator::JensenOut | Estimator::Endpoints => EstimatorOptions {
                samples: false,
                averaging: false,
                semi_minor: false,
            },
            Estimator::Segment(_) => EstimatorOptions {
                samples: true,
                averaging: false,
                semi_minor: false,
            },
            Estimator::Sone(_) => EstimatorOptions {
                samples: true,
                averaging: true,
                semi_minor: true,
            },
            Estimator::Kernel(_) => EstimatorOptions {
                samples: true,
                averaging: true,
                semi_minor: false,
            },
        }
    }

    /// The estimator with `samples` averaging samples per region (segment: on the chord;
    /// Sone: in the disk and in the ellipse; kernel: points drawn around the chord, at most
    /// [`KernelParams::MAX_SAMPLES`], which [`Estimator::prepare`] enforces); unchanged when
    /// it takes no samples ([`EstimatorOptions::samples`]).
    pub const fn with_samples(self, samples: SampleBudget) -> Self {
        match self {
            Estimator::Segment(p) => Estimator::Segment(p.with_samples(samples)),
            Estimator::Sone(p) => Estimator::Sone(p.with_samples(samples)),
            Estimator::Kernel(p) => Estimator::Kernel(p.with_samples(samples)),
            e => e,
        }
    }

    /// The estimator with its averaging set to `averaging`; unchanged when it has none
    /// ([`EstimatorOptions::averaging`]).
    pub const fn with_averaging(self, averaging: Averaging) -> Self {
        match self {
            Estimator::Sone(p) => Estimator::Sone(p.with_averaging(averaging)),
            Estimator::Kernel(p) => Estimator::Kernel(p.with_averaging(averaging)),
            e => e,
        }
    }

    /// The estimator with the semi-minor axis reading of Eq. (2) set to `semi_minor`;
    /// unchanged when it has no ellipse ([`EstimatorOptions::semi_minor`]).
    pub const fn with_semi_minor(self, semi_minor: SemiMinorAxis) -> Self {
        match self {
            Estimator::Sone(mut p) => {
                p.semi_minor = semi_minor;
                Estimator::Sone(p)
            }
            e => e,
        }
    }

    /// The estimator's averaging (`None` when it has none).
    pub const fn averaging(&self) -> Option<Averaging> {
        match self {
            Estimator::Sone(p) => Some(p.averaging),
            Estimator::Kernel(p) => Some(p.averaging),
            _ => None,
        }
    }

    /// The estimator's semi-minor axis reading (`None` when it has no ellipse).
    pub const fn semi_minor(&self) -> Option<SemiMinorAxis> {
        match self {
            Estimator::Sone(p) => Some(p.semi_minor),
            _ => None,
        }
    }
}

#[cfg(test)]
mod options_tests {
    use super::*;

    /// Each option an estimator says it takes changes it, and each it says it does not take
    /// leaves it unchanged (so the flags refused by the command line are the ignored ones).
    #[test]
    fn options_say_what_the_setters_change() {
        for &e in Estimator::ALL {
            let o = e.options();
            let budget = SampleBudget::fixed(3);
            assert_eq!(e.with_samples(budget) != e, o.samples, "{e}");
            let other = match e.averaging() {
                Some(Averaging::Prefiltered) => Averaging::MonteCarlo,
                _ => Averaging::Prefiltered,
            };
            assert_eq!(e.with_averaging(other) != e, o.averaging, "{e}");
            assert_eq!(e.averaging().is_some(), o.averaging, "{e}");
            let b = match e.semi_minor() {
                Some(SemiMinorAxis::Width) => SemiMinorAxis::HalfWidth,
                _ => SemiMinorAxis::Width,
            };
            assert_eq!(e.with_semi_minor(b) != e, o.semi_minor, "{e}");
            assert_eq!(e.semi_minor().is_some(), o.semi_minor, "{e}");
        }
        assert_eq!(
            EstimatorOptions::names_of(|o| o.samples),
            "segment, sone and kernel"
        );
        assert_eq!(EstimatorOptions::names_of(|o| o.semi_minor), "sone");
    }
}

/// An estimator with its per-material constants resolved. `Send + Sync`, cheap to clone (the
/// kernel's table is shared by reference count); [`PreparedEstimator::estimate`] takes
/// `&self`.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedEstimator {
    estimator: Estimator,
    theta2: f64,
    /// Factor on σs in Eq. (2) (Sone; see `WidthScattering`).
    sigma_s_scale: f64,
    g: f64,
    /// The kernel estimator's table (shared per η among live estimators), `None` for the
    /// others.
    kernel: Option<Arc<KernelTable>>,
}

impl PreparedEstimator {
    /// The estimator this was prepared from.
    pub fn estimator(&self) -> Estimator {
        self.estimator
    }

    /// ⟨θ²⟩ (rad²) used in Eq. (2), for the Sone estimator.
    pub fn mean_square_angle(&self) -> Option<f64> {
        matches!(self.estimator, Estimator::Sone(_)).then_some(self.theta2)
    }

    /// Estimates the homogeneous σa and σs (per channel) for the pair (`x_i`, `x_o`) of
    /// surface points of the object that `surface` and `field` describe.
    ///
    /// * `x_i`, `x_o`: incident and exitant points as the renderer's point type (their
    ///   normals orient the averaging plane; their own coefficients are looked up directly).
    /// * `rng`: the caller's uniform stream; fixed budgets draw 2 numbers per averaging stage
    ///   (1 for `segment`), point lookups none.
    ///
    /// Never allocates, never panics on valid input; the coefficients always lie in the range
    /// the profiles accept, `[0, bssrdf_core::SIGMA_MAX]` (1e12 per unit length): larger
    /// values (a field returning +∞, or 1e15) are clamped to it
    /// ([`Coefficients::clamp_to_range`](crate::Coefficients::clamp_to_range)), so an
    /// estimate is always a valid profile argument. If `field.bounds()` says the field is constant, the constant is returned without
    /// any lookup or projection ([`crate::Diagnostics::short_circuit`]); components that the
    /// bounds show to be constant are not averaged. Fields with their own averaging space
    /// ([`CoefficientField::averaged`]) are averaged there and each mean is mapped back with
    /// [`CoefficientField::coefficients_of_mean`].
    #[inline]
    pub fn estimate<S, F, U>(
        &self,
        surface: &S,
        field: &F,
        x_i: &S::Point,
        x_o: &S::Point,
        rng: &mut U,
    ) -> Estimate
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
        U: UniformSource + ?Sized,
    {
        let known = Known::new(field.bounds());
        let mut probe = Probe::new(surface, field, x_i, x_o);
        if let Some(c) = known.constant_field() {
            probe.diag.short_circuit = true;
            probe.diag.region = Region::Constant;
            probe.diag.constant_components = 6;
            return Estimate {
                coefficients: probe.to_coefficients(c).clamp_to_range(),
                diagnostics: probe.diag,
            };
        }
        probe.diag.constant_components = known.constant_components();
        let raw = match &self.estimator {
            Estimator::JensenIn => point_lookup::single_point(&mut probe, true),
            Estimator::JensenOut => point_lookup::single_point(&mut probe, false),
            Estimator::Endpoints => point_lookup::endpoints(&mut probe),
            Estimator::Segment(p) => segment::estimate(p, &mut probe, &known, rng),
            Estimator::Sone(p) => {
                sone::estimate(p, self.theta2, self.sigma_s_scale, &mut probe, &known, rng)
            }
            Estimator::Kernel(p) => match &self.kernel {
                Some(table) => kernel::estimate(p, self.g, table, &mut probe, &known, rng),
                // Unreachable: `prepare` gives every kernel estimator its table.
                None => point_lookup::endpoints(&mut probe),
            },
        };
        Estimate {
            coefficients: probe.to_coefficients(known.finish(raw)).clamp_to_range(),
            diagnostics: probe.diag,
        }
    }
}
