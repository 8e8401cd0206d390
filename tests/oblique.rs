//! Light arriving at an angle (docs/oblique-incidence.md): under the 4 × 4 quad of
//! docs/shapes.md, 3 units above a half-space (σa 0.01, σs 1, η 1), most of the light the
//! view receives entered obliquely. With the oblique shape (`oblique_shape`, on by default
//! beside the angular coupling) the BSSRDF render must be within 3 % (+ 3 SE) of the path
//! tracer; without the coupling and the shape it is 1.15× (docs/tabulated-profile.md), which
//! the test must tell apart. Under a distant light with the view oblique too, both sides'
//! factors act at once and their product must keep the totals.

use bssrdf_core::glam::DVec3;
use bssrdf_core::{ProfileModel, Rgb};
use het_estimate::Coefficients;
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::primitives;
use tracer::integrator::Method;
use tracer::light::Light;
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

use crate::common::harness::render_multiple;
use crate::common::shapes::{bssrdf, mean_se, ratio};

/// The half-space under the quad, seen over the quad's footprint (8 × 8 pixels); with
/// `sky`, under a uniform sky too.
fn quad_scene(coupled: bool, sky: bool) -> Scene {
    let field = MediumField::homogeneous(Coefficients::grey(0.01, 1.0)).unwrap();
    let camera = Camera::orthographic(DVec3::Z, DVec3::NEG_Z, DVec3::Y, 4.0, 4.0, 8, 8).unwrap();
    let mut builder = SceneBuilder::new(RenderSettings::new(8, 8, 1), camera);
    if sky {
        builder = builder.light(Light::environment(Rgb::splat(0.3)).unwrap());
    }
    builder
        .light(
            // 4 × 4, emitting downward (edge_u × edge_v = −z).
            Light::quad(
                DVec3::new(-2.0, -2.0, 3.0),
                DVec3::new(0.0, 4.0, 0.0),
                DVec3::new(4.0, 0.0, 0.0),
                Rgb::ONE,
            )
            .unwrap(),
        )
        .object(
            "half-space",
            primitives::half_space(0.0, [0.0, 0.0], 400.0, 200.0, 40),
            Material::Translucent(Translucent {
                angular_coupling: coupled,
                oblique_shape: coupled,
                ..Translucent::new("m", field, 0.0, 1.0)
            }),
        )
        .build()
        .unwrap()
}

/// Image means (red channel) over `seeds`, mean and standard error.
fn measure(scene: &Scene, method: Method, spp: u32, seeds: std::ops::Range<u64>) -> (f64, f64) {
    mean_se(seeds.map(|seed| {
        let r = render_multiple(scene, method, 8, spp, seed);
        let c = r.counters;
        assert!(c.capped == 0 && c.leaks * 10_000 <= c.paths, "{c:?}");
        r.pixels.iter().map(|p| p[0]).sum::<f64>() / r.pixels.len() as f64
    }))
}

#[test]
fn quad_over_a_half_space_matches_the_path_tracer() {
    let pt = measure(&quad_scene(true, false), Method::PathTraced, 512, 0..4);
    let method = bssrdf(ProfileModel::Tabulated);
    let (q_on, se_on) = ratio(measure(&quad_scene(true, false), method, 128, 10..14), pt);
    let (q_off, se_off) = ratio(measure(&quad_scene(false, false), method, 128, 10..14), pt);
    eprintln!(
        "quad: BSSRDF/PT {q_on:.3} ± {se_on:.3}, without the coupling {q_off:.3} ± {se_off:.3}"
    );
    assert!(
        se_on < 0.01 && se_off < 0.01,
        "test too weak: ± {se_on}, ± {se_off}"
    );
    assert!(
        (q_on - 1.0).abs() < 0.03 + 3.0 * se_on,
        "with the oblique shape: BSSRDF/PT {q_on:.3} ± {se_on:.3}"
    );
    assert!(
        (q_off - 1.0).abs() > 0.03 + 3.0 * se_off,
        "without it the test cannot fail: BSSRDF/PT {q_off:.3} ± {se_off:.3}"
    );
}

/// The probes lean toward the light sample next-event estimation takes at every x_i, drawn
/// first: one of two lights (the quad and a uniform sky), a point on the quad or a direction
/// of the sky. The render must stay within 3 % (+ 3 SE) of the path tracer: the light sample
/// is shared by every x_i of a probe set and chosen before them, which is unbiased only if
/// the probes' density is the one given that sample and the sample's own weight is the light's.
#[test]
fn quad_and_sky_with_the_light_sample_drawn_first() {
    let pt = measure(&quad_scene(true, true), Method::PathTraced, 512, 0..4);
    let method = bssrdf(ProfileModel::Tabulated);
    let (q, se) = ratio(measure(&quad_scene(true, true), method, 128, 10..14), pt);
    eprintln!("quad and sky: BSSRDF/PT {q:.3} ± {se:.3}");
    assert!(se < 0.01, "test too weak: ± {se}");
    assert!(
        (q - 1.0).abs() < 0.03 + 3.0 * se,
        "BSSRDF/PT {q:.3} ± {se:.3}"
    );
}

/// A half-space (σa 0.1, σs 0.9, η 1) under a directional light 60° from the normal, seen
/// 60° from the normal on the light's side (`same_side`) or on the far side, over a
/// 0.5 × 0.5 patch (4 × 4 pixels), with the oblique shape.
fn distant_scene(same_side: bool) -> Scene {
    let field = MediumField::homogeneous(Coefficients::grey(0.1, 0.9)).unwrap();
    let t = 60f64.to_radians();
    let towards = DVec3::new(t.sin(), 0.0, t.cos()); // from the surface to the light
    let eye = DVec3::new(if same_side { t.sin() } else { -t.sin() }, 0.0, t.cos());
    let camera = Camera::orthographic(eye, -eye, DVec3::Y, 0.5, 0.5, 4, 4).unwrap();
    SceneBuilder::new(RenderSettings::new(4, 4, 1), camera)
        .light(Light::directional(-towards, Rgb::ONE).unwrap())
        .object(
            "half-space",
            primitives::half_space(0.0, [0.0, 0.0], 400.0, 200.0, 40),
            Material::Translucent(Translucent {
                oblique_shape: true,
                ..Translucent::new("m", field, 0.0, 1.0)
            }),
        )
        .build()
        .unwrap()
}

/// With the light and the view both 60° off the normal, the path tracer sees the same exitance
/// on the light's side and on the far side, and the BSSRDF render must be within 3 % (+ 3 SE)
/// of it on both. Normalising each side's factor on its own left their product's cross term in
/// the totals: 0.74 of the path tracer on the light's side, 1.38 on the far side.
#[test]
fn light_and_view_both_oblique_keep_the_totals() {
    let method = bssrdf(ProfileModel::Tabulated);
    for same_side in [true, false] {
        let scene = distant_scene(same_side);
        let pt = measure(&scene, Method::PathTraced, 1024, 0..4);
        let (q, se) = ratio(measure(&scene, method, 256, 10..14), pt);
        eprintln!("light 60°, view 60° (same side: {same_side}): BSSRDF/PT {q:.3} ± {se:.3}");
        assert!(se < 0.01, "test too weak: ± {se}");
        assert!(
            (q - 1.0).abs() < 0.03 + 3.0 * se,
            "same side {same_side}: BSSRDF/PT {q:.3} ± {se:.3}"
        );
    }
}
