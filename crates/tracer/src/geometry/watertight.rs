//! Watertight ray/triangle intersection (WBW13: Woop, Benthin & Wald 2013, "Watertight
//! Ray/Triangle Intersection", JCGT 2(1), Listing 1 and §4: the `f32` test with a
//! double-precision fallback for the edge functions when one of them is exactly zero).
//!
//! The ray is transformed once into a sheared space where it runs along +z from the origin;
//! a triangle is hit when its three 2-D edge functions `U, V, W` (evaluated on the sheared
//! vertex xy) have the same sign. Edge functions of a shared edge are evaluated identically for
//! both triangles, so a ray cannot pass between them: it hits one, or both when it runs exactly
//! through the edge. Double-sided; no epsilon on the barycentrics.

use glam::{DVec3, Vec3};

/// A triangle's vertices in BVH leaf order (`f32`, in the BVH's scaled space).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LeafTri {
    pub v: [[f32; 3]; 3],
}

impl LeafTri {
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Self {
        Self {
            v: [v0.to_array(), v1.to_array(), v2.to_array()],
        }
    }
}

/// The per-ray constants of the test: the dominant axis `kz` (with `kx`, `ky` swapped when
/// `dir[kz] < 0` to keep the winding), and the shear `(Sx, Sy, Sz)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ShearedRay {
    pub org: [f32; 3],
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

/// The result of a successful test: distance and the unnormalised edge functions.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TriHit {
    /// Distance along the ray.
    pub t: f32,
    /// `U + V + W`: its sign tells which side of the triangle the ray comes from (opposite
    /// signs for opposite sides); its magnitude normalises the barycentrics.
    pub det: f32,
}

impl ShearedRay {
    #[inline]
    pub fn new(org: [f32; 3], dir: [f32; 3]) -> Self {
        let a = [dir[0].abs(), dir[1].abs(), dir[2].abs()];
        let kz = if a[0] > a[1] {
            if a[0] > a[2] { 0 } else { 2 }
        } else if a[1] > a[2] {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / dir[kz];
        Self {
            org,
            kx,
            ky,
            kz,
            sx: dir[kx] * sz,
            sy: dir[ky] * sz,
            sz,
        }
    }

    /// The watertight test against `tri` for `t ∈ [t_min, t_max]`.
    #[inline(always)]
    pub fn intersect(&self, tri: &LeafTri, t_min: f32, t_max: f32) -> Option<TriHit> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let o = self.org;
        let a = [tri.v[0][0] - o[0], tri.v[0][1] - o[1], tri.v[0][2] - o[2]];
        let b = [tri.v[1][0] - o[0], tri.v[1][1] - o[1], tri.v[1][2] - o[2]];
        let c = [tri.v[2][0] - o[0], tri.v[2][1] - o[1], tri.v[2][2] - o[2]];
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // The ray passes (numerically) through an edge or a vertex: re-evaluate the edge
            // functions in f64 from the same f32 sheared coordinates, so both triangles of the
            // edge agree (paper §4).
            let (u64_, v64, w64) = edge_functions_f64(ax, ay, bx, by, cx, cy);
            u = u64_ as f32;
            v = v64 as f32;
            w = w64 as f32;
            // Keep the sign even when the f64 value underflows f32.
            u = fix_sign(u, u64_);
            v = fix_sign(v, v64);
            w = fix_sign(w, w64);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = self.sz * a[kz];
        let bz = self.sz * b[kz];
        let cz = self.sz * c[kz];
        let t_scaled = u * az + v * bz + w * cz;
        // Compare t = T/det with the range without dividing: flip signs so det > 0.
        let (t_s, d_abs) = if det < 0.0 {
            (-t_scaled, -det)
        } else {
            (t_scaled, det)
        };
        if t_s < t_min * d_abs || t_s > t_max * d_abs {
            return None;
        }
        let t = t_s / d_abs;
        if !(t >= t_min && t <= t_max) {
            return None;
        }
        Some(TriHit { t, det })
    }
}

#[cold]
#[inline(never)]
fn edge_functions_f64(ax: f32, ay: f32, bx: f32, by: f32, cx: f32, cy: f32) -> (f64, f64, f64) {
    let (ax, ay, bx, by, cx, cy) = (
        ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
    );
    (cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax)
}

#[inline]
fn fix_sign(x: f32, x64: f64) -> f32 {
    if x == 0.0 && x64 != 0.0 {
        (f32::MIN_POSITIVE).copysign(x64 as f32)
    } else {
        x
    }
}

/// The same test in `f64` on `f64` data, used once per reported hit to get accurate
/// barycentrics and distance. Returns `(t, b0, b1, b2)` with the barycentrics clamped to the
/// triangle (the `f32` test accepted the hit; `f64` may put it a rounding error outside).
#[inline]
pub(crate) fn refine_f64(org: DVec3, dir: DVec3, v: [DVec3; 3]) -> Option<(f64, [f64; 3])> {
    let d = dir.to_array();
    let a_ = [d[0].abs(), d[1].abs(), d[2].abs()];
    let kz = if a_[0] > a_[1] {
        if a_[0] > a_[2] { 0 } else { 2 }
    } else if a_[1] > a_[2] {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sz = 1.0 / d[kz];
    let sx = d[kx] * sz;
    let sy = d[ky] * sz;
    let a = (v[0] - org).to_array();
    let b = (v[1] - org).to_array();
    let c = (v[2] - org).to_array();
    let ax = a[kx] - sx * a[kz];
    let ay = a[ky] - sy * a[kz];
    let bx = b[kx] - sx * b[kz];
    let by = b[ky] - sy * b[kz];
    let cx = c[kx] - sx * c[kz];
    let cy = c[ky] - sy * c[kz];
    let mut u = cx * by - cy * bx;
    let mut v_ = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    let det = u + v_ + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // Clamp to the triangle on the det's side.
    let s = det.signum();
    u = (u * s).max(0.0);
    v_ = (v_ * s).max(0.0);
    w = (w * s).max(0.0);
    let sum = u + v_ + w;
    if sum <= 0.0 {
        return None;
    }
    let b_ = [u / sum, v_ / sum, w / sum];
    let t = (b_[0] * a[kz] + b_[1] * b[kz] + b_[2] * c[kz]) * sz;
    Some((t, b_))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> LeafTri {
        LeafTri::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        )
    }

    #[test]
    fn hits_inside_misses_outside_both_sides() {
        let t = tri();
        let down = ShearedRay::new([0.25, 0.25, 2.0], [0.0, 0.0, -1.0]);
        let h = down.intersect(&t, 0.0, f32::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        let up = ShearedRay::new([0.25, 0.25, -2.0], [0.0, 0.0, 1.0]);
        let h2 = up.intersect(&t, 0.0, f32::INFINITY).unwrap();
        assert!((h2.t - 2.0).abs() < 1e-6);
        assert!(h.det.signum() != h2.det.signum(), "facing differs by side");
        let miss = ShearedRay::new([0.75, 0.75, 2.0], [0.0, 0.0, -1.0]);
        assert!(miss.intersect(&t, 0.0, f32::INFINITY).is_none());
        // Range limits.
        assert!(down.intersect(&t, 0.0, 1.5).is_none());
        assert!(down.intersect(&t, 2.5, 10.0).is_none());
        // Behind the origin.
        let away = ShearedRay::new([0.25, 0.25, 2.0], [0.0, 0.0, 1.0]);
        assert!(away.intersect(&t, 0.0, f32::INFINITY).is_none());
    }

    #[test]
    fn shared_edge_is_hit_by_at_least_one_triangle() {
        // Two triangles sharing the diagonal (0,0)-(1,1); rays exactly along the diagonal.
        let t1 = LeafTri::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        );
        let t2 = LeafTri::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        for i in 1..100 {
            let x = i as f32 / 100.0;
            let r = ShearedRay::new([x, x, 1.0], [0.0, 0.0, -1.0]);
            let n = [&t1, &t2]
                .iter()
                .filter(|t| r.intersect(t, 0.0, f32::INFINITY).is_some())
                .count();
            assert!(n >= 1, "leak at x = {x}");
        }
    }

    #[test]
    fn refine_matches_closed_form() {
        let v = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(0.0, 2.0, 1.0),
        ];
        let (t, b) = refine_f64(DVec3::new(0.5, 0.25, 3.0), DVec3::NEG_Z, v).unwrap();
        assert!((t - 2.0).abs() < 1e-14);
        // p = b0 v0 + b1 v1 + b2 v2 = (0.5, 0.25): b1 = 0.25, b2 = 0.125.
        assert!(
            (b[1] - 0.25).abs() < 1e-14 && (b[2] - 0.125).abs() < 1e-14,
            "{b:?}"
        );
    }
}
