//! Wavefront OBJ loading through tobj (feature `obj`).

use std::path::Path;

use glam::{DVec3, Vec2, Vec3};

use super::TriangleMesh;
use super::obj_lines::TextGuard;
use crate::error::MeshError;

/// Loads every object and group of an OBJ file into one mesh (faces triangulated, one index
/// per vertex; materials are ignored, and `mtllib` files are not opened). Normals are kept
/// only when every part has them; texture coordinates when any part has them (see
/// [`TriangleMesh::append`]). The file is read as a stream of lines through a guard: a
/// binary file (a NUL byte, a line over 16 MiB) is refused after one buffer, not read whole. The mesh is not validated here: call
/// [`TriangleMesh::prepare`].
pub fn load_obj(path: &Path) -> Result<TriangleMesh, MeshError> {
    let file = path.display().to_string();
    let load_error = |message: String| MeshError::Load {
        file: file.clone(),
        message,
    };
    let opened = std::fs::File::open(path).map_err(|e| load_error(format!("cannot open: {e}")))?;
    let mut reader = TextGuard::new(std::io::BufReader::with_capacity(1 << 16, opened));
    let loaded = tobj::load_obj_buf(&mut reader, &tobj::GPU_LOAD_OPTIONS, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    if let Some((line, message)) = reader.problem() {
        return Err(MeshError::AtLine {
            file: file.clone(),
            line: *line,
            message: message.clone(),
        });
    }
    let (models, _materials) = loaded.map_err(|e| located(path, load_error(e.to_string())))?;
    let mut mesh = TriangleMesh::default();
    for m in &models {
        let m = &m.mesh;
        let n = m.positions.len() / 3;
        let part = TriangleMesh {
            positions: m
                .positions
                .chunks_exact(3)
                .map(|c| DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])))
                .collect(),
            normals: (m.normals.len() == 3 * n && n > 0).then(|| {
                m.normals
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect()
            }),
            uvs: (m.texcoords.len() == 2 * n && n > 0).then(|| {
                m.texcoords
                    .chunks_exact(2)
                    .map(|c| Vec2::new(c[0], c[1]))
                    .collect()
            }),
            triangles: m
                .indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        };
        mesh.append(&part);
    }
    // Validated here too, so that a failure can be traced back to its line.
    mesh.validate(&file).map_err(|e| located(path, e))?;
    Ok(mesh)
}

/// `error` with the OBJ file line that causes it, when one can be found
/// ([`super::obj_lines::first_problem`]); otherwise `error` itself.
fn located(path: &Path, error: MeshError) -> MeshError {
    let Ok(file) = std::fs::File::open(path) else {
        return error;
    };
    match super::obj_lines::first_problem(std::io::BufReader::with_capacity(1 << 16, file)) {
        Some((line, message)) => MeshError::AtLine {
            file: path.display().to_string(),
            line,
            message,
        },
        None => error,
    }
}
