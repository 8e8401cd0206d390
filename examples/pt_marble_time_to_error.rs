//! How long the reference path tracer needs to reach a median per-pixel relative standard error
//! of 1 % on the marble block (a chromatic, refractive, high-albedo medium), and how much of
//! its noise is chroma noise:
//!
//!     cargo run --release --example pt_marble_time_to_error [-- SCENE... --spp N --runs N --threads N]
//!
//! Renders each scene (default `examples/scenes/marble.toml`; any scene file given, e.g. a
//! curved marble) with the path tracer RUNS times (default 16) with seeds 1..=RUNS, SPP samples
//! per pixel each (default 4), with the scene's own scattering orders and depth. As
//! `pt_time_to_error` (statistics in `experiments::time_to_error`), the median over pixels and
//! channels of the relative standard error of the mean of all RUNS × SPP samples gives the time
//! to 1 %: the measured wall (and CPU) time × (e / 1 %)². Also printed:
//! * the chroma noise: the median over pixels of the standard error of R − G and of B − G,
//!   relative to the pixel's mean grey value (R + G + B)/3, at RUNS × SPP samples;
//! * both the relative error and the chroma noise again over the pixels that see a translucent
//!   object (the primary ray through the pixel's centre hits one), where the medium's noise is;
//! * the image mean per channel ± its standard error over the runs, to check that a change of
//!   the estimator leaves the image unchanged within noise.

use experiments::time_to_error::{ErrorSpread, cpu_seconds};
use het_bssrdf::tracer;
use pipeline::job::{RenderJob, render_scene};
use tracer::integrator::Method;
use tracer::render::Budget;
use tracer::scene::{Material, Scene};

const USAGE: &str = "usage: pt_marble_time_to_error [SCENE...] [--spp N] [--runs N] [--threads N]";

/// Per pixel (row-major), whether the camera ray through its centre first hits a translucent
/// object.
fn translucent_pixels(scene: &Scene) -> Vec<bool> {
    let (w, h) = scene.camera().resolution();
    (0..w * h)
        .map(|i| {
            let ray = scene
                .camera()
                .ray(f64::from(i % w) + 0.5, f64::from(i / w) + 0.5);
            scene.geometry().intersect(&ray).is_some_and(|hit| {
                matches!(
                    scene.objects()[hit.object as usize].material,
                    Material::Translucent(_)
                )
            })
        })
        .collect()
}

fn main() {
    let mut scenes = Vec::new();
    let (mut spp, mut runs, mut threads) = (4u32, 16u32, None);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut number = |name: &str| -> u32 {
            args.next().and_then(|v| v.parse().ok()).unwrap_or_else(|| {
                eprintln!("{name} needs a positive integer\n{USAGE}");
                std::process::exit(2)
            })
        };
        match a.as_str() {
            "--spp" => spp = number("--spp").max(1),
            "--runs" => runs = number("--runs").max(2),
            "--threads" => threads = Some(number("--threads")),
            s if s.starts_with("--") => {
                eprintln!("unknown option {s}\n{USAGE}");
                std::process::exit(2)
            }
            _ => scenes.push(std::path::PathBuf::from(a)),
        }
    }
    if scenes.is_empty() {
        scenes.push(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/marble.toml").into());
    }
    if let Some(threads) = threads {
        tracer::rayon::ThreadPoolBuilder::new()
            .num_threads(threads as usize)
            .build_global()
            .unwrap();
    }
    for path in &scenes {
        let scene = Scene::load(path).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(1)
        });
        let mut job = RenderJob::from_scene(&scene, Method::PathTraced);
        job.budget = Budget::Samples(spp);
        let cpu0 = cpu_seconds();
        let mut wall = 0.0;
        let mut images = Vec::new();
        for seed in 1..=u64::from(runs) {
            job.seed = seed;
            let out = render_scene(&scene, &job).unwrap_or_else(|e| {
                eprintln!("{}: {e}", path.display());
                std::process::exit(1)
            });
            wall += out.seconds;
            images.push(out.film.pixels);
        }
        let cpu = cpu0.zip(cpu_seconds()).map(|(a, b)| b - a);
        let s = ErrorSpread::of(&images);
        let seen = translucent_pixels(&scene);
        let on = ErrorSpread::of_pixels(&images, |p| seen[p]);
        let factor = s.time_factor(0.01);
        let (w, h) = scene.camera().resolution();
        println!(
            "{}, {w} x {h}, scattering {}: {runs} runs x {spp} spp = {} spp",
            path.display(),
            job.scattering,
            runs * spp
        );
        println!(
            "  median per-pixel relative standard error: {:.4} %",
            100.0 * s.median_relative
        );
        println!(
            "  chroma noise (median per-pixel s.e. / grey mean): R-G {:.4} %, B-G {:.4} %",
            100.0 * s.chroma_rg,
            100.0 * s.chroma_bg
        );
        println!(
            "  on the {} pixels that see a translucent object: relative error {:.4} %, chroma \
             R-G {:.4} %, B-G {:.4} %",
            seen.iter().filter(|&&s| s).count(),
            100.0 * on.median_relative,
            100.0 * on.chroma_rg,
            100.0 * on.chroma_bg
        );
        println!(
            "  image mean: R {:.6} ± {:.6}, G {:.6} ± {:.6}, B {:.6} ± {:.6}",
            s.image_mean[0],
            s.image_mean_se[0],
            s.image_mean[1],
            s.image_mean_se[1],
            s.image_mean[2],
            s.image_mean_se[2]
        );
        println!(
            "  wall time {wall:.1} s -> to 1 %: {:.0} s ({:.0} spp)",
            wall * factor,
            f64::from(runs * spp) * factor
        );
        if let Some(cpu) = cpu {
            println!("  CPU time {cpu:.1} s -> to 1 %: {:.0} CPU s", cpu * factor);
        }
    }
}
