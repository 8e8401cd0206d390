//! Rough surfaces in renders (docs/lighting-and-surfaces.md): a translucent object's rough
//! boundary tends to the smooth one as its roughness goes to 0, under the path tracer and
//! under the BSSRDF; a diffuse plane with a textured albedo and a textured Oren–Nayar
//! roughness shows, under a uniform sky, the closed form of its albedo at normal view.

use std::f64::consts::PI;
use std::sync::Arc;

use bssrdf_core::{Rgb, Scattering};
use glam::DVec3;
use het_estimate::Coefficients;
use tracer::camera::Camera;
use tracer::field::{
    Axis, Field, Filter, ImageMapping, MediumField, PlanarProjection, Texture, Wrap,
};
use tracer::geometry::primitives;
use tracer::integrator::{Method, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{RenderOptions, render};
use tracer::scene::{Diffuse, Material, RenderSettings, Scene, SceneBuilder, Translucent};

use crate::common::half_space::image_mean_and_se;

const OPTIONS: PathOptions = PathOptions {
    scattering: Scattering::All,
    max_depth: 10,
};

/// A 4 × 4 × 1 translucent slab (η 1.5; a scattering medium, or a black absorbing one when not
/// `scatters`) of boundary roughness `roughness` (`None`: smooth) under a sky of 0.5 and a quad
/// light of radiance `light` to the side, its top face's middle seen from above at
/// an angle (so that the Fresnel reflection of the sky and the light's glossy highlight are in
/// view).
fn slab(roughness: Option<f64>, light: f64, scatters: bool) -> Scene {
    let n = 8;
    let camera = Camera::perspective(
        DVec3::new(0.0, -3.0, 4.0),
        DVec3::ZERO,
        DVec3::Z,
        30.0,
        n,
        n,
    )
    .unwrap();
    let medium = MediumField::homogeneous(if scatters {
        Coefficients {
            sigma_a: Rgb::new(0.02, 0.05, 0.2),
            sigma_s: Rgb::new(2.0, 1.5, 1.0),
        }
    } else {
        Coefficients::grey(50.0, 0.0)
    })
    .unwrap();
    let mut t = Translucent::new("slab", medium, 0.0, 1.5);
    if let Some(r) = roughness {
        t = t.with_roughness(Field::constant(Rgb::splat(r)).unwrap());
    }
    SceneBuilder::new(RenderSettings::new(n, n, 1), camera)
        .light(Light::environment(Rgb::splat(0.5)).unwrap())
        .light(
            // Facing the slab, where the camera's mirror rays off the top face meet it.
            Light::quad(
                DVec3::new(-1.0, 2.0, 3.0),
                DVec3::new(0.0, 1.0, -1.0),
                DVec3::new(2.0, 0.0, 0.0),
                Rgb::splat(light),
            )
            .unwrap(),
        )
        .object(
            "slab",
            primitives::cuboid(DVec3::new(-2.0, -2.0, -1.0), DVec3::new(2.0, 2.0, 0.0)),
            Material::Translucent(t),
        )
        .build()
        .unwrap()
}

/// Per pixel and channel, the mean and standard error of `seeds` renders of `spp` samples.
fn pixel_stats(scene: &Scene, method: Method, spp: u32, seeds: u64) -> (Vec<Rgb>, Vec<Rgb>) {
    let integrator = PathIntegrator::new(scene, method, OPTIONS).unwrap();
    let (w, h) = scene.camera().resolution();
    let images: Vec<Vec<Rgb>> = (0..seeds)
        .map(|s| render(w, h, &integrator, &RenderOptions::samples(spp, 70 + s)).pixels)
        .collect();
    let k = seeds as f64;
    (0..(w * h) as usize)
        .map(|p| {
            let m = images.iter().fold(Rgb::ZERO, |a, img| a + img[p]) * (1.0 / k);
            let var = images
                .iter()
                .fold(Rgb::ZERO, |a, img| a + (img[p] - m) * (img[p] - m))
                * (1.0 / (k - 1.0));
            (m, (var * (1.0 / k)).map(f64::sqrt))
        })
        .unzip()
}

/// As the roughness goes to 0 (r = 0.04, α = 0.0016, just above the threshold where the
/// boundary is treated as smooth) the rough boundary renders as the smooth one, with the path
/// tracer and with Sone's BSSRDF: image means per channel within 4 SE (the SE under 1.5 % of
/// the mean). A rougher boundary (r = 0.5) renders measurably differently (a test that could
/// not tell would prove nothing): on a black medium, whose image is the boundary's reflection
/// alone, the light's sharp mirror image becomes a glossy highlight (some pixel differs by more
/// than 8 SE).
#[test]
fn a_nearly_smooth_boundary_renders_as_the_smooth_one() {
    let (smooth, nearly) = (slab(None, 3.0, true), slab(Some(0.04), 3.0, true));
    let (black, black_rough) = (slab(None, 30.0, false), slab(Some(0.5), 30.0, false));
    for method in ["pt", "sone"] {
        let method: Method = method.parse().unwrap();
        let stats = |scene: &Scene| pixel_stats(scene, method, 32, 10);
        let ((a, sa), (b, sb)) = (stats(&smooth), stats(&nearly));
        let image = |m: &[Rgb], se: &[Rgb]| {
            let n = m.len() as f64;
            let mean = m.iter().fold(Rgb::ZERO, |x, &y| x + y) * (1.0 / n);
            // Pixels are independent: the SE of their mean.
            let se = se.iter().fold(Rgb::ZERO, |x, &y| x + y * y).map(f64::sqrt) * (1.0 / n);
            (mean, se)
        };
        let ((ma, sea), (mb, seb)) = (image(&a, &sa), image(&b, &sb));
        for k in 0..3 {
            let z = (ma[k] - mb[k]) / (sea[k] * sea[k] + seb[k] * seb[k]).sqrt();
            eprintln!(
                "{}: channel {k}: smooth {:.4} ± {:.4}, r 0.04 {:.4} ± {:.4} (z {z:.2})",
                method.name(),
                ma[k],
                sea[k],
                mb[k],
                seb[k]
            );
            assert!(z.abs() < 4.0, "{}: channel {k}: z = {z}", method.name());
            assert!(
                seb[k] < 0.015 * mb[k],
                "test too weak: {} ± {}",
                mb[k],
                seb[k]
            );
        }
        let ((a, sa), (c, sc)) = (stats(&black), stats(&black_rough));
        let apart = (0..a.len())
            .map(|p| {
                let d = (a[p][0] - c[p][0]) / (sa[p][0].powi(2) + sc[p][0].powi(2)).sqrt();
                d.abs()
            })
            .fold(0.0, f64::max);
        eprintln!(
            "{}: r 0.5 against smooth: max pixel |z| = {apart:.1}",
            method.name()
        );
        assert!(
            apart > 8.0,
            "{}: roughness 0.5 changes nothing",
            method.name()
        );
    }
}

/// The white furnace of the rough boundary in a render: a sphere that absorbs nothing (σs = 2,
/// η = 1.5) under a uniform sky of radiance L, with a rough boundary (r = 0.5, and stripes of
/// r = 0.2 and 0.8), path traced: every path leaves the sphere eventually, and the boundary
/// loses nothing (the energy-conserving lobe, `crate::bsdf::dielectric`), so every pixel
/// inside its outline shows L, within 4 SE + 0.1 %. The single-scattering lobe alone would
/// show the sphere about a fifth darker (light crosses the boundary many times from inside,
/// losing 7-17 % at each crossing at α = 0.25).
#[test]
fn a_lossless_rough_sphere_vanishes_in_a_white_furnace() {
    let l = 1.0;
    let n = 8;
    let camera = Camera::orthographic(
        DVec3::new(0.0, 0.0, 3.0),
        DVec3::NEG_Z,
        DVec3::Y,
        1.0,
        1.0,
        n,
        n,
    )
    .unwrap();
    let medium = MediumField::homogeneous(Coefficients::grey(0.0, 2.0)).unwrap();
    let constant = Field::constant(Rgb::splat(0.5)).unwrap();
    let stripes = Field::stripe(
        0.25,
        0.3,
        [Rgb::splat(0.2), Rgb::splat(0.8)],
        PlanarProjection::new(Axis::Z, DVec3::ZERO),
    )
    .unwrap();
    for roughness in [constant, stripes] {
        let scene = SceneBuilder::new(RenderSettings::new(n, n, 1), camera)
            .light(Light::environment(Rgb::splat(l)).unwrap())
            .object(
                "ball",
                primitives::icosphere(DVec3::ZERO, 1.0, 5),
                Material::Translucent(
                    Translucent::new("ball", medium.clone(), 0.0, 1.5).with_roughness(roughness),
                ),
            )
            .build()
            .unwrap();
        let integrator = PathIntegrator::new(
            &scene,
            Method::PathTraced,
            PathOptions {
                scattering: Scattering::All,
                max_depth: 64,
            },
        )
        .unwrap();
        let (m, se, counters) = image_mean_and_se(&integrator, 16, 8);
        eprintln!("furnace: {:.4} ± {:.4}", m[0], se[0]);
        assert_eq!(counters.capped + counters.leaks, 0);
        assert!(
            (m[0] - l).abs() < 4.0 * se[0] + 1e-3 * l,
            "the sphere shows: {} ± {}",
            m[0],
            se[0]
        );
        assert!(se[0] < 0.01 * l, "test too weak: ± {}", se[0]);
    }
}

/// A diffuse plane under a uniform sky of radiance L, seen straight down by an orthographic
/// camera: every pixel shows ρ/π ∫ L f π/ρ … = ρ L E(σ), E the Oren–Nayar albedo at normal
/// view, where `s = ω_i·n − cos θ_i = 0` for every ω_i: E = 1 / (1 + (1/2 − 2/(3π)) σ)
/// (Fujii's normalisation alone; 1 for σ = 0). The albedo is a 4 × 4 image (nearest texels,
/// each 2 × 2 pixels) and the roughness stripes of σ = 0 and 1 (4 pixels wide), so each pixel
/// has its own closed form; every pixel must agree within 4.5 SE (64 pixels), and the SE be
/// under 2 % of the value.
#[test]
fn a_textured_rough_diffuse_plane_shows_its_closed_form() {
    let l = 1.5;
    let n = 8;
    let texels: Vec<[f32; 3]> = (0..16)
        .map(|k| {
            let v = 0.1 + 0.05 * k as f32;
            [v, 0.9 - 0.4 * v, 0.5]
        })
        .collect();
    let texture = Arc::new(Texture::from_texels("albedo.exr", 4, 4, texels.clone()).unwrap());
    let projection = PlanarProjection::new(Axis::Z, DVec3::ZERO);
    let albedo = Field::image(
        texture,
        ImageMapping::Planar {
            projection,
            size: [2.0, 2.0],
        },
        Wrap::Clamp,
        Filter::Nearest,
        Rgb::ONE,
    )
    .unwrap();
    let roughness =
        Field::stripe(1.0, 0.0, [Rgb::splat(0.0), Rgb::splat(1.0)], projection).unwrap();
    let camera = Camera::orthographic(
        DVec3::new(0.0, 0.0, 3.0),
        DVec3::NEG_Z,
        DVec3::Y,
        2.0,
        2.0,
        n,
        n,
    )
    .unwrap();
    let scene = SceneBuilder::new(RenderSettings::new(n, n, 1), camera)
        .light(Light::environment(Rgb::splat(l)).unwrap())
        .object(
            "plane",
            primitives::cuboid(DVec3::new(-3.0, -3.0, -0.5), DVec3::new(3.0, 3.0, 0.0)),
            Material::Diffuse(Diffuse {
                albedo: albedo.clone(),
                roughness: Some(roughness.clone()),
            }),
        )
        .build()
        .unwrap();
    let integrator = PathIntegrator::new(&scene, Method::PathTraced, OPTIONS).unwrap();
    let seeds = 8;
    let images: Vec<Vec<Rgb>> = (0..seeds)
        .map(|s| render(n, n, &integrator, &RenderOptions::samples(64, 50 + s)).pixels)
        .collect();
    let c = 0.5 - 2.0 / (3.0 * PI);
    let mut max_z = 0.0f64;
    let mut distinct = Vec::new();
    for y in 0..n {
        for x in 0..n {
            // The pixel's centre on the plane (row 0 at the top, +y up).
            let p = DVec3::new(
                -1.0 + (x as f64 + 0.5) * 0.25,
                1.0 - (y as f64 + 0.5) * 0.25,
                0.0,
            );
            let rho = albedo.eval(p, glam::DVec2::ZERO);
            let sigma = roughness.eval(p, glam::DVec2::ZERO)[0];
            let want = rho * (l / (1.0 + c * sigma));
            let k = (y * n + x) as usize;
            for ch in 0..3 {
                let v: Vec<f64> = images.iter().map(|img| img[k][ch]).collect();
                let m = v.iter().sum::<f64>() / seeds as f64;
                let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (seeds - 1) as f64;
                let se = (var / seeds as f64).sqrt();
                assert!(
                    se < 0.02 * want[ch],
                    "pixel ({x}, {y}): test too weak: ± {se}"
                );
                // Cosine sampling of a uniform sky on a Lambertian texel has no variance:
                // such a pixel must then be exact (to rounding).
                let z = if se > 0.0 {
                    ((m - want[ch]) / se).abs()
                } else if (m - want[ch]).abs() <= 1e-9 * want[ch] {
                    0.0
                } else {
                    f64::INFINITY
                };
                max_z = max_z.max(z);
            }
            distinct.push((want[0] * 1e6) as i64);
        }
    }
    distinct.sort();
    distinct.dedup();
    eprintln!(
        "max |z| = {max_z:.2} over {} distinct values",
        distinct.len()
    );
    assert!(max_z < 4.5, "max |z| = {max_z}");
    assert!(distinct.len() >= 16, "the texture does not show");
}
