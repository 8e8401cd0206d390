//! The diffusion-derived averaging kernel (`kernel`): average σa and σs with the
//! depth-integrated photon measurement density of the diffusion approximation, instead of
//! Sone's uniform ellipse. Derivation, assumptions and measurements: docs/kernel.md.
//!
//! To first order in a perturbation δσa, the diffusion equation gives
//! δ ln Φ(x_i → x_o) ≈ −∫ δσa(x) G(s_i, x) G(x, s_o) / G(s_i, s_o) dx (the Born/Rytov
//! approximation of diffuse optical tomography; key `Arr99` in docs/references.md), with G the
//! half-space Green's function ([`crate::green`]) and s_i, s_o the sources one transport mean
//! free path below x_i and x_o. When the coefficients vary only along the surface, the weight
//! of a surface point p is W₂(p) = ∫ G(s_i, (p, ζ)) G((p, ζ), s_o) dζ
//! ([`crate::kernel_table`]), and the homogeneous medium that changes ln Φ as the real one does
//! (to first order) has σ̄a = ∫ W₂ σa dA / ∫ W₂ dA. That linear average is measurably too
//! dark for strong contrasts (light prefers the clear regions, a second-order effect), so the
//! estimator takes the weighted power mean (∫ W₂ σa^p dA / ∫ W₂ dA)^{1/p} with p = 7/8 by
//! default ([`KernelParams::exponent`]; p = 1 is the first-order average). σs is averaged
//! arithmetically with the same weight.
//!
//! # Steps, for a pair (x_i, x_o)
//! 1. Start from the endpoint mean ½(σ(x_i) + σ(x_o)).
//! 2. Draw N points p_k in the averaging plane of Sone's estimator (the plane through the
//!    chord with FHK14's modified normal, see `chord.rs`) from a proposal density q that
//!    covers the kernel ([`Proposal`]), project each onto the surface by the two rays
//!    ±normal (paper §3.2), and look up the coefficients there once.
//! 3. Per colour channel, weight each point by W₂(p_k)/q(p_k) with W₂ evaluated at the
//!    current estimate (from the table, in the channel's transport units), and take the
//!    self-normalised weighted (power) means of σa and σs.
//! 4. Repeat step 3 [`KernelParams::iterations`] times in all (the weight depends on the
//!    coefficients it averages); later iterations reuse the same points and lookups. Every
//!    iteration but the last reweights only the first max([`PILOT_POINTS`], N/4) points: it
//!    only sets the next iteration's kernel.
//!
//! # Limits
//! * d → 0: the endpoint mean, as every region estimator.
//! * A channel whose σt' is 0 (vacuum, or σs' = 0 with σa = 0) has no diffusion length: it
//!   keeps its current estimate. κ = σtr/σt' ∈ [0, √3] covers σa = 0 (power-law kernel) and
//!   pure absorbers.
//! * Huge σt: distances in transport units leave the table and the kernel collapses onto the
//!   chord and the endpoints; weights are evaluated relative to their value on the chord, so
//!   they do not underflow there. If every weight of a channel is 0 (all samples missed or
//!   fell where the kernel vanishes) the channel keeps its previous estimate and
//!   [`crate::Diagnostics::fallback`] is set.
//! * Reciprocity: the points are built from the canonical chord (its two ends in a fixed
//!   order) and W₂ is symmetric, so swapping x_i and x_o gives the same estimate bit for bit
//!   whenever the averaging plane is the same.

use std::f64::consts::PI;
use std::mem::MaybeUninit;

use bssrdf_core::ParamError;
use glam::{DVec2, DVec3};

use crate::budget::{MissPolicy, SampleBudget};
use crate::chord::Chord;
use crate::estimator_output::Region;
use crate::field::{CoefficientField, Coefficients};
use crate::kernel_table::KernelTable;
use crate::known::Known;
use crate::prefilter::{Averaging, Flatness};
use crate::random::UniformSource;
use crate::region_average::{CHUNK, Probe};
use crate::sampling::{DiskPoints, PointSet};
use crate::surface::SurfaceQuery;

/// Parameters of the `kernel` estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct KernelParams {
    /// Points drawn from the proposal, each projected and looked up once (default 64). Only
    /// fixed budgets, at most [`KernelParams::MAX_SAMPLES`].
    pub samples: SampleBudget,
    /// Weighted averages computed in all, each with the kernel of the previous estimate
    /// (default 2; 1 uses the kernel of the endpoint mean). 1 to 8.
    pub iterations: u32,
    /// Projection misses: hits only (default) or endpoint mean.
    pub misses: MissPolicy,
    /// The exponent p of the weighted power mean σ̄a = (Σ w σa^p / Σ w)^{1/p}, in (0, 1]
    /// (default 7/8). p = 1 is the first-order (Born/Rytov) average; p = ½ is close to
    /// averaging σtr ∝ √σa (the eikonal picture). Chosen by measurement
    /// (docs/kernel.md#measurements). σs is averaged arithmetically.
    pub exponent: f64,
    /// `Prefiltered` (default): where the pair is flat ([`KernelParams::flatness`]) and the
    /// field answers at points of space ([`CoefficientField::averaged_at_point`]), the points
    /// are read in the averaging plane, which is then the surface, without projection rays;
    /// elsewhere they are projected. `MonteCarlo`: always project (the estimator as derived).
    /// The points and weights are the same either way.
    pub averaging: Averaging,
    /// When a pair counts as flat for [`KernelParams::averaging`] (Sone's criterion).
    pub flatness: Flatness,
}

impl KernelParams {
    /// Largest number of samples (the points are kept on the stack between iterations).
    pub const MAX_SAMPLES: u32 = 1024;
    /// Largest number of iterations.
    pub const MAX_ITERATIONS: u32 = 8;

    /// The defaults: 64 points, 2 iterations, hits only, power mean p = 7/8 (chosen by
    /// measurement, docs/kernel.md#measurements).
    pub const fn new() -> Self {
        Self {
            samples: SampleBudget::fixed(64),
            iterations: 2,
            misses: MissPolicy::HitsOnly,
            exponent: 0.875,
            averaging: Averaging::Prefiltered,
            flatness: Flatness::DEFAULT,
        }
    }

    /// The same parameters with the points read in the plane where possible (`Prefiltered`)
    /// or always projected (`MonteCarlo`): [`KernelParams::averaging`].
    pub const fn with_averaging(mut self, averaging: Averaging) -> Self {
        self.averaging = averaging;
        self
    }

    /// The same parameters with `samples` points.
    pub const fn with_samples(mut self, samples: SampleBudget) -> Self {
        self.samples = samples;
        self
    }

    /// The same parameters with the power-mean exponent `exponent` (p of
    /// [`KernelParams::exponent`]).
    pub const fn with_exponent(mut self, exponent: f64) -> Self {
        self.exponent = exponent;
        self
    }

    /// The same parameters with `iterations` weighted averages.
    pub const fn with_iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
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

    /// Checks the parameters (used by `Estimator::prepare`): a fixed budget of at most
    /// [`Self::MAX_SAMPLES`] points, 1 to [`Self::MAX_ITERATIONS`] iterations, an exponent in
    /// (0, 1].
    pub fn validate(&self) -> Result<(), ParamError> {
        if !self.exponent.is_finite() {
            return Err(ParamError::NotFinite {
                name: "kernel exponent",
                value: self.exponent,
            });
        }
        if !(self.exponent > 0.0 && self.exponent <= 1.0) {
            return Err(ParamError::OutOfRange {
                name: "kernel exponent",
                range: "(0, 1]",
                value: self.exponent,
            });
        }
        match self.samples {
            SampleBudget::Fixed(n) if n.get() <= Self::MAX_SAMPLES => {}
            SampleBudget::Fixed(n) => {
                return Err(ParamError::OutOfRange {
                    name: "kernel samples",
                    range: "[1, 1024]",
                    value: n.get() as f64,
                });
            }
            _ => {
                return Err(ParamError::OutOfRange {
                    name: "kernel samples",
                    range: "a fixed budget",
                    value: f64::NAN,
                });
            }
        }
        if !(1..=Self::MAX_ITERATIONS).contains(&self.iterations) {
            return Err(ParamError::OutOfRange {
                name: "kernel iterations",
                range: "[1, 8]",
                value: self.iterations as f64,
            });
        }
        Ok(())
    }

    fn sample_count(&self) -> u32 {
        match self.samples {
            SampleBudget::Fixed(n) => n.get().min(Self::MAX_SAMPLES),
            SampleBudget::TargetRelError { max, .. } => max.get().min(Self::MAX_SAMPLES),
        }
    }
}

impl Default for KernelParams {
    fn default() -> Self {
        Self::new()
    }
}

/// The proposal density of the sample points, in chord coordinates (a along the chord from
/// its midpoint, b across it in the averaging plane; scene units): an equal mixture of two
/// isotropic laws centred on the chord's ends (−h, 0) and (h, 0), each with radial density
/// c/(ρ + c)² (so ρ = c·u/(1 − u) from a uniform u) and area density c/(2πρ(ρ + c)²).
///
/// Why this shape: W₂ is largest (log-singular) above the two sources and spreads along the
/// chord and over a few diffusion lengths around it, with a power-law tail ~ρ⁻³ when σa = 0;
/// the mixture has the singularity at the same places (so W₂/q → 0 there) and the same tail,
/// so the weights W₂/q stay bounded. The scale c is the larger of d/2 and the largest
/// transport mean free path of the starting estimate (capped at 100 d).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proposal {
    /// Half the chord length h = d/2.
    pub half: f64,
    /// The radial scale c (> 0).
    pub scale: f64,
}

impl Proposal {
    /// The point for `u` ∈ [0, 1)²: `u[0]` picks the end (below or above ½) and the radius,
    /// `u[1]` the angle.
    #[inline]
    pub fn sample(&self, u: [f64; 2]) -> DVec2 {
        let (centre, v) = if u[0] < 0.5 {
            (-self.half, 2.0 * u[0])
        } else {
            (self.half, 2.0 * u[0] - 1.0)
        };
        let rho = self.scale * v / (1.0 - v);
        let (s, c) = crate::sampling::sin_cos_turn(u[1]);
        DVec2::new(centre + rho * c, rho * s)
    }

    /// The distances of `p` from the chord's two ends (−h, 0) and (h, 0).
    #[inline]
    pub fn distances(&self, p: DVec2) -> (f64, f64) {
        (
            DVec2::new(p.x + self.half, p.y).length(),
            DVec2::new(p.x - self.half, p.y).length(),
        )
    }

    /// The area density (1/length²) of [`Proposal::sample`] at a point at `distances` from
    /// the two ends; +∞ at an end.
    #[inline]
    pub fn pdf(&self, distances: (f64, f64)) -> f64 {
        let c = self.scale;
        let radial = |r: f64| c / (2.0 * PI * r * (r + c) * (r + c));
        0.5 * (radial(distances.0) + radial(distances.1))
    }

    /// 1/[`Proposal::pdf`], and 0 where the pdf is infinite (at an end) or 0. In units of c
    /// (xₖ = ρₖ/c, Dₖ = xₖ(xₖ + 1)²), 1/q = 4πc²·D₀D₁/(D₀ + D₁): one division where the pdf
    /// takes three, and no overflow (xₖ ≤ 2⁵³ + 1 for the proposal's own points).
    #[inline]
    pub fn inv_pdf(&self, distances: (f64, f64)) -> f64 {
        let c = self.scale;
        let inv_c = 1.0 / c;
        let cube = |r: f64| {
            let x = r * inv_c;
            x * (x + 1.0) * (x + 1.0)
        };
        let (d0, d1) = (cube(distances.0), cube(distances.1));
        let v = (4.0 * PI * c * c) * (d0 * d1 / (d0 + d1));
        if v.is_finite() {
            v
        } else {
            // Both ends at once (0/0), or c² out of range: through the pdf itself.
            let q = self.pdf(distances);
            if q.is_finite() && q > 0.0 {
                1.0 / q
            } else {
                0.0
            }
        }
    }
}

/// Fewest points an iteration other than the last reweights (module docs, steps 3–4):
/// those iterations reweight the first max(`PILOT_POINTS`, N/4) of the N points.
///
/// They only choose the kernel of the next iteration, whose coefficients enter the weight
/// smoothly, so their noise reaches the final average at second order; the last iteration
/// reweights every point. Up to 64 points (the default) nothing changes; at 128 and 512
/// points the estimate costs 12 and 18 % less, and its spread is the same within 2 %
/// (docs/kernel.md#cost).
pub const PILOT_POINTS: usize = 64;

/// One looked-up sample point.
#[derive(Debug, Clone, Copy)]
struct Sample {
    /// Distances from the chord's ends (scene units).
    rho: (f64, f64),
    /// 1/q at the point (0 where q is infinite).
    inv_q: f64,
    /// σa^p per channel (p the power-mean exponent) and σs.
    a_p: [f64; 3],
    s: [f64; 3],
}

/// Estimates σ̄a, σ̄s for one pair (see the module docs). `g` is the material's HG mean
/// cosine and `table` its kernel table (prepared once).
pub(crate) fn estimate<S, F, U>(
    params: &KernelParams,
    g: f64,
    table: &KernelTable,
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
    probe.diag.region = Region::Kernel;
    // Step 1: start from the endpoint mean. Means live in the field's averaging space; the
    // kernel's weights need coefficients.
    let start = known.finish(probe.endpoints());
    let start_sigma = probe.to_coefficients(start);
    let pair = KernelPair {
        chord,
        d: chord.length(),
        g,
        table,
        exponent: if !probe.field.capabilities().own_averaging_space {
            params.exponent
        } else {
            1.0
        },
        wanted: std::array::from_fn(|c| !known.channel_constant(c)),
    };

    // Step 2: the points, projected and looked up once.
    let proposal = pair.proposal(&start_sigma);
    let lift_radius = lifting_radius(params, probe, &chord);
    // Uninitialised storage: zeroing 72 KiB per estimate would cost more than the estimate.
    let mut store = [const { MaybeUninit::<Sample>::uninit() }; KernelParams::MAX_SAMPLES as usize];
    let samples = pair.look_up(params, &proposal, lift_radius, probe, rng, &mut store);

    // Steps 3–4: reweight the same points with the kernel of the current estimate.
    pair.reweight(params, samples, start, probe, known)
}

/// What the steps of one pair's estimate share: the chord, the material's kernel, and the
/// channels averaged with their power-mean exponent.
struct KernelPair<'t> {
    chord: Chord,
    /// The chord length d.
    d: f64,
    /// The material's HG mean cosine.
    g: f64,
    /// The material's kernel table (W₂ per κ, in transport units).
    table: &'t KernelTable,
    /// The power-mean exponent p ([`KernelParams::exponent`]; 1 for a field with its own
    /// averaging space, whose means are arithmetic there).
    exponent: f64,
    /// The channels not known constant from the field's bounds.
    wanted: [bool; 3],
}

impl KernelPair<'_> {
    /// The proposal around the chord ([`Proposal`]): its scale c is the larger of d/2 and the
    /// longest transport mean free path 1/σt' of the starting estimate `start` (capped at
    /// 100 d).
    #[inline]
    fn proposal(&self, start: &Coefficients) -> Proposal {
        let reduced = |a: f64, s: f64| a + (1.0 - self.g) * s;
        let mut longest_mfp: f64 = 0.0;
        for c in (0..3).filter(|&c| self.wanted[c]) {
            let st = reduced(start.sigma_a[c], start.sigma_s[c]);
            if st > 0.0 {
                longest_mfp = longest_mfp.max(1.0 / st);
            }
        }
        Proposal {
            half: self.chord.half_len,
            scale: self.chord.half_len.max(longest_mfp.min(100.0 * self.d)),
        }
    }

    /// Step 2 (module docs): N points p_k drawn from `proposal` in the averaging plane,
    /// projected onto the surface by the two rays ±normal (paper §3.2) or read on the local
    /// quadric within `lift_radius` of the midpoint, and looked up once; the hits are stored
    /// in `store` with their distances from the chord's ends, 1/q, σa^p and σs, and returned.
    #[inline]
    fn look_up<'s, S, F, U>(
        &self,
        params: &KernelParams,
        proposal: &Proposal,
        lift_radius: f64,
        probe: &mut Probe<'_, S, F>,
        rng: &mut U,
        store: &'s mut [MaybeUninit<Sample>; KernelParams::MAX_SAMPLES as usize],
    ) -> &'s [Sample]
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
        U: UniformSource + ?Sized,
    {
        let chord = &self.chord;
        let n = params.sample_count() as usize;
        let miss_endpoints = params.misses == MissPolicy::Endpoints;
        let set = DiskPoints::new(rng);
        let mut len = 0usize;
        // The points a chunk at a time: read together in the plane, or projected together.
        let mut chunk = Chunk::new();
        for first in (0..n).step_by(CHUNK) {
            let m = CHUNK.min(n - first);
            chunk.draw(chord, proposal, &set, first, m);
            probe.lift_or_project(
                &chunk.origins[..m],
                chord.mid,
                lift_radius,
                chord.normal,
                &mut chunk.found[..m],
            );
            if miss_endpoints {
                for f in &mut chunk.found[..m] {
                    f.get_or_insert_with(|| probe.endpoints());
                }
            }
            len = chunk.store(m, self.exponent, store, len);
        }
        probe.diag.samples += n as u32;
        // SAFETY: the first `len` elements were initialised by `write` above (and `Sample` is
        // `Copy`, so nothing needs dropping).
        unsafe { std::slice::from_raw_parts(store.as_ptr().cast::<Sample>(), len) }
    }

    /// Steps 3–4 (module docs): [`KernelParams::iterations`] weighted averages of the same
    /// `samples`, each with the kernel W₂ of the previous estimate (the first with that of
    /// `start`, the endpoint mean). Sets [`crate::Diagnostics::fallback`] when the last left
    /// a channel at its previous estimate.
    #[inline]
    fn reweight<S, F>(
        &self,
        params: &KernelParams,
        samples: &[Sample],
        start: Coefficients,
        probe: &mut Probe<'_, S, F>,
        known: &Known,
    ) -> Coefficients
    where
        S: SurfaceQuery + ?Sized,
        F: CoefficientField<S::Point> + ?Sized,
    {
        let n = params.sample_count() as usize;
        let mut est = start;
        let mut fell_back = false;
        for iteration in 0..params.iterations {
            // Every iteration but the last only sets the next one's kernel: a pilot prefix of
            // the points serves it (an R2 prefix, spread over the whole proposal).
            let used = if iteration + 1 < params.iterations {
                &samples[..samples.len().min(PILOT_POINTS.max(n / 4))]
            } else {
                samples
            };
            let (next, fell) = self.weighted_average(used, est, probe.to_coefficients(est));
            fell_back = fell;
            est = known.finish(next);
        }
        probe.diag.fallback |= fell_back;
        est
    }

    /// Step 3 (module docs), one iteration: per channel, the W₂/q-weighted (power) means of
    /// `used` with the kernel of the current estimate `est` (whose coefficients are `sigma`);
    /// a channel without a weight keeps `est` (the flag returned).
    #[inline]
    fn weighted_average(
        &self,
        used: &[Sample],
        est: Coefficients,
        sigma: Coefficients,
    ) -> (Coefficients, bool) {
        let wanted = self.wanted;
        let mut next = est;
        let mut fell_back = false;
        let mut done = [false; 3];
        for c in (0..3).filter(|&c| wanted[c]) {
            if done[c] {
                continue;
            }
            // Channels with the same current coefficients share the weights (grey media: one
            // weight per point for all three channels).
            let group: [bool; 3] = std::array::from_fn(|k| {
                wanted[k]
                    && !done[k]
                    && sigma.sigma_a[k] == sigma.sigma_a[c]
                    && sigma.sigma_s[k] == sigma.sigma_s[c]
            });
            (0..3).for_each(|k| done[k] |= group[k]);
            let medium = (sigma.sigma_a[c], sigma.sigma_s[c], self.g);
            match weighted_means(used, group, medium, self.d, self.table, self.exponent) {
                Some(means) => {
                    for k in (0..3).filter(|&k| group[k]) {
                        next.sigma_a[k] = means[k].0;
                        next.sigma_s[k] = means[k].1;
                    }
                }
                None => fell_back = true,
            }
        }
        (next, fell_back)
    }
}

/// One chunk of step 2's points (at most [`CHUNK`]), handled in passes with no dependency
/// from one point to the next (the processor overlaps the points' square roots): the points
/// and their densities ([`Chunk::draw`]), the values (`found`, by the caller), then σa^p and
/// the stored samples ([`Chunk::store`]).
struct Chunk {
    /// The points in the averaging plane (scene space).
    origins: [DVec3; CHUNK],
    /// The coefficients read or projected at each point (`None`: a miss).
    found: [Option<Coefficients>; CHUNK],
    /// Distances from the chord's ends, and 1/q.
    rho: [(f64, f64); CHUNK],
    inv_q: [f64; CHUNK],
}

impl Chunk {
    #[inline]
    fn new() -> Self {
        Chunk {
            origins: [DVec3::ZERO; CHUNK],
            found: [None; CHUNK],
            rho: [(0.0, 0.0); CHUNK],
            inv_q: [0.0; CHUNK],
        }
    }

    /// Points `first..first + m` of `set`, drawn from `proposal` in chord coordinates and
    /// placed in the averaging plane of `chord`, with their distances from its ends and 1/q.
    #[inline]
    fn draw(
        &mut self,
        chord: &Chord,
        proposal: &Proposal,
        set: &DiskPoints,
        first: usize,
        m: usize,
    ) {
        for j in 0..m {
            let p = proposal.sample(set.unit_square((first + j) as u32));
            self.origins[j] = chord.mid + p.x * chord.x_hat + p.y * chord.minor_dir;
            self.rho[j] = proposal.distances(p);
            self.inv_q[j] = proposal.inv_pdf(self.rho[j]);
        }
    }

    /// σa^p in place of σa for the first `m` points found, then those points stored as
    /// samples in `store` after its first `len`; the new length.
    #[inline]
    fn store(
        &mut self,
        m: usize,
        exponent: f64,
        store: &mut [MaybeUninit<Sample>; KernelParams::MAX_SAMPLES as usize],
        mut len: usize,
    ) -> usize {
        for c in self.found[..m].iter_mut().flatten() {
            c.sigma_a.0 = power(c.sigma_a.0, exponent);
        }
        for j in 0..m {
            if let Some(c) = self.found[j] {
                store[len].write(Sample {
                    rho: self.rho[j],
                    inv_q: self.inv_q[j],
                    a_p: c.sigma_a.0,
                    s: c.sigma_s.0,
                });
                len += 1;
            }
        }
        len
    }
}

/// The radius around the chord's midpoint within which step 2 reads its points on the pair's
/// local quadric (in the plane, where the pair is flat) instead of projecting them by rays:
/// with [`Averaging::Prefiltered`], for a field defined in space, or read through texture
/// coordinates that are one affine map over the region; 0 (every point projected) otherwise.
#[inline]
fn lifting_radius<S, F>(params: &KernelParams, probe: &mut Probe<'_, S, F>, chord: &Chord) -> f64
where
    S: SurfaceQuery + ?Sized,
    F: CoefficientField<S::Point> + ?Sized,
{
    if params.averaging == Averaging::Prefiltered
        && (probe.field.capabilities().point_lookup || probe.field.capabilities().reads_uv)
    {
        probe.prepare_prefilter(params.flatness, chord);
        let radius = probe.lifting_radius(&chord.ellipse(chord.half_len));
        if radius > 0.0 {
            probe.diag.field_averages += 1;
            if radius < f64::INFINITY {
                probe.diag.lifted = true;
            }
        } else {
            probe.diag.prefilter_fallback = true;
        }
        radius
    } else {
        0.0
    }
}

/// `a^p` per channel, computed once per distinct value (grey fields: once). The default
/// p = 7/8 is √a·⁴√a·⁸√a and p = 3/4 is √a·⁴√a: square roots instead of a `powf`.
#[inline]
fn power(a: [f64; 3], p: f64) -> [f64; 3] {
    let f = |x: f64| {
        if p == 1.0 {
            x
        } else if p == 0.875 {
            let r2 = x.sqrt();
            let r4 = r2.sqrt();
            r2 * r4 * r4.sqrt()
        } else if p == 0.75 {
            let r = x.sqrt();
            r * r.sqrt()
        } else {
            x.powf(p)
        }
    };
    let a0 = f(a[0]);
    let a1 = if a[1] == a[0] { a0 } else { f(a[1]) };
    let a2 = if a[2] == a[0] {
        a0
    } else if a[2] == a[1] {
        a1
    } else {
        f(a[2])
    };
    [a0, a1, a2]
}

/// The W₂/q-weighted means (σa as the power mean of exponent `exponent`, σs arithmetic) of
/// the channels selected by `group` of `samples` (the other channels' entries are 0, and
/// `group`'s channels with equal sums share one root), with
/// the kernel of a homogeneous medium (`sigma_a`, `sigma_s`, `g`) for a chord of length `d`;
/// `None` when that medium has no diffusion length (σt' = 0) or every weight is 0.
#[inline]
fn weighted_means(
    samples: &[Sample],
    group: [bool; 3],
    (sigma_a, sigma_s, g): (f64, f64, f64),
    d: f64,
    table: &KernelTable,
    exponent: f64,
) -> Option<[(f64, f64); 3]> {
    let st = sigma_a + (1.0 - g) * sigma_s;
    if !(st > 0.0 && st.is_finite()) {
        return None;
    }
    let kappa = (3.0 * sigma_a / st).sqrt();
    let d_t = d * st;
    let table = table.at_kappa(kappa);
    let (mut wa, mut ws, mut w) = ([0.0; 3], [0.0; 3], 0.0);
    // A batch at a time, in three passes (log-weights, weights, sums): the passes have no
    // dependency from one point to the next, so the processor overlaps the points (the sums
    // are in the points' order, as in one pass).
    let mut weights = [0.0; CHUNK];
    for batch in samples.chunks(CHUNK) {
        let weights = &mut weights[..batch.len()];
        for (l, s) in weights.iter_mut().zip(batch) {
            let (ri, ro) = (s.rho.0 * st, s.rho.1 * st);
            // W₂ relative to its exponential factor on the chord: ρ_i + ρ_o ≥ d, so the
            // exponent is ≤ h and nothing underflows near the chord whatever σt·d.
            *l = table.log_weight(ri, ro) - kappa * ((ri + ro) - d_t);
        }
        for (l, s) in weights.iter_mut().zip(batch) {
            *l = l.exp() * s.inv_q;
        }
        for (&weight, s) in weights.iter().zip(batch) {
            // A subnormal weight has lost its precision: weight·σ / weight would be off by
            // up to ~1e-9 relative (outside the field's range). Such a point carries nothing
            // next to any normal one, so it is dropped (all dropped: the caller's fallback);
            // as a zero, which adds nothing, rather than by a branch.
            let weight = if weight < f64::MIN_POSITIVE {
                0.0
            } else {
                weight
            };
            // Every channel is summed (cheaper than masking); only `group`'s are returned.
            for k in 0..3 {
                wa[k] += weight * s.a_p[k];
                ws[k] += weight * s.s[k];
            }
            w += weight;
        }
    }
    if !(w > 0.0 && w.is_finite()) {
        return None;
    }
    let mut means = [(0.0, 0.0); 3];
    for k in (0..3).filter(|&k| group[k]) {
        let (a_p, s) = (wa[k] / w, ws[k] / w);
        // Grey fields: the channels' sums are equal, and the root is taken once.
        let a = match (0..k).find(|&j| group[j] && wa[j] == wa[k]) {
            Some(j) => means[j].0,
            None if exponent == 1.0 => a_p,
            None => a_p.powf(1.0 / exponent),
        };
        means[k] = (a, s);
    }
    Some(means)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;
    use bssrdf_core::chi_square::ChiSquareTest;

    /// The square-root forms of a^p equal `powf` to within a few ulps, from 0 to 1e6.
    #[test]
    fn powers_by_square_roots_are_powf() {
        for p in [0.875, 0.75] {
            for x in [0.0, 1e-300, 1e-12, 0.005, 0.1, 0.37, 1.0, 2.5, 1e3, 1e6] {
                let [got, ..] = power([x, x, x], p);
                let want = x.powf(p);
                assert!(
                    (got - want).abs() <= 8.0 * f64::EPSILON * want,
                    "{x}^{p}: {got} against {want}"
                );
            }
        }
    }

    /// `inv_pdf` is 1/`pdf` (to rounding) over twelve decades of distance, 0 at an end, and
    /// finite where the products overflow.
    #[test]
    fn inverse_pdf_is_the_pdfs_inverse() {
        for scale in [1e-3, 1.5, 1e4] {
            let prop = Proposal { half: 0.7, scale };
            for r0 in [1e-6, 0.01, 0.7, 1.4, 3.0, 1e3, 1e6] {
                for r1 in [1e-6, 0.3, 1.4, 50.0, 1e6] {
                    let (got, want) = (prop.inv_pdf((r0, r1)), 1.0 / prop.pdf((r0, r1)));
                    assert!((got - want).abs() <= 1e-13 * want, "{got} against {want}");
                }
            }
            assert_eq!(prop.inv_pdf((0.0, 1.4)), 0.0);
            assert_eq!(prop.inv_pdf((1.4, 0.0)), 0.0);
        }
        // Scene units far from 1: the same relation.
        let huge = Proposal {
            half: 1e150,
            scale: 1e150,
        };
        let unit = Proposal {
            half: 1.0,
            scale: 1.0,
        };
        let (got, want) = (huge.inv_pdf((1e150, 3e150)), 1e300 / unit.pdf((1.0, 3.0)));
        assert!(
            want.is_finite() && (got - want).abs() <= 1e-13 * want,
            "{got} against {want}"
        );
    }

    /// The proposal's points follow its pdf: chi-square over polar cells around the first
    /// end (12 rings equal in u = ρ/(ρ + c), the last reaching ∞, × 16 sectors), with each
    /// cell's expected probability integrated numerically from `pdf` in (u, φ) coordinates.
    /// 200,000 points, i.i.d. (each from its own shifted set), fixed seed, significance 1e-4.
    #[test]
    fn proposal_points_follow_its_pdf_chi_square() {
        let prop = Proposal {
            half: 1.5,
            scale: 1.5,
        };
        let (rings, sectors) = (12usize, 16usize);
        let cell_of = |p: DVec2| {
            let rel = p - DVec2::new(-prop.half, 0.0);
            let rho = rel.length();
            let u = rho / (rho + prop.scale);
            let ring = ((u * rings as f64) as usize).min(rings - 1);
            let phi = rel.y.atan2(rel.x).rem_euclid(2.0 * PI);
            let sector = ((phi / (2.0 * PI)) * sectors as f64) as usize % sectors;
            ring * sectors + sector
        };
        let n = 200_000u64;
        let mut counts = vec![0u64; rings * sectors];
        let mut rng = SplitMix64::new(11);
        for i in 0..n {
            let u = DiskPoints::new(&mut rng).unit_square((i % 97) as u32);
            counts[cell_of(prop.sample(u))] += 1;
        }
        // ∫ q dA over each cell: dA = ρ dρ dφ, ρ = c u/(1 − u), dρ/du = c/(1 − u)².
        let mut expected = vec![0f64; rings * sectors];
        for (cell, e) in expected.iter_mut().enumerate() {
            let (ring, sector) = (cell / sectors, cell % sectors);
            // The other end (u = 2/3, φ = 0) is a corner of four cells: its 1/ρ singularity
            // needs a finer rule there.
            let touches_other_end = (ring == 7 || ring == 8) && (sector == 0 || sector == 15);
            let m = if touches_other_end { 800 } else { 48 };
            let (du, dphi) = (1.0 / rings as f64, 2.0 * PI / sectors as f64);
            let mut sum = 0.0;
            for a in 0..m {
                for b in 0..m {
                    let u = (ring as f64 + (a as f64 + 0.5) / m as f64) * du;
                    let phi = (sector as f64 + (b as f64 + 0.5) / m as f64) * dphi;
                    let rho = prop.scale * u / (1.0 - u);
                    let jac = rho * prop.scale / ((1.0 - u) * (1.0 - u));
                    let p = DVec2::new(-prop.half + rho * phi.cos(), rho * phi.sin());
                    sum += prop.pdf(prop.distances(p)) * jac;
                }
            }
            *e = sum * du * dphi / (m * m) as f64 * n as f64;
        }
        let total: f64 = expected.iter().sum();
        assert!((total / n as f64 - 1.0).abs() < 1e-3, "{total}");
        let r = ChiSquareTest::SINGLE.check(&counts, &expected).unwrap();
        assert!(r.passes(), "{r}");
    }

    #[test]
    fn params_are_validated() {
        assert!(KernelParams::new().validate().is_ok());
        let too_many = KernelParams::new().with_samples(SampleBudget::fixed(2000));
        assert!(too_many.validate().is_err());
        assert!(KernelParams::new().with_iterations(0).validate().is_err());
        assert!(KernelParams::new().with_iterations(9).validate().is_err());
        for p in [0.0, -0.5, 1.5, f64::NAN] {
            assert!(
                KernelParams::new().with_exponent(p).validate().is_err(),
                "{p}"
            );
        }
        assert!(KernelParams::new().with_exponent(1.0).validate().is_ok());
        let adaptive = KernelParams::new().with_samples(SampleBudget::TargetRelError {
            rel_se: 0.01,
            max: std::num::NonZeroU32::new(64).unwrap(),
        });
        assert!(adaptive.validate().is_err());
    }

    #[test]
    fn weights_are_finite_at_extremes() {
        let table = KernelTable::shared(1.0);
        let samples = [
            Sample {
                rho: (0.0, 1.0),
                inv_q: 0.0,
                a_p: [0.1; 3],
                s: [1.0; 3],
            },
            Sample {
                rho: (1e12, 1e12),
                inv_q: 1e36,
                a_p: [0.2; 3],
                s: [1.0; 3],
            },
            Sample {
                rho: (0.5, 0.6),
                inv_q: 1.0,
                a_p: [0.3; 3],
                s: [2.0; 3],
            },
        ];
        for (a, s, g) in [
            (0.0, 1.0, 0.0),
            (1.0, 0.0, 0.0),
            (1e6, 1e6, 0.9),
            (1e-6, 1e-6, -0.9),
        ] {
            for d in [1e-9, 1.0, 1e6] {
                if let Some(m) = weighted_means(&samples, [true; 3], (a, s, g), d, &table, 1.0) {
                    let (ma, ms) = m[0];
                    assert!(ma.is_finite() && ms.is_finite(), "{a} {s} {g} {d}");
                    assert!((0.1..=0.3).contains(&ma), "{ma}");
                }
            }
        }
        assert!(weighted_means(&samples, [true; 3], (0.0, 0.0, 0.0), 1.0, &table, 1.0).is_none());
    }
}
