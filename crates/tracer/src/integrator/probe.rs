//! Importance sampling of incident points x_i around an exitant point x_o with probe rays
//! (after pbrt-v4 §11.4.3, `TabulatedBSSRDF::Sample` / `PdfSp`, with two variance reductions).
//!
//! A probe along axis `a` of x_o's shading frame (the normal or one of the two tangents) picks
//! a colour channel `c` uniformly, samples a radius r from that channel's radial profile (the
//! homogeneous profile of the coefficients at x_o, from the profile table), an angle φ
//! uniformly, and traces the chord of the sphere of radius `r_max,c` (holding
//! [`PROBE_ENERGY_FRACTION`] of the profile's energy) along the axis at (r, φ).
//!
//! pbrt traces one probe along a randomly chosen axis and keeps one of its hits at random.
//! Here every camera sample traces **one probe per axis and keeps every hit**: a multi-sample
//! estimator with balance-heuristic weights over the three axes (Veach 1997, §9.2), so each
//! hit x contributes `f(x) / p(x)` with
//!
//! `p(x) = Σ_axes (1/3) Σ_c [|x − x_o| < r_max,c] · p_r,c(r_a) / (2π r_a) · |n(x) · axis|`,
//!
//! `r_a` the distance from x_o to x projected on the plane perpendicular to the axis and
//! `p_r,c` the channel's radial density (per unit length). `E[Σ_hits f/p] = ∫ f dA` over the
//! surface inside the largest probe sphere: on a flat surface the normal probe then always
//! finds x_i instead of succeeding one time in four, and the random choice between the top and
//! the bottom of a thin slab disappears.

use bssrdf_core::{ProfileFamily, ProfileTable, RadialProfile, TableSampler};
use glam::DVec3;
use het_estimate::Coefficients;

use crate::field::MediumField;
use crate::geometry::{Geometry, Hit, Ray};
use crate::rng::Rng;
use crate::volume::orthonormal_basis;

/// Fraction of the profile's energy inside the probe sphere.
pub const PROBE_ENERGY_FRACTION: f64 = 0.999;
/// Most intersections kept per probe chord.
pub const MAX_PROBE_HITS: usize = 16;

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

    /// The largest probe radius over the channels at coefficients `c` (0 if none scatters).
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

/// A found incident point and its estimator weight `1/p(x)` (length², see the module docs).
#[derive(Debug, Clone, Copy)]
pub struct ProbeHit {
    /// The incident point.
    pub hit: Hit,
    /// `1 / p(x)`.
    pub weight: f64,
}

/// The incident points found by the three probes of one camera sample.
pub struct ProbeSet {
    hits: [Option<ProbeHit>; 3 * MAX_PROBE_HITS],
    len: usize,
}

impl ProbeSet {
    /// The hits.
    pub fn iter(&self) -> impl Iterator<Item = &ProbeHit> {
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

/// Traces one probe per axis around `x_o` on `object` (see the module docs); `coeffs` are the
/// coefficients at x_o that shape the sampling density.
pub fn probe(
    geometry: &Geometry,
    object: u32,
    x_o: &Hit,
    coeffs: Coefficients,
    sampler: &ProbeSampler,
    rng: &mut Rng,
) -> ProbeSet {
    let channels = sampler.channels(coeffs);
    let frame = Frame::new(x_o.ns);
    let mut set = ProbeSet {
        hits: [None; 3 * MAX_PROBE_HITS],
        len: 0,
    };
    for axis in 0..3 {
        let ch = rng.below(3) as usize;
        let (u_r, u_phi) = (rng.uniform(), rng.uniform());
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
        let base = x_o.p + r * (phi.cos() * vx + phi.sin() * vy) - half * vz;
        let chord = Ray::with_range(base, vz, 0.0, 2.0 * half);
        let mut kept = 0;
        geometry.for_each_object_hit(object, &chord, |h| {
            if kept < MAX_PROBE_HITS {
                let p = density(x_o.p, &frame, h, &channels);
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

/// `p(x)` of the module docs, for a surface point `x_i` and coefficients `coeffs` at x_o.
pub fn probe_density(x_o: &Hit, coeffs: Coefficients, sampler: &ProbeSampler, x_i: &Hit) -> f64 {
    density(x_o.p, &Frame::new(x_o.ns), x_i, &sampler.channels(coeffs))
}

fn density<P: RadialProfile>(
    x_o: DVec3,
    frame: &Frame,
    x_i: &Hit,
    channels: &[Option<(P, f64)>; 3],
) -> f64 {
    let d = x_i.p - x_o;
    let dist = d.length();
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
    for (prof, r_max) in channels.iter().flatten() {
        if dist >= *r_max {
            continue;
        }
        for axis in 0..3 {
            let r = r_proj[axis];
            if r > 0.0 {
                pdf += prof.pdf_r(r) / (3.0 * std::f64::consts::TAU * r) * nl[axis].abs();
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
