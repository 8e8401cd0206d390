//! One render of a scene with one method, and its files: EXR (f32 RGB), a PNG preview and a
//! JSON sidecar (scene, method, spp, seed, wall time, rays traced, counters). Shared by the
//! `render`, `converge` and `reproduce` commands.

use std::path::{Path, PathBuf};

use bssrdf_core::{ProfileModel, Scattering};
use serde_json::json;

use tracer::error::OutputError;
use tracer::film::Film;
use tracer::integrator::{Method, PathCounters, PathIntegrator, PathOptions, RenderError};
use tracer::output::{
    ExrAttribute, OutputSet, exr_bytes, json_bytes, parent_dir, png_bytes, resolve_output,
};
use tracer::render::{Budget, RenderObserver, RenderOptions, Rendered, Shard, render_observed};
use tracer::scene::Scene;

/// Default most surface interactions per camera path.
pub const DEFAULT_MAX_DEPTH: u32 = 8;

/// The scattering orders a scene counts when its `[render]` section does not say: all of
/// them, the light a picture shows. The artist parameters' colour inversion assumes every
/// order too (`docs/artist-parameters.md`). The paper's experiments exclude single
/// scattering, and their scenes say `scattering = "multiple"` themselves.
pub const DEFAULT_SCATTERING: Scattering = Scattering::All;

/// What a render needs besides the scene.
#[derive(Debug, Clone)]
pub struct RenderJob {
    /// How translucent objects are rendered.
    pub method: Method,
    /// Samples per pixel or time budget.
    pub budget: Budget,
    /// Seed of every random stream.
    pub seed: u64,
    /// Scattering orders counted.
    pub scattering: Scattering,
    /// Most surface interactions per path.
    pub max_depth: u32,
    /// Show a progress bar.
    pub progress: bool,
    /// Render one shard of the image (`render --tile I/N`), recorded in the files written;
    /// `None`: the whole image, as an ordinary render.
    pub shard: Option<crate::shard::ShardJob>,
}

impl RenderJob {
    /// The scene's own settings (spp, seed, max depth, scattering) with `method`. A scene
    /// without `[render] scattering` counts every order ([`DEFAULT_SCATTERING`]).
    pub fn from_scene(scene: &Scene, method: Method) -> Self {
        Self {
            method,
            budget: Budget::Samples(scene.settings().spp),
            seed: scene.settings().seed,
            scattering: scene.settings().scattering.unwrap_or(DEFAULT_SCATTERING),
            max_depth: scene.settings().max_depth.unwrap_or(DEFAULT_MAX_DEPTH),
            progress: false,
            shard: None,
        }
    }

    /// The render loop's options for this job.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            budget: self.budget,
            seed: self.seed,
            shard: self.shard.as_ref().map_or(Shard::WHOLE, |s| s.shard),
        }
    }
}

/// A finished render.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RenderOutcome {
    /// The image.
    pub film: Film,
    /// Samples per pixel taken.
    pub spp: u32,
    /// Wall-clock seconds of sampling.
    pub seconds: f64,
    /// Wall-clock seconds of preparing the method (profile tables, shape corrections), not
    /// in `seconds`; 0 for a checkpoint.
    pub prepare_seconds: f64,
    /// Rays traced (all kinds).
    pub rays: u64,
    /// Integrator counters.
    pub counters: PathCounters,
    /// The method's name.
    pub method: String,
    /// Warnings about the scene for this method (see [`PathIntegrator::warnings`]): one line
    /// each for the terminal, the full text for the sidecar.
    pub warnings: Vec<tracer::integrator::warnings::Warning>,
    /// What the preparation did that a user may want to know (see [`PathIntegrator::notes`]).
    pub notes: Vec<String>,
    /// How each translucent object was rendered (see [`PathIntegrator::object_plans`]).
    pub objects: Vec<(String, tracer::integrator::plan::ObjectPlan)>,
    /// True when the render was interrupted: `spp` counts the completed passes only.
    pub interrupted: bool,
    /// True for a checkpoint written while the render goes on (`spp` so far).
    pub checkpoint: bool,
}

impl RenderOutcome {
    /// The image of the passes completed so far, to be written as a checkpoint while the
    /// render goes on (`checkpoint` set, no warnings yet).
    pub fn checkpoint(
        film: Film,
        spp: u32,
        seconds: f64,
        rays: u64,
        counters: PathCounters,
        method: String,
    ) -> Self {
        Self {
            film,
            spp,
            seconds,
            prepare_seconds: 0.0,
            rays,
            counters,
            method,
            warnings: Vec::new(),
            notes: Vec::new(),
            objects: Vec::new(),
            interrupted: false,
            checkpoint: true,
        }
    }
}

impl RenderOutcome {
    /// `final`, `checkpoint` or `interrupted`, as a shard's EXR header records it.
    pub fn state(&self) -> &'static str {
        if self.interrupted {
            "interrupted"
        } else if self.checkpoint {
            "checkpoint"
        } else {
            "final"
        }
    }
}

/// Renders `scene` with `job`.
pub fn render_scene(scene: &Scene, job: &RenderJob) -> Result<RenderOutcome, RenderError> {
    Ok(render_prepared_with_bar(scene, &prepare(scene, job)?, job))
}

/// [`render_prepared`] behind a progress bar when `job.progress` is set.
pub fn render_prepared_with_bar(
    scene: &Scene,
    prepared: &Prepared<'_>,
    job: &RenderJob,
) -> RenderOutcome {
    let (w, h) = scene.camera().resolution();
    let observer = crate::progress::RenderBar::new(job.method.name(), w, h, job.progress);
    let outcome = render_prepared(scene, prepared, job, &observer);
    observer.finish();
    outcome
}

/// [`render_scene`] reporting progress and completed passes to `observer`.
pub fn render_scene_observed(
    scene: &Scene,
    job: &RenderJob,
    observer: &dyn RenderObserver<PathCounters>,
) -> Result<RenderOutcome, RenderError> {
    let prepared = prepare(scene, job)?;
    Ok(render_prepared(scene, &prepared, job, observer))
}

/// A method prepared for a scene, to render at any budget and seed: what
/// [`render_prepared`] needs besides the job.
pub struct Prepared<'s> {
    integrator: PathIntegrator<'s>,
    seconds: f64,
}

impl Prepared<'_> {
    /// Wall-clock seconds the preparation took.
    pub fn seconds(&self) -> f64 {
        self.seconds
    }
}

/// Prepares `job.method` for `scene` (profile tables, estimators, shape corrections), with a
/// progress bar for the long parts when `job.progress` is set. An interrupt during a shape
/// correction stops it ([`RenderError::Interrupted`]).
pub fn prepare<'s>(scene: &'s Scene, job: &RenderJob) -> Result<Prepared<'s>, RenderError> {
    let t0 = std::time::Instant::now();
    let bar = crate::progress::PrepareBar::new(job.progress);
    let integrator = PathIntegrator::new_observed(
        scene,
        job.method,
        PathOptions {
            scattering: job.scattering,
            max_depth: job.max_depth,
        },
        &bar,
    );
    bar.finish();
    Ok(Prepared {
        integrator: integrator?,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Renders `scene` with a method `prepared` for it, at `job`'s budget and seed (its method,
/// scattering and depth are the preparation's), reporting to `observer`.
pub fn render_prepared(
    scene: &Scene,
    prepared: &Prepared<'_>,
    job: &RenderJob,
    observer: &dyn RenderObserver<PathCounters>,
) -> RenderOutcome {
    let integrator = &prepared.integrator;
    let (w, h) = scene.camera().resolution();
    let rays_before = scene.geometry().rays_traced();
    let Rendered {
        pixels,
        spp,
        seconds,
        counters,
        interrupted,
        ..
    } = render_observed(w, h, integrator, &job.options(), observer);
    let mut film = Film::new(w, h);
    film.pixels = pixels;
    RenderOutcome {
        film,
        spp,
        seconds,
        prepare_seconds: prepared.seconds,
        rays: scene.geometry().rays_traced() - rays_before,
        counters,
        method: integrator.method().name().to_string(),
        warnings: integrator.warnings().to_vec(),
        notes: integrator.notes(),
        objects: integrator.object_plans(),
        interrupted,
        checkpoint: false,
    }
}

/// The PNG and JSON paths written beside an EXR path.
pub fn sidecar_paths(exr: &Path) -> (PathBuf, PathBuf) {
    (exr.with_extension("png"), exr.with_extension("json"))
}

/// Checks before a long run that `path` can be written: it is not a directory, device or FIFO
/// and its parent is a directory ([`resolve_output`]: a symbolic link is checked at its target),
/// and that directory accepts new files (see [`check_dir_accepts_files`]).
pub fn check_output_path(path: &Path) -> Result<(), OutputError> {
    let target = resolve_output(path)?;
    check_dir_accepts_files(&parent_dir(&target), path)
}

/// [`check_output_path`] for a render's EXR and the PNG and JSON written beside it.
pub fn check_render_outputs(exr: &Path) -> Result<(), OutputError> {
    let (png, json) = sidecar_paths(exr);
    [exr, &png, &json]
        .into_iter()
        .try_for_each(check_output_path)
}

/// Checks that `dir` exists and that a file can be created in it, by creating and removing an
/// empty probe file (`.het-bssrdf-probe.<pid>.<n>`): a read-only or foreign directory fails
/// here, before a long run, instead of when its results are written. `path` is the output the
/// error names.
pub fn check_dir_accepts_files(dir: &Path, path: &Path) -> Result<(), OutputError> {
    static PROBE_COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
        });
    }
    let probe = dir.join(format!(
        ".het-bssrdf-probe.{}.{}",
        std::process::id(),
        PROBE_COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            action: "create files in the directory of",
            source,
        })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The metadata every render's EXR header holds (pbrt-v4 style): the generator, the samples
/// per pixel, the seed, the method and the profile (`None`: `"none"`, the path tracer). No
/// render time: a duration makes every file unique, and the bytes of an EXR must be
/// reproducible for a given seed (its hash is a render's fingerprint; a merge of shards
/// rebuilds the same header from the shards' sidecars). The time is the sidecar's
/// `wall_seconds`.
pub fn render_attributes(
    spp: u32,
    seed: u64,
    method: &str,
    profile: Option<&str>,
) -> Vec<(&'static str, ExrAttribute)> {
    vec![
        (
            "generator",
            ExrAttribute::Text(format!("het-bssrdf {}", env!("CARGO_PKG_VERSION"))),
        ),
        (
            "samplesPerPixel",
            ExrAttribute::Int(i32::try_from(spp).unwrap_or(i32::MAX)),
        ),
        ("seed", ExrAttribute::Text(seed.to_string())),
        ("method", ExrAttribute::Text(method.to_string())),
        (
            "profile",
            ExrAttribute::Text(profile.unwrap_or("none").to_string()),
        ),
    ]
}

/// The profile of each translucent object a BSSRDF renders under `method` (by name, in the
/// scene's order): the method's own `--profile`, else the material's, else the default for
/// its η ([`tracer::scene::Translucent::profile_model`]). Objects the path tracer renders
/// have none.
pub fn object_profiles(scene: &Scene, method: Method) -> Vec<(String, ProfileModel)> {
    let Method::Bssrdf { profile, .. } = method else {
        return Vec::new();
    };
    let plans = tracer::integrator::plan::plan(scene, method);
    scene
        .translucent_objects()
        .filter(|(i, _)| plans[*i as usize].is_some_and(|p| !p.path_traced))
        .map(|(i, t)| {
            (
                scene.objects()[i as usize].name.clone(),
                t.profile_model(profile),
            )
        })
        .collect()
}

/// What a render's sidecar and EXR header record as its `profile`: the one profile every
/// BSSRDF-rendered object used (`tabulated`), or each object's (`` `a`: tabulated, `b`: pbd ``)
/// when they differ; `None` when no object is rendered by a BSSRDF.
pub fn profile_summary(profiles: &[(String, ProfileModel)]) -> Option<String> {
    let first = profiles.first()?.1;
    Some(if profiles.iter().all(|(_, m)| *m == first) {
        first.name().to_string()
    } else {
        profiles
            .iter()
            .map(|(n, m)| format!("`{n}`: {}", m.name()))
            .collect::<Vec<_>>()
            .join(", ")
    })
}

/// Writes the EXR, the PNG preview (exposure in stops) and the JSON sidecar of a render.
/// The preview and the sidecar's `mean_rgb` are made from the values the EXR holds (`f32`,
/// [`Film::as_stored`]), so that an image assembled from files (a merge of shards) writes the
/// same ones. A shard (`job.shard`) also records which rows it holds and the scene's hash, in
/// the EXR header and in the sidecar's `shard`.
pub fn write_render(
    outcome: &RenderOutcome,
    scene: &Scene,
    job: &RenderJob,
    exr: &Path,
    exposure: f64,
) -> Result<(), OutputError> {
    let profiles = object_profiles(scene, job.method);
    let profile = profile_summary(&profiles);
    let estimator = match job.method {
        Method::Bssrdf { estimator, .. } => Some(format!("{estimator:?}")),
        Method::PathTraced => None,
    };
    let film = outcome.film.as_stored();
    let mut attributes =
        render_attributes(outcome.spp, job.seed, &outcome.method, profile.as_deref());
    let time_budget_seconds = match job.budget {
        Budget::Time(t) => Some(t.as_secs_f64()),
        Budget::Samples(_) => None,
    };
    let checksum = crate::shard::pixel_checksum(&film);
    if let Some(shard) = &job.shard {
        attributes.extend(shard.attributes(&crate::shard::ShardHeader {
            exposure,
            time_budget_seconds,
            state: outcome.state(),
            pixel_checksum: checksum.clone(),
        }));
    }
    let value = json!({
        "scene": scene.source_path().map(|p| p.display().to_string()).unwrap_or_else(|| scene.display_name().to_string()),
        "method": outcome.method,
        "profile": profile,
        "estimator_parameters": estimator,
        "averaging": job.method.averaging().map(|a| a.name()),
        "artist_invert": scene
            .artist_inversions()
            .into_iter()
            .map(|(name, at)| (name, serde_json::Value::from(at.name())))
            .collect::<serde_json::Map<_, _>>(),
        "scattering": job.scattering.name(),
        "spp": outcome.spp,
        "time_budget_seconds": time_budget_seconds,
        "seed": job.seed,
        "max_depth": job.max_depth,
        "width": film.width,
        "height": film.height,
        "wall_seconds": outcome.seconds,
        "prepare_seconds": outcome.prepare_seconds,
        "notes": outcome.notes,
        "objects": outcome
            .objects
            .iter()
            .map(|(name, p)| json!({
                "name": name,
                "rendered_by": match job.method {
                    Method::Bssrdf { estimator, .. } if !p.path_traced => estimator.name(),
                    _ => "pt",
                },
                "profile": profiles.iter().find(|(n, _)| n == name).map(|(_, m)| m.name()),
                "shape_correction": p.corrected,
                "clear_medium": p.clear,
                "optically_small": p.small,
            }))
            .collect::<Vec<_>>(),
        "rays_traced": outcome.rays,
        "threads": rayon::current_num_threads(),
        "counters": outcome.counters,
        "warnings": outcome.warnings.iter().map(|w| w.detail.as_str()).collect::<Vec<_>>(),
        "mean_rgb": film.mean().0,
        "pixel_checksum": checksum,
        "interrupted": outcome.interrupted,
        "checkpoint": outcome.checkpoint,
        "max_collisions": tracer::integrator::walk::collision_cap(),
        "preview_exposure": exposure,
        "shard": job.shard.as_ref().map(crate::shard::ShardJob::to_json),
    });
    write_image_set(
        &film,
        &attributes,
        &crate::provenance::stamped(value),
        exr,
        exposure,
    )
}

/// Writes `film` as an EXR with `attributes` in its header, its PNG preview (exposure in
/// stops) and the sidecar `sidecar` beside it ([`sidecar_paths`]): small files first, images
/// last, renamed into place together or not at all ([`OutputSet`]).
pub fn write_image_set(
    film: &Film,
    attributes: &[(&str, ExrAttribute)],
    sidecar: &serde_json::Value,
    exr: &Path,
    exposure: f64,
) -> Result<(), OutputError> {
    let (png, json_path) = sidecar_paths(exr);
    let mut set = OutputSet::new();
    set.add(&json_path, json_bytes(sidecar, &json_path)?);
    set.add(&png, png_bytes(film, &png, exposure)?);
    set.add(exr, exr_bytes(film, exr, attributes)?);
    set.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A method prepared once (as `converge` prepares each method) renders every budget and
    /// seed exactly as a fresh preparation does: the integrator keeps no state between renders.
    #[test]
    fn a_method_prepared_once_renders_as_a_fresh_one() {
        let scene = Scene::from_toml_str(crate::scenes::CHECKER_SLAB, Path::new("."), "slab")
            .unwrap()
            .with_resolution(12, 12)
            .unwrap();
        let method: Method = "sone".parse().unwrap();
        let mut job = RenderJob::from_scene(&scene, method);
        let prepared = prepare(&scene, &job).unwrap();
        for (spp, seed) in [(2, 3), (1, 5), (2, 3)] {
            job.budget = Budget::Samples(spp);
            job.seed = seed;
            let reused = render_prepared(&scene, &prepared, &job, &tracer::render::NoObserver);
            let fresh = render_scene(&scene, &job).unwrap();
            assert_eq!(
                reused.film.pixels, fresh.film.pixels,
                "spp {spp}, seed {seed}"
            );
            assert_eq!(reused.prepare_seconds, prepared.seconds());
            assert!(fresh.prepare_seconds > 0.0);
        }
    }
}
