//! Test harness, not a reference: the render calls several test modules share.

use bssrdf_core::Scattering;
use het_estimate::Averaging;
use tracer::integrator::{Method, PathCounters, PathIntegrator, PathOptions};
use tracer::render::{RenderOptions, Rendered, render};
use tracer::scene::Scene;

/// `method` on `scene` at `n × n` pixels, `spp` samples per pixel and `seed`, multiple
/// scattering, at most 8 surface interactions, the whole image.
pub fn render_multiple(
    scene: &Scene,
    method: Method,
    n: u32,
    spp: u32,
    seed: u64,
) -> Rendered<PathCounters> {
    let integrator = PathIntegrator::new(
        scene,
        method,
        PathOptions {
            scattering: Scattering::Multiple,
            max_depth: 8,
        },
    )
    .unwrap();
    render(n, n, &integrator, &RenderOptions::samples(spp, seed))
}

/// The example scene `examples/scenes/<file>` as shipped.
pub fn example_scene(file: &str) -> Scene {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
    let text = std::fs::read_to_string(dir.join(file)).unwrap();
    Scene::from_toml_str(&text, &dir, file).unwrap()
}

/// Sone with `samples` per averaging stage and the given averaging.
pub fn sone(samples: u32, averaging: Averaging) -> Method {
    "sone"
        .parse::<Method>()
        .unwrap()
        .with_estimator_samples(Some(samples))
        .with_averaging(Some(averaging))
}

/// The shared asset `../shared/assets/bunny.obj` (used by path, never copied), or `None` with
/// a note when it is absent, so that a test can skip itself; absent in CI is an error.
pub fn shared_bunny() -> Option<std::path::PathBuf> {
    let path = bunny_path();
    if path.is_file() {
        return Some(path);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "shared asset `../shared/assets/bunny.obj` is missing in CI"
    );
    eprintln!("note: `../shared/assets/bunny.obj` is absent: test skipped");
    None
}

/// `../shared/assets/bunny.obj` beside the repository's root, whether it is there or not.
pub fn bunny_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/bunny.obj")
}
