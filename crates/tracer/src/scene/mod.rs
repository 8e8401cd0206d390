//! Scenes: the validated runtime form ([`Scene`]), loading from TOML ([`Scene::load`]), and a
//! programmatic [`SceneBuilder`] for tests and experiments.
//!
//! # File format (TOML)
//! Units are explicit: lengths in scene units, angles in degrees, coefficients in 1/scene-unit
//! (after `unit_scale`), colours as a number (grey) or `[r, g, b]` (linear). Unknown keys are
//! errors; every error names the file, the key path (`material[1].sigma_a.width`) and the line.
//! Every key, with its type, default, units and an example, is in `docs/scene-format.md`.
//!
//! * `[render]`: `width`, `height`, `spp` (all ≥ 1), `seed` (default 0), optional `max_depth`,
//!   `estimator` (a name the renderer parses), `averaging` (`prefiltered | monte-carlo`),
//!   `scattering` (`multiple | single | all`; a render counts `all` when it is not given).
//! * `[camera]`: `type = "perspective"` with `eye`, `target`, `up`, `fov_y` (degrees, full
//!   vertical), or `type = "orthographic"` with `centre`, `direction` (view direction; rays start
//!   on the plane through `centre`), `up`, `width`, `height` (of the view rectangle).
//! * `[[texture]]`: `name`, `path` (relative to the scene file), `linear` (default false: 8/16-bit
//!   images hold sRGB colours; EXR is always linear). A texture is decoded only if a material
//!   used by some shape refers to it.
//! * `[[material]]`: `type = "translucent"` with `name`, `sigma_a`, `sigma_s` (fields, see
//!   below), `g` (default 0, |g| < 1), `eta` (default 1, ≥ 1), optional `profile`
//!   (`dipole | pbd | better-dipole | tabulated`; default tabulated where η ≤ 1.6, else pbd), `unit_scale` (default 1: file coefficients × unit_scale =
//!   1/scene-unit). Instead of `sigma_a` and `sigma_s`, a translucent material may give the
//!   artist parameters `subsurface_color` (field, in [0, 1]) and `subsurface_radius` (field,
//!   mean free path per channel in file units), with optional `radius_scale` (RGB, default 1)
//!   and `invert = "before" | "after"`; `anisotropy` is another name for `g`
//!   (`docs/artist-parameters.md`, [`crate::field::MediumField::artist`]). A translucent
//!   material's optional `roughness` (a grey field in [0, 1], default 0: smooth) makes its
//!   boundary a GGX microfacet dielectric of α = roughness² ([`Translucent::roughness`]). Or
//!   `type = "diffuse"` with `name`, `albedo` (a field in [0, 1]) and an optional Oren–Nayar
//!   `roughness` (a grey field in [0, 1], default 0: Lambertian; [`Diffuse`]). Unused
//!   materials are validated but their textures are not decoded
//!   (`docs/lighting-and-surfaces.md`).
//! * Fields: a number or `[r, g, b]` (constant), or a table with `type`:
//!   `constant` (`value`); `stripe` (`width`, `angle` in degrees, `values = [v0, v1]`, `axis`,
//!   `origin`); `check` (`width`, `values`, `axis`, `origin`); `image` (`texture`, `mapping =
//!   "planar" | "uv"`, `axis`, `origin`, `size = [W, H]` for planar, `wrap = "repeat" | "clamp"`,
//!   `filter = "bilinear" | "nearest"`, `scale`). See [`crate::field`] for the projection.
//! * `[[light]]`: `directional` (`direction` it travels, `irradiance`), `point` (`position`,
//!   `intensity`), `quad` (`corner`, `edge_u`, `edge_v`, `radiance`; emits on the side of
//!   edge_u × edge_v and becomes an emissive object), `environment` (`radiance`, or an
//!   equirectangular `.exr` or Radiance `.hdr` image `filename` with `scale` (RGB, default 1),
//!   `rotation` (degrees about the map's up axis, default 0) and `up` (`"x" | "y" | "z"`,
//!   default z): [`crate::light::EnvironmentMap`]), `beam` (`origin`, `direction`, `power`).
//! * `[[shape]]`: `box` (`min`, `max`), `sphere` (`centre`, `radius`, `subdivisions`),
//!   `half_space` (`top`, `centre`, `size`, `depth`, `subdivisions`), `obj`, `gltf`, `ply`
//!   (`path`, and `if_missing`: what to tell the user when the file does not exist; glTF also
//!   `allow_outside_assets`, `shape_correction`, `shape_correction_seed`); each with
//!   `material`, optional `name` and `transform = { scale, rotate = { axis, degrees },
//!   translate }`.
//!
//! Translucent objects must not overlap one another (one inside the other, or crossing): the
//! path tracer has no nested media, so such scenes are refused when built, naming both objects
//! ([`Scene::require_disjoint_media`]). Opaque objects may lie inside or cross a translucent one.

mod builder;
mod load;
mod locate;
mod overlap;
mod shape;

pub mod desc;

pub use builder::SceneBuilder;
pub use load::LoadOptions;

use std::path::{Path, PathBuf};

use crate::camera::CameraError;

use bssrdf_core::{ParamError, ProfileFamily, ProfileModel, Rgb, Scattering};
use glam::DVec3;
use het_estimate::{Estimator, PreparedEstimator};

use crate::camera::Camera;
use crate::error::SceneError;
use crate::field::{Field, MediumField};
use crate::geometry::{Geometry, MeshReport, ObjectSurface};
use crate::light::{BeamLight, Light};

/// Render settings from `[render]`.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels (≥ 1).
    pub width: u32,
    /// Image height in pixels (≥ 1).
    pub height: u32,
    /// Samples per pixel (≥ 1).
    pub spp: u32,
    /// Random seed.
    pub seed: u64,
    /// Maximum path depth, if given.
    pub max_depth: Option<u32>,
    /// The BSSRDF estimator, if given (`render.estimator`, parsed at load).
    pub estimator: Option<het_estimate::Estimator>,
    /// Sone's averaging, if given (`render.averaging`: `prefiltered` or `monte-carlo`; the
    /// command line's `--averaging` overrides it).
    pub averaging: Option<het_estimate::Averaging>,
    /// Scattering orders, if given.
    pub scattering: Option<Scattering>,
}

impl RenderSettings {
    /// Settings with seed 0 and nothing optional.
    pub fn new(width: u32, height: u32, spp: u32) -> Self {
        Self {
            width,
            height,
            spp,
            seed: 0,
            max_depth: None,
            estimator: None,
            averaging: None,
            scattering: None,
        }
    }
}

/// A translucent material.
#[derive(Debug, Clone, PartialEq)]
pub struct Translucent {
    /// Material name.
    pub name: String,
    /// σa and σs (1/scene-unit, `unit_scale` applied).
    pub medium: MediumField,
    /// Henyey–Greenstein asymmetry, |g| < 1.
    pub g: f64,
    /// Relative index of refraction n_medium / n_outside ≥ 1.
    pub eta: f64,
    /// Profile model requested by the material, if any.
    pub profile: Option<ProfileModel>,
    /// Whether a BSSRDF render with the tabulated profile weighs each pair by the slab
    /// profile of the object's local thickness (reflection on the entry side, transmission
    /// through the opposite face; `integrator/bssrdf.rs`, docs/shapes.md). Default true; the
    /// scene key `thickness_aware = false` turns it off (the half-space profile everywhere).
    pub thickness_aware: bool,
    /// Whether a BSSRDF render scales the profile by the shape correction measured by random
    /// walks in the object when the render is prepared (`correction/mod.rs`,
    /// docs/shapes.md): small and curved bodies answer uniform light as the volume does. Its
    /// preparation costs seconds (more with higher albedo and larger objects). Scene key
    /// `shape_correction`; `None` (no key) leaves the choice to the render
    /// ([`crate::integrator::Correction`]: by default, the objects too small for a half-space
    /// profile).
    pub shape_correction: Option<bool>,
    /// Seed of the shape correction's random numbers (scene key `shape_correction_seed`;
    /// default [`Translucent::DEFAULT_CORRECTION_SEED`]). The correction is a Monte Carlo
    /// measurement made once per render; another seed shows its own spread.
    pub correction_seed: u64,
    /// Whether a BSSRDF render with the tabulated profile scales it by the half-space's
    /// angular coupling T(α, μ_i, μ_o) (`bssrdf_core::tabulated::angular`, docs/tabulated-profile.md):
    /// exact for a flat half-space in every pair of directions, not only at normal incidence.
    /// Scene key `angular_coupling`; default true.
    pub angular_coupling: bool,
    /// Whether the angular coupling also carries its oblique shape: the radial part M and the
    /// forward shift of light entering at an angle (`bssrdf_core::tabulated::oblique`,
    /// docs/oblique-incidence.md). Scene key `oblique_shape`; default true. Without it, a
    /// half-space under a large quad light renders 1.19 times the path tracer; with it,
    /// renders take 1.09–1.12 times as long on the marble examples and have 3–18 % more noise
    /// at equal samples where the shape hardly moves light (the probes follow its azimuthal shape for
    /// the light's two sampled directions; docs/oblique-incidence.md, "On by default").
    pub oblique_shape: bool,
    /// The `unit_scale` that was applied to the file's coefficients.
    pub unit_scale: f64,
    /// The boundary's roughness `r ∈ [0, 1]` (a grey field; scene key `roughness`), `None` for
    /// a smooth boundary: a GGX microfacet dielectric of α = r² ([`crate::bsdf`]) in the path
    /// tracer, and its directional transmittance in the BSSRDF's Fresnel terms
    /// (`integrator/bssrdf.rs`). No effect at η = 1 (no boundary), and α below
    /// [`crate::bsdf::SMOOTH_ALPHA`] is smooth.
    pub roughness: Option<Field>,
    /// Key of the material in the scene file (`material[2]`) for messages.
    pub key: String,
    /// Line of the material in the scene file, if loaded from one.
    pub line: Option<usize>,
}

impl Translucent {
    /// The shape correction's seed when the scene gives none.
    pub const DEFAULT_CORRECTION_SEED: u64 = 0x005a_4ec0_77ec;

    /// What a BSSRDF render of this material prepares once: the profile family of `model` (or
    /// the material's own `profile`, or [`ProfileModel::default_for`] its η) counting `scattering`, with the material's
    /// g and η, and `estimator` prepared for its g. The error names the failing part
    /// (`"profile"` or `"estimator"`).
    pub fn prepare_bssrdf(
        &self,
        model: Option<ProfileModel>,
        scattering: Scattering,
        estimator: Estimator,
    ) -> Result<(ProfileFamily, PreparedEstimator), (&'static str, ParamError)> {
        let model = self.profile_model(model);
        let family =
            ProfileFamily::new(model, scattering, self.g, self.eta).map_err(|e| ("profile", e))?;
        let prepared = estimator
            .prepare(self.g, self.eta)
            .map_err(|e| ("estimator", e))?;
        Ok((family, prepared))
    }

    /// The profile a BSSRDF renders this material with: `model` (the command line's), else the
    /// material's own `profile`, else [`ProfileModel::default_for`] its η.
    pub fn profile_model(&self, model: Option<ProfileModel>) -> ProfileModel {
        model
            .or(self.profile)
            .unwrap_or(ProfileModel::default_for(self.eta))
    }

    /// A translucent material with no profile and unit scale 1 (validated when the scene is
    /// built).
    pub fn new(name: impl Into<String>, medium: MediumField, g: f64, eta: f64) -> Self {
        let name = name.into();
        Self {
            key: format!("material `{name}`"),
            name,
            medium,
            g,
            eta,
            profile: None,
            thickness_aware: true,
            shape_correction: None,
            correction_seed: Self::DEFAULT_CORRECTION_SEED,
            angular_coupling: true,
            oblique_shape: true,
            unit_scale: 1.0,
            roughness: None,
            line: None,
        }
    }

    /// The same material with the boundary's roughness field `roughness` (see
    /// [`Translucent::roughness`]).
    pub fn with_roughness(mut self, roughness: Field) -> Self {
        self.roughness = Some(roughness);
        self
    }
}

/// An opaque diffuse reflector: Lambertian, or Oren–Nayar where it is rough
/// ([`crate::bsdf::diffuse`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Diffuse {
    /// Albedo ρ in [0, 1] per channel (a field: constant, pattern or image).
    pub albedo: Field,
    /// The Oren–Nayar roughness σ ∈ [0, 1] (a grey field), `None` for Lambertian.
    pub roughness: Option<Field>,
}

impl Diffuse {
    /// The albedo at `hit`.
    #[inline]
    pub fn albedo_at(&self, hit: &crate::geometry::Hit) -> Rgb {
        self.albedo.eval(hit.p, hit.uv)
    }

    /// The roughness σ at `hit` (0 for a Lambertian surface).
    #[inline]
    pub fn roughness_at(&self, hit: &crate::geometry::Hit) -> f64 {
        self.roughness
            .as_ref()
            .map_or(0.0, |r| r.eval(hit.p, hit.uv)[0])
    }
}

/// What an object is made of.
// One per object, matched outside hot loops: the size difference does not matter, and an
// unboxed `Translucent` keeps patterns like `Material::Translucent(Translucent { medium, .. })`.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum Material {
    /// A participating medium inside a (closed) mesh.
    Translucent(Translucent),
    /// A diffuse reflector (Lambertian, or rough).
    Diffuse(Diffuse),
    /// An emitter (the geometry of a quad light).
    Emissive {
        /// Emitted radiance (on the light's emitting side).
        radiance: Rgb,
    },
}

impl Material {
    /// A Lambertian reflector of constant albedo (checked when the scene is built).
    pub fn diffuse(albedo: Rgb) -> Material {
        Material::Diffuse(Diffuse {
            albedo: Field::Constant(albedo),
            roughness: None,
        })
    }

    /// True when a field of the material is read through texture coordinates (an image
    /// with `mapping = "uv"`): its objects need a mesh with UVs.
    pub fn reads_uv(&self) -> bool {
        let uv = |f: &Field| !f.is_volumetric();
        match self {
            Material::Translucent(t) => {
                !t.medium.is_volumetric() || t.roughness.as_ref().is_some_and(uv)
            }
            Material::Diffuse(d) => uv(&d.albedo) || d.roughness.as_ref().is_some_and(uv),
            Material::Emissive { .. } => false,
        }
    }

    /// The translucent material, if this is one.
    pub fn translucent(&self) -> Option<&Translucent> {
        match self {
            Material::Translucent(t) => Some(t),
            _ => None,
        }
    }
}

/// One object of the scene: `scene.geometry()`'s object with the same index.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Object name (`shape[i]` by default, `light[j]` for quad lights).
    pub name: String,
    /// Its material.
    pub material: Material,
    /// Topology of its mesh (closedness, orientation).
    pub report: MeshReport,
    /// Index into `scene.lights()` when the object is a light's geometry.
    pub emitter: Option<usize>,
    /// Key in the scene file (`shape[3]`, `light[0]`).
    pub key: String,
    /// Line in the scene file, if loaded from one.
    pub line: Option<usize>,
    /// Where the mesh came from: a file path, or `<box>`, `<sphere>`…
    pub source: String,
}

/// A validated scene: camera, lights, objects with their materials, and the geometry.
#[derive(Debug)]
pub struct Scene {
    camera: Camera,
    lights: Vec<Light>,
    objects: Vec<Object>,
    geometry: Geometry,
    settings: RenderSettings,
    source_path: Option<PathBuf>,
    display_name: String,
    inputs: Vec<PathBuf>,
    notes: Vec<LoadNote>,
}

/// Something the loader read but could not honour (for example a part of a glTF material that
/// is not read, `docs/gltf.md`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoadNote {
    /// The file it is about (a glTF model).
    pub file: String,
    /// What in that file (`material `jade``).
    pub subject: String,
    /// One sentence.
    pub text: String,
}

impl std::fmt::Display for LoadNote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}: {}", self.file, self.subject, self.text)
    }
}

impl Scene {
    /// What the loader read but could not honour, one sentence each. Renders list them among
    /// their warnings, one warning per file.
    pub fn load_notes(&self) -> &[LoadNote] {
        &self.notes
    }

    /// The camera. Its resolution is always `settings().width × settings().height`.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }
    /// Every light (quad lights are also objects).
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }
    /// The objects: `objects()[i]` is object `i` of [`Scene::geometry`].
    pub fn objects(&self) -> &[Object] {
        &self.objects
    }
    /// The meshes and their BVHs.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }
    /// `[render]`.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }
    /// The scene file, when loaded from one.
    pub fn source_path(&self) -> Option<&Path> {
        self.source_path.as_deref()
    }
    /// The name used in messages (the file path, or the builder's name).
    pub fn display_name(&self) -> &str {
        &self.display_name
    }
    /// The same scene rendered at `width × height` pixels: the camera and `[render]` change
    /// together, so that they always agree. A zero size is an error.
    pub fn with_resolution(mut self, width: u32, height: u32) -> Result<Self, CameraError> {
        self.camera = self.camera.with_resolution(width, height)?;
        (self.settings.width, self.settings.height) = (width, height);
        Ok(self)
    }

    /// The same scene with every artist material's estimators inverting at `invert`
    /// (overriding the materials' `invert` keys; σ materials are unchanged).
    pub fn with_invert(mut self, invert: crate::field::InvertAt) -> Self {
        for o in &mut self.objects {
            if let Material::Translucent(t) = &mut o.material {
                t.medium = t.medium.clone().with_invert(invert);
            }
        }
        self
    }

    /// Where each artist material's estimators invert, by material name (empty when the scene
    /// has no artist material), for provenance.
    pub fn artist_inversions(&self) -> Vec<(String, crate::field::InvertAt)> {
        let mut out: Vec<(String, crate::field::InvertAt)> = Vec::new();
        for (_, t) in self.translucent_objects() {
            if let Some(map) = t.medium.artist_map()
                && !out.iter().any(|(n, _)| *n == t.name)
            {
                out.push((t.name.clone(), map.invert()));
            }
        }
        out
    }

    /// The files read while loading besides the scene file itself: every mesh, and every
    /// texture of a used material (for cache keys and provenance).
    pub fn input_files(&self) -> &[PathBuf] {
        &self.inputs
    }

    /// The surface of `object` for the estimators.
    pub fn object_surface(&self, object: u32) -> ObjectSurface<'_> {
        ObjectSurface::new(&self.geometry, object)
    }

    /// The beam lights (for the beam experiment).
    pub fn beams(&self) -> impl Iterator<Item = &BeamLight> {
        self.lights.iter().filter_map(|l| match l {
            Light::Beam(b) => Some(b),
            _ => None,
        })
    }

    /// Total environment radiance arriving along an escaped ray travelling in `dir`.
    pub fn environment_radiance(&self, dir: DVec3) -> Rgb {
        let mut l = Rgb::ZERO;
        for light in &self.lights {
            l += light.le(dir);
        }
        l
    }

    /// Indices of the translucent objects.
    pub fn translucent_objects(&self) -> impl Iterator<Item = (u32, &Translucent)> {
        self.objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| o.material.translucent().map(|t| (i as u32, t)))
    }

    fn invalid(&self, key: String, line: Option<usize>, message: String) -> SceneError {
        SceneError::Invalid {
            file: PathBuf::from(&self.display_name),
            key,
            line,
            message,
        }
    }

    /// Errors when a translucent object's mesh is not closed (open edges, non-manifold or
    /// inconsistently oriented edges): the volumetric path tracer needs a well-defined inside.
    /// BSSRDF renders tolerate open meshes and need not call this.
    pub fn require_closed_translucent(&self) -> Result<(), SceneError> {
        for o in &self.objects {
            if matches!(o.material, Material::Translucent(_)) && !o.report.is_closed() {
                return Err(self.invalid(
                    o.key.clone(),
                    o.line,
                    format!(
                        "the translucent mesh `{}` ({}) is {}; the path tracer needs a closed mesh",
                        o.name,
                        o.source,
                        o.report.summary()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Errors when a translucent object's medium has a field defined only on the surface (a
    /// UV-mapped image) and its mesh has no texture coordinates. With them, the path tracer
    /// reads such a field inside the body at the texture coordinates of the nearest surface
    /// point ([`crate::field::MediumField::with_interior`]); without them the field has no
    /// value anywhere.
    pub fn require_volumetric(&self) -> Result<(), SceneError> {
        for (i, t) in self.translucent_objects() {
            if self.geometry().mesh(i).uvs.is_some() {
                continue;
            }
            for (which, f) in t.medium.named_fields() {
                if !f.is_volumetric() {
                    return Err(self.invalid(
                        format!("{}.{which}", t.key),
                        t.line,
                        format!(
                            "material `{}`: {which} is a UV-mapped image and the mesh of `{}` has no texture coordinates, so it has no value inside the body for a volumetric (path-traced) render; give the mesh texture coordinates or use a planar projection (`mapping = \"planar\"`)",
                            t.name,
                            self.objects[i as usize].name
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Whether the path tracer can walk translucent object `object`: a closed mesh, and a
    /// medium defined in space or read through texture coordinates the mesh has (the two
    /// checks of [`Scene::require_path_traceable`], for one object).
    pub fn can_path_trace(&self, object: u32) -> bool {
        let Some(o) = self.objects.get(object as usize) else {
            return false;
        };
        let Some(t) = o.material.translucent() else {
            return false;
        };
        o.report.is_closed()
            && (t.medium.is_volumetric() || self.geometry().mesh(object).uvs.is_some())
    }

    /// Both checks a volumetric path-traced render needs.
    pub fn require_path_traceable(&self) -> Result<(), SceneError> {
        self.require_volumetric()?;
        self.require_closed_translucent()
    }
}
