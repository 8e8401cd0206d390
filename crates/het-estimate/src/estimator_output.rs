//! What an estimator returns: the averaged coefficients and how they were obtained.

use bssrdf_core::Rgb;

use crate::field::Coefficients;

/// The homogeneous parameters estimated for one pair (x_i, x_o).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Averaged σa and σs per channel (1/length). Always in `[0, 1e12]` (the profiles'
    /// range, `bssrdf_core::SIGMA_MAX`), and within the field's bounds when it reports them.
    pub coefficients: Coefficients,
    /// How the estimate was obtained.
    pub diagnostics: Diagnostics,
}

/// The region a coefficient average was taken over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum Region {
    /// No lookup at all: the field is constant (its bounds say so).
    #[default]
    Constant,
    /// One point lookup (Jensen).
    Point,
    /// The two endpoints x_i and x_o (also the d → 0 limit of the region estimators).
    Endpoints,
    /// The chord x_i–x_o, projected onto the surface.
    Segment,
    /// The Sone ellipse, projected onto the surface.
    Ellipse,
    /// The Sone ellipse with a vanishing minor axis (w = 0: ⟨θ²⟩ = 0, ⟨σs⟩ = 0, …): the
    /// average is taken along the chord with the ellipse's limiting (semicircle) density.
    DegenerateEllipse,
    /// The diffusion-derived kernel's weighted average over points around the chord
    /// (docs/kernel.md).
    Kernel,
}

/// Diagnostics of one estimate (for rare-event counters and debugging; never needed to use
/// the coefficients).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Diagnostics {
    /// The region the final average was taken over.
    pub region: Region,
    /// Points drawn in averaging regions (all stages; the Sone disk and ellipse are added).
    pub samples: u32,
    /// [`crate::SurfaceQuery::project`] calls.
    pub projections: u32,
    /// Projections where neither ray hit the object.
    pub misses: u32,
    /// [`crate::CoefficientField::coefficients`] calls.
    pub lookups: u32,
    /// The constant-field short-circuit was taken: the field's bounds say it is constant, so
    /// nothing was projected or looked up.
    pub short_circuit: bool,
    /// How many of the six (coefficient, channel) values the bounds showed to be constant and
    /// were therefore taken from the bounds instead of averaged.
    pub constant_components: u8,
    /// Some channel had no hits at all and fell back to the endpoint average.
    pub fallback: bool,
    /// The modified normal was undefined (n_i ∥ chord) and a fallback plane normal was used.
    pub normal_fallback: bool,
    /// Ellipse averages answered by [`crate::CoefficientField::ellipse_average`] instead of
    /// sampling (Sone: up to 1 for the disk + 3 for the ellipses).
    pub field_averages: u8,
    /// Prefiltered averaging was asked for, but some region had to be projected by rays
    /// ([`crate::Flatness`]): the surface departs too far from its local quadric there (a
    /// crease, a corner, a thin part, a region spanning much of a small object), or, for a
    /// field read through texture coordinates, the charts at x_i and x_o disagreed
    /// ([`crate::UvChart::between`]).
    pub prefilter_fallback: bool,
    /// Some region was sampled at points placed on the pair's local quadric, without rays
    /// ([`crate::local_surface`]): the surface was too curved for the flat footprint, but
    /// smooth enough for the quadric.
    pub lifted: bool,
    /// Of those, a flat pair whose texture-coordinate charts disagreed (a seam or a stretch
    /// between x_i and x_o, [`crate::UvChart::between`]).
    pub chart_fallback: bool,
    /// Sone: the step-1 disk means ⟨σa⟩, ⟨σs⟩ that entered Eq. (2).
    pub disk_mean: Option<Coefficients>,
    /// Sone: the width w of Eq. (2) per channel (scene units); the ellipse's semi-minor axis
    /// is `SoneParams::semi_minor.from_width(w)`.
    pub width: Option<Rgb>,
    /// With `SampleBudget::TargetRelError`: the largest estimated relative standard error
    /// over the averaged channels (and, for Sone, over both stages).
    pub rel_std_error: Option<f64>,
}
