//! Mesh loading (OBJ, glTF, the bunny) and validation through files.

use std::path::Path;

use glam::DVec3;
use tracer::error::MeshError;
use tracer::geometry::gltf::load_gltf;
use tracer::geometry::obj::load_obj;
use tracer::geometry::{Geometry, Ray, Transform, TriangleMesh};

use crate::common::asset;

pub const CUBE_OBJ: &str = "\
# unit cube as quads, with normals and texture coordinates
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 -1
vn 0 0 1
vn 0 -1 0
vn 0 1 0
vn -1 0 0
vn 1 0 0
f 1/1/1 4/4/1 3/3/1 2/2/1
f 5/1/2 6/2/2 7/3/2 8/4/2
f 1/1/3 2/2/3 6/3/3 5/4/3
f 4/1/4 8/4/4 7/3/4 3/2/4
f 1/1/5 5/2/5 8/3/5 4/4/5
f 2/1/6 3/2/6 7/3/6 6/4/6
";

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn obj_cube_loads_closed_with_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "cube.obj", CUBE_OBJ);
    let mut m = load_obj(&p).unwrap();
    assert_eq!(m.triangles.len(), 12, "quads are triangulated");
    assert!(m.normals.is_some() && m.uvs.is_some());
    // Vertices are duplicated per (position, normal, uv) but welded for topology.
    let r = m.prepare(&p.display().to_string()).unwrap();
    assert!(r.is_closed(), "{r:?}");
    assert_eq!(r.vertices, 8);
    assert!((r.signed_volume - 1.0).abs() < 1e-6);
    // Shading normals come from the file.
    let g = Geometry::build(vec![m]);
    let h = g
        .intersect(&Ray::new(DVec3::new(0.5, 0.5, 3.0), DVec3::NEG_Z))
        .unwrap();
    assert!(h.ns.abs_diff_eq(DVec3::Z, 1e-6) && h.ng.abs_diff_eq(DVec3::Z, 1e-12));
    assert!(h.uv.x >= 0.0 && h.uv.x <= 1.0);
}

#[test]
fn obj_box_missing_a_face_is_open() {
    let dir = tempfile::tempdir().unwrap();
    let text: String = CUBE_OBJ
        .lines()
        .filter(|l| !l.starts_with("f 2/1/6"))
        .map(|l| format!("{l}\n"))
        .collect();
    let p = write(dir.path(), "open.obj", &text);
    let mut m = load_obj(&p).unwrap();
    let r = m.prepare("open.obj").unwrap();
    assert!(!r.is_closed());
    assert_eq!(r.boundary_edges, 4);
    assert!(!r.flipped, "an open mesh is never flipped");
}

#[test]
fn obj_inside_out_cube_is_flipped() {
    let dir = tempfile::tempdir().unwrap();
    // Reverse every face's vertex order.
    let text: String = CUBE_OBJ
        .lines()
        .map(|l| {
            if let Some(rest) = l.strip_prefix("f ") {
                let mut v: Vec<&str> = rest.split_whitespace().collect();
                v.reverse();
                format!("f {}\n", v.join(" "))
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let p = write(dir.path(), "inverted.obj", &text);
    let mut m = load_obj(&p).unwrap();
    assert!(m.signed_volume() < 0.0);
    let r = m.prepare("inverted.obj").unwrap();
    assert!(r.flipped && r.is_closed() && r.signed_volume > 0.0);
    let g = Geometry::build(vec![m]);
    let h = g
        .intersect(&Ray::new(DVec3::new(0.5, 0.5, 3.0), DVec3::NEG_Z))
        .unwrap();
    assert!(
        h.ng.z > 0.99,
        "geometric normal points outward after the fix"
    );
}

#[test]
fn bad_obj_files_are_rejected_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("empty.obj", "o nothing\nv 0 0 0\n", "no triangles"),
        (
            "nan.obj",
            "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
            "non-finite",
        ),
        (
            "degenerate.obj",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
            "degenerate",
        ),
        ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", ""),
    ];
    for (name, text, what) in cases {
        let p = write(dir.path(), name, text);
        let err = match load_obj(&p) {
            Err(e) => e,
            Ok(mut m) => m.prepare(&p.display().to_string()).unwrap_err(),
        };
        let msg = err.to_string();
        assert!(msg.contains(name), "{msg}");
        assert!(msg.contains(what), "{name}: {msg}");
    }
    let e = load_obj(&dir.path().join("absent.obj")).unwrap_err();
    assert!(matches!(e, MeshError::Load { .. }) && e.to_string().contains("absent.obj"));
}

/// A tetrahedron in a glTF file with an external buffer, under two nested nodes (translation,
/// then scale), with texture coordinates.
pub fn write_gltf(dir: &Path) -> std::path::PathBuf {
    let pos: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let idx: [u16; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
    let uv: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [0.0, 0.25], [0.5, 0.5]];
    let mut bin = Vec::new();
    pos.iter()
        .flatten()
        .for_each(|f| bin.extend_from_slice(&f.to_le_bytes()));
    idx.iter()
        .for_each(|i| bin.extend_from_slice(&i.to_le_bytes()));
    uv.iter()
        .flatten()
        .for_each(|f| bin.extend_from_slice(&f.to_le_bytes()));
    assert_eq!(bin.len(), 104);
    std::fs::write(dir.join("tet.bin"), &bin).unwrap();
    let json = r#"{
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"translation": [10, 0, 0], "children": [1]}, {"scale": [2, 2, 2], "mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2}, "indices": 1}]}],
  "buffers": [{"uri": "tet.bin", "byteLength": 104}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 24},
    {"buffer": 0, "byteOffset": 72, "byteLength": 32}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
    {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"},
    {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}
  ]
}"#;
    write(dir, "tet.gltf", json)
}

#[test]
fn gltf_applies_node_transforms_and_flips_v() {
    let dir = tempfile::tempdir().unwrap();
    let p = write_gltf(dir.path());
    let mut m = load_gltf(&p).unwrap();
    assert_eq!(m.triangles.len(), 4);
    let (lo, hi) = m.bounds();
    assert!(lo.abs_diff_eq(DVec3::new(10.0, 0.0, 0.0), 1e-6), "{lo:?}");
    assert!(hi.abs_diff_eq(DVec3::new(12.0, 2.0, 2.0), 1e-6), "{hi:?}");
    let uvs = m.uvs.as_ref().unwrap();
    assert_eq!(
        uvs[2],
        glam::Vec2::new(0.0, 0.75),
        "v is flipped to the OBJ convention"
    );
    let r = m.prepare("tet.gltf").unwrap();
    assert!(r.is_closed());
    assert!((r.signed_volume - 8.0 / 6.0).abs() < 1e-6);
    // A broken file is reported with its name.
    let bad = write(dir.path(), "bad.gltf", "{ not json");
    let e = load_gltf(&bad).unwrap_err();
    assert!(e.to_string().contains("bad.gltf"), "{e}");
}

#[test]
fn bunny_loads_closed() {
    let Some(p) = asset("bunny.obj") else {
        return;
    };
    let mut m = load_obj(&p).unwrap();
    let r = m.prepare(&p.display().to_string()).unwrap();
    assert_eq!(r.triangles, 27_864);
    assert!(r.is_closed(), "{}", r.summary());
    assert!(r.signed_volume > 0.0);
    // Rays from the centroid of the bounding box in many directions all hit (it is closed).
    let g = Geometry::build(vec![m]);
    let (lo, hi) = g.object_bounds(0);
    let c = 0.5 * (lo + hi);
    let mut rng = tracer::rng::Rng::from_keys(31, &[]);
    let mut inside = 0;
    for _ in 0..2000 {
        let d = crate::common::random_dir(&mut rng);
        let mut n = 0;
        g.for_each_object_hit(0, &Ray::new(c - 10.0 * (hi - lo).length() * d, d), |_| {
            n += 1
        });
        assert!(
            n % 2 == 0,
            "a line crosses a closed surface an even number of times, got {n}"
        );
        inside += (n > 0) as usize;
    }
    assert!(inside > 1000);
}

#[test]
fn transforms_scale_rotate_translate_in_that_order() {
    let mut m = TriangleMesh::new(
        vec![
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ],
        vec![[0, 1, 2]],
    );
    m.transform(&Transform {
        scale: DVec3::new(2.0, 3.0, 4.0),
        rotation: Transform::rotation_axis_angle(DVec3::Z, 90.0),
        translation: DVec3::new(0.0, 0.0, 10.0),
    });
    // (1,0,0) → scale (2,0,0) → rotate 90° about z (0,2,0) → translate (0,2,10).
    assert!(m.positions[0].abs_diff_eq(DVec3::new(0.0, 2.0, 10.0), 1e-6));
    assert!(m.positions[1].abs_diff_eq(DVec3::new(-3.0, 0.0, 10.0), 1e-6));
    assert!(m.positions[2].abs_diff_eq(DVec3::new(0.0, 0.0, 14.0), 1e-6));
}
