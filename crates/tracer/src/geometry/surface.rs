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
    /// rays; one on an object that is its own axis-aligned box
    /// ([`Geometry::project_onto_box`]), which finds the same hit.
    #[inline]
    fn project(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        // A box: one ray where its planes say the nearer crossing is.
        if let Some(hit) = self.geometry.project_onto_box(self.object, origin, dir) {
            return hit;
        }
        self.project_by_rays(origin, dir)
    }
}

impl ObjectSurface<'_> {
    /// [`het_estimate::SurfaceQuery::project`] by a ray each way, on any mesh.
    fn project_by_rays(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
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

    /// On boxes the one-ray projection finds what the two rays find: the same hit or none,
    /// for lines from inside, outside and near the surface, in every direction.
    #[test]
    fn box_projection_equals_the_two_rays() {
        let (lo, hi) = (DVec3::new(-3.0, 1.0, -2.0), DVec3::new(4.0, 2.5, 0.0));
        let g = Geometry::build(vec![primitives::subdivided_cuboid(lo, hi, [4, 2, 3])]);
        let s = ObjectSurface::new(&g, 0);
        let (mut fast, mut hits) = (0, 0);
        for k in 0..4000 {
            let t = k as f64;
            let u = DVec3::new((0.37 * t).sin(), (0.71 * t).cos(), (1.13 * t).sin());
            // Origins from well inside to well outside, some on a face.
            let origin = 0.5 * (lo + hi) + (hi - lo) * 0.9 * u;
            let origin = if k % 7 == 0 {
                DVec3::new(origin.x, origin.y, hi.z)
            } else {
                origin
            };
            let dir = DVec3::new((2.3 * t).sin(), (1.7 * t).cos(), (0.9 * t).cos() + 0.2);
            let dir = if k % 11 == 0 {
                DVec3::Z
            } else {
                dir.normalize()
            };
            let want = s.project_by_rays(origin, dir);
            let got = s.project(origin, dir);
            fast += usize::from(g.project_onto_box(0, origin, dir).is_some());
            match (got, want) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert!(
                        (a.p - b.p).length() <= 1e-12 * (1.0 + b.p.length()) && a.ns == b.ns,
                        "line {k}: {:?} against {:?}",
                        a.p,
                        b.p
                    );
                }
                (None, None) => {}
                (a, b) => panic!("line {k}: {a:?} against {b:?}"),
            }
        }
        assert!(hits > 800 && fast > 3500, "{hits} hits, {fast} by the box");
        // Not a box: no shortcut.
        let sphere = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, 1.0, 2)]);
        assert!(sphere.project_onto_box(0, DVec3::ZERO, DVec3::Z).is_none());
    }

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
