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
//! Each pixel's spread has ν = RUNS − 1 degrees of freedom, so the median over pixels of the
//! estimated standard errors sits below the true one by √(median χ²_ν / ν) (Wilson–Hilferty:
//! median χ²_ν ≈ ν(1 − 2/(9ν))³; 0.978 for 16 runs). The printed median is divided by that
//! factor, which is exact when every pixel has the same relative error and close otherwise.

use bssrdf_core::Scattering;
use experiments::run::{RenderJob, render_scene};
use experiments::scenes::CHECKER_SLAB;
use het_bssrdf::{bssrdf_core, tracer};
use tracer::integrator::Method;
use tracer::render::Budget;
use tracer::scene::Scene;

/// User + system CPU seconds of this process so far (Linux; `None` elsewhere).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may contain spaces).
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the whole line: 12 and 13 after the name.
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0) // USER_HZ is 100 on Linux
}

fn main() {
    let args: Vec<u32> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("arguments: SPP RUNS THREADS (integers)"))
        .collect();
    let spp = args.first().copied().unwrap_or(8);
    let runs = args.get(1).copied().unwrap_or(16).max(2);
    if let Some(&threads) = args.get(2) {
        rayon::ThreadPoolBuilder::new()
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
    let k = f64::from(runs);
    let mut rel = Vec::with_capacity(images[0].len() * 3);
    for p in 0..images[0].len() {
        for c in 0..3 {
            let v: Vec<f64> = images.iter().map(|im| im[p][c]).collect();
            let mean = v.iter().sum::<f64>() / k;
            let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0);
            if mean > 0.0 {
                rel.push((var / k).sqrt() / mean);
            }
        }
    }
    rel.sort_by(f64::total_cmp);
    let nu = k - 1.0;
    let chi_median_ratio = (1.0 - 2.0 / (9.0 * nu)).powi(3);
    let median = rel[rel.len() / 2] / chi_median_ratio.sqrt();
    let factor = (median / 0.01).powi(2);
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
