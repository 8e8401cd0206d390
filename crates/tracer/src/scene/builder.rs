//! [`SceneBuilder`]: scenes made in code, and the final assembly shared with the TOML loader
//! (mesh preparation, quad-light geometry, BVH build).

use std::path::PathBuf;

use bssrdf_core::Rgb;
use bssrdf_core::error::{check_eta, check_g, check_sigma};

use super::locate::Locator;
use super::{Material, Object, RenderSettings, Scene, Translucent};
use crate::camera::Camera;
use crate::error::SceneError;
use crate::geometry::{Geometry, TriangleMesh, primitives};
use crate::light::Light;

/// Builds a [`Scene`] without a file (tests, the beam experiment).
///
/// ```
/// use tracer::scene::{SceneBuilder, RenderSettings, Material, Translucent};
/// use tracer::camera::Camera;
/// use tracer::light::Light;
/// use tracer::field::MediumField;
/// use tracer::geometry::primitives;
/// use het_estimate::Coefficients;
/// use bssrdf_core::Rgb;
/// use glam::DVec3;
///
/// let medium = MediumField::homogeneous(Coefficients::grey(0.01, 1.0)).unwrap();
/// let scene = SceneBuilder::new(
///     RenderSettings::new(64, 64, 4),
///     Camera::orthographic(DVec3::new(0.0, 0.0, 1.0), DVec3::NEG_Z, DVec3::Y, 30.0, 30.0, 64, 64)
///         .unwrap(),
/// )
/// .light(Light::beam(DVec3::new(0.0, 0.0, 1.0), DVec3::NEG_Z, Rgb::ONE).unwrap())
/// .object(
///     "slab",
///     primitives::half_space(0.0, [0.0, 0.0], 1000.0, 500.0, 32),
///     Material::Translucent(Translucent::new("slab", medium, 0.0, 1.0)),
/// )
/// .build()
/// .unwrap();
/// assert_eq!(scene.objects().len(), 1);
/// ```
#[derive(Debug, Clone)]
pub struct SceneBuilder {
    settings: RenderSettings,
    camera: Camera,
    lights: Vec<Light>,
    objects: Vec<(String, TriangleMesh, Material)>,
    name: String,
}

impl SceneBuilder {
    /// A scene with these settings and camera (their resolutions must agree).
    pub fn new(settings: RenderSettings, camera: Camera) -> Self {
        Self {
            settings,
            camera,
            lights: Vec::new(),
            objects: Vec::new(),
            name: "<builder scene>".into(),
        }
    }

    /// The name used in error messages (default `<builder scene>`).
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }

    /// Adds a light (a quad light also becomes an emissive object).
    pub fn light(mut self, light: Light) -> Self {
        self.lights.push(light);
        self
    }

    /// Adds an object (validated and oriented outward at build).
    pub fn object(
        mut self,
        name: impl Into<String>,
        mesh: TriangleMesh,
        material: Material,
    ) -> Self {
        self.objects.push((name.into(), mesh, material));
        self
    }

    /// Validates everything and builds the BVHs.
    pub fn build(self) -> Result<Scene, SceneError> {
        let file = PathBuf::from(&self.name);
        let invalid = |key: String, message: String| SceneError::Invalid {
            file: file.clone(),
            key,
            line: None,
            message,
        };
        validate_settings(&self.settings).map_err(|(k, m)| invalid(format!("render.{k}"), m))?;
        if self.camera.resolution() != (self.settings.width, self.settings.height) {
            return Err(invalid(
                "camera".into(),
                format!(
                    "camera resolution {:?} differs from the render settings {}x{}",
                    self.camera.resolution(),
                    self.settings.width,
                    self.settings.height
                ),
            ));
        }
        let mut pending = Vec::new();
        for (name, mesh, material) in self.objects {
            if pending.iter().any(|p: &PendingObject| p.name == name) {
                return Err(invalid(name, "duplicate object name".into()));
            }
            validate_material(&material).map_err(|(k, m)| invalid(format!("{name}.{k}"), m))?;
            pending.push(PendingObject {
                key: name.clone(),
                line: None,
                source: format!("<{name}>"),
                name,
                mesh,
                material,
            });
        }
        assemble(
            AssemblyInfo {
                file,
                display_name: self.name.clone(),
                source_path: None,
                locator: &Locator::empty(),
                inputs: Vec::new(),
                notes: Vec::new(),
            },
            self.settings,
            self.camera,
            self.lights,
            pending,
        )
    }
}

/// An object before mesh preparation.
pub(crate) struct PendingObject {
    pub name: String,
    pub key: String,
    pub line: Option<usize>,
    pub source: String,
    pub mesh: TriangleMesh,
    pub material: Material,
}

pub(crate) struct AssemblyInfo<'a> {
    pub file: PathBuf,
    pub display_name: String,
    pub source_path: Option<PathBuf>,
    pub locator: &'a Locator,
    pub inputs: Vec<PathBuf>,
    /// What the loader read but could not honour (glTF material notes), for the warnings.
    pub notes: Vec<super::LoadNote>,
}

/// Checks `[render]` values; `Err((key, message))`.
pub(crate) fn validate_settings(s: &RenderSettings) -> Result<(), (&'static str, String)> {
    for (k, v) in [("width", s.width), ("height", s.height), ("spp", s.spp)] {
        if v == 0 {
            return Err((k, format!("`{k}` must be at least 1, got 0")));
        }
    }
    if s.max_depth == Some(0) {
        return Err(("max_depth", "`max_depth` must be at least 1, got 0".into()));
    }
    Ok(())
}

fn rgb_ok(v: Rgb) -> bool {
    v.is_finite() && v.min_component() >= 0.0
}

/// Checks a material's values; `Err((key below the material, message))`.
pub(crate) fn validate_material(m: &Material) -> Result<(), (String, String)> {
    match m {
        Material::Translucent(t) => validate_translucent(t),
        Material::Diffuse(d) => {
            validate_albedo(&d.albedo)?;
            match &d.roughness {
                Some(r) => validate_roughness(r),
                None => Ok(()),
            }
        }
        Material::Emissive { radiance } => {
            if rgb_ok(*radiance) {
                Ok(())
            } else {
                Err((
                    "radiance".into(),
                    format!(
                        "radiance must be finite and non-negative, got {:?}",
                        radiance.0
                    ),
                ))
            }
        }
    }
}

/// Checks a diffuse `albedo` field: within [0, 1] everywhere.
pub(crate) fn validate_albedo(albedo: &crate::field::Field) -> Result<(), (String, String)> {
    let (lo, hi) = (albedo.min(), albedo.max());
    if !(rgb_ok(lo) && rgb_ok(hi) && hi.max_component() <= 1.0) {
        return Err((
            "albedo".into(),
            if albedo.is_constant() {
                format!("albedo must be in [0, 1], got {:?}", hi.0)
            } else {
                format!(
                    "albedo must be in [0, 1] everywhere, but it reaches {:?}",
                    hi.0
                )
            },
        ));
    }
    Ok(())
}

fn validate_translucent(t: &Translucent) -> Result<(), (String, String)> {
    validate_translucent_scalars(t.g, t.eta, t.unit_scale)?;
    if let Some(r) = &t.roughness {
        validate_roughness(r)?;
    }
    validate_medium(t)
}

/// Checks a `roughness` field: grey, and within [0, 1] everywhere (its values are already
/// finite and non-negative, as every field's).
pub(crate) fn validate_roughness(r: &crate::field::Field) -> Result<(), (String, String)> {
    let key = || "roughness".to_string();
    if !r.is_grey() {
        return Err((
            key(),
            "roughness is one number per point: give a number, a grey pattern, or a grey image \
             (with equal channels and a grey `scale`)"
                .into(),
        ));
    }
    let (lo, hi) = (r.min()[0], r.max()[0]);
    if !(lo >= 0.0 && hi <= 1.0) {
        return Err((
            key(),
            format!("roughness must lie in [0, 1], got values from {lo} to {hi}"),
        ));
    }
    Ok(())
}

/// Checks a translucent material's `g`, `eta` and `unit_scale` with the bounds every profile
/// and estimator accepts (`bssrdf_core::error`), so that no method can reject them later.
pub(crate) fn validate_translucent_scalars(
    g: f64,
    eta: f64,
    unit_scale: f64,
) -> Result<(), (String, String)> {
    check_g(g).map_err(|e| ("g".to_string(), format!("|g| must be < 1: {e}")))?;
    check_eta(eta).map_err(|e| {
        (
            "eta".to_string(),
            format!("eta (n_medium / n_outside): {e}"),
        )
    })?;
    if !(unit_scale.is_finite() && unit_scale > 0.0) {
        return Err((
            "unit_scale".into(),
            format!("unit_scale must be finite and positive, got {unit_scale}"),
        ));
    }
    Ok(())
}

/// Checks σa and σs everywhere (after `unit_scale`) against the bounds every profile accepts:
/// finite, ≥ 0 and ≤ 1e12 per scene unit (`bssrdf_core::error::check_sigma`). For an artist
/// medium, checks the bounds of the inverted σa and σs, and that its inversion was built for
/// the material's g and η.
pub(crate) fn validate_medium(t: &Translucent) -> Result<(), (String, String)> {
    let b = t.medium.field_bounds();
    let [(ka, _), (ks, _)] = t.medium.named_fields();
    for (k, name, lo, hi) in [
        (ka, "sigma_a", b.min.sigma_a, b.max.sigma_a),
        (ks, "sigma_s", b.min.sigma_s, b.max.sigma_s),
    ] {
        for v in lo.0.into_iter().chain(hi.0) {
            check_sigma(name, v).map_err(|e| {
                (
                    k.to_string(),
                    format!("{e} (per scene unit, after unit_scale)"),
                )
            })?;
        }
    }
    if let Some(map) = t.medium.artist_map() {
        let inv = map.inversion();
        let g =
            t.g.clamp(-bssrdf_core::family::G_MAX, bssrdf_core::family::G_MAX);
        if inv.eta() != t.eta || inv.g() != g {
            return Err((
                "subsurface_color".into(),
                format!(
                    "the colour inversion was built for g = {}, eta = {} but the material has g = {}, eta = {}",
                    inv.g(),
                    inv.eta(),
                    t.g,
                    t.eta
                ),
            ));
        }
    }
    Ok(())
}

/// Prepares every mesh, adds the quad lights' geometry and builds the BVHs.
pub(crate) fn assemble(
    info: AssemblyInfo<'_>,
    settings: RenderSettings,
    camera: Camera,
    mut lights: Vec<Light>,
    pending: Vec<PendingObject>,
) -> Result<Scene, SceneError> {
    let mut objects = Vec::with_capacity(pending.len());
    let mut meshes = Vec::with_capacity(pending.len());
    for p in pending {
        let mut mesh = p.mesh;
        let report = mesh.prepare(&p.source).map_err(|source| SceneError::Mesh {
            file: info.file.clone(),
            key: p.key.clone(),
            line: p.line,
            source: Box::new(source),
        })?;
        meshes.push(mesh);
        objects.push(Object {
            name: p.name,
            material: p.material,
            report,
            emitter: None,
            key: p.key,
            line: p.line,
            source: p.source,
        });
    }
    for (j, light) in lights.iter_mut().enumerate() {
        if let Light::Quad(q) = light {
            let mut mesh = primitives::quad(q.corner, q.edge_u, q.edge_v);
            let key = format!("light[{j}]");
            let report = mesh.prepare(&key).map_err(|source| SceneError::Mesh {
                file: info.file.clone(),
                key: key.clone(),
                line: info.locator.line_of_key(&key),
                source: Box::new(source),
            })?;
            q.object = Some(objects.len() as u32);
            meshes.push(mesh);
            objects.push(Object {
                name: key.clone(),
                material: Material::Emissive {
                    radiance: q.radiance,
                },
                report,
                emitter: Some(j),
                line: info.locator.line_of_key(&key),
                key,
                source: "<quad light>".into(),
            });
        }
    }
    let scene = Scene {
        camera,
        lights,
        objects,
        geometry: Geometry::build(meshes),
        settings,
        source_path: info.source_path,
        display_name: info.display_name,
        inputs: info.inputs,
        notes: info.notes,
    };
    scene.require_disjoint_media()?;
    Ok(scene)
}
