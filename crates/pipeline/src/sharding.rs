//! Renders split across machines: what makes a render one shard of a larger one, and what
//! its files record (the merge is [`crate::shard_merge`]).
//!
//! **Partition.** Shard `I` of `N` holds the image rows `y` with `y mod N = I`
//! ([`tracer::render::Shard`]): interleaved rows, so that every shard samples every band of
//! the image and the shards take about the same time. Every pixel sample draws from its own
//! random stream (seed, pixel, sample index), so a shard's rows are exactly those of a whole
//! render with the same seed.
//!
//! **Shard files.** A shard is an ordinary render's set of files: a full-size EXR whose rows
//! outside the shard are black, its PNG preview and its JSON sidecar. The EXR header records
//! `shard=I/N`, `partition=interleaved-rows`, `sceneHash=…`, `exposure`, `timeBudget`,
//! `state` (`final`, `checkpoint` or `interrupted`) and `pixelChecksum` besides the usual
//! metadata (generator, spp, seed, method, profile); the sidecar's `shard` object holds the
//! shard's identity (`index`, `count`, `partition`, `scene_hash`) and its `pixel_checksum`
//! the checksum. The scene hash is 64-bit FNV-1a over the scene file's bytes followed by those
//! of every file it reads (meshes, textures, a glTF file's external buffers and images), in
//! order; the pixel checksum is FNV-1a over the stored `f32` values ([`pixel_checksum`]).
//! Both are identity checks against mixed or corrupted files, not cryptographic ones.

use std::path::PathBuf;

use serde_json::{Value, json};
use tracer::error::OutputError;
use tracer::film::Film;
use tracer::output::ExrAttribute;
use tracer::render::Shard;
use tracer::scene::Scene;

/// The partition's name, as written in shard files.
pub const PARTITION: &str = "interleaved-rows";

/// What makes a render one shard of a larger one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShardJob {
    /// Which rows.
    pub shard: Shard,
    /// [`scene_hash`] of the scene rendered.
    pub scene_hash: String,
}

impl ShardJob {
    /// Shard `shard` of a render of `scene` (reads the scene's files to hash them).
    pub fn new(shard: Shard, scene: &Scene) -> Result<Self, OutputError> {
        Ok(Self {
            shard,
            scene_hash: scene_hash(scene)?,
        })
    }

    /// The EXR header entries of a shard (after a render's usual ones): which rows, the
    /// scene's hash, and what else the merge checks against the sidecar and the other shards
    /// (see [`ShardHeader`]).
    pub fn attributes(&self, header: &ShardHeader) -> Vec<(&'static str, ExrAttribute)> {
        vec![
            ("shard", ExrAttribute::Text(self.shard.to_string())),
            ("partition", ExrAttribute::Text(PARTITION.to_string())),
            ("sceneHash", ExrAttribute::Text(self.scene_hash.clone())),
            ("exposure", ExrAttribute::Text(header.exposure.to_string())),
            (
                "timeBudget",
                ExrAttribute::Text(
                    header
                        .time_budget_seconds
                        .map_or_else(|| "none".to_string(), |t| t.to_string()),
                ),
            ),
            ("state", ExrAttribute::Text(header.state.to_string())),
            (
                "pixelChecksum",
                ExrAttribute::Text(header.pixel_checksum.clone()),
            ),
        ]
    }

    /// The sidecar's `shard` object.
    pub fn to_json(&self) -> Value {
        json!({
            "index": self.shard.index(),
            "count": self.shard.count(),
            "partition": PARTITION,
            "scene_hash": self.scene_hash,
        })
    }
}

/// What a shard's header records besides its rows and scene: the values that make a shard EXR
/// beside a sidecar of another render (another exposure or budget, a checkpoint, a corrupted
/// copy) detectable from the EXR alone.
#[derive(Debug, Clone, PartialEq)]
pub struct ShardHeader {
    /// Exposure of the PNG preview, in stops.
    pub exposure: f64,
    /// The time budget, when the render had one.
    pub time_budget_seconds: Option<f64>,
    /// `final`, `checkpoint` or `interrupted`.
    pub state: &'static str,
    /// [`pixel_checksum`] of the pixels the EXR holds.
    pub pixel_checksum: String,
}

/// The checksum of an image's pixel data as an EXR stores it: `fnv1a64:` and 16 hex digits of
/// FNV-1a over the `f32` values (little-endian R, G, B of each pixel, rows from the top). A
/// flipped bit in the file's pixel blocks changes a decoded value, hence the checksum.
pub fn pixel_checksum(film: &Film) -> String {
    let mut hash = FNV_OFFSET;
    for p in &film.pixels {
        for c in 0..3 {
            hash = fnv1a(hash, &(p[c] as f32).to_le_bytes());
        }
    }
    format!("fnv1a64:{hash:016x}")
}

/// FNV-1a's 64-bit offset basis.
const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// 64-bit FNV-1a (Fowler, Noll, Vo) of `bytes`, continuing from `hash`.
fn fnv1a(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
    hash
}

/// The scene's identity for merges: `fnv1a64:` and 16 hex digits of FNV-1a over the scene
/// file's bytes and then those of every file it reads, in order. A scene built in code (no
/// file) hashes its name.
pub fn scene_hash(scene: &Scene) -> Result<String, OutputError> {
    let mut hash = FNV_OFFSET;
    let files = scene
        .source_path()
        .into_iter()
        .chain(scene.input_files().iter().map(PathBuf::as_path));
    let mut any = false;
    for path in files {
        let io = |source| OutputError::Io {
            path: path.to_path_buf(),
            action: "read (to hash the scene)",
            source,
        };
        let mut file = std::fs::File::open(path).map_err(io)?;
        let mut buf = vec![0u8; 1 << 16];
        loop {
            match std::io::Read::read(&mut file, &mut buf) {
                Ok(0) => break,
                Ok(n) => hash = fnv1a(hash, &buf[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io(e)),
            }
        }
        any = true;
    }
    if !any {
        hash = fnv1a(hash, scene.display_name().as_bytes());
    }
    Ok(format!("fnv1a64:{hash:016x}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_known_answers() {
        // Published FNV-1a 64-bit test vectors: "" and "a".
        assert_eq!(fnv1a(0xcbf2_9ce4_8422_2325, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(0xcbf2_9ce4_8422_2325, b"a"), 0xaf63_dc4c_8601_ec8c);
    }
}
