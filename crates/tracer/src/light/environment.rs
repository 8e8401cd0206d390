//! Image-based lighting: the radiance arriving from infinitely far away, read from an
//! equirectangular (latitude–longitude) image and importance-sampled in proportion to it
//! (pbrt3 §12.6 and §14.2.4, `InfiniteAreaLight`; pbrt-v4 §12.5.2, `ImageInfiniteLight`, which
//! uses another parameterisation).
//!
//! # Directions and pixels
//! The map has an *up* axis (`z` by default, the scenes' vertical; `y` for assets modelled
//! y-up) and a frame `(x', y', z' = up)` made by cycling the world axes: up `z` gives
//! `(x, y, z)`, up `y` gives `(z, x, y)`, up `x` gives `(y, z, x)`. A direction `ω` that a ray
//! looks toward (radiance arrives along `−ω`) has polar angle `θ = acos(ω·z')` from up and
//! azimuth `φ = atan2(ω·y', ω·x')`, and reads the image at
//!
//! `u = (φ − rotation) / 2π` (wrapped into `[0, 1)`; `u = 0` is the left edge),
//! `v = θ / π` (`v = 0`, the top row, is straight up; the bottom row straight down).
//!
//! So `rotation` (degrees in the scene file) turns the map about up, counter-clockwise seen from
//! above: the image's left edge, which faces `+x'` at rotation 0, faces the azimuth
//! `rotation`. The radiance is the bilinear interpolation of the texels (centres at
//! `((i + ½)/W, (j + ½)/H)`, repeating across the left and right edges, clamped at the top and
//! bottom rows) times the per-channel `scale`.
//!
//! # Sampling
//! Directions are sampled from a piecewise-constant distribution over the texels
//! ([`PiecewiseConstant2D`]) whose value for texel `(i, j)` is the mean over its channels of the
//! scaled radiance averaged over the texel, times `sin θ_j` at the texel row's centre (pbrt3
//! §14.2.4: the equirectangular map's area element is `sin θ dθ dφ`). The average of the
//! bilinear interpolation over a texel is exactly `Σ w_a w_b t(i + a, j + b)` over the 3 × 3
//! texels around it, with `w = (1/8, 3/4, 1/8)` (in one dimension the half-texel on each side
//! blends the neighbour in with weight falling from ½ to 0: `∫₀^½ (½ − s) ds = 1/8`), so the
//! distribution is positive wherever the radiance is. With `(u, v)` drawn with density
//! `p(u, v)`, the direction has the solid-angle density
//!
//! `p(ω) = p(u, v) / (2π² sin θ)`
//!
//! (the Jacobian of `(u, v) ↦ ω`, `dω = sin θ dθ dφ = 2π² sin θ du dv`), exactly, although
//! `sin θ` varies inside a texel's row.

use std::f64::consts::PI;
use std::sync::Arc;

use bssrdf_core::Rgb;
use glam::DVec3;

use serde::Deserialize;

use super::Light;
use crate::distribution::PiecewiseConstant2D;
use crate::error::SceneError;
use crate::field::{Axis, Texture};
use crate::scene::desc::{AxisDesc, DescContext, RgbDesc};

/// `[[light]]` with `type = "environment"`: a constant `radiance`, or an image `filename`
/// with its `scale`, `rotation` and `up` ([`EnvironmentMap`]).
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

impl EnvironmentDesc {
    /// The environment light: read from the image `filename` (through `cx`), or constant
    /// (`radiance`; `scale`, `rotation` and `up` then refused).
    pub fn build(self, cx: &dyn DescContext) -> Result<Light, SceneError> {
        let Some(rel) = &self.filename else {
            let Some(radiance) = self.radiance else {
                return Err(cx.invalid(
                    "",
                    "an environment light needs `radiance` (constant) or `filename` (an image)"
                        .into(),
                ));
            };
            for (name, given) in [
                ("scale", self.scale.is_some()),
                ("rotation", self.rotation.is_some()),
                ("up", self.up.is_some()),
            ] {
                if given {
                    return Err(cx.invalid(
                        name,
                        format!("`{name}` applies to an environment map (`filename`)"),
                    ));
                }
            }
            return Light::environment(Rgb(radiance.0))
                .map_err(|e| cx.invalid(e.key(), e.to_string()));
        };
        if self.radiance.is_some() {
            return Err(cx.invalid(
                "radiance",
                "give `radiance` (constant) or `filename` (an image), not both; `scale` \
                 multiplies the image"
                    .into(),
            ));
        }
        let ext = std::path::Path::new(rel)
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if !matches!(ext.as_deref(), Some("exr" | "hdr")) {
            return Err(cx.invalid(
                "filename",
                format!(
                    "`{rel}`: an environment map is an `.exr` or Radiance `.hdr` image \
                     (linear radiance)"
                ),
            ));
        }
        let texture = cx.texture("filename", rel, true)?;
        let map = EnvironmentMap::new(
            Arc::new(texture),
            Rgb(self.scale.map_or([1.0; 3], |s| s.0)),
            Axis::from(self.up.unwrap_or(AxisDesc::Z)),
            self.rotation.unwrap_or(0.0),
        )
        .map_err(|e| {
            let sub = match e {
                EnvironmentError::BadRotation(_) => "rotation",
                _ => "scale",
            };
            cx.invalid(sub, e.to_string())
        })?;
        Ok(Light::environment_map(map))
    }
}

/// The bilinear filter's average over one texel, per neighbour offset −1, 0, +1 (module docs).
const TEXEL_AVERAGE: [f64; 3] = [0.125, 0.75, 0.125];

/// An environment map: radiance by direction from an equirectangular image (module docs).
#[derive(Debug)]
pub struct EnvironmentMap {
    texture: Arc<Texture>,
    /// Per-channel multiplier of the texels.
    scale: Rgb,
    /// The map's up axis.
    up: Axis,
    /// Turn about up, radians.
    rotation: f64,
    /// Importance over the texels (module docs).
    distribution: PiecewiseConstant2D,
    /// The radiance averaged over the sphere of directions, `∫ L dω / 4π`.
    mean: Rgb,
}

impl PartialEq for EnvironmentMap {
    fn eq(&self, other: &Self) -> bool {
        // The distribution and the mean follow from these.
        self.texture == other.texture
            && self.scale == other.scale
            && self.up == other.up
            && self.rotation == other.rotation
    }
}

/// Why an environment map cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EnvironmentError {
    /// `scale` is negative or not finite.
    #[error("`scale` must be finite and non-negative, got {0:?}")]
    BadScale([f64; 3]),
    /// `rotation` is not finite.
    #[error("`rotation` must be a finite number of degrees, got {0}")]
    BadRotation(f64),
}

impl EnvironmentMap {
    /// The map of `texture` (its texels are radiance, linear RGB, already checked finite and
    /// non-negative by [`Texture`]), times `scale`, with its up axis `up` and turned by
    /// `rotation_degrees` about it.
    pub fn new(
        texture: Arc<Texture>,
        scale: Rgb,
        up: Axis,
        rotation_degrees: f64,
    ) -> Result<Self, EnvironmentError> {
        if !(scale.is_finite() && scale.min_component() >= 0.0) {
            return Err(EnvironmentError::BadScale(scale.0));
        }
        if !rotation_degrees.is_finite() {
            return Err(EnvironmentError::BadRotation(rotation_degrees));
        }
        let (w, h) = (texture.width as usize, texture.height as usize);
        let fetch = |i: i64, j: i64| -> Rgb {
            let i = i.rem_euclid(w as i64) as u32;
            let j = j.clamp(0, h as i64 - 1) as u32;
            Rgb(texture.texel(i, j).map(f64::from))
        };
        let mut func = Vec::with_capacity(w * h);
        let mut total = Rgb::ZERO;
        let d_phi = 2.0 * PI / w as f64;
        for j in 0..h {
            let theta = |k: usize| PI * k as f64 / h as f64;
            let sin_centre = (PI * (j as f64 + 0.5) / h as f64).sin();
            // ∫ sin θ dθ dφ over one texel of the row.
            let solid_angle = d_phi * (theta(j).cos() - theta(j + 1).cos());
            for i in 0..w {
                let mut average = Rgb::ZERO;
                for (a, wa) in TEXEL_AVERAGE.iter().enumerate() {
                    for (b, wb) in TEXEL_AVERAGE.iter().enumerate() {
                        average +=
                            fetch(i as i64 + a as i64 - 1, j as i64 + b as i64 - 1) * (wa * wb);
                    }
                }
                let radiance = average * scale;
                total += radiance * solid_angle;
                func.push(radiance.mean() * sin_centre);
            }
        }
        Ok(Self {
            distribution: PiecewiseConstant2D::new(&func, w, h),
            mean: total * (1.0 / (4.0 * PI)),
            texture,
            scale,
            up,
            rotation: rotation_degrees.to_radians(),
        })
    }

    /// The image file, for messages.
    pub fn file(&self) -> &str {
        &self.texture.file
    }

    /// The radiance averaged over every direction, `∫ L dω / 4π` (bilinear texels weighted by
    /// their rows' solid angle).
    pub fn mean_radiance(&self) -> Rgb {
        self.mean
    }

    /// `ω` in the map's frame `(x', y', z')` (module docs).
    #[inline]
    fn to_local(&self, d: DVec3) -> DVec3 {
        match self.up {
            Axis::Z => d,
            Axis::Y => DVec3::new(d.z, d.x, d.y),
            Axis::X => DVec3::new(d.y, d.z, d.x),
        }
    }

    /// The world direction of `l` given in the map's frame.
    #[inline]
    fn to_world(&self, l: DVec3) -> DVec3 {
        match self.up {
            Axis::Z => l,
            Axis::Y => DVec3::new(l.y, l.z, l.x),
            Axis::X => DVec3::new(l.z, l.x, l.y),
        }
    }

    /// The image coordinates `(u, v)` of the unit direction `d`, and `sin θ`.
    #[inline]
    fn uv(&self, d: DVec3) -> ([f64; 2], f64) {
        let l = self.to_local(d);
        let phi = l.y.atan2(l.x) - self.rotation;
        let mut u = (phi / (2.0 * PI)).rem_euclid(1.0);
        if u >= 1.0 {
            u = 0.0; // rem_euclid of a tiny negative number rounds to 1
        }
        let cos = l.z.clamp(-1.0, 1.0);
        let v = (cos.acos() / PI).min(1.0 - f64::EPSILON / 2.0);
        ([u, v], (l.x * l.x + l.y * l.y).sqrt().min(1.0))
    }

    /// The unit direction at image coordinates `(u, v)`, and `sin θ`.
    #[inline]
    fn direction(&self, uv: [f64; 2]) -> (DVec3, f64) {
        let theta = PI * uv[1];
        let phi = 2.0 * PI * uv[0] + self.rotation;
        let (sin_t, cos_t) = theta.sin_cos();
        let (sin_p, cos_p) = phi.sin_cos();
        (
            self.to_world(DVec3::new(sin_t * cos_p, sin_t * sin_p, cos_t)),
            sin_t,
        )
    }

    /// The scaled radiance at image coordinates `(u, v)` (bilinear, module docs).
    #[inline]
    fn radiance_at(&self, uv: [f64; 2]) -> Rgb {
        let t = &self.texture;
        let (w, h) = (t.width as i64, t.height as i64);
        let x = uv[0] * w as f64 - 0.5;
        let y = uv[1] * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (i0, j0) = (x0 as i64, y0 as i64);
        let fetch = |i: i64, j: i64| -> Rgb {
            Rgb(t
                .texel(i.rem_euclid(w) as u32, j.clamp(0, h - 1) as u32)
                .map(f64::from))
        };
        let top = fetch(i0, j0) * (1.0 - fx) + fetch(i0 + 1, j0) * fx;
        let bottom = fetch(i0, j0 + 1) * (1.0 - fx) + fetch(i0 + 1, j0 + 1) * fx;
        (top * (1.0 - fy) + bottom * fy) * self.scale
    }

    /// The radiance arriving along `−d` (`d` unit: the direction looked toward).
    #[inline(never)] // out of the light loop of scenes without a map
    pub fn radiance(&self, d: DVec3) -> Rgb {
        self.radiance_at(self.uv(d).0)
    }

    /// Samples a direction `ω` toward the environment with the uniforms `u ∈ [0, 1)²`:
    /// `(ω, p(ω), L(ω))`, the solid-angle density (module docs). `None` for the measure-zero
    /// samples at a pole, where the density is not defined.
    #[inline(never)] // out of the light loop of scenes without a map
    pub fn sample(&self, u: [f64; 2]) -> Option<(DVec3, f64, Rgb)> {
        // The distribution picks the row (v) with the first number.
        let (uv, p_uv) = self.distribution.sample(u);
        let (w, sin_t) = self.direction(uv);
        let pdf = p_uv / (2.0 * PI * PI * sin_t);
        (pdf.is_finite() && pdf > 0.0).then(|| (w, pdf, self.radiance_at(uv)))
    }

    /// The solid-angle density with which [`EnvironmentMap::sample`] produces the unit
    /// direction `d`.
    #[inline(never)] // out of the light loop of scenes without a map
    pub fn pdf(&self, d: DVec3) -> f64 {
        let (uv, sin_t) = self.uv(d);
        if sin_t <= 0.0 {
            return 0.0;
        }
        let p = self.distribution.pdf(uv) / (2.0 * PI * PI * sin_t);
        if p.is_finite() { p } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::sphere_bins::SphereBins;
    use bssrdf_core::chi_square::ChiSquareTest;

    /// A `w × h` map of random texels in [0, 4) (a few black), for the tests.
    fn random_map(w: u32, h: u32, up: Axis, rotation: f64) -> EnvironmentMap {
        let mut rng = Rng::from_keys(17, &[u64::from(w), u64::from(h)]);
        let texels = (0..w * h)
            .map(|k| {
                if k % 7 == 0 {
                    [0.0; 3]
                } else {
                    [0, 1, 2].map(|_| (4.0 * rng.uniform()) as f32)
                }
            })
            .collect();
        let t = Texture::from_texels("random.exr", w, h, texels).unwrap();
        EnvironmentMap::new(Arc::new(t), Rgb::new(1.0, 0.5, 2.0), up, rotation).unwrap()
    }

    #[test]
    fn directions_and_pixels_round_trip() {
        for up in [Axis::X, Axis::Y, Axis::Z] {
            let m = random_map(16, 8, up, 37.0);
            for k in 0..200 {
                let uv = [
                    (k as f64 * 0.618).fract(),
                    (k as f64 * 0.377).fract() * 0.98 + 0.01,
                ];
                let (d, _) = m.direction(uv);
                assert!((d.length() - 1.0).abs() < 1e-12);
                let (back, _) = m.uv(d);
                let du = (back[0] - uv[0]).abs();
                assert!(du.min(1.0 - du) < 1e-9 && (back[1] - uv[1]).abs() < 1e-9);
            }
            // Up is the top row.
            assert!(m.uv(up.unit()).0[1] < 1e-9);
        }
        // Rotation 90° about z: the left edge (u = 0) faces +y.
        let m = random_map(16, 8, Axis::Z, 90.0);
        assert!(m.uv(DVec3::Y).0[0] < 1e-9 || m.uv(DVec3::Y).0[0] > 1.0 - 1e-9);
    }

    /// The density integrates to 1 over the sphere, and is what `sample` reports.
    #[test]
    fn density_integrates_to_one() {
        let m = random_map(24, 12, Axis::Y, 10.0);
        let (nt, np) = (600, 1200);
        let mut total = 0.0;
        for a in 0..nt {
            let cos = 1.0 - 2.0 * (a as f64 + 0.5) / nt as f64;
            let sin = (1.0 - cos * cos).sqrt();
            for b in 0..np {
                let phi = 2.0 * PI * (b as f64 + 0.5) / np as f64;
                let d = DVec3::new(sin * phi.cos(), sin * phi.sin(), cos);
                total += m.pdf(d) * 4.0 * PI / (nt * np) as f64;
            }
        }
        assert!((total - 1.0).abs() < 2e-3, "{total}");
        let mut rng = Rng::from_keys(3, &[]);
        for _ in 0..1000 {
            let (d, p, l) = m.sample(rng.uniform2()).unwrap();
            assert!((m.pdf(d) - p).abs() <= 1e-9 * p, "{} vs {p}", m.pdf(d));
            assert!((m.radiance(d) - l).max_component().abs() < 1e-9);
        }
    }

    /// χ² test of sampled directions against the density `pdf`, integrated over bins of
    /// equal solid angle in the world frame (independent of the sampler's cdf).
    #[test]
    fn sampler_matches_its_density() {
        let checks = [(Axis::Z, 0.0), (Axis::Y, 123.0)];
        let test = ChiSquareTest::family(1e-4, checks.len() as u32);
        for (up, rotation) in checks {
            let m = random_map(12, 6, up, rotation);
            let bins = SphereBins { nt: 20, np: 40 };
            // Enough sub-cells that the texels' edges crossing a bin do not bias it.
            let expected = bins.probabilities(48, |d| m.pdf(d));
            let n = 400_000;
            let mut counts = vec![0u64; bins.len()];
            let mut rng = Rng::from_keys(9, &[up as u64]);
            for _ in 0..n {
                let (d, _, _) = m.sample(rng.uniform2()).unwrap();
                counts[bins.index(d)] += 1;
            }
            let expected: Vec<f64> = expected.iter().map(|p| p * n as f64).collect();
            let r = test.check(&counts, &expected).unwrap();
            assert!(r.passes(), "up {up:?}: {r}");
        }
    }

    /// The irradiance of a half sky (radiance L above the horizon, 0 below; the horizon on a
    /// texel edge) on a plane whose normal is at β from up, estimated with the map's sampler
    /// and density as next-event estimation does: π L (1 + cos β)/2 within 4 SE + 0.05 % (the
    /// bilinear blur of the horizon takes δ²/6 ≈ 0.04 % from β = 0, δ = half a texel row).
    #[test]
    fn half_sky_irradiance_by_sampling() {
        let l = 2.0f32;
        let texels = (0..64 * 32)
            .map(|k| if k / 64 < 16 { [l; 3] } else { [0.0; 3] })
            .collect();
        let t = Texture::from_texels("half.exr", 64, 32, texels).unwrap();
        let m = EnvironmentMap::new(Arc::new(t), Rgb::ONE, Axis::Z, 0.0).unwrap();
        let mut rng = Rng::from_keys(1, &[]);
        for beta in [0.0f64, 60.0, 120.0] {
            let b = beta.to_radians();
            let n = DVec3::new(0.0, b.sin(), b.cos());
            let k = 1_000_000;
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..k {
                let v = match m.sample(rng.uniform2()) {
                    Some((w, p, radiance)) => radiance[0] * w.dot(n).max(0.0) / p,
                    None => 0.0,
                };
                s += v;
                s2 += v * v;
            }
            let mean = s / k as f64;
            let se = ((s2 / k as f64 - mean * mean) / k as f64).sqrt();
            let want = PI * f64::from(l) * (1.0 + b.cos()) / 2.0;
            assert!(
                (mean - want).abs() < 4.0 * se + 5e-4 * want,
                "β {beta}: {mean} ± {se} against {want}"
            );
        }
    }

    /// A constant map: radiance equal to the texel everywhere, mean equal to it, density close
    /// to uniform (exactly uniform in θ's cosine would be 1/4π; rows differ by sin θ's
    /// variation inside them).
    #[test]
    fn constant_map() {
        let t = Texture::from_texels("c.exr", 8, 4, vec![[0.5, 1.0, 2.0]; 32]).unwrap();
        let m = EnvironmentMap::new(Arc::new(t), Rgb::splat(2.0), Axis::Z, 0.0).unwrap();
        let mut rng = Rng::from_keys(1, &[]);
        for _ in 0..100 {
            let d = crate::light::uniform_sphere(rng.uniform2());
            assert!(
                (m.radiance(d) - Rgb::new(1.0, 2.0, 4.0))
                    .max_component()
                    .abs()
                    < 1e-12
            );
        }
        assert!(
            (m.mean_radiance() - Rgb::new(1.0, 2.0, 4.0))
                .max_component()
                .abs()
                < 1e-12
        );
        assert!(
            EnvironmentMap::new(m.texture.clone(), Rgb::new(1.0, -1.0, 0.0), Axis::Z, 0.0).is_err()
        );
        assert!(EnvironmentMap::new(m.texture.clone(), Rgb::ONE, Axis::Z, f64::NAN).is_err());
    }
}
