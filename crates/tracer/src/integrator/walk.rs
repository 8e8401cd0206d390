//! The random walk inside one closed translucent object: delta tracking to the next real
//! collision or the boundary, Henyey–Greenstein scattering, and the boundary itself
//! (index-matched: pass straight through; smooth dielectric η > 1: Fresnel reflection,
//! refraction or total internal reflection, chosen stochastically with their probabilities,
//! pbrt-v4 §9.5; rough dielectric: a GGX microsurface, [`crate::bsdf::RoughDielectric`]).
//! Shared by the camera path tracer and the light tracer of the beam experiment.
//!
//! Other objects inside or crossing the medium: the walk intersects the whole scene, and a
//! surface of another object met before the boundary ends the walk ([`WalkEnd::Surface`]); the
//! caller shades it (an opaque core, a floor the object is sunk into) and may walk on from it in
//! the same medium. Overlapping translucent objects are refused when the scene is built
//! (`Scene::require_disjoint_media`).
//!
//! Termination: a path ends when it is absorbed (probability σa/σ̄ at each tentative collision)
//! or leaves the object. With σa = 0 inside a *closed, finite* object every walk still leaves
//! with probability 1 (the expected number of collisions grows like (size·σt)², e.g. ~1e6 for a
//! unit cube at σt = 1e3); a hard cap ([`MAX_COLLISIONS`] unless [`set_collision_cap`] changes
//! it) guards against pathological inputs,
//! and every capped path is counted ([`PathCounters::capped`]) rather than dropped silently.

use bssrdf_core::Rgb;
use glam::DVec3;

use crate::bsdf::{DielectricSample, Frame, Lobe, RoughDielectric, alpha_from_roughness};
use crate::field::Field;
use crate::geometry::{Geometry, Hit, Ray};
use crate::integrator::counters::PathCounters;
use crate::rng::Rng;
use crate::scene::Translucent;
use crate::volume::{FreeFlight, Interaction, TrackingCounters, sample_hg};

/// Collisions allowed in one walk before it is stopped and counted as capped, by default.
pub const MAX_COLLISIONS: u64 = 100_000_000;

static COLLISION_CAP: std::sync::atomic::AtomicU64 =
    std::sync::atomic::AtomicU64::new(MAX_COLLISIONS);

/// Sets the collision cap of every walk started afterwards (`render`/`beam`
/// `--max-collisions`): a walk longer than this is stopped and counted in
/// [`PathCounters::capped`], which the commands report. A lower cap bounds the time one path can
/// take in an optically huge medium, at the cost of the light those paths would have carried.
pub fn set_collision_cap(cap: u64) {
    COLLISION_CAP.store(cap.max(1), std::sync::atomic::Ordering::Relaxed);
}

/// The collision cap in force (see [`set_collision_cap`]).
pub fn collision_cap() -> u64 {
    COLLISION_CAP.load(std::sync::atomic::Ordering::Relaxed)
}

/// The boundary interface of a translucent object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interface<'a> {
    /// Relative index η = n_inside / n_outside (≥ 1).
    pub eta: f64,
    /// The boundary's roughness field (r, α = r²; [`crate::scene::Translucent::roughness`]),
    /// `None` for a smooth boundary.
    pub roughness: Option<&'a Field>,
}

/// What happens to a ray meeting an interface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Crossing {
    /// Reflection (Fresnel or total internal reflection; specular, or off a microfacet) into
    /// this direction.
    Reflect(DVec3),
    /// Transmission into this direction (refracted when η ≠ 1).
    Transmit(DVec3),
    /// Lost at a rough boundary: no sample of the energy-conserving lobe was kept in
    /// [`crate::bsdf::dielectric::MAX_TRIES`] draws (probability below 1e-14). The walk ends as
    /// if absorbed.
    Lost,
}

impl Interface<'static> {
    /// A smooth boundary of relative index `eta`.
    pub const fn smooth(eta: f64) -> Self {
        Interface {
            eta,
            roughness: None,
        }
    }
}

impl<'a> Interface<'a> {
    /// The boundary of `material`.
    pub fn of(material: &'a Translucent) -> Self {
        Interface {
            eta: material.eta,
            roughness: material.roughness.as_ref(),
        }
    }

    /// True for an index-matched boundary.
    pub fn is_index_matched(&self) -> bool {
        self.eta == 1.0
    }

    /// The microfacet roughness α at the boundary point `hit` when the boundary acts as a
    /// rough one there (η ≠ 1 and α ≥ [`crate::bsdf::SMOOTH_ALPHA`]); `None` where it is
    /// smooth.
    #[inline]
    pub fn rough_alpha(&self, hit: &Hit) -> Option<f64> {
        let r = self.roughness?;
        let alpha = alpha_from_roughness(r.eval(hit.p, hit.uv)[0]);
        (!RoughDielectric::is_smooth(self.eta, alpha)).then_some(alpha)
    }

    /// Crosses the interface at the boundary point `hit` (outward normal `hit.ng`), smooth or
    /// rough there ([`Interface::cross`], [`Interface::cross_rough`]).
    #[inline]
    pub fn cross_at(&self, dir: DVec3, hit: &Hit, rng: &mut Rng) -> Crossing {
        match self.rough_alpha(hit) {
            Some(alpha) => self.cross_rough(dir, hit.ng, alpha, rng).0,
            None => self.cross(dir, hit.ng, rng),
        }
    }

    /// Crosses a rough boundary of roughness `alpha` at a surface with outward normal `ng`
    /// (from either side): reflection or refraction through a microfacet normal drawn from
    /// those visible from `−dir`, by the energy-conserving lobe
    /// ([`RoughDielectric::sample_conserving`]), so that the walk stays analog and the boundary
    /// loses no light. Returns the crossing and the single-scattering sample it kept (its
    /// density and `G/G1`, from which a caller that knows the single-scattering albedo E forms
    /// the conserving lobe's density `pdf · (G/G1) / E` for MIS); `Lost` in the 1e-14 case where
    /// no sample was kept.
    #[inline(never)] // out of the walk's loop for smooth boundaries
    pub fn cross_rough(
        &self,
        dir: DVec3,
        ng: DVec3,
        alpha: f64,
        rng: &mut Rng,
    ) -> (Crossing, Option<DielectricSample>) {
        let frame = Frame::new(ng);
        let wo = frame.to_local(-dir);
        let Some(s) = RoughDielectric::new(self.eta, alpha).sample_conserving(wo, rng) else {
            return (Crossing::Lost, None);
        };
        let w = frame.to_world(s.wi).normalize();
        let crossing = match s.lobe {
            Lobe::Reflection => Crossing::Reflect(w),
            Lobe::Transmission => Crossing::Transmit(w),
        };
        (crossing, Some(s))
    }

    /// Crosses the interface at a surface with outward normal `ng`, for a ray travelling along
    /// `dir`: from outside when `dir·ng < 0`, from inside otherwise. Reflection is chosen with
    /// the Fresnel probability, so the path weight is unchanged (analog).
    pub fn cross(&self, dir: DVec3, ng: DVec3, rng: &mut Rng) -> Crossing {
        if self.is_index_matched() {
            return Crossing::Transmit(dir);
        }
        let cos_n = dir.dot(ng);
        // Normal on the incident side, and the relative index across the boundary.
        let (n, eta_rel) = if cos_n < 0.0 {
            (ng, self.eta)
        } else {
            (-ng, 1.0 / self.eta)
        };
        let cos_i = (-dir.dot(n)).clamp(0.0, 1.0);
        let f = bssrdf_core::fresnel::dielectric(cos_i, eta_rel);
        if rng.uniform() < f {
            return Crossing::Reflect(reflect(dir, n));
        }
        match refract(dir, n, eta_rel) {
            Some(t) => Crossing::Transmit(t),
            None => Crossing::Reflect(reflect(dir, n)),
        }
    }
}

/// Mirror reflection of `dir` about the normal `n`.
pub fn reflect(dir: DVec3, n: DVec3) -> DVec3 {
    (dir - 2.0 * dir.dot(n) * n).normalize()
}

/// Refraction of `dir` through a surface with normal `n` on the incident side and relative
/// index `eta = n_t / n_i`; `None` under total internal reflection.
pub fn refract(dir: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = -dir.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((dir / eta + (cos_i / eta - cos_t) * n).normalize())
}

/// How a walk ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WalkEnd {
    /// The path left the object through `hit` travelling along `dir` (outside).
    Exited {
        /// The boundary point.
        hit: Hit,
        /// Direction outside the object.
        dir: DVec3,
        /// The last real scattering vertex and the phase-function pdf of the direction that
        /// left it, when that direction reached the boundary without a specular event (for
        /// MIS against light sampling); `None` after a specular interface event.
        last_scatter: Option<(DVec3, f64)>,
    },
    /// The path met the surface of another object (`hit.object` ≠ the walk's object) inside
    /// the medium, travelling along `dir`.
    Surface {
        /// The surface point.
        hit: Hit,
        /// Direction of travel when it was reached.
        dir: DVec3,
        /// As for [`WalkEnd::Exited`].
        last_scatter: Option<(DVec3, f64)>,
    },
    /// Absorbed inside.
    Absorbed,
    /// Stopped by [`MAX_COLLISIONS`] (counted).
    Capped,
    /// No boundary found (counted).
    Leaked,
}

/// Where a walk starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkStart {
    /// A point inside the medium: the entry hit's `spawn_origin(dir)`, or a point just off a
    /// surface inside it.
    pub origin: DVec3,
    /// The unit direction of travel.
    pub dir: DVec3,
    /// The vertex the walk starts from, as [`WalkEnd::Exited`] reports it if no event happens
    /// (its point and the direction's pdf there, for MIS); `None` when entering through the
    /// boundary.
    pub last_scatter: Option<(DVec3, f64)>,
}

/// One object's medium as the walk sees it.
pub struct WalkMedium<'a, M: FreeFlight> {
    /// The scene geometry.
    pub geometry: &'a Geometry,
    /// The object's index.
    pub object: u32,
    /// The free-flight sampler: one channel ([`crate::volume::ChannelView`]) or every channel
    /// with a hero ([`crate::spectral::HeroTracking`]).
    pub medium: &'a M,
    /// HG mean cosine.
    pub g: f64,
    /// The boundary.
    pub interface: Interface<'a>,
}

impl<M: FreeFlight> WalkMedium<'_, M> {
    /// Walks from `from` until the path leaves, meets another object's surface, is absorbed
    /// or is capped. `order` counts real scattering events and is incremented at each one;
    /// `on_scatter(p, dir_in, order, rng)` is called at every real scattering vertex before the
    /// new direction is sampled (next-event estimation goes there).
    pub fn walk(
        &self,
        from: WalkStart,
        order: &mut u32,
        rng: &mut Rng,
        counters: &mut PathCounters,
        mut on_scatter: impl FnMut(DVec3, DVec3, u32, &mut Rng),
    ) -> WalkEnd {
        let mut weight = Rgb::ONE;
        self.walk_carrying(
            from,
            order,
            &mut weight,
            rng,
            counters,
            |p, d, k, _, rng| on_scatter(p, d, k, rng),
        )
    }

    /// [`WalkMedium::walk`] carrying the per-channel path weight `weight`, which every flight
    /// multiplies ([`FreeFlight`]: unchanged for one channel, the density ratios to the hero
    /// for hero tracking, up to a common factor); `on_scatter` also receives the weight at the
    /// scattering vertex.
    pub fn walk_carrying(
        &self,
        from: WalkStart,
        order: &mut u32,
        weight: &mut Rgb,
        rng: &mut Rng,
        counters: &mut PathCounters,
        mut on_scatter: impl FnMut(DVec3, DVec3, u32, Rgb, &mut Rng),
    ) -> WalkEnd {
        let WalkStart {
            mut origin,
            dir: mut d,
            mut last_scatter,
        } = from;
        let mut collisions = 0u64;
        let cap = collision_cap();
        let mut tracking = TrackingCounters::default();
        let (lo, hi) = self.geometry.object_bounds(self.object);
        let end = loop {
            // The flight first, up to where the ray leaves the object's bounding box; the scene
            // only when the flight reaches a surface (see [`Self::flight`]).
            let (interaction, boundary) = match self.flight(
                origin,
                d,
                box_exit(origin, d, lo, hi),
                rng,
                &mut tracking,
                weight,
            ) {
                Some(found) => found,
                None => {
                    counters.leaks += 1;
                    break WalkEnd::Leaked;
                }
            };
            match interaction {
                Interaction::Absorb { .. } => break WalkEnd::Absorbed,
                Interaction::Scatter { t } => {
                    collisions += 1;
                    if collisions > cap {
                        counters.capped += 1;
                        break WalkEnd::Capped;
                    }
                    let p = origin + t * d;
                    *order += 1;
                    on_scatter(p, d, *order, *weight, rng);
                    let nd = sample_hg(d, self.g, rng);
                    last_scatter = Some((p, bssrdf_core::hg::phase(d.dot(nd), self.g)));
                    origin = p;
                    d = nd;
                }
                Interaction::Pass if boundary.is_some_and(|b| b.object != self.object) => {
                    break WalkEnd::Surface {
                        hit: boundary.expect("a pass has its surface"),
                        dir: d,
                        last_scatter,
                    };
                }
                Interaction::Pass => {
                    let boundary = boundary.expect("a pass has its surface");
                    if boundary.ng.dot(d) <= 0.0 {
                        // Seen from outside although we are inside: the origin sat numerically
                        // on the far side of a face. Step over the face and go on.
                        counters.wrong_side += 1;
                        origin = boundary.spawn_origin(d);
                        continue;
                    }
                    match self.interface.cross_at(d, &boundary, rng) {
                        Crossing::Transmit(out) => {
                            break WalkEnd::Exited {
                                hit: boundary,
                                dir: out,
                                last_scatter,
                            };
                        }
                        Crossing::Reflect(r) => {
                            last_scatter = None;
                            origin = boundary.spawn_origin(r);
                            d = r;
                        }
                        Crossing::Lost => break WalkEnd::Absorbed,
                    }
                }
            }
        };
        counters.scatterings += collisions;
        counters.add_tracking(&tracking);
        end
    }

    /// One flight from `origin` along `d`: the next real interaction before the first surface
    /// of the scene, with that surface when the flight reaches it (`Pass`); `None` when no
    /// surface is found (the ray has leaked out of the closed object).
    ///
    /// The flight is sampled first, up to `t_box` (where the ray leaves the object's bounding
    /// box, beyond which no surface that ends the walk can lie), and the scene is asked only
    /// whether anything lies on the segment up to the sampled collision: inside a medium
    /// most flights end in a collision far from any surface, and an occlusion query on a
    /// short segment costs less than the closest hit of the whole ray. When a surface is on
    /// the segment (or the flight reached `t_box`), the flight is sampled again up to the
    /// closest hit with the same random numbers: its tentative collisions are the same up to
    /// that surface, where it passes, and it leaves `rng` and `weight` exactly as sampling
    /// up to the surface from the start does. The outcome is therefore the same sample as
    /// delta tracking against the closest hit, random number for random number (up to the
    /// rounding of the two hit tests, for a collision within it of a surface).
    fn flight(
        &self,
        origin: DVec3,
        d: DVec3,
        t_box: f64,
        rng: &mut Rng,
        tracking: &mut TrackingCounters,
        weight: &mut Rgb,
    ) -> Option<(Interaction, Option<Hit>)> {
        if t_box > 0.0 {
            let (saved_rng, saved_weight) = (rng.clone(), *weight);
            let sampled = self
                .medium
                .sample_flight(origin, d, t_box, rng, tracking, weight);
            match sampled {
                Interaction::Scatter { t } | Interaction::Absorb { t }
                    if !self.geometry.occluded(&Ray::with_range(origin, d, 0.0, t)) =>
                {
                    return Some((sampled, None));
                }
                _ => {
                    // (The tentative collisions drawn stay counted: they were work done.)
                    *rng = saved_rng;
                    *weight = saved_weight;
                }
            }
        }
        let boundary = self.geometry.intersect(&Ray::new(origin, d))?;
        let sampled = self
            .medium
            .sample_flight(origin, d, boundary.t, rng, tracking, weight);
        Some((sampled, Some(boundary)))
    }
}

/// The distance along `origin + t·d` at which the ray leaves the box `[lo, hi]` (slab test),
/// 0 when `origin` is outside it (or anything is NaN).
#[inline]
fn box_exit(origin: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    let mut far = f64::INFINITY;
    for k in 0..3 {
        let (o, lo, hi) = (origin[k], lo[k], hi[k]);
        // `!(lo <= o && o <= hi)` is also true for NaN.
        if !(lo <= o && o <= hi) {
            return 0.0;
        }
        // Moving along this axis, the ray leaves through the face it moves toward; parallel
        // to it (d = 0), never through this pair of faces.
        let exit = if d[k] > 0.0 {
            (hi - o) / d[k]
        } else if d[k] < 0.0 {
            (lo - o) / d[k]
        } else {
            f64::INFINITY
        };
        far = far.min(exit);
    }
    far
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::field::{Axis, Field, MediumField, PlanarProjection};
    use crate::geometry::primitives;
    use crate::light::Light;
    use crate::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};
    use crate::spectral::{HeroTracking, SpectralView};

    #[test]
    fn box_exit_is_the_nearest_far_face_and_zero_outside() {
        let (lo, hi) = (DVec3::splat(-1.0), DVec3::splat(1.0));
        assert_eq!(box_exit(DVec3::ZERO, DVec3::X, lo, hi), 1.0);
        let d = DVec3::new(1.0, 1.0, 0.0).normalize();
        assert!((box_exit(DVec3::new(0.5, 0.0, 0.0), d, lo, hi) - 0.5 * 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(box_exit(DVec3::new(2.0, 0.0, 0.0), DVec3::X, lo, hi), 0.0);
        assert_eq!(
            box_exit(DVec3::new(2.0, 0.0, 0.0), DVec3::NEG_X, lo, hi),
            0.0
        );
        // On a face: along its plane, or out through it.
        assert_eq!(box_exit(DVec3::new(0.0, 1.0, 0.0), DVec3::X, lo, hi), 1.0);
        assert_eq!(box_exit(DVec3::new(0.0, 1.0, 0.0), DVec3::Y, lo, hi), 0.0);
        assert_eq!(box_exit(DVec3::splat(f64::NAN), DVec3::X, lo, hi), 0.0);
    }

    /// A chromatic checked sphere (radius 1.5, η 1.3) with an opaque cube inside it.
    fn sphere_with_core() -> Scene {
        let projection = PlanarProjection::new(Axis::Z, DVec3::ZERO);
        let sigma_a = Field::check(
            0.4,
            [Rgb::new(0.05, 0.2, 0.5), Rgb::new(1.0, 0.3, 0.1)],
            projection,
        )
        .unwrap();
        let sigma_s = Field::constant(Rgb::new(2.0, 3.0, 4.0)).unwrap();
        let medium = MediumField::new(sigma_a, sigma_s);
        let camera =
            Camera::orthographic(DVec3::Z * 5.0, DVec3::NEG_Z, DVec3::Y, 4.0, 4.0, 8, 8).unwrap();
        SceneBuilder::new(RenderSettings::new(8, 8, 1), camera)
            .light(Light::environment(Rgb::ONE).unwrap())
            .object(
                "ball",
                primitives::icosphere(DVec3::ZERO, 1.5, 3),
                Material::Translucent(Translucent::new("m", medium, 0.3, 1.3)),
            )
            .object(
                "core",
                primitives::cuboid(DVec3::splat(-0.3), DVec3::splat(0.3)),
                Material::diffuse(Rgb::splat(0.5)),
            )
            .build()
            .unwrap()
    }

    /// The walk as delta tracking against the closest hit of every flight (what
    /// [`WalkMedium::flight`] must reproduce): the boundary first, then the flight up to it.
    fn closest_hit_walk<M: FreeFlight>(
        walk: &WalkMedium<'_, M>,
        start: DVec3,
        dir: DVec3,
        weight: &mut Rgb,
        rng: &mut Rng,
    ) -> WalkEnd {
        let (mut origin, mut d, mut last) = (start, dir, None);
        let mut tracking = TrackingCounters::default();
        loop {
            let Some(b) = walk.geometry.intersect(&Ray::new(origin, d)) else {
                return WalkEnd::Leaked;
            };
            match walk
                .medium
                .sample_flight(origin, d, b.t, rng, &mut tracking, weight)
            {
                Interaction::Absorb { .. } => return WalkEnd::Absorbed,
                Interaction::Scatter { t } => {
                    let p = origin + t * d;
                    let nd = sample_hg(d, walk.g, rng);
                    last = Some((p, bssrdf_core::hg::phase(d.dot(nd), walk.g)));
                    (origin, d) = (p, nd);
                }
                Interaction::Pass if b.object != walk.object => {
                    return WalkEnd::Surface {
                        hit: b,
                        dir: d,
                        last_scatter: last,
                    };
                }
                Interaction::Pass => {
                    if b.ng.dot(d) <= 0.0 {
                        origin = b.spawn_origin(d);
                        continue;
                    }
                    match walk.interface.cross_at(d, &b, rng) {
                        Crossing::Transmit(out) => {
                            return WalkEnd::Exited {
                                hit: b,
                                dir: out,
                                last_scatter: last,
                            };
                        }
                        Crossing::Reflect(r) => {
                            last = None;
                            origin = b.spawn_origin(r);
                            d = r;
                        }
                        Crossing::Lost => return WalkEnd::Absorbed,
                    }
                }
            }
        }
    }

    /// Sampling each flight first and querying the scene only on its segment gives the walks
    /// of delta tracking against the closest hit, random number for random number: the same
    /// ends, weights and random streams afterwards, for 3000 walks in a chromatic sphere
    /// (hero tracking) with a surface inside.
    #[test]
    fn flights_first_walk_as_closest_hit_tracking_does() {
        let scene = sphere_with_core();
        let Material::Translucent(t) = &scene.objects()[0].material else {
            unreachable!()
        };
        let (mut surfaces, mut exits) = (0, 0);
        for k in 0..3000u64 {
            let flight = HeroTracking {
                medium: SpectralView::new(&t.medium),
                hero: (k % 3) as usize,
            };
            let walk = WalkMedium {
                geometry: scene.geometry(),
                object: 0,
                medium: &flight,
                g: t.g,
                interface: Interface::of(t),
            };
            let entry = scene
                .geometry()
                .intersect(&Ray::new(DVec3::new(0.1, -0.2, 5.0), DVec3::NEG_Z))
                .unwrap();
            let start = entry.spawn_origin(DVec3::NEG_Z);
            let (mut a, mut b) = (Rng::from_keys(7, &[k]), Rng::from_keys(7, &[k]));
            let (mut wa, mut wb) = (Rgb::ONE, Rgb::ONE);
            let mut order = 0;
            let mut counters = PathCounters::default();
            let from = WalkStart {
                origin: start,
                dir: DVec3::NEG_Z,
                last_scatter: None,
            };
            let end = walk.walk_carrying(
                from,
                &mut order,
                &mut wa,
                &mut a,
                &mut counters,
                |_, _, _, _, _| {},
            );
            let want = closest_hit_walk(&walk, start, DVec3::NEG_Z, &mut wb, &mut b);
            assert_eq!(end, want, "walk {k}");
            assert_eq!(wa, wb, "walk {k}");
            assert_eq!(a.next_u64(), b.next_u64(), "walk {k}");
            surfaces += matches!(end, WalkEnd::Surface { .. }) as u32;
            exits += matches!(end, WalkEnd::Exited { .. }) as u32;
        }
        // Both kinds of pass happened.
        assert!(surfaces > 100 && exits > 100, "{surfaces} {exits}");
    }

    #[test]
    fn refraction_obeys_snell_and_tir() {
        let n = DVec3::Z;
        let dir = DVec3::new(0.6, 0.0, -0.8);
        let t = refract(dir, n, 1.5).unwrap();
        let sin_i = 0.6;
        let sin_t = (1.0 - t.z * t.z).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-12);
        assert!(t.z < 0.0);
        // From inside (eta_rel = 1/1.5) beyond the critical angle: TIR.
        let inside = DVec3::new(0.8, 0.0, 0.6);
        assert!(refract(inside, -n, 1.0 / 1.5).is_none());
    }

    #[test]
    fn fresnel_crossing_frequency_matches_reflectance() {
        let iface = Interface::smooth(1.5);
        let dir = DVec3::new(0.6, 0.0, -0.8);
        let f = bssrdf_core::fresnel::dielectric(0.8, 1.5);
        let mut rng = Rng::from_keys(3, &[]);
        let n = 200_000;
        let refl = (0..n)
            .filter(|_| matches!(iface.cross(dir, DVec3::Z, &mut rng), Crossing::Reflect(_)))
            .count();
        let p = refl as f64 / n as f64;
        let se = (f * (1.0 - f) / n as f64).sqrt();
        assert!((p - f).abs() < 4.0 * se, "{p} vs {f}");
    }
}
