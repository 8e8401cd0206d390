//! A guided azimuthal density for the normal probe ([`crate::probe`], "Guided azimuths"):
//! where the caller knows which way from x_o the integrand leans (the tabulated profile's
//! oblique shape, whose forward shift makes the BSSRDF a product of clamped Fourier series in
//! the azimuth of x_i about x_o: docs/oblique-incidence.md), the normal probe draws its
//! azimuth from that shape, tabulated over [`AZIMUTH_BINS`] equal bins and mixed defensively
//! with the uniform azimuth (Hesterberg 1995, key `Hes95` in docs/references.md; Veach 1997
//! §9.2), and the probe density carries the mixture's exact density (1/radian), so the
//! estimate stays unbiased whatever the guide says.
//!
//! The shape is the caller's ([`AzimuthGuide`]): one for all colour channels (the probe's
//! channel only chooses its radius), at radial nodes the guide chooses, up to two factors
//! max(0, 1 + Σ_n a_n cos n(φ − φ_j)), n = 1, 2, 3, each about its own direction in x_o's
//! tangent plane. At a projected radius r the guided part g
//! is the shape of the node the guide names for r (the nearest of its own): piecewise
//! constant over [`AZIMUTH_BINS`] equal bins, its value in a bin the product at the bin's
//! midpoint divided by the sum over the bins. A probe set reads a node's shape once, when it
//! samples the normal probe's azimuth, and its density again at the point found
//! ([`GuidedAzimuths`] keeps the last few). Where the integrand is a sum of parts that lean
//! different ways (light arriving by two sampled directions), a second guide's shape can take
//! a share of the guided part ([`GuidedAzimuths::mixed_with`]).

use std::cell::Cell;
use std::f64::consts::TAU;

use glam::DVec3;

use crate::SurfacePoint;
use crate::frame::orthonormal_basis;

/// Equal bins of the guided part's piecewise-constant density over [0, 2π).
pub const AZIMUTH_BINS: usize = 32;
/// The share β of the azimuths drawn from the guided part (the rest uniform): a defensive
/// mixture, so that the density is at least (1 − β)/(2π) everywhere. With a perfect guide
/// a share β leaves the variance that guiding by the same density adds to a flat integrand,
/// which vanishes as β → 1; with a rough guide the uniform share bounds the weights. The
/// renderer's guides are exact for the directions its light arrives by (the light sample
/// and the continuation, each drawn before the probes), and on the scenes of
/// docs/oblique-incidence.md ("Two guides") 0.9 was quieter than ½ everywhere and as quiet
/// as 0.8 and 0.95.
pub const GUIDED_SHARE: f64 = 0.9;

/// What the caller knows at x_o: the preferred azimuthal shape of the points around it, a
/// product of up to two clamped Fourier series Π_j max(0, 1 + Σ_n a_jn cos n(φ − φ_j)),
/// n = 1, 2, 3, each about its own direction φ_j (the oblique shape's two sides, in the
/// renderer: docs/oblique-incidence.md), given at radial nodes and mixed linearly between
/// them (module docs).
pub trait AzimuthGuide {
    /// The directions of φ_j (any vectors; their projections on x_o's tangent plane are used,
    /// and a factor whose projection is 0 or not finite is left out).
    fn directions(&self) -> [DVec3; 2];
    /// The radial node whose shape stands for projected distance `r` (length) from x_o: any
    /// index the guide's [`AzimuthGuide::amplitudes`] takes, the same for the same r.
    fn radial_node(&self, r: f64) -> usize;
    /// The amplitudes a_jn (unitless) of the two factors at radial node `node`. A factor with
    /// a non-finite amplitude is left out.
    fn amplitudes(&self, node: usize) -> [[f64; 3]; 2];
}

/// An [`AzimuthGuide`] at one x_o, ready for the probes ([`crate::probe::ProbeDensity::around`]):
/// the cosines of each bin's midpoint about the guide's directions in x_o's frame, and the
/// last few node shapes it was read at, each with its normalisation (a probe set samples one node's azimuth and
/// then reads its density at the point found: one shape per set where the normal probe finds
/// one point). Built by the caller once per x_o, on its stack (under 1 KB).
pub struct GuidedAzimuths<'g> {
    guide: &'g dyn AzimuthGuide,
    /// cos(φ_m − φ_j) at every bin midpoint φ_m for each factor j (0 for a factor left out,
    /// whose amplitudes are then 0 too, so that it is 1 everywhere).
    cosines: [[f64; AZIMUTH_BINS]; 2],
    /// Whether each factor's direction projects on the tangent plane.
    used: [bool; 2],
    /// The shapes read last, keyed by node; replaced in turn.
    shapes: [Cell<Option<(usize, NodeShape)>>; SHAPES_KEPT],
    /// The slot of `shapes` the next new shape goes to.
    next: Cell<usize>,
    /// A second guide whose own shape takes the given part of the guided share
    /// ([`GuidedAzimuths::mixed_with`]).
    other: Option<(&'g GuidedAzimuths<'g>, f64)>,
}

/// How many node shapes a [`GuidedAzimuths`] keeps.
const SHAPES_KEPT: usize = 4;

/// One node's guided shape: the factors' amplitudes (a factor left out has 0) and the
/// piecewise density's scale, `AZIMUTH_BINS / (2π Σ_bins value)`; `None`: g uniform.
#[derive(Debug, Clone, Copy)]
struct NodeShape {
    amplitudes: [[f64; 3]; 2],
    scale: Option<f64>,
}

impl<'g> GuidedAzimuths<'g> {
    /// `guide` around x_o, whose normal fixes the frame the angles are measured in (the one
    /// [`crate::probe::ProbeDensity::around`] uses at the same point). `None` when neither of
    /// the guide's directions projects on the tangent plane: the azimuth is then uniform.
    pub fn new(guide: &'g dyn AzimuthGuide, x_o: &impl SurfacePoint) -> Option<Self> {
        let (fs, ft) = orthonormal_basis(x_o.normal());
        let mid = midpoint_angles();
        let mut used = [false; 2];
        let mut cosines = [[0.0; AZIMUTH_BINS]; 2];
        for (j, d) in guide.directions().into_iter().enumerate() {
            let (x, y) = (d.dot(fs), d.dot(ft));
            if x.is_finite() && y.is_finite() && (x != 0.0 || y != 0.0) {
                let l = x.hypot(y);
                let (c0, s0) = (x / l, y / l);
                used[j] = true;
                for (u, &(s, c)) in cosines[j].iter_mut().zip(mid) {
                    *u = c * c0 + s * s0;
                }
            }
        }
        (used[0] || used[1]).then(|| Self {
            guide,
            cosines,
            used,
            shapes: Default::default(),
            next: Cell::new(0),
            other: None,
        })
    }

    /// The shape at radius `r`, from the ones kept or read from the guide; with `cum`, also
    /// the cumulative sums of its bin values (`cum[m]` the sum of the first m).
    fn shape(&self, r: f64, cum: Option<&mut [f64; AZIMUTH_BINS + 1]>) -> NodeShape {
        let node = self.guide.radial_node(r);
        let kept = self.shapes.iter().find_map(|c| match c.get() {
            Some((k, s)) if k == node => Some(s),
            _ => None,
        });
        if let (Some(shape), None) = (kept, &cum) {
            return shape;
        }
        let shape = kept.unwrap_or_else(|| {
            let mut amplitudes = self.guide.amplitudes(node);
            for (j, a) in amplitudes.iter_mut().enumerate() {
                if !self.used[j] || !a.iter().all(|v| v.is_finite()) {
                    *a = [0.0; 3];
                }
            }
            NodeShape {
                amplitudes,
                scale: None,
            }
        });
        let mut sums = [0.0; AZIMUTH_BINS + 1];
        let cum = cum.unwrap_or(&mut sums);
        if shape.amplitudes == [[0.0; 3]; 2] {
            cum.iter_mut().enumerate().for_each(|(m, c)| *c = m as f64);
        } else {
            for m in 0..AZIMUTH_BINS {
                cum[m + 1] = cum[m] + self.value(&shape, m);
            }
        }
        if kept.is_some() {
            return shape;
        }
        let total = cum[AZIMUTH_BINS];
        let shape = NodeShape {
            scale: (shape.amplitudes != [[0.0; 3]; 2] && total > 0.0 && total.is_finite())
                .then(|| AZIMUTH_BINS as f64 / (TAU * total)),
            ..shape
        };
        let slot = self.next.get();
        self.shapes[slot].set(Some((node, shape)));
        self.next.set((slot + 1) % SHAPES_KEPT);
        shape
    }

    /// The product of the shape's factors at bin `m`'s midpoint (unnormalised, ≥ 0).
    #[inline]
    fn value(&self, shape: &NodeShape, m: usize) -> f64 {
        series(&shape.amplitudes[0], self.cosines[0][m])
            * series(&shape.amplitudes[1], self.cosines[1][m])
    }

    /// This guide with `other`'s shape mixed into its guided part, which becomes
    /// (1 − s) g + s g_other, s = `share` (clamped to [0, 1]; NaN gives 0): for an integrand
    /// that is a sum of two parts, each leaning its own way (light arriving by two sampled
    /// directions). Only `other`'s own shape counts, not what is mixed into it.
    pub fn mixed_with(mut self, other: &'g GuidedAzimuths<'g>, share: f64) -> Self {
        let s = if share.is_nan() {
            0.0
        } else {
            share.clamp(0.0, 1.0)
        };
        self.other = Some((other, s));
        self
    }

    /// This guide's own shape g(φ | r) (1/radian) at `phi`.
    fn own_pdf(&self, r: f64, phi: f64) -> f64 {
        let shape = self.shape(r, None);
        match shape.scale {
            Some(scale) => self.value(&shape, bin_of(phi)) * scale,
            None => 1.0 / TAU,
        }
    }

    /// An azimuth drawn from this guide's own shape at fraction `v` ∈ [0, 1] of its
    /// cumulative distribution.
    fn own_sample(&self, r: f64, v: f64) -> f64 {
        let mut cum = [0.0; AZIMUTH_BINS + 1];
        let shape = self.shape(r, Some(&mut cum));
        if shape.scale.is_none() {
            // Uniform: the bins' sums are 0, 1, …, AZIMUTH_BINS.
            cum.iter_mut().enumerate().for_each(|(m, c)| *c = m as f64);
        }
        invert_bins(&cum, v)
    }

    /// p(φ | r) (1/radian) of the azimuth at projected radius `r` (length), whatever the
    /// probe's channel: (1 − β)/(2π) + β g(φ), `phi` any angle in x_o's frame, g the guided
    /// part (with a second guide mixed in, [`Self::mixed_with`]).
    pub fn pdf(&self, r: f64, phi: f64) -> f64 {
        let g = match self.other {
            Some((o, s)) => (1.0 - s) * self.own_pdf(r, phi) + s * o.own_pdf(r, phi),
            None => self.own_pdf(r, phi),
        };
        (1.0 - GUIDED_SHARE) / TAU + GUIDED_SHARE * g
    }

    /// An azimuth in [0, 2π) at projected radius `r` from one uniform number `u` in [0, 1):
    /// below 1 − β uniform, else by inverting g's cumulative distribution (with a second
    /// guide, the one the remainder of `u` falls to, in proportion to their parts).
    pub fn sample(&self, r: f64, u: f64) -> f64 {
        let beta = GUIDED_SHARE;
        if u < 1.0 - beta {
            return TAU * u / (1.0 - beta);
        }
        let v = ((u - (1.0 - beta)) / beta).clamp(0.0, 1.0);
        match self.other {
            Some((o, s)) if v >= 1.0 - s => o.own_sample(r, ((v - (1.0 - s)) / s).min(1.0)),
            Some((_, s)) => self.own_sample(r, (v / (1.0 - s)).min(1.0)),
            None => self.own_sample(r, v),
        }
    }
}

/// 1 + Σ_n a_n cos nθ clamped at 0, from u = cos θ (cos 2θ, cos 3θ by Chebyshev).
#[inline]
fn series(a: &[f64; 3], u: f64) -> f64 {
    (1.0 + a[0] * u + a[1] * (2.0 * u * u - 1.0) + a[2] * (4.0 * u * u - 3.0) * u).max(0.0)
}

/// The bin of angle `phi` (any angle; taken modulo 2π).
#[inline]
fn bin_of(phi: f64) -> usize {
    let t = phi.rem_euclid(TAU) / TAU * AZIMUTH_BINS as f64;
    (t as usize).min(AZIMUTH_BINS - 1)
}

/// The angle in [0, 2π) at fraction `v` ∈ [0, 1] of the piecewise-constant density whose
/// cumulative bin values are `cum` (positive total).
fn invert_bins(cum: &[f64; AZIMUTH_BINS + 1], v: f64) -> f64 {
    let target = v * cum[AZIMUTH_BINS];
    // The bin holding `target`: the last k with cum[k] ≤ target, moved down past empty
    // bins at the top.
    let mut k = cum
        .partition_point(|&c| c <= target)
        .saturating_sub(1)
        .min(AZIMUTH_BINS - 1);
    while k > 0 && cum[k + 1] - cum[k] <= 0.0 {
        k -= 1;
    }
    let w = cum[k + 1] - cum[k];
    let f = if w > 0.0 {
        ((target - cum[k]) / w).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let phi = TAU * (k as f64 + f) / AZIMUTH_BINS as f64;
    if phi < TAU { phi } else { 0.0 }
}

/// sin and cos of every bin's midpoint angle.
fn midpoint_angles() -> &'static [(f64, f64); AZIMUTH_BINS] {
    static SC: std::sync::OnceLock<[(f64, f64); AZIMUTH_BINS]> = std::sync::OnceLock::new();
    SC.get_or_init(|| {
        std::array::from_fn(|k| (TAU * (k as f64 + 0.5) / AZIMUTH_BINS as f64).sin_cos())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SplitMix64, UniformSource};
    use bssrdf_core::chi_square::ChiSquareTest;

    /// Guides with a different shape at every node ⌊r⌋: one clamped, one with a factor left
    /// out by a non-finite amplitude, one with a single direction.
    struct Nodes(usize);
    impl AzimuthGuide for Nodes {
        fn directions(&self) -> [DVec3; 2] {
            [DVec3::new(1.0, 0.5, 0.2), DVec3::new(-0.3, 1.0, 7.0)]
        }
        fn radial_node(&self, r: f64) -> usize {
            r.max(0.0) as usize
        }
        fn amplitudes(&self, node: usize) -> [[f64; 3]; 2] {
            let k = node as f64;
            match self.0 {
                0 => [[2.5 - 0.2 * k, 1.2, 0.6], [0.8, -0.4, 0.1 * k]],
                1 => [[0.3 * k, 0.0, 0.0], [f64::NAN, 0.0, 0.0]],
                _ => [[0.0; 3], [-1.5, 0.2 * k, 0.3]],
            }
        }
    }

    struct At(DVec3);
    impl SurfacePoint for At {
        fn position(&self) -> DVec3 {
            DVec3::ZERO
        }
        fn normal(&self) -> DVec3 {
            self.0
        }
    }

    /// At every radius (six nodes, one uniform) and for every guide, alone or mixed with
    /// another, read in turns that overflow the shapes kept, p(φ | r) integrates to 1 and is
    /// at least (1 − β)/(2π); its samples follow it (χ² over twice its bins, fixed seed; a
    /// mixture sampled half and half instead of by its share fails at χ² ≈ 10⁴). Directions
    /// that do not project give no guide.
    #[test]
    fn guided_azimuths_are_normalised_defensive_and_sampled_by_their_density() {
        let x_o = At(DVec3::new(0.1, -0.2, 1.0).normalize());
        let radii = [0.0, 2.0, 3.4, 7.75, 12.5, 40.0];
        let test = ChiSquareTest::family(1e-4, 5 * radii.len() as u32);
        let mut rng = SplitMix64::new(44);
        let guides = [Nodes(0), Nodes(1), Nodes(2)];
        let plain = |k: usize| GuidedAzimuths::new(&guides[k], &x_o).expect("directions project");
        let (second, third) = (plain(2), plain(0));
        // Each guide alone, and mixed with another (a part of 0.3 of the guided share, and
        // all of it).
        let cases = [
            ("0", plain(0)),
            ("1", plain(1)),
            ("2", plain(2)),
            ("0 + 0.3 of 2", plain(0).mixed_with(&second, 0.3)),
            ("1 + all of 0", plain(1).mixed_with(&third, 1.0)),
        ];
        for (name, g) in &cases {
            for r in radii {
                let n = 100 * AZIMUTH_BINS;
                let sum: f64 = (0..n)
                    .map(|k| g.pdf(r, TAU * (k as f64 + 0.5) / n as f64) * TAU / n as f64)
                    .sum();
                assert!((sum - 1.0).abs() < 1e-12, "{name} {r}: {sum}");
                for k in 0..n {
                    let p = g.pdf(r, TAU * k as f64 / n as f64 - 5.0 * TAU);
                    assert!(p >= (1.0 - GUIDED_SHARE) / TAU - 1e-15, "{name} {r}");
                }
                let samples = 100_000;
                let bins = 2 * AZIMUTH_BINS;
                let mut observed = vec![0u64; bins];
                for _ in 0..samples {
                    let phi = g.sample(r, rng.next_f64());
                    assert!((0.0..TAU).contains(&phi), "{name} {r}: {phi}");
                    observed[((phi / TAU * bins as f64) as usize).min(bins - 1)] += 1;
                }
                let expected: Vec<f64> = (0..bins)
                    .map(|k| {
                        let phi = TAU * (k as f64 + 0.5) / bins as f64;
                        samples as f64 * g.pdf(r, phi) * TAU / bins as f64
                    })
                    .collect();
                let chi = test.check(&observed, &expected).expect("a test");
                assert!(chi.passes(), "{name} {r}: {chi}");
            }
        }
        // Read back after the shapes kept were replaced: the same density.
        let guide = Nodes(0);
        let g = GuidedAzimuths::new(&guide, &x_o).expect("directions project");
        let first = g.pdf(3.4, 0.4);
        for r in [5.0, 6.0, 7.0, 8.0, 9.0] {
            g.pdf(r, 0.4);
        }
        assert_eq!(first.to_bits(), g.pdf(3.4, 0.4).to_bits());
        assert!((first - g.pdf(7.2, 0.4)).abs() > 1e-3, "nodes differ");
        // A guide along the normal has nothing to say.
        struct Up;
        impl AzimuthGuide for Up {
            fn directions(&self) -> [DVec3; 2] {
                [DVec3::Z, DVec3::splat(f64::NAN)]
            }
            fn radial_node(&self, _: f64) -> usize {
                0
            }
            fn amplitudes(&self, _: usize) -> [[f64; 3]; 2] {
                [[1.0; 3]; 2]
            }
        }
        assert!(GuidedAzimuths::new(&Up, &At(DVec3::Z)).is_none());
    }
}
