//! Image textures: decoding (PNG through `image`, EXR through `exr`), validation and filtered
//! lookup.
//!
//! Texel values are linear RGB `f32`. 8- and 16-bit images are decoded from sRGB
//! (IEC 61966-2-1) unless the texture is declared `linear` (it holds data, not colour); EXR
//! files are always linear. Alpha is ignored; grey images give equal channels.
//!
//! Image space: texel `(i, j)` (column `i` from the left, row `j` from the top) covers
//! `[i, i+1) × [j, j+1)` in continuous texel coordinates; normalised coordinates `(u, v_down)`
//! are those divided by the image size (`v_down` grows downward).

use std::path::Path;
use std::sync::OnceLock;

use super::area_table::AreaTable;
pub use super::texture_mapping::Wrap;

use crate::error::TextureError;

/// Reconstruction filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Filter {
    /// The texel containing the point.
    Nearest,
    /// Bilinear interpolation between the four nearest texel centres.
    #[default]
    Bilinear,
}

/// A decoded image: linear RGB texels, row-major, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    /// The file it came from (for messages).
    pub file: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    texels: Vec<[f32; 3]>,
    min: [f32; 3],
    max: [f32; 3],
    grey: bool,
    area: LazyAreaTable,
}

/// The summed-area table, built on first use (see [`Texture::area_table`]). Equal and
/// printed regardless of whether it was built: it is a cache of the texels.
#[derive(Clone, Default)]
struct LazyAreaTable(OnceLock<AreaTable>);

impl PartialEq for LazyAreaTable {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for LazyAreaTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.get().is_some() {
            "built"
        } else {
            "not built"
        })
    }
}

impl Texture {
    /// A texture from linear texels (row-major, row 0 at the top). Every value must be finite
    /// and non-negative; the error names `file` and the texel.
    pub fn from_texels(
        file: &str,
        width: u32,
        height: u32,
        texels: Vec<[f32; 3]>,
    ) -> Result<Texture, TextureError> {
        if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
            return Err(TextureError::Empty {
                file: file.to_string(),
                width,
                height,
            });
        }
        let mut min = [f32::INFINITY; 3];
        let mut max = [0.0f32; 3];
        let mut grey = true;
        for (k, t) in texels.iter().enumerate() {
            for c in 0..3 {
                let v = t[c];
                if !(v.is_finite() && v >= 0.0) {
                    return Err(TextureError::BadTexel {
                        file: file.to_string(),
                        x: (k % width as usize) as u32,
                        y: (k / width as usize) as u32,
                        channel: c,
                        value: v,
                    });
                }
                min[c] = min[c].min(v);
                max[c] = max[c].max(v);
            }
            grey &= t[0] == t[1] && t[1] == t[2];
        }
        Ok(Texture {
            file: file.to_string(),
            width,
            height,
            texels,
            min,
            max,
            grey,
            area: LazyAreaTable::default(),
        })
    }

    /// Decodes an image file: `.exr` (linear) through `exr`, anything else through `image`
    /// (PNG; 8/16-bit decoded from sRGB unless `linear`, float images such as Radiance `.hdr`
    /// linear). The decoded size is checked before any pixel is decoded
    /// ([`check_decoded_size`]).
    pub fn load(path: &Path, linear: bool) -> Result<Texture, TextureError> {
        let file = path.display().to_string();
        #[cfg(not(feature = "hdr"))]
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("hdr"))
        {
            return Err(TextureError::Unsupported {
                file,
                message: "Radiance HDR images need the `hdr` feature of het-bssrdf-tracer".into(),
            });
        }
        let is_exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let read_error = |e| match e {
            crate::output::ExrReadError::Io(source) => TextureError::Io {
                file: file.clone(),
                source,
            },
            crate::output::ExrReadError::Decode(message) => TextureError::Decode {
                file: file.clone(),
                message,
            },
        };
        if is_exr {
            let (w, h, channels) = crate::output::exr_size(path).map_err(read_error)?;
            // The decoder's channels (as f32), the R, G, B copies and the pixels.
            check_decoded_size(
                &file,
                w,
                h,
                f64::from(w) * f64::from(h) * (4.0 * channels as f64 + 24.0),
            )?;
            let (w, h, px) = crate::output::decode_exr_rgb(path).map_err(read_error)?;
            return Texture::from_texels(&file, w, h, px);
        }
        let bytes = std::fs::read(path).map_err(|source| TextureError::Io {
            file: file.clone(),
            source,
        })?;
        Self::from_encoded(&file, &bytes, linear)
    }

    /// Decodes an encoded image held in memory (PNG, and the other formats the `image` crate
    /// was built with, such as the JPEG of glTF files): 8- and 16-bit images from sRGB unless
    /// `linear`, float images linear; grey images give equal channels, alpha is dropped. The
    /// image's size is read from its header and checked ([`check_decoded_size`]) before any
    /// pixel is decoded. `file` names the texture in errors.
    #[cfg(any(feature = "png", feature = "hdr"))]
    pub fn from_encoded(file: &str, bytes: &[u8], linear: bool) -> Result<Texture, TextureError> {
        use image::{DynamicImage, ImageDecoder};
        let decode_error = |message: String| TextureError::Decode {
            file: file.to_string(),
            message,
        };
        let limit_mb = decoder_limit_mb();
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| decode_error(e.to_string()))?;
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(limit_mb.saturating_mul(1 << 20));
        reader.limits(limits);
        let limit_error = |e: image::ImageError| {
            decode_error(match e {
                image::ImageError::Limits(l) => format!(
                    "{l}: the image needs more than the decoder's memory limit of {limit_mb} MiB; \
                     set {TEXTURE_LIMIT_VAR}=<MiB> to raise it"
                ),
                e => e.to_string(),
            })
        };
        let decoder = reader.into_decoder().map_err(limit_error)?;
        let (w, h) = decoder.dimensions();
        check_decoded_size(file, w, h, decoder.total_bytes() as f64)?;
        let img = DynamicImage::from_decoder(decoder).map_err(limit_error)?;
        let lut: Vec<f32> = (0..256)
            .map(|i| {
                let x = i as f64 / 255.0;
                (if linear {
                    x
                } else {
                    crate::output::srgb_decode(x)
                }) as f32
            })
            .collect();
        let wide = |s: u16| {
            let x = s as f64 / 65535.0;
            (if linear {
                x
            } else {
                crate::output::srgb_decode(x)
            }) as f32
        };
        let narrow = |b: u8| lut[b as usize];
        let float = |x: f32| x;
        let texels = match &img {
            DynamicImage::ImageLuma8(b) => spread(b.as_raw(), 1, narrow),
            DynamicImage::ImageLumaA8(b) => spread(b.as_raw(), 2, narrow),
            DynamicImage::ImageRgb8(b) => spread(b.as_raw(), 3, narrow),
            DynamicImage::ImageRgba8(b) => spread(b.as_raw(), 4, narrow),
            DynamicImage::ImageLuma16(b) => spread(b.as_raw(), 1, wide),
            DynamicImage::ImageLumaA16(b) => spread(b.as_raw(), 2, wide),
            DynamicImage::ImageRgb16(b) => spread(b.as_raw(), 3, wide),
            DynamicImage::ImageRgba16(b) => spread(b.as_raw(), 4, wide),
            DynamicImage::ImageRgb32F(b) => spread(b.as_raw(), 3, float),
            DynamicImage::ImageRgba32F(b) => spread(b.as_raw(), 4, float),
            other => spread(other.to_rgb16().as_raw(), 3, wide),
        };
        drop(img);
        Texture::from_texels(file, w, h, texels)
    }

    /// Without the `png` and `hdr` features no encoded image can be decoded.
    #[cfg(not(any(feature = "png", feature = "hdr")))]
    pub fn from_encoded(file: &str, _bytes: &[u8], _linear: bool) -> Result<Texture, TextureError> {
        Err(TextureError::Unsupported {
            file: file.to_string(),
            message: "PNG textures need the `png` feature of het-bssrdf-tracer".into(),
        })
    }

    /// Texel `(i, j)` (column, row from the top).
    #[inline]
    pub fn texel(&self, i: u32, j: u32) -> [f32; 3] {
        self.texels[j as usize * self.width as usize + i as usize]
    }

    /// Smallest value of each channel.
    pub fn min(&self) -> [f32; 3] {
        self.min
    }
    /// Largest value of each channel.
    pub fn max(&self) -> [f32; 3] {
        self.max
    }
    /// True when every texel has equal channels.
    pub fn is_grey(&self) -> bool {
        self.grey
    }

    /// The texture's summed-area table ([`super::area_table`]), built on the first call (once,
    /// thread-safe; later calls wait for or share it). Only prefiltered averaging calls this,
    /// so textures read by other methods never pay for a table.
    pub fn area_table(&self) -> &AreaTable {
        self.area
            .0
            .get_or_init(|| AreaTable::build(self.width, self.height, &self.texels))
    }

    /// True once [`Texture::area_table`] has built the table (observability for tests and
    /// tools: a texture no prefiltered average read has none).
    pub fn has_area_table(&self) -> bool {
        self.area.0.get().is_some()
    }

    /// The filtered value at normalised image coordinates `(u, v_down)` (see the module docs).
    #[inline]
    pub fn lookup(&self, u: f64, v_down: f64, wrap: Wrap, filter: Filter) -> [f64; 3] {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = u * w as f64;
        let y = v_down * h as f64;
        let fetch = |i: i64, j: i64| -> [f64; 3] {
            let (i, j) = match wrap {
                Wrap::Repeat => (i.rem_euclid(w), j.rem_euclid(h)),
                Wrap::Clamp => (i.clamp(0, w - 1), j.clamp(0, h - 1)),
            };
            self.texels[(j * w + i) as usize].map(|c| c as f64)
        };
        // Guard against NaN/inf coordinates (never from finite points): clamp into a sane
        // integer range before converting.
        let to_i = |f: f64| f.clamp(-1e15, 1e15) as i64;
        match filter {
            Filter::Nearest => fetch(to_i(x.floor()), to_i(y.floor())),
            Filter::Bilinear => {
                let (xc, yc) = (x - 0.5, y - 0.5);
                let (x0, y0) = (xc.floor(), yc.floor());
                let (fx, fy) = (xc - x0, yc - y0);
                let (i0, j0) = (to_i(x0), to_i(y0));
                let a = fetch(i0, j0);
                let b = fetch(i0 + 1, j0);
                let c = fetch(i0, j0 + 1);
                let d = fetch(i0 + 1, j0 + 1);
                let mut out = [0.0; 3];
                for k in 0..3 {
                    let top = a[k] + fx * (b[k] - a[k]);
                    let bottom = c[k] + fx * (d[k] - c[k]);
                    out[k] = top + fy * (bottom - top);
                }
                out
            }
        }
    }
}

/// Linear RGB texels from interleaved samples with `channels` per pixel (1 or 2: grey, read
/// from the first; 3 or 4: RGB, alpha dropped), each converted by `f`.
#[cfg_attr(not(any(feature = "png", feature = "hdr")), allow(dead_code))]
fn spread<S: Copy>(raw: &[S], channels: usize, f: impl Fn(S) -> f32) -> Vec<[f32; 3]> {
    raw.chunks_exact(channels)
        .map(|px| {
            if channels < 3 {
                [f(px[0]); 3]
            } else {
                [f(px[0]), f(px[1]), f(px[2])]
            }
        })
        .collect()
}

/// Refuses, before any pixel is decoded, a `w × h` texture whose decoding would need more
/// than the decoder's memory limit ([`decoder_limit_mb`]) or than the memory this process may
/// still allocate ([`crate::memory::check`]): `decoded` bytes of the decoder's own image plus
/// the texture's `f32` texels, both held while one is converted to the other. (A 20000²
/// greyscale PNG is 400 MB decoded, but 4.8 GB of texels.)
pub fn check_decoded_size(file: &str, w: u32, h: u32, decoded: f64) -> Result<(), TextureError> {
    let texels = f64::from(w) * f64::from(h) * crate::memory::TEXTURE_BYTES_PER_TEXEL;
    let total = decoded + texels;
    let limit_mb = decoder_limit_mb();
    let error = |message: String| TextureError::Decode {
        file: file.to_string(),
        message,
    };
    if total > limit_mb as f64 * (1u64 << 20) as f64 {
        return Err(error(format!(
            "the {w}x{h} image needs about {} decoded ({} for the decoder's image, {} for its \
             f32 texels), more than the decoder's memory limit of {limit_mb} MiB; set \
             {TEXTURE_LIMIT_VAR}=<MiB> to raise it",
            crate::error::human_bytes(total),
            crate::error::human_bytes(decoded),
            crate::error::human_bytes(texels),
        )));
    }
    crate::memory::check(|| format!("decoding the {w}x{h} image"), total)
        .map_err(|e| error(e.to_string()))
}

/// The environment variable that overrides the image decoder's memory limit (MiB).
pub const TEXTURE_LIMIT_VAR: &str = "HET_BSSRDF_TEXTURE_LIMIT_MB";

/// The image decoder's memory limit in MiB: [`TEXTURE_LIMIT_VAR`] when set to a positive whole
/// number, else 512 (the `image` crate's default). It bounds the decoder's allocations and the
/// decoded texture as a whole ([`check_decoded_size`]), which refuses decompression bombs (a
/// 20000² PNG of 389 kB) before they are allocated.
pub fn decoder_limit_mb() -> u64 {
    std::env::var(TEXTURE_LIMIT_VAR)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .filter(|&v| v > 0)
        .unwrap_or(512)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex() -> Texture {
        // 2x2: (0,0)=0, (1,0)=1, (0,1)=2, (1,1)=3 in every channel.
        Texture::from_texels("t.png", 2, 2, vec![[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]]).unwrap()
    }

    #[test]
    fn nearest_and_wrap() {
        let t = tex();
        assert_eq!(t.lookup(0.25, 0.25, Wrap::Repeat, Filter::Nearest)[0], 0.0);
        assert_eq!(t.lookup(0.75, 0.25, Wrap::Repeat, Filter::Nearest)[0], 1.0);
        assert_eq!(t.lookup(0.25, 0.75, Wrap::Repeat, Filter::Nearest)[0], 2.0);
        assert_eq!(t.lookup(1.25, -0.25, Wrap::Repeat, Filter::Nearest)[0], 2.0);
        assert_eq!(t.lookup(1.25, -0.25, Wrap::Clamp, Filter::Nearest)[0], 1.0);
    }

    #[test]
    fn bilinear_interpolates_between_texel_centres() {
        let t = tex();
        // Texel centres at 0.25 and 0.75: halfway is the mean of the four.
        let v = t.lookup(0.5, 0.5, Wrap::Clamp, Filter::Bilinear)[0];
        assert!((v - 1.5).abs() < 1e-12);
        // At a texel centre the value is exact.
        assert!((t.lookup(0.75, 0.25, Wrap::Clamp, Filter::Bilinear)[0] - 1.0).abs() < 1e-12);
        // A quarter of the way from centre (0,0) to (1,0) along x: 0.25.
        let v = t.lookup(0.375, 0.25, Wrap::Clamp, Filter::Bilinear)[0];
        assert!((v - 0.25).abs() < 1e-12);
        // Independent check: bilinear weights at an arbitrary point.
        let (u, w) = (0.6, 0.4);
        let (fx, fy) = (u * 2.0 - 0.5, w * 2.0 - 0.5);
        let expect = (1.0 - fx) * (1.0 - fy) * 0.0
            + fx * (1.0 - fy) * 1.0
            + (1.0 - fx) * fy * 2.0
            + fx * fy * 3.0;
        assert!((t.lookup(u, w, Wrap::Clamp, Filter::Bilinear)[0] - expect).abs() < 1e-12);
        // Repeat wraps across the edge: at u = 0 the value is halfway between columns 1 and 0.
        let v = t.lookup(0.0, 0.25, Wrap::Repeat, Filter::Bilinear)[0];
        assert!((v - 0.5).abs() < 1e-12);
    }

    #[test]
    fn bad_texels_are_named() {
        let e = Texture::from_texels("bad.exr", 2, 1, vec![[0.0; 3], [0.0, f32::NAN, 0.0]])
            .unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("bad.exr") && s.contains("x = 1") && s.contains("y = 0"),
            "{s}"
        );
        assert!(Texture::from_texels("neg.exr", 1, 1, vec![[-1.0, 0.0, 0.0]]).is_err());
    }
}
