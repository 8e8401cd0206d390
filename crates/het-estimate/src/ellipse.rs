//! The averaging region of the paper's §3: an ellipse (or disk) lying in a plane in space,
//! whose points are projected onto the surface along the plane's normal.

use glam::{DVec2, DVec3};

/// An ellipse in a plane of scene space: `centre + s·semi_major + t·semi_minor` for
/// `s² + t² ≤ 1`.
///
/// Invariants kept by the estimators that build it: `semi_major`, `semi_minor` and `normal`
/// are mutually orthogonal, `normal` is a unit vector, `|semi_minor| ≤ |semi_major|` is *not*
/// required (Eq. (2) can give w > d for σa = 0 and long chords), and either semi-axis may have
/// length zero (a degenerate ellipse: a segment or a point).
///
/// For the Sone estimator (paper §3.1): `centre` is the chord midpoint m = (x_i + x_o)/2,
/// `semi_major` = (d/2)·x̂ along the chord, `semi_minor` = b·(n_i* × x̂), `normal` = n_i*
/// (FHK14's modified normal). The step-1 disk is the same type with b = d/2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarEllipse {
    /// Centre of the ellipse (scene units).
    pub centre: DVec3,
    /// Semi-major axis vector (its length is the semi-axis length a).
    pub semi_major: DVec3,
    /// Semi-minor axis vector (its length is the semi-axis length b), orthogonal to
    /// `semi_major`.
    pub semi_minor: DVec3,
    /// Unit normal of the ellipse's plane: the direction of the two projection rays.
    pub normal: DVec3,
}

impl PlanarEllipse {
    /// The point of the ellipse that corresponds to `unit` in the unit disk (the linear map
    /// that scales the disk's axes to the ellipse's semi-axes; it preserves uniformity, since
    /// its Jacobian `a·b` is constant).
    #[inline]
    pub fn point(&self, unit: DVec2) -> DVec3 {
        self.centre + unit.x * self.semi_major + unit.y * self.semi_minor
    }

    /// Area π·a·b (scene units²).
    pub fn area(&self) -> f64 {
        std::f64::consts::PI * self.semi_major.length() * self.semi_minor.length()
    }
}
