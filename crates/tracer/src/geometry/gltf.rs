//! glTF 2.0 loading (`.gltf` with external or embedded buffers, `.glb`; feature `gltf`).

use std::path::Path;

use glam::{DAffine3, DMat4, DVec3, Vec2, Vec3};

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
    check_buffer_uris(&document, path, &err)?;
    let buffers =
        gltf::import_buffers(&document, path.parent(), blob).map_err(|e| err(e.to_string()))?;
    check_buffer_lengths(&document, &buffers, &err)?;
    let mut mesh = TriangleMesh::default();
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    match scene {
        Some(scene) => {
            let mut path = Vec::new();
            for node in scene.nodes() {
                visit(&node, DMat4::IDENTITY, &buffers, &mut mesh, &mut path, &err)?;
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

/// Most nested nodes (the glTF node hierarchy must be a forest; deeper chains are refused
/// rather than risking the stack).
const MAX_NODE_DEPTH: usize = 256;

/// Adds `node` and its descendants. `path` holds the node indices from the scene root down to
/// the parent: a node already on it is a cycle (a node its own child, or A → B → A), which
/// the glTF specification forbids and which would otherwise recurse until the stack overflows.
fn visit(
    node: &gltf::Node<'_>,
    parent: DMat4,
    buffers: &[gltf::buffer::Data],
    out: &mut TriangleMesh,
    path: &mut Vec<usize>,
    err: &dyn Fn(String) -> MeshError,
) -> Result<(), MeshError> {
    if let Some(k) = path.iter().position(|&n| n == node.index()) {
        let cycle: Vec<String> = path[k..]
            .iter()
            .chain([&node.index()])
            .map(|n| n.to_string())
            .collect();
        return Err(err(format!(
            "node {} is its own ancestor (cycle of nodes {}); the node hierarchy must be a tree",
            node.index(),
            cycle.join(" → ")
        )));
    }
    if path.len() >= MAX_NODE_DEPTH {
        return Err(err(format!(
            "node {} is nested more than {MAX_NODE_DEPTH} levels deep",
            node.index()
        )));
    }
    let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(|x| x as f64)));
    let world = parent * local;
    if let Some(m) = node.mesh() {
        add_mesh(&m, &DAffine3::from_mat4(world), buffers, out, err)?;
    }
    path.push(node.index());
    for child in node.children() {
        visit(&child, world, buffers, out, path, err)?;
    }
    path.pop();
    Ok(())
}

/// Refuses buffer URIs that name something other than a regular file (a device such as
/// `/dev/zero` reads until memory runs out, a FIFO blocks forever), before anything is read.
fn check_buffer_uris(
    document: &gltf::Document,
    path: &Path,
    err: &dyn Fn(String) -> MeshError,
) -> Result<(), MeshError> {
    let base = path.parent().unwrap_or(Path::new("."));
    for buffer in document.buffers() {
        let gltf::buffer::Source::Uri(uri) = buffer.source() else {
            continue;
        };
        if uri.starts_with("data:") {
            continue;
        }
        let decoded = percent_decode(uri);
        let file = base.join(&decoded);
        match std::fs::metadata(&file) {
            Ok(m) if !m.is_file() => {
                return Err(err(format!(
                    "buffer {} uri `{uri}` names a {}, not a regular file",
                    buffer.index(),
                    crate::output::file_kind(&m.file_type())
                )));
            }
            _ => {} // missing files are reported by the importer
        }
    }
    Ok(())
}

/// `%XX` escapes of a relative URI decoded (glTF buffer URIs are RFC 3986 references).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every buffer must hold exactly its declared `byteLength` (the importer pads the data to a
/// multiple of 4 bytes, and accepts longer data).
fn check_buffer_lengths(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    err: &dyn Fn(String) -> MeshError,
) -> Result<(), MeshError> {
    for (buffer, data) in document.buffers().zip(buffers) {
        let declared = buffer.length();
        if data.0.len() != declared.next_multiple_of(4) && data.0.len() != declared {
            return Err(err(format!(
                "buffer {} declares byteLength {declared} but holds {} bytes",
                buffer.index(),
                data.0.len()
            )));
        }
    }
    Ok(())
}

/// Every element an accessor claims must have been read: the reader stops silently at the
/// end of the buffer view, which turned 1000 claimed indices on a 12-index buffer into one
/// triangle.
fn check_count(
    accessor: Option<gltf::Accessor<'_>>,
    read: usize,
    what: &str,
    err: &dyn Fn(String) -> MeshError,
) -> Result<(), MeshError> {
    match accessor {
        Some(a) if a.count() != read => Err(err(format!(
            "accessor {} claims {} {what} but its buffer holds {read}",
            a.index(),
            a.count()
        ))),
        _ => Ok(()),
    }
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
        let positions: Vec<DVec3> = rd
            .read_positions()
            .ok_or_else(|| {
                err(format!(
                    "mesh {} primitive {} has no positions",
                    m.index(),
                    prim.index()
                ))
            })?
            .map(|p| Vec3::from_array(p).as_dvec3())
            .collect();
        let n = positions.len();
        let normals: Option<Vec<Vec3>> = rd
            .read_normals()
            .map(|it| it.map(Vec3::from_array).collect());
        let uvs: Option<Vec<Vec2>> = rd
            .read_tex_coords(0)
            .map(|tc| tc.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect());
        check_count(prim.get(&gltf::Semantic::Positions), n, "positions", err)?;
        let idx: Vec<u32> = match rd.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        check_count(prim.indices(), idx.len(), "indices", err)?;
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
