//! Mesh files that used to crash, hang or load wrongly, through the binary: node cycles (a
//! stack overflow, exit 134), index accessors claiming more than their buffer holds (loaded as
//! fewer triangles), a wrong `byteLength` (accepted), and buffer URIs naming a FIFO (a hang).
//! Each is refused with a message naming the file and the node, accessor or buffer. OBJ
//! errors name the file line (they named vertices and triangles after tobj's re-indexing).

mod common;

use std::path::Path;
use std::process::Command;

use common::{CUBE_OBJ, NODES, Scratch, edit, gltf, tetra_bin, with_gltf, with_obj};

/// A scratch directory with `tetra.bin`, `m.gltf` (the given document) and `s.toml`.
fn setup(doc: &str) -> Scratch {
    let s = Scratch::new();
    s.write("tetra.bin", tetra_bin());
    s.write("m.gltf", doc);
    s.write("s.toml", with_gltf("m.gltf"));
    s
}

/// Runs a render of `s.toml` with a time limit (a FIFO buffer used to hang the loader).
fn render(dir: &Path) -> (Option<i32>, String) {
    let r = common::run_within(
        dir,
        &["render", "s.toml", "--method", "pt", "--out", "out.exr"],
        30,
    );
    (r.code, r.stderr)
}

#[track_caller]
fn assert_refused(s: &Scratch, needles: &[&str]) {
    let (code, stderr) = render(s.path());
    assert_eq!(code, Some(1), "{stderr}");
    for n in ["m.gltf"].iter().chain(needles) {
        assert!(stderr.contains(n), "`{n}` missing from: {stderr}");
    }
    assert!(!s.join("out.exr").exists());
}

#[test]
fn the_valid_fixture_renders() {
    let s = setup(&gltf(NODES, 12, 72, "tetra.bin"));
    let (code, stderr) = render(s.path());
    assert_eq!(code, Some(0), "{stderr}");
}

#[test]
fn node_cycles_are_reported_with_the_node() {
    // A node its own child, and 0 → 1 → 0.
    let s = setup(&gltf(
        r#"[{"mesh": 0, "children": [0]}]"#,
        12,
        72,
        "tetra.bin",
    ));
    assert_refused(&s, &["node 0", "cycle"]);
    let s = setup(&gltf(
        r#"[{"mesh": 0, "children": [1]}, {"children": [0]}]"#,
        12,
        72,
        "tetra.bin",
    ));
    assert_refused(&s, &["node 0", "0 → 1 → 0"]);
}

#[test]
fn accessor_counts_and_buffer_lengths_are_checked() {
    let s = setup(&gltf(NODES, 1000, 72, "tetra.bin"));
    assert_refused(&s, &["accessor 1", "1000 indices"]);
    let s = setup(&gltf(NODES, 12, 64, "tetra.bin"));
    assert_refused(&s, &["buffer 0", "byteLength 64"]);
}

#[test]
fn buffer_uris_naming_a_fifo_are_refused() {
    let s = setup(&gltf(NODES, 12, 72, "pipe.bin"));
    let ok = Command::new("mkfifo")
        .arg(s.join("pipe.bin"))
        .status()
        .unwrap()
        .success();
    assert!(ok);
    assert_refused(&s, &["buffer 0", "pipe.bin", "FIFO"]);
}

#[test]
fn obj_errors_name_the_file_line() {
    let s = Scratch::new();
    let cube_lines = CUBE_OBJ.lines().count();
    let cases = [
        (
            "nan.obj",
            edit(CUBE_OBJ, "v 1 0 0\n", "v 1 nan 0\n"),
            3,
            "non-finite",
        ),
        (
            "range.obj",
            format!("{CUBE_OBJ}f 1 2 99\n"),
            cube_lines + 1,
            "vertex 99",
        ),
        (
            "flat.obj",
            format!("{CUBE_OBJ}f 1 2 2\nf 1 2 3\n"),
            cube_lines + 1,
            "degenerate",
        ),
    ];
    for (name, text, line, what) in cases {
        s.write(name, text);
        s.write("bad.toml", with_obj(name));
        s.assert_rejected(
            &["render", "bad.toml", "--out", "out.exr"],
            1,
            &[&format!("{name}:{line}:"), what],
        );
    }
}
