//! Importance sampling of incident points x_i around an exitant point x_o with probe rays
//! (pbrt-v4 §11.4.3, `TabulatedBSSRDF::Sample` / `PdfSp`; pbrt-v3 §15.4.1).
//!
//! A probe picks a projection axis in x_o's shading frame (the normal with probability 1/2,
//! each tangent with 1/4) and a colour channel (1/3 each), samples a radius r from that
//! channel's radial profile (the homogeneous profile of the coefficients at x_o, via the
//! profile table), an angle φ uniformly, and traces the chord of the sphere of radius r_max
//! (the radius holding 99.9 % of the profile's energy) along the axis at that (r, φ). One of
//! the chord's intersections with the object is chosen uniformly. The area density of the
//! chosen point sums every (axis, channel) way it could have been produced:
//!
//! `pdf(x_i) = (1/n_hits) Σ_axes Σ_channels P(axis) P(ch) · p_r,ch(r_axis) / (2π r_axis) · |n_i · axis|`
//!
//! with `r_axis` the distance from x_o to x_i projected on the plane perpendicular to the axis
//! and `p_r` the radial density (per unit length) of the channel's profile.

use bssrdf_core::{ProfileFamily, ProfileTable, RadialProfile};
use glam::DVec3;
use het_estimate::Coefficients;

use crate::field::MediumField;
use crate::geometry::{Geometry, Hit, Ray};
use crate::rng::Rng;
use crate::volume::orthonormal_basis;

/// Fraction of the profile's energy inside the probe sphere.
pub const PROBE_ENERGY_FRACTION: f64 = 0.999;
/// Most intersections of one probe chord that are kept.
pub const MAX_PROBE_HITS: usize = 32;
/// Probability of each projection axis: tangent s, tangent t, normal.
const AXIS_PROB: [f64; 3] = [0.25, 0.25, 0.5];

/// The profile table and fallback coefficients of one translucent material.
pub struct ProbeSampler {
    table: ProfileTable,
    /// Used where the coefficients at x_o do not scatter at all (no profile to sample).
    fallback: Coefficients,
}

impl ProbeSampler {
    /// Builds the table of `family` (once per material).
    pub fn new(family: ProfileFamily, medium: &MediumField) -> Self {
        let fallback = medium.field_bounds().max;
        Self {
            table: ProfileTable::new(family),
            fallback,
        }
    }
}

/// A sampled incident point and its area density (1/length²).
#[derive(Debug, Clone, Copy)]
pub struct ProbeSample {
    /// The incident point.
    pub hit: Hit,
    /// Area density of choosing it.
    pub pdf: f64,
}

/// Samples x_i around `x_o` on `object` (see the module docs); `coeffs` are the coefficients
/// at x_o that shape the sampling density. `None` when the probe finds no point.
pub fn sample_probe(
    geometry: &Geometry,
    object: u32,
    x_o: &Hit,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    rng: &mut Rng,
) -> Option<ProbeSample> {
    let coeffs = if coeffs.sigma_s.max_component() > 0.0 {
        coeffs
    } else {
        sampler.fallback
    };
    let radial: [_; 3] = std::array::from_fn(|c| {
        sampler
            .table
            .sampler(coeffs.sigma_a[c], coeffs.sigma_s[c])
            .ok()
    });
    let frame = Frame::new(x_o.ns);
    let u = rng.uniform();
    let axis = if u < AXIS_PROB[0] {
        0
    } else if u < AXIS_PROB[0] + AXIS_PROB[1] {
        1
    } else {
        2
    };
    let ch = rng.below(3) as usize;
    let prof = radial[ch].as_ref()?;
    let r = prof.sample_r(rng.uniform())?;
    let r_max = prof.radius_for_fraction(PROBE_ENERGY_FRACTION);
    if r.is_nan() || r >= r_max || !r_max.is_finite() {
        return None;
    }
    let phi = std::f64::consts::TAU * rng.uniform();
    let (vx, vy, vz) = frame.axes(axis);
    let half = (r_max * r_max - r * r).sqrt();
    let base = x_o.p + r * (phi.cos() * vx + phi.sin() * vy) - half * vz;
    let probe = Ray::with_range(base, vz, 0.0, 2.0 * half);
    let mut hits = [None; MAX_PROBE_HITS];
    let mut n = 0;
    geometry.for_each_object_hit(object, &probe, |h| {
        if n < MAX_PROBE_HITS {
            hits[n] = Some(*h);
            n += 1;
        }
    });
    if n == 0 {
        return None;
    }
    let hit = hits[rng.below(n as u32) as usize]?;
    let pdf = pdf_area(x_o.p, &frame, &hit, &radial) / n as f64;
    (pdf > 0.0 && pdf.is_finite()).then_some(ProbeSample { hit, pdf })
}

/// Area density (1/length²) with which one probe from `x_o` (coefficients `coeffs` there)
/// reaches the surface point `x_i` along some chord, before the uniform choice among the
/// chord's hits: [`sample_probe`] returns `x_i` with this density divided by the number of
/// hits on the chord it traced.
pub fn probe_density(x_o: &Hit, coeffs: Coefficients, sampler: &ProbeSampler, x_i: &Hit) -> f64 {
    let coeffs = if coeffs.sigma_s.max_component() > 0.0 {
        coeffs
    } else {
        sampler.fallback
    };
    let radial: [_; 3] = std::array::from_fn(|c| {
        sampler
            .table
            .sampler(coeffs.sigma_a[c], coeffs.sigma_s[c])
            .ok()
    });
    pdf_area(x_o.p, &Frame::new(x_o.ns), x_i, &radial)
}

/// Area density of producing `x_i` from `x_o` with one probe, before the 1/n_hits choice.
fn pdf_area<P: RadialProfile>(
    x_o: DVec3,
    frame: &Frame,
    x_i: &Hit,
    radial: &[Option<P>; 3],
) -> f64 {
    let d = x_i.p - x_o;
    let dl = DVec3::new(d.dot(frame.s), d.dot(frame.t), d.dot(frame.n));
    let nl = DVec3::new(
        x_i.ng.dot(frame.s),
        x_i.ng.dot(frame.t),
        x_i.ng.dot(frame.n),
    );
    let r_proj = [
        (dl.y * dl.y + dl.z * dl.z).sqrt(),
        (dl.z * dl.z + dl.x * dl.x).sqrt(),
        (dl.x * dl.x + dl.y * dl.y).sqrt(),
    ];
    let mut pdf = 0.0;
    for axis in 0..3 {
        let r = r_proj[axis];
        if r.is_nan() || r <= 0.0 {
            continue;
        }
        for prof in radial.iter().flatten() {
            pdf += AXIS_PROB[axis] / 3.0 * prof.pdf_r(r) / (std::f64::consts::TAU * r)
                * nl[axis].abs();
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
