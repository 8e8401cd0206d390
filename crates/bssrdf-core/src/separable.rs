//! The separable BSSRDF S(x_i, ω_i; x_o, ω_o) of a homogeneous half-space: what a renderer
//! multiplies the light arriving at x_i by to get the radiance leaving x_o. The tracer's
//! BSSRDF renderers evaluate exactly this ([`SeparableBssrdf::combine`] and the factors it is
//! made of), so an outside renderer that calls it renders what `het-bssrdf` validates.
//!
//! # The formula
//! The separable form of pbrt-v3 §11.4.1 with pbrt-v4's normalised Fresnel lobe
//! (`NormalizedFresnelBxDF`, pbrt-v4 §11.4):
//!
//! ```text
//! S = R(|x_i − x_o|; σa, σs) · (1 − F_r(cos θ_i)) · (1 − F_r(cos θ_o)) / (c π) · T(α', cos θ_i, cos θ_o)
//! c = 1 − 2 C₁(1/η)
//! ```
//!
//! * R (1/length², per channel) is the family's radial profile ([`crate::RadialProfile::eval`]):
//!   the exitance per unit power entering at normal incidence, with the orders the family's
//!   [`Scattering`] selects (single scattering, multiple scattering or both: for the
//!   diffusion models, the model's multiple-scattering term plus the
//!   [`crate::single_scattering`] term; for the tabulated profile both come from its table).
//! * F_r is the dielectric Fresnel reflectance at the relative index η
//!   ([`crate::fresnel::dielectric`]); θ_i, θ_o the angles of ω_i, ω_o to the normals.
//! * c normalises the entry lobe `S_w(ω) = (1 − F_r(cos θ))/(c π)` so that light entering
//!   from a uniform hemisphere is carried in full: ∫ S_w cos θ dω = 1. **Dividing by π alone
//!   (JMLH01's `F_t R F_t / π`) makes S darker by the factor c**: c = 0.939 at η = 1.3 and
//!   0.908 at η = 1.5, so the path-traced reference is 6.5 % and 10 % brighter than that.
//! * T is the tabulated profile's angular coupling ([`crate::tabulated::angular`]), read at
//!   the pair's reduced albedo α' = σs'/σt' per channel; 1 for the other models, or when
//!   turned off ([`SeparableBssrdf::with_angular_coupling`]).
//! * M is the coupling's radial part, the oblique shape ([`crate::tabulated::oblique`]): how
//!   the radial shape of the response changes with the two cosines (light entering obliquely
//!   leaves closer to where it entered), at r = |x_i − x_o| in the pair's reduced mean free
//!   paths; it integrates to 1 against R for every pair, so T keeps the totals. 1 wherever T
//!   is, or when turned off ([`SeparableBssrdf::with_oblique_shape`]).
//!
//! Units: S is in 1/(length²·sr). Directions ω_i (toward the light) and ω_o (toward the
//! viewer) point *out of* the medium, as do the normals.
//!
//! Reciprocity: S is symmetric under (x_i, ω_i) ↔ (x_o, ω_o) bit for bit: the two Fresnel
//! factors are multiplied before they meet R, and T and M order their cosines.
//!
//! ```
//! use bssrdf_core::glam::DVec3;
//! use bssrdf_core::{Coefficients, Crossing, ProfileModel, Rgb, Scattering, SeparableBssrdf};
//!
//! fn main() -> Result<(), bssrdf_core::ParamError> {
//!     // Once per material: model, scattering orders, g, η.
//!     let bssrdf = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.3)?;
//!     // Per pair: the homogeneous coefficients (from an estimator, or the material's own).
//!     let c = Coefficients::new(Rgb::new(0.01, 0.02, 0.05), Rgb::splat(1.0));
//!     let up = DVec3::Z;
//!     let x_i = Crossing::new(DVec3::new(0.5, 0.0, 0.0), up, DVec3::new(0.6, 0.0, 0.8));
//!     let x_o = Crossing::new(DVec3::ZERO, up, up);
//!     let s: Rgb = bssrdf.eval(&c, &x_i, &x_o)?; // 1/(length²·sr)
//!     assert!(s.min_component() > 0.0);
//!     // Reciprocal bit for bit.
//!     assert_eq!(s, bssrdf.eval(&c, &x_o, &x_i)?);
//!     Ok(())
//! }
//! ```

use std::f64::consts::PI;

use glam::DVec3;

use crate::coefficients::Coefficients;
use crate::error::ParamError;
use crate::family::{FamilyOptions, ProfileFamily};
use crate::fresnel::{dielectric, fresnel_moment};
use crate::model::{ProfileModel, Scattering};
use crate::rgb::Rgb;
use crate::tabulated::half_space::AlbedoRow;
use crate::tabulated::{AngularCoupling, ObliqueShape};

/// Where light crosses the boundary: the surface point, the normal there (unit, out of the
/// medium) and the direction of the light outside (unit, pointing away from the surface:
/// toward the light at x_i, toward the viewer at x_o).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The surface point (scene units).
    pub point: DVec3,
    /// The unit normal, pointing out of the medium.
    pub normal: DVec3,
    /// The unit direction outside, pointing away from the surface.
    pub direction: DVec3,
}

impl Crossing {
    /// A crossing at `point` with unit `normal` and unit `direction` (see the fields).
    pub const fn new(point: DVec3, normal: DVec3, direction: DVec3) -> Self {
        Self {
            point,
            normal,
            direction,
        }
    }

    /// The cosine of the direction to the normal (not clamped).
    #[inline]
    pub fn cos(&self) -> f64 {
        self.direction.dot(self.normal)
    }

    fn check(&self, name: &'static str) -> Result<(), ParamError> {
        for v in [self.point, self.normal, self.direction] {
            if let Some(&value) = v.to_array().iter().find(|x| !x.is_finite()) {
                return Err(ParamError::NotFinite { name, value });
            }
        }
        Ok(())
    }
}

/// One channel's forward shift ([`SeparableBssrdf::shift_series`]) at the oblique shape's
/// radial nodes: [`SeparableBssrdf::shift_amplitudes`] is linear in the radius's weight
/// between the two nodes [`ShiftSeries::node`] names, and [`ShiftSeries::amplitudes_at`]
/// gives each node's amplitudes, so a caller can read each node once and interpolate itself.
#[derive(Debug, Clone, Copy)]
pub struct ShiftSeries<'a> {
    shape: &'a ObliqueShape,
    /// The channel's reduced albedo α' (unitless).
    alpha: f64,
    /// The channel's reduced extinction σt' (1/length).
    sigma_tp: f64,
}

impl ShiftSeries<'_> {
    /// The radial nodes around distance `r` (length): the lower node k and the weight
    /// w ∈ [0, 1] of node k + 1 ([`ObliqueShape::radial_node`] at σt' r); k + 1 <
    /// [`crate::tabulated::oblique_file::N_RADII`]. NaN gives (0, 0).
    pub fn node(&self, r: f64) -> (usize, f64) {
        ObliqueShape::radial_node(self.sigma_tp * r)
    }

    /// The radial node nearest distance `r` (length) in ln r ([`ObliqueShape::nearest_node`]
    /// at σt' r: [`Self::node`]'s k where its weight is below ½, else k + 1), without the
    /// logarithm [`Self::node`] takes.
    pub fn nearest_node(&self, r: f64) -> usize {
        ObliqueShape::nearest_node(self.sigma_tp * r)
    }

    /// Both sides' amplitudes a_n = C_n · sinⁿθ_side (n = 1, 2, 3; unitless, finite) at
    /// radial node `node`, as [`SeparableBssrdf::shift_amplitudes`] at that node's radius:
    /// `[incident side, exit side]` of light entering at cosine `cos_i` and leaving at
    /// `cos_o`. 0 for non-finite cosines.
    pub fn amplitudes_at(&self, node: usize, cos_i: f64, cos_o: f64) -> [[f64; 3]; 2] {
        let k = self.shape.shifts_at_node(self.alpha, node, cos_i, cos_o);
        [side_amplitudes(cos_i, k[0]), side_amplitudes(cos_o, k[1])]
    }
}

/// One side's amplitudes a_n = C_n · sinⁿθ (n = 1, 2, 3) from its shift coefficients `c` and
/// cosine `side_cos`; 0 where any is not finite.
fn side_amplitudes(side_cos: f64, c: [f64; 3]) -> [f64; 3] {
    let a = amplitudes(&c, 1.0 - side_cos * side_cos);
    if a.iter().all(|v| v.is_finite()) {
        a
    } else {
        [0.0; 3]
    }
}

/// The amplitudes C_n sinⁿθ of cos nφ (n = 1, 2, 3) from the coefficients `c` and q = sin²θ
/// (a negative q is 0).
#[inline]
fn amplitudes(c: &[f64; 3], q: f64) -> [f64; 3] {
    let q = q.max(0.0);
    let s = q.sqrt();
    [c[0] * s, c[1] * q, c[2] * q * s]
}

/// Whether the series 1 + Σ_n a_n cos nφ cannot go negative (Σ |a_n| ≤ 1), so needs no clamp.
#[inline]
fn cannot_go_negative(a: &[f64; 3]) -> bool {
    a.iter().map(|v| v.abs()).sum::<f64>() <= 1.0
}

/// 1 + Σ_n a_n x_n, unclamped: a series at the harmonics `x` (cos nφ, or sinⁿθ cos nφ with
/// the bare coefficients).
#[inline]
fn series(a: &[f64; 3], x: &[f64; 3]) -> f64 {
    1.0 + a[0] * x[0] + a[1] * x[1] + a[2] * x[2]
}

/// A prepared separable BSSRDF (see the module docs): the profile family, the Fresnel
/// normalisation c and, for the tabulated profile, its angular coupling. Build once per
/// material (the coupling costs about a millisecond); evaluation allocates nothing.
/// `Send + Sync`; a clone copies its tables (about 10 KB with the coupling, 470 KB with the
/// oblique shape).
#[derive(Debug, Clone, PartialEq)]
pub struct SeparableBssrdf {
    family: ProfileFamily,
    /// c = 1 − 2 C₁(1/η).
    norm: f64,
    coupling: Option<AngularCoupling>,
    /// The coupling's radial part M (with the coupling: `crate::tabulated::oblique`).
    oblique: Option<ObliqueShape>,
}

impl SeparableBssrdf {
    /// The BSSRDF of `model` counting the orders `scattering` selects, for the
    /// Henyey–Greenstein mean cosine `g ∈ (−1, 1)` and the relative index `eta ∈ [1, 3]`
    /// (η ≤ 1.6 for the tabulated model); the angular coupling is on for the tabulated
    /// model. Errors name the invalid parameter.
    pub fn new(
        model: ProfileModel,
        scattering: Scattering,
        g: f64,
        eta: f64,
    ) -> Result<Self, ParamError> {
        Ok(Self::from_family(ProfileFamily::with_options(
            model,
            scattering,
            g,
            eta,
            FamilyOptions::default(),
        )?))
    }

    /// The BSSRDF of a prepared family (its model, scattering orders, g and η); the angular
    /// coupling is on when the family's model is [`ProfileModel::Tabulated`].
    pub fn from_family(family: ProfileFamily) -> Self {
        Self::from_family_with(family, true, true)
    }

    /// The BSSRDF of a prepared family with the tabulated profile's angular coupling
    /// (`coupling`) and its oblique shape (`oblique`, only with the coupling) each on or off;
    /// the other models have neither. Builds only the tables it keeps (the oblique shape costs
    /// milliseconds and about 230 KB per material), which a renderer that turns them off by
    /// default wants rather than [`Self::from_family`] followed by `with_*(false)`.
    pub fn from_family_with(family: ProfileFamily, coupling: bool, oblique: bool) -> Self {
        let coupling = coupling && family.model() == ProfileModel::Tabulated;
        let oblique = oblique && coupling;
        let coupling = coupling.then(|| AngularCoupling::new(family.eta(), family.scattering()));
        let oblique = oblique.then(|| ObliqueShape::new(family.eta(), family.scattering()));
        Self {
            norm: 1.0 - 2.0 * fresnel_moment(1, 1.0 / family.eta()),
            family,
            coupling,
            oblique,
        }
    }

    /// The same BSSRDF with the tabulated profile's angular coupling on (`true`, the default
    /// for the tabulated model) or off (T = 1). The other models have no coupling: `true`
    /// leaves them without one.
    pub fn with_angular_coupling(mut self, on: bool) -> Self {
        if on == self.coupling.is_some() {
            return self;
        }
        let tabulated = on && self.family.model() == ProfileModel::Tabulated;
        self.coupling =
            tabulated.then(|| AngularCoupling::new(self.family.eta(), self.family.scattering()));
        self.oblique =
            tabulated.then(|| ObliqueShape::new(self.family.eta(), self.family.scattering()));
        self
    }

    /// The same BSSRDF with the coupling's radial part M (the oblique shape,
    /// [`crate::tabulated::oblique`]) on (the default wherever the coupling is) or off (the
    /// coupling T alone, the normal-incidence radial shape for every pair of directions).
    /// Without the coupling, `true` leaves S without it.
    pub fn with_oblique_shape(mut self, on: bool) -> Self {
        if on == self.oblique.is_some() {
            return self;
        }
        self.oblique = (on && self.coupling.is_some())
            .then(|| ObliqueShape::new(self.family.eta(), self.family.scattering()));
        self
    }

    /// The profile family R is evaluated from.
    pub fn family(&self) -> &ProfileFamily {
        &self.family
    }
    /// Relative index of refraction η.
    pub fn eta(&self) -> f64 {
        self.family.eta()
    }
    /// The normalisation c = 1 − 2 C₁(1/η) of the entry lobe (1 at η = 1).
    pub fn normalisation(&self) -> f64 {
        self.norm
    }
    /// True when S includes the angular coupling T.
    pub fn has_angular_coupling(&self) -> bool {
        self.coupling.is_some()
    }
    /// True when S includes the coupling's radial part M ([`Self::with_oblique_shape`]).
    pub fn has_oblique_shape(&self) -> bool {
        self.oblique.is_some()
    }

    /// 1 − F_r(cos θ): the fraction of light crossing the boundary at cosine `cos` to the
    /// normal (unitless, in [0, 1]; 1 at η = 1; `cos` clamped to [0, 1]).
    #[inline]
    pub fn transmission(&self, cos: f64) -> f64 {
        1.0 - dielectric(cos, self.family.eta())
    }

    /// The entry lobe S_w(cos θ) = (1 − F_r(cos θ))/(c π) (1/sr): the angular part of S at
    /// one end of the pair, ∫ S_w cos θ dω = 1 over the hemisphere.
    #[inline]
    pub fn entry_lobe(&self, cos: f64) -> f64 {
        self.transmission(cos) / (self.norm * PI)
    }

    /// The angular part of S without the coupling, (1 − F_r(cos_i))(1 − F_r(cos_o))/(c π)
    /// (1/sr): the product of the two transmissions is formed first, so it is symmetric in
    /// the two cosines bit for bit.
    #[inline]
    pub fn fresnel_factor(&self, cos_i: f64, cos_o: f64) -> f64 {
        Self::boundary_factor(
            self.transmission(cos_i),
            self.transmission(cos_o),
            self.norm,
        )
    }

    /// The angular part of S through any boundary: `transmission_i · transmission_o / (norm π)`
    /// (1/sr), the fractions of light the boundary lets through at the two ends (unitless) over
    /// its normalisation (the smooth boundary's are 1 − F_r and c,
    /// [`Self::fresnel_factor`]; a rough one's are its directional transmittances). The product
    /// of the transmissions is formed first, so it is symmetric in the two ends bit for bit.
    #[inline]
    pub fn boundary_factor(transmission_i: f64, transmission_o: f64, norm: f64) -> f64 {
        let fresnel = transmission_i * transmission_o;
        fresnel / (norm * PI)
    }

    /// R(r) per channel (1/length²) at the coefficients `c`: the family's profile, each
    /// channel validated as [`ProfileFamily::profile`] does (`[0, 1e12]`).
    #[inline]
    pub fn profile(&self, c: &Coefficients, r: f64) -> Result<Rgb, ParamError> {
        Ok(self.family.profile_rgb(c.sigma_a, c.sigma_s)?.eval_rgb(r))
    }

    /// The angular coupling T(α', cos_i, cos_o) per channel at the reduced albedos of `c`
    /// (1 without a coupling, and for a channel that does not scatter or whose coefficients
    /// are invalid). Symmetric in the two cosines bit for bit.
    #[inline]
    pub fn coupling(&self, c: &Coefficients, cos_i: f64, cos_o: f64) -> Rgb {
        let Some(t) = self.coupling.as_ref() else {
            return Rgb::ONE;
        };
        // The reduced albedo per channel, as the tabulated profile reads its rows; a channel
        // that does not scatter (its profile is 0) gets NaN, hence T = 1.
        let alpha = std::array::from_fn(|ch| {
            self.family
                .reduced_albedo(c.sigma_a[ch], c.sigma_s[ch])
                .ok()
                .flatten()
                .unwrap_or(f64::NAN)
        });
        Rgb(t.factors(alpha, cos_i, cos_o))
    }

    /// The coupling of the pair `incident` → `exitant` at the coefficients `c`: T(α',
    /// cos_i, cos_o) ([`Self::coupling`]) times, with the oblique shape
    /// ([`Self::with_oblique_shape`], [`crate::tabulated::oblique`]), its radial part
    /// M(σt' r; α', cos_i, cos_o) and the forward shift, a product of one factor per side,
    ///
    /// max(0, 1 + Σ_n C_n(σt' r; α', μ_i → μ_o) sinⁿθ_i cos nφ_i)
    ///   · max(0, 1 + Σ_n C_n(σt' r; α', μ_o → μ_i) sinⁿθ_o cos nφ_o) / N,   n = 1, 2, 3,
    ///
    /// (N the mean of the product over the chord's azimuth, so that the totals stay T's:
    /// `sides_factor`), r = |x_o − x_i|, φ_i the angle between x_o − x_i and
    /// t_i = −(ω_i − (ω_i·n_i) n_i), the incident light's direction of travel along the
    /// surface (|t_i| = sin θ_i), and φ_o the
    /// angle between x_i − x_o and t_o, the same for light arriving along −ω_o at x_o (α' and
    /// σt' the reduced albedo and extinction per channel, at which the tabulated profile reads
    /// its shape; C_n from [`ObliqueShape::shift`]). 1 without a coupling. Symmetric under
    /// `incident` ↔ `exitant` bit for bit (the two sides' factors swap, their product
    /// commutes, and N is symmetric in them).
    pub fn coupling_between(
        &self,
        c: &Coefficients,
        incident: &Crossing,
        exitant: &Crossing,
    ) -> Rgb {
        let (cos_i, cos_o) = (incident.cos(), exitant.cos());
        let (Some(t), Some(m)) = (self.coupling.as_ref(), self.oblique.as_ref()) else {
            return self.coupling(c, cos_i, cos_o);
        };
        let chord = exitant.point - incident.point;
        let r = chord.length();
        // The reduced albedo and optical radius per channel, read once for every factor (a
        // channel that does not scatter, or whose coefficients are invalid, gets NaN: 1).
        let mut alpha = [f64::NAN; 3];
        let mut x = [f64::NAN; 3];
        for ch in 0..3 {
            if let Ok(reduced) = self.family.reduced_of(c.sigma_a[ch], c.sigma_s[ch]) {
                alpha[ch] = reduced.albedo.unwrap_or(f64::NAN);
                x[ch] = reduced.sigma_tp * r;
            }
        }
        // Each albedo's place on the tables' grids, found once for T and M.
        let rows = AlbedoRow::of_each(alpha);
        let tt = t.factors_on(rows, cos_i, cos_o);
        let pf = m.pair_on(rows, x, cos_i, cos_o);
        // Each side's harmonics sinⁿθ cos nφ, φ the angle between the chord (from that side)
        // and its light's direction of travel along the surface t (|t| = sin θ), both in that
        // side's tangent plane: with x̂ the chord's projection on it, normalised, u = x̂·t and
        // q = |t|², u, 2u² − q and (4u² − 3q)u (Chebyshev). On a plane x̂ is the chord's own
        // direction; on a curved pair, dividing by the chord's full length instead shrank u,
        // which moves the series' mean off 1 (by −C₂ q (1 − c²), c the projection's share of
        // the chord) and made spheres a mean free path across 8–14 % darker. Each side is
        // written from its own end of the chord, so that the swap exchanges them exactly.
        let harmonics = |side: &Crossing, toward: DVec3| -> [f64; 3] {
            let travel = side.normal * side.cos() - side.direction;
            let along = (toward - side.normal * toward.dot(side.normal)).length();
            let (u, q) = (toward.dot(travel) / along, travel.length_squared());
            if !(u.is_finite() && q.is_finite()) {
                return [0.0; 3];
            }
            [u, 2.0 * u * u - q, (4.0 * u * u - 3.0 * q) * u]
        };
        let (h_i, h_o) = (harmonics(incident, chord), harmonics(exitant, -chord));
        let (t_i, t_o) = (
            incident.normal * cos_i - incident.direction,
            exitant.normal * cos_o - exitant.direction,
        );
        let (q_i, q_o) = (t_i.length_squared(), t_o.length_squared());
        let w = t_i.dot(t_o);
        let w = if w.is_finite() { w } else { 0.0 };
        // The product of the two sides' factors, formed before it meets T and M; a channel
        // whose shift coefficients equal the previous one's reuses its product.
        let mut sides = [0.0; 3];
        for ch in 0..3 {
            let p = &pf[ch];
            sides[ch] =
                if ch > 0 && p.incident == pf[ch - 1].incident && p.exitant == pf[ch - 1].exitant {
                    sides[ch - 1]
                } else {
                    sides_factor(&p.incident, &h_i, q_i, &p.exitant, &h_o, q_o, w)
                };
        }
        Rgb(std::array::from_fn(|ch| tt[ch] * pf[ch].m * sides[ch]))
    }

    /// One side's forward-shift amplitudes a_n = C_n(σt' r; α', μ_side → μ_other) · sinⁿθ_side
    /// (n = 1, 2, 3; unitless) for channel `channel` of `c` at distance `r` (length; σt' and
    /// α' the channel's reduced extinction and albedo): the coefficients of cos nφ in that
    /// side's factor max(0, 1 + Σ_n a_n cos nφ) of [`Self::coupling_between`], φ measured
    /// at the side's own end of the chord from its light's direction of travel along the
    /// surface (docs/oblique-incidence.md; C_n from [`ObliqueShape::shift`]). The exit side of
    /// a pair is `shift_amplitudes(c, ch, r, cos_o, cos_i)`, the incident side
    /// `shift_amplitudes(c, ch, r, cos_i, cos_o)`. What a probe sampler that draws azimuths
    /// from the shift needs (`het_estimate::azimuth`). 0 without the oblique shape, for a
    /// channel that does not scatter or has invalid coefficients, and for non-finite input.
    pub fn shift_amplitudes(
        &self,
        c: &Coefficients,
        channel: usize,
        r: f64,
        side_cos: f64,
        other_cos: f64,
    ) -> [f64; 3] {
        let Some(m) = self.oblique.as_ref() else {
            return [0.0; 3];
        };
        let ch = channel.min(2);
        let Ok(reduced) = self.family.reduced_of(c.sigma_a[ch], c.sigma_s[ch]) else {
            return [0.0; 3];
        };
        let Some(alpha) = reduced.albedo else {
            return [0.0; 3];
        };
        side_amplitudes(
            side_cos,
            m.shift(alpha, reduced.sigma_tp * r, side_cos, other_cos),
        )
    }

    /// The forward shift of channel `channel` of `c` read node by node
    /// ([`ShiftSeries`]): what a probe sampler that draws azimuths from the shift caches
    /// around one x_o. `None` without the oblique shape, for a channel that does not scatter
    /// and for invalid coefficients.
    pub fn shift_series(&self, c: &Coefficients, channel: usize) -> Option<ShiftSeries<'_>> {
        let shape = self.oblique.as_ref()?;
        let ch = channel.min(2);
        let reduced = self.family.reduced_of(c.sigma_a[ch], c.sigma_s[ch]).ok()?;
        let alpha = reduced.albedo?;
        (alpha.is_finite() && reduced.sigma_tp.is_finite()).then_some(ShiftSeries {
            shape,
            alpha,
            sigma_tp: reduced.sigma_tp,
        })
    }

    /// S from its parts: the profile value `rd` (1/length², per channel; R(r), or another
    /// profile a renderer weighs the pair by), the coupling `t` (per channel;
    /// [`SeparableBssrdf::coupling`], or 1) and the two cosines:
    /// `rd · (1 − F_r(cos_i))(1 − F_r(cos_o))/(c π) · t`. [`SeparableBssrdf::eval`] is this
    /// with R and T of the pair; the tracer calls it with its own profile choice (slab
    /// profiles on thin parts).
    #[inline]
    pub fn combine(&self, rd: Rgb, t: Rgb, cos_i: f64, cos_o: f64) -> Rgb {
        rd * self.fresnel_factor(cos_i, cos_o) * t
    }

    /// S(x_i, ω_i; x_o, ω_o) (1/(length²·sr), per channel) at the homogeneous coefficients
    /// `c` (1/length), light entering at `incident` and leaving at `exitant`: 0 when either
    /// direction is not in front of its normal (light cannot cross there). Errors: a
    /// coefficient outside `[0, 1e12]`, or a non-finite point, normal or direction.
    pub fn eval(
        &self,
        c: &Coefficients,
        incident: &Crossing,
        exitant: &Crossing,
    ) -> Result<Rgb, ParamError> {
        incident.check("incident")?;
        exitant.check("exitant")?;
        let (cos_i, cos_o) = (incident.cos(), exitant.cos());
        let rd = self.profile(c, (incident.point - exitant.point).length())?;
        if cos_i <= 0.0 || cos_o <= 0.0 {
            return Ok(Rgb::ZERO);
        }
        Ok(self.combine(
            rd,
            self.coupling_between(c, incident, exitant),
            cos_i,
            cos_o,
        ))
    }
}

/// The two sides' forward-shift factors together,
/// max(0, 1 + Σ_n a_n cos nφ_i) · max(0, 1 + Σ_n b_n cos nφ_o) / N, with a_n = C_n sinⁿθ_i
/// of the incident side and b_n = C'_n sinⁿθ_o of the exit side (`c_*` the coefficients
/// C_n, `h_*` the harmonics sinⁿθ cos nφ of that side, `q_*` = sin²θ), and `w` = t_i · t_o,
/// the dot product of the two lights' directions of travel along the surface (|t| = sin θ).
///
/// N is the mean of the product over the chord's azimuth φ, so that the product averages to
/// 1 at every distance and the totals stay T's. Both azimuths turn with the chord: on a plane,
/// with β the angle between t_i and t_o, φ_o = φ_i + π − β, so for series that cannot go
/// negative N = 1 + ½ Σ_n (−1)ⁿ a_n b_n cos nβ, where sinⁿθ_i sinⁿθ_o cos nβ is w, 2w² − s and
/// (4w² − 3s)w (s = sin²θ_i sin²θ_o). Where a series would go negative it is clamped at 0 and
/// N is the mean of the clamped product over 48 midpoints (`clamped_product_mean`).
///
/// Normalising each side on its own (the first version) left the product's cross term,
/// ½ Σ (−1)ⁿ a_n b_n cos nβ, in the totals: with both the light and the view 60° off the
/// normal, a half-space at η 1 under a distant light rendered at 0.74–0.80 of the path tracer
/// with the view on the light's side and 1.27–1.38 on the far side, where the path tracer sees
/// the same exitance on both sides (docs/oblique-incidence.md, "Validation").
///
/// Swapping the sides swaps the arguments and leaves `w` and the result unchanged bit for bit
/// (the clamped mean is taken in an order fixed by the amplitudes, not by the sides).
#[inline]
fn sides_factor(
    c_i: &[f64; 3],
    h_i: &[f64; 3],
    q_i: f64,
    c_o: &[f64; 3],
    h_o: &[f64; 3],
    q_o: f64,
    w: f64,
) -> f64 {
    let value = series(c_i, h_i).max(0.0) * series(c_o, h_o).max(0.0);
    let (a, b) = (amplitudes(c_i, q_i), amplitudes(c_o, q_o));
    let mean = if cannot_go_negative(&a) && cannot_go_negative(&b) {
        let s = q_i.max(0.0) * q_o.max(0.0);
        1.0 + 0.5
            * (-(c_i[0] * c_o[0]) * w + c_i[1] * c_o[1] * (2.0 * w * w - s)
                - c_i[2] * c_o[2] * ((4.0 * w * w - 3.0 * s) * w))
    } else {
        clamped_product_mean(a, b, q_i.max(0.0) * q_o.max(0.0), w)
    };
    if mean > 0.0 && mean.is_finite() {
        value / mean
    } else {
        1.0
    }
}

/// The mean over φ of max(0, 1 + Σ a_n cos nφ) · max(0, 1 + Σ b_n (−1)ⁿ cos n(φ − β)), with
/// cos β = w / √s (β = 0 where s = 0, where one side has no direction of travel and its
/// amplitudes are 0), over 48 midpoints. Symmetric in a and b (both series are even in φ), and
/// evaluated with the pair in an order fixed by their values, so swapping them gives the same
/// bits. Where one series cannot go negative, only the other's first three Fourier moments
/// are needed, ⟨f⟩ + Σ_n b_n (−1)ⁿ cos nβ ⟨f cos nφ⟩, and f being even, half the midpoints.
fn clamped_product_mean(a: [f64; 3], b: [f64; 3], s: f64, w: f64) -> f64 {
    const K: usize = 48;
    static TRIG: std::sync::OnceLock<[([f64; 3], [f64; 3]); K]> = std::sync::OnceLock::new();
    let trig = TRIG.get_or_init(|| {
        std::array::from_fn(|k| {
            let phi = std::f64::consts::TAU * (k as f64 + 0.5) / K as f64;
            let n = [1.0, 2.0, 3.0];
            (n.map(|n| (n * phi).cos()), n.map(|n| (n * phi).sin()))
        })
    });
    let ordered = a
        .iter()
        .zip(&b)
        .map(|(x, y)| x.total_cmp(y))
        .find(|o| o.is_ne())
        .is_none_or(|o| o.is_lt());
    let (a, b) = if ordered { (a, b) } else { (b, a) };
    let cb = if s > 0.0 {
        (w / s.sqrt()).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    let sb = (1.0 - cb * cb).max(0.0).sqrt();
    // cos nβ, sin nβ, with the (−1)ⁿ of φ_o = φ + π − β folded in.
    let cn = [-cb, 2.0 * cb * cb - 1.0, -((4.0 * cb * cb - 3.0) * cb)];
    let sn = [-sb, 2.0 * sb * cb, -((3.0 - 4.0 * sb * sb) * sb)];
    if cannot_go_negative(&a) || cannot_go_negative(&b) {
        // f the clamped series, the other one's cosine moments against it.
        let (f, g) = if cannot_go_negative(&b) {
            (a, b)
        } else {
            (b, a)
        };
        let g = [g[0] * cn[0], g[1] * cn[1], g[2] * cn[2]];
        let total: f64 = trig[..K / 2]
            .iter()
            .map(|(c, _)| series(&f, c).max(0.0) * series(&g, c))
            .sum();
        return total / (K / 2) as f64;
    }
    // The second series' coefficients of cos nφ and sin nφ: cos n(φ − β) = cos nφ cos nβ +
    // sin nφ sin nβ.
    let (bc, bs) = (
        [b[0] * cn[0], b[1] * cn[1], b[2] * cn[2]],
        [b[0] * sn[0], b[1] * sn[1], b[2] * sn[2]],
    );
    let total: f64 = trig
        .iter()
        .map(|(c, s)| {
            let f = series(&a, c);
            if f > 0.0 {
                f * (series(&bc, c) + series(&bs, s) - 1.0).max(0.0)
            } else {
                0.0
            }
        })
        .sum();
    total / K as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RadialProfile;

    fn crossing(x: f64, dir: DVec3) -> Crossing {
        Crossing::new(DVec3::new(x, 0.0, 0.0), DVec3::Z, dir.normalize())
    }

    /// The amplitudes the probe sampler reads are the exit side's factor of `coupling_between`:
    /// with light entering along the normal (no incident shift), moving x_i from the exit
    /// side's direction of travel (φ_o = 0) to the opposite side (φ_o = π) at the same
    /// distance changes the coupling by (1 + a₁ + a₂ + a₃)/(1 − a₁ + a₂ − a₃) (T and M see
    /// only the cosines and r; N cancels). Without the oblique shape they are 0.
    #[test]
    fn shift_amplitudes_are_the_exit_side_s_series() {
        let b = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.3).unwrap();
        let c = Coefficients::new(Rgb::new(0.01, 0.05, 0.3), Rgb::splat(2.0));
        let (s60, c60) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
        // ω_o tilted toward +x: light arriving along −ω_o travels toward −x.
        let exit = Crossing::new(DVec3::ZERO, DVec3::Z, DVec3::new(s60, 0.0, c60));
        let mut tested = 0;
        for r in [0.2, 0.7, 1.5, 4.0] {
            let at = |x: f64| Crossing::new(DVec3::new(x, 0.0, 0.0), DVec3::Z, DVec3::Z);
            let ahead = b.coupling_between(&c, &at(-r), &exit);
            let behind = b.coupling_between(&c, &at(r), &exit);
            for ch in 0..3 {
                let a = b.shift_amplitudes(&c, ch, r, c60, 1.0);
                assert!(
                    a.iter().all(|v| v.is_finite()) && a[0] != 0.0,
                    "{r} {ch}: {a:?}"
                );
                let (p, q) = (1.0 + a[0] + a[1] + a[2], 1.0 - a[0] + a[1] - a[2]);
                if p > 0.0 && q > 0.0 {
                    let want = p / q;
                    let got = ahead[ch] / behind[ch];
                    assert!(
                        (got / want - 1.0).abs() < 1e-12,
                        "{r} {ch}: {got} vs {want}"
                    );
                    tested += 1;
                }
            }
        }
        assert!(tested >= 6, "too few positive series: {tested}");
        let plain = b.clone().with_oblique_shape(false);
        assert_eq!(plain.shift_amplitudes(&c, 0, 1.0, c60, 1.0), [0.0; 3]);
        assert_eq!(b.shift_amplitudes(&c, 0, f64::NAN, c60, 1.0), [0.0; 3]);
    }

    /// On a curved pair the sides' factors keep the mean they have on a plane: x_o on top of
    /// a sphere seen along its normal (the exit side's factor is 1), x_i 30° and 60° around
    /// it, light entering x_i at 45° and 70° from x_i's normal, averaged over the light's
    /// azimuth about that normal, against the same cosines and chord length on a plane.
    /// With the chord's full length in place of its projection on the tangent plane the
    /// ratio falls to about 1 − C₂ sin²θ_i (1 − cos²(α/2)): 0.907 in the first case here.
    #[test]
    fn a_curved_pair_keeps_the_sides_mean() {
        let b = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.0).unwrap();
        let c = Coefficients::new(Rgb::new(0.001, 0.03, 0.2), Rgb::splat(1.0));
        let exit = Crossing::new(DVec3::ZERO, DVec3::Z, DVec3::Z);
        let k = 3600;
        let mut worst: f64 = 0.0;
        for radius in [0.5, 2.0] {
            for alpha in [30f64.to_radians(), 60f64.to_radians()] {
                // x_i on the sphere of centre (0, 0, −radius), its normal and tangent frame.
                let n_i = DVec3::new(alpha.sin(), 0.0, alpha.cos());
                let x_i = radius * n_i - DVec3::new(0.0, 0.0, radius);
                let (e1, e2) = (DVec3::new(alpha.cos(), 0.0, -alpha.sin()), DVec3::Y);
                let r = x_i.length();
                for theta in [45f64.to_radians(), 70f64.to_radians()] {
                    let mean = |at: DVec3, n: DVec3, (u, v): (DVec3, DVec3)| {
                        let mut sum = Rgb::ZERO;
                        for j in 0..k {
                            let psi = std::f64::consts::TAU * (j as f64 + 0.5) / k as f64;
                            let w = theta.cos() * n + theta.sin() * (psi.cos() * u + psi.sin() * v);
                            sum += b.coupling_between(&c, &Crossing::new(at, n, w), &exit);
                        }
                        sum * (1.0 / k as f64)
                    };
                    let curved = mean(x_i, n_i, (e1, e2));
                    let flat = mean(DVec3::new(r, 0.0, 0.0), DVec3::Z, (DVec3::X, DVec3::Y));
                    for ch in 0..3 {
                        let q = curved[ch] / flat[ch];
                        worst = worst.max((q - 1.0).abs());
                        assert!(
                            (q - 1.0).abs() < 2e-3,
                            "radius {radius} α {alpha} θ {theta} ch {ch}: {q}"
                        );
                    }
                }
            }
        }
        eprintln!("largest departure {worst:.2e}");
    }

    /// The two sides' factors average to 1 over the chord's azimuth whatever the angle
    /// between the two lights' directions of travel, so that the totals are T · M's: light
    /// and view both oblique, on the same side, opposite, and across, at distances where the
    /// series are clamped and where they are not. The product of two separately normalised
    /// factors fails this by up to 40 % (a half-space under a distant light at 60°, seen at
    /// 60°: 0.74–0.80 of the path tracer on the light's side, 1.27–1.38 on the far side).
    #[test]
    fn sides_average_to_one_whatever_their_relative_azimuth() {
        let b = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.0).unwrap();
        let c = Coefficients::new(Rgb::new(0.001, 0.03, 0.2), Rgb::splat(1.0));
        let dir = |theta: f64, azimuth: f64| {
            let (t, a) = (theta.to_radians(), azimuth.to_radians());
            DVec3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos())
        };
        // Midpoints over the chord's azimuth: the factors are smooth but for the clamp's kinks.
        // Where a series is clamped, N is a 48-point mean, good to about 1e-3; elsewhere it is
        // exact.
        let k = 3600;
        let mut kinds = [0; 3];
        for (theta_i, theta_o) in [
            (60.0, 60.0),
            (84.0, 45.0),
            (30.0, 80.0),
            (20.0, 25.0),
            (10.0, 40.0),
        ] {
            for r in [0.03, 0.3, 1.0, 4.0] {
                let (ci, co) = (dir(theta_i, 0.0).z, dir(theta_o, 0.0).z);
                let over = |a: [f64; 3]| !cannot_go_negative(&a);
                let sides: [[bool; 2]; 3] = std::array::from_fn(|ch| {
                    [
                        over(b.shift_amplitudes(&c, ch, r, ci, co)),
                        over(b.shift_amplitudes(&c, ch, r, co, ci)),
                    ]
                });
                let is_clamped = sides.map(|[i, o]| i || o);
                for [i, o] in sides {
                    kinds[usize::from(i) + usize::from(o)] += 1;
                }
                let mean = |beta: f64| {
                    let exit = Crossing::new(DVec3::ZERO, DVec3::Z, dir(theta_o, beta));
                    let mut sum = Rgb::ZERO;
                    for j in 0..k {
                        let phi = std::f64::consts::TAU * (j as f64 + 0.5) / k as f64;
                        let at = DVec3::new(r * phi.cos(), r * phi.sin(), 0.0);
                        let incident = Crossing::new(at, DVec3::Z, dir(theta_i, 17.0));
                        sum += b.coupling_between(&c, &incident, &exit);
                    }
                    sum * (1.0 / k as f64)
                };
                let same = mean(17.0);
                for beta in [197.0, 107.0, 60.0] {
                    let other = mean(beta);
                    for ch in 0..3 {
                        let tolerance = if is_clamped[ch] { 2e-3 } else { 1e-9 };
                        assert!(
                            (other[ch] / same[ch] - 1.0).abs() < tolerance,
                            "θ {theta_i}/{theta_o} r {r} β {beta} ch {ch}: {} vs {}",
                            other[ch],
                            same[ch]
                        );
                    }
                }
            }
        }
        // Every way of computing N is met: neither series clamped (closed form), one (its
        // moments), both (the product's midpoints).
        assert!(
            kinds.iter().all(|&n| n >= 3),
            "too few of a kind: {kinds:?}"
        );
    }

    /// A shift series read node by node and interpolated with its node's weight gives
    /// `shift_amplitudes` at every radius (both sides, every channel, radii from inside the
    /// first node to beyond the last), to rounding; without the oblique shape there is none.
    #[test]
    fn shift_series_interpolates_to_the_shift_amplitudes() {
        let b = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::All, 0.2, 1.3).unwrap();
        let c = Coefficients::new(Rgb::new(0.01, 0.05, 0.3), Rgb::new(2.0, 1.0, 3.0));
        let (ci, co) = (0.35, 0.8);
        let mut nodes = std::collections::BTreeSet::new();
        for ch in 0..3 {
            let s = b.shift_series(&c, ch).expect("a scattering channel");
            for k in 0..200 {
                let r = 1e-3 * 1.06f64.powi(k);
                let (node, w) = s.node(r);
                assert!(
                    node + 1 < crate::tabulated::oblique_file::N_RADII && (0.0..=1.0).contains(&w)
                );
                nodes.insert(node);
                for (side, (this, other)) in [(ci, co), (co, ci)].into_iter().enumerate() {
                    let (lo, hi) = (
                        s.amplitudes_at(node, ci, co)[side],
                        s.amplitudes_at(node + 1, ci, co)[side],
                    );
                    let want = b.shift_amplitudes(&c, ch, r, this, other);
                    for n in 0..3 {
                        let got = (1.0 - w) * lo[n] + w * hi[n];
                        assert!(
                            (got - want[n]).abs() <= 1e-12 * (1.0 + want[n].abs()),
                            "{ch} {r} {n}: {got} vs {want:?}"
                        );
                    }
                }
            }
        }
        assert!(nodes.len() >= 10, "radii cover too few nodes: {nodes:?}");
        assert!(
            b.clone()
                .with_oblique_shape(false)
                .shift_series(&c, 0)
                .is_none()
        );
    }

    /// `from_family_with` builds what `from_family` and the `with_*` switches would keep,
    /// and nothing the switches would drop.
    #[test]
    fn from_family_with_keeps_only_what_it_is_asked_for() {
        let family = ProfileFamily::with_options(
            ProfileModel::Tabulated,
            Scattering::All,
            0.0,
            1.3,
            FamilyOptions::default(),
        )
        .unwrap();
        let full = SeparableBssrdf::from_family(family);
        assert_eq!(SeparableBssrdf::from_family_with(family, true, true), full);
        let plain = SeparableBssrdf::from_family_with(family, true, false);
        assert_eq!(plain, full.clone().with_oblique_shape(false));
        assert!(plain.has_angular_coupling() && !plain.has_oblique_shape());
        let none = SeparableBssrdf::from_family_with(family, false, true);
        assert_eq!(none, full.with_angular_coupling(false));
        assert!(!none.has_angular_coupling() && !none.has_oblique_shape());
        assert_eq!(
            plain.clone().with_oblique_shape(true),
            SeparableBssrdf::from_family(family)
        );
    }

    /// S is R times the two transmissions over cπ (times T): checked term by term against the
    /// Fresnel formula and the profile evaluated on their own, for every model.
    #[test]
    fn s_is_the_product_of_its_documented_terms() {
        let c = Coefficients::new(Rgb::new(0.01, 0.1, 0.5), Rgb::new(1.0, 2.0, 0.7));
        let (a, b) = (
            crossing(0.4, DVec3::new(0.3, 0.1, 0.9)),
            crossing(0.0, DVec3::new(-0.5, 0.2, 0.6)),
        );
        for &model in ProfileModel::ALL {
            for eta in [1.0, 1.3, 1.5] {
                let s = SeparableBssrdf::new(model, Scattering::All, 0.2, eta).unwrap();
                let (ci, co) = (a.cos(), b.cos());
                // c from its definition by midpoint quadrature of the external Fresnel
                // reflectance: C1(1/η) = ∫ F_r(μ; 1/η) μ dμ.
                let n = 200_000;
                let c1: f64 = (0..n)
                    .map(|k| {
                        let mu = (k as f64 + 0.5) / n as f64;
                        dielectric(mu, eta) * mu
                    })
                    .sum::<f64>()
                    / n as f64;
                assert!((s.normalisation() - (1.0 - 2.0 * c1)).abs() < 1e-8);
                let family = ProfileFamily::new(model, Scattering::All, 0.2, eta).unwrap();
                let got = s.eval(&c, &a, &b).unwrap();
                let t = s.coupling_between(&c, &a, &b);
                if model != ProfileModel::Tabulated {
                    assert_eq!(t, Rgb::ONE);
                }
                // Without the oblique shape the coupling is T alone.
                let plain = s.clone().with_oblique_shape(false);
                assert!(!plain.has_oblique_shape());
                assert_eq!(plain.coupling_between(&c, &a, &b), s.coupling(&c, ci, co));
                for ch in 0..3 {
                    let r = family
                        .profile(c.sigma_a[ch], c.sigma_s[ch])
                        .unwrap()
                        .eval(0.4);
                    let want = r * (1.0 - dielectric(ci, eta)) * (1.0 - dielectric(co, eta))
                        / ((1.0 - 2.0 * c1) * PI)
                        * t[ch];
                    assert!(
                        (got[ch] - want).abs() <= 1e-7 * want,
                        "{model} η {eta} ch {ch}: {} vs {want}",
                        got[ch]
                    );
                }
            }
        }
    }

    /// ∫ S_w cos θ dω = 1: the entry lobe carries the light of a uniform sky in full.
    #[test]
    fn entry_lobe_is_normalised() {
        for eta in [1.0, 1.2, 1.5, 2.5] {
            let s =
                SeparableBssrdf::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, eta).unwrap();
            // ∫ S_w(μ) μ 2π dμ by the midpoint rule.
            let n = 100_000;
            let integral: f64 = (0..n)
                .map(|k| {
                    let mu = (k as f64 + 0.5) / n as f64;
                    s.entry_lobe(mu) * mu * 2.0 * PI
                })
                .sum::<f64>()
                / n as f64;
            assert!((integral - 1.0).abs() < 1e-6, "η {eta}: {integral}");
        }
    }

    #[test]
    fn reciprocal_finite_and_typed_errors() {
        let s = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::All, 0.0, 1.4).unwrap();
        let c = Coefficients::new(Rgb::new(0.01, 0.3, 2.0), Rgb::new(1.0, 0.5, 0.0));
        for k in 0..50 {
            let t = k as f64;
            let a = crossing(0.1 * t, DVec3::new(t.sin(), t.cos(), 1.5 + (2.0 * t).sin()));
            let b = crossing(0.0, DVec3::new((3.0 * t).cos(), 0.2, 0.1 + 0.05 * t));
            let (x, y) = (s.eval(&c, &a, &b).unwrap(), s.eval(&c, &b, &a).unwrap());
            assert!(x.is_finite() && x.min_component() >= 0.0);
            assert_eq!(x, y);
        }
        // Behind the surface: 0.
        let below = crossing(0.2, DVec3::new(0.0, 0.3, -1.0));
        let up = crossing(0.0, DVec3::Z);
        assert_eq!(s.eval(&c, &below, &up).unwrap(), Rgb::ZERO);
        // Invalid input is a typed error naming the part.
        let nan = Crossing::new(DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Z, DVec3::Z);
        let e = s.eval(&c, &nan, &up).unwrap_err();
        assert!(e.to_string().contains("incident"), "{e}");
        let e = s
            .eval(&Coefficients::grey(-1.0, 1.0), &up, &up)
            .unwrap_err();
        assert!(e.to_string().contains("sigma_a"), "{e}");
        assert!(SeparableBssrdf::new(ProfileModel::Dipole, Scattering::All, 0.0, 0.5).is_err());
        // The coupling can be turned off, and is absent for the diffusion models.
        assert!(s.has_angular_coupling());
        assert!(
            !s.clone()
                .with_angular_coupling(false)
                .has_angular_coupling()
        );
        assert!(s.has_oblique_shape());
        assert!(
            !s.clone()
                .with_angular_coupling(false)
                .with_oblique_shape(true)
                .has_oblique_shape()
        );
        let pbd = SeparableBssrdf::new(ProfileModel::Pbd, Scattering::All, 0.0, 1.4).unwrap();
        assert!(!pbd.with_angular_coupling(true).has_angular_coupling());
    }
}
