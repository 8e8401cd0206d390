//! One render of a scene with one method, and its files: EXR (f32 RGB), a PNG preview and a
//! JSON sidecar (scene, method, spp, seed, wall time, rays traced, counters). Shared by the
//! `render`, `converge` and `reproduce` commands.

use std::path::{Path, PathBuf};
use std::str::FromStr;

use bssrdf_core::{ProfileModel, Scattering};
use het_estimate::Estimator;
use serde_json::json;

use crate::error::OutputError;
use crate::film::Film;
use crate::integrator::{Method, PathCounters, PathIntegrator, PathOptions, RenderError};
use crate::output::{OutputSet, exr_bytes, json_bytes, parent_dir, png_bytes, resolve_output};
use crate::render::{
    Budget, ProgressObserver, RenderObserver, RenderOptions, Rendered, render_observed,
};
use crate::scene::Scene;

/// Default most surface interactions per camera path.
pub const DEFAULT_MAX_DEPTH: u32 = 8;

impl FromStr for Method {
    type Err = String;
    /// `pt`, or an estimator name (`jensen-in`, `jensen-out`, `endpoints`, `segment`, `sone`)
    /// with the estimator's default parameters and each material's own profile.
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "pt" {
            return Ok(Method::PathTraced);
        }
        Estimator::from_str(s)
            .map(|estimator| Method::Bssrdf {
                estimator,
                profile: None,
            })
            .map_err(|e| format!("{e}; or `pt` for the path-traced reference"))
    }
}

impl Method {
    /// The method with `n` averaging samples per region (segment: on the chord; Sone: in the
    /// disk and in the ellipse); other methods are unchanged.
    pub fn with_estimator_samples(self, n: Option<u32>) -> Self {
        let Some(n) = n else { return self };
        let budget = het_estimate::SampleBudget::fixed(n.max(1));
        match self {
            Method::Bssrdf {
                estimator: Estimator::Segment(p),
                profile,
            } => Method::Bssrdf {
                estimator: Estimator::Segment(p.with_samples(budget)),
                profile,
            },
            Method::Bssrdf {
                estimator: Estimator::Sone(p),
                profile,
            } => Method::Bssrdf {
                estimator: Estimator::Sone(p.with_samples(budget)),
                profile,
            },
            m => m,
        }
    }

    /// The method with its profile model overridden (BSSRDF methods only).
    pub fn with_profile(self, profile: Option<ProfileModel>) -> Self {
        match self {
            Method::Bssrdf { estimator, .. } => Method::Bssrdf { estimator, profile },
            m => m,
        }
    }
}

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
}

impl RenderJob {
    /// The scene's own settings (spp, seed, max depth, scattering) with `method`.
    pub fn from_scene(scene: &Scene, method: Method) -> Self {
        Self {
            method,
            budget: Budget::Samples(scene.settings.spp),
            seed: scene.settings.seed,
            scattering: scene.settings.scattering.unwrap_or_default(),
            max_depth: scene.settings.max_depth.unwrap_or(DEFAULT_MAX_DEPTH),
            progress: false,
        }
    }

    /// The render loop's options for this job.
    pub fn options(&self) -> RenderOptions {
        RenderOptions {
            budget: self.budget,
            seed: self.seed,
            progress: self.progress,
            label: self.method.name().to_string(),
        }
    }
}

/// A finished render.
#[derive(Debug, Clone)]
pub struct RenderOutcome {
    /// The image.
    pub film: Film,
    /// Samples per pixel taken.
    pub spp: u32,
    /// Wall-clock seconds of sampling.
    pub seconds: f64,
    /// Rays traced (all kinds).
    pub rays: u64,
    /// Integrator counters.
    pub counters: PathCounters,
    /// The method's name.
    pub method: String,
    /// Warnings about the scene for this method (see [`PathIntegrator::warnings`]).
    pub warnings: Vec<String>,
    /// True when the render was interrupted: `spp` counts the completed passes only.
    pub interrupted: bool,
    /// True for a checkpoint written while the render goes on (`spp` so far).
    pub checkpoint: bool,
}

/// Renders `scene` with `job`.
pub fn render_scene(scene: &Scene, job: &RenderJob) -> Result<RenderOutcome, RenderError> {
    let (w, h) = scene.camera.resolution();
    let observer = ProgressObserver::new(&job.options(), w, h);
    let outcome = render_scene_observed(scene, job, &observer);
    observer.finish();
    outcome
}

/// [`render_scene`] reporting progress and completed passes to `observer`.
pub fn render_scene_observed(
    scene: &Scene,
    job: &RenderJob,
    observer: &dyn RenderObserver<PathCounters>,
) -> Result<RenderOutcome, RenderError> {
    let integrator = PathIntegrator::new(
        scene,
        job.method,
        PathOptions {
            scattering: job.scattering,
            max_depth: job.max_depth,
        },
    )?;
    let (w, h) = scene.camera.resolution();
    let rays_before = scene.geometry.rays_traced();
    let Rendered {
        pixels,
        spp,
        seconds,
        counters,
        interrupted,
        ..
    } = render_observed(w, h, &integrator, &job.options(), observer);
    let mut film = Film::new(w, h);
    film.pixels = pixels;
    Ok(RenderOutcome {
        film,
        spp,
        seconds,
        rays: scene.geometry.rays_traced() - rays_before,
        counters,
        method: job.method.name().to_string(),
        warnings: integrator.warnings().to_vec(),
        interrupted,
        checkpoint: false,
    })
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

/// Writes the EXR, the PNG preview (exposure in stops) and the JSON sidecar of a render.
pub fn write_render(
    outcome: &RenderOutcome,
    scene: &Scene,
    job: &RenderJob,
    exr: &Path,
    exposure: f64,
) -> Result<(), OutputError> {
    let (png, json_path) = sidecar_paths(exr);
    let profile = match job.method {
        Method::Bssrdf { profile, .. } => Some(
            profile
                .map(|p| p.name().to_string())
                .unwrap_or_else(|| "per material".to_string()),
        ),
        Method::PathTraced => None,
    };
    let estimator = match job.method {
        Method::Bssrdf { estimator, .. } => Some(format!("{estimator:?}")),
        Method::PathTraced => None,
    };
    let value = json!({
        "scene": scene.source_path.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| scene.display_name.clone()),
        "method": outcome.method,
        "profile": profile,
        "estimator_parameters": estimator,
        "scattering": job.scattering.name(),
        "spp": outcome.spp,
        "seed": job.seed,
        "max_depth": job.max_depth,
        "width": outcome.film.width,
        "height": outcome.film.height,
        "wall_seconds": outcome.seconds,
        "rays_traced": outcome.rays,
        "threads": rayon::current_num_threads(),
        "counters": outcome.counters,
        "warnings": outcome.warnings,
        "mean_rgb": outcome.film.mean().0,
        "interrupted": outcome.interrupted,
        "checkpoint": outcome.checkpoint,
        "max_collisions": crate::integrator::walk::collision_cap(),
    });
    // Small files first, images last, renamed into place together or not at all.
    let mut set = OutputSet::new();
    set.add(&json_path, json_bytes(&value, &json_path)?);
    set.add(&png, png_bytes(&outcome.film, &png, exposure)?);
    set.add(exr, exr_bytes(&outcome.film, exr)?);
    set.commit()
}
