//! The path tracer inside a UV-painted body (issue 37): the medium there is the texture at the
//! texture coordinates of the nearest surface point (`MediumField::with_interior`).

use std::sync::Arc;

use bssrdf_core::{Rgb, Scattering};
use glam::{DVec2, DVec3};
use tracer::camera::Camera;
use tracer::field::{
    Axis, Field, Filter, ImageMapping, MediumField, PlanarProjection, Texture, Wrap,
};
use tracer::geometry::primitives;
use tracer::integrator::{Method, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

/// A 20 × 20 × 1 slab whose σa is an 8 × 8 random texture over 8 × 8 units, either projected
/// along z or read through texture coordinates equal to that projection on every face, seen
/// from above on its middle 6 × 6.
fn slab(uv: bool) -> Scene {
    let (lo, hi) = (DVec3::new(-10.0, -10.0, -1.0), DVec3::new(10.0, 10.0, 0.0));
    let mut mesh = primitives::subdivided_cuboid(lo, hi, [20, 20, 1]);
    let size = 8.0;
    // The planar projection's image coordinates (s/W + ½, ½ − t/H, rows down) as (u, 1 − v).
    mesh.uvs = Some(
        mesh.positions
            .iter()
            .map(|p| DVec2::new(p.x / size + 0.5, p.y / size + 0.5).as_vec2())
            .collect(),
    );
    let texels: Vec<[f32; 3]> = (0..64u32)
        .map(|k| {
            let v = 0.02 + 0.5 * ((k.wrapping_mul(2_654_435_761) >> 7) % 1000) as f32 / 1000.0;
            [v, 0.5 * v, 0.1]
        })
        .collect();
    let texture = Arc::new(Texture::from_texels("random", 8, 8, texels).unwrap());
    let mapping = if uv {
        ImageMapping::Uv
    } else {
        ImageMapping::Planar {
            projection: PlanarProjection::new(Axis::Z, DVec3::ZERO),
            size: [size, size],
        }
    };
    let sigma_a = Field::image(texture, mapping, Wrap::Repeat, Filter::Nearest, Rgb::ONE).unwrap();
    let medium = MediumField::new(sigma_a, Field::constant(Rgb::splat(2.0)).unwrap());
    let camera = Camera::orthographic(
        DVec3::new(0.0, 0.0, 2.0),
        DVec3::NEG_Z,
        DVec3::Y,
        6.0,
        6.0,
        12,
        12,
    )
    .unwrap();
    SceneBuilder::new(RenderSettings::new(12, 12, 1), camera)
        .light(Light::environment(Rgb::ONE).unwrap())
        .object(
            "slab",
            mesh,
            Material::Translucent(Translucent::new("m", medium, 0.0, 1.0)),
        )
        .build()
        .unwrap()
}

/// The UV-mapped slab path-traces to the planar-projected slab's image (the same paths: both
/// media agree everywhere a path goes but within a unit of the far sides), and it is not
/// refused.
#[test]
fn a_uv_map_equal_to_a_planar_projection_renders_the_same_image() {
    let (planar, uv) = (slab(false), slab(true));
    assert!(uv.require_path_traceable().is_ok());
    let options = PathOptions {
        scattering: Scattering::All,
        max_depth: 16,
    };
    let image = |s: &Scene| {
        let integrator = PathIntegrator::new(s, Method::PathTraced, options).unwrap();
        render(12, 12, &integrator, &RenderOptions::samples(16, 5)).pixels
    };
    let (a, b) = (image(&planar), image(&uv));
    let (mut diff, mut norm) = (0.0, 0.0);
    for (p, q) in a.iter().zip(&b) {
        for c in 0..3 {
            diff += (p[c] - q[c]).powi(2);
            norm += p[c].powi(2);
        }
    }
    let rel = (diff / norm).sqrt();
    assert!(rel < 1e-3, "relative L2 {rel}");
    // The texture shows in the image (the comparison is not of two flat images).
    let reds: Vec<f64> = a.iter().map(|p| p[0]).collect();
    let spread = reds.iter().cloned().fold(0.0, f64::max)
        - reds.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(spread > 0.05, "the texture shows: red spread {spread}");
}

/// Inside the body the medium is the texture at the nearest surface point: below the middle of
/// the top face it is the top's texel; near a side, the side's.
#[test]
fn the_interior_reads_the_nearest_surface_point() {
    let s = slab(true);
    let Material::Translucent(t) = &s.objects()[0].material else {
        panic!("translucent");
    };
    let medium = t.medium.clone().with_interior(s.geometry().mesh(0));
    assert!(medium.is_path_traceable() && !medium.is_volumetric());
    let planar = slab(false);
    let Material::Translucent(p) = &planar.objects()[0].material else {
        panic!("translucent");
    };
    for (x, y) in [(0.3, 0.2), (-2.7, 1.9), (3.3, -3.9)] {
        let inside = DVec3::new(x, y, -0.3);
        assert_eq!(
            medium.at_point(inside).sigma_a,
            p.medium.at_point(inside).sigma_a,
            "({x}, {y})"
        );
    }
}
