//! The raw scene description: what the TOML file says, before validation. Each section or
//! array element with a `type` key is read in two steps (the `type`, then the struct of that
//! type) so that serde's errors keep their position in the file.

use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};

/// A colour or coefficient: a number (grey) or `[r, g, b]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RgbDesc(pub [f64; 3]);

impl<'de> Deserialize<'de> for RgbDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RgbDesc;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number (grey) or an array of three numbers [r, g, b]")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RgbDesc, E> {
                Ok(RgbDesc([v; 3]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RgbDesc, E> {
                Ok(RgbDesc([v as f64; 3]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<RgbDesc, E> {
                Ok(RgbDesc([v as f64; 3]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<RgbDesc, A::Error> {
                rgb_from_seq(seq, &self)
            }
        }
        d.deserialize_any(V)
    }
}

fn rgb_from_seq<'de, A: SeqAccess<'de>>(
    mut seq: A,
    exp: &dyn de::Expected,
) -> Result<RgbDesc, A::Error> {
    let mut v = [0.0; 3];
    for (i, c) in v.iter_mut().enumerate() {
        *c = seq
            .next_element::<f64>()?
            .ok_or_else(|| de::Error::invalid_length(i, exp))?;
    }
    if seq.next_element::<de::IgnoredAny>()?.is_some() {
        return Err(de::Error::invalid_length(4, exp));
    }
    Ok(RgbDesc(v))
}

/// Exactly `N` elements: serde's fixed-size arrays silently ignore extra elements, so that
/// `min = [-2, -2, -2, 5]` would load as `[-2, -2, -2]`.
fn exact<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(
    d: D,
) -> Result<[T; N], D::Error> {
    let v: Vec<T> = Vec::deserialize(d)?;
    let n = v.len();
    v.try_into()
        .map_err(|_| de::Error::invalid_length(n, &format!("an array of {N} elements").as_str()))
}

/// [`exact`] for an optional key.
fn exact_opt<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(
    d: D,
) -> Result<Option<[T; N]>, D::Error> {
    exact(d).map(Some)
}

/// A coefficient field: a number (grey constant), `[r, g, b]` (constant), or a table with a
/// `type` (constant | stripe | check | image).
#[derive(Debug, Clone, PartialEq)]
pub enum FieldDesc {
    /// A constant written as a number or an array.
    Constant(RgbDesc),
    /// A table.
    Table(Box<FieldTable>),
}

impl<'de> Deserialize<'de> for FieldDesc {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = FieldDesc;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "a number (grey), an array [r, g, b], or a table with `type` = \"constant\" | \"stripe\" | \"check\" | \"image\"",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<FieldDesc, E> {
                Ok(FieldDesc::Constant(RgbDesc([v; 3])))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<FieldDesc, E> {
                Ok(FieldDesc::Constant(RgbDesc([v as f64; 3])))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<FieldDesc, E> {
                Ok(FieldDesc::Constant(RgbDesc([v as f64; 3])))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<FieldDesc, A::Error> {
                rgb_from_seq(seq, &self).map(FieldDesc::Constant)
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<FieldDesc, A::Error> {
                FieldTable::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(|t| FieldDesc::Table(Box::new(t)))
            }
        }
        d.deserialize_any(V)
    }
}

/// The kinds of field tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldKind {
    /// `value`.
    Constant,
    /// `width`, `angle` (degrees), `values`, `axis`, `origin`.
    Stripe,
    /// `width`, `values`, `axis`, `origin`.
    Check,
    /// `texture`, `mapping`, `axis`, `origin`, `size`, `wrap`, `filter`, `scale`.
    Image,
}

/// A field table. Which keys apply depends on `type`; the loader rejects the others.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldTable {
    /// The kind.
    #[serde(rename = "type")]
    pub kind: FieldKind,
    /// constant: the value.
    pub value: Option<RgbDesc>,
    /// stripe / check: band width or cell side (scene units; `unit_scale` does not apply to
    /// lengths).
    pub width: Option<f64>,
    /// stripe: angle θ in DEGREES; bands vary along (cos θ, sin θ) in the (s, t) plane.
    pub angle: Option<f64>,
    /// stripe / check: the two values.
    #[serde(default, deserialize_with = "exact_opt")]
    pub values: Option<[RgbDesc; 2]>,
    /// Projection axis `"x" | "y" | "z"` (default z).
    pub axis: Option<AxisDesc>,
    /// Projection origin (default `[0, 0, 0]`).
    #[serde(default, deserialize_with = "exact_opt")]
    pub origin: Option<[f64; 3]>,
    /// image: the `[[texture]]` name.
    pub texture: Option<String>,
    /// image: `"planar"` (default) or `"uv"`.
    pub mapping: Option<MappingDesc>,
    /// image, planar: world size `[W, H]` of the image (scene units).
    #[serde(default, deserialize_with = "exact_opt")]
    pub size: Option<[f64; 2]>,
    /// image: `"repeat"` (default) or `"clamp"`.
    pub wrap: Option<WrapDesc>,
    /// image: `"bilinear"` (default) or `"nearest"`.
    pub filter: Option<FilterDesc>,
    /// image: per-channel multiplier of the texel values (default 1).
    pub scale: Option<RgbDesc>,
}

/// Projection axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AxisDesc {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

/// Image mapping.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MappingDesc {
    /// Planar projection.
    Planar,
    /// Mesh texture coordinates.
    Uv,
}

/// Wrap mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WrapDesc {
    /// Tile.
    Repeat,
    /// Clamp to the edge.
    Clamp,
}

/// Filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FilterDesc {
    /// Nearest texel.
    Nearest,
    /// Bilinear.
    Bilinear,
}

/// `[render]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDesc {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Random seed (default 0).
    #[serde(default)]
    pub seed: u64,
    /// Maximum path depth (renderer default when absent).
    pub max_depth: Option<u32>,
    /// BSSRDF estimator name.
    pub estimator: Option<String>,
    /// Sone's averaging: `"prefiltered" | "monte-carlo"`.
    pub averaging: Option<String>,
    /// `"multiple" | "single" | "all"`.
    pub scattering: Option<String>,
}

/// `[camera]` with `type = "perspective"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerspectiveDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Eye position.
    #[serde(deserialize_with = "exact")]
    pub eye: [f64; 3],
    /// Point looked at.
    #[serde(deserialize_with = "exact")]
    pub target: [f64; 3],
    /// Up direction on screen.
    #[serde(deserialize_with = "exact")]
    pub up: [f64; 3],
    /// Full vertical field of view in DEGREES.
    pub fov_y: f64,
}

/// `[camera]` with `type = "orthographic"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrthographicDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Centre of the view rectangle (rays start on its plane).
    #[serde(deserialize_with = "exact")]
    pub centre: [f64; 3],
    /// View direction (rays travel along it).
    #[serde(deserialize_with = "exact")]
    pub direction: [f64; 3],
    /// Up direction on screen.
    #[serde(deserialize_with = "exact")]
    pub up: [f64; 3],
    /// View width (scene units).
    pub width: f64,
    /// View height (scene units).
    pub height: f64,
}

/// `[[texture]]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureDesc {
    /// Name used by fields.
    pub name: String,
    /// Image file, relative to the scene file.
    pub path: String,
    /// True when an 8/16-bit image holds data rather than sRGB colour (default false; EXR is
    /// always linear).
    #[serde(default)]
    pub linear: bool,
}

/// `[[material]]` with `type = "translucent"`: `sigma_a` and `sigma_s`, or the artist
/// parameters `subsurface_color` and `subsurface_radius` (not both).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TranslucentDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Name used by shapes.
    pub name: String,
    /// Absorption coefficient field (per file unit, see `unit_scale`).
    pub sigma_a: Option<FieldDesc>,
    /// Scattering coefficient field (per file unit).
    pub sigma_s: Option<FieldDesc>,
    /// Artist colour (the diffuse colour of a thick flat slab under uniform light), in [0, 1].
    pub subsurface_color: Option<FieldDesc>,
    /// Artist mean free path per channel (file units; σt = 1/(radius · radius_scale)).
    pub subsurface_radius: Option<FieldDesc>,
    /// Per-channel multiplier of `subsurface_radius` (default 1).
    pub radius_scale: Option<RgbDesc>,
    /// Where the estimators invert an artist medium: `"before"` or `"after"` averaging.
    pub invert: Option<String>,
    /// HG asymmetry (default 0), |g| < 1.
    pub g: Option<f64>,
    /// Another name for `g` (OpenPBR's `subsurface_scatter_anisotropy`).
    pub anisotropy: Option<f64>,
    /// Relative index of refraction ≥ 1 (default 1).
    #[serde(default = "one")]
    pub eta: f64,
    /// Profile model name (dipole | pbd | better-dipole | tabulated).
    pub profile: Option<String>,
    /// With the tabulated profile, weigh pairs by the slab profile of the local thickness
    /// (default true; `Translucent::thickness_aware`).
    pub thickness_aware: Option<bool>,
    /// Scale the BSSRDF by the shape correction measured in the object (default false;
    /// `Translucent::shape_correction`).
    pub shape_correction: Option<bool>,
    /// Seed of the shape correction's random numbers (only with `shape_correction = true`;
    /// `Translucent::correction_seed`).
    pub shape_correction_seed: Option<u64>,
    /// With the tabulated profile, scale it by the half-space's angular coupling (default
    /// true; `Translucent::angular_coupling`).
    pub angular_coupling: Option<bool>,
    /// With the angular coupling, also its oblique shape (default false;
    /// `Translucent::oblique_shape`).
    pub oblique_shape: Option<bool>,
    /// Coefficients in the file × unit_scale = coefficients per scene unit (default 1), e.g.
    /// 1000 for coefficients per mm in a scene modelled in metres. An artist radius is
    /// divided by it.
    #[serde(default = "one")]
    pub unit_scale: f64,
    /// The boundary's roughness r ∈ [0, 1] (a grey field; default 0, smooth): a GGX
    /// microfacet boundary of α = r² (`Translucent::roughness`).
    pub roughness: Option<FieldDesc>,
}

fn one() -> f64 {
    1.0
}

/// `[[material]]` with `type = "diffuse"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiffuseDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Name used by shapes.
    pub name: String,
    /// Albedo in [0, 1] per channel (a field: a number, `[r, g, b]`, or a pattern or image
    /// table).
    pub albedo: FieldDesc,
    /// Oren–Nayar roughness σ ∈ [0, 1] (a grey field; default 0, Lambertian;
    /// `crate::bsdf::diffuse`).
    pub roughness: Option<FieldDesc>,
}

/// `[[light]]` with `type = "directional"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Direction the light TRAVELS.
    #[serde(deserialize_with = "exact")]
    pub direction: [f64; 3],
    /// Irradiance on a surface perpendicular to the light.
    pub irradiance: RgbDesc,
}

/// `[[light]]` with `type = "point"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Position.
    #[serde(deserialize_with = "exact")]
    pub position: [f64; 3],
    /// Intensity (W/sr).
    pub intensity: RgbDesc,
}

/// `[[light]]` with `type = "quad"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadDesc {
    #[serde(rename = "type")]
    _type: String,
    /// A corner.
    #[serde(deserialize_with = "exact")]
    pub corner: [f64; 3],
    /// First edge.
    #[serde(deserialize_with = "exact")]
    pub edge_u: [f64; 3],
    /// Second edge; light leaves on the side of edge_u × edge_v.
    #[serde(deserialize_with = "exact")]
    pub edge_v: [f64; 3],
    /// Radiance.
    pub radiance: RgbDesc,
}

/// `[[light]]` with `type = "environment"`: a constant `radiance`, or an image `filename`
/// with its `scale`, `rotation` and `up` ([`crate::light::EnvironmentMap`]).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Constant radiance (W/(sr·m²)), without `filename`.
    pub radiance: Option<RgbDesc>,
    /// An equirectangular image of the radiance (`.exr` or Radiance `.hdr`; linear), relative
    /// to the scene file.
    pub filename: Option<String>,
    /// With `filename`: per-channel multiplier of the texels (default 1).
    pub scale: Option<RgbDesc>,
    /// With `filename`: turn of the map about its up axis in DEGREES, counter-clockwise seen
    /// from above (default 0).
    pub rotation: Option<f64>,
    /// With `filename`: the map's up axis, `"x" | "y" | "z"` (default z).
    pub up: Option<AxisDesc>,
}

/// `[[light]]` with `type = "beam"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamDesc {
    #[serde(rename = "type")]
    _type: String,
    /// Start point.
    #[serde(deserialize_with = "exact")]
    pub origin: [f64; 3],
    /// Direction of travel.
    #[serde(deserialize_with = "exact")]
    pub direction: [f64; 3],
    /// Power.
    pub power: RgbDesc,
}

/// A shape's optional transform: `p' = translate + R(rotate) · (scale ⊙ p)`.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct TransformDesc {
    /// Uniform (number) or per-axis (`[sx, sy, sz]`) scale, applied first.
    pub scale: Option<RgbDesc>,
    /// Rotation about an axis, applied second.
    pub rotate: Option<RotateDesc>,
    /// Translation, applied last.
    #[serde(default, deserialize_with = "exact_opt")]
    pub translate: Option<[f64; 3]>,
}

/// Axis-angle rotation.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotateDesc {
    /// Rotation axis (need not be unit).
    #[serde(deserialize_with = "exact")]
    pub axis: [f64; 3],
    /// Angle in DEGREES, right-handed about `axis`.
    pub degrees: f64,
}

/// Keys shared by every shape.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeCommon {
    /// Material name (required, except on a glTF shape, which then takes its materials from
    /// the file).
    pub material: Option<String>,
    /// Optional object name (default `shape[i]`).
    pub name: Option<String>,
    /// Optional transform.
    pub transform: Option<TransformDesc>,
}

macro_rules! shape_desc {
    ($(#[$doc:meta])* $name:ident { $($(#[$fdoc:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            #[serde(rename = "type")]
            _type: String,
            /// Material name (required, except on a glTF shape: see [`ShapeCommon`]).
            pub material: Option<String>,
            /// Optional object name.
            pub name: Option<String>,
            /// Optional transform.
            pub transform: Option<TransformDesc>,
            $($(#[$fdoc])* pub $field: $ty,)*
        }
        impl $name {
            /// The keys shared by every shape.
            pub fn common(&self) -> ShapeCommon {
                ShapeCommon {
                    material: self.material.clone(),
                    name: self.name.clone(),
                    transform: self.transform.clone(),
                }
            }
        }
    };
}

shape_desc!(
    /// `[[shape]]` with `type = "box"`.
    BoxDesc {
        /// Smallest corner.
        #[serde(deserialize_with = "exact")]
        min: [f64; 3],
        /// Largest corner.
        #[serde(deserialize_with = "exact")]
        max: [f64; 3],
    }
);

shape_desc!(
    /// `[[shape]]` with `type = "sphere"`.
    SphereDesc {
        /// Centre.
        #[serde(deserialize_with = "exact")]
        centre: [f64; 3],
        /// Radius.
        radius: f64,
        /// Icosphere subdivisions (default 5: 20,480 triangles; at most 9).
        subdivisions: Option<u32>,
    }
);

shape_desc!(
    /// `[[shape]]` with `type = "half_space"`: a large box whose top face is `z = top`.
    HalfSpaceDesc {
        /// Height of the surface (default 0).
        top: Option<f64>,
        /// Centre of the top face in x, y (default `[0, 0]`).
        #[serde(default, deserialize_with = "exact_opt")]
        centre: Option<[f64; 2]>,
        /// Side of the top face (default 1000).
        size: Option<f64>,
        /// Depth below the top (default size / 2).
        depth: Option<f64>,
        /// Grid subdivisions of the top face (default 32).
        subdivisions: Option<u32>,
    }
);

shape_desc!(
    /// `[[shape]]` with `type = "obj"`, `"gltf"` or `"ply"`.
    MeshFileDesc {
        /// Mesh file (.obj; .gltf or .glb; .ply), relative to the scene file.
        path: String,
        /// How to get the mesh when `path` does not exist (for a scene shipped without its
        /// model, e.g. "run `sh scripts/fetch-bunny.sh`"): printed in the error.
        if_missing: Option<String>,
        /// A glTF shape without `material` only: the `shape_correction` of every translucent
        /// material the file creates (as the material key; unset, the render decides).
        shape_correction: Option<bool>,
        /// A glTF shape without `material` only: their `shape_correction_seed`.
        shape_correction_seed: Option<u64>,
        /// glTF only: let the file's buffer and image URIs name files outside its own folder
        /// (default false; see [`crate::geometry::gltf_assets`]).
        allow_outside_assets: Option<bool>,
    }
);
