//! The top-level BVH over objects, so that the all-object queries
//! ([`super::Geometry::intersect`], [`super::Geometry::occluded`]) visit only the objects whose
//! boxes the ray crosses instead of looping over all of them.
//!
//! It is the same 8-wide obvhs tree as each object's, built over the objects' boxes: a ray
//! through 1000 objects visits about four levels instead of a binary tree's ten, which is what
//! keeps the cost of many objects close to that of a few (`cargo bench --bench tracing --
//! objects`). Leaves hold one object each.
//!
//! # Precision
//! The tree lives in its own `f32` frame, like an object's: coordinates relative to the centre
//! of all the boxes, scaled by a power of two so that the scene's extent is about 2¹², and
//! boxes padded by [`BOX_PAD_REL`] of that extent and rounded outward. A ray that starts far
//! from the scene first moves its origin in `f64` to one extent before the scene's box, so that
//! its `f32` origin is as precise as that of a ray inside it. The tree only culls: each object
//! it reaches is tested once more in `f64` against its exact padded box (`slab`), which gives
//! the entry distance the object's own test starts from. So the tree culls nothing that the
//! per-object test would keep, whatever the distance from the origin (tested to 1e6,
//! `tests/tracer`).

use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as BvhRay, RayHit};

use super::cwbvh::{PaddedBox, build_cwbvh, safe_inv, slab};

/// Target extent of the scene in the tree's scaled space: 2¹², as for objects.
const SCALED_EXTENT_LOG2: i32 = 12;
/// Object boxes are padded by this fraction of the scene's extent (2⁻¹⁶, as triangles are in
/// an object's tree), which covers the non-conservative rounding of obvhs's slab test for rays
/// that start within tens of extents of the scene.
const BOX_PAD_REL: f64 = 1.0 / 65536.0;

/// The tree (see the module docs).
#[derive(Debug, Default)]
pub(crate) struct Tlas {
    bvh: Option<CwBvh>,
    /// Object of each of the tree's primitives.
    objects: Vec<u32>,
    /// Exact padded box of each of the tree's primitives (world units).
    boxes: Vec<(DVec3, DVec3)>,
    /// The scene's padded box (world units).
    lo: DVec3,
    hi: DVec3,
    centre: DVec3,
    scale: f64,
}

/// `x` rounded to `f32` toward −∞ (`down`) or +∞.
fn round_f32(x: f64, down: bool) -> f32 {
    let r = x as f32;
    match (down, f64::from(r)) {
        (true, v) if v > x => r.next_down(),
        (false, v) if v < x => r.next_up(),
        _ => r,
    }
}

impl Tlas {
    /// Builds the tree over `boxes[i] = (lo, hi)` (already padded, finite) of the objects
    /// `ids`.
    pub fn build(boxes: &[(DVec3, DVec3)], ids: Vec<u32>) -> Self {
        if ids.is_empty() {
            return Tlas::default();
        }
        let (lo, hi) = ids.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &o| (lo.min(boxes[o as usize].0), hi.max(boxes[o as usize].1)),
        );
        let centre = 0.5 * (lo + hi);
        let extent = (hi - lo).max_element();
        let scale = if extent > 0.0 && extent.is_finite() {
            2f64.powi((SCALED_EXTENT_LOG2 - extent.log2().ceil() as i32).clamp(-120, 120))
        } else {
            1.0
        };
        let pad = BOX_PAD_REL * extent.max(f64::MIN_POSITIVE) * scale;
        let scaled: Vec<PaddedBox> = ids
            .iter()
            .map(|&o| {
                let (blo, bhi) = boxes[o as usize];
                let a = (blo - centre) * scale - pad;
                let b = (bhi - centre) * scale + pad;
                PaddedBox(Aabb::new(
                    Vec3A::from_array(std::array::from_fn(|k| round_f32(a[k], true))),
                    Vec3A::from_array(std::array::from_fn(|k| round_f32(b[k], false))),
                ))
            })
            .collect();
        let bvh = build_cwbvh(&scaled, BvhBuildParams::medium_build());
        let objects: Vec<u32> = bvh
            .primitive_indices
            .iter()
            .map(|&i| ids[i as usize])
            .collect();
        let boxes = objects.iter().map(|&o| boxes[o as usize]).collect();
        Tlas {
            bvh: Some(bvh),
            objects,
            boxes,
            lo,
            hi,
            centre,
            scale,
        }
    }

    /// Visits, nearest box first as far as the tree can order them, every object whose box
    /// the ray enters within `[t_min, t_max]`, where `visit(object, t_enter, t_max)`
    /// (`t_enter`: where the ray enters the object's box) returns the (possibly shrunk)
    /// `t_max`, or `None` to stop the traversal.
    #[inline]
    pub fn traverse(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_min: f64,
        mut t_max: f64,
        mut visit: impl FnMut(u32, f64, f64) -> Option<f64>,
    ) {
        let Some(bvh) = self.bvh.as_ref() else {
            return;
        };
        let inv = DVec3::ONE / dir;
        // One object (a medium alone, as in most validation scenes): its exact box is the
        // whole tree, so skip the tree.
        if let [object] = self.objects[..] {
            let (lo, hi) = self.boxes[0];
            if let Some(enter) = slab(lo, hi, origin, inv, t_min, t_max) {
                visit(object, enter, t_max);
            }
            return;
        }
        let Some(enter) = slab(self.lo, self.hi, origin, inv, t_min, t_max) else {
            return;
        };
        // Move a far origin to one extent before the scene's box (see the module docs).
        let extent = (self.hi - self.lo).max_element();
        let shift = (enter - extent).max(0.0);
        let o = ((origin + shift * dir - self.centre) * self.scale).as_vec3a();
        let d = dir.as_vec3a();
        let to_tree = |t: f64| ((t - shift) * self.scale).min(f64::from(f32::MAX)) as f32;
        let ray = BvhRay {
            origin: o,
            direction: d,
            inv_direction: Vec3A::new(safe_inv(d.x), safe_inv(d.y), safe_inv(d.z)),
            tmin: to_tree(t_min).max(0.0),
            tmax: to_tree(t_max).next_up(),
        };
        let mut hit = RayHit::none();
        bvh.ray_traverse(ray, &mut hit, |_, id| {
            let (lo, hi) = self.boxes[id];
            let Some(enter) = slab(lo, hi, origin, inv, t_min, t_max) else {
                return f32::INFINITY;
            };
            match visit(self.objects[id], enter, t_max) {
                // Shrink the tree's ray only when the object shrank ours, rounded up so that
                // nothing nearer than the new t_max is culled.
                Some(t) if t < t_max => {
                    t_max = t;
                    to_tree(t).next_up()
                }
                Some(_) => f32::INFINITY,
                // Stop: an empty interval ends the traversal.
                None => f32::NEG_INFINITY,
            }
        });
    }
}
