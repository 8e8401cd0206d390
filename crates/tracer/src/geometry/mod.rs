//! Triangle meshes, the BVH-backed ray queries and the surface-projection query of the
//! estimators.
//!
//! # Precision
//! The public API is `f64`; the BVH and the triangle test run in `f32` on vertices stored in
//! BVH leaf order. A hit's position is recomputed in `f64` from the triangle's vertices and
//! barycentrics (not `o + t·d`), and its error bound [`Hit::p_error`] drives
//! [`Hit::spawn_origin`], the offset used to start a new ray from the surface.
//!
//! # Robustness
//! * The ray/triangle test is watertight (WBW13: Woop, Benthin & Wald 2013, "Watertight
//!   Ray/Triangle Intersection", JCGT 2(1)): rays never slip between the triangles of a closed
//!   mesh.
//! * obvhs's node test clamps the entry distance to an absolute `1e-4`, which would skip
//!   surfaces closer than that to the ray origin. Every object's BVH is therefore built on
//!   vertices scaled by a power of two (exact in floating point) that maps the object's extent
//!   to about 2¹², so that `1e-4` lies far below `f32` resolution of the object.
//! * obvhs's slab test is not conservative, so triangle boxes are padded by 2⁻¹⁶ of the
//!   object's extent (Ize13): rays through the edges of axis-aligned boxes are not lost.
//!
//! Tested (`tests/tracer/geometry.rs`): 1e5 random rays from inside a closed icosphere and
//! rays through every vertex and edge midpoint all hit; rays from inside a cube toward its
//! corners, edges and face diagonals all hit; the BVH agrees with a brute-force f64 scan.

mod bvh;
pub mod closest;
mod curvature;
mod cwbvh;
#[cfg(feature = "gltf")]
pub mod gltf;
pub mod gltf_assets;
#[cfg(feature = "gltf")]
pub mod gltf_material;
pub mod holes;
pub mod mesh;
#[cfg(feature = "obj")]
pub mod obj;
#[cfg(feature = "obj")]
mod obj_lines;
pub mod object_surface;
#[cfg(feature = "ply")]
pub mod ply;
pub mod primitives;
mod tlas;
mod watertight;

pub use bvh::Geometry;
pub use mesh::{MeshReport, Transform, TriangleMesh};
pub use object_surface::ObjectSurface;

use glam::{DVec2, DVec3};

/// A ray `origin + t·dir` restricted to `t ∈ [t_min, t_max]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Origin in scene units.
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
    /// Smallest accepted distance (usually 0: offset the origin instead, see
    /// [`Hit::spawn_origin`]).
    pub t_min: f64,
    /// Largest accepted distance (`f64::INFINITY` for an unbounded ray).
    pub t_max: f64,
}

impl Ray {
    /// An unbounded ray, `t ∈ [0, ∞)`. `dir` must be a unit vector.
    #[inline]
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        debug_assert!(origin.is_finite() && (dir.length_squared() - 1.0).abs() < 1e-6);
        Self {
            origin,
            dir,
            t_min: 0.0,
            t_max: f64::INFINITY,
        }
    }

    /// A ray with `t ∈ [0, t_max]`. `dir` must be a unit vector.
    #[inline]
    pub fn segment(origin: DVec3, dir: DVec3, t_max: f64) -> Self {
        Self {
            t_max,
            ..Self::new(origin, dir)
        }
    }

    /// A ray with `t ∈ [t_min, t_max]`. `dir` must be a unit vector.
    #[inline]
    pub fn with_range(origin: DVec3, dir: DVec3, t_min: f64, t_max: f64) -> Self {
        Self {
            t_min,
            t_max,
            ..Self::new(origin, dir)
        }
    }

    /// A shadow ray from `from` toward `to` that stops just short of `to`, so that the
    /// surface holding `to` (a light, a surface point) does not occlude it. The shortening is
    /// [`OFFSET_REL`] of `|to|_∞ + distance`, the same scale as the origin offset. `None` when the
    /// two points coincide.
    #[inline]
    pub fn between(from: DVec3, to: DVec3) -> Option<Self> {
        let d = to - from;
        let dist = d.length();
        if dist.is_nan() || dist <= 0.0 || !dist.is_finite() {
            return None;
        }
        let shrink = OFFSET_REL * (to.abs().max_element() + dist);
        Some(Self::segment(from, d / dist, (dist - shrink).max(0.0)))
    }

    /// The point at distance `t`.
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.dir
    }
}

/// A ray/surface intersection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray (in scene units, the ray direction being unit).
    pub t: f64,
    /// Position, recomputed in `f64` from the triangle's vertices and barycentrics.
    pub p: DVec3,
    /// Unit geometric normal (from the triangle's winding; outward for closed meshes, which
    /// are oriented at load).
    pub ng: DVec3,
    /// Unit interpolated shading normal, flipped into `ng`'s hemisphere; equal to `ng` when
    /// the mesh has no normals.
    pub ns: DVec3,
    /// Texture coordinates (zero when the mesh has none). `v` points up: `(0, 0)` is the
    /// bottom-left corner of an image.
    pub uv: DVec2,
    /// Object index (the mesh's index in [`Geometry::build`]).
    pub object: u32,
    /// Triangle index within its object's mesh.
    pub prim: u32,
    /// Barycentrics `(b1, b2)` of vertices 1 and 2: `p = (1-b1-b2)·v0 + b1·v1 + b2·v2`.
    pub bary: DVec2,
    /// Bound on the distance between `p` and the surface as the `f32` intersection test sees
    /// it (scene units): [`OFFSET_REL`] × (`|p − c|_∞` + the triangle's largest extent), `c`
    /// the centre of the object's local frame (the triangles are stored relative to it).
    pub p_error: f64,
}

impl Hit {
    /// The origin for a new ray leaving this hit along `dir`: `p` moved off the surface by
    /// [`Hit::p_error`] along `±ng`, on the side `dir` points to. A ray started there with
    /// `t_min = 0` does not re-hit this triangle (tested), whether it goes back out
    /// (reflection) or through the surface (transmission).
    #[inline]
    pub fn spawn_origin(&self, dir: DVec3) -> DVec3 {
        offset_along_normal(self.p, self.ng, dir, self.p_error)
    }

    /// A ray leaving this hit along the unit direction `dir` (see [`Hit::spawn_origin`]).
    #[inline]
    pub fn spawn_ray(&self, dir: DVec3) -> Ray {
        Ray::new(self.spawn_origin(dir), dir)
    }
}

impl het_estimate::SurfacePoint for Hit {
    #[inline]
    fn position(&self) -> DVec3 {
        self.p
    }
    #[inline]
    fn normal(&self) -> DVec3 {
        self.ns
    }
    #[inline]
    fn geometric_normal(&self) -> DVec3 {
        self.ng
    }
}

/// Relative origin offset: `2⁻¹⁸ ≈ 3.8e-6`, i.e. 32 `f32` ulps of the coordinate scale.
///
/// Why this value: vertices and the triangle test are `f32`. Rounding the new origin to `f32`
/// moves it by up to half an ulp per coordinate (≈ 0.9·ε·|p|_∞ along the normal, with
/// ε = 2⁻²³), and the watertight test evaluates the triangle's plane from vertex − origin
/// differences, with rounding errors of a few ε·(triangle extent). So the offset must scale with
/// `|p|_∞ + extent`, not with `|p|` alone: near the origin of a ground plane made of two huge
/// triangles, an offset of 1e-6·|p| is far too small. Measured (`offset_scale_survey` in the
/// integration tests, 480,000 spawned rays over six convex meshes from a 1e-3 sphere to a
/// 2e3 slab): no offset → 50–75 % self-hits; 1/32 of this value (1 ulp of `|p| + extent`) → 2
/// self-hits, 1/16 → 1; 1/8 and above → none. 32 ulps leaves a factor 8 of margin and stays small: for a
/// unit-size object, 4e-6, far below any mean free path a scene should use (a 1e-4 thick slab
/// is crossed correctly, tested).
pub const OFFSET_REL: f64 = 1.0 / 262_144.0;

/// Moves `p` off the surface with geometric normal `ng` by `OFFSET_REL · |p|_∞` along `±ng`,
/// on the side `dir` points to, so that a ray from the result along `dir` does not re-hit
/// the surface at `p`.
///
/// This version only knows `p`; it is exact for triangles no larger than `|p|_∞`. Hits from
/// [`Geometry`] carry a bound that also covers large triangles: prefer [`Hit::spawn_origin`].
#[inline]
pub fn offset_ray_origin(p: DVec3, ng: DVec3, dir: DVec3) -> DVec3 {
    offset_along_normal(p, ng, dir, OFFSET_REL * p.abs().max_element())
}

#[inline]
fn offset_along_normal(p: DVec3, ng: DVec3, dir: DVec3, dist: f64) -> DVec3 {
    // Guard p = 0 exactly (no scale information): use the smallest normal f32 scale.
    let dist = dist.max(OFFSET_REL * f32::MIN_POSITIVE as f64);
    if ng.dot(dir) >= 0.0 {
        p + dist * ng
    } else {
        p - dist * ng
    }
}
