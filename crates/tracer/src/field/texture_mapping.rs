//! Planar projection: the map from a 3-D point to the 2-D coordinates `(s, t)` of a pattern or
//! a planar-mapped image. The field is then constant along the projection axis (the paper's
//! assumption that coefficients vary only along tangent directions, §3.1). Also how an image
//! repeats beyond its edges ([`Wrap`]).

use glam::{DVec2, DVec3};
use het_estimate::prefilter::PlaneFootprint;

/// How lookups outside `[0, 1]²` behave.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Wrap {
    /// Tile the image.
    #[default]
    Repeat,
    /// Extend the edge texels.
    Clamp,
}

/// A coordinate axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z (default: the paper's experiments lie on the plane z = 0).
    #[default]
    Z,
}

impl Axis {
    /// The unit vector along the axis.
    pub const fn unit(self) -> DVec3 {
        match self {
            Axis::X => DVec3::X,
            Axis::Y => DVec3::Y,
            Axis::Z => DVec3::Z,
        }
    }

    /// `"x"`, `"y"` or `"z"`, as scene files spell it.
    pub const fn name(self) -> &'static str {
        match self {
            Axis::X => "x",
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }

    /// `"x"`, `"y"` or `"z"`.
    pub fn parse(s: &str) -> Option<Axis> {
        match s {
            "x" | "X" => Some(Axis::X),
            "y" | "Y" => Some(Axis::Y),
            "z" | "Z" => Some(Axis::Z),
            _ => None,
        }
    }
}

/// Projection along `axis` with `origin` mapped to `(s, t) = (0, 0)`.
///
/// Mapping of the other two coordinates (cyclic, so that `ŝ × t̂ = axis`):
/// * axis z: `(s, t) = (x − o_x, y − o_y)`;
/// * axis x: `(s, t) = (y − o_y, z − o_z)`;
/// * axis y: `(s, t) = (z − o_z, x − o_x)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanarProjection {
    /// The axis the field is constant along.
    pub axis: Axis,
    /// The point mapped to `(0, 0)` (only its two in-plane coordinates matter).
    pub origin: DVec3,
}

impl PlanarProjection {
    /// Projection along `axis` about `origin`.
    pub const fn new(axis: Axis, origin: DVec3) -> Self {
        Self { axis, origin }
    }

    /// `(s, t)` of `p`.
    #[inline]
    pub fn st(&self, p: DVec3) -> (f64, f64) {
        self.st_vector(p - self.origin)
    }

    /// The linear part of [`PlanarProjection::st`]: `(s, t)` components of a displacement.
    #[inline]
    pub fn st_vector(&self, d: DVec3) -> (f64, f64) {
        match self.axis {
            Axis::Z => (d.x, d.y),
            Axis::X => (d.y, d.z),
            Axis::Y => (d.z, d.x),
        }
    }

    /// The vector of the pattern's plane with components `(s, t)`: the inverse of
    /// [`PlanarProjection::st_vector`] on that plane.
    #[inline]
    pub fn plane_vector(&self, s: f64, t: f64) -> DVec3 {
        match self.axis {
            Axis::Z => DVec3::new(s, t, 0.0),
            Axis::X => DVec3::new(0.0, s, t),
            Axis::Y => DVec3::new(t, 0.0, s),
        }
    }

    /// The footprint of the ellipse `e` in the `(s, t)` plane (the field is constant along
    /// the axis, so the ellipse's points are read at their `(s, t)`): uniformly weighted.
    pub fn footprint(&self, e: &het_estimate::PlanarEllipse) -> PlaneFootprint {
        let mut fp = PlaneFootprint::of_ellipse(e, |v| {
            let (s, t) = self.st_vector(v);
            DVec2::new(s, t)
        });
        let (s, t) = self.st(e.centre);
        fp.centre = DVec2::new(s, t);
        fp
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_is_cyclic_and_right_handed() {
        let o = DVec3::new(1.0, 2.0, 3.0);
        let p = DVec3::new(5.0, 7.0, 11.0);
        assert_eq!(PlanarProjection::new(Axis::Z, o).st(p), (4.0, 5.0));
        assert_eq!(PlanarProjection::new(Axis::X, o).st(p), (5.0, 8.0));
        assert_eq!(PlanarProjection::new(Axis::Y, o).st(p), (8.0, 4.0));
        // ŝ × t̂ = axis for each choice.
        assert_eq!(DVec3::X.cross(DVec3::Y), DVec3::Z);
        assert_eq!(DVec3::Y.cross(DVec3::Z), DVec3::X);
        assert_eq!(DVec3::Z.cross(DVec3::X), DVec3::Y);
    }
}
