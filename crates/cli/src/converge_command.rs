//! `het-bssrdf converge`: error against run time for several methods, on a scene file or on
//! the beam experiment (`--beam`), against a path-traced reference; writes
//! `convergence.csv`, `convergence.png` (+ `.svg`), `summary.json` with the speed-up of each
//! BSSRDF method over path tracing, and the largest run of every method as an image.

use crate::diag::say;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use bssrdf_core::ProfileModel;
use experiments::beam::{PhotonBudget, write_beam_map};
use experiments::converge::{MethodSummary, check_dir, summarize_with_reference, write_outputs};
use experiments::study::{
    BeamBudgets, BeamReference, REFERENCE_SEED_OFFSET, beam_study, default_cache_dir,
    reference_file, reference_key, scene_reference, scene_study,
};
use pipeline::files::write_render;
use pipeline::job::RenderJob;
use tracer::integrator::Method;
use tracer::output::read_exr;
use tracer::scene::Scene;

use crate::beam_command::{SetupArgs, run_method};
use crate::common::parse_positive;
use crate::flags::{EstimatorFlags, Given};

/// Flags that set up the beam experiment: they do not apply to a scene.
const BEAM_ONLY: &[&str] = &[
    "preset",
    "texture",
    "values",
    "width",
    "angle",
    "sigma_s",
    "g",
    "extent",
    "resolution",
    "reference_photons",
    "max_photons",
    "max_subsamples",
    "min_radius",
];

/// Flags of scene studies: they do not apply to the beam experiment.
const SCENE_ONLY: &[&str] = &[
    "reference_spp",
    "max_spp",
    "max_depth",
    "allow_outside_assets",
];

/// Arguments of `het-bssrdf converge`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The scene file (TOML); omit it with `--beam`.
    #[arg(required_unless_present = "beam")]
    scene: Option<PathBuf>,
    /// Study the beam experiment instead of a scene (with the `beam` set-up flags).
    #[arg(long)]
    beam: bool,
    #[command(flatten)]
    setup: SetupArgs,
    /// Methods, comma-separated: `pt` and any of the BSSRDF estimators (the possible values).
    #[arg(long, value_delimiter = ',', value_parser = crate::choices::method(), default_value = "pt,jensen-out,endpoints,sone")]
    methods: Vec<Method>,
    #[command(flatten)]
    estimator: EstimatorFlags,
    /// A reference image (EXR). Default: path traced at `--reference-spp` (scene: cached in
    /// `--cache-dir` under a hash of everything the render reads) or `--reference-photons`
    /// (beam, in --out).
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Directory of cached scene references (default: `$XDG_CACHE_HOME/het-bssrdf`, else
    /// `~/.cache/het-bssrdf`; `--out` when it cannot be written).
    #[arg(long, env = "HET_BSSRDF_CACHE_DIR")]
    cache_dir: Option<PathBuf>,
    /// Samples per pixel of the rendered reference.
    #[arg(long, value_parser = parse_positive, default_value_t = 1024, allow_hyphen_values = true)]
    reference_spp: u64,
    /// Scene: most surface interactions per path (default: the scene's, else 8). The scene's
    /// scattering orders are overridden by `--scattering`, as for `render`.
    #[arg(long, value_parser = parse_positive, allow_hyphen_values = true)]
    max_depth: Option<u64>,
    /// Largest spp of the scene runs (doubling from 1).
    #[arg(long, value_parser = parse_positive, default_value_t = 64, allow_hyphen_values = true)]
    max_spp: u64,
    /// Beam: photons of the rendered reference.
    #[arg(long, value_parser = parse_positive, default_value_t = 1 << 24, allow_hyphen_values = true)]
    reference_photons: u64,
    /// Beam: largest photon count of the `pt` runs (doubling from 2^16).
    #[arg(long, value_parser = parse_positive, default_value_t = 1 << 22, allow_hyphen_values = true)]
    max_photons: u64,
    /// Beam: largest K of the BSSRDF runs (K × K points per pixel, doubling from 1).
    #[arg(long, value_parser = parse_positive, default_value_t = 4, allow_hyphen_values = true)]
    max_subsamples: u64,
    /// Beam: ignore pixels closer than R to the beam (the singular peak).
    #[arg(long = "min-radius", default_value_t = 1.0, allow_hyphen_values = true)]
    min_radius: f64,
    /// Seed of the runs (the reference uses a different one).
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    seed: u64,
    /// Scene: let glTF files read buffers and images outside their own folder (refused by
    /// default: a downloaded glTF file is untrusted input).
    #[arg(long)]
    allow_outside_assets: bool,
    /// Output directory (created if missing).
    #[arg(short, long)]
    out: Option<PathBuf>,
}

/// Keeps the latest item of each method: runs come in increasing budget per method, so this
/// is the largest one, whatever the budget's unit or rounding.
fn keep_latest<T>(finals: &mut Vec<(String, T)>, method: &str, item: T) {
    match finals.last_mut() {
        Some((m, latest)) if m == method => *latest = item,
        _ => finals.push((method.to_string(), item)),
    }
}

fn doubling(from: u64, to: u64) -> Vec<u64> {
    std::iter::successors(Some(from), |&v| Some(v * 2))
        .take_while(|&v| v <= to)
        .collect()
}

fn print_summary(summary: &[MethodSummary]) {
    for s in summary {
        let pt = match (s.pt_time_to_same_error, s.speedup) {
            (Some(t), Some(x)) => format!(
                "path tracing needs {t:.3} s{} -> speed-up {x:.1}x",
                if s.pt_extrapolated {
                    " (extrapolated)"
                } else {
                    ""
                }
            ),
            _ => "no path-tracing runs".into(),
        };
        let aware = match (s.pt_time_reference_aware, s.speedup_reference_aware) {
            (Some(t), Some(x)) if s.pt_extrapolated => {
                format!(" (with the reference's own noise: {t:.3} s -> {x:.1}x)")
            }
            _ => String::new(),
        };
        say!(
            "{:>24}: converged rel. L2 {:.4} after {:.3} s; {pt}{aware}",
            s.method,
            s.converged_error,
            s.time_to_converge
        );
    }
}

/// Runs the subcommand.
pub fn run(args: Args, given: &Given) -> anyhow::Result<()> {
    if args.methods.is_empty() {
        bail!("--methods: give at least one method");
    }
    args.estimator.check(&args.methods)?;
    if args.beam {
        given.refuse(SCENE_ONLY, "with --beam (it applies to a scene study)")?;
    } else {
        given.refuse(
            BEAM_ONLY,
            "to a scene study (it sets up the beam experiment, with --beam)",
        )?;
    }
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = match &args.scene {
            Some(s) if !args.beam => s
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            _ => format!("beam-{}", args.setup.tag()),
        };
        PathBuf::from(format!("converge-{stem}"))
    });
    if args.beam {
        run_beam(&args, &out)
    } else {
        run_scene(&args, given, &out)
    }
}

/// Creates the output directory and checks that it accepts files. Called once the inputs have
/// been read and validated, so that a bad input leaves nothing behind, and before any long run.
fn prepare_out(out: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| {
        format!(
            "invalid --out: cannot create the output directory `{}`",
            out.display()
        )
    })?;
    check_dir(out).context("invalid --out")?;
    Ok(())
}

/// The directory of cached references: `--cache-dir` (or `HET_BSSRDF_CACHE_DIR`), else the
/// user's cache directory, checked before any rendering; when it cannot be created or written,
/// `out` (with a warning).
fn cache_dir(given: Option<&Path>, out: &Path) -> PathBuf {
    let Some(dir) = given.map(Path::to_path_buf).or_else(default_cache_dir) else {
        return out.to_path_buf();
    };
    let usable = std::fs::create_dir_all(&dir).is_ok()
        && pipeline::files::check_dir_accepts_files(&dir, &dir.join("reference-pt.exr")).is_ok();
    if usable {
        dir
    } else {
        say!(
            "warning: the reference cache `{}` cannot be written; caching in `{}` instead",
            dir.display(),
            out.display()
        );
        out.to_path_buf()
    }
}

fn run_scene(args: &Args, given: &Given, out: &Path) -> anyhow::Result<()> {
    let file = args
        .scene
        .as_ref()
        .expect("clap requires a scene without --beam");
    let scene = Scene::load_with(
        file,
        tracer::scene::LoadOptions::default().with_allow_outside_assets(args.allow_outside_assets),
    )?;
    let mut base = RenderJob::from_scene(&scene, Method::PathTraced);
    if given.has("scattering") {
        base.scattering = args.setup.scattering;
    }
    if let Some(d) = args.max_depth {
        base.max_depth = u32::try_from(d).context("--max-depth is too large")?;
    }
    let given = args.reference.as_deref().map(read_exr).transpose()?;
    prepare_out(out)?;
    let reference = match given {
        Some(film) => film,
        None => cached_scene_reference(args, &scene, &base, out)?,
    };
    let spp: Vec<u32> = doubling(1, args.max_spp)
        .into_iter()
        .map(|s| s as u32)
        .collect();
    let methods: Vec<Method> = args
        .methods
        .iter()
        .map(|m| args.estimator.apply(*m, scene.settings().averaging))
        .collect();
    let bar = pipeline::progress::bar((methods.len() * spp.len()) as u64, "converge", "runs");
    let mut finals = Vec::new();
    let mut log = RunLog::new(out);
    let runs = scene_study(
        &scene,
        &RenderJob {
            seed: args.seed,
            ..base.clone()
        },
        &methods,
        &spp,
        &reference,
        |run, outcome| {
            bar.inc(1);
            bar.suspend(|| log.record(run));
            keep_latest(&mut finals, &run.method, outcome.clone());
        },
    )?;
    bar.finish_and_clear();
    // Results first (they are small and the point of the run), images last.
    let reference_budget = args.reference.is_none().then_some(args.reference_spp);
    let summary = summarize_with_reference(&runs, reference_budget);
    let title = format!("{} — error against time", scene.display_name());
    write_outputs(
        out,
        &title,
        &runs,
        &summary,
        serde_json::json!({
            "scene": file.display().to_string(),
            "reference_spp": args.reference_spp,
            // Seconds each method took to prepare (profile tables, shape corrections), once
            // per method and not in its runs' times.
            "prepare_seconds": finals
                .iter()
                .map(|(name, o)| (name.clone(), serde_json::Value::from(o.prepare_seconds)))
                .collect::<serde_json::Map<_, _>>(),
        }),
    )?;
    let job = RenderJob {
        seed: args.seed,
        ..base
    };
    write_final_renders(&finals, &methods, &scene, &job, out)?;
    print_summary(&summary);
    note_prepare_times(&finals);
    say!(
        "wrote {}/convergence.csv, convergence.png, summary.json",
        out.display()
    );
    Ok(())
}

/// The path-traced reference of `scene` at `--reference-spp`: read from the reference cache,
/// else rendered into it (with a progress bar).
fn cached_scene_reference(
    args: &Args,
    scene: &Scene,
    base: &RenderJob,
    out: &Path,
) -> anyhow::Result<tracer::film::Film> {
    let file = args
        .scene
        .as_ref()
        .expect("clap requires a scene without --beam");
    let spp = u32::try_from(args.reference_spp).context("--reference-spp is too large")?;
    let key = reference_key(scene, base, spp)
        .with_context(|| format!("cannot read the inputs of `{}`", file.display()))?;
    let cache = reference_file(&cache_dir(args.cache_dir.as_deref(), out), key);
    if !cache.is_file() {
        say!(
            "rendering the path-traced reference at {spp} spp into {}",
            cache.display()
        );
    }
    let mut job = base.clone();
    job.progress = true;
    let (film, _) = scene_reference(scene, &job, spp, &cache)
        .with_context(|| format!("cannot make the reference `{}`", cache.display()))?;
    Ok(film)
}

/// Writes the largest run of every method as `<out>/<method>.exr` (with its PNG and sidecar),
/// rendered with `job`'s settings and that method.
fn write_final_renders(
    finals: &[(String, pipeline::job::RenderOutcome)],
    methods: &[Method],
    scene: &Scene,
    job: &RenderJob,
    out: &Path,
) -> anyhow::Result<()> {
    for (name, outcome) in finals {
        let method = *methods
            .iter()
            .find(|m| m.name() == name)
            .expect("every run comes from one of the methods");
        let job = RenderJob {
            method,
            ..job.clone()
        };
        write_render(outcome, scene, &job, &out.join(format!("{name}.exr")), 0.0)?;
    }
    Ok(())
}

/// A note for each method whose preparation took long enough to matter (it is not in its
/// runs' times).
fn note_prepare_times(finals: &[(String, pipeline::job::RenderOutcome)]) {
    for (name, outcome) in finals {
        if outcome.prepare_seconds >= 0.5 {
            say!(
                "note: preparing `{name}` took {:.1} s, once, not counted in its times above",
                outcome.prepare_seconds
            );
        }
    }
}

/// `convergence.csv` rewritten (atomically) after every finished run, so that a study stopped
/// early (an interrupt, a later failure) keeps the runs it finished.
struct RunLog {
    path: PathBuf,
    runs: Vec<experiments::converge::Run>,
}

impl RunLog {
    fn new(out: &Path) -> Self {
        Self {
            path: out.join("convergence.csv"),
            runs: Vec::new(),
        }
    }

    fn record(&mut self, run: &experiments::converge::Run) {
        self.runs.push(run.clone());
        let text = experiments::converge::csv(&self.runs);
        if let Err(e) = tracer::output::write_atomic(&self.path, text.as_bytes()) {
            say!("warning: {e}: the runs so far are not saved");
        }
    }
}

fn run_beam(args: &Args, out: &Path) -> anyhow::Result<()> {
    let setup = args.setup.setup()?;
    // The beam's half-space is index-matched (η = 1).
    let profile = args
        .estimator
        .profile
        .unwrap_or(ProfileModel::default_for(1.0));
    let given = args.reference.as_deref().map(read_exr).transpose()?;
    prepare_out(out)?;
    let reference: Vec<f64> = match given {
        Some(film) => film.pixels.iter().map(|p| p[0]).collect(),
        None => beam_reference(args, &setup, profile, out)?,
    };
    let budgets = BeamBudgets {
        photons: doubling(1 << 16, args.max_photons.max(1 << 16)),
        subsamples: doubling(1, args.max_subsamples)
            .into_iter()
            .map(|k| k as u32)
            .collect(),
    };
    let runs_total = beam_runs_total(&args.methods, &budgets);
    let bar = pipeline::progress::bar(runs_total as u64, "converge", "runs");
    let mut finals = Vec::new();
    let mut log = RunLog::new(out);
    let methods: Vec<Method> = args
        .methods
        .iter()
        .map(|&m| args.estimator.apply_options(m, None))
        .collect();
    let runs = beam_study(
        &setup,
        &methods,
        profile,
        &budgets,
        args.seed,
        BeamReference {
            values: &reference,
            min_radius: args.min_radius,
        },
        |run, map| {
            bar.inc(1);
            bar.suspend(|| log.record(run));
            keep_latest(&mut finals, &run.method, map.clone());
        },
    )?;
    bar.finish_and_clear();
    // Results first (they are small and the point of the run), images last.
    let reference_budget = args.reference.is_none().then_some(args.reference_photons);
    let summary = summarize_with_reference(&runs, reference_budget);
    let title = format!("beam ({}) — error against time", args.setup.tag());
    write_outputs(
        out,
        &title,
        &runs,
        &summary,
        serde_json::json!({ "setup": setup, "min_radius": args.min_radius }),
    )?;
    for (name, map) in &finals {
        write_beam_map(
            map,
            &setup,
            &out.join(format!("{name}.exr")),
            serde_json::json!({"seed": args.seed}),
        )?;
    }
    print_summary(&summary);
    say!(
        "wrote {}/convergence.csv, convergence.png, summary.json",
        out.display()
    );
    Ok(())
}

/// The beam's path-traced reference (red channel) with `--reference-photons`: read from
/// `<out>/reference-pt-<N>photons.exr`, else traced and written there.
fn beam_reference(
    args: &Args,
    setup: &experiments::beam::BeamSetup,
    profile: ProfileModel,
    out: &Path,
) -> anyhow::Result<Vec<f64>> {
    let path = out.join(format!(
        "reference-pt-{}photons.exr",
        args.reference_photons
    ));
    if path.is_file() {
        return Ok(read_exr(&path)?.pixels.iter().map(|p| p[0]).collect());
    }
    let map = run_method(
        setup,
        Method::PathTraced,
        profile,
        PhotonBudget::Count(args.reference_photons),
        1,
        args.seed.wrapping_add(REFERENCE_SEED_OFFSET),
        true,
    )?;
    write_beam_map(
        &map,
        setup,
        &path,
        serde_json::json!({"seed": args.seed.wrapping_add(REFERENCE_SEED_OFFSET)}),
    )?;
    Ok(map.values)
}

/// How many runs the beam study makes: one per photon budget for the path tracer, one per
/// subsample count for each BSSRDF method.
fn beam_runs_total(methods: &[Method], budgets: &BeamBudgets) -> usize {
    methods
        .iter()
        .map(|m| {
            if *m == Method::PathTraced {
                budgets.photons.len()
            } else {
                budgets.subsamples.len()
            }
        })
        .sum()
}
