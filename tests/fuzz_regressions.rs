//! Inputs found by the scene-parser fuzzer (`fuzz/`, target `scene_toml`; see
//! `docs/stability.md`), kept as regression tests: each must load or fail with an error that
//! names the file, never panic — in the test profile too, where debug assertions are on.

use std::path::Path;

use tracer::scene::Scene;

/// Loads `text` as the fuzz target does and returns the error message, if any.
fn load(text: &str) -> Result<Scene, String> {
    let name = "fuzz-regression.toml";
    Scene::from_toml_str(text, Path::new("/nonexistent/het-bssrdf-fuzz"), name).map_err(|e| {
        let message = e.to_string();
        assert!(
            message.starts_with(name),
            "error without the file name: {message}"
        );
        message
    })
}

/// Fuzz crash `crash-f1afc319…` (a one-digit change of a valid scene: half-space
/// subdivisions 16 → 15): obvhs's CWBVH validation, run after every build when debug
/// assertions are on, asserted that each node's quantisation origin lies within an absolute
/// 1e-5 of its parent's bounds, which f32 rounding at the tracer's scaled coordinates (up to
/// ~4e3) does not guarantee. A valid scene, so it must load.
#[test]
fn half_space_with_15_subdivisions_loads() {
    let scene = load(include_str!(
        "fuzz_regressions/cwbvh_validation_half_space_15.toml"
    ))
    .expect("valid scene");
    assert_eq!(scene.objects().len(), 4); // slab, box, ball, and the quad light's geometry
}
