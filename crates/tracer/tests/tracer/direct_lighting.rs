//! Rendered images against closed forms for every kind of light that next-event estimation
//! samples, and multiple importance sampling against each of its strategies alone.
//!
//! The receiver is a Lambertian floor (albedo ρ) seen straight down by an orthographic camera,
//! so the exact image mean is the mean over the view of L(x) = ρ E(x) / π:
//! * quad light of radiance L_e: E from Lambert's polygon formula ([`lambert_irradiance`]);
//! * point light of intensity I at height h: E = I h / d³;
//! * uniform environment of radiance L_env: L = ρ L_env.
//!
//! A flat translucent half-space then checks the same lights through the media code of both
//! renders: the three light strategies must agree, and the BSSRDF renderer must differ from the
//! path tracer under a quad light by the same factor as under a uniform environment (that
//! factor is the homogeneous profile's own error, measured here, not assumed).

use std::f64::consts::PI;

use bssrdf_core::{ProfileModel, Rgb, Scattering};
use glam::DVec3;
use het_estimate::Coefficients;
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::primitives;
use tracer::integrator::{LightStrategy, Method, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

use crate::common::lambert_irradiance;

const RHO: f64 = 0.5;
/// Pixels per side of every test image.
const N: u32 = 4;

/// The floor (top face z = 0, Lambertian albedo [`RHO`]) or a translucent half-space, seen
/// from above over `[-half, half]²`, lit by `lights`.
fn scene(lights: &[Light], half: f64, material: Material) -> Scene {
    let camera = Camera::orthographic(
        DVec3::new(0.0, 0.0, 0.5),
        DVec3::NEG_Z,
        DVec3::Y,
        2.0 * half,
        2.0 * half,
        N,
        N,
    )
    .unwrap();
    let mut b = SceneBuilder::new(RenderSettings::new(N, N, 1), camera);
    for l in lights {
        b = b.light(l.clone());
    }
    b.object(
        "floor",
        primitives::half_space(0.0, [0.0, 0.0], 1000.0, 500.0, 32),
        material,
    )
    .build()
    .unwrap()
}

fn floor(lights: &[Light], half: f64) -> Scene {
    scene(lights, half, Material::diffuse(Rgb::splat(RHO)))
}

fn half_space(lights: &[Light], half: f64, eta: f64) -> Scene {
    let medium = MediumField::homogeneous(Coefficients::grey(0.01, 1.0)).unwrap();
    scene(
        lights,
        half,
        Material::Translucent(Translucent::new("m", medium, 0.0, eta)),
    )
}

/// A quad of side `size` centred above the origin at height `h`, emitting downward.
fn quad(size: f64, h: f64, radiance: f64) -> Light {
    Light::quad(
        DVec3::new(-0.5 * size, -0.5 * size, h),
        DVec3::new(0.0, size, 0.0),
        DVec3::new(size, 0.0, 0.0),
        Rgb::splat(radiance),
    )
    .unwrap()
}

/// The corners of a quad light, for Lambert's formula.
fn vertices(light: &Light) -> [DVec3; 4] {
    match light {
        Light::Quad(q) => q.vertices(),
        _ => unreachable!("a quad light"),
    }
}

/// Mean over `[-half, half]²` of `f`, by the midpoint rule on a 200 × 200 grid (the integrands
/// are smooth; the rule's error is far below the tests' statistical tolerances).
fn view_mean(half: f64, f: impl Fn(f64, f64) -> f64) -> f64 {
    let m = 200;
    let h = 2.0 * half / m as f64;
    let mut s = 0.0;
    for i in 0..m {
        for j in 0..m {
            s += f(-half + (i as f64 + 0.5) * h, -half + (j as f64 + 0.5) * h);
        }
    }
    s / (m * m) as f64
}

/// Image mean (red channel) and its standard error over 8 independent renders.
fn image_mean(scene: &Scene, method: Method, strategy: LightStrategy, spp: u32) -> (f64, f64) {
    let integrator = PathIntegrator::new(
        scene,
        method,
        PathOptions {
            scattering: Scattering::Multiple,
            max_depth: 8,
        },
    )
    .unwrap()
    .with_light_strategy(strategy);
    let seeds = 8u64;
    let means: Vec<f64> = (0..seeds)
        .map(|seed| {
            let r = render(N, N, &integrator, &RenderOptions::samples(spp, 7000 + seed));
            assert_eq!(r.counters.capped + r.counters.leaks, 0, "{:?}", r.counters);
            r.pixels.iter().map(|p| p[0]).sum::<f64>() / r.pixels.len() as f64
        })
        .collect();
    let m = means.iter().sum::<f64>() / seeds as f64;
    let var = means.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (seeds - 1) as f64;
    (m, (var / seeds as f64).sqrt())
}

fn assert_close(what: &str, (m, se): (f64, f64), want: f64) {
    assert!(
        (m - want).abs() < 4.0 * se,
        "{what}: {m} ± {se}, exact {want} ({:+.1} SE)",
        (m - want) / se
    );
    assert!(se < 0.02 * want, "{what}: test too weak, SE {se} of {want}");
}

#[test]
fn quad_light_on_a_lambertian_floor_matches_the_form_factor() {
    // (side, height, half-width of the view): the case, a small light far away (next
    // event estimation carries nearly all of it), and a large light close by.
    for (size, h, half) in [(4.0, 3.0, 2.0), (1.0, 30.0, 2.0), (10.0, 1.0, 1.0)] {
        let light = quad(size, h, 1.0);
        let verts = vertices(&light);
        let want = view_mean(half, |x, y| {
            RHO / PI * lambert_irradiance(DVec3::new(x, y, 0.0), DVec3::Z, &verts)
        });
        let got = image_mean(
            &floor(&[light], half),
            Method::PathTraced,
            LightStrategy::Mis,
            64,
        );
        assert_close(&format!("quad {size} at height {h}"), got, want);
    }
}

#[test]
fn point_light_on_a_lambertian_floor_is_rho_i_cos_over_pi_d2() {
    let (pos, intensity) = (DVec3::new(0.3, -0.2, 2.0), 5.0);
    let light = Light::point(pos, Rgb::splat(intensity)).unwrap();
    let half = 1.5;
    let want = view_mean(half, |x, y| {
        let d = pos - DVec3::new(x, y, 0.0);
        let dist = d.length();
        // L = ρ I cos θ / (π d²), cos θ = h / d.
        RHO * intensity * (pos.z / dist) / (PI * dist * dist)
    });
    let got = image_mean(
        &floor(&[light], half),
        Method::PathTraced,
        LightStrategy::Mis,
        16,
    );
    assert_close("point light", got, want);
}

#[test]
fn uniform_environment_on_a_lambertian_floor_is_rho_l() {
    let l_env = 0.8;
    let got = image_mean(
        &floor(&[Light::environment(Rgb::splat(l_env)).unwrap()], 1.0),
        Method::PathTraced,
        LightStrategy::Mis,
        64,
    );
    assert_close("environment", got, RHO * l_env);
}

#[test]
fn light_sampling_and_direction_sampling_agree_with_mis_and_the_closed_form() {
    // A quad and a dim environment together: each strategy alone reaches both.
    let light = quad(4.0, 3.0, 1.0);
    let l_env = 0.2;
    let lights = [
        light.clone(),
        Light::environment(Rgb::splat(l_env)).unwrap(),
    ];
    let half = 2.0;
    let verts = vertices(&light);
    // The quad hides part of the environment's sky: E_env = π L_env − L_env · E_quad(L = 1).
    let want = view_mean(half, |x, y| {
        let e_q = lambert_irradiance(DVec3::new(x, y, 0.0), DVec3::Z, &verts);
        RHO / PI * (e_q + l_env * (PI - e_q))
    });
    let scene = floor(&lights, half);
    for strategy in [
        LightStrategy::Mis,
        LightStrategy::LightOnly,
        LightStrategy::DirectionOnly,
    ] {
        let got = image_mean(&scene, Method::PathTraced, strategy, 128);
        assert_close(&format!("{strategy:?}"), got, want);
    }
}

/// Pairwise agreement of the three strategies at 4 combined standard errors.
fn strategies_agree(what: &str, scene: &Scene, method: Method, spp: u32) {
    let runs: Vec<(LightStrategy, (f64, f64))> = [
        LightStrategy::Mis,
        LightStrategy::LightOnly,
        LightStrategy::DirectionOnly,
    ]
    .into_iter()
    .map(|s| (s, image_mean(scene, method, s, spp)))
    .collect();
    for (i, (sa, (a, ea))) in runs.iter().enumerate() {
        assert!(*ea < 0.03 * a, "{what} {sa:?}: test too weak, {a} ± {ea}");
        for (sb, (b, eb)) in &runs[i + 1..] {
            let se = (ea * ea + eb * eb).sqrt();
            assert!(
                (a - b).abs() < 4.0 * se,
                "{what}: {sa:?} {a} ± {ea} vs {sb:?} {b} ± {eb}"
            );
        }
    }
}

fn sone(profile: ProfileModel) -> Method {
    Method::bssrdf("sone".parse().unwrap(), Some(profile))
}

#[test]
fn strategies_agree_through_media_in_both_renders() {
    let light = [quad(4.0, 3.0, 1.0)];
    // The path tracer connects to lights through an index-matched boundary only.
    strategies_agree(
        "path tracer, eta 1",
        &half_space(&light, 0.5, 1.0),
        Method::PathTraced,
        64,
    );
    // The BSSRDF renderer gathers light at x_i outside the boundary, at any eta.
    for eta in [1.0, 1.3] {
        strategies_agree(
            &format!("BSSRDF, eta {eta}"),
            &half_space(&light, 0.5, eta),
            sone(ProfileModel::Dipole),
            128,
        );
    }
}

#[test]
fn bssrdf_differs_from_the_path_tracer_under_a_quad_as_under_a_uniform_environment() {
    // Under illumination that is uniform over many diffusion lengths, the BSSRDF/PT ratio is the
    // homogeneous profile's own error, whatever the light. Measured here (dipole, σa 0.01,
    // σs 1, 8 seeds): 1.238 ± 0.005 at η = 1 and 1.100 ± 0.003 at η = 1.3 under the
    // environment; 1.233 ± 0.003 and 1.105 ± 0.005 under a 60 × 60 quad at height 10. With next-
    // event estimation toward quads broken (the bug of commit 92e75bc) the quad gives 1.96 and
    // 0.83. (Under a 4 × 4 quad at height 3 the ratio is larger, 1.49 and 1.31: the light then
    // varies over a diffusion length, where the dipole's radial shape is wrong as well.)
    let env = [Light::environment(Rgb::ONE).unwrap()];
    let big = [quad(60.0, 10.0, 1.0)];
    for eta in [1.0, 1.3] {
        let ratio = |lights: &[Light]| {
            let s = half_space(lights, 0.5, eta);
            let (b, eb) = image_mean(&s, sone(ProfileModel::Dipole), LightStrategy::Mis, 128);
            let (p, ep) = image_mean(&s, Method::PathTraced, LightStrategy::Mis, 256);
            let r = b / p;
            (r, r * ((eb / b).powi(2) + (ep / p).powi(2)).sqrt())
        };
        let (r_env, e_env) = ratio(&env);
        let (r_quad, e_quad) = ratio(&big);
        let se = (e_env * e_env + e_quad * e_quad).sqrt();
        assert!(se < 0.02 * r_env, "test too weak: {se}");
        // 4 SE, plus 1 % for the different angular spread of the two lights.
        assert!(
            (r_quad - r_env).abs() < 4.0 * se + 0.01 * r_env,
            "eta {eta}: BSSRDF/PT {r_quad} ± {e_quad} under the quad, {r_env} ± {e_env} under \
             the environment"
        );
    }
}

/// A quad light seen in the mirror reflection of a smooth dielectric (η = 1.3) is traced as
/// that reflection's light sample, not found by the random choice between reflection and
/// transmission (which shows it with probability R ≈ 1.7 % at weight 1: speckles). Seen
/// straight down under a quad 4 wide at height 2, every pixel's mirror ray reaches the light
/// at normal incidence, so the reflected radiance is R L_e with R = ((η − 1)/(η + 1))². With
/// a medium that absorbs everything that enters (σa = 100 over a depth of 500, σs = 0: the
/// path tracer's) each pixel is exactly that, at 1 spp; with a medium of albedo 10⁻³ (the
/// BSSRDF's) it is that plus a faint subsurface glow, with a spread over seeds below 1 % of R
/// L_e (the random choice gives a spread of √((1 − R)/(R · spp)) ≈ 190 % at 4 spp).
#[test]
fn a_light_reflected_in_a_smooth_dielectric_is_sampled_not_hit_by_chance() {
    let (eta, le) = (1.3, 6.0);
    let r = ((eta - 1.0) / (eta + 1.0)) * ((eta - 1.0) / (eta + 1.0));
    let want = r * le;
    let light = quad(4.0, 2.0, le);
    let material = |sigma_a: f64, sigma_s: f64| {
        let medium = MediumField::homogeneous(Coefficients::grey(sigma_a, sigma_s)).unwrap();
        Material::Translucent(Translucent::new("glass", medium, 0.0, eta))
    };
    let options = PathOptions {
        scattering: Scattering::All,
        max_depth: 8,
    };
    // The path tracer through an absorbing, non-scattering medium: exact at 1 spp.
    let absorbing = scene(std::slice::from_ref(&light), 1.0, material(100.0, 0.0));
    let pt = PathIntegrator::new(&absorbing, Method::PathTraced, options).unwrap();
    for seed in 0..4 {
        let img = render(N, N, &pt, &RenderOptions::samples(1, seed));
        for p in &img.pixels {
            assert!(
                (p[0] - want).abs() < 1e-9 * want,
                "pt, seed {seed}: {} vs {want}",
                p[0]
            );
        }
    }
    // A BSSRDF: the reflection is the same in every sample; the glow below it is faint.
    let dark = scene(&[light], 1.0, material(10.0, 0.01));
    let sone = PathIntegrator::new(&dark, sone(ProfileModel::Tabulated), options).unwrap();
    let per_seed: Vec<Vec<f64>> = (0..8)
        .map(|seed| {
            render(N, N, &sone, &RenderOptions::samples(4, seed))
                .pixels
                .iter()
                .map(|p| p[0])
                .collect()
        })
        .collect();
    for px in 0..(N * N) as usize {
        let v: Vec<f64> = per_seed.iter().map(|img| img[px]).collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
        assert!(
            mean >= want && mean < 1.01 * want,
            "sone, pixel {px}: {mean} vs R L_e = {want}"
        );
        assert!(sd < 0.01 * want, "sone, pixel {px}: spread {sd} of {want}");
    }
}
