//! `het-bssrdf render`: render a scene file with one method (the path-traced reference or a
//! BSSRDF estimator) to EXR, with a PNG preview and a JSON sidecar beside it.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use bssrdf_core::{ProfileModel, Scattering};
use experiments::run::{RenderJob, render_scene, sidecar_paths, write_render};
use het_estimate::{Estimator, SoneParams};
use tracer::integrator::Method;
use tracer::render::Budget;
use tracer::scene::Scene;

use crate::common::{check_writable, parse_exr_out, parse_positive, parse_seconds, warn_counters};
use crate::flags::check_method_flags;

/// Arguments of `het-bssrdf render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The scene file (TOML).
    scene: PathBuf,
    /// `pt` (the path-traced reference) or a BSSRDF estimator: jensen-in, jensen-out,
    /// endpoints, segment, sone. Default: the scene's `render.estimator`, else `sone`.
    #[arg(long, value_parser = crate::choices::method())]
    method: Option<Method>,
    /// Profile model for BSSRDF methods (default: each material's, else dipole).
    #[arg(long, value_parser = crate::choices::profile())]
    profile: Option<ProfileModel>,
    /// Averaging samples per region of the segment and Sone estimators (default: 16 on the
    /// segment; 16 in the disk and 32 in the ellipse for Sone).
    #[arg(long, value_parser = parse_positive)]
    estimator_samples: Option<u64>,
    /// Samples per pixel (default: the scene's `render.spp`).
    #[arg(long, value_parser = parse_positive, conflicts_with = "time", allow_hyphen_values = true)]
    spp: Option<u64>,
    /// Time budget in seconds instead of a sample count (doubling passes while they fit).
    #[arg(long, value_parser = parse_seconds, allow_hyphen_values = true)]
    time: Option<Duration>,
    /// Seed (default: the scene's `render.seed`).
    #[arg(long, allow_hyphen_values = true)]
    seed: Option<u64>,
    /// Scattering orders inside media: multiple, single or all (default: the scene's, else
    /// multiple, as in the paper).
    #[arg(long, value_parser = crate::choices::scattering())]
    scattering: Option<Scattering>,
    /// Most surface interactions per path (default: the scene's, else 8).
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true)]
    max_depth: Option<u64>,
    /// Output EXR (default: `<scene>-<method>.exr` in the current directory); the PNG preview
    /// and JSON sidecar are written beside it.
    #[arg(short, long, value_parser = parse_exr_out)]
    out: Option<PathBuf>,
    /// Exposure of the PNG preview, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f64,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let scene = Scene::load(&args.scene)?;
    let method = match args.method {
        Some(m) => m,
        None => Method::Bssrdf {
            estimator: scene
                .settings
                .estimator
                .unwrap_or(Estimator::Sone(SoneParams::paper())),
            profile: None,
        },
    };
    check_method_flags(
        &[method],
        args.profile.is_some(),
        args.estimator_samples.is_some(),
    )?;
    let method = method.with_profile(args.profile).with_estimator_samples(
        args.estimator_samples
            .map(|n| n.min(u32::MAX as u64) as u32),
    );
    let mut job = RenderJob::from_scene(&scene, method);
    if let Some(spp) = args.spp {
        job.budget = Budget::Samples(u32::try_from(spp).context("--spp is too large")?);
    }
    if let Some(t) = args.time {
        job.budget = Budget::Time(t);
    }
    if let Some(seed) = args.seed {
        job.seed = seed;
    }
    if let Some(s) = args.scattering {
        job.scattering = s;
    }
    if let Some(d) = args.max_depth {
        job.max_depth = u32::try_from(d).context("--max-depth is too large")?;
    }
    job.progress = true;
    let stem = args
        .scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from(format!("{stem}-{}.exr", method.name())));
    check_writable(&out)?;
    let outcome = render_scene(&scene, &job)
        .with_context(|| format!("cannot render `{}`", args.scene.display()))?;
    write_render(&outcome, &scene, &job, &out, args.exposure)?;
    let (png, json) = sidecar_paths(&out);
    eprintln!(
        "{}: {} spp in {:.2} s ({:.2} Mrays/s); wrote {}, {}, {}",
        outcome.method,
        outcome.spp,
        outcome.seconds,
        outcome.rays as f64 / outcome.seconds.max(1e-9) / 1e6,
        out.display(),
        png.display(),
        json.display()
    );
    let px = outcome.film.pixels.len().max(1) as f64;
    let mean: [f64; 3] =
        std::array::from_fn(|c| outcome.film.pixels.iter().map(|p| p[c]).sum::<f64>() / px);
    eprintln!(
        "mean pixel value (R, G, B): {:.6}, {:.6}, {:.6}",
        mean[0], mean[1], mean[2]
    );
    for w in &outcome.warnings {
        eprintln!("warning: {w}");
    }
    warn_counters(&outcome.counters);
    Ok(())
}
