//! The shape correction's random walks: a walk reversed from x_o into the body (or into the
//! half-space below its tangent plane, the reference), its flights delta-tracked and its
//! escapes ratio-tracked through the medium's field, and the boundary it crosses. What the
//! walks measure, and why they track the way they do: the parent module's docs.

use crate::field::MediumField;
use crate::geometry::{Hit, ObjectSurface, Ray};
use crate::integrator::walk::{reflect, refract};
use crate::rng::Rng;
use crate::volume::{
    self, ChannelView, LowTransmittance, RatioTracking, TrackedFlight, TrackingCounters,
    direction_about,
};
use bssrdf_core::Scattering;
use glam::{DVec2, DVec3};
use het_estimate::probe::ProbeChords;
use std::f64::consts::TAU;

/// Steps (collisions and boundary events) after which a walk stops: a guard against
/// pathological inputs (σa = 0 in a huge body); Russian roulette ends walks long before.
pub(super) const MAX_STEPS: u32 = 20_000;
/// Russian roulette below this path weight (survivors carry it).
pub(super) const RR_WEIGHT: f64 = 0.05;

/// The tangent plane at x_o as a surface for probe chords: the half-space reference.
pub(super) struct TangentPlane {
    pub(super) p0: DVec3,
    pub(super) n: DVec3,
    pub(super) object: u32,
}

impl ProbeChords for TangentPlane {
    type Point = Hit;
    fn for_each_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, f: &mut dyn FnMut(&Hit)) {
        let dn = dir.dot(self.n);
        if dn == 0.0 {
            return;
        }
        let t = (self.p0 - origin).dot(self.n) / dn;
        if (0.0..=t_max).contains(&t) {
            f(&self.hit(t, origin + t * dir));
        }
    }
}

/// The tangent plane as the estimators' surface: a projection is the line's crossing with
/// the plane (it meets it once, in one direction or the other), and the plane is flat.
impl het_estimate::SurfaceQuery for TangentPlane {
    type Point = Hit;
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let dn = dir.dot(self.n);
        if dn == 0.0 {
            return None;
        }
        let t = (self.p0 - origin).dot(self.n) / dn;
        t.is_finite().then(|| self.hit(t.abs(), origin + t * dir))
    }
    fn curvature(&self, _: &Hit) -> Option<het_estimate::Curvature> {
        Some(het_estimate::Curvature::ZERO)
    }
}

impl TangentPlane {
    /// The plane's point `p`, met at ray distance `t`, as a hit (no triangle, no texture
    /// coordinates).
    pub(super) fn hit(&self, t: f64, p: DVec3) -> Hit {
        Hit {
            t,
            p,
            ng: self.n,
            ns: self.n,
            uv: DVec2::ZERO,
            object: self.object,
            prim: u32::MAX,
            bary: DVec2::ZERO,
            p_error: 0.0,
        }
    }
}

pub(super) enum Boundary<'a> {
    Body(&'a ObjectSurface<'a>),
    Plane(&'a TangentPlane),
}

/// Where a flight from `pos` along `d` meets the boundary.
pub(super) enum Crossing {
    /// Nothing ahead: the tangent plane is behind the flight, which ends in a collision.
    Open,
    /// A face met from outside (numerically behind it): the walk steps over it and resumes
    /// at `resume`, just past it, on `hit`.
    Behind { resume: DVec3, hit: Option<Hit> },
    /// The boundary at distance `s`, point `p`, normal `ng` facing the flight (`cos` = d·ng
    /// > 0), and the body's hit there (none on the plane).
    At {
        s: f64,
        p: DVec3,
        ng: DVec3,
        cos: f64,
        hit: Option<Hit>,
    },
}

impl Boundary<'_> {
    /// The boundary ahead of a flight from `pos` along `d`, `on` the face it starts on;
    /// `None` when a flight inside the body finds no far side (a leak through a crack:
    /// nothing more leaves).
    pub(super) fn crossing(&self, pos: DVec3, d: DVec3, on: Option<Hit>) -> Option<Crossing> {
        let (s, p, ng, hit) = match self {
            Boundary::Body(surface) => {
                let origin = on.map_or(pos, |h| h.spawn_origin(d));
                let h = surface
                    .geometry
                    .intersect_object(surface.object, &Ray::new(origin, d))?;
                ((h.p - pos).length(), h.p, h.ng, Some(h))
            }
            Boundary::Plane(pl) => {
                let dn = d.dot(pl.n);
                if dn <= 0.0 {
                    return Some(Crossing::Open);
                }
                let s = (-(pos - pl.p0).dot(pl.n) / dn).max(0.0);
                (s, pos + s * d, pl.n, None)
            }
        };
        let cos = d.dot(ng);
        Some(if cos <= 0.0 {
            let step = 1e-9_f64.max(hit.map_or(0.0, |h| h.p_error));
            Crossing::Behind {
                resume: p + d * step,
                hit,
            }
        } else {
            Crossing::At { s, p, ng, cos, hit }
        })
    }
}

/// What a walk scatters in.
#[derive(Clone, Copy)]
pub(super) enum EscapeMedium<'m> {
    /// One σt (1/length) and single-scattering albedo everywhere: x_o's coefficients.
    Homogeneous { sigma_t: f64, albedo: f64 },
    /// The medium's own field, in one channel (its majorant σ̄ ≥ σt everywhere must be
    /// positive and finite: [`super::walk_medium`] and [`super::point_sums`] see to it).
    Field {
        field: &'m MediumField,
        channel: usize,
    },
}

/// Largest majorant / smallest σt for which the walks track the field: tracking takes about
/// that many tentative collisions per real one in the thinnest part, so a medium of a
/// sharper contrast (σt from 1e-6 to 1e6 is valid input) is walked in x_o's coefficients.
pub(super) const MAX_TRACKING_CONTRAST: f64 = 100.0;
/// Most tentative collisions one delta- or ratio-tracked flight takes (a guard: a flight
/// that long in a medium whose σt is far below its majorant ends as absorbed).
pub(super) const MAX_TRACKING: u32 = 1_000_000;
/// Ratio tracking stops once the transmittance estimate falls below this (a relative bias of
/// at most this much in the tally).
pub(super) const MIN_TRANSMITTANCE: f64 = 1e-9;

/// Where a reversed walk starts ([`Walk::escape`]): at the boundary point `x_o`, along the
/// direction `d` refracted into the medium, with the weight `w` of the Fresnel transmission
/// there.
pub(super) struct Entry<'h> {
    pub(super) x_o: &'h Hit,
    pub(super) d: DVec3,
    pub(super) w: f64,
}

/// A walk's medium and which escapes count.
pub(super) struct Walk<'m> {
    pub(super) medium: EscapeMedium<'m>,
    pub(super) g: f64,
    pub(super) eta: f64,
    pub(super) orders: Scattering,
}

impl Walk<'_> {
    /// The expected weight with which a walk entering at `x_o`, reversing light that leaves
    /// along `w_o` (unit, outside; weighted by its Fresnel transmission, 0 if `w_o` is behind
    /// the geometric normal), leaves through `boundary` after a counted number of scattering
    /// events. Expected-value estimation: from every vertex the flight's chance of reaching the
    /// boundary times the Fresnel transmission there is tallied; absorption by weighting (×ϖ
    /// per collision) with Russian roulette. In a homogeneous medium that chance is e^{−σt·s}
    /// and the walk goes on with a collision before the boundary or a Fresnel reflection at it,
    /// chosen by their probabilities (1 − e^{−σt·s} and e^{−σt·s}·F) with the weight multiplied
    /// by their sum; it draws 5 numbers per step whatever happens, so that two walks with the
    /// same generator stay in step until their boundaries differ. In a field
    /// ([`Walk::escape_tracked`]) the chance is ratio-tracked and the flight delta-tracked.
    pub(super) fn escape(
        &self,
        boundary: &Boundary<'_>,
        x_o: &Hit,
        w_o: DVec3,
        rng: &mut Rng,
    ) -> f64 {
        let n = x_o.ng;
        let mu = w_o.dot(n);
        if mu <= 0.0 {
            return 0.0;
        }
        let w = 1.0 - bssrdf_core::fresnel::dielectric(mu, self.eta);
        let Some(d) = refract(-w_o, n, self.eta) else {
            return 0.0;
        };
        let entry = Entry { x_o, d, w };
        match self.medium {
            EscapeMedium::Homogeneous { sigma_t, albedo } => {
                self.escape_homogeneous(sigma_t, albedo, boundary, entry, rng)
            }
            EscapeMedium::Field { field, channel } => {
                let medium = ChannelView::new(field, channel);
                self.escape_tracked(&medium, boundary, entry, rng.next_u64())
            }
        }
    }

    /// [`Walk::escape`] in a homogeneous medium of extinction `sigma_t` and single-scattering
    /// `albedo`, from `entry`.
    pub(super) fn escape_homogeneous(
        &self,
        sigma_t: f64,
        albedo: f64,
        boundary: &Boundary<'_>,
        entry: Entry<'_>,
        rng: &mut Rng,
    ) -> f64 {
        let Entry { x_o, mut d, mut w } = entry;
        let mut pos = x_o.p;
        let mut on: Option<Hit> = Some(*x_o);
        let mut order = 0u32;
        let mut tally = 0.0;
        for _ in 0..MAX_STEPS {
            let u = [0; 5].map(|_| rng.uniform());
            let Some(crossing) = boundary.crossing(pos, d, on) else {
                return tally;
            };
            let t = match crossing {
                Crossing::Open => -(1.0 - u[0]).ln() / sigma_t,
                Crossing::Behind { resume, hit } => {
                    pos = resume;
                    on = hit;
                    continue;
                }
                Crossing::At { s, p, ng, cos, hit } => {
                    let reach = (-sigma_t * s).exp();
                    let f = bssrdf_core::fresnel::dielectric(cos, 1.0 / self.eta);
                    if self.counts(order) {
                        tally += w * reach * (1.0 - f);
                    }
                    let (collide, reflect_p) = (1.0 - reach, reach * f);
                    let total = collide + reflect_p;
                    if total <= 0.0 {
                        return tally;
                    }
                    w *= total;
                    if u[3] * total >= collide {
                        d = reflect(d, -ng);
                        pos = p;
                        on = hit;
                        continue;
                    }
                    // A collision before the boundary: the exponential truncated to [0, s).
                    -(1.0 - u[0] * collide).ln() / sigma_t
                }
            };
            pos += t * d;
            on = None;
            order += 1;
            w *= albedo;
            d = self.scatter(d, u[1], u[2]);
            match roulette(w, u[4]) {
                Some(survivor) => w = survivor,
                None => return tally,
            }
        }
        tally
    }

    /// [`Walk::escape`] in a field `medium` (one channel), from `entry`, with the tracking of
    /// [`crate::volume`]. At each vertex the chance of reaching the boundary is estimated by
    /// ratio tracking ([`volume::ratio_tracking`] without a control extinction, stopping below
    /// [`MIN_TRANSMITTANCE`]: an unbiased estimate of the transmittance to within that) and
    /// tallied; the walk then goes on by delta tracking ([`volume::next_collision`]): a real
    /// collision scatters with weight ×σs/σt, reaching the boundary reflects with probability
    /// F and ends otherwise (that escape was tallied already, in expectation). Step k draws its
    /// numbers from generators keyed by (`key`, k), so that the walks in the body and under
    /// the plane stay in step however many tentative collisions each takes: hence the floor
    /// rather than the path tracer's roulette, which would draw numbers of its own.
    pub(super) fn escape_tracked(
        &self,
        medium: &ChannelView<'_>,
        boundary: &Boundary<'_>,
        entry: Entry<'_>,
        key: u64,
    ) -> f64 {
        let Entry { x_o, mut d, mut w } = entry;
        let mut pos = x_o.p;
        let mut on: Option<Hit> = Some(*x_o);
        let mut order = 0u32;
        let mut tally = 0.0;
        let mut counters = TrackingCounters::default();
        // Steps over a face met from behind do not count, so that such a step in one walk
        // does not put it out of step with the other.
        let mut step = 0u64;
        for _ in 0..MAX_STEPS {
            let Some(crossing) = boundary.crossing(pos, d, on) else {
                return tally;
            };
            let mut rng = Rng::from_keys(key, &[step, 0]);
            let (s_max, at) = match crossing {
                Crossing::Open => (f64::INFINITY, None),
                Crossing::Behind { resume, hit } => {
                    pos = resume;
                    on = hit;
                    continue;
                }
                Crossing::At { s, p, ng, cos, hit } => {
                    let f = bssrdf_core::fresnel::dielectric(cos, 1.0 / self.eta);
                    if self.counts(order) {
                        let mut ratio = Rng::from_keys(key, &[step, 1]);
                        let tracking = RatioTracking {
                            control: 0.0,
                            ending: LowTransmittance::Floor {
                                floor: MIN_TRANSMITTANCE,
                                max_steps: MAX_TRACKING,
                            },
                        };
                        let transmittance = volume::ratio_tracking(
                            medium,
                            pos,
                            d,
                            s,
                            tracking,
                            &mut ratio,
                            &mut counters,
                        );
                        tally += w * transmittance * (1.0 - f);
                    }
                    (s, Some((p, ng, f, hit)))
                }
            };
            step += 1;
            // Delta tracking to the next real collision, or to the boundary.
            let flight = volume::next_collision(
                medium,
                pos,
                d,
                s_max,
                MAX_TRACKING,
                &mut rng,
                &mut counters,
            );
            match (flight, at) {
                (TrackedFlight::Collision(c), _) => {
                    pos += c.t * d;
                    on = None;
                    order += 1;
                    w *= c.sigma_s / (c.sigma_a + c.sigma_s);
                    d = self.scatter(d, rng.uniform(), rng.uniform());
                    match roulette(w, rng.uniform()) {
                        Some(survivor) => w = survivor,
                        None => return tally,
                    }
                }
                (TrackedFlight::Pass, Some((p, ng, f, hit))) if rng.uniform() < f => {
                    d = reflect(d, -ng);
                    pos = p;
                    on = hit;
                }
                // Left through the boundary (tallied above), or a flight that found neither a
                // collision nor the boundary within the guard: absorbed.
                _ => return tally,
            }
        }
        tally
    }

    /// The direction after a scattering event: Henyey–Greenstein about `d` from two uniform
    /// numbers.
    #[inline]
    pub(super) fn scatter(&self, d: DVec3, u_cos: f64, u_phi: f64) -> DVec3 {
        let cos = bssrdf_core::hg::sample_cos_theta(self.g, u_cos);
        direction_about(d, cos, TAU * u_phi)
    }

    pub(super) fn counts(&self, order: u32) -> bool {
        match self.orders {
            Scattering::Multiple => order >= 2,
            Scattering::Single => order == 1,
            Scattering::All => order >= 1,
        }
    }
}

/// Russian roulette below [`RR_WEIGHT`]: the weight to go on with (`w`, or `RR_WEIGHT` for a
/// survivor), `None` when the walk ends; `u` uniform.
#[inline]
pub(super) fn roulette(w: f64, u: f64) -> Option<f64> {
    if w >= RR_WEIGHT {
        Some(w)
    } else if u * RR_WEIGHT >= w {
        None
    } else {
        Some(RR_WEIGHT)
    }
}
