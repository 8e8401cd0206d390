//! The reference path tracer around an index-matched (η = 1) sphere standing on a diffuse
//! floor under a uniform environment light: light that crosses the sphere without scattering
//! is reached both by next-event estimation from the floor (ratio-tracked shadow ray) and by
//! the cosine-sampled continuation (a walk that passes straight through). Both strategies must
//! weight it by MIS and classify its scattering order identically (`docs/physics.md#path-tracer`).

use bssrdf_core::{Rgb, Scattering};
use glam::DVec3;
use het_estimate::Coefficients;
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::primitives;
use tracer::integrator::Method;
use tracer::light::Light;
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

use crate::common::half_space::mean_and_se;

/// Sphere radius and the height of its centre above the floor z = 0.
const RADIUS: f64 = 1.0;
const HEIGHT: f64 = 1.2;
/// The camera sees the floor patch [X0, X0 + SIDE] × [−SIDE/2, SIDE/2] beside the sphere.
const X0: f64 = 1.1;
const SIDE: f64 = 0.6;

/// The sphere (coefficients `sigma_a`, `sigma_s`, isotropic, η = 1) on a floor of albedo
/// `albedo`, seen from straight above over a patch that does not lie under the sphere, so
/// every camera ray meets the floor first.
fn floor_and_sphere(sigma_a: f64, sigma_s: f64, albedo: f64) -> Scene {
    let n = 4;
    let camera = Camera::orthographic(
        DVec3::new(X0 + 0.5 * SIDE, 0.0, 0.01),
        DVec3::NEG_Z,
        DVec3::Y,
        SIDE,
        SIDE,
        n,
        n,
    )
    .unwrap();
    let medium = MediumField::homogeneous(Coefficients::grey(sigma_a, sigma_s)).unwrap();
    let big = 1000.0;
    SceneBuilder::new(RenderSettings::new(n, n, 1), camera)
        .light(Light::environment(Rgb::ONE).unwrap())
        .object(
            "floor",
            primitives::quad(
                DVec3::new(-big, -big, 0.0),
                DVec3::new(2.0 * big, 0.0, 0.0),
                DVec3::new(0.0, 2.0 * big, 0.0),
            ),
            Material::diffuse(Rgb::splat(albedo)),
        )
        .object(
            "sphere",
            primitives::icosphere(DVec3::new(0.0, 0.0, HEIGHT), RADIUS, 5),
            Material::Translucent(Translucent::new("m", medium, 0.0, 1.0)),
        )
        .build()
        .unwrap()
}

/// The view factor from a floor point at horizontal distance `d` from the sphere's centre to
/// the sphere (wholly above the floor): F = R² h / D³ with D² = d² + h², i.e. the cosine-
/// weighted fraction (1/π)∫cos θ dω of the hemisphere the sphere covers.
fn view_factor(d: f64) -> f64 {
    let dd = (d * d + HEIGHT * HEIGHT).sqrt();
    RADIUS * RADIUS * HEIGHT / (dd * dd * dd)
}

/// The mean of `f(d)` over the camera's floor patch (midpoint rule, 400 × 400 points).
fn patch_mean(f: impl Fn(f64) -> f64) -> f64 {
    let m = 400;
    let mut s = 0.0;
    for i in 0..m {
        for j in 0..m {
            let x = X0 + SIDE * (i as f64 + 0.5) / m as f64;
            let y = SIDE * ((j as f64 + 0.5) / m as f64 - 0.5);
            s += f((x * x + y * y).sqrt());
        }
    }
    s / (m * m) as f64
}

#[test]
fn light_through_an_index_matched_sphere_is_counted_once() {
    // White furnace: a non-absorbing sphere and a white floor under unit environment radiance
    // leave the radiance 1 everywhere. Counting the unscattered light through the sphere by
    // both strategies at full weight pushes the floor above 1 (by ≈ 2 % here).
    let scene = floor_and_sphere(0.0, 0.3, 1.0);
    let (m, se) = mean_and_se(&scene, Method::PathTraced, Scattering::All, 1024, 8);
    assert!(
        (m - 1.0).abs() < 4.0 * se,
        "furnace floor {m} ± {se}, exact 1"
    );
    assert!(se < 2e-3, "test too weak: se {se}");
}

#[test]
fn unscattered_light_through_a_medium_is_excluded_by_both_strategies() {
    // A purely absorbing sphere never scatters, so under `multiple` (or `single`) every light
    // path that crosses it is excluded, whichever strategy found it. What is left is the sky
    // the floor sees directly: ρ (1 − F) with F the sphere's view factor (floor–sphere–floor
    // paths all cross the sphere).
    let albedo = 0.8;
    let scene = floor_and_sphere(0.7, 0.0, albedo);
    let want = albedo * patch_mean(|d| 1.0 - view_factor(d));
    for scattering in [Scattering::Multiple, Scattering::Single] {
        let (m, se) = mean_and_se(&scene, Method::PathTraced, scattering, 1024, 8);
        assert!(
            (m - want).abs() < 4.0 * se + 1e-4,
            "{scattering}: floor {m} ± {se}, exact {want}"
        );
        assert!(se < 2e-3, "test too weak: se {se}");
    }
    // Under `all` the same scene sees the sphere's transmitted light as well.
    let (m, se) = mean_and_se(&scene, Method::PathTraced, Scattering::All, 1024, 8);
    assert!(m > want + 4.0 * se, "all: {m} ± {se} should exceed {want}");
}
