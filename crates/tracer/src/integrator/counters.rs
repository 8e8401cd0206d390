//! Rare-event and work counters kept by the integrators (pbrt's `STAT_COUNTER` idea), merged
//! deterministically and printed beside timings so that no cap or fallback biases a result
//! silently.

use serde::Serialize;

use crate::render::Counters;
use crate::volume::TrackingCounters;

/// Counters of one render (or one row of it).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub struct PathCounters {
    /// Camera paths (or photons) started.
    pub paths: u64,
    /// Real scattering events inside media.
    pub scatterings: u64,
    /// Tentative collisions drawn by delta tracking.
    pub delta_steps: u64,
    /// Tentative collisions drawn by ratio tracking (shadow rays through media).
    pub ratio_steps: u64,
    /// Paths stopped by the collision cap inside one medium (see `walk::MAX_COLLISIONS`); their
    /// remaining contribution is lost, so a non-zero count means a (tiny) bias.
    pub capped: u64,
    /// Rays inside a closed object that found no boundary (slipped between triangles or
    /// started numerically outside); the path is terminated.
    pub leaks: u64,
    /// Boundary hits seen from the wrong side inside a medium (numerical), stepped over.
    pub wrong_side: u64,
    /// BSSRDF shading points that traced probes (the denominator of `probe_misses`).
    pub probe_sets: u64,
    /// BSSRDF shading points whose probes found no incident point.
    pub probe_misses: u64,
    /// BSSRDF parameter estimates made.
    pub estimates: u64,
    /// Averaging samples drawn by the estimators.
    pub estimator_samples: u64,
    /// Estimator projections that missed the object.
    pub projection_misses: u64,
    /// Estimates answered by the constant-field short-circuit.
    pub short_circuits: u64,
    /// Estimates where a channel fell back to the endpoint average (no hits at all).
    pub estimator_fallbacks: u64,
    /// Estimates with at least one region average answered by the field's prefiltered
    /// (constant-time) average instead of sampling.
    pub prefiltered: u64,
    /// Estimates where prefiltered averaging applied but some region was projected by rays
    /// (`het_estimate::Flatness`): the surface departs too far from the pair's local quadric
    /// there (a crease, a corner, a thin part, a region spanning much of a small object), or
    /// the texture coordinates of a UV-mapped field were not one affine map over the region
    /// (`het_estimate::UvChart`).
    pub prefilter_fallbacks: u64,
    /// Estimates where some region was sampled at points placed on the pair's local quadric,
    /// without rays (curved, but smooth enough for the quadric: `het_estimate::local_surface`).
    pub lifted: u64,
    /// Of those, estimates on flat pairs whose texture-coordinate charts disagreed (a UV seam
    /// or stretch between x_i and x_o).
    pub chart_fallbacks: u64,
    /// Profile evaluations ([`super::profile_eval`]) whose estimated coefficients the profile
    /// rejected; those channels
    /// contribute 0, so a non-zero count means a bias (never expected: scenes are validated
    /// with the profiles' own bounds at load).
    pub profile_failures: u64,
}

impl PathCounters {
    /// Records one parameter estimate and its diagnostics.
    pub fn record_estimate(&mut self, d: &het_estimate::Diagnostics) {
        self.estimates += 1;
        self.estimator_samples += d.samples as u64;
        self.projection_misses += d.misses as u64;
        self.short_circuits += d.short_circuit as u64;
        self.estimator_fallbacks += d.fallback as u64;
        self.prefiltered += (d.field_averages > 0) as u64;
        self.prefilter_fallbacks += d.prefilter_fallback as u64;
        self.lifted += d.lifted as u64;
        self.chart_fallbacks += d.chart_fallback as u64;
    }

    /// Adds tracking work.
    pub fn add_tracking(&mut self, t: &TrackingCounters) {
        self.delta_steps += t.delta_steps;
        self.ratio_steps += t.ratio_steps;
    }
}

impl Counters for PathCounters {
    fn merge(&mut self, o: &Self) {
        self.paths += o.paths;
        self.scatterings += o.scatterings;
        self.delta_steps += o.delta_steps;
        self.ratio_steps += o.ratio_steps;
        self.capped += o.capped;
        self.leaks += o.leaks;
        self.wrong_side += o.wrong_side;
        self.probe_sets += o.probe_sets;
        self.probe_misses += o.probe_misses;
        self.estimates += o.estimates;
        self.estimator_samples += o.estimator_samples;
        self.projection_misses += o.projection_misses;
        self.short_circuits += o.short_circuits;
        self.estimator_fallbacks += o.estimator_fallbacks;
        self.prefiltered += o.prefiltered;
        self.prefilter_fallbacks += o.prefilter_fallbacks;
        self.lifted += o.lifted;
        self.chart_fallbacks += o.chart_fallbacks;
        self.profile_failures += o.profile_failures;
    }
}
