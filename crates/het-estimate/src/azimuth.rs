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
/// the directions of the guide's factors in x_o's frame, and the last few node shapes it was
/// read at, each with its normalisation (a probe set samples one node's azimuth and then reads
/// its density at the point found: one shape per set where the normal probe finds one point).
/// Built by the caller once per x_o, on its stack (about 350 bytes).
pub struct GuidedAzimuths<'g> {
    guide: &'g dyn AzimuthGuide,
    /// (cos φ_j, sin φ_j) of each factor's direction j in x_o's frame ((0, 0) for a factor
    /// left out, whose amplitudes are then 0 too, so that it is 1 everywhere).
    axes: [(f64, f64); 2],
    /// Whether each factor's direction projects on the tangent plane.
    used: [bool; 2],
    /// The nodes of the shapes read last (`usize::MAX`: an empty slot), looked through before
    /// `shapes` is read.
    nodes: [Cell<usize>; SHAPES_KEPT],
    /// The shapes of `nodes`, slot for slot; replaced in turn.
    shapes: [Cell<NodeShape>; SHAPES_KEPT],
    /// The slot the next new shape goes to.
    next: Cell<usize>,
    /// A second guide whose own shape takes the given part of the guided share
    /// ([`GuidedAzimuths::mixed_with`]).
    other: Option<(&'g GuidedAzimuths<'g>, f64)>,
}

/// How many node shapes a [`GuidedAzimuths`] keeps.
const SHAPES_KEPT: usize = 4;

/// One node's guided shape: each factor's series as a cubic in u = cos(φ − φ_j)
/// ([`Cubic`]; a factor left out is 1) and the piecewise density's scale,
/// `AZIMUTH_BINS / (2π Σ_bins value)`; `None`: g uniform.
#[derive(Debug, Clone, Copy)]
struct NodeShape {
    factors: [Cubic; 2],
    scale: Option<f64>,
}

impl NodeShape {
    /// No amplitudes: the uniform azimuth (what an empty slot holds).
    const UNIFORM: NodeShape = NodeShape {
        factors: [Cubic::ONE; 2],
        scale: None,
    };
}

/// A series 1 + Σ_n a_n cos nθ (n = 1, 2, 3) as the cubic in u = cos θ it is (cos 2θ =
/// 2u² − 1, cos 3θ = 4u³ − 3u): coefficients of 1, u, u², u³.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cubic([f64; 4]);

impl Cubic {
    /// The series with no harmonics.
    const ONE: Cubic = Cubic([1.0, 0.0, 0.0, 0.0]);

    fn of(a: &[f64; 3]) -> Self {
        Self([1.0 - a[1], a[0] - 3.0 * a[2], 2.0 * a[1], 4.0 * a[2]])
    }

    /// The series at u = cos θ, clamped at 0.
    #[inline]
    fn at(&self, u: f64) -> f64 {
        let p = &self.0;
        (p[0] + u * (p[1] + u * (p[2] + u * p[3]))).max(0.0)
    }
}

impl<'g> GuidedAzimuths<'g> {
    /// `guide` around x_o, whose normal fixes the frame the angles are measured in (the one
    /// [`crate::probe::ProbeDensity::around`] uses at the same point). `None` when neither of
    /// the guide's directions projects on the tangent plane: the azimuth is then uniform.
    pub fn new(guide: &'g dyn AzimuthGuide, x_o: &impl SurfacePoint) -> Option<Self> {
        let (fs, ft) = orthonormal_basis(x_o.normal());
        let mut used = [false; 2];
        let mut axes = [(0.0, 0.0); 2];
        for (j, d) in guide.directions().into_iter().enumerate() {
            let (x, y) = (d.dot(fs), d.dot(ft));
            if x.is_finite() && y.is_finite() && (x != 0.0 || y != 0.0) {
                // The library's hypot only where the squares overflow or underflow.
                let l = match (x * x + y * y).sqrt() {
                    l if l.is_normal() => l,
                    _ => x.hypot(y),
                };
                used[j] = true;
                axes[j] = (x / l, y / l);
            }
        }
        (used[0] || used[1]).then(|| Self {
            guide,
            axes,
            used,
            nodes: std::array::from_fn(|_| Cell::new(usize::MAX)),
            shapes: std::array::from_fn(|_| Cell::new(NodeShape::UNIFORM)),
            next: Cell::new(0),
            other: None,
        })
    }

    /// The shape at radius `r`, from the ones kept or read from the guide; with `values`, also
    /// its bins' values (unnormalised; all 1 where it is uniform).
    fn shape(&self, r: f64, values: Option<&mut [f64; AZIMUTH_BINS]>) -> NodeShape {
        let node = self.guide.radial_node(r);
        let kept = self
            .nodes
            .iter()
            .position(|k| k.get() == node)
            .map(|slot| self.shapes[slot].get());
        if let (Some(shape), None) = (kept, &values) {
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
                factors: amplitudes.map(|a| Cubic::of(&a)),
                scale: None,
            }
        });
        let mut own = [0.0; AZIMUTH_BINS];
        let values = values.unwrap_or(&mut own);
        let flat = shape.factors == [Cubic::ONE; 2];
        if flat {
            values.fill(1.0);
        } else {
            for (m, v) in values.iter_mut().enumerate() {
                *v = self.value(&shape, m);
            }
        }
        if kept.is_some() {
            return shape;
        }
        let total = sum_of(values);
        let shape = NodeShape {
            scale: (!flat && total > 0.0 && total.is_finite())
                .then(|| AZIMUTH_BINS as f64 / (TAU * total)),
            ..shape
        };
        let slot = self.next.get();
        self.nodes[slot].set(node);
        self.shapes[slot].set(shape);
        self.next.set((slot + 1) % SHAPES_KEPT);
        shape
    }

    /// The product of the shape's factors at bin `m`'s midpoint φ_m (unnormalised, ≥ 0), each
    /// at cos(φ_m − φ_j).
    #[inline]
    fn value(&self, shape: &NodeShape, m: usize) -> f64 {
        let (s, c) = midpoint_angles()[m];
        let [(c0, s0), (c1, s1)] = self.axes;
        shape.factors[0].at(c * c0 + s * s0) * shape.factors[1].at(c * c1 + s * s1)
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

    /// This guide's own shape g(φ | r) (1/radian) in bin `bin`.
    fn own_pdf(&self, r: f64, bin: usize) -> f64 {
        let shape = self.shape(r, None);
        match shape.scale {
            Some(scale) => self.value(&shape, bin) * scale,
            None => 1.0 / TAU,
        }
    }

    /// An azimuth (in turns) drawn from this guide's own shape at fraction `v` ∈ [0, 1] of its
    /// cumulative distribution.
    fn own_sample(&self, r: f64, v: f64) -> f64 {
        let mut values = [0.0; AZIMUTH_BINS];
        if self.shape(r, Some(&mut values)).scale.is_none() {
            values.fill(1.0); // uniform
        }
        invert_bins(&values, v)
    }

    /// p(φ | r) (1/radian) of the azimuth at projected radius `r` (length), whatever the
    /// probe's channel: (1 − β)/(2π) + β g(φ), `phi` any angle in x_o's frame, g the guided
    /// part (with a second guide mixed in, [`Self::mixed_with`]).
    pub fn pdf(&self, r: f64, phi: f64) -> f64 {
        self.pdf_in_bin(r, bin_of(phi))
    }

    /// [`Self::pdf`] at the azimuth of the offset (`x`, `y`) in x_o's frame (the angle
    /// atan2(y, x), its bin found from the signs and comparisons, without the arctangent).
    pub fn pdf_toward(&self, r: f64, x: f64, y: f64) -> f64 {
        self.pdf_in_bin(r, bin_toward(x, y))
    }

    fn pdf_in_bin(&self, r: f64, bin: usize) -> f64 {
        let g = match self.other {
            Some((o, s)) => (1.0 - s) * self.own_pdf(r, bin) + s * o.own_pdf(r, bin),
            None => self.own_pdf(r, bin),
        };
        (1.0 - GUIDED_SHARE) / TAU + GUIDED_SHARE * g
    }

    /// An azimuth in [0, 2π) at projected radius `r` from one uniform number `u` in [0, 1):
    /// below 1 − β uniform, else by inverting g's cumulative distribution (with a second
    /// guide, the one the remainder of `u` falls to, in proportion to their parts).
    pub fn sample(&self, r: f64, u: f64) -> f64 {
        let phi = TAU * self.sample_turn(r, u);
        if phi < TAU { phi } else { 0.0 }
    }

    /// [`Self::sample`] in turns (φ / 2π ∈ [0, 1)): what `crate::sampling::sin_cos_turn`
    /// takes.
    pub fn sample_turn(&self, r: f64, u: f64) -> f64 {
        let beta = GUIDED_SHARE;
        if u < 1.0 - beta {
            return u / (1.0 - beta);
        }
        let v = ((u - (1.0 - beta)) / beta).clamp(0.0, 1.0);
        match self.other {
            Some((o, s)) if v >= 1.0 - s => o.own_sample(r, ((v - (1.0 - s)) / s).min(1.0)),
            Some((_, s)) => self.own_sample(r, (v / (1.0 - s)).min(1.0)),
            None => self.own_sample(r, v),
        }
    }
}

/// The bin of angle `phi` (any angle; taken modulo 2π).
#[inline]
fn bin_of(phi: f64) -> usize {
    let t = phi.rem_euclid(TAU) / TAU * AZIMUTH_BINS as f64;
    (t as usize).min(AZIMUTH_BINS - 1)
}

/// The bin of the angle atan2(`y`, `x`) (as [`bin_of`] would give it): the quadrant from the
/// signs, then within it the number of the quadrant's inner bin edges β_k = kπ/16 the angle
/// has passed (y' cos β_k ≥ x' sin β_k, both rotated into the first quadrant). NaN and the
/// offset (0, 0) give bin 0.
#[inline]
fn bin_toward(x: f64, y: f64) -> usize {
    const PER_QUADRANT: usize = AZIMUTH_BINS / 4;
    let (quadrant, xr, yr) = if x > 0.0 && y >= 0.0 {
        (0, x, y)
    } else if x <= 0.0 && y > 0.0 {
        (1, y, -x)
    } else if x < 0.0 && y <= 0.0 {
        (2, -x, -y)
    } else if x >= 0.0 && y < 0.0 {
        (3, -y, x)
    } else {
        return 0;
    };
    let edges = quadrant_edges();
    let passed = edges.iter().filter(|&&(s, c)| yr * c >= xr * s).count();
    quadrant * PER_QUADRANT + passed
}

/// (sin β_k, cos β_k) of the inner bin edges β_k = 2πk / [`AZIMUTH_BINS`] of the first
/// quadrant, k = 1, …, AZIMUTH_BINS/4 − 1.
fn quadrant_edges() -> &'static [(f64, f64); AZIMUTH_BINS / 4 - 1] {
    static EDGES: std::sync::OnceLock<[(f64, f64); AZIMUTH_BINS / 4 - 1]> =
        std::sync::OnceLock::new();
    EDGES.get_or_init(|| {
        std::array::from_fn(|k| (TAU * (k + 1) as f64 / AZIMUTH_BINS as f64).sin_cos())
    })
}

/// The sum of the bins' values, in four running sums (independent, so that they overlap).
#[inline]
fn sum_of(values: &[f64; AZIMUTH_BINS]) -> f64 {
    let mut part = [0.0; 4];
    for chunk in values.chunks_exact(4) {
        for (p, v) in part.iter_mut().zip(chunk) {
            *p += v;
        }
    }
    (part[0] + part[1]) + (part[2] + part[3])
}

/// The angle in turns, in [0, 1), at fraction `v` ∈ [0, 1] of the piecewise-constant density
/// whose bins' values are `values` (non-negative, positive total): the first non-empty bin
/// whose running sum passes v × total, and the fraction of it that reaches v × total (where
/// rounding leaves v × total beyond every running sum, the end of the last non-empty bin).
fn invert_bins(values: &[f64; AZIMUTH_BINS], v: f64) -> f64 {
    let target = v * sum_of(values);
    let mut below = 0.0;
    let mut last = 0;
    for (k, &w) in values.iter().enumerate() {
        if w > 0.0 {
            if below + w > target {
                let f = ((target - below) / w).clamp(0.0, 1.0);
                return turn_of(k, f);
            }
            last = k;
        }
        below += w;
    }
    turn_of(last, 1.0)
}

/// The angle in turns at fraction `f` of bin `k`, in [0, 1) (1 wraps to 0).
#[inline]
fn turn_of(k: usize, f: f64) -> f64 {
    let turn = (k as f64 + f) / AZIMUTH_BINS as f64;
    if turn < 1.0 { turn } else { 0.0 }
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

    /// The bin found without the arctangent is atan2's: on 10⁵ random directions at every
    /// scale, on the bins' edges and the axes (±0 included), and for NaN (bin 0, as `bin_of`
    /// gives NaN). The offset (0, 0), which has no angle, is bin 0 whatever its zeros' signs.
    #[test]
    fn the_bin_toward_a_direction_is_the_bin_of_its_angle() {
        let mut rng = SplitMix64::new(9);
        for (x, y) in [(0.0, 0.0), (-0.0, -0.0), (0.0, -0.0), (-0.0, 0.0)] {
            assert_eq!(bin_toward(x, y), 0);
        }
        let mut cases = vec![(f64::NAN, 1.0), (1.0, f64::NAN)];
        for (x, y) in [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)] {
            for z in [0.0, -0.0] {
                cases.push((x, if y == 0.0 { z } else { y }));
                cases.push((if x == 0.0 { z } else { x }, y));
            }
        }
        for k in 0..AZIMUTH_BINS {
            // Just inside each bin, on both sides of its lower edge.
            for d in [1e-9, -1e-9] {
                let (s, c) = (TAU * k as f64 / AZIMUTH_BINS as f64 + d).sin_cos();
                cases.push((c, s));
            }
        }
        for _ in 0..100_000 {
            let phi = TAU * rng.next_f64();
            let scale = 10f64.powf(12.0 * rng.next_f64() - 6.0);
            cases.push((scale * phi.cos(), scale * phi.sin()));
        }
        for (x, y) in cases {
            assert_eq!(bin_toward(x, y), bin_of(y.atan2(x)), "({x}, {y})");
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
