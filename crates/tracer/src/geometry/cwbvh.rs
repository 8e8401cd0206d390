//! The 8-wide obvhs tree (CWBVH) as both levels of [`super::Geometry`] build and query it:
//! each object's tree over its triangles' padded boxes ([`super::bvh`]) and the top-level tree
//! over the objects' boxes ([`super::tlas`]).

use glam::DVec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::ploc::PlocBuilder;
use obvhs::{Boundable, BvhBuildParams};

/// A triangle's padded bounding box, what the BVH is built on.
pub(super) struct PaddedBox(pub(super) Aabb);

impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// `1/x` for the BVH node test, finite and with the sign convention of obvhs's octant test
/// (`x < 0` ⇔ negative inverse; `±0` → `+1e30`).
#[inline]
pub(super) fn safe_inv(x: f32) -> f32 {
    if x == 0.0 {
        1e30
    } else {
        (1.0 / x).clamp(-1e30, 1e30)
    }
}

/// Builds the CWBVH as obvhs's `cwbvh::builder::build_cwbvh` helper does (PLOC, reinsertion,
/// conversion to the 8-wide tree), minus the helper's `validate()` in debug builds: that check
/// asserts node quantisation origins within an absolute 1e-5 of their parent's bounds, below
/// f32 resolution at the scaled coordinates used here (up to ~4e3, ulp 2.4e-4), and it panicked
/// on valid scenes when debug assertions are on (found by the scene fuzzer,
/// `tests/fuzz_regressions.rs`). The origins' rounding is harmless: children are quantised
/// conservatively relative to them. The BVH is checked against brute force in the tests.
pub(super) fn build_cwbvh(boxes: &[PaddedBox], config: BvhBuildParams) -> CwBvh {
    let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
        config.ploc_search_distance,
        boxes,
        (0..boxes.len() as u32).collect(),
        config.sort_precision,
        config.search_depth_threshold,
    );
    ReinsertionOptimizer::default().run(&mut bvh2, config.reinsertion_batch_ratio, None);
    bvh2_to_cwbvh(&bvh2, config.max_prims_per_leaf.clamp(1, 3), true, false)
}

/// Entry distance of the ray into `[lo, hi]` within `[t_min, t_max]`, if it enters.
#[inline]
pub(super) fn slab(
    lo: DVec3,
    hi: DVec3,
    origin: DVec3,
    inv_dir: DVec3,
    t_min: f64,
    t_max: f64,
) -> Option<f64> {
    let t0 = (lo - origin) * inv_dir;
    let t1 = (hi - origin) * inv_dir;
    let near = t0.min(t1);
    let far = t0.max(t1);
    // NaN (0 · inf) components are ignored by max/min of f64 (they return the other).
    let enter = near.max_element().max(t_min);
    let exit = far.min_element().min(t_max);
    (enter <= exit).then_some(enter)
}
