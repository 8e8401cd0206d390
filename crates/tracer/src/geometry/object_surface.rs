//! [`ObjectSurface`]: the estimators' [`het_estimate::SurfaceQuery`] on one object.

use glam::DVec3;

use het_estimate::Projected;

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
        match self.geometry.project_onto_box(self.object, origin, dir) {
            Projected::At(hit) => Some(hit),
            Projected::Miss => None,
            Projected::Undecided => self.project_by_rays(origin, dir),
        }
    }

    /// `project`, searching both rays within `reach` first (short rays visit
    /// few BVH nodes) and beyond it only where neither hits there: the same hit.
    #[inline]
    fn project_within(&self, origin: DVec3, dir: DVec3, reach: f64) -> Option<Hit> {
        match self.geometry.project_onto_box(self.object, origin, dir) {
            Projected::At(hit) => Some(hit),
            Projected::Miss => None,
            Projected::Undecided if reach.is_finite() && reach > 0.0 => {
                self.project_by_rays_within(origin, dir, reach)
            }
            Projected::Undecided => self.project_by_rays(origin, dir),
        }
    }

    /// On an object that is its own axis-aligned box, the crossing from the box's planes,
    /// without a ray ([`Geometry::project_position_onto_box`]); `Undecided` on other meshes.
    #[inline]
    fn project_position(&self, origin: DVec3, dir: DVec3) -> Projected {
        self.geometry
            .project_position_onto_box(self.object, origin, dir)
    }

    /// [`Geometry::project_positions_onto_box`]: the box's planes and the direction's
    /// reciprocal once for all the origins.
    fn project_positions(&self, origins: &[DVec3], dir: DVec3, out: &mut [Projected]) {
        self.geometry
            .project_positions_onto_box(self.object, origins, dir, out)
    }

    /// The chart of the hit's triangle ([`Geometry::uv_chart`]).
    fn uv_chart(&self, p: &Hit) -> Option<het_estimate::UvChart> {
        self.geometry.uv_chart(p)
    }

    /// The mesh's curvature at the hit ([`Geometry::curvature`]).
    fn curvature(&self, p: &Hit) -> Option<het_estimate::Curvature> {
        self.geometry.curvature(p)
    }
}

impl ObjectSurface<'_> {
    /// [`ObjectSurface::project_by_rays`], looking within `reach` first: a ray each way over
    /// `[0, reach]` (the second no further than the first's hit); where neither hits, the
    /// rest of both lines, `[reach, ∞)`. The nearer hit overall, as `project_by_rays` finds
    /// it (a hit within `reach` on one side is nearer than any beyond it on either).
    fn project_by_rays_within(&self, origin: DVec3, dir: DVec3, reach: f64) -> Option<Hit> {
        let g = self.geometry;
        let fwd = g.intersect_object(self.object, &Ray::segment(origin, dir, reach));
        let t_max = fwd.map_or(reach, |h| h.t);
        let back = g.intersect_object(self.object, &Ray::segment(origin, -dir, t_max));
        match (fwd, back) {
            (Some(f), Some(b)) => return Some(if b.t < f.t { b } else { f }),
            (Some(h), None) | (None, Some(h)) => return Some(h),
            (None, None) => {}
        }
        // The rest, overlapping the first search a little (the f32 traversal rounds its
        // bounds): a hit there was not found within `reach`, so it is beyond it.
        let from = 0.999 * reach;
        let fwd = g.intersect_object(
            self.object,
            &Ray::with_range(origin, dir, from, f64::INFINITY),
        );
        let t_max = fwd.map_or(f64::INFINITY, |h| h.t);
        let back = g.intersect_object(self.object, &Ray::with_range(origin, -dir, from, t_max));
        match (fwd, back) {
            (Some(f), Some(b)) => Some(if b.t < f.t { b } else { f }),
            (f, b) => f.or(b),
        }
    }

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
    /// for lines from inside, outside and near the surface, in every direction; and so does
    /// the position from the planes alone, a hair inside the face.
    #[test]
    fn box_projection_equals_the_two_rays() {
        let (lo, hi) = (DVec3::new(-3.0, 1.0, -2.0), DVec3::new(4.0, 2.5, 0.0));
        let g = Geometry::build(vec![primitives::subdivided_cuboid(lo, hi, [4, 2, 3])]);
        let s = ObjectSurface::new(&g, 0);
        let (mut fast, mut hits, mut positions) = (0, 0, 0);
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
            // The position from the planes: the ray's hit to f32 precision, a hair inside the
            // face the ray crossed; a miss where the rays miss.
            match (g.project_position_onto_box(0, origin, dir), want) {
                (Projected::At(p), Some(b)) => {
                    positions += 1;
                    assert!(
                        (p - b.p).length() <= 1e-5,
                        "line {k}: {p:?} against {:?}",
                        b.p
                    );
                    let n = b.ng;
                    let a = n.abs().max_position();
                    let face = if n[a] > 0.0 { hi[a] } else { lo[a] };
                    let inside = (face - p[a]) * n[a];
                    assert!(inside > 0.0 && inside < 1e-7, "line {k}: {inside}");
                    assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "line {k}: {p:?}");
                }
                (Projected::Miss, None) | (Projected::Undecided, _) => {}
                (got, want) => panic!("line {k}: {got:?} against {want:?}"),
            }
            fast += usize::from(g.project_onto_box(0, origin, dir) != Projected::Undecided);
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
        assert!(positions > hits * 9 / 10, "{positions} of {hits}");
        // Not a box: no shortcut.
        let sphere = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, 1.0, 2)]);
        assert_eq!(
            sphere.project_onto_box(0, DVec3::ZERO, DVec3::Z),
            Projected::Undecided
        );
    }

    /// Looking within a reach first finds `project`'s hit, for every reach, on lines from
    /// inside, outside and near a sphere.
    #[test]
    fn projection_within_a_reach_is_the_projection() {
        let g = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, 10.0, 4)]);
        let s = ObjectSurface::new(&g, 0);
        let (mut hits, mut near) = (0, 0);
        for k in 0..3000 {
            let t = k as f64;
            let u = DVec3::new((0.37 * t).sin(), (0.71 * t).cos(), (1.13 * t).sin());
            let origin = 12.0 * u;
            let dir =
                DVec3::new((2.3 * t).sin(), (1.7 * t).cos(), (0.9 * t).cos() + 0.2).normalize();
            let want = s.project(origin, dir);
            for reach in [1e-3, 0.5, 3.0, 30.0] {
                let got = s.project_within(origin, dir, reach);
                assert_eq!(
                    got.map(|h| (h.p, h.prim)),
                    want.map(|h| (h.p, h.prim)),
                    "{k} {reach}"
                );
                near += usize::from(got.is_some_and(|h| h.t <= reach));
            }
            hits += usize::from(want.is_some());
        }
        assert!(
            hits > 1000 && near > 1000,
            "{hits} hits, {near} within reach"
        );
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

    /// The sampled averages on a box (Sone's and the kernel's, both projecting every point) are
    /// the same whether each point is projected by a ray or placed by the box's planes (a
    /// field defined in space, its cell boundaries off the faces): the same points, so the
    /// same values, to the bit, for pairs on one face and across edges. Placing the points on
    /// the farther crossing, or off the surface by a texture cell, would change them.
    #[test]
    fn sampled_averages_on_a_box_read_the_same_values_without_rays() {
        use crate::field::{Axis, Field, MediumField, PlanarProjection};
        use het_estimate::{Averaging, Estimator, KernelParams, SoneParams};

        /// The same surface with only `project`: every point by rays.
        struct ByRays<'a>(ObjectSurface<'a>);
        impl SurfaceQuery for ByRays<'_> {
            type Point = Hit;
            fn project(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
                self.0.project(origin, dir)
            }
        }

        let (lo, hi) = (DVec3::new(-10.0, -10.0, -10.0), DVec3::new(10.0, 10.0, 0.0));
        let g = Geometry::build(vec![primitives::cuboid(lo, hi)]);
        let planes = ObjectSurface::new(&g, 0);
        let rays = ByRays(planes);
        let check = Field::check(
            4.0,
            [bssrdf_core::Rgb::splat(0.005), bssrdf_core::Rgb::splat(0.1)],
            PlanarProjection::new(Axis::Z, DVec3::new(0.37, -0.61, 0.0)),
        )
        .unwrap();
        let field = MediumField::new(check, Field::constant(bssrdf_core::Rgb::ONE).unwrap());
        for estimator in [
            Estimator::Sone(SoneParams::paper().with_averaging(Averaging::MonteCarlo)),
            Estimator::Kernel(KernelParams::new().with_averaging(Averaging::MonteCarlo)),
        ] {
            let prepared = estimator.prepare(0.0, 1.0).unwrap();
            same_values_without_rays(&g, &planes, &rays, &field, &prepared);
        }
    }

    /// The comparison of [`sampled_averages_on_a_box_read_the_same_values_without_rays`] for
    /// one estimator on the box `g` ([-10, 10]² × [-10, 0]).
    fn same_values_without_rays(
        g: &Geometry,
        planes: &ObjectSurface<'_>,
        rays: &impl SurfaceQuery<Point = Hit>,
        field: &crate::field::MediumField,
        estimator: &het_estimate::PreparedEstimator,
    ) {
        use crate::rng::Rng;
        let mut rng = Rng::from_keys(5, &[]);
        // Points on the top face and on the +x side, up to 8 apart.
        let on_box = |rng: &mut Rng| {
            let (u, v) = (rng.uniform(), rng.uniform());
            let (origin, dir) = if rng.uniform() < 0.5 {
                (DVec3::new(6.0 + 4.0 * u, -4.0 + 8.0 * v, 5.0), DVec3::NEG_Z)
            } else {
                (DVec3::new(15.0, -4.0 + 8.0 * v, -8.0 * u), DVec3::NEG_X)
            };
            g.intersect(&Ray::new(origin, dir)).unwrap()
        };
        let (mut across, mut lookups, mut planes_rays) = (0, 0, 0);
        for k in 0..300 {
            let (x_i, x_o) = (on_box(&mut rng), on_box(&mut rng));
            across += usize::from(x_i.ns != x_o.ns);
            let (mut r1, mut r2) = (Rng::from_keys(k, &[]), Rng::from_keys(k, &[]));
            let before = g.rays_traced();
            let a = estimator.estimate(planes, field, &x_i, &x_o, &mut r1);
            planes_rays += g.rays_traced() - before;
            let b = estimator.estimate(rays, field, &x_i, &x_o, &mut r2);
            assert_eq!(a.coefficients, b.coefficients, "pair {k}");
            let (da, db) = (a.diagnostics, b.diagnostics);
            assert_eq!(
                (da.projections, da.misses, da.lookups),
                (db.projections, db.misses, db.lookups),
                "pair {k}"
            );
            lookups += da.lookups;
        }
        assert!(
            across > 100 && lookups > 10_000,
            "{across} pairs across, {lookups} lookups, {estimator:?}"
        );
        // The planes settle nearly every point: a ray only where a line grazes an edge.
        assert!(
            planes_rays * 1000 < lookups as u64,
            "{planes_rays} rays, {lookups} lookups, {:?}",
            g.object_box_extent(0)
        );
    }
}
