//! Samples per second of the two renders through the same tracer: the reference path tracer
//! and the BSSRDF renderer with each estimator, on the built-in checker slab (the paper's
//! Figure 5 situation) at 32 × 32, one sample per pixel per iteration, single-threaded so that
//! ratios are stable on a shared machine.
//!
//! Run: `cargo bench --bench render`. Ids are `render/<method>` (`<estimator>-tabulated`: the
//! same scene with the tabulated profile instead of the scene's dipole, without the oblique
//! shape; `… oblique` with it, as by default; `… sphere`: the slab's material on a sphere of
//! radius 10 (10 mean free paths) filling the same view, a curved surface); criterion reports
//! the time per 1024 camera samples and the throughput in samples/s. Compare methods as
//! ratios.
//!
//! `render/sone eta=1.3` and `render/sone eta=1.3 roughness=0.3` render the same slab with a
//! refractive boundary, smooth and rough (docs/lighting-and-surfaces.md): their ratio is the
//! cost of the rough boundary per BSSRDF sample.

use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use het_bssrdf::bssrdf_core::{ProfileModel, Scattering};
use het_bssrdf::experiments::scenes::CHECKER_SLAB;
use het_bssrdf::tracer::integrator::{Method, PathIntegrator, PathOptions};
use het_bssrdf::tracer::render::{RenderOptions, render};
use het_bssrdf::tracer::scene::Scene;

/// The built-in checker slab at 32 × 32, its material's `eta = 1.0` line replaced by
/// `material` (the material's other keys stay).
fn slab(material: &str) -> Scene {
    built_in(CHECKER_SLAB.replace("eta = 1.0", material))
}

/// [`slab`] with the box replaced by a sphere of radius 10 whose top is the slab's top
/// (z = 0), under the same light and camera: the same material on a curved surface.
fn sphere(material: &str) -> Scene {
    let text = CHECKER_SLAB.replace("eta = 1.0", material);
    let box_at = text.find("[[shape]]").expect("the slab's shape");
    let ball = "[[shape]]\ntype = \"sphere\"\nname = \"ball\"\nmaterial = \"checker\"\n\
                centre = [0.0, 0.0, -10.0]\nradius = 10.0\n";
    built_in(format!("{}{ball}", &text[..box_at]))
}

fn built_in(text: String) -> Scene {
    Scene::from_toml_str(&text, std::path::Path::new("."), "checker-slab")
        .expect("built-in scene")
        .with_resolution(32, 32)
        .expect("positive")
}

fn renders(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let mut group = c.benchmark_group("render");
    group
        .throughput(Throughput::Elements(32 * 32))
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .sample_size(20);
    let method = |name: &str| -> Method { name.parse().expect("built-in method") };
    let tabulated = |name: &str| {
        Method::bssrdf(
            name.parse().expect("built-in estimator"),
            Some(ProfileModel::Tabulated),
        )
    };
    let mut cases: Vec<(String, Scene, Method)> =
        ["pt", "jensen-out", "endpoints", "segment", "sone"]
            .into_iter()
            .map(|name| (name.to_string(), slab("eta = 1.0"), method(name)))
            .collect();
    // A refractive boundary, smooth and rough (docs/lighting-and-surfaces.md).
    cases.push(("sone eta=1.3".into(), slab("eta = 1.3"), method("sone")));
    cases.push((
        "sone eta=1.3 roughness=0.3".into(),
        slab("eta = 1.3\nroughness = 0.3"),
        method("sone"),
    ));
    // The tabulated profile with its angular coupling, without and with the oblique shape
    // (docs/oblique-incidence.md): the cost of the tabulated S per BSSRDF sample.
    for name in ["sone", "endpoints"] {
        cases.push((
            format!("{name}-tabulated"),
            slab("eta = 1.0\noblique_shape = false"),
            tabulated(name),
        ));
        cases.push((
            format!("{name}-tabulated oblique"),
            slab("eta = 1.0\noblique_shape = true"),
            tabulated(name),
        ));
    }
    // The same on a curved surface, with the estimator whose cost the shape raises most.
    for shape in [false, true] {
        let on = if shape { " oblique" } else { "" };
        cases.push((
            format!("endpoints-tabulated sphere{on}"),
            sphere(&format!("eta = 1.0\noblique_shape = {shape}")),
            tabulated("endpoints"),
        ));
    }
    for (id, scene, method) in &cases {
        let integrator = PathIntegrator::new(
            scene,
            *method,
            PathOptions {
                scattering: Scattering::Multiple,
                max_depth: 8,
            },
        )
        .expect("renderable");
        let mut seed = 0;
        group.bench_function(id.as_str(), |b| {
            b.iter(|| {
                seed += 1;
                pool.install(|| render(32, 32, &integrator, &RenderOptions::samples(1, seed)))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, renders);
criterion_main!(benches);
