//! Helpers shared by the CLI integration tests: running the built binary in a scratch
//! directory, listing directories (hidden files included), and the scene and image fixtures.

#![allow(dead_code)] // each test crate uses a different subset

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use bssrdf_core::Rgb;
use tracer::film::Film;

/// What one run of the binary did.
#[derive(Debug)]
pub struct Run {
    /// Exit code (`None` when killed by a signal).
    pub code: Option<i32>,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

/// Runs `het-bssrdf args…` with `dir` as the working directory.
pub fn run_in(dir: &Path, args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run het-bssrdf");
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Runs `het-bssrdf args…` in `dir` like [`run_in`], but kills it and panics if it has not
/// ended after `seconds` (for inputs that used to hang or grow without bound).
#[track_caller]
pub fn run_within(dir: &Path, args: &[&str], seconds: u64) -> Run {
    run_program_within(dir, env!("CARGO_BIN_EXE_het-bssrdf"), args, seconds)
}

/// Runs `program args…` in `dir`, killed (and the test failed) after `seconds`.
#[track_caller]
pub fn run_program_within(dir: &Path, program: &str, args: &[&str], seconds: u64) -> Run {
    let mut child = Command::new(program)
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run het-bssrdf");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait").is_some() {
            let out = child.wait_with_output().expect("output");
            return Run {
                code: out.status.code(),
                stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
                stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
            };
        }
        if start.elapsed() > Duration::from_secs(seconds) {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "het-bssrdf {} did not end within {seconds} s",
                args.join(" ")
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Every path under `dir` (files and directories, hidden ones included: the atomic writers'
/// temporary files start with a dot), relative to `dir`, sorted, directories marked `/`.
pub fn listing(dir: &Path) -> Vec<String> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).expect("read_dir") {
            let p = e.expect("dir entry").path();
            let rel = p.strip_prefix(root).unwrap().display().to_string();
            // Do not follow links; descend into real directories only.
            let meta = std::fs::symlink_metadata(&p).expect("metadata");
            if meta.is_dir() {
                out.push(format!("{rel}/"));
                walk(root, &p, out);
            } else {
                out.push(rel);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// A scratch directory: the working directory of the runs, holding their inputs.
pub struct Scratch {
    dir: tempfile::TempDir,
}

impl Scratch {
    /// An empty scratch directory.
    pub fn new() -> Self {
        Self {
            dir: tempfile::tempdir().expect("tempdir"),
        }
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// `path()/rel`.
    pub fn join(&self, rel: &str) -> PathBuf {
        self.dir.path().join(rel)
    }

    /// Writes `bytes` to `rel` (creating parent directories) and returns the full path.
    pub fn write(&self, rel: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.join(rel);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).expect("create_dir_all");
        }
        std::fs::write(&p, bytes).expect("write input");
        p
    }

    /// Runs the binary here.
    pub fn run(&self, args: &[&str]) -> Run {
        run_in(self.path(), args)
    }

    /// Runs `args`, which must be rejected: exit code `code` (1: a run-time error, 2: a usage
    /// error from clap), no panic, the error line printed once without a repeated cause, every
    /// `needle` in stderr, and nothing created, changed or left behind (temporary files
    /// included) in the scratch directory. Returns stderr.
    #[track_caller]
    pub fn assert_rejected(&self, args: &[&str], code: i32, needles: &[&str]) -> String {
        let before = snapshot(self.path());
        let r = self.run(args);
        let after = snapshot(self.path());
        let what = format!("het-bssrdf {}", args.join(" "));
        assert_eq!(
            r.code,
            Some(code),
            "{what}: expected exit code {code}\nstderr:\n{}",
            r.stderr
        );
        assert!(
            !r.stderr.contains("panicked"),
            "{what} panicked:\n{}",
            r.stderr
        );
        for n in needles {
            assert!(
                r.stderr.contains(n),
                "{what}: `{n}` missing from stderr:\n{}",
                r.stderr
            );
        }
        assert_no_repeated_cause(&r.stderr, &what);
        let names = |v: &Snapshot| v.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
        assert_eq!(
            names(&before),
            names(&after),
            "{what} created or removed files in {}",
            self.path().display()
        );
        for ((name, a), (_, b)) in before.iter().zip(&after) {
            assert!(a == b, "{what} changed {name}");
        }
        r.stderr
    }
}

/// A directory listing with each file's contents.
type Snapshot = Vec<(String, Option<Vec<u8>>)>;

/// The listing of `dir` with each file's contents, to detect created, removed or rewritten
/// files.
fn snapshot(dir: &Path) -> Snapshot {
    listing(dir)
        .into_iter()
        .map(|rel| {
            let p = dir.join(&rel);
            let bytes = if rel.ends_with('/') {
                None
            } else {
                std::fs::read(&p).ok()
            };
            (rel, bytes)
        })
        .collect()
}

/// The `error: …` line must not print the same cause twice in a row (`a: b: b`).
#[track_caller]
fn assert_no_repeated_cause(stderr: &str, what: &str) {
    for line in stderr.lines().filter(|l| l.starts_with("error:")) {
        let parts: Vec<&str> = line.split(": ").collect();
        for w in parts.windows(2) {
            assert!(w[0] != w[1], "{what}: repeated cause in `{line}`");
        }
    }
}

/// True when this process can write into a directory without write permission (root, or a
/// container that ignores permissions); then read-only checks cannot be tested.
pub fn permissions_ignored(dir: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let probe_dir = dir.join(".perm-probe");
    std::fs::create_dir(&probe_dir).unwrap();
    std::fs::set_permissions(&probe_dir, std::fs::Permissions::from_mode(0o555)).unwrap();
    let ignored = std::fs::write(probe_dir.join("x"), b"x").is_ok();
    let _ = std::fs::remove_file(probe_dir.join("x"));
    std::fs::set_permissions(&probe_dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    std::fs::remove_dir(&probe_dir).unwrap();
    ignored
}

/// A small valid scene: the shared minimal scene (`tests/fixtures/minimal-scene.toml`, an
/// index-matched translucent box seen by an orthographic camera, 8 × 8 pixels at 1 spp) lit
/// from above.
pub const MINIMAL: &str = concat!(
    include_str!("../../../../tests/fixtures/minimal-scene.toml"),
    "\n[[light]]\ntype = \"directional\"\ndirection = [0.0, 0.0, -1.0]\nirradiance = 1.0\n"
);

/// `text` with `from` replaced by `to`; panics if `from` is absent (so that a test can never
/// silently run the unmodified scene).
#[track_caller]
pub fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` not found in the scene");
    text.replacen(from, to, 1)
}

/// [`MINIMAL`] with its box replaced by an OBJ shape named `blob` reading `path`.
pub fn with_obj(path: &str) -> String {
    edit(
        MINIMAL,
        "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
        &format!("type = \"obj\"\nname = \"blob\"\nmaterial = \"m\"\npath = \"{path}\""),
    )
}

/// [`MINIMAL`] with σa read from the image `path` (texture `t`, planar, 2 × 2 units).
pub fn with_texture(path: &str) -> String {
    let s = edit(
        MINIMAL,
        "sigma_a = 0.1",
        "sigma_a = { type = \"image\", texture = \"t\", size = [2.0, 2.0], scale = 0.1 }",
    );
    format!("{s}\n[[texture]]\nname = \"t\"\npath = \"{path}\"\n")
}

/// A unit cube as six quads (closed, outward-facing).
pub const CUBE_OBJ: &str = "\
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 4 8 7 3
f 1 5 8 4
f 2 3 7 6
";

/// A `w × h` film with a smooth positive gradient.
pub fn gradient(w: u32, h: u32) -> Film {
    let mut f = Film::new(w, h);
    for y in 0..h {
        for x in 0..w {
            f.set(
                x,
                y,
                Rgb::new(
                    0.1 + x as f64 / w as f64,
                    0.2 + y as f64 / h as f64,
                    0.3 + ((x * 7 + y * 13) % 17) as f64 / 17.0,
                ),
            );
        }
    }
    f
}

/// A closed tetrahedron: 4 `f32` positions (48 bytes) then 12 `u16` indices (24 bytes).
pub fn tetra_bin() -> Vec<u8> {
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
pub fn gltf(nodes: &str, index_count: u32, byte_length: u32, uri: &str) -> String {
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

/// The nodes of [`gltf`]'s usual document: one node holding the mesh.
pub const NODES: &str = r#"[{"mesh": 0}]"#;

/// [`MINIMAL`] with its box replaced by a glTF shape named `tet` reading `path`.
pub fn with_gltf(path: &str) -> String {
    edit(
        MINIMAL,
        "type = \"box\"\nmaterial = \"m\"\nmin = [-1.0, -1.0, -1.0]\nmax = [1.0, 1.0, 0.0]",
        &format!("type = \"gltf\"\nname = \"tet\"\nmaterial = \"m\"\npath = \"{path}\""),
    )
}

/// A `w × h` 8-bit greyscale PNG of zeros, made without holding its pixels: the zlib stream is
/// one fixed-Huffman deflate block (a literal 0, then matches of 258 bytes at distance 1), so
/// a 20000² image (400 MB decoded) is a file of about 2.5 MB.
pub fn black_grey_png(w: u32, h: u32) -> Vec<u8> {
    /// Deflate's bit order: values LSB first, Huffman codes MSB first.
    struct Bits {
        out: Vec<u8>,
        acc: u32,
        n: u32,
    }
    impl Bits {
        fn bit(&mut self, b: u32) {
            self.acc |= (b & 1) << self.n;
            self.n += 1;
            if self.n == 8 {
                self.out.push(self.acc as u8);
                self.acc = 0;
                self.n = 0;
            }
        }
        fn code(&mut self, code: u32, len: u32) {
            for i in (0..len).rev() {
                self.bit(code >> i);
            }
        }
    }
    let total = u64::from(h) * (u64::from(w) + 1); // a filter byte (0) per row
    let mut bits = Bits {
        out: vec![0x78, 0x01],
        acc: 0,
        n: 0,
    };
    bits.bit(1); // BFINAL
    bits.bit(1); // BTYPE = 01 (fixed Huffman), LSB first
    bits.bit(0);
    bits.code(0x30, 8); // literal 0
    let rest = total - 1;
    for _ in 0..rest / 258 {
        bits.code(0xC5, 8); // length 258 (symbol 285)
        bits.code(0, 5); // distance 1
    }
    for _ in 0..rest % 258 {
        bits.code(0x30, 8);
    }
    bits.code(0, 7); // end of block (symbol 256)
    while bits.n != 0 {
        bits.bit(0);
    }
    let mut zlib = bits.out;
    // Adler-32 of `total` zero bytes: a stays 1, b adds 1 per byte.
    let adler = (((total % 65521) as u32) << 16) | 1;
    zlib.extend_from_slice(&adler.to_be_bytes());
    let crc = |bytes: &[u8]| {
        let mut c = 0xFFFF_FFFFu32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    };
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut chunk = |kind: &[u8], data: &[u8]| {
        png.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        png.extend_from_slice(&body);
        png.extend_from_slice(&crc(&body).to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]); // 8-bit grey, deflate, no interlace
    chunk(b"IHDR", &ihdr);
    chunk(b"IDAT", &zlib);
    chunk(b"IEND", &[]);
    png
}

/// Runs `het-bssrdf args…` in `dir` under the shell limits `limits` (e.g. `ulimit -v
/// 1000000`), within `seconds`.
#[track_caller]
pub fn run_limited(dir: &Path, limits: &str, args: &[&str], seconds: u64) -> Run {
    let script = format!("{limits} && exec \"$0\" \"$@\"");
    let mut sh_args = vec!["-c", &script, env!("CARGO_BIN_EXE_het-bssrdf")];
    sh_args.extend_from_slice(args);
    run_program_within(dir, "sh", &sh_args, seconds)
}

/// A running `het-bssrdf`, killed if the test fails before waiting for it.
pub struct Running(Option<Child>);

impl Running {
    pub fn id(&self) -> u32 {
        self.0.as_ref().expect("running").id()
    }
    pub fn wait_with_output(mut self) -> std::io::Result<std::process::Output> {
        self.0.take().expect("running").wait_with_output()
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        if let Some(c) = &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// Starts `het-bssrdf args…` in `dir` without waiting.
pub fn spawn(dir: &Path, args: &[&str]) -> Running {
    Running(Some(
        Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
            .args(args)
            .current_dir(dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn het-bssrdf"),
    ))
}

/// Sends `signal` (`INT`, `TERM`) to the child.
pub fn signal(child: &Running, signal: &str) {
    let ok = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .expect("run kill")
        .success();
    assert!(ok, "kill -{signal} failed");
}

/// Waits for `cond` for at most 60 s.
#[track_caller]
pub fn wait_for(what: &str, cond: impl Fn() -> bool) {
    let start = Instant::now();
    while !cond() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs `het-bssrdf args…` in `dir`, sends it `sig` 1.5 s after it started, and returns its
/// exit code and stderr.
pub fn interrupted_after_a_while(dir: &Path, args: &[&str], sig: &str) -> (Option<i32>, String) {
    let child = spawn(dir, args);
    std::thread::sleep(Duration::from_millis(1500));
    signal(&child, sig);
    let out = child.wait_with_output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The JSON sidecar at `path`.
pub fn sidecar(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("read sidecar")).expect("sidecar JSON")
}

/// No temporary (`.….tmp`) or probe file left in `dir`.
#[track_caller]
pub fn assert_no_temporaries(dir: &Path) {
    let files = listing(dir);
    assert!(
        !files
            .iter()
            .any(|f| f.ends_with(".tmp") || f.contains(".het-bssrdf-probe")),
        "temporary files left: {files:?}"
    );
}
