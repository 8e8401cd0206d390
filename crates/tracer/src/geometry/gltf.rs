//! glTF 2.0 loading (`.gltf` with external or embedded buffers, `.glb`; feature `gltf`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{DAffine3, DMat4, DVec3, Vec2, Vec3};

use super::TriangleMesh;
use super::gltf_assets::{self, AssetScope, ModelFolder, Resolved};
use super::gltf_material::GltfMaterial;
use crate::error::{MeshError, TextureError};
use crate::field::Texture;

/// Receives each triangle primitive, transformed to world space, with its material index.
type Sink<'s> = dyn FnMut(Option<usize>, &TriangleMesh) + 's;

/// An opened glTF file: its document and buffers, read once, and its images' sources
/// resolved (not read).
struct Opened {
    document: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
    /// Each image's URI, resolved (`None`: the image is in a buffer view).
    images: Vec<Option<Resolved>>,
    /// The external files read (buffers), canonical, in buffer order.
    files: Vec<PathBuf>,
}

fn open(
    path: &Path,
    scope: AssetScope,
    err: &dyn Fn(String) -> MeshError,
) -> Result<Opened, MeshError> {
    let gltf::Gltf { document, mut blob } =
        gltf::Gltf::open(path).map_err(|e| err(e.to_string()))?;
    let folder = ModelFolder::of(path).map_err(&err)?;
    let mut buffers = Vec::new();
    let mut files = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let declared = buffer.length();
        let mut data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                err(format!(
                    "buffer {i} refers to the binary chunk of a .glb, but the file has none"
                ))
            })?,
            gltf::buffer::Source::Uri(uri) => {
                match gltf_assets::resolve(uri, &folder, scope)
                    .map_err(|m| err(format!("buffer {i}: {m}")))?
                {
                    Resolved::Data => {
                        gltf::buffer::Data::from_source(buffer.source(), None)
                            .map_err(|e| err(format!("buffer {i}: {e}")))?
                            .0
                    }
                    Resolved::Missing => {
                        return Err(err(format!("buffer {i} uri `{uri}`: no such file")));
                    }
                    Resolved::File(file) => {
                        let bound = declared.next_multiple_of(4) as u64;
                        let bytes = gltf_assets::read_bounded(
                            &file,
                            bound,
                            &format!("byteLength {declared}"),
                        )
                        .map_err(|m| err(format!("buffer {i} uri `{uri}`: {m}")))?;
                        files.push(file);
                        bytes
                    }
                }
            }
        };
        // Every buffer must hold exactly its declared `byteLength`, up to the padding to a
        // multiple of 4 bytes (the sizes are the document's, never a file's).
        if data.len() < declared {
            return Err(err(format!(
                "buffer {i} declares byteLength {declared} but holds fewer bytes"
            )));
        }
        if data.len() > declared.next_multiple_of(4) {
            return Err(err(format!(
                "buffer {i} declares byteLength {declared} but holds more bytes"
            )));
        }
        while data.len() % 4 != 0 {
            data.push(0);
        }
        buffers.push(gltf::buffer::Data(data));
    }
    let images = document
        .images()
        .map(|image| match image.source() {
            gltf::image::Source::View { .. } => Ok(None),
            gltf::image::Source::Uri { uri, .. } => gltf_assets::resolve(uri, &folder, scope)
                .map(Some)
                .map_err(|m| err(format!("image {}: {m}", image.index()))),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Opened {
        document,
        buffers,
        images,
        files,
    })
}

/// Walks the nodes of the default scene (or the first scene; with no scene at all, every
/// mesh once, untransformed), handing every triangle primitive to `sink`.
fn walk(
    o: &Opened,
    sink: &mut Sink<'_>,
    err: &dyn Fn(String) -> MeshError,
) -> Result<(), MeshError> {
    let scene = o
        .document
        .default_scene()
        .or_else(|| o.document.scenes().next());
    match scene {
        Some(scene) => {
            let mut path = Vec::new();
            for node in scene.nodes() {
                visit(&node, DMat4::IDENTITY, &o.buffers, sink, &mut path, err)?;
            }
        }
        None => {
            for m in o.document.meshes() {
                add_mesh(&m, &DAffine3::IDENTITY, &o.buffers, sink, err)?;
            }
        }
    }
    Ok(())
}

fn load_error(path: &Path) -> impl Fn(String) -> MeshError {
    let file = path.display().to_string();
    move |message: String| MeshError::Load {
        file: file.clone(),
        message,
    }
}

/// Loads every triangle primitive of every mesh instanced by the nodes of the default scene
/// (or the first scene; with no scene at all, every mesh once, untransformed) into one mesh,
/// with the node transforms applied (normals by the inverse transpose). Strips and fans are
/// converted to triangle lists; points and lines are skipped. Texture coordinates (set 0) are
/// converted to the OBJ convention `v ↦ 1 − v`. Images are not decoded. The mesh is not
/// validated here: call [`TriangleMesh::prepare`]. External files must be inside the model's
/// folder ([`load_gltf_with`] takes another scope).
pub fn load_gltf(path: &Path) -> Result<TriangleMesh, MeshError> {
    load_gltf_with(path, AssetScope::default()).map(|(mesh, _)| mesh)
}

/// [`load_gltf`] with external files read within `scope` ([`gltf_assets`]); also returns the
/// external files read (canonical paths), for the scene's list of inputs.
pub fn load_gltf_with(
    path: &Path,
    scope: AssetScope,
) -> Result<(TriangleMesh, Vec<PathBuf>), MeshError> {
    let err = load_error(path);
    let opened = open(path, scope, &err)?;
    let mut mesh = TriangleMesh::default();
    walk(&opened, &mut |_, part| mesh.append(part), &err)?;
    Ok((mesh, opened.files))
}

/// One material's share of a glTF file: its triangles (world space) and what the material
/// says about a translucent volume.
#[derive(Debug, Clone)]
pub struct GltfPart {
    /// The material, as written in the file.
    pub material: GltfMaterial,
    /// Every triangle that uses it.
    pub mesh: TriangleMesh,
}

/// A glTF file split by material, for scenes that take their materials from the file.
pub struct GltfModel {
    file: PathBuf,
    opened: Opened,
    /// One part per material used by a triangle primitive, in material order (glTF's default
    /// material last).
    pub parts: Vec<GltfPart>,
}

impl std::fmt::Debug for GltfModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GltfModel")
            .field("file", &self.file)
            .field("parts", &self.parts)
            .finish_non_exhaustive()
    }
}

/// Loads `path` split by material (see [`load_gltf`] for what is read from the meshes, and
/// [`GltfMaterial`] for what is read from the materials). Images are not decoded here:
/// [`GltfModel::decode_image`] decodes the ones a scene uses.
pub fn load_gltf_parts(path: &Path) -> Result<GltfModel, MeshError> {
    load_gltf_parts_with(path, AssetScope::default())
}

/// [`load_gltf_parts`] with external files read within `scope` ([`gltf_assets`]).
pub fn load_gltf_parts_with(path: &Path, scope: AssetScope) -> Result<GltfModel, MeshError> {
    let err = load_error(path);
    let opened = open(path, scope, &err)?;
    // Material index → triangles; `None` (glTF's default material) sorts first in a BTreeMap,
    // and is moved last below.
    let mut by_material: BTreeMap<Option<usize>, TriangleMesh> = BTreeMap::new();
    walk(
        &opened,
        &mut |m, part| by_material.entry(m).or_default().append(part),
        &err,
    )?;
    let mut parts = Vec::with_capacity(by_material.len());
    let mut default = None;
    for (index, mesh) in by_material {
        let material = match index.and_then(|i| opened.document.materials().nth(i)) {
            Some(m) => GltfMaterial::read(&m).map_err(|e| {
                err(format!(
                    "material {} (`{}`): {}: {}",
                    m.index().unwrap_or(0),
                    m.name().unwrap_or(""),
                    e.field,
                    e.message
                ))
            })?,
            None => GltfMaterial::default_material(),
        };
        let part = GltfPart { material, mesh };
        if index.is_none() {
            default = Some(part);
        } else {
            parts.push(part);
        }
    }
    parts.extend(default);
    Ok(GltfModel {
        file: path.to_path_buf(),
        opened,
        parts,
    })
}

impl GltfModel {
    /// The file it was read from.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The external files read so far (buffers), canonical paths.
    pub fn files_read(&self) -> &[PathBuf] {
        &self.opened.files
    }

    /// The file image `index` is read from, when it is an external file (canonical path).
    pub fn image_file(&self, index: usize) -> Option<&Path> {
        match self.opened.images.get(index) {
            Some(Some(Resolved::File(p))) => Some(p),
            _ => None,
        }
    }

    /// Decodes image `index` of the file (8- and 16-bit images from sRGB, as glTF specifies
    /// for base colour; float images linear) through [`Texture::from_encoded`], which checks
    /// the decoded size first. The texture is named `file#image[index]`. An external image
    /// file is read up to the decoder's memory limit
    /// ([`crate::field::decoder_limit_mb`]).
    pub fn decode_image(&self, index: usize) -> Result<Texture, TextureError> {
        let name = format!("{}#image[{index}]", self.file.display());
        let decode = |message: String| TextureError::Decode {
            file: name.clone(),
            message,
        };
        let image = self
            .opened
            .document
            .images()
            .nth(index)
            .ok_or_else(|| decode(format!("the file has no image {index}")))?;
        let owned;
        let bytes: &[u8] = match (image.source(), &self.opened.images[index]) {
            (gltf::image::Source::View { view, .. }, _) => {
                let buffer = &self.opened.buffers[view.buffer().index()].0;
                let (start, len) = (view.offset(), view.length());
                start
                    .checked_add(len)
                    .and_then(|end| buffer.get(start..end))
                    .ok_or_else(|| {
                        decode(format!(
                            "buffer view {} (offset {start}, length {len}) lies outside its buffer",
                            view.index()
                        ))
                    })?
            }
            (gltf::image::Source::Uri { uri, .. }, Some(Resolved::Data)) => {
                owned = gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), None)
                    .map_err(|e| decode(e.to_string()))?;
                &owned.0
            }
            (gltf::image::Source::Uri { uri, .. }, Some(Resolved::File(file))) => {
                let limit_mb = crate::field::decoder_limit_mb();
                owned = gltf::buffer::Data(
                    gltf_assets::read_bounded(
                        file,
                        limit_mb.saturating_mul(1 << 20),
                        &format!("the decoder's memory limit of {limit_mb} MiB"),
                    )
                    .map_err(|m| decode(format!("uri `{uri}`: {m}")))?,
                );
                &owned.0
            }
            (gltf::image::Source::Uri { uri, .. }, _) => {
                return Err(decode(format!("uri `{uri}`: no such file")));
            }
        };
        Texture::from_encoded(&name, bytes, false)
    }
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
    out: &mut Sink<'_>,
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
    out: &mut Sink<'_>,
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
        out(prim.material().index(), &part);
    }
    Ok(())
}
