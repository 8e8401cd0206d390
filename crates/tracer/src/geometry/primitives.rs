//! Generated meshes: boxes (optionally with subdivided faces), icospheres, the "half-space"
//! slab and quads. Every closed primitive is watertight (shared edges have bit-identical
//! vertices) and oriented outward.

use std::collections::HashMap;

use glam::{DVec3, Vec2};

use super::TriangleMesh;

/// An axis-aligned box with corners `min` and `max`, 12 triangles, outward winding, per-face
/// texture coordinates in `[0, 1]²`.
pub fn cuboid(min: DVec3, max: DVec3) -> TriangleMesh {
    subdivided_cuboid(min, max, [1, 1, 1])
}

/// An axis-aligned box whose faces are grids: `n[a]` segments along axis `a` (each ≥ 1). The
/// grid coordinates along an axis are computed by one formula for every face, so shared edges
/// match exactly and the mesh is closed. Per-face texture coordinates in `[0, 1]²`.
///
/// Subdividing keeps triangles small, which keeps the ray-origin offset small (it scales with
/// the triangle's extent, see [`super::Hit::p_error`]).
pub fn subdivided_cuboid(min: DVec3, max: DVec3, n: [u32; 3]) -> TriangleMesh {
    let n = n.map(|k| k.max(1));
    let coord = |axis: usize, k: u32| -> f64 {
        if k == 0 {
            min[axis]
        } else if k == n[axis] {
            max[axis]
        } else {
            min[axis] + (max[axis] - min[axis]) * (k as f64 / n[axis] as f64)
        }
    };
    let mut mesh = TriangleMesh {
        uvs: Some(Vec::new()),
        ..Default::default()
    };
    for a in 0..3 {
        // (b, c) cyclic after a, so that e_b × e_c = e_a.
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for (side, outward_positive) in [(min[a], false), (max[a], true)] {
            let base = mesh.positions.len() as u32;
            let (nb, nc) = (n[b], n[c]);
            for j in 0..=nc {
                for i in 0..=nb {
                    let mut p = DVec3::ZERO;
                    p[a] = side;
                    p[b] = coord(b, i);
                    p[c] = coord(c, j);
                    mesh.positions.push(p);
                    mesh.uvs
                        .as_mut()
                        .unwrap()
                        .push(Vec2::new(i as f32 / nb as f32, j as f32 / nc as f32));
                }
            }
            let idx = |i: u32, j: u32| base + j * (nb + 1) + i;
            for j in 0..nc {
                for i in 0..nb {
                    let (q0, q1, q2, q3) =
                        (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
                    if outward_positive {
                        mesh.triangles.push([q0, q1, q2]);
                        mesh.triangles.push([q0, q2, q3]);
                    } else {
                        mesh.triangles.push([q0, q2, q1]);
                        mesh.triangles.push([q0, q3, q2]);
                    }
                }
            }
        }
    }
    mesh
}

/// A large box standing in for a semi-infinite medium: its top face is the plane `z = top`,
/// spanning `[cx − size/2, cx + size/2] × [cy − size/2, cy + size/2]`, and it extends `depth`
/// below. The top face is a `subdivisions × subdivisions` grid (the sides match it) so that
/// triangles stay small (see [`subdivided_cuboid`]).
pub fn half_space(
    top: f64,
    centre_xy: [f64; 2],
    size: f64,
    depth: f64,
    subdivisions: u32,
) -> TriangleMesh {
    let h = 0.5 * size;
    subdivided_cuboid(
        DVec3::new(centre_xy[0] - h, centre_xy[1] - h, top - depth),
        DVec3::new(centre_xy[0] + h, centre_xy[1] + h, top),
        [subdivisions, subdivisions, 1],
    )
}

/// A sphere of radius `radius` about `centre`: an icosahedron whose faces are split
/// `subdivisions` times (20·4^s triangles; s = 6 gives 81,920), vertices projected onto the
/// sphere, radial unit normals, no texture coordinates.
pub fn icosphere(centre: DVec3, radius: f64, subdivisions: u32) -> TriangleMesh {
    let (dirs, triangles) = unit_icosphere(subdivisions);
    TriangleMesh {
        positions: dirs.iter().map(|d| centre + radius * *d).collect(),
        normals: Some(dirs.iter().map(|d| d.as_vec3()).collect()),
        uvs: None,
        triangles,
    }
}

fn unit_icosphere(subdivisions: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::with_capacity(f.len() * 3 / 2);
        let mut next = Vec::with_capacity(f.len() * 4);
        let mut midpoint = |a: u32, b: u32, v: &mut Vec<DVec3>| -> u32 {
            let key = (a.min(b), a.max(b));
            *mid.entry(key).or_insert_with(|| {
                v.push((v[a as usize] + v[b as usize]).normalize());
                (v.len() - 1) as u32
            })
        };
        for [a, b, c] in f {
            let ab = midpoint(a, b, &mut v);
            let bc = midpoint(b, c, &mut v);
            let ca = midpoint(c, a, &mut v);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    (v, f)
}

/// A one-sided quad `corner + s·edge_u + t·edge_v`, `s, t ∈ [0, 1]`, as two triangles whose
/// geometric normal is `edge_u × edge_v`; texture coordinates `(s, t)`.
pub fn quad(corner: DVec3, edge_u: DVec3, edge_v: DVec3) -> TriangleMesh {
    let p = [
        corner,
        corner + edge_u,
        corner + edge_u + edge_v,
        corner + edge_v,
    ];
    TriangleMesh {
        positions: p.to_vec(),
        normals: None,
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ]),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_closedness() {
        let s = icosphere(DVec3::ZERO, 1.0, 3);
        assert_eq!(s.triangles.len(), 20 * 64);
        let r = s.topology();
        assert!(r.is_closed() && r.signed_volume > 0.0, "{r:?}");
        // Volume approaches 4π/3 from below.
        assert!(r.signed_volume < 4.0 / 3.0 * std::f64::consts::PI && r.signed_volume > 4.0);

        let b = subdivided_cuboid(DVec3::splat(-1.0), DVec3::new(2.0, 1.0, 0.5), [3, 4, 5]);
        assert_eq!(b.triangles.len(), 2 * 2 * (3 * 4 + 4 * 5 + 5 * 3));
        let r = b.topology();
        assert!(r.is_closed(), "{r:?}");
        assert!((r.signed_volume - 3.0 * 2.0 * 1.5).abs() < 1e-9);

        let h = half_space(0.0, [0.0, 0.0], 100.0, 50.0, 8);
        let r = h.topology();
        assert!(r.is_closed());
        assert_eq!(h.bounds().1.z, 0.0);

        let q = quad(DVec3::ZERO, DVec3::X, DVec3::Y);
        let r = q.topology();
        assert_eq!(r.boundary_edges, 4);
        let [a, b, c] = q.triangle_vertices(0);
        assert!(
            (b - a)
                .cross(c - a)
                .normalize()
                .abs_diff_eq(DVec3::Z, 1e-12)
        );
    }
}
