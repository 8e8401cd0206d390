//! Texture coordinates near a surface point, as an affine map: what a field read through
//! texture coordinates needs for a constant-time average over Sone's ellipse, and for the
//! kernel's in-plane reads (`docs/physics.md#prefiltered-averages`).
//!
//! A renderer's mesh interpolates texture coordinates linearly over each triangle, so over one
//! triangle `uv(x) = uv(x₀) + (∇u·(x − x₀), ∇v·(x − x₀))` exactly, with ∇u, ∇v the gradients of
//! the coordinates in the triangle's plane (pbrt-v4 §6.5.3 computes the same map the other way
//! round, as ∂p/∂u and ∂p/∂v). A surface reports it through
//! [`crate::SurfaceQuery::uv_chart`]. The averaging region of a pair spans many triangles, so
//! the estimators take the chart at the region's centre from the charts at x_i and x_o, and
//! only where the two describe one affine map ([`UvChart::between`]): the same gradients
//! within [`UvChart::TOLERANCE`], and each end's chart predicting the other end's coordinates
//! within that tolerance of the chord's length in texture space (about). Across a seam (an atlas
//! whose islands meet between x_i and x_o) or where the parameterisation stretches, the
//! charts disagree and the region is sampled instead, counted as a prefilter fallback.

use glam::{DVec2, DVec3};

/// The affine map `x ↦ uv + (grad_u·(x − origin), grad_v·(x − origin))` from points of the
/// surface near `origin` to texture coordinates (unitless; `grad_*` in 1/scene unit, lying
/// in the surface's tangent plane, so that the part of `x − origin` along the normal does not
/// count).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UvChart {
    /// Where the chart is taken (scene units).
    pub origin: DVec3,
    /// Texture coordinates at `origin`.
    pub uv: DVec2,
    /// Gradient of u in the tangent plane (1/scene unit).
    pub grad_u: DVec3,
    /// Gradient of v in the tangent plane (1/scene unit).
    pub grad_v: DVec3,
}

impl UvChart {
    /// How far two charts may disagree and still be read as one affine map: 2 % of the
    /// gradients' size, so that the mean chart's gradients are within 1 % of either end's (a
    /// texture-space footprint within 1 % of its size; compare the 2° of [`crate::Flatness`],
    /// under which the flat footprint shifts by up to 0.44 % of the chord).
    pub const TOLERANCE: f64 = 0.02;

    /// The chart of the triangle `(p[k], uv[k])`, k = 0, 1, 2 (texture coordinates linear
    /// over it), taken at `origin` with coordinates `uv_origin`; `None` for a triangle of
    /// zero area or non-finite input.
    ///
    /// With edges e₁ = p₁ − p₀, e₂ = p₂ − p₀ and n = e₁ × e₂, the dual vectors
    /// f₁ = (e₂ × n)/|n|², f₂ = (n × e₁)/|n|² satisfy fᵢ·eⱼ = δᵢⱼ and lie in the plane, so
    /// ∇u = Δu₁ f₁ + Δu₂ f₂ (and ∇v alike) reproduces the coordinates at all three vertices.
    pub fn of_triangle(
        p: [DVec3; 3],
        uv: [DVec2; 3],
        origin: DVec3,
        uv_origin: DVec2,
    ) -> Option<UvChart> {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let n = e1.cross(e2);
        let n2 = n.length_squared();
        if !(n2 > 0.0 && n2.is_finite()) {
            return None;
        }
        let f1 = e2.cross(n) / n2;
        let f2 = n.cross(e1) / n2;
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let chart = UvChart {
            origin,
            uv: uv_origin,
            grad_u: d1.x * f1 + d2.x * f2,
            grad_v: d1.y * f1 + d2.y * f2,
        };
        chart.is_finite().then_some(chart)
    }

    /// The texture coordinates the chart gives at `x`.
    #[inline]
    pub fn uv_at(&self, x: DVec3) -> DVec2 {
        self.uv + self.map_vector(x - self.origin)
    }

    /// The texture-space image of a vector `v` (scene units) of the tangent plane.
    #[inline]
    pub fn map_vector(&self, v: DVec3) -> DVec2 {
        DVec2::new(self.grad_u.dot(v), self.grad_v.dot(v))
    }

    /// The size of the gradients, √(|∇u|² + |∇v|²) (1/scene unit).
    #[inline]
    fn scale(&self) -> f64 {
        (self.grad_u.length_squared() + self.grad_v.length_squared()).sqrt()
    }

    fn is_finite(&self) -> bool {
        self.origin.is_finite()
            && self.uv.is_finite()
            && self.grad_u.is_finite()
            && self.grad_v.is_finite()
    }

    /// The unit normal of the chart's tangent plane, ∇u × ∇v normalised (its sign follows the
    /// map's orientation); `None` for a degenerate chart.
    fn plane_normal(&self) -> Option<DVec3> {
        self.grad_u.cross(self.grad_v).try_normalize()
    }

    /// The chart with its gradients turned by the smallest rotation that takes its tangent
    /// plane's normal `n` to the unit vector `m` (Rodrigues' formula with w = n × m,
    /// c = n·m: v ↦ v + w × v + w × (w × v)/(1 + c); exact, and the identity where n = m).
    fn turned(&self, n: DVec3, m: DVec3) -> UvChart {
        let (w, c) = (n.cross(m), n.dot(m));
        let turn = |v: DVec3| v + w.cross(v) + w.cross(w.cross(v)) / (1.0 + c);
        UvChart {
            grad_u: turn(self.grad_u),
            grad_v: turn(self.grad_v),
            ..*self
        }
    }

    /// The chart at the midpoint of `a.origin` and `b.origin` (the averaging region's centre
    /// for a pair whose charts these are), when `a` and `b` are one affine map within
    /// [`UvChart::TOLERANCE`] (module docs): their gradients differ by at most that fraction
    /// of the larger one's size, and each predicts the other's coordinates within that
    /// fraction of the chord's texture-space length. The midpoint chart has the mean
    /// gradients and the mean coordinates. `None` otherwise: the region is to be sampled.
    ///
    /// On a curved surface the two tangent planes differ: each chart's gradients are first
    /// turned into the mean tangent plane (normal n_a + n_b) by the smallest rotation, so that
    /// a parameterisation that follows the surface (one that does not stretch or twist between
    /// the ends) passes wherever the surface bends, and the mean chart lies in the mean plane.
    /// Symmetric in `a` and `b`, bit for bit.
    pub fn between(a: &UvChart, b: &UvChart) -> Option<UvChart> {
        let tol = Self::TOLERANCE;
        let scale = a.scale().max(b.scale());
        if !(scale > 0.0 && scale.is_finite() && a.is_finite() && b.is_finite()) {
            return None;
        }
        let (na, nb) = (a.plane_normal()?, b.plane_normal()?);
        // Opposite orientations (a mirrored island) are not one map.
        let mean = (na + nb).try_normalize().filter(|_| na.dot(nb) > 0.0)?;
        let (ta, tb) = (a.turned(na, mean), b.turned(nb, mean));
        let grad_diff = ((ta.grad_u - tb.grad_u).length_squared()
            + (ta.grad_v - tb.grad_v).length_squared())
        .sqrt();
        if grad_diff > tol * scale {
            return None;
        }
        // A jump in the coordinates between the two ends (a seam) shows as a prediction error;
        // rounding of the stored coordinates is allowed for on top.
        let chord = b.origin - a.origin;
        let reach =
            tol * scale * chord.length() + 1e-6 * (1.0 + a.uv.abs().max(b.uv.abs())).max_element();
        let off_b = (a.uv_at(b.origin) - b.uv).length();
        let off_a = (b.uv_at(a.origin) - a.uv).length();
        if !(off_a <= reach && off_b <= reach) {
            return None;
        }
        Some(UvChart {
            origin: 0.5 * (a.origin + b.origin),
            uv: 0.5 * (a.uv + b.uv),
            grad_u: 0.5 * (ta.grad_u + tb.grad_u),
            grad_v: 0.5 * (ta.grad_v + tb.grad_v),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// uv = (0.1 x + 0.03 y + 0.5, −0.02 x + 0.2 y + 0.25) on the plane z = 1.
    fn affine(x: DVec3) -> DVec2 {
        DVec2::new(0.1 * x.x + 0.03 * x.y + 0.5, -0.02 * x.x + 0.2 * x.y + 0.25)
    }

    /// The right triangle with legs of 1 along x and y at `offset`, on the plane z = 1.
    fn unit_triangle(offset: DVec3) -> [DVec3; 3] {
        [
            DVec3::Z,
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(0.0, 1.0, 1.0),
        ]
        .map(|p| p + offset)
    }

    fn chart_at(p: [DVec3; 3], origin: DVec3) -> UvChart {
        UvChart::of_triangle(p, p.map(affine), origin, affine(origin)).unwrap()
    }

    /// The charts at `xi`, on the unit triangle at the origin, and at `xo`, on the unit
    /// triangle at `offset`.
    fn end_charts(offset: DVec3, xi: DVec3, xo: DVec3) -> (UvChart, UvChart) {
        (
            chart_at(unit_triangle(DVec3::ZERO), xi),
            chart_at(unit_triangle(offset), xo),
        )
    }

    #[test]
    fn a_triangle_chart_reproduces_the_linear_coordinates() {
        let p = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(3.0, 0.5, 1.0),
            DVec3::new(-1.0, 2.0, 1.0),
        ];
        let c = chart_at(p, DVec3::new(0.5, 0.5, 1.0));
        assert!((c.grad_u - DVec3::new(0.1, 0.03, 0.0)).length() < 1e-14);
        assert!((c.grad_v - DVec3::new(-0.02, 0.2, 0.0)).length() < 1e-14);
        for x in [DVec3::new(7.0, -3.0, 1.0), DVec3::new(-2.0, 11.0, 1.0)] {
            assert!((c.uv_at(x) - affine(x)).length() < 1e-13);
        }
        // Off the plane, along the normal: the same coordinates.
        let x = DVec3::new(2.0, 1.0, 1.0);
        assert_eq!(c.uv_at(x + 3.0 * DVec3::Z), c.uv_at(x));
        // A degenerate triangle has no chart.
        let flat = [p[0], p[1], 2.0 * p[1] - p[0]];
        assert!(UvChart::of_triangle(flat, flat.map(affine), p[0], affine(p[0])).is_none());
    }

    #[test]
    fn two_ends_of_one_map_give_its_midpoint_chart() {
        let (xi, xo) = (DVec3::new(0.2, 0.2, 1.0), DVec3::new(6.3, 2.1, 1.0));
        let (a, b) = end_charts(DVec3::new(6.0, 2.0, 0.0), xi, xo);
        let mid = UvChart::between(&a, &b).unwrap();
        assert!((mid.origin - 0.5 * (xi + xo)).length() < 1e-15);
        let x = DVec3::new(3.0, -4.0, 1.0);
        assert!((mid.uv_at(x) - affine(x)).length() < 1e-13);
    }

    #[test]
    fn a_seam_or_a_stretch_between_the_ends_is_refused() {
        let (xi, xo) = (DVec3::new(0.2, 0.2, 1.0), DVec3::new(4.2, 0.3, 1.0));
        let (a, b) = end_charts(DVec3::new(4.0, 0.0, 0.0), xi, xo);
        let shifted = |du: f64| UvChart {
            uv: b.uv + DVec2::new(du, 0.0),
            ..b
        };
        // A seam: the second island is the same map shifted by 0.3 in u.
        assert!(UvChart::between(&a, &shifted(0.3)).is_none());
        // A small shift, within 2 % of the chord's texture length (0.4): accepted.
        assert!(UvChart::between(&a, &shifted(0.004)).is_some());
        // A stretch: the second triangle's u grows 5 % faster.
        let stretched = UvChart {
            grad_u: 1.05 * a.grad_u,
            ..b
        };
        assert!(UvChart::between(&a, &stretched).is_none());
        // Symmetric, and bit for bit the same midpoint either way.
        assert_eq!(UvChart::between(&a, &b), UvChart::between(&b, &a));
    }
}
