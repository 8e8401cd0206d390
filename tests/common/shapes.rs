//! Finite shapes for comparing the BSSRDF renderer with the path tracer beyond half-spaces
//! (issue 18; `examples/shapes.rs` and the `shapes` tests): homogeneous media with σt = 1 (so
//! sizes are in mean free paths), g = 0, a uniform environment light of radiance 1 and an
//! orthographic view.
//!
//! The compared quantity is the light that went through the medium, per image: the image mean
//! minus what both methods add outside the medium (the environment seen past the object and
//! the Fresnel reflection of the environment at the surface), which [`outside_light`] computes
//! deterministically on a fine grid of camera rays. Dividing the BSSRDF/PT ratio of that
//! quantity on a shape by the same ratio on the half-space removes the profile's own
//! half-space error and leaves the error of the half-space assumption on the shape.

use std::path::Path;

use bssrdf_core::glam::DVec3;
use bssrdf_core::{ProfileModel, Rgb, Scattering};
use het_estimate::Coefficients;
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::{Ray, TriangleMesh, primitives};
use tracer::integrator::{Method, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

/// A test shape: its mesh and the orthographic view of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// The reference: a 400 × 400 × 200 box seen on a 0.5 × 0.5 patch of its top.
    HalfSpace,
    /// The half-space seen on a 0.5-wide window at this cosine μ from its normal
    /// (`examples/shapes.rs -- --oblique`): the exit-direction part of the error.
    #[allow(dead_code)]
    Oblique(f64),
    /// A 100 × 100 slab of this thickness seen on a 0.5 × 0.5 patch of its top.
    Slab(f64),
    /// A sphere of this radius, seen whole.
    Sphere(f64),
    /// The corner of a 10-mfp cube seen along its diagonal, over a 2 × 2 window about it.
    BoxCorner,
    /// (Used by `examples/shapes.rs` only.) The Stanford bunny of `examples/scenes/bunny.toml` (about 9 mfp tall), seen whole from
    /// the side.
    #[allow(dead_code)]
    Bunny,
}

impl Shape {
    /// The shapes of the table, in its order (`examples/shapes.rs`).
    #[allow(dead_code)]
    pub const TABLE: [Shape; 6] = [
        Shape::Slab(0.5),
        Shape::Slab(2.0),
        Shape::Sphere(1.0),
        Shape::Sphere(10.0),
        Shape::BoxCorner,
        Shape::Bunny,
    ];

    /// A row label.
    pub fn label(self) -> String {
        match self {
            Shape::HalfSpace => "half-space".into(),
            Shape::Oblique(mu) => format!("half-space seen at μ = {mu}"),
            Shape::Slab(t) => format!("slab {t} mfp"),
            Shape::Sphere(r) => format!("sphere r = {r} mfp"),
            Shape::BoxCorner => "box corner".into(),
            Shape::Bunny => "bunny".into(),
        }
    }

    /// Pixels per side of the image (uniform views need few).
    pub fn pixels(self) -> u32 {
        match self {
            Shape::HalfSpace | Shape::Oblique(_) | Shape::Slab(_) | Shape::BoxCorner => 4,
            Shape::Sphere(_) | Shape::Bunny => 16,
        }
    }

    /// The mesh and camera; `bunny` is the path of `bunny.obj` (only [`Shape::Bunny`] reads it).
    fn mesh_and_camera(self, bunny: &Path) -> (TriangleMesh, Camera) {
        let n = self.pixels();
        let top_view = |w: f64, z: f64| {
            Camera::orthographic(DVec3::new(0.0, 0.0, z), DVec3::NEG_Z, DVec3::Y, w, w, n, n)
                .unwrap()
        };
        match self {
            Shape::HalfSpace => (
                primitives::half_space(0.0, [0.0, 0.0], 400.0, 200.0, 40),
                top_view(0.5, 1.0),
            ),
            Shape::Oblique(mu) => {
                let d = DVec3::new(-(1.0 - mu * mu).sqrt(), 0.0, -mu);
                (
                    primitives::half_space(0.0, [0.0, 0.0], 400.0, 200.0, 40),
                    Camera::orthographic(-d, d, DVec3::Y, 0.5, 0.5, n, n).unwrap(),
                )
            }
            Shape::Slab(t) => (
                primitives::subdivided_cuboid(
                    DVec3::new(-50.0, -50.0, -t),
                    DVec3::new(50.0, 50.0, 0.0),
                    [40, 40, 1],
                ),
                top_view(0.5, 1.0),
            ),
            Shape::Sphere(r) => (
                primitives::icosphere(DVec3::ZERO, r, 5),
                top_view(2.2 * r, 2.0 * r),
            ),
            Shape::BoxCorner => {
                let d = DVec3::ONE.normalize();
                (
                    primitives::subdivided_cuboid(DVec3::splat(-10.0), DVec3::ZERO, [10, 10, 10]),
                    Camera::orthographic(2.0 * d, -d, DVec3::Z, 2.0, 2.0, n, n).unwrap(),
                )
            }
            Shape::Bunny => {
                let mut mesh = tracer::geometry::obj::load_obj(bunny).expect("bunny.obj");
                let xf = tracer::geometry::Transform {
                    scale: DVec3::splat(60.0),
                    rotation: tracer::geometry::Transform::rotation_axis_angle(DVec3::X, 90.0),
                    translation: DVec3::ZERO,
                };
                mesh.transform(&xf);
                let (lo, hi) = mesh.bounds();
                let c = 0.5 * (lo + hi);
                let w = 1.05 * (hi - lo).max_element();
                let eye = DVec3::new(c.x, lo.y - 1.0, c.z);
                let cam = Camera::orthographic(eye, DVec3::Y, DVec3::Z, w, w, n, n).unwrap();
                (mesh, cam)
            }
        }
    }
}

/// The medium and boundary of one column of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    /// Single-scattering albedo ϖ (σt = 1).
    pub albedo: f64,
    /// Relative refractive index.
    pub eta: f64,
    /// Henyey–Greenstein g.
    pub g: f64,
}

impl Medium {
    /// The four g = 0 columns (`examples/shapes.rs`).
    #[allow(dead_code)]
    pub const COLUMNS: [Medium; 4] = [
        Medium::new(0.9, 1.0),
        Medium::new(0.99, 1.0),
        Medium::new(0.9, 1.3),
        Medium::new(0.99, 1.3),
    ];
    /// ϖ and η with g = 0.
    pub const fn new(albedo: f64, eta: f64) -> Self {
        Self {
            albedo,
            eta,
            g: 0.0,
        }
    }
    /// A column label.
    pub fn label(self) -> String {
        if self.g == 0.0 {
            format!("η {}, ϖ {}", self.eta, self.albedo)
        } else {
            format!("η {}, ϖ {}, g {}", self.eta, self.albedo, self.g)
        }
    }
}

/// `shape` filled with `medium` under a uniform environment of radiance 1, with the material's
/// `thickness_aware` set (false: the half-space profile everywhere, `examples/shapes.rs --
/// --half-space`) and its `shape_correction` (`examples/shapes.rs -- --corrected`).
pub fn shape_scene_with(
    shape: Shape,
    medium: Medium,
    bunny: &Path,
    thickness_aware: bool,
    shape_correction: bool,
) -> Scene {
    shape_scene_material(shape, medium, bunny, |m| Translucent {
        thickness_aware,
        shape_correction: Some(shape_correction),
        ..m
    })
}

/// `shape` filled with `medium` under a uniform environment of radiance 1, its material
/// (the defaults of `Translucent::new`) passed through `material` first.
pub fn shape_scene_material(
    shape: Shape,
    medium: Medium,
    bunny: &Path,
    material: impl FnOnce(Translucent) -> Translucent,
) -> Scene {
    let (mesh, camera) = shape.mesh_and_camera(bunny);
    let (w, h) = camera.resolution();
    let field =
        MediumField::homogeneous(Coefficients::grey(1.0 - medium.albedo, medium.albedo)).unwrap();
    SceneBuilder::new(RenderSettings::new(w, h, 1), camera)
        .light(Light::environment(Rgb::ONE).unwrap())
        .object(
            "shape",
            mesh,
            Material::Translucent(material(Translucent::new("m", field, medium.g, medium.eta))),
        )
        .build()
        .unwrap()
}

/// The image mean (red channel) of the light that never entered the medium, for both methods:
/// the environment (radiance 1) past the object and its Fresnel reflection on the object,
/// averaged over a `k × k` grid of camera rays per pixel (a reflected ray that hits the object
/// again is left out: that light went through the medium).
pub fn outside_light(scene: &Scene, eta: f64, k: u32) -> f64 {
    let (w, h) = scene.camera().resolution();
    let mut sum = 0.0;
    for py in 0..h {
        for px in 0..w {
            for j in 0..k {
                for i in 0..k {
                    let fx = px as f64 + (i as f64 + 0.5) / k as f64;
                    let fy = py as f64 + (j as f64 + 0.5) / k as f64;
                    let ray = scene.camera().ray(fx, fy);
                    sum += match scene.geometry().intersect(&ray) {
                        None => 1.0,
                        Some(hit) => {
                            let cos = (-ray.dir.dot(hit.ng)).clamp(0.0, 1.0);
                            let refl = ray.dir + 2.0 * cos * hit.ng;
                            let again = scene
                                .geometry()
                                .occluded(&Ray::new(hit.spawn_origin(refl), refl));
                            if eta == 1.0 || again {
                                0.0
                            } else {
                                bssrdf_core::fresnel::dielectric(cos, eta)
                            }
                        }
                    };
                }
            }
        }
    }
    sum / (w as f64 * h as f64 * (k * k) as f64)
}

/// One render's measurement: the mean light through the medium per image, and the fraction of
/// BSSRDF shading points whose probes found nothing (0 for the path tracer).
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    /// Image mean minus [`outside_light`].
    pub through: f64,
    /// Probe misses / probe sets (`examples/shapes.rs`).
    #[allow(dead_code)]
    pub miss_fraction: f64,
}

/// Renders `scene` with `method` (multiple scattering, at most 8 surface interactions) at
/// `spp` samples per pixel for each seed in `seeds`; asserts that no path was capped and that
/// at most 1e-4 of the paths leaked (a ray slipping through an edge of the box, a bias far
/// below the tolerances).
pub fn measure(
    scene: &Scene,
    method: Method,
    outside: f64,
    spp: u32,
    seeds: std::ops::Range<u64>,
) -> Vec<Sample> {
    measure_orders(scene, method, Scattering::Multiple, outside, spp, seeds)
}

/// [`measure`] counting the scattering orders `scattering`.
pub fn measure_orders(
    scene: &Scene,
    method: Method,
    scattering: Scattering,
    outside: f64,
    spp: u32,
    seeds: std::ops::Range<u64>,
) -> Vec<Sample> {
    let integrator = PathIntegrator::new(
        scene,
        method,
        PathOptions {
            scattering,
            max_depth: 8,
        },
    )
    .unwrap();
    let (w, h) = scene.camera().resolution();
    seeds
        .map(|seed| {
            let r = render(w, h, &integrator, &RenderOptions::samples(spp, seed));
            let c = r.counters;
            assert!(c.capped == 0 && c.leaks * 10_000 <= c.paths, "{c:?}");
            let mean = r.pixels.iter().map(|p| p[0]).sum::<f64>() / r.pixels.len() as f64;
            Sample {
                through: mean - outside,
                miss_fraction: if c.probe_sets > 0 {
                    c.probe_misses as f64 / c.probe_sets as f64
                } else {
                    0.0
                },
            }
        })
        .collect()
}

/// Mean and standard error of the mean.
pub fn mean_se(xs: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let xs: Vec<f64> = xs.into_iter().collect();
    let n = xs.len() as f64;
    let m = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, (var / n).sqrt())
}

/// The ratio `a/b` of two independent means with standard errors, and its standard error
/// (first order).
pub fn ratio((a, sa): (f64, f64), (b, sb): (f64, f64)) -> (f64, f64) {
    let q = a / b;
    (q, q.abs() * ((sa / a).powi(2) + (sb / b).powi(2)).sqrt())
}

/// The BSSRDF method used for homogeneous shapes: the estimator plays no part (a constant
/// field short-circuits), so the cheapest one, with `profile`.
pub fn bssrdf(profile: ProfileModel) -> Method {
    Method::bssrdf("jensen-out".parse().unwrap(), Some(profile))
}
