//! Output writers (EXR, PNG preview, grey EXR maps, JSON sidecars) and EXR reading.
//!
//! Every writer is atomic: the file is encoded in memory, written to a temporary file in the
//! destination directory (`.<name>.<pid>.<n>.tmp`) and renamed into place. On any error the
//! temporary file is removed and nothing is left behind; an existing file at the destination is
//! replaced only on success. Errors name the path.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use bssrdf_core::Rgb;

use crate::error::OutputError;
use crate::film::Film;

static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically (see the module docs).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    if path.is_dir() {
        return Err(OutputError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    let name = path.file_name().ok_or_else(|| OutputError::IsDirectory {
        path: path.to_path_buf(),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir,
        });
    }
    let tmp = dir.join(format!(
        ".{}.{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id(),
        TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let io = |action, source| OutputError::Io {
        path: path.to_path_buf(),
        action,
        source,
    };
    let result = (|| {
        let mut f = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(|e| io("create a temporary file for", e))?;
        f.write_all(bytes).map_err(|e| io("write", e))?;
        f.sync_all().map_err(|e| io("flush", e))?;
        drop(f);
        fs::rename(&tmp, path).map_err(|e| io("rename into place", e))
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Writes a pretty-printed JSON sidecar atomically.
pub fn write_json(value: &serde_json::Value, path: &Path) -> Result<(), OutputError> {
    let mut s = serde_json::to_string_pretty(value).map_err(|e| OutputError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    s.push('\n');
    write_atomic(path, s.as_bytes())
}

/// The sRGB transfer function (sRGB: IEC 61966-2-1): linear `[0, 1]` → encoded `[0, 1]`.
#[inline]
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse sRGB transfer function: encoded `[0, 1]` → linear `[0, 1]`.
#[inline]
pub fn srgb_decode(encoded: f64) -> f64 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// The 8-bit sRGB preview value of a linear value after exposure: `x · 2^stops`, sRGB
/// encoded, clamped to `[0, 1]`, rounded (NaN → 0).
#[inline]
pub fn preview_byte(linear: f64, exposure_stops: f64) -> u8 {
    let v = srgb_encode(linear * exposure_stops.exp2());
    if v.is_nan() {
        0
    } else {
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// Writes the film as an 8-bit sRGB PNG preview: exposure `2^exposure_stops`, then the sRGB
/// curve (applied here, not by the encoder), then clamping.
pub fn write_png(film: &Film, path: &Path, exposure_stops: f64) -> Result<(), OutputError> {
    #[cfg(feature = "png")]
    {
        let mut buf = Vec::with_capacity(film.pixels.len() * 3);
        for p in &film.pixels {
            for c in 0..3 {
                buf.push(preview_byte(p[c], exposure_stops));
            }
        }
        let img = image::RgbImage::from_raw(film.width, film.height, buf).ok_or_else(|| {
            OutputError::Encode {
                path: path.to_path_buf(),
                message: "film size does not match its pixel count".into(),
            }
        })?;
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, image::ImageFormat::Png)
            .map_err(|e| OutputError::Encode {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        write_atomic(path, &bytes.into_inner())
    }
    #[cfg(not(feature = "png"))]
    {
        let _ = (film, exposure_stops);
        Err(OutputError::Unsupported {
            path: path.to_path_buf(),
            feature: "png",
        })
    }
}

/// A custom attribute of an EXR header, as pbrt-v4 records render metadata
/// (`samplesPerPixel`, `seed`, …).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ExrAttribute {
    /// A 32-bit integer (`int`).
    Int(i32),
    /// A 32-bit float (`float`).
    Float(f32),
    /// Latin-1 text (`string`).
    Text(String),
}

/// Writes the film as an EXR with three `f32` channels R, G, B.
pub fn write_exr(film: &Film, path: &Path) -> Result<(), OutputError> {
    write_exr_with_attributes(film, path, &[])
}

/// The EXR header attribute (a string) in which [`write_exr_with_attributes`] records its
/// metadata: `name=value` pairs joined by `; `.
pub const METADATA_ATTRIBUTE: &str = "hetBssrdf";

/// [`write_exr`] with render metadata in the header (names and values must be Latin-1), as
/// pbrt-v4 records its own; they are joined into the one string attribute
/// [`METADATA_ATTRIBUTE`] so that the file's bytes stay reproducible.
pub fn write_exr_with_attributes(
    film: &Film,
    path: &Path,
    attributes: &[(&str, ExrAttribute)],
) -> Result<(), OutputError> {
    #[cfg(feature = "exr")]
    {
        use exr::meta::attribute::{AttributeValue, Text};
        use exr::prelude::*;
        check_size(film.width, film.height, film.pixels.len(), path)?;
        let w = film.width as usize;
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = film.pixels[y * w + x];
            (p[0] as f32, p[1] as f32, p[2] as f32)
        });
        let mut image = Image::from_encoded_channels(
            (film.width as usize, film.height as usize),
            fixed_order(),
            channels,
        );
        if !attributes.is_empty() {
            // One attribute holding every pair, in the caller's order: the EXR crate keeps
            // custom attributes in a hash map whose order changes from process to process, so
            // several attributes would make the file's bytes differ between identical renders.
            let joined = attributes
                .iter()
                .map(|(name, value)| match value {
                    ExrAttribute::Int(v) => format!("{name}={v}"),
                    ExrAttribute::Float(v) => format!("{name}={v}"),
                    ExrAttribute::Text(v) => format!("{name}={v}"),
                })
                .collect::<Vec<_>>()
                .join("; ");
            let text = Text::new_or_none(&joined).ok_or_else(|| OutputError::Encode {
                path: path.to_path_buf(),
                message: format!("EXR header text must be Latin-1: `{joined}`"),
            })?;
            image
                .layer_data
                .attributes
                .other
                .insert(Text::from(METADATA_ATTRIBUTE), AttributeValue::Text(text));
        }
        encode_exr(path, |bytes| image.write().to_buffered(bytes))
    }
    #[cfg(not(feature = "exr"))]
    {
        let _ = (film, attributes);
        Err(OutputError::Unsupported {
            path: path.to_path_buf(),
            feature: "exr",
        })
    }
}

/// Writes a single-channel map (e.g. the beam experiment's exitance) as an EXR with one `f32`
/// channel `Y`; `values` is row-major, row 0 at the top.
pub fn write_grey_exr(
    width: u32,
    height: u32,
    values: &[f64],
    path: &Path,
) -> Result<(), OutputError> {
    #[cfg(feature = "exr")]
    {
        use exr::prelude::*;
        check_size(width, height, values.len(), path)?;
        let w = width as usize;
        let channels = SpecificChannels::build()
            .with_channel("Y")
            .with_pixel_fn(|Vec2(x, y): Vec2<usize>| (values[y * w + x] as f32,));
        let image = Image::from_encoded_channels(
            (width as usize, height as usize),
            fixed_order(),
            channels,
        );
        encode_exr(path, |bytes| image.write().to_buffered(bytes))
    }
    #[cfg(not(feature = "exr"))]
    {
        let _ = (width, height, values);
        Err(OutputError::Unsupported {
            path: path.to_path_buf(),
            feature: "exr",
        })
    }
}

/// The encoding of every EXR written: the `exr` crate's default compression and tiling, with
/// chunks in increasing-y order. The default (unspecified order, declared RANDOM_Y) writes
/// chunks as the compressing threads finish them, so the file's bytes would depend on the
/// thread count and timing; in a fixed order they are reproducible.
#[cfg(feature = "exr")]
fn fixed_order() -> exr::prelude::Encoding {
    exr::prelude::Encoding {
        line_order: exr::prelude::LineOrder::Increasing,
        ..exr::prelude::Encoding::default()
    }
}

/// Encodes an EXR into memory with `write` and writes it atomically to `path`.
#[cfg(feature = "exr")]
fn encode_exr(
    path: &Path,
    write: impl FnOnce(&mut std::io::Cursor<Vec<u8>>) -> exr::error::UnitResult,
) -> Result<(), OutputError> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    write(&mut bytes).map_err(|e| OutputError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    write_atomic(path, &bytes.into_inner())
}

#[cfg(feature = "exr")]
fn check_size(width: u32, height: u32, n: usize, path: &Path) -> Result<(), OutputError> {
    if width == 0 || height == 0 || width as usize * height as usize != n {
        return Err(OutputError::Encode {
            path: path.to_path_buf(),
            message: format!("{width}x{height} image with {n} values"),
        });
    }
    Ok(())
}

/// Reads an EXR written by [`write_exr`] or [`write_grey_exr`] (or any EXR whose first layer
/// has R, G, B channels, or a single Y channel, any sample type) into a film. A grey map
/// becomes equal channels.
pub fn read_exr(path: &Path) -> Result<Film, OutputError> {
    let (w, h, px) = decode_exr_rgb(path).map_err(|e| match e {
        ExrReadError::Io(source) => OutputError::Io {
            path: path.to_path_buf(),
            action: "read",
            source,
        },
        ExrReadError::Decode(message) => OutputError::Decode {
            path: path.to_path_buf(),
            message,
        },
    })?;
    Ok(Film {
        width: w,
        height: h,
        pixels: px
            .into_iter()
            .map(|p| Rgb::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect(),
    })
}

/// Why an EXR could not be read.
#[derive(Debug)]
#[cfg_attr(not(feature = "exr"), allow(dead_code))]
pub(crate) enum ExrReadError {
    Io(std::io::Error),
    Decode(String),
}

/// Reads the first valid layer of an EXR as RGB `f32` (row-major, row 0 at the top).
pub(crate) fn decode_exr_rgb(path: &Path) -> Result<(u32, u32, Vec<[f32; 3]>), ExrReadError> {
    #[cfg(feature = "exr")]
    {
        use exr::prelude::*;
        let bytes = fs::read(path).map_err(ExrReadError::Io)?;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .non_parallel()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(|e| ExrReadError::Decode(e.to_string()))?;
        let layer = &image.layer_data;
        let (w, h) = (layer.size.width(), layer.size.height());
        let find = |name: &str| {
            layer.channel_data.list.iter().find(|c| {
                let s = c.name.to_string();
                s == name || s.rsplit('.').next() == Some(name)
            })
        };
        let values =
            |c: &AnyChannel<FlatSamples>| -> Vec<f32> { c.sample_data.values_as_f32().collect() };
        let pixels: Vec<[f32; 3]> = match (find("R"), find("G"), find("B"), find("Y")) {
            (Some(r), Some(g), Some(b), _) => {
                let (r, g, b) = (values(r), values(g), values(b));
                (0..w * h).map(|i| [r[i], g[i], b[i]]).collect()
            }
            (_, _, _, Some(y)) => values(y).into_iter().map(|v| [v; 3]).collect(),
            _ => {
                return Err(ExrReadError::Decode(format!(
                    "no R, G, B or Y channels (found: {})",
                    layer
                        .channel_data
                        .list
                        .iter()
                        .map(|c| c.name.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
        };
        if pixels.len() != w * h {
            return Err(ExrReadError::Decode(
                "channel sizes do not match the image size".into(),
            ));
        }
        Ok((w as u32, h as u32, pixels))
    }
    #[cfg(not(feature = "exr"))]
    {
        let _ = path;
        Err(ExrReadError::Decode(
            "EXR support needs the `exr` feature of het-bssrdf-tracer".into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_and_known_values() {
        // IEC 61966-2-1: 0.5 linear encodes to 0.7354; 0.0031308 is the knee.
        assert!((srgb_encode(0.5) - 0.735_356_983_052_449).abs() < 1e-9);
        assert!((srgb_encode(0.003_130_8) - 0.040_449_936).abs() < 1e-8);
        for i in 0..=100 {
            let x = i as f64 / 100.0;
            assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-12);
        }
        assert_eq!(preview_byte(1.0, 0.0), 255);
        assert_eq!(preview_byte(0.25, 1.0), preview_byte(0.5, 0.0));
        assert_eq!(preview_byte(f64::NAN, 0.0), 0);
    }
}
