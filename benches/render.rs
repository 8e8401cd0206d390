//! Samples per second of the two renders through the same tracer: the reference path tracer
//! and the BSSRDF renderer with each estimator, on the built-in checker slab (the paper's
//! Figure 5 situation) at 32 × 32, one sample per pixel per iteration, single-threaded so that
//! ratios are stable on a shared machine.
//!
//! Run: `cargo bench --bench render`. Ids are `render/<method>` (`<estimator>-tabulated`: the
//! same scene with the tabulated profile instead of the scene's dipole); criterion reports the time
//! per 1024 camera samples and the throughput in samples/s. Compare methods as ratios.
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

fn renders(c: &mut Criterion) {
    let scene = Scene::from_toml_str(CHECKER_SLAB, std::path::Path::new("."), "checker-slab")
        .expect("built-in scene")
        .with_resolution(32, 32)
        .expect("positive");
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
    for name in ["pt", "jensen-out", "endpoints", "segment", "sone"] {
        let method: Method = name.parse().expect("built-in method");
        let integrator = PathIntegrator::new(
            &scene,
            method,
            PathOptions {
                scattering: Scattering::Multiple,
                max_depth: 8,
            },
        )
        .expect("renderable");
        let mut seed = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                seed += 1;
                pool.install(|| render(32, 32, &integrator, &RenderOptions::samples(1, seed)))
            })
        });
    }
    for (name, boundary) in [
        ("sone eta=1.3", "eta = 1.3"),
        ("sone eta=1.3 roughness=0.3", "eta = 1.3\nroughness = 0.3"),
    ] {
        let text = CHECKER_SLAB.replace("eta = 1.0", boundary);
        let scene = Scene::from_toml_str(&text, std::path::Path::new("."), "checker-slab")
            .expect("built-in scene")
            .with_resolution(32, 32)
            .expect("positive");
        let method: Method = "sone".parse().expect("built-in method");
        let integrator = PathIntegrator::new(
            &scene,
            method,
            PathOptions {
                scattering: Scattering::Multiple,
                max_depth: 8,
            },
        )
        .expect("renderable");
        let mut seed = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                seed += 1;
                pool.install(|| render(32, 32, &integrator, &RenderOptions::samples(1, seed)))
            })
        });
    }
    // The same scene with the tabulated profile (and so its angular coupling and oblique
    // shape, docs/oblique-incidence.md): the cost of the tabulated S per BSSRDF sample.
    for name in ["sone", "endpoints"] {
        let estimator = name.parse().expect("built-in estimator");
        let method = Method::bssrdf(estimator, Some(ProfileModel::Tabulated));
        let integrator = PathIntegrator::new(
            &scene,
            method,
            PathOptions {
                scattering: Scattering::Multiple,
                max_depth: 8,
            },
        )
        .expect("renderable");
        let mut seed = 0;
        group.bench_function(format!("{name}-tabulated"), |b| {
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
