//! The BSSRDF renderer against the path tracer beyond half-spaces (issue 18): slabs, spheres
//! and a box corner, homogeneous, g = 0, multiple scattering, uniform environment light,
//! orthographic view, tabulated profile with the slab profile on thin parts (the default;
//! `tests/common/shapes.rs` has the set-up;
//! `examples/shapes.rs` prints the whole table with more samples).
//!
//! Each case is the double ratio q = (BSSRDF/PT on the shape) / (BSSRDF/PT on the
//! half-space), with its standard error over 4 fixed seeds (8 for the box corner).
//! * The `shapes_*` tests validate: the half-space profile is good enough for each of their
//!   cases, |q − 1| < 0.15 (+ 3 SE; the SE must be below 3 % of q, and is 0.5–2.7 % at these
//!   samples, so the window is about ±17–23 %).
//! * The `regression_guard_*` tests do not: they hold the cases that are still outside 15 %
//!   (small and curved bodies lose or gain light; docs/shapes.md) to the value q0 that
//!   `examples/shapes.rs` measured (8 seeds, 4–16× these samples), ±10 % (+ 3 SE), so that a
//!   change that makes such a case worse, or better, fails and gets looked at. They are
//!   regression guards of today's numbers, not evidence for any claim.
//!
//! The half-space ratio itself (the tabulated profile's own error) must be within 5 %; the
//! profile's own error on anisotropic half-spaces is `anisotropic_half_spaces_match_the_path_tracer`'s.
//!
//! The `shapes_corrected_*` cases turn the material's `shape_correction` on
//! (docs/shapes.md, "The shape correction").

use bssrdf_core::ProfileModel;
use tracer::integrator::Method;

use crate::common::harness::{bunny_path, shared_bunny};
use crate::common::shapes::{
    Medium, Shape, bssrdf, mean_se, measure, outside_light, ratio, shape_scene_material,
    shape_scene_with,
};

/// Accepted tolerance of one case.
#[derive(Debug, Clone, Copy)]
enum Tolerance {
    /// |q − 1| < 0.15: validation.
    Within15,
    /// A measured q0 (outside 15 %): q within ±10 % of it. A regression guard, not validation;
    /// only the `regression_guard_*` tests use it.
    RegressionGuard(f64),
}

const SEEDS: u64 = 4;

/// Light through the medium (mean, SE) for the path tracer and the tabulated BSSRDF.
/// `corrected`: the material's `shape_correction` is on (the path tracer ignores it).
fn pair(shape: Shape, medium: Medium, seed0: u64, corrected: bool) -> ((f64, f64), (f64, f64)) {
    // The bunny's path is read only by `Shape::Bunny`.
    let scene = shape_scene_with(shape, medium, &bunny_path(), true, corrected);
    let outside = outside_light(&scene, medium.eta, 16);
    let (spp_pt, spp_b) = if shape.pixels() <= 4 {
        (1024, 256)
    } else {
        (64, 16)
    };
    // The box corner's light comes from long paths near three faces: its standard error over
    // 4 seeds scatters about 3 % of q, so it takes twice the seeds.
    let n_seeds = if shape == Shape::BoxCorner {
        2 * SEEDS
    } else {
        SEEDS
    };
    let seeds = seed0..seed0 + n_seeds;
    let pt = measure(&scene, Method::PathTraced, outside, spp_pt, seeds.clone());
    let b = measure(
        &scene,
        bssrdf(ProfileModel::Tabulated),
        outside,
        spp_b,
        seeds,
    );
    (
        mean_se(pt.iter().map(|s| s.through)),
        mean_se(b.iter().map(|s| s.through)),
    )
}

fn check(medium: Medium, cases: &[(Shape, Tolerance)], seed0: u64) {
    check_with(medium, cases, seed0, false)
}

fn check_with(medium: Medium, cases: &[(Shape, Tolerance)], seed0: u64, corrected: bool) {
    let (pt_hs, b_hs) = pair(Shape::HalfSpace, medium, seed0, corrected);
    let hs = ratio(b_hs, pt_hs);
    assert!(
        (hs.0 - 1.0).abs() < 0.05 + 4.0 * hs.1,
        "{}: half-space BSSRDF/PT {:.3} ± {:.3}",
        medium.label(),
        hs.0,
        hs.1
    );
    let mut failures = Vec::new();
    for (k, &(shape, tol)) in cases.iter().enumerate() {
        let (pt, b) = pair(shape, medium, seed0 + 100 * (k as u64 + 1), corrected);
        let (q, se) = ratio(ratio(b, pt), hs);
        eprintln!("{} {}: q = {q:.3} ± {se:.3}", medium.label(), shape.label());
        assert!(se < 0.03 * q, "test too weak: {} {q} ± {se}", shape.label());
        let ok = match tol {
            Tolerance::Within15 => (q - 1.0).abs() < 0.15 + 3.0 * se,
            Tolerance::RegressionGuard(q0) => (q - q0).abs() < 0.1 * q0 + 3.0 * se,
        };
        if !ok {
            failures.push(format!("{}: q = {q:.3} ± {se:.3}, {tol:?}", shape.label()));
        }
    }
    assert!(failures.is_empty(), "{}: {failures:#?}", medium.label());
}

use Tolerance::{RegressionGuard, Within15};

#[test]
fn shapes_index_matched_albedo_0_9() {
    check(
        Medium::new(0.9, 1.0),
        &[
            (Shape::Slab(0.5), Within15),
            (Shape::Slab(2.0), Within15),
            (Shape::Sphere(1.0), Within15),
            (Shape::Sphere(10.0), Within15),
        ],
        10_000,
    );
}

#[test]
fn shapes_index_matched_albedo_0_99() {
    check(
        Medium::new(0.99, 1.0),
        &[
            (Shape::Slab(0.5), Within15),
            (Shape::Slab(2.0), Within15),
            (Shape::Sphere(1.0), Within15),
            (Shape::Sphere(10.0), Within15),
            (Shape::BoxCorner, Within15),
        ],
        20_000,
    );
}

#[test]
fn shapes_refractive_albedo_0_9() {
    check(
        Medium::new(0.9, 1.3),
        &[(Shape::Slab(0.5), Within15), (Shape::Slab(2.0), Within15)],
        30_000,
    );
}

#[test]
fn shapes_refractive_albedo_0_99() {
    check(
        Medium::new(0.99, 1.3),
        &[(Shape::Slab(0.5), Within15), (Shape::Slab(2.0), Within15)],
        40_000,
    );
}

/// Regression guards, not validation (module docs): the cases of the four g = 0 columns that
/// are still outside 15 % without the shape correction.
#[test]
fn regression_guard_shapes_outside_15_percent() {
    check(
        Medium::new(0.9, 1.0),
        &[(Shape::BoxCorner, RegressionGuard(0.81))],
        10_500,
    );
    check(
        Medium::new(0.9, 1.3),
        &[
            (Shape::Sphere(1.0), RegressionGuard(0.47)),
            (Shape::Sphere(10.0), RegressionGuard(0.81)),
            (Shape::BoxCorner, RegressionGuard(0.64)),
        ],
        30_500,
    );
    check(
        Medium::new(0.99, 1.3),
        &[
            (Shape::Sphere(1.0), RegressionGuard(0.53)),
            (Shape::Sphere(10.0), RegressionGuard(0.82)),
            (Shape::BoxCorner, RegressionGuard(0.81)),
        ],
        40_500,
    );
}

/// With the shape correction (`shape_correction = true`, docs/shapes.md "The shape
/// correction"): the column the half-space assumption served worst (spheres 0.47 and 0.81, the
/// corner 0.64 without it) comes within 15 %.
#[test]
fn shapes_corrected_refractive_albedo_0_9() {
    check_with(
        Medium::new(0.9, 1.3),
        &[
            (Shape::Slab(0.5), Within15),
            (Shape::Sphere(1.0), Within15),
            (Shape::Sphere(10.0), Within15),
            (Shape::BoxCorner, Within15),
        ],
        50_000,
        true,
    );
}

/// With the shape correction at η 1, ϖ 0.9: the thin slab, the sphere of radius 10 (0.88
/// without it) and the box corner (0.81 without it) within 15 % (the sphere of radius 1, 0.96,
/// is too noisy at these samples for the test's 3 % bound).
#[test]
fn shapes_corrected_index_matched_albedo_0_9() {
    check_with(
        Medium::new(0.9, 1.0),
        &[
            (Shape::Slab(0.5), Within15),
            (Shape::Sphere(10.0), Within15),
            (Shape::BoxCorner, Within15),
        ],
        60_000,
        true,
    );
}

/// With the shape correction at η 1.3, ϖ 0.99: the spheres and the corner (0.53, 0.81 and
/// 0.81 without it) within 15 %.
#[test]
fn shapes_corrected_refractive_albedo_0_99() {
    check_with(
        Medium::new(0.99, 1.3),
        &[
            (Shape::Sphere(1.0), Within15),
            (Shape::Sphere(10.0), Within15),
            (Shape::BoxCorner, Within15),
        ],
        80_000,
        true,
    );
}

/// With the shape correction, the bunny (about 9 mfp tall, ears and paws 1–2 mfp across) in
/// all four columns within 15 % (0.87, 1.10, 0.65, 0.86 without it). Needs the shared asset
/// `../shared/assets/bunny.obj`; skipped with a note where it is absent, and an error in CI.
#[test]
fn shapes_corrected_bunny() {
    if shared_bunny().is_none() {
        return;
    }
    for (k, medium) in Medium::COLUMNS.iter().enumerate() {
        check_with(
            *medium,
            &[(Shape::Bunny, Within15)],
            90_000 + 1_000 * k as u64,
            true,
        );
    }
}

/// The tabulated profile's angular coupling (docs/tabulated-profile.md, "Angular coupling"):
/// a half-space at η 1, ϖ 0.9 seen at μ = 0.3 under a uniform sky. With the separable Fresnel
/// lobes alone the BSSRDF gives 0.89 of the path tracer there (`examples/shapes.rs --
/// --oblique`); with the coupling (the default) it must be within 4 % (+ 3 SE), and without it
/// (`angular_coupling = false`) it must not be, so that the test can fail.
#[test]
fn angular_coupling_makes_an_oblique_half_space_exact() {
    let medium = Medium::new(0.9, 1.0);
    let bunny = std::path::Path::new("unused");
    let seeds = 70_000..70_000 + SEEDS;
    let scene = |coupled: bool| {
        shape_scene_material(Shape::Oblique(0.3), medium, bunny, |m| {
            tracer::scene::Translucent {
                angular_coupling: coupled,
                ..m
            }
        })
    };
    let on = scene(true);
    let outside = outside_light(&on, medium.eta, 16);
    let pt = mean_se(
        measure(&on, Method::PathTraced, outside, 2048, seeds.clone())
            .iter()
            .map(|s| s.through),
    );
    let through = |scene: &tracer::scene::Scene| {
        mean_se(
            measure(
                scene,
                bssrdf(ProfileModel::Tabulated),
                outside,
                256,
                seeds.clone(),
            )
            .iter()
            .map(|s| s.through),
        )
    };
    let (q_on, se_on) = ratio(through(&on), pt);
    let (q_off, se_off) = ratio(through(&scene(false)), pt);
    eprintln!(
        "oblique half-space: BSSRDF/PT {q_on:.3} ± {se_on:.3} coupled, {q_off:.3} ± {se_off:.3} not"
    );
    assert!(
        se_on < 0.02 && se_off < 0.02,
        "test too weak: ± {se_on}, ± {se_off}"
    );
    assert!(
        (q_on - 1.0).abs() < 0.04 + 3.0 * se_on,
        "with the coupling: BSSRDF/PT {q_on:.3} ± {se_on:.3}"
    );
    assert!(
        (q_off - 1.0).abs() > 0.04 + 3.0 * se_off,
        "without the coupling the test cannot fail: BSSRDF/PT {q_off:.3} ± {se_off:.3}"
    );
}

/// What "multiple" means at g ≠ 0, and the totals the tabulated profile takes for it
/// (issue 38; docs/tabulated-profile.md, "Anisotropic scattering"): homogeneous half-spaces
/// under a uniform sky, seen along the normal, BSSRDF/PT within 3 % (+ 3 SE) for multiple
/// scattering alone and for all orders. Under a uniform sky the angular coupling's
/// normalisation makes the BSSRDF image the profile's total, so this checks the totals
/// against the path tracer's Henyey–Greenstein transport. Before, the tabulated profile's
/// multiple scattering was the similar isotropic medium's (0.72 of the path tracer's at g 0.6,
/// η 1, ϖ 0.9), and its total the similar medium's (1.13× at g 0.6, η 1.3, ϖ 0.9).
#[test]
fn anisotropic_half_spaces_match_the_path_tracer() {
    use bssrdf_core::Scattering;

    use crate::common::shapes::measure_orders;
    let bunny = std::path::Path::new("unused");
    let mut failures = Vec::new();
    // (g, η, ϖ, orders, path tracer's samples per pixel: more where its noise is larger)
    for (k, (g, eta, albedo, scattering, spp_pt)) in [
        (0.6, 1.0, 0.9, Scattering::Multiple, 1024),
        (0.6, 1.3, 0.9, Scattering::All, 4096),
        (0.3, 1.3, 0.99, Scattering::Multiple, 1024),
    ]
    .into_iter()
    .enumerate()
    {
        let medium = Medium {
            g,
            ..Medium::new(albedo, eta)
        };
        let scene = shape_scene_with(Shape::HalfSpace, medium, bunny, true, false);
        let outside = outside_light(&scene, eta, 16);
        let seeds = 110_000 + 10 * k as u64..110_004 + 10 * k as u64;
        let through = |method, spp| {
            let s = measure_orders(&scene, method, scattering, outside, spp, seeds.clone());
            mean_se(s.iter().map(|s| s.through))
        };
        let pt = through(Method::PathTraced, spp_pt);
        let b = through(bssrdf(ProfileModel::Tabulated), 256);
        let (q, se) = ratio(b, pt);
        eprintln!(
            "{} {scattering}: BSSRDF/PT {q:.4} ± {se:.4}",
            medium.label()
        );
        assert!(se < 0.01, "test too weak: {} ± {se}", medium.label());
        if (q - 1.0).abs() >= 0.03 + 3.0 * se {
            failures.push(format!("{} {scattering}: {q:.4} ± {se:.4}", medium.label()));
        }
    }
    assert!(failures.is_empty(), "BSSRDF/PT: {failures:#?}");
}
