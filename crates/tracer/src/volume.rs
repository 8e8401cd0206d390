//! Free-flight sampling and transmittance in heterogeneous media, one colour channel at a time.
//!
//! * [`sample_interaction`]: delta (Woodcock) tracking against a constant majorant σ̄ ≥ σt(x)
//!   (Woodcock et al. 1965; pbrt-v4 §14.2.2 and `SampleT_maj`). Tentative collisions are drawn
//!   at rate σ̄; at each one a single uniform number chooses absorption (probability σa/σ̄),
//!   real scattering (σs/σ̄) or a null collision (1 − σt/σ̄). This is an *analog* estimator: the
//!   path weight never changes, which keeps the estimators simple and lets the caller count
//!   scattering orders exactly. For a constant field the majorant equals σt, so null collisions
//!   never happen and the method reduces to exact exponential free-flight sampling.
//! * [`transmittance`]: residual ratio tracking (Novák, Selle & Jarosz 2014, "NSJ14", §5):
//!   with a control extinction σc ≤ σt(x) everywhere ([`ChannelMedium::control`], the field's
//!   smallest σt), the estimate is `exp(−σc d) · Π (1 − (σt(x_k) − σc)/(σ̄ − σc))` over
//!   tentative collisions drawn at the residual rate σ̄ − σc. It is unbiased for any σc in
//!   [0, min σt]; σc = 0 is plain ratio tracking. A larger σc draws fewer collisions (on the
//!   checker slab, σ̄ = 1.1 and σc = 1.005: about 12× fewer) and lowers the variance. An
//!   unbiased Russian roulette starts once the running product falls below [`RR_THRESHOLD`],
//!   so that shadow rays through stiff media cost O(1) expected steps beyond that point. For a
//!   constant field the exact `exp(−σt d)` is returned instead.
//!
//! Units: distances in scene units, coefficients in 1/scene unit. Directions must be unit
//! vectors so that `t` is a distance.

use bssrdf_core::Rgb;
use glam::DVec3;

use crate::field::MediumField;
use crate::rng::Rng;

/// Ratio tracking plays Russian roulette once the transmittance estimate drops below this.
pub const RR_THRESHOLD: f64 = 0.1;

/// Coefficients of one colour channel at a point: `(sigma_a, sigma_s)`.
pub trait ChannelMedium {
    /// σa and σs (1/length) of the traced channel at `p`.
    fn coefficients(&self, p: DVec3) -> (f64, f64);
    /// A majorant σ̄ ≥ σa(x) + σs(x) for every point of the medium.
    fn majorant(&self) -> f64;
    /// `Some((σa, σs))` when the channel is constant over the whole medium.
    fn constant(&self) -> Option<(f64, f64)>;
    /// A control extinction σc ≤ σa(x) + σs(x) for every point of the medium, used by
    /// [`transmittance`] (residual ratio tracking). The default, 0, is always valid.
    fn control(&self) -> f64 {
        0.0
    }
}

/// An exponential variate of rate 1, −ln(1 − u) with u uniform in [0, 1): finite and ≥ 0.
/// (`ln` of 1 − u rather than `ln_1p` of −u: the same numbers to within rounding, where it
/// cannot matter for a free-flight distance, at less than half the cost.)
#[inline]
pub(crate) fn unit_exponential(rng: &mut Rng) -> f64 {
    -(1.0 - rng.uniform()).ln()
}

/// Outcome of free-flight sampling along a segment `origin + t·dir`, `0 < t < t_max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Interaction {
    /// A real scattering event at distance `t`.
    Scatter {
        /// Distance along the ray.
        t: f64,
    },
    /// The path is absorbed at distance `t`.
    Absorb {
        /// Distance along the ray.
        t: f64,
    },
    /// No real collision before `t_max`: the path reaches the end of the segment.
    Pass,
}

/// Counters of the work done by the tracking routines (tentative collisions), for stats.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TrackingCounters {
    /// Tentative (real + null) collisions drawn by delta tracking.
    pub delta_steps: u64,
    /// Tentative collisions drawn by ratio tracking.
    pub ratio_steps: u64,
}

/// Samples the next real interaction along `origin + t·dir` for `t ∈ (0, t_max)` by delta
/// tracking (see the module docs). `t_max` may be infinite.
pub fn sample_interaction<M: ChannelMedium + ?Sized>(
    medium: &M,
    origin: DVec3,
    dir: DVec3,
    t_max: f64,
    rng: &mut Rng,
    counters: &mut TrackingCounters,
) -> Interaction {
    match next_collision(medium, origin, dir, t_max, u32::MAX, rng, counters) {
        // Absorption and scattering split the real collision by the same number: xi < σa.
        TrackedFlight::Collision(c) if c.xi < c.sigma_a => Interaction::Absorb { t: c.t },
        TrackedFlight::Collision(c) => Interaction::Scatter { t: c.t },
        TrackedFlight::Pass | TrackedFlight::Stopped => Interaction::Pass,
    }
}

/// A real collision found by delta tracking ([`next_collision`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    /// Distance along the ray.
    pub t: f64,
    /// σa there (1/length).
    pub sigma_a: f64,
    /// σs there (1/length).
    pub sigma_s: f64,
    /// The uniform number that made the tentative collision real, scaled by σ̄:
    /// `xi < σa + σs`. `xi < σa` chooses absorption in an analog walk
    /// ([`sample_interaction`]); a walk that weights by the albedo instead ignores it.
    pub xi: f64,
}

/// How a delta-tracked flight ends ([`next_collision`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrackedFlight {
    /// A real collision before `t_max`.
    Collision(Collision),
    /// No real collision before `t_max`.
    Pass,
    /// The guard on tentative collisions ran out first.
    Stopped,
}

/// Delta (Woodcock) tracking: the first real collision along `origin + t·dir`,
/// `t ∈ (0, t_max)`, drawing tentative collisions at the majorant's rate σ̄ and making each
/// real with probability σt/σ̄ (Woodcock et al. 1965; pbrt-v4 §14.2.2). Each tentative
/// collision draws two numbers, an exponential flight and the uniform `xi`, in that order.
/// At most `max_steps` tentative collisions are drawn (`u32::MAX`: no guard in practice). A
/// medium whose majorant is not positive is crossed without collision.
#[inline]
pub fn next_collision<M: ChannelMedium + ?Sized>(
    medium: &M,
    origin: DVec3,
    dir: DVec3,
    t_max: f64,
    max_steps: u32,
    rng: &mut Rng,
    counters: &mut TrackingCounters,
) -> TrackedFlight {
    let majorant = medium.majorant();
    if majorant.is_nan() || majorant <= 0.0 {
        return TrackedFlight::Pass;
    }
    let mut t = 0.0;
    for _ in 0..max_steps {
        t += unit_exponential(rng) / majorant;
        counters.delta_steps += 1;
        if t >= t_max {
            return TrackedFlight::Pass;
        }
        let (sigma_a, sigma_s) = medium.coefficients(origin + t * dir);
        let xi = rng.uniform() * majorant;
        if xi < sigma_a + sigma_s {
            return TrackedFlight::Collision(Collision {
                t,
                sigma_a,
                sigma_s,
                xi,
            });
        }
    }
    TrackedFlight::Stopped
}

/// A free-flight sampler the random walk ([`crate::integrator::walk`]) can use: the next real
/// interaction along `origin + t·dir`, `t ∈ (0, t_max)`, and what the sampled event does to
/// the per-channel path weight `weight` (which it multiplies; only ratios between its channels
/// matter, so a sampler may rescale it).
///
/// * One channel ([`ChannelMedium`], blanket implementation): analog delta tracking
///   ([`sample_interaction`]), the weight untouched: a grey medium, or a medium traced one
///   channel at a time.
/// * Every channel at once, sampled with a hero channel ([`crate::spectral::HeroTracking`]):
///   the weight takes the ratio of each channel's path density to the hero's (spectral MIS,
///   `docs/physics.md#spectral-mis`).
pub trait FreeFlight {
    /// Samples the next interaction (see the trait docs).
    fn sample_flight(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        rng: &mut Rng,
        counters: &mut TrackingCounters,
        weight: &mut Rgb,
    ) -> Interaction;
}

impl<M: ChannelMedium> FreeFlight for M {
    #[inline]
    fn sample_flight(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        rng: &mut Rng,
        counters: &mut TrackingCounters,
        _weight: &mut Rgb,
    ) -> Interaction {
        sample_interaction(self, origin, dir, t_max, rng, counters)
    }
}

/// Transmittance `exp(−∫₀^{t_max} σt)` along `origin + t·dir`: exact for constant media,
/// otherwise the residual ratio-tracking estimate against the medium's control extinction,
/// with Russian roulette below [`RR_THRESHOLD`] ([`ratio_tracking`]; unbiased, see the
/// module docs).
pub fn transmittance<M: ChannelMedium + ?Sized>(
    medium: &M,
    origin: DVec3,
    dir: DVec3,
    t_max: f64,
    rng: &mut Rng,
    counters: &mut TrackingCounters,
) -> f64 {
    if let Some((sigma_a, sigma_s)) = medium.constant() {
        let tau = (sigma_a + sigma_s) * t_max;
        return if tau.is_finite() { (-tau).exp() } else { 0.0 };
    }
    let tracking = RatioTracking {
        control: medium.control(),
        ending: LowTransmittance::Roulette(RR_THRESHOLD),
    };
    ratio_tracking(medium, origin, dir, t_max, tracking, rng, counters)
}

/// How [`ratio_tracking`] treats a running estimate that has become small.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LowTransmittance {
    /// Russian roulette once the estimate is below the threshold: it survives with
    /// probability estimate/threshold and goes on as the threshold. Unbiased, and O(1)
    /// expected steps beyond that point; what [`transmittance`] does.
    Roulette(f64),
    /// The estimate counts as 0 once it is below `floor` at a tentative collision, or after
    /// `max_steps` tentative collisions: a relative bias of at most `floor`, and no number
    /// drawn but the flights' (for walks whose numbers must stay in step with a twin's: the
    /// shape correction, `crate::correction`).
    Floor {
        /// The smallest estimate tracked further.
        floor: f64,
        /// The most tentative collisions drawn.
        max_steps: u32,
    },
}

/// The settings of one ratio-tracked transmittance ([`ratio_tracking`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatioTracking {
    /// The control extinction σc (1/length), clamped to [0, σ̄]: 0 is plain ratio tracking.
    pub control: f64,
    /// What happens to a small estimate.
    pub ending: LowTransmittance,
}

/// Residual ratio tracking (Novák, Selle & Jarosz 2014, §5): the unbiased transmittance
/// estimate `exp(−σc d) · Π (1 − (σt(x_k) − σc)/(σ̄ − σc))` over tentative collisions drawn at
/// the residual rate σ̄ − σc along `origin + t·dir`, `t ∈ (0, t_max)`, one exponential number
/// each (plus one per roulette). A medium whose majorant is not positive transmits 1.
pub fn ratio_tracking<M: ChannelMedium + ?Sized>(
    medium: &M,
    origin: DVec3,
    dir: DVec3,
    t_max: f64,
    tracking: RatioTracking,
    rng: &mut Rng,
    counters: &mut TrackingCounters,
) -> f64 {
    let majorant = medium.majorant();
    if majorant.is_nan() || majorant <= 0.0 {
        return 1.0;
    }
    // σc in [0, σ̄]: the control part is integrated exactly, the residual is ratio-tracked.
    let control = tracking.control.clamp(0.0, majorant);
    let residual = majorant - control;
    let mut tr = if control > 0.0 {
        (-control * t_max).exp()
    } else {
        1.0
    };
    if residual <= 0.0 {
        return tr;
    }
    let (roulette, floor, max_steps) = match tracking.ending {
        LowTransmittance::Roulette(threshold) => (threshold, 0.0, u32::MAX),
        LowTransmittance::Floor { floor, max_steps } => (0.0, floor, max_steps),
    };
    let mut t = 0.0;
    for _ in 0..max_steps {
        if tr < roulette {
            // Survive with probability tr / threshold and continue with weight threshold:
            // the expectation is unchanged.
            if rng.uniform() * roulette >= tr {
                return 0.0;
            }
            tr = roulette;
        }
        t += unit_exponential(rng) / residual;
        counters.ratio_steps += 1;
        if t >= t_max {
            return tr;
        }
        if tr < floor {
            return 0.0;
        }
        let (sigma_a, sigma_s) = medium.coefficients(origin + t * dir);
        tr *= (1.0 - (sigma_a + sigma_s - control).max(0.0) / residual).max(0.0);
    }
    0.0
}

pub use het_estimate::frame::orthonormal_basis;

/// The unit vector with polar cosine `cos_theta` and azimuth `phi` about the unit axis `axis`.
pub fn direction_about(axis: DVec3, cos_theta: f64, phi: f64) -> DVec3 {
    let (t, b) = orthonormal_basis(axis);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    (t * (sin_theta * phi.cos()) + b * (sin_theta * phi.sin()) + axis * cos_theta).normalize()
}

/// Samples a new propagation direction after scattering by Henyey–Greenstein with mean cosine
/// `g` (propagation convention of `bssrdf_core::hg`). The sample's pdf equals the phase
/// function value, so analog path weights are unchanged.
pub fn sample_hg(dir: DVec3, g: f64, rng: &mut Rng) -> DVec3 {
    let cos_theta = bssrdf_core::hg::sample_cos_theta(g, rng.uniform());
    direction_about(dir, cos_theta, std::f64::consts::TAU * rng.uniform())
}

/// One colour channel of a scene's [`MediumField`] as a [`ChannelMedium`]: what delta and
/// ratio tracking see (the path tracer's walk, its shadow rays, the beam experiment).
pub struct ChannelView<'a> {
    field: &'a MediumField,
    channel: usize,
    majorant: f64,
    control: f64,
    constant: Option<(f64, f64)>,
}

impl<'a> ChannelView<'a> {
    /// Channel `channel` of `field`.
    pub fn new(field: &'a MediumField, channel: usize) -> Self {
        let majorant = field.majorant()[channel];
        let constant = field.is_constant().then(|| {
            let c = field.at_point(DVec3::ZERO);
            (c.sigma_a[channel], c.sigma_s[channel])
        });
        let min = field.field_bounds().min;
        Self {
            field,
            channel,
            majorant,
            control: min.sigma_a[channel] + min.sigma_s[channel],
            constant,
        }
    }
}

impl ChannelMedium for ChannelView<'_> {
    #[inline]
    fn coefficients(&self, p: DVec3) -> (f64, f64) {
        if let Some(c) = self.constant {
            return c;
        }
        let c = self.field.at_point(p);
        (c.sigma_a[self.channel], c.sigma_s[self.channel])
    }
    fn majorant(&self) -> f64 {
        self.majorant
    }
    fn constant(&self) -> Option<(f64, f64)> {
        self.constant
    }
    fn control(&self) -> f64 {
        self.control
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A medium whose σa, σs depend on x only: two slabs split at x = split.
    struct TwoLayer {
        split: f64,
        left: (f64, f64),
        right: (f64, f64),
    }

    /// [`TwoLayer`] that reports its smallest σt as the control extinction.
    struct Controlled(TwoLayer);
    impl ChannelMedium for Controlled {
        fn coefficients(&self, p: DVec3) -> (f64, f64) {
            self.0.coefficients(p)
        }
        fn majorant(&self) -> f64 {
            self.0.majorant()
        }
        fn constant(&self) -> Option<(f64, f64)> {
            None
        }
        fn control(&self) -> f64 {
            (self.0.left.0 + self.0.left.1).min(self.0.right.0 + self.0.right.1)
        }
    }

    impl ChannelMedium for TwoLayer {
        fn coefficients(&self, p: DVec3) -> (f64, f64) {
            if p.x < self.split {
                self.left
            } else {
                self.right
            }
        }
        fn majorant(&self) -> f64 {
            (self.left.0 + self.left.1).max(self.right.0 + self.right.1)
        }
        fn constant(&self) -> Option<(f64, f64)> {
            None
        }
    }

    struct Constant(f64, f64);
    impl ChannelMedium for Constant {
        fn coefficients(&self, _: DVec3) -> (f64, f64) {
            (self.0, self.1)
        }
        fn majorant(&self) -> f64 {
            self.0 + self.1
        }
        fn constant(&self) -> Option<(f64, f64)> {
            Some((self.0, self.1))
        }
    }

    #[test]
    fn delta_tracking_first_collision_distribution_in_two_layers() {
        // Along +x from 0: σt = 0.5 on [0, 1), 2.0 beyond. The first real collision (scatter or
        // absorb) has CDF 1 − exp(−τ(t)) with τ piecewise linear. Chi-square over 20 bins of
        // equal probability (plus the "pass" cell), fixed seed, level 1e-4.
        let m = TwoLayer {
            split: 1.0,
            left: (0.1, 0.4),
            right: (1.5, 0.5),
        };
        let tau = |t: f64| {
            if t < 1.0 {
                0.5 * t
            } else {
                0.5 + 2.0 * (t - 1.0)
            }
        };
        let t_max = 2.0;
        let p_pass = (-tau(t_max)).exp();
        let bins = 20;
        // Bin edges in τ: equal probability of the collision part.
        let tau_edges: Vec<f64> = (0..=bins)
            .map(|k| -(1.0 - k as f64 / bins as f64 * (1.0 - p_pass)).ln())
            .collect();
        let inv_tau = |x: f64| {
            if x < 0.5 {
                x / 0.5
            } else {
                1.0 + (x - 0.5) / 2.0
            }
        };
        let edges: Vec<f64> = tau_edges.iter().map(|&x| inv_tau(x)).collect();
        let n = 200_000;
        let mut counts = vec![0u64; bins + 1];
        let mut rng = Rng::from_keys(11, &[]);
        let mut c = TrackingCounters::default();
        for _ in 0..n {
            match sample_interaction(&m, DVec3::ZERO, DVec3::X, t_max, &mut rng, &mut c) {
                Interaction::Pass => counts[bins] += 1,
                Interaction::Scatter { t } | Interaction::Absorb { t } => {
                    let k = edges.partition_point(|&e| e <= t) - 1;
                    counts[k.min(bins - 1)] += 1;
                }
            }
        }
        let expected: Vec<f64> = (0..=bins)
            .map(|k| {
                let p = if k == bins {
                    p_pass
                } else {
                    (1.0 - p_pass) / bins as f64
                };
                p * n as f64
            })
            .collect();
        let r = bssrdf_core::chi_square::ChiSquareTest::SINGLE
            .check(&counts, &expected)
            .unwrap();
        assert!(r.passes(), "{r}, counts = {counts:?}");
    }

    #[test]
    fn delta_tracking_absorption_fraction_matches_local_albedo() {
        // In the left layer σa/σt = 0.2: the fraction of collisions there that absorb must be
        // 0.2 within 4 standard errors.
        let m = TwoLayer {
            split: 1.0,
            left: (0.1, 0.4),
            right: (1.5, 0.5),
        };
        let mut rng = Rng::from_keys(12, &[]);
        let mut c = TrackingCounters::default();
        let (mut absorbed, mut total) = (0u64, 0u64);
        for _ in 0..200_000 {
            match sample_interaction(&m, DVec3::ZERO, DVec3::X, 1.0, &mut rng, &mut c) {
                Interaction::Absorb { .. } => {
                    absorbed += 1;
                    total += 1
                }
                Interaction::Scatter { .. } => total += 1,
                Interaction::Pass => {}
            }
        }
        let p = absorbed as f64 / total as f64;
        let se = (0.2 * 0.8 / total as f64).sqrt();
        assert!((p - 0.2).abs() < 4.0 * se, "absorbed fraction {p}");
    }

    /// Mean and standard error of `n` transmittance estimates through `m` along +x to 2.5.
    fn mean_transmittance(m: &dyn ChannelMedium, seed: u64, n: usize) -> (f64, f64, u64) {
        let mut rng = Rng::from_keys(seed, &[]);
        let mut c = TrackingCounters::default();
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let t = transmittance(m, DVec3::ZERO, DVec3::X, 2.5, &mut rng, &mut c);
            assert!((0.0..=1.0).contains(&t));
            s += t;
            s2 += t * t;
        }
        let mean = s / n as f64;
        (
            mean,
            ((s2 / n as f64 - mean * mean) / n as f64).sqrt(),
            c.ratio_steps,
        )
    }

    /// The floor setting (the shape correction's): unbiased to within its floor, drawing
    /// only the flights' numbers (one per tentative collision, no roulette draw), and 0 once
    /// the guard on steps runs out.
    #[test]
    fn ratio_tracking_with_a_floor_is_unbiased_and_draws_one_number_per_step() {
        let m = TwoLayer {
            split: 1.0,
            left: (0.1, 0.4),
            right: (1.5, 0.5),
        };
        let exact = (-(0.5 * 1.0 + 2.0 * 1.5f64)).exp(); // t_max = 2.5
        let floor = RatioTracking {
            control: 0.0,
            ending: LowTransmittance::Floor {
                floor: 1e-9,
                max_steps: 1_000_000,
            },
        };
        let mut rng = Rng::from_keys(17, &[]);
        let mut c = TrackingCounters::default();
        let n = 400_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let t = ratio_tracking(&m, DVec3::ZERO, DVec3::X, 2.5, floor, &mut rng, &mut c);
            assert!((0.0..=1.0).contains(&t));
            s += t;
            s2 += t * t;
        }
        let mean = s / n as f64;
        let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
        assert!(
            (mean - exact).abs() < 4.0 * se,
            "{mean} vs {exact} (se {se})"
        );
        // One number per tentative collision: a generator that tracked k steps is where a
        // twin stands after k draws.
        let (mut a, mut twin) = (Rng::from_keys(5, &[]), Rng::from_keys(5, &[]));
        let mut c = TrackingCounters::default();
        for _ in 0..1000 {
            let before = c.ratio_steps;
            ratio_tracking(&m, DVec3::ZERO, DVec3::X, 2.5, floor, &mut a, &mut c);
            for _ in before..c.ratio_steps {
                twin.uniform();
            }
            assert_eq!(a.uniform(), twin.uniform());
        }
        // The guard: a flight longer than max_steps tentative collisions counts as 0.
        let short = RatioTracking {
            ending: LowTransmittance::Floor {
                floor: 1e-9,
                max_steps: 2,
            },
            ..floor
        };
        // An empty layer 100 long under a majorant of 2: about 100 tentative collisions to
        // cross 50 of it, each leaving the estimate at 1.
        let empty = TwoLayer {
            split: 100.0,
            left: (0.0, 0.0),
            right: (1.0, 1.0),
        };
        let t = ratio_tracking(&empty, DVec3::ZERO, DVec3::X, 50.0, floor, &mut a, &mut c);
        assert_eq!(t, 1.0);
        let t = ratio_tracking(&empty, DVec3::ZERO, DVec3::X, 50.0, short, &mut a, &mut c);
        assert_eq!(t, 0.0);
    }

    #[test]
    fn ratio_tracking_is_unbiased_and_exact_for_constant_media() {
        let layers = || TwoLayer {
            split: 1.0,
            left: (0.1, 0.4),
            right: (1.5, 0.5),
        };
        let exact = (-(0.5 * 1.0 + 2.0 * 1.5f64)).exp(); // t_max = 2.5
        let n = 400_000;
        // Plain ratio tracking (control 0) and residual ratio tracking (control = the smaller
        // σt, 0.5): both unbiased within 4 standard errors.
        let (plain, plain_se, plain_steps) = mean_transmittance(&layers(), 13, n);
        assert!(
            (plain - exact).abs() < 4.0 * plain_se,
            "ratio tracking: {plain} vs {exact} (se {plain_se})"
        );
        let (res, res_se, res_steps) = mean_transmittance(&Controlled(layers()), 13, n);
        assert!(
            (res - exact).abs() < 4.0 * res_se,
            "residual ratio tracking: {res} vs {exact} (se {res_se})"
        );
        // The residual rate is 1.5 instead of 2: fewer tentative collisions (and, the
        // control part being exact, a smaller spread).
        assert!(res_steps < plain_steps, "{res_steps} vs {plain_steps}");
        assert!(res_se < plain_se, "{res_se} vs {plain_se}");
        let mut rng = Rng::from_keys(13, &[]);
        let mut c = TrackingCounters::default();
        let k = Constant(0.3, 0.7);
        let t = transmittance(&k, DVec3::ZERO, DVec3::Y, 2.0, &mut rng, &mut c);
        assert_eq!(t, (-2.0f64).exp());
        assert_eq!(
            transmittance(&k, DVec3::ZERO, DVec3::Y, f64::INFINITY, &mut rng, &mut c),
            0.0
        );
        // An infinite segment through a varying medium with a positive control: 0, not NaN.
        let t = transmittance(
            &Controlled(layers()),
            DVec3::ZERO,
            DVec3::X,
            f64::INFINITY,
            &mut rng,
            &mut c,
        );
        assert_eq!(t, 0.0);
    }

    #[test]
    fn vacuum_passes_and_never_loops() {
        let v = Constant(0.0, 0.0);
        let mut rng = Rng::from_keys(14, &[]);
        let mut c = TrackingCounters::default();
        assert_eq!(
            sample_interaction(&v, DVec3::ZERO, DVec3::X, f64::INFINITY, &mut rng, &mut c),
            Interaction::Pass
        );
        assert_eq!(
            transmittance(&v, DVec3::ZERO, DVec3::X, 1e9, &mut rng, &mut c),
            1.0
        );
    }

    #[test]
    fn hg_directions_have_mean_cosine_g() {
        let mut rng = Rng::from_keys(15, &[]);
        let axis = DVec3::new(0.3, -0.5, 0.8).normalize();
        for g in [-0.7, 0.0, 0.85] {
            let n = 100_000;
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..n {
                let d = sample_hg(axis, g, &mut rng);
                assert!((d.length() - 1.0).abs() < 1e-12);
                let c = d.dot(axis);
                s += c;
                s2 += c * c;
            }
            let mean = s / n as f64;
            let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
            assert!((mean - g).abs() < 4.0 * se, "g={g}: {mean}");
        }
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::X,
            DVec3::new(1.0, 2.0, -3.0).normalize(),
        ] {
            let (t, b) = orthonormal_basis(n);
            assert!(t.dot(b).abs() < 1e-12 && t.dot(n).abs() < 1e-12 && b.dot(n).abs() < 1e-12);
            assert!((t.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
        }
    }
}
