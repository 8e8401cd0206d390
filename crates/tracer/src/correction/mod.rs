//! The shape correction: a per-point, per-direction factor that makes the BSSRDF's response to
//! uniform light on a finite body equal the volume's, measured by random walks in the body
//! itself when the render is prepared (docs/shapes.md, "The shape correction", has the
//! measurements and the variants rejected).
//!
//! A half-space profile weighs the surface around x_o by R(|x_i − x_o|). On a finite body that
//! misses (issue 18) light that enters one face and leaves another, and the smaller absorbing
//! volume per unit of surface. Under uniform, unoccluded incident light both are summed up, for
//! light leaving x_o along ω, by one number: by reciprocity the probability P(x_o, ω) that a
//! walk entering the medium at x_o along the refraction of −ω (weighted by the Fresnel
//! transmission at η) leaves it again after the scattering orders the profile models (two or
//! more for `Multiple`, one for `Single`, one or more for `All`). The BSSRDF's own response to
//! the same light is proportional to B(x_o) = ∫_surface R(x_i, x_o) dA(x_i) (the Fresnel and
//! S_w factors are the same on every shape). The correction is
//!
//! c(x_o, ω) = [P_body(x_o, ω) / P_half(x_o, ω)] / [B_body(x_o) / B_half(x_o)],
//!
//! "half" meaning the half-space bounded by the tangent plane at x_o. The walks scatter in the
//! medium itself wherever it varies and is defined in space (a pattern or a planar image: the
//! half-space below the tangent plane then holds the same field), so that a heterogeneous
//! body's light is measured as it travels through the cells its surface does not show; in the
//! coefficients at x_o for a uniform medium, a UV-mapped one (which has no values inside the
//! body) and one whose σt spans more than [`MAX_TRACKING_CONTRAST`] ([`walk_medium`]). B is
//! the profile at x_o's coefficients. On a half-space c = 1 whatever the profile's own error; on a
//! body, the corrected BSSRDF responds to uniform light in the same ratio to the path tracer as
//! it does on a half-space.
//!
//! S is scaled by f(x_i, ω_i)·f(x_o, ω_o), f = c/√c̄, with c̄ the mean of c over the light a
//! uniform sky brings to an incident point (weight (1 − F(μ))μ): under uniform light the exit
//! along ω_o then gets c(ω_o) exactly, and the product of the two factors keeps S symmetric in
//! the pair (docs/reciprocity.md). Where c varies within the profile's reach (corners), two
//! fixed-point steps ([`Sums::refine`]) make the response right with the factors the incident
//! points actually carry.
//!
//! Estimation:
//! * ω at 5 exit cosines ([`MU_NODES`]) × 6 azimuths ([`PHI_NODES`]) in the tangent frame of the
//!   shading normal; f is interpolated linearly between them.
//! * P by expected-value walks ([`Walk::escape`]) with common random numbers (both techniques:
//!   SG69 in docs/references.md): the walk in the body and the walk under the tangent plane
//!   draw the same numbers at each step, so that where the body looks like its tangent
//!   plane they agree step for step. The reciprocity that turns exitance under a uniform sky
//!   into an escape probability is that of Vea97 (adjoint transport). In a heterogeneous
//!   medium the flights are delta-tracked (Woo65 in docs/references.md) and the chance of
//!   reaching the boundary is ratio-tracked (NSJ14) against the medium's majorant, by
//!   [`crate::volume`]'s trackers, each step from random numbers keyed by the step's index,
//!   so that the two walks stay in step however many null collisions each takes.
//! * B by probe sets on the body and on the tangent plane with the same random numbers.
//! * Points drawn uniformly by area on the object's mesh (the material's fixed
//!   `correction_seed`, keyed per object and point, so renders stay deterministic whatever
//!   the thread count), about one per h² of surface with h half
//!   the material's diffusion length, bounded by the object's extent. The raw sums are pooled
//!   over each point's neighbourhood (a Gaussian of width h, weighted by the agreement of the
//!   normals so that the two faces of a thin part do not mix) before dividing, with the
//!   symmetries imposed and the azimuthal dependence kept to its first harmonic
//!   ([`Sums::regularised`]); f is interpolated from the points the same way at render time.
//!
//! In a heterogeneous medium that the walks go through, B weighs each probe pair at the
//! estimator's coefficients for it, on the body and on the tangent plane (whose half-space
//! holds the same field), as the render does; so c measures what the shape does to the
//! BSSRDF actually rendered, whose light reaches as far as the averaged coefficients say
//! (with x_o's own coefficients instead, a point in an absorbing stripe next to clear ones was
//! corrected for a short profile while the render used a long one). A uniform or UV-mapped
//! medium keeps x_o's coefficients, in which its walks scatter too.
//!
//! What it does not correct: the spatial and angular distribution of non-uniform light (c is
//! exact for uniform light, a first-order correction otherwise).

use std::f64::consts::TAU;

use bssrdf_core::Rgb;
use glam::DVec3;
use het_estimate::Coefficients;
use rayon::prelude::*;

pub(crate) mod factors;
mod paired_walks;

use self::factors::{
    DIRECTIONS, Directional, Grid, MU_NODES, PHI_NODES, Sample, ShapeCorrection, mu_weights,
};
use self::paired_walks::{Boundary, EscapeMedium, MAX_TRACKING_CONTRAST, TangentPlane, Walk};
use crate::field::MediumField;
use crate::geometry::{Geometry, Hit, ObjectSurface, Ray};
use crate::integrator::bssrdf::BssrdfObject;
use crate::integrator::counters::PathCounters;
use crate::integrator::preparation::PrepareObserver;
use crate::integrator::profile_eval::eval_profile;
use crate::optical_size::light_reach;
use crate::rng::Rng;
use crate::volume::orthonormal_basis;

/// Which random numbers a sample point draws: the correction's seed
/// (`Translucent::correction_seed`), combined with the object's index and the point's.
/// Every generator of the correction comes from here, so the keys are spelled once.
#[derive(Debug, Clone, Copy)]
struct PointKey {
    seed: u64,
    object: u64,
    index: u64,
}

impl PointKey {
    /// Stream of the walks ([`PointKey::rng`]); `k` packs the direction node and the walk.
    const WALKS: u64 = 1;
    /// Stream of the probe sets; the body's and the tangent plane's share it, so that their
    /// probes are paired (common random numbers).
    const PROBES: u64 = 2;

    /// The generator that places the point on the surface.
    fn placement(self) -> Rng {
        Rng::from_keys(self.seed, &[self.object, self.index])
    }

    /// The generator of draw `k` of `stream` ([`PointKey::WALKS`] or [`PointKey::PROBES`]).
    fn rng(self, stream: u64, k: u64) -> Rng {
        Rng::from_keys(self.seed, &[self.object, self.index, stream, k])
    }
}
/// Walks per sample point, channel and direction node.
pub const WALKS_PER_NODE: u32 = 12;
/// Probe sets per sample point for B.
pub const PROBES_PER_POINT: u32 = 128;
/// Radius, in diffusion lengths (or transport mean free paths, whichever is longer:
/// [`light_reach`]), of the half-ball below a point that, held by the body,
/// sets c = 1 there without walks: light that reaches it before leaving or being absorbed is
/// of order e^{−6} of the total.
const HALF_BALL: f64 = 6.0;
/// Fixed-point steps after the first estimate ([`Sums::refine`]).
const ITERATIONS: usize = 2;
/// Bounds on the number of sample points per object.
const MIN_POINTS: usize = 64;
const MAX_POINTS: usize = 4096;
/// Bounds on c: a point where the estimates are degenerate keeps c within them.
const C_RANGE: (f64, f64) = (0.05, 20.0);

/// The steps of a preparation that `observer` watches, and whether any was skipped because
/// it asked to stop (then the build returns nothing, even if the observer changed its mind).
struct Steps<'a> {
    observer: &'a dyn PrepareObserver,
    skipped: std::sync::atomic::AtomicBool,
}

impl<'a> Steps<'a> {
    fn new(observer: &'a dyn PrepareObserver) -> Self {
        Self {
            observer,
            skipped: false.into(),
        }
    }

    /// One step of the current stage: `None` (skipped) once the observer asks to stop, else
    /// `work()`, reported as done.
    fn step<T>(&self, work: impl FnOnce() -> T) -> Option<T> {
        if self.observer.stop_requested() {
            self.skipped
                .store(true, std::sync::atomic::Ordering::Relaxed);
            return None;
        }
        let done = work();
        self.observer.advance(1);
        Some(done)
    }

    /// True when a step was skipped.
    fn stopped(&self) -> bool {
        self.skipped.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// The direction outside the medium of node `(j, k)` about the unit normal `n`.
fn node_direction(n: DVec3, j: usize, k: usize) -> DVec3 {
    let (t, b) = orthonormal_basis(n);
    let mu = MU_NODES[j];
    let phi = TAU * k as f64 / PHI_NODES as f64;
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    (n * mu + (t * phi.cos() + b * phi.sin()) * s).normalize()
}

impl ShapeCorrection {
    /// Measures the correction for `object` rendered by `bssrdf` with `medium`.
    /// `seed` keys every random number it draws. In three stages: the raw sums at sample
    /// points ([`Build::measure`]), pooled over each point's neighbourhood ([`Build::pool`]),
    /// then the fixed-point steps ([`Build::refine`]).
    pub fn build(
        bssrdf: &BssrdfObject,
        geometry: &Geometry,
        object: u32,
        medium: &MediumField,
        seed: u64,
        observer: &dyn PrepareObserver,
    ) -> Option<Self> {
        let t0 = std::time::Instant::now();
        let mesh = geometry.mesh(object);
        let (lo, hi) = geometry.object_bounds(object);
        let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let h = sample_spacing(medium, bssrdf.family.g(), extent);
        let area = mesh.surface_area();
        let n_points = ((area / (h * h)).ceil() as usize).clamp(MIN_POINTS, MAX_POINTS);
        let build = Build {
            bssrdf,
            surface: ObjectSurface { geometry, object },
            medium,
            walk_medium: walk_medium(medium),
            seed,
            steps: Steps::new(observer),
        };
        // Progress: the walks at each point, then (a faster stage) each fixed-point step's
        // responses.
        observer.stage("correction walks", n_points as u64);
        let raw = build.measure(n_points, extent)?;
        let hits: Vec<Hit> = raw.iter().map(|(x, _, _)| *x).collect();
        let points: Vec<DVec3> = hits.iter().map(|x| x.p).collect();
        let grid = Grid::new(&points, h, lo, hi);
        let weights = incident_weights(bssrdf.eta());
        let pooled = Build::pool(&raw, &hits, &grid);
        let mut corr = Self {
            samples: hits
                .iter()
                .zip(&pooled)
                .map(|(x, s)| Sample {
                    p: x.p,
                    n: x.ns,
                    f: s.as_ref().map_or(Directional::ONE, |s| s.factor(&weights)),
                })
                .collect(),
            grid,
            vertices: None,
            seconds: 0.0,
        };
        observer.stage("correction steps", (raw.len() * ITERATIONS) as u64);
        for _ in 0..ITERATIONS {
            build.refine(&mut corr, &raw, &hits, &pooled, &weights)?;
        }
        corr.vertices = corr.vertex_factors(mesh);
        corr.seconds = t0.elapsed().as_secs_f64();
        Some(corr)
    }
}

/// The raw estimates at one sample point: the point, the medium's coefficients there, and its
/// sums, `None` where the body holds the half-ball below it (c = 1 without walks).
type RawPoint = (Hit, Coefficients, Option<Sums>);

/// What the stages of [`ShapeCorrection::build`] read: the object measured, its BSSRDF, its
/// medium and the one the walks go through ([`walk_medium`]), the seed of its random numbers
/// and the steps its observer watches.
struct Build<'a> {
    bssrdf: &'a BssrdfObject,
    surface: ObjectSurface<'a>,
    medium: &'a MediumField,
    walk_medium: Option<&'a MediumField>,
    seed: u64,
    steps: Steps<'a>,
}

impl Build<'_> {
    /// The random numbers of sample point `i` ([`PointKey`]).
    fn key(&self, i: usize) -> PointKey {
        PointKey {
            seed: self.seed,
            object: self.surface.object as u64,
            index: i as u64,
        }
    }

    /// `n_points` sample points drawn uniformly by area on the object (of bounding-box extent
    /// `extent`), with their raw sums; `None` when the observer stopped the build.
    fn measure(&self, n_points: usize, extent: f64) -> Option<Vec<RawPoint>> {
        let (geometry, object) = (self.surface.geometry, self.surface.object);
        let (bssrdf, medium, walk_medium) = (self.bssrdf, self.medium, self.walk_medium);
        let mesh = geometry.mesh(object);
        // Triangle CDF by area.
        let mut cdf = Vec::with_capacity(mesh.triangle_count());
        let mut acc = 0.0;
        for i in 0..mesh.triangle_count() {
            let [a, b, c] = mesh.triangle_vertices(i);
            acc += 0.5 * (b - a).cross(c - a).length();
            cdf.push(acc);
        }
        let grey = medium.is_grey();
        // Points whose body holds the half-ball of HALF_BALL diffusion lengths below them have
        // c = 1 (the walks and probes in the body and under the plane agree but for what
        // leaves that ball): no walks there (`None`).
        let raw: Vec<RawPoint> = (0..n_points)
            .into_par_iter()
            .filter_map(|i| {
                self.steps
                    .step(|| {
                        let mut rng = self.key(i).placement();
                        let x_o = sample_surface(geometry, object, &cdf, acc, extent, &mut rng)?;
                        let coeffs = medium.at_surface(x_o.p, x_o.uv);
                        // In a heterogeneous medium the light x_o sees may come from its most
                        // translucent parts.
                        let reach_of = if walk_medium.is_some() {
                            medium.field_bounds().min
                        } else {
                            coeffs
                        };
                        let reach = HALF_BALL * light_reach(reach_of, bssrdf.family.g()).0;
                        let sums = (!contains_half_ball(&self.surface, &x_o, reach)).then(|| {
                            let key = self.key(i);
                            point_sums(bssrdf, &self.surface, &x_o, coeffs, walk_medium, grey, key)
                        });
                        Some((x_o, coeffs, sums))
                    })
                    .flatten()
            })
            .collect();
        (!self.steps.stopped()).then_some(raw)
    }

    /// The raw sums of every point pooled over its neighbourhood in `grid` (built over the
    /// points `hits`) and regularised ([`Sums::regularised`]); `None` for the points without
    /// walks.
    fn pool(raw: &[RawPoint], hits: &[Hit], grid: &Grid) -> Vec<Option<Sums>> {
        // Pool the raw sums over each point's neighbourhood before dividing: a ratio of sums
        // over a few hundred walks, not a mean of per-point ratios over a few dozen (whose
        // bias, of order 1/(escapes per point), would not average out).
        (0..raw.len())
            .into_par_iter()
            .map(|i| {
                raw[i].2.as_ref()?;
                let mut pooled = Sums::default();
                grid.around(hits, i, |j, w| {
                    if let Some(sums) = &raw[j].2 {
                        pooled.add_scaled(sums, w);
                    }
                });
                Some(pooled.regularised())
            })
            .collect()
    }

    /// One fixed-point step of `corr` (module docs): where c varies on the scale of the
    /// profile (corners, edges), the incident side's factor differs from x_o's, so f ← √(f ·
    /// T / B'), B' the body's response with the current factors at the incident points, T what
    /// it should be. `raw` and `pooled` are the points' sums, `hits` the points (the grid's),
    /// `weights` the incident light's ([`incident_weights`]); `None` when the observer stopped
    /// the build.
    fn refine(
        &self,
        corr: &mut ShapeCorrection,
        raw: &[RawPoint],
        hits: &[Hit],
        pooled: &[Option<Sums>],
        weights: &[f64; DIRECTIONS],
    ) -> Option<()> {
        let response: Vec<Option<Rgb>> = raw
            .par_iter()
            .enumerate()
            .map(|(i, (x, coeffs, sums))| {
                self.steps
                    .step(|| {
                        sums.as_ref()?;
                        Some(body_response(
                            self.bssrdf,
                            &self.surface,
                            self.walk_medium,
                            x,
                            *coeffs,
                            self.key(i),
                            |x_i| corr.at(x_i.p, x_i.ns).incident_mean(weights),
                        ))
                    })
                    .flatten()
            })
            .collect();
        if self.steps.stopped() {
            return None;
        }
        let updated: Vec<Directional> = (0..raw.len())
            .into_par_iter()
            .map(|i| {
                let Some(p) = &pooled[i] else {
                    return Directional::ONE;
                };
                let mut b_prime = Rgb::ZERO;
                corr.grid.around(hits, i, |j, w| {
                    if let Some(r) = response[j] {
                        b_prime += r * w;
                    }
                });
                p.refine(&corr.samples[i].f, b_prime)
            })
            .collect();
        for (s, f) in corr.samples.iter_mut().zip(updated) {
            s.f = f;
        }
        Some(())
    }
}

/// Whether the body holds the half-ball of radius `reach` below the tangent plane at `x_o`, as
/// far as 37 rays from x_o into the body can tell (straight down, and 12 azimuths at each of
/// three depressions down to 1° below the tangent plane): none meets the surface within
/// `reach`. A polyhedral body whose faces, edges and corners stay farther than `reach` passes;
/// so would a feature that slips between the rays, which the ±1° fan makes narrow.
fn contains_half_ball(surface: &ObjectSurface<'_>, x_o: &Hit, reach: f64) -> bool {
    if !reach.is_finite() {
        return false;
    }
    let n = x_o.ns;
    let (t, b) = orthonormal_basis(n);
    let ray_clear = |d: DVec3| {
        surface
            .geometry
            .intersect_object(
                surface.object,
                &Ray::with_range(x_o.spawn_origin(d), d, 0.0, reach),
            )
            .is_none()
    };
    if !ray_clear(-n) {
        return false;
    }
    for depression in [0.017_f64, 0.3, 0.7] {
        let (sd, cd) = depression.sin_cos();
        for k in 0..12 {
            let phi = TAU * k as f64 / 12.0;
            let d = (t * phi.cos() + b * phi.sin()) * cd - n * sd;
            if !ray_clear(d) {
                return false;
            }
        }
    }
    true
}

/// The field the walks scatter in: the medium itself where it has values inside the body
/// (defined in space) and varies, and its σt stays within [`MAX_TRACKING_CONTRAST`] of its
/// majorant; `None` (x_o's coefficients) otherwise.
fn walk_medium(medium: &MediumField) -> Option<&MediumField> {
    let b = medium.field_bounds();
    let floor = b.min.sigma_a + b.min.sigma_s;
    let trackable = (0..3).all(|c| medium.majorant()[c] <= MAX_TRACKING_CONTRAST * floor[c]);
    (medium.is_volumetric() && !medium.is_constant() && trackable).then_some(medium)
}

/// The spacing h of the sample points: half the diffusion length 1/σtr (or transport mean
/// free path, whichever is longer) of the most translucent part of the medium (the scale on
/// which the profile, and so the correction, varies); when the walks scatter in a patterned
/// field, at most a quarter of its bands' or cells' width, since c then changes from cell to
/// cell (docs/shapes.md, "Heterogeneous bodies"); bounded to [extent/40, extent/4].
fn sample_spacing(medium: &MediumField, g: f64, extent: f64) -> f64 {
    let reach = 0.5 * light_reach(medium.field_bounds().min, g).0;
    let cells = match medium.pattern_width() {
        Some(w) if walk_medium(medium).is_some() => 0.25 * w,
        _ => f64::INFINITY,
    };
    reach.min(cells).clamp(extent / 40.0, extent / 4.0)
}

/// A point drawn uniformly by area on `object`'s mesh, as a hit (shading normal, texture
/// coordinates): found by a short ray onto the sampled point along −n_g.
fn sample_surface(
    geometry: &Geometry,
    object: u32,
    cdf: &[f64],
    total: f64,
    extent: f64,
    rng: &mut Rng,
) -> Option<Hit> {
    let u = rng.uniform() * total;
    let tri = cdf.partition_point(|&a| a <= u).min(cdf.len() - 1);
    let [a, b, c] = geometry.mesh(object).triangle_vertices(tri);
    let [u1, u2] = rng.uniform2();
    let su = u1.sqrt();
    let p = a * (1.0 - su) + b * (su * (1.0 - u2)) + c * (su * u2);
    let ng = (b - a).cross(c - a).normalize_or_zero();
    if ng == DVec3::ZERO {
        return None;
    }
    let eps = 1e-6 * extent.max(p.abs().max_element());
    geometry
        .intersect_object(object, &Ray::with_range(p + ng * eps, -ng, 0.0, 2.0 * eps))
        .filter(|h| h.prim as usize == tri || (h.p - p).length() < 4.0 * eps)
}

/// The raw estimates at one sample point x_o (see the module docs), the walks in `field` when
/// given (a heterogeneous medium defined in space), else in x_o's coefficients `coeffs`.
fn point_sums(
    bssrdf: &BssrdfObject,
    surface: &ObjectSurface<'_>,
    x_o: &Hit,
    coeffs: Coefficients,
    field: Option<&MediumField>,
    grey: bool,
    key: PointKey,
) -> Sums {
    let plane = TangentPlane {
        p0: x_o.p,
        n: x_o.ng,
        object: x_o.object,
    };
    // P: walks per exit cosine and channel (one channel for a grey medium).
    let mut p_body = [Rgb::ZERO; DIRECTIONS];
    let mut p_half = [Rgb::ZERO; DIRECTIONS];
    let channels = if grey { 1 } else { 3 };
    let eta = bssrdf.eta();
    for ch in 0..channels {
        let medium = match field {
            Some(field) => {
                let majorant = field.majorant()[ch];
                if !(majorant > 0.0 && majorant.is_finite()) {
                    continue;
                }
                EscapeMedium::Field { field, channel: ch }
            }
            None => {
                let sigma_t = coeffs.sigma_a[ch] + coeffs.sigma_s[ch];
                if !(sigma_t > 0.0 && sigma_t.is_finite()) {
                    continue;
                }
                EscapeMedium::Homogeneous {
                    sigma_t,
                    albedo: coeffs.sigma_s[ch] / sigma_t,
                }
            }
        };
        let walk = Walk {
            medium,
            g: bssrdf.family.g(),
            eta,
            orders: bssrdf.family.scattering(),
        };
        for j in 0..MU_NODES.len() {
            for k in 0..PHI_NODES {
                let d = j * PHI_NODES + k;
                let w_o = node_direction(x_o.ns, j, k);
                for m in 0..WALKS_PER_NODE as u64 {
                    let draw = (d as u64) << 32 | m;
                    let mut rb = key.rng(PointKey::WALKS, draw);
                    let mut rh = key.rng(PointKey::WALKS, draw);
                    p_body[d][ch] += walk.escape(&Boundary::Body(surface), x_o, w_o, &mut rb);
                    p_half[d][ch] += walk.escape(&Boundary::Plane(&plane), x_o, w_o, &mut rh);
                }
            }
        }
    }
    if grey {
        for d in 0..DIRECTIONS {
            p_body[d] = Rgb::splat(p_body[d][0]);
            p_half[d] = Rgb::splat(p_half[d][0]);
        }
    }
    // B: probes, all channels at once; in a heterogeneous medium the walks go through, each
    // pair weighed at the estimator's coefficients for it, on the body and on the plane (the
    // half-space below it holds the same field), as the render weighs it.
    let b_body = body_response(bssrdf, surface, field, x_o, coeffs, key, |_| Rgb::ONE);
    let mut b_half = Rgb::ZERO;
    let mut counters = PathCounters::default();
    for k in 0..PROBES_PER_POINT as u64 {
        let mut rng = key.rng(PointKey::PROBES, k);
        for hit in bssrdf.probe_set(&plane, x_o, coeffs, &mut rng).iter() {
            let r = (hit.hit.p - x_o.p).length();
            let c = match field {
                Some(field) => {
                    let mut own = Rng::from_keys(rng.next_u64(), &[]);
                    let est = bssrdf
                        .estimator
                        .estimate(&plane, field, &hit.hit, x_o, &mut own);
                    counters.record_estimate(&est.diagnostics);
                    est.coefficients
                }
                None => coeffs,
            };
            b_half += eval_profile(&bssrdf.family, c, r, &mut counters) * hit.weight;
        }
    }
    Sums {
        p_body,
        p_half,
        b_body,
        b_half,
    }
}

/// The raw estimates at one point (or pooled over a neighbourhood): walk escapes P per exit
/// cosine and channel in the body and under the tangent plane, and probe sums B.
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    p_body: [Rgb; DIRECTIONS],
    p_half: [Rgb; DIRECTIONS],
    b_body: Rgb,
    b_half: Rgb,
}

impl Sums {
    /// The sums with the symmetries the estimates must have imposed, and the azimuthal
    /// dependence kept to its first harmonic, which lowers their noise: under the tangent plane
    /// P does not depend on the azimuth (its nodes are averaged), at μ = 1 every azimuth node
    /// is the same direction (averaged too), and elsewhere P_body(μ, ·) is projected on
    /// {1, cos φ, sin φ}.
    fn regularised(&self) -> Sums {
        let mut out = *self;
        let k_n = PHI_NODES as f64;
        for j in 0..MU_NODES.len() {
            let row = j * PHI_NODES..(j + 1) * PHI_NODES;
            let mut half = Rgb::ZERO;
            let (mut a0, mut a1, mut b1) = (Rgb::ZERO, Rgb::ZERO, Rgb::ZERO);
            for (k, d) in row.clone().enumerate() {
                let phi = TAU * k as f64 / k_n;
                half += self.p_half[d] * (1.0 / k_n);
                a0 += self.p_body[d] * (1.0 / k_n);
                a1 += self.p_body[d] * (2.0 * phi.cos() / k_n);
                b1 += self.p_body[d] * (2.0 * phi.sin() / k_n);
            }
            let symmetric = j + 1 == MU_NODES.len();
            for (k, d) in row.enumerate() {
                let phi = TAU * k as f64 / k_n;
                out.p_half[d] = half;
                out.p_body[d] = if symmetric {
                    a0
                } else {
                    a0 + a1 * phi.cos() + b1 * phi.sin()
                };
            }
        }
        out
    }

    fn add_scaled(&mut self, o: &Sums, w: f64) {
        for j in 0..DIRECTIONS {
            self.p_body[j] += o.p_body[j] * w;
            self.p_half[j] += o.p_half[j] * w;
        }
        self.b_body += o.b_body * w;
        self.b_half += o.b_half * w;
    }

    /// P_body/P_half at direction node `d` and channel `ch`.
    fn p_ratio(&self, d: usize, ch: usize) -> Option<f64> {
        let (pb, ph) = (self.p_body[d][ch], self.p_half[d][ch]);
        (ph > 0.0).then(|| pb / ph)
    }

    /// c(ω_d) = (P_body/P_half)/(B_body/B_half) per channel, then f = c / √c̄ with c̄ the mean
    /// of c over incident light as the BSSRDF gathers it at x_i (`weights`:
    /// [`incident_weights`]); 1 in a channel where an estimate is empty.
    fn factor(&self, weights: &[f64; DIRECTIONS]) -> Directional {
        let mut out = Directional::ONE;
        for ch in 0..3 {
            let (bb, bh) = (self.b_body[ch], self.b_half[ch]);
            if !(bb > 0.0 && bh > 0.0) {
                continue;
            }
            let mut c = Directional::ONE;
            let mut ok = true;
            for j in 0..DIRECTIONS {
                match self.p_ratio(j, ch).map(|r| r / (bb / bh)) {
                    Some(v) if v.is_finite() => c.0[j][ch] = v.clamp(C_RANGE.0, C_RANGE.1),
                    _ => ok = false,
                }
            }
            if !ok {
                continue;
            }
            let mean = c.incident_mean(weights)[ch];
            for j in 0..DIRECTIONS {
                out.0[j][ch] = c.0[j][ch] / mean.sqrt();
            }
        }
        out
    }

    /// One fixed-point step: with B' the body's response to uniform light under the current
    /// factors at the incident points (pooled like these sums), the factor that would make the
    /// response right is f* = T/B', T(μ) = B_half·P_body(μ)/P_half(μ); the step returns
    /// √(f·f*), which reaches f* at once when f is off by a constant factor.
    fn refine(&self, f: &Directional, b_prime: Rgb) -> Directional {
        let mut out = *f;
        for ch in 0..3 {
            if !(b_prime[ch] > 0.0 && self.b_half[ch] > 0.0) {
                continue;
            }
            for j in 0..DIRECTIONS {
                let Some(r) = self.p_ratio(j, ch) else {
                    continue;
                };
                let target = self.b_half[ch] * r / b_prime[ch];
                if target.is_finite() && target > 0.0 {
                    out.0[j][ch] = (f.0[j][ch] * target).sqrt().clamp(C_RANGE.0, C_RANGE.1);
                }
            }
        }
        out
    }
}

/// Σ over [`PROBES_PER_POINT`] probe sets around x_o on the body of R(x_i, x_o)·g(x_i)/p(x_i)
/// (per channel): B_body for g = 1, the body's response to uniform light with the incident
/// factors of the current correction for g = ⟨f(x_i)⟩. R at x_o's coefficients `coeffs`, or,
/// for a heterogeneous `field` (the one the walks go through), at the estimator's coefficients
/// for each pair, as the render weighs it. The same probes for every g (and as the tangent
/// plane's, common random numbers).
fn body_response(
    bssrdf: &BssrdfObject,
    surface: &ObjectSurface<'_>,
    field: Option<&MediumField>,
    x_o: &Hit,
    coeffs: Coefficients,
    key: PointKey,
    g: impl Fn(&Hit) -> Rgb,
) -> Rgb {
    let mut sum = Rgb::ZERO;
    let mut counters = PathCounters::default();
    for k in 0..PROBES_PER_POINT as u64 {
        let mut rng = key.rng(PointKey::PROBES, k);
        for hit in bssrdf.probe_set(surface, x_o, coeffs, &mut rng).iter() {
            let r = match field {
                Some(field) => {
                    bssrdf
                        .profile(surface, field, &hit.hit, x_o, &mut rng, &mut counters)
                        .rd
                }
                None => {
                    bssrdf
                        .weigh(surface, coeffs, &hit.hit, x_o, &mut counters)
                        .0
                }
            };
            sum += r * g(&hit.hit) * hit.weight;
        }
    }
    sum
}

/// Weights W_d with ⟨f⟩ = Σ_d W_d f(ω_d) for f interpolated between the direction nodes as
/// [`Directional::at`] does: the mean of f over the light a BSSRDF's incident point gathers
/// from a uniform sky, ∫ (1 − F(μ)) μ f dω / ∫ (1 − F(μ)) μ dω (midpoint rule in μ, 256
/// intervals; the azimuthal mean of the periodic-linear interpolant is that of its nodes).
fn incident_weights(eta: f64) -> [f64; DIRECTIONS] {
    let n = 256;
    let mut weights = [0.0; DIRECTIONS];
    let mut den = 0.0;
    for k in 0..n {
        let mu = (k as f64 + 0.5) / n as f64;
        let w = (1.0 - bssrdf_core::fresnel::dielectric(mu, eta)) * mu;
        den += w;
        for (j, hat) in mu_weights(mu) {
            for a in 0..PHI_NODES {
                weights[j * PHI_NODES + a] += w * hat / PHI_NODES as f64;
            }
        }
    }
    weights.map(|w| w / den)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{TriangleMesh, primitives};
    use crate::integrator::bssrdf::PairEnd;
    use crate::render::NoObserver;
    use crate::scene::Translucent;
    use bssrdf_core::ProfileModel;
    use bssrdf_core::Scattering;
    use std::sync::atomic::{AtomicU64, Ordering::SeqCst};

    /// The seed of the materials built here ([`Translucent::new`]'s).
    const SEED: u64 = Translucent::DEFAULT_CORRECTION_SEED;

    fn corrected(mesh: TriangleMesh, albedo: f64, eta: f64) -> (Geometry, BssrdfObject) {
        let field = MediumField::homogeneous(Coefficients::grey(1.0 - albedo, albedo)).unwrap();
        corrected_in(mesh, field, eta)
    }

    fn corrected_in(mesh: TriangleMesh, field: MediumField, eta: f64) -> (Geometry, BssrdfObject) {
        let geometry = Geometry::build(vec![mesh]);
        let t = Translucent::new("m", field.clone(), 0.0, eta);
        let (lo, hi) = geometry.object_bounds(0);
        let mut b = BssrdfObject::new(
            &t,
            Some(ProfileModel::Tabulated),
            Scattering::Multiple,
            "jensen-out".parse().unwrap(),
            (hi - lo).max_element(),
        )
        .unwrap();
        b.correction = Some(
            ShapeCorrection::build(&b, &geometry, 0, &field, t.correction_seed, &NoObserver)
                .expect("not stopped"),
        );
        (geometry, b)
    }

    /// Counts a preparation's steps, and asks it to stop once `stop_after` are done, or only
    /// at its `blink`-th poll (an observer that changes its mind).
    struct Watcher {
        units: AtomicU64,
        done: AtomicU64,
        polls: AtomicU64,
        stop_after: u64,
        blink: u64,
    }

    impl Watcher {
        fn stopping_after(stop_after: u64) -> Self {
            Self {
                units: 0.into(),
                done: 0.into(),
                polls: 0.into(),
                stop_after,
                blink: u64::MAX,
            }
        }
        fn blinking_at(blink: u64) -> Self {
            Self {
                blink,
                ..Self::stopping_after(u64::MAX)
            }
        }
        fn counts(&self) -> (u64, u64) {
            (self.units.load(SeqCst), self.done.load(SeqCst))
        }
    }

    impl PrepareObserver for Watcher {
        fn stage(&self, _: &str, units: u64) {
            self.units.fetch_add(units, SeqCst);
        }
        fn advance(&self, units: u64) {
            self.done.fetch_add(units, SeqCst);
        }
        fn stop_requested(&self) -> bool {
            self.polls.fetch_add(1, SeqCst) == self.blink || self.counts().1 >= self.stop_after
        }
    }

    /// The build reports every step it announces and gives the same correction whoever
    /// watches; asked to stop, it returns none, long before its walks are done (at most one
    /// step in flight per thread after the request), and so it does when the observer asks
    /// once and then no more: a correction from some of its points is never returned.
    #[test]
    fn the_build_reports_its_steps_and_stops_when_asked() {
        let field = MediumField::homogeneous(Coefficients::grey(0.1, 0.9)).unwrap();
        let (geometry, b) = corrected_in(
            primitives::icosphere(DVec3::ZERO, 1.0, 2),
            field.clone(),
            1.3,
        );
        let plain = b.correction.as_ref().unwrap();
        let watcher = Watcher::stopping_after(u64::MAX);
        let watched = ShapeCorrection::build(&b, &geometry, 0, &field, SEED, &watcher).unwrap();
        let (units, done) = watcher.counts();
        // Every point's walks, then every point found at each fixed-point step.
        assert_eq!(units, (plain.samples.len() * (1 + ITERATIONS)) as u64);
        assert_eq!(done, units);
        assert!(
            plain
                .samples
                .iter()
                .zip(&watched.samples)
                .all(|(a, b)| a.f == b.f)
        );
        assert_eq!(plain.samples.len(), watched.samples.len());
        // Another seed draws other points and walks: another estimate of the same thing.
        let reseeded = ShapeCorrection::build(&b, &geometry, 0, &field, 7, &NoObserver).unwrap();
        assert!(
            plain
                .samples
                .iter()
                .zip(&reseeded.samples)
                .any(|(a, b)| a.f != b.f),
            "the seed changed no factor"
        );

        let stopping = Watcher::stopping_after(5);
        assert!(ShapeCorrection::build(&b, &geometry, 0, &field, SEED, &stopping).is_none());
        let (units, done) = stopping.counts();
        let threads = rayon::current_num_threads() as u64;
        assert!(
            done >= 5 && done <= 5 + threads,
            "{done} steps done of {units}"
        );
        // Once in the walks, once in the fixed-point steps (each step polls once).
        for blink in [10, plain.samples.len() as u64 + 5] {
            let blinking = Watcher::blinking_at(blink);
            assert!(
                ShapeCorrection::build(&b, &geometry, 0, &field, SEED, &blinking).is_none(),
                "poll {blink}"
            );
        }
    }

    fn hit_from_above(geometry: &Geometry, p: DVec3, n: DVec3) -> Hit {
        geometry
            .intersect_object(0, &Ray::new(p + 3.0 * n, -n))
            .unwrap()
    }

    /// Far from the edges of a box 8 mfp deep (4.4 diffusion lengths at ϖ 0.9) the body is a
    /// half-space and c = 1 whatever the profile's own error: the walks and probes in the
    /// body and under the tangent plane must measure the same thing (start, Fresnel at η 1.3,
    /// orders counted, probe radii). The mean of f over its 30 direction nodes within 2.5 %
    /// and every node within 10 % (the pooled estimate's noise is about 2.5 % per node here).
    #[test]
    fn the_correction_is_one_on_a_half_space() {
        let mesh = primitives::subdivided_cuboid(
            DVec3::new(-8.0, -8.0, -8.0),
            DVec3::new(8.0, 8.0, 0.0),
            [8, 8, 4],
        );
        let (geometry, b) = corrected(mesh, 0.9, 1.3);
        let c = b.correction.as_ref().unwrap();
        let f = c.at(hit_from_above(&geometry, DVec3::ZERO, DVec3::Z).p, DVec3::Z);
        let values: Vec<f64> = f.0.iter().map(|v| v[0]).collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        assert!((mean - 1.0).abs() < 0.025, "mean f {mean}: {values:?}");
        for (d, v) in values.iter().enumerate() {
            let (j, k) = (d / PHI_NODES, d % PHI_NODES);
            assert!(
                (v - 1.0).abs() < 0.1,
                "f(μ = {}, azimuth node {k}) = {v}: {values:?}",
                MU_NODES[j],
            );
        }
    }

    /// Grey checks constant along x, of side `width`, with σa `sigma_a[0]` in the cell
    /// around the origin and `sigma_a[1]` in its neighbours, σs everywhere.
    fn checks(width: f64, sigma_a: [f64; 2], sigma_s: f64) -> MediumField {
        use crate::field::{Axis, Field, PlanarProjection};
        let projection = PlanarProjection::new(Axis::X, DVec3::ZERO);
        let values = sigma_a.map(Rgb::splat);
        let field = MediumField::new(
            Field::check(width, values, projection).unwrap(),
            Field::constant(Rgb::splat(sigma_s)).unwrap(),
        );
        assert_eq!(field.at_point(DVec3::ZERO).sigma_a[0], sigma_a[0]);
        field
    }

    /// The mean and standard error of `n` escapes from the origin of the half-space z < 0
    /// (η 1, g 0, all orders), leaving along `w_o`, in `medium`.
    fn escapes(medium: EscapeMedium<'_>, w_o: DVec3, n: u64) -> (f64, f64) {
        let plane = TangentPlane {
            p0: DVec3::ZERO,
            n: DVec3::Z,
            object: 0,
        };
        let x_o = plane.hit(0.0, DVec3::ZERO);
        let walk = Walk {
            medium,
            g: 0.0,
            eta: 1.0,
            orders: Scattering::All,
        };
        let (mut sum, mut sum2) = (0.0, 0.0);
        for i in 0..n {
            let mut rng = Rng::from_keys(7, &[i]);
            let e = walk.escape(&Boundary::Plane(&plane), &x_o, w_o, &mut rng);
            sum += e;
            sum2 += e * e;
        }
        let mean = sum / n as f64;
        let var = (sum2 / n as f64 - mean * mean).max(0.0);
        (mean, (var / (n - 1) as f64).sqrt())
    }

    /// Tracked through a field whose majorant is four times the σt around the walk (three
    /// tentative collisions in four are null), a walk escapes a half-space at η = 1 with
    /// Chandrasekhar's plane albedo A(ϖ, μ0) = 1 − H(μ0)√(1 − ϖ) (docs/physics.md, "Half-space":
    /// ϖ 0.9, A(0.9, 1) = 0.41494748, A(0.9, 0.5) = 0.507939), and so does the homogeneous
    /// walk: 30,000 walks each, within 4 standard errors. The cells are 10,000 wide, so the
    /// walks stay in the one around the origin.
    #[test]
    fn tracked_walks_meet_chandrasekhar_with_null_collisions() {
        let field = checks(1e4, [0.1, 3.1], 0.9);
        assert_eq!(field.majorant()[0], 4.0);
        for (mu, albedo) in [(1.0_f64, 0.41494748), (0.5, 0.507939)] {
            let w_o = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let media = [
                EscapeMedium::Field {
                    field: &field,
                    channel: 0,
                },
                EscapeMedium::Homogeneous {
                    sigma_t: 1.0,
                    albedo: 0.9,
                },
            ];
            for medium in media {
                let (mean, se) = escapes(medium, w_o, 30_000);
                assert!(
                    (mean - albedo).abs() < 4.0 * se,
                    "μ0 {mu}: {mean} ± {se} against {albedo}"
                );
            }
        }
    }

    /// The walks scatter in the medium below the surface, not in the coefficients at x_o: under
    /// a clear cell 0.05 deep (σa 0, σs 1) lie cells with σa 1000. In the coefficients at
    /// x_o (ϖ = 1, η = 1) every walk leaves again (A = 1); in the field a walk leaves only if
    /// it scatters within the clear cell, with probability at most 1 − e^{−0.05} = 0.049
    /// (the absorbing cells send back less than 0.1 % of what enters them).
    #[test]
    fn tracked_walks_see_the_medium_below_the_surface() {
        let field = checks(0.1, [0.0, 1000.0], 1.0);
        let field_walks = EscapeMedium::Field {
            field: &field,
            channel: 0,
        };
        let (mean, se) = escapes(field_walks, DVec3::Z, 4000);
        assert!(mean < 0.049 + 4.0 * se, "{mean} ± {se}");
        let local = EscapeMedium::Homogeneous {
            sigma_t: 1.0,
            albedo: 1.0,
        };
        let (mean, se) = escapes(local, DVec3::Z, 1000);
        assert!(mean > 0.95, "{mean} ± {se}");
    }

    /// The walks scatter in a varying field defined in space, unless its σt spans more than
    /// [`MAX_TRACKING_CONTRAST`], and the points are a quarter of its cells' width apart; a
    /// uniform medium keeps half its diffusion length (here 1/√(3 · 0.01 · 6.01) / 2 = 1.18).
    #[test]
    fn patterned_media_are_walked_in_and_sampled_by_their_cells() {
        let patterned = checks(2.0, [0.01, 0.6], 6.0);
        assert!(walk_medium(&patterned).is_some());
        assert_eq!(sample_spacing(&patterned, 0.0, 8.0), 0.5);
        let uniform = checks(2.0, [0.01, 0.01], 6.0);
        assert!(walk_medium(&uniform).is_none());
        // σt from 1e-6 to 1e6: tracking would take 1e12 tentative collisions per real one.
        assert!(walk_medium(&checks(2.0, [0.0, 1e6], 1e-6)).is_none());
        assert!(walk_medium(&checks(2.0, [0.0, 99.0], 1.0)).is_some());
        let h = sample_spacing(&uniform, 0.0, 8.0);
        assert!((h - 1.1777).abs() < 1e-3, "{h}");
    }

    /// Common random numbers survive tracking: in a slab 3 deep and 100 wide, a walk that never
    /// meets the slab's bottom or sides takes the same steps as its twin under the tangent
    /// plane, although each flight toward the bottom ratio-tracks a different distance than
    /// the plane's (which has no boundary there), so that the two walks draw different numbers
    /// of tentative collisions. With per-step generators 1170 of 2000 twin walks (in checks
    /// 4 wide, σs 0.99, σa 0.01 and 0.5) agree to 1e-9; with one stream per walk, 373, most
    /// put out of step at their first downward flight. The test asks for half.
    #[test]
    fn tracked_twin_walks_stay_in_step() {
        let geometry = Geometry::build(vec![primitives::subdivided_cuboid(
            DVec3::new(-50.0, -50.0, -3.0),
            DVec3::new(50.0, 50.0, 0.0),
            [2, 2, 2],
        )]);
        let surface = ObjectSurface {
            geometry: &geometry,
            object: 0,
        };
        let x_o = hit_from_above(&geometry, DVec3::ZERO, DVec3::Z);
        let plane = TangentPlane {
            p0: x_o.p,
            n: x_o.ng,
            object: 0,
        };
        let field = checks(4.0, [0.01, 0.5], 0.99);
        let walk = Walk {
            medium: EscapeMedium::Field {
                field: &field,
                channel: 0,
            },
            g: 0.0,
            eta: 1.3,
            orders: Scattering::All,
        };
        let mut same = 0;
        for i in 0..2000 {
            let mut rb = Rng::from_keys(3, &[i]);
            let mut rp = Rng::from_keys(3, &[i]);
            let body = walk.escape(&Boundary::Body(&surface), &x_o, DVec3::Z, &mut rb);
            let half = walk.escape(&Boundary::Plane(&plane), &x_o, DVec3::Z, &mut rp);
            if (body - half).abs() <= 1e-9 * half.abs().max(1e-3) {
                same += 1;
            }
        }
        assert!(same >= 1000, "{same} of 2000 twins agree");
    }

    /// The early out: the centre of a large box face holds the half-ball, a point 2 from an
    /// edge does not (reach 5), nor does a point on a sphere of radius 10, nor a thin slab.
    #[test]
    fn the_half_ball_test_passes_flat_interiors_only() {
        let big = Geometry::build(vec![primitives::subdivided_cuboid(
            DVec3::new(-50.0, -50.0, -50.0),
            DVec3::new(50.0, 50.0, 0.0),
            [4, 4, 4],
        )]);
        let surface = ObjectSurface {
            geometry: &big,
            object: 0,
        };
        let centre = hit_from_above(&big, DVec3::new(0.3, 0.1, 0.0), DVec3::Z);
        assert!(contains_half_ball(&surface, &centre, 5.0));
        let near_edge = hit_from_above(&big, DVec3::new(48.0, 0.1, 0.0), DVec3::Z);
        assert!(!contains_half_ball(&surface, &near_edge, 5.0));
        assert!(!contains_half_ball(&surface, &centre, f64::INFINITY));
        let sphere = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, 10.0, 4)]);
        let on_sphere = hit_from_above(&sphere, DVec3::new(0.0, 0.0, 10.0), DVec3::Z);
        let surface = ObjectSurface {
            geometry: &sphere,
            object: 0,
        };
        assert!(!contains_half_ball(&surface, &on_sphere, 5.0));
        let slab = Geometry::build(vec![primitives::subdivided_cuboid(
            DVec3::new(-50.0, -50.0, -2.0),
            DVec3::new(50.0, 50.0, 0.0),
            [4, 4, 1],
        )]);
        let top = hit_from_above(&slab, DVec3::new(0.3, 0.1, 0.0), DVec3::Z);
        let surface = ObjectSurface {
            geometry: &slab,
            object: 0,
        };
        assert!(!contains_half_ball(&surface, &top, 5.0));
    }

    /// Stiff and extreme media build a finite, positive correction: no absorption (walks end
    /// only by leaving), no scattering, an optically huge and an optically tiny body, a
    /// refractive boundary with total internal reflection, g near ±1.
    #[test]
    fn extreme_media_give_finite_positive_factors() {
        let cases = [
            (Coefficients::grey(0.0, 1.0), 0.0, 1.3),
            (Coefficients::grey(1.0, 0.0), 0.0, 1.0),
            (Coefficients::grey(5e5, 5e5), 0.0, 3.0),
            (Coefficients::grey(1e-7, 1e-6), 0.0, 1.0),
            (Coefficients::grey(0.01, 2.0), 0.95, 1.5),
            (Coefficients::grey(0.01, 2.0), -0.95, 1.0),
        ];
        for (c, g, eta) in cases {
            let geometry = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, 1.0, 2)]);
            let field = MediumField::homogeneous(c).unwrap();
            let t = Translucent::new("m", field.clone(), g, eta);
            let (lo, hi) = geometry.object_bounds(0);
            // The tabulated profile stops at η 1.6; the dipole takes η 3.
            let profile = if eta > 1.6 {
                ProfileModel::Dipole
            } else {
                ProfileModel::Tabulated
            };
            let mut b = BssrdfObject::new(
                &t,
                Some(profile),
                Scattering::Multiple,
                "jensen-out".parse().unwrap(),
                (hi - lo).max_element(),
            )
            .unwrap();
            let corr =
                ShapeCorrection::build(&b, &geometry, 0, &field, t.correction_seed, &NoObserver)
                    .expect("not stopped");
            let x = hit_from_above(
                &geometry,
                DVec3::ZERO,
                DVec3::new(0.2, 0.3, 1.0).normalize(),
            );
            let f = corr.at_hit(&x);
            for v in f.0 {
                for ch in 0..3 {
                    assert!(
                        v[ch].is_finite() && v[ch] > 0.0,
                        "{c:?} g {g} eta {eta}: {v:?}"
                    );
                }
            }
            b.correction = Some(corr);
            let s = b.eval(
                &ObjectSurface {
                    geometry: &geometry,
                    object: 0,
                },
                &field,
                PairEnd { hit: &x, w: x.ns },
                PairEnd { hit: &x, w: x.ns },
                &mut Rng::from_keys(1, &[]),
                &mut PathCounters::default(),
            );
            assert!((0..3).all(|ch| s[ch].is_finite()), "{c:?}: S = {s:?}");
        }
    }

    /// The correction keeps S reciprocal bit for bit (the two factors are multiplied before
    /// they meet S), and it is not vacuous: on a sphere of radius 1 mfp it changes S.
    #[test]
    fn the_corrected_bssrdf_is_reciprocal_and_differs_from_the_uncorrected_one() {
        let (geometry, mut b) = corrected(primitives::icosphere(DVec3::ZERO, 1.0, 3), 0.9, 1.3);
        let surface = ObjectSurface {
            geometry: &geometry,
            object: 0,
        };
        let field = MediumField::homogeneous(Coefficients::grey(0.1, 0.9)).unwrap();
        let x_i = hit_from_above(
            &geometry,
            DVec3::ZERO,
            DVec3::new(0.3, 0.1, 1.0).normalize(),
        );
        let x_o = hit_from_above(
            &geometry,
            DVec3::ZERO,
            DVec3::new(-0.5, 0.4, 0.6).normalize(),
        );
        let w_i = (x_i.ns + DVec3::new(0.4, -0.2, 0.0)).normalize();
        let w_o = (x_o.ns + DVec3::new(0.0, 0.7, 0.1)).normalize();
        let mut counters = PathCounters::default();
        let mut eval = |b: &BssrdfObject, a: &Hit, wa, c: &Hit, wc| {
            let mut rng = Rng::from_keys(1, &[]);
            let (incident, exitant) = (PairEnd { hit: a, w: wa }, PairEnd { hit: c, w: wc });
            b.eval(&surface, &field, incident, exitant, &mut rng, &mut counters)
        };
        let s = eval(&b, &x_i, w_i, &x_o, w_o);
        let swapped = eval(&b, &x_o, w_o, &x_i, w_i);
        assert_eq!(s, swapped);
        let correction = b.correction.take();
        let plain = eval(&b, &x_i, w_i, &x_o, w_o);
        assert!(correction.is_some());
        assert!(
            (s[0] / plain[0] - 1.0).abs() > 0.2,
            "corrected {} against {}",
            s[0],
            plain[0]
        );
    }
}
