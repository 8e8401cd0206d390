//! Mesh files that used to crash, hang or load wrongly, through the binary: node cycles (a
//! stack overflow, exit 134), index accessors claiming more than their buffer holds (loaded as
//! fewer triangles), a wrong `byteLength` (accepted), and buffer URIs naming a FIFO (a hang).
//! Each is refused with a message naming the file and the node, accessor or buffer. OBJ
//! errors name the file line (they named vertices and triangles after tobj's re-indexing).

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{CUBE_OBJ, MINIMAL, Scratch, edit, with_obj};

/// A closed tetrahedron: 4 `f32` positions (48 bytes) then 12 `u16` indices (24 bytes).
fn tetra_bin() -> Vec<u8> {
    let mut b = Vec::new();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// The glTF document with the given nodes, index count, buffer length and buffer URI.
fn gltf(nodes: &str, index_count: u32, byte_length: u32, uri: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": {nodes},
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "buffers": [{{"uri": "{uri}", "byteLength": {byte_length}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 24}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
      "min": [0, 0, 0], "max": [1, 1, 1]}},
    {{"bufferView": 1, "componentType": 5123, "count": {index_count}, "type": "SCALAR"}}
  ]
}}"#
    )
}

const NODES: &str = r#"[{"mesh": 0}]"#;

/// A scratch directory with `tetra.bin`, `m.gltf` (the given document) and `s.toml`.
fn setup(doc: &str) -> Scratch {
    let s = Scratch::new();
    s.write("tetra.bin", tetra_bin());
    s.write("m.gltf", doc);
    s.write(
        "s.toml",
        edit(
            MINIMAL,
            "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
            "type = \"gltf\"\nname = \"tet\"\nmaterial = \"m\"\npath = \"m.gltf\"",
        ),
    );
    s
}

/// Runs a render of `s.toml` with a time limit (a FIFO buffer used to hang the loader).
fn render(dir: &Path) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .args(["render", "s.toml", "--method", "pt", "--out", "out.exr"])
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            let out = child.wait_with_output().unwrap();
            return (
                out.status.code(),
                String::from_utf8_lossy(&out.stderr).into_owned(),
            );
        }
        if start.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("het-bssrdf render hung for 30 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
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
