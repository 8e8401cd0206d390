//! Fuzz target: the TOML scene parser must never panic. Any UTF-8 text gives either a scene or
//! a `SceneError` whose message names the scene file (every variant starts with
//! `file[:line]: key:`); non-UTF-8 input is not text and is skipped.
//!
//! Relative mesh and texture paths resolve against a directory that does not exist, so the
//! target exercises parsing and validation, not the file system. Inputs that ask for heavy but
//! valid work (icospheres of 7–9 subdivisions: 0.3–5 M triangles; half-space grids of 65–1024
//! subdivisions) are skipped: building their BVHs takes tens of seconds under the fuzzer's
//! instrumentation and says nothing about the parser (the limits themselves, > 9 and > 1024,
//! stay covered).

#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use tracer::scene::Scene;

/// The name the errors must carry.
const NAME: &str = "fuzz-scene.toml";

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if asks_for_heavy_meshes(text) {
        return;
    }
    let base = Path::new("/nonexistent/het-bssrdf-fuzz");
    if let Err(e) = Scene::from_toml_str(text, base, NAME) {
        let message = e.to_string();
        assert!(
            message.starts_with(NAME),
            "error does not name the scene file: {message}"
        );
    }
});

/// True when some `subdivisions = n` (decimal) has n in 7..=9 or 65..=1024.
fn asks_for_heavy_meshes(text: &str) -> bool {
    text.match_indices("subdivisions").any(|(i, key)| {
        let rest = text[i + key.len()..].trim_start();
        let Some(rest) = rest.strip_prefix('=') else {
            return false;
        };
        let digits: String = rest
            .trim_start()
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '_')
            .filter(|c| *c != '_')
            .collect();
        digits
            .parse::<u64>()
            .is_ok_and(|n| (7..=9).contains(&n) || (65..=1024).contains(&n))
    })
}
