//! The closest point of a triangle mesh to a point of space: what defines a UV-painted medium
//! inside its body for the path tracer (σ(x) = texture(uv(closest(x))),
//! [`crate::field::MediumField::with_interior`]).
//!
//! A binary tree of f64 boxes over the triangles (median split of the centroids along the
//! longest axis, up to 4 triangles a leaf), searched depth first, nearer child first,
//! a subtree skipped when its box is no nearer than the best point so far. The point of one
//! triangle nearest to a query is Ericson's region test (ERI05: "Real-Time Collision
//! Detection", §5.1.5), which also gives its barycentrics.

use glam::DVec3;

use super::TriangleMesh;

/// Most triangles in a leaf.
const LEAF: usize = 4;

/// The nearest point of a mesh: its triangle (index in the mesh), barycentrics of vertices
/// 1 and 2 (`p = (1 − b1 − b2)·v0 + b1·v1 + b2·v2`) and squared distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// Triangle index in the mesh.
    pub prim: u32,
    /// Barycentrics `(b1, b2)`.
    pub bary: [f64; 2],
    /// The point (scene units).
    pub point: DVec3,
    /// Squared distance from the query.
    pub dist2: f64,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Inner node: index of the first child (the second follows it); leaf: first triangle in
    /// `order`.
    first: u32,
    /// 0 for an inner node, else the leaf's triangle count.
    count: u32,
}

/// A closest-point tree over one mesh's triangles.
#[derive(Debug, Clone)]
pub struct ClosestPointTree {
    nodes: Vec<Node>,
    /// Triangle indices in leaf order.
    order: Vec<u32>,
    /// Vertices of each triangle (mesh order).
    tris: Vec<[DVec3; 3]>,
}

impl ClosestPointTree {
    /// The tree over `mesh`'s triangles (O(n log n)).
    pub fn new(mesh: &TriangleMesh) -> Self {
        let tris: Vec<[DVec3; 3]> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle_vertices(i))
            .collect();
        let centroids: Vec<DVec3> = tris.iter().map(|t| (t[0] + t[1] + t[2]) / 3.0).collect();
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
        nodes.push(Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            first: 0,
            count: 0,
        });
        // (node, range) still to split.
        let mut todo = vec![(0usize, 0usize, order.len())];
        while let Some((node, start, end)) = todo.pop() {
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for &t in &order[start..end] {
                for v in tris[t as usize] {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            if end - start <= LEAF {
                nodes[node] = Node {
                    lo,
                    hi,
                    first: start as u32,
                    count: (end - start) as u32,
                };
                continue;
            }
            let (mut clo, mut chi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for &t in &order[start..end] {
                clo = clo.min(centroids[t as usize]);
                chi = chi.max(centroids[t as usize]);
            }
            let axis = (chi - clo).max_position();
            let mid = (start + end) / 2;
            order[start..end].select_nth_unstable_by(mid - start, |a, b| {
                centroids[*a as usize][axis].total_cmp(&centroids[*b as usize][axis])
            });
            let first = nodes.len();
            let blank = Node {
                lo: DVec3::ZERO,
                hi: DVec3::ZERO,
                first: 0,
                count: 0,
            };
            nodes.push(blank);
            nodes.push(blank);
            nodes[node] = Node {
                lo,
                hi,
                first: first as u32,
                count: 0,
            };
            todo.push((first, start, mid));
            todo.push((first + 1, mid, end));
        }
        Self { nodes, order, tris }
    }

    /// The point of the mesh nearest to `p`; `None` for an empty mesh or a point that is not
    /// finite.
    pub fn nearest(&self, p: DVec3) -> Option<Nearest> {
        if self.tris.is_empty() || !p.is_finite() {
            return None;
        }
        let mut best: Option<Nearest> = None;
        let mut best_d2 = f64::INFINITY;
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if box_dist2(&node, p) >= best_d2 {
                continue;
            }
            if node.count > 0 {
                let s = node.first as usize;
                for &t in &self.order[s..s + node.count as usize] {
                    let (q, bary) = closest_on_triangle(p, &self.tris[t as usize]);
                    let d2 = (q - p).length_squared();
                    if d2 < best_d2 {
                        best_d2 = d2;
                        best = Some(Nearest {
                            prim: t,
                            bary,
                            point: q,
                            dist2: d2,
                        });
                    }
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let (da, db) = (
                box_dist2(&self.nodes[a as usize], p),
                box_dist2(&self.nodes[b as usize], p),
            );
            // Nearer child on top of the stack (searched first).
            let (near, far) = if da <= db { (a, b) } else { (b, a) };
            if top + 2 > stack.len() {
                // Deeper than any balanced tree of 2^63 leaves: cannot happen with median
                // splits; search the nearer child only rather than overflow.
                stack[top] = near;
                top += 1;
                continue;
            }
            stack[top] = far;
            stack[top + 1] = near;
            top += 2;
        }
        best
    }
}

/// Squared distance from `p` to the node's box (0 inside).
#[inline]
fn box_dist2(n: &Node, p: DVec3) -> f64 {
    let d = (n.lo - p).max(p - n.hi).max(DVec3::ZERO);
    d.length_squared()
}

/// The point of triangle `t` nearest to `p` and its barycentrics `(b1, b2)` (ERI05 §5.1.5).
fn closest_on_triangle(p: DVec3, t: &[DVec3; 3]) -> (DVec3, [f64; 2]) {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom == 0.0 {
        // A degenerate triangle: its first vertex.
        return (a, [0.0, 0.0]);
    }
    let (v, w) = (vb / denom, vc / denom);
    (a + ab * v + ac * w, [v, w])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives;

    /// Against a brute-force scan of every triangle, at points inside, on and outside an
    /// icosphere and a box; the barycentrics give the point.
    #[test]
    fn nearest_matches_brute_force() {
        for mesh in [
            primitives::icosphere(DVec3::new(0.5, -1.0, 2.0), 2.0, 3),
            primitives::subdivided_cuboid(DVec3::ZERO, DVec3::new(3.0, 1.0, 2.0), [3, 2, 2]),
        ] {
            let tree = ClosestPointTree::new(&mesh);
            for k in 0..500 {
                let t = k as f64;
                let p = DVec3::new(
                    3.0 * (0.37 * t).sin(),
                    3.0 * (0.71 * t).cos() - 0.5,
                    2.0 + 3.0 * (1.13 * t).sin(),
                );
                let got = tree.nearest(p).unwrap();
                let want = (0..mesh.triangle_count())
                    .map(|i| {
                        let (q, _) = closest_on_triangle(p, &mesh.triangle_vertices(i));
                        (q - p).length_squared()
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!((got.dist2 - want).abs() <= 1e-12 * (1.0 + want), "{k}");
                let v = mesh.triangle_vertices(got.prim as usize);
                let [b1, b2] = got.bary;
                let q = (1.0 - b1 - b2) * v[0] + b1 * v[1] + b2 * v[2];
                assert!((q - got.point).length() < 1e-12, "{k}");
            }
        }
        assert!(
            ClosestPointTree::new(&TriangleMesh::new(vec![], vec![]))
                .nearest(DVec3::ZERO)
                .is_none()
        );
    }
}
