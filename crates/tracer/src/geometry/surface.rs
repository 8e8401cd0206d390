//! [`ObjectSurface`]: the estimators' [`het_estimate::SurfaceQuery`] on one object.

use glam::DVec3;

use super::{Geometry, Hit, Ray};

/// The surface of one object of a [`Geometry`], as the estimators see it.
#[derive(Debug, Clone, Copy)]
pub struct ObjectSurface<'a> {
    /// The geometry.
    pub geometry: &'a Geometry,
    /// The object being shaded.
    pub object: u32,
}

impl<'a> ObjectSurface<'a> {
    /// The surface of `object`.
    pub fn new(geometry: &'a Geometry, object: u32) -> Self {
        Self { geometry, object }
    }
}

impl het_estimate::SurfaceQuery for ObjectSurface<'_> {
    type Point = Hit;

    /// Traces the full lines `origin + t·dir` and `origin − t·dir`, `t ≥ 0`, against this
    /// object only, and returns the hit nearer to `origin` (paper §3.2, Figure 3). Counts two
    /// rays.
    #[inline]
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let fwd = self
            .geometry
            .intersect_object(self.object, &Ray::new(origin, dir));
        let t_max = fwd.map_or(f64::INFINITY, |h| h.t);
        let back = self
            .geometry
            .intersect_object(self.object, &Ray::segment(origin, -dir, t_max));
        match (fwd, back) {
            (Some(f), Some(b)) => Some(if b.t < f.t { b } else { f }),
            (f, b) => f.or(b),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives;
    use het_estimate::{SurfacePoint, SurfaceQuery};

    #[test]
    fn projects_onto_the_nearer_side() {
        let g = Geometry::build(vec![
            primitives::cuboid(DVec3::new(-5.0, -5.0, -1.0), DVec3::new(5.0, 5.0, 0.0)),
            primitives::cuboid(DVec3::new(-5.0, -5.0, 3.0), DVec3::new(5.0, 5.0, 4.0)),
        ]);
        let s = ObjectSurface::new(&g, 0);
        // Above the slab: the top face (z = 0) is nearer than the bottom (z = -1).
        let h = s.project(DVec3::new(1.0, 2.0, 0.3), DVec3::Z).unwrap();
        assert!((h.position().z - 0.0).abs() < 1e-12 && h.object == 0);
        assert!(h.normal().abs_diff_eq(DVec3::Z, 1e-12));
        // Inside the slab near the bottom.
        let h = s.project(DVec3::new(1.0, 2.0, -0.8), DVec3::Z).unwrap();
        assert!((h.position().z + 1.0).abs() < 1e-12);
        // Outside the slab's footprint: no hit.
        assert!(s.project(DVec3::new(7.0, 0.0, 0.0), DVec3::Z).is_none());
    }
}
