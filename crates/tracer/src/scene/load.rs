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
    AssemblyInfo, PendingObject, assemble, validate_albedo, validate_material, validate_medium,
    validate_roughness, validate_settings, validate_translucent_scalars,
};
use super::desc::*;
use super::locate::Locator;
use super::{Diffuse, Material, RenderSettings, Scene, Translucent};
use crate::camera::{Camera, CameraError};
use crate::error::{FieldError, SceneError};
use crate::field::{ArtistMap, Field, Filter, ImageMapping, InvertAt, MediumField, Texture, Wrap};
use crate::geometry::{Transform, TriangleMesh};
use crate::light::{Light, LightDesc};

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

    /// The description of kind `type` at `key` ([`Tagged`]): an unknown kind is an error
    /// listing the kinds.
    fn tagged<T: Tagged>(&self, v: &Val<'_>, key: &str) -> Result<T, SceneError> {
        let expected = T::KINDS
            .iter()
            .map(|k| format!("\"{k}\""))
            .collect::<Vec<_>>()
            .join(" | ");
        let kind = self.type_of(v, key, &expected)?;
        T::from_kind(kind, ValueDeserializer::from(v.clone()))
            .ok_or_else(|| {
                self.parse_msg(
                    &format!("{key}.type"),
                    format!("unknown {} type `{kind}`, expected {expected}", T::WHAT),
                )
            })?
            .map_err(|e| self.parse_err(e, key))
    }

    /// A description's error at `key`: its own key below `key`, or `key` itself.
    fn desc_error(&self, key: &str, e: DescError) -> SceneError {
        match e.key {
            Some(sub) => self.invalid(&format!("{key}.{sub}"), e.message),
            None => self.invalid(key, e.message),
        }
    }

    /// The image at `rel` (relative to the scene file), named by `key`: checked readable,
    /// recorded as an input, decoded.
    fn read_texture(&self, key: &str, rel: &str, linear: bool) -> Result<Texture, SceneError> {
        let path = self.resolve(rel);
        self.check_readable(key, &path)?;
        Texture::load(&path, linear).map_err(|source| SceneError::Texture {
            file: self.file.clone(),
            line: self.loc.line_of_key(key),
            key: key.to_string(),
            source: Box::new(source),
        })
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
        let pending = self.objects(shapes, &materials, &textures)?;
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

    /// The shapes with their materials, building the materials some shape uses (decoding only
    /// their textures, each once).
    fn objects(
        &self,
        shapes: Vec<ShapePlan>,
        materials: &HashMap<String, MaterialPlan>,
        textures: &Textures,
    ) -> Result<Vec<PendingObject>, SceneError> {
        let mut decoded: HashMap<String, Arc<Texture>> = HashMap::new();
        let mut built: HashMap<String, Material> = HashMap::new();
        let mut pending = Vec::with_capacity(shapes.len());
        for s in shapes {
            let material = match &s.material {
                ShapeMaterial::Built(m) => (**m).clone(),
                ShapeMaterial::Named(name) => match built.get(name) {
                    Some(m) => m.clone(),
                    None => {
                        let m = self.realize(&materials[name], textures, &mut decoded)?;
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
        Ok(pending)
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
        let (cam, fov_key) = match self.tagged(v, "camera")? {
            CameraDesc::Perspective(d) => (
                Camera::perspective(
                    d.eye.into(),
                    d.target.into(),
                    d.up.into(),
                    d.fov_y,
                    s.width,
                    s.height,
                ),
                "camera.fov_y",
            ),
            CameraDesc::Orthographic(d) => (
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
            ),
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

    fn textures(&self, t: &DeTable<'_>) -> Result<Textures, SceneError> {
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
        textures: &Textures,
    ) -> Result<HashMap<String, MaterialPlan>, SceneError> {
        let mut out = HashMap::new();
        for (key, v) in self.elements(t, "material")? {
            let d: MaterialDesc = self.tagged(v, &key)?;
            let plan = match &d {
                MaterialDesc::Translucent(d) => self.translucent_plan(d, &key, textures)?,
                MaterialDesc::Diffuse(d) => self.diffuse_plan(d, &key, textures)?,
            };
            if out.contains_key(d.name()) {
                return Err(self.invalid(
                    &format!("{key}.name"),
                    format!("duplicate material name `{}`", d.name()),
                ));
            }
            out.insert(d.name().to_string(), plan);
        }
        Ok(out)
    }

    /// A diffuse material's plan; its constant fields are checked now (unused materials too),
    /// its images when they are decoded.
    fn diffuse_plan(
        &self,
        d: &DiffuseDesc,
        key: &str,
        textures: &Textures,
    ) -> Result<MaterialPlan, SceneError> {
        let albedo = self.field_spec(&d.albedo, &format!("{key}.albedo"), textures)?;
        let roughness = d
            .roughness
            .as_ref()
            .map(|r| self.field_spec(r, &format!("{key}.roughness"), textures))
            .transpose()?;
        let checked = |r: Result<(), (String, String)>| {
            r.map_err(|(k, msg)| self.invalid(&format!("{key}.{k}"), msg))
        };
        if let FieldSpec::Ready(f) = &albedo {
            checked(validate_albedo(f))?;
        }
        if let Some(FieldSpec::Ready(r)) = &roughness {
            checked(validate_roughness(r))?;
        }
        Ok(MaterialPlan::Diffuse {
            albedo,
            roughness,
            key: key.to_string(),
        })
    }

    /// Validates a field description without decoding images.
    fn field_spec(
        &self,
        d: &FieldDesc,
        key: &str,
        textures: &Textures,
    ) -> Result<FieldSpec, SceneError> {
        let typed = match d {
            FieldDesc::Constant(v) => TypedField::Constant(*v),
            FieldDesc::Table(t) => {
                TypedField::try_from((**t).clone()).map_err(|e| self.desc_error(key, e))?
            }
        };
        let rgb2 = |v: [RgbDesc; 2]| [Rgb(v[0].0), Rgb(v[1].0)];
        let field = match typed {
            TypedField::Constant(v) => Field::constant(Rgb(v.0)),
            TypedField::Stripe(s) => Field::stripe(
                s.width,
                s.angle.to_radians(),
                rgb2(s.values),
                s.projection.into(),
            ),
            TypedField::Check(c) => Field::check(c.width, rgb2(c.values), c.projection.into()),
            TypedField::Image(i) => return self.image_spec(i, key, textures),
        };
        field
            .map(FieldSpec::Ready)
            .map_err(|e: FieldError| self.invalid(key, e.to_string()))
    }

    /// An image field, checked: its texture is defined, its size and scale are valid.
    fn image_spec(
        &self,
        d: ImageDesc,
        key: &str,
        textures: &Textures,
    ) -> Result<FieldSpec, SceneError> {
        if !textures.contains_key(&d.texture) {
            let mut known: Vec<&String> = textures.keys().collect();
            known.sort();
            return Err(self.invalid(
                &format!("{key}.texture"),
                format!("unknown texture `{}` (defined: {known:?})", d.texture),
            ));
        }
        let mapping = match d.mapping {
            ImageMappingDesc::Uv => ImageMapping::Uv,
            ImageMappingDesc::Planar { projection, size } => {
                for (i, s) in size.iter().enumerate() {
                    if !(s.is_finite() && *s > 0.0) {
                        return Err(self.invalid(
                            &format!("{key}.size"),
                            format!("size[{i}] must be finite and positive, got {s}"),
                        ));
                    }
                }
                ImageMapping::Planar {
                    projection: projection.into(),
                    size,
                }
            }
        };
        let scale = Rgb(d.scale.0);
        if !(scale.is_finite() && scale.min_component() >= 0.0) {
            return Err(self.invalid(
                &format!("{key}.scale"),
                format!("scale must be finite and non-negative, got {:?}", scale.0),
            ));
        }
        Ok(FieldSpec::Image {
            texture: d.texture,
            mapping,
            wrap: d.wrap.into(),
            filter: d.filter.into(),
            scale,
            key: key.to_string(),
        })
    }

    /// A translucent material's scalar keys, checked with the bounds every profile and
    /// estimator accepts (so that unused materials are checked too).
    fn translucent_scalars(
        &self,
        d: &TranslucentDesc,
        key: &str,
    ) -> Result<TranslucentScalars, SceneError> {
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
        validate_translucent_scalars(g, d.eta, d.unit_scale)
            .map_err(|(k, m)| self.invalid(&format!("{key}.{k}"), m))?;
        Ok(TranslucentScalars {
            name: d.name.clone(),
            g,
            eta: d.eta,
            profile,
            thickness_aware: d.thickness_aware.unwrap_or(true),
            shape_correction: d.shape_correction,
            correction_seed: d
                .shape_correction_seed
                .unwrap_or(Translucent::DEFAULT_CORRECTION_SEED),
            angular_coupling: d.angular_coupling.unwrap_or(true),
            oblique_shape: d.oblique_shape.unwrap_or(true),
            unit_scale: d.unit_scale,
            key: key.to_string(),
            line: self.loc.line_of_key(key),
        })
    }

    /// A translucent material's plan: σa and σs, or the artist parameters (a constant zero
    /// radius with a constant colour becomes a diffuse surface of that colour).
    fn translucent_plan(
        &self,
        d: &TranslucentDesc,
        key: &str,
        textures: &Textures,
    ) -> Result<MaterialPlan, SceneError> {
        let scalars = self.translucent_scalars(d, key)?;
        let field =
            |f: &FieldDesc, name: &str| self.field_spec(f, &format!("{key}.{name}"), textures);
        let roughness = d
            .roughness
            .as_ref()
            .map(|r| field(r, "roughness"))
            .transpose()?;
        if let Some(FieldSpec::Ready(r)) = &roughness {
            validate_roughness(r).map_err(|(k, m)| self.invalid(&format!("{key}.{k}"), m))?;
        }
        let artist_keys = d.subsurface_color.is_some()
            || d.subsurface_radius.is_some()
            || d.radius_scale.is_some()
            || d.invert.is_some();
        let medium = match (
            &d.sigma_a,
            &d.sigma_s,
            &d.subsurface_color,
            &d.subsurface_radius,
        ) {
            (Some(a), Some(s), None, None) if !artist_keys => MediumPlan::Coefficients {
                sigma_a: field(a, "sigma_a")?,
                sigma_s: field(s, "sigma_s")?,
            },
            (None, None, Some(c), Some(r)) => {
                match self.artist_plan(d, key, [c, r], textures, roughness.is_some())? {
                    Ok(m) => m,
                    Err(diffuse) => return Ok(MaterialPlan::Ready(diffuse)),
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
        Ok(MaterialPlan::Translucent {
            scalars,
            medium,
            roughness,
        })
    }

    /// The artist parameters' medium (`[colour, radius]`: their fields), checked; or `Err`
    /// the diffuse material that a constant zero radius makes of a constant colour (which
    /// takes no `roughness`: `rough`).
    fn artist_plan(
        &self,
        d: &TranslucentDesc,
        key: &str,
        [colour, radius]: [&FieldDesc; 2],
        textures: &Textures,
        rough: bool,
    ) -> Result<Result<MediumPlan, Material>, SceneError> {
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
        let colour = self.field_spec(colour, &format!("{key}.subsurface_color"), textures)?;
        let radius = self.field_spec(radius, &format!("{key}.subsurface_radius"), textures)?;
        if let FieldSpec::Ready(Field::Constant(cv)) = &colour
            && cv.max_component() > 1.0
        {
            return Err(self.invalid(
                &format!("{key}.subsurface_color"),
                format!("subsurface_color must lie in [0, 1], got {:?}", cv.0),
            ));
        }
        let FieldSpec::Ready(Field::Constant(rv)) = &radius else {
            return Ok(Ok(MediumPlan::Artist {
                colour,
                radius,
                scale,
                invert,
            }));
        };
        if !(*rv * scale).is_zero() {
            return Ok(Ok(MediumPlan::Artist {
                colour,
                radius,
                scale,
                invert,
            }));
        }
        // No distance to travel: a diffuse surface of the colour.
        let FieldSpec::Ready(Field::Constant(cv)) = colour else {
            return Err(self.invalid(
                &format!("{key}.subsurface_radius"),
                "a zero subsurface_radius makes a diffuse surface, which needs a constant subsurface_color",
            ));
        };
        if rough {
            return Err(self.invalid(
                &format!("{key}.roughness"),
                "a zero subsurface_radius makes a diffuse surface, which has no \
                 dielectric boundary to be rough: use a `diffuse` material and its \
                 `roughness`",
            ));
        }
        Ok(Err(Material::diffuse(cv)))
    }

    /// Builds a material, decoding the textures it uses (once per texture).
    fn realize(
        &self,
        plan: &MaterialPlan,
        textures: &Textures,
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
                scalars,
                medium,
                roughness,
            } => self.realize_translucent(scalars, medium, roughness.as_ref(), textures, decoded),
        }
    }

    /// Builds a translucent material: its roughness and medium, decoding their textures.
    fn realize_translucent(
        &self,
        s: &TranslucentScalars,
        medium: &MediumPlan,
        roughness: Option<&FieldSpec>,
        textures: &Textures,
        decoded: &mut HashMap<String, Arc<Texture>>,
    ) -> Result<Material, SceneError> {
        let key = |sub: &str| format!("{}.{sub}", s.key);
        // σa and σs (or the colour and radius) first: their textures are decoded, and listed
        // among the scene's inputs, before the roughness's.
        let (a, b) = match medium {
            MediumPlan::Coefficients { sigma_a, sigma_s } => (sigma_a, sigma_s),
            MediumPlan::Artist { colour, radius, .. } => (colour, radius),
        };
        let a = self.realize_field(a, textures, decoded)?;
        let b = self.realize_field(b, textures, decoded)?;
        let roughness = match roughness {
            None => None,
            Some(r) => {
                let r = self.realize_field(r, textures, decoded)?;
                validate_roughness(&r).map_err(|(k, m)| self.invalid(&key(&k), m))?;
                Some(r)
            }
        };
        let medium = match medium {
            MediumPlan::Coefficients { .. } => MediumField::new(a, b).scaled(s.unit_scale),
            MediumPlan::Artist { scale, invert, .. } => {
                let model = s.profile.unwrap_or(ProfileModel::default_for(s.eta));
                let inversion = AlbedoInversion::shared(model, s.g, s.eta)
                    .map_err(|e| self.invalid(&key("profile"), e.to_string()))?;
                MediumField::artist(
                    a,
                    b.scaled_rgb(*scale * (1.0 / s.unit_scale)),
                    ArtistMap::new(inversion, *invert),
                )
                .map_err(|e| self.invalid(&key("subsurface_color"), e.to_string()))?
            }
        };
        let t = s.clone().into_translucent(medium, roughness);
        validate_medium(&t).map_err(|(k, m)| self.invalid(&key(&k), m))?;
        Ok(Material::Translucent(t))
    }

    fn realize_field(
        &self,
        spec: &FieldSpec,
        textures: &Textures,
        decoded: &mut HashMap<String, Arc<Texture>>,
    ) -> Result<Field, SceneError> {
        let (texture, mapping, wrap, filter, scale, key) = match spec {
            FieldSpec::Ready(f) => return Ok(f.clone()),
            FieldSpec::Image {
                texture,
                mapping,
                wrap,
                filter,
                scale,
                key,
            } => (texture, mapping, wrap, filter, scale, key),
        };
        let tex = match decoded.get(texture) {
            Some(t) => t.clone(),
            None => {
                let (tkey, desc) = &textures[texture];
                let t = self.read_texture(&format!("{tkey}.path"), &desc.path, desc.linear)?;
                let t = Arc::new(t);
                decoded.insert(texture.clone(), t.clone());
                t
            }
        };
        Field::image(tex, *mapping, *wrap, *filter, *scale)
            .map_err(|e| self.invalid(key, e.to_string()))
    }

    fn lights(&self, t: &DeTable<'_>) -> Result<Vec<Light>, SceneError> {
        let mut out = Vec::new();
        for (key, v) in self.elements(t, "light")? {
            let d: LightDesc = self.tagged(v, &key)?;
            out.push(d.build(&At {
                cx: self,
                key: &key,
            })?);
        }
        Ok(out)
    }

    fn shapes(
        &self,
        t: &DeTable<'_>,
        materials: &HashMap<String, MaterialPlan>,
    ) -> Result<Vec<ShapePlan>, SceneError> {
        let mut descs = Vec::new();
        // The primitives' triangles, counted before any is generated; the limits are read
        // once (a check per shape read them 100,000 times for as many boxes).
        let room = crate::memory::headroom();
        let mut tessellated = 0.0;
        for (key, v) in self.elements(t, "shape")? {
            let d: ShapeDesc = self.tagged(v, &key)?;
            if let Some(added) = d.tessellated_triangles() {
                tessellated += added;
                self.check_tessellation(room, tessellated, &format!("{key}.subdivisions"))?;
            }
            descs.push((key, d));
        }
        let mut out = ShapeList::default();
        for (i, (key, d)) in descs.into_iter().enumerate() {
            let common = d.common();
            let primitive = |m: Result<TriangleMesh, DescError>, source: &str| {
                m.map(|m| (m, source.to_string()))
                    .map_err(|e| self.desc_error(&key, e))
            };
            let (mesh, source) = match &d {
                ShapeDesc::Box(b) => primitive(TriangleMesh::try_from(b), "<box>")?,
                ShapeDesc::Sphere(s) => primitive(TriangleMesh::try_from(s), "<sphere>")?,
                ShapeDesc::HalfSpace(h) => primitive(TriangleMesh::try_from(h), "<half_space>")?,
                ShapeDesc::Obj(m) => self.mesh_file(MeshKind::Obj, m, &key)?,
                ShapeDesc::Ply(m) => self.mesh_file(MeshKind::Ply, m, &key)?,
                #[cfg(feature = "gltf")]
                ShapeDesc::Gltf(m) if m.material.is_none() => {
                    self.gltf_parts(m, i, &key, &mut out)?;
                    continue;
                }
                ShapeDesc::Gltf(m) => self.mesh_file(MeshKind::Gltf, m, &key)?,
            };
            let material = self.shape_material(&common, &key, materials)?;
            let name = common.name.clone().unwrap_or_else(|| format!("shape[{i}]"));
            let xf = self.shape_transform(&common, &key)?;
            out.add(
                self,
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
        Ok(out.plans)
    }

    /// The material a shape names: given, and defined.
    fn shape_material(
        &self,
        common: &ShapeCommon,
        key: &str,
        materials: &HashMap<String, MaterialPlan>,
    ) -> Result<String, SceneError> {
        let Some(material) = common.material.clone() else {
            return Err(self.invalid(
                &format!("{key}.material"),
                "missing `material` (only a glTF shape may leave it out, to use the \
                 file's materials)",
            ));
        };
        if !materials.contains_key(&material) {
            let mut known: Vec<&String> = materials.keys().collect();
            known.sort();
            return Err(self.invalid(
                &format!("{key}.material"),
                format!("unknown material `{material}` (defined: {known:?})"),
            ));
        }
        Ok(material)
    }

    /// A mesh file shape's keys checked, and its file: where glTF reads its assets from, and
    /// the path (existing and readable; `if_missing` tells how to get it).
    fn mesh_path(
        &self,
        kind: MeshKind,
        d: &MeshFileDesc,
        key: &str,
    ) -> Result<(PathBuf, crate::geometry::gltf_assets::AssetScope), SceneError> {
        let k = |sub: &str| format!("{key}.{sub}");
        let correction = (d.shape_correction, d.shape_correction_seed);
        if (correction.0.is_some() || correction.1.is_some())
            && (kind != MeshKind::Gltf || d.material.is_some())
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
        if d.allow_outside_assets.is_some() && kind != MeshKind::Gltf {
            return Err(self.invalid(
                &k("allow_outside_assets"),
                "only a glTF shape reads external files by URI",
            ));
        }
        let scope = if d.allow_outside_assets.unwrap_or(false) || self.options.allow_outside_assets
        {
            crate::geometry::gltf_assets::AssetScope::Anywhere
        } else {
            crate::geometry::gltf_assets::AssetScope::ModelFolder
        };
        let path = self.resolve(&d.path);
        if let Some(hint) = &d.if_missing
            && !path.exists()
        {
            return Err(self.invalid(
                &k("path"),
                format!("the mesh `{}` does not exist: {hint}", path.display()),
            ));
        }
        self.check_readable(&k("path"), &path)?;
        Ok((path, scope))
    }

    /// A mesh file's error, at the shape's `path`.
    fn mesh_error(&self, key: &str, source: crate::error::MeshError) -> SceneError {
        let key = format!("{key}.path");
        SceneError::Mesh {
            file: self.file.clone(),
            line: self.loc.line_of_key(&key),
            key,
            source: Box::new(source),
        }
    }

    /// The mesh of an `obj`, `ply` or `gltf` shape (with a `material`), and its source.
    fn mesh_file(
        &self,
        kind: MeshKind,
        d: &MeshFileDesc,
        key: &str,
    ) -> Result<(TriangleMesh, String), SceneError> {
        let (path, scope) = self.mesh_path(kind, d, key)?;
        let mesh = self
            .load_mesh(kind, &path, scope)
            .map_err(|e| self.mesh_error(key, e))?;
        Ok((mesh, path.display().to_string()))
    }

    /// A glTF shape without `material`: one object per material of the file, each with the
    /// file's material.
    #[cfg(feature = "gltf")]
    fn gltf_parts(
        &self,
        d: &MeshFileDesc,
        i: usize,
        key: &str,
        out: &mut ShapeList,
    ) -> Result<(), SceneError> {
        let (path, scope) = self.mesh_path(MeshKind::Gltf, d, key)?;
        let mut model = crate::geometry::gltf::load_gltf_parts_with(&path, scope)
            .map_err(|e| self.mesh_error(key, e))?;
        self.inputs
            .borrow_mut()
            .extend_from_slice(model.files_read());
        let common = d.common();
        let shape = common.name.clone().unwrap_or_else(|| format!("shape[{i}]"));
        let xf = self.shape_transform(&common, key)?;
        let scale = xf.map_or(DVec3::ONE, |t| t.scale);
        // Materials that share an image decode it once.
        let mut images = HashMap::new();
        for part in std::mem::take(&mut model.parts) {
            let name = format!("{shape}/{}", part.material.name);
            let mut material =
                self.gltf_material(&model, &part.material, &mut images, &name, key, scale)?;
            if let Material::Translucent(t) = &mut material {
                if let Some(on) = d.shape_correction {
                    t.shape_correction = Some(on);
                }
                if let Some(seed) = d.shape_correction_seed {
                    t.correction_seed = seed;
                }
            }
            out.add(
                self,
                ShapePlan {
                    name,
                    key: key.to_string(),
                    material: ShapeMaterial::Built(Box::new(material)),
                    mesh: part.mesh,
                    source: path.display().to_string(),
                },
                xf.as_ref(),
            )?;
        }
        Ok(())
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
                let colour = self
                    .gltf_colour(model, colour, images, &field_key)?
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

    /// A glTF material's subsurface colour: constant, or its image (decoded once per image,
    /// named in errors by `field_key`).
    #[cfg(feature = "gltf")]
    fn gltf_colour(
        &self,
        model: &crate::geometry::gltf::GltfModel,
        colour: crate::geometry::gltf_material::GltfColour,
        images: &mut HashMap<usize, Arc<Texture>>,
        field_key: &str,
    ) -> Result<Result<Field, FieldError>, SceneError> {
        use crate::geometry::gltf_material::GltfColour;
        let (factor, texture) = match colour {
            GltfColour::Constant(c) => return Ok(Field::constant(Rgb(c))),
            GltfColour::Texture { factor, texture } => (factor, texture),
        };
        let tex = match images.get(&texture.image) {
            Some(t) => t.clone(),
            None => {
                if let Some(file) = model.image_file(texture.image) {
                    self.inputs.borrow_mut().push(file.to_path_buf());
                }
                let t =
                    model
                        .decode_image(texture.image)
                        .map_err(|source| SceneError::Texture {
                            file: self.file.clone(),
                            line: self.loc.line_of_key(field_key),
                            key: field_key.to_string(),
                            source: Box::new(source),
                        })?;
                let t = Arc::new(t);
                images.insert(texture.image, t.clone());
                t
            }
        };
        Ok(Field::image(
            tex,
            ImageMapping::Uv,
            texture.wrap,
            Filter::Bilinear,
            Rgb(factor),
        ))
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

    /// Loads a mesh file; a glTF file's external files (read within `scope`) are added to
    /// the scene's inputs.
    #[cfg_attr(not(feature = "gltf"), allow(unused_variables))]
    fn load_mesh(
        &self,
        kind: MeshKind,
        path: &Path,
        scope: crate::geometry::gltf_assets::AssetScope,
    ) -> Result<TriangleMesh, crate::error::MeshError> {
        let file = path.display().to_string();
        match kind {
            #[cfg(feature = "obj")]
            MeshKind::Obj => crate::geometry::obj::load_obj(path),
            #[cfg(feature = "gltf")]
            MeshKind::Gltf => {
                let (mesh, files) = crate::geometry::gltf::load_gltf_with(path, scope)?;
                self.inputs.borrow_mut().extend(files);
                Ok(mesh)
            }
            #[cfg(feature = "ply")]
            MeshKind::Ply => crate::geometry::ply::load_ply(path),
            #[allow(unreachable_patterns)] // with every mesh feature on
            _ => Err(crate::error::MeshError::Unsupported {
                file,
                format: match kind {
                    MeshKind::Obj => "OBJ",
                    MeshKind::Gltf => "glTF",
                    MeshKind::Ply => "PLY",
                },
                feature: match kind {
                    MeshKind::Obj => "obj",
                    MeshKind::Gltf => "gltf",
                    MeshKind::Ply => "ply",
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

/// The textures by name, with their keys (`texture[0]`).
type Textures = HashMap<String, (String, TextureDesc)>;

/// A description's place in the file, for the conversions that read files and name keys
/// ([`DescContext`]).
struct At<'a> {
    cx: &'a Cx,
    /// The description's key (`light[2]`).
    key: &'a str,
}

impl At<'_> {
    fn key(&self, sub: &str) -> String {
        if sub.is_empty() {
            self.key.to_string()
        } else {
            format!("{}.{sub}", self.key)
        }
    }
}

impl DescContext for At<'_> {
    fn invalid(&self, sub: &str, message: String) -> SceneError {
        self.cx.invalid(&self.key(sub), message)
    }

    fn texture(&self, sub: &str, rel: &str, linear: bool) -> Result<Texture, SceneError> {
        self.cx.read_texture(&self.key(sub), rel, linear)
    }
}

/// The kinds of mesh files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum MeshKind {
    Obj,
    Gltf,
    Ply,
}

/// A material after validation, before its textures are decoded.
enum MaterialPlan {
    Ready(Material),
    Diffuse {
        albedo: FieldSpec,
        roughness: Option<FieldSpec>,
        /// The material's key (`material[1]`), for messages.
        key: String,
    },
    Translucent {
        scalars: TranslucentScalars,
        medium: MediumPlan,
        /// The boundary's roughness.
        roughness: Option<FieldSpec>,
    },
}

/// A translucent material's medium before its textures are decoded.
enum MediumPlan {
    /// σa and σs (per file unit).
    Coefficients {
        sigma_a: FieldSpec,
        sigma_s: FieldSpec,
    },
    /// The artist parameters.
    Artist {
        /// The subsurface colour, in [0, 1].
        colour: FieldSpec,
        /// The mean free path per channel (file units).
        radius: FieldSpec,
        /// `radius_scale`.
        scale: Rgb,
        /// Where the estimators invert the colour.
        invert: InvertAt,
    },
}

/// A translucent material's values besides its medium and roughness, checked: the
/// [`Translucent`] they make once the medium is built.
#[derive(Debug, Clone)]
struct TranslucentScalars {
    name: String,
    g: f64,
    eta: f64,
    profile: Option<ProfileModel>,
    thickness_aware: bool,
    shape_correction: Option<bool>,
    correction_seed: u64,
    angular_coupling: bool,
    oblique_shape: bool,
    unit_scale: f64,
    key: String,
    line: Option<usize>,
}

impl TranslucentScalars {
    /// The material with `medium` (per scene unit) and `roughness`.
    fn into_translucent(self, medium: MediumField, roughness: Option<Field>) -> Translucent {
        Translucent {
            name: self.name,
            medium,
            g: self.g,
            eta: self.eta,
            profile: self.profile,
            thickness_aware: self.thickness_aware,
            shape_correction: self.shape_correction,
            correction_seed: self.correction_seed,
            angular_coupling: self.angular_coupling,
            oblique_shape: self.oblique_shape,
            unit_scale: self.unit_scale,
            roughness,
            key: self.key,
            line: self.line,
        }
    }
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

/// The shapes' objects so far, and their names.
#[derive(Default)]
struct ShapeList {
    plans: Vec<ShapePlan>,
    names: HashSet<String>,
}

impl ShapeList {
    /// Checks the object's name is new, applies its shape's transform and adds it.
    fn add(
        &mut self,
        cx: &Cx,
        mut plan: ShapePlan,
        transform: Option<&Transform>,
    ) -> Result<(), SceneError> {
        if !self.names.insert(plan.name.clone()) {
            return Err(cx.invalid(
                &format!("{}.name", plan.key),
                format!("duplicate shape name `{}`", plan.name),
            ));
        }
        if let Some(xf) = transform {
            plan.mesh.transform(xf);
        }
        self.plans.push(plan);
        Ok(())
    }
}
