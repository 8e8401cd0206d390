//! Faults and load through the built binary: interrupts keep the completed passes, checkpoints
//! do not change a pixel, outputs that are not ours (symbolic links, FIFOs) are never replaced,
//! every output path is checked before the work starts, and absurd sizes are refused with the
//! figure instead of overflowing or aborting.

mod common;

use std::process::Command;

use common::{
    MINIMAL, Scratch, assert_no_temporaries, edit, gradient, interrupted_after_a_while, sidecar,
    signal, spawn, wait_for, with_texture,
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

/// The first SIGINT or SIGTERM writes the completed passes, says so in the sidecar and exits
/// with 128 + the signal number.
#[test]
fn an_interrupt_writes_the_completed_passes() {
    for (sig, code) in [("INT", 130), ("TERM", 143)] {
        let s = Scratch::new();
        s.write("ok.toml", MINIMAL);
        let (status, stderr) = interrupted_after_a_while(s.path(), ENDLESS, sig);
        assert_eq!(status, Some(code), "SIG{sig}: {stderr}");
        assert!(stderr.contains(&format!("SIG{sig}")), "{stderr}");
        let json = sidecar(&s.join("out.json"));
        assert_eq!(json["interrupted"], true, "{json}");
        let spp = json["spp"].as_u64().unwrap();
        assert!(spp > 0 && spp < 100_000_000, "spp {spp}");
        let film = tracer::output::read_exr(&s.join("out.exr")).unwrap();
        assert!(film.pixels.iter().all(|p| p.is_finite()));
        assert!(film.mean().0.iter().any(|&v| v > 0.0), "black image");
        assert!(s.join("out.png").is_file());
        assert_no_temporaries(s.path());
    }
}

/// An interrupt while a shape correction is being measured (17 s for this box on a 2-core
/// machine) stops the preparation within a step, writes nothing, and exits with 130. Were the
/// preparation deaf to it, the render would run it to the end and then report an interrupt
/// before its first pass instead.
#[test]
fn an_interrupt_stops_the_preparation() {
    let s = Scratch::new();
    let scene = edit(
        &edit(
            &edit(
                MINIMAL,
                "sigma_a = 0.1\nsigma_s = 1.0\n",
                "sigma_a = 0.0001\nsigma_s = 50.0\nshape_correction = true\n",
            ),
            "min = [-1.0, -1.0, -1.0]",
            "min = [-20.0, -20.0, -20.0]",
        ),
        "max = [1.0, 1.0, 0.0]",
        "max = [20.0, 20.0, 0.0]",
    );
    s.write("slow.toml", scene);
    let (status, stderr) = interrupted_after_a_while(
        s.path(),
        &[
            "render",
            "slow.toml",
            "--method",
            "sone",
            "--out",
            "out.exr",
        ],
        "INT",
    );
    assert_eq!(status, Some(130), "{stderr}");
    assert!(
        stderr.contains("stopped while its shape correction was being measured"),
        "{stderr}"
    );
    assert!(!s.join("out.exr").exists() && !s.join("out.json").exists());
    assert_no_temporaries(s.path());
}

/// `--checkpoint` writes the image while the render runs, and a full render's pixels do not
/// depend on whether checkpoints were written.
#[test]
fn checkpoints_are_written_and_change_no_pixel() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let child = spawn(s.path(), &[ENDLESS, &["--checkpoint", "0.2"]].concat());
    let json = s.join("out.json");
    wait_for("a checkpoint", || json.is_file());
    let first = sidecar(&json);
    assert_eq!(first["checkpoint"], true, "{first}");
    assert_eq!(first["interrupted"], false, "{first}");
    assert!(s.join("out.exr").is_file() && s.join("out.png").is_file());
    signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(143));
    assert_no_temporaries(s.path());

    let base = ["render", "ok.toml", "--method", "pt", "--spp", "300"];
    let r = s.run(&[&base[..], &["--out", "plain.exr"]].concat());
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let r = s.run(
        &[
            &base[..],
            &["--out", "ckpt.exr", "--checkpoint", "0.000001"],
        ]
        .concat(),
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(sidecar(&s.join("ckpt.json"))["checkpoint"], false);
    let a = tracer::output::read_exr(&s.join("plain.exr")).unwrap();
    let b = tracer::output::read_exr(&s.join("ckpt.exr")).unwrap();
    assert_eq!(a.pixels, b.pixels);
}

/// `beam --method pt` interrupted writes the photons traced so far.
#[test]
fn an_interrupted_beam_writes_its_photons() {
    let s = Scratch::new();
    let (status, stderr) = interrupted_after_a_while(
        s.path(),
        &[
            "beam",
            "--method",
            "pt",
            "--photons",
            "100000000000",
            "--resolution",
            "8",
            "--out",
            "beam.exr",
        ],
        "INT",
    );
    assert_eq!(status, Some(130), "{stderr}");
    let json = sidecar(&s.join("beam.json"));
    assert_eq!(json["interrupted"], true, "{json}");
    let photons = json["map"]["samples"].as_u64().unwrap();
    assert!(photons > 0 && photons < 100_000_000_000, "{photons}");
    assert_no_temporaries(s.path());
}

/// `--out` through a symbolic link writes the link's target and keeps the link.
#[test]
fn a_symlinked_output_is_written_through() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    std::fs::create_dir(s.join("real")).unwrap();
    s.write("real/target.exr", b"old");
    std::os::unix::fs::symlink("real/target.exr", s.join("link.exr")).unwrap();
    let r = s.run(&["render", "ok.toml", "--method", "pt", "--out", "link.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let meta = std::fs::symlink_metadata(s.join("link.exr")).unwrap();
    assert!(meta.file_type().is_symlink(), "the link was replaced");
    let film = tracer::output::read_exr(&s.join("real/target.exr")).unwrap();
    assert_eq!((film.width, film.height), (8, 8));
    assert_no_temporaries(s.path());
}

/// `--out` naming a FIFO (or a device) is refused before the render and left alone.
#[test]
fn a_fifo_output_is_refused_and_kept() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let ok = Command::new("mkfifo")
        .arg(s.join("pipe.exr"))
        .status()
        .expect("run mkfifo")
        .success();
    assert!(ok);
    let r = s.run(&["render", "ok.toml", "--method", "pt", "--out", "pipe.exr"]);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(
        r.stderr.contains("pipe.exr") && r.stderr.contains("FIFO"),
        "{}",
        r.stderr
    );
    use std::os::unix::fs::FileTypeExt;
    let ft = std::fs::symlink_metadata(s.join("pipe.exr"))
        .unwrap()
        .file_type();
    assert!(ft.is_fifo(), "the FIFO was replaced");
    assert!(!s.join("pipe.png").exists() && !s.join("pipe.json").exists());
    assert_no_temporaries(s.path());
}

/// A sidecar path that is a directory, or a parent that is a file, is found before the render.
#[test]
fn every_output_path_is_checked_first() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    std::fs::create_dir(s.join("out.json")).unwrap();
    s.assert_rejected(
        &["render", "ok.toml", "--out", "out.exr"],
        1,
        &["--out", "out.json", "directory"],
    );
    s.write("file.txt", "x");
    s.assert_rejected(
        &["render", "ok.toml", "--out", "file.txt/out.exr"],
        1,
        &["--out", "file.txt", "is a file, not a directory"],
    );
}

/// `beam --subsamples K` with K × K beyond 32 bits is refused with the flag named (it gave 0
/// samples and a NaN map, or silently 131,073 samples).
#[test]
fn absurd_subsamples_are_refused() {
    let s = Scratch::new();
    for k in ["65536", "65537", "18446744073709551615"] {
        s.assert_rejected(
            &[
                "beam",
                "--resolution",
                "4",
                "--subsamples",
                k,
                "--out",
                "b.exr",
            ],
            1,
            &["--subsamples", "points per pixel"],
        );
    }
}

/// An image too large for memory is refused with the figure before anything is allocated.
#[test]
fn huge_images_are_refused_with_the_figure() {
    let s = Scratch::new();
    for size in ["100000", "4294967295"] {
        let scene = edit(
            &edit(MINIMAL, "width = 8\n", &format!("width = {size}\n")),
            "height = 8\n",
            &format!("height = {size}\n"),
        );
        s.write("big.toml", scene);
        s.assert_rejected(
            &["render", "big.toml", "--out", "big.exr"],
            1,
            &[
                "big.toml",
                "render.width",
                "render",
                "of memory",
                "available",
            ],
        );
        std::fs::remove_file(s.join("big.toml")).unwrap();
    }
    s.assert_rejected(
        &["beam", "--resolution", "4294967295", "--out", "b.exr"],
        1,
        &["--resolution", "beam map", "of memory"],
    );
}

/// An optically huge medium: `--max-collisions` bounds each path, and the cut paths are
/// reported (stderr and sidecar) with the cap.
#[test]
fn the_collision_cap_is_controlled_and_reported() {
    let s = Scratch::new();
    s.write(
        "thick.toml",
        edit(
            &edit(MINIMAL, "sigma_a = 0.1", "sigma_a = 0.0"),
            "sigma_s = 1.0",
            "sigma_s = 1000.0",
        ),
    );
    let r = s.run(&[
        "render",
        "thick.toml",
        "--method",
        "pt",
        "--max-collisions",
        "50",
        "--out",
        "t.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stderr.contains("hit the collision cap of 50 collisions")
            && r.stderr.contains("--max-collisions"),
        "{}",
        r.stderr
    );
    let json = sidecar(&s.join("t.json"));
    assert_eq!(json["max_collisions"], 50, "{json}");
    assert!(json["counters"]["capped"].as_u64().unwrap() > 0, "{json}");
}

/// A PNG texture over the image decoder's memory limit: the error names the limit and the
/// environment variable that raises it, and raising it lets the render run.
#[test]
fn a_png_over_the_decoder_limit_names_the_limit_and_the_override() {
    let s = Scratch::new();
    tracer::output::write_png(&gradient(1024, 1024), &s.join("big.png"), 0.0).unwrap();
    s.write("tex.toml", with_texture("big.png"));
    let run = |limit_mb: &str| {
        Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
            .args(["render", "tex.toml", "--method", "pt", "--out", "o.exr"])
            .env("HET_BSSRDF_TEXTURE_LIMIT_MB", limit_mb)
            .current_dir(s.path())
            .output()
            .unwrap()
    };
    let out = run("1");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    for needle in [
        "big.png",
        "memory limit of 1 MiB",
        "HET_BSSRDF_TEXTURE_LIMIT_MB",
    ] {
        assert!(stderr.contains(needle), "`{needle}` missing: {stderr}");
    }
    let out = run("64");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A scene whose primitives become many triangles says how many.
#[test]
fn a_large_triangle_count_is_reported() {
    let s = Scratch::new();
    s.write(
        "sphere.toml",
        edit(
            MINIMAL,
            "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
            "type = \"sphere\"\nmaterial = \"m\"\ncentre = [0.0, 0.0, 0.0]\nradius = 1.0\nsubdivisions = 8",
        ),
    );
    let r = s.run(&["render", "sphere.toml", "--method", "pt", "--out", "s.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    // 20 · 4⁸ = 1,310,720 triangles.
    assert!(r.stderr.contains("1.3 million triangles"), "{}", r.stderr);
}

/// Primitives whose triangles would not fit in memory are refused, with the figure, before
/// they are generated (4,000 spheres of 5,242,880 triangles: 2 × 10¹⁰ triangles).
#[test]
fn huge_tessellations_are_refused_with_the_figure() {
    let s = Scratch::new();
    let sphere = "[[shape]]\ntype = \"sphere\"\nmaterial = \"m\"\ncentre = [0.0, 0.0, -5.0]\nradius = 1.0\nsubdivisions = 9\n";
    s.write("many.toml", format!("{MINIMAL}\n{}", sphere.repeat(4000)));
    s.assert_rejected(
        &["render", "many.toml", "--out", "m.exr"],
        1,
        &[
            "many.toml",
            "subdivisions",
            "million triangles",
            "of memory",
        ],
    );
}

/// A second signal while the first one's output is being written quits at once: exit 128 +
/// the signal, "quitting" on stderr, no temporary file left, and the image on disk is still a whole one
/// (the last checkpoint's, or the final one if its rename came first). The image is large
/// (2000²) so that writing it takes far longer than the gap between the two signals.
#[test]
fn a_second_interrupt_quits_at_once() {
    let s = Scratch::new();
    s.write(
        "big.toml",
        edit(
            MINIMAL,
            "width = 8\nheight = 8",
            "width = 2000\nheight = 2000",
        ),
    );
    let child = spawn(
        s.path(),
        &[
            "render",
            "big.toml",
            "--method",
            "pt",
            "--spp",
            "100000000",
            "--out",
            "out.exr",
            "--checkpoint",
            "0.1",
        ],
    );
    let json = s.join("out.json");
    wait_for("a checkpoint", || json.is_file());
    // Two different signals back to back: a second SIGINT sent at once could be merged with
    // the first by the kernel (pending signals of one kind do not queue), and a pause between
    // them lets a loaded machine finish the write first.
    signal(&child, "INT");
    signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        matches!(out.status.code(), Some(130 | 143)),
        "{:?}: {stderr}",
        out.status
    );
    assert!(stderr.contains("quitting"), "{stderr}");
    assert_no_temporaries(s.path());
    let film = tracer::output::read_exr(&s.join("out.exr")).expect("a whole image");
    assert_eq!((film.width, film.height), (2000, 2000));
}
