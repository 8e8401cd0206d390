//! Probe-ray sampling of incident points on the tracer's objects: the library's sampler
//! ([`het_estimate::probe`], which documents the technique and its density) over the
//! per-object BVH.

use bssrdf_core::ProfileFamily;
use glam::DVec3;
use het_estimate::Coefficients;
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

    /// The same probes without the weights ([`lib::probe_points_within_into`]): the points
    /// into `points`, and the density that weights each on demand.
    pub(crate) fn probe_points_into<C: ProbeChords<Point = Hit>>(
        &self,
        points: &mut ProbePoints,
        chords: &C,
        x_o: &Hit,
        coeffs: Coefficients,
        max_radius: f64,
        rng: &mut Rng,
    ) -> lib::ProbeDensity<'_> {
        lib::probe_points_within_into(points, chords, x_o, coeffs, &self.0, max_radius, rng)
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
