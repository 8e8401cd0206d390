//! The merge of a render's shards (`het-bssrdf merge`) into the whole image; the shards'
//! identity and files are [`crate::sharding`]'s.
//!
//! **Merge.** [`merge`] takes every shard's EXR (the sidecar beside each is read too), checks
//! that each EXR's own header says what its sidecar says (spp, seed, method, profile, tool
//! version, split, scene hash, exposure, budget, state, checksum) and that its decoded pixels
//! have the checksum of its header (a flipped bit is refused), that they are shards of one
//! render (same scene hash, seed, method, profile, estimator parameters, scattering, depth,
//! size, collision cap, tool version, budget, preview exposure and shard count, in the
//! sidecars and in the headers) and that each index `0..N` is there exactly once, and copies
//! each shard's rows into the image. With a sample budget the merged EXR and PNG are byte for byte those of the whole
//! render with the same seed: pixels are copied as stored (`f32`), the header is rebuilt by
//! [`crate::files::render_attributes`] as a whole render's, and the preview is made from the
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

use crate::files::{render_attributes, sidecar_paths, write_image_set};

use crate::sharding::{PARTITION, pixel_checksum};

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
    /// The EXR header's metadata pairs.
    header: Vec<(String, String)>,
    shard: Shard,
    /// The image's width and height.
    size: (u32, u32),
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

/// Reads one shard's EXR, its header and its sidecar, and checks that they agree; returns the
/// image apart.
fn read_part(path: &Path) -> Result<(Part, Film), MergeError> {
    let (json_path, sidecar) = read_sidecar(path)?;
    let shard = finished_shard(path, &json_path, &sidecar)?;
    let header = read_exr_metadata(path)?;
    check_header(path, &json_path, &header, &sidecar, shard)?;
    let film = read_exr(path)?;
    check_pixels(path, &json_path, &sidecar, &header, &film)?;
    Ok((
        Part {
            path: path.to_path_buf(),
            sidecar,
            header,
            shard,
            size: (film.width, film.height),
        },
        film,
    ))
}

/// The path and parsed JSON of the sidecar beside the shard `path`.
fn read_sidecar(path: &Path) -> Result<(PathBuf, Value), MergeError> {
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
    Ok((json_path, sidecar))
}

/// The shard that the sidecar `json_path` of `path` states, checked to be one of this
/// partition and finished (neither interrupted nor a checkpoint).
fn finished_shard(path: &Path, json_path: &Path, sidecar: &Value) -> Result<Shard, MergeError> {
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
    Ok(shard)
}

/// Checks a shard's pixels against its sidecar's size and its header's checksum.
fn check_pixels(
    path: &Path,
    json_path: &Path,
    sidecar: &Value,
    header: &[(String, String)],
    film: &Film,
) -> Result<(), MergeError> {
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
    let stated = header_value(header, "pixelChecksum").unwrap_or("none");
    let actual = pixel_checksum(film);
    if stated != actual {
        return Err(shard_err(
            path,
            format!(
                "its pixel data does not match the checksum in its header (pixelChecksum \
                 {stated}, pixels {actual}): the file is corrupted; render this shard again"
            ),
        ));
    }
    Ok(())
}

/// The value of `name` in an EXR header's metadata pairs.
fn header_value<'a>(header: &'a [(String, String)], name: &str) -> Option<&'a str> {
    header
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
}

/// A JSON number or string as the EXR header writes it (`f64` by Rust's shortest round-trip
/// form, integers as integers).
fn as_header_text(v: &Value) -> Option<String> {
    match v {
        Value::String(s) => Some(s.clone()),
        Value::Number(n) if n.is_u64() || n.is_i64() => Some(n.to_string()),
        Value::Number(n) => n.as_f64().map(|f| f.to_string()),
        _ => None,
    }
}

/// The header entries a shard's EXR must hold, each with what its sidecar says (the key
/// named in errors and the value as header text; `None`: missing or invalid in the sidecar).
fn expected_header(
    sidecar: &Value,
    shard: Shard,
) -> Vec<(&'static str, &'static str, Option<String>)> {
    let s = &sidecar["shard"];
    let state = match (&sidecar["interrupted"], &sidecar["checkpoint"]) {
        (Value::Bool(false), Value::Bool(false)) => Some("final".to_string()),
        (Value::Bool(true), _) => Some("interrupted".to_string()),
        (_, Value::Bool(true)) => Some("checkpoint".to_string()),
        _ => None,
    };
    vec![
        (
            "generator",
            "tool.version",
            sidecar["tool"]["version"]
                .as_str()
                .map(|v| format!("het-bssrdf {v}")),
        ),
        ("samplesPerPixel", "spp", as_header_text(&sidecar["spp"])),
        ("seed", "seed", as_header_text(&sidecar["seed"])),
        ("method", "method", as_header_text(&sidecar["method"])),
        (
            "profile",
            "profile",
            match &sidecar["profile"] {
                Value::Null => Some("none".to_string()),
                v => as_header_text(v),
            },
        ),
        ("shard", "shard", Some(shard.to_string())),
        (
            "partition",
            "shard.partition",
            as_header_text(&s["partition"]),
        ),
        (
            "sceneHash",
            "shard.scene_hash",
            as_header_text(&s["scene_hash"]),
        ),
        (
            "exposure",
            "preview_exposure",
            as_header_text(&sidecar["preview_exposure"]),
        ),
        (
            "timeBudget",
            "time_budget_seconds",
            match &sidecar["time_budget_seconds"] {
                Value::Null => Some("none".to_string()),
                v => as_header_text(v),
            },
        ),
        ("state", "interrupted, checkpoint", state),
        (
            "pixelChecksum",
            "pixel_checksum",
            as_header_text(&sidecar["pixel_checksum"]),
        ),
    ]
}

/// Checks that the shard EXR's own header says what its sidecar says (see
/// [`expected_header`]): an EXR from another render (another spp, seed, method, exposure,
/// scene or split; a checkpoint) beside a good sidecar is refused.
fn check_header(
    path: &Path,
    json_path: &Path,
    header: &[(String, String)],
    sidecar: &Value,
    shard: Shard,
) -> Result<(), MergeError> {
    for (name, key, expected) in expected_header(sidecar, shard) {
        let found = header_value(header, name);
        if found.is_none() {
            return Err(shard_err(
                path,
                format!(
                    "its header has no `{name}`: not a shard EXR of this version of \
                     het-bssrdf ({}); render it again",
                    env!("CARGO_PKG_VERSION")
                ),
            ));
        }
        if found != expected.as_deref() {
            return Err(shard_err(
                path,
                format!(
                    "its header does not match its sidecar `{}`: {name} is {} in the EXR, \
                     {key} is {} in the sidecar; the files are from different renders",
                    json_path.display(),
                    found.unwrap_or("none"),
                    expected.as_deref().unwrap_or("missing"),
                ),
            ));
        }
    }
    Ok(())
}

/// The value at a `/`-separated `key` of a sidecar.
fn at<'a>(v: &'a Value, key: &str) -> &'a Value {
    key.split('/').fold(v, |v, k| &v[k])
}

/// Checks that `parts` are the shards of one render, each index once: their sidecars agree on
/// every key of [`SHARED`] (and on the preview's exposure unless `exposure_given`, the merge's
/// own `--exposure`), and so do their EXR headers, but for the shard index, the pixel checksum
/// and, under a time budget, the sample count.
fn check_consistent(parts: &[Part], exposure_given: bool) -> Result<(), MergeError> {
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
    if !exposure_given {
        keys.push((
            "preview_exposure",
            "preview exposure (stops; give the merge --exposure to choose one)",
        ));
    }
    let differs = |part: &Part, what: String| {
        MergeError::Inconsistent(format!(
            "`{}` and `{}` are shards of different renders: {what}",
            part.path.display(),
            first.path.display(),
        ))
    };
    for part in &parts[1..] {
        for (key, name) in &keys {
            let (a, b) = (at(&first.sidecar, key), at(&part.sidecar, key));
            if a != b {
                return Err(differs(part, format!("{name} {b} vs {a}")));
            }
        }
        for (name, value) in &part.header {
            let own = matches!(name.as_str(), "shard" | "pixelChecksum")
                || (time_budget && name == "samplesPerPixel")
                || (exposure_given && name == "exposure");
            let theirs = header_value(&first.header, name);
            if !own && theirs != Some(value.as_str()) {
                return Err(differs(
                    part,
                    format!("EXR header {name} {value} vs {}", theirs.unwrap_or("none")),
                ));
            }
        }
        if part.header.len() != first.header.len() {
            return Err(differs(
                part,
                "their EXR headers hold different entries".into(),
            ));
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

/// Reads the shards `inputs` and copies each one's rows into one image as it is read (so that
/// one shard's image is held at a time); checks that they all have the same size.
fn assemble(inputs: &[PathBuf]) -> Result<(Vec<Part>, Film), MergeError> {
    let mut parts: Vec<Part> = Vec::with_capacity(inputs.len());
    let mut film: Option<Film> = None;
    for path in inputs {
        let (part, image) = read_part(path)?;
        let merged = match &mut film {
            Some(f) => f,
            None => {
                let (w, h) = part.size;
                tracer::memory::check(
                    || format!("merging {w}x{h} shards"),
                    f64::from(w) * f64::from(h) * tracer::memory::RENDER_BYTES_PER_PIXEL,
                )
                .map_err(|e| shard_err(&part.path, e.to_string()))?;
                film.insert(Film::new(w, h))
            }
        };
        if (merged.width, merged.height) != part.size {
            return Err(MergeError::Inconsistent(format!(
                "`{}` and `{}` are shards of different renders: image size {}x{} vs {}x{}",
                part.path.display(),
                parts[0].path.display(),
                part.size.0,
                part.size.1,
                merged.width,
                merged.height
            )));
        }
        let w = merged.width as usize;
        for y in (0..merged.height).filter(|&y| part.shard.holds_row(y)) {
            let row = y as usize * w..(y as usize + 1) * w;
            merged.pixels[row.clone()].copy_from_slice(&image.pixels[row]);
        }
        parts.push(part);
    }
    Ok((parts, film.expect("at least one shard was read")))
}

/// The samples per pixel of each shard of `by_index`, from its sidecar.
fn shard_spps(by_index: &[&Part]) -> Result<Vec<u32>, MergeError> {
    by_index
        .iter()
        .map(|p| {
            p.sidecar["spp"]
                .as_u64()
                .and_then(|v| u32::try_from(v).ok())
                .ok_or_else(|| shard_err(&p.path, "its sidecar has no valid `spp`"))
        })
        .collect()
}

/// The merged EXR's header attributes: those of a render with `spp` samples per pixel and the
/// `first` shard's seed, method, profile and writer's version, and, for a time-budgeted render,
/// each shard's sample count (`per_shard_spp`).
fn merged_attributes(
    first: &Part,
    spp: u32,
    per_shard_spp: Option<&[u32]>,
) -> Result<Vec<(&'static str, ExrAttribute)>, MergeError> {
    let seed = first.sidecar["seed"]
        .as_u64()
        .ok_or_else(|| shard_err(&first.path, "its sidecar has no valid `seed`"))?;
    let method = first.sidecar["method"]
        .as_str()
        .ok_or_else(|| shard_err(&first.path, "its sidecar has no valid `method`"))?;
    let mut attributes = render_attributes(spp, seed, method, first.sidecar["profile"].as_str());
    // The shards' writer, not this one, generated the pixels (all shards share a version).
    if let (Some(version), Some(generator)) = (
        first.sidecar["tool"]["version"].as_str(),
        attributes.iter_mut().find(|(k, _)| *k == "generator"),
    ) {
        generator.1 = ExrAttribute::Text(format!("het-bssrdf {version}"));
    }
    if let Some(spps) = per_shard_spp {
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
    Ok(attributes)
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
    let (parts, film) = assemble(inputs)?;
    check_consistent(&parts, exposure.is_some())?;
    let first = &parts[0];
    let count = first.shard.count();
    let mut by_index: Vec<&Part> = parts.iter().collect();
    by_index.sort_by_key(|p| p.shard.index());
    let spps = shard_spps(&by_index)?;
    let (lo, hi) = (
        spps.iter().copied().min().unwrap_or(0),
        spps.iter().copied().max().unwrap_or(0),
    );
    let time_budget = !first.sidecar["time_budget_seconds"].is_null();
    let attributes = merged_attributes(first, lo, time_budget.then_some(spps.as_slice()))?;
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
    let exposure = exposure
        .or_else(|| first.sidecar["preview_exposure"].as_f64())
        .unwrap_or(0.0);
    let mut sidecar = first.sidecar.clone();
    if let Some(obj) = sidecar.as_object_mut() {
        obj.insert("preview_exposure".into(), json!(exposure));
        obj.remove("shard");
        obj.remove("threads");
        obj.insert("spp".into(), json!(lo));
        obj.insert("wall_seconds".into(), json!(wall_max));
        obj.insert("rays_traced".into(), json!(rays));
        obj.insert("counters".into(), summed_counters(&parts)?);
        obj.insert("warnings".into(), Value::Array(warnings));
        obj.insert("mean_rgb".into(), json!(film.mean().0));
        obj.insert("pixel_checksum".into(), json!(pixel_checksum(&film)));
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
    use crate::files::write_render;
    use crate::job::{RenderJob, render_scene};
    use crate::sharding::ShardJob;
    use tracer::render::Budget;
    use tracer::scene::Scene;

    /// A checkpoint's EXR copied over a finished shard's (same spp, seed, pixels: only its
    /// state differs) was merged; its header's `state` now refuses it.
    #[test]
    fn a_checkpoint_exr_beside_a_final_sidecar_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene::from_toml_str(
            include_str!("../../../examples/scenes/checker-slab.toml"),
            Path::new("."),
            "slab",
        )
        .unwrap()
        .with_resolution(6, 5)
        .unwrap();
        let mut job = RenderJob::from_scene(&scene, "pt".parse().unwrap());
        job.budget = Budget::Samples(1);
        let mut paths = Vec::new();
        let mut last = None;
        for i in 0..2 {
            job.shard = Some(ShardJob::new(Shard::new(i, 2).unwrap(), &scene).unwrap());
            let outcome = render_scene(&scene, &job).unwrap();
            let path = dir.path().join(format!("s-{i}.exr"));
            write_render(&outcome, &scene, &job, &path, 0.0).unwrap();
            paths.push(path);
            last = Some(outcome);
        }
        let out = dir.path().join("m.exr");
        merge(&paths, &out, None).unwrap();
        let mut checkpoint = last.unwrap();
        checkpoint.checkpoint = true;
        let x = dir.path().join("x.exr");
        write_render(&checkpoint, &scene, &job, &x, 0.0).unwrap();
        std::fs::copy(&x, &paths[1]).unwrap();
        let e = merge(&paths, &out, None).unwrap_err().to_string();
        assert!(e.contains("state is checkpoint in the EXR"), "{e}");
        assert!(e.contains("s-1.exr"), "{e}");
    }
}
