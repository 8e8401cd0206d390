//! The camera path loop shared by the reference path tracer and the BSSRDF renderer.
//!
//! Both renders trace the same camera rays through the same BVH, shade diffuse surfaces the
//! same way (next-event estimation with MIS against cosine sampling, pbrt-v4 §13.4), use the
//! same lights and the same Russian roulette; they differ only where a path meets a
//! translucent object:
//! * [`Method::PathTraced`]: the path refracts in and performs the volumetric random walk
//!   ([`super::walk`]), with next-event estimation at every real scattering vertex through
//!   index-matched boundaries (shadow transmittance by ratio tracking). A walk that crosses an
//!   index-matched medium without scattering keeps the MIS vertex before the medium, and a
//!   shadow ray through a medium classifies its light as having entered one, so that both
//!   strategies weight and classify the same light path alike (`docs/physics.md#path-tracer`);
//! * [`Method::Bssrdf`]: an incident point x_i is importance-sampled with probe rays
//!   ([`super::probe_gathering`]), the estimator turns (x_i, x_o) into homogeneous
//!   coefficients, the profile is evaluated at r = |x_i − x_o|, and irradiance is gathered at
//!   x_i.
//!
//! Radiance is RGB, and every path carries all three channels. A grey medium is walked once
//! for all three. In a medium whose coefficients differ between channels the path uses
//! *spectral MIS* (pbrt-v4 §14.2.2; `docs/physics.md#spectral-mis`): on entering the first one
//! it picks a hero channel uniformly, whose coefficients drive free-flight sampling from then
//! on ([`crate::spectral`]), and carries the other channels with the ratios of their path
//! densities to the hero's. The path keeps `r_u`, each channel's unidirectional path density
//! relative to the hero's, and its throughput `beta` is kept divided by the mean of `r_u` (the
//! one-sample balance heuristic over the channels): `beta` is the weighted throughput that
//! light found by the path, by chance or by next-event estimation, multiplies. Next-event
//! estimation is weighted against direction sampling as before (power heuristic on the
//! solid-angle pdfs), and its shadow rays estimate each channel's transmittance through a
//! chromatic medium by that channel's own ratio tracking; the two weights together still sum
//! to 1 per channel (`docs/physics.md#spectral-mis`).
//!
//! Objects inside a medium: a path inside a translucent object (path tracing) carries that
//! object as its current medium. The walk ends at any other object's surface
//! ([`WalkEnd::Surface`]); a diffuse surface there is shaded as anywhere else (next-event
//! estimation through the medium, cosine continuation) and the path walks on in the same
//! medium. Shadow rays know the medium they start in.

use bssrdf_core::{ProfileModel, Rgb, Scattering};
use glam::DVec3;
use het_estimate::azimuth::GuidedAzimuths;
use het_estimate::{CoefficientField, Estimator};

use crate::bsdf::{Frame, RoughDielectric, TransmittanceTable, oren_nayar};
use crate::correction::factors::ShapeCorrection;
use crate::geometry::{Hit, OFFSET_REL, ObjectSurface, Ray};
use crate::integrator::RenderError;
use crate::integrator::bssrdf::{BssrdfObject, PairEnd, PairWeight, ShiftGuide, facing_normal};
use crate::integrator::counters::PathCounters;
use crate::integrator::lighting::{LightSet, Vertex, power_heuristic};
use crate::integrator::preparation::PrepareObserver;
use crate::integrator::probe_gathering::Gathering;
use crate::integrator::walk::{Crossing, Interface, WalkEnd, WalkMedium, WalkStart};
use crate::light::{Light, LightSample};
use crate::render::{Counters, PixelEstimator};
use crate::rng::Rng;
use crate::scene::{Diffuse, Material, Scene, Translucent};
use crate::spectral::{HeroTracking, SpectralView};
use crate::volume::{ChannelView, FreeFlight, direction_about, transmittance};

/// Russian roulette starts after this many surface interactions.
const RR_DEPTH: u32 = 3;
/// Most boundary crossings followed by one shadow ray.
const MAX_SHADOW_CROSSINGS: u32 = 64;

/// How translucent objects are rendered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// The reference: volumetric path tracing inside every translucent object.
    PathTraced,
    /// A homogeneous BSSRDF with parameters from `estimator`.
    Bssrdf {
        /// How (x_i, x_o) become homogeneous coefficients.
        estimator: Estimator,
        /// Profile model; `None` uses each material's own (the tabulated exact profile where
        /// it applies, else photon beam diffusion).
        profile: Option<ProfileModel>,
        /// Which translucent objects get the BSSRDF, and which get the shape correction.
        policy: Policy,
    },
}

/// How a BSSRDF method applies to a scene's translucent objects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Policy {
    /// Which objects get the BSSRDF; the others are path traced.
    pub coverage: Coverage,
    /// Which of them get the shape correction.
    pub correction: Correction,
}

/// Which BSSRDF objects get the shape correction (`render --shape-correction`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Correction {
    /// Each material's own `shape_correction` where it sets one; else the objects too small
    /// for a half-space profile ([`crate::optical_size::is_optically_small`]). The
    /// default of `render` and of `--method auto`.
    Auto,
    /// Each material's own `shape_correction`, off where it sets none: the library's default
    /// ([`Method::bssrdf`]), so that a render is what its scene says.
    #[default]
    Materials,
    /// Every BSSRDF object.
    On,
    /// None.
    Off,
}

impl Correction {
    /// The names of `--shape-correction` (the library's `Materials` is not one).
    pub const NAMES: [&'static str; 3] = ["auto", "on", "off"];

    /// `auto`, `materials`, `on` or `off`.
    pub fn name(self) -> &'static str {
        match self {
            Correction::Auto => "auto",
            Correction::Materials => "materials",
            Correction::On => "on",
            Correction::Off => "off",
        }
    }

    /// Whether an object whose material says `material` (its `shape_correction`, if set)
    /// and which is `small` (optically small for a half-space profile) gets the correction.
    pub fn applies(self, material: Option<bool>, small: bool) -> bool {
        match self {
            Correction::On => true,
            Correction::Off => false,
            Correction::Auto => material.unwrap_or(small),
            Correction::Materials => material.unwrap_or(false),
        }
    }
}

impl std::str::FromStr for Correction {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(Correction::Auto),
            "on" => Ok(Correction::On),
            "off" => Ok(Correction::Off),
            _ => Err(format!("unknown shape correction `{s}`: auto, on or off")),
        }
    }
}

/// Which translucent objects a BSSRDF method renders with its BSSRDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Coverage {
    /// Every translucent object (`--method sone`, `kernel`, …: the estimators as such).
    #[default]
    Every,
    /// The objects a half-space profile fits; the optically small ones
    /// ([`crate::optical_size::is_optically_small`]) are path traced, where the path
    /// tracer can walk them (`--method auto`).
    HalfSpaceOnly,
}

impl Method {
    /// `pt`, `auto`, or the estimator's name.
    pub fn name(&self) -> &'static str {
        match self {
            Method::PathTraced => "pt",
            Method::Bssrdf {
                policy:
                    Policy {
                        coverage: Coverage::HalfSpaceOnly,
                        ..
                    },
                ..
            } => "auto",
            Method::Bssrdf { estimator, .. } => estimator.name(),
        }
    }

    /// `auto`: `estimator` (Sone's with its defaults, for `--method auto`) where a half-space
    /// profile fits, the path tracer inside optically small objects.
    pub fn auto(estimator: Estimator) -> Self {
        Method::Bssrdf {
            estimator,
            profile: None,
            policy: Policy {
                coverage: Coverage::HalfSpaceOnly,
                correction: Correction::Auto,
            },
        }
    }

    /// A BSSRDF method with `estimator` on every translucent object.
    pub fn bssrdf(estimator: Estimator, profile: Option<ProfileModel>) -> Self {
        Method::Bssrdf {
            estimator,
            profile,
            policy: Policy::default(),
        }
    }

    /// The same method with the shape correction chosen by `correction` (BSSRDF methods
    /// only).
    pub fn with_correction(self, correction: Correction) -> Self {
        match self {
            Method::Bssrdf {
                estimator,
                profile,
                policy,
            } => Method::Bssrdf {
                estimator,
                profile,
                policy: Policy {
                    correction,
                    ..policy
                },
            },
            m => m,
        }
    }
}

/// Options shared by both methods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathOptions {
    /// Which orders of scattering inside media count (the paper: multiple only).
    pub scattering: Scattering,
    /// Most surface interactions per path.
    pub max_depth: u32,
}

/// Per-object data prepared once per render.
enum ObjectKind<'s> {
    Opaque,
    Translucent {
        material: MaterialOf<'s>,
        bssrdf: Option<Box<BssrdfObject>>,
        /// The medium has the same coefficients in every channel.
        grey: bool,
        /// The rough boundary's albedo and transmittance, when the boundary is rough.
        boundary: Option<std::sync::Arc<TransmittanceTable>>,
    },
}

impl ObjectKind<'_> {
    /// Whether a shadow ray crosses this object's boundary and goes on through its medium
    /// (ratio-tracked, [`PathIntegrator::shadow`]): a path-traced index-matched medium. Every
    /// other object blocks shadow rays.
    fn passes_shadow_rays(&self) -> bool {
        matches!(self, ObjectKind::Translucent { material, bssrdf: None, .. } if material.eta == 1.0)
    }
}

/// A translucent object's material: the scene's, or, for a path-traced object whose medium is
/// UV-mapped, a copy whose medium holds the object's body
/// ([`crate::field::MediumField::with_interior`]), boxed so that the objects stay small.
enum MaterialOf<'s> {
    Scene(&'s Translucent),
    Own(Box<Translucent>),
}

impl std::ops::Deref for MaterialOf<'_> {
    type Target = Translucent;
    fn deref(&self) -> &Translucent {
        match self {
            MaterialOf::Scene(t) => t,
            MaterialOf::Own(t) => t,
        }
    }
}

/// A cosine-distributed direction about the unit normal `n` (pdf `cos/π`, pbrt-v4 §A.5.3 by
/// the `cos = √u` inversion) and its cosine; `None` at grazing (`cos = 0`), where the pdf
/// vanishes. The continuation of both a diffuse bounce and a BSSRDF's incident side.
fn cosine_continuation(n: DVec3, rng: &mut Rng) -> Option<(DVec3, f64)> {
    cosine_direction(n, rng.uniform2())
}

/// [`cosine_continuation`] from the uniforms `u` ∈ [0, 1)².
fn cosine_direction(n: DVec3, u: [f64; 2]) -> Option<(DVec3, f64)> {
    let cos = u[0].sqrt();
    (cos > 0.0).then(|| (direction_about(n, cos, std::f64::consts::TAU * u[1]), cos))
}

/// A shadow ray toward a light sample, measured from the ray's actual origin.
///
/// The origin is the shading point moved off its surface ([`Hit::spawn_origin`]), which on a
/// large triangle is far more than any relative shortening of the light's distance: a segment
/// sized from the shading point would overshoot the light and hit the light's own geometry.
/// So the segment is aimed from the origin at the sampled point and:
/// * toward an area light with geometry (a quad), runs a little *past* the point, and a hit on
///   the light's own object counts as reaching it;
/// * toward a point light, stops just short of it (as [`Ray::between`]);
/// * toward a light at infinity, is unbounded.
struct ShadowSegment {
    origin: DVec3,
    dir: DVec3,
    t_max: f64,
    light_object: Option<u32>,
}

impl ShadowSegment {
    fn toward(origin: DVec3, ls: &LightSample) -> Option<Self> {
        let Some(y) = ls.point else {
            return Some(Self {
                origin,
                dir: ls.wi,
                t_max: f64::INFINITY,
                light_object: None,
            });
        };
        match ls.object {
            Some(object) => {
                let d = y - origin;
                let dist = d.length();
                if !(dist > 0.0 && dist.is_finite()) {
                    return None;
                }
                Some(Self {
                    origin,
                    dir: d / dist,
                    t_max: dist * (1.0 + 1e-3) + OFFSET_REL * y.abs().max_element(),
                    light_object: Some(object),
                })
            }
            None => {
                let r = Ray::between(origin, y)?;
                Some(Self {
                    origin,
                    dir: r.dir,
                    t_max: r.t_max,
                    light_object: None,
                })
            }
        }
    }
}

/// Light reaching a vertex by next-event estimation.
#[derive(Debug, Clone, Copy)]
struct Direct {
    /// Radiance (before the path weight).
    l: Rgb,
    /// The shadow segment crossed an index-matched medium: the light path it completes has
    /// entered a medium (with no scattering there), which the scattering-order filter must
    /// see exactly as it sees the direction-sampled path through the same medium.
    through_medium: bool,
    /// The sampled direction toward the light (zero when nothing was found).
    wi: DVec3,
}

/// Next-event estimation's random choices, a light and a point on it: drawn by
/// [`PathIntegrator::direct`] itself, or beforehand where something else must lean toward
/// the light sample first (the oblique shape's probe guide, [`PathIntegrator::gather`]).
#[derive(Debug, Clone, Copy)]
struct LightPick {
    /// Chooses the light.
    u: f64,
    /// Chooses the sample on it.
    u2: [f64; 2],
}

impl LightPick {
    /// The light's number, then the sample's (struct fields are evaluated in the order
    /// written).
    fn draw(rng: &mut Rng) -> Self {
        Self {
            u: rng.uniform(),
            u2: rng.uniform2(),
        }
    }
}

/// What a BSSRDF vertex with the oblique shape draws before its probes, so that the probes
/// can lean the way S does for the directions its light then arrives by
/// ([`PathIntegrator::gather`]): next-event estimation's light sample, which every x_i
/// gathers from, and the uniforms of the continuation's cosine-distributed direction, which
/// the carrier x_i takes about its own normal ([`cosine_direction`]).
#[derive(Debug, Clone, Copy)]
struct DrawnFirst {
    light: LightPick,
    continuation: [f64; 2],
}

impl DrawnFirst {
    /// The light sample, then the continuation's uniforms.
    fn draw(rng: &mut Rng) -> Self {
        Self {
            light: LightPick::draw(rng),
            continuation: rng.uniform2(),
        }
    }
}

/// The point of a BSSRDF vertex's probe set the path continues from, its weight, and the
/// continuation's uniforms where they were drawn before the probes ([`DrawnFirst`]).
struct Carrier {
    x_i: Hit,
    weight: CarrierWeight,
    continuation: Option<[f64; 2]>,
}

impl Direct {
    const NONE: Direct = Direct {
        l: Rgb::ZERO,
        through_medium: false,
        wi: DVec3::ZERO,
    };
}

/// A vertex next-event estimation samples lights from ([`PathIntegrator::direct`]).
#[derive(Debug, Clone, Copy)]
struct LightVertex {
    /// Where the light is sampled from.
    p: DVec3,
    /// The translucent object the vertex lies in, where its shadow rays start (path tracing).
    medium: Option<u32>,
    /// The kind of vertex: which lights it may choose ([`LightSet::at`]).
    at: Vertex,
}

/// What a shadow segment lets through.
#[derive(Debug, Clone, Copy)]
struct Transmission {
    /// Transmittance per channel (0 when blocked).
    tr: Rgb,
    /// The segment crossed an index-matched medium.
    through_medium: bool,
}

impl Transmission {
    const BLOCKED: Transmission = Transmission {
        tr: Rgb::ZERO,
        through_medium: false,
    };
}

/// A translucent object a path walks in (path tracing).
#[derive(Clone, Copy)]
struct MediumObject<'a> {
    /// The object's index.
    object: u32,
    /// Its material.
    material: &'a Translucent,
    /// The medium has the same coefficients in every channel (one walk carries all three).
    grey: bool,
}

/// The previous vertex of a path, for MIS when the path hits an emitter by chance.
#[derive(Debug, Clone, Copy)]
enum Prev {
    /// Camera or a specular event: emission counts fully.
    Specular,
    /// A smooth dielectric's mirror reflection whose directly seen emitter (a quad light) was
    /// added when the reflection was chosen ([`PathIntegrator::mirror_emission`]): an emitter
    /// reached next counts zero, so that it is not counted twice; the environment counts fully.
    MirrorCounted,
    /// A vertex where light sampling was also done: direction pdf (solid angle), and the kind
    /// of vertex (which lights its light sampling could have chosen: [`LightSet::at`]).
    Sampled { p: DVec3, pdf: f64, at: Vertex },
}

impl Prev {
    /// The light-sampled vertex and its direction pdf, if any.
    fn sampled(self) -> Option<(DVec3, f64)> {
        match self {
            Prev::Sampled { p, pdf, .. } => Some((p, pdf)),
            Prev::Specular | Prev::MirrorCounted => None,
        }
    }
}

/// The integrator: a [`PixelEstimator`] over a scene.
pub struct PathIntegrator<'s> {
    scene: &'s Scene,
    method: Method,
    options: PathOptions,
    objects: Vec<ObjectKind<'s>>,
    /// The lights next-event estimation samples on surfaces and in media ([`LightSet::at`]).
    surface_lights: LightSet,
    /// Whether much of the direct light at surfaces arrives by the continuation's sampled
    /// direction: an environment, which next-event estimation either leaves to direction
    /// sampling ([`LightSet::at`]) or shares with it by MIS, where the cosine-distributed
    /// continuation takes most of it near the normal. The oblique shape's probes then lean
    /// the continuation's way too ([`PathIntegrator::gather`]). Not for delta lights, which
    /// only next-event estimation reaches, nor for quads, which the continuation seldom hits.
    guide_continuation: bool,
    medium_lights: LightSet,
    warnings: Vec<crate::integrator::warnings::Warning>,
    strategy: LightStrategy,
    /// Defer the profile weight of a carrier that gathered no light ([`Deferred`]).
    defer_weights: bool,
    /// Trace smooth dielectrics' mirror directions to the emitters they see
    /// ([`PathIntegrator::mirror_emission`]): the scene has a quad light.
    mirror_nee: bool,
    /// Some object lets shadow rays through ([`ObjectKind::passes_shadow_rays`]); without
    /// one, a shadow ray from outside every medium is an any-hit query.
    shadows_cross_objects: bool,
}

/// How light sources are found: the two strategies of multiple importance sampling (Veach
/// 1997, "Vea97", §9.2), or one of them alone.
///
/// Only [`LightStrategy::Mis`] is unbiased for every scene; the single strategies exist to
/// test it (each is unbiased exactly where it can reach every light, and the three must
/// agree there):
/// * [`LightStrategy::LightOnly`] counts only next-event estimation for lights it can sample,
///   so light that NEE cannot connect to (through a refractive boundary) is lost;
/// * [`LightStrategy::DirectionOnly`] counts only lights hit by direction-sampled rays, so
///   delta lights (directional, point) are lost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LightStrategy {
    /// Next-event estimation and direction sampling, combined by the power heuristic.
    #[default]
    Mis,
    /// Next-event estimation alone (weight 1); lights hit by chance count only when NEE could
    /// not have sampled them.
    LightOnly,
    /// Direction sampling alone: no next-event estimation; lights hit by chance count fully.
    DirectionOnly,
}

impl LightStrategy {
    /// Weight of a next-event sample with light pdf `light` against direction pdf `dir` (both
    /// solid angle, the light pdf including the light-selection probability).
    #[inline]
    fn nee_weight(self, light: f64, dir: f64) -> f64 {
        match self {
            LightStrategy::Mis => power_heuristic(light, dir),
            LightStrategy::LightOnly => 1.0,
            LightStrategy::DirectionOnly => 0.0,
        }
    }

    /// Weight of a light reached by a direction-sampled ray (pdf `dir`) that next-event
    /// estimation would have sampled with pdf `light` (0 when it cannot).
    #[inline]
    fn hit_weight(self, dir: f64, light: f64) -> f64 {
        match self {
            LightStrategy::Mis => power_heuristic(dir, light),
            LightStrategy::LightOnly => {
                if light > 0.0 {
                    0.0
                } else {
                    1.0
                }
            }
            LightStrategy::DirectionOnly => 1.0,
        }
    }
}

/// One camera path being traced: the per-path context every shading step of
/// [`PathIntegrator::li`] takes. What the path has gathered and carries, where it is and the
/// vertex it comes from, and the random stream it draws from and the counters it records into.
struct PathState<'r> {
    /// Radiance gathered so far.
    l: Rgb,
    /// Throughput per channel, divided by the mean of `r_u` (spectral MIS).
    beta: Rgb,
    /// The hero channel, chosen on entering the first chromatic medium.
    hero: Option<usize>,
    /// Each channel's unidirectional path density relative to the hero's, scaled to mean 1
    /// (pbrt-v4's `r_u`); all 1 until the path enters a chromatic medium.
    r_u: Rgb,
    /// Real scattering events inside media so far.
    order: u32,
    /// The path has been inside a medium (the scattering-order filter applies).
    entered: bool,
    /// The translucent object the path is travelling in (path tracing).
    medium: Option<u32>,
    prev: Prev,
    /// A factor of `beta` not evaluated yet: the BSSRDF profile weight of the point the path
    /// continued from, deferred because that point gathered no light (see [`Deferred`]).
    deferred: Option<Deferred>,
    /// The path's random numbers.
    rng: &'r mut Rng,
    /// The render's counters (of this row).
    counters: &'r mut PathCounters,
}

/// The profile weight `R(x_i, x_o)·scale` of a BSSRDF continuation, owed to `beta`.
///
/// At each BSSRDF vertex the path continues from one incident point x_i (the carrier). Its
/// weight needs an estimate (averaging over a region: the costly part of a BSSRDF sample),
/// which is wasted when nothing reaches the camera through the rest of the path: on a convex
/// object lit from one side, carriers on the unlit faces continue into the void. When the
/// carrier gathered no light itself, its weight is therefore evaluated only when the path
/// first adds light ([`PathIntegrator::settle`]). The factor multiplies `beta`, so evaluating
/// it later gives the same value in distribution (its random numbers come from the same
/// stream, later): the image stays unbiased and deterministic for a seed. Russian roulette
/// reads `beta` without it (any continuation probability keeps the estimate unbiased).
struct Deferred {
    object: u32,
    x_i: Hit,
    x_o: Hit,
    scale: f64,
    /// The continuation's direction at x_i (about x_i's shading normal) and the exit
    /// direction at x_o about the normal `n_o`, for the angular coupling
    /// ([`BssrdfObject::coupling`]).
    w_i: DVec3,
    w_o: DVec3,
    n_o: DVec3,
}

impl PathState<'_> {
    /// Adds `contribution` if the scattering-order filter lets this path's light through.
    fn add(&mut self, contribution: Rgb, order: u32, entered: bool, filter: Scattering) {
        if !entered || filter.counts(order) {
            self.l += contribution;
        }
    }

    /// Multiplies the path by the per-channel density ratios `q` of a walk (see
    /// [`carried`]).
    fn carry(&mut self, q: Rgb) {
        if q != Rgb::ONE {
            (self.beta, self.r_u) = carried(self.beta, self.r_u, q);
        }
    }
}

/// The throughput and `r_u` of a path with throughput `beta` and relative densities `r_u`
/// (mean 1) after a walk that multiplied each channel's density relative to the hero's by
/// `q` (up to a common factor, [`crate::spectral`]): both times `q`, divided by the mean of
/// the new `r_u` — pbrt-v4's `beta / r_u.Average()` kept as the throughput itself, so that
/// every contribution is simply `beta` times the light. The hero's channel of `q` and of `r_u`
/// is positive, so the mean is.
#[inline]
fn carried(beta: Rgb, r_u: Rgb, q: Rgb) -> (Rgb, Rgb) {
    let r = r_u * q;
    let s = r.mean();
    if s > 0.0 && s.is_finite() {
        (beta * q * (1.0 / s), r * (1.0 / s))
    } else {
        (Rgb::ZERO, Rgb::ONE)
    }
}

/// A BSSRDF vertex being shaded ([`PathIntegrator::subsurface`]): the object, and its exitant
/// side, which every incident point pairs with.
struct BssrdfVertex<'a> {
    /// The object's material.
    material: &'a Translucent,
    /// Its BSSRDF.
    b: &'a BssrdfObject,
    /// Its surface (the probes' and the estimator's).
    surface: ObjectSurface<'a>,
    /// The exitant point x_o.
    x_o: &'a Hit,
    /// The direction ω_o toward the viewer (unit).
    w_o: DVec3,
    /// The normal S measures ω_o against ([`facing_normal`]).
    n_o: DVec3,
    /// The boundary's roughness α at x_o (0 where it is smooth).
    alpha_o: f64,
}

/// The profile weight of the incident point a BSSRDF vertex continues from (the carrier,
/// [`PathIntegrator::gather`]).
enum CarrierWeight {
    /// Evaluated: the factor `R·weight·scale` of `beta` (per channel), and the pair's weight for
    /// the angular coupling.
    Evaluated(Rgb, PairWeight),
    /// Owed, the carrier having gathered no light ([`Deferred`]): the scale of the profile
    /// weight still to be evaluated.
    Owed(f64),
}

/// What a path did at a rough boundary met from outside
/// ([`PathIntegrator::rough_boundary`]).
enum Crossed {
    /// Refracted into the medium along this direction.
    Entered(DVec3),
    /// Reflected (on with this step) or lost.
    Stepped(Step),
}

/// The outcome of shading one surface interaction.
enum Step {
    /// Trace this ray (outside any medium) next.
    Continue(Ray),
    /// A walk inside a medium reached this surface travelling along the direction: shade it
    /// next, without tracing.
    Arrive(Hit, DVec3),
    Stop,
}

impl<'s> PathIntegrator<'s> {
    /// Prepares `method` for `scene`. The path tracer needs every translucent object closed
    /// and every translucent field defined in the volume; the BSSRDF renderer builds a profile
    /// table and prepares its estimator for each translucent material.
    pub fn new(
        scene: &'s Scene,
        method: Method,
        options: PathOptions,
    ) -> Result<Self, RenderError> {
        Self::new_observed(scene, method, options, &crate::render::NoObserver)
    }

    /// [`PathIntegrator::new`] reporting the long parts of preparation (shape corrections)
    /// to `observer`, which may stop it ([`RenderError::Interrupted`]).
    pub fn new_observed(
        scene: &'s Scene,
        method: Method,
        options: PathOptions,
        observer: &dyn PrepareObserver,
    ) -> Result<Self, RenderError> {
        if method == Method::PathTraced {
            scene.require_path_traceable()?;
        }
        let plans = crate::integrator::plan::plan(scene, method);
        let mut objects = Vec::with_capacity(scene.objects().len());
        for (index, object) in scene.objects().iter().enumerate() {
            objects.push(match (&object.material, plans[index]) {
                (Material::Translucent(t), Some(plan)) => {
                    let bssrdf = match method {
                        Method::Bssrdf {
                            estimator, profile, ..
                        } if !plan.path_traced => {
                            let (lo, hi) = scene.geometry().object_bounds(index as u32);
                            let mut b = BssrdfObject::new(
                                t,
                                profile,
                                options.scattering,
                                estimator,
                                (hi - lo).max_element(),
                            )
                            .map_err(|(what, e)| RenderError::param(&object.name, what, e))?;
                            // The tables Sone's prefiltered averages read, before any sample.
                            if estimator.reads_region_averages() {
                                t.medium.build_area_tables();
                            }
                            if plan.corrected {
                                b.correction = Some(
                                    ShapeCorrection::build(
                                        &b,
                                        scene.geometry(),
                                        index as u32,
                                        &t.medium,
                                        t.correction_seed,
                                        observer,
                                    )
                                    .ok_or_else(|| {
                                        RenderError::Interrupted {
                                            object: object.name.clone(),
                                        }
                                    })?,
                                );
                            }
                            Some(Box::new(b))
                        }
                        _ => None,
                    };
                    // A path-traced UV-mapped medium is read inside the body at its nearest
                    // surface point.
                    let material = if bssrdf.is_none() && !t.medium.is_volumetric() {
                        let mut own = t.clone();
                        own.medium = own
                            .medium
                            .with_interior(scene.geometry().mesh(index as u32));
                        MaterialOf::Own(Box::new(own))
                    } else {
                        MaterialOf::Scene(t)
                    };
                    ObjectKind::Translucent {
                        material,
                        bssrdf,
                        grey: t.medium.is_grey(),
                        boundary: crate::integrator::bssrdf::boundary_table(t),
                    }
                }
                _ => ObjectKind::Opaque,
            });
        }
        let warnings = crate::integrator::warnings::scene_warnings(scene, method);
        let shadows_cross_objects = objects.iter().any(ObjectKind::passes_shadow_rays);
        let surface_lights = LightSet::at(scene.lights(), Vertex::Surface);
        Ok(Self {
            scene,
            method,
            options,
            objects,
            guide_continuation: scene
                .lights()
                .iter()
                .any(|l| matches!(l, Light::Environment(_))),
            surface_lights,
            medium_lights: LightSet::at(scene.lights(), Vertex::Medium),
            warnings,
            strategy: LightStrategy::Mis,
            defer_weights: true,
            mirror_nee: scene.lights().iter().any(|l| matches!(l, Light::Quad(_))),
            shadows_cross_objects,
        })
    }

    /// Uses `strategy` to find lights instead of multiple importance sampling (for tests and
    /// diagnostics: see [`LightStrategy`]).
    pub fn with_light_strategy(mut self, strategy: LightStrategy) -> Self {
        self.strategy = strategy;
        self
    }

    /// Evaluates every BSSRDF continuation's profile weight at once (`false`) instead of when
    /// the path first adds light (`true`, the default). At each BSSRDF vertex the path goes on
    /// from one incident point; when that point gathered no light, its weight (an estimate,
    /// the costly part of a BSSRDF sample) is owed to the path's throughput and evaluated
    /// only if light arrives later, which on a convex object lit from one side it mostly does
    /// not. Both give the same image in expectation; the switch exists to test that, and to
    /// measure what deferring saves.
    pub fn with_deferred_weights(mut self, defer: bool) -> Self {
        self.defer_weights = defer;
        self
    }

    /// Things about the scene that make this method's image misleading (printed by the CLI).
    pub fn warnings(&self) -> &[crate::integrator::warnings::Warning] {
        &self.warnings
    }

    /// What preparing the render did that a user may want to know: one line per object a
    /// BSSRDF method path-traces (clear media; small objects under `--method auto`), and one per object whose shape correction
    /// was measured (points, spacing, wall time).
    pub fn notes(&self) -> Vec<String> {
        let plans = self.object_plans();
        let traced = |clear: bool| -> Vec<String> {
            plans
                .iter()
                .filter(|(_, p)| {
                    p.path_traced
                        && p.clear == clear
                        && matches!(self.method, Method::Bssrdf { .. })
                })
                .map(|(name, _)| format!("`{name}`"))
                .collect()
        };
        let groups = [
            (
                traced(true),
                "its medium does not scatter (a clear absorbing dielectric, which no BSSRDF \
                 describes)",
            ),
            (
                traced(false),
                "too small for a half-space profile (`--method auto`; `--method sone` renders \
                 it with the BSSRDF)",
            ),
        ];
        let traced = groups
            .into_iter()
            .filter(|(names, _)| !names.is_empty())
            .map(|(names, why)| format!("path traced, {why}: {}", names.join(", ")));
        let corrections = self.scene.objects().iter().zip(&self.objects).filter_map(
            |(object, kind)| match kind {
                ObjectKind::Translucent {
                    bssrdf: Some(b), ..
                } => b.correction.as_ref().map(|c| {
                    let (points, h, seconds) = c.summary();
                    format!(
                        "shape correction of `{}`: {points} points {h:.3} apart, measured in \
                         {seconds:.2} s",
                        object.name
                    )
                }),
                _ => None,
            },
        );
        traced.chain(corrections).collect()
    }

    /// The method rendered.
    pub fn method(&self) -> Method {
        self.method
    }

    /// How each translucent object is rendered, by name ([`crate::integrator::plan::plan`]):
    /// what the sidecar records.
    pub fn object_plans(&self) -> Vec<(String, crate::integrator::plan::ObjectPlan)> {
        crate::integrator::plan::plan(self.scene, self.method)
            .into_iter()
            .zip(self.scene.objects())
            .filter_map(|(p, o)| Some((o.name.clone(), p?)))
            .collect()
    }

    /// Radiance arriving along `ray` (one sample).
    pub fn li(&self, ray: Ray, rng: &mut Rng, counters: &mut PathCounters) -> Rgb {
        counters.paths += 1;
        let mut st = PathState {
            l: Rgb::ZERO,
            beta: Rgb::ONE,
            hero: None,
            r_u: Rgb::ONE,
            order: 0,
            entered: false,
            medium: None,
            prev: Prev::Specular,
            deferred: None,
            rng,
            counters,
        };
        let mut ray = ray;
        let mut arrived = None;
        let filter = self.options.scattering;
        for depth in 0..self.options.max_depth {
            let hit = match arrived.take() {
                Some((hit, dir)) => {
                    ray = Ray::new(ray.origin, dir);
                    hit
                }
                None => match self.scene.geometry().intersect(&ray) {
                    Some(hit) => hit,
                    None => {
                        let le = self.escaped(&ray, st.prev);
                        if !le.is_zero() {
                            self.settle(&mut st);
                            st.add(st.beta * le, st.order, st.entered, filter);
                        }
                        break;
                    }
                },
            };
            let step = match &self.objects[hit.object as usize] {
                ObjectKind::Translucent { .. } if st.medium.is_some() => {
                    // Another medium met from inside one: only where two objects touch
                    // (overlaps are refused at load). Step over its face.
                    st.counters.wrong_side += 1;
                    self.go_on(hit.spawn_ray(ray.dir), &mut st)
                }
                ObjectKind::Translucent {
                    material,
                    bssrdf,
                    grey,
                    ..
                } => match bssrdf {
                    None => {
                        let medium = MediumObject {
                            object: hit.object,
                            material,
                            grey: *grey,
                        };
                        self.volumetric(&hit, &ray, medium, &mut st)
                    }
                    Some(b) => self.subsurface(&hit, &ray, material, b, &mut st),
                },
                ObjectKind::Opaque => match &self.scene.objects()[hit.object as usize].material {
                    Material::Emissive { .. } => {
                        let le = self.emitted(&hit, &ray, st.prev);
                        if !le.is_zero() {
                            self.settle(&mut st);
                            st.add(st.beta * le, st.order, st.entered, filter);
                        }
                        Step::Stop
                    }
                    Material::Diffuse(d) => self.diffuse(&hit, &ray, d, &mut st),
                    Material::Translucent(_) => unreachable!("translucent objects are prepared"),
                },
            };
            match step {
                Step::Continue(next) => ray = next,
                Step::Arrive(hit, dir) => arrived = Some((hit, dir)),
                Step::Stop => break,
            }
            if depth + 1 >= RR_DEPTH {
                let q = st.beta.max_component().min(0.95);
                if q.is_nan() || q <= 0.0 || st.rng.uniform() >= q {
                    break;
                }
                st.beta /= q;
            }
        }
        st.l
    }

    /// Environment radiance along an escaped ray, MIS-weighted against light sampling.
    fn escaped(&self, ray: &Ray, prev: Prev) -> Rgb {
        let mut le = Rgb::ZERO;
        for (i, light) in self.scene.lights().iter().enumerate() {
            if let Light::Environment(_) = light {
                let w = match prev {
                    Prev::Specular | Prev::MirrorCounted => 1.0,
                    Prev::Sampled { p, pdf, at } => {
                        let pl = light.pdf_li(p, ray.dir, p + ray.dir) * self.light_pdf(i, at);
                        self.strategy.hit_weight(pdf, pl)
                    }
                };
                le += light.le(ray.dir) * w;
            }
        }
        le
    }

    /// Emission of an emissive object hit by chance, MIS-weighted.
    fn emitted(&self, hit: &Hit, ray: &Ray, prev: Prev) -> Rgb {
        let Some(i) = self.scene.objects()[hit.object as usize].emitter else {
            return Rgb::ZERO;
        };
        let light = &self.scene.lights()[i];
        let le = light.emitted(hit, -ray.dir);
        match prev {
            Prev::Specular => le,
            Prev::MirrorCounted => Rgb::ZERO,
            Prev::Sampled { p, pdf, at } => {
                let pl = light.pdf_li(p, ray.dir, hit.p) * self.light_pdf(i, at);
                le * self.strategy.hit_weight(pdf, pl)
            }
        }
    }

    /// Next-event estimation for a smooth dielectric's mirror reflection at `hit` toward `dir`
    /// with reflectance `r`: the emitter (a quad light) that direction sees directly, times
    /// `r`, added to the path now; the path then chooses reflection or transmission as
    /// before, and a reflection marks its next vertex [`Prev::MirrorCounted`], where an emitter
    /// counts zero. A delta BSDF has one direction, so tracing it is its light sample, with
    /// MIS weight 1 and 0 for the random hit. pbrt-v4 (§13.1.1) skips light sampling at delta
    /// BSDFs and leaves lights to the random choice, which shows a small bright light in a
    /// smooth dielectric (reflectance a few per cent at normal incidence) as speckles; here it
    /// is smooth at any spp, for one ray per reflection off a translucent object. The
    /// environment is left to the random choice: it is seen by every path that escapes, and a
    /// uniform one then gives every path the same value (the white furnaces stay exact).
    /// Skipped without quad lights, and under [`LightStrategy::DirectionOnly`] (which counts
    /// lights hit by chance only).
    fn mirror_emission(&self, hit: &Hit, dir: DVec3, r: f64, st: &mut PathState<'_>) -> bool {
        if !self.mirror_nee || self.strategy == LightStrategy::DirectionOnly || r <= 0.0 {
            return false;
        }
        let ray = hit.spawn_ray(dir);
        if let Some(h) = self.scene.geometry().intersect(&ray) {
            let le = self.emitted(&h, &ray, Prev::Specular);
            if !le.is_zero() {
                self.settle(st);
                st.add(
                    st.beta * le * r,
                    st.order,
                    st.entered,
                    self.options.scattering,
                );
            }
        }
        true
    }

    fn lights(&self, at: Vertex) -> &LightSet {
        match at {
            Vertex::Surface => &self.surface_lights,
            Vertex::Medium => &self.medium_lights,
        }
    }

    fn light_pdf(&self, i: usize, at: Vertex) -> f64 {
        let lights = self.lights(at);
        if lights.contains(i) {
            lights.select_pdf()
        } else {
            0.0
        }
    }

    /// The direction from `p` toward the light sample `pick` (NEE's choice of a surface light
    /// and its point), for the oblique shape's probe guide ([`BssrdfObject::shift_guide`]).
    /// `None` where there is no light or no light at `p` (behind a quad, a beam).
    fn light_direction(&self, p: DVec3, pick: LightPick) -> Option<DVec3> {
        let i = self.lights(Vertex::Surface).select(pick.u)?;
        Some(self.scene.lights()[i].sample_li(p, pick.u2)?.wi)
    }

    /// Next-event estimation from the vertex `v`: one light chosen uniformly, its sample
    /// weighted by `f(wi)` (BSDF·cos or phase value) and MIS against `pdf(wi)` (the direction
    /// sampler's pdf), times the transmittance per channel of the shadow ray from
    /// `origin_for(wi)`. Returns radiance (before path weight) and whether the shadow ray
    /// crossed a medium.
    fn direct(
        &self,
        v: LightVertex,
        origin_for: impl Fn(DVec3) -> DVec3,
        f_and_pdf: impl Fn(DVec3) -> (f64, f64),
        rng: &mut Rng,
        counters: &mut PathCounters,
    ) -> Direct {
        let pick = LightPick::draw(rng);
        self.direct_with(v, pick, origin_for, f_and_pdf, rng, counters)
    }

    /// [`Self::direct`] with the light and its sample drawn beforehand (`pick`).
    fn direct_with(
        &self,
        v: LightVertex,
        pick: LightPick,
        origin_for: impl Fn(DVec3) -> DVec3,
        f_and_pdf: impl Fn(DVec3) -> (f64, f64),
        rng: &mut Rng,
        counters: &mut PathCounters,
    ) -> Direct {
        let LightPick { u, u2 } = pick;
        if self.strategy == LightStrategy::DirectionOnly {
            return Direct::NONE;
        }
        let lights = self.lights(v.at);
        let Some(i) = lights.select(u) else {
            return Direct::NONE;
        };
        let light = &self.scene.lights()[i];
        let Some(ls) = light.sample_li(v.p, u2) else {
            return Direct::NONE;
        };
        let (f, pdf_dir) = f_and_pdf(ls.wi);
        if f.is_nan() || f <= 0.0 {
            return Direct::NONE;
        }
        let origin = origin_for(ls.wi);
        let Some(seg) = ShadowSegment::toward(origin, &ls) else {
            return Direct::NONE;
        };
        let shadow = self.shadow(&seg, v.medium, rng, counters);
        if shadow.tr.is_zero() {
            return Direct::NONE;
        }
        let w = if ls.delta {
            1.0
        } else {
            self.strategy
                .nee_weight(ls.pdf * lights.select_pdf(), pdf_dir)
        };
        Direct {
            l: ls.li * shadow.tr * (f * w / lights.select_pdf()),
            through_medium: shadow.through_medium,
            wi: ls.wi,
        }
    }

    /// Transmittance of the shadow segment `seg`, which starts inside `medium` (if any): 0 if
    /// anything opaque is in the way; through index-matched media (path tracing only) by ratio
    /// tracking, per channel. A hit on the sampled light's own object ends the segment: the
    /// light is reached.
    fn shadow(
        &self,
        seg: &ShadowSegment,
        medium: Option<u32>,
        rng: &mut Rng,
        counters: &mut PathCounters,
    ) -> Transmission {
        // From outside every medium, toward a light that is no object, past objects that
        // all block: only whether anything is hit matters (pbrt-v4's `IntersectP`), without
        // the closest hit's search and its hit record.
        if medium.is_none() && seg.light_object.is_none() && !self.shadows_cross_objects {
            let ray = Ray::with_range(seg.origin, seg.dir, 0.0, seg.t_max);
            return if self.scene.geometry().occluded(&ray) {
                Transmission::BLOCKED
            } else {
                Transmission {
                    tr: Rgb::ONE,
                    through_medium: false,
                }
            };
        }
        let dir = seg.dir;
        let mut origin = seg.origin;
        let mut remaining = seg.t_max;
        let mut inside = medium;
        let mut tr = Rgb::ONE;
        let mut through_medium = false;
        for _ in 0..MAX_SHADOW_CROSSINGS {
            let ray = Ray::with_range(origin, dir, 0.0, remaining);
            let hit = self.scene.geometry().intersect(&ray);
            if let Some(m) = inside {
                // The segment up to the hit (or to its end) lies inside medium `m`; a ray that
                // finds no boundary inside a closed object has leaked and is left as it is.
                let t = hit.map_or(remaining, |h| h.t);
                through_medium = true;
                if t.is_finite() {
                    tr *= self.medium_transmittance(m, origin, dir, t, rng, counters);
                    if tr.is_zero() {
                        return Transmission::BLOCKED;
                    }
                }
            }
            let Some(h) = hit else {
                return Transmission { tr, through_medium };
            };
            if Some(h.object) == seg.light_object {
                return Transmission { tr, through_medium };
            }
            if !self.objects[h.object as usize].passes_shadow_rays() {
                return Transmission::BLOCKED;
            }
            inside = (dir.dot(h.ng) < 0.0).then_some(h.object);
            origin = h.spawn_origin(dir);
            remaining -= h.t;
            if remaining <= 0.0 {
                return Transmission { tr, through_medium };
            }
        }
        Transmission::BLOCKED
    }

    /// Transmittance of the medium of `object` along `origin + t·dir`, `t ∈ (0, t_max)`: one
    /// estimate for a grey medium, one per channel, each by its own residual ratio tracking,
    /// for a chromatic one (whatever the path's hero: the shadow ray's own sampling does not
    /// depend on it, `docs/physics.md#spectral-mis`).
    fn medium_transmittance(
        &self,
        object: u32,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        rng: &mut Rng,
        counters: &mut PathCounters,
    ) -> Rgb {
        let ObjectKind::Translucent { material, grey, .. } = &self.objects[object as usize] else {
            return Rgb::ONE;
        };
        let mut tc = crate::volume::TrackingCounters::default();
        let mut one = |c: usize| {
            let view = ChannelView::new(&material.medium, c);
            transmittance(&view, origin, dir, t_max, rng, &mut tc)
        };
        let tr = if *grey {
            Rgb::splat(one(0))
        } else {
            Rgb([one(0), one(1), one(2)])
        };
        counters.add_tracking(&tc);
        tr
    }

    /// A diffuse surface: NEE plus cosine-weighted continuation. Inside a medium the shadow
    /// ray starts in it and the continuation walks on in it.
    fn diffuse(&self, hit: &Hit, ray: &Ray, material: &Diffuse, st: &mut PathState<'_>) -> Step {
        let n = if hit.ns.dot(ray.dir) < 0.0 {
            hit.ns
        } else {
            -hit.ns
        };
        let albedo = material.albedo_at(hit);
        // π f / ρ: 1 (Lambert), or the Oren–Nayar factor of a rough surface.
        let sigma = material.roughness_at(hit);
        let shape = |wi: DVec3| {
            if sigma > 0.0 {
                oren_nayar(sigma, n, -ray.dir, wi)
            } else {
                1.0
            }
        };
        let ld = self.direct(
            LightVertex {
                p: hit.p,
                medium: st.medium,
                at: Vertex::Surface,
            },
            |wi| hit.spawn_origin(wi),
            |wi| {
                let c = wi.dot(n);
                if c > 0.0 {
                    let pdf = c / std::f64::consts::PI;
                    (shape(wi) * pdf, pdf)
                } else {
                    (0.0, 0.0)
                }
            },
            st.rng,
            st.counters,
        );
        if !ld.l.is_zero() {
            self.settle(st);
        }
        // Light whose shadow ray crossed a medium has entered one, as the cosine-sampled path
        // through the same medium will have (`entered` set with no scattering added).
        st.add(
            st.beta * albedo * ld.l,
            st.order,
            st.entered || ld.through_medium,
            self.options.scattering,
        );
        let Some((wi, cos)) = cosine_continuation(n, st.rng) else {
            return Step::Stop;
        };
        st.beta *= albedo * shape(wi);
        st.prev = Prev::Sampled {
            p: hit.p,
            pdf: cos / std::f64::consts::PI,
            at: Vertex::Surface,
        };
        self.go_on(hit.spawn_ray(wi), st)
    }

    /// Continues a path along `ray`: outside any medium, the caller traces it; inside one, the
    /// walk carries it to the boundary or to the next surface in the medium.
    fn go_on(&self, ray: Ray, st: &mut PathState<'_>) -> Step {
        let Some(object) = st.medium else {
            return Step::Continue(ray);
        };
        let ObjectKind::Translucent { material, grey, .. } = &self.objects[object as usize] else {
            unreachable!("a path's medium is a translucent object");
        };
        let medium = MediumObject {
            object,
            material,
            grey: *grey,
        };
        let from = WalkStart {
            origin: ray.origin,
            dir: ray.dir,
            last_scatter: st.prev.sampled(),
        };
        self.traverse(medium, from, st)
    }

    /// Path tracing inside the translucent object `medium` hit at `hit` by `ray`: refraction
    /// in, then the walk ([`Self::traverse`]).
    fn volumetric(
        &self,
        hit: &Hit,
        ray: &Ray,
        medium: MediumObject<'_>,
        st: &mut PathState<'_>,
    ) -> Step {
        let material = medium.material;
        let interface = Interface::of(material);
        if ray.dir.dot(hit.ng) >= 0.0 {
            // Arrived from inside (a camera inside the object): pass the face.
            return Step::Continue(hit.spawn_ray(ray.dir));
        }
        let dir = match interface.rough_alpha(hit) {
            Some(alpha) => match self.rough_boundary(hit, ray.dir, hit.ng, alpha, &interface, st) {
                Crossed::Entered(t) => t,
                Crossed::Stepped(step) => return step,
            },
            None => {
                // A light seen in the mirror direction is found by next-event estimation
                // (weighed by MIS against this reflection), so the reflection does not count
                // it again when it hits the light ([`Prev::MirrorCounted`]).
                let counted = !interface.is_index_matched() && {
                    let cos_i = (-ray.dir.dot(hit.ng)).clamp(0.0, 1.0);
                    let r = bssrdf_core::fresnel::dielectric(cos_i, material.eta);
                    let mirror = crate::integrator::walk::reflect(ray.dir, hit.ng);
                    self.mirror_emission(hit, mirror, r, st)
                };
                match interface.cross(ray.dir, hit.ng, st.rng) {
                    Crossing::Reflect(r) => {
                        st.prev = if counted {
                            Prev::MirrorCounted
                        } else {
                            Prev::Specular
                        };
                        return Step::Continue(hit.spawn_ray(r));
                    }
                    Crossing::Transmit(t) => t,
                    Crossing::Lost => return Step::Stop,
                }
            }
        };
        st.entered = true;
        // Through an index-matched boundary the direction is unchanged: the vertex before the
        // entry still is the one an unscattered exit is weighed against (its light sample saw
        // through the medium).
        let from = WalkStart {
            origin: hit.spawn_origin(dir),
            dir,
            last_scatter: if interface.is_index_matched() {
                st.prev.sampled()
            } else {
                None
            },
        };
        self.traverse(medium, from, st)
    }

    /// A rough boundary met from outside at `hit` by a ray travelling along `dir`, about the
    /// macro-normal `n` (facing the ray), with roughness `alpha`: next-event estimation on the
    /// reflection lobe, MIS-weighted against the boundary's own sampling (pbrt-v4 §13.4 with
    /// the energy-conserving rough dielectric `f / E` of [`crate::bsdf::dielectric`]: the
    /// highlights of lights on a rough surface), then a sampled crossing. Returns the
    /// transmitted direction, or the step taken when the path was reflected (on, with the
    /// sample's density for MIS) or lost.
    #[inline(never)] // out of the smooth boundaries' path
    fn rough_boundary(
        &self,
        hit: &Hit,
        dir: DVec3,
        n: DVec3,
        alpha: f64,
        interface: &Interface<'_>,
        st: &mut PathState<'_>,
    ) -> Crossed {
        let frame = Frame::new(n);
        let wo = frame.to_local(-dir);
        let bsdf = RoughDielectric::new(interface.eta, alpha);
        // The single-scattering albedo seen from ω_o, which the conserving lobe divides by.
        let albedo = match self.boundary_table(hit.object) {
            Some(t) => t.albedo(wo.z, alpha),
            None => 1.0,
        };
        let conserving_pdf = |l: DVec3, pdf: f64| {
            let d = bsdf.distribution;
            pdf * (d.g(wo, l) / d.g1(wo)) / albedo
        };
        if albedo > 0.0 {
            let ld = self.direct(
                LightVertex {
                    p: hit.p,
                    medium: st.medium,
                    at: Vertex::Surface,
                },
                |wi| hit.spawn_origin(wi),
                |wi| {
                    let l = frame.to_local(wi);
                    if l.z <= 0.0 {
                        return (0.0, 0.0); // the transmission lobe finds no light inside
                    }
                    (
                        bsdf.f(wo, l) * l.z / albedo,
                        conserving_pdf(l, bsdf.pdf(wo, l)),
                    )
                },
                st.rng,
                st.counters,
            );
            if !ld.l.is_zero() {
                self.settle(st);
            }
            st.add(
                st.beta * ld.l,
                st.order,
                st.entered || ld.through_medium,
                self.options.scattering,
            );
        }
        match interface.cross_rough(dir, n, alpha, st.rng) {
            (Crossing::Transmit(t), _) => Crossed::Entered(t),
            (Crossing::Reflect(r), Some(s)) => {
                st.prev = Prev::Sampled {
                    p: hit.p,
                    pdf: conserving_pdf(s.wi, s.pdf),
                    at: Vertex::Surface,
                };
                Crossed::Stepped(Step::Continue(hit.spawn_ray(r)))
            }
            _ => Crossed::Stepped(Step::Stop),
        }
    }

    /// The rough boundary's table of `object` (a translucent object with a rough boundary).
    fn boundary_table(&self, object: u32) -> Option<&TransmittanceTable> {
        match self.objects.get(object as usize)? {
            ObjectKind::Translucent { boundary, .. } => boundary.as_deref(),
            ObjectKind::Opaque => None,
        }
    }

    /// The volumetric random walk in `medium` from `from` (see [`super::walk`]), with
    /// next-event estimation at every counted scattering vertex through an index-matched
    /// boundary. `from.last_scatter` is the light-sampled vertex the walk starts from (a
    /// diffuse surface inside the medium), for MIS if the walk leaves or reaches an emitter
    /// unscattered. A path entering its first chromatic medium picks its hero channel here; a
    /// chromatic medium is walked with hero tracking, its density ratios carried into `beta`
    /// and `r_u` (spectral MIS, [`carried`]).
    fn traverse(&self, medium: MediumObject<'_>, from: WalkStart, st: &mut PathState<'_>) -> Step {
        let MediumObject {
            object,
            material,
            grey,
        } = medium;
        if st.hero.is_none() && !grey {
            st.hero = Some(st.rng.below(3) as usize);
        }
        // The vertex before the medium (`from` is its sampled part): a walk that leaves
        // without scattering keeps it, with the lights its own light sampling could choose.
        let before = st.prev;
        st.medium = Some(object);
        let nee = Interface::of(material).is_index_matched() && !self.medium_lights.is_empty();
        let filter = self.options.scattering;
        self.settle(st);
        let (beta, r_u) = (st.beta, st.r_u);
        let mut added = Rgb::ZERO;
        let mut scattered = false;
        let mut nee_counters = PathCounters::default();
        let mut order = st.order;
        let mut q = Rgb::ONE;
        let on_scatter = |p: DVec3, d_in: DVec3, k: u32, q: Rgb, rng: &mut Rng| {
            scattered = true;
            if nee && filter.counts(k) {
                let g = material.g;
                let ld = self.direct(
                    LightVertex {
                        p,
                        medium: Some(object),
                        at: Vertex::Medium,
                    },
                    |_| p,
                    |wi| {
                        let f = bssrdf_core::hg::phase(d_in.dot(wi), g);
                        (f, f)
                    },
                    rng,
                    &mut nee_counters,
                );
                if !ld.l.is_zero() {
                    // The throughput at this vertex, weighted over the heroes.
                    added += carried(beta, r_u, q).0 * ld.l;
                }
            }
        };
        let (rng, counters) = (&mut *st.rng, &mut *st.counters);
        let end = match st.hero {
            Some(hero) if !grey => {
                let flight = HeroTracking {
                    medium: SpectralView::new(&material.medium),
                    hero,
                };
                self.walk_in(medium, &flight)
                    .walk_carrying(from, &mut order, &mut q, rng, counters, on_scatter)
            }
            _ => {
                let flight = ChannelView::new(&material.medium, 0);
                self.walk_in(medium, &flight)
                    .walk_carrying(from, &mut order, &mut q, rng, counters, on_scatter)
            }
        };
        st.counters.merge(&nee_counters);
        st.l += added;
        st.carry(q);
        st.order = order;
        // A scattering vertex without light sampling (η > 1) leaves nothing to weigh against.
        let prev = |last_scatter: Option<(DVec3, f64)>| match last_scatter {
            _ if !scattered => before,
            Some((p, pdf)) if nee => Prev::Sampled {
                p,
                pdf,
                at: Vertex::Medium,
            },
            _ => Prev::Specular,
        };
        match end {
            WalkEnd::Exited {
                hit: exit,
                dir,
                last_scatter,
            } => {
                st.prev = prev(last_scatter);
                st.medium = None;
                Step::Continue(exit.spawn_ray(dir))
            }
            WalkEnd::Surface {
                hit,
                dir,
                last_scatter,
            } => {
                st.prev = prev(last_scatter);
                Step::Arrive(hit, dir)
            }
            WalkEnd::Absorbed | WalkEnd::Capped | WalkEnd::Leaked => Step::Stop,
        }
    }

    /// The walk of [`Self::traverse`] in `medium` with the free-flight sampler `flight`.
    fn walk_in<'a, M: FreeFlight>(
        &'a self,
        medium: MediumObject<'a>,
        flight: &'a M,
    ) -> WalkMedium<'a, M> {
        WalkMedium {
            geometry: self.scene.geometry(),
            object: medium.object,
            medium: flight,
            g: medium.material.g,
            interface: Interface::of(medium.material),
        }
    }

    /// The BSSRDF at x_o = `hit`: Fresnel reflection (η > 1), then incident points x_i from
    /// probe rays ([`super::probe_gathering`]), and at each of them the estimated homogeneous
    /// coefficients, the profile at r = |x_i − x_o|, and irradiance through pbrt-v4's
    /// normalised Fresnel lobe S_w(ω_i) = (1 − F_r(cos θ_i)) / (c π), c = 1 − 2 C1(1/η)
    /// (pbrt-v4 §11.4, `NormalizedFresnelBxDF`), times the tabulated profile's angular
    /// coupling where it applies ([`BssrdfObject::coupling`]). The path continues from one of
    /// the x_i with a cosine-sampled direction. In three steps: the exit through the boundary
    /// here, gathering at the incident points ([`Self::gather`]) and the continuation
    /// ([`Self::continue_from`]).
    fn subsurface(
        &self,
        hit: &Hit,
        ray: &Ray,
        material: &Translucent,
        b: &BssrdfObject,
        st: &mut PathState<'_>,
    ) -> Step {
        if ray.dir.dot(hit.ng) >= 0.0 {
            return Step::Continue(hit.spawn_ray(ray.dir));
        }
        let Some(n_o) = facing_normal(hit, -ray.dir) else {
            return Step::Continue(hit.spawn_ray(ray.dir));
        };
        // The exit through the boundary: Fresnel reflection of a smooth boundary with its
        // probability (a light in the mirror direction found by next-event estimation); a
        // rough one reflects off a sampled microfacet (light found by next-event estimation
        // too) or transmits with the weight whose mean is T(μ_o; α), the rough transmittance S
        // uses ([`BssrdfObject::transmission`]).
        let alpha_o = b.rough_alpha(hit);
        match alpha_o {
            Some(alpha) => {
                let interface = Interface::of(material);
                if let Crossed::Stepped(step) =
                    self.rough_boundary(hit, ray.dir, n_o, alpha, &interface, st)
                {
                    return step;
                }
            }
            None if material.eta != 1.0 => {
                let cos_o = (-ray.dir.dot(n_o)).clamp(0.0, 1.0);
                let r = bssrdf_core::fresnel::dielectric(cos_o, material.eta);
                let mirror = crate::integrator::walk::reflect(ray.dir, n_o);
                let counted = self.mirror_emission(hit, mirror, r, st);
                if st.rng.uniform() < r {
                    st.prev = if counted {
                        Prev::MirrorCounted
                    } else {
                        Prev::Specular
                    };
                    return Step::Continue(hit.spawn_ray(mirror));
                }
            }
            None => {}
        }
        let alpha_o = alpha_o.unwrap_or(0.0);
        if let Some(f_o) = b.correction_along(hit, -ray.dir, n_o) {
            st.beta *= f_o; // the shape correction's exit factor
        }
        let v = BssrdfVertex {
            material,
            b,
            surface: ObjectSurface {
                geometry: self.scene.geometry(),
                object: hit.object,
            },
            x_o: hit,
            w_o: -ray.dir,
            n_o,
            alpha_o,
        };
        let Some(carrier) = self.gather(&v, st) else {
            return Step::Stop;
        };
        self.continue_from(&v, carrier, st)
    }

    /// The incident points x_i of the BSSRDF vertex `v`, from probe rays
    /// ([`super::probe_gathering`]), each gathering light by next-event estimation (S_w, the
    /// shape correction's entry factor for the light's direction, the profile weight and the
    /// angular coupling), added to the path; and the carrier, the point the path continues from
    /// ([`Gathering`]), with its weight. `None` when the probes found no point or none carries
    /// the path.
    fn gather(&self, v: &BssrdfVertex<'_>, st: &mut PathState<'_>) -> Option<Carrier> {
        let (material, b, hit) = (v.material, v.b, v.x_o);
        let at_xo = material.medium.coefficients(hit);
        let mut set = crate::integrator::probe_gathering::ProbePoints::new();
        // Only with the oblique shape: the light sample every x_i gathers from and the
        // continuation's direction are drawn first, and the probes lean the way S does for
        // them (renders without the shape are unchanged).
        let first = b.has_oblique_shape().then(|| DrawnFirst::draw(st.rng));
        let pick = first.map(|f| f.light);
        let [light, continuation] = self.shift_guides(v, at_xo, first);
        let continuation = continuation
            .as_ref()
            .and_then(|g| GuidedAzimuths::new(g, hit));
        let guide = match (
            light.as_ref().and_then(|g| GuidedAzimuths::new(g, hit)),
            &continuation,
        ) {
            // Half each: which of the two carries more light is not known at x_o.
            (Some(l), Some(c)) => Some(l.mixed_with(c, 0.5)),
            (l, _) => l,
        };
        let guide = guide.as_ref().or(continuation.as_ref());
        let density = b.probe_points_into(&mut set, &v.surface, hit, at_xo, guide, st.rng);
        st.counters.probe_sets += 1;
        if set.is_empty() {
            st.counters.probe_misses += 1;
            return None;
        }
        // Every point may gather light; one carries the path on (see [`Gathering`]). None
        // when p(x) = 0 at every hit (a sphere's edge, or x_o itself).
        let gathering = Gathering::new(&set, &density, st.rng)?;
        let (carrier, scale) = (gathering.carrier(), gathering.carrier_scale());
        let mut next = None;
        for (k, (&x_i, _)) in set.found().enumerate() {
            let Some(weight) = gathering.weight_if_gathering(k, st.rng) else {
                continue;
            };
            let alpha_i = b.alpha_at(&x_i);
            let ld = self.direct_with(
                LightVertex {
                    p: x_i.p,
                    medium: None,
                    at: Vertex::Surface,
                },
                pick.unwrap_or_else(|| LightPick::draw(st.rng)),
                |wi| x_i.spawn_origin(wi),
                |wi| {
                    // S_w · cos against the continuation's pdf (cosine about the shading
                    // normal), with the normal rule the light tracer uses too.
                    let Some(n) = facing_normal(&x_i, wi) else {
                        return (0.0, 0.0);
                    };
                    let cos = wi.dot(n);
                    let pdf = wi.dot(x_i.ns).max(0.0) / std::f64::consts::PI;
                    (b.entry_lobe(cos, alpha_i, v.alpha_o) * cos, pdf)
                },
                st.rng,
                st.counters,
            );
            // The shape correction's entry factor for the light's direction, and the direction
            // and normal the angular coupling reads.
            let w_light = ld.wi;
            let (ld, n_light) = match facing_normal(&x_i, ld.wi) {
                Some(n) if !ld.l.is_zero() => (
                    b.correction_along(&x_i, ld.wi, n)
                        .map_or(ld.l, |f_i| ld.l * f_i),
                    n,
                ),
                _ => (ld.l, x_i.ns),
            };
            if ld.is_zero() && k != carrier {
                continue; // nothing to gather, nothing to carry
            }
            if ld.is_zero() && self.defer_weights {
                // Nothing to gather: the carrier owes its (costly) estimate.
                next = Some((x_i, CarrierWeight::Owed(weight * scale)));
                continue;
            }
            let pw = b.profile(&v.surface, &material.medium, &x_i, hit, st.rng, st.counters);
            let w = pw.rd * weight;
            self.settle(st);
            if !ld.is_zero() {
                st.l += st.beta * w * ld * b.coupling(&pw, w_light, n_light, v.w_o, v.n_o);
            }
            if k == carrier {
                next = Some((x_i, CarrierWeight::Evaluated(w * scale, pw)));
            }
        }
        next.map(|(x_i, weight)| Carrier {
            x_i,
            weight,
            continuation: first.map(|f| f.continuation),
        })
    }

    /// The oblique shape's probe guides at the BSSRDF vertex `v` (x_o's coefficients
    /// `at_xo`) for what was drawn `first`: the light sample's, and the continuation's where
    /// direct light arrives by it too (an environment: `guide_continuation`). `[None, None]`
    /// without the shape.
    fn shift_guides<'b>(
        &self,
        v: &BssrdfVertex<'b>,
        at_xo: het_estimate::Coefficients,
        first: Option<DrawnFirst>,
    ) -> [Option<ShiftGuide<'b>>; 2] {
        let (b, hit) = (v.b, v.x_o);
        let light = b.shift_guide(at_xo, v.w_o, v.n_o, || {
            first.and_then(|f| self.light_direction(hit.p, f.light))
        });
        let continuation = first.filter(|_| self.guide_continuation).and_then(|f| {
            b.shift_guide(at_xo, v.w_o, v.n_o, || {
                cosine_direction(hit.ns, f.continuation).map(|(w, _)| w)
            })
        });
        [light, continuation]
    }

    /// The path's continuation from the carrier `x_i` of the BSSRDF vertex `v`, whose weight is
    /// `carried`: a cosine-sampled direction about x_i's shading normal, weighted by S_w, the
    /// shape correction's entry factor and the angular coupling (now, or with the profile
    /// weight when that is owed, [`Deferred`]).
    fn continue_from(
        &self,
        v: &BssrdfVertex<'_>,
        carrier: Carrier,
        st: &mut PathState<'_>,
    ) -> Step {
        let (b, x_i) = (v.b, carrier.x_i);
        let carried = match carrier.weight {
            CarrierWeight::Evaluated(w, pw) => {
                st.beta *= w;
                Ok(pw)
            }
            CarrierWeight::Owed(scale) => {
                // One factor is owed at a time: settle an older one first. The new one is
                // owed once the continuation's direction is known (below).
                self.settle(st);
                Err(scale)
            }
        };
        if st.beta.is_zero() {
            return Step::Stop;
        }
        let continuation = match carrier.continuation {
            Some(u) => cosine_direction(x_i.ns, u),
            None => cosine_continuation(x_i.ns, st.rng),
        };
        let Some((wi, cos)) = continuation else {
            return Step::Stop;
        };
        if facing_normal(&x_i, wi).is_none() {
            // Below the geometric surface: S is 0 there (light cannot arrive from inside).
            return Step::Stop;
        }
        // S_w·cos / (cos/π) = (1 − F(cos)) / c.
        st.beta *= b.entry_lobe(cos, b.alpha_at(&x_i), v.alpha_o) * std::f64::consts::PI;
        if let Some(f_i) = b.correction_along(&x_i, wi, x_i.ns) {
            st.beta *= f_i; // the shape correction's entry factor for the continuation
        }
        // The angular coupling for the continuation: now, or when the owed weight is settled.
        match carried {
            Ok(pw) => st.beta *= b.coupling(&pw, wi, x_i.ns, v.w_o, v.n_o),
            Err(scale) => {
                st.deferred = Some(Deferred {
                    object: v.surface.object,
                    x_i,
                    x_o: *v.x_o,
                    scale,
                    w_i: wi,
                    w_o: v.w_o,
                    n_o: v.n_o,
                })
            }
        }
        st.prev = Prev::Sampled {
            p: x_i.p,
            pdf: cos / std::f64::consts::PI,
            at: Vertex::Surface,
        };
        Step::Continue(x_i.spawn_ray(wi))
    }

    /// Evaluates the path's deferred profile weight, if any, into `beta` (see [`Deferred`]).
    fn settle(&self, st: &mut PathState<'_>) {
        let Some(d) = st.deferred.take() else {
            return;
        };
        let Some((material, b)) = self.bssrdf_object(d.object) else {
            unreachable!("a deferred weight belongs to a BSSRDF object");
        };
        let surface = ObjectSurface {
            geometry: self.scene.geometry(),
            object: d.object,
        };
        let pw = b.profile(
            &surface,
            &material.medium,
            &d.x_i,
            &d.x_o,
            st.rng,
            st.counters,
        );
        st.beta *= pw.rd * d.scale * b.coupling(&pw, d.w_i, d.x_i.ns, d.w_o, d.n_o);
    }

    /// The translucent material and BSSRDF data of `object`, when it is rendered with a
    /// BSSRDF.
    pub(crate) fn bssrdf_object(&self, object: u32) -> Option<(&Translucent, &BssrdfObject)> {
        match self.objects.get(object as usize)? {
            ObjectKind::Translucent {
                material,
                bssrdf: Some(b),
                ..
            } => Some((&**material, b.as_ref())),
            _ => None,
        }
    }

    /// The BSSRDF S(x_i, ω_i; x_o, ω_o) this renderer evaluates (1/(length²·sr), per channel;
    /// see `integrator/bssrdf.rs`): light entering at `x_i` from the direction `w_i` (unit,
    /// pointing out of the medium toward the light) and leaving at `x_o` toward `w_o` (unit,
    /// toward the viewer), with the coefficients the method's estimator gives for the pair
    /// (random numbers from `rng`). `None` unless both points lie on the same object and that
    /// object is rendered with a BSSRDF (a BSSRDF method, a translucent object). Symmetric
    /// under (x_i, ω_i) ↔ (x_o, ω_o) for the averaging estimators (docs/reciprocity.md).
    pub fn evaluate_bssrdf(
        &self,
        x_i: &Hit,
        w_i: DVec3,
        x_o: &Hit,
        w_o: DVec3,
        rng: &mut Rng,
    ) -> Option<Rgb> {
        if x_i.object != x_o.object {
            return None;
        }
        let (material, b) = self.bssrdf_object(x_i.object)?;
        let surface = ObjectSurface {
            geometry: self.scene.geometry(),
            object: x_i.object,
        };
        let mut counters = PathCounters::default();
        Some(b.eval(
            &surface,
            &material.medium,
            PairEnd { hit: x_i, w: w_i },
            PairEnd { hit: x_o, w: w_o },
            rng,
            &mut counters,
        ))
    }

    /// The scene rendered.
    pub fn scene(&self) -> &'s Scene {
        self.scene
    }

    /// The options rendered with.
    pub fn options(&self) -> PathOptions {
        self.options
    }

    /// The coefficients of object `object` at its surface point `hit` (point lookup).
    pub fn lookup(&self, hit: &Hit) -> Option<het_estimate::Coefficients> {
        match &self.objects[hit.object as usize] {
            ObjectKind::Translucent { material, .. } => Some(material.medium.coefficients(hit)),
            ObjectKind::Opaque => None,
        }
    }
}

impl PixelEstimator for PathIntegrator<'_> {
    type Counters = PathCounters;
    fn sample(&self, fx: f64, fy: f64, rng: &mut Rng, counters: &mut PathCounters) -> Rgb {
        let ray = self.scene.camera().ray(fx, fy);
        self.li(ray, rng, counters)
    }
}
