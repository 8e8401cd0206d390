//! Light arriving at an angle (issue 43): the BSSRDF renderer (tabulated profile, its default
//! angular coupling) against the path tracer on a homogeneous half-space (σt = 1, g = 0; a
//! 400 × 400 × 200 box) lit
//!
//! * by a distant light at 0°, 30°, 60° and 80° from the normal, seen along the normal on a
//!   0.5 × 0.5 patch (4 × 4 pixels; at 0° with η ≠ 1 seen 20° off the normal, so that the
//!   light's mirror image is out of view). At η = 1 it is a directional light (irradiance 1 across
//!   its direction). At η ≠ 1 the path tracer cannot reach a delta light through a refractive
//!   boundary (next-event estimation cannot connect through it), so both renderers get a
//!   distant square quad instead: 100 units away along the direction, 30 wide (0.09 sr, ±8.5°
//!   about it), radiance set for irradiance 1 across its direction.
//! * by the 4 × 4 quad of `docs/shapes.md` (radiance 1, 3 units above the surface, facing it),
//!   seen along the normal over its footprint (16 × 16 pixels), at σa 0.01, σs 1.
//!
//! The compared quantity is the image mean minus the light that never entered the medium (the
//! quad's Fresnel reflection, F(1)·L_e at every pixel under it; nothing for the distant
//! lights, whose mirror images are out of view). Ratios BSSRDF/PT ± 1 SE over the seeds.
//!
//!     cargo run --release --example oblique_light -- [--quick] [--scattering all] [--only distant|quad] [--eta 1.3] [--pt-scale K] [--seeds N] [--angles 0,30] [--view D] [--shape both]
//!
//! `--view D` sees the distant light's patch D° off the normal (D > 0 on the light's side,
//! D < 0 on the far side); `--shape both` adds a column with the oblique shape off, from the
//! BSSRDF's same seeds.
//!
//! `--quick` quarters the samples and halves the seeds (4 by default); `--pt-scale K`
//! multiplies the path tracer's samples by K (the distant quad at η ≠ 1 is found by the path
//! tracer's exits alone, and needs many).

#[path = "../tests/common/shapes.rs"]
#[allow(dead_code)]
mod shapes;

use bssrdf_core::glam::DVec3;
use bssrdf_core::{ProfileModel, Rgb, Scattering};
use het_bssrdf::{bssrdf_core, het_estimate, tracer};
use het_estimate::Coefficients;
use shapes::{bssrdf, mean_se, ratio};
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::primitives;
use tracer::integrator::{Method, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

/// The light of one case.
#[derive(Debug, Clone, Copy)]
enum Lighting {
    /// A distant light this many degrees from the normal.
    Distant(f64),
    /// The 4 × 4 quad 3 units above.
    Quad,
}

/// Distance and width of the distant quad (η ≠ 1).
const FAR: f64 = 100.0;
const FAR_WIDTH: f64 = 30.0;

fn scene(
    light: Lighting,
    sigma: (f64, f64),
    eta: f64,
    view_deg: Option<f64>,
    shape: bool,
) -> (Scene, f64) {
    let (sa, ss) = sigma;
    let field = MediumField::homogeneous(Coefficients::grey(sa, ss)).unwrap();
    let (camera, light, outside) = match light {
        Lighting::Distant(deg) => {
            let t = deg.to_radians();
            let towards = DVec3::new(t.sin(), 0.0, t.cos()); // from the surface to the light
            // Seen along the normal; at 0° with η ≠ 1, 20° off it, so that the distant quad's
            // mirror image (3 times the signal, and noisy in both renderers) is out of view.
            // `--view D`: seen D° off the normal, on the light's side for D > 0 (light leaving
            // back toward where it came from) and on the far side for D < 0.
            let view = if let Some(v) = view_deg {
                let a = v.to_radians();
                DVec3::new(-a.sin(), 0.0, -a.cos())
            } else if deg == 0.0 && eta != 1.0 {
                let a = 20f64.to_radians();
                DVec3::new(-a.sin(), 0.0, -a.cos())
            } else {
                DVec3::NEG_Z
            };
            let cam = Camera::orthographic(-view, view, DVec3::Y, 0.5, 0.5, 4, 4).unwrap();
            if eta == 1.0 {
                (cam, Light::directional(-towards, Rgb::ONE).unwrap(), 0.0)
            } else {
                // A square facing the origin, centred FAR along `towards`.
                let u = towards.cross(DVec3::Y).normalize() * FAR_WIDTH;
                let v = DVec3::Y * FAR_WIDTH;
                let centre = FAR * towards;
                // Irradiance across the direction ≈ L · A / FAR² (small solid angle): exact
                // solid angle of the square seen from the origin.
                let a = 0.5 * FAR_WIDTH / FAR;
                let omega = 4.0 * (a * a / (1.0 + 2.0 * a * a).sqrt()).asin();
                let radiance = 1.0 / omega;
                // Edge order so that the emitting side faces the origin.
                let (eu, ev) = if u.cross(v).dot(-towards) > 0.0 {
                    (u, v)
                } else {
                    (v, u)
                };
                let corner = centre - 0.5 * eu - 0.5 * ev;
                let light = Light::quad(corner, eu, ev, Rgb::splat(radiance)).unwrap();
                (cam, light, 0.0)
            }
        }
        Lighting::Quad => {
            let cam =
                Camera::orthographic(DVec3::Z, DVec3::NEG_Z, DVec3::Y, 4.0, 4.0, 16, 16).unwrap();
            // Emitting downward: edge_u × edge_v = −z.
            let light = Light::quad(
                DVec3::new(-2.0, -2.0, 3.0),
                DVec3::new(0.0, 4.0, 0.0),
                DVec3::new(4.0, 0.0, 0.0),
                Rgb::ONE,
            )
            .unwrap();
            (cam, light, bssrdf_core::fresnel::dielectric(1.0, eta))
        }
    };
    let (w, h) = camera.resolution();
    let scene = SceneBuilder::new(RenderSettings::new(w, h, 1), camera)
        .light(light)
        .object(
            "half-space",
            primitives::half_space(0.0, [0.0, 0.0], 400.0, 200.0, 40),
            // With and without the oblique shape (on by default; `oblique_shape` in a scene).
            Material::Translucent(Translucent {
                oblique_shape: shape,
                ..Translucent::new("m", field, 0.0, eta)
            }),
        )
        .build()
        .unwrap();
    (scene, outside)
}

fn measure(
    scene: &Scene,
    method: Method,
    scattering: Scattering,
    outside: f64,
    spp: u32,
    seeds: std::ops::Range<u64>,
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
    let (w, h) = scene.camera().resolution();
    mean_se(seeds.map(|seed| {
        let r = render(w, h, &integrator, &RenderOptions::samples(spp, seed));
        r.pixels.iter().map(|p| p[0]).sum::<f64>() / r.pixels.len() as f64 - outside
    }))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let arg = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let scattering: Scattering = arg("--scattering")
        .map(|s| {
            s.parse()
                .expect("--scattering takes multiple, single or all")
        })
        .unwrap_or(Scattering::Multiple);
    let only = arg("--only");
    let etas: Vec<f64> = arg("--eta")
        .map(|s| s.split(',').map(|e| e.parse().expect("--eta")).collect())
        .unwrap_or(vec![1.0, 1.3]);
    let seeds: u64 = arg("--seeds")
        .map(|s| s.parse().expect("--seeds takes a count"))
        .unwrap_or(if quick { 2 } else { 4 });
    let pt_scale: u32 = arg("--pt-scale")
        .map(|s| s.parse().expect("--pt-scale takes a factor"))
        .unwrap_or(1);
    let scale = if quick { 4 } else { 1 };
    let view_deg: Option<f64> = arg("--view").map(|s| s.parse().expect("--view takes degrees"));
    // `--shape both` adds a column with the oblique shape off (same seeds).
    let both = arg("--shape").as_deref() == Some("both");
    let mut cases: Vec<(Lighting, f64, (f64, f64))> = Vec::new();
    if only.as_deref() != Some("quad") {
        let angles: Vec<f64> = arg("--angles")
            .map(|s| s.split(',').map(|a| a.parse().expect("--angles")).collect())
            .unwrap_or(vec![0.0, 30.0, 60.0, 80.0]);
        for &deg in &angles {
            for albedo in [0.9, 0.99] {
                cases.push((Lighting::Distant(deg), albedo, (1.0 - albedo, albedo)));
            }
        }
    }
    if only.as_deref() != Some("distant") {
        cases.push((Lighting::Quad, 1.0 / 1.01, (0.01, 1.0)));
    }
    if both {
        println!("| light | η | ϖ | PT | BSSRDF | BSSRDF/PT | shape off: BSSRDF/PT |");
        println!("|---|---:|---:|---:|---:|---:|---:|");
    } else {
        println!("| light | η | ϖ | PT | BSSRDF | BSSRDF/PT |");
        println!("|---|---:|---:|---:|---:|---:|");
    }
    for &eta in &etas {
        for &(light, albedo, sigma) in &cases {
            let t0 = std::time::Instant::now();
            let view = match light {
                Lighting::Distant(_) => view_deg,
                Lighting::Quad => None,
            };
            let (scene, outside) = scene(light, sigma, eta, view, true);
            let (spp_pt, spp_b) = match light {
                Lighting::Distant(_) if eta == 1.0 => (4096, 1024),
                Lighting::Distant(_) => (16384, 1024),
                Lighting::Quad => (1024, 256),
            };
            let pt = measure(
                &scene,
                Method::PathTraced,
                scattering,
                outside,
                spp_pt * pt_scale / scale,
                0..seeds,
            );
            let bssrdf_mean = |scene: &Scene| {
                measure(
                    scene,
                    bssrdf(ProfileModel::Tabulated),
                    scattering,
                    outside,
                    spp_b / scale,
                    100..100 + seeds,
                )
            };
            let b = bssrdf_mean(&scene);
            let (q, se) = ratio(b, pt);
            let off = both.then(|| {
                ratio(
                    bssrdf_mean(&self::scene(light, sigma, eta, view, false).0),
                    pt,
                )
            });
            let label = match light {
                Lighting::Distant(d) => format!("distant {d}°"),
                Lighting::Quad => "4 × 4 quad".into(),
            };
            let label = match view {
                Some(v) => format!("{label}, seen at {v}°"),
                None => label,
            };
            let off = off.map_or(String::new(), |(q, se)| format!(" {q:.3} ± {se:.3} |"));
            println!(
                "| {label} | {eta} | {albedo:.3} | {:.5} ± {:.5} | {:.5} ± {:.5} | {q:.3} ± {se:.3} |{off}",
                pt.0, pt.1, b.0, b.1
            );
            eprintln!("  ({:.1} s)", t0.elapsed().as_secs_f64());
        }
    }
}
