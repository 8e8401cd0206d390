//! Which objects share volume: the load-time refusal of overlapping translucent objects, and
//! the list of opaque objects inside or crossing a translucent one.
//!
//! The volumetric path tracer tracks at most one medium at a time: a path inside a translucent
//! object meets opaque surfaces (which it shades there, still inside the medium) but not a second
//! medium. Two translucent objects whose volumes overlap (one nested in the other, or crossing
//! each other) would need nested media, so such scenes are refused when they are built.
//! Objects that only touch (a shared face) do not overlap.
//!
//! Two closed meshes A and B share volume when their surfaces cross or when one lies inside
//! the other. The test:
//! * *surfaces cross*: some edge of A passes through a triangle of B strictly between its end
//!   points, or an edge of B through a triangle of A (a transversal intersection curve of two
//!   triangle meshes has its end points on such edge crossings), and a point next to the
//!   crossing lies inside both (so that faces that only touch do not count);
//! * *containment* (surfaces that do not cross): a point just inside A, next to the centroid
//!   of A's largest triangle, lies inside B (ray parity, majority of three directions), or the
//!   same with A and B swapped. Stepping inside A keeps a face shared with B from counting.
//!
//! Open meshes have no inside: for them only the crossing test applies (and the containment
//! test when the *other* mesh is closed, with a point on the open surface).

use glam::DVec3;

use super::{Material, Scene};
use crate::error::SceneError;
use crate::geometry::{Geometry, Ray};

impl Scene {
    /// Errors, naming both objects, when two translucent objects share volume: the path tracer
    /// has no nested media (see the module docs).
    pub fn require_disjoint_media(&self) -> Result<(), SceneError> {
        let media: Vec<u32> = self.translucent_objects().map(|(i, _)| i).collect();
        for (k, &a) in media.iter().enumerate() {
            for &b in &media[k + 1..] {
                if self.share_volume(a, b) {
                    let (oa, ob) = (&self.objects[a as usize], &self.objects[b as usize]);
                    return Err(SceneError::Invalid {
                        file: self.display_name.clone().into(),
                        key: ob.key.clone(),
                        line: ob.line,
                        message: format!(
                            "the translucent objects `{}` ({}) and `{}` ({}) overlap (one inside \
                             the other, or crossing); nested media are not supported: make them \
                             disjoint (touching is fine)",
                            oa.name, oa.key, ob.name, ob.key
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Pairs `(translucent, opaque)` of objects that share volume: an opaque core inside a
    /// translucent object, or an opaque object (a floor, a plinth) the translucent one is sunk
    /// into.
    pub fn opaque_inside_media(&self) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        for (t, _) in self.translucent_objects() {
            for (o, object) in self.objects.iter().enumerate() {
                if !matches!(object.material, Material::Translucent(_))
                    && self.share_volume(t, o as u32)
                {
                    pairs.push((t, o as u32));
                }
            }
        }
        pairs
    }

    fn share_volume(&self, a: u32, b: u32) -> bool {
        let closed = [a, b].map(|i| self.objects[i as usize].report.is_closed());
        volumes_overlap(&self.geometry, a, b, closed)
    }
}

/// Relative distance (of the edge length, or of the triangle size) kept away from end points
/// and surfaces, so that touching objects do not count as overlapping.
const MARGIN: f64 = 1e-4;

/// Directions of the parity rays (fixed, not axis-aligned, not coplanar).
const PARITY_DIRS: [[f64; 3]; 3] = [
    [0.267_261_2, 0.534_522_5, 0.801_783_7],
    [-0.624_695, 0.312_347_5, -0.715_891_1],
    [0.408_248_3, -0.816_496_6, 0.408_248_3],
];

/// True when objects `a` and `b` of `geometry` share volume (see the module docs). `closed`
/// tells which of the two meshes are closed (have an inside).
pub(crate) fn volumes_overlap(geometry: &Geometry, a: u32, b: u32, closed: [bool; 2]) -> bool {
    let (alo, ahi) = geometry.object_bounds(a);
    let (blo, bhi) = geometry.object_bounds(b);
    if alo.cmpgt(bhi).any() || blo.cmpgt(ahi).any() {
        return false;
    }
    if edges_cross(geometry, a, b, closed) || edges_cross(geometry, b, a, [closed[1], closed[0]]) {
        return true;
    }
    (closed[1] && inside(geometry, b, interior_point(geometry, a, closed[0])))
        || (closed[0] && inside(geometry, a, interior_point(geometry, b, closed[1])))
}

/// Some edge of `from`'s mesh passes through a triangle of `to`, from one side of its plane to
/// the other, away from the edge's end points, and (when both meshes are closed) a point next to
/// the crossing, just inside both meshes, confirms it. The confirmation keeps touching objects
/// apart: an edge lying in a shared face, or grazing the border of the other mesh's face, is
/// "crossed" numerically but has no point inside both next to it.
fn edges_cross(geometry: &Geometry, from: u32, to: u32, closed: [bool; 2]) -> bool {
    let mesh = geometry.mesh(from);
    (0..mesh.triangle_count()).any(|i| {
        let v = mesh.triangle_vertices(i);
        let centroid = (v[0] + v[1] + v[2]) / 3.0;
        // Outward for closed meshes (oriented at load).
        let n_from = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
        (0..3).any(|k| {
            let (p, q) = (v[k], v[(k + 1) % 3]);
            let len = (q - p).length();
            if len.is_nan() || len <= 0.0 {
                return false;
            }
            let s = MARGIN * len;
            let ray = Ray::with_range(p, (q - p) / len, s, len - s);
            let mut crosses = false;
            geometry.for_each_object_hit(to, &ray, |h| {
                let (dp, dq) = ((p - h.p).dot(h.ng), (q - h.p).dot(h.ng));
                if crosses || dp * dq >= 0.0 || dp.abs().min(dq.abs()) <= s {
                    return;
                }
                if !(closed[0] && closed[1]) {
                    crosses = true;
                    return;
                }
                // Into `from`'s triangle, off its plane inward, and inside `to`'s face.
                let c =
                    h.p + s * (centroid - h.p).normalize_or_zero() - 2.0 * s * n_from - s * h.ng;
                crosses = inside(geometry, from, c) && inside(geometry, to, c);
            });
            crosses
        })
    })
}

/// A point of `object`: just inside it (against the outward normal of its largest triangle)
/// when it is closed, else that triangle's centroid.
fn interior_point(geometry: &Geometry, object: u32, closed: bool) -> DVec3 {
    let mesh = geometry.mesh(object);
    let area = |i: usize| {
        let [p, q, r] = mesh.triangle_vertices(i);
        (q - p).cross(r - p).length()
    };
    let largest = (0..mesh.triangle_count())
        .max_by(|&i, &j| area(i).total_cmp(&area(j)))
        .unwrap_or(0);
    let [p, q, r] = mesh.triangle_vertices(largest);
    let centroid = (p + q + r) / 3.0;
    if !closed {
        return centroid;
    }
    // Closed meshes are oriented outward at load: step against the winding normal.
    let n = (q - p).cross(r - p).normalize_or_zero();
    let size = (q - p).length().max((r - p).length());
    centroid - n * (MARGIN * size)
}

/// True when `p` is inside the closed mesh `object`: an odd number of crossings along at least
/// two of three fixed directions.
fn inside(geometry: &Geometry, object: u32, p: DVec3) -> bool {
    let odd = PARITY_DIRS
        .iter()
        .filter(|d| {
            let mut n = 0u32;
            let ray = Ray::new(p, DVec3::from_array(**d).normalize());
            geometry.for_each_object_hit(object, &ray, |_| n += 1);
            n % 2 == 1
        })
        .count();
    odd >= 2
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{TriangleMesh, primitives};

    fn boxed(lo: [f64; 3], hi: [f64; 3]) -> TriangleMesh {
        let mut m = primitives::cuboid(DVec3::from_array(lo), DVec3::from_array(hi));
        m.prepare("<test box>").unwrap();
        m
    }

    fn overlap(a: TriangleMesh, b: TriangleMesh) -> bool {
        let g = Geometry::build(vec![a, b]);
        volumes_overlap(&g, 0, 1, [true, true])
    }

    #[test]
    fn nested_crossing_touching_and_apart() {
        let unit = || boxed([0.0; 3], [1.0; 3]);
        // Nested, no surface crossing: containment.
        assert!(overlap(unit(), boxed([0.2; 3], [0.8; 3])));
        assert!(overlap(boxed([0.2; 3], [0.8; 3]), unit()));
        // Nested and flush with one face.
        assert!(overlap(unit(), boxed([0.0, 0.2, 0.2], [0.5, 0.8, 0.8])));
        // Crossing.
        assert!(overlap(unit(), boxed([0.5, 0.5, -0.5], [1.5, 1.5, 0.5])));
        // Curved surfaces crossing.
        let ball = |c: [f64; 3], r: f64| {
            let mut m = primitives::icosphere(DVec3::from_array(c), r, 2);
            m.prepare("<test ball>").unwrap();
            m
        };
        assert!(overlap(ball([0.0; 3], 1.0), ball([1.5, 0.0, 0.0], 1.0)));
        assert!(overlap(unit(), ball([0.5, 0.5, 1.2], 0.5)));
        assert!(!overlap(ball([0.0; 3], 1.0), ball([2.5, 0.0, 0.0], 1.0)));
        // Sharing a face (also a part of one, and on a subdivided face), and apart.
        assert!(!overlap(unit(), boxed([1.0, 0.0, 0.0], [2.0, 1.0, 1.0])));
        assert!(!overlap(unit(), boxed([0.2, 0.3, 1.0], [0.7, 0.6, 1.5])));
        let mut slab = primitives::half_space(0.0, [0.0, 0.0], 200.0, 100.0, 15);
        slab.prepare("<test slab>").unwrap();
        assert!(!overlap(slab, boxed([18.0, -2.0, 0.0], [22.0, 2.0, 4.0])));
        assert!(!overlap(unit(), boxed([3.0; 3], [4.0; 3])));
    }
}
