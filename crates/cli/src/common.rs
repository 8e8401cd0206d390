//! Helpers shared by the subcommands: method names, output paths, summaries.

use crate::diag::say;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context;
use tracer::integrator::PathCounters;
use tracer::output::OutputLock;

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

/// Parses the `--out` of a command that writes an EXR with its PNG preview and JSON sidecar
/// beside it (same stem): the path must end in `.exr`, since any other extension would name
/// the preview or the sidecar and one file would overwrite another.
pub fn parse_exr_out(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("exr") => Ok(path),
        _ => Err(format!(
            "`{s}` must end in `.exr`: the image is an EXR, and its PNG preview and JSON sidecar \
             are written beside it with the same stem"
        )),
    }
}

/// Fails early, before a long run, if `path` (the `--out` value or its default) or the PNG and
/// JSON written beside it cannot be written. The library error names the path; the context
/// names the flag.
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
    pipeline::files::check_render_outputs(path).context("invalid --out")
}

/// Claims the output set of a run (the EXR `exr` and the PNG and JSON beside it) before its
/// work starts: every path writable ([`check_writable`]), none of them one of the run's
/// `inputs` (a scene's texture, a shard being merged), the set locked against other runs
/// ([`OutputLock`]), and the temporaries a killed run left for it removed. Keep the lock until
/// the last file is written.
pub fn claim_outputs(exr: &Path, inputs: &[&Path]) -> anyhow::Result<OutputLock> {
    check_writable(exr)?;
    let (png, json) = pipeline::files::sidecar_paths(exr);
    let set = [exr, png.as_path(), json.as_path()];
    tracer::output::check_not_inputs(set, inputs).context("invalid --out")?;
    let lock = OutputLock::acquire(exr).context("invalid --out")?;
    if lock.is_held() {
        for path in set {
            tracer::output::remove_stale_temporaries(path);
        }
    } else {
        say!(
            "note: the file system of `{}` cannot lock it: another run writing the same files \
             would not be detected",
            exr.display()
        );
    }
    Ok(lock)
}

/// One line per rare event that happened, so that no cap or fallback is silent. The estimators'
/// averaging counts, fallbacks below 1 % of the estimates and leaks below 10⁻⁵ of the paths,
/// only with `verbose` (the sidecar's `counters` always has them).
pub fn warn_counters(c: &PathCounters, verbose: bool) {
    if c.capped > 0 {
        say!(
            "warning: {} of {} paths ({:.3} %) hit the collision cap of {} collisions and were cut \
             (their remaining light is lost); --max-collisions sets the cap",
            c.capped,
            c.paths,
            100.0 * c.capped as f64 / c.paths.max(1) as f64,
            tracer::integrator::walk::collision_cap()
        );
    }
    // A handful of rays in millions lost to rounding at edges and corners changes no pixel
    // visibly: said with --verbose (the sidecar's `counters.leaks` always has the count); more
    // than one path in 100,000 is a mesh that is not closed where it claims to be.
    if c.leaks > 0 && (verbose || c.leaks * 100_000 > c.paths) {
        say!(
            "warning: {} rays inside a closed object found no boundary (paths ended; {:.2e} of \
             the paths)",
            c.leaks,
            c.leaks as f64 / c.paths.max(1) as f64
        );
    }
    if c.profile_failures > 0 {
        say!(
            "warning: {} profile evaluations rejected their estimated coefficients (those channels contributed 0)",
            c.profile_failures
        );
    }
    if c.estimator_fallbacks > 0 && (verbose || c.estimator_fallbacks * 100 > c.estimates) {
        say!(
            "note: {} estimates fell back to the endpoint average (every projection missed)",
            c.estimator_fallbacks
        );
    }
    if verbose && c.prefiltered + c.prefilter_fallbacks + c.lifted > 0 {
        let charts = if c.chart_fallbacks > 0 {
            format!(
                " ({} of them where the texture coordinates were not one affine map)",
                c.chart_fallbacks
            )
        } else {
            String::new()
        };
        say!(
            "averaging: of {} estimates, {} read a region in closed form, {} sampled a region on \
             the surface's local quadric (no rays), {} projected a region by rays{charts}",
            c.estimates,
            c.prefiltered,
            c.lifted,
            c.prefilter_fallbacks
        );
    }
}

/// Refuses, before anything is allocated, a render of the scene's `width × height` by
/// `method` that would not fit in the memory this process may still allocate (its films, and
/// the summed-area tables its preparation builds); the error names the scene's keys and the
/// figure.
pub fn check_image_memory(
    scene: &tracer::scene::Scene,
    method: tracer::integrator::Method,
    file: &Path,
) -> anyhow::Result<()> {
    let (width, height) = scene.camera().resolution();
    let tables = tracer::memory::area_table_bytes(scene, method);
    tracer::memory::check_render(width, height, tables)
        .with_context(|| format!("{}: render.width, render.height", file.display()))
}

/// Triangle count above which a render says how many triangles its shapes became.
const MANY_TRIANGLES: usize = 1_000_000;

/// Says how many triangles the scene's shapes became when that is many (spheres and other
/// primitives are tessellated), so that a slow build or a large memory use is explained.
pub fn note_triangles(scene: &tracer::scene::Scene) {
    let n = scene.geometry().triangle_count();
    if n >= MANY_TRIANGLES {
        say!(
            "note: the scene's {} objects are {:.1} million triangles",
            scene.geometry().object_count(),
            n as f64 / 1e6
        );
    }
}
