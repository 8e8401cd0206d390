//! One render of a scene with one method ([`RenderJob`] → [`RenderOutcome`]), prepared once
//! and rendered for as many budgets and seeds as a study needs. Its files are written by
//! [`crate::files`]. Shared by the `render`, `converge` and `reproduce` commands.

use bssrdf_core::Scattering;

use tracer::film::Film;
use tracer::integrator::{Method, PathCounters, PathIntegrator, PathOptions, RenderError};
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
    pub shard: Option<crate::sharding::ShardJob>,
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A method prepared once (as `converge` prepares each method) renders every budget and
    /// seed exactly as a fresh preparation does: the integrator keeps no state between renders.
    #[test]
    fn a_method_prepared_once_renders_as_a_fresh_one() {
        let scene = Scene::from_toml_str(
            include_str!("../../../examples/scenes/checker-slab.toml"),
            Path::new("."),
            "slab",
        )
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
