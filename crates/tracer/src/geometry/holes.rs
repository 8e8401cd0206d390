//! Closing the holes of a scanned mesh, so that it bounds a volume the path tracer can walk
//! (`render --method pt` needs closed translucent meshes). Used by `examples/close_holes.rs`,
//! which `scripts/fetch-bunny.sh` runs on the Stanford bunny (whose base has open holes).
//!
//! A hole is a loop of boundary edges (edges used by one triangle). Each loop is closed by a
//! fan of triangles around the mean of its vertices (a new vertex), wound opposite to the
//! boundary edges' own triangles so that the orientation stays consistent. This is the
//! simplest filling that makes every edge shared by exactly two triangles; it does not try to
//! follow the surface's curvature (a minimal-area or smooth fill would), which is fine for the
//! small, nearly planar holes of a scan.

use std::collections::HashMap;

use glam::{DVec3, Vec2, Vec3};

use super::mesh::TriangleMesh;

/// Fills every hole of `mesh` (see the module docs) and returns how many loops were closed.
/// Vertices are matched by exact position, so that a vertex duplicated for another normal or
/// texture coordinate does not open an edge. New vertices get the mean normal and texture
/// coordinate of their loop where the mesh has them. A mesh without holes is left unchanged.
pub fn fill_holes(mesh: &mut TriangleMesh) -> usize {
    // Weld by exact position: the first vertex of each position stands for all.
    let mut first: HashMap<[u64; 3], u32> = HashMap::new();
    let ids: Vec<u32> = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            *first
                .entry(p.to_array().map(f64::to_bits))
                .or_insert(i as u32)
        })
        .collect();
    // Uses of each undirected edge, and the direction of the last use.
    let mut uses: HashMap<(u32, u32), (u32, (u32, u32))> = HashMap::new();
    for t in &mesh.triangles {
        let w = t.map(|k| ids[k as usize]);
        for k in 0..3 {
            let (a, b) = (w[k], w[(k + 1) % 3]);
            if a == b {
                continue;
            }
            let e = uses.entry((a.min(b), a.max(b))).or_insert((0, (a, b)));
            e.0 += 1;
            e.1 = (a, b);
        }
    }
    // A boundary edge a → b (one use) is walked b → a by the hole's loop.
    let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut boundary: Vec<(u32, u32)> = uses
        .values()
        .filter(|(n, _)| *n == 1)
        .map(|&(_, (a, b))| (b, a))
        .collect();
    boundary.sort_unstable();
    for &(from, to) in &boundary {
        next.entry(from).or_default().push(to);
    }
    let mut filled = 0;
    for &(start, _) in &boundary {
        // Walk from `start`, taking unused edges. Where the walk comes back to a vertex it has
        // passed (two holes meeting at a vertex), the loop since then is closed on its own, so
        // that no fan uses one vertex twice (which would give its edges to the fan's centre
        // four triangles).
        let mut lp = vec![start];
        let mut at = start;
        while let Some(to) = next.get_mut(&at).and_then(Vec::pop) {
            if let Some(j) = lp.iter().position(|&v| v == to) {
                // At least 3 long: a loop of 2 would use one edge in both directions, which
                // is then used twice and not a boundary edge.
                close_loop(mesh, &lp[j..]);
                filled += 1;
                lp.truncate(j + 1);
            } else {
                lp.push(to);
            }
            at = to;
        }
    }
    filled
}

/// Adds the fan of triangles closing the loop `lp` (vertex indices in walking order).
fn close_loop(mesh: &mut TriangleMesh, lp: &[u32]) {
    let n = lp.len();
    if n == 3 {
        mesh.triangles.push([lp[0], lp[1], lp[2]]);
        return;
    }
    let centre = lp
        .iter()
        .map(|&i| mesh.positions[i as usize])
        .sum::<DVec3>()
        / n as f64;
    let c = mesh.positions.len() as u32;
    mesh.positions.push(centre);
    if let Some(normals) = &mut mesh.normals {
        let sum: Vec3 = lp.iter().map(|&i| normals[i as usize]).sum();
        normals.push(sum.normalize_or_zero());
    }
    if let Some(uvs) = &mut mesh.uvs {
        let sum: Vec2 = lp.iter().map(|&i| uvs[i as usize]).sum();
        uvs.push(sum / n as f32);
    }
    for k in 0..n {
        mesh.triangles.push([lp[k], lp[(k + 1) % n], c]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitives;

    /// `mesh` without the triangles at `drop` (indices into its triangle list).
    fn without(mut mesh: TriangleMesh, drop: &[usize]) -> TriangleMesh {
        let mut k = 0;
        mesh.triangles.retain(|_| {
            k += 1;
            !drop.contains(&(k - 1))
        });
        mesh
    }

    /// A cube without its top face (a quad hole), and an icosphere with holes where five
    /// triangles were, become closed and consistently oriented:
    /// the topology report says so, and the enclosed volume is close to the solid's.
    #[test]
    fn holes_are_closed_with_consistent_orientation() {
        let cube = primitives::cuboid(DVec3::ZERO, DVec3::ONE);
        let full = cube.topology();
        assert!(full.is_closed());
        // Find the two triangles of the top face (z = 1 at every corner).
        let top: Vec<usize> = (0..cube.triangles.len())
            .filter(|&i| {
                cube.triangles[i]
                    .iter()
                    .all(|&v| cube.positions[v as usize].z == 1.0)
            })
            .collect();
        assert_eq!(top.len(), 2);
        let mut open = without(cube, &top);
        assert!(!open.topology().is_closed());
        assert_eq!(fill_holes(&mut open), 1);
        let r = open.topology();
        assert!(r.is_closed(), "{r:?}");
        assert!((r.signed_volume.abs() - 1.0).abs() < 1e-12, "{r:?}");
        // Nothing left to fill.
        let before = open.clone();
        assert_eq!(fill_holes(&mut open), 0);
        assert_eq!(open, before);

        let ball = primitives::icosphere(DVec3::ZERO, 1.0, 2);
        let volume = ball.topology().signed_volume;
        let mut open = without(ball, &[0, 40, 41, 150, 151]);
        let holes = open.topology().boundary_edges;
        assert!(holes > 0);
        let filled = fill_holes(&mut open);
        assert!((1..=5).contains(&filled), "{filled} loops");
        let r = open.topology();
        assert!(r.is_closed(), "{r:?}");
        assert!(
            (r.signed_volume - volume).abs() < 0.01 * volume.abs(),
            "{} vs {volume}",
            r.signed_volume
        );
    }

    /// Two holes that meet at one vertex (two removed triangles sharing a corner, no edge):
    /// the walk comes back to that vertex, and each hole is closed on its own. Every such pair
    /// around the first 20 triangles, so that the walk meets both orders of the two holes'
    /// edges at the shared vertex.
    #[test]
    fn holes_meeting_at_a_vertex_are_closed_separately() {
        let ball = primitives::icosphere(DVec3::ZERO, 1.0, 2);
        let t = &ball.triangles;
        let shared = |a: usize, b: usize| t[a].iter().filter(|v| t[b].contains(v)).count();
        let mut pairs = 0;
        for first in 0..20 {
            for other in (first + 1..t.len()).filter(|&j| shared(first, j) == 1) {
                let mut open = without(ball.clone(), &[first, other]);
                assert_eq!(fill_holes(&mut open), 2, "{first}, {other}");
                let r = open.topology();
                assert!(r.is_closed(), "{first}, {other}: {r:?}");
                assert_eq!(r.triangles, ball.triangles.len());
                pairs += 1;
            }
        }
        assert!(pairs > 50, "{pairs}");
    }
}
