//! Stanford PLY loading through ply-rs-bw (feature `ply`), ASCII and binary: the mesh format of
//! most pbrt and Mitsuba scenes.
//!
//! Read: the `vertex` element's `x`, `y`, `z` (required), `nx`, `ny`, `nz` (normals, kept when
//! all three are present) and `u`, `v` (or `s`, `t`, or `texture_u`, `texture_v`: texture
//! coordinates); the `face` element's `vertex_indices` (or `vertex_index`) lists, polygons
//! triangulated as fans. Other elements and properties are ignored.

use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::TriangleMesh;
use crate::error::MeshError;

/// Loads the mesh of a PLY file. The mesh is not validated here: call
/// [`TriangleMesh::prepare`].
pub fn load_ply(path: &Path) -> Result<TriangleMesh, MeshError> {
    let file = path.display().to_string();
    let fail = |message: String| MeshError::Load {
        file: file.clone(),
        message,
    };
    let bytes = std::fs::read(path).map_err(|e| fail(e.to_string()))?;
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut bytes.as_slice())
        .map_err(|e| fail(e.to_string()))?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| fail("no `vertex` element".into()))?;
    let faces = ply
        .payload
        .get("face")
        .ok_or_else(|| fail("no `face` element".into()))?;

    let vec3 = |e: &DefaultElement, keys: [&str; 3]| -> Option<Vec3> {
        let c = keys.map(|k| e.get(k).and_then(Property::to_f32_lossy));
        Some(Vec3::new(c[0]?, c[1]?, c[2]?))
    };
    let mut positions = Vec::with_capacity(vertices.len());
    for (i, e) in vertices.iter().enumerate() {
        positions.push(
            vec3(e, ["x", "y", "z"])
                .ok_or_else(|| fail(format!("vertex {i} lacks a numeric x, y or z")))?
                .as_dvec3(),
        );
    }
    let normals: Option<Vec<Vec3>> = vertices
        .iter()
        .map(|e| vec3(e, ["nx", "ny", "nz"]))
        .collect();
    let uvs: Option<Vec<Vec2>> = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"]]
        .iter()
        .find_map(|[ku, kv]| {
            vertices
                .iter()
                .map(|e| {
                    let u = e.get(*ku)?.to_f32_lossy()?;
                    let v = e.get(*kv)?.to_f32_lossy()?;
                    Some(Vec2::new(u, v))
                })
                .collect()
        });

    let mut triangles = Vec::with_capacity(faces.len());
    for (i, f) in faces.iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .ok_or_else(|| fail(format!("face {i} has no `vertex_indices` list")))?;
        let idx = indices(list).ok_or_else(|| {
            fail(format!(
                "face {i}: `vertex_indices` must be a list of non-negative integers"
            ))
        })?;
        if idx.len() < 3 {
            return Err(fail(format!(
                "face {i} has {} vertices, at least 3 are needed",
                idx.len()
            )));
        }
        for k in 1..idx.len() - 1 {
            triangles.push([idx[0], idx[k], idx[k + 1]]);
        }
    }
    let n = positions.len();
    Ok(TriangleMesh {
        positions,
        normals: normals.filter(|v| v.len() == n && n > 0),
        uvs: uvs.filter(|v| v.len() == n && n > 0),
        triangles,
    })
}

/// The vertex indices of an integer list property; `None` for another type or a negative
/// index.
fn indices(p: &Property) -> Option<Vec<u32>> {
    fn conv<T: Copy>(v: &[T], f: impl Fn(T) -> Option<u32>) -> Option<Vec<u32>> {
        v.iter().map(|&x| f(x)).collect()
    }
    match p {
        Property::ListChar(v) => conv(v, |x| u32::try_from(x).ok()),
        Property::ListUChar(v) => conv(v, |x| Some(u32::from(x))),
        Property::ListShort(v) => conv(v, |x| u32::try_from(x).ok()),
        Property::ListUShort(v) => conv(v, |x| Some(u32::from(x))),
        Property::ListInt(v) => conv(v, |x| u32::try_from(x).ok()),
        Property::ListUInt(v) => Some(v.clone()),
        _ => None,
    }
}
