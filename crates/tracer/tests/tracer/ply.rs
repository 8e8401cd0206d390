//! PLY meshes (ASCII and binary), tested like OBJ: a unit cube written by the test loads
//! closed with its attributes, both encodings give the same mesh, and bad files are rejected
//! naming the file.

use glam::{DVec3, Vec2, Vec3};
use tracer::geometry::ply::load_ply;
use tracer::geometry::{Geometry, Ray};

/// The unit cube's corners.
const CORNERS: [[f32; 3]; 8] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [0.0, 1.0, 1.0],
];
/// Its six faces as outward-facing quads.
const QUADS: [[u32; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [3, 7, 6, 2],
    [0, 4, 7, 3],
    [1, 2, 6, 5],
];

/// The texture coordinate written for corner `i` (distinct per corner).
fn uv(i: usize) -> [f32; 2] {
    [i as f32 / 8.0, 1.0 - i as f32 / 16.0]
}

fn header(format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment unit cube\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
    )
}

fn ascii_cube() -> Vec<u8> {
    let mut s = header("ascii");
    for (i, c) in CORNERS.iter().enumerate() {
        let [u, v] = uv(i);
        s += &format!("{} {} {} {u} {v}\n", c[0], c[1], c[2]);
    }
    for q in QUADS {
        s += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    s.into_bytes()
}

fn binary_cube() -> Vec<u8> {
    let mut b = header("binary_little_endian").into_bytes();
    for (i, c) in CORNERS.iter().enumerate() {
        for x in c.iter().chain(&uv(i)) {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    for q in QUADS {
        b.push(4);
        for i in q {
            b.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    b
}

#[test]
fn ascii_and_binary_cubes_load_closed_with_uvs() {
    let dir = tempfile::tempdir().unwrap();
    let mut meshes = Vec::new();
    for (name, bytes) in [("a.ply", ascii_cube()), ("b.ply", binary_cube())] {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let m = load_ply(&p).unwrap();
        assert_eq!(m.triangles.len(), 12, "{name}: quads are triangulated");
        assert_eq!(
            m.positions,
            CORNERS.map(|c| Vec3::from(c).as_dvec3()).to_vec(),
            "{name}"
        );
        let uvs: Vec<Vec2> = (0..8).map(|i| Vec2::from(uv(i))).collect();
        assert_eq!(m.uvs.as_ref(), Some(&uvs), "{name}");
        assert!(m.normals.is_none(), "{name}: the file has no normals");
        meshes.push(m);
    }
    assert_eq!(meshes[0], meshes[1], "ASCII and binary differ");
    let mut m = meshes.pop().unwrap();
    let r = m.prepare("b.ply").unwrap();
    assert!(r.is_closed(), "{r:?}");
    assert!((r.signed_volume - 1.0).abs() < 1e-6, "{r:?}");
    let g = Geometry::build(vec![m]);
    let h = g
        .intersect(&Ray::new(DVec3::new(0.25, 0.5, 3.0), DVec3::NEG_Z))
        .unwrap();
    assert!((h.t - 2.0).abs() < 1e-9 && h.ng.abs_diff_eq(DVec3::Z, 1e-12));
}

#[test]
fn bad_ply_files_are_rejected_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let ascii = String::from_utf8(ascii_cube()).unwrap();
    let cases = [
        ("header.ply", ascii.replacen("ply\n", "plx\n", 1), ""),
        (
            "noface.ply",
            ascii.replacen("element face 6", "element side 6", 1),
            "face",
        ),
        (
            "negative.ply",
            ascii.replacen("4 0 3 2 1", "4 0 3 2 -1", 1),
            "non-negative",
        ),
        (
            "novertex.ply",
            ascii.replacen("property float z\n", "property float w\n", 1),
            "vertex 0",
        ),
    ];
    for (name, text, words) in cases {
        assert_ne!(text, ascii, "{name}: the edit did not apply");
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let e = load_ply(&p).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains(words), "{name}: {e}");
    }
}
