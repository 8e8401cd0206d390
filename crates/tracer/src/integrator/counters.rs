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
    /// Profile evaluations whose estimated coefficients the profile rejected; those channels
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

    /// The diffuse reflectance profile `R(r)` (1/length², the paper's Eq. 1 kernel) of the
    /// coefficients `c`, per channel, at distance `r`. A channel whose coefficients `family`
    /// rejects contributes 0 and is counted in [`PathCounters::profile_failures`].
    pub fn eval_profile(
        &mut self,
        family: &bssrdf_core::ProfileFamily,
        c: het_estimate::Coefficients,
        r: f64,
    ) -> bssrdf_core::Rgb {
        self.per_distinct_channel(c, |counters, sigma_a, sigma_s| {
            counters.eval_profile_channel(family, sigma_a, sigma_s, r)
        })
    }

    /// `eval(self, σa, σs)` for each channel of `c`, evaluated once per distinct pair of
    /// coefficients (a grey material costs one evaluation, not three); a channel equal to an
    /// earlier one repeats its value and, when that failed, its failure count.
    #[inline]
    fn per_distinct_channel(
        &mut self,
        c: het_estimate::Coefficients,
        mut eval: impl FnMut(&mut Self, f64, f64) -> f64,
    ) -> bssrdf_core::Rgb {
        let mut rd = bssrdf_core::Rgb::ZERO;
        let mut failed = [0u64; 3];
        for ch in 0..3 {
            let key = (c.sigma_a[ch].to_bits(), c.sigma_s[ch].to_bits());
            if let Some(e) =
                (0..ch).find(|&e| (c.sigma_a[e].to_bits(), c.sigma_s[e].to_bits()) == key)
            {
                rd[ch] = rd[e];
                failed[ch] = failed[e];
                self.profile_failures += failed[e];
                continue;
            }
            let before = self.profile_failures;
            rd[ch] = eval(self, c.sigma_a[ch], c.sigma_s[ch]);
            failed[ch] = self.profile_failures - before;
        }
        rd
    }

    /// [`PathCounters::eval_profile`] for one channel's coefficients (1/length).
    pub fn eval_profile_channel(
        &mut self,
        family: &bssrdf_core::ProfileFamily,
        sigma_a: f64,
        sigma_s: f64,
        r: f64,
    ) -> f64 {
        use bssrdf_core::RadialProfile;
        match family.profile(sigma_a, sigma_s) {
            Ok(profile) => profile.eval(r),
            Err(_) => {
                self.profile_failures += 1;
                0.0
            }
        }
    }

    /// The slab profile of `family` at coefficients `c` and thickness `d` (length; +∞ for
    /// the half-space), on `face` at distance `r` (1/length², per channel); a family without
    /// a slab table gives its half-space profile at `r`. Failures count as
    /// [`PathCounters::eval_profile`]'s.
    pub fn eval_slab_profile(
        &mut self,
        family: &bssrdf_core::ProfileFamily,
        c: het_estimate::Coefficients,
        d: f64,
        face: bssrdf_core::SlabFace,
        r: f64,
    ) -> bssrdf_core::Rgb {
        self.per_distinct_channel(c, |counters, sigma_a, sigma_s| {
            // As deep as the half-space: the slab table's own limit, without building it.
            if family.slab_is_half_space(sigma_a, sigma_s, d) {
                return match face {
                    bssrdf_core::SlabFace::Reflection => {
                        counters.eval_profile_channel(family, sigma_a, sigma_s, r)
                    }
                    bssrdf_core::SlabFace::Transmission => 0.0,
                };
            }
            match family.slab(sigma_a, sigma_s, d) {
                Ok(Some(slab)) => slab.eval(face, r),
                Ok(None) => counters.eval_profile_channel(family, sigma_a, sigma_s, r),
                Err(_) => {
                    counters.profile_failures += 1;
                    0.0
                }
            }
        })
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

#[cfg(test)]
mod tests {
    use super::*;
    use bssrdf_core::{ProfileFamily, ProfileModel, Scattering};

    #[test]
    fn rejected_profiles_are_counted_not_silent() {
        let family =
            ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0).unwrap();
        let mut c = PathCounters::default();
        let ok = c.eval_profile_channel(&family, 0.01, 1.0, 0.5);
        assert!(ok.is_finite() && ok > 0.0, "{ok}");
        assert_eq!(c.profile_failures, 0);
        // Above the profiles' bound (1e12) and negative: 0, each counted.
        assert_eq!(c.eval_profile_channel(&family, 1e13, 1.0, 0.5), 0.0);
        assert_eq!(c.eval_profile_channel(&family, -1.0, 1.0, 0.5), 0.0);
        assert_eq!(c.profile_failures, 2);
        let mut merged = PathCounters::default();
        merged.merge(&c);
        assert_eq!(merged.profile_failures, 2, "merge drops the count");
    }

    /// Channels with equal coefficients are evaluated once but give, and count, what three
    /// evaluations would: the same values, and a failure per failing channel.
    #[test]
    fn equal_channels_are_evaluated_once_with_the_same_result() {
        let family =
            ProfileFamily::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.3).unwrap();
        let coeffs = |a: [f64; 3], s: [f64; 3]| het_estimate::Coefficients {
            sigma_a: bssrdf_core::Rgb(a),
            sigma_s: bssrdf_core::Rgb(s),
        };
        for (c, failures) in [
            (coeffs([0.01, 0.01, 0.2], [1.0, 1.0, 1.0]), 0),
            (coeffs([0.01, 0.3, 0.01], [1.0, 2.0, 1.0]), 0),
            (coeffs([-1.0, 0.05, -1.0], [1.0, 1.0, 1.0]), 2),
            (coeffs([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]), 3),
        ] {
            for d in [0.7, 3.0, 1e4, f64::INFINITY] {
                for face in [
                    bssrdf_core::SlabFace::Reflection,
                    bssrdf_core::SlabFace::Transmission,
                ] {
                    let mut counters = PathCounters::default();
                    let got = counters.eval_slab_profile(&family, c, d, face, 0.4);
                    assert_eq!(counters.profile_failures, failures);
                    for ch in 0..3 {
                        let mut one = PathCounters::default();
                        let want = one.eval_slab_profile(
                            &family,
                            coeffs([c.sigma_a[ch]; 3], [c.sigma_s[ch]; 3]),
                            d,
                            face,
                            0.4,
                        );
                        assert_eq!(got[ch], want[0], "{c:?} d {d} {face:?} channel {ch}");
                    }
                }
            }
            let mut counters = PathCounters::default();
            let got = counters.eval_profile(&family, c, 0.4);
            assert_eq!(counters.profile_failures, failures);
            for ch in 0..3 {
                let mut one = PathCounters::default();
                let want = one.eval_profile_channel(&family, c.sigma_a[ch], c.sigma_s[ch], 0.4);
                assert_eq!(got[ch], want);
            }
        }
    }
}
