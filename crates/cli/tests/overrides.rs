//! Method overrides (`--profile`, `--estimator-samples`, `--averaging`, `--semi-minor`) reach
//! the runs and their sidecars, for `converge` (on a tiny scene), `beam` and `render`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The built-in checker slab at `size` × `size` pixels, with `render_extra` added to its
/// `[render]` table, written as `slab.toml` in `dir`.
fn tiny_slab(dir: &Path, size: u32, render_extra: &str) -> PathBuf {
    let scene = include_str!("../../../examples/scenes/checker-slab.toml")
        .replace("width = 128", &format!("width = {size}"))
        .replace("height = 128", &format!("height = {size}"))
        .replace("[render]", &format!("[render]\n{render_extra}"));
    let path = dir.join("slab.toml");
    std::fs::write(&path, scene).unwrap();
    path
}

#[test]
fn converge_writes_each_methods_largest_render_with_its_real_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = tiny_slab(dir.path(), 8, "");
    let out = dir.path().join("study");
    let status = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .env("HET_BSSRDF_CACHE_DIR", dir.path().join("cache"))
        .args([
            "converge",
            scene_path.to_str().unwrap(),
            "--methods",
            "pt,sone",
        ])
        .args(["--profile", "pbd", "--estimator-samples", "3"])
        .args([
            "--reference-spp",
            "2",
            "--max-spp",
            "2",
            "--out",
            out.to_str().unwrap(),
        ])
        .status()
        .unwrap();
    assert!(status.success());
    for name in ["pt", "sone"] {
        assert!(
            out.join(format!("{name}.exr")).is_file(),
            "{name}.exr missing"
        );
    }
    let sone: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sone.json")).unwrap()).unwrap();
    assert_eq!(sone["profile"], "pbd");
    assert_eq!(sone["spp"], 2, "the largest run is the one written");
    let params = sone["estimator_parameters"].as_str().unwrap();
    assert!(
        params.contains("Fixed(3)"),
        "estimator parameters lost: {params}"
    );
    let csv = std::fs::read_to_string(out.join("convergence.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 2 * 2, "{csv}");
}

#[test]
fn beam_uses_the_requested_estimator_samples() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map.exr");
    let status = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .args([
            "beam",
            "--preset",
            "stripe",
            "--method",
            "sone",
            "--estimator-samples",
            "3",
            "--averaging",
            "monte-carlo",
        ])
        .args([
            "--resolution",
            "6",
            "--subsamples",
            "1",
            "--out",
            out.to_str().unwrap(),
        ])
        .status()
        .unwrap();
    assert!(status.success());
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.with_extension("json")).unwrap())
            .unwrap();
    let c = &v["map"]["counters"];
    let (samples, estimates) = (
        c["estimator_samples"].as_u64().unwrap(),
        c["estimates"].as_u64().unwrap(),
    );
    assert!(estimates > 0);
    // Sone draws N points in the disk and N in the ellipse.
    assert_eq!(
        samples,
        6 * estimates,
        "{samples} samples for {estimates} estimates"
    );
    assert_eq!(v["averaging"], "monte-carlo");
    assert_eq!(c["prefiltered"], 0);
}

/// The default averaging is prefiltered: on the beam's flat half-space with its stripe
/// texture every estimate is answered by the closed form (no samples, no fallback), and the
/// sidecar says so. `--averaging` with an estimator that does not average over an ellipse is
/// refused.
#[test]
fn beam_prefilters_by_default_and_records_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("map.exr");
    let beam = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
            .args(["beam", "--preset", "check", "--resolution", "6"])
            .args(["--subsamples", "1", "--out", out.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap()
    };
    assert!(beam(&["--method", "sone"]).status.success());
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.with_extension("json")).unwrap())
            .unwrap();
    let c = &v["map"]["counters"];
    assert_eq!(v["averaging"], "prefiltered");
    assert!(c["estimates"].as_u64().unwrap() > 0);
    assert_eq!(c["prefiltered"], c["estimates"]);
    assert_eq!(c["estimator_samples"], 0);
    assert_eq!(c["prefilter_fallbacks"], 0);
    let refused = beam(&["--method", "jensen-out", "--averaging", "monte-carlo"]);
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("--averaging does not apply"), "{err}");
}

/// Runs `cmd`, asks for success, and reads the sidecar of its output `out`.
fn sidecar_of_run(cmd: &mut Command, out: &Path) -> serde_json::Value {
    let run = cmd.output().unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(out.with_extension("json")).unwrap()).unwrap()
}

/// `--semi-minor w/2` sizes Sone's ellipse with the paper's b = w/2 instead of the default
/// b = w: the beam map changes (on the check preset the ellipse then covers other cells), the
/// sidecar records the reading (`w` by default), the render sidecar's estimator parameters
/// carry it, and the flag is refused for an estimator without Sone's ellipse.
#[test]
fn semi_minor_reaches_sones_ellipse_and_the_sidecars() {
    let dir = tempfile::tempdir().unwrap();
    let map = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let v = sidecar_of_run(
            Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
                .args(["beam", "--preset", "check", "--resolution", "12"])
                .args(["--subsamples", "1", "--out", out.to_str().unwrap()])
                .args(extra),
            &out,
        );
        (v, std::fs::read(&out).unwrap())
    };
    let (full, full_exr) = map("full.exr", &["--method", "sone"]);
    let (half, half_exr) = map("half.exr", &["--method", "sone", "--semi-minor", "w/2"]);
    assert_eq!(half["semi_minor"], "w/2");
    assert_eq!(full["semi_minor"], "w");
    assert_ne!(half_exr, full_exr, "b = w gave the same map as b = w/2");

    let refused = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .args([
            "beam",
            "--preset",
            "check",
            "--resolution",
            "4",
            "--method",
            "kernel",
        ])
        .args(["--semi-minor", "w", "--out"])
        .arg(dir.path().join("refused.exr"))
        .output()
        .unwrap();
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("--semi-minor does not apply"), "{err}");
    assert!(!dir.path().join("refused.exr").exists());

    let scene_path = tiny_slab(dir.path(), 4, "");
    let out = dir.path().join("slab.exr");
    // The default is b = w; the flag selects the paper's b = w/2.
    for (flag, recorded) in [
        (None, "semi_minor: Width"),
        (Some("w/2"), "semi_minor: HalfWidth"),
    ] {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"));
        cmd.args(["render", scene_path.to_str().unwrap(), "--method", "sone"])
            .args(["--spp", "1", "--out", out.to_str().unwrap()]);
        if let Some(b) = flag {
            cmd.args(["--semi-minor", b]);
        }
        let v = sidecar_of_run(&mut cmd, &out);
        let params = v["estimator_parameters"].as_str().unwrap();
        assert!(params.contains(recorded), "{flag:?}: {params}");
    }
}

/// A scene file's `averaging` reaches the render when `--averaging` is absent, and the flag
/// wins over it when given (both applied by the same `RegionFlags::apply`).
#[test]
fn scene_averaging_applies_unless_the_flag_is_given() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = tiny_slab(dir.path(), 4, "averaging = \"monte-carlo\"");
    let out = dir.path().join("slab.exr");
    let render = |extra: &[&str]| {
        sidecar_of_run(
            Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
                .args(["render", scene_path.to_str().unwrap(), "--method", "sone"])
                .args(["--spp", "1", "--out", out.to_str().unwrap()])
                .args(extra),
            &out,
        )
    };
    assert_eq!(render(&[])["averaging"], "monte-carlo");
    assert_eq!(
        render(&["--averaging", "prefiltered"])["averaging"],
        "prefiltered"
    );
}
