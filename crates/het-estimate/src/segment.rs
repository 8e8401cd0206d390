//! The chord average: the mean of the coefficients along the segment x_i–x_o, projected onto
//! the surface. A second reading of the paper's description of the d'Eon–Irving heuristic
//! ("averages of coefficients between incident and exitant points", §4); it is *not* claimed
//! to be dEI11's rule (docs/physics.md#heuristics).

use crate::budget::{MissPolicy, SampleBudget};
use crate::estimator_output::Region;
use crate::field::{CoefficientField, Coefficients};
use crate::known::Known;
use crate::random::UniformSource;
use crate::region_average::{Probe, average};
use crate::sampling::SegmentPoints;
use crate::surface::SurfaceQuery;
use bssrdf_core::Rgb;

/// Parameters of the `segment` estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SegmentParams {
    /// Sample points along the chord (default 16).
    pub samples: SampleBudget,
    /// What a sample whose projection misses contributes (default hits only).
    pub misses: MissPolicy,
}

impl SegmentParams {
    /// The defaults: 16 stratified points, hits only.
    pub const fn new() -> Self {
        Self {
            samples: SampleBudget::fixed(16),
            misses: MissPolicy::HitsOnly,
        }
    }

    /// The same parameters with `samples` points.
    pub const fn with_samples(mut self, samples: SampleBudget) -> Self {
        self.samples = samples;
        self
    }

    /// The same parameters with projection misses handled by `misses`.
    pub const fn with_misses(mut self, misses: MissPolicy) -> Self {
        self.misses = misses;
        self
    }
}

impl Default for SegmentParams {
    fn default() -> Self {
        Self::new()
    }
}

/// Mean along the chord: points `x(t) = m + (2t − 1)(d/2) x̂` with `t` from a randomly shifted
/// golden-ratio sequence (uniform in arc length), each projected onto the surface by the two
/// rays ±n_i* (FHK14's modified normal, as for the Sone estimator). d → 0 gives the endpoint
/// mean (a point lookup).
pub(crate) fn estimate<S, F, U>(
    params: &SegmentParams,
    probe: &mut Probe<'_, S, F>,
    known: &Known,
    rng: &mut U,
) -> Coefficients
where
    S: SurfaceQuery + ?Sized,
    F: CoefficientField<S::Point> + ?Sized,
    U: UniformSource + ?Sized,
{
    let Some(chord) = probe.chord() else {
        return probe.endpoints();
    };
    probe.diag.region = Region::Segment;
    let miss_endpoints = params.misses == MissPolicy::Endpoints;
    let averaged = average::<SegmentPoints, _>(params.samples, known.varying(), rng, |t, acc| {
        probe.project_and_add(chord.point(t), chord.normal, Rgb::ONE, miss_endpoints, acc)
    });
    probe.diag.samples += averaged.samples;
    probe.diag.rel_std_error = averaged.rel_se;
    let (mean, fell_back) = averaged.acc.mean_or(Rgb::ONE, || probe.endpoints());
    probe.diag.fallback |= fell_back;
    mean
}
