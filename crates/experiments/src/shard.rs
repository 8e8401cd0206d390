//! Renders split across machines: the files of one shard (`render --tile I/N`) and their merge
//! (`het-bssrdf merge`).
//!
//! **Partition.** Shard `I` of `N` holds the image rows `y` with `y mod N = I`
//! ([`tracer::render::Shard`]): interleaved rows, so that every shard samples every band of
//! the image and the shards take about the same time. Every pixel sample draws from its own
//! random stream (seed, pixel, sample index), so a shard's rows are exactly those of a whole
//! render with the same seed.
//!
//! **Shard files.** A shard is an ordinary render's set of files: a full-size EXR whose rows
//! outside the shard are black, its PNG preview and its JSON sidecar. The EXR header records
//! `shard=I/N`, `partition=interleaved-rows` and `sceneHash=…` besides the usual metadata;
//! the sidecar's `shard` object holds the same (`index`, `count`, `partition`, `scene_hash`).
//! The scene hash is 64-bit FNV-1a over the scene file's bytes followed by those of every
//! file it reads (meshes, textures), in order: an identity check against mixing renders of
//! edited scenes, not a cryptographic one.
//!
//! **Merge.** [`merge`] takes every shard's EXR (the sidecar beside each is read too), checks
//! that they are shards of one render (same scene hash, seed, method, profile, estimator
//! parameters, scattering, depth, size, collision cap, tool version, budget and shard count)
//! and that each index `0..N` is there exactly once, and copies each shard's rows into the
//! image. With a sample budget the merged EXR and PNG are byte for byte those of the whole
//! render with the same seed: pixels are copied as stored (`f32`), the header is rebuilt by
//! [`crate::run::render_attributes`] as a whole render's, and the preview is made from the
//! stored values by both. The merged sidecar sums the shards' counters and rays, gives
//! `wall_seconds` as the longest shard's, and lists every shard under `merged`
//! (`wall_seconds_sum`, a CPU-time-like total, and per-shard spp, time, rays and threads).
//!
//! **Time budgets.** Each shard of `render --time T --tile I/N` gets the budget `T` of its
//! own, and reaches its own sample count `spp_I` (recorded in its sidecar). The merge
//! guarantees that every row of shard `I` equals the same row of a whole render with
//! `--spp spp_I` and the same seed; it cannot equal a whole time-budgeted render, whose sample
//! count depends on the machine. The merged header's `samplesPerPixel` is the smallest
//! `spp_I`, `samplesPerPixelPerShard` lists them all, and the sidecar says `spp` (smallest),
//! `time_budget_seconds` and each shard's spp under `merged.shards`.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use tracer::error::OutputError;
use tracer::film::Film;
use tracer::output::{ExrAttribute, read_exr, read_exr_metadata};
use tracer::render::Shard;
use tracer::scene::Scene;

use crate::run::{render_attributes, sidecar_paths, write_image_set};

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

    /// The EXR header entries of a shard (after a render's usual ones).
    pub fn attributes(&self) -> Vec<(&'static str, ExrAttribute)> {
        vec![
            ("shard", ExrAttribute::Text(self.shard.to_string())),
            ("partition", ExrAttribute::Text(PARTITION.to_string())),
            ("sceneHash", ExrAttribute::Text(self.scene_hash.clone())),
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
    let mut hash = 0xcbf2_9ce4_8422_2325;
    let files = scene
        .source_path()
        .into_iter()
        .chain(scene.input_files().iter().map(PathBuf::as_path));
    let mut any = false;
    for path in files {
        let bytes = std::fs::read(path).map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            action: "read (to hash the scene)",
            source,
        })?;
        hash = fnv1a(hash, &bytes);
        any = true;
    }
    if !any {
        hash = fnv1a(hash, scene.display_name().as_bytes());
    }
    Ok(format!("fnv1a64:{hash:016x}"))
}

/// Why shards could not be merged.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MergeError {
    /// A file could not be read or written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// One shard's files are unusable.
    #[error("`{}`: {message}", path.display())]
    Shard {
        /// The shard's EXR.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The shards do not make one image (they name their files).
    #[error("{0}")]
    Inconsistent(String),
}

/// A shard read for merging.
struct Part {
    path: PathBuf,
    sidecar: Value,
    shard: Shard,
    film: Film,
}

/// What [`merge`] made.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct MergeSummary {
    /// Number of shards.
    pub count: u32,
    /// Smallest and largest samples per pixel of the shards (equal under a sample budget).
    pub spp: (u32, u32),
    /// True when the shards had a time budget (the merge is not a whole render's image).
    pub time_budget: bool,
    /// The PNG and JSON written beside the EXR.
    pub sidecars: (PathBuf, PathBuf),
}

/// The sidecar keys that shards of one render share (besides `shard.count` and
/// `shard.scene_hash`), and how a difference is named.
const SHARED: &[(&str, &str)] = &[
    ("seed", "seed"),
    ("method", "method"),
    ("profile", "profile"),
    ("estimator_parameters", "estimator parameters"),
    ("scattering", "scattering"),
    ("max_depth", "max depth"),
    ("width", "width"),
    ("height", "height"),
    ("max_collisions", "collision cap"),
    ("time_budget_seconds", "time budget (seconds)"),
];

fn shard_err(path: &Path, message: impl Into<String>) -> MergeError {
    MergeError::Shard {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Reads one shard's EXR, its header and its sidecar, and checks that they agree.
fn read_part(path: &Path) -> Result<Part, MergeError> {
    let (_, json_path) = sidecar_paths(path);
    let text = std::fs::read_to_string(&json_path).map_err(|source| OutputError::Io {
        path: json_path.clone(),
        action: "read the sidecar of the shard",
        source,
    })?;
    let sidecar: Value = serde_json::from_str(&text).map_err(|e| {
        shard_err(
            path,
            format!(
                "its sidecar `{}` is not valid JSON: {e}",
                json_path.display()
            ),
        )
    })?;
    let s = &sidecar["shard"];
    let field = |key: &str| {
        s[key]
            .as_u64()
            .and_then(|v| u32::try_from(v).ok())
            .ok_or_else(|| {
                shard_err(
                    path,
                    format!(
                        "not a shard: its sidecar `{}` has no valid `shard.{key}` (shards are \
                     written by `render --tile I/N`)",
                        json_path.display()
                    ),
                )
            })
    };
    let (index, count) = (field("index")?, field("count")?);
    let shard = Shard::new(index, count).ok_or_else(|| {
        shard_err(
            path,
            format!(
                "`shard` of `{}` is {index}/{count}: the index must be below the count",
                json_path.display()
            ),
        )
    })?;
    if s["partition"].as_str() != Some(PARTITION) {
        return Err(shard_err(
            path,
            format!(
                "`shard.partition` of `{}` is {}, not \"{PARTITION}\"",
                json_path.display(),
                s["partition"]
            ),
        ));
    }
    for key in ["interrupted", "checkpoint"] {
        if sidecar[key] != Value::Bool(false) {
            return Err(shard_err(
                path,
                format!(
                    "`{key}` is {} in `{}`: only a finished shard can be merged; render it again",
                    sidecar[key],
                    json_path.display()
                ),
            ));
        }
    }
    let header = read_exr_metadata(path)?;
    let get = |name: &str| {
        header
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    };
    let hash = s["scene_hash"].as_str();
    if get("shard") != Some(&shard.to_string()) || get("sceneHash") != hash {
        return Err(shard_err(
            path,
            format!(
                "its header (shard {}, scene hash {}) does not match its sidecar `{}` (shard \
                 {shard}, scene hash {}): the files are from different renders",
                get("shard").unwrap_or("none"),
                get("sceneHash").unwrap_or("none"),
                json_path.display(),
                hash.unwrap_or("none"),
            ),
        ));
    }
    let film = read_exr(path)?;
    let size = (sidecar["width"].as_u64(), sidecar["height"].as_u64());
    if size != (Some(film.width.into()), Some(film.height.into())) {
        return Err(shard_err(
            path,
            format!(
                "the image is {}x{} but its sidecar `{}` says width {}, height {}",
                film.width,
                film.height,
                json_path.display(),
                sidecar["width"],
                sidecar["height"]
            ),
        ));
    }
    Ok(Part {
        path: path.to_path_buf(),
        sidecar,
        shard,
        film,
    })
}

/// The value at a `/`-separated `key` of a sidecar.
fn at<'a>(v: &'a Value, key: &str) -> &'a Value {
    key.split('/').fold(v, |v, k| &v[k])
}

/// Checks that `parts` are the shards of one render, each index once.
fn check_consistent(parts: &[Part]) -> Result<(), MergeError> {
    let first = &parts[0];
    let time_budget = !first.sidecar["time_budget_seconds"].is_null();
    let mut keys: Vec<(&str, &str)> = vec![
        ("shard/scene_hash", "scene (hash of its files)"),
        ("shard/count", "shard count N"),
        ("tool/version", "het-bssrdf version"),
    ];
    keys.extend_from_slice(SHARED);
    if !time_budget {
        keys.push(("spp", "samples per pixel"));
    }
    for part in &parts[1..] {
        for (key, name) in &keys {
            let (a, b) = (at(&first.sidecar, key), at(&part.sidecar, key));
            if a != b {
                return Err(MergeError::Inconsistent(format!(
                    "`{}` and `{}` are shards of different renders: {name} {b} vs {a}",
                    part.path.display(),
                    first.path.display(),
                )));
            }
        }
    }
    let count = first.shard.count();
    let mut holder: Vec<Option<&Path>> = vec![None; count as usize];
    for part in parts {
        let slot = &mut holder[part.shard.index() as usize];
        if let Some(other) = slot {
            return Err(MergeError::Inconsistent(format!(
                "`{}` and `{}` are both shard {}",
                other.display(),
                part.path.display(),
                part.shard
            )));
        }
        *slot = Some(&part.path);
    }
    let missing: Vec<String> = (0..count)
        .filter(|&i| holder[i as usize].is_none())
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        let given = parts
            .iter()
            .map(|p| format!("`{}` ({})", p.path.display(), p.shard))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(MergeError::Inconsistent(format!(
            "shard{} {} missing: given {given}",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", "),
        )));
    }
    Ok(())
}

/// The sum of the integer fields of the shards' `counters`.
fn summed_counters(parts: &[Part]) -> Result<Value, MergeError> {
    let mut sum = serde_json::Map::new();
    for part in parts {
        let Some(counters) = part.sidecar["counters"].as_object() else {
            return Err(shard_err(
                &part.path,
                "its sidecar has no `counters` object",
            ));
        };
        for (k, v) in counters {
            let v = v.as_u64().ok_or_else(|| {
                shard_err(
                    &part.path,
                    format!("`counters.{k}` of its sidecar is not a count: {v}"),
                )
            })?;
            let total = sum.get(k).and_then(Value::as_u64).unwrap_or(0);
            sum.insert(k.clone(), json!(total.saturating_add(v)));
        }
    }
    Ok(Value::Object(sum))
}

/// Merges the shards `inputs` (EXR paths, each with its sidecar beside it) into `out`, with its
/// PNG preview (exposure `exposure` stops, default the shards' `preview_exposure`) and
/// sidecar; see the module docs. Nothing is written unless every check passes.
pub fn merge(
    inputs: &[PathBuf],
    out: &Path,
    exposure: Option<f64>,
) -> Result<MergeSummary, MergeError> {
    if inputs.is_empty() {
        return Err(MergeError::Inconsistent("no shards given".into()));
    }
    let parts = inputs
        .iter()
        .map(|p| read_part(p))
        .collect::<Result<Vec<_>, _>>()?;
    check_consistent(&parts)?;
    let first = &parts[0];
    let (width, height) = (first.film.width, first.film.height);
    let count = first.shard.count();
    let mut by_index: Vec<&Part> = parts.iter().collect();
    by_index.sort_by_key(|p| p.shard.index());
    let mut film = Film::new(width, height);
    let w = width as usize;
    for y in 0..height {
        let src = &by_index[(y % count) as usize].film;
        let row = y as usize * w..(y as usize + 1) * w;
        film.pixels[row.clone()].copy_from_slice(&src.pixels[row]);
    }
    let spp = |p: &Part| {
        p.sidecar["spp"]
            .as_u64()
            .and_then(|v| u32::try_from(v).ok())
            .ok_or_else(|| shard_err(&p.path, "its sidecar has no valid `spp`"))
    };
    let spps = by_index
        .iter()
        .map(|p| spp(p))
        .collect::<Result<Vec<_>, _>>()?;
    let (lo, hi) = (
        spps.iter().copied().min().unwrap_or(0),
        spps.iter().copied().max().unwrap_or(0),
    );
    let time_budget = !first.sidecar["time_budget_seconds"].is_null();
    let seed = first.sidecar["seed"]
        .as_u64()
        .ok_or_else(|| shard_err(&first.path, "its sidecar has no valid `seed`"))?;
    let method = first.sidecar["method"]
        .as_str()
        .ok_or_else(|| shard_err(&first.path, "its sidecar has no valid `method`"))?;
    let mut attributes = render_attributes(lo, seed, method, first.sidecar["profile"].as_str());
    // The shards' writer, not this one, generated the pixels (all shards share a version).
    if let (Some(version), Some(generator)) = (
        first.sidecar["tool"]["version"].as_str(),
        attributes.iter_mut().find(|(k, _)| *k == "generator"),
    ) {
        generator.1 = ExrAttribute::Text(format!("het-bssrdf {version}"));
    }
    if time_budget {
        attributes.push((
            "samplesPerPixelPerShard",
            ExrAttribute::Text(
                spps.iter()
                    .map(u32::to_string)
                    .collect::<Vec<_>>()
                    .join(","),
            ),
        ));
    }
    let secs = |p: &Part| p.sidecar["wall_seconds"].as_f64().unwrap_or(0.0);
    let wall_sum: f64 = by_index.iter().map(|p| secs(p)).sum();
    let wall_max = by_index.iter().map(|p| secs(p)).fold(0.0, f64::max);
    let rays: u64 = by_index
        .iter()
        .map(|p| p.sidecar["rays_traced"].as_u64().unwrap_or(0))
        .fold(0, u64::saturating_add);
    let mut warnings: Vec<Value> = Vec::new();
    for p in &by_index {
        for w in p.sidecar["warnings"].as_array().into_iter().flatten() {
            if !warnings.contains(w) {
                warnings.push(w.clone());
            }
        }
    }
    let mut sidecar = first.sidecar.clone();
    if let Some(obj) = sidecar.as_object_mut() {
        obj.remove("shard");
        obj.remove("threads");
        obj.insert("spp".into(), json!(lo));
        obj.insert("wall_seconds".into(), json!(wall_max));
        obj.insert("rays_traced".into(), json!(rays));
        obj.insert("counters".into(), summed_counters(&parts)?);
        obj.insert("warnings".into(), Value::Array(warnings));
        obj.insert("mean_rgb".into(), json!(film.mean().0));
        obj.insert(
            "merged".into(),
            json!({
                "partition": PARTITION,
                "count": count,
                "scene_hash": first.sidecar["shard"]["scene_hash"],
                "wall_seconds_sum": wall_sum,
                "wall_seconds_max": wall_max,
                "shards": by_index.iter().zip(&spps).map(|(p, spp)| json!({
                    "file": p.path.display().to_string(),
                    "index": p.shard.index(),
                    "spp": spp,
                    "wall_seconds": secs(p),
                    "rays_traced": p.sidecar["rays_traced"],
                    "threads": p.sidecar["threads"],
                })).collect::<Vec<_>>(),
            }),
        );
    }
    let exposure = exposure
        .or_else(|| first.sidecar["preview_exposure"].as_f64())
        .unwrap_or(0.0);
    write_image_set(
        &film,
        &attributes,
        &crate::provenance::stamped(sidecar),
        out,
        exposure,
    )?;
    Ok(MergeSummary {
        count,
        spp: (lo, hi),
        time_budget,
        sidecars: sidecar_paths(out),
    })
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
