//! Importance sampling of incident points x_i around an exitant point x_o with probe rays:
//! what every renderer that uses a BSSRDF needs besides the profile and the estimator.
//!
//! The technique is pbrt-v4's probe-ray sampling (pbrt-v4 §11.4.3, `TabulatedBSSRDF::Sample`
//! and `PdfSp`; key `pbrt4` in `docs/references.md`) with two variance reductions of this
//! project's own.
//!
//! # The sampler
//! A probe along axis `a` of x_o's shading frame (the normal, or one of the two tangents)
//! picks a colour channel `c` uniformly, samples a radius `r` from that channel's radial
//! profile (the homogeneous profile of the coefficients at x_o, from a
//! [`ProfileTable`]), an angle φ uniformly, and traces the chord of the sphere of radius
//! `r_max,c` (holding [`PROBE_ENERGY_FRACTION`] of the profile's energy) along the axis at
//! (r, φ). The renderer supplies the chord's intersections through [`ProbeChords`].
//!
//! pbrt traces one probe along a randomly chosen axis and keeps one of its hits at random.
//! [`probe`] traces **one probe per axis and keeps every hit**: a multi-sample estimator with
//! balance-heuristic weights over the three axes (Veach 1997, §9.2), so each hit x contributes
//! `f(x) / p(x)` with
//!
//! `p(x) = Σ_axes (1/3) Σ_c [|x − x_o| < r_max,c] · p_r,c(r_a) / (2π r_a) · |n_g(x) · axis|`,
//!
//! `r_a` the distance from x_o to x projected on the plane perpendicular to the axis, `p_r,c`
//! the channel's radial density (1/length) and `n_g` the geometric normal at x. Then
//! `E[Σ_hits f/p] = ∫ f dA` over the object's surface inside the largest probe sphere: on a
//! flat surface the normal probe always finds x_i, instead of succeeding one time in four,
//! and the random choice between the two faces of a thin slab disappears.
//!
//! # Units
//! `p(x)` is an area density (1/length²), so [`ProbeHit::weight`] `= 1/p(x)` is an area; the
//! BSSRDF term of a hit is `S(x_i, x_o) · E(x_i) · weight`. [`axis_densities`] splits `p(x)`
//! by axis, for callers that combine the axes with other weights (the balance heuristic's
//! weight of axis `a` is `p_a(x) / p(x)`).
//!
//! # Use
//! ```
//! use bssrdf_core::{ProfileFamily, ProfileModel, Scattering};
//! use het_estimate::glam::DVec3;
//! use het_estimate::probe::{ProbeChords, ProbeSampler, probe};
//! use het_estimate::{Coefficients, SplitMix64, SurfacePoint};
//!
//! // The renderer's surface point and its "all hits of a segment" query; here the plane z = 0.
//! #[derive(Clone, Copy)]
//! struct Hit(DVec3);
//! impl SurfacePoint for Hit {
//!     fn position(&self) -> DVec3 { self.0 }
//!     fn normal(&self) -> DVec3 { DVec3::Z }
//! }
//! struct Floor;
//! impl ProbeChords for Floor {
//!     type Point = Hit;
//!     fn for_each_hit(&self, o: DVec3, d: DVec3, t_max: f64, mut f: impl FnMut(&Hit)) {
//!         let t = -o.z / d.z;
//!         if t >= 0.0 && t <= t_max { f(&Hit(o + t * d)) }
//!     }
//! }
//!
//! // Once per material:
//! let family = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.3)?;
//! let c = Coefficients::grey(0.01, 1.0);
//! let sampler = ProbeSampler::new(family, c);
//! // Per shading point x_o:
//! let x_o = Hit(DVec3::ZERO);
//! let mut rng = SplitMix64::new(7);
//! let set = probe(&Floor, &x_o, c, &sampler, &mut rng);
//! for h in set.iter() {
//!     let r = (h.hit.position() - x_o.position()).length();
//!     assert!(r < sampler.probe_radius(c) && h.weight > 0.0);
//! }
//! # Ok::<(), bssrdf_core::ParamError>(())
//! ```

use bssrdf_core::{ProfileFamily, ProfileTable, RadialProfile, TableSampler};
use glam::DVec3;

use crate::frame::orthonormal_basis;
use crate::{Coefficients, SurfacePoint, UniformSource};

/// Fraction of the profile's energy inside the probe sphere.
pub const PROBE_ENERGY_FRACTION: f64 = 0.999;
/// Most intersections kept per probe chord.
pub const MAX_PROBE_HITS: usize = 16;

/// Every intersection of a probe segment with the object being shaded: the one geometric
/// query probe sampling needs. Implemented by the renderer over its own acceleration
/// structure (the tracer uses its per-object BVH).
pub trait ProbeChords {
    /// The renderer's surface point. Its [`SurfacePoint::geometric_normal`] enters the
    /// sampling density.
    type Point: SurfacePoint + Copy;

    /// Calls `f` for every crossing of the segment `origin + t·dir`, `t ∈ [0, t_max]` (`dir` a
    /// unit vector), with the object being shaded, in increasing `t`. A crossing through a
    /// shared edge or vertex should be reported once.
    fn for_each_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, f: impl FnMut(&Self::Point));
}

impl<C: ProbeChords + ?Sized> ProbeChords for &C {
    type Point = C::Point;
    fn for_each_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, f: impl FnMut(&Self::Point)) {
        (**self).for_each_hit(origin, dir, t_max, f)
    }
}

/// The profile table of one material and the coefficients to sample with where x_o's own do
/// not scatter. Build once per material (the table costs 0.15 ms for the dipole, 40 ms for
/// photon beam diffusion).
#[derive(Debug, Clone)]
pub struct ProbeSampler {
    table: ProfileTable,
    fallback: Coefficients,
}

impl ProbeSampler {
    /// The sampler of `family`. `fallback` is used where the coefficients at x_o do not
    /// scatter at all (no profile to sample): the field's largest coefficients are a good
    /// choice.
    pub fn new(family: ProfileFamily, fallback: Coefficients) -> Self {
        Self {
            table: ProfileTable::new(family),
            fallback,
        }
    }

    /// The largest probe radius over the channels at coefficients `c` (length; 0 if none
    /// scatters).
    pub fn probe_radius(&self, c: Coefficients) -> f64 {
        self.channels(c)
            .iter()
            .flatten()
            .map(|(_, r)| *r)
            .fold(0.0, f64::max)
    }

    /// The radial samplers and probe radii of the three channels at coefficients `c`.
    fn channels(&self, c: Coefficients) -> [Option<(TableSampler<'_>, f64)>; 3] {
        let c = if c.sigma_s.max_component() > 0.0 {
            c
        } else {
            self.fallback
        };
        std::array::from_fn(|ch| {
            let s = self.table.sampler(c.sigma_a[ch], c.sigma_s[ch]).ok()?;
            let r_max = s.radius_for_fraction(PROBE_ENERGY_FRACTION);
            (r_max.is_finite() && r_max > 0.0).then_some((s, r_max))
        })
    }
}

/// A found incident point and its estimator weight `1/p(x)` (an area, see the module docs).
#[derive(Debug, Clone, Copy)]
pub struct ProbeHit<P> {
    /// The incident point.
    pub hit: P,
    /// `1 / p(x)`.
    pub weight: f64,
}

/// The incident points found by the three probes of one shading point (no allocation: at
/// most [`MAX_PROBE_HITS`] per probe).
#[derive(Debug, Clone)]
pub struct ProbeSet<P> {
    hits: [Option<ProbeHit<P>>; 3 * MAX_PROBE_HITS],
    len: usize,
}

impl<P> ProbeSet<P> {
    /// The hits.
    pub fn iter(&self) -> impl Iterator<Item = &ProbeHit<P>> {
        self.hits[..self.len].iter().flatten()
    }
    /// Number of hits.
    pub fn len(&self) -> usize {
        self.len
    }
    /// True when no probe found anything.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// Traces one probe per axis around `x_o` (see the module docs); `coeffs` are the coefficients
/// at x_o that shape the sampling density. Draws 3 uniform numbers per axis from `rng`.
pub fn probe<C: ProbeChords, U: UniformSource>(
    chords: &C,
    x_o: &impl SurfacePoint,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    rng: &mut U,
) -> ProbeSet<C::Point> {
    let channels = sampler.channels(coeffs);
    let origin = x_o.position();
    let frame = Frame::new(x_o.normal());
    let mut set = ProbeSet {
        hits: [None; 3 * MAX_PROBE_HITS],
        len: 0,
    };
    for axis in 0..3 {
        let ch = ((rng.next_f64() * 3.0) as usize).min(2);
        let (u_r, u_phi) = (rng.next_f64(), rng.next_f64());
        let Some((prof, r_max)) = channels[ch].as_ref() else {
            continue;
        };
        let Some(r) = prof.sample_r(u_r) else {
            continue;
        };
        if r.is_nan() || r >= *r_max {
            continue;
        }
        let phi = std::f64::consts::TAU * u_phi;
        let (vx, vy, vz) = frame.axes(axis);
        let half = (r_max * r_max - r * r).sqrt();
        let base = origin + r * (phi.cos() * vx + phi.sin() * vy) - half * vz;
        let mut kept = 0;
        chords.for_each_hit(base, vz, 2.0 * half, |h| {
            if kept < MAX_PROBE_HITS {
                let p = axis_densities_in(origin, &frame, h, &channels)
                    .iter()
                    .sum::<f64>();
                if p > 0.0 && p.is_finite() {
                    set.hits[set.len] = Some(ProbeHit {
                        hit: *h,
                        weight: 1.0 / p,
                    });
                    set.len += 1;
                    kept += 1;
                }
            }
        });
    }
    set
}

/// `p(x)` of the module docs (1/length²): the density with which [`probe`] around `x_o`, with
/// coefficients `coeffs` there, finds the surface point `x_i`.
pub fn probe_density(
    x_o: &impl SurfacePoint,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    x_i: &impl SurfacePoint,
) -> f64 {
    axis_densities(x_o, coeffs, sampler, x_i).iter().sum()
}

/// The three axes' terms of [`probe_density`] (tangent s, tangent t, normal), each already
/// divided by 3 (the axes' share); their sum is `p(x)`.
pub fn axis_densities(
    x_o: &impl SurfacePoint,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    x_i: &impl SurfacePoint,
) -> [f64; 3] {
    axis_densities_in(
        x_o.position(),
        &Frame::new(x_o.normal()),
        x_i,
        &sampler.channels(coeffs),
    )
}

fn axis_densities_in<P: RadialProfile>(
    x_o: DVec3,
    frame: &Frame,
    x_i: &impl SurfacePoint,
    channels: &[Option<(P, f64)>; 3],
) -> [f64; 3] {
    let d = x_i.position() - x_o;
    let dist = d.length();
    let ng = x_i.geometric_normal();
    let dl = DVec3::new(d.dot(frame.s), d.dot(frame.t), d.dot(frame.n));
    let nl = DVec3::new(ng.dot(frame.s), ng.dot(frame.t), ng.dot(frame.n));
    let r_proj = [
        (dl.y * dl.y + dl.z * dl.z).sqrt(),
        (dl.z * dl.z + dl.x * dl.x).sqrt(),
        (dl.x * dl.x + dl.y * dl.y).sqrt(),
    ];
    let mut pdf = [0.0; 3];
    for (prof, r_max) in channels.iter().flatten() {
        if dist >= *r_max {
            continue;
        }
        for axis in 0..3 {
            let r = r_proj[axis];
            if r > 0.0 {
                pdf[axis] += prof.pdf_r(r) / (3.0 * std::f64::consts::TAU * r) * nl[axis].abs();
            }
        }
    }
    pdf
}

/// The shading frame at x_o.
struct Frame {
    s: DVec3,
    t: DVec3,
    n: DVec3,
}

impl Frame {
    fn new(n: DVec3) -> Self {
        let (s, t) = orthonormal_basis(n);
        Self { s, t, n }
    }
    /// `(vx, vy, vz)` for projection axis `axis` (0 = s, 1 = t, 2 = n): vz is the probe
    /// direction and (vx, vy) span the plane the radius is sampled in.
    fn axes(&self, axis: usize) -> (DVec3, DVec3, DVec3) {
        match axis {
            0 => (self.t, self.n, self.s),
            1 => (self.n, self.s, self.t),
            _ => (self.s, self.t, self.n),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SplitMix64;
    use bssrdf_core::{ProfileModel, Scattering};

    #[derive(Clone, Copy)]
    struct P(DVec3, DVec3);
    impl SurfacePoint for P {
        fn position(&self) -> DVec3 {
            self.0
        }
        fn normal(&self) -> DVec3 {
            self.1
        }
    }

    /// Two parallel planes z = 0 (normal +z) and z = −h (normal −z): a slab of thickness h.
    struct Slab(f64);
    impl ProbeChords for Slab {
        type Point = P;
        fn for_each_hit(&self, o: DVec3, d: DVec3, t_max: f64, mut f: impl FnMut(&P)) {
            let mut hits = [
                (-o.z / d.z, DVec3::Z),
                ((-self.0 - o.z) / d.z, DVec3::NEG_Z),
            ];
            hits.sort_by(|a, b| a.0.total_cmp(&b.0));
            for (t, n) in hits {
                if t.is_finite() && (0.0..=t_max).contains(&t) {
                    f(&P(o + t * d, n));
                }
            }
        }
    }

    /// `E[Σ_hits f/p] = ∫ f dA` over the surface inside the largest probe sphere (radius R),
    /// here for `f = e^{−|x − x_o|/ℓ}` on a slab of thickness h < R, with closed forms
    /// `2πℓ²[1 − (1 + R/ℓ)e^{−R/ℓ}]` on the top face and `2πℓ²[(1 + h/ℓ)e^{−h/ℓ} −
    /// (1 + R/ℓ)e^{−R/ℓ}]` on the bottom one. ℓ = 1/σ_tr of the widest channel keeps f/p
    /// bounded, as the BSSRDF itself does in a renderer.
    #[test]
    fn the_estimator_integrates_over_the_surface_inside_the_probe_sphere() {
        let family =
            ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0).unwrap();
        let c = Coefficients {
            sigma_a: crate::Rgb::new(0.02, 0.05, 0.2),
            sigma_s: crate::Rgb::new(1.0, 1.5, 2.0),
        };
        let sampler = ProbeSampler::new(family, c);
        let big_r = sampler.probe_radius(c);
        let h = 0.4 * big_r;
        let ell = 1.0 / (3.0 * 0.02 * 1.02f64).sqrt();
        let e = |x: f64| (1.0 + x / ell) * (-x / ell).exp();
        let tau = std::f64::consts::TAU;
        let want = tau * ell * ell * ((1.0 - e(big_r)) + (e(h) - e(big_r)));
        let x_o = P(DVec3::ZERO, DVec3::Z);
        let mut rng = SplitMix64::new(11);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let set = probe(&Slab(h), &x_o, c, &sampler, &mut rng);
            let w: f64 = set
                .iter()
                .map(|hit| (-hit.hit.position().length() / ell).exp() * hit.weight)
                .sum();
            s += w;
            s2 += w * w;
        }
        let mean = s / n as f64;
        let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
        assert!(
            (mean - want).abs() < 4.0 * se,
            "{mean} ± {se}, integral {want}"
        );
        assert!(se < 0.015 * want, "test too weak: {mean} ± {se} of {want}");
    }

    #[test]
    fn density_splits_by_axis_and_matches_each_hit() {
        let family =
            ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.3).unwrap();
        let c = Coefficients::grey(0.05, 1.0);
        let sampler = ProbeSampler::new(family, c);
        let x_o = P(DVec3::ZERO, DVec3::Z);
        let mut rng = SplitMix64::new(3);
        let mut seen = 0;
        for _ in 0..100 {
            for hit in probe(&Slab(0.5), &x_o, c, &sampler, &mut rng).iter() {
                let axes = axis_densities(&x_o, c, &sampler, &hit.hit);
                let p = probe_density(&x_o, c, &sampler, &hit.hit);
                assert!((axes.iter().sum::<f64>() - p).abs() <= 1e-12 * p);
                assert!((hit.weight * p - 1.0).abs() < 1e-12);
                seen += 1;
            }
        }
        assert!(seen > 100);
        // Outside every probe sphere the density is zero.
        let far = P(
            DVec3::new(10.0 * sampler.probe_radius(c), 0.0, 0.0),
            DVec3::Z,
        );
        assert_eq!(probe_density(&x_o, c, &sampler, &far), 0.0);
    }
}
