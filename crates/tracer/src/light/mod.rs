//! Light sources and their sampling for next-event estimation.
//!
//! Conventions (radiometry as in pbrt4 §4 and §12):
//! * `wi` points from the shading point toward the light.
//! * [`LightSample::li`] is the incident radiance along `−wi` **divided by the pdf** of the
//!   sample (solid angle); for delta lights it is the factor such that a BSDF `f` contributes
//!   `f · li · |cos θ_i|`.
//! * Radiance, irradiance and intensity are linear RGB; units are whatever the scene's
//!   radiometric unit is (W for power, W/sr for intensity, W/m² for irradiance, W/(sr·m²) for
//!   radiance, with m = the scene unit).
//!
//! Environment lights are constant or read from an image ([`environment`]), and are sampled in
//! proportion to the image.

pub mod environment;

pub use environment::{EnvironmentDesc, EnvironmentError, EnvironmentMap};

use std::f64::consts::PI;
use std::sync::Arc;

use bssrdf_core::Rgb;
use glam::DVec3;
use serde::Deserialize;

use crate::error::SceneError;
use crate::geometry::Hit;
use crate::scene::desc::{DescContext, RgbDesc, exact, tagged};

tagged!(
    /// `[[light]]` in a scene file: its kind's description. Each converts itself to a
    /// [`Light`] ([`LightDesc::build`]).
    pub enum LightDesc for "light" {
        /// `type = "directional"`.
        "directional" => Directional(DirectionalDesc),
        /// `type = "point"`.
        "point" => Point(PointDesc),
        /// `type = "quad"`.
        "quad" => Quad(QuadDesc),
        /// `type = "environment"`.
        "environment" => Environment(EnvironmentDesc),
        /// `type = "beam"`.
        "beam" => Beam(BeamDesc),
    }
);

impl LightDesc {
    /// The light described; `cx` reads an environment map's image and names the keys of
    /// invalid values.
    pub fn build(self, cx: &dyn DescContext) -> Result<Light, SceneError> {
        let light = match self {
            LightDesc::Directional(d) => Light::try_from(d),
            LightDesc::Point(d) => Light::try_from(d),
            LightDesc::Quad(d) => Light::try_from(d),
            LightDesc::Environment(d) => return d.build(cx),
            LightDesc::Beam(d) => Light::try_from(d),
        };
        light.map_err(|e| cx.invalid(e.key(), e.to_string()))
    }
}

/// A light source.
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    /// Parallel light from infinitely far away.
    Directional(DirectionalLight),
    /// An isotropic point source.
    Point(PointLight),
    /// A one-sided emitting parallelogram; also an object of the scene's geometry.
    Quad(QuadLight),
    /// Radiance from every direction at infinity: constant, or an image ([`EnvironmentMap`]).
    Environment(EnvironmentLight),
    /// A pencil beam (the paper's beam experiment): not sampled by [`Light::sample_li`] and
    /// invisible to camera rays.
    Beam(BeamLight),
}

/// Parallel light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction in which the light TRAVELS.
    pub direction: DVec3,
    /// Irradiance on a surface perpendicular to `direction`.
    pub irradiance: Rgb,
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

impl TryFrom<DirectionalDesc> for Light {
    type Error = LightError;
    fn try_from(d: DirectionalDesc) -> Result<Light, LightError> {
        Light::directional(d.direction.into(), Rgb(d.irradiance.0))
    }
}

/// Isotropic point light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLight {
    /// Position.
    pub position: DVec3,
    /// Radiant intensity (per steradian).
    pub intensity: Rgb,
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

impl TryFrom<PointDesc> for Light {
    type Error = LightError;
    fn try_from(d: PointDesc) -> Result<Light, LightError> {
        Light::point(d.position.into(), Rgb(d.intensity.0))
    }
}

/// A one-sided parallelogram `corner + s·edge_u + t·edge_v`, `s, t ∈ [0, 1]`, emitting
/// constant radiance on the side of `edge_u × edge_v`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadLight {
    /// A corner.
    pub corner: DVec3,
    /// First edge.
    pub edge_u: DVec3,
    /// Second edge.
    pub edge_v: DVec3,
    /// Emitted radiance.
    pub radiance: Rgb,
    /// Unit normal `edge_u × edge_v / |…|` (the emitting side).
    pub normal: DVec3,
    /// Area `|edge_u × edge_v|`.
    pub area: f64,
    /// The scene object holding its geometry, once added to a scene.
    pub object: Option<u32>,
}

impl QuadLight {
    /// The four corners in order: `corner`, `+ edge_u`, `+ edge_u + edge_v`, `+ edge_v` (wound
    /// so that `edge_u × edge_v` is the emitting side).
    pub fn vertices(&self) -> [DVec3; 4] {
        [
            self.corner,
            self.corner + self.edge_u,
            self.corner + self.edge_u + self.edge_v,
            self.corner + self.edge_v,
        ]
    }
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

impl TryFrom<QuadDesc> for Light {
    type Error = LightError;
    fn try_from(d: QuadDesc) -> Result<Light, LightError> {
        Light::quad(
            d.corner.into(),
            d.edge_u.into(),
            d.edge_v.into(),
            Rgb(d.radiance.0),
        )
    }
}

/// Environment radiance: constant, or read from an image.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentLight {
    /// Radiance arriving from every direction, when there is no `map` (zero with one).
    pub radiance: Rgb,
    /// The radiance by direction, from an image (replaces `radiance`).
    pub map: Option<Arc<EnvironmentMap>>,
}

impl EnvironmentLight {
    /// The radiance arriving along `−dir` (`dir` unit, the direction looked toward).
    #[inline]
    pub fn radiance_toward(&self, dir: DVec3) -> Rgb {
        match &self.map {
            None => self.radiance,
            Some(m) => m.radiance(dir),
        }
    }

    /// A direction toward the environment with the uniforms `u ∈ [0, 1)²`, its solid-angle
    /// density and the radiance along it: uniform on the sphere for a constant environment
    /// (pbrt-v4 §A.5.2), in proportion to the image for a map ([`EnvironmentMap::sample`]).
    #[inline]
    pub fn sample(&self, u: [f64; 2]) -> Option<(DVec3, f64, Rgb)> {
        match &self.map {
            None => Some((uniform_sphere(u), 1.0 / (4.0 * PI), self.radiance)),
            Some(m) => m.sample(u),
        }
    }

    /// The solid-angle density with which [`EnvironmentLight::sample`] produces `dir`.
    #[inline]
    pub fn pdf(&self, dir: DVec3) -> f64 {
        match &self.map {
            None => 1.0 / (4.0 * PI),
            Some(m) => m.pdf(dir),
        }
    }

    /// The radiance averaged over every direction.
    pub fn mean_radiance(&self) -> Rgb {
        match &self.map {
            None => self.radiance,
            Some(m) => m.mean_radiance(),
        }
    }
}

/// A pencil beam entering the scene at `origin` along `direction`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamLight {
    /// Start of the beam.
    pub origin: DVec3,
    /// Unit direction of travel.
    pub direction: DVec3,
    /// Power carried by the beam.
    pub power: Rgb,
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

impl TryFrom<BeamDesc> for Light {
    type Error = LightError;
    fn try_from(d: BeamDesc) -> Result<Light, LightError> {
        Light::beam(d.origin.into(), d.direction.into(), Rgb(d.power.0))
    }
}

/// A sample of incident light at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: DVec3,
    /// Distance to the sampled point (`f64::INFINITY` for directional and environment).
    pub dist: f64,
    /// The sampled point on the light (point and quad lights), or `None` at infinity. A
    /// shadow ray must end here, measured from wherever the ray actually starts (an origin
    /// offset off the surface is not the shading point).
    pub point: Option<DVec3>,
    /// The scene object holding the light's geometry (quad lights in a scene): a shadow ray
    /// that hits this object has reached the light, since a planar emitter cannot occlude
    /// its own front.
    pub object: Option<u32>,
    /// Incident radiance along `−wi` divided by `pdf` (see the module docs).
    pub li: Rgb,
    /// Solid-angle pdf of `wi` (1 for delta lights).
    pub pdf: f64,
    /// True for delta lights (directional, point): no MIS.
    pub delta: bool,
}

/// Invalid light parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LightError {
    /// A direction that is zero or not finite.
    #[error("`{0}` must be a finite non-zero vector")]
    BadDirection(&'static str),
    /// A position that is not finite.
    #[error("`{0}` must be finite")]
    NonFinite(&'static str),
    /// An emission value that is negative or not finite.
    #[error("`{what}` must be finite and non-negative, got {value:?}")]
    BadValue {
        /// Which value.
        what: &'static str,
        /// The value.
        value: [f64; 3],
    },
    /// Quad edges that are zero or parallel.
    #[error("the quad's edges are zero or parallel (area 0)")]
    DegenerateQuad,
}

impl LightError {
    /// The scene file's key (below the light's table) that holds the invalid value.
    pub fn key(&self) -> &'static str {
        match self {
            LightError::BadDirection(w) | LightError::NonFinite(w) => w,
            LightError::BadValue { what, .. } => what,
            LightError::DegenerateQuad => "edge_v",
        }
    }
}

fn check_rgb(what: &'static str, v: Rgb) -> Result<Rgb, LightError> {
    if v.is_finite() && v.min_component() >= 0.0 {
        Ok(v)
    } else {
        Err(LightError::BadValue { what, value: v.0 })
    }
}

fn check_dir(what: &'static str, d: DVec3) -> Result<DVec3, LightError> {
    if d.is_finite() {
        d.try_normalize().ok_or(LightError::BadDirection(what))
    } else {
        Err(LightError::BadDirection(what))
    }
}

fn check_pos(what: &'static str, p: DVec3) -> Result<DVec3, LightError> {
    if p.is_finite() {
        Ok(p)
    } else {
        Err(LightError::NonFinite(what))
    }
}

impl Light {
    /// The light's kind as scene files name it (`type = "…"`), for messages.
    pub const fn kind(&self) -> &'static str {
        match self {
            Light::Directional(_) => "directional",
            Light::Point(_) => "point",
            Light::Quad(_) => "quad",
            Light::Environment(_) => "environment",
            Light::Beam(_) => "beam",
        }
    }

    /// Parallel light travelling along `direction` (normalised here).
    pub fn directional(direction: DVec3, irradiance: Rgb) -> Result<Light, LightError> {
        Ok(Light::Directional(DirectionalLight {
            direction: check_dir("direction", direction)?,
            irradiance: check_rgb("irradiance", irradiance)?,
        }))
    }

    /// Point light.
    pub fn point(position: DVec3, intensity: Rgb) -> Result<Light, LightError> {
        Ok(Light::Point(PointLight {
            position: check_pos("position", position)?,
            intensity: check_rgb("intensity", intensity)?,
        }))
    }

    /// One-sided quad emitting `radiance` on the side of `edge_u × edge_v`.
    pub fn quad(
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
        radiance: Rgb,
    ) -> Result<Light, LightError> {
        check_pos("corner", corner)?;
        check_pos("edge_u", edge_u)?;
        check_pos("edge_v", edge_v)?;
        let n = edge_u.cross(edge_v);
        let area = n.length();
        if !(area > 0.0 && area.is_finite()) {
            return Err(LightError::DegenerateQuad);
        }
        Ok(Light::Quad(QuadLight {
            corner,
            edge_u,
            edge_v,
            radiance: check_rgb("radiance", radiance)?,
            normal: n / area,
            area,
            object: None,
        }))
    }

    /// Constant environment.
    pub fn environment(radiance: Rgb) -> Result<Light, LightError> {
        Ok(Light::Environment(EnvironmentLight {
            radiance: check_rgb("radiance", radiance)?,
            map: None,
        }))
    }

    /// An environment read from an image ([`EnvironmentMap`]).
    pub fn environment_map(map: EnvironmentMap) -> Light {
        Light::Environment(EnvironmentLight {
            radiance: Rgb::ZERO,
            map: Some(Arc::new(map)),
        })
    }

    /// Pencil beam.
    pub fn beam(origin: DVec3, direction: DVec3, power: Rgb) -> Result<Light, LightError> {
        Ok(Light::Beam(BeamLight {
            origin: check_pos("origin", origin)?,
            direction: check_dir("direction", direction)?,
            power: check_rgb("power", power)?,
        }))
    }

    /// True for lights that cannot be hit by chance (directional, point, beam).
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Directional(_) | Light::Point(_) | Light::Beam(_)
        )
    }

    /// Samples incident light at `p` with the uniforms `u ∈ [0, 1)²`:
    /// * directional: `wi = −direction`, `li = irradiance`;
    /// * point: `li = intensity / dist²`;
    /// * quad: a uniform point on the quad, pdf converted to solid angle
    ///   (`dist² / (area · cos θ_light)`); `None` when `p` is behind the emitting side;
    /// * environment: a uniform direction on the sphere, pdf `1/(4π)`, or for an image a
    ///   direction drawn in proportion to it ([`EnvironmentMap::sample`]);
    /// * beam: always `None`.
    #[inline]
    pub fn sample_li(&self, p: DVec3, u: [f64; 2]) -> Option<LightSample> {
        match self {
            Light::Directional(l) => Some(LightSample {
                wi: -l.direction,
                dist: f64::INFINITY,
                point: None,
                object: None,
                li: l.irradiance,
                pdf: 1.0,
                delta: true,
            }),
            Light::Point(l) => {
                let d = l.position - p;
                let dist2 = d.length_squared();
                if dist2 <= 0.0 {
                    return None;
                }
                let dist = dist2.sqrt();
                Some(LightSample {
                    wi: d / dist,
                    dist,
                    point: Some(l.position),
                    object: None,
                    li: l.intensity / dist2,
                    pdf: 1.0,
                    delta: true,
                })
            }
            Light::Quad(q) => {
                let y = q.corner + u[0] * q.edge_u + u[1] * q.edge_v;
                let d = y - p;
                let dist2 = d.length_squared();
                let dist = dist2.sqrt();
                if dist.is_nan() || dist <= 0.0 {
                    return None;
                }
                let wi = d / dist;
                let cos_l = -wi.dot(q.normal);
                if cos_l <= 0.0 {
                    return None;
                }
                let pdf = dist2 / (q.area * cos_l);
                if !(pdf.is_finite() && pdf > 0.0) {
                    return None;
                }
                Some(LightSample {
                    wi,
                    dist,
                    point: Some(y),
                    object: q.object,
                    li: q.radiance / pdf,
                    pdf,
                    delta: false,
                })
            }
            Light::Environment(e) => {
                let (wi, pdf, radiance) = e.sample(u)?;
                Some(LightSample {
                    wi,
                    dist: f64::INFINITY,
                    point: None,
                    object: None,
                    li: radiance / pdf,
                    pdf,
                    delta: false,
                })
            }
            Light::Beam(_) => None,
        }
    }

    /// The solid-angle pdf with which [`Light::sample_li`] at `p` would have produced the
    /// direction `wi` reaching the light at `point_on_light` (ignored for the environment).
    /// Use it for MIS when a path hits an area light or escapes to the environment by chance.
    /// 0 for delta lights and for the back of a quad.
    #[inline]
    pub fn pdf_li(&self, p: DVec3, wi: DVec3, point_on_light: DVec3) -> f64 {
        match self {
            Light::Quad(q) => {
                let cos_l = -wi.dot(q.normal);
                if cos_l <= 0.0 {
                    return 0.0;
                }
                (point_on_light - p).length_squared() / (q.area * cos_l)
            }
            Light::Environment(e) => e.pdf(wi),
            _ => 0.0,
        }
    }

    /// Radiance arriving along an escaped ray travelling in `dir` (environment lights; zero
    /// for the others).
    #[inline]
    pub fn le(&self, dir: DVec3) -> Rgb {
        match self {
            Light::Environment(e) => e.radiance_toward(dir),
            _ => Rgb::ZERO,
        }
    }

    /// Radiance emitted by a quad at `hit` toward `wo` (unit, pointing away from the light,
    /// toward the viewer): the quad's radiance on its emitting side, zero behind; zero for
    /// other lights.
    #[inline]
    pub fn emitted(&self, _hit: &Hit, wo: DVec3) -> Rgb {
        match self {
            Light::Quad(q) if wo.dot(q.normal) > 0.0 => q.radiance,
            _ => Rgb::ZERO,
        }
    }

    /// Total emitted power (luminance of the RGB power), for choosing lights in proportion to
    /// it. Lights at infinity need the radius of the scene's bounding sphere.
    pub fn power(&self, scene_radius: f64) -> f64 {
        match self {
            Light::Directional(l) => l.irradiance.luminance() * PI * scene_radius * scene_radius,
            Light::Point(l) => 4.0 * PI * l.intensity.luminance(),
            Light::Quad(q) => PI * q.area * q.radiance.luminance(),
            Light::Environment(e) => {
                4.0 * PI * PI * scene_radius * scene_radius * e.mean_radiance().luminance()
            }
            Light::Beam(b) => b.power.luminance(),
        }
    }
}

/// Uniform direction on the unit sphere (pbrt-v4 §A.5.2: `z = 1 − 2u₀`, `φ = 2πu₁`).
#[inline]
pub fn uniform_sphere(u: [f64; 2]) -> DVec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delta_lights() {
        let d = Light::directional(DVec3::new(0.0, 0.0, -2.0), Rgb::splat(3.0)).unwrap();
        let s = d.sample_li(DVec3::ZERO, [0.3, 0.4]).unwrap();
        assert_eq!(s.wi, DVec3::Z);
        assert!(s.delta && s.dist.is_infinite() && s.li == Rgb::splat(3.0));
        let p = Light::point(DVec3::new(0.0, 2.0, 0.0), Rgb::splat(8.0)).unwrap();
        let s = p.sample_li(DVec3::ZERO, [0.0, 0.0]).unwrap();
        assert!(s.li == Rgb::splat(2.0) && s.dist == 2.0 && s.wi == DVec3::Y);
        assert!(
            Light::beam(DVec3::ZERO, DVec3::NEG_Z, Rgb::ONE)
                .unwrap()
                .sample_li(DVec3::ZERO, [0.5; 2])
                .is_none()
        );
        assert!(Light::quad(DVec3::ZERO, DVec3::X, DVec3::X, Rgb::ONE).is_err());
        assert!(Light::point(DVec3::ZERO, Rgb::splat(-1.0)).is_err());
    }

    #[test]
    fn quad_is_one_sided_and_pdf_consistent() {
        let q = Light::quad(
            DVec3::new(-1.0, -1.0, 2.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            Rgb::ONE,
        )
        .unwrap();
        // Emits toward +z (X × Y): a point below it sees its back.
        assert!(q.sample_li(DVec3::ZERO, [0.5, 0.5]).is_none());
        let above = DVec3::new(0.0, 0.0, 5.0);
        let s = q.sample_li(above, [0.25, 0.75]).unwrap();
        let y = DVec3::new(-0.5, 0.5, 2.0);
        assert!((q.pdf_li(above, s.wi, y) - s.pdf).abs() < 1e-12 * s.pdf);
    }
}
