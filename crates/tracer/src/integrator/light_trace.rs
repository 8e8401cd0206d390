//! A light tracer for the BSSRDF methods: the adjoint of the camera-traced BSSRDF render
//! ([`super::path`]), for checking that the two agree (reciprocity, docs/reciprocity.md).
//!
//! Each light path:
//! 1. picks a light uniformly and samples an emitted ray from it (below);
//! 2. traces it to the first surface; if that is a translucent object rendered with a BSSRDF
//!    and the ray arrives from outside, the hit is the incident point x_i (anything else ends
//!    the path: opaque objects absorb);
//! 3. samples exitant points x_o around x_i with the renderer's probe rays, now centred on
//!    x_i (`het_estimate::probe`, the same sampler and density as the camera tracer's search
//!    for x_i around x_o);
//! 4. connects every x_o to the camera ([`crate::camera::Camera::connect`]: the pinhole's
//!    importance W_e, pbrt3 §16.1.1, pbrt-v4's `PerspectiveCamera::We`, or the orthographic pixel
//!    whose ray reaches x_o, with the cos/area Jacobian), checks visibility, evaluates the
//!    BSSRDF S(x_i, ω_i; x_o, ω_o) with the estimator in its physical roles (x_i is where the
//!    light enters; `integrator/bssrdf.rs`) and splats the contribution into that pixel.
//!
//! Path weight: a light path starting with flux weight Φ (below) reaching x_i with geometric
//! cosine cos_g and shading-side cosine cos_s (the normal rule of S) carries
//! Φ · cos_s / cos_g (the projected solid angle of the camera tracer's irradiance integral is
//! measured against the shading normal: the adjoint's shading-normal correction, Vea97 §5.3),
//! and adds
//! Φ · (cos_s/cos_g) · S · (1/p(x_o)) · W_e · cos_o to the pixel, p the probe density and
//! W_e cos_o the camera importance at x_o.
//!
//! Emitters ([`LightTraceError::UnsupportedLight`] for the rest):
//! * quad: a uniform point, a cosine-distributed direction, Φ = L_e · A · π;
//! * point: a uniform direction, Φ = I · 4π;
//! * directional (bounded scene): a uniform point on the disk, perpendicular to the light,
//!   that covers the bounding sphere of the BSSRDF objects, Φ = E · π R²;
//! * environment (bounded scene): a direction ω toward the sky drawn as next-event estimation
//!   draws it (uniform for a constant environment, in proportion to an image,
//!   [`crate::light::EnvironmentMap`]), the ray travelling along −ω from a point on the disk
//!   as for directional light, Φ = L(ω) / p(ω) · π R² (L · 4π · π R² for a constant one).
//!
//! Beams are refused (the camera tracer does not see them). The light tracer renders only
//! light that leaves a light, enters a translucent object once and leaves it toward the
//! camera: no emitters seen directly, no Fresnel (specular) reflections, no light that enters
//! a BSSRDF object a second time. Scenes with diffuse surfaces are refused
//! ([`LightTraceError::DiffuseSurface`]), since their light would be missing.
//!
//! Determinism: light path `k` draws from its own stream (`seed`, k), paths are traced in
//! chunks of fixed size, each chunk records its splats in path order, and the chunks' splats
//! are added to the film in chunk order, so the image is bit-identical whatever the thread
//! count.

use std::f64::consts::PI;
use std::time::Instant;

use bssrdf_core::Rgb;
use glam::DVec3;
use rayon::prelude::*;

use crate::film::Film;
use crate::geometry::{Hit, ObjectSurface, Ray, offset_ray_origin};
use crate::integrator::bssrdf::{PairEnd, facing_normal};
use crate::integrator::counters::PathCounters;
use crate::integrator::{Method, PathIntegrator, PathOptions, RenderError};
use crate::light::{Light, uniform_sphere};
use crate::render::Counters;
use crate::rng::Rng;
use crate::scene::{Material, Scene};
use crate::volume::direction_about;

/// Light paths per chunk (the unit of parallel work; fixed, so the result does not depend on
/// the thread count).
const CHUNK: u64 = 4096;
/// Chunks traced in parallel before their splats are added to the film.
const BATCH: u64 = 64;
/// First key of every light path's random stream (camera samples use 1).
const STREAM_KEY: u64 = 0x11c7;

/// Which point of a pair the estimator is told is the incident one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Roles {
    /// x_i is where the light enters (the physical roles; the default).
    #[default]
    Physical,
    /// The roles swapped: the estimator is asked for (x_o, x_i). Wrong for a non-reciprocal
    /// estimator (`jensen-in`, `jensen-out`); exists to show that (docs/reciprocity.md).
    Swapped,
}

/// Why a light-traced render cannot start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LightTraceError {
    /// The method is the path tracer.
    #[error("the light tracer renders BSSRDF methods only, not `pt`")]
    NotBssrdf,
    /// A light the light tracer cannot emit from.
    #[error(
        "light {index} is a {kind} light: the light tracer emits from quad, point, directional \
         and environment lights"
    )]
    UnsupportedLight {
        /// Its index in the scene's lights.
        index: usize,
        /// Its kind.
        kind: &'static str,
    },
    /// A diffuse object, whose reflected light the light tracer does not follow.
    #[error(
        "object `{object}` is diffuse: the light tracer follows light from a light into a \
         translucent object and out to the camera only, so the light it reflects would be \
         missing"
    )]
    DiffuseSurface {
        /// The object's name.
        object: String,
    },
    /// Preparing the BSSRDF failed.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// Options of [`LightTracer::render`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightTraceOptions {
    /// Light paths traced in all.
    pub paths: u64,
    /// Seed of every path's random stream.
    pub seed: u64,
}

/// A light-traced image.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct LightTraced {
    /// The image: mean radiance per pixel, as a camera-traced render's.
    pub film: Film,
    /// Light paths traced.
    pub paths: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Counters (`paths` counts light paths).
    pub counters: PathCounters,
}

/// An emitter, with what sampling it needs.
#[derive(Debug, Clone, Copy)]
enum Emitter<'s> {
    Quad(crate::light::QuadLight),
    Point(crate::light::PointLight),
    /// Parallel light from infinity, travelling along `direction`.
    Directional {
        direction: DVec3,
        irradiance: Rgb,
    },
    /// Light from every direction at infinity.
    Environment(&'s crate::light::EnvironmentLight),
}

/// The disk that a light from infinity is emitted from: centre and radius of the bounding
/// sphere of the BSSRDF objects, and how far back (from the centre) rays start so that they
/// begin outside all geometry.
#[derive(Debug, Clone, Copy)]
struct Disk {
    centre: DVec3,
    radius: f64,
    back: f64,
}

/// The light tracer over a scene and a BSSRDF method (see the module docs).
pub struct LightTracer<'s> {
    camera_side: PathIntegrator<'s>,
    emitters: Vec<Emitter<'s>>,
    disk: Disk,
    roles: Roles,
}

impl<'s> LightTracer<'s> {
    /// Prepares `method` (a BSSRDF method) on `scene` exactly as the camera tracer does.
    pub fn new(
        scene: &'s Scene,
        method: Method,
        options: PathOptions,
    ) -> Result<Self, LightTraceError> {
        if !matches!(method, Method::Bssrdf { .. }) {
            return Err(LightTraceError::NotBssrdf);
        }
        if let Some(o) = scene
            .objects()
            .iter()
            .find(|o| matches!(o.material, Material::Diffuse { .. }))
        {
            return Err(LightTraceError::DiffuseSurface {
                object: o.name.clone(),
            });
        }
        let mut emitters = Vec::with_capacity(scene.lights().len());
        for (index, light) in scene.lights().iter().enumerate() {
            emitters.push(match light {
                Light::Quad(q) => Emitter::Quad(*q),
                Light::Point(p) => Emitter::Point(*p),
                Light::Directional(d) => Emitter::Directional {
                    direction: d.direction,
                    irradiance: d.irradiance,
                },
                Light::Environment(e) => Emitter::Environment(e),
                Light::Beam(_) => {
                    return Err(LightTraceError::UnsupportedLight {
                        index,
                        kind: "beam",
                    });
                }
            });
        }
        let camera_side = PathIntegrator::new(scene, method, options)?;
        let disk = emission_disk(scene);
        Ok(Self {
            camera_side,
            emitters,
            disk,
            roles: Roles::Physical,
        })
    }

    /// Tells the estimator `roles` (default [`Roles::Physical`]).
    pub fn with_roles(mut self, roles: Roles) -> Self {
        self.roles = roles;
        self
    }

    /// Things about the scene that make this method's image misleading (as the camera
    /// tracer's).
    pub fn warnings(&self) -> &[crate::integrator::warnings::Warning] {
        self.camera_side.warnings()
    }

    /// Traces `options.paths` light paths (in parallel, deterministic; see the module docs).
    pub fn render(&self, options: &LightTraceOptions) -> LightTraced {
        let start = Instant::now();
        let scene = self.camera_side.scene();
        let (w, h) = scene.camera().resolution();
        let mut film = Film::new(w, h);
        let mut counters = PathCounters::default();
        let chunks = options.paths.div_ceil(CHUNK);
        let mut first = 0;
        while first < chunks {
            let end = (first + BATCH).min(chunks);
            let traced: Vec<(Vec<(u32, Rgb)>, PathCounters)> = (first..end)
                .into_par_iter()
                .map(|c| {
                    let mut splats = Vec::new();
                    let mut counters = PathCounters::default();
                    let paths = c * CHUNK..((c + 1) * CHUNK).min(options.paths);
                    for k in paths {
                        let mut rng = Rng::from_keys(options.seed, &[STREAM_KEY, k]);
                        self.trace(&mut rng, &mut splats, &mut counters);
                    }
                    (splats, counters)
                })
                .collect();
            for (splats, c) in &traced {
                for &(i, v) in splats {
                    film.pixels[i as usize] += v;
                }
                counters.merge(c);
            }
            first = end;
        }
        if options.paths > 0 {
            film.scale(1.0 / options.paths as f64);
        }
        LightTraced {
            film,
            paths: options.paths,
            seconds: start.elapsed().as_secs_f64(),
            counters,
        }
    }

    /// One light path; its contributions are pushed to `splats` as (pixel index, value).
    fn trace(&self, rng: &mut Rng, splats: &mut Vec<(u32, Rgb)>, counters: &mut PathCounters) {
        counters.paths += 1;
        let n = self.emitters.len();
        if n == 0 {
            return;
        }
        let emitter = self.emitters[rng.below(n as u32) as usize];
        let Some((ray, flux)) = self.emit(emitter, rng) else {
            return;
        };
        let flux = flux * n as f64;
        let scene = self.camera_side.scene();
        let geometry = scene.geometry();
        let Some(x_i) = geometry.intersect(&ray) else {
            return;
        };
        let Some((material, b)) = self.camera_side.bssrdf_object(x_i.object) else {
            return;
        };
        let w_i = -ray.dir;
        let cos_g = w_i.dot(x_i.ng);
        let Some(n_i) = facing_normal(&x_i, w_i) else {
            return;
        };
        if cos_g <= 0.0 {
            return;
        }
        let beta = flux * (w_i.dot(n_i) / cos_g);
        let at_xi = self.camera_side.lookup(&x_i).unwrap_or_default();
        let surface = ObjectSurface {
            geometry,
            object: x_i.object,
        };
        let mut set = crate::integrator::probe_gathering::ProbePoints::new();
        let density = b.probe_points_into(&mut set, &surface, &x_i, at_xi, None, rng);
        if set.is_empty() {
            counters.probe_misses += 1;
            return;
        }
        let camera = scene.camera();
        let width = camera.resolution().0;
        for (&x_o, axis) in set.found() {
            let Some(c) = camera.connect(x_o.p) else {
                continue;
            };
            let w_o = c.to_camera;
            let cos_o = w_o.dot(x_o.ng);
            if cos_o <= 0.0 || !self.sees(&x_o, w_o, c.dist) {
                continue;
            }
            // The point's weight 1/p(x), only for the points the camera sees.
            let Some(weight) = density.weight(&x_o, axis) else {
                continue;
            };
            let (light_end, camera_end) =
                (PairEnd { hit: &x_i, w: w_i }, PairEnd { hit: &x_o, w: w_o });
            let s = match self.roles {
                Roles::Physical => b.eval(
                    &surface,
                    &material.medium,
                    light_end,
                    camera_end,
                    rng,
                    counters,
                ),
                Roles::Swapped => b.eval(
                    &surface,
                    &material.medium,
                    camera_end,
                    light_end,
                    rng,
                    counters,
                ),
            };
            let v = beta * s * (weight * c.importance * cos_o);
            if v.is_finite() && !v.is_zero() {
                splats.push((c.pixel.1 * width + c.pixel.0, v));
            }
        }
    }

    /// Nothing blocks the segment from `x_o` toward the camera (length `dist`).
    fn sees(&self, x_o: &Hit, to_camera: DVec3, dist: f64) -> bool {
        let origin = x_o.spawn_origin(to_camera);
        let Some(ray) = Ray::between(origin, origin + dist * to_camera) else {
            return false;
        };
        !self.camera_side.scene().geometry().occluded(&ray)
    }

    /// An emitted ray and its flux weight (emitted power per unit pdf, see the module docs).
    fn emit(&self, emitter: Emitter<'_>, rng: &mut Rng) -> Option<(Ray, Rgb)> {
        let u = rng.uniform2();
        let v = rng.uniform2();
        match emitter {
            Emitter::Quad(q) => {
                let y = q.corner + u[0] * q.edge_u + u[1] * q.edge_v;
                let cos = v[0].sqrt();
                if cos <= 0.0 {
                    return None;
                }
                let dir = direction_about(q.normal, cos, 2.0 * PI * v[1]);
                let origin = offset_ray_origin(y, q.normal, dir);
                Some((Ray::new(origin, dir), q.radiance * (q.area * PI)))
            }
            Emitter::Point(p) => Some((
                Ray::new(p.position, uniform_sphere(u)),
                p.intensity * (4.0 * PI),
            )),
            Emitter::Directional {
                direction,
                irradiance,
            } => self.disk_ray(direction, irradiance, v),
            Emitter::Environment(e) => {
                let (w, pdf, radiance) = e.sample(u)?;
                self.disk_ray(-w, radiance / pdf, v)
            }
        }
    }

    /// A ray travelling along `dir` from a point of the emission disk drawn with `v`, and its
    /// flux weight: `per_direction` (irradiance, or radiance over the direction's density) times
    /// the disk's area.
    fn disk_ray(&self, dir: DVec3, per_direction: Rgb, v: [f64; 2]) -> Option<(Ray, Rgb)> {
        let d = self.disk;
        if d.radius.is_nan() || d.radius <= 0.0 {
            return None;
        }
        let (t, b) = het_estimate::frame::orthonormal_basis(dir);
        let r = d.radius * v[0].sqrt();
        let phi = 2.0 * PI * v[1];
        let origin = d.centre - d.back * dir + r * (phi.cos() * t + phi.sin() * b);
        Some((
            Ray::new(origin, dir),
            per_direction * (PI * d.radius * d.radius),
        ))
    }
}

/// The emission disk of lights at infinity: the bounding sphere of the BSSRDF objects, rays
/// starting outside the bounding sphere of all geometry.
fn emission_disk(scene: &Scene) -> Disk {
    let geometry = scene.geometry();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (object, _) in scene.translucent_objects() {
        let (a, b) = geometry.object_bounds(object);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return Disk {
            centre: DVec3::ZERO,
            radius: 0.0,
            back: 0.0,
        };
    }
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * (hi - lo).length();
    let (all_lo, all_hi) = geometry.bounds();
    let all_centre = 0.5 * (all_lo + all_hi);
    let back = (all_centre - centre).length() + 0.5 * (all_hi - all_lo).length();
    Disk {
        centre,
        radius: radius * (1.0 + 1e-9),
        back: back * 1.01 + 1e-9,
    }
}
