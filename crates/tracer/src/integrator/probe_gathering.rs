//! The tracer's side of probe-ray sampling: incident points on the tracer's objects by the
//! library's sampler ([`het_estimate::probe`], which documents the technique and its density)
//! over the per-object BVH ([`ObjectSurface`]'s probe chords), and how a BSSRDF vertex uses
//! the points it found ([`Gathering`]: which gather light, which carries the path on).

use bssrdf_core::ProfileFamily;
use glam::DVec3;
use het_estimate::Coefficients;
use het_estimate::azimuth::GuidedAzimuths;
use het_estimate::probe::{self as lib, ProbeChords};

pub use het_estimate::probe::{MAX_PROBE_HITS, PROBE_ENERGY_FRACTION};

use crate::field::MediumField;
use crate::geometry::{Geometry, Hit, ObjectSurface, Ray};
use crate::rng::Rng;

/// The profile table and fallback coefficients of one translucent material.
pub struct ProbeSampler(lib::ProbeSampler);

impl ProbeSampler {
    /// Builds the table of `family` (once per material); the probe spheres cover every
    /// profile the medium's estimates can become (its bounds).
    pub fn new(family: ProfileFamily, medium: &MediumField) -> Self {
        Self(lib::ProbeSampler::new(family, medium.field_bounds()))
    }

    /// The largest probe radius over the channels at coefficients `c` (0 if none scatters).
    pub fn probe_radius(&self, c: Coefficients) -> f64 {
        self.0.probe_radius(c)
    }

    /// [`probe_within`] over any surface of tracer hits: the object (`ObjectSurface`), or the
    /// shape correction's tangent plane.
    pub(crate) fn probe_chords<C: ProbeChords<Point = Hit>>(
        &self,
        chords: &C,
        x_o: &Hit,
        coeffs: Coefficients,
        max_radius: f64,
        rng: &mut Rng,
    ) -> ProbeSet {
        lib::probe_within(chords, x_o, coeffs, &self.0, max_radius, rng)
    }

    /// The same probes without the weights ([`lib::probe_points_within_into`]): the density
    /// of the probes around `x_o`, radii capped at `max_radius`, the normal probe's azimuth
    /// drawn from `guide` where there is one ([`lib::ProbeDensity::around`]); its
    /// `trace_into` traces them and weights each point on demand.
    pub(crate) fn density_around<'a>(
        &'a self,
        x_o: &Hit,
        coeffs: Coefficients,
        max_radius: f64,
        guide: Option<&'a GuidedAzimuths<'a>>,
    ) -> lib::ProbeDensity<'a> {
        lib::ProbeDensity::around(x_o, coeffs, &self.0, max_radius, guide)
    }
}

/// A found incident point and its estimator weight `1/p(x)`.
pub type ProbeHit = lib::ProbeHit<Hit>;
/// The incident points found by the three probes of one camera sample.
pub type ProbeSet = lib::ProbeSet<Hit>;
/// The incident points found by the three probes of one camera sample, before their weights.
pub type ProbePoints = lib::ProbePoints<Hit>;

impl ProbeChords for ObjectSurface<'_> {
    type Point = Hit;
    #[inline]
    fn for_each_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, f: &mut dyn FnMut(&Hit)) {
        self.geometry.for_each_object_hit(
            self.object,
            &Ray::with_range(origin, dir, 0.0, t_max),
            f,
        );
    }
}

/// Traces one probe per axis around `x_o` on `object`; `coeffs` are the coefficients at x_o
/// that shape the sampling density.
pub fn probe(
    geometry: &Geometry,
    object: u32,
    x_o: &Hit,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    rng: &mut Rng,
) -> ProbeSet {
    probe_within(geometry, object, x_o, coeffs, sampler, f64::INFINITY, rng)
}

/// [`probe`] with the probe radius at most `max_radius` ([`het_estimate::probe::probe_within`]).
pub fn probe_within(
    geometry: &Geometry,
    object: u32,
    x_o: &Hit,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    max_radius: f64,
    rng: &mut Rng,
) -> ProbeSet {
    sampler.probe_chords(
        &ObjectSurface { geometry, object },
        x_o,
        coeffs,
        max_radius,
        rng,
    )
}

/// The density `p(x)` (1/length²) with which [`probe`] around `x_o` finds `x_i`.
pub fn probe_density(x_o: &Hit, coeffs: Coefficients, sampler: &ProbeSampler, x_i: &Hit) -> f64 {
    lib::probe_density(x_o, coeffs, &sampler.0, x_i)
}

/// The density with which [`probe_within`] (radius at most `max_radius`) finds `x_i`.
pub fn probe_density_within(
    x_o: &Hit,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    max_radius: f64,
    x_i: &Hit,
) -> f64 {
    lib::probe_density_within(x_o, coeffs, &sampler.0, max_radius, x_i)
}

/// The MIS weight below which a probe point other than the carrier gathers light only by
/// Russian roulette ([`Gathering::weight_if_gathering`]). The points this skips are a tangent
/// probe's on a smooth surface (weights near 0 under the projection heuristic of
/// [`het_estimate::probe`]); on a body narrower than the probe spheres, where the balance
/// heuristic gives every probe a third or so, a threshold of 1 (roulette on every point)
/// raised a light-against-camera test's standard error 1.6× (`tests/reciprocity.rs`).
pub const ROULETTE_MIS: f64 = 0.2;

/// How the points of one probe set are used at a BSSRDF vertex: every point may gather light,
/// and one, the carrier, continues the path.
///
/// * The carrier is chosen in proportion to its MIS weight m_k, so that the path carries
///   (Σ m / m_k) times its estimator weight: under the projection heuristic the points'
///   weights differ by orders of magnitude on a curved surface, and a uniform choice (factor
///   n) would make the indirect light as noisy as that spread.
/// * A point other than the carrier whose MIS weight is below [`ROULETTE_MIS`] gathers with
///   probability m / [`ROULETTE_MIS`] (its weight divided by that): a tangent probe's hits on
///   a smooth surface then rarely cost a shadow ray and an estimate, which on
///   `marble-sphere.toml` saved a fifth of the render's time at the same noise
///   (docs/curved-objects.md, "Probes and light on curved surfaces").
pub struct Gathering {
    weights: [Option<lib::Weighed>; 3 * MAX_PROBE_HITS],
    carrier: usize,
    scale: f64,
}

impl Gathering {
    /// Weighs every point of `set` with `density` and chooses the carrier (one uniform draw
    /// from `rng`); `None` when no point has a weight.
    pub fn new(set: &ProbePoints, density: &lib::ProbeDensity<'_>, rng: &mut Rng) -> Option<Self> {
        let mut weights = [None; 3 * MAX_PROBE_HITS];
        let mut total = 0.0;
        for (k, (x_i, axis)) in set.found().enumerate() {
            weights[k] = density.weigh(x_i, axis);
            total += weights[k].map_or(0.0, |w| w.mis);
        }
        if total <= 0.0 {
            return None;
        }
        let u = rng.uniform() * total;
        let mut acc = 0.0;
        let (mut carrier, mut mis) = (0, 1.0);
        for (k, w) in weights[..set.len()].iter().enumerate() {
            if let Some(w) = w {
                (carrier, mis) = (k, w.mis);
                acc += w.mis;
                if u < acc {
                    break;
                }
            }
        }
        Some(Self {
            weights,
            carrier,
            scale: total / mis,
        })
    }

    /// The index (in the set's order) of the point that continues the path.
    pub fn carrier(&self) -> usize {
        self.carrier
    }

    /// The carrier's factor beyond its own estimator weight: Σ m / m_carrier, the inverse of
    /// the probability of choosing it.
    pub fn carrier_scale(&self) -> f64 {
        self.scale
    }

    /// Point `k`'s estimator weight (an area, 1/p_a(x) times its MIS weight, divided by its
    /// roulette survival probability) if it gathers light in this sample; `None` if it has no
    /// weight or the roulette dropped it (one uniform draw from `rng` for a point below
    /// [`ROULETTE_MIS`] that is not the carrier).
    pub fn weight_if_gathering(&self, k: usize, rng: &mut Rng) -> Option<f64> {
        let w = self.weights[k]?;
        if k != self.carrier && w.mis < ROULETTE_MIS {
            let survival = w.mis / ROULETTE_MIS;
            if rng.uniform() >= survival {
                return None;
            }
            return Some(w.weight / survival);
        }
        Some(w.weight)
    }
}
