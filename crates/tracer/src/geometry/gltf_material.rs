//! The glTF material parameters that describe a translucent volume (feature `gltf`).
//!
//! glTF 2.0 has no ratified subsurface-scattering extension. What a file can say about a
//! translucent volume is spread over several extensions; this module reads them as written,
//! without interpreting them. The mapping to the project's artist parameters
//! (`subsurface_color`, `subsurface_radius`, `anisotropy`, η) is
//! [`GltfMaterial::interpret`]; it is documented in `docs/gltf.md`.
//!
//! Read:
//! * `pbrMetallicRoughness.baseColorFactor` and `baseColorTexture` (texture coordinate set 0);
//! * `KHR_materials_volume`: `thicknessFactor`, `attenuationDistance`, `attenuationColor`;
//! * `KHR_materials_diffuse_transmission`: `diffuseTransmissionFactor`,
//!   `diffuseTransmissionColorFactor`;
//! * `KHR_materials_ior`: `ior`;
//! * `KHR_materials_transmission`: `transmissionFactor` (specular transmission through the
//!   surface: with a volume, the volume's boundary is a clear dielectric);
//! * the two Khronos drafts for scattering volumes: `KHR_materials_volume_scatter`
//!   (`multiscatterColor`, `scatterAnisotropy`) and its successor `KHR_materials_scatter`
//!   (`multiscatterColorFactor`, `scatterStrengthFactor`, `scatterAnisotropy`).
//!
//! Everything else a material holds (metallic-roughness, normal, occlusion and emissive
//! textures, textures inside the extensions, other extensions) is listed in
//! [`GltfMaterial::ignored`], so that the scene loader can warn about it.

use gltf::json::Value;

use crate::field::Wrap;

/// A reference to an image through a glTF texture.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfTextureRef {
    /// Index of the glTF image.
    pub image: usize,
    /// How lookups outside `[0, 1]²` behave (from the texture's sampler; glTF's default is
    /// repeat, and mirrored repeat is read as repeat).
    pub wrap: Wrap,
}

/// `KHR_materials_volume`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeExt {
    /// `thicknessFactor` (0, the default, means thin-walled: no volume).
    pub thickness: f64,
    /// `attenuationDistance` in scene units (default +∞: no attenuation).
    pub attenuation_distance: f64,
    /// `attenuationColor` (default white).
    pub attenuation_color: [f64; 3],
}

/// `KHR_materials_diffuse_transmission`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffuseTransmissionExt {
    /// `diffuseTransmissionFactor` (default 0).
    pub factor: f64,
    /// `diffuseTransmissionColorFactor` (default white).
    pub color: [f64; 3],
}

/// `KHR_materials_volume_scatter` or `KHR_materials_scatter` (Khronos drafts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeScatterExt {
    /// `multiscatterColor` (or `multiscatterColorFactor`) times `scatterStrengthFactor`: the
    /// multiple-scattering albedo of the volume (default 0 in the older draft, 1 in the newer).
    pub multiscatter_color: [f64; 3],
    /// `scatterAnisotropy`: the Henyey–Greenstein g (default 0).
    pub anisotropy: f64,
}

/// What a glTF material says about a translucent volume, as written in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfMaterial {
    /// Index of the material in the file (`None`: glTF's default material, for primitives
    /// without one).
    pub index: Option<usize>,
    /// The material's name, or `material[i]`.
    pub name: String,
    /// `baseColorFactor` (RGB; alpha is ignored).
    pub base_color: [f64; 3],
    /// `baseColorTexture`, multiplied by `base_color`.
    pub base_color_texture: Option<GltfTextureRef>,
    /// `KHR_materials_ior.ior` (glTF's default is 1.5).
    pub ior: f64,
    /// `KHR_materials_volume`, if present.
    pub volume: Option<VolumeExt>,
    /// `KHR_materials_diffuse_transmission`, if present.
    pub diffuse_transmission: Option<DiffuseTransmissionExt>,
    /// `KHR_materials_volume_scatter` or `KHR_materials_scatter`, if present.
    pub volume_scatter: Option<VolumeScatterExt>,
    /// `KHR_materials_transmission.transmissionFactor`, if the extension is present (default
    /// 0 inside it).
    pub transmission: Option<f64>,
    /// What the material holds that is not read (`"normalTexture"`,
    /// `"KHR_materials_clearcoat"`, …).
    pub ignored: Vec<String>,
}

/// An invalid value in a material; `field` is the JSON path inside the material.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialFieldError {
    /// `extensions.KHR_materials_volume.attenuationDistance`, for example.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

/// glTF's default refractive index.
pub const GLTF_DEFAULT_IOR: f64 = 1.5;

impl GltfMaterial {
    /// glTF's default material (white, no extensions), used by primitives without a
    /// material.
    pub fn default_material() -> GltfMaterial {
        GltfMaterial {
            index: None,
            name: "default material".to_string(),
            base_color: [1.0; 3],
            base_color_texture: None,
            ior: GLTF_DEFAULT_IOR,
            volume: None,
            diffuse_transmission: None,
            volume_scatter: None,
            transmission: None,
            ignored: Vec::new(),
        }
    }

    /// Reads `m`. Values outside the ranges the extensions allow (negative factors, colours
    /// outside [0, 1], a non-positive attenuation distance, an index of refraction below 1)
    /// are errors naming the field.
    pub fn read(m: &gltf::Material<'_>) -> Result<GltfMaterial, MaterialFieldError> {
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let base_color = check_colour(
            "pbrMetallicRoughness.baseColorFactor",
            [r, g, b].map(f64::from),
        )?;
        let base_color_texture = pbr
            .base_color_texture()
            .map(|info| texture_ref(&info.texture()));
        let mut out = GltfMaterial {
            index: m.index(),
            name: m
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("material[{}]", m.index().unwrap_or(0))),
            base_color,
            base_color_texture,
            ior: GLTF_DEFAULT_IOR,
            volume: None,
            diffuse_transmission: None,
            volume_scatter: None,
            transmission: None,
            ignored: ignored_core_fields(m),
        };
        let Some(ext) = m.extensions() else {
            return Ok(out);
        };
        for (name, v) in ext {
            out.read_extension(name, v)?;
        }
        Ok(out)
    }

    /// Reads the material extension `name` (its object `v`) into `self`; an unknown extension
    /// is noted as ignored.
    fn read_extension(&mut self, name: &str, v: &Value) -> Result<(), MaterialFieldError> {
        let path = |k: &str| format!("extensions.{name}.{k}");
        match name {
            "KHR_materials_volume" => {
                let thickness = number(v, "thicknessFactor", 0.0, &path)?;
                if thickness < 0.0 {
                    return Err(bad(path("thicknessFactor"), "must be ≥ 0"));
                }
                let attenuation_distance = number(v, "attenuationDistance", f64::INFINITY, &path)?;
                if attenuation_distance <= 0.0 {
                    return Err(bad(path("attenuationDistance"), "must be > 0"));
                }
                let attenuation_color = colour(v, "attenuationColor", &path)?;
                ignore_textures(v, &["thicknessTexture"], name, &mut self.ignored);
                self.volume = Some(VolumeExt {
                    thickness,
                    attenuation_distance,
                    attenuation_color,
                });
            }
            "KHR_materials_diffuse_transmission" => {
                let factor = number(v, "diffuseTransmissionFactor", 0.0, &path)?;
                if !(0.0..=1.0).contains(&factor) {
                    return Err(bad(path("diffuseTransmissionFactor"), "must be in [0, 1]"));
                }
                let color = colour(v, "diffuseTransmissionColorFactor", &path)?;
                ignore_textures(
                    v,
                    &[
                        "diffuseTransmissionTexture",
                        "diffuseTransmissionColorTexture",
                    ],
                    name,
                    &mut self.ignored,
                );
                self.diffuse_transmission = Some(DiffuseTransmissionExt { factor, color });
            }
            "KHR_materials_transmission" => {
                let factor = number(v, "transmissionFactor", 0.0, &path)?;
                if !(0.0..=1.0).contains(&factor) {
                    return Err(bad(path("transmissionFactor"), "must be in [0, 1]"));
                }
                ignore_textures(v, &["transmissionTexture"], name, &mut self.ignored);
                self.transmission = Some(factor);
            }
            "KHR_materials_ior" => {
                let ior = number(v, "ior", GLTF_DEFAULT_IOR, &path)?;
                // glTF allows ior = 0 (a special value for an infinite index); the
                // project accepts η in [1, 3] and the loader checks that range.
                if ior < 1.0 {
                    return Err(bad(path("ior"), "must be ≥ 1 (η < 1 is not supported)"));
                }
                self.ior = ior;
            }
            "KHR_materials_volume_scatter" | "KHR_materials_scatter" => {
                self.volume_scatter = Some(read_volume_scatter(name, v, &mut self.ignored)?);
            }
            other => self.ignored.push(other.to_string()),
        }
        Ok(())
    }
}

/// Reads the scattering draft `name` (`KHR_materials_volume_scatter`, or the newer
/// `KHR_materials_scatter` with its other key and default for the multi-scatter colour):
/// the colour scaled by the scatter strength, and the anisotropy.
fn read_volume_scatter(
    name: &str,
    v: &Value,
    ignored: &mut Vec<String>,
) -> Result<VolumeScatterExt, MaterialFieldError> {
    let path = |k: &str| format!("extensions.{name}.{k}");
    let newer = name == "KHR_materials_scatter";
    let (key, default) = if newer {
        ("multiscatterColorFactor", [1.0; 3])
    } else {
        ("multiscatterColor", [0.0; 3])
    };
    let mut multiscatter_color = match v.get(key) {
        None => default,
        Some(_) => colour(v, key, &path)?,
    };
    let strength = number(v, "scatterStrengthFactor", 1.0, &path)?;
    if !(0.0..=1.0).contains(&strength) {
        return Err(bad(path("scatterStrengthFactor"), "must be in [0, 1]"));
    }
    multiscatter_color = multiscatter_color.map(|c| c * strength);
    let anisotropy = number(v, "scatterAnisotropy", 0.0, &path)?;
    if anisotropy.abs() >= 1.0 {
        return Err(bad(path("scatterAnisotropy"), "must be in (−1, 1)"));
    }
    ignore_textures(
        v,
        &["multiscatterColorTexture", "scatterStrengthTexture"],
        name,
        ignored,
    );
    Ok(VolumeScatterExt {
        multiscatter_color,
        anisotropy,
    })
}

/// What the core material of `m` sets that the project does not read: a base colour texture
/// on another texture coordinate set, metallic-roughness, normal and occlusion textures,
/// emission.
fn ignored_core_fields(m: &gltf::Material<'_>) -> Vec<String> {
    let pbr = m.pbr_metallic_roughness();
    let mut ignored = Vec::new();
    if let Some(t) = pbr.base_color_texture()
        && t.tex_coord() != 0
    {
        ignored.push(format!(
            "baseColorTexture.texCoord {} (texture coordinate set 0 is used)",
            t.tex_coord()
        ));
    }
    if pbr.metallic_roughness_texture().is_some() {
        ignored.push("metallicRoughnessTexture".to_string());
    }
    if pbr.metallic_factor() != 0.0 {
        ignored.push(format!("metallicFactor {}", pbr.metallic_factor()));
    }
    if m.normal_texture().is_some() {
        ignored.push("normalTexture".to_string());
    }
    if m.occlusion_texture().is_some() {
        ignored.push("occlusionTexture".to_string());
    }
    if m.emissive_texture().is_some() || m.emissive_factor() != [0.0; 3] {
        ignored.push("emissive".to_string());
    }
    ignored
}

fn bad(field: String, message: &str) -> MaterialFieldError {
    MaterialFieldError {
        field,
        message: message.to_string(),
    }
}

fn texture_ref(t: &gltf::Texture<'_>) -> GltfTextureRef {
    use gltf::texture::WrappingMode;
    let s = t.sampler();
    let wrap = if matches!(s.wrap_s(), WrappingMode::ClampToEdge)
        && matches!(s.wrap_t(), WrappingMode::ClampToEdge)
    {
        Wrap::Clamp
    } else {
        Wrap::Repeat
    };
    GltfTextureRef {
        image: t.source().index(),
        wrap,
    }
}

/// A finite number at `key` of the extension object `v` (or `default` when absent).
fn number(
    v: &Value,
    key: &str,
    default: f64,
    path: &dyn Fn(&str) -> String,
) -> Result<f64, MaterialFieldError> {
    match v.get(key) {
        None => Ok(default),
        Some(x) => x
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| bad(path(key), &format!("must be a finite number, not {x}"))),
    }
}

/// An RGB colour in [0, 1]³ at `key` (white when absent).
fn colour(
    v: &Value,
    key: &str,
    path: &dyn Fn(&str) -> String,
) -> Result<[f64; 3], MaterialFieldError> {
    let Some(x) = v.get(key) else {
        return Ok([1.0; 3]);
    };
    let arr = x.as_array().filter(|a| a.len() == 3).ok_or_else(|| {
        bad(
            path(key),
            &format!("must be an array of 3 numbers, not {x}"),
        )
    })?;
    let mut c = [0.0; 3];
    for (k, e) in arr.iter().enumerate() {
        c[k] = e
            .as_f64()
            .ok_or_else(|| bad(path(key), &format!("element {k} is not a number: {e}")))?;
    }
    check_colour(&path(key), c)
}

fn check_colour(field: &str, c: [f64; 3]) -> Result<[f64; 3], MaterialFieldError> {
    if c.iter().all(|x| (0.0..=1.0).contains(x)) {
        Ok(c)
    } else {
        Err(bad(
            field.to_string(),
            &format!("must be a colour in [0, 1], not {c:?}"),
        ))
    }
}

fn ignore_textures(v: &Value, keys: &[&str], ext: &str, ignored: &mut Vec<String>) {
    for k in keys {
        if v.get(*k).is_some() {
            ignored.push(format!("{ext}.{k}"));
        }
    }
}

/// Where a translucent glTF material's colour comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum GltfColour {
    /// A constant linear RGB colour.
    Constant([f64; 3]),
    /// `factor` times the image of `texture`, read through texture coordinate set 0.
    Texture {
        /// The base colour factor.
        factor: [f64; 3],
        /// The base colour texture.
        texture: GltfTextureRef,
    },
}

/// What the project renders for a glTF material ([`GltfMaterial::interpret`]).
#[derive(Debug, Clone, PartialEq)]
pub enum GltfInterpretation {
    /// A translucent volume in artist parameters: `colour` is the multiple-scattering
    /// albedo (`subsurface_color`), `mean_free_path` the per-channel 1/σt in file units
    /// (`subsurface_radius`), `anisotropy` the HG g, `eta` the relative index.
    Translucent {
        /// `subsurface_color`.
        colour: GltfColour,
        /// `subsurface_radius` (file units).
        mean_free_path: [f64; 3],
        /// HG g.
        anisotropy: f64,
        /// Relative index of refraction.
        eta: f64,
    },
    /// A clear absorbing volume (no scattering): σa per file unit, index `eta`.
    Absorbing {
        /// σa (1/file unit).
        sigma_a: [f64; 3],
        /// Relative index of refraction.
        eta: f64,
    },
    /// An opaque diffuse surface of this albedo.
    Diffuse {
        /// Lambertian albedo.
        albedo: [f64; 3],
    },
}

/// The longest mean free path a channel gets, in attenuation distances, when its
/// attenuation colour is white (σt = 0 would make the channel transparent, which an artist
/// medium cannot express).
pub const MAX_MEAN_FREE_PATH_IN_DISTANCES: f64 = 1e6;

impl GltfMaterial {
    /// How the project reads this material, and notes on what it does not use (for the
    /// loader's warnings). The rules (`docs/gltf.md`):
    ///
    /// * A volume (`KHR_materials_volume` with `thicknessFactor` > 0 and a finite
    ///   `attenuationDistance` d) is translucent when it also scatters: with a scattering
    ///   draft its colour is the draft's multi-scatter colour, with
    ///   `KHR_materials_diffuse_transmission` it is the base colour (factor × texture). Its
    ///   extinction follows the scattering drafts: σt = −ln(attenuationColor)/d per channel,
    ///   so the mean free path is d / −ln(attenuationColor).
    /// * A volume without either is a clear absorbing dielectric: σa = −ln(attenuationColor)/d,
    ///   σs = 0. Every method path-traces it (a BSSRDF sees no subsurface light in it:
    ///   [`crate::integrator::plan::is_clear`]). With `KHR_materials_transmission` and no
    ///   finite `attenuationDistance` it is clear glass, σa = 0.
    /// * Anything else, thin-walled volumes included, is an opaque diffuse surface of the base
    ///   colour factor.
    pub fn interpret(&self) -> (GltfInterpretation, Vec<String>) {
        let mut notes: Vec<String> = self
            .ignored
            .iter()
            .map(|s| format!("`{s}` is not read"))
            .collect();
        let transmits = self.transmission.is_some_and(|t| t > 0.0);
        let scatters = self.volume_scatter.is_some()
            || self.diffuse_transmission.is_some_and(|t| t.factor > 0.0);
        if let (Some(v), true, false) = (self.volume, transmits, scatters)
            && v.thickness > 0.0
            && !v.attenuation_distance.is_finite()
        {
            // Clear glass: KHR_materials_volume's default attenuation is none.
            return (
                GltfInterpretation::Absorbing {
                    sigma_a: [0.0; 3],
                    eta: self.ior,
                },
                notes,
            );
        }
        if transmits && self.volume.is_none_or(|v| v.thickness <= 0.0) {
            notes.push(
                "KHR_materials_transmission without a volume (thin-walled transmission) is not \
                 rendered: an opaque diffuse surface of the base colour; give it \
                 KHR_materials_volume with thicknessFactor > 0 to render it as a clear \
                 dielectric"
                    .to_string(),
            );
        }
        let volume = self
            .volume
            .filter(|v| v.thickness > 0.0 && v.attenuation_distance.is_finite());
        let Some(v) = volume else {
            if let Some(v) = self.volume {
                notes.push(if v.thickness <= 0.0 {
                    "KHR_materials_volume with thicknessFactor 0 is thin-walled: rendered as \
                     an opaque diffuse surface"
                        .to_string()
                } else {
                    "KHR_materials_volume without a finite attenuationDistance gives no \
                     scattering scale: rendered as an opaque diffuse surface"
                        .to_string()
                });
            }
            if self.diffuse_transmission.is_some() || self.volume_scatter.is_some() {
                notes.push(
                    "diffuse transmission and scattering need a volume (KHR_materials_volume \
                     with thicknessFactor > 0 and a finite attenuationDistance): not rendered"
                        .to_string(),
                );
            }
            return (self.diffuse(&mut notes), notes);
        };
        let interpretation = self.volume_interpretation(v, &mut notes);
        (interpretation, notes)
    }

    /// The base colour: its factor, times its texture if it has one.
    fn base_colour(&self) -> GltfColour {
        match &self.base_color_texture {
            Some(t) => GltfColour::Texture {
                factor: self.base_color,
                texture: t.clone(),
            },
            None => GltfColour::Constant(self.base_color),
        }
    }

    /// An opaque diffuse surface of the base colour factor (noting an unread texture).
    fn diffuse(&self, notes: &mut Vec<String>) -> GltfInterpretation {
        if self.base_color_texture.is_some() {
            notes.push(
                "baseColorTexture is not read on an opaque surface (diffuse surfaces take \
                 a constant albedo; the base colour factor is used)"
                    .to_string(),
            );
        }
        GltfInterpretation::Diffuse {
            albedo: self.base_color,
        }
    }

    /// A volume `v` (thickness > 0, finite attenuation distance): translucent with a
    /// scattering draft or diffuse transmission, else clear and absorbing.
    fn volume_interpretation(&self, v: VolumeExt, notes: &mut Vec<String>) -> GltfInterpretation {
        let eta = self.ior;
        let d = v.attenuation_distance;
        // −ln(c) per channel, with white channels capped (see MAX_MEAN_FREE_PATH_IN_DISTANCES)
        // and black ones floored at the smallest positive colour.
        let optical = v
            .attenuation_color
            .map(|c| (-(c.max(f64::MIN_POSITIVE)).ln()).max(1.0 / MAX_MEAN_FREE_PATH_IN_DISTANCES));
        if v.attenuation_color.contains(&1.0) {
            notes.push(format!(
                "attenuationColor is white in some channel: that channel's mean free path is \
                 capped at {MAX_MEAN_FREE_PATH_IN_DISTANCES:e} attenuation distances"
            ));
        }
        let mean_free_path = optical.map(|o| d / o);
        if let Some(s) = self.volume_scatter {
            if self.base_color_texture.is_some() {
                notes.push(
                    "baseColorTexture is not read: with a scattering extension the volume's \
                     colour is its multi-scatter colour"
                        .to_string(),
                );
            }
            GltfInterpretation::Translucent {
                colour: GltfColour::Constant(s.multiscatter_color),
                mean_free_path,
                anisotropy: s.anisotropy,
                eta,
            }
        } else if let Some(t) = self.diffuse_transmission.filter(|t| t.factor > 0.0) {
            if t.factor < 1.0 || t.color != [1.0; 3] {
                notes.push(format!(
                    "diffuseTransmissionFactor {} and diffuseTransmissionColorFactor {:?} are \
                     not read: the whole surface is the boundary of the scattering volume",
                    t.factor, t.color
                ));
            }
            GltfInterpretation::Translucent {
                colour: self.base_colour(),
                mean_free_path,
                anisotropy: 0.0,
                eta,
            }
        } else {
            GltfInterpretation::Absorbing {
                sigma_a: v
                    .attenuation_color
                    .map(|c| (-(c.max(f64::MIN_POSITIVE)).ln()).max(0.0) / d),
                eta,
            }
        }
    }
}
