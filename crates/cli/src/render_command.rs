//! `het-bssrdf render`: render a scene file with one method (the path-traced reference or a
//! BSSRDF estimator) to EXR, with a PNG preview and a JSON sidecar beside it.

use crate::diag::say;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, bail};
use bssrdf_core::Scattering;
use het_estimate::{Estimator, SoneParams};
use pipeline::files::{sidecar_paths, write_render};
use pipeline::job::{RenderJob, RenderOutcome, render_scene_observed};
use tracer::film::Film;
use tracer::integrator::{Method, PathCounters};
use tracer::render::{Budget, Partial};
use tracer::scene::Scene;

use crate::checkpoint::Checkpoints;
use crate::common::{
    check_image_memory, check_writable, claim_outputs, note_triangles, parse_exr_out,
    parse_positive, parse_seconds, set_collision_cap, warn_counters,
};
use crate::flags::EstimatorFlags;
use crate::signals;

/// Which way paths are traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Trace {
    /// From the camera (every method).
    #[default]
    Camera,
    /// From the lights, splatted to the camera (BSSRDF methods; quad, point, directional and
    /// environment lights; no diffuse surfaces): light entering a translucent object once
    /// and leaving it toward the camera, for reciprocity checks (docs/reciprocity.md).
    Light,
}

/// Arguments of `het-bssrdf render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The scene file (TOML).
    scene: PathBuf,
    /// `auto` (default): each translucent object with the scene's `render.estimator` (else
    /// `sone`) where a half-space profile fits, and the path tracer inside objects too small
    /// for one (the sidecar's `objects` says which). `pt`: the path-traced reference
    /// everywhere. An estimator (the other possible values): that BSSRDF on every object.
    #[arg(long, value_parser = crate::choices::method())]
    method: Option<Method>,
    /// Shape correction of BSSRDF objects (docs/shapes.md): `auto` corrects the objects too
    /// small for a half-space profile, unless their material says `shape_correction = false`;
    /// `on` corrects every one, `off` none. Default: `auto` with `--method auto`; with an
    /// estimator named, each material's own `shape_correction` (off where it sets none).
    #[arg(long, value_parser = crate::choices::correction())]
    shape_correction: Option<tracer::integrator::Correction>,
    #[command(flatten)]
    estimator: EstimatorFlags,
    /// Where the estimators invert artist materials' colours and radii: `before` averaging
    /// (per point) or `after` (default: each material's `invert`; see
    /// docs/artist-parameters.md).
    #[arg(long, value_parser = crate::choices::invert())]
    invert: Option<tracer::field::InvertAt>,
    /// Samples per pixel (default: the scene's `render.spp`).
    #[arg(long, value_parser = parse_positive, conflicts_with = "time", allow_hyphen_values = true)]
    spp: Option<u64>,
    /// Time budget in seconds instead of a sample count (doubling passes while they fit).
    #[arg(long, value_parser = parse_seconds, allow_hyphen_values = true)]
    time: Option<Duration>,
    /// Seed (default: the scene's `render.seed`).
    #[arg(long, allow_hyphen_values = true)]
    seed: Option<u64>,
    /// Scattering orders inside media: multiple, single or all (default: the scene's
    /// `render.scattering`, else all; the paper's experiments use multiple).
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
    /// Most collisions of one path inside a medium before it is cut (and counted); bounds the
    /// time a path can take in an optically huge medium (default 100,000,000).
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true)]
    max_collisions: Option<u64>,
    /// Render only shard I of N of the image (0 ≤ I < N): the rows y with y mod N = I, with the
    /// same per-pixel seeds as the whole render; the others are left black. `het-bssrdf
    /// merge` assembles the N shards (see deploy/ for Slurm and Kubernetes examples).
    #[arg(long, value_name = "I/N")]
    tile: Option<tracer::render::Shard>,
    /// Write the image so far (EXR, PNG and JSON, the sidecar marked as a checkpoint) after
    /// each pass that ends at least this many seconds after the previous checkpoint.
    #[arg(long, value_parser = parse_seconds, allow_hyphen_values = true)]
    checkpoint: Option<Duration>,
    /// Let glTF files read buffers and images outside their own folder (refused by default:
    /// a downloaded glTF file is untrusted input; a shape's `allow_outside_assets = true`
    /// allows it for that shape).
    #[arg(long)]
    allow_outside_assets: bool,
    /// Trace paths from the `camera` (default) or from the `light`s. A light-traced render
    /// traces spp × width × height light paths; it takes no --time, --tile or --checkpoint.
    #[arg(long, value_enum, default_value_t = Trace::Camera)]
    trace: Trace,
    /// Print each warning's full text (what was measured, why it matters) instead of its one
    /// line, and the estimators' averaging counts; the sidecar always holds the full text.
    #[arg(short, long)]
    verbose: bool,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let scene = load_scene(&args)?;
    let method = choose_method(&args, &scene)?;
    let job = build_job(&args, &scene, method)?;
    let out = output_path(&args, method);
    let mut inputs: Vec<&std::path::Path> = vec![args.scene.as_path()];
    inputs.extend(scene.input_files().iter().map(PathBuf::as_path));
    let _lock = claim_outputs(&out, &inputs)?;
    let partial_out = prepare_partial_out(&out, args.checkpoint.is_some())?;
    let partial_to = partial_out.as_deref().unwrap_or(&out);
    let wrote_partial = std::sync::atomic::AtomicBool::new(false);
    let (width, height) = scene.camera().resolution();
    check_image_memory(&scene, method, &args.scene)?;
    note_triangles(&scene);
    if args.trace == Trace::Light {
        if args.time.is_some() || args.tile.is_some() || args.checkpoint.is_some() {
            bail!("--trace light takes a sample count (--spp), not --time, --tile or --checkpoint");
        }
        return run_light_traced(&scene, &job, &out, args.exposure, args.verbose);
    }
    set_collision_cap(args.max_collisions);
    signals::install(signals::Mode::Finish)?;
    let rays_before = scene.geometry().rays_traced();
    let write_checkpoint = |partial: &Partial<'_, PathCounters>| -> anyhow::Result<()> {
        let mut film = Film::new(partial.width, partial.height);
        film.pixels = partial.mean();
        let outcome = RenderOutcome::checkpoint(
            film,
            partial.spp,
            partial.seconds,
            scene.geometry().rays_traced() - rays_before,
            *partial.counters,
            method.name().to_string(),
        );
        write_render(&outcome, &scene, &job, partial_to, args.exposure)?;
        wrote_partial.store(true, std::sync::atomic::Ordering::Relaxed);
        Ok(())
    };
    let observer = Checkpoints::new(
        pipeline::progress::RenderBar::new(
            method.name(),
            width,
            args.tile.map_or(height, |t| t.rows(height)),
            job.progress,
        ),
        args.checkpoint,
        &write_checkpoint,
    );
    let outcome = render_scene_observed(&scene, &job, &observer);
    observer.finish();
    let outcome = outcome.with_context(|| format!("cannot render `{}`", args.scene.display()))?;
    if outcome.interrupted {
        return write_interrupted(
            &outcome,
            &scene,
            &job,
            &out,
            partial_out.as_deref(),
            args.exposure,
        );
    }
    write_render(&outcome, &scene, &job, &out, args.exposure)?;
    if let Some(p) = &partial_out
        && wrote_partial.load(std::sync::atomic::Ordering::Relaxed)
    {
        // This run's checkpoints, superseded by its finished render.
        let (png, json) = sidecar_paths(p);
        for path in [p.as_path(), &png, &json] {
            let _ = std::fs::remove_file(path);
        }
    }
    report_finished(&outcome, &job, &out, args.verbose);
    Ok(())
}

/// The scene of `args`, loaded (with glTF assets outside their folder if allowed) and with
/// `--invert` applied.
fn load_scene(args: &Args) -> anyhow::Result<Scene> {
    let scene = Scene::load_with(
        &args.scene,
        tracer::scene::LoadOptions::default().with_allow_outside_assets(args.allow_outside_assets),
    )?;
    Ok(match args.invert {
        Some(at) => scene.with_invert(at),
        None => scene,
    })
}

/// The method to render with: `--method` (else `auto` with the scene's estimator, else
/// `sone`), with `--shape-correction` and the estimator flags applied.
fn choose_method(args: &Args, scene: &Scene) -> anyhow::Result<Method> {
    let method = match args.method {
        Some(m) => m,
        None => Method::auto(
            scene
                .settings()
                .estimator
                .unwrap_or(Estimator::Sone(SoneParams::new())),
        ),
    };
    if args.shape_correction.is_some() && method == Method::PathTraced {
        bail!("--shape-correction does not apply to `pt`: it corrects BSSRDF objects");
    }
    let method = match args.shape_correction {
        Some(c) => method.with_correction(c),
        None => method,
    };
    args.estimator.check(&[method])?;
    Ok(args.estimator.apply(method, scene.settings().averaging))
}

/// The scene's render job with `method`, overridden by the command line's budget, seed,
/// scattering, depth and shard.
fn build_job(args: &Args, scene: &Scene, method: Method) -> anyhow::Result<RenderJob> {
    let mut job = RenderJob::from_scene(scene, method);
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
    if let Some(shard) = args.tile {
        job.shard = Some(
            pipeline::sharding::ShardJob::new(shard, scene)
                .with_context(|| format!("cannot hash the scene `{}`", args.scene.display()))?,
        );
    }
    Ok(job)
}

/// The output EXR: `--out`, else `<scene>-<method>[-tile-I-of-N].exr` in the current
/// directory.
fn output_path(args: &Args, method: Method) -> PathBuf {
    let stem = args
        .scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tile = args
        .tile
        .map(|t| format!("-tile-{}-of-{}", t.index(), t.count()))
        .unwrap_or_default();
    args.out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{stem}-{}{tile}.exr", method.name())))
}

/// Where this run's partial images (checkpoints, an interrupted render) go when `out` already
/// holds a finished render, which is replaced only by another finished one: that path, checked
/// writable and cleared of stale temporaries; `None` when they go to `out` itself.
fn prepare_partial_out(
    out: &std::path::Path,
    checkpoints: bool,
) -> anyhow::Result<Option<PathBuf>> {
    let partial_out = holds_finished_render(out).then(|| partial_path(out));
    if let Some(p) = &partial_out {
        check_writable(p)?;
        let (png, json) = sidecar_paths(p);
        for path in [p.as_path(), &png, &json] {
            tracer::output::remove_stale_temporaries(path);
        }
        if checkpoints {
            say!(
                "note: `{}` holds a finished render, kept until this one finishes; checkpoints go \
                 to `{}`",
                out.display(),
                p.display()
            );
        }
    }
    Ok(partial_out)
}

/// Writes an interrupted render's completed passes (to `partial_out` if set, else `out`), then
/// fails with the error that says what was written, or that nothing was.
fn write_interrupted(
    outcome: &RenderOutcome,
    scene: &Scene,
    job: &RenderJob,
    out: &std::path::Path,
    partial_out: Option<&std::path::Path>,
    exposure: f64,
) -> anyhow::Result<()> {
    let signal = signals::received().map_or("interrupt", signals::name);
    if outcome.spp == 0 {
        bail!("{signal} before the first pass completed; nothing written");
    }
    let partial_to = partial_out.unwrap_or(out);
    write_render(outcome, scene, job, partial_to, exposure)?;
    let (png, json) = sidecar_paths(partial_to);
    let kept = match partial_out {
        Some(_) => format!(
            "; the finished render at `{}` was kept, not replaced",
            out.display()
        ),
        None => String::new(),
    };
    bail!(
        "{signal}: wrote the {} spp completed ({}, {}, {}; the sidecar says \"interrupted\": true){kept}",
        outcome.spp,
        partial_to.display(),
        png.display(),
        json.display()
    )
}

/// Prints a finished render's summary: time and speed, the files written, the mean pixel value
/// (over a shard's rows only), its notes, warnings and path counters.
fn report_finished(outcome: &RenderOutcome, job: &RenderJob, out: &std::path::Path, verbose: bool) {
    let (png, json) = sidecar_paths(out);
    say!(
        "{}: {} spp in {:.2} s ({:.2} Mrays/s); wrote {}, {}, {}",
        outcome.method,
        outcome.spp,
        outcome.seconds,
        outcome.rays as f64 / outcome.seconds.max(1e-9) / 1e6,
        out.display(),
        png.display(),
        json.display()
    );
    // The mean over the rendered pixels (a shard's rows only).
    let shard = job.options().shard;
    let w = outcome.film.width.max(1) as usize;
    let rendered: Vec<_> = outcome
        .film
        .pixels
        .chunks(w)
        .enumerate()
        .filter(|(y, _)| shard.holds_row(*y as u32))
        .flat_map(|(_, row)| row)
        .collect();
    let px = rendered.len().max(1) as f64;
    let mean: [f64; 3] = std::array::from_fn(|c| rendered.iter().map(|p| p[c]).sum::<f64>() / px);
    say!(
        "mean pixel value (R, G, B){}: {:.6}, {:.6}, {:.6}",
        if shard.is_whole() {
            ""
        } else {
            " of the shard's rows"
        },
        mean[0],
        mean[1],
        mean[2]
    );
    for n in &outcome.notes {
        say!("note: {n}");
    }
    print_warnings(&outcome.warnings, &json, verbose);
    warn_counters(&outcome.counters, verbose);
}

/// Each warning as one line, or (`verbose`) as its full text; without `verbose`, one line
/// more says where the full texts are.
fn print_warnings(
    warnings: &[tracer::integrator::warnings::Warning],
    sidecar: &std::path::Path,
    verbose: bool,
) {
    for w in warnings {
        if verbose {
            say!("warning: {}", w.detail);
        } else {
            say!("warning: {}", w.summary);
        }
    }
    if !verbose && warnings.iter().any(|w| w.summary != w.detail) {
        say!(
            "(the full text of each warning is in {}, or run with --verbose)",
            sidecar.display()
        );
    }
}

/// True when `out` holds a finished render: its EXR exists and its sidecar says neither
/// `interrupted` nor `checkpoint`.
fn holds_finished_render(out: &std::path::Path) -> bool {
    let (_, json) = sidecar_paths(out);
    let Ok(text) = std::fs::read_to_string(json) else {
        return false;
    };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return false;
    };
    out.is_file()
        && v["interrupted"] == serde_json::Value::Bool(false)
        && v["checkpoint"] == serde_json::Value::Bool(false)
}

/// Where the partial images of a render to `out` go when `out` holds a finished one:
/// `<stem>.partial.exr` beside it (with its PNG and JSON).
fn partial_path(out: &std::path::Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    out.with_file_name(format!("{stem}.partial.exr"))
}

/// `render --trace light`: the light tracer ([`tracer::integrator::LightTracer`]) with
/// spp × width × height light paths, written as a camera-traced render is.
fn run_light_traced(
    scene: &Scene,
    job: &RenderJob,
    out: &std::path::Path,
    exposure: f64,
    verbose: bool,
) -> anyhow::Result<()> {
    use tracer::integrator::{LightTraceOptions, LightTracer, PathOptions};
    let Budget::Samples(spp) = job.budget else {
        bail!("--trace light takes a sample count (--spp)");
    };
    let options = PathOptions {
        scattering: job.scattering,
        max_depth: job.max_depth,
    };
    let tracer = LightTracer::new(scene, job.method, options)
        .with_context(|| format!("cannot light-trace `{}`", scene.display_name()))?;
    let (width, height) = scene.camera().resolution();
    let paths = u64::from(spp) * u64::from(width) * u64::from(height);
    let rays_before = scene.geometry().rays_traced();
    let traced = tracer.render(&LightTraceOptions {
        paths,
        seed: job.seed,
    });
    let method = format!("{}-light-traced", job.method.name());
    let mut outcome = RenderOutcome::checkpoint(
        traced.film,
        spp,
        traced.seconds,
        scene.geometry().rays_traced() - rays_before,
        traced.counters,
        method,
    );
    outcome.checkpoint = false;
    outcome.warnings = tracer.warnings().to_vec();
    write_render(&outcome, scene, job, out, exposure)?;
    let (png, json) = sidecar_paths(out);
    let mean = outcome.film.mean();
    say!(
        "{}: {paths} light paths in {:.2} s ({:.2} Mrays/s); wrote {}, {}, {}",
        outcome.method,
        outcome.seconds,
        outcome.rays as f64 / outcome.seconds.max(1e-9) / 1e6,
        out.display(),
        png.display(),
        json.display()
    );
    say!(
        "mean pixel value (R, G, B): {:.6}, {:.6}, {:.6}",
        mean[0],
        mean[1],
        mean[2]
    );
    print_warnings(&outcome.warnings, &json, verbose);
    warn_counters(&outcome.counters, verbose);
    Ok(())
}
