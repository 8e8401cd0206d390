//! Drivers of convergence studies: each method at doubling budgets, compared with a
//! path-traced reference. The reference is rendered with a seed different from every study
//! run, so that its noise is independent of theirs.

use std::path::{Path, PathBuf};

use bssrdf_core::ProfileModel;

use crate::beam::{BeamMap, BeamSetup, PhotonBudget, run_method};
use crate::converge::Run;
use crate::metrics::{MetricsError, compare, compare_films};
use crate::run::{RenderJob, RenderOutcome, render_scene};
use tracer::error::SceneError;
use tracer::film::Film;
use tracer::integrator::{Method, RenderError};
use tracer::output::{read_exr, write_exr};
use tracer::render::Budget;
use tracer::scene::Scene;

/// Seed offset of references, so that they never share random streams with the study runs.
pub const REFERENCE_SEED_OFFSET: u64 = 0x5eed_0000;

/// Why a study failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StudyError {
    /// A render could not start.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The beam scene was invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The reference does not match the runs.
    #[error("reference: {0}")]
    Metrics(#[from] MetricsError),
    /// Reading or writing a file.
    #[error(transparent)]
    Output(#[from] tracer::error::OutputError),
}

/// Where the cached path-traced reference of a scene file lives: beside the scene, with its
/// spp and seed in the name.
pub fn reference_path(scene_file: &Path, spp: u32, seed: u64) -> PathBuf {
    let stem = scene_file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    scene_file.with_file_name(format!("{stem}.reference-pt-{spp}spp-seed{seed}.exr"))
}

/// The path-traced reference of `scene` at `spp`: read from `cache` if it exists, otherwise
/// rendered (seed `seed + REFERENCE_SEED_OFFSET`) and written there. Returns the film and
/// whether it was rendered now.
pub fn scene_reference(
    scene: &Scene,
    job: &RenderJob,
    spp: u32,
    cache: &Path,
) -> Result<(Film, bool), StudyError> {
    if cache.is_file() {
        return Ok((read_exr(cache)?, false));
    }
    let mut job = job.clone();
    job.method = Method::PathTraced;
    job.budget = Budget::Samples(spp);
    job.seed = job.seed.wrapping_add(REFERENCE_SEED_OFFSET);
    let outcome = render_scene(scene, &job)?;
    write_exr(&outcome.film, cache)?;
    Ok((outcome.film, true))
}

/// Renders `scene` with every method at every spp in `spp` and compares with `reference`.
/// `on_run` sees each run and its outcome (to write images, report progress).
pub fn scene_study(
    scene: &Scene,
    base: &RenderJob,
    methods: &[Method],
    spp: &[u32],
    reference: &Film,
    mut on_run: impl FnMut(&Run, &RenderOutcome),
) -> Result<Vec<Run>, StudyError> {
    let mut runs = Vec::new();
    for &method in methods {
        for &s in spp {
            let mut job = base.clone();
            job.method = method;
            job.budget = Budget::Samples(s);
            let outcome = render_scene(scene, &job)?;
            let run = Run {
                method: method.name().to_string(),
                budget: s as u64,
                unit: "spp",
                seconds: outcome.seconds,
                metrics: compare_films(&outcome.film, reference, None)?,
            };
            on_run(&run, &outcome);
            runs.push(run);
        }
    }
    Ok(runs)
}

/// Budgets of a beam study.
#[derive(Debug, Clone)]
pub struct BeamBudgets {
    /// Photon counts of the `pt` runs.
    pub photons: Vec<u64>,
    /// K of the BSSRDF runs (K × K points per pixel).
    pub subsamples: Vec<u32>,
}

/// Runs every method of a beam study and compares each map with `reference` (pixels whose
/// centre is closer than `min_radius` to the beam are ignored).
#[allow(clippy::too_many_arguments)]
pub fn beam_study(
    setup: &BeamSetup,
    methods: &[Method],
    profile: ProfileModel,
    budgets: &BeamBudgets,
    seed: u64,
    reference: &[f64],
    min_radius: f64,
    mut on_run: impl FnMut(&Run, &BeamMap),
) -> Result<Vec<Run>, StudyError> {
    let n = setup.resolution as usize;
    if reference.len() != n * n {
        let side = (reference.len() as f64).sqrt() as u32;
        return Err(MetricsError::SizeMismatch {
            test: (n as u32, n as u32),
            reference: (side, side),
        }
        .into());
    }
    let e = setup.extent;
    let keep = |i: usize| {
        let (x, y) = (i % n, i / n);
        let px = -e + (x as f64 + 0.5) * 2.0 * e / n as f64;
        let py = e - (y as f64 + 0.5) * 2.0 * e / n as f64;
        px.hypot(py) >= min_radius
    };
    let mut runs = Vec::new();
    for &method in methods {
        let (label, budgets): (String, Vec<(u64, &'static str)>) = match method {
            Method::PathTraced => (
                "pt".into(),
                budgets.photons.iter().map(|&p| (p, "photons")).collect(),
            ),
            Method::Bssrdf { profile: p, .. } => (
                format!("{}-{}", method.name(), p.unwrap_or(profile)),
                budgets
                    .subsamples
                    .iter()
                    .map(|&k| ((k * k) as u64, "points/pixel"))
                    .collect(),
            ),
        };
        for (budget, unit) in budgets {
            let (photons, sub) = match method {
                Method::PathTraced => (PhotonBudget::Count(budget), 1),
                _ => (
                    PhotonBudget::Count(1),
                    (budget as f64).sqrt().round() as u32,
                ),
            };
            let map = run_method(setup, method, profile, photons, sub, seed, &|_| {})?;
            let run = Run {
                method: label.clone(),
                budget: if unit == "photons" {
                    map.samples
                } else {
                    budget
                },
                unit,
                seconds: map.seconds,
                metrics: compare(&map.values, reference, 1, keep)?,
            };
            on_run(&run, &map);
            runs.push(run);
        }
    }
    Ok(runs)
}
