//! The index-matched half-space scene of the validation tests and `examples/validation.rs`,
//! and the mean image value with its standard error over independent renders.

use bssrdf_core::glam::DVec3;
use bssrdf_core::{Rgb, Scattering};
use het_estimate::Coefficients;
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::primitives;
use tracer::integrator::{Method, PathCounters, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{Counters, RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

/// A huge half-space (top z = 0, η = `eta`, isotropic) seen from above over a 0.5 × 0.5 patch
/// (4 × 4 pixels), lit by a directional light travelling along `−light_to` with unit
/// irradiance on a surface perpendicular to it.
pub fn half_space_scene(sigma_a: f64, sigma_s: f64, light_to: DVec3, eta: f64) -> Scene {
    let medium = MediumField::homogeneous(Coefficients::grey(sigma_a, sigma_s)).unwrap();
    half_space_scene_with(medium, light_to, eta)
}

/// [`half_space_scene`] with any medium field.
pub fn half_space_scene_with(medium: MediumField, light_to: DVec3, eta: f64) -> Scene {
    let light = Light::directional(-light_to.normalize(), Rgb::ONE).unwrap();
    half_space_lit(Translucent::new("m", medium, 0.0, eta), light)
}

/// The half-space of [`half_space_scene`] made of `material`, lit by `light` alone.
pub fn half_space_lit(material: Translucent, light: Light) -> Scene {
    let n = 4;
    let camera = Camera::orthographic(
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::NEG_Z,
        DVec3::Y,
        0.5,
        0.5,
        n,
        n,
    )
    .unwrap();
    SceneBuilder::new(RenderSettings::new(n, n, 1), camera)
        .light(light)
        .object(
            "half-space",
            primitives::half_space(0.0, [0.0, 0.0], 400.0, 200.0, 40),
            Material::Translucent(material),
        )
        .build()
        .unwrap()
}

/// Mean image value (red channel) and its standard error from `seeds` independent renders of
/// `spp` samples per pixel; asserts that no path was capped or leaked.
pub fn mean_and_se(
    scene: &Scene,
    method: Method,
    scattering: Scattering,
    spp: u32,
    seeds: u64,
) -> (f64, f64) {
    let options = PathOptions {
        scattering,
        max_depth: 8,
    };
    let (m, se, lost) = mean_and_se_rgb(scene, method, options, spp, seeds);
    assert_eq!(lost, 0, "paths capped or leaked");
    (m[0], se[0])
}

/// Per-channel image mean and its standard error from `seeds` independent renders (seeds
/// 1000, 1001, …) of `spp` samples per pixel, with the number of paths capped or leaked.
pub fn mean_and_se_rgb(
    scene: &Scene,
    method: Method,
    options: PathOptions,
    spp: u32,
    seeds: u64,
) -> (Rgb, Rgb, u64) {
    let integrator = PathIntegrator::new(scene, method, options).unwrap();
    let (m, se, counters) = image_mean_and_se(&integrator, spp, seeds);
    (m, se, counters.capped + counters.leaks)
}

/// Per-channel image mean and its standard error from `seeds` independent renders (seeds
/// 1000, 1001, …) of `spp` samples per pixel with `integrator`, at the scene's resolution,
/// with the counters of all the renders together.
pub fn image_mean_and_se(
    integrator: &PathIntegrator,
    spp: u32,
    seeds: u64,
) -> (Rgb, Rgb, PathCounters) {
    let (w, h) = integrator.scene().camera().resolution();
    let mut counters = PathCounters::default();
    let means: Vec<Rgb> = (0..seeds)
        .map(|seed| {
            let r = render(w, h, integrator, &RenderOptions::samples(spp, 1000 + seed));
            counters.merge(&r.counters);
            r.pixels.iter().fold(Rgb::ZERO, |a, &p| a + p) * (1.0 / r.pixels.len() as f64)
        })
        .collect();
    let m = means.iter().fold(Rgb::ZERO, |a, &x| a + x) * (1.0 / seeds as f64);
    let var = means.iter().fold(Rgb::ZERO, |a, &x| a + (x - m) * (x - m));
    let se = (var * (1.0 / ((seeds - 1) * seeds) as f64)).map(f64::sqrt);
    (m, se, counters)
}
