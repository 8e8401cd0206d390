//! The shape correction on a heterogeneous body, per channel: a sphere whose σa has stripes of
//! 30:1 contrast in the red channel only (green and blue homogeneous), under a uniform sky, a
//! side quad light or a side point light, rendered by the path tracer and by Sone's BSSRDF
//! with and without the correction. Prints, per channel, the BSSRDF's light through the medium
//! over the path tracer's (the image mean minus what both add outside the medium), with the
//! standard error over seeds: a hue shift shows as channels that disagree.
//!
//!     cargo run --release --example striped_sphere -- [--quick] [--eta 1.3] [--light sky|quad|point]
//!
//! The set-up follows `tests/common/shapes.rs` (σt = 1 in the clear stripes, so lengths are in
//! mean free paths; g = 0; all scattering orders).

use bssrdf_core::glam::DVec3;
use bssrdf_core::{Rgb, Scattering};
use het_bssrdf::{bssrdf_core, tracer};
use tracer::camera::Camera;
use tracer::field::{Axis, Field, MediumField, PlanarProjection};
use tracer::geometry::primitives;
use tracer::integrator::{Correction, Method, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

fn scene(eta: f64, light: &str, radius: f64) -> Scene {
    let n = 24;
    let camera = Camera::orthographic(
        DVec3::new(0.0, 0.0, 3.0 * radius),
        DVec3::NEG_Z,
        DVec3::Y,
        2.2 * radius,
        2.2 * radius,
        n,
        n,
    )
    .unwrap();
    // Red: σa 0.01 / 0.3 in stripes of width 1 mfp along x (30:1); green and blue uniform.
    let sigma_a = Field::stripe(
        1.0,
        0.0,
        [Rgb([0.01, 0.05, 0.05]), Rgb([0.3, 0.05, 0.05])],
        PlanarProjection::new(Axis::Z, DVec3::ZERO),
    )
    .unwrap();
    let medium = MediumField::new(sigma_a, Field::constant(Rgb::splat(0.99)).unwrap());
    let mut builder = SceneBuilder::new(RenderSettings::new(n, n, 1), camera);
    builder = match light {
        "sky" => builder.light(Light::environment(Rgb::ONE).unwrap()),
        "quad" => builder
            .light(
                Light::quad(
                    DVec3::new(3.0 * radius, -radius, -radius),
                    DVec3::new(0.0, 0.0, 2.0 * radius),
                    DVec3::new(0.0, 2.0 * radius, 0.0), // (0, 0, 1) × (0, 1, 0) = −x: toward the sphere
                    Rgb::splat(1.0),
                )
                .unwrap(),
            )
            .light(Light::environment(Rgb::splat(0.1)).unwrap()),
        _ => builder
            .light(Light::point(DVec3::new(4.0 * radius, 0.0, radius), Rgb::splat(50.0)).unwrap())
            .light(Light::environment(Rgb::splat(0.1)).unwrap()),
    };
    builder
        .object(
            "sphere",
            primitives::icosphere(DVec3::ZERO, radius, 5),
            Material::Translucent(Translucent::new("m", medium, 0.0, eta)),
        )
        .build()
        .unwrap()
}

/// Per channel: the mean over seeds of the mean radiance of the pixels whose centre sees the
/// sphere, and its standard error.
fn measure(scene: &Scene, method: Method, spp: u32, seeds: u64) -> [(f64, f64); 3] {
    let integrator = PathIntegrator::new(
        scene,
        method,
        PathOptions {
            scattering: Scattering::All,
            max_depth: 32,
        },
    )
    .unwrap();
    let (w, h) = scene.camera().resolution();
    let mask: Vec<bool> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let ray = scene.camera().ray(x as f64 + 0.5, y as f64 + 0.5);
            scene.geometry().intersect(&ray).is_some()
        })
        .collect();
    let count = mask.iter().filter(|m| **m).count() as f64;
    let per_seed: Vec<[f64; 3]> = (0..seeds)
        .map(|seed| {
            let r = render(w, h, &integrator, &RenderOptions::samples(spp, 1000 + seed));
            let mut sum = [0.0; 3];
            for (p, m) in r.pixels.iter().zip(&mask) {
                if *m {
                    for c in 0..3 {
                        sum[c] += p[c];
                    }
                }
            }
            sum.map(|s| s / count)
        })
        .collect();
    std::array::from_fn(|c| {
        let xs: Vec<f64> = per_seed.iter().map(|s| s[c]).collect();
        let n = xs.len() as f64;
        let m = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        (m, (var / n).sqrt())
    })
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let eta: f64 = arg("--eta").map_or(1.0, |s| s.parse().unwrap());
    let light = arg("--light").unwrap_or_else(|| "sky".into());
    let radius: f64 = arg("--radius").map_or(3.0, |s| s.parse().unwrap());
    let seeds = if quick { 4 } else { 8 };
    let s = scene(eta, &light, radius);
    let sone: het_bssrdf::het_estimate::Estimator = "sone".parse().unwrap();
    let t = std::time::Instant::now();
    let pt = measure(&s, Method::PathTraced, if quick { 64 } else { 256 }, seeds);
    eprintln!("pt: {:.1} s", t.elapsed().as_secs_f64());
    println!(
        "sphere r = {radius} mfp, red σa stripes 0.01/0.3 (width 1 mfp), green and blue σa 0.05, σs 0.99, η {eta}, {light} light; per channel BSSRDF/PT over the sphere's pixels (± 1 SE over {seeds} seeds)"
    );
    for (label, correction) in [
        ("sone, uncorrected", Correction::Off),
        ("sone, corrected", Correction::On),
    ] {
        let t = std::time::Instant::now();
        let m = Method::bssrdf(sone, None).with_correction(correction);
        let b = measure(&s, m, if quick { 16 } else { 64 }, seeds);
        let ratio: Vec<String> = (0..3)
            .map(|c| {
                let (a, sa) = b[c];
                let (p, sp) = pt[c];
                let q = a / p;
                format!(
                    "{q:.3} ± {:.3}",
                    q * ((sa / a).powi(2) + (sp / p).powi(2)).sqrt()
                )
            })
            .collect();
        println!(
            "{label:>20}: R {} | G {} | B {}  ({:.1} s)",
            ratio[0],
            ratio[1],
            ratio[2],
            t.elapsed().as_secs_f64()
        );
    }
}
