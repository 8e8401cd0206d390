//! `converge` keeps every run it finished: `convergence.csv` is rewritten after each run, so a
//! study interrupted (or failing) later still leaves its finished runs, and results are
//! written before images.

mod common;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Rows of a convergence CSV after its header.
fn rows(path: &std::path::Path) -> usize {
    std::fs::read_to_string(path).map_or(0, |t| t.lines().count().saturating_sub(1))
}

#[test]
fn an_interrupted_study_keeps_the_runs_it_finished() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(&scene, common::MINIMAL).unwrap();
    let out = dir.path().join("conv");
    // A long study: path tracing at doubling budgets up to 2^30 spp (over an hour on this
    // 8 × 8 scene; it is stopped after its first runs). Up to 2^22, as before, it took 20 s
    // in all, so on a loaded machine it could finish before the signal arrived.
    let mut child = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .arg("converge")
        .arg(&scene)
        .args([
            "--methods",
            "pt",
            "--reference-spp",
            "2",
            "--max-spp",
            "1073741824",
        ])
        .arg("--cache-dir")
        .arg(dir.path().join("cache"))
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let csv = out.join("convergence.csv");
    let start = Instant::now();
    while rows(&csv) < 2 {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no finished run was saved within 2 minutes"
        );
        assert!(child.try_wait().unwrap().is_none(), "the study ended early");
        std::thread::sleep(Duration::from_millis(50));
    }
    let kept = rows(&csv);
    assert!(
        child.try_wait().unwrap().is_none(),
        "the study ended before it was interrupted"
    );
    // SIGTERM, not SIGINT: a shell without job control starts background commands with
    // SIGINT ignored, and the child inherits that, so under `cmd &` (a CI script run in the
    // background) a SIGINT never reached the study, which then ran to its end.
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    assert!(
        !status.success(),
        "an interrupted study must not report success"
    );
    // The finished runs are still there (a rewrite is atomic: never a half-written file).
    assert!(rows(&csv) >= kept, "{} rows left of {kept}", rows(&csv));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.lines().nth(1).unwrap().starts_with("pt,"), "{text}");
}
