//! [`Geometry`]: one obvhs CWBVH per object, triangles copied into BVH leaf order, the
//! watertight triangle test in the traversal closure.
//!
//! One BVH per object makes the per-object queries of the BSSRDF methods
//! ([`Geometry::intersect_object`], [`Geometry::for_each_object_hit`]) traverse only that
//! object; the all-object queries walk a top-level tree over the objects' boxes
//! ([`super::tlas`]), shrinking the ray as hits are found. Each object's triangles are stored
//! in its own local frame (relative to its centre, scaled by a power of two), and rays are
//! moved into that frame in `f64`, so precision does not depend on where the object is.

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use glam::{DVec2, DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as BvhRay, RayHit};

use super::cwbvh::{PaddedBox, build_cwbvh, safe_inv, slab};
use super::tlas::Tlas;
use super::watertight::{LeafTri, ShearedRay, refine_f64};
use het_estimate::{Projected, UvChart};

use super::{Hit, OFFSET_REL, Ray, TriangleMesh};

/// Target extent of an object in the BVH's scaled space (see the module docs of
/// [`crate::geometry`]): 2¹².
const SCALED_EXTENT_LOG2: i32 = 12;
/// Largest coordinate magnitude allowed in scaled space: 2³².
const SCALED_COORD_LOG2: i32 = 32;
/// Triangle bounding boxes are padded by this fraction of the object's extent (2⁻¹⁶) before
/// the BVH is built. obvhs's slab test is not conservative (Ize13): a ray through a triangle
/// edge that lies on its node's boundary (every edge of an axis-aligned box) can be culled by
/// a one-ulp difference between the entry and exit distances. The slab test's rounding error
/// grows with the distance from the ray origin to the node (≈ 3 ulps of it); the padding
/// (≈ 128 ulps of the object's extent) covers rays starting within about 40 extents of the
/// object, which includes every ray of a random walk inside it.
const BOX_PAD_REL: f32 = 1.0 / 65536.0;
/// Lower bound of the padding in ulps of the object's largest coordinate magnitude. For an
/// object far from the origin compared with its size (a unit sphere at (1e4, −2e4, 3e4):
/// scaled by 2¹¹, coordinates ≈ 6e7 with an ulp of 4, against an extent pad of 0.06) the
/// extent-relative pad is below one ulp of the box coordinates and vanishes when added to them,
/// and a ray from the centre through a shared vertex leaked (`tests/precision.rs`). Near the
/// origin (magnitude < 16 × extent) the extent pad is the larger and nothing changes.
const BOX_PAD_COORD_ULPS: f64 = 8.0;

/// The padding of an object's world bounds in the conservative box tests (the top-level tree's
/// leaves): 1e-6 of its extent.
fn box_pad(lo: DVec3, hi: DVec3) -> DVec3 {
    let extent = (hi - lo).max_element();
    DVec3::splat(
        if extent.is_finite() {
            1e-6 * extent
        } else {
            0.0
        } + 1e-30,
    )
}

/// One object's acceleration structure.
#[derive(Debug)]
struct ObjectAccel {
    bvh: Option<CwBvh>,
    /// Triangles in BVH leaf order, in the object's local frame: `(p − centre) · scale`.
    tris: Vec<LeafTri>,
    /// Origin of the local frame: the centre of the world bounds. Storing the triangles
    /// relative to it keeps their `f32` precision relative to the object's size wherever the
    /// object is (far from the world origin, world coordinates would round to a large fraction
    /// of the object).
    centre: DVec3,
    /// Leaf index → triangle index in the object's mesh.
    prims: Vec<u32>,
    /// Power of two mapping world to scaled coordinates.
    scale: f64,
    inv_scale: f64,
    /// World-space bounds.
    lo: DVec3,
    hi: DVec3,
    /// The bounds padded for the conservative box tests.
    plo: DVec3,
    phi: DVec3,
    /// The extents when the mesh is its own bounding box ([`TriangleMesh::box_extent`]).
    box_extent: Option<DVec3>,
    /// Per-vertex curvature tensors ([`super::curvature`]), computed on the first
    /// [`Geometry::curvature`] query (only the BSSRDF estimators ask).
    curvature: std::sync::OnceLock<Option<Vec<[f32; 6]>>>,
}

/// Scene geometry: triangle meshes (object id = index) with their BVHs, and the ray queries.
///
/// `Send + Sync`; every query takes `&self` and keeps its state on the stack (no allocation
/// except in [`Geometry::for_each_object_hit`] beyond 32 crossings).
#[derive(Debug)]
pub struct Geometry {
    objects: Vec<ObjectAccel>,
    /// The top-level tree over the objects that have triangles.
    tlas: Tlas,
    meshes: Vec<TriangleMesh>,
    triangles: usize,
    counter: RayCounter,
}

/// A relaxed, striped counter: each thread adds to its own cache line.
#[derive(Debug)]
struct RayCounter {
    stripes: Box<[Padded]>,
}

#[derive(Debug, Default)]
#[repr(align(64))]
struct Padded(AtomicU64);

const STRIPES: usize = 16;
static NEXT_STRIPE: AtomicUsize = AtomicUsize::new(0);
thread_local! {
    static STRIPE: Cell<usize> = const { Cell::new(usize::MAX) };
}

impl RayCounter {
    fn new() -> Self {
        Self {
            stripes: (0..STRIPES).map(|_| Padded::default()).collect(),
        }
    }
    #[inline]
    fn add(&self, n: u64) {
        let i = STRIPE.with(|s| {
            let mut i = s.get();
            if i == usize::MAX {
                i = NEXT_STRIPE.fetch_add(1, Ordering::Relaxed) % STRIPES;
                s.set(i);
            }
            i
        });
        self.stripes[i].0.fetch_add(n, Ordering::Relaxed);
    }
    fn total(&self) -> u64 {
        self.stripes
            .iter()
            .map(|s| s.0.load(Ordering::Relaxed))
            .sum()
    }
}

/// The `f32` ray of one object's scaled space.
#[derive(Clone, Copy)]
struct ScaledRay {
    bvh: BvhRay,
    sheared: ShearedRay,
}

impl ObjectAccel {
    fn build(mesh: &TriangleMesh) -> Self {
        let (lo, hi) = mesh.bounds();
        let extent = (hi - lo).max_element();
        let centre = if extent.is_finite() {
            0.5 * (lo + hi)
        } else {
            DVec3::ZERO
        };
        let magnitude = (lo - centre).abs().max((hi - centre).abs()).max_element();
        let scale = if extent > 0.0 && extent.is_finite() {
            let e = SCALED_EXTENT_LOG2 - extent.log2().ceil() as i32;
            let e_max = if magnitude > 0.0 {
                SCALED_COORD_LOG2 - magnitude.log2().ceil() as i32
            } else {
                e
            };
            2f64.powi(e.min(e_max).clamp(-120, 120))
        } else {
            1.0
        };
        if mesh.triangles.is_empty() {
            return Self {
                bvh: None,
                tris: Vec::new(),
                centre,
                prims: Vec::new(),
                scale,
                inv_scale: 1.0 / scale,
                lo,
                hi,
                plo: lo - box_pad(lo, hi),
                phi: hi + box_pad(lo, hi),
                box_extent: None,
                curvature: std::sync::OnceLock::new(),
            };
        }
        let scaled: Vec<[Vec3A; 3]> = mesh
            .triangles
            .iter()
            .map(|t| {
                t.map(|k| Vec3A::from(((mesh.positions[k as usize] - centre) * scale).as_vec3()))
            })
            .collect();
        // 128 ulps of the extent, but never less than 8 ulps of the largest coordinate: far
        // from the origin the extent-relative pad alone rounds away (min − pad == min in f32).
        let pad = Vec3A::splat(
            (f64::from(BOX_PAD_REL) * extent * scale)
                .max(BOX_PAD_COORD_ULPS * f64::from(f32::EPSILON) * magnitude * scale)
                as f32,
        );
        let boxes: Vec<PaddedBox> = scaled
            .iter()
            .map(|v| {
                let aabb = Aabb::from_points(v);
                PaddedBox(Aabb::new(aabb.min - pad, aabb.max + pad))
            })
            .collect();
        let bvh = build_cwbvh(&boxes, BvhBuildParams::medium_build());
        let tris = bvh
            .primitive_indices
            .iter()
            .map(|&i| {
                let v = &scaled[i as usize];
                LeafTri::new(v[0].into(), v[1].into(), v[2].into())
            })
            .collect();
        let prims = bvh.primitive_indices.clone();
        Self {
            bvh: Some(bvh),
            tris,
            centre,
            prims,
            scale,
            inv_scale: 1.0 / scale,
            lo,
            hi,
            plo: lo - box_pad(lo, hi),
            phi: hi + box_pad(lo, hi),
            box_extent: mesh.box_extent(),
            curvature: std::sync::OnceLock::new(),
        }
    }

    /// The ray in the object's local frame, its origin first moved in `f64` along the ray to
    /// `shift` (the returned distances are relative to it): a ray that starts far from the
    /// object (a camera ray) keeps the precision of one that starts near it.
    #[inline]
    fn scaled_ray(&self, ray: &Ray, t_min: f64, t_max: f64, shift: f64) -> ScaledRay {
        let o = ((ray.origin + shift * ray.dir - self.centre) * self.scale).as_vec3();
        let d = ray.dir.as_vec3();
        let bvh = BvhRay {
            origin: o.into(),
            direction: d.into(),
            inv_direction: Vec3A::new(safe_inv(d.x), safe_inv(d.y), safe_inv(d.z)),
            tmin: ((t_min - shift).max(0.0) * self.scale) as f32,
            tmax: ((t_max - shift) * self.scale).min(f64::from(f32::MAX)) as f32,
        };
        ScaledRay {
            bvh,
            sheared: ShearedRay::new(o.to_array(), d.to_array()),
        }
    }

    /// [`ObjectAccel::origin_shift`] when the ray is known to enter the padded bounds at
    /// `enter`: one extent before it.
    #[inline]
    fn shift_from_entry(&self, enter: f64) -> f64 {
        (enter - (self.hi - self.lo).max_element()).max(0.0)
    }

    /// How far along the ray its origin can move toward the object before the `f32` tests:
    /// to one object extent before the padded bounds (0 for a ray that starts near or inside
    /// them, or does not reach them after `t_min`).
    #[inline]
    fn origin_shift(&self, ray: &Ray) -> f64 {
        let extent = (self.hi - self.lo).max_element();
        let far = (ray.origin - self.centre).abs().max_element();
        if far.is_nan() || far <= 4.0 * extent {
            return 0.0;
        }
        let pad = extent + 1e-30;
        slab(
            self.lo - pad,
            self.hi + pad,
            ray.origin,
            DVec3::ONE / ray.dir,
            0.0,
            f64::INFINITY,
        )
        .unwrap_or(0.0)
    }

    /// The world bounds padded for the conservative box tests.
    #[inline]
    fn padded_bounds(&self) -> (DVec3, DVec3) {
        (self.plo, self.phi)
    }

    /// Closest hit in `[t_min, t_max]` (world units): `(leaf, t_world)`.
    #[inline]
    fn closest(&self, ray: &Ray, t_min: f64, t_max: f64, shift: f64) -> Option<(u32, f64)> {
        let bvh = self.bvh.as_ref()?;
        let r = self.scaled_ray(ray, t_min, t_max, shift);
        let mut hit = RayHit::none();
        let tris = &self.tris;
        let sheared = r.sheared;
        if bvh.ray_traverse(r.bvh, &mut hit, |br, id| {
            match sheared.intersect(&tris[id], br.tmin, br.tmax) {
                Some(h) => h.t,
                None => f32::INFINITY,
            }
        }) {
            Some((hit.primitive_id, shift + hit.t as f64 * self.inv_scale))
        } else {
            None
        }
    }

    #[inline]
    fn any(&self, ray: &Ray, shift: f64) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let r = self.scaled_ray(ray, ray.t_min, ray.t_max, shift);
        let tris = &self.tris;
        let sheared = r.sheared;
        !bvh.ray_traverse_miss(r.bvh, |br, id| {
            match sheared.intersect(&tris[id], br.tmin, br.tmax) {
                Some(h) => h.t,
                None => f32::INFINITY,
            }
        })
    }
}

impl Geometry {
    /// Builds one BVH per mesh; object `i` is `meshes[i]`. Meshes should have been validated
    /// ([`TriangleMesh::prepare`]); an empty mesh gives an object that is never hit.
    pub fn build(meshes: Vec<TriangleMesh>) -> Geometry {
        let objects: Vec<ObjectAccel> = meshes.iter().map(ObjectAccel::build).collect();
        let triangles = meshes.iter().map(|m| m.triangles.len()).sum();
        let boxes: Vec<(DVec3, DVec3)> = objects.iter().map(ObjectAccel::padded_bounds).collect();
        let ids = (0..objects.len() as u32)
            .filter(|&k| objects[k as usize].bvh.is_some())
            .collect();
        let tlas = Tlas::build(&boxes, ids);
        Geometry {
            objects,
            tlas,
            meshes,
            triangles,
            counter: RayCounter::new(),
        }
    }

    /// Number of objects.
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Total number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles
    }

    /// The mesh of `object`.
    pub fn mesh(&self, object: u32) -> &TriangleMesh {
        &self.meshes[object as usize]
    }

    /// World-space bounds `(min, max)` of `object`.
    pub fn object_bounds(&self, object: u32) -> (DVec3, DVec3) {
        let o = &self.objects[object as usize];
        (o.lo, o.hi)
    }

    /// The object's extents along x, y and z when its mesh is exactly its own axis-aligned
    /// bounding box ([`TriangleMesh::box_extent`]), else `None`.
    pub fn object_box_extent(&self, object: u32) -> Option<DVec3> {
        self.objects[object as usize].box_extent
    }

    /// Bounds of every object together.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.objects.iter().filter(|o| o.bvh.is_some()).fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), o| (lo.min(o.lo), hi.max(o.hi)),
        )
    }

    /// Rays traced so far by every query of this geometry (each call of `intersect`,
    /// `intersect_object`, `occluded`, `for_each_object_hit` counts one; `project` counts
    /// two). Relaxed, per-thread striped atomics: cheap, exact once the threads are joined.
    pub fn rays_traced(&self) -> u64 {
        self.counter.total()
    }

    /// Walks the top-level tree for `ray`, nearest object box first, calling
    /// `visit(object, its structure, origin shift, t_max)`, which returns the new `t_max` or
    /// `None` to stop.
    #[inline]
    fn visit_objects(
        &self,
        ray: &Ray,
        mut visit: impl FnMut(u32, &ObjectAccel, f64, f64) -> Option<f64>,
    ) {
        self.tlas.traverse(
            ray.origin,
            ray.dir,
            ray.t_min,
            ray.t_max,
            |k, enter, t_max| {
                let obj = &self.objects[k as usize];
                visit(k, obj, obj.shift_from_entry(enter), t_max)
            },
        );
    }

    /// The closest intersection over all objects in `[ray.t_min, ray.t_max]`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.counter.add(1);
        let mut best: Option<(u32, u32, f64)> = None;
        self.visit_objects(ray, |k, obj, shift, t_max| {
            match obj.closest(ray, ray.t_min, t_max, shift) {
                Some((leaf, t)) => {
                    best = Some((k, leaf, t));
                    Some(t)
                }
                None => Some(t_max),
            }
        });
        best.map(|(k, leaf, t)| self.make_hit(k, leaf, ray, t))
    }

    /// For an object whose mesh is its own axis-aligned box ([`Geometry::object_box_extent`]):
    /// the crossing of the whole line `origin + t·dir` (unit `dir`, `t` of either sign) nearest
    /// to `origin`, the projection of Sone's estimators, found from the box's planes alone
    /// ([`BoxLine::crossing`]).
    #[inline]
    fn box_crossing(&self, object: u32, origin: DVec3, dir: DVec3) -> Projected<BoxCrossing> {
        match self.box_line(object, dir) {
            Some(line) => line.crossing(origin),
            None => Projected::Undecided,
        }
    }

    /// The lines along `dir` through `object`, when it is its own axis-aligned box.
    #[inline]
    fn box_line(&self, object: u32, dir: DVec3) -> Option<BoxLine> {
        let o = &self.objects[object as usize];
        let extent = o.box_extent?;
        Some(BoxLine {
            lo: o.lo,
            hi: o.hi,
            // Far above the f32 precision of the object's triangles (about 1e-7 of the
            // extent).
            margin: 1e-5 * extent.max_element(),
            dir,
            inv: (dir.abs().min_element() >= 1e-12).then(|| dir.recip()),
        })
    }

    /// For an object whose mesh is its own axis-aligned box ([`Geometry::object_box_extent`]):
    /// the hit of Sone's projection, the crossing of the whole line `origin + t·dir` (unit
    /// `dir`, `t` of either sign) nearest to `origin`. The box's planes say where that
    /// crossing is (or that the line misses the box, or that they cannot settle it within the
    /// f32 margin of the triangles: [`Projected::Undecided`]), and one ray over a short
    /// window around it finds the triangle, where a general mesh needs a ray each way. The hit is the
    /// ray's own (the same `t`, point and normals as the two-ray projection's);
    /// [`Projected::Undecided`] also for an origin on the surface and when the window
    /// finds no triangle.
    pub fn project_onto_box(&self, object: u32, origin: DVec3, dir: DVec3) -> Projected<Hit> {
        let c = match self.box_crossing(object, origin, dir) {
            Projected::At(c) => c,
            Projected::Miss => return Projected::Miss,
            Projected::Undecided => return Projected::Undecided,
        };
        // An origin on the surface: a window about t = 0 would need rays both ways.
        if c.t.abs() <= c.margin {
            return Projected::Undecided;
        }
        let (d, t) = if c.t > 0.0 { (dir, c.t) } else { (-dir, -c.t) };
        match self.intersect_object(
            object,
            &Ray::with_range(origin, d, t - c.margin, t + c.margin),
        ) {
            Some(hit) => Projected::At(hit),
            None => Projected::Undecided,
        }
    }

    /// [`Geometry::project_onto_box`] without a ray: the point where the line crosses the
    /// box's face, computed from the planes in f64, moved inward by a hair (1e-9 of the
    /// coordinates' magnitude, far below any texture's scale).
    /// The hair matters where a face lies on a cell boundary of a field (the checker slab's
    /// sides): the point then reads the medium behind the face, as the path tracer's volume
    /// does, rather than whichever side rounding picks. An origin on the surface (the points
    /// of an averaging ellipse that lies in a face) projects to itself, as the rays find. No
    /// triangle is found, so there are no texture coordinates: for fields defined in space
    /// only.
    #[inline]
    pub fn project_position_onto_box(&self, object: u32, origin: DVec3, dir: DVec3) -> Projected {
        match self.box_line(object, dir) {
            Some(line) => line.position(origin),
            None => Projected::Undecided,
        }
    }

    /// [`Geometry::project_position_onto_box`] for several origins along one direction, into
    /// `out` (the direction's share of the work done once).
    pub fn project_positions_onto_box(
        &self,
        object: u32,
        origins: &[DVec3],
        dir: DVec3,
        out: &mut [Projected],
    ) {
        match self.box_line(object, dir) {
            Some(line) => {
                for (o, r) in origins.iter().zip(out.iter_mut()) {
                    *r = line.position(*o);
                }
            }
            None => out.fill(Projected::Undecided),
        }
    }

    /// The closest intersection with `object`'s triangles in `[ray.t_min, ray.t_max]`.
    #[inline]
    pub fn intersect_object(&self, object: u32, ray: &Ray) -> Option<Hit> {
        self.counter.add(1);
        let obj = &self.objects[object as usize];
        obj.closest(ray, ray.t_min, ray.t_max, obj.origin_shift(ray))
            .map(|(leaf, t)| self.make_hit(object, leaf, ray, t))
    }

    /// True when any object is hit in `[ray.t_min, ray.t_max]` (stops at the first hit). For
    /// a shadow ray toward a point use [`Ray::between`].
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.counter.add(1);
        let mut hit = false;
        self.visit_objects(ray, |_, obj, shift, t_max| {
            if obj.any(ray, shift) {
                hit = true;
                None
            } else {
                Some(t_max)
            }
        });
        hit
    }

    /// Calls `f` for every crossing of the ray with `object` in `[ray.t_min, ray.t_max]`, in
    /// increasing `t`. A ray through a shared edge or vertex is reported once (duplicates with
    /// the same facing within a few `f32` ulps of each other are merged). No allocation up
    /// to 32 crossings.
    pub fn for_each_object_hit(&self, object: u32, ray: &Ray, mut f: impl FnMut(&Hit)) {
        self.counter.add(1);
        let obj = &self.objects[object as usize];
        let Some(bvh) = obj.bvh.as_ref() else {
            return;
        };
        let shift = obj.origin_shift(ray);
        let r = obj.scaled_ray(ray, ray.t_min, ray.t_max, shift);
        let mut buf = CrossingBuf::new();
        let tris = &obj.tris;
        let sheared = r.sheared;
        bvh.ray_traverse_anyhit(r.bvh, |br, id| {
            if let Some(h) = sheared.intersect(&tris[id], br.tmin, br.tmax) {
                buf.push(Crossing {
                    t: h.t,
                    leaf: id as u32,
                    front: h.det > 0.0,
                });
            }
        });
        let crossings = buf.sorted();
        let o_mag = r.bvh.origin.abs().max_element();
        let mut last: Option<Crossing> = None;
        for c in crossings.iter() {
            if let Some(l) = last {
                let tol = 32.0 * f32::EPSILON * (c.t.abs() + o_mag);
                if l.front == c.front && c.t - l.t <= tol {
                    continue;
                }
            }
            last = Some(*c);
            let hit = self.make_hit(object, c.leaf, ray, shift + c.t as f64 * obj.inv_scale);
            f(&hit);
        }
    }

    /// The texture coordinates around `hit` as an affine map: the linear interpolation over
    /// its triangle ([`UvChart::of_triangle`]), taken at the hit. `None` for a mesh without
    /// texture coordinates or a triangle of zero area.
    pub fn uv_chart(&self, hit: &Hit) -> Option<UvChart> {
        let mesh = self.meshes.get(hit.object as usize)?;
        let uvs = mesh.uvs.as_ref()?;
        let idx = mesh.triangles.get(hit.prim as usize)?;
        let uv = idx.map(|k| uvs[k as usize].as_dvec2());
        UvChart::of_triangle(mesh.triangle_vertices(hit.prim as usize), uv, hit.p, hit.uv)
    }

    /// The surface's curvature at `hit` (module `geometry::curvature`: RUS04's per-vertex tensors from
    /// the shading normals, interpolated); the object's tensors are computed on the first
    /// call. `None` for an empty mesh.
    pub fn curvature(&self, hit: &Hit) -> Option<het_estimate::Curvature> {
        let mesh = self.meshes.get(hit.object as usize)?;
        let tensors = self.objects[hit.object as usize]
            .curvature
            .get_or_init(|| super::curvature::vertex_tensors(mesh));
        super::curvature::at_hit(mesh, tensors.as_ref()?, hit)
    }

    /// Builds the full hit record for leaf `leaf` of `object`: barycentrics and distance
    /// refined in `f64`, position from the vertices, normals, texture coordinates.
    #[inline]
    fn make_hit(&self, object: u32, leaf: u32, ray: &Ray, t_approx: f64) -> Hit {
        let obj = &self.objects[object as usize];
        let prim = obj.prims[leaf as usize];
        let c = obj.centre;
        // The mesh's own f64 vertices (the f32 leaf copy only decides hit or miss).
        let v = self.meshes[object as usize].triangle_vertices(prim as usize);
        let (t, b) = refine_f64(ray.origin, ray.dir, v).unwrap_or((t_approx, [1.0 / 3.0; 3]));
        let p = b[0] * v[0] + b[1] * v[1] + b[2] * v[2];
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let mesh = &self.meshes[object as usize];
        let (mut ns, mut uv) = (ng, DVec2::ZERO);
        if mesh.normals.is_some() || mesh.uvs.is_some() {
            let idx = mesh.triangles[prim as usize];
            if let Some(normals) = &mesh.normals {
                let n = b[0] * normals[idx[0] as usize].as_dvec3()
                    + b[1] * normals[idx[1] as usize].as_dvec3()
                    + b[2] * normals[idx[2] as usize].as_dvec3();
                let n = n.normalize_or_zero();
                if n != DVec3::ZERO {
                    ns = if n.dot(ng) < 0.0 { -n } else { n };
                }
            }
            if let Some(uvs) = &mesh.uvs {
                uv = b[0] * uvs[idx[0] as usize].as_dvec2()
                    + b[1] * uvs[idx[1] as usize].as_dvec2()
                    + b[2] * uvs[idx[2] as usize].as_dvec2();
            }
        }
        let lo = v[0].min(v[1]).min(v[2]);
        let hi = v[0].max(v[1]).max(v[2]);
        // The f32 test sees the object in its local frame: the error scales with the
        // distance from the object's centre, not from the world origin.
        let p_error = OFFSET_REL * ((p - c).abs().max_element() + (hi - lo).max_element());
        Hit {
            t,
            p,
            ng,
            ns,
            uv,
            object,
            prim,
            bary: DVec2::new(b[1], b[2]),
            p_error,
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Crossing {
    t: f32,
    leaf: u32,
    front: bool,
}

/// Up to 32 crossings on the stack, then a heap vector.
struct CrossingBuf {
    inline: [Crossing; 32],
    n: usize,
    heap: Vec<Crossing>,
}

impl CrossingBuf {
    fn new() -> Self {
        Self {
            inline: [Crossing {
                t: 0.0,
                leaf: 0,
                front: false,
            }; 32],
            n: 0,
            heap: Vec::new(),
        }
    }
    #[inline]
    fn push(&mut self, c: Crossing) {
        if self.n < self.inline.len() {
            self.inline[self.n] = c;
            self.n += 1;
        } else {
            if self.heap.is_empty() {
                self.heap.extend_from_slice(&self.inline);
            }
            self.heap.push(c);
        }
    }
    fn sorted(&mut self) -> &[Crossing] {
        let s: &mut [Crossing] = if self.heap.is_empty() {
            &mut self.inline[..self.n]
        } else {
            &mut self.heap
        };
        s.sort_unstable_by(|a, b| a.t.total_cmp(&b.t));
        s
    }
}

/// Lines of one direction through an axis-aligned box ([`Geometry::box_crossing`]).
#[derive(Debug, Clone, Copy)]
struct BoxLine {
    lo: DVec3,
    hi: DVec3,
    /// The box's share of the decision margin (length).
    margin: f64,
    /// The unit direction, and its reciprocal unless the lines run parallel to a face.
    dir: DVec3,
    inv: Option<DVec3>,
}

impl BoxLine {
    /// The crossing of the line through `origin` nearest to `origin`.
    /// [`Projected::Undecided`]: a case the planes do not settle within the margin of the
    /// mesh's f32 triangles (the line grazes an edge or face, or the origin lies halfway
    /// between the two crossings). An origin on the surface (|t| within the margin) is a
    /// crossing here; tracing it is left to the caller.
    #[inline(always)]
    fn crossing(&self, origin: DVec3) -> Projected<BoxCrossing> {
        let (lo, hi, dir) = (self.lo, self.hi, self.dir);
        // Margin (length): the box's, and that of the origin's own precision.
        let m = self.margin + 1e-9 * origin.abs().max_element();
        let (t_in, axis_in, t_out, axis_out) = if let Some(inv) = self.inv {
            // The slab test on all three axes at once (the common case).
            let (t1, t2) = ((lo - origin) * inv, (hi - origin) * inv);
            let (near, far) = (t1.min(t2), t1.max(t2));
            (
                near.max_element(),
                near.max_position(),
                far.min_element(),
                far.min_position(),
            )
        } else {
            // The same test axis by axis, where an axis the lines run parallel to bounds
            // nothing (or misses). Kept apart from the common case above: one loop for both,
            // or masking the parallel axes out of the vector form, costs 2-3 % of a `sone`
            // render of the checker slab.
            let (mut t_in, mut t_out) = (f64::NEG_INFINITY, f64::INFINITY);
            let (mut axis_in, mut axis_out) = (0, 0);
            for a in 0..3 {
                if dir[a].abs() < 1e-12 {
                    // Parallel to this pair of planes: inside them, or a clear miss.
                    if origin[a] < lo[a] - m || origin[a] > hi[a] + m {
                        return Projected::Miss;
                    }
                    if origin[a] < lo[a] + m || origin[a] > hi[a] - m {
                        return Projected::Undecided;
                    }
                    continue;
                }
                let (t1, t2) = ((lo[a] - origin[a]) / dir[a], (hi[a] - origin[a]) / dir[a]);
                if t1.min(t2) > t_in {
                    (t_in, axis_in) = (t1.min(t2), a);
                }
                if t1.max(t2) < t_out {
                    (t_out, axis_out) = (t1.max(t2), a);
                }
            }
            (t_in, axis_in, t_out, axis_out)
        };
        if !(t_in.is_finite() && t_out.is_finite()) {
            return Projected::Undecided;
        }
        if t_in > t_out + m {
            return Projected::Miss;
        }
        if t_out - t_in < 4.0 * m {
            return Projected::Undecided;
        }
        let (near, far, axis, entering) = if t_in.abs() <= t_out.abs() {
            (t_in, t_out, axis_in, true)
        } else {
            (t_out, t_in, axis_out, false)
        };
        if far.abs() - near.abs() <= 2.0 * m {
            return Projected::Undecided;
        }
        // The line leaves the box along `dir` through the face whose outward normal has the
        // sign of dir[axis]; it enters through the opposite one.
        let sign = if (dir[axis] > 0.0) != entering {
            1.0
        } else {
            -1.0
        };
        Projected::At(BoxCrossing {
            t: near,
            margin: m,
            axis,
            sign,
            plane: if sign > 0.0 { hi[axis] } else { lo[axis] },
        })
    }

    /// The crossing's position, a hair inside its face
    /// ([`Geometry::project_position_onto_box`]).
    #[inline]
    fn position(&self, origin: DVec3) -> Projected {
        let c = match self.crossing(origin) {
            Projected::At(c) => c,
            Projected::Miss => return Projected::Miss,
            Projected::Undecided => return Projected::Undecided,
        };
        let mut p = (origin + c.t * self.dir).clamp(self.lo, self.hi);
        let hair = 1e-9 * (1.0 + p.abs().max_element());
        let on_face = c.plane - c.sign * hair;
        match c.axis {
            0 => p.x = on_face,
            1 => p.y = on_face,
            _ => p.z = on_face,
        }
        Projected::At(p)
    }
}

/// The nearer crossing of a line with a box ([`Geometry::box_crossing`]).
#[derive(Debug, Clone, Copy)]
struct BoxCrossing {
    /// Signed distance along the line.
    t: f64,
    /// The margin the crossing was settled with (length).
    margin: f64,
    /// The axis of the crossed face, and the sign of its outward normal on that axis.
    axis: usize,
    sign: f64,
    /// The face's coordinate on `axis`.
    plane: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives;

    #[test]
    fn simple_queries() {
        let g = Geometry::build(vec![
            primitives::cuboid(DVec3::splat(-1.0), DVec3::splat(1.0)),
            primitives::icosphere(DVec3::new(0.0, 0.0, 5.0), 1.0, 3),
        ]);
        assert_eq!(g.object_count(), 2);
        let r = Ray::new(DVec3::new(0.1, 0.2, 10.0), DVec3::NEG_Z);
        let h = g.intersect(&r).unwrap();
        assert_eq!(h.object, 1, "{h:?}");
        assert!(
            (h.p.z - 6.0).abs() < 0.05 && (h.t - (10.0 - h.p.z)).abs() < 1e-12,
            "{h:?}"
        );
        assert!(h.ng.z > 0.9 && h.ns.z > 0.9);
        let h0 = g.intersect_object(0, &r).unwrap();
        assert_eq!(h0.object, 0);
        assert!((h0.p.z - 1.0).abs() < 1e-12 && (h0.t - 9.0).abs() < 1e-12);
        assert!(h0.ng.abs_diff_eq(DVec3::Z, 1e-12));
        assert!(g.occluded(&r));
        assert!(!g.occluded(&Ray::segment(r.origin, r.dir, 3.0)));
        let mut ts = Vec::new();
        g.for_each_object_hit(0, &r, |h| ts.push(h.t));
        assert_eq!(ts.len(), 2);
        assert!((ts[0] - 9.0).abs() < 1e-12 && (ts[1] - 11.0).abs() < 1e-12);
        assert!(g.rays_traced() >= 5);
    }
}
