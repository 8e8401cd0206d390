//! Indexed triangle meshes: validation, topology report (closedness, orientation), outward
//! orientation and transforms.

use glam::{DAffine3, DMat3, DQuat, DVec3, Vec2, Vec3};

use crate::error::MeshError;

/// An indexed triangle mesh in scene units.
///
/// Attributes are per vertex: `normals` and `uvs`, when present, have one entry per position.
/// Texture coordinates use the OBJ convention (`v` up: `(0, 0)` is the bottom-left corner of an
/// image); the glTF loader converts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions (`f64`, so that a mesh far from the origin keeps its shape: in `f32`
    /// a unit sphere at 1e6 rounds to steps of 0.06).
    pub positions: Vec<DVec3>,
    /// Per-vertex shading normals (need not be unit; normalised after interpolation).
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles as vertex-index triples; the winding (counter-clockwise seen from outside)
    /// defines the geometric normal `(v1 − v0) × (v2 − v0)`.
    pub triangles: Vec<[u32; 3]>,
}

/// Topology of a mesh: whether it is closed and consistently oriented.
///
/// Edges are found on vertices welded by exact position, so seams where a loader duplicated a
/// vertex for a different normal or texture coordinate do not count as open edges.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct MeshReport {
    /// Number of triangles.
    pub triangles: usize,
    /// Number of distinct vertex positions.
    pub vertices: usize,
    /// Edges used by exactly one triangle (holes).
    pub boundary_edges: usize,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: usize,
    /// Edges shared by two triangles that traverse it in the same direction (one of the two is
    /// inside out relative to the other).
    pub inconsistent_edges: usize,
    /// Signed volume `Σ v0·(v1×v2)/6` after orientation (positive for an outward-oriented closed
    /// mesh; meaningless for an open one).
    pub signed_volume: f64,
    /// True when the orientation step flipped every triangle (the input was inside out).
    pub flipped: bool,
}

impl MeshReport {
    /// Closed, manifold and consistently oriented: a well-defined inside.
    pub fn is_closed(&self) -> bool {
        self.triangles > 0
            && self.boundary_edges == 0
            && self.non_manifold_edges == 0
            && self.inconsistent_edges == 0
    }

    /// One line for logs: "closed, 27864 triangles" or "open: 4 boundary edges, …".
    pub fn summary(&self) -> String {
        if self.is_closed() {
            format!(
                "closed, {} triangles{}",
                self.triangles,
                if self.flipped {
                    " (was inside out: flipped)"
                } else {
                    ""
                }
            )
        } else {
            format!(
                "not closed: {} boundary edges, {} non-manifold edges, {} inconsistently oriented edges ({} triangles)",
                self.boundary_edges,
                self.non_manifold_edges,
                self.inconsistent_edges,
                self.triangles
            )
        }
    }
}

/// A similarity-style transform applied to meshes as `p' = translate + R·(scale ⊙ p)`: scale
/// first (uniform or per axis; negative values mirror, and the winding is then reversed so that
/// normals stay consistent), then rotate, then translate. Normals are transformed by the
/// inverse transpose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    /// Per-axis scale (must be non-zero).
    pub scale: DVec3,
    /// Rotation.
    pub rotation: DQuat,
    /// Translation (scene units).
    pub translation: DVec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// No change.
    pub const IDENTITY: Transform = Transform {
        scale: DVec3::ONE,
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// Rotation by `degrees` about `axis` (right-handed: counter-clockwise looking down the
    /// axis toward the origin). `axis` need not be unit; it must be non-zero.
    pub fn rotation_axis_angle(axis: DVec3, degrees: f64) -> DQuat {
        DQuat::from_axis_angle(axis.normalize(), degrees.to_radians())
    }

    /// The affine matrix of this transform.
    pub fn to_affine(&self) -> DAffine3 {
        DAffine3::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

impl TriangleMesh {
    /// A mesh without normals or texture coordinates.
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            positions,
            normals: None,
            uvs: None,
            triangles,
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three vertices of triangle `i` in `f64`.
    #[inline]
    pub fn triangle_vertices(&self, i: usize) -> [DVec3; 3] {
        let t = self.triangles[i];
        t.map(|k| self.positions[k as usize])
    }

    /// Axis-aligned bounds of the referenced vertices, `(min, max)`; `(0, 0)` when empty.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for t in &self.triangles {
            for &k in t {
                let p = self.positions[k as usize];
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        if lo.x > hi.x {
            (DVec3::ZERO, DVec3::ZERO)
        } else {
            (lo, hi)
        }
    }

    /// The extents `max − min` of the bounds when the mesh is exactly its own axis-aligned
    /// bounding box (the `box` and `half_space` primitives, or a file holding one), else
    /// `None`. A box: every extent positive; every triangle lies in one face plane of the
    /// bounds with its geometric normal facing out; shading normals, where there are any,
    /// are that face's normal; and each face's triangles cover its area (to 1e-9 relative).
    /// On such a mesh the distance from any surface point along the inward normal to the far
    /// side is the extent along that normal's axis, which lets a renderer measure thickness
    /// without tracing a ray.
    pub fn box_extent(&self) -> Option<DVec3> {
        let (lo, hi) = self.bounds();
        let extent = hi - lo;
        if self.triangles.is_empty() || !extent.is_finite() || extent.min_element() <= 0.0 {
            return None;
        }
        let mut face_area = [0.0f64; 6];
        for (i, t) in self.triangles.iter().enumerate() {
            let v = self.triangle_vertices(i);
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            let face = (0..3).find_map(|a| {
                let side = if v.iter().all(|p| p[a] == lo[a]) {
                    -1.0
                } else if v.iter().all(|p| p[a] == hi[a]) {
                    1.0
                } else {
                    return None;
                };
                (n[a] * side > 0.0).then_some((a, side))
            })?;
            let (axis, side) = face;
            if let Some(normals) = &self.normals {
                let facing = t.iter().all(|&k| {
                    let m = normals[k as usize].as_dvec3();
                    let len = m.length();
                    len > 0.0 && m[axis] * side >= len * (1.0 - 1e-6)
                });
                if !facing {
                    return None;
                }
            }
            face_area[2 * axis + usize::from(side > 0.0)] += 0.5 * n.length();
        }
        (0..6)
            .all(|f| {
                let a = f / 2;
                let want = extent[(a + 1) % 3] * extent[(a + 2) % 3];
                (face_area[f] - want).abs() <= 1e-9 * want
            })
            .then_some(extent)
    }

    /// Total area (scene units²).
    pub fn surface_area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, c] = self.triangle_vertices(i);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Signed volume `Σ (v0−c)·((v1−c)×(v2−c))/6` about the bounding-box centre `c` (for
    /// precision). Positive when a closed mesh is oriented outward.
    pub fn signed_volume(&self) -> f64 {
        let (lo, hi) = self.bounds();
        let c = 0.5 * (lo + hi);
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, d] = self.triangle_vertices(i);
                (a - c).dot((b - c).cross(d - c))
            })
            .sum::<f64>()
            / 6.0
    }

    /// Checks that the mesh is usable: non-empty, indices in range, finite attributes of the
    /// right length, no zero-area triangle. `file` names the mesh in errors.
    pub fn validate(&self, file: &str) -> Result<(), MeshError> {
        let file_s = || file.to_string();
        if self.triangles.is_empty() || self.positions.is_empty() {
            return Err(MeshError::Empty { file: file_s() });
        }
        let n = self.positions.len();
        for (i, p) in self.positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(MeshError::NonFinite {
                    file: file_s(),
                    attribute: "position",
                    vertex: i,
                    value: p.as_vec3().to_array(),
                });
            }
        }
        if let Some(normals) = &self.normals {
            if normals.len() != n {
                return Err(MeshError::AttributeCount {
                    file: file_s(),
                    attribute: "normals",
                    expected: n,
                    found: normals.len(),
                });
            }
            if let Some((i, v)) = normals.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(MeshError::NonFinite {
                    file: file_s(),
                    attribute: "normal",
                    vertex: i,
                    value: v.to_array(),
                });
            }
        }
        if let Some(uvs) = &self.uvs {
            if uvs.len() != n {
                return Err(MeshError::AttributeCount {
                    file: file_s(),
                    attribute: "texture coordinates",
                    expected: n,
                    found: uvs.len(),
                });
            }
            if let Some((i, v)) = uvs.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(MeshError::NonFinite {
                    file: file_s(),
                    attribute: "texture coordinate",
                    vertex: i,
                    value: [v.x, v.y, 0.0],
                });
            }
        }
        for (i, t) in self.triangles.iter().enumerate() {
            if let Some(&k) = t.iter().find(|&&k| k as usize >= n) {
                return Err(MeshError::IndexOutOfRange {
                    file: file_s(),
                    triangle: i,
                    index: k,
                    vertices: n,
                });
            }
            let [a, b, c] = self.triangle_vertices(i);
            if (b - a).cross(c - a) == DVec3::ZERO {
                return Err(MeshError::Degenerate {
                    file: file_s(),
                    triangle: i,
                    vertices: *t,
                });
            }
        }
        Ok(())
    }

    /// Welded vertex ids for topology: positions that agree to within 2⁻²⁴ of the mesh's
    /// extent are one vertex (each coordinate rounded to that grid). Files split vertices
    /// along texture seams and at poles, where a generator's `sin(2π)` or `sin(π)` leaves a
    /// residue of 1e-16 that f32 storage keeps: exact equality would call such a sphere open.
    fn welded_ids(&self) -> (Vec<u32>, usize) {
        let (lo, hi) = self.bounds();
        let extent = (hi - lo).max_element();
        let step = if extent.is_finite() && extent > 0.0 {
            extent / (1u64 << 24) as f64
        } else {
            0.0
        };
        let mut map = std::collections::HashMap::with_capacity(self.positions.len());
        let ids = self
            .positions
            .iter()
            .map(|p| {
                let key = if step > 0.0 {
                    let q = ((*p - lo) / step).round();
                    [q.x.to_bits(), q.y.to_bits(), q.z.to_bits()]
                } else {
                    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
                };
                let next = map.len() as u32;
                *map.entry(key).or_insert(next)
            })
            .collect();
        (ids, map.len())
    }

    /// The topology report without changing the mesh. Assumes [`TriangleMesh::validate`]
    /// passed.
    pub fn topology(&self) -> MeshReport {
        let (ids, vertices) = self.welded_ids();
        // Each directed edge as (undirected key, forward?) sorted by key: runs of equal keys
        // are the uses of one edge.
        let mut edges: Vec<(u64, bool)> = Vec::with_capacity(3 * self.triangles.len());
        for t in &self.triangles {
            let w = t.map(|k| ids[k as usize]);
            for e in 0..3 {
                let (a, b) = (w[e], w[(e + 1) % 3]);
                let (lo, hi, fwd) = if a < b { (a, b, true) } else { (b, a, false) };
                edges.push(((lo as u64) << 32 | hi as u64, fwd));
            }
        }
        edges.sort_unstable();
        let mut report = MeshReport {
            triangles: self.triangles.len(),
            vertices,
            ..Default::default()
        };
        let mut i = 0;
        while i < edges.len() {
            let mut j = i;
            let mut forward = 0;
            while j < edges.len() && edges[j].0 == edges[i].0 {
                forward += edges[j].1 as usize;
                j += 1;
            }
            match j - i {
                1 => report.boundary_edges += 1,
                2 => {
                    if forward != 1 {
                        report.inconsistent_edges += 1;
                    }
                }
                _ => report.non_manifold_edges += 1,
            }
            i = j;
        }
        report.signed_volume = self.signed_volume();
        report
    }

    /// Reverses the winding of every triangle (the geometric normals flip; shading normals
    /// are left as they are).
    pub fn flip_winding(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    /// Computes the topology report and, when the mesh is closed but inside out (negative
    /// signed volume), flips its winding so that geometric normals point outward.
    pub fn orient_outward(&mut self) -> MeshReport {
        let mut report = self.topology();
        if report.is_closed() && report.signed_volume < 0.0 {
            self.flip_winding();
            report.flipped = true;
            report.signed_volume = -report.signed_volume;
        }
        report
    }

    /// Validates (errors name `file`) and orients the mesh; returns the report.
    pub fn prepare(&mut self, file: &str) -> Result<MeshReport, MeshError> {
        self.validate(file)?;
        Ok(self.orient_outward())
    }

    /// Applies `t` (see [`Transform`]).
    pub fn transform(&mut self, t: &Transform) {
        self.apply_affine(&t.to_affine());
    }

    /// Applies an affine map: positions by `m`, normals by the inverse transpose of its linear
    /// part; the winding is reversed when the map mirrors (negative determinant).
    pub fn apply_affine(&mut self, m: &DAffine3) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        let lin: DMat3 = m.matrix3;
        if let Some(normals) = &mut self.normals {
            let nm = lin.inverse().transpose();
            for n in normals.iter_mut() {
                *n = (nm * n.as_dvec3()).normalize_or_zero().as_vec3();
            }
        }
        if lin.determinant() < 0.0 {
            self.flip_winding();
        }
    }

    /// Appends `other`'s triangles. The result has normals only when both parts have them
    /// (otherwise it is shaded flat); texture coordinates are kept when either part has them,
    /// the other part getting `(0, 0)`.
    pub fn append(&mut self, other: &TriangleMesh) {
        let base = self.positions.len() as u32;
        let self_empty = self.positions.is_empty();
        let n_self = self.positions.len();
        self.positions.extend_from_slice(&other.positions);
        self.normals = match (self.normals.take(), &other.normals) {
            (Some(mut a), Some(b)) => {
                a.extend_from_slice(b);
                Some(a)
            }
            (None, Some(b)) if self_empty => Some(b.clone()),
            _ => None,
        };
        self.uvs = match (self.uvs.take(), &other.uvs) {
            (None, None) => None,
            (a, b) => {
                let mut a = a.unwrap_or_else(|| vec![Vec2::ZERO; n_self]);
                match b {
                    Some(b) => a.extend_from_slice(b),
                    None => a.extend(std::iter::repeat_n(Vec2::ZERO, other.positions.len())),
                }
                Some(a)
            }
        };
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|k| k + base)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives;

    #[test]
    fn box_extent_only_for_a_whole_outward_box() {
        let (lo, hi) = (DVec3::new(-1.0, 2.0, 0.5), DVec3::new(3.0, 2.5, 4.0));
        let want = Some(hi - lo);
        assert_eq!(primitives::cuboid(lo, hi).box_extent(), want);
        assert_eq!(
            primitives::subdivided_cuboid(lo, hi, [3, 1, 5]).box_extent(),
            want
        );
        assert_eq!(
            primitives::half_space(0.0, [1.0, 2.0], 10.0, 4.0, 6).box_extent(),
            Some(DVec3::new(10.0, 10.0, 4.0))
        );
        assert_eq!(
            primitives::icosphere(DVec3::ZERO, 1.0, 2).box_extent(),
            None
        );
        // A face missing: not a box (a ray through the hole would leave).
        let mut open = primitives::cuboid(lo, hi);
        open.triangles.truncate(10);
        assert_eq!(open.box_extent(), None);
        // Inside out.
        let mut flipped = primitives::cuboid(lo, hi);
        for t in &mut flipped.triangles {
            t.swap(1, 2);
        }
        assert_eq!(flipped.box_extent(), None);
        // A shading normal that is not the face's.
        let mut bent = primitives::cuboid(lo, hi);
        let n = bent.positions.len();
        bent.normals = Some(vec![Vec3::new(0.3, 0.3, 0.9); n]);
        assert_eq!(bent.box_extent(), None);
        // A vertex moved inside: a triangle leaves the face planes.
        let mut dented = primitives::subdivided_cuboid(lo, hi, [2, 2, 2]);
        let mid = dented
            .positions
            .iter()
            .position(|p| p.z == hi.z && p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y)
            .unwrap();
        dented.positions[mid].z -= 0.1;
        assert_eq!(dented.box_extent(), None);
        // Empty and flat meshes.
        assert_eq!(TriangleMesh::default().box_extent(), None);
        let flat = primitives::quad(DVec3::ZERO, DVec3::X, DVec3::Y);
        assert_eq!(flat.box_extent(), None);
    }

    #[test]
    fn cube_is_closed_and_outward() {
        let mut m = primitives::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
        let r = m.prepare("cube").unwrap();
        assert!(r.is_closed(), "{r:?}");
        assert!(!r.flipped);
        assert!((r.signed_volume - 8.0).abs() < 1e-12);
    }

    #[test]
    fn missing_face_gives_boundary_edges() {
        let mut m = primitives::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
        m.triangles.truncate(10); // drop one face (2 triangles)
        let r = m.topology();
        assert!(!r.is_closed());
        assert_eq!(r.boundary_edges, 4);
    }

    #[test]
    fn inside_out_sphere_is_flipped() {
        let mut m = primitives::icosphere(DVec3::new(1.0, 2.0, 3.0), 2.0, 2);
        m.flip_winding();
        assert!(m.signed_volume() < 0.0);
        let r = m.orient_outward();
        assert!(r.flipped && r.is_closed());
        assert!(m.signed_volume() > 0.0);
    }

    #[test]
    fn one_flipped_triangle_is_inconsistent() {
        let mut m = primitives::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0));
        m.triangles[0].swap(1, 2);
        let r = m.topology();
        assert_eq!(r.inconsistent_edges, 3);
        assert!(!r.is_closed());
    }

    #[test]
    fn mirror_transform_keeps_outward_orientation() {
        let mut m = primitives::icosphere(DVec3::ZERO, 1.0, 1);
        let v0 = m.signed_volume();
        m.transform(&Transform {
            scale: DVec3::new(-2.0, 1.0, 1.0),
            rotation: Transform::rotation_axis_angle(DVec3::Z, 30.0),
            translation: DVec3::new(5.0, 0.0, 0.0),
        });
        assert!((m.signed_volume() - 2.0 * v0).abs() < 1e-5 * v0);
        // Normals still radial (outward) from the new centre.
        let n = m.normals.as_ref().unwrap();
        for (p, n) in m.positions.iter().zip(n) {
            let radial = (*p - DVec3::new(5.0, 0.0, 0.0)).normalize();
            // Scaled sphere: the normal is not radial, but it points outward.
            assert!(radial.dot(n.as_dvec3()) > 0.0);
        }
    }

    #[test]
    fn validation_errors() {
        let good = primitives::cuboid(DVec3::ZERO, DVec3::ONE);
        let mut m = good.clone();
        m.triangles.clear();
        assert!(matches!(m.validate("e.obj"), Err(MeshError::Empty { .. })));
        let mut m = good.clone();
        m.triangles[3][1] = 1000;
        let e = m.validate("i.obj").unwrap_err();
        assert!(matches!(
            e,
            MeshError::IndexOutOfRange {
                triangle: 3,
                index: 1000,
                ..
            }
        ));
        assert!(e.to_string().contains("i.obj"));
        let mut m = good.clone();
        m.positions[2].y = f64::NAN;
        assert!(matches!(
            m.validate("n.obj"),
            Err(MeshError::NonFinite { vertex: 2, .. })
        ));
        let mut m = good.clone();
        let t = m.triangles[5];
        m.triangles[5] = [t[0], t[0], t[2]];
        assert!(matches!(
            m.validate("d.obj"),
            Err(MeshError::Degenerate { triangle: 5, .. })
        ));
    }
}
