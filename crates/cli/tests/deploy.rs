//! The Slurm scripts of `deploy/slurm` run as Slurm runs them (issue 39, case 12): a task of a
//! job array, with the array's variables set by hand. N comes from `SHARDS`, never from the
//! array's bounds, so one failed task can be run again alone and a partial array renders
//! shards of the right split.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::{MINIMAL, Scratch, edit};

fn script(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../deploy/slurm")
        .join(name)
}

/// Runs `deploy/slurm/<name>` with bash in `s`, with the environment `env` (plus the binary
/// as `HET_BSSRDF`), and returns its exit code and stderr.
fn run_script(s: &Scratch, name: &str, env: &[(&str, &str)]) -> (Option<i32>, String) {
    let out = Command::new("bash")
        .arg(script(name))
        .current_dir(s.path())
        .env("HET_BSSRDF", env!("CARGO_BIN_EXE_het-bssrdf"))
        .envs(env.iter().copied())
        .output()
        .expect("run bash");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Task `i` of an array whose bounds are `lo..=hi`, for a split into `shards`.
fn task(s: &Scratch, i: u32, (lo, hi): (u32, u32), shards: &str) -> (Option<i32>, String) {
    let (i, lo, hi) = (i.to_string(), lo.to_string(), hi.to_string());
    run_script(
        s,
        "render-shard.sbatch",
        &[
            ("SCENE", "s.toml"),
            ("OUT", "out/frame"),
            ("SHARDS", shards),
            ("RENDER_ARGS", "--method pt"),
            ("SLURM_ARRAY_TASK_ID", &i),
            ("SLURM_ARRAY_TASK_MIN", &lo),
            ("SLURM_ARRAY_TASK_MAX", &hi),
            ("SLURM_CPUS_PER_TASK", "1"),
        ],
    )
}

/// The `shard` entry of a shard EXR's header.
fn shard_of(s: &Scratch, i: u32) -> String {
    let header =
        tracer::output::read_exr_metadata(&s.join(&format!("out/frame-shard-{i}.exr"))).unwrap();
    header.into_iter().find(|(k, _)| k == "shard").unwrap().1
}

#[test]
fn slurm_tasks_take_n_from_shards_not_from_the_array() {
    let s = Scratch::new();
    s.write(
        "s.toml",
        edit(MINIMAL, "width = 8\nheight = 8", "width = 9\nheight = 7"),
    );
    std::fs::create_dir(s.join("out")).unwrap();
    // `--array=0,1` of a 3-way split rendered tiles 0/2 and 1/2; now 0/3 and 1/3.
    for i in 0..2 {
        let (code, stderr) = task(&s, i, (0, 1), "3");
        assert_eq!(code, Some(0), "task {i}: {stderr}");
        assert_eq!(shard_of(&s, i), format!("{i}/3"));
    }
    // Re-running one task alone (`--array=2`) was refused (its array does not start at 0).
    let (code, stderr) = task(&s, 2, (2, 2), "3");
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(shard_of(&s, 2), "2/3");
    let (code, stderr) = run_script(&s, "merge.sbatch", &[("OUT", "out/frame"), ("SHARDS", "3")]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(s.join("out/frame.exr").is_file());
    // A task without a shard of the split, and no SHARDS at all, are errors that say why.
    let (code, stderr) = task(&s, 3, (0, 3), "3");
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("SHARDS=3"), "{stderr}");
    let (code, stderr) = run_script(
        &s,
        "render-shard.sbatch",
        &[
            ("SCENE", "s.toml"),
            ("OUT", "o"),
            ("SLURM_ARRAY_TASK_ID", "0"),
        ],
    );
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("SHARDS"), "{stderr}");
}
