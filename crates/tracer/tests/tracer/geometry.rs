//! BVH queries against brute force, watertightness, crossings, counters.

use glam::DVec3;
use rayon::prelude::*;
use tracer::geometry::{Geometry, Ray, TriangleMesh, primitives};
use tracer::rng::Rng;

use crate::common::{brute_triangle, random_dir};

/// A scene of several objects: a sphere, a box, a soup of random triangles (open, overlapping).
fn test_geometry() -> Geometry {
    let mut rng = Rng::from_keys(11, &[]);
    let mut soup = TriangleMesh::default();
    for k in 0..300u32 {
        let c = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
        for _ in 0..3 {
            let p = c + 0.4 * (DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5);
            soup.positions.push(p);
        }
        soup.triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    Geometry::build(vec![
        primitives::icosphere(DVec3::new(0.3, -0.2, 0.1), 1.1, 3),
        primitives::cuboid(DVec3::new(-2.5, -2.5, -2.5), DVec3::new(-1.0, 2.5, -1.5)),
        soup,
    ])
}

/// Brute-force closest hit: `(object, prim, t, margin)` where margin is the smallest
/// barycentric of the hit (how far from an edge).
fn brute_closest(g: &Geometry, only: Option<u32>, ray: &Ray) -> Option<(u32, u32, f64)> {
    let mut best: Option<(u32, u32, f64)> = None;
    for obj in 0..g.object_count() as u32 {
        if only.is_some_and(|o| o != obj) {
            continue;
        }
        let m = g.mesh(obj);
        for i in 0..m.triangles.len() {
            let v = m.triangle_vertices(i);
            if let Some(t) = brute_triangle(ray.origin, ray.dir, v, ray.t_min, ray.t_max)
                && best.is_none_or(|b| t < b.2)
            {
                best = Some((obj, i as u32, t));
            }
        }
    }
    best
}

/// True when the ray passes within `eps` (relative barycentric) of an edge of `v`: the
/// f32 and f64 tests may then legitimately disagree.
fn near_edge(ray: &Ray, v: [DVec3; 3], eps: f64) -> bool {
    // Barycentrics of the ray/plane intersection.
    let n = (v[1] - v[0]).cross(v[2] - v[0]);
    let denom = n.dot(ray.dir);
    if denom.abs() < 1e-12 * n.length() {
        return true;
    }
    let t = n.dot(v[0] - ray.origin) / denom;
    let p = ray.at(t);
    let area = n.length_squared();
    let b1 = (p - v[0]).cross(v[2] - v[0]).dot(n) / area;
    let b2 = (v[1] - v[0]).cross(p - v[0]).dot(n) / area;
    let b0 = 1.0 - b1 - b2;
    b0.abs() < eps || b1.abs() < eps || b2.abs() < eps
}

/// A ray from a random point of [-4, 4]³ toward a random point of [-2, 2]³.
fn random_ray(rng: &mut Rng) -> Ray {
    let o = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 8.0 - 4.0;
    let target = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
    Ray::new(o, (target - o).normalize())
}

#[test]
fn closest_hit_matches_brute_force() {
    let g = test_geometry();
    let mut rng = Rng::from_keys(12, &[]);
    let (mut hits, mut ambiguous) = (0, 0);
    for _ in 0..3000 {
        let ray = random_ray(&mut rng);
        for only in [None, Some(0), Some(2)] {
            let fast = match only {
                None => g.intersect(&ray),
                Some(o) => g.intersect_object(o, &ray),
            };
            let slow = brute_closest(&g, only, &ray);
            match (fast, slow) {
                (Some(h), Some((o, p, t))) => {
                    hits += 1;
                    if (h.object, h.prim) != (o, p) {
                        // Only a near-tie is acceptable.
                        assert!(
                            (h.t - t).abs() < 1e-5 * (1.0 + t),
                            "{h:?} vs brute {o} {p} {t}"
                        );
                        ambiguous += 1;
                    } else {
                        assert!((h.t - t).abs() < 1e-9 * (1.0 + t), "t {} vs {t}", h.t);
                        assert!((h.p - ray.at(t)).length() < 1e-9 * (1.0 + t));
                        assert!((h.t - (h.p - ray.origin).dot(ray.dir)).abs() < 1e-9 * (1.0 + t));
                    }
                }
                (None, None) => {}
                (Some(h), None) => {
                    let v = g.mesh(h.object).triangle_vertices(h.prim as usize);
                    assert!(
                        near_edge(&ray, v, 1e-5),
                        "BVH hit {h:?} that brute force misses"
                    );
                    ambiguous += 1;
                }
                (None, Some((o, p, t))) => {
                    let v = g.mesh(o).triangle_vertices(p as usize);
                    assert!(
                        near_edge(&ray, v, 1e-5),
                        "brute hit {o} {p} at {t} missed by the BVH"
                    );
                    ambiguous += 1;
                }
            }
        }
    }
    assert!(hits > 2000, "too few hits to be a test: {hits}");
    assert!(ambiguous < 5, "{ambiguous} ambiguous cases");
}

#[test]
fn occlusion_matches_brute_force() {
    let g = test_geometry();
    let mut rng = Rng::from_keys(13, &[]);
    let (mut occluded, mut free) = (0, 0);
    for _ in 0..4000 {
        let r = random_ray(&mut rng);
        let ray = Ray::with_range(r.origin, r.dir, 0.0, 6.0 * rng.uniform());
        let fast = g.occluded(&ray);
        let slow = brute_closest(&g, None, &ray);
        if fast != slow.is_some() {
            // Tolerate only grazing cases and hits at the very end of the segment.
            let at_end = slow.is_some_and(|s| (s.2 - ray.t_max).abs() < 1e-5);
            let grazing = slow.is_some_and(|(o, p, _)| {
                near_edge(&ray, g.mesh(o).triangle_vertices(p as usize), 1e-5)
            });
            assert!(
                at_end || grazing || fast,
                "occlusion disagrees for {ray:?}: {slow:?}"
            );
            if fast && slow.is_none() {
                let h = g.intersect(&ray).expect("occluded but no closest hit");
                assert!(
                    (h.t - ray.t_max).abs() < 1e-5 * (1.0 + h.t)
                        || near_edge(
                            &ray,
                            g.mesh(h.object).triangle_vertices(h.prim as usize),
                            1e-5
                        )
                );
            }
        }
        if fast { occluded += 1 } else { free += 1 }
    }
    assert!(occluded > 500 && free > 500, "{occluded} / {free}");
}

#[test]
fn closed_icosphere_has_no_leaks() {
    // 1e5 random rays from inside a closed icosphere all hit it (obvhs's Möller–Trumbore
    // leaks ~1e-6 of them through shared edges: crates.md).
    let centre = DVec3::new(0.25, -1.5, 3.0);
    let g = Geometry::build(vec![primitives::icosphere(centre, 2.0, 4)]);
    let misses: usize = (0..8u64)
        .into_par_iter()
        .map(|chunk| {
            let mut rng = Rng::from_keys(14, &[chunk]);
            let mut misses = 0;
            for _ in 0..12_500 {
                // Uniform in a ball of radius 1.8 (inside the inscribed sphere of the mesh).
                let p = loop {
                    let q = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
                    if q.length_squared() <= 1.0 {
                        break q;
                    }
                };
                let ray = Ray::new(centre + 1.8 * p, random_dir(&mut rng));
                if g.intersect_object(0, &ray).is_none() {
                    misses += 1;
                }
            }
            misses
        })
        .sum();
    assert_eq!(misses, 0, "rays leaked out of a closed mesh");

    // Structured rays: from the exact centre through every vertex and every edge midpoint (rays
    // that run exactly along shared edges).
    let m = g.mesh(0);
    let mut dirs: Vec<DVec3> = m.positions.iter().map(|p| *p - centre).collect();
    for t in &m.triangles {
        for e in 0..3 {
            let (a, b) = (
                m.positions[t[e] as usize],
                m.positions[t[(e + 1) % 3] as usize],
            );
            dirs.push(0.5 * (a + b) - centre);
        }
    }
    for d in dirs {
        let ray = Ray::new(centre, d.normalize());
        assert!(g.intersect(&ray).is_some(), "leak along {d:?}");
    }
}

#[test]
fn axis_aligned_box_has_no_leaks_through_edges_and_corners() {
    // Rays from the centre of a cube toward corners, edge midpoints and face diagonals (the
    // shared edge of each face's two triangles).
    let g = Geometry::build(vec![primitives::cuboid(
        DVec3::splat(-1.0),
        DVec3::splat(1.0),
    )]);
    let mut n = 0;
    for x in -2..=2 {
        for y in -2..=2 {
            for z in -2..=2 {
                let d = DVec3::new(x as f64, y as f64, z as f64);
                if d == DVec3::ZERO {
                    continue;
                }
                for o in [
                    DVec3::ZERO,
                    DVec3::new(0.5, 0.5, 0.0),
                    DVec3::new(-0.3, 0.3, 0.3),
                ] {
                    let ray = Ray::new(o, d.normalize());
                    assert!(g.intersect(&ray).is_some(), "leak from {o:?} along {d:?}");
                    n += 1;
                }
            }
        }
    }
    assert_eq!(n, 124 * 3);
}

#[test]
fn crossings_of_lines_through_a_sphere_and_a_box() {
    let centre = DVec3::new(1.0, 2.0, -3.0);
    let g = Geometry::build(vec![
        primitives::icosphere(centre, 1.5, 3),
        primitives::cuboid(DVec3::new(5.0, -1.0, -1.0), DVec3::new(7.0, 1.0, 1.0)),
    ]);
    let mut rng = Rng::from_keys(15, &[]);
    for _ in 0..2000 {
        let d = random_dir(&mut rng);
        // A line at distance < 1.3 from the centre (inside the inscribed radius), starting
        // outside the sphere.
        let (u, v) = (d.any_orthonormal_pair().0, d.any_orthonormal_pair().1);
        let (a, b) = (rng.uniform() * 2.0 - 1.0, rng.uniform() * 2.0 - 1.0);
        let off = 0.9 * (a * u + b * v);
        let ray = Ray::new(centre + off - 5.0 * d, d);
        let mut ts = Vec::new();
        let mut facing = Vec::new();
        g.for_each_object_hit(0, &ray, |h| {
            ts.push(h.t);
            facing.push(h.ng.dot(ray.dir));
        });
        assert_eq!(ts.len(), 2, "{ray:?}: {ts:?}");
        assert!(ts[0] < ts[1]);
        assert!(facing[0] < 0.0 && facing[1] > 0.0, "enter then leave");
        // Each crossing is the closest hit of the ray started at (just after) the previous one.
        let first = g.intersect_object(0, &ray).unwrap();
        assert!((first.t - ts[0]).abs() < 1e-12);
        // None of the box's crossings are reported for the sphere.
        let mut nbox = 0;
        g.for_each_object_hit(1, &ray, |_| nbox += 1);
        let brute_box = (0..12)
            .filter(|&i| {
                brute_triangle(
                    ray.origin,
                    ray.dir,
                    g.mesh(1).triangle_vertices(i),
                    0.0,
                    f64::INFINITY,
                )
                .is_some()
            })
            .count();
        assert_eq!(nbox, brute_box);
    }
    // Through the box along x: enters at x = 5, leaves at x = 7.
    let ray = Ray::new(DVec3::new(0.0, 0.3, 0.2), DVec3::X);
    let mut ts = Vec::new();
    g.for_each_object_hit(1, &ray, |h| ts.push(h.t));
    assert_eq!(ts.len(), 2);
    assert!((ts[0] - 5.0).abs() < 1e-12 && (ts[1] - 7.0).abs() < 1e-12);
    // Exactly through the shared diagonal of two faces (y = z on the x faces): still two
    // crossings, not four.
    let ray = Ray::new(DVec3::new(0.0, 0.4, 0.4), DVec3::X);
    let mut ts = Vec::new();
    g.for_each_object_hit(1, &ray, |h| ts.push(h.t));
    assert_eq!(ts.len(), 2, "{ts:?}");
    // Through a vertex of the icosphere from the centre outward: one crossing; the full line
    // through the centre and that vertex: two.
    let v = g.mesh(0).positions[0];
    let d = (v - centre).normalize();
    let mut n = 0;
    g.for_each_object_hit(0, &Ray::new(centre, d), |_| n += 1);
    assert_eq!(n, 1);
    let mut n = 0;
    g.for_each_object_hit(0, &Ray::new(centre - 3.0 * d, d), |_| n += 1);
    assert_eq!(n, 2);
    // Range restriction.
    let mut n = 0;
    g.for_each_object_hit(
        1,
        &Ray::with_range(DVec3::new(0.0, 0.3, 0.2), DVec3::X, 6.0, 10.0),
        |_| n += 1,
    );
    assert_eq!(n, 1);
}

#[test]
fn rays_traced_counts_every_query_across_threads() {
    let g = Geometry::build(vec![primitives::icosphere(DVec3::ZERO, 1.0, 2)]);
    let before = g.rays_traced();
    (0..10_000u64).into_par_iter().for_each(|i| {
        let mut rng = Rng::from_keys(16, &[i]);
        let r = Ray::new(DVec3::ZERO, random_dir(&mut rng));
        g.intersect(&r);
        g.occluded(&r);
    });
    assert_eq!(g.rays_traced() - before, 20_000);
}

#[test]
fn empty_and_tiny_objects() {
    // An object with no triangles is never hit; a tiny object (1e-5 across) is hit at the
    // right place from 5e-7 away and from inside (obvhs's node test clamps distances below an
    // absolute 1e-4, which the BVH's scaled space keeps out of the way).
    let lo = DVec3::new(1e-5, 2e-5, 3e-5);
    let tiny = primitives::cuboid(lo, lo + 1e-5);
    let g = Geometry::build(vec![TriangleMesh::new(vec![DVec3::ZERO], vec![]), tiny]);
    let o = lo + DVec3::new(0.5e-5, 0.5e-5, -5e-7);
    let h = g
        .intersect(&Ray::new(o, DVec3::Z))
        .expect("tiny box missed");
    assert_eq!(h.object, 1);
    let bottom = g.object_bounds(1).0.z;
    assert!((h.t - (bottom - o.z)).abs() < 1e-15, "t = {}", h.t);
    // From inside the tiny box, at 2e-7 from its top face.
    let inside = lo + DVec3::new(0.5e-5, 0.5e-5, 0.98e-5);
    let h = g
        .intersect(&Ray::new(inside, DVec3::Z))
        .expect("top face missed from inside");
    let top = g.object_bounds(1).1.z; // the f32 vertex height
    assert!((h.t - (top - inside.z)).abs() < 1e-15, "t = {}", h.t);
    assert!(
        g.intersect_object(0, &Ray::new(DVec3::ZERO, DVec3::Z))
            .is_none()
    );
}

/// Many objects of mixed sizes (600 boxes and spheres from 1e-3 to 1 across, touching and
/// overlapping, plus one 200-wide floor), optionally far from the origin: the top-level tree
/// must give the brute-force closest hit and occlusion, for rays starting inside the cluster
/// and for rays from 1e4 and 1e8 away.
#[test]
fn many_objects_match_brute_force() {
    for offset in [DVec3::ZERO, DVec3::new(1e6, -3e5, 2e5)] {
        let mut rng = Rng::from_keys(21, &[]);
        let mut meshes = vec![primitives::cuboid(
            offset + DVec3::new(-100.0, -100.0, -3.0),
            offset + DVec3::new(100.0, 100.0, -2.5),
        )];
        for k in 0..600 {
            let c = offset + DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
            let size = 10f64.powf(-3.0 * rng.uniform());
            meshes.push(if k % 2 == 0 {
                primitives::cuboid(c, c + DVec3::splat(size))
            } else {
                primitives::icosphere(c, 0.5 * size, 1)
            });
        }
        let g = Geometry::build(meshes);
        let (mut hits, mut mismatches) = (0, 0);
        for i in 0..4000 {
            let target =
                offset + DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0;
            // Inside the cluster, or from far away (1e4 and 1e8: the top-level tree must move
            // a far origin toward the scene before its f32 test).
            let o = match i % 4 {
                0 | 2 => {
                    offset + DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 5.0 - 2.5
                }
                1 => target + 1e4 * random_dir(&mut rng),
                _ => target + 1e8 * random_dir(&mut rng),
            };
            let ray = Ray::new(o, (target - o).normalize());
            let fast = g.intersect(&ray).map(|h| (h.object, h.prim, h.t));
            let slow = brute_closest(&g, None, &ray);
            if fast.is_some() {
                hits += 1;
            }
            let agree = match (fast, slow) {
                (Some(a), Some(b)) => (a.0, a.1) == (b.0, b.1) || (a.2 - b.2).abs() < 1e-6 * b.2,
                (None, None) => true,
                _ => false,
            };
            if !agree {
                // Grazing rays may differ between the f32 and f64 triangle tests.
                let grazing = [fast.map(|a| (a.0, a.1)), slow.map(|b| (b.0, b.1))]
                    .into_iter()
                    .flatten()
                    .any(|(o, p)| near_edge(&ray, g.mesh(o).triangle_vertices(p as usize), 1e-5));
                assert!(
                    grazing,
                    "offset {offset}: {fast:?} vs brute {slow:?} for {ray:?}"
                );
                mismatches += 1;
            }
            let short =
                Ray::with_range(ray.origin, ray.dir, 0.0, slow.map_or(1e5, |b| 0.999 * b.2));
            assert!(
                !g.occluded(&short) || mismatches > 0,
                "offset {offset}: occluded before the first brute-force hit"
            );
            if slow.is_some() {
                assert!(
                    g.occluded(&ray) || mismatches > 0,
                    "offset {offset}: not occluded"
                );
            }
        }
        assert!(
            hits > 1500,
            "offset {offset}: too few hits to be a test: {hits}"
        );
        assert!(
            mismatches < 5,
            "offset {offset}: {mismatches} grazing mismatches"
        );
    }
}
