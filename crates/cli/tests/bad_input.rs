//! Every class of bad input, through the built binary: a clear message naming the file and the
//! key (or the flag), a non-zero exit code (1 for run-time errors, 2 for usage errors), and
//! nothing written — the scratch directory, which is the working directory and holds the
//! inputs and the requested outputs, is byte-for-byte unchanged, with no temporary files left.
//!
//! `valid_inputs_succeed` runs the same fixtures unbroken, so that each rejection below is
//! caused by the one defect the test introduces.

mod common;

use bssrdf_core::Rgb;
use common::{CUBE_OBJ, MINIMAL, Scratch, edit, gradient, listing, with_obj, with_texture};
use tracer::output::{write_exr, write_png};

/// A render of `bad.toml` into `out.exr`.
const RENDER: &[&str] = &["render", "bad.toml", "--out", "out.exr"];

#[test]
fn valid_inputs_succeed() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    for method in ["pt", "sone"] {
        let out = format!("{method}.exr");
        let r = s.run(&["render", "ok.toml", "--method", method, "--out", &out]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
    }
    write_exr(&gradient(4, 3), &s.join("tex.exr")).unwrap();
    s.write("tex.toml", with_texture("tex.exr"));
    s.write("cube.obj", CUBE_OBJ);
    s.write("obj.toml", with_obj("cube.obj"));
    for scene in ["tex.toml", "obj.toml"] {
        let r = s.run(&["render", scene, "--method", "pt", "--out", "x.exr"]);
        assert_eq!(r.code, Some(0), "{scene}: {}", r.stderr);
    }
    let r = s.run(&[
        "beam",
        "--resolution",
        "4",
        "--subsamples",
        "1",
        "--out",
        "beam.exr",
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let r = s.run(&["compare", "pt.exr", "sone.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let files = listing(s.path());
    for f in [
        "pt.exr",
        "pt.png",
        "pt.json",
        "sone.exr",
        "x.exr",
        "beam.exr",
        "beam.png",
        "beam.json",
        "pt-diff.png",
    ] {
        assert!(files.iter().any(|x| x == f), "{f} missing from {files:?}");
    }
    assert!(
        !files
            .iter()
            .any(|f| f.ends_with(".tmp") || f.contains("probe")),
        "temporary files left: {files:?}"
    );
}

#[test]
fn malformed_toml_names_the_file_and_line() {
    let s = Scratch::new();
    s.write("bad.toml", edit(MINIMAL, "spp = 1", "spp = = 1"));
    s.assert_rejected(RENDER, 1, &["bad.toml:4", "malformed TOML"]);
    // converge creates its output directory only once the scene has loaded.
    s.assert_rejected(
        &["converge", "bad.toml", "--out", "conv"],
        1,
        &["bad.toml:4"],
    );
    s.write("bad.toml", edit(MINIMAL, "[camera]", "[camera"));
    s.assert_rejected(RENDER, 1, &["bad.toml:6", "malformed TOML"]);
}

#[test]
fn unknown_keys_name_the_key_path() {
    let s = Scratch::new();
    s.write("bad.toml", edit(MINIMAL, "spp = 1", "spp_per_pixel = 4"));
    s.assert_rejected(
        RENDER,
        1,
        &["bad.toml:4", "`render.spp_per_pixel`", "unknown field"],
    );
    s.write(
        "bad.toml",
        edit(MINIMAL, "sigma_s = 1.0", "sigma_s = 1.0\nsigma_t = 2.0"),
    );
    s.assert_rejected(RENDER, 1, &["bad.toml", "`material[0].sigma_t`"]);
    s.write(
        "bad.toml",
        edit(
            MINIMAL,
            "sigma_a = 0.1",
            "sigma_a = { type = \"stripe\", width = 1.0, values = [0.1, 0.2], colour = 3.0 }",
        ),
    );
    s.assert_rejected(RENDER, 1, &["bad.toml", "`material[0].sigma_a.colour`"]);
    s.write("bad.toml", format!("{MINIMAL}\n[extras]\na = 1\n"));
    s.assert_rejected(RENDER, 1, &["bad.toml", "`extras`"]);
}

#[test]
fn missing_mesh_file_names_the_path_and_the_shape() {
    let s = Scratch::new();
    s.write("bad.toml", with_obj("meshes/absent.obj"));
    s.assert_rejected(
        RENDER,
        1,
        &["bad.toml", "`shape[0].path`", "meshes/absent.obj"],
    );
}

#[test]
fn missing_scene_file_is_named() {
    let s = Scratch::new();
    s.assert_rejected(
        &["render", "absent.toml", "--out", "x.exr"],
        1,
        &["absent.toml"],
    );
    s.assert_rejected(
        &["converge", "absent.toml", "--out", "c"],
        1,
        &["absent.toml"],
    );
}

#[test]
fn missing_texture_of_a_used_material() {
    let s = Scratch::new();
    s.write("bad.toml", with_texture("textures/absent.exr"));
    s.assert_rejected(
        RENDER,
        1,
        &["bad.toml", "`texture[0].path`", "textures/absent.exr"],
    );
}

#[test]
fn unreadable_or_truncated_textures() {
    let s = Scratch::new();
    let key = "`texture[0].path`";
    // A directory where the image should be.
    std::fs::create_dir(s.join("dir.exr")).unwrap();
    s.write("bad.toml", with_texture("dir.exr"));
    s.assert_rejected(RENDER, 1, &["bad.toml", key, "dir.exr"]);
    // Not an EXR at all.
    s.write("junk.exr", "this is not an image\n");
    s.write("bad.toml", with_texture("junk.exr"));
    s.assert_rejected(RENDER, 1, &["bad.toml", key, "junk.exr", "decode"]);
    // Valid files cut in half.
    let full = s.join("full.exr");
    write_exr(&gradient(32, 32), &full).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    s.write("half.exr", &bytes[..bytes.len() / 2]);
    s.write("bad.toml", with_texture("half.exr"));
    s.assert_rejected(RENDER, 1, &["bad.toml", key, "half.exr", "decode"]);
    let full = s.join("full.png");
    write_png(&gradient(32, 32), &full, 0.0).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    s.write("half.png", &bytes[..bytes.len() / 2]);
    s.write("bad.toml", with_texture("half.png"));
    s.assert_rejected(RENDER, 1, &["bad.toml", key, "half.png", "decode"]);
    // No read permission (only testable without root).
    if common::permissions_ignored(s.path()) {
        eprintln!("note: running with permissions that ignore mode bits: unreadable file skipped");
    } else {
        use std::os::unix::fs::PermissionsExt;
        let p = s.join("full.exr");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o000)).unwrap();
        s.write("bad.toml", with_texture("full.exr"));
        s.assert_rejected(RENDER, 1, &["bad.toml", key, "full.exr"]);
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o644)).unwrap();
    }
}

#[test]
fn nan_inf_and_negative_texels_name_the_texel_and_file() {
    let s = Scratch::new();
    for (name, value, shown) in [
        ("nan.exr", f64::NAN, "NaN"),
        ("inf.exr", f64::INFINITY, "inf"),
        ("neg.exr", -0.5, "-0.5"),
    ] {
        let mut f = gradient(3, 2);
        f.set(2, 1, Rgb::new(0.3, value, 0.3));
        write_exr(&f, &s.join(name)).unwrap();
        s.write("bad.toml", with_texture(name));
        s.assert_rejected(
            RENDER,
            1,
            &[
                "bad.toml",
                "`texture[0].path`",
                name,
                "x = 2",
                "y = 1",
                "channel 1",
                shown,
            ],
        );
    }
}

#[test]
fn negative_or_nan_coefficients() {
    let s = Scratch::new();
    for (from, to, key, shown) in [
        (
            "sigma_a = 0.1",
            "sigma_a = -1",
            "`material[0].sigma_a`",
            "-1",
        ),
        (
            "sigma_s = 1.0",
            "sigma_s = nan",
            "`material[0].sigma_s`",
            "NaN",
        ),
        (
            "sigma_s = 1.0",
            "sigma_s = -inf",
            "`material[0].sigma_s`",
            "-inf",
        ),
        (
            "sigma_a = 0.1",
            "sigma_a = { type = \"check\", width = 1.0, values = [0.1, [0.2, nan, 0.1]] }",
            "`material[0].sigma_a`",
            "values[1]",
        ),
    ] {
        s.write("bad.toml", edit(MINIMAL, from, to));
        s.assert_rejected(RENDER, 1, &["bad.toml", key, shown]);
    }
    // The beam experiment's flags.
    s.assert_rejected(
        &["beam", "--sigma-s", "-1", "--out", "b.exr"],
        1,
        &["--sigma-s", "-1"],
    );
    s.assert_rejected(
        &[
            "beam",
            "--texture",
            "stripe",
            "--values",
            "0.1,nan",
            "--out",
            "b.exr",
        ],
        1,
        &["--values", "NaN"],
    );
}

#[test]
fn g_out_of_range() {
    let s = Scratch::new();
    for g in ["1.0", "-1.0", "1.5", "nan"] {
        s.write(
            "bad.toml",
            edit(MINIMAL, "sigma_s = 1.0", &format!("sigma_s = 1.0\ng = {g}")),
        );
        s.assert_rejected(RENDER, 1, &["bad.toml:19", "`material[0].g`", "|g|"]);
    }
    for g in ["1", "-1", "2.5"] {
        s.assert_rejected(&["beam", "--g", g, "--out", "b.exr"], 1, &["--g"]);
    }
}

#[test]
fn empty_and_degenerate_meshes() {
    let s = Scratch::new();
    let cases = [
        (
            "empty.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_string(),
            "no triangles",
        ),
        ("zero-bytes.obj", String::new(), "no triangles"),
        (
            "flat.obj",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n".into(),
            "degenerate",
        ),
        // A closed cube plus one triangle with a repeated vertex.
        (
            "cube-plus.obj",
            format!("{CUBE_OBJ}f 1 2 2\n"),
            "degenerate",
        ),
    ];
    for (name, text, words) in cases {
        s.write(name, text);
        s.write("bad.toml", with_obj(name));
        s.assert_rejected(RENDER, 1, &["bad.toml", "`shape[0]", name, words]);
    }
}

#[test]
fn open_mesh_is_refused_by_the_path_tracer_only() {
    let s = Scratch::new();
    // The cube without its +x face: 4 boundary edges.
    let open: String = CUBE_OBJ
        .lines()
        .filter(|l| *l != "f 2 3 7 6")
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(open.lines().count(), CUBE_OBJ.lines().count() - 1);
    s.write("lidless.obj", open);
    s.write("bad.toml", with_obj("lidless.obj"));
    s.assert_rejected(
        &["render", "bad.toml", "--method", "pt", "--out", "out.exr"],
        1,
        &[
            "bad.toml",
            "`shape[0]`",
            "`blob`",
            "lidless.obj",
            "not closed",
            "4 boundary edges",
        ],
    );
    let r = s.run(&["render", "bad.toml", "--method", "sone", "--out", "out.exr"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let files = listing(s.path());
    for f in ["out.exr", "out.png", "out.json"] {
        assert!(files.iter().any(|x| x == f), "{f} missing from {files:?}");
    }
}

#[test]
fn zero_or_negative_counts() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let usage = |args: &[&str], flag: &str| {
        s.assert_rejected(args, 2, &[flag, "positive"]);
    };
    usage(
        &["render", "ok.toml", "--spp", "0", "--out", "o.exr"],
        "--spp",
    );
    usage(
        &["render", "ok.toml", "--spp", "-3", "--out", "o.exr"],
        "--spp",
    );
    usage(
        &["render", "ok.toml", "--max-depth", "0", "--out", "o.exr"],
        "--max-depth",
    );
    usage(
        &["beam", "--resolution", "0", "--out", "b.exr"],
        "--resolution",
    );
    usage(
        &["beam", "--resolution", "-8", "--out", "b.exr"],
        "--resolution",
    );
    usage(
        &["beam", "--method", "pt", "--photons", "0", "--out", "b.exr"],
        "--photons",
    );
    usage(
        &[
            "beam",
            "--method",
            "pt",
            "--photons",
            "-5",
            "--out",
            "b.exr",
        ],
        "--photons",
    );
    usage(
        &["beam", "--subsamples", "0", "--out", "b.exr"],
        "--subsamples",
    );
    usage(
        &["converge", "ok.toml", "--max-spp", "0", "--out", "c"],
        "--max-spp",
    );
    usage(
        &["converge", "ok.toml", "--reference-spp", "-1", "--out", "c"],
        "--reference-spp",
    );
    usage(
        &["converge", "--beam", "--max-photons", "0", "--out", "c"],
        "--max-photons",
    );
    usage(
        &["render", "ok.toml", "--time", "0", "--out", "o.exr"],
        "--time",
    );
    for (from, to, key) in [
        ("spp = 1", "spp = 0", "`render.spp`"),
        ("spp = 1", "spp = -4", "`render.spp`"),
        ("width = 8", "width = 0", "`render.width`"),
        ("height = 8", "height = 0", "`render.height`"),
    ] {
        s.write("bad.toml", edit(MINIMAL, from, to));
        s.assert_rejected(RENDER, 1, &["bad.toml", key]);
    }
}

/// A scene whose render would take hours: the output checks must come first.
fn slow_scene() -> String {
    edit(
        MINIMAL,
        "width = 8\nheight = 8\nspp = 1",
        "width = 4096\nheight = 4096\nspp = 65536",
    )
}

#[test]
fn unwritable_outputs_fail_before_the_run() {
    let s = Scratch::new();
    s.write("slow.toml", slow_scene());
    std::fs::create_dir(s.join("taken.exr")).unwrap();
    let slow_beam = [
        "beam",
        "--method",
        "pt",
        "--resolution",
        "2048",
        "--photons",
        "1000000000000",
    ];
    for out in ["/nonexistent/dir/x.exr", "taken.exr"] {
        let what: &[&str] = if out == "taken.exr" {
            &["--out", "`taken.exr`", "is a directory"]
        } else {
            &["--out", out, "does not exist"]
        };
        s.assert_rejected(
            &["render", "slow.toml", "--method", "pt", "--out", out],
            1,
            what,
        );
        let mut args = slow_beam.to_vec();
        args.extend(["--out", out]);
        s.assert_rejected(&args, 1, what);
    }
    // converge: its output directory is a file, or inside a file.
    s.write("plain", "keep me");
    for out in ["plain", "plain/sub"] {
        s.assert_rejected(
            &["converge", "slow.toml", "--max-spp", "64", "--out", out],
            1,
            &["--out", "plain"],
        );
    }
    // A read-only directory (root ignores permissions: then this part is skipped).
    if common::permissions_ignored(s.path()) {
        eprintln!(
            "note: running with permissions that ignore read-only directories: read-only output directory skipped"
        );
        return;
    }
    use std::os::unix::fs::PermissionsExt;
    let ro = s.join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        s.assert_rejected(
            &["render", "slow.toml", "--method", "pt", "--out", "ro/x.exr"],
            1,
            &["--out", "ro/x.exr", "ermission denied"],
        );
        let mut args = slow_beam.to_vec();
        args.extend(["--out", "ro/b.exr"]);
        s.assert_rejected(&args, 1, &["--out", "ro/b.exr", "ermission denied"]);
        s.assert_rejected(
            &["converge", "slow.toml", "--out", "ro"],
            1,
            &["--out", "ro", "ermission denied"],
        );
    }));
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    if let Err(e) = result {
        std::panic::resume_unwind(e);
    }
}

#[test]
fn compare_bad_images() {
    let s = Scratch::new();
    write_exr(&gradient(4, 4), &s.join("ref.exr")).unwrap();
    write_exr(&gradient(5, 4), &s.join("wide.exr")).unwrap();
    write_png(&gradient(4, 4), &s.join("image.png"), 0.0).unwrap();
    s.write("notes.exr", "not an image\n");
    s.assert_rejected(
        &["compare", "absent.exr", "ref.exr"],
        1,
        &["absent.exr", "first argument"],
    );
    s.assert_rejected(
        &["compare", "ref.exr", "absent.exr"],
        1,
        &["absent.exr", "second argument"],
    );
    s.assert_rejected(
        &["compare", "image.png", "ref.exr"],
        1,
        &["image.png", "first argument", "decode"],
    );
    s.assert_rejected(
        &["compare", "ref.exr", "notes.exr"],
        1,
        &["notes.exr", "second argument", "decode"],
    );
    s.assert_rejected(
        &["compare", "wide.exr", "ref.exr"],
        1,
        &["wide.exr", "ref.exr", "sizes differ", "(5, 4)", "(4, 4)"],
    );
    // An explicit difference-image path is not written either.
    s.assert_rejected(
        &["compare", "wide.exr", "ref.exr", "--diff", "d.png"],
        1,
        &["sizes differ"],
    );
    // --min-counts: a count, and the reference's beam sidecar to convert values to photons.
    s.assert_rejected(
        &["compare", "ref.exr", "ref.exr", "--min-counts", "-1"],
        1,
        &["--min-counts", "-1"],
    );
    s.assert_rejected(
        &["compare", "ref.exr", "ref.exr", "--min-counts", "100"],
        1,
        &["--min-counts", "ref.json", "het-bssrdf beam"],
    );
    s.assert_rejected(
        &["compare", "wide.exr", "ref.exr", "--min-counts", "100"],
        1,
        &["sizes differ"],
    );
}

#[test]
fn unknown_method_names_the_accepted_ones() {
    let s = Scratch::new();
    s.write("ok.toml", MINIMAL);
    let accepted = [
        "jensen-in",
        "jensen-out",
        "endpoints",
        "segment",
        "sone",
        "`pt`",
    ];
    let with = |flag: &'static str| {
        let mut v = vec![flag, "`nope`"];
        v.extend(accepted);
        v
    };
    s.assert_rejected(
        &["render", "ok.toml", "--method", "nope", "--out", "o.exr"],
        2,
        &with("--method"),
    );
    s.assert_rejected(
        &["beam", "--method", "nope", "--out", "b.exr"],
        2,
        &with("--method"),
    );
    s.assert_rejected(
        &["converge", "ok.toml", "--methods", "pt,nope", "--out", "c"],
        2,
        &with("--methods"),
    );
    // The scene's own `render.estimator`.
    s.write(
        "bad.toml",
        edit(MINIMAL, "spp = 1", "spp = 1\nestimator = \"nope\""),
    );
    let mut needles = vec!["bad.toml", "render.estimator", "`nope`"];
    needles.extend(accepted);
    s.assert_rejected(RENDER, 1, &needles);
}

/// A reader that stops early (`het-bssrdf compare a.exr b.exr | head -1`) is not a failure:
/// the command exits 0 without a panic (`println!` used to panic on the closed pipe, exit
/// 101), and still writes its difference image.
#[test]
fn compare_into_a_closed_pipe_succeeds() {
    use std::process::{Command, Stdio};
    let s = Scratch::new();
    write_exr(&gradient(64, 64), &s.join("a.exr")).unwrap();
    write_exr(&gradient(64, 64), &s.join("b.exr")).unwrap();
    for json in [false, true] {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"));
        cmd.args(["compare", "a.exr", "b.exr", "--diff", "d.png"])
            .current_dir(s.path())
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        if json {
            cmd.arg("--json");
        }
        let mut child = cmd.spawn().expect("run het-bssrdf");
        // Close the reading end before the command has read its images and written its map.
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("wait");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "json {json}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(s.join("d.png").exists());
        std::fs::remove_file(s.join("d.png")).unwrap();
    }
}
