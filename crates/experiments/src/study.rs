//! Drivers of convergence studies: each method at doubling budgets, compared with a
//! path-traced reference. The reference is rendered with a seed different from every study
//! run, so that its noise is independent of theirs.

use std::path::{Path, PathBuf};

use bssrdf_core::ProfileModel;

use crate::beam::{BeamMap, BeamSetup, PhotonBudget, run_method};
use crate::converge::Run;
use crate::metrics::{MetricsError, compare, compare_films};
use pipeline::job::{RenderJob, RenderOutcome, prepare, render_prepared_with_bar, render_scene};
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

/// The cache key of the path-traced reference of `scene` rendered as `job` at `spp`: a 64-bit
/// FNV-1a hash of everything the render reads, namely the tool's version, the scene file's
/// bytes, the name and bytes of every mesh and texture file it read, and the job's spp, seed,
/// maximum depth and scattering selection. Any change to one of them gives another key, so a
/// stale reference is never reused.
pub fn reference_key(scene: &Scene, job: &RenderJob, spp: u32) -> std::io::Result<u64> {
    let mut h = Fnv1a::default();
    h.write(env!("CARGO_PKG_VERSION").as_bytes());
    if let Some(p) = &scene.source_path() {
        h.write(&std::fs::read(p)?);
    } else {
        h.write(scene.display_name().as_bytes());
    }
    for p in scene.input_files() {
        h.write(p.to_string_lossy().as_bytes());
        h.write(&std::fs::read(p)?);
    }
    h.write(&u64::from(spp).to_le_bytes());
    h.write(&job.seed.to_le_bytes());
    h.write(&u64::from(job.max_depth).to_le_bytes());
    h.write(job.scattering.name().as_bytes());
    Ok(h.0)
}

/// The file of the cached reference with `key` in the cache directory `dir`.
pub fn reference_file(dir: &Path, key: u64) -> PathBuf {
    dir.join(format!("reference-pt-{key:016x}.exr"))
}

/// The default cache directory: `$XDG_CACHE_HOME/het-bssrdf`, else `$HOME/.cache/het-bssrdf`;
/// `None` when neither variable is set.
pub fn default_cache_dir() -> Option<PathBuf> {
    let non_empty = |v: &str| {
        std::env::var_os(v)
            .filter(|s| !s.is_empty())
            .map(PathBuf::from)
    };
    non_empty("XDG_CACHE_HOME")
        .or_else(|| non_empty("HOME").map(|h| h.join(".cache")))
        .map(|d| d.join("het-bssrdf"))
}

/// 64-bit FNV-1a: a stable hash (unlike `std`'s), so that keys survive toolchain updates.
/// Each write is length-prefixed so that concatenations cannot collide.
struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    fn write(&mut self, bytes: &[u8]) {
        for &b in (bytes.len() as u64).to_le_bytes().iter().chain(bytes) {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
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
        // Prepared once per method (a shape correction is measured once, not per budget);
        // each run's `seconds` is its sampling time.
        let mut job = base.clone();
        job.method = method;
        let prepared = prepare(scene, &job)?;
        for &s in spp {
            job.budget = Budget::Samples(s);
            let outcome = render_prepared_with_bar(scene, &prepared, &job);
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

/// What a beam study compares its maps with.
#[derive(Debug, Clone, Copy)]
pub struct BeamReference<'a> {
    /// The reference map's values, row by row.
    pub values: &'a [f64],
    /// Pixels whose centre is closer than this to the beam are ignored (the singular peak).
    pub min_radius: f64,
}

/// Runs every method of a beam study and compares each map with `reference` (pixels whose
/// centre is closer than its `min_radius` to the beam are ignored).
pub fn beam_study(
    setup: &BeamSetup,
    methods: &[Method],
    profile: ProfileModel,
    budgets: &BeamBudgets,
    seed: u64,
    reference: BeamReference<'_>,
    mut on_run: impl FnMut(&Run, &BeamMap),
) -> Result<Vec<Run>, StudyError> {
    let BeamReference {
        values: reference,
        min_radius,
    } = reference;
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
