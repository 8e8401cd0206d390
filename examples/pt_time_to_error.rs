//! How long the reference path tracer needs to reach a given per-pixel error on the checker
//! slab (issue 14's path-tracer target: a median per-pixel relative standard error of 1 %, all
//! scattering orders, 128 × 128):
//!
//!     cargo run --release --example pt_time_to_error [-- SPP RUNS THREADS]
//!
//! Renders the built-in `checker-slab.toml` RUNS times (default 16) with independent seeds
//! (1..=RUNS), SPP samples per pixel each (default 8), with all scattering orders. Per pixel
//! and channel, the standard error of the mean of all RUNS × SPP samples is the spread of the
//! RUNS images over √RUNS; its ratio to the mean is the relative standard error. The median over
//! pixels and channels, e, falls as 1/√(samples), so the time to reach 1 % is the measured
//! time × (e / 1 %)². The wall time is the sum of the renders' sampling times; the CPU time
//! (user + system of the process, from `/proc/self/stat` on Linux) is printed beside it, since
//! on a shared machine the wall time includes waiting for the cores.
//!
//! The median is corrected for its bias with few runs (`experiments::time_to_error`).

use bssrdf_core::Scattering;
use experiments::scenes::CHECKER_SLAB;
use experiments::time_to_error::{ErrorSpread, cpu_seconds};
use het_bssrdf::{bssrdf_core, tracer};
use pipeline::job::{RenderJob, render_scene};
use tracer::integrator::Method;
use tracer::render::Budget;
use tracer::scene::Scene;

fn main() {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("arguments: SPP RUNS THREADS (integers)"))
        .collect();
    let spp = args.first().copied().unwrap_or(8);
    let runs = args.get(1).copied().unwrap_or(16).max(2);
    if let Some(&threads) = args.get(2) {
        tracer::rayon::ThreadPoolBuilder::new()
            .num_threads(threads as usize)
            .build_global()
            .unwrap();
    }
    let scene =
        Scene::from_toml_str(CHECKER_SLAB, std::path::Path::new("."), "checker-slab.toml").unwrap();
    let mut job = RenderJob::from_scene(&scene, Method::PathTraced);
    job.scattering = Scattering::All;
    job.budget = Budget::Samples(spp);
    let cpu0 = cpu_seconds();
    let mut wall = 0.0;
    let mut images = Vec::new();
    for seed in 1..=u64::from(runs) {
        job.seed = seed;
        let out = render_scene(&scene, &job).unwrap();
        wall += out.seconds;
        images.push(out.film.pixels);
    }
    let cpu = cpu0.zip(cpu_seconds()).map(|(a, b)| b - a);
    let spread = ErrorSpread::of(&images);
    let median = spread.median_relative;
    let factor = spread.time_factor(0.01);
    println!(
        "checker slab, all scattering orders, 128 x 128: {runs} runs x {spp} spp = {} spp",
        runs * spp
    );
    println!(
        "median per-pixel relative standard error: {:.4} %",
        100.0 * median
    );
    println!(
        "wall time {wall:.1} s -> to 1 %: {:.0} s ({:.0} spp)",
        wall * factor,
        f64::from(runs * spp) * factor
    );
    if let Some(cpu) = cpu {
        println!(
            "CPU time {cpu:.1} s -> to 1 %: {:.0} CPU s ({:.0} s on 2 cores if fully parallel)",
            cpu * factor,
            cpu * factor / 2.0
        );
    }
}
