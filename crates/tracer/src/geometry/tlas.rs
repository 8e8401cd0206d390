//! The top-level BVH over objects: a binary tree of `f64` bounding boxes whose leaves hold a
//! few objects each, so that the all-object queries ([`super::Geometry::intersect`],
//! [`super::Geometry::occluded`]) visit only the objects whose boxes the ray crosses instead of
//! looping over all of them. Built by median splits of the box centres along the widest axis;
//! traversed front to back with an explicit stack, shrinking the ray as hits are found.
//!
//! `f64` throughout and boxes padded like the per-object box test, so the tree culls nothing
//! that the per-object test would keep, whatever the distance from the origin.

use glam::DVec3;

/// Objects per leaf: one, so that a leaf's box is its object's and the object needs no box
/// test of its own.
const LEAF_OBJECTS: usize = 1;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: `count > 0`, objects `order[first..first + count]`. Inner: children `first` and
    /// `first + 1`.
    first: u32,
    count: u32,
}

/// The tree (see the module docs).
#[derive(Debug, Default)]
pub(crate) struct Tlas {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

/// Entry distance of the ray into `[lo, hi]` within `[t_min, t_max]`, if it enters.
#[inline]
pub(crate) fn slab(
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

impl Tlas {
    /// Builds the tree over `boxes[i] = (lo, hi)` (already padded) of the objects `ids`.
    pub fn build(boxes: &[(DVec3, DVec3)], ids: Vec<u32>) -> Self {
        let mut t = Tlas {
            nodes: Vec::with_capacity(2 * ids.len().max(1)),
            order: ids,
        };
        if t.order.is_empty() {
            return t;
        }
        t.nodes.push(Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            first: 0,
            count: 0,
        });
        let n = t.order.len();
        t.split(0, 0, n, boxes);
        t
    }

    fn split(&mut self, node: usize, first: usize, count: usize, boxes: &[(DVec3, DVec3)]) {
        let objs = &mut self.order[first..first + count];
        let (lo, hi) = objs.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &o| (lo.min(boxes[o as usize].0), hi.max(boxes[o as usize].1)),
        );
        self.nodes[node].lo = lo;
        self.nodes[node].hi = hi;
        if count <= LEAF_OBJECTS {
            self.nodes[node].first = first as u32;
            self.nodes[node].count = count as u32;
            return;
        }
        let centre = |o: u32| boxes[o as usize].0 + boxes[o as usize].1;
        let (clo, chi) = objs.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &o| (lo.min(centre(o)), hi.max(centre(o))),
        );
        let axis = (chi - clo).max_position();
        let mid = count / 2;
        objs.select_nth_unstable_by(mid, |&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]));
        let left = self.nodes.len();
        let empty = Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            first: 0,
            count: 0,
        };
        self.nodes.push(empty);
        self.nodes.push(empty);
        self.nodes[node].first = left as u32;
        self.split(left, first, mid, boxes);
        self.split(left + 1, first + mid, count - mid, boxes);
    }

    /// Visits, nearest box first, every object whose box the ray enters within
    /// `[t_min, t_max]`, where `visit(object, t_enter, t_max)` (`t_enter`: where the ray enters
    /// the object's box) returns the (possibly shrunk) `t_max`, or `None` to stop the
    /// traversal.
    #[inline]
    pub fn traverse(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_min: f64,
        mut t_max: f64,
        mut visit: impl FnMut(u32, f64, f64) -> Option<f64>,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = DVec3::ONE / dir;
        // Nodes to visit with their entry distances; each box is tested once, when pushed.
        let mut stack = [(0u32, 0f64); 64];
        let root = &self.nodes[0];
        let Some(enter) = slab(root.lo, root.hi, origin, inv, t_min, t_max) else {
            return;
        };
        stack[0] = (0, enter);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (index, enter) = stack[top];
            if enter > t_max {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for &o in &self.order[first..first + node.count as usize] {
                    match visit(o, enter, t_max) {
                        Some(t) => t_max = t,
                        None => return,
                    }
                }
                continue;
            }
            let (a, b) = (node.first as usize, node.first as usize + 1);
            let ta = slab(
                self.nodes[a].lo,
                self.nodes[a].hi,
                origin,
                inv,
                t_min,
                t_max,
            );
            let tb = slab(
                self.nodes[b].lo,
                self.nodes[b].hi,
                origin,
                inv,
                t_min,
                t_max,
            );
            // Push the farther child first so that the nearer one is visited first.
            let (near, far) = match (ta, tb) {
                (Some(x), Some(y)) if y < x => ((b, Some(y)), (a, Some(x))),
                _ => ((a, ta), (b, tb)),
            };
            for (child, t) in [far, near] {
                if let Some(t) = t
                    && top < stack.len()
                {
                    stack[top] = (child as u32, t);
                    top += 1;
                }
            }
        }
    }
}
