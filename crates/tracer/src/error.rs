//! Typed errors of the tracer's infrastructure, grouped by who is at fault.
//!
//! * [`MeshError`]: a mesh (file or generated) is unusable (empty, bad indices, NaN vertices,
//!   degenerate triangles, a loader failure). It names the mesh file.
//! * [`TextureError`]: an image texture cannot be decoded or holds invalid texels. It names the
//!   image file (and the texel).
//! * [`FieldError`]: a coefficient field was given invalid parameters (negative or NaN value,
//!   zero width…). The scene loader wraps it with the key that holds the field.
//! * [`SceneError`]: a scene description is invalid. Every variant names the scene file and the
//!   key path (`material[2].sigma_a.width`), and gives the line when it is known.
//! * [`OutputError`]: an output file could not be written or read back. It names the path.

use std::fmt;
use std::path::PathBuf;

/// A mesh that cannot be used. `file` is the mesh file, or a description of a generated mesh
/// (`"<sphere shape[1]>"`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// A problem found at a line of a text mesh file (OBJ).
    #[error("{file}:{line}: {message}")]
    AtLine {
        /// Mesh file.
        file: String,
        /// Line number, from 1.
        line: usize,
        /// What is wrong there.
        message: String,
    },
    /// No triangles (or no vertices).
    #[error("{file}: the mesh has no triangles")]
    Empty {
        /// Mesh file.
        file: String,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "{file}: triangle {triangle} refers to vertex {index}, but the mesh has {vertices} vertices"
    )]
    IndexOutOfRange {
        /// Mesh file.
        file: String,
        /// Triangle index.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A vertex attribute holds NaN or infinity.
    #[error("{file}: vertex {vertex} has a non-finite {attribute} {value:?}")]
    NonFinite {
        /// Mesh file.
        file: String,
        /// `"position"`, `"normal"` or `"texture coordinate"`.
        attribute: &'static str,
        /// Vertex index.
        vertex: usize,
        /// The value (texture coordinates are padded with 0).
        value: [f32; 3],
    },
    /// A triangle with zero area (two equal vertices or three collinear ones).
    #[error("{file}: triangle {triangle} (vertices {vertices:?}) is degenerate: its area is zero")]
    Degenerate {
        /// Mesh file.
        file: String,
        /// Triangle index.
        triangle: usize,
        /// Its vertex indices.
        vertices: [u32; 3],
    },
    /// A per-vertex attribute array whose length differs from the number of positions.
    #[error("{file}: {attribute} has {found} entries but the mesh has {expected} vertices")]
    AttributeCount {
        /// Mesh file.
        file: String,
        /// `"normals"` or `"texture coordinates"`.
        attribute: &'static str,
        /// Number of positions.
        expected: usize,
        /// Number of attribute entries.
        found: usize,
    },
    /// The file could not be parsed by the loader.
    #[error("{file}: cannot load mesh: {message}")]
    Load {
        /// Mesh file.
        file: String,
        /// The loader's message.
        message: String,
    },
    /// The format's cargo feature is disabled.
    #[error("{file}: {format} meshes need the `{feature}` feature of het-bssrdf-tracer")]
    Unsupported {
        /// Mesh file.
        file: String,
        /// Format name.
        format: &'static str,
        /// The cargo feature to enable.
        feature: &'static str,
    },
}

/// An image texture that cannot be used. `file` is the image file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TextureError {
    /// The file cannot be opened or read.
    #[error("{file}: cannot read texture")]
    Io {
        /// Image file.
        file: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The decoder rejected the file.
    #[error("{file}: cannot decode texture: {message}")]
    Decode {
        /// Image file.
        file: String,
        /// The decoder's message.
        message: String,
    },
    /// A texel is NaN, infinite or negative.
    #[error(
        "{file}: texel (x = {x}, y = {y}) channel {channel} is {value}: texture values must be finite and non-negative"
    )]
    BadTexel {
        /// Image file.
        file: String,
        /// Column (0 = left).
        x: u32,
        /// Row (0 = top).
        y: u32,
        /// Channel (0 = R, 1 = G, 2 = B).
        channel: usize,
        /// The value read (after sRGB decoding).
        value: f32,
    },
    /// Zero width or height.
    #[error("{file}: the image is empty ({width}x{height})")]
    Empty {
        /// Image file.
        file: String,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// The format is not supported (or its feature is disabled).
    #[error("{file}: {message}")]
    Unsupported {
        /// Image file.
        file: String,
        /// What is missing.
        message: String,
    },
}

/// Invalid parameters of a coefficient field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldError {
    /// A coefficient value (or scale) is negative, NaN or infinite.
    #[error("{what} must be finite and non-negative, got {value:?}")]
    BadValue {
        /// Which value (`"value"`, `"values[1]"`, `"scale"`).
        what: String,
        /// The RGB value given.
        value: [f64; 3],
    },
    /// A length (stripe width, image size) is not finite and positive.
    #[error("{what} must be finite and positive, got {value}")]
    BadLength {
        /// Which length.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// Any other invalid parameter.
    #[error("{0}")]
    Other(String),
}

/// A key path inside a scene file with an optional line number, e.g. `material[1].g (line 12)`.
fn fmt_location(
    f: &mut fmt::Formatter<'_>,
    file: &std::path::Path,
    key: &str,
    line: &Option<usize>,
) -> fmt::Result {
    write!(f, "{}", file.display())?;
    if let Some(l) = line {
        write!(f, ":{l}")?;
    }
    if !key.is_empty() {
        write!(f, ": `{key}`")?;
    }
    Ok(())
}

/// An invalid scene description. Every variant names the scene file (`file`) and the key path
/// (`key`, e.g. `shape[3].path`; empty for the whole document), and the line when known.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// Malformed TOML, an unknown key, a missing key or a value of the wrong type.
    #[error("{}: {message}", Loc(file, key, line))]
    Parse {
        /// Scene file.
        file: PathBuf,
        /// Key path.
        key: String,
        /// 1-based line, when known.
        line: Option<usize>,
        /// What was expected.
        message: String,
    },
    /// A file (the scene itself, a mesh or a texture) cannot be read.
    #[error("{}: cannot read `{}`", Loc(file, key, line), path.display())]
    Io {
        /// Scene file.
        file: PathBuf,
        /// The key that referenced `path` (empty for the scene file itself).
        key: String,
        /// 1-based line of the key, when known.
        line: Option<usize>,
        /// The file that could not be read.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A mesh is unusable.
    #[error("{}", Loc(file, key, line))]
    Mesh {
        /// Scene file.
        file: PathBuf,
        /// The shape's key.
        key: String,
        /// 1-based line of the key, when known.
        line: Option<usize>,
        /// What is wrong with the mesh (names the mesh file).
        source: Box<MeshError>,
    },
    /// A texture is unusable.
    #[error("{}", Loc(file, key, line))]
    Texture {
        /// Scene file.
        file: PathBuf,
        /// The texture's key.
        key: String,
        /// 1-based line of the key, when known.
        line: Option<usize>,
        /// What is wrong with the texture (names the image file).
        source: Box<TextureError>,
    },
    /// A value is out of range or inconsistent (|g| ≥ 1, negative coefficient, unknown
    /// material name, duplicate name, open mesh where a closed one is required…).
    #[error("{}: {message}", Loc(file, key, line))]
    Invalid {
        /// Scene file.
        file: PathBuf,
        /// Key path.
        key: String,
        /// 1-based line of the key, when known.
        line: Option<usize>,
        /// What is wrong and what was expected.
        message: String,
    },
}

impl SceneError {
    /// The scene file the error refers to.
    pub fn file(&self) -> &std::path::Path {
        match self {
            SceneError::Parse { file, .. }
            | SceneError::Io { file, .. }
            | SceneError::Mesh { file, .. }
            | SceneError::Texture { file, .. }
            | SceneError::Invalid { file, .. } => file,
        }
    }
    /// The key path the error refers to (empty for the whole document).
    pub fn key(&self) -> &str {
        match self {
            SceneError::Parse { key, .. }
            | SceneError::Io { key, .. }
            | SceneError::Mesh { key, .. }
            | SceneError::Texture { key, .. }
            | SceneError::Invalid { key, .. } => key,
        }
    }
}

/// Display helper: `file:line: `key``.
struct Loc<'a>(&'a PathBuf, &'a String, &'a Option<usize>);

impl fmt::Display for Loc<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt_location(f, self.0, self.1, self.2)
    }
}

/// An output file that could not be written, or an input image that could not be read back.
/// Every variant names the path.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The directory that should hold the file does not exist.
    #[error("cannot write `{}`: directory `{}` does not exist", path.display(), dir.display())]
    MissingDirectory {
        /// The requested output path.
        path: PathBuf,
        /// Its parent directory.
        dir: PathBuf,
    },
    /// The path names an existing directory.
    #[error("cannot write `{}`: it is a directory", path.display())]
    IsDirectory {
        /// The requested output path.
        path: PathBuf,
    },
    /// The path names something that is neither a regular file nor a directory (a device, a
    /// FIFO, a socket): it is never replaced by a file.
    #[error("cannot write `{}`: it is a {kind}, not a regular file; choose another output path", path.display())]
    NotRegular {
        /// The requested output path.
        path: PathBuf,
        /// What it is (`"character device"`, `"FIFO"`…).
        kind: &'static str,
    },
    /// A component of the path's parent is a file, not a directory.
    #[error("cannot write `{}`: `{}` is a file, not a directory", path.display(), parent.display())]
    ParentIsFile {
        /// The requested output path.
        path: PathBuf,
        /// The parent component that is a file.
        parent: PathBuf,
    },
    /// Any other I/O failure (permission denied, disk full…).
    #[error("cannot {action} `{}`", path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// `"write"`, `"read"`, `"rename into place"`…
        action: &'static str,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The encoder failed (nothing was written).
    #[error("cannot encode `{}`: {message}", path.display())]
    Encode {
        /// The path.
        path: PathBuf,
        /// The encoder's message.
        message: String,
    },
    /// The file could not be decoded.
    #[error("cannot decode `{}`: {message}", path.display())]
    Decode {
        /// The path.
        path: PathBuf,
        /// The decoder's message.
        message: String,
    },
    /// The format's cargo feature is disabled.
    #[error("cannot write `{}`: the `{feature}` feature of het-bssrdf-tracer is disabled", path.display())]
    Unsupported {
        /// The path.
        path: PathBuf,
        /// The cargo feature to enable.
        feature: &'static str,
    },
    /// Another process holds the lock of the output set (see [`crate::output::OutputLock`]).
    #[error("cannot write `{}`: another het-bssrdf run ({holder}) is writing it and the files beside it; wait for it to end or choose another output", path.display())]
    Busy {
        /// The requested output path.
        path: PathBuf,
        /// Who holds the lock, as it wrote in the lock file (`pid 1234 on node7`).
        holder: String,
    },
    /// The output would replace a file the run reads.
    #[error("cannot write `{}`: it is `{}`, an input of this run, which it would replace; choose another output", path.display(), input.display())]
    IsInput {
        /// The requested output path.
        path: PathBuf,
        /// The input it resolves to.
        input: PathBuf,
    },
}
/// Work that would need more memory than the machine has available, refused before anything
/// is allocated.
#[derive(Debug, thiserror::Error)]
#[error("{what} would need about {} of memory, more than the {} available (limit: {limit})", human_bytes(*bytes), human_bytes(*available))]
pub struct TooLarge {
    /// What is too large, with its size (`"a 20000x20000 render"`).
    pub what: String,
    /// The estimate, in bytes.
    pub bytes: f64,
    /// The memory available, in bytes.
    pub available: f64,
    /// Which limit gives `available` (see [`crate::memory::headroom`]).
    pub limit: &'static str,
}

/// A byte count in words: `9.6 GB`, `512 MB`, `12 kB` (decimal units).
pub fn human_bytes(bytes: f64) -> String {
    const UNITS: [&str; 7] = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = bytes;
    let mut i = 0;
    while v >= 1000.0 && i + 1 < UNITS.len() {
        v /= 1000.0;
        i += 1;
    }
    if i == 0 {
        format!("{v:.0} bytes")
    } else {
        format!("{v:.1} {}", UNITS[i])
    }
}
