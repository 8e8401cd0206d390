//! The three colour channels of a profile, prepared and evaluated together.
//!
//! A renderer's inner loop evaluates `R(r)` for every channel at every incident point; with
//! [`ProfileFamily::profile_rgb`] that is one call ([`RgbProfile::eval_rgb`]), and many radii
//! for one parameter set are one more ([`RgbProfile::eval_many`]). Channels with the same
//! coefficients (grey media) are evaluated once.
//!
//! # Cost (which call belongs where)
//! Measured with `cargo bench --bench profiles -- "per-material|rgb"` on the project's 2-core
//! machine while it was also compiling (so read them as upper bounds, ±50 %):
//! * **Per material, once:** [`ProfileFamily::new`] (Fresnel moments by quadrature) and
//!   [`crate::ProfileTable::new`] (about 0.15 ms for the dipole, 40 ms for photon beam
//!   diffusion).
//! * **Per pair of points:** [`ProfileFamily::profile_rgb`] plus [`RgbProfile::eval_rgb`]
//!   costs 0.26 µs for three distinct dipole channels and 21 µs for photon beam diffusion (a
//!   depth quadrature per channel). Where PBD is too slow for an inner loop, the table's
//!   tabulated evaluation ([`crate::table::RadiusSampler`]'s `eval`) costs the same for every
//!   model; it is an approximation, within 1.5 % of the exact profile weighted by energy but
//!   up to 35 % off at single radii in the far tail and near r = 0 (tested).
//! * **Never per sample:** [`RadialProfile::total`] and [`RadialProfile::radius_for_fraction`]
//!   integrate numerically wherever no closed form exists: with single scattering included,
//!   `total` costs 4 µs for the dipole and 2.3 ms for PBD, and `radius_for_fraction(0.999)`
//!   4.1 ms and 6.8 ms. Use the table's `total` and `radius_for_fraction` (0.2 µs) instead.

use crate::error::ParamError;
use crate::family::{Profile, ProfileFamily};
use crate::profile::RadialProfile;
use crate::rgb::Rgb;

/// One [`Profile`] per colour channel, from [`ProfileFamily::profile_rgb`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbProfile {
    channels: [Profile; 3],
    /// Every channel has the same coefficients: evaluate channel 0 only.
    grey: bool,
}

impl ProfileFamily {
    /// The profiles of the three channels of `(σa, σs)` (1/length per channel; each value
    /// validated as by [`ProfileFamily::profile`]). Cost: a few ns per channel, no allocation.
    pub fn profile_rgb(&self, sigma_a: Rgb, sigma_s: Rgb) -> Result<RgbProfile, ParamError> {
        let grey = sigma_a.0.iter().all(|&v| v == sigma_a[0])
            && sigma_s.0.iter().all(|&v| v == sigma_s[0]);
        let first = self.profile(sigma_a[0], sigma_s[0])?;
        let channels = if grey {
            [first; 3]
        } else {
            [
                first,
                self.profile(sigma_a[1], sigma_s[1])?,
                self.profile(sigma_a[2], sigma_s[2])?,
            ]
        };
        Ok(RgbProfile { channels, grey })
    }
}

impl RgbProfile {
    /// The profile of channel `c` (0, 1 or 2; larger values clamp to 2).
    pub fn channel(&self, c: usize) -> &Profile {
        &self.channels[c.min(2)]
    }

    /// `R(r)` of every channel (1/length² each; see [`RadialProfile::eval`]).
    #[inline]
    pub fn eval_rgb(&self, r: f64) -> Rgb {
        if self.grey {
            Rgb::splat(self.channels[0].eval(r))
        } else {
            Rgb(std::array::from_fn(|c| self.channels[c].eval(r)))
        }
    }

    /// `R(r)` of every channel at each radius of `radii`, written to the matching element of
    /// `out`. Only the first `min(radii.len(), out.len())` entries are evaluated.
    pub fn eval_many(&self, radii: &[f64], out: &mut [Rgb]) {
        for (o, &r) in out.iter_mut().zip(radii) {
            *o = self.eval_rgb(r);
        }
    }

    /// The total diffuse reflectance of every channel (see [`RadialProfile::total`] for its
    /// cost: per material, not per sample).
    pub fn total_rgb(&self) -> Rgb {
        if self.grey {
            Rgb::splat(self.channels[0].total())
        } else {
            Rgb(std::array::from_fn(|c| self.channels[c].total()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ProfileModel, Scattering};

    #[test]
    fn rgb_matches_the_channels_and_grey_is_shared() {
        let family = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.3, 1.3)
            .expect("valid family");
        let (sa, ss) = (Rgb::new(0.01, 0.1, 1.0), Rgb::new(1.0, 2.0, 0.5));
        let p = family.profile_rgb(sa, ss).unwrap();
        let radii = [0.0, 0.01, 0.5, 3.0, 1e6];
        let mut out = [Rgb::ZERO; 5];
        p.eval_many(&radii, &mut out);
        for (k, &r) in radii.iter().enumerate() {
            for c in 0..3 {
                let one = family.profile(sa[c], ss[c]).unwrap().eval(r);
                assert_eq!(out[k][c], one, "r {r} channel {c}");
                assert_eq!(p.eval_rgb(r)[c], one);
            }
        }
        // Distinct channels really differ (the test would not see a channel mix-up otherwise).
        assert!(out[2][0] != out[2][1] && out[2][1] != out[2][2]);
        let grey = family
            .profile_rgb(Rgb::splat(0.1), Rgb::splat(2.0))
            .unwrap();
        assert!(grey.grey);
        assert_eq!(
            grey.eval_rgb(0.5),
            Rgb::splat(family.profile(0.1, 2.0).unwrap().eval(0.5))
        );
        assert_eq!(
            p.total_rgb()[1],
            family.profile(sa[1], ss[1]).unwrap().total()
        );
    }

    #[test]
    fn invalid_channels_are_errors() {
        let family = ProfileFamily::new(ProfileModel::Pbd, Scattering::All, 0.0, 1.0).unwrap();
        assert!(
            family
                .profile_rgb(Rgb::new(0.1, f64::NAN, 0.1), Rgb::ONE)
                .is_err()
        );
        assert!(
            family
                .profile_rgb(Rgb::ONE, Rgb::new(1.0, 1.0, -1.0))
                .is_err()
        );
    }
}

#[cfg(test)]
mod table_accuracy {
    use crate::{ProfileFamily, ProfileModel, ProfileTable, RadialProfile, Scattering};

    /// The table's evaluation `total·pdf_r/(2πr)` against the exact profile, for the claim in
    /// the module docs: within 1.5 % weighted by r² (the energy per log-radius), although single
    /// radii in the far tail or near r = 0 differ by up to about 35 %.
    #[test]
    fn tabulated_evaluation_is_close_in_energy() {
        for model in [ProfileModel::Dipole, ProfileModel::Pbd] {
            let fam = ProfileFamily::new(model, Scattering::Multiple, 0.0, 1.3).unwrap();
            let table = ProfileTable::new(fam);
            let mut worst: f64 = 0.0;
            let mut worst_w: f64 = 0.0;
            for &sa in &[0.001, 0.003, 0.01, 0.03, 0.1, 0.3] {
                let exact = fam.profile(sa, 1.0).unwrap();
                let tab = table.sampler(sa, 1.0).unwrap();
                let (mut num, mut den) = (0.0, 0.0);
                for k in 0..400 {
                    let r = 0.01 * (1.0f64.exp().powf(k as f64 * 0.02));
                    let (a, b) = (exact.eval(r), tab.eval(r));
                    if a > 1e-6 * exact.eval(0.01) {
                        worst = worst.max((b / a - 1.0).abs());
                    }
                    num += (b - a).abs() * r * r;
                    den += a * r * r;
                }
                worst_w = worst_w.max(num / den);
            }
            assert!(worst_w < 0.015, "{model}: energy-weighted error {worst_w}");
            assert!(worst < 0.5, "{model}: pointwise error {worst}");
        }
    }
}
