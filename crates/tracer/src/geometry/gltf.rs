//! glTF 2.0 loading (`.gltf` with external or embedded buffers, `.glb`; feature `gltf`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{DAffine3, DMat4, DVec3, Vec2, Vec3};

use super::TriangleMesh;
use super::gltf_material::GltfMaterial;
use crate::error::{MeshError, TextureError};
use crate::field::Texture;

/// Receives each triangle primitive, transformed to world space, with its material index.
type Sink<'s> = dyn FnMut(Option<usize>, &TriangleMesh) + 's;

/// An opened glTF file: its document and buffers, read once.
struct Opened {
    document: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
}

fn open(path: &Path, err: &dyn Fn(String) -> MeshError) -> Result<Opened, MeshError> {
    let gltf::Gltf { document, blob } = gltf::Gltf::open(path).map_err(|e| err(e.to_string()))?;
    check_buffer_uris(&document, path, err)?;
    let buffers =
        gltf::import_buffers(&document, path.parent(), blob).map_err(|e| err(e.to_string()))?;
    check_buffer_lengths(&document, &buffers, err)?;
    Ok(Opened { document, buffers })
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
/// validated here: call [`TriangleMesh::prepare`].
pub fn load_gltf(path: &Path) -> Result<TriangleMesh, MeshError> {
    let err = load_error(path);
    let opened = open(path, &err)?;
    let mut mesh = TriangleMesh::default();
    walk(&opened, &mut |_, part| mesh.append(part), &err)?;
    Ok(mesh)
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
    let err = load_error(path);
    let opened = open(path, &err)?;
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

    /// Decodes image `index` of the file (8- and 16-bit images from sRGB, as glTF specifies
    /// for base colour; float images linear). The texture is named `file#image[index]`.
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
        let data = gltf::image::Data::from_source(
            image.source(),
            self.file.parent(),
            &self.opened.buffers,
        )
        .map_err(|e| decode(e.to_string()))?;
        let texels = image_texels(&data).map_err(decode)?;
        Texture::from_texels(&name, data.width, data.height, texels)
    }
}

/// Linear RGB texels of a decoded glTF image (grey and grey-alpha images are spread to RGB,
/// alpha is dropped).
fn image_texels(d: &gltf::image::Data) -> Result<Vec<[f32; 3]>, String> {
    use gltf::image::Format;
    let srgb8: Vec<f32> = (0..256)
        .map(|i| crate::output::srgb_decode(i as f64 / 255.0) as f32)
        .collect();
    let srgb16 = |x: u16| crate::output::srgb_decode(x as f64 / 65535.0) as f32;
    let (channels, bytes_per) = match d.format {
        Format::R8 => (1, 1),
        Format::R8G8 => (2, 1),
        Format::R8G8B8 => (3, 1),
        Format::R8G8B8A8 => (4, 1),
        Format::R16 => (1, 2),
        Format::R16G16 => (2, 2),
        Format::R16G16B16 => (3, 2),
        Format::R16G16B16A16 => (4, 2),
        Format::R32G32B32FLOAT => (3, 4),
        Format::R32G32B32A32FLOAT => (4, 4),
    };
    let stride = channels * bytes_per;
    let n = d.width as usize * d.height as usize;
    if d.pixels.len() < n * stride {
        return Err(format!(
            "{}×{} image holds {} bytes, fewer than its size needs",
            d.width,
            d.height,
            d.pixels.len()
        ));
    }
    let value = |px: &[u8], c: usize| -> f32 {
        // Grey (1 or 2 channels): every colour channel reads channel 0.
        let c = if channels < 3 { 0 } else { c };
        let at = c * bytes_per;
        match bytes_per {
            1 => srgb8[px[at] as usize],
            2 => srgb16(u16::from_le_bytes([px[at], px[at + 1]])),
            _ => f32::from_le_bytes([px[at], px[at + 1], px[at + 2], px[at + 3]]),
        }
    };
    Ok(d.pixels[..n * stride]
        .chunks_exact(stride)
        .map(|px| [value(px, 0), value(px, 1), value(px, 2)])
        .collect())
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
