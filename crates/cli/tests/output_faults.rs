//! Outputs under faults (issue 39, cases 7 to 11): no temporary file survives a signal, a file
//! size limit or a killed run; SIGHUP keeps the finished passes; two runs never mix their files
//! in one output set; no output replaces an input of its run; an interrupt never replaces a
//! finished render with a partial one; and a closed stderr does not stop the work.

mod common;

use std::process::Stdio;

use common::{
    MINIMAL, Scratch, assert_no_temporaries, edit, gradient, interrupted_after_a_while, listing,
    sidecar, signal, spawn, wait_for, with_texture,
};

/// A render whose budget (10⁸ spp of 8 × 8 pixels) cannot finish during the test.
const ENDLESS: &[&str] = &[
    "render",
    "ok.toml",
    "--method",
    "pt",
    "--spp",
    "100000000",
    "--out",
    "out.exr",
];

/// [`MINIMAL`] at `w × h` pixels.
fn sized(w: u32, h: u32) -> String {
    edit(
        MINIMAL,
        "width = 8\nheight = 8",
        &format!("width = {w}\nheight = {h}"),
    )
}

/// Case 7: `merge` had no signal handler, so SIGINT or SIGTERM while it wrote left hidden
/// temporary files (an 8 MB PNG). The signal now removes them and exits 128 + the signal.
#[test]
fn a_signal_while_merge_writes_leaves_no_temporaries() {
    let s = Scratch::new();
    // 4000 × 3000: writing the merged files (a 144 MB EXR) takes long enough to be caught.
    s.write("big.toml", sized(4000, 3000));
    for i in 0..2 {
        let r = s.run(&[
            "render",
            "big.toml",
            "--method",
            "pt",
            "--tile",
            &format!("{i}/2"),
            "-o",
            &format!("s-{i}.exr"),
        ]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
    }
    for (sig, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        let child = spawn(s.path(), &["merge", "s-0.exr", "s-1.exr", "-o", "m.exr"]);
        // Signal it as soon as one of its temporary files exists.
        let writing = || {
            listing(s.path())
                .iter()
                .any(|f| f.starts_with(".m.") && f.ends_with(".tmp"))
        };
        let start = std::time::Instant::now();
        while !writing() {
            assert!(start.elapsed().as_secs() < 120, "merge never wrote");
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
        // SAFETY: a signal to the child this test started.
        assert_eq!(unsafe { libc::kill(child.id() as i32, sig) }, 0);
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{stderr}");
        assert_no_temporaries(s.path());
        assert!(
            !listing(s.path()).iter().any(|f| f.ends_with(".lock")),
            "lock file left: {:?}",
            listing(s.path())
        );
    }
}

/// Case 7: under `ulimit -f` a render died silently of SIGXFSZ (exit 153) and left its
/// temporary files. The limit now gives a write error like any other (EFBIG), exit 1, with
/// nothing left behind.
#[test]
fn a_file_size_limit_is_a_reported_write_error() {
    let s = Scratch::new();
    s.write("s.toml", sized(256, 256)); // noisy: its EXR and PNG far over 4 kB
    let r = common::run_limited(
        s.path(),
        "ulimit -f 8",
        &["render", "s.toml", "--method", "pt", "-o", "out.exr"],
        60,
    );
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(r.stderr.contains("File too large"), "{}", r.stderr);
    assert!(r.stderr.contains("out."), "{}", r.stderr);
    assert_no_temporaries(s.path());
    assert_eq!(listing(s.path()), ["s.toml"]);
}

/// Case 7: the temporary files of a killed run were never cleaned up. The next run that writes
/// the same output set removes them (and no other file).
#[test]
fn stale_temporaries_of_a_killed_run_are_removed() {
    let s = Scratch::new();
    s.write("s.toml", MINIMAL);
    let stale = [".out.exr.4194000.0.tmp", ".out.png.4194000.1.tmp"];
    for f in stale {
        s.write(f, "half an image");
    }
    s.write(".other.exr.4194000.2.tmp", "not ours");
    let r = s.run(&["render", "s.toml", "--method", "pt", "-o", "out.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(
        listing(s.path()),
        [
            ".other.exr.4194000.2.tmp",
            "out.exr",
            "out.json",
            "out.png",
            "s.toml"
        ]
    );
}

/// Case 7: SIGHUP (a closed terminal or ssh session) killed the render with all its finished
/// passes. It now keeps them, like SIGTERM, and exits 129.
#[test]
fn sighup_keeps_the_completed_passes() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let (status, stderr) = interrupted_after_a_while(s.path(), ENDLESS, "HUP");
    assert_eq!(status, Some(129), "{stderr}");
    assert!(stderr.contains("SIGHUP"), "{stderr}");
    let json = sidecar(&s.join("out.json"));
    assert_eq!(json["interrupted"], true, "{json}");
    assert!(json["spp"].as_u64().unwrap() > 0, "{json}");
    assert_no_temporaries(s.path());
}

/// Case 8: two renders to one `-o` mixed their files (the sidecar said seed 2, the EXR seed
/// 1). The second run is now refused while the first holds the set, naming it; the first's
/// files are all its own.
#[test]
fn a_second_run_to_one_output_set_is_refused() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let mut first_args = ENDLESS.to_vec();
    first_args.extend_from_slice(&["--seed", "1", "--checkpoint", "0.05"]);
    let first = spawn(s.path(), &first_args);
    wait_for("the first run's checkpoint", || {
        s.join("out.json").is_file()
    });
    let mut second = ENDLESS.to_vec();
    second.extend_from_slice(&["--seed", "2"]);
    // Refused at once (a second writer, not refused, would render for ever).
    let r = common::run_within(s.path(), &second, 60);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(
        r.stderr.contains("another het-bssrdf run") && r.stderr.contains("out.exr"),
        "{}",
        r.stderr
    );
    signal(&first, "INT");
    let out = first.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130));
    assert_eq!(sidecar(&s.join("out.json"))["seed"], 1);
    let header = tracer::output::read_exr_metadata(&s.join("out.exr")).unwrap();
    assert!(
        header.contains(&("seed".to_string(), "1".to_string())),
        "{header:?}"
    );
    assert_no_temporaries(s.path());
    // The lock went with the run: a new one may write the set.
    let r = s.run(&[
        "render", "ok.toml", "--method", "pt", "--seed", "2", "-o", "out.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(sidecar(&s.join("out.json"))["seed"], 2);
}

/// Case 9: `render marble.toml -o marble-veins.exr` replaced the scene's own texture with its
/// preview, and `merge … -o s-1.exr` overwrote one of its inputs. Both are refused, naming
/// the input, with nothing written.
#[test]
fn an_output_that_is_an_input_of_the_run_is_refused() {
    let s = Scratch::new();
    tracer::output::write_png(&gradient(16, 8), &s.join("veins.png"), 0.0).unwrap();
    s.write("tex.toml", with_texture("veins.png"));
    s.assert_rejected(
        &["render", "tex.toml", "--method", "pt", "-o", "veins.exr"],
        1,
        &["veins.png", "an input of this run"],
    );
    // Through a symbolic link, the same.
    std::os::unix::fs::symlink("tex.toml", s.join("alias.json")).unwrap();
    s.assert_rejected(
        &["render", "tex.toml", "--method", "pt", "-o", "alias.exr"],
        1,
        &["alias.json", "an input of this run"],
    );
    s.write("s.toml", sized(6, 5));
    for i in 0..2 {
        let r = s.run(&[
            "render",
            "s.toml",
            "--method",
            "pt",
            "--tile",
            &format!("{i}/2"),
            "-o",
            &format!("s-{i}.exr"),
        ]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
    }
    s.assert_rejected(
        &["merge", "s-0.exr", "s-1.exr", "-o", "s-1.exr"],
        1,
        &["s-1.exr", "an input of this run"],
    );
}

/// Case 10: an interrupt with a finished output already there replaced the finished 64-spp
/// files with a 27-spp partial, and the message did not say so. The partial now goes beside
/// it (`out.partial.exr`), and the message says the finished render was kept.
#[test]
fn an_interrupt_never_replaces_a_finished_render() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let r = s.run(&[
        "render", "ok.toml", "--method", "pt", "--spp", "4", "-o", "out.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let finished: Vec<Vec<u8>> = ["out.exr", "out.png", "out.json"]
        .iter()
        .map(|f| std::fs::read(s.join(f)).unwrap())
        .collect();
    let mut args = ENDLESS.to_vec();
    args.extend_from_slice(&["--checkpoint", "0.05"]);
    let (status, stderr) = interrupted_after_a_while(s.path(), &args, "INT");
    assert_eq!(status, Some(130), "{stderr}");
    assert!(
        stderr.contains("out.partial.exr") && stderr.contains("was kept"),
        "{stderr}"
    );
    for (f, bytes) in ["out.exr", "out.png", "out.json"].iter().zip(&finished) {
        assert!(
            &std::fs::read(s.join(f)).unwrap() == bytes,
            "{f} was replaced"
        );
    }
    let partial = sidecar(&s.join("out.partial.json"));
    assert_eq!(partial["interrupted"], true, "{partial}");
    assert_no_temporaries(s.path());
    // A run that finishes replaces the finished render and removes its own partial files.
    let r = s.run(&[
        "render",
        "ok.toml",
        "--method",
        "pt",
        "--spp",
        "8",
        "--checkpoint",
        "0.000001",
        "-o",
        "out.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(sidecar(&s.join("out.json"))["spp"], 8);
    assert!(!s.join("out.partial.exr").exists());
}

/// Case 11: with stderr closed (`2>&1 | head -c0`) a render panicked with exit 101 and
/// `reproduce` aborted after its first step. Diagnostics to a closed stream are now dropped:
/// the work is done and the exit status is the command's own.
#[test]
fn a_closed_stderr_does_not_stop_the_work() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let run_closed = |args: &[&str]| {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
            .args(args)
            .current_dir(s.path())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stderr.take()); // the reader goes away before the first line
        child.wait().unwrap().code()
    };
    assert_eq!(
        run_closed(&["render", "ok.toml", "--method", "pt", "-o", "out.exr"]),
        Some(0)
    );
    assert!(s.join("out.exr").is_file() && s.join("out.json").is_file());
    assert_eq!(
        run_closed(&["reproduce", "--scale", "tiny", "--out", "r"]),
        Some(0)
    );
    assert!(s.join("r/report.md").is_file());
    // An error is still an error (exit 1), even when it cannot be printed.
    assert_eq!(run_closed(&["render", "missing.toml"]), Some(1));
}
