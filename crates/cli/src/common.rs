//! Helpers shared by the subcommands: method names, output paths, progress bars, summaries.

use std::path::Path;
use std::time::Duration;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use tracer::integrator::{Method, PathCounters};

/// Parses a `--method` value (`pt` or an estimator name).
pub fn parse_method(s: &str) -> Result<Method, String> {
    s.parse()
}

/// Parses a duration in seconds (> 0).
pub fn parse_seconds(s: &str) -> Result<Duration, String> {
    let v: f64 = s
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    if !(v > 0.0 && v.is_finite()) {
        return Err(format!(
            "the time budget must be a positive number of seconds, got {s}"
        ));
    }
    Ok(Duration::from_secs_f64(v))
}

/// Applies `--max-collisions`, if given (see [`tracer::integrator::walk::set_collision_cap`]).
pub fn set_collision_cap(cap: Option<u64>) {
    if let Some(cap) = cap {
        tracer::integrator::walk::set_collision_cap(cap);
    }
}

/// Parses a positive integer.
pub fn parse_positive(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(v) if v > 0 => Ok(v),
        _ => Err(format!("expected a positive whole number, got `{s}`")),
    }
}

/// A progress bar on stderr over `len` units (hidden when stderr is not a terminal).
pub fn progress(len: u64, prefix: &str, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{prefix:>14}} [{{bar:40}}] {{human_pos}}/{{human_len}} {unit}  {{elapsed}}<{{eta}}"
        ))
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_prefix(prefix.to_string());
    bar
}

/// Fails early, before a long run, if `path` (the `--out` value or its default) or the PNG and
/// JSON written beside it cannot be written. The library error names the path; the context
/// names the flag.
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
    tracer::experiment::run::check_render_outputs(path).context("invalid --out")
}

/// One line per rare event that happened, so that no cap or fallback is silent.
pub fn warn_counters(c: &PathCounters) {
    if c.capped > 0 {
        eprintln!(
            "warning: {} of {} paths ({:.3} %) hit the collision cap of {} collisions and were cut \
             (their remaining light is lost); --max-collisions sets the cap",
            c.capped,
            c.paths,
            100.0 * c.capped as f64 / c.paths.max(1) as f64,
            tracer::integrator::walk::collision_cap()
        );
    }
    if c.leaks > 0 {
        eprintln!(
            "warning: {} rays inside a closed object found no boundary (paths ended)",
            c.leaks
        );
    }
    if c.estimator_fallbacks > 0 {
        eprintln!(
            "note: {} estimates fell back to the endpoint average (every projection missed)",
            c.estimator_fallbacks
        );
    }
}

/// Refuses, before anything is allocated, a render of the scene's `width × height` that would
/// not fit in memory; the error names the scene's keys and the figure.
pub fn check_image_memory(width: u32, height: u32, scene: &Path) -> anyhow::Result<()> {
    tracer::memory::check_render(width, height)
        .with_context(|| format!("{}: render.width, render.height", scene.display()))
}

/// Triangle count above which a render says how many triangles its shapes became.
const MANY_TRIANGLES: usize = 1_000_000;

/// Says how many triangles the scene's shapes became when that is many (spheres and other
/// primitives are tessellated), so that a slow build or a large memory use is explained.
pub fn note_triangles(scene: &tracer::scene::Scene) {
    let n = scene.geometry.triangle_count();
    if n >= MANY_TRIANGLES {
        eprintln!(
            "note: the scene's {} objects are {:.1} million triangles",
            scene.geometry.object_count(),
            n as f64 / 1e6
        );
    }
}
