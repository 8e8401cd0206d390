//! The camera-path integrators against exact results: the reference path tracer's emergent
//! radiance from a half-space (Chandrasekhar), the BSSRDF renderer against its own profile's
//! analytic prediction, determinism across thread counts, and the probe sampler's density.

use bssrdf_core::{ProfileFamily, ProfileModel, RadialProfile, Rgb, Scattering};
use glam::DVec3;
use het_estimate::{Coefficients, Estimator};
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::primitives;
use tracer::integrator::{Method, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{Budget, RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

use crate::common::chandrasekhar::emergent_radiance;

/// A huge index-matched half-space (top z = 0) seen from above over a small central patch,
/// lit by a directional light travelling along `-light_to` (unit irradiance).
fn half_space_scene(sigma_a: f64, sigma_s: f64, light_to: DVec3, eta: f64) -> Scene {
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
    let medium = MediumField::homogeneous(Coefficients::grey(sigma_a, sigma_s)).unwrap();
    SceneBuilder::new(RenderSettings::new(n, n, 1), camera)
        .light(Light::directional(-light_to.normalize(), Rgb::ONE).unwrap())
        .object(
            "half-space",
            primitives::half_space(0.0, [0.0, 0.0], 400.0, 200.0, 40),
            Material::Translucent(Translucent::new("m", medium, 0.0, eta)),
        )
        .build()
        .unwrap()
}

/// Mean image value and its standard error from `seeds` independent renders.
fn mean_and_se(
    scene: &Scene,
    method: Method,
    scattering: Scattering,
    spp: u32,
    seeds: u64,
) -> (f64, f64) {
    let integrator = PathIntegrator::new(
        scene,
        method,
        PathOptions {
            scattering,
            max_depth: 8,
        },
    )
    .unwrap();
    let (w, h) = scene.camera.resolution();
    let means: Vec<f64> = (0..seeds)
        .map(|seed| {
            let r = render(
                w,
                h,
                &integrator,
                &RenderOptions {
                    budget: Budget::Samples(spp),
                    seed: 1000 + seed,
                    progress: false,
                    label: String::new(),
                },
            );
            assert_eq!(r.counters.capped + r.counters.leaks, 0, "{:?}", r.counters);
            r.pixels.iter().map(|p| p[0]).sum::<f64>() / r.pixels.len() as f64
        })
        .collect();
    let m = means.iter().sum::<f64>() / seeds as f64;
    let var = means.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (seeds - 1) as f64;
    (m, (var / seeds as f64).sqrt())
}

#[test]
fn path_tracer_emergent_radiance_matches_chandrasekhar() {
    // Radiance toward +z from an index-matched isotropic half-space; next-event estimation
    // through the boundary, the scattering-order switch and delta tracking all take part.
    for (omega, light_to) in [(0.9, DVec3::Z), (0.99, DVec3::new(0.6, 0.0, 0.8))] {
        let mu0 = light_to.normalize().z;
        let scene = half_space_scene(1.0 - omega, omega, light_to, 1.0);
        let (all, single) = emergent_radiance(omega, 1.0, mu0);
        for (scattering, want) in [
            (Scattering::All, all),
            (Scattering::Single, single),
            (Scattering::Multiple, all - single),
        ] {
            let (m, se) = mean_and_se(&scene, Method::PathTraced, scattering, 256, 8);
            assert!(
                (m - want).abs() < 4.0 * se,
                "ϖ={omega} μ0={mu0} {scattering}: {m} ± {se}, exact {want}"
            );
            assert!(se < 0.02 * want, "test too weak: se {se}");
        }
    }
}

#[test]
fn bssrdf_render_of_a_homogeneous_half_space_matches_the_profile_total() {
    // Under uniform normal irradiance E = 1 on an index-matched half-space, the BSSRDF renderer
    // computes L = (1/π) ∫ R(r) E dA = ρ_tot/π, where ρ_tot is the profile's total. The probe
    // only reaches r < r_max (99.9 % of the energy of the sampling profile), so the render may
    // fall short by at most ~0.1 %.
    let (sigma_a, sigma_s) = (0.05, 1.0);
    let scene = half_space_scene(sigma_a, sigma_s, DVec3::Z, 1.0);
    for model in [ProfileModel::Dipole, ProfileModel::Pbd] {
        let family = ProfileFamily::new(model, Scattering::Multiple, 0.0, 1.0).unwrap();
        let want = family.profile(sigma_a, sigma_s).unwrap().total() / std::f64::consts::PI;
        for name in ["jensen-out", "sone"] {
            let estimator: Estimator = name.parse().unwrap();
            let method = Method::Bssrdf {
                estimator,
                profile: Some(model),
            };
            let (m, se) = mean_and_se(&scene, method, Scattering::Multiple, 64, 8);
            let tol = 4.0 * se + 1.5e-3 * want;
            assert!(
                (m - want).abs() < tol,
                "{model} {name}: {m} ± {se}, predicted {want}"
            );
            assert!(se < 0.02 * want, "test too weak: se {se}");
        }
    }
}

#[test]
fn renders_are_identical_whatever_the_thread_count() {
    let scene = Scene::from_toml_str(
        include_str!("../examples/scenes/checker-slab.toml"),
        std::path::Path::new("examples/scenes"),
        "checker-slab.toml",
    )
    .unwrap();
    let small = |threads: usize, method: Method| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let integrator = PathIntegrator::new(
            &scene,
            method,
            PathOptions {
                scattering: Scattering::Multiple,
                max_depth: 8,
            },
        )
        .unwrap();
        pool.install(|| {
            render(
                128,
                128,
                &integrator,
                &RenderOptions {
                    budget: Budget::Samples(2),
                    seed: 9,
                    progress: false,
                    label: String::new(),
                },
            )
        })
    };
    for method in [Method::PathTraced, "sone".parse().unwrap()] {
        let a = small(1, method);
        let b = small(2, method);
        assert!(a.pixels.iter().any(|p| p[0] > 0.0));
        assert!(
            a.pixels == b.pixels,
            "{} differs between 1 and 2 threads",
            method.name()
        );
        assert_eq!(a.counters, b.counters);
    }
}

#[test]
fn probe_sampling_density_integrates_to_its_success_probability_on_a_sphere() {
    // On a convex closed mesh every probe chord crosses it exactly twice, so the density of
    // the returned x_i is probe_density/2 and its integral over the surface must equal the
    // fraction of probes that succeed. The integral is estimated independently by shooting
    // rays from the centre (solid-angle sampling: area density cos α / (4π |x|²)). The sphere
    // is small against the mean free path so that every projection axis, including the
    // tangents, contributes.
    use tracer::integrator::probe::{ProbeSampler, probe_density, sample_probe};
    use tracer::rng::Rng;
    let medium = MediumField::homogeneous(Coefficients::grey(0.2, 2.0)).unwrap();
    let scene = SceneBuilder::new(
        RenderSettings::new(1, 1, 1),
        Camera::orthographic(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::NEG_Z,
            DVec3::Y,
            1.0,
            1.0,
            1,
            1,
        )
        .unwrap(),
    )
    .object(
        "ball",
        primitives::icosphere(DVec3::ZERO, 1.0, 4),
        Material::Translucent(Translucent::new("m", medium.clone(), 0.0, 1.0)),
    )
    .build()
    .unwrap();
    let family = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.0).unwrap();
    let sampler = ProbeSampler::new(family, &medium);
    let c = Coefficients::grey(0.2, 2.0);
    let x_o = scene
        .geometry
        .intersect(&tracer::geometry::Ray::new(
            DVec3::new(0.1, 0.2, 5.0),
            DVec3::NEG_Z,
        ))
        .unwrap();
    let mut rng = Rng::from_keys(77, &[]);
    let n = 400_000;
    let mut successes = 0u64;
    let mut two_hit_pdf_sum = 0.0;
    for _ in 0..n {
        if let Some(s) = sample_probe(&scene.geometry, 0, &x_o, c, &sampler, &mut rng) {
            successes += 1;
            // The returned pdf is probe_density / n_hits with n_hits = 2.
            two_hit_pdf_sum += s.pdf * 2.0 / probe_density(&x_o, c, &sampler, &s.hit);
        }
    }
    let p = successes as f64 / n as f64;
    let p_se = (p * (1.0 - p) / n as f64).sqrt();
    assert!(
        (two_hit_pdf_sum / successes as f64 - 1.0).abs() < 1e-3,
        "chords with ≠ 2 hits"
    );
    let m = 400_000;
    let (mut s, mut s2) = (0.0, 0.0);
    for _ in 0..m {
        let [u1, u2] = rng.uniform2();
        let z = 1.0 - 2.0 * u1;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let d = DVec3::new(
            r * (std::f64::consts::TAU * u2).cos(),
            r * (std::f64::consts::TAU * u2).sin(),
            z,
        );
        let hit = scene
            .geometry
            .intersect(&tracer::geometry::Ray::new(DVec3::ZERO, d))
            .unwrap();
        let area_pdf = d.dot(hit.ng).abs() / (4.0 * std::f64::consts::PI * hit.t * hit.t);
        let v = probe_density(&x_o, c, &sampler, &hit) / 2.0 / area_pdf;
        s += v;
        s2 += v * v;
    }
    let integral = s / m as f64;
    let i_se = ((s2 / m as f64 - integral * integral) / m as f64).sqrt();
    let se = p_se.hypot(i_se);
    assert!(p > 0.5, "success fraction {p}");
    assert!(
        (p - integral).abs() < 4.0 * se,
        "success {p} ± {p_se}, ∫pdf {integral} ± {i_se}"
    );
}
