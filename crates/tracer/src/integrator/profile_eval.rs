//! The material's diffuse reflectance profile evaluated at the homogeneous coefficients an
//! estimate gives for a pair (the paper's Eq. 1 kernel R, per channel): the half-space profile
//! at a distance, or the slab profile of a thin part (`bssrdf_core::slab_profile`). Coefficients
//! the profile family rejects give 0 in that channel and are counted in
//! [`PathCounters::profile_failures`], so that no failure biases an image silently.

use bssrdf_core::{ProfileFamily, RadialProfile, Rgb, SlabFace};
use het_estimate::Coefficients;

use crate::integrator::counters::PathCounters;

/// The diffuse reflectance profile `R(r)` (1/length², the paper's Eq. 1 kernel) of the
/// coefficients `c`, per channel, at distance `r`. A channel whose coefficients `family`
/// rejects contributes 0 and is counted in [`PathCounters::profile_failures`].
pub fn eval_profile(
    family: &ProfileFamily,
    c: Coefficients,
    r: f64,
    counters: &mut PathCounters,
) -> Rgb {
    per_distinct_channel(c, counters, |counters, sigma_a, sigma_s| {
        eval_profile_channel(family, sigma_a, sigma_s, r, counters)
    })
}

/// `eval(counters, σa, σs)` for each channel of `c`, evaluated once per distinct pair of
/// coefficients (a grey material costs one evaluation, not three); a channel equal to an
/// earlier one repeats its value and, when that failed, its failure count.
#[inline]
fn per_distinct_channel(
    c: Coefficients,
    counters: &mut PathCounters,
    mut eval: impl FnMut(&mut PathCounters, f64, f64) -> f64,
) -> Rgb {
    let mut rd = Rgb::ZERO;
    let mut failed = [0u64; 3];
    for ch in 0..3 {
        let key = (c.sigma_a[ch].to_bits(), c.sigma_s[ch].to_bits());
        if let Some(e) = (0..ch).find(|&e| (c.sigma_a[e].to_bits(), c.sigma_s[e].to_bits()) == key)
        {
            rd[ch] = rd[e];
            failed[ch] = failed[e];
            counters.profile_failures += failed[e];
            continue;
        }
        let before = counters.profile_failures;
        rd[ch] = eval(counters, c.sigma_a[ch], c.sigma_s[ch]);
        failed[ch] = counters.profile_failures - before;
    }
    rd
}

/// [`eval_profile`] for one channel's coefficients (1/length).
pub fn eval_profile_channel(
    family: &ProfileFamily,
    sigma_a: f64,
    sigma_s: f64,
    r: f64,
    counters: &mut PathCounters,
) -> f64 {
    match family.profile(sigma_a, sigma_s) {
        Ok(profile) => profile.eval(r),
        Err(_) => {
            counters.profile_failures += 1;
            0.0
        }
    }
}

/// The slab profile of `family` at coefficients `c` and thickness `d` (length; +∞ for the
/// half-space), on `face` at distance `r` (1/length², per channel); a family without a slab
/// table gives its half-space profile at `r`. Failures count as [`eval_profile`]'s.
pub fn eval_slab_profile(
    family: &ProfileFamily,
    c: Coefficients,
    d: f64,
    face: SlabFace,
    r: f64,
    counters: &mut PathCounters,
) -> Rgb {
    per_distinct_channel(c, counters, |counters, sigma_a, sigma_s| {
        // As deep as the half-space: the slab table's own limit, without building it.
        if family.slab_is_half_space(sigma_a, sigma_s, d) {
            return match face {
                SlabFace::Reflection => eval_profile_channel(family, sigma_a, sigma_s, r, counters),
                SlabFace::Transmission => 0.0,
            };
        }
        match family.slab(sigma_a, sigma_s, d) {
            Ok(Some(slab)) => slab.eval(face, r),
            Ok(None) => eval_profile_channel(family, sigma_a, sigma_s, r, counters),
            Err(_) => {
                counters.profile_failures += 1;
                0.0
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Counters;
    use bssrdf_core::{ProfileModel, Scattering};

    #[test]
    fn rejected_profiles_are_counted_not_silent() {
        let family =
            ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0).unwrap();
        let mut c = PathCounters::default();
        let ok = eval_profile_channel(&family, 0.01, 1.0, 0.5, &mut c);
        assert!(ok.is_finite() && ok > 0.0, "{ok}");
        assert_eq!(c.profile_failures, 0);
        // Above the profiles' bound (1e12) and negative: 0, each counted.
        assert_eq!(eval_profile_channel(&family, 1e13, 1.0, 0.5, &mut c), 0.0);
        assert_eq!(eval_profile_channel(&family, -1.0, 1.0, 0.5, &mut c), 0.0);
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
        let coeffs = |a: [f64; 3], s: [f64; 3]| Coefficients {
            sigma_a: Rgb(a),
            sigma_s: Rgb(s),
        };
        for (c, failures) in [
            (coeffs([0.01, 0.01, 0.2], [1.0, 1.0, 1.0]), 0),
            (coeffs([0.01, 0.3, 0.01], [1.0, 2.0, 1.0]), 0),
            (coeffs([-1.0, 0.05, -1.0], [1.0, 1.0, 1.0]), 2),
            (coeffs([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]), 3),
        ] {
            for d in [0.7, 3.0, 1e4, f64::INFINITY] {
                for face in [SlabFace::Reflection, SlabFace::Transmission] {
                    let mut counters = PathCounters::default();
                    let got = eval_slab_profile(&family, c, d, face, 0.4, &mut counters);
                    assert_eq!(counters.profile_failures, failures);
                    for ch in 0..3 {
                        let mut one = PathCounters::default();
                        let want = eval_slab_profile(
                            &family,
                            coeffs([c.sigma_a[ch]; 3], [c.sigma_s[ch]; 3]),
                            d,
                            face,
                            0.4,
                            &mut one,
                        );
                        assert_eq!(got[ch], want[0], "{c:?} d {d} {face:?} channel {ch}");
                    }
                }
            }
            let mut counters = PathCounters::default();
            let got = eval_profile(&family, c, 0.4, &mut counters);
            assert_eq!(counters.profile_failures, failures);
            for ch in 0..3 {
                let mut one = PathCounters::default();
                let want =
                    eval_profile_channel(&family, c.sigma_a[ch], c.sigma_s[ch], 0.4, &mut one);
                assert_eq!(got[ch], want);
            }
        }
    }
}
