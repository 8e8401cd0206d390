//! A glTF file downloaded from the web is untrusted input (issue 39, cases 4 and 5): its buffer
//! and image URIs may name only regular files inside the model's folder unless the user allows
//! others (`--allow-outside-assets`, or `allow_outside_assets = true` on the shape); devices
//! and FIFOs are refused at once, whatever the scope; and no error echoes another file's size
//! or contents.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::{NODES, Scratch, edit, gltf, run_within, tetra_bin, with_gltf};

/// `model/m.gltf` whose buffer URI is `uri` (`SCRATCH` in it stands for the scratch
/// directory), `model/tetra.bin`, a valid buffer outside the model's folder (`outside.bin`)
/// with a symbolic link to it inside (`model/link.bin`), and `s.toml` rendering the model.
fn setup(uri: &str) -> Scratch {
    let s = Scratch::new();
    s.write("model/tetra.bin", tetra_bin());
    s.write("outside.bin", tetra_bin());
    std::os::unix::fs::symlink(s.join("outside.bin"), s.join("model/link.bin")).unwrap();
    let uri = uri.replace("SCRATCH", &s.path().display().to_string());
    s.write("model/m.gltf", gltf(NODES, 12, 72, &uri));
    s.write("s.toml", with_gltf("model/m.gltf"));
    s
}

/// `render s.toml` with `extra` flags, within 30 s.
fn render(s: &Scratch, extra: &[&str]) -> common::Run {
    let mut args = vec!["render", "s.toml", "--method", "pt", "-o", "out.exr"];
    args.extend_from_slice(extra);
    run_within(s.path(), &args, 30)
}

#[track_caller]
fn assert_refused(s: &Scratch, extra: &[&str], needles: &[&str]) -> String {
    let r = render(s, extra);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    for n in ["m.gltf"].iter().chain(needles) {
        assert!(r.stderr.contains(n), "`{n}` missing from: {}", r.stderr);
    }
    assert!(!r.stderr.contains("panicked"), "{}", r.stderr);
    assert!(!s.join("out.exr").exists());
    r.stderr
}

/// `../`, absolute paths, `file://` and a symbolic link out of the folder were followed.
#[test]
fn buffer_uris_outside_the_models_folder_are_refused_unless_allowed() {
    for uri in [
        "../outside.bin",
        "SCRATCH/outside.bin",
        "file://SCRATCH/outside.bin",
        "link.bin",
    ] {
        let s = setup(uri);
        assert_refused(
            &s,
            &[],
            &[
                "buffer 0",
                "outside the model's folder",
                "--allow-outside-assets",
            ],
        );
        let r = render(&s, &["--allow-outside-assets"]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        std::fs::remove_file(s.join("out.exr")).unwrap();
        // The scene key allows it for its shape.
        let scene = std::fs::read_to_string(s.join("s.toml")).unwrap();
        s.write(
            "s.toml",
            edit(
                &scene,
                "path = \"model/m.gltf\"",
                "path = \"model/m.gltf\"\nallow_outside_assets = true",
            ),
        );
        let r = render(&s, &[]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
    }
}

/// An error message revealed the size of `/etc/passwd` ("declares byteLength 72 but holds N
/// bytes"); it is now refused as outside the folder, and even when allowed, the message says
/// only that the sizes differ.
#[test]
fn errors_never_echo_another_files_size_or_contents() {
    let secret = "root:x:0:0:a secret line\n".repeat(3);
    let s = setup("../secret.txt");
    s.write("secret.txt", &secret);
    let needles = ["buffer 0", "outside the model's folder"];
    let leaks = [
        format!("{} bytes", secret.len()),
        format!("{} bytes", secret.len().next_multiple_of(4)),
        "secret line".to_string(),
    ];
    for (flags, needles) in [
        (&[][..], &needles[..]),
        (
            &["--allow-outside-assets"][..],
            &["buffer 0", "byteLength 72"][..],
        ),
    ] {
        let stderr = assert_refused(&s, flags, needles);
        for leak in &leaks {
            assert!(!stderr.contains(leak.as_str()), "`{leak}` leaked: {stderr}");
        }
    }
}

/// jade.gltf (its base-colour image is read when the scene is loaded) with the image URI
/// replaced by `uri`, under `model/`, and a scene rendering it.
fn jade_with_image(uri: &str) -> Scratch {
    let jade = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/models/jade.gltf");
    let text = std::fs::read_to_string(jade).unwrap();
    let start = text
        .find("\"uri\": \"data:image/png")
        .expect("jade's image URI");
    let end = start + text[start..].find("\"\n").unwrap() + 1;
    let s = Scratch::new();
    s.write(
        "model/jade.gltf",
        format!("{}\"uri\": \"{uri}\"{}", &text[..start], &text[end..]),
    );
    let scene = common::MINIMAL.replace(
        "[[shape]]\ntype = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
        "[[shape]]\ntype = \"gltf\"\nname = \"jade\"\npath = \"model/jade.gltf\"",
    );
    assert!(scene.contains("jade.gltf"));
    s.write("s.toml", scene);
    s
}

/// An image URI of `/dev/zero` grew memory without bound (436 MB after 18 s), and a FIFO hung
/// for ever. Both are refused at once now, even with outside files allowed.
#[test]
fn image_uris_naming_devices_or_fifos_are_refused_at_once() {
    let run = |s: &Scratch, extra: &[&str]| {
        let mut args = vec!["render", "s.toml", "--method", "sone", "-o", "out.exr"];
        args.extend_from_slice(extra);
        run_within(s.path(), &args, 30)
    };
    let s = jade_with_image("/dev/zero");
    let r = run(&s, &[]);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(
        r.stderr.contains("image 0") && r.stderr.contains("outside"),
        "{}",
        r.stderr
    );
    let r = run(&s, &["--allow-outside-assets"]);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(r.stderr.contains("character device"), "{}", r.stderr);

    let s = jade_with_image("pipe.png");
    let made = Command::new("mkfifo")
        .arg(s.join("model/pipe.png"))
        .status()
        .unwrap()
        .success();
    assert!(made);
    let r = run(&s, &[]);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(
        r.stderr.contains("pipe.png") && r.stderr.contains("FIFO"),
        "{}",
        r.stderr
    );
    // The valid model, with its image in a file inside the folder, renders.
    let s = jade_with_image("veins.png");
    tracer::output::write_png(&common::gradient(16, 8), &s.join("model/veins.png"), 0.0).unwrap();
    let r = run(&s, &["--spp", "1"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}
