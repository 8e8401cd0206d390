//! Ray-origin offset: a ray spawned from a hit never re-hits the same triangle, whether it
//! leaves the surface or crosses it, at every scale and position; and the offset stays small
//! enough for thin features.

use glam::DVec3;
use tracer::geometry::{Geometry, Hit, Ray, TriangleMesh, offset_ray_origin, primitives};
use tracer::rng::Rng;

use crate::common::random_dir;

/// Hits on `object` from random rays aimed at points of its bounding box from outside.
fn sample_hits(g: &Geometry, object: u32, n: usize, rng: &mut Rng) -> Vec<Hit> {
    let (lo, hi) = g.object_bounds(object);
    let c = 0.5 * (lo + hi);
    let r = 0.5 * (hi - lo).length();
    let mut hits = Vec::with_capacity(n);
    while hits.len() < n {
        let target = lo + (hi - lo) * DVec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let o = c + 3.0 * r * random_dir(rng);
        let d = (target - o).normalize();
        if let Some(h) = g.intersect_object(object, &Ray::new(o, d)) {
            hits.push(h);
        }
    }
    hits
}

/// For a convex closed object: rays leaving outward must miss it; rays going inward must
/// hit another triangle. Returns the number of violations among `n` hits × 4 directions,
/// with the origin offset by `scale × p_error` (scale 1 = the tracer's offset).
fn violations(g: &Geometry, object: u32, hits: &[Hit], scale: f64, rng: &mut Rng) -> usize {
    let mut bad = 0;
    for h in hits {
        for _ in 0..4 {
            let d = random_dir(rng);
            let o = if scale == 1.0 {
                h.spawn_origin(d)
            } else {
                let s = if h.ng.dot(d) >= 0.0 { 1.0 } else { -1.0 };
                h.p + s * scale * h.p_error * h.ng
            };
            let next = g.intersect_object(object, &Ray::new(o, d));
            let outward = h.ng.dot(d) > 0.0;
            match next {
                Some(_) if outward => bad += 1,
                Some(n) if n.prim == h.prim => bad += 1,
                None if !outward => bad += 1,
                _ => {}
            }
        }
    }
    bad
}

fn convex_cases() -> Vec<(&'static str, TriangleMesh)> {
    vec![
        (
            "unit sphere at origin",
            primitives::icosphere(DVec3::ZERO, 1.0, 4),
        ),
        (
            "small sphere far away",
            primitives::icosphere(DVec3::new(1e3, -2e3, 5e2), 0.5, 4),
        ),
        (
            "tiny sphere",
            primitives::icosphere(DVec3::new(2e-3, 0.0, -1e-3), 1e-3, 4),
        ),
        (
            "huge sphere",
            primitives::icosphere(DVec3::new(0.0, 3e4, 0.0), 1e4, 4),
        ),
        // Two huge triangles per face: hits near the origin are far from their vertices.
        (
            "half-space, unsubdivided",
            primitives::half_space(0.0, [0.0, 0.0], 2e3, 1e3, 1),
        ),
        (
            "box off-centre",
            primitives::cuboid(DVec3::new(10.0, 10.0, 10.0), DVec3::new(10.5, 12.0, 10.01)),
        ),
    ]
}

#[test]
fn spawned_rays_never_rehit_their_triangle() {
    let mut rng = Rng::from_keys(21, &[]);
    for (name, mesh) in convex_cases() {
        let g = Geometry::build(vec![mesh]);
        let hits = sample_hits(&g, 0, 5000, &mut rng);
        let bad = violations(&g, 0, &hits, 1.0, &mut rng);
        assert_eq!(
            bad, 0,
            "{name}: {bad} self-intersections or leaks out of 20000 spawned rays"
        );
    }
    // Hits near the origin of the unsubdivided half-space (|p| ≈ 0, triangles 2e3 wide).
    let g = Geometry::build(vec![primitives::half_space(0.0, [0.0, 0.0], 2e3, 1e3, 1)]);
    let mut bad = 0;
    for _ in 0..5000 {
        let o =
            DVec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 1.0) * DVec3::new(1e-3, 1e-3, 1.0);
        let h = g.intersect(&Ray::new(o, DVec3::NEG_Z)).unwrap();
        let d = random_dir(&mut rng);
        match g.intersect(&h.spawn_ray(d)) {
            Some(n) if d.z > 0.0 || n.prim == h.prim => bad += 1,
            None if d.z < 0.0 => bad += 1,
            _ => {}
        }
    }
    assert_eq!(bad, 0);
}

#[test]
fn plain_offset_function_is_safe_for_triangles_no_larger_than_p() {
    // offset_ray_origin only knows p: check it on a sphere away from the origin, where the
    // triangles are smaller than |p|.
    let mut rng = Rng::from_keys(22, &[]);
    let g = Geometry::build(vec![primitives::icosphere(
        DVec3::new(3.0, -4.0, 2.0),
        1.0,
        4,
    )]);
    let hits = sample_hits(&g, 0, 5000, &mut rng);
    let mut bad = 0;
    for h in &hits {
        let d = random_dir(&mut rng);
        let next = g.intersect(&Ray::new(offset_ray_origin(h.p, h.ng, d), d));
        match next {
            Some(n) if h.ng.dot(d) > 0.0 || n.prim == h.prim => bad += 1,
            None if h.ng.dot(d) < 0.0 => bad += 1,
            _ => {}
        }
    }
    assert_eq!(bad, 0);
}

#[test]
fn offset_is_small_enough_for_thin_slabs() {
    // A slab 1e-4 thick and 2 wide (the offset is OFFSET_REL · (|p| + triangle extent), about
    // 1.1e-5 here): a ray transmitted through the top face must hit the bottom face, at the
    // distance the slab's thickness predicts.
    let mut rng = Rng::from_keys(23, &[]);
    let g = Geometry::build(vec![primitives::cuboid(
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, 1.0, 1e-4),
    )]);
    for _ in 0..5000 {
        let o = DVec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 1.0);
        let top = g.intersect(&Ray::new(o, DVec3::NEG_Z)).unwrap();
        assert!(top.ng.z > 0.99);
        // Downward direction within 60° of the normal.
        let d = loop {
            let d = random_dir(&mut rng);
            if d.z < -0.5 {
                break d;
            }
        };
        let h = g
            .intersect(&top.spawn_ray(d))
            .expect("ray escaped through the slab");
        assert!(h.ng.z < -0.99, "did not reach the bottom face: {h:?}");
        let expect = 1e-4 / -d.z;
        assert!(
            (h.t - expect).abs() < top.p_error / -d.z * 1.01 + 1e-12,
            "t {} vs {expect}",
            h.t
        );
    }
}

/// Diagnostic (not a pass/fail test of the chosen value): self-hit rates with smaller offsets.
/// `cargo test -p het-bssrdf-tracer --test tracer offset::offset_scale_survey -- --ignored --nocapture`
#[test]
#[ignore]
fn offset_scale_survey() {
    let mut rng = Rng::from_keys(24, &[]);
    for (name, mesh) in convex_cases() {
        let g = Geometry::build(vec![mesh]);
        let hits = sample_hits(&g, 0, 20_000, &mut rng);
        let row: Vec<String> = [0.0, 1.0 / 32.0, 1.0 / 16.0, 1.0 / 8.0, 1.0 / 4.0, 1.0]
            .iter()
            .map(|&s| {
                format!(
                    "{:>6}",
                    violations(&g, 0, &hits, if s == 1.0 { 0.999_999 } else { s }, &mut rng)
                )
            })
            .collect();
        eprintln!(
            "{name:>28}: violations of 80000 at 0, 1/32, 1/16, 1/8, 1/4, 1 × offset: {}",
            row.join(" ")
        );
    }
}
