//! glTF 2.0 loading (`.gltf` with external or embedded buffers, `.glb`; feature `gltf`).

use std::path::Path;

use glam::{DAffine3, DMat4, Vec2, Vec3};

use super::TriangleMesh;
use crate::error::MeshError;

/// Loads every triangle primitive of every mesh instanced by the nodes of the default scene
/// (or the first scene; with no scene at all, every mesh once, untransformed) into one mesh,
/// with the node transforms applied (normals by the inverse transpose). Strips and fans are
/// converted to triangle lists; points and lines are skipped. Texture coordinates (set 0) are
/// converted to the OBJ convention `v ↦ 1 − v`. Images are not decoded. The mesh is not
/// validated here: call [`TriangleMesh::prepare`].
pub fn load_gltf(path: &Path) -> Result<TriangleMesh, MeshError> {
    let file = path.display().to_string();
    let err = |message: String| MeshError::Load {
        file: file.clone(),
        message,
    };
    let gltf::Gltf { document, blob } = gltf::Gltf::open(path).map_err(|e| err(e.to_string()))?;
    let buffers =
        gltf::import_buffers(&document, path.parent(), blob).map_err(|e| err(e.to_string()))?;
    let mut mesh = TriangleMesh::default();
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    match scene {
        Some(scene) => {
            for node in scene.nodes() {
                visit(&node, DMat4::IDENTITY, &buffers, &mut mesh, &err)?;
            }
        }
        None => {
            for m in document.meshes() {
                add_mesh(&m, &DAffine3::IDENTITY, &buffers, &mut mesh, &err)?;
            }
        }
    }
    Ok(mesh)
}

fn visit(
    node: &gltf::Node<'_>,
    parent: DMat4,
    buffers: &[gltf::buffer::Data],
    out: &mut TriangleMesh,
    err: &dyn Fn(String) -> MeshError,
) -> Result<(), MeshError> {
    let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(|x| x as f64)));
    let world = parent * local;
    if let Some(m) = node.mesh() {
        add_mesh(&m, &DAffine3::from_mat4(world), buffers, out, err)?;
    }
    for child in node.children() {
        visit(&child, world, buffers, out, err)?;
    }
    Ok(())
}

fn add_mesh(
    m: &gltf::Mesh<'_>,
    xf: &DAffine3,
    buffers: &[gltf::buffer::Data],
    out: &mut TriangleMesh,
    err: &dyn Fn(String) -> MeshError,
) -> Result<(), MeshError> {
    use gltf::mesh::Mode;
    for prim in m.primitives() {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            continue;
        }
        let rd = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = rd
            .read_positions()
            .ok_or_else(|| {
                err(format!(
                    "mesh {} primitive {} has no positions",
                    m.index(),
                    prim.index()
                ))
            })?
            .map(Vec3::from_array)
            .collect();
        let n = positions.len();
        let normals: Option<Vec<Vec3>> = rd
            .read_normals()
            .map(|it| it.map(Vec3::from_array).collect());
        let uvs: Option<Vec<Vec2>> = rd
            .read_tex_coords(0)
            .map(|tc| tc.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect());
        let idx: Vec<u32> = match rd.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        let triangles: Vec<[u32; 3]> = match mode {
            Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            Mode::TriangleStrip => (0..idx.len().saturating_sub(2))
                .map(|i| {
                    if i % 2 == 0 {
                        [idx[i], idx[i + 1], idx[i + 2]]
                    } else {
                        [idx[i + 1], idx[i], idx[i + 2]]
                    }
                })
                .collect(),
            _ => (1..idx.len().saturating_sub(1))
                .map(|i| [idx[0], idx[i], idx[i + 1]])
                .collect(),
        };
        let mut part = TriangleMesh {
            positions,
            normals: normals.filter(|v| v.len() == n),
            uvs: uvs.filter(|v| v.len() == n),
            triangles,
        };
        part.apply_affine(xf);
        out.append(&part);
    }
    Ok(())
}
