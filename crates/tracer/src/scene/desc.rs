//! The typed scene description: what the TOML file says, one type per kind of camera,
//! material, field, light and shape, before validation. Each section or array element with a
//! `type` key is read in two steps (the `type`, then the struct of that kind: [`Tagged`]) so
//! that serde's errors keep their position in the file. The lights' descriptions live beside
//! the lights ([`crate::light::LightDesc`]), and each converts itself to its runtime type.

use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};

use crate::error::SceneError;
use crate::field::{Axis, Filter, PlanarProjection, Texture, Wrap};

/// A description read by its `type` key: one struct per kind, chosen before it is read so
/// that serde's errors keep their position in the file (a `#[serde(tag = "type")]` enum
/// buffers the table and loses it). Implemented by the crate's `tagged!` macro, which declares
/// the enum of a section's kinds.
pub trait Tagged: Sized {
    /// What the descriptions describe (`"light"`), for messages.
    const WHAT: &'static str;
    /// The kinds, as the `type` key spells them.
    const KINDS: &'static [&'static str];
    /// The description of `kind` read from `d`, or `None` for a kind not in [`Tagged::KINDS`].
    fn from_kind<'de, D: Deserializer<'de>>(kind: &str, d: D) -> Option<Result<Self, D::Error>>;
}

/// Declares an enum of descriptions, one variant per `type`, and its [`Tagged`] impl:
/// `tagged!(/** doc */ pub enum LightDesc for "light" { "point" => Point(PointDesc), … })`.
macro_rules! tagged {
    (
        $(#[$doc:meta])* $vis:vis enum $name:ident for $what:literal {
            $($(#[$vdoc:meta])* $kind:literal => $variant:ident($ty:ty)),* $(,)?
        }
    ) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq)]
        $vis enum $name {
            $($(#[$vdoc])* $variant($ty),)*
        }
        impl $crate::scene::desc::Tagged for $name {
            const WHAT: &'static str = $what;
            const KINDS: &'static [&'static str] = &[$($kind),*];
            fn from_kind<'de, D: serde::Deserializer<'de>>(
                kind: &str,
                d: D,
            ) -> Option<Result<Self, D::Error>> {
                match kind {
                    $($kind => Some(<$ty as serde::Deserialize>::deserialize(d).map($name::$variant)),)*
                    _ => None,
                }
            }
        }
    };
}
pub(crate) use tagged;

/// What converting a description may ask of the loader: its files (named relative to the
/// scene file) and errors that name the description's keys, file and line.
pub trait DescContext {
    /// An invalid value at `sub`, a key below the description (`""`: the description itself).
    fn invalid(&self, sub: &str, message: String) -> SceneError;
    /// The image at `rel` (relative to the scene file), named by the key `sub`, decoded
    /// (`linear`: 8/16-bit values are data, not sRGB) and recorded as an input of the scene.
    fn texture(&self, sub: &str, rel: &str, linear: bool) -> Result<Texture, SceneError>;
}

/// A description whose keys do not hold together: the key at fault below the description
/// (`None`: the description itself) and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct DescError {
    /// The key below the description (`"width"`), or `None` for the description itself.
    pub key: Option<&'static str>,
    /// What is wrong, and what is accepted.
    pub message: String,
}

impl DescError {
    pub(crate) fn at(key: &'static str, message: impl Into<String>) -> Self {
        Self {
            key: Some(key),
            message: message.into(),
        }
    }

    pub(crate) fn here(message: impl Into<String>) -> Self {
        Self {
            key: None,
            message: message.into(),
        }
    }
}

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
pub(crate) fn exact<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(
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

/// A field table as written: every kind's keys, each optional. [`TypedField::try_from`] keeps
/// those of its `type` and refuses the others.
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

impl FieldKind {
    /// The kind as `type` spells it.
    pub fn name(self) -> &'static str {
        match self {
            FieldKind::Constant => "constant",
            FieldKind::Stripe => "stripe",
            FieldKind::Check => "check",
            FieldKind::Image => "image",
        }
    }

    /// The keys a table of this kind takes, besides `type`.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            FieldKind::Constant => &["value"],
            FieldKind::Stripe => &["width", "angle", "values", "axis", "origin"],
            FieldKind::Check => &["width", "values", "axis", "origin"],
            FieldKind::Image => &[
                "texture", "mapping", "axis", "origin", "size", "wrap", "filter", "scale",
            ],
        }
    }
}

impl FieldTable {
    /// The first key given that `self.kind` does not take.
    fn foreign_key(&self) -> Option<&'static str> {
        let FieldTable {
            kind,
            value,
            width,
            angle,
            values,
            axis,
            origin,
            texture,
            mapping,
            size,
            wrap,
            filter,
            scale,
        } = self;
        [
            ("value", value.is_some()),
            ("width", width.is_some()),
            ("angle", angle.is_some()),
            ("values", values.is_some()),
            ("axis", axis.is_some()),
            ("origin", origin.is_some()),
            ("texture", texture.is_some()),
            ("mapping", mapping.is_some()),
            ("size", size.is_some()),
            ("wrap", wrap.is_some()),
            ("filter", filter.is_some()),
            ("scale", scale.is_some()),
        ]
        .into_iter()
        .find(|(k, given)| *given && !kind.keys().contains(k))
        .map(|(k, _)| k)
    }
}

/// A field table with its `type` applied: the keys of its kind, defaults filled in.
#[derive(Debug, Clone, PartialEq)]
pub enum TypedField {
    /// `type = "constant"`: the value.
    Constant(RgbDesc),
    /// `type = "stripe"`.
    Stripe(StripeDesc),
    /// `type = "check"`.
    Check(CheckDesc),
    /// `type = "image"`.
    Image(ImageDesc),
}

/// A planar projection: the axis projected along and the origin (scene units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionDesc {
    /// Projection axis (default z).
    pub axis: AxisDesc,
    /// Projection origin (default `[0, 0, 0]`).
    pub origin: [f64; 3],
}

/// A stripe field: bands of two values.
#[derive(Debug, Clone, PartialEq)]
pub struct StripeDesc {
    /// Band width (scene units).
    pub width: f64,
    /// Angle θ in DEGREES (default 0); bands vary along (cos θ, sin θ) in the (s, t) plane.
    pub angle: f64,
    /// The two values.
    pub values: [RgbDesc; 2],
    /// How points map to the (s, t) plane.
    pub projection: ProjectionDesc,
}

/// A check field: square cells of two values.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckDesc {
    /// Cell side (scene units).
    pub width: f64,
    /// The two values.
    pub values: [RgbDesc; 2],
    /// How points map to the (s, t) plane.
    pub projection: ProjectionDesc,
}

/// An image field.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageDesc {
    /// The `[[texture]]` name.
    pub texture: String,
    /// How points find their texel.
    pub mapping: ImageMappingDesc,
    /// Wrap mode (default repeat).
    pub wrap: WrapDesc,
    /// Filter (default bilinear).
    pub filter: FilterDesc,
    /// Per-channel multiplier of the texel values (default 1).
    pub scale: RgbDesc,
}

/// An image field's mapping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ImageMappingDesc {
    /// Planar projection of an image of world size `[W, H]` (scene units).
    Planar {
        /// The projection.
        projection: ProjectionDesc,
        /// World size of the image.
        size: [f64; 2],
    },
    /// The mesh's texture coordinates.
    Uv,
}

impl TryFrom<FieldTable> for TypedField {
    type Error = DescError;

    /// Keeps the keys of the table's kind: a key of another kind, or a missing required key,
    /// is an error naming it and the kind's keys.
    fn try_from(t: FieldTable) -> Result<Self, DescError> {
        let kind = t.kind.name();
        if let Some(k) = t.foreign_key() {
            return Err(DescError::at(
                k,
                format!(
                    "`{k}` does not apply to a `{kind}` field (its keys: {})",
                    t.kind.keys().join(", ")
                ),
            ));
        }
        let need = |k: &str| DescError::here(format!("a `{kind}` field needs `{k}`"));
        let projection = ProjectionDesc {
            axis: t.axis.unwrap_or(AxisDesc::Z),
            origin: t.origin.unwrap_or([0.0; 3]),
        };
        Ok(match t.kind {
            FieldKind::Constant => TypedField::Constant(t.value.ok_or_else(|| need("value"))?),
            FieldKind::Stripe => TypedField::Stripe(StripeDesc {
                width: t.width.ok_or_else(|| need("width"))?,
                angle: t.angle.unwrap_or(0.0),
                values: t.values.ok_or_else(|| need("values"))?,
                projection,
            }),
            FieldKind::Check => TypedField::Check(CheckDesc {
                width: t.width.ok_or_else(|| need("width"))?,
                values: t.values.ok_or_else(|| need("values"))?,
                projection,
            }),
            FieldKind::Image => {
                let texture = t.texture.clone().ok_or_else(|| need("texture"))?;
                TypedField::Image(ImageDesc {
                    texture,
                    mapping: image_mapping(&t, projection)?,
                    wrap: t.wrap.unwrap_or(WrapDesc::Repeat),
                    filter: t.filter.unwrap_or(FilterDesc::Bilinear),
                    scale: t.scale.unwrap_or(RgbDesc([1.0; 3])),
                })
            }
        })
    }
}

/// An image table's mapping: `"uv"` refuses the planar keys; planar needs `size`.
fn image_mapping(
    t: &FieldTable,
    projection: ProjectionDesc,
) -> Result<ImageMappingDesc, DescError> {
    match t.mapping.unwrap_or(MappingDesc::Planar) {
        MappingDesc::Uv => {
            for (k, given) in [
                ("axis", t.axis.is_some()),
                ("origin", t.origin.is_some()),
                ("size", t.size.is_some()),
            ] {
                if given {
                    return Err(DescError::at(
                        k,
                        format!("`{k}` does not apply to `mapping = \"uv\"`"),
                    ));
                }
            }
            Ok(ImageMappingDesc::Uv)
        }
        MappingDesc::Planar => {
            let size = t.size.ok_or_else(|| {
                DescError::here("a planar image field needs `size = [W, H]` (scene units)")
            })?;
            Ok(ImageMappingDesc::Planar { projection, size })
        }
    }
}

impl From<AxisDesc> for Axis {
    fn from(a: AxisDesc) -> Axis {
        match a {
            AxisDesc::X => Axis::X,
            AxisDesc::Y => Axis::Y,
            AxisDesc::Z => Axis::Z,
        }
    }
}

impl From<WrapDesc> for Wrap {
    fn from(w: WrapDesc) -> Wrap {
        match w {
            WrapDesc::Repeat => Wrap::Repeat,
            WrapDesc::Clamp => Wrap::Clamp,
        }
    }
}

impl From<FilterDesc> for Filter {
    fn from(f: FilterDesc) -> Filter {
        match f {
            FilterDesc::Bilinear => Filter::Bilinear,
            FilterDesc::Nearest => Filter::Nearest,
        }
    }
}

impl From<ProjectionDesc> for PlanarProjection {
    fn from(p: ProjectionDesc) -> PlanarProjection {
        PlanarProjection::new(p.axis.into(), p.origin.into())
    }
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

tagged!(
    /// `[camera]`: its kind's description.
    pub enum CameraDesc for "camera" {
        /// `type = "perspective"`.
        "perspective" => Perspective(PerspectiveDesc),
        /// `type = "orthographic"`.
        "orthographic" => Orthographic(OrthographicDesc),
    }
);

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
    /// With the angular coupling, also its oblique shape (default true;
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

tagged!(
    /// `[[material]]`: its kind's description.
    #[allow(clippy::large_enum_variant)] // a few per scene, read once
    pub enum MaterialDesc for "material" {
        /// `type = "translucent"`.
        "translucent" => Translucent(TranslucentDesc),
        /// `type = "diffuse"`.
        "diffuse" => Diffuse(DiffuseDesc),
    }
);

impl MaterialDesc {
    /// The material's name.
    pub fn name(&self) -> &str {
        match self {
            MaterialDesc::Translucent(d) => &d.name,
            MaterialDesc::Diffuse(d) => &d.name,
        }
    }
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

tagged!(
    /// `[[shape]]`: its kind's description.
    pub enum ShapeDesc for "shape" {
        /// `type = "box"`.
        "box" => Box(BoxDesc),
        /// `type = "sphere"`.
        "sphere" => Sphere(SphereDesc),
        /// `type = "half_space"`.
        "half_space" => HalfSpace(HalfSpaceDesc),
        /// `type = "obj"`.
        "obj" => Obj(MeshFileDesc),
        /// `type = "gltf"`.
        "gltf" => Gltf(MeshFileDesc),
        /// `type = "ply"`.
        "ply" => Ply(MeshFileDesc),
    }
);
