//! Spectral MIS in chromatic media: free flights sampled with one *hero* channel, every channel
//! carried along (pbrt-v4 §14.2.2, the `VolPathIntegrator`; in the null-scattering path space
//! of pbrt-v4 §14.1.4–14.1.5, after Miller, Georgiev & Jarosz 2019).
//!
//! Where σa and σs differ between channels, one path samples its flights by delta tracking
//! against the hero channel h's majorant σ̄_h (Woodcock tracking as in [`crate::volume`]: a
//! tentative collision at rate σ̄_h absorbs with probability σa,h/σ̄_h, scatters with σs,h/σ̄_h,
//! and is null otherwise). Every channel c is carried: each sampled event multiplies the path
//! weight of channel c by the ratio of the density channel c's own (analog) tracking gives
//! that event to the hero's:
//! * a real scattering at distance t from the flight's start: T̄_c σs,c / (T̄_h σs,h), with
//!   T̄_c = exp(−σ̄_c t) the majorant transmittance of the flight;
//! * a null collision: σn,c / σn,h with σn = σ̄ − σa − σs (the T̄ factors are folded in at the
//!   flight's end, where the product of all of them is T̄ over the flight's whole length);
//! * reaching the end of the segment: T̄_c / T̄_h;
//! * absorption ends the path, which carries no light.
//!
//! Each channel's tracking being analog, its path density equals its integrand along the
//! flight, so one ratio q_c is at the same time the update of the throughput β_c = f_c / p_h
//! and of the rescaled unidirectional path density r_u,c = p_c / p_h (pbrt-v4's `beta` and
//! `r_u` get identical updates in the medium). The path tracer divides β by the mean of r_u
//! over the channels: f_c / ((1/3) Σ_k p_k), the one-sample balance heuristic over the three
//! channels as sampling techniques (Vea97 §9.2.4) — the hero being chosen uniformly. Only ratios
//! between the channels of q matter, so [`HeroTracking`] rescales it when its largest channel
//! leaves [1e-100, 1e100], and the product over any number of collisions neither overflows nor
//! underflows in the channel that counts. The path tracer's use, and what next-event estimation does: `integrator/path.rs`
//! and `docs/physics.md#spectral-mis`.
//!
//! Units: distances in scene units, coefficients in 1/scene unit; `dir` is a unit vector.

use bssrdf_core::Rgb;
use glam::DVec3;

use crate::field::MediumField;
use crate::rng::Rng;
use crate::volume::{FreeFlight, Interaction, TrackingCounters, unit_exponential};

/// Coefficients of every channel at a point: what hero tracking sees.
pub trait SpectralMedium {
    /// σa and σs (1/length) of every channel at `p`.
    fn coefficients(&self, p: DVec3) -> (Rgb, Rgb);
    /// A per-channel majorant σ̄ ≥ σa(x) + σs(x) for every point of the medium.
    fn majorant(&self) -> Rgb;
}

impl<M: SpectralMedium + ?Sized> SpectralMedium for &M {
    #[inline]
    fn coefficients(&self, p: DVec3) -> (Rgb, Rgb) {
        (**self).coefficients(p)
    }
    #[inline]
    fn majorant(&self) -> Rgb {
        (**self).majorant()
    }
}

/// All three channels of a scene's [`MediumField`] as a [`SpectralMedium`] (the path tracer's
/// walk in a chromatic medium). Coefficients come from the field's point lookup,
/// [`MediumField::at_point`], as [`crate::volume::ChannelView`]'s do.
pub struct SpectralView<'a> {
    field: &'a MediumField,
    majorant: Rgb,
    constant: Option<(Rgb, Rgb)>,
}

impl<'a> SpectralView<'a> {
    /// Every channel of `field`.
    pub fn new(field: &'a MediumField) -> Self {
        let constant = field.is_constant().then(|| {
            let c = field.at_point(DVec3::ZERO);
            (c.sigma_a, c.sigma_s)
        });
        Self {
            field,
            majorant: field.majorant(),
            constant,
        }
    }
}

impl SpectralMedium for SpectralView<'_> {
    #[inline]
    fn coefficients(&self, p: DVec3) -> (Rgb, Rgb) {
        if let Some(c) = self.constant {
            return c;
        }
        let c = self.field.at_point(p);
        (c.sigma_a, c.sigma_s)
    }
    fn majorant(&self) -> Rgb {
        self.majorant
    }
}

/// A medium walked with hero channel `hero` (0, 1 or 2) carrying every channel: the
/// [`FreeFlight`] of a chromatic medium.
pub struct HeroTracking<M> {
    /// The medium.
    pub medium: M,
    /// The channel whose coefficients drive the sampling.
    pub hero: usize,
}

impl<M: SpectralMedium> FreeFlight for HeroTracking<M> {
    /// The next real interaction along `origin + t·dir`, `t ∈ (0, t_max)`, by delta tracking
    /// with the majorant of the hero's channel, multiplying `weight` by each channel's density
    /// ratio to the hero's (see the module docs), rescaled when its largest channel leaves
    /// [1e-100, 1e100]. The hero's own channel is multiplied by 1 at every step, so it stays
    /// positive. `t_max` may be infinite only where the hero surely collides.
    #[inline]
    fn sample_flight(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        rng: &mut Rng,
        counters: &mut TrackingCounters,
        weight: &mut Rgb,
    ) -> Interaction {
        let hero = self.hero;
        let majorant = self.medium.majorant();
        let m_h = majorant[hero];
        if m_h.is_nan() || m_h <= 0.0 {
            // The hero sees vacuum: it passes with probability 1; the other channels'
            // densities of passing are their majorant transmittances.
            fold_majorant(weight, majorant, hero, t_max);
            return Interaction::Pass;
        }
        let mut t = 0.0;
        loop {
            t += unit_exponential(rng) / m_h;
            counters.delta_steps += 1;
            if t >= t_max {
                fold_majorant(weight, majorant, hero, t_max);
                return Interaction::Pass;
            }
            let (sigma_a, sigma_s) = self.medium.coefficients(origin + t * dir);
            let xi = rng.uniform() * m_h;
            if xi < sigma_a[hero] {
                return Interaction::Absorb { t };
            }
            if xi < sigma_a[hero] + sigma_s[hero] {
                // σs,h > xi − σa,h ≥ 0 here.
                *weight *= sigma_s * (1.0 / sigma_s[hero]);
                fold_majorant(weight, majorant, hero, t);
                return Interaction::Scatter { t };
            }
            // A null collision: σn,h ≥ σ̄_h − xi > 0.
            let sigma_n = (majorant - sigma_a - sigma_s).map(|s| s.max(0.0));
            *weight *= sigma_n * (1.0 / sigma_n[hero]);
            normalise(weight);
        }
    }
}

/// Rescales `weight` so that its largest channel is 1 when that channel has left
/// [1e-100, 1e100] (only ratios between channels matter, and the hero's channel, multiplied by
/// 1 at every step, stays near 1 otherwise); an infinite channel becomes 1 and the finite ones
/// 0, a weight with no positive channel is left as it is.
#[inline]
fn normalise(weight: &mut Rgb) {
    let max = weight.max_component();
    if (1e-100..=1e100).contains(&max) {
        return;
    }
    if max.is_infinite() {
        *weight = weight.map(|w| if w.is_infinite() { 1.0 } else { 0.0 });
    } else if max > 0.0 {
        *weight *= 1.0 / max;
    }
}

/// Multiplies `weight` by the majorant transmittance ratio T̄_c / T̄_h = exp(−(σ̄_c − σ̄_h) t)
/// of a flight of length `t`, then normalises it.
#[inline]
fn fold_majorant(weight: &mut Rgb, majorant: Rgb, hero: usize, t: f64) {
    let m_h = majorant[hero];
    for c in 0..3 {
        let d = majorant[c] - m_h;
        if d != 0.0 {
            weight[c] *= (-d * t).exp();
        }
    }
    normalise(weight);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two layers split at x = 1 with different coefficients per channel.
    struct Layers {
        left: (Rgb, Rgb),
        right: (Rgb, Rgb),
    }

    impl SpectralMedium for Layers {
        fn coefficients(&self, p: DVec3) -> (Rgb, Rgb) {
            if p.x < 1.0 { self.left } else { self.right }
        }
        fn majorant(&self) -> Rgb {
            (self.left.0 + self.left.1).zip_map(self.right.0 + self.right.1, f64::max)
        }
    }

    fn layers() -> Layers {
        Layers {
            left: (Rgb::new(0.1, 0.3, 0.05), Rgb::new(0.4, 1.2, 0.2)),
            right: (Rgb::new(0.5, 0.2, 1.0), Rgb::new(1.5, 0.6, 3.0)),
        }
    }

    /// The optical depth of channel `c` from 0 to `t` along +x through [`layers`].
    fn tau(c: usize, t: f64) -> f64 {
        let m = layers();
        let (l, r) = (m.left.0[c] + m.left.1[c], m.right.0[c] + m.right.1[c]);
        if t < 1.0 { l * t } else { l + r * (t - 1.0) }
    }

    /// The one-sample balance heuristic over the heroes: with the hero drawn uniformly and
    /// channel c scored w_c / mean(w) (β = r_u = w from 1), the estimates of every channel's
    /// transmittance T_c (passes) and of its first-scattering probability ∫ σs,c T_c dt over
    /// [0, t_max] (scatterings) are unbiased within 4 standard errors. In these layers no hero
    /// would do alone: hero 0's σn is 0 on the right, where channel 1's is 0.7, so hero 0
    /// never samples channel 1's null collisions there; the other heroes make up for it.
    #[test]
    fn balance_over_heroes_estimates_every_channels_transmittance_and_scattering() {
        let m = layers();
        let t_max = 2.0;
        // ∫₀^{t_max} σs,c(t) exp(−τ_c(t)) dt in closed form over the two layers.
        let scatter = |c: usize| {
            let (tl, sl) = (m.left.0[c] + m.left.1[c], m.left.1[c]);
            let (tr, sr) = (m.right.0[c] + m.right.1[c], m.right.1[c]);
            sl / tl * (1.0 - (-tl).exp())
                + (-tl).exp() * sr / tr * (1.0 - (-tr * (t_max - 1.0)).exp())
        };
        let n = 600_000;
        let mut rng = Rng::from_keys(31, &[]);
        let mut counters = TrackingCounters::default();
        let (mut pass, mut pass2) = (Rgb::ZERO, Rgb::ZERO);
        let (mut scat, mut scat2) = (Rgb::ZERO, Rgb::ZERO);
        for _ in 0..n {
            let hero = rng.below(3) as usize;
            let mut w = Rgb::ONE;
            let i = HeroTracking { medium: &m, hero }.sample_flight(
                DVec3::ZERO,
                DVec3::X,
                t_max,
                &mut rng,
                &mut counters,
                &mut w,
            );
            let score = w * (1.0 / w.mean());
            match i {
                Interaction::Pass => {
                    pass += score;
                    pass2 += score * score;
                }
                Interaction::Scatter { .. } => {
                    scat += score;
                    scat2 += score * score;
                }
                Interaction::Absorb { .. } => {}
            }
        }
        for c in 0..3 {
            for (sum, sum2, want, what) in [
                (pass[c], pass2[c], (-tau(c, t_max)).exp(), "transmittance"),
                (scat[c], scat2[c], scatter(c), "scattering"),
            ] {
                let mean = sum / n as f64;
                let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
                assert!(
                    (mean - want).abs() < 4.0 * se,
                    "channel {c} {what}: {mean} ± {se}, exact {want}"
                );
                assert!(se < 0.02 * want, "test too weak: {what} se {se}");
            }
        }
    }

    /// A weight that would overflow is rescaled, and the hero's channel stays positive.
    #[test]
    fn weights_stay_finite_over_long_walks() {
        let m = layers();
        let mut rng = Rng::from_keys(32, &[]);
        let mut counters = TrackingCounters::default();
        let mut w = Rgb::ONE;
        for _ in 0..100_000 {
            let i = HeroTracking {
                medium: &m,
                hero: 1,
            }
            .sample_flight(DVec3::ZERO, DVec3::X, 0.9, &mut rng, &mut counters, &mut w);
            if matches!(i, Interaction::Absorb { .. }) {
                continue;
            }
            assert!(
                w.is_finite() && w[1] > 0.0 && w.max_component() == 1.0,
                "{w:?}"
            );
        }
        // The hero sees vacuum: it passes, with the others' majorant transmittance.
        let vacuum = Layers {
            left: (Rgb::new(0.0, 1.0, 0.0), Rgb::ZERO),
            right: (Rgb::new(0.0, 1.0, 0.0), Rgb::ZERO),
        };
        let mut w = Rgb::ONE;
        let i = HeroTracking {
            medium: &vacuum,
            hero: 0,
        }
        .sample_flight(DVec3::ZERO, DVec3::X, 2.0, &mut rng, &mut counters, &mut w);
        assert_eq!(i, Interaction::Pass);
        assert_eq!(w, Rgb::new(1.0, (-2.0f64).exp(), 1.0));
    }
}
