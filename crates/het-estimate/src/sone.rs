//! The estimator of Sone, Hachisuka & Koike (paper §3): average the coefficients over an
//! ellipse around the chord whose minor axis is the path-integral width of Eq. (2).
//!
//! Steps, for a pair (x_i, x_o) with chord length d, midpoint m, chord direction x̂ and
//! FHK14's modified normal n_i* (the averaging plane contains x_i and x_o; we take the modified
//! normal of n_i + n_o, which equals n_i* on flat surfaces and keeps the estimate reciprocal on
//! curved ones, see `chord.rs`):
//! 1. ⟨σs⟩, ⟨σa⟩: area means over the disk of radius d/2 centred at m in that plane (§3.1),
//!    each sample x' projected to the surface by the two rays ±n_i* from x' (nearer hit;
//!    §3.2, Figure 3);
//! 2. w from Eq. (2) with those means ([`crate::path_integral::width`]); b = w (default) or
//!    w/2 (the paper's literal wording, [`SoneParams::paper`]);
//! 3. σ̄s, σ̄a: area means (Eq. (3)) over the ellipse with semi-axes d/2 along x̂ and b along
//!    n_i* × x̂, projected likewise. The measure is area in the ellipse's plane (not surface
//!    area after projection), as the paper's sampling implies.
//!
//! σs and σa are averaged separately (not the albedo, not σt), as in Eq. (3).
//!
//! # Prefiltered averaging
//! With [`Averaging::Prefiltered`] (the default), steps 1 and 3 first ask the field's
//! constant-time [`CoefficientField::ellipse_average`] (closed forms for stripes and checks,
//! see [`crate::prefilter`]), if the field has one and the pair is flat by
//! [`SoneParams::flatness`]; a curved pair is sampled and flagged
//! ([`crate::Diagnostics::prefilter_fallback`]). A field read through texture coordinates
//! ([`FieldCapabilities::reads_uv`](crate::FieldCapabilities::reads_uv)) is averaged through the region's chart
//! ([`crate::UvChart::between`]: the UV Jacobian at the region's centre), and sampled (and
//! flagged) where the charts at x_i and x_o disagree. [`Averaging::MonteCarlo`] always samples.
//!
//! # Colour
//! Eq. (2) gives one width per channel, so each channel has its own ellipse. One unit-disk
//! sample u is mapped to every channel's ellipse (`m + (d/2)u.x x̂ + b_c u.y (n_i*×x̂)`), so the
//! channels share their random numbers (correlated, smooth colour noise). Channels whose
//! widths coincide (grey fields, or equal step-1 means) share one ellipse: one projection and
//! one lookup serve them all. Channels known constant from the field's bounds take no part.
//!
//! # Limits
//! * d → 0 (x_i = x_o, or a chord below rounding noise): the endpoint mean (a point lookup).
//! * w → 0 (⟨θ²⟩ = 0, ⟨σs⟩ = 0, …): the ellipse degenerates to the chord. Its area average
//!   tends to the chord average *weighted by the semicircle density* √(1 − s²) (s ∈ [−1, 1]
//!   along the chord), which is what the same sampling gives with b = 0; we keep that limit
//!   (continuous in w) rather than switching to the uniform chord mean, and report
//!   [`Region::DegenerateEllipse`].
//! * No hits: see [`MissPolicy`]; with hits only, a channel without hits gets the endpoint
//!   mean (for step 1 too), flagged in the diagnostics.

use std::num::NonZeroU32;

use bssrdf_core::Rgb;

use crate::budget::{MissPolicy, SampleBudget};
use crate::chord::Chord;
use crate::estimator_output::Region;
use crate::field::{CoefficientField, Coefficients};
use crate::known::{Known, sanitise};
use crate::path_integral::{MeanSquareAngle, SemiMinorAxis, width_unchecked};
use crate::prefilter::{Averaging, Flatness};
use crate::random::UniformSource;
use crate::region_average::{Accumulator, Averaged, Channels, Probe, Reading, average_chunks};
use crate::sampling::DiskPoints;
use crate::surface::SurfaceQuery;

/// Parameters of the `sone` estimator. Defaults ([`SoneParams::new`]) follow the paper's
/// reading ([`SoneParams::paper`]) except for the ellipse's semi-minor axis, b = w, which
/// the path-tracer comparison favours over the literal b = w/2 (docs/physics.md#path-width).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SoneParams {
    /// Samples of the step-1 disk (default 16).
    pub disk: SampleBudget,
    /// Samples of the step-3 ellipse (default 32; per colour ellipse, see the module docs).
    pub ellipse: SampleBudget,
    /// ⟨θ²⟩ in Eq. (2): exact HG value (default) or 2(1 − g).
    pub mean_square_angle: MeanSquareAngle,
    /// Semi-minor axis from w: w (default) or w/2 (the literal reading).
    pub semi_minor: SemiMinorAxis,
    /// Which scattering coefficient (and ⟨θ²⟩) Eq. (2) uses for an anisotropic medium.
    pub width_scattering: WidthScattering,
    /// Projection misses: hits only (default) or endpoint mean.
    pub misses: MissPolicy,
    /// Prefiltered (default) or Monte Carlo averaging. Prefiltered asks
    /// [`CoefficientField::ellipse_average`] first, for fields that have it
    /// ([`FieldCapabilities::ellipse_average`](crate::FieldCapabilities::ellipse_average)) and pairs that pass `flatness`, and samples
    /// otherwise; Monte Carlo always samples.
    pub averaging: Averaging,
    /// The fallback criterion of prefiltered averaging (default: normals within 2°).
    pub flatness: Flatness,
}

/// Which scattering coefficient Eq. (2) uses when g ≠ 0. The paper calls its σs, σa and g
/// "the reduced scattering and absorption coefficients, and the average cosine", which reads
/// either way; the three readings differ only for g ≠ 0. Measured against the beam light
/// tracer at g = 0.8 (`docs/physics.md#path-width`): `Reduced` is the worst on both presets,
/// `Unreduced` and `SimilarIsotropic` tie, all within 0.005 in mean |log10|.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum WidthScattering {
    /// σs and the phase function's own ⟨θ²⟩ (PAT04's path model of the real medium). Default.
    #[default]
    Unreduced,
    /// The reduced σs' = (1 − g)σs with the phase function's own ⟨θ²⟩.
    Reduced,
    /// The similar isotropic medium: σs' = (1 − g)σs and the isotropic ⟨θ²⟩.
    SimilarIsotropic,
}

impl WidthScattering {
    /// `(g at which ⟨θ²⟩ is evaluated, factor on σs)` for a medium with HG parameter `g`.
    pub fn resolve(self, g: f64) -> (f64, f64) {
        match self {
            WidthScattering::Unreduced => (g, 1.0),
            WidthScattering::Reduced => (g, 1.0 - g),
            WidthScattering::SimilarIsotropic => (0.0, 1.0 - g),
        }
    }
}

impl crate::names::Named for WidthScattering {
    const WHAT: &'static str = "width scattering";
    const ALL: &'static [Self] = &[
        WidthScattering::Unreduced,
        WidthScattering::Reduced,
        WidthScattering::SimilarIsotropic,
    ];
    fn name(self) -> &'static str {
        match self {
            WidthScattering::Unreduced => "unreduced",
            WidthScattering::Reduced => "reduced",
            WidthScattering::SimilarIsotropic => "similar-isotropic",
        }
    }
}

named_display_fromstr!(WidthScattering);

impl SoneParams {
    /// The defaults: the paper's reading ([`SoneParams::paper`]) with b = w, the semi-minor
    /// axis the path-tracer comparison favours (closer on both beam presets, on the checker
    /// half-space and end to end; docs/physics.md#path-width). `reproduce` runs
    /// [`SoneParams::paper`].
    pub const fn new() -> Self {
        let mut p = Self::paper();
        p.semi_minor = SemiMinorAxis::Width;
        p
    }

    /// The paper's literal reading: exact ⟨θ²⟩, b = w/2, hits only, 16 disk + 32 ellipse
    /// samples (the paper gives no counts; see the benchmark's standard-deviation table to
    /// choose).
    pub const fn paper() -> Self {
        Self {
            disk: SampleBudget::fixed(16),
            ellipse: SampleBudget::fixed(32),
            mean_square_angle: MeanSquareAngle::Exact,
            semi_minor: SemiMinorAxis::HalfWidth,
            width_scattering: WidthScattering::Unreduced,
            misses: MissPolicy::HitsOnly,
            averaging: Averaging::Prefiltered,
            flatness: Flatness::DEFAULT,
        }
    }

    /// The defaults with error-controlled sampling, for reference renders: each stage
    /// samples until the estimated relative standard error of every averaged channel is 1%
    /// (at most 4096 points per stage).
    pub const fn reference() -> Self {
        Self::new().with_samples(SampleBudget::TargetRelError {
            rel_se: 0.01,
            max: NonZeroU32::new(4096).unwrap(),
        })
    }

    /// The same parameters with `averaging`.
    pub const fn with_averaging(mut self, averaging: Averaging) -> Self {
        self.averaging = averaging;
        self
    }

    /// The same parameters with `samples` for both the disk and the ellipse.
    pub const fn with_samples(mut self, samples: SampleBudget) -> Self {
        self.disk = samples;
        self.ellipse = samples;
        self
    }

    /// The same parameters with `disk` samples in the disk stage ([`SoneParams::disk`]).
    pub const fn with_disk(mut self, disk: SampleBudget) -> Self {
        self.disk = disk;
        self
    }

    /// The same parameters with `ellipse` samples in the ellipse stage
    /// ([`SoneParams::ellipse`]).
    pub const fn with_ellipse(mut self, ellipse: SampleBudget) -> Self {
        self.ellipse = ellipse;
        self
    }

    /// The same parameters with ⟨θ²⟩ computed as `mean_square_angle`.
    pub const fn with_mean_square_angle(mut self, mean_square_angle: MeanSquareAngle) -> Self {
        self.mean_square_angle = mean_square_angle;
        self
    }

    /// The same parameters with the ellipse's semi-minor axis `semi_minor`.
    pub const fn with_semi_minor(mut self, semi_minor: SemiMinorAxis) -> Self {
        self.semi_minor = semi_minor;
        self
    }

    /// The same parameters with the path width's scattering coefficient `width_scattering`.
    pub const fn with_width_scattering(mut self, width_scattering: WidthScattering) -> Self {
        self.width_scattering = width_scattering;
        self
    }

    /// The same parameters with projection misses handled by `misses`.
    pub const fn with_misses(mut self, misses: MissPolicy) -> Self {
        self.misses = misses;
        self
    }

    /// The same parameters with the flatness criterion `flatness`.
    pub const fn with_flatness(mut self, flatness: Flatness) -> Self {
        self.flatness = flatness;
        self
    }
}

impl Default for SoneParams {
    fn default() -> Self {
        Self::new()
    }
}

/// Up to three ellipses (one per distinct colour width) sharing each unit-disk sample.
struct Ellipses {
    semi_minor: [f64; 3],
    channels: [Channels; 3],
    len: usize,
}

impl Ellipses {
    /// Groups the averaged channels (`wanted`) by equal semi-minor axis.
    fn group(b: Rgb, wanted: [bool; 3]) -> Self {
        let mut e = Ellipses {
            semi_minor: [0.0; 3],
            channels: [Rgb::ZERO; 3],
            len: 0,
        };
        for c in (0..3).filter(|&c| wanted[c]) {
            let same = |x: f64, y: f64| x == y || (x - y).abs() <= 1e-9 * x.max(y);
            match (0..e.len).find(|&g| same(e.semi_minor[g], b[c])) {
                Some(g) => e.channels[g][c] = 1.0,
                None => {
                    e.semi_minor[e.len] = b[c];
                    e.channels[e.len][c] = 1.0;
                    e.len += 1;
                }
            }
        }
        e
    }
}

/// Estimates σ̄a, σ̄s for one pair (see the module docs). `theta2` is ⟨θ²⟩ and
/// `sigma_s_scale` the factor on σs in Eq. (2) (both prepared once, see [`WidthScattering`]).
pub(crate) fn estimate<S, F, U>(
    params: &SoneParams,
    theta2: f64,
    sigma_s_scale: f64,
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
    let mut pair = SonePair::new(params, chord, probe, known);
    // Step 1: ⟨σs⟩, ⟨σa⟩ over the disk of radius d/2 (§3.1).
    let disk_mean = pair.disk_mean(probe, known, rng);
    // Step 2: the width of Eq. (2) per channel, and the semi-minor axis.
    let w = path_widths(theta2, sigma_s_scale, &disk_mean, chord.length());
    let b = w.map(|w| params.semi_minor.from_width(w));
    // Step 3: Eq. (3) over each distinct ellipse.
    let groups = Ellipses::group(b, pair.wanted);
    let mean = pair.ellipse_mean(&groups, probe, known, rng);

    let degenerate = (0..groups.len).all(|g| groups.semi_minor[g] <= 1e-12 * chord.half_len);
    probe.diag.region = if degenerate {
        Region::DegenerateEllipse
    } else {
        Region::Ellipse
    };
    probe.diag.disk_mean = Some(disk_mean);
    probe.diag.width = Some(w);
    probe.diag.rel_std_error = pair.rel_se;
    mean
}

/// Step 2: the width w of Eq. (2) per channel, from the step-1 means `disk_mean` (σs scaled
/// by `sigma_s_scale`, see [`WidthScattering`]) over a chord of length `d`.
#[inline]
fn path_widths(theta2: f64, sigma_s_scale: f64, disk_mean: &Coefficients, d: f64) -> Rgb {
    Rgb(std::array::from_fn(|c| {
        width_unchecked(
            theta2,
            sigma_s_scale * disk_mean.sigma_s[c],
            disk_mean.sigma_a[c],
            d,
        )
    }))
}

/// What the steps of one pair's estimate share: the chord, how its regions are read, the
/// channels averaged, and the largest relative standard error so far.
struct SonePair<'p> {
    params: &'p SoneParams,
    chord: Chord,
    /// [`MissPolicy::Endpoints`]: a missed projection counts as the endpoint mean.
    miss_endpoints: bool,
    /// The channels not known constant from the field's bounds (as flags and as weights).
    wanted: [bool; 3],
    wanted_rgb: Rgb,
    /// Prefiltered averaging applies to this field ([`SoneParams::averaging`]).
    prefiltered: bool,
    /// The field has closed-form ellipse averages.
    closed_form: bool,
    /// With `SampleBudget::TargetRelError`: the largest estimated relative standard error of
    /// the stages sampled so far.
    rel_se: Option<f64>,
}

impl<'p> SonePair<'p> {
    /// The pair's shared state; with prefiltered averaging, the flatness test of
    /// `params.flatness` is prepared here, so that each region is then read in closed form,
    /// on the local quadric, or by rays.
    #[inline]
    fn new<S, F>(
        params: &'p SoneParams,
        chord: Chord,
        probe: &mut Probe<'_, S, F>,
        known: &Known,
    ) -> Self
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
    {
        let wanted: [bool; 3] = std::array::from_fn(|c| !known.channel_constant(c));
        let closed_form = probe.field.capabilities().ellipse_average;
        let prefiltered = params.averaging == Averaging::Prefiltered
            && (closed_form
                || probe.field.capabilities().point_lookup
                || probe.field.capabilities().reads_uv);
        if prefiltered {
            probe.prepare_prefilter(params.flatness, &chord);
        }
        SonePair {
            params,
            chord,
            miss_endpoints: params.misses == MissPolicy::Endpoints,
            wanted,
            wanted_rgb: Rgb(wanted.map(|w| if w { 1.0 } else { 0.0 })),
            prefiltered,
            closed_form,
            rel_se: None,
        }
    }

    /// Keeps the larger relative standard error.
    #[inline]
    fn note_se(&mut self, e: Option<f64>) {
        if let Some(e) = e {
            self.rel_se = Some(self.rel_se.map_or(e, |r| r.max(e)));
        }
    }

    /// How the region `e` is read: as the prefilter decides, or by rays.
    #[inline]
    fn reading<S, F>(&self, probe: &mut Probe<'_, S, F>, e: &crate::PlanarEllipse) -> Reading
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
    {
        if self.prefiltered {
            probe.reading(e, self.closed_form)
        } else {
            Reading::Rays
        }
    }

    /// Step 1: ⟨σs⟩, ⟨σa⟩ over the disk of radius d/2 centred at the midpoint (paper §3.1),
    /// in closed form where the field has it, else sampled with each point projected by the
    /// two rays ±n_i* (§3.2); as coefficients.
    #[inline]
    fn disk_mean<S, F, U>(
        &mut self,
        probe: &mut Probe<'_, S, F>,
        known: &Known,
        rng: &mut U,
    ) -> Coefficients
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
        U: UniformSource + ?Sized,
    {
        let disk = self.chord.ellipse(self.chord.half_len);
        let disk_reading = self.reading(probe, &disk);
        let field_disk = match disk_reading {
            Reading::ClosedForm => probe.field_ellipse_average(&disk),
            _ => None,
        };
        let disk_mean = match field_disk {
            Some(c) => {
                probe.diag.field_averages += 1;
                sanitise(c)
            }
            None => {
                let lift = sampled_reading(disk_reading, probe);
                let miss_endpoints = self.miss_endpoints;
                let budget = self.params.disk;
                let averaged =
                    average_chunks::<DiskPoints, _>(budget, known.varying(), rng, |us, acc| {
                        probe.read_ellipse_points(&disk, us, Rgb::ONE, miss_endpoints, acc, lift)
                    });
                probe.diag.samples += averaged.samples;
                self.note_se(averaged.rel_se);
                let (mean, fell_back) = averaged.acc.mean_or(self.wanted_rgb, || probe.endpoints());
                probe.diag.fallback |= fell_back;
                mean
            }
        };
        probe.to_coefficients(known.finish(disk_mean))
    }

    /// Step 3: σ̄s, σ̄a by Eq. (3), area means over each distinct ellipse of `groups` (semi-axes
    /// d/2 along x̂ and b along n_i* × x̂): field averages first, then the remaining ellipses
    /// sampled together.
    #[inline]
    fn ellipse_mean<S, F, U>(
        &mut self,
        groups: &Ellipses,
        probe: &mut Probe<'_, S, F>,
        known: &Known,
        rng: &mut U,
    ) -> Coefficients
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
        U: UniformSource + ?Sized,
    {
        let mut acc = Accumulator::default();
        let mut sampled: [Option<Reading>; 3] = [None; 3];
        for (g, how) in sampled.iter_mut().enumerate().take(groups.len) {
            let e = self.chord.ellipse(groups.semi_minor[g]);
            let r = self.reading(probe, &e);
            let field_avg = match r {
                Reading::ClosedForm => probe.field_ellipse_average(&e),
                _ => None,
            };
            match field_avg {
                Some(c) => {
                    probe.diag.field_averages += 1;
                    acc.add(&sanitise(c), groups.channels[g]);
                }
                None => *how = Some(sampled_reading(r, probe)),
            }
        }
        if sampled.iter().any(|s| s.is_some()) {
            let averaged = self.sample_ellipses(groups, &sampled, probe, known, rng);
            acc.merge(&averaged.acc);
        }
        let (mean, fell_back) = acc.mean_or(self.wanted_rgb, || probe.endpoints());
        probe.diag.fallback |= fell_back;
        mean
    }

    /// Step 3, sampled: the ellipses of `groups` whose reading `sampled` gives, with one
    /// unit-disk point mapped to every such ellipse (the channels share their random numbers,
    /// module docs), each point projected by the two rays ±n_i* (§3.2) or read on the
    /// quadric.
    #[inline]
    fn sample_ellipses<S, F, U>(
        &mut self,
        groups: &Ellipses,
        sampled: &[Option<Reading>; 3],
        probe: &mut Probe<'_, S, F>,
        known: &Known,
        rng: &mut U,
    ) -> Averaged
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
        U: UniformSource + ?Sized,
    {
        let mut tracked_channels = Rgb::ZERO;
        for g in (0..groups.len).filter(|&g| sampled[g].is_some()) {
            tracked_channels += groups.channels[g];
        }
        let (va, vs) = known.varying();
        let ellipses: [_; 3] = std::array::from_fn(|g| self.chord.ellipse(groups.semi_minor[g]));
        let miss_endpoints = self.miss_endpoints;
        // Group by group over each chunk: every channel is in one group, so each channel
        // still sums its points in order.
        let averaged = average_chunks::<DiskPoints, _>(
            self.params.ellipse,
            (va * tracked_channels, vs * tracked_channels),
            rng,
            |us, acc| {
                for g in 0..groups.len {
                    if let Some(how) = sampled[g] {
                        let e = &ellipses[g];
                        let ch = groups.channels[g];
                        probe.read_ellipse_points(e, us, ch, miss_endpoints, acc, how);
                    }
                }
            },
        );
        probe.diag.samples += averaged.samples;
        self.note_se(averaged.rel_se);
        averaged
    }
}

/// How a region whose closed form was not used is sampled: on the local quadric where its
/// reading allows (a [`Reading::ClosedForm`] whose closed form declined reads its points on
/// the quadric too, where the field reads points), by rays otherwise.
fn sampled_reading<S, F>(reading: Reading, probe: &Probe<'_, S, F>) -> Reading
where
    S: SurfaceQuery + ?Sized,
    F: CoefficientField<S::Point> + ?Sized,
{
    match reading {
        Reading::ClosedForm
            if probe.field.capabilities().point_lookup || probe.field.capabilities().reads_uv =>
        {
            Reading::Lifted
        }
        Reading::Lifted => Reading::Lifted,
        _ => Reading::Rays,
    }
}
