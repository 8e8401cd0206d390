//! TOML → [`Scene`]: parsing with positions, validation with key paths, lazy texture
//! decoding, mesh loading.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use bssrdf_core::{AlbedoInversion, ProfileModel, Rgb, Scattering};
use glam::{DQuat, DVec3};
use serde::Deserialize;
use toml::Spanned;
use toml::de::{DeTable, DeValue, ValueDeserializer};

use super::builder::{
    AssemblyInfo, PendingObject, assemble, validate_material, validate_medium, validate_settings,
    validate_translucent_scalars,
};
use super::desc::*;
use super::locate::Locator;
use super::{Diffuse, Material, RenderSettings, Scene, Translucent};
use crate::camera::{Camera, CameraError};
use crate::error::{FieldError, SceneError};
use crate::field::{
    ArtistMap, Axis, Field, Filter, ImageMapping, InvertAt, MediumField, PlanarProjection, Texture,
    Wrap,
};
use crate::geometry::{Transform, TriangleMesh, primitives};
use crate::light::{EnvironmentError, EnvironmentMap, Light, LightError};

const SECTIONS: &[&str] = &["render", "camera", "texture", "material", "light", "shape"];

/// How a scene file is loaded.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct LoadOptions {
    /// Let every glTF file's buffer and image URIs name files outside the glTF file's own
    /// folder (the command line's `--allow-outside-assets`; a shape's `allow_outside_assets =
    /// true` allows it for that shape). Default: refused, since a glTF file downloaded from the
    /// web is untrusted input ([`crate::geometry::gltf_assets`]).
    pub allow_outside_assets: bool,
}

impl LoadOptions {
    /// These options with `allow_outside_assets` set to `allow`.
    pub fn with_allow_outside_assets(mut self, allow: bool) -> Self {
        self.allow_outside_assets = allow;
        self
    }
}

impl Scene {
    /// Loads a scene file; relative paths inside it are relative to its directory.
    pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        Self::load_with(path, LoadOptions::default())
    }

    /// [`Scene::load`] with `options`.
    pub fn load_with(path: impl AsRef<Path>, options: LoadOptions) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            file: path.to_path_buf(),
            key: String::new(),
            line: None,
            path: path.to_path_buf(),
            source,
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        let mut scene =
            Self::from_toml_str_with(&text, base, &path.display().to_string(), options)?;
        scene.source_path = Some(path.to_path_buf());
        Ok(scene)
    }

    /// Parses a scene from TOML text. `base_dir` resolves relative mesh and texture paths;
    /// `display_name` names the scene in errors.
    pub fn from_toml_str(
        text: &str,
        base_dir: &Path,
        display_name: &str,
    ) -> Result<Scene, SceneError> {
        Self::from_toml_str_with(text, base_dir, display_name, LoadOptions::default())
    }

    /// [`Scene::from_toml_str`] with `options`.
    pub fn from_toml_str_with(
        text: &str,
        base_dir: &Path,
        display_name: &str,
        options: LoadOptions,
    ) -> Result<Scene, SceneError> {
        let file = PathBuf::from(display_name);
        let root = DeTable::parse(text).map_err(|e| {
            let line = e
                .span()
                .map(|s| 1 + text[..s.start.min(text.len())].matches('\n').count());
            SceneError::Parse {
                file: file.clone(),
                key: String::new(),
                line,
                message: format!("malformed TOML: {}", e.message()),
            }
        })?;
        let loc = Locator::new(text, &root);
        let cx = Cx {
            file,
            base_dir: base_dir.to_path_buf(),
            loc,
            inputs: Default::default(),
            notes: Default::default(),
            options,
        };
        cx.load(&root, display_name)
    }
}

/// Loading context: the file name, the base directory and the key locator.
struct Cx {
    file: PathBuf,
    base_dir: PathBuf,
    loc: Locator,
    /// Every mesh and texture file found readable, in the order they were checked.
    inputs: std::cell::RefCell<Vec<PathBuf>>,
    /// What was read but cannot be honoured (glTF material notes).
    notes: std::cell::RefCell<Vec<super::LoadNote>>,
    options: LoadOptions,
}

type Val<'i> = Spanned<DeValue<'i>>;

impl Cx {
    fn parse_err(&self, e: toml::de::Error, fallback_key: &str) -> SceneError {
        let (key, line) = match e.span() {
            Some(s) => {
                let k = self.loc.key_at(s.start);
                // Keep the more specific of the located key and the context key.
                let k = if k.starts_with(fallback_key) {
                    k
                } else {
                    fallback_key.to_string()
                };
                (k, self.loc.line_of(s.start))
            }
            None => (fallback_key.to_string(), self.loc.line_of_key(fallback_key)),
        };
        SceneError::Parse {
            file: self.file.clone(),
            key,
            line,
            message: e.message().to_string(),
        }
    }

    fn parse_msg(&self, key: &str, message: impl Into<String>) -> SceneError {
        SceneError::Parse {
            file: self.file.clone(),
            key: key.to_string(),
            line: self.loc.line_of_key(key),
            message: message.into(),
        }
    }

    /// Refuses, before they are generated, primitives whose `triangles` so far would not fit
    /// in `room` (see [`crate::memory`]).
    fn check_tessellation(
        &self,
        room: crate::memory::Headroom,
        triangles: f64,
        key: &str,
    ) -> Result<(), SceneError> {
        crate::memory::check_within(
            room,
            || {
                format!(
                    "the scene's primitives ({:.1} million triangles)",
                    triangles / 1e6
                )
            },
            triangles * crate::memory::BYTES_PER_TRIANGLE,
        )
        .map_err(|e| self.invalid(key, e.to_string()))
    }

    fn invalid(&self, key: &str, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            file: self.file.clone(),
            key: key.to_string(),
            line: self.loc.line_of_key(key),
            message: message.into(),
        }
    }

    fn de<'i, T: Deserialize<'i>>(&self, v: &Val<'i>, key: &str) -> Result<T, SceneError> {
        T::deserialize(ValueDeserializer::from(v.clone())).map_err(|e| self.parse_err(e, key))
    }

    /// The `type` of a table element, as a string.
    fn type_of<'a>(
        &self,
        v: &'a Val<'_>,
        key: &str,
        expected: &str,
    ) -> Result<&'a str, SceneError> {
        let DeValue::Table(t) = v.get_ref() else {
            return Err(self.parse_msg(key, format!("expected a table with `type` = {expected}")));
        };
        match t.get("type").map(|t| t.get_ref()) {
            Some(DeValue::String(s)) => Ok(s.as_ref()),
            Some(_) => Err(self.parse_msg(
                &format!("{key}.type"),
                format!("`type` must be a string: {expected}"),
            )),
            None => Err(self.parse_msg(key, format!("missing key `type` (expected {expected})"))),
        }
    }

    fn elements<'a, 'i>(
        &self,
        root: &'a DeTable<'i>,
        name: &str,
    ) -> Result<Vec<(String, &'a Val<'i>)>, SceneError> {
        match root.get(name).map(|v| v.get_ref()) {
            None => Ok(Vec::new()),
            Some(DeValue::Array(a)) => Ok(a
                .iter()
                .enumerate()
                .map(|(i, v)| (format!("{name}[{i}]"), v))
                .collect()),
            Some(_) => {
                Err(self.parse_msg(name, format!("expected an array of tables `[[{name}]]`")))
            }
        }
    }

    fn resolve(&self, rel: &str) -> PathBuf {
        let p = Path::new(rel);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }

    fn check_readable(&self, key: &str, path: &Path) -> Result<(), SceneError> {
        match std::fs::metadata(path) {
            Ok(m) if m.is_file() => {
                self.inputs.borrow_mut().push(path.to_path_buf());
                Ok(())
            }
            Ok(_) => Err(SceneError::Io {
                file: self.file.clone(),
                key: key.to_string(),
                line: self.loc.line_of_key(key),
                path: path.to_path_buf(),
                source: std::io::Error::other("not a regular file"),
            }),
            Err(source) => Err(SceneError::Io {
                file: self.file.clone(),
                key: key.to_string(),
                line: self.loc.line_of_key(key),
                path: path.to_path_buf(),
                source,
            }),
        }
    }

    fn load(&self, root: &Spanned<DeTable<'_>>, display_name: &str) -> Result<Scene, SceneError> {
        let t = root.get_ref();
        for (k, _) in t.iter() {
            if !SECTIONS.contains(&k.get_ref().as_ref()) {
                return Err(SceneError::Parse {
                    file: self.file.clone(),
                    key: k.get_ref().to_string(),
                    line: self.loc.line_of(k.span().start),
                    message: format!(
                        "unknown section `{}`, expected one of: {}",
                        k.get_ref(),
                        SECTIONS.join(", ")
                    ),
                });
            }
        }
        let settings = self.settings(t)?;
        let camera = self.camera(t, &settings)?;
        let textures = self.textures(t)?;
        let materials = self.materials(t, &textures)?;
        let lights = self.lights(t)?;
        let shapes = self.shapes(t, &materials)?;

        // Build the materials used by some shape (decoding only their textures).
        let mut decoded: HashMap<String, Arc<Texture>> = HashMap::new();
        let mut built: HashMap<String, Material> = HashMap::new();
        let mut pending = Vec::with_capacity(shapes.len());
        for s in shapes {
            let material = match &s.material {
                ShapeMaterial::Built(m) => (**m).clone(),
                ShapeMaterial::Named(name) => match built.get(name) {
                    Some(m) => m.clone(),
                    None => {
                        let plan = &materials[name];
                        let m = self.realize(plan, &textures, &mut decoded)?;
                        built.insert(name.clone(), m.clone());
                        m
                    }
                },
            };
            if s.mesh.uvs.is_none() && material.reads_uv() {
                return Err(self.invalid(
                    &s.key,
                    format!(
                        "object `{}` has no texture coordinates, but its material `{}` maps an image by `mapping = \"uv\"`; use a planar mapping or a mesh with UVs",
                        s.name, s.material.name(&s.name)
                    ),
                ));
            }
            pending.push(PendingObject {
                name: s.name,
                line: self.loc.line_of_key(&s.key),
                key: s.key,
                source: s.source,
                mesh: s.mesh,
                material,
            });
        }
        assemble(
            AssemblyInfo {
                file: self.file.clone(),
                display_name: display_name.to_string(),
                source_path: None,
                locator: &self.loc,
                inputs: self.inputs.take(),
                notes: self.notes.take(),
            },
            settings,
            camera,
            lights,
            pending,
        )
    }

    fn settings(&self, t: &DeTable<'_>) -> Result<RenderSettings, SceneError> {
        let v = t.get("render").ok_or_else(|| {
            self.parse_msg("", "missing section [render] (width, height, spp, seed)")
        })?;
        let r: RenderDesc = self.de(v, "render")?;
        let scattering = match &r.scattering {
            None => None,
            Some(s) => Some(
                s.parse::<Scattering>()
                    .map_err(|e| self.invalid("render.scattering", e.to_string()))?,
            ),
        };
        let estimator = match &r.estimator {
            None => None,
            Some(name) => Some(name.parse::<het_estimate::Estimator>().map_err(|e| {
                self.invalid(
                    "render.estimator",
                    format!("{e} (`pt` is not an estimator: the path tracer is chosen with `--method pt`)"),
                )
            })?),
        };
        let averaging = match &r.averaging {
            None => None,
            Some(name) => Some(
                name.parse::<het_estimate::Averaging>()
                    .map_err(|e| self.invalid("render.averaging", e.to_string()))?,
            ),
        };
        let s = RenderSettings {
            averaging,
            width: r.width,
            height: r.height,
            spp: r.spp,
            seed: r.seed,
            max_depth: r.max_depth,
            estimator,
            scattering,
        };
        validate_settings(&s).map_err(|(k, m)| self.invalid(&format!("render.{k}"), m))?;
        Ok(s)
    }

    fn camera(&self, t: &DeTable<'_>, s: &RenderSettings) -> Result<Camera, SceneError> {
        let v = t
            .get("camera")
            .ok_or_else(|| self.parse_msg("", "missing section [camera]"))?;
        const KINDS: &str = "\"perspective\" | \"orthographic\"";
        let (cam, fov_key) = match self.type_of(v, "camera", KINDS)? {
            "perspective" => {
                let d: PerspectiveDesc = self.de(v, "camera")?;
                (
                    Camera::perspective(
                        d.eye.into(),
                        d.target.into(),
                        d.up.into(),
                        d.fov_y,
                        s.width,
                        s.height,
                    ),
                    "camera.fov_y",
                )
            }
            "orthographic" => {
                let d: OrthographicDesc = self.de(v, "camera")?;
                (
                    Camera::orthographic(
                        d.centre.into(),
                        d.direction.into(),
                        d.up.into(),
                        d.width,
                        d.height,
                        s.width,
                        s.height,
                    ),
                    "camera.width",
                )
            }
            other => {
                return Err(self.parse_msg(
                    "camera.type",
                    format!("unknown camera type `{other}`, expected {KINDS}"),
                ));
            }
        };
        cam.map_err(|e| {
            let key = match e {
                CameraError::BadFov(_) | CameraError::BadViewSize(..) => fov_key,
                CameraError::BadFrame => "camera.up",
                CameraError::BadResolution(..) => "render.width",
                _ => "camera",
            };
            self.invalid(key, e.to_string())
        })
    }

    fn textures(
        &self,
        t: &DeTable<'_>,
    ) -> Result<HashMap<String, (String, TextureDesc)>, SceneError> {
        let mut out = HashMap::new();
        for (key, v) in self.elements(t, "texture")? {
            let d: TextureDesc = self.de(v, &key)?;
            if out.contains_key(&d.name) {
                return Err(self.invalid(
                    &format!("{key}.name"),
                    format!("duplicate texture name `{}`", d.name),
                ));
            }
            out.insert(d.name.clone(), (key, d));
        }
        Ok(out)
    }

    fn materials(
        &self,
        t: &DeTable<'_>,
        textures: &HashMap<String, (String, TextureDesc)>,
    ) -> Result<HashMap<String, MaterialPlan>, SceneError> {
        const KINDS: &str = "\"translucent\" | \"diffuse\"";
        let mut out = HashMap::new();
        for (key, v) in self.elements(t, "material")? {
            let plan = match self.type_of(v, &key, KINDS)? {
                "translucent" => {
                    let d: TranslucentDesc = self.de(v, &key)?;
                    self.translucent_plan(&d, &key, textures)?
                }
                "diffuse" => {
                    let d: DiffuseDesc = self.de(v, &key)?;
                    let albedo = self.field_spec(&d.albedo, &format!("{key}.albedo"), textures)?;
                    let roughness = d
                        .roughness
                        .as_ref()
                        .map(|r| self.field_spec(r, &format!("{key}.roughness"), textures))
                        .transpose()?;
                    // Constant values are checked now (unused materials too); images when
                    // they are decoded.
                    let ready = |f: &FieldSpec| match f {
                        FieldSpec::Ready(f) => f.clone(),
                        FieldSpec::Image { .. } => Field::Constant(Rgb::ZERO),
                    };
                    let probe = Material::Diffuse(Diffuse {
                        albedo: ready(&albedo),
                        roughness: roughness.as_ref().map(ready),
                    });
                    validate_material(&probe)
                        .map_err(|(k, msg)| self.invalid(&format!("{key}.{k}"), msg))?;
                    (
                        d.name.clone(),
                        MaterialPlan::Diffuse {
                            albedo,
                            roughness,
                            key: key.clone(),
                        },
                    )
                }
                other => {
                    return Err(self.parse_msg(
                        &format!("{key}.type"),
                        format!("unknown material type `{other}`, expected {KINDS}"),
                    ));
                }
            };
            if out.contains_key(&plan.0) {
                return Err(self.invalid(
                    &format!("{key}.name"),
                    format!("duplicate material name `{}`", plan.0),
                ));
            }
            out.insert(plan.0, plan.1);
        }
        Ok(out)
    }

    /// Validates a field description without decoding images.
    fn field_spec(
        &self,
        d: &FieldDesc,
        key: &str,
        textures: &HashMap<String, (String, TextureDesc)>,
    ) -> Result<FieldSpec, SceneError> {
        let ferr = |e: FieldError| self.invalid(key, e.to_string());
        let tbl = match d {
            FieldDesc::Constant(v) => {
                return Field::constant(Rgb(v.0))
                    .map(FieldSpec::Ready)
                    .map_err(ferr);
            }
            FieldDesc::Table(t) => t,
        };
        // Which keys each kind accepts.
        let present: Vec<(&str, bool)> = vec![
            ("value", tbl.value.is_some()),
            ("width", tbl.width.is_some()),
            ("angle", tbl.angle.is_some()),
            ("values", tbl.values.is_some()),
            ("axis", tbl.axis.is_some()),
            ("origin", tbl.origin.is_some()),
            ("texture", tbl.texture.is_some()),
            ("mapping", tbl.mapping.is_some()),
            ("size", tbl.size.is_some()),
            ("wrap", tbl.wrap.is_some()),
            ("filter", tbl.filter.is_some()),
            ("scale", tbl.scale.is_some()),
        ];
        let (kind, allowed, required): (&str, &[&str], &[&str]) = match tbl.kind {
            FieldKind::Constant => ("constant", &["value"], &["value"]),
            FieldKind::Stripe => (
                "stripe",
                &["width", "angle", "values", "axis", "origin"],
                &["width", "values"],
            ),
            FieldKind::Check => (
                "check",
                &["width", "values", "axis", "origin"],
                &["width", "values"],
            ),
            FieldKind::Image => (
                "image",
                &[
                    "texture", "mapping", "axis", "origin", "size", "wrap", "filter", "scale",
                ],
                &["texture"],
            ),
        };
        for (k, is) in &present {
            if *is && !allowed.contains(k) {
                return Err(self.invalid(
                    &format!("{key}.{k}"),
                    format!(
                        "`{k}` does not apply to a `{kind}` field (its keys: {})",
                        allowed.join(", ")
                    ),
                ));
            }
        }
        for r in required {
            if !present.iter().any(|(k, is)| k == r && *is) {
                return Err(self.invalid(key, format!("a `{kind}` field needs `{r}`")));
            }
        }
        let axis = match tbl.axis.unwrap_or(AxisDesc::Z) {
            AxisDesc::X => Axis::X,
            AxisDesc::Y => Axis::Y,
            AxisDesc::Z => Axis::Z,
        };
        let projection = PlanarProjection::new(axis, DVec3::from(tbl.origin.unwrap_or([0.0; 3])));
        let values = tbl.values.map(|v| [Rgb(v[0].0), Rgb(v[1].0)]);
        match tbl.kind {
            FieldKind::Constant => Field::constant(Rgb(tbl.value.unwrap().0))
                .map(FieldSpec::Ready)
                .map_err(ferr),
            FieldKind::Stripe => Field::stripe(
                tbl.width.unwrap(),
                tbl.angle.unwrap_or(0.0).to_radians(),
                values.unwrap(),
                projection,
            )
            .map(FieldSpec::Ready)
            .map_err(ferr),
            FieldKind::Check => Field::check(tbl.width.unwrap(), values.unwrap(), projection)
                .map(FieldSpec::Ready)
                .map_err(ferr),
            FieldKind::Image => {
                let name = tbl.texture.clone().unwrap();
                if !textures.contains_key(&name) {
                    let mut known: Vec<&String> = textures.keys().collect();
                    known.sort();
                    return Err(self.invalid(
                        &format!("{key}.texture"),
                        format!("unknown texture `{name}` (defined: {known:?})"),
                    ));
                }
                let mapping = match tbl.mapping.unwrap_or(MappingDesc::Planar) {
                    MappingDesc::Uv => {
                        for k in ["axis", "origin", "size"] {
                            if present.iter().any(|(p, is)| *p == k && *is) {
                                return Err(self.invalid(
                                    &format!("{key}.{k}"),
                                    format!("`{k}` does not apply to `mapping = \"uv\"`"),
                                ));
                            }
                        }
                        ImageMapping::Uv
                    }
                    MappingDesc::Planar => {
                        let size = tbl.size.ok_or_else(|| {
                            self.invalid(
                                key,
                                "a planar image field needs `size = [W, H]` (scene units)",
                            )
                        })?;
                        for (i, s) in size.iter().enumerate() {
                            if !(s.is_finite() && *s > 0.0) {
                                return Err(self.invalid(
                                    &format!("{key}.size"),
                                    format!("size[{i}] must be finite and positive, got {s}"),
                                ));
                            }
                        }
                        ImageMapping::Planar { projection, size }
                    }
                };
                let scale = Rgb(tbl.scale.map_or([1.0; 3], |s| s.0));
                if !(scale.is_finite() && scale.min_component() >= 0.0) {
                    return Err(self.invalid(
                        &format!("{key}.scale"),
                        format!("scale must be finite and non-negative, got {:?}", scale.0),
                    ));
                }
                Ok(FieldSpec::Image {
                    texture: name,
                    mapping,
                    wrap: match tbl.wrap.unwrap_or(WrapDesc::Repeat) {
                        WrapDesc::Repeat => Wrap::Repeat,
                        WrapDesc::Clamp => Wrap::Clamp,
                    },
                    filter: match tbl.filter.unwrap_or(FilterDesc::Bilinear) {
                        FilterDesc::Bilinear => Filter::Bilinear,
                        FilterDesc::Nearest => Filter::Nearest,
                    },
                    scale,
                    key: key.to_string(),
                })
            }
        }
    }

    /// A translucent material's plan: σa and σs, or the artist parameters (a constant zero
    /// radius with a constant colour becomes a diffuse surface of that colour).
    fn translucent_plan(
        &self,
        d: &TranslucentDesc,
        key: &str,
        textures: &HashMap<String, (String, TextureDesc)>,
    ) -> Result<(String, MaterialPlan), SceneError> {
        let profile = match &d.profile {
            None => None,
            Some(p) => Some(
                p.parse::<ProfileModel>()
                    .map_err(|e| self.invalid(&format!("{key}.profile"), e.to_string()))?,
            ),
        };
        let g = match (d.g, d.anisotropy) {
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    &format!("{key}.anisotropy"),
                    "give `g` or `anisotropy` (the same parameter), not both",
                ));
            }
            (g, a) => g.or(a).unwrap_or(0.0),
        };
        if d.shape_correction_seed.is_some() && d.shape_correction == Some(false) {
            return Err(self.invalid(
                &format!("{key}.shape_correction_seed"),
                "a seed for the shape correction, which `shape_correction = false` turns off: \
                 remove one of the two",
            ));
        }
        // Validate the scalar values now with placeholder constant fields (so that unused
        // materials are checked too).
        let probe = Translucent {
            name: d.name.clone(),
            medium: MediumField::new(Field::Constant(Rgb::ZERO), Field::Constant(Rgb::ZERO)),
            g,
            eta: d.eta,
            profile,
            thickness_aware: d.thickness_aware.unwrap_or(true),
            shape_correction: d.shape_correction,
            correction_seed: d
                .shape_correction_seed
                .unwrap_or(Translucent::DEFAULT_CORRECTION_SEED),
            angular_coupling: d.angular_coupling.unwrap_or(true),
            oblique_shape: d.oblique_shape.unwrap_or(false),
            unit_scale: d.unit_scale,
            roughness: None,
            key: key.to_string(),
            line: self.loc.line_of_key(key),
        };
        validate_translucent_scalars(&probe)
            .map_err(|(k, m)| self.invalid(&format!("{key}.{k}"), m))?;
        let field =
            |f: &FieldDesc, name: &str| self.field_spec(f, &format!("{key}.{name}"), textures);
        let roughness = d
            .roughness
            .as_ref()
            .map(|r| field(r, "roughness"))
            .transpose()?;
        if let Some(FieldSpec::Ready(r)) = &roughness {
            crate::scene::builder::validate_roughness(r)
                .map_err(|(k, m)| self.invalid(&format!("{key}.{k}"), m))?;
        }
        let artist_keys = d.subsurface_color.is_some()
            || d.subsurface_radius.is_some()
            || d.radius_scale.is_some()
            || d.invert.is_some();
        let plan = match (
            &d.sigma_a,
            &d.sigma_s,
            &d.subsurface_color,
            &d.subsurface_radius,
        ) {
            (Some(a), Some(s), None, None) if !artist_keys => MaterialPlan::Translucent {
                base: probe,
                sigma_a: field(a, "sigma_a")?,
                sigma_s: field(s, "sigma_s")?,
                artist: None,
                roughness,
            },
            (None, None, Some(c), Some(r)) => {
                let scale = Rgb(d.radius_scale.map_or([1.0; 3], |s| s.0));
                if !(scale.is_finite() && scale.min_component() >= 0.0) {
                    return Err(self.invalid(
                        &format!("{key}.radius_scale"),
                        format!(
                            "radius_scale must be finite and non-negative, got {:?}",
                            scale.0
                        ),
                    ));
                }
                let invert = match &d.invert {
                    None => InvertAt::DEFAULT,
                    Some(s) => s.parse().map_err(|e: bssrdf_core::UnknownName| {
                        self.invalid(&format!("{key}.invert"), e.to_string())
                    })?,
                };
                let colour = field(c, "subsurface_color")?;
                let radius = field(r, "subsurface_radius")?;
                if let FieldSpec::Ready(Field::Constant(cv)) = &colour
                    && cv.max_component() > 1.0
                {
                    return Err(self.invalid(
                        &format!("{key}.subsurface_color"),
                        format!("subsurface_color must lie in [0, 1], got {:?}", cv.0),
                    ));
                }
                if let FieldSpec::Ready(Field::Constant(rv)) = &radius
                    && (*rv * scale).is_zero()
                {
                    // No distance to travel: a diffuse surface of the colour.
                    let FieldSpec::Ready(Field::Constant(cv)) = colour else {
                        return Err(self.invalid(
                            &format!("{key}.subsurface_radius"),
                            "a zero subsurface_radius makes a diffuse surface, which needs a constant subsurface_color",
                        ));
                    };
                    if roughness.is_some() {
                        return Err(self.invalid(
                            &format!("{key}.roughness"),
                            "a zero subsurface_radius makes a diffuse surface, which has no \
                             dielectric boundary to be rough: use a `diffuse` material and its \
                             `roughness`",
                        ));
                    }
                    MaterialPlan::Ready(Material::diffuse(cv))
                } else {
                    MaterialPlan::Translucent {
                        base: probe,
                        sigma_a: colour,
                        sigma_s: radius,
                        artist: Some((scale, invert)),
                        roughness,
                    }
                }
            }
            _ => {
                return Err(self.invalid(
                    key,
                    format!(
                        "material `{}`: give either `sigma_a` and `sigma_s`, or `subsurface_color` and `subsurface_radius` (with optional `radius_scale`, `invert`), not a mix",
                        d.name
                    ),
                ));
            }
        };
        Ok((d.name.clone(), plan))
    }

    /// Builds a material, decoding the textures it uses (once per texture).
    fn realize(
        &self,
        plan: &MaterialPlan,
        textures: &HashMap<String, (String, TextureDesc)>,
        decoded: &mut HashMap<String, Arc<Texture>>,
    ) -> Result<Material, SceneError> {
        match plan {
            MaterialPlan::Ready(m) => Ok(m.clone()),
            MaterialPlan::Diffuse {
                albedo,
                roughness,
                key,
            } => {
                let m = Material::Diffuse(Diffuse {
                    albedo: self.realize_field(albedo, textures, decoded)?,
                    roughness: roughness
                        .as_ref()
                        .map(|r| self.realize_field(r, textures, decoded))
                        .transpose()?,
                });
                validate_material(&m)
                    .map_err(|(k, msg)| self.invalid(&format!("{key}.{k}"), msg))?;
                Ok(m)
            }
            MaterialPlan::Translucent {
                base,
                sigma_a,
                sigma_s,
                artist,
                roughness,
            } => {
                let a = self.realize_field(sigma_a, textures, decoded)?;
                let s = self.realize_field(sigma_s, textures, decoded)?;
                let mut t = base.clone();
                if let Some(r) = roughness {
                    let r = self.realize_field(r, textures, decoded)?;
                    crate::scene::builder::validate_roughness(&r)
                        .map_err(|(k, m)| self.invalid(&format!("{}.{k}", t.key), m))?;
                    t.roughness = Some(r);
                }
                t.medium = match artist {
                    None => MediumField::new(a, s).scaled(base.unit_scale),
                    Some((scale, invert)) => {
                        let model = t.profile.unwrap_or(ProfileModel::default_for(t.eta));
                        let inversion =
                            AlbedoInversion::shared(model, t.g, t.eta).map_err(|e| {
                                self.invalid(&format!("{}.profile", t.key), e.to_string())
                            })?;
                        MediumField::artist(
                            a,
                            s.scaled_rgb(*scale * (1.0 / base.unit_scale)),
                            ArtistMap::new(inversion, *invert),
                        )
                        .map_err(|e| {
                            self.invalid(&format!("{}.subsurface_color", t.key), e.to_string())
                        })?
                    }
                };
                validate_medium(&t).map_err(|(k, m)| self.invalid(&format!("{}.{k}", t.key), m))?;
                Ok(Material::Translucent(t))
            }
        }
    }

    fn realize_field(
        &self,
        spec: &FieldSpec,
        textures: &HashMap<String, (String, TextureDesc)>,
        decoded: &mut HashMap<String, Arc<Texture>>,
    ) -> Result<Field, SceneError> {
        match spec {
            FieldSpec::Ready(f) => Ok(f.clone()),
            FieldSpec::Image {
                texture,
                mapping,
                wrap,
                filter,
                scale,
                key,
            } => {
                let tex = match decoded.get(texture) {
                    Some(t) => t.clone(),
                    None => {
                        let (tkey, desc) = &textures[texture];
                        let path = self.resolve(&desc.path);
                        let path_key = format!("{tkey}.path");
                        self.check_readable(&path_key, &path)?;
                        let t = Texture::load(&path, desc.linear).map_err(|source| {
                            SceneError::Texture {
                                file: self.file.clone(),
                                line: self.loc.line_of_key(&path_key),
                                key: path_key.clone(),
                                source: Box::new(source),
                            }
                        })?;
                        let t = Arc::new(t);
                        decoded.insert(texture.clone(), t.clone());
                        t
                    }
                };
                Field::image(tex, *mapping, *wrap, *filter, *scale)
                    .map_err(|e| self.invalid(key, e.to_string()))
            }
        }
    }

    fn lights(&self, t: &DeTable<'_>) -> Result<Vec<Light>, SceneError> {
        const KINDS: &str = "\"directional\" | \"point\" | \"quad\" | \"environment\" | \"beam\"";
        let mut out = Vec::new();
        for (key, v) in self.elements(t, "light")? {
            let light = match self.type_of(v, &key, KINDS)? {
                "directional" => {
                    let d: DirectionalDesc = self.de(v, &key)?;
                    Light::directional(d.direction.into(), Rgb(d.irradiance.0))
                }
                "point" => {
                    let d: PointDesc = self.de(v, &key)?;
                    Light::point(d.position.into(), Rgb(d.intensity.0))
                }
                "quad" => {
                    let d: QuadDesc = self.de(v, &key)?;
                    Light::quad(
                        d.corner.into(),
                        d.edge_u.into(),
                        d.edge_v.into(),
                        Rgb(d.radiance.0),
                    )
                }
                "environment" => {
                    let d: EnvironmentDesc = self.de(v, &key)?;
                    match self.environment(&d, &key)? {
                        Some(map) => Ok(map),
                        None => Light::environment(Rgb(d.radiance.map_or([0.0; 3], |r| r.0))),
                    }
                }
                "beam" => {
                    let d: BeamDesc = self.de(v, &key)?;
                    Light::beam(d.origin.into(), d.direction.into(), Rgb(d.power.0))
                }
                other => {
                    return Err(self.parse_msg(
                        &format!("{key}.type"),
                        format!("unknown light type `{other}`, expected {KINDS}"),
                    ));
                }
            };
            out.push(light.map_err(|e| {
                let sub = match &e {
                    LightError::BadDirection(w) | LightError::NonFinite(w) => *w,
                    LightError::BadValue { what, .. } => what,
                    LightError::DegenerateQuad => "edge_v",
                };
                self.invalid(&format!("{key}.{sub}"), e.to_string())
            })?);
        }
        Ok(out)
    }

    /// An environment light read from an image (`filename`), or `None` for a constant one
    /// (`radiance`; `scale`, `rotation` and `up` then refused).
    fn environment(&self, d: &EnvironmentDesc, key: &str) -> Result<Option<Light>, SceneError> {
        let k = |sub: &str| format!("{key}.{sub}");
        let Some(rel) = &d.filename else {
            if d.radiance.is_none() {
                return Err(self.invalid(
                    key,
                    "an environment light needs `radiance` (constant) or `filename` (an image)",
                ));
            }
            for (name, given) in [
                ("scale", d.scale.is_some()),
                ("rotation", d.rotation.is_some()),
                ("up", d.up.is_some()),
            ] {
                if given {
                    return Err(self.invalid(
                        &k(name),
                        format!("`{name}` applies to an environment map (`filename`)"),
                    ));
                }
            }
            return Ok(None);
        };
        if d.radiance.is_some() {
            return Err(self.invalid(
                &k("radiance"),
                "give `radiance` (constant) or `filename` (an image), not both; `scale` \
                 multiplies the image",
            ));
        }
        let path = self.resolve(rel);
        let path_key = k("filename");
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("exr" | "hdr")) {
            return Err(self.invalid(
                &path_key,
                format!(
                    "`{rel}`: an environment map is an `.exr` or Radiance `.hdr` image \
                     (linear radiance)"
                ),
            ));
        }
        self.check_readable(&path_key, &path)?;
        let texture = Texture::load(&path, true).map_err(|source| SceneError::Texture {
            file: self.file.clone(),
            line: self.loc.line_of_key(&path_key),
            key: path_key.clone(),
            source: Box::new(source),
        })?;
        let up = match d.up.unwrap_or(AxisDesc::Z) {
            AxisDesc::X => Axis::X,
            AxisDesc::Y => Axis::Y,
            AxisDesc::Z => Axis::Z,
        };
        let map = EnvironmentMap::new(
            Arc::new(texture),
            Rgb(d.scale.map_or([1.0; 3], |s| s.0)),
            up,
            d.rotation.unwrap_or(0.0),
        )
        .map_err(|e| {
            let sub = match e {
                EnvironmentError::BadRotation(_) => "rotation",
                _ => "scale",
            };
            self.invalid(&k(sub), e.to_string())
        })?;
        Ok(Some(Light::environment_map(map)))
    }

    fn shapes(
        &self,
        t: &DeTable<'_>,
        materials: &HashMap<String, MaterialPlan>,
    ) -> Result<Vec<ShapePlan>, SceneError> {
        const KINDS: &str = "\"box\" | \"sphere\" | \"half_space\" | \"obj\" | \"gltf\" | \"ply\"";
        let mut out: Vec<ShapePlan> = Vec::new();
        let mut names = HashSet::new();
        let shapes = self.elements(t, "shape")?;
        // The primitives' triangles, counted before any is generated; the limits are read
        // once (a check per shape read them 100,000 times for as many boxes).
        let room = crate::memory::headroom();
        let mut tessellated = 0.0;
        for (key, v) in &shapes {
            let added = match self.type_of(v, key, KINDS)? {
                "sphere" => {
                    let d: SphereDesc = self.de(v, key)?;
                    20.0 * 4f64.powi(d.subdivisions.unwrap_or(5).min(9) as i32)
                }
                "half_space" => {
                    let d: HalfSpaceDesc = self.de(v, key)?;
                    2.0 * f64::from(d.subdivisions.unwrap_or(32).min(1024)).powi(2) + 10.0
                }
                _ => continue,
            };
            tessellated += added;
            self.check_tessellation(room, tessellated, &format!("{key}.subdivisions"))?;
        }
        for (i, (key, v)) in shapes.into_iter().enumerate() {
            let k = |sub: &str| format!("{key}.{sub}");
            let (common, mesh, source) = match self.type_of(v, &key, KINDS)? {
                "box" => {
                    let d: BoxDesc = self.de(v, &key)?;
                    let (lo, hi) = (DVec3::from(d.min), DVec3::from(d.max));
                    if !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all()) {
                        return Err(self.invalid(
                            &k("max"),
                            format!(
                                "need min < max in every axis, got min {:?}, max {:?}",
                                d.min, d.max
                            ),
                        ));
                    }
                    (d.common(), primitives::cuboid(lo, hi), "<box>".to_string())
                }
                "sphere" => {
                    let d: SphereDesc = self.de(v, &key)?;
                    let c = DVec3::from(d.centre);
                    if !(d.radius.is_finite() && d.radius > 0.0) {
                        return Err(self.invalid(
                            &k("radius"),
                            format!("radius must be finite and positive, got {}", d.radius),
                        ));
                    }
                    if !c.is_finite() {
                        return Err(self.invalid(&k("centre"), "centre must be finite"));
                    }
                    let s = d.subdivisions.unwrap_or(5);
                    if s > 9 {
                        return Err(self.invalid(
                            &k("subdivisions"),
                            format!("at most 9 (5,242,880 triangles), got {s}"),
                        ));
                    }
                    (
                        d.common(),
                        primitives::icosphere(c, d.radius, s),
                        "<sphere>".to_string(),
                    )
                }
                "half_space" => {
                    let d: HalfSpaceDesc = self.de(v, &key)?;
                    let size = d.size.unwrap_or(1000.0);
                    let depth = d.depth.unwrap_or(0.5 * size);
                    let top = d.top.unwrap_or(0.0);
                    let centre = d.centre.unwrap_or([0.0, 0.0]);
                    let sub = d.subdivisions.unwrap_or(32);
                    for (name, val) in [("size", size), ("depth", depth)] {
                        if !(val.is_finite() && val > 0.0) {
                            return Err(self.invalid(
                                &k(name),
                                format!("{name} must be finite and positive, got {val}"),
                            ));
                        }
                    }
                    if !(top.is_finite() && centre.iter().all(|c| c.is_finite())) {
                        return Err(self.invalid(&k("top"), "top and centre must be finite"));
                    }
                    if sub == 0 || sub > 1024 {
                        return Err(self.invalid(
                            &k("subdivisions"),
                            format!("must be in 1..=1024, got {sub}"),
                        ));
                    }
                    (
                        d.common(),
                        primitives::half_space(top, centre, size, depth, sub),
                        "<half_space>".to_string(),
                    )
                }
                kind @ ("obj" | "gltf" | "ply") => {
                    let d: MeshFileDesc = self.de(v, &key)?;
                    let correction = (d.shape_correction, d.shape_correction_seed);
                    if (correction.0.is_some() || correction.1.is_some())
                        && (kind != "gltf" || d.material.is_some())
                    {
                        let which = if correction.0.is_some() {
                            "shape_correction"
                        } else {
                            "shape_correction_seed"
                        };
                        return Err(self.invalid(
                            &k(which),
                            "applies to a glTF shape that uses the file's materials (no \
                             `material`); set it on the material instead",
                        ));
                    }
                    if correction.0 == Some(false) && correction.1.is_some() {
                        return Err(self.invalid(
                            &k("shape_correction_seed"),
                            "a seed for the shape correction, which `shape_correction = false` \
                             turns off: remove one of the two",
                        ));
                    }
                    if d.allow_outside_assets.is_some() && kind != "gltf" {
                        return Err(self.invalid(
                            &k("allow_outside_assets"),
                            "only a glTF shape reads external files by URI",
                        ));
                    }
                    #[cfg_attr(not(feature = "gltf"), allow(unused_variables))]
                    let scope = if d.allow_outside_assets.unwrap_or(false)
                        || self.options.allow_outside_assets
                    {
                        crate::geometry::gltf_assets::AssetScope::Anywhere
                    } else {
                        crate::geometry::gltf_assets::AssetScope::ModelFolder
                    };
                    let (common, rel) = (d.common(), d.path);
                    let path = self.resolve(&rel);
                    if let Some(hint) = &d.if_missing
                        && !path.exists()
                    {
                        return Err(self.invalid(
                            &k("path"),
                            format!("the mesh `{}` does not exist: {hint}", path.display()),
                        ));
                    }
                    self.check_readable(&k("path"), &path)?;
                    let mesh_error = |source| SceneError::Mesh {
                        file: self.file.clone(),
                        key: k("path"),
                        line: self.loc.line_of_key(&k("path")),
                        source: Box::new(source),
                    };
                    #[cfg(feature = "gltf")]
                    if kind == "gltf" && common.material.is_none() {
                        let mut model = crate::geometry::gltf::load_gltf_parts_with(&path, scope)
                            .map_err(mesh_error)?;
                        self.inputs
                            .borrow_mut()
                            .extend_from_slice(model.files_read());
                        let shape = common.name.clone().unwrap_or_else(|| format!("shape[{i}]"));
                        let xf = self.shape_transform(&common, &key)?;
                        let scale = xf.map_or(DVec3::ONE, |t| t.scale);
                        // Materials that share an image decode it once.
                        let mut images = HashMap::new();
                        for part in std::mem::take(&mut model.parts) {
                            let name = format!("{shape}/{}", part.material.name);
                            let mut material = self.gltf_material(
                                &model,
                                &part.material,
                                &mut images,
                                &name,
                                &key,
                                scale,
                            )?;
                            if let Material::Translucent(t) = &mut material {
                                if let Some(on) = correction.0 {
                                    t.shape_correction = Some(on);
                                }
                                if let Some(seed) = correction.1 {
                                    t.correction_seed = seed;
                                }
                            }
                            self.add_shape(
                                &mut out,
                                &mut names,
                                ShapePlan {
                                    name,
                                    key: key.clone(),
                                    material: ShapeMaterial::Built(Box::new(material)),
                                    mesh: part.mesh,
                                    source: path.display().to_string(),
                                },
                                xf.as_ref(),
                            )?;
                        }
                        continue;
                    }
                    let mesh = self.load_mesh(kind, &path, scope).map_err(mesh_error)?;
                    (common, mesh, path.display().to_string())
                }
                other => {
                    return Err(self.parse_msg(
                        &k("type"),
                        format!("unknown shape type `{other}`, expected {KINDS}"),
                    ));
                }
            };
            let Some(material) = common.material.clone() else {
                return Err(self.invalid(
                    &k("material"),
                    "missing `material` (only a glTF shape may leave it out, to use the \
                     file's materials)",
                ));
            };
            if !materials.contains_key(&material) {
                let mut known: Vec<&String> = materials.keys().collect();
                known.sort();
                return Err(self.invalid(
                    &k("material"),
                    format!("unknown material `{material}` (defined: {known:?})"),
                ));
            }
            let name = common.name.clone().unwrap_or_else(|| format!("shape[{i}]"));
            let xf = self.shape_transform(&common, &key)?;
            self.add_shape(
                &mut out,
                &mut names,
                ShapePlan {
                    name,
                    key,
                    material: ShapeMaterial::Named(material),
                    mesh,
                    source,
                },
                xf.as_ref(),
            )?;
        }
        Ok(out)
    }

    /// The material of one glTF material's part (`docs/gltf.md`): the file's values read by
    /// [`GltfMaterial::interpret`](crate::geometry::gltf_material::GltfMaterial::interpret),
    /// lengths scaled by the shape's `scale`, checked like a scene material; what is not read
    /// becomes a note for the render's warnings.
    #[cfg(feature = "gltf")]
    fn gltf_material(
        &self,
        model: &crate::geometry::gltf::GltfModel,
        m: &crate::geometry::gltf_material::GltfMaterial,
        images: &mut HashMap<usize, Arc<Texture>>,
        name: &str,
        key: &str,
        scale: DVec3,
    ) -> Result<Material, SceneError> {
        use crate::geometry::gltf_material::GltfInterpretation as I;
        let (interpretation, notes) = m.interpret();
        let file = model.file().display().to_string();
        for text in notes {
            self.notes.borrow_mut().push(super::LoadNote {
                file: file.clone(),
                subject: format!("material `{}`", m.name),
                text,
            });
        }
        let field_key = format!("{key}.path");
        let invalid =
            |msg: String| self.invalid(&field_key, format!("{file}: material `{}`: {msg}", m.name));
        // Lengths in the file × s are lengths in the scene (a non-uniform scale: its
        // geometric mean).
        let s = (scale.x * scale.y * scale.z).abs().cbrt();
        let material = match interpretation {
            I::Diffuse { albedo } => Material::diffuse(Rgb(albedo)),
            I::Absorbing { sigma_a, eta } => {
                let medium = MediumField::homogeneous(het_estimate::Coefficients {
                    sigma_a: Rgb(sigma_a) * (1.0 / s),
                    sigma_s: Rgb::ZERO,
                })
                .map_err(|e| invalid(e.to_string()))?;
                Material::Translucent(Translucent::new(name, medium, 0.0, eta))
            }
            I::Translucent {
                colour,
                mean_free_path,
                anisotropy,
                eta,
            } => {
                use crate::geometry::gltf_material::GltfColour;
                let colour = match colour {
                    GltfColour::Constant(c) => Field::constant(Rgb(c)),
                    GltfColour::Texture { factor, texture } => {
                        let tex = match images.get(&texture.image) {
                            Some(t) => t.clone(),
                            None => {
                                if let Some(file) = model.image_file(texture.image) {
                                    self.inputs.borrow_mut().push(file.to_path_buf());
                                }
                                let t = model.decode_image(texture.image).map_err(|source| {
                                    SceneError::Texture {
                                        file: self.file.clone(),
                                        line: self.loc.line_of_key(&field_key),
                                        key: field_key.clone(),
                                        source: Box::new(source),
                                    }
                                })?;
                                let t = Arc::new(t);
                                images.insert(texture.image, t.clone());
                                t
                            }
                        };
                        Field::image(
                            tex,
                            ImageMapping::Uv,
                            texture.wrap,
                            Filter::Bilinear,
                            Rgb(factor),
                        )
                    }
                }
                .map_err(|e| invalid(e.to_string()))?;
                let mfp =
                    Field::constant(Rgb(mean_free_path) * s).map_err(|e| invalid(e.to_string()))?;
                // The material's profile, as for a scene material without a `profile` key: it
                // defines the medium through its inversion, and renders it by default.
                let profile = ProfileModel::default_for(eta);
                let inversion = AlbedoInversion::shared(profile, anisotropy, eta)
                    .map_err(|e| invalid(e.to_string()))?;
                let medium =
                    MediumField::artist(colour, mfp, ArtistMap::new(inversion, InvertAt::DEFAULT))
                        .map_err(|e| invalid(e.to_string()))?;
                let mut t = Translucent::new(name, medium, anisotropy, eta);
                t.profile = Some(profile);
                Material::Translucent(t)
            }
        };
        validate_material(&material).map_err(|(k, msg)| invalid(format!("{k}: {msg}")))?;
        Ok(material)
    }

    /// The shape's `transform`, checked (once per shape, however many objects it makes).
    fn shape_transform(
        &self,
        common: &ShapeCommon,
        key: &str,
    ) -> Result<Option<Transform>, SceneError> {
        common
            .transform
            .as_ref()
            .map(|tf| self.transform(tf, &format!("{key}.transform")))
            .transpose()
    }

    /// Checks the shape's name is new, applies its transform and adds it to `out`.
    fn add_shape(
        &self,
        out: &mut Vec<ShapePlan>,
        names: &mut HashSet<String>,
        mut plan: ShapePlan,
        transform: Option<&Transform>,
    ) -> Result<(), SceneError> {
        if !names.insert(plan.name.clone()) {
            return Err(self.invalid(
                &format!("{}.name", plan.key),
                format!("duplicate shape name `{}`", plan.name),
            ));
        }
        if let Some(xf) = transform {
            plan.mesh.transform(xf);
        }
        out.push(plan);
        Ok(())
    }

    /// Loads a mesh file; a glTF file's external files (read within `scope`) are added to
    /// the scene's inputs.
    #[cfg_attr(not(feature = "gltf"), allow(unused_variables))]
    fn load_mesh(
        &self,
        kind: &str,
        path: &Path,
        scope: crate::geometry::gltf_assets::AssetScope,
    ) -> Result<TriangleMesh, crate::error::MeshError> {
        let file = path.display().to_string();
        match kind {
            #[cfg(feature = "obj")]
            "obj" => crate::geometry::obj::load_obj(path),
            #[cfg(feature = "gltf")]
            "gltf" => {
                let (mesh, files) = crate::geometry::gltf::load_gltf_with(path, scope)?;
                self.inputs.borrow_mut().extend(files);
                Ok(mesh)
            }
            #[cfg(feature = "ply")]
            "ply" => crate::geometry::ply::load_ply(path),
            _ => Err(crate::error::MeshError::Unsupported {
                file,
                format: match kind {
                    "obj" => "OBJ",
                    "gltf" => "glTF",
                    _ => "PLY",
                },
                feature: match kind {
                    "obj" => "obj",
                    "gltf" => "gltf",
                    _ => "ply",
                },
            }),
        }
    }

    fn transform(&self, d: &TransformDesc, key: &str) -> Result<Transform, SceneError> {
        let mut t = Transform::IDENTITY;
        if let Some(s) = d.scale {
            let s = DVec3::from(s.0);
            if !(s.is_finite() && s.abs().min_element() > 0.0) {
                return Err(self.invalid(
                    &format!("{key}.scale"),
                    format!("scale must be finite and non-zero, got {:?}", s.to_array()),
                ));
            }
            t.scale = s;
        }
        if let Some(r) = &d.rotate {
            let axis = DVec3::from(r.axis);
            if !(axis.is_finite() && axis.length() > 0.0 && r.degrees.is_finite()) {
                return Err(self.invalid(
                    &format!("{key}.rotate"),
                    "rotate needs a finite non-zero `axis` and finite `degrees`",
                ));
            }
            t.rotation = DQuat::from_axis_angle(axis.normalize(), r.degrees.to_radians());
        }
        if let Some(tr) = d.translate {
            let tr = DVec3::from(tr);
            if !tr.is_finite() {
                return Err(self.invalid(&format!("{key}.translate"), "translate must be finite"));
            }
            t.translation = tr;
        }
        Ok(t)
    }
}

/// A material after validation, before its textures are decoded.
#[allow(clippy::large_enum_variant)] // a few per scene, built once
enum MaterialPlan {
    Ready(Material),
    Diffuse {
        albedo: FieldSpec,
        roughness: Option<FieldSpec>,
        /// The material's key (`material[1]`), for messages.
        key: String,
    },
    Translucent {
        base: Translucent,
        /// σa, or the artist colour.
        sigma_a: FieldSpec,
        /// σs, or the artist radius.
        sigma_s: FieldSpec,
        /// For artist parameters: the radius scale and where estimators invert.
        artist: Option<(Rgb, InvertAt)>,
        /// The boundary's roughness.
        roughness: Option<FieldSpec>,
    },
}

/// A validated field; images are decoded later, only if used.
enum FieldSpec {
    Ready(Field),
    Image {
        texture: String,
        mapping: ImageMapping,
        wrap: Wrap,
        filter: Filter,
        scale: Rgb,
        key: String,
    },
}

/// A shape's material: named in the scene file, or read from the mesh file (glTF).
enum ShapeMaterial {
    Named(String),
    /// Only glTF files carry materials.
    #[cfg_attr(not(feature = "gltf"), allow(dead_code))]
    Built(Box<Material>),
}

impl ShapeMaterial {
    /// The material's name in messages (a built material carries its object's name).
    fn name<'a>(&'a self, object: &'a str) -> &'a str {
        match self {
            ShapeMaterial::Named(n) => n,
            ShapeMaterial::Built(_) => object,
        }
    }
}

struct ShapePlan {
    name: String,
    key: String,
    material: ShapeMaterial,
    mesh: TriangleMesh,
    source: String,
}
