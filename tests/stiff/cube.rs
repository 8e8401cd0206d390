//! The white-furnace scenes of the stiff-media tests, shared by `tests/stiff.rs` and
//! `examples/stability_sweep.rs` (which includes this file with `#[path]`, so it uses only the
//! library crates and `glam`).
//!
//! Scene: the closed unit cube [−½, ½]³ (12 triangles, outward winding), or an icosphere of
//! radius ½ (5120 triangles), filled with a homogeneous grey medium, HG g = 0, under a uniform
//! environment of radiance 1; an orthographic camera looks along −(1, 1, 1) with a view that
//! lies inside the object's silhouette, so every pixel sees the object and nothing else.

use std::time::Instant;

use bssrdf_core::glam::DVec3;
use bssrdf_core::{Rgb, Scattering};
use het_estimate::Coefficients;
use tracer::camera::Camera;
use tracer::field::MediumField;
use tracer::geometry::primitives;
use tracer::integrator::{Method, PathCounters, PathIntegrator, PathOptions};
use tracer::light::Light;
use tracer::render::{RenderOptions, render};
use tracer::scene::{Material, RenderSettings, Scene, SceneBuilder, Translucent};

/// Environment radiance.
pub const L_ENV: f64 = 1.0;

/// The closed object of a furnace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// The unit cube [−½, ½]³ (12 triangles; its faces lie on f32-representable planes).
    Cube,
    /// An icosphere of radius ½ about the origin, 4 subdivisions (5120 tilted triangles).
    Sphere,
}

/// One furnace configuration and its render budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    /// The object.
    pub shape: Shape,
    /// Scattering coefficient (1/length).
    pub sigma_s: f64,
    /// Absorption coefficient (1/length).
    pub sigma_a: f64,
    /// Relative index of refraction of the cube.
    pub eta: f64,
    /// Image side in pixels.
    pub resolution: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Render seed.
    pub seed: u64,
}

impl Case {
    /// A case at `resolution²` pixels × `spp`.
    pub const fn new(sigma_s: f64, sigma_a: f64, eta: f64, resolution: u32, spp: u32) -> Self {
        Self {
            shape: Shape::Cube,
            sigma_s,
            sigma_a,
            eta,
            resolution,
            spp,
            seed: 7,
        }
    }

    /// The same case on a sphere.
    pub const fn sphere(self) -> Self {
        Self {
            shape: Shape::Sphere,
            ..self
        }
    }

    /// `cube, σs=…, σa=…, η=…` for tables and messages.
    pub fn label(&self) -> String {
        let shape = match self.shape {
            Shape::Cube => "cube",
            Shape::Sphere => "sphere",
        };
        let short = |v: f64| {
            if v == 0.0 || (1e-2..1e3).contains(&v) {
                format!("{v}")
            } else {
                format!("{v:e}")
            }
        };
        format!(
            "{shape}, σs = {}, σa = {}, η = {}, {}² px",
            short(self.sigma_s),
            short(self.sigma_a),
            self.eta,
            self.resolution
        )
    }

    /// The expected pixel value as a string: `= 1` for σa = 0, `≤ 1` otherwise.
    pub fn expectation(&self) -> &'static str {
        if self.sigma_a == 0.0 { "= 1" } else { "≤ 1" }
    }

    /// The scene.
    pub fn scene(&self) -> Scene {
        let n = self.resolution;
        let medium = MediumField::homogeneous(Coefficients::grey(self.sigma_a, self.sigma_s))
            .expect("valid medium");
        // The view lies inside the silhouette: the cube's hexagon has inscribed radius
        // √2/2 ≈ 0.707 (view corner at 0.566), the sphere's disk radius ½ (corner at 0.42).
        let (mesh, view) = match self.shape {
            Shape::Cube => (
                primitives::cuboid(DVec3::splat(-0.5), DVec3::splat(0.5)),
                0.8,
            ),
            Shape::Sphere => (primitives::icosphere(DVec3::ZERO, 0.5, 4), 0.6),
        };
        let camera =
            Camera::orthographic(DVec3::splat(2.0), -DVec3::ONE, DVec3::Z, view, view, n, n)
                .expect("valid camera");
        SceneBuilder::new(RenderSettings::new(n, n, self.spp), camera)
            .name("stiff furnace cube")
            .light(Light::environment(Rgb::splat(L_ENV)).expect("valid light"))
            .object(
                "furnace",
                mesh,
                Material::Translucent(Translucent::new("furnace", medium, 0.0, self.eta)),
            )
            .build()
            .expect("valid scene")
    }
}

/// What a furnace render measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Pixels.
    pub pixels: usize,
    /// Mean pixel value (channel 0; the medium is grey, so all channels are equal).
    pub mean: f64,
    /// Standard error of `mean`: the sample standard deviation of the pixel means / √pixels.
    pub se: f64,
    /// Smallest and largest pixel value.
    pub range: (f64, f64),
    /// Every pixel value (all channels) finite.
    pub finite: bool,
    /// Real collisions (scatterings) per camera path.
    pub collisions_per_path: f64,
    /// Tentative delta-tracking collisions per camera path.
    pub delta_steps_per_path: f64,
    /// Collisions per path that entered the cube (all camera paths hit it; at η > 1 a Fresnel
    /// reflection sends some away without entering, estimated here as the Fresnel reflectance
    /// of the three seen faces at the camera's incidence cos θ = 1/√3).
    pub collisions_per_entering_path: f64,
    /// The merged counters.
    pub counters: PathCounters,
    /// Wall-clock seconds of the render.
    pub seconds: f64,
    /// Capped walks.
    pub capped: u64,
    /// Leaked walks.
    pub leaks: u64,
    /// Wrong-side boundary hits stepped over.
    pub wrong_side: u64,
    /// Tentative delta-tracking collisions in total.
    pub delta_steps: u64,
}

impl Measurement {
    /// (mean − L_ENV)/SE.
    pub fn z(&self) -> f64 {
        (self.mean - L_ENV) / self.se
    }
}

/// Renders `case` with the reference path tracer (`Scattering::All`) and measures it.
pub fn measure(case: &Case) -> Measurement {
    let scene = case.scene();
    let integrator = PathIntegrator::new(
        &scene,
        Method::PathTraced,
        PathOptions {
            scattering: Scattering::All,
            // Convex object, no other geometry: a path has at most two surface interactions
            // (enter, leave), so this bound never truncates a path.
            max_depth: 64,
        },
    )
    .expect("path-traceable scene");
    let start = Instant::now();
    let img = render(
        case.resolution,
        case.resolution,
        &integrator,
        &RenderOptions::samples(case.spp, case.seed),
    );
    let seconds = start.elapsed().as_secs_f64();
    let values: Vec<f64> = img.pixels.iter().map(|p| p[0]).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let c = img.counters;
    let paths = c.paths.max(1) as f64;
    let cos = 1.0 / 3f64.sqrt();
    let reflected = bssrdf_core::fresnel::dielectric(cos, case.eta);
    Measurement {
        pixels: values.len(),
        mean,
        se: (var / n).sqrt(),
        range: values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            }),
        finite: img.pixels.iter().all(|p| p.is_finite()),
        collisions_per_path: c.scatterings as f64 / paths,
        delta_steps_per_path: c.delta_steps as f64 / paths,
        collisions_per_entering_path: c.scatterings as f64 / (paths * (1.0 - reflected)),
        counters: c,
        seconds,
        capped: c.capped,
        leaks: c.leaks,
        wrong_side: c.wrong_side,
        delta_steps: c.delta_steps,
    }
}

/// σt = 10, index-matched, lossless.
pub const MATCHED_10: Case = Case::new(10.0, 0.0, 1.0, 16, 16);
/// σt = 10.1, index-matched, σa = 0.1.
pub const ABSORBING_10: Case = Case::new(10.0, 0.1, 1.0, 16, 16);
/// σt = 10, dielectric η = 1.5, lossless.
pub const DIELECTRIC_10: Case = Case::new(10.0, 0.0, 1.5, 16, 16);
/// σt = 100, index-matched, lossless.
pub const MATCHED_100: Case = Case::new(100.0, 0.0, 1.0, 16, 16);
/// σt = 1e3, index-matched, lossless.
pub const MATCHED_1E3: Case = Case::new(1e3, 0.0, 1.0, 16, 8);
/// σt = 1e3, index-matched, σa = 1e-3.
pub const ABSORBING_1E3: Case = Case::new(1e3, 1e-3, 1.0, 16, 8);
/// σt = 1e3, dielectric η = 1.5, lossless.
pub const DIELECTRIC_1E3: Case = Case::new(1e3, 0.0, 1.5, 16, 4);
/// σt = 1e3 in the icosphere (tilted faces), index-matched, lossless.
pub const SPHERE_1E3: Case = Case::new(1e3, 0.0, 1.0, 16, 4).sphere();
/// σt = 1e3 in the icosphere, dielectric η = 1.5, lossless.
pub const SPHERE_DIELECTRIC_1E3: Case = Case::new(1e3, 0.0, 1.5, 16, 2).sphere();
/// σt = 1e4, index-matched, lossless (`#[ignore]`d in the tests).
pub const MATCHED_1E4: Case = Case::new(1e4, 0.0, 1.0, 16, 16);
/// σt = 1e4, dielectric η = 1.5, lossless (`#[ignore]`d in the tests).
pub const DIELECTRIC_1E4: Case = Case::new(1e4, 0.0, 1.5, 16, 4);
/// σt = 1e4 in the icosphere, index-matched, lossless (`#[ignore]`d in the tests).
pub const SPHERE_1E4: Case = Case::new(1e4, 0.0, 1.0, 16, 4).sphere();

/// Every configuration, in the order of the table in `docs/stability.md`.
pub const ALL: [Case; 12] = [
    MATCHED_10,
    ABSORBING_10,
    DIELECTRIC_10,
    MATCHED_100,
    MATCHED_1E3,
    ABSORBING_1E3,
    DIELECTRIC_1E3,
    SPHERE_1E3,
    SPHERE_DIELECTRIC_1E3,
    MATCHED_1E4,
    DIELECTRIC_1E4,
    SPHERE_1E4,
];
