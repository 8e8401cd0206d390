//! A render's files: EXR (f32 RGB), a PNG preview and a JSON sidecar (scene, method, spp,
//! seed, wall time, rays traced, counters), written together and atomically; and the checks
//! that they can be written, made before a long run.

use std::path::{Path, PathBuf};

use bssrdf_core::ProfileModel;
use serde_json::json;

use tracer::error::OutputError;
use tracer::film::Film;
use tracer::integrator::Method;
use tracer::output::{
    ExrAttribute, OutputSet, exr_bytes, json_bytes, parent_dir, png_bytes, resolve_output,
};
use tracer::render::Budget;
use tracer::scene::Scene;

use crate::job::{RenderJob, RenderOutcome};

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
    let checksum = crate::sharding::pixel_checksum(&film);
    if let Some(shard) = &job.shard {
        attributes.extend(shard.attributes(&crate::sharding::ShardHeader {
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
        "shard": job.shard.as_ref().map(crate::sharding::ShardJob::to_json),
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
