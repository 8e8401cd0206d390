//! The separable BSSRDF both BSSRDF renderers evaluate (the camera-traced one in
//! [`super::path`], the light-traced one in [`super::light_trace`]): `bssrdf-core`'s public
//! [`SeparableBssrdf`], whose parts ([`SeparableBssrdf::entry_lobe`],
//! [`SeparableBssrdf::coupling`], [`SeparableBssrdf::combine`]) the renderers call where their
//! sampling splits S:
//!
//! S(x_i, ω_i; x_o, ω_o) = (1 − F_r(cos θ_o)) · R(|x_i − x_o|; σ̄a, σ̄s) · S_w(ω_i),
//! S_w(ω_i) = (1 − F_r(cos θ_i)) / (c π), c = 1 − 2 C1(1/η)
//!
//! (pbrt3 §11.4.1, the separable BSSRDF, with the normalised Fresnel lobe of pbrt-v4's
//! `NormalizedFresnelBxDF` (key pbrt4, its source); F_r the dielectric
//! Fresnel reflectance at relative index η, C1 its first moment), with R the material's
//! diffuse reflectance profile (1/length²) at the homogeneous coefficients σ̄a, σ̄s the
//! estimator gives for the pair (x_i, x_o). The directions ω_i (toward the light) and ω_o
//! (toward the viewer) point out of the medium.
//!
//! Rough boundary (a material with `roughness`, η ≠ 1; `crate::bsdf::transmittance`): both
//! Fresnel transmittances 1 − F_r(cos θ) become the fraction T(cos θ; α) that the
//! energy-conserving rough dielectric lets through at the point's α, and c becomes
//! √(c(α_i) c(α_o)) with c(α) = 2 ∫₀¹ T(μ; α) μ dμ (c(α) for a constant roughness; the
//! geometric mean keeps S symmetric when the roughness is textured). The camera path realises
//! the exit's T by sampling the boundary (it refracts with probability T), the light tracer
//! evaluates it. Both tend to the smooth terms as α → 0.
//!
//! Reciprocity: written as R · (1 − F_r(cos θ_i))(1 − F_r(cos θ_o)) / (c π), S is symmetric
//! under (x_i, ω_i) ↔ (x_o, ω_o) whenever the estimate is (every averaging estimator;
//! not the point lookups `jensen-in`/`jensen-out`, see docs/reciprocity.md). Both cosines use
//! the same rule ([`facing_normal`]), and the product of the two Fresnel factors is formed
//! before it meets the profile, so the swap gives the same value bit for bit.
//!
//! Angular coupling ([`BssrdfObject::coupling`], docs/tabulated-profile.md "Angular
//! coupling"): with the tabulated profile (unless the material sets `angular_coupling =
//! false`), S is also multiplied by T(α', cos θ_i, cos θ_o), the exact half-space response per
//! pair of directions over the separable one, per channel at the pair's reduced albedo. T is
//! symmetric in its two cosines bit for bit, so reciprocity holds as above. T carries its
//! radial part M(σt' r; α', cos θ_i, cos θ_o) (the oblique shape,
//! docs/oblique-incidence.md), symmetric in the cosines as T is. Pairs weighed by the slab
//! profile's transmission keep T = 1.
//!
//! Thin parts ([`BssrdfObject::profile`], docs/shapes.md "Thin parts: the slab profile"):
//! with the tabulated profile, |g| ≤ [`SLAB_MAX_G`] and a material that is `thickness_aware`
//! (the default), a pair
//! that sits as on a slab ([`slab_pair`]) is weighed by the slab profile of
//! `bssrdf_core::slab_profile` at the object's local thickness d, the mean of the two points'
//! thicknesses along their inward normals ([`thickness`]): the reflection R_slab(|x_i − x_o|;
//! d) for two points on one face, the transmission T_slab(ρ; d) for points on opposite faces,
//! ρ the distance from the beam's axis as the slab table measures it. Other pairs keep the
//! half-space profile. Every choice is symmetric in the two points, so reciprocity holds as
//! above.

use std::f64::consts::PI;
use std::sync::Arc;

use bssrdf_core::{
    Crossing, ProfileFamily, ProfileModel, Rgb, Scattering, SeparableBssrdf, ShiftSeries, SlabFace,
};
use glam::DVec3;
use het_estimate::azimuth::{AzimuthGuide, GuidedAzimuths};
use het_estimate::{Estimator, PreparedEstimator};

use crate::bsdf::{SMOOTH_ALPHA, TransmittanceTable, alpha_from_roughness};
use crate::field::{Field, MediumField};
use crate::geometry::{Hit, ObjectSurface, Ray};
use crate::integrator::counters::PathCounters;
use crate::integrator::probe_gathering::ProbeSampler;
use crate::integrator::profile_eval::{eval_profile, eval_slab_profile};
use crate::rng::Rng;
use crate::scene::Translucent;

/// BSSRDF data of one translucent object, prepared once per render.
pub(crate) struct BssrdfObject {
    /// The profile family R.
    pub family: ProfileFamily,
    /// Probe sampling of the other point of a pair around a given one.
    pub sampler: ProbeSampler,
    /// How a pair becomes homogeneous coefficients.
    pub estimator: PreparedEstimator,
    /// S itself: the Fresnel factors, their normalisation c and the angular coupling
    /// (`bssrdf_core::separable`).
    bssrdf: SeparableBssrdf,
    /// The longest side of the object's bounding box: the extent the probe radii are drawn
    /// within ([`super::probe_gathering::probe_within`]).
    pub extent: f64,
    /// Weigh pairs by the slab profile of the local thickness (see the module docs): the
    /// material is `thickness_aware`, the family has a slab table (tabulated model) and
    /// |g| ≤ [`SLAB_MAX_G`].
    thickness_aware: bool,
    /// How far a thickness ray looks for the far side ([`thickness`]): twice the thickness
    /// from which the slab is the half-space for every coefficient the estimates can become
    /// (the field's smallest, [`bssrdf_core::ProfileFamily::half_space_thickness`]); +∞
    /// where no such thickness exists.
    far_side_reach: f64,
    /// The shape correction c (module docs of [`crate::correction`]), when the material
    /// asks for it: the profile is scaled by √(c(x_i) c(x_o)).
    pub correction: Option<crate::correction::factors::ShapeCorrection>,
    /// The rough boundary, when the material has one (module docs).
    rough: Option<RoughBoundary>,
}

/// A rough boundary's roughness and its transmittance table.
struct RoughBoundary {
    /// r (α = r²) over the surface.
    roughness: Field,
    /// T(μ; α) and c(α) over the material's range of α.
    table: Arc<TransmittanceTable>,
}

/// The table of `material`'s rough boundary over its range of α ([`TransmittanceTable`],
/// shared); `None` for a smooth or index-matched boundary.
pub(crate) fn boundary_table(material: &Translucent) -> Option<Arc<TransmittanceTable>> {
    let r = material.roughness.as_ref()?;
    let (lo, hi) = (
        alpha_from_roughness(r.min()[0]),
        alpha_from_roughness(r.max()[0]),
    );
    (material.eta != 1.0 && hi >= SMOOTH_ALPHA)
        .then(|| TransmittanceTable::shared(material.eta, lo.max(SMOOTH_ALPHA), hi))
}

/// The profile weight of one pair, with what the angular coupling needs to finish it
/// ([`BssrdfObject::coupling`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PairWeight {
    /// R (1/length², per channel): the half-space or slab profile at the pair's coefficients.
    pub rd: Rgb,
    /// The homogeneous coefficients the estimator gave for the pair.
    coeffs: het_estimate::Coefficients,
    /// The incident and exitant points: where the coupling's radial part and forward shift
    /// are read.
    points: (DVec3, DVec3),
    /// Whether R is a reflection profile (the half-space's, or a slab's reflection), to which
    /// the half-space's angular coupling applies; not for slab transmission.
    reflection: bool,
}

impl BssrdfObject {
    /// Prepares `material` for a BSSRDF render with `estimator` and the profile `profile`
    /// (or the material's own), for an object whose bounding box's longest side is `extent`;
    /// the error names the failing part (see [`Translucent::prepare_bssrdf`]).
    pub fn new(
        material: &Translucent,
        profile: Option<ProfileModel>,
        scattering: Scattering,
        estimator: Estimator,
        extent: f64,
    ) -> Result<Self, (&'static str, bssrdf_core::ParamError)> {
        let (family, estimator) = material.prepare_bssrdf(profile, scattering, estimator)?;
        let thickness_aware = material.thickness_aware
            && family.model() == ProfileModel::Tabulated
            && family.g().abs() <= SLAB_MAX_G;
        // The tabulated profile's angular coupling, unless the material turns it off
        // (`angular_coupling = false`), with its oblique shape where the material turns it on
        // (`oblique_shape = true`); neither table is built unless kept.
        let bssrdf = SeparableBssrdf::from_family_with(
            family,
            material.angular_coupling,
            material.oblique_shape,
        );
        let rough = boundary_table(material).map(|table| RoughBoundary {
            roughness: material
                .roughness
                .clone()
                .expect("a rough boundary has a roughness"),
            table,
        });
        // A pair whose mean thickness is beyond the half-space thickness of the field's
        // smallest coefficients is weighed by the half-space profile in every channel (the
        // thickness grows as the coefficients fall): if one end's ray finds no far side
        // within twice that, the pair's mean is beyond it whatever the other's.
        let lo = material.medium.field_bounds().min;
        let far_side_reach = (0..3)
            .map(|c| family.half_space_thickness(lo.sigma_a[c], lo.sigma_s[c]))
            .try_fold(0.0f64, |m, d| d.map(|d| m.max(d)))
            .map_or(f64::INFINITY, |d| 2.0 * d);
        Ok(Self {
            bssrdf,
            rough,
            thickness_aware,
            far_side_reach,
            sampler: ProbeSampler::new(family, &material.medium),
            family,
            estimator,
            extent,
            correction: None,
        })
    }

    /// Relative index of refraction η.
    pub fn eta(&self) -> f64 {
        self.bssrdf.eta()
    }

    /// One probe set around `x_o` over `chords` (the object, or the shape correction's
    /// tangent plane), with the radii the renderers use on this object (at most its extent:
    /// [`super::probe_gathering::probe_within`]).
    pub(crate) fn probe_set<C: het_estimate::probe::ProbeChords<Point = Hit>>(
        &self,
        chords: &C,
        x_o: &Hit,
        coeffs: het_estimate::Coefficients,
        rng: &mut Rng,
    ) -> crate::integrator::probe_gathering::ProbeSet {
        self.sampler
            .probe_chords(chords, x_o, coeffs, self.extent, rng)
    }

    /// [`BssrdfObject::probe_set`] without the weights: the points into `points`, and
    /// the density that weights each when the caller needs it. With a `guide`, the normal
    /// probe draws its azimuth from it ([`het_estimate::azimuth`]); `None` is the uniform
    /// azimuth, draw for draw.
    pub(crate) fn probe_points_into<'a, C: het_estimate::probe::ProbeChords<Point = Hit>>(
        &'a self,
        points: &mut crate::integrator::probe_gathering::ProbePoints,
        chords: &C,
        x_o: &Hit,
        coeffs: het_estimate::Coefficients,
        guide: Option<&'a GuidedAzimuths<'a>>,
        rng: &mut Rng,
    ) -> het_estimate::probe::ProbeDensity<'a> {
        let density = self.sampler.density_around(x_o, coeffs, self.extent, guide);
        density.trace_into(points, chords, rng);
        density
    }

    /// Whether this BSSRDF has the oblique shape (`oblique_shape`), whose probes a guide
    /// leans toward the light ([`Self::shift_guide`]).
    pub(crate) fn has_oblique_shape(&self) -> bool {
        self.bssrdf.has_oblique_shape()
    }

    /// The oblique shape's two azimuthal factors as the normal probe's guide around x_o
    /// (docs/oblique-incidence.md, "Sampling"): the incident side's about the direction
    /// `toward_light` returns (called only with the shape): a direction light arrives by that
    /// was drawn before x_i, from x_o toward the light sample next-event estimation then
    /// takes at every x_i (the same direction at x_i for a distant light or an environment,
    /// the same point on a quad, seen from x_i up to the parallax), or the continuation's
    /// direction (`integrator::path`, "two guides"). The exit side's is about the direction
    /// of travel of light arriving along −`w_o`. `n` is x_o's shading normal. `None` without
    /// the oblique shape. A side whose direction lies along the normal, or below the surface,
    /// is left out.
    pub(crate) fn shift_guide(
        &self,
        coeffs: het_estimate::Coefficients,
        w_o: DVec3,
        n: DVec3,
        toward_light: impl FnOnce() -> Option<DVec3>,
    ) -> Option<ShiftGuide<'_>> {
        if !self.bssrdf.has_oblique_shape() {
            return None;
        }
        let mu_o = w_o.dot(n).clamp(0.0, 1.0);
        let (incident, mu_i) = match toward_light() {
            Some(w) if w.dot(n) > 0.0 => (w - w.dot(n) * n, w.dot(n).min(1.0)),
            _ => (DVec3::ZERO, 1.0),
        };
        Some(ShiftGuide {
            series: self.bssrdf.shift_series(&coeffs, GUIDE_CHANNEL),
            directions: [incident, n * mu_o - w_o],
            cosines: (mu_i, mu_o),
        })
    }

    /// The boundary's roughness α at `hit` where it acts as a rough one (α ≥
    /// [`SMOOTH_ALPHA`]); `None` where it is smooth (and for every point of a smooth
    /// material). The rule of [`crate::integrator::walk::Interface::rough_alpha`].
    #[inline]
    pub fn rough_alpha(&self, hit: &Hit) -> Option<f64> {
        let r = self.rough.as_ref()?;
        let alpha = alpha_from_roughness(r.roughness.eval(hit.p, hit.uv)[0]);
        (alpha >= SMOOTH_ALPHA).then_some(alpha)
    }

    /// [`BssrdfObject::rough_alpha`], 0 where the boundary is smooth.
    #[inline]
    pub fn alpha_at(&self, hit: &Hit) -> f64 {
        self.rough_alpha(hit).unwrap_or(0.0)
    }

    /// The fraction of light crossing the boundary at incidence cosine `cos` (unitless): 1 −
    /// F_r(cos θ) for a smooth boundary (`alpha` = 0; 1 for η = 1), the rough transmittance
    /// T(cos; α) otherwise (module docs).
    #[inline]
    pub fn transmission(&self, cos: f64, alpha: f64) -> f64 {
        match &self.rough {
            Some(r) if alpha > 0.0 => r.table.transmittance(cos, alpha),
            _ => self.bssrdf.transmission(cos),
        }
    }

    /// The normalisation of S_w for a pair whose boundary roughness is `alpha_i` at x_i and
    /// `alpha_o` at x_o: c, or √(c(α_i) c(α_o)) through a rough boundary (module docs).
    #[inline]
    fn pair_norm(&self, alpha_i: f64, alpha_o: f64) -> f64 {
        match &self.rough {
            Some(r) if alpha_i > 0.0 || alpha_o > 0.0 => {
                let c = |a: f64| {
                    if a > 0.0 {
                        r.table.norm(a)
                    } else {
                        self.bssrdf.normalisation()
                    }
                };
                (c(alpha_i) * c(alpha_o)).sqrt()
            }
            _ => self.bssrdf.normalisation(),
        }
    }

    /// S_w at incidence cosine `cos` (1/sr): (1 − F_r(cos)) / (c π), or through a rough
    /// boundary T(cos; α_i) / (√(c(α_i) c(α_o)) π).
    #[inline]
    pub fn entry_lobe(&self, cos: f64, alpha_i: f64, alpha_o: f64) -> f64 {
        self.transmission(cos, alpha_i) / (self.pair_norm(alpha_i, alpha_o) * PI)
    }

    /// R(|x_i − x_o|) (1/length², per channel) at the coefficients the estimator gives for
    /// the pair, `x_i` the incident point (where light enters) and `x_o` the exitant one;
    /// for a thickness-aware object the slab profile's reflection or transmission at the
    /// pair's thickness instead (module docs). The estimate and profile evaluation are
    /// recorded in `counters`.
    pub fn profile(
        &self,
        surface: &ObjectSurface<'_>,
        medium: &MediumField,
        x_i: &Hit,
        x_o: &Hit,
        rng: &mut Rng,
        counters: &mut PathCounters,
    ) -> PairWeight {
        // The estimator draws from a generator of its own, seeded by one draw of the path's:
        // however many numbers an estimate takes (none for a closed form, hundreds for
        // sampling), the path's own numbers stay the same, so renders that differ only in
        // how they average (prefiltered or sampled, 16 or 256 points) follow the same paths
        // and can be compared pixel by pixel.
        let mut own = Rng::from_keys(rng.next_u64(), &[]);
        let est = self.estimator.estimate(surface, medium, x_i, x_o, &mut own);
        counters.record_estimate(&est.diagnostics);
        let (rd, reflection) = self.weigh(surface, est.coefficients, x_i, x_o, counters);
        PairWeight {
            rd,
            coeffs: est.coefficients,
            points: (x_i.p, x_o.p),
            reflection,
        }
    }

    /// The angular coupling per channel for a pair weighed as `w`, light arriving from the unit
    /// direction `w_i` about the normal `n_i` at x_i and leaving toward `w_o` about `n_o` at
    /// x_o (the normals S uses, [`facing_normal`]): T(α', μ_i, μ_o) times the oblique shape's
    /// radial part and forward shift (`SeparableBssrdf::coupling_between`;
    /// [`bssrdf_core::tabulated::angular`], [`bssrdf_core::tabulated::oblique`]); 1 without a
    /// coupling or for slab transmission.
    /// Symmetric in the two cosines, bit for bit.
    #[inline]
    pub fn coupling(&self, w: &PairWeight, w_i: DVec3, n_i: DVec3, w_o: DVec3, n_o: DVec3) -> Rgb {
        if !w.reflection {
            return Rgb::splat(1.0);
        }
        let incident = Crossing::new(w.points.0, n_i, w_i);
        let exitant = Crossing::new(w.points.1, n_o, w_o);
        self.bssrdf.coupling_between(&w.coeffs, &incident, &exitant)
    }

    /// The shape correction's factor f(hit, ω) for the unit direction `w` outside the medium
    /// about the normal `n` (`crate::correction`; S is scaled by f(x_i, ω_i)·f(x_o, ω_o)),
    /// or `None` when the material has no correction.
    #[inline]
    pub fn correction_along(&self, hit: &Hit, w: DVec3, n: DVec3) -> Option<Rgb> {
        self.correction.as_ref().map(|c| c.at_hit(hit).along(w, n))
    }

    /// The profile of the pair at the homogeneous coefficients `coeffs`: the half-space
    /// profile at |x_i − x_o|, or for a thickness-aware object the slab profile's reflection or
    /// transmission where the pair sits as on a slab (module docs); and whether it is a
    /// reflection profile ([`PairWeight::reflection`]). Without the shape correction and the
    /// angular coupling.
    pub(crate) fn weigh(
        &self,
        surface: &ObjectSurface<'_>,
        coeffs: het_estimate::Coefficients,
        x_i: &Hit,
        x_o: &Hit,
        counters: &mut PathCounters,
    ) -> (Rgb, bool) {
        let r = (x_i.p - x_o.p).length();
        if !self.thickness_aware {
            return (eval_profile(&self.family, coeffs, r, counters), true);
        }
        let reach = self.far_side_reach;
        let d = 0.5 * (thickness(surface, x_i, reach) + thickness(surface, x_o, reach));
        match slab_pair(x_i, x_o, d) {
            Some((face, dist)) => (
                eval_slab_profile(&self.family, coeffs, d, face, dist, counters),
                face == SlabFace::Reflection,
            ),
            None => (eval_profile(&self.family, coeffs, r, counters), true),
        }
    }

    /// The full S(x_i, ω_i; x_o, ω_o) (1/(length²·sr), per channel; see the module docs) of
    /// the pair `incident` (x_i, ω_i) and `exitant` (x_o, ω_o); 0 when either direction is
    /// behind its surface ([`facing_normal`]).
    pub fn eval(
        &self,
        surface: &ObjectSurface<'_>,
        medium: &MediumField,
        incident: PairEnd<'_>,
        exitant: PairEnd<'_>,
        rng: &mut Rng,
        counters: &mut PathCounters,
    ) -> Rgb {
        let PairEnd { hit: x_i, w: w_i } = incident;
        let PairEnd { hit: x_o, w: w_o } = exitant;
        let (Some(n_i), Some(n_o)) = (facing_normal(x_i, w_i), facing_normal(x_o, w_o)) else {
            return Rgb::ZERO;
        };
        let (cos_i, cos_o) = (w_i.dot(n_i), w_o.dot(n_o));
        let (alpha_i, alpha_o) = (self.alpha_at(x_i), self.alpha_at(x_o));
        let w = self.profile(surface, medium, x_i, x_o, rng, counters);
        let t = self.coupling(&w, w_i, n_i, w_o, n_o);
        // Through a smooth boundary (α = 0) the transmissions and normalisation are
        // SeparableBssrdf's own, so this is its `combine` bit for bit.
        let angular = SeparableBssrdf::boundary_factor(
            self.transmission(cos_i, alpha_i),
            self.transmission(cos_o, alpha_o),
            self.pair_norm(alpha_i, alpha_o),
        );
        let s = w.rd * angular * t;
        match (
            self.correction_along(x_i, w_i, n_i),
            self.correction_along(x_o, w_o, n_o),
        ) {
            // The product of the two factors is formed before it meets S (reciprocity, as
            // above).
            (Some(f_i), Some(f_o)) => s * (f_i * f_o),
            _ => s,
        }
    }
}

/// One end of a BSSRDF pair: the surface point and the unit direction, pointing out of the
/// medium, along which light crosses the boundary there (toward the light at x_i, toward the
/// viewer at x_o).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PairEnd<'h> {
    /// The surface point.
    pub hit: &'h Hit,
    /// The direction outside the medium (unit).
    pub w: DVec3,
}

/// The normal the BSSRDF measures the direction `w` (unit, pointing away from the surface)
/// against at `hit`: `None` when `w` is not in front of the geometric normal (light cannot
/// cross the surface from there), else the shading normal where `w` is in front of it too,
/// else the geometric normal. The same rule at x_i and x_o keeps S reciprocal.
#[inline]
pub(crate) fn facing_normal(hit: &Hit, w: DVec3) -> Option<DVec3> {
    if w.dot(hit.ng) <= 0.0 {
        None
    } else if w.dot(hit.ns) > 0.0 {
        Some(hit.ns)
    } else {
        Some(hit.ng)
    }
}

/// The object's thickness at `hit` (length): the distance along the inward shading normal −n_s
/// to the object's surface on the far side, +∞ when the ray leaves without meeting it (an
/// open mesh) or meets it only beyond `reach` (where the caller no longer tells thicknesses
/// apart). One ray against the object's own BVH, over `[0, reach]`; none on an object that is
/// exactly its own bounding box (`box`, `half_space`), where it is the box's extent along the
/// normal. On the 40-mm marble sphere (`marble-sphere.toml`, whose diameter is nearly three
/// times the reach) the thickness rays' share of a `sone` render fell from 8.5 % to 3.2 %
/// (`perf`), the image bit-identical.
pub(crate) fn thickness(surface: &ObjectSurface<'_>, hit: &Hit, reach: f64) -> f64 {
    if let Some(extent) = surface.geometry.object_box_extent(surface.object) {
        // A box's shading normal is its face's axis (`TriangleMesh::box_extent`).
        return extent[hit.ns.abs().max_position()];
    }
    thickness_by_ray(surface, hit, reach)
}

/// [`thickness`] measured by its ray whatever the object's shape.
fn thickness_by_ray(surface: &ObjectSurface<'_>, hit: &Hit, reach: f64) -> f64 {
    let dir = -hit.ns;
    let ray = Ray::with_range(hit.spawn_origin(dir), dir, 0.0, reach);
    surface
        .geometry
        .intersect_object(surface.object, &ray)
        .map_or(f64::INFINITY, |h| (h.p - hit.p).length())
}

/// Largest |g| for which the slab profile is used. The slab table is isotropic and reaches
/// g ≠ 0 through similarity, which in a slab a few transport mean free paths thin turns
/// forward-scattered light into unscattered light the profile leaves out: measured on the
/// shapes of docs/shapes.md it improves every thin slab at g = 0.5 and makes the 2 mfp slab
/// worse at g = 0.8, where the half-space profile is kept.
pub const SLAB_MAX_G: f64 = 0.5;

/// How far (as a fraction of the thickness) a pair may depart from a slab's geometry and still
/// be weighed by the slab profile ([`slab_pair`]). Measured on the shapes of docs/shapes.md:
/// 0.25 made the sphere of radius 1 mfp overshoot at ϖ 0.99; 0.1 leaves every sphere, box
/// corner and bunny cell as close to the path tracer as the half-space profile or closer
/// (within 0.01).
pub const SLAB_TOLERANCE: f64 = 0.1;

/// Whether the pair (x_i, x_o) sits as on a slab of thickness `d` (finite), and if so on which
/// face and at which distance the slab profile weighs it. With Δ = x_i − x_o, the depths of
/// each point below the other's tangent plane, a = −Δ·n_o and b = Δ·n_i, are 0 for two
/// points on one face of a slab and d for points on opposite faces. The pair is
/// * a reflection pair when n_i · n_o ≥ 0 and |a|, |b| ≤ [`SLAB_TOLERANCE`]·d: R_slab(|Δ|);
/// * a transmission pair when n_i · n_o < 0 and |a − d|, |b − d| ≤ [`SLAB_TOLERANCE`]·d:
///   T_slab(ρ), ρ² = |Δ|² − a·b (the distance from the beam's axis; exactly the slab table's
///   on a slab, clamped at 0);
/// * otherwise `None`: the half-space profile at |Δ| (curved bodies, corners: where the
///   thickness along the normal does not describe the path between the points).
///
/// Symmetric under x_i ↔ x_o (a and b swap), so the BSSRDF stays reciprocal.
pub(crate) fn slab_pair(x_i: &Hit, x_o: &Hit, d: f64) -> Option<(SlabFace, f64)> {
    if !d.is_finite() {
        return None;
    }
    let delta = x_i.p - x_o.p;
    let (a, b) = (-delta.dot(x_o.ns), delta.dot(x_i.ns));
    let tol = SLAB_TOLERANCE * d;
    if x_i.ns.dot(x_o.ns) >= 0.0 {
        (a.abs() <= tol && b.abs() <= tol).then(|| (SlabFace::Reflection, delta.length()))
    } else {
        ((a - d).abs() <= tol && (b - d).abs() <= tol).then(|| {
            (
                SlabFace::Transmission,
                (delta.length_squared() - a * b).max(0.0).sqrt(),
            )
        })
    }
}

/// The oblique shape's forward shifts as an azimuthal guide for the normal probe
/// ([`BssrdfObject::shift_guide`]): factor 0 the incident side D(μ_i → μ_o), about the
/// direction toward the light; factor 1 the exit side D(μ_o → μ_i), about the direction of
/// travel of light arriving along −ω_o. Their amplitudes are the series of
/// [`SeparableBssrdf::shift_amplitudes`], so the guide leans the way S does.
pub(crate) struct ShiftGuide<'a> {
    /// The forward shift of the channel the guide follows ([`GUIDE_CHANNEL`]); `None`: no
    /// shift there, so no guide.
    series: Option<ShiftSeries<'a>>,
    directions: [DVec3; 2],
    /// (μ_i, μ_o): the incident side's cosine (the light's at x_o) and the exit side's.
    cosines: (f64, f64),
}

/// The colour channel whose forward shift guides the probes' azimuth for all three (green,
/// the largest weight of luminance): one guide per x_o, read once per point, whatever the
/// probe's channel (`het_estimate::probe`, "Guided azimuths"). The other channels' shifts
/// differ only through their albedo and σt', and the guide needs only to lean the right way.
pub(crate) const GUIDE_CHANNEL: usize = 1;

impl AzimuthGuide for ShiftGuide<'_> {
    fn directions(&self) -> [DVec3; 2] {
        self.directions
    }

    /// The table's radial node nearest σt' r in ln x.
    fn radial_node(&self, r: f64) -> usize {
        self.series.map_or(0, |s| s.nearest_node(r))
    }

    fn amplitudes(&self, node: usize) -> [[f64; 3]; 2] {
        let (mu_i, mu_o) = self.cosines;
        self.series
            .map_or([[0.0; 3]; 2], |s| s.amplitudes_at(node, mu_i, mu_o))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn hit(p: DVec3, n: DVec3) -> Hit {
        Hit {
            t: 1.0,
            p,
            ng: n,
            ns: n,
            uv: DVec2::ZERO,
            object: 0,
            prim: 0,
            bary: DVec2::ZERO,
            p_error: 0.0,
        }
    }

    #[test]
    fn slab_pairs_are_classified_as_on_a_slab_and_symmetrically() {
        let d = 2.0;
        let top = |x: f64| hit(DVec3::new(x, 0.0, 0.0), DVec3::Z);
        let bottom = |x: f64| hit(DVec3::new(x, 0.0, -d), DVec3::NEG_Z);
        // Same face: reflection at the distance; opposite faces: transmission at the lateral
        // distance from the axis.
        assert_eq!(
            slab_pair(&top(3.0), &top(0.0), d),
            Some((SlabFace::Reflection, 3.0))
        );
        let (face, rho) = slab_pair(&bottom(1.5), &top(0.0), d).unwrap();
        assert_eq!(face, SlabFace::Transmission);
        assert!((rho - 1.5).abs() < 1e-12);
        // Symmetric in the pair.
        for (a, b) in [(bottom(1.5), top(0.0)), (top(0.7), top(-2.0))] {
            assert_eq!(slab_pair(&a, &b, d), slab_pair(&b, &a, d));
        }
        // On a sphere of radius 1 (thickness 2 along every normal) the back hemisphere away
        // from the antipode and far points of the front one are not slab pairs.
        let on_sphere = |th: f64| {
            let n = DVec3::new(th.sin(), 0.0, th.cos());
            hit(n, n)
        };
        let north = on_sphere(0.0);
        assert!(slab_pair(&on_sphere(2.0), &north, 2.0).is_none()); // 115°
        assert!(slab_pair(&on_sphere(1.2), &north, 2.0).is_none()); // 69°
        assert!(slab_pair(&on_sphere(3.1), &north, 2.0).is_some()); // near the antipode
        assert!(slab_pair(&on_sphere(0.3), &north, 2.0).is_some()); // near x_o
        // An open mesh (no far side) keeps the half-space profile.
        assert!(slab_pair(&top(1.0), &top(0.0), f64::INFINITY).is_none());
    }

    /// On a box the thickness without a ray is the one its ray measures, at points all over
    /// every face; a sphere has no box extent and keeps the ray.
    #[test]
    fn a_box_thickness_is_its_rays() {
        use crate::geometry::{Geometry, Ray, primitives};
        let (lo, hi) = (DVec3::new(-1.5, 0.25, -3.0), DVec3::new(2.0, 1.25, -0.5));
        let geometry = Geometry::build(vec![
            primitives::subdivided_cuboid(lo, hi, [3, 2, 4]),
            primitives::icosphere(DVec3::new(10.0, 0.0, 0.0), 1.0, 3),
        ]);
        assert!(geometry.object_box_extent(0).is_some());
        assert!(geometry.object_box_extent(1).is_none());
        let surface = ObjectSurface::new(&geometry, 0);
        let centre = 0.5 * (lo + hi);
        let mut checked = 0;
        for k in 0..500 {
            // Rays from a sphere around the box toward random points inside it.
            let t = k as f64;
            let dir_out = DVec3::new((1.7 * t).sin(), (2.3 * t).cos(), (0.9 * t).sin()).normalize();
            let target = centre
                + (hi - lo) * 0.45 * DVec3::new((0.3 * t).sin(), (0.7 * t).cos(), (1.1 * t).sin());
            let origin = centre + 20.0 * dir_out;
            let Some(h) = geometry.intersect(&Ray::new(origin, (target - origin).normalize()))
            else {
                continue;
            };
            assert_eq!(h.object, 0);
            let (fast, ray) = (
                thickness(&surface, &h, f64::INFINITY),
                thickness_by_ray(&surface, &h, f64::INFINITY),
            );
            assert!(
                (fast - ray).abs() <= 1e-9 * fast,
                "at {:?}: {fast} against {ray}",
                h.p
            );
            checked += 1;
        }
        assert!(checked > 400, "{checked}");
        let sphere = ObjectSurface::new(&geometry, 1);
        let h = geometry
            .intersect(&Ray::new(DVec3::new(10.0, 0.0, 5.0), DVec3::NEG_Z))
            .unwrap();
        let inf = f64::INFINITY;
        assert!((thickness(&sphere, &h, inf) - thickness_by_ray(&sphere, &h, inf)).abs() == 0.0);
        // The ray looks as far as `reach`: the diameter within it, +∞ beyond it.
        let full = thickness(&sphere, &h, inf);
        assert!((full - 2.0).abs() < 0.01, "{full}");
        assert_eq!(thickness(&sphere, &h, 1.01 * full), full);
        assert_eq!(thickness(&sphere, &h, 0.99 * full), inf);
    }

    /// The thickness rays' reach: a pair whose far side lies beyond it is weighed exactly as
    /// with an unbounded ray, by the half-space profile. A marble-like material on a sphere of
    /// 40 (in units where σs ≈ 2), far thicker than the half-space thickness (about 15), and
    /// on one of 4 (a slab pair's thickness, well within it).
    #[test]
    fn the_thickness_rays_reach_changes_no_weight() {
        use crate::geometry::{Geometry, primitives};
        let coeffs =
            het_estimate::Coefficients::new(Rgb([0.042, 0.082, 0.142]), Rgb([2.19, 2.62, 3.0]));
        let medium = MediumField::homogeneous(coeffs).expect("a medium");
        let material = Translucent::new("marble", medium, 0.0, 1.3);
        let make = || {
            BssrdfObject::new(
                &material,
                Some(ProfileModel::Tabulated),
                Scattering::All,
                Estimator::JensenOut,
                80.0,
            )
            .expect("a BSSRDF")
        };
        let object = make();
        assert!(object.thickness_aware);
        let reach = object.far_side_reach;
        assert!(reach.is_finite() && reach > 10.0 && reach < 80.0, "{reach}");
        // The same material weighing with rays that look all the way (the weights before the
        // reach existed).
        let mut unbounded_object = make();
        unbounded_object.far_side_reach = f64::INFINITY;
        for radius in [40.0, 4.0] {
            let geometry = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, radius, 5)]);
            let surface = ObjectSurface::new(&geometry, 0);
            let at = |theta: f64| {
                let d = DVec3::new(theta.sin(), 0.0, theta.cos());
                geometry
                    .intersect(&Ray::new(3.0 * radius * d, -d))
                    .expect("a hit")
            };
            let x_o = at(0.0);
            let mut counters = PathCounters::default();
            for theta in [0.02, 0.1, 0.4, 1.0, 2.0, 3.0] {
                let x_i = at(theta);
                let bounded = object.weigh(&surface, coeffs, &x_i, &x_o, &mut counters);
                let unbounded = unbounded_object.weigh(&surface, coeffs, &x_i, &x_o, &mut counters);
                // Where the unbounded weight is a transmission (0 beyond the half-space
                // thickness), the bounded one is the half-space profile at the chord, which
                // is at least as long: below a millionth of the profile near x_o.
                if unbounded.1 || radius < 10.0 {
                    assert_eq!(bounded, unbounded, "radius {radius}, θ {theta}");
                } else {
                    let near = object
                        .weigh(&surface, coeffs, &at(0.02), &x_o, &mut counters)
                        .0;
                    assert!(
                        (0..3).all(|c| bounded.0[c] < 1e-6 * near[c]),
                        "{:?} against {near:?}",
                        bounded.0
                    );
                }
            }
        }
    }

    /// The oblique shape's probe guide leans the way S does: over 64 azimuths of x_i at a
    /// fixed distance from x_o, the guided azimuth density (`het_estimate::azimuth`) rises
    /// and falls with S, for light at 60° with the view along the normal (the incident side's
    /// factor), the view at 60° with light along the normal (the exit side's) and both
    /// (correlation above 0.9; a guide about the opposite directions correlates below 0.1:
    /// measured −0.72 to 0.005).
    /// Without the shape there is no guide, and `toward_light` is not called.
    #[test]
    fn shift_guide_leans_the_way_s_does() {
        use het_estimate::azimuth::GuidedAzimuths;
        let c = het_estimate::Coefficients::grey(0.01, 1.0);
        let medium = MediumField::homogeneous(c).expect("a medium");
        let make = |shape: bool| {
            let material = Translucent {
                oblique_shape: shape,
                ..Translucent::new("m", medium.clone(), 0.0, 1.0)
            };
            BssrdfObject::new(
                &material,
                Some(ProfileModel::Tabulated),
                Scattering::Multiple,
                Estimator::JensenOut,
                400.0,
            )
            .expect("a BSSRDF")
        };
        let plain = make(false);
        assert!(
            plain
                .shift_guide(c, DVec3::Z, DVec3::Z, || panic!("called without the shape"))
                .is_none()
        );
        let b = make(true);
        let at60 = |x: f64| DVec3::new(x * 60f64.to_radians().sin(), 0.0, 60f64.to_radians().cos());
        let correlation = |a: &[f64], b: &[f64]| {
            let n = a.len() as f64;
            let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
            let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
            let va: f64 = a.iter().map(|x| (x - ma) * (x - ma)).sum();
            let vb: f64 = b.iter().map(|y| (y - mb) * (y - mb)).sum();
            cov / (va * vb).sqrt()
        };
        for (light, view) in [
            (at60(1.0), DVec3::Z),
            (DVec3::Z, at60(-1.0)),
            (at60(1.0), at60(0.5)),
        ] {
            let (light, view) = (light.normalize(), view.normalize());
            let guide = b
                .shift_guide(c, view, DVec3::Z, || Some(light))
                .expect("a guide with the shape");
            // The same guide about the opposite directions.
            struct Flipped<'a>(&'a ShiftGuide<'a>);
            impl AzimuthGuide for Flipped<'_> {
                fn directions(&self) -> [DVec3; 2] {
                    self.0.directions().map(|d| -d)
                }
                fn radial_node(&self, r: f64) -> usize {
                    self.0.radial_node(r)
                }
                fn amplitudes(&self, node: usize) -> [[f64; 3]; 2] {
                    self.0.amplitudes(node)
                }
            }
            let at_o = hit(DVec3::ZERO, DVec3::Z);
            let flipped = Flipped(&guide);
            let guided = GuidedAzimuths::new(&guide, &at_o).expect("directions");
            let opposite = GuidedAzimuths::new(&flipped, &at_o).expect("directions");
            for r in [1.0, 4.0] {
                let phis: Vec<f64> = (0..64)
                    .map(|k| (k as f64 + 0.5) * std::f64::consts::TAU / 64.0)
                    .collect();
                let x_o = Crossing::new(DVec3::ZERO, DVec3::Z, view);
                let s: Vec<f64> = phis
                    .iter()
                    .map(|&phi| {
                        let x_i = DVec3::new(r * phi.cos(), r * phi.sin(), 0.0);
                        b.bssrdf
                            .coupling_between(&c, &Crossing::new(x_i, DVec3::Z, light), &x_o)
                            .0[GUIDE_CHANNEL]
                    })
                    .collect();
                // φ in the probes' frame at x_o (`orthonormal_basis(+z)`), from its world
                // angle: both guides are read at the same points.
                let (fs, ft) = het_estimate::frame::orthonormal_basis(DVec3::Z);
                let local = |phi: f64| {
                    let d = DVec3::new(phi.cos(), phi.sin(), 0.0);
                    d.dot(ft).atan2(d.dot(fs))
                };
                let p: Vec<f64> = phis.iter().map(|&phi| guided.pdf(r, local(phi))).collect();
                let q: Vec<f64> = phis
                    .iter()
                    .map(|&phi| opposite.pdf(r, local(phi)))
                    .collect();
                let (cp, cq) = (correlation(&p, &s), correlation(&q, &s));
                assert!(
                    cp > 0.9 && cq < 0.1,
                    "light {light}, view {view}, r {r}: {cp} {cq}"
                );
            }
        }
    }
}
