//! Ray-query throughput of the tracer's [`Geometry`] (obvhs CWBVH, leaf-order triangles, the
//! watertight test, `f64` hit records) on closed icospheres of ~100k and ~1M triangles
//! (generated in code, no files).
//!
//! Run: `cargo bench --bench tracing` (add `-- 1310720` or `-- closest` to filter). Ids are
//! `tracing/<query>/<ray set>/tris=<N>`; criterion reports throughput in elements/s = rays/s
//! (single thread unless the id says `2 threads`). Ray sets, 8192 rays each, generated once:
//! * `interior`: origins uniform inside the sphere, uniform directions (a subsurface random
//!   walk looking for the boundary);
//! * `camera`: origins on a sphere of 3 radii, aimed at uniform points of the bounding box
//!   (about 60 % hit);
//! * `segments`: interior origins with a length uniform in [0, 2r] (shadow / free-flight
//!   tests; about half are occluded).
//!
//! `closest` builds the full [`tracer::geometry::Hit`] (f64 refinement, normals); `occluded`
//! stops at the first hit; `crossings` is `for_each_object_hit` over the whole line.
//!
//! `objects/<query>/<n>` (`cargo bench --bench tracing -- objects`): the same queries on
//! scenes of `n` = 10 … 3000 boxes, for the cost of the top-level tree over objects.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use rayon::prelude::*;
use tracer::geometry::{Geometry, Ray, primitives};
use tracer::rng::Rng;

const RAYS: usize = 8192;

fn dir(rng: &mut Rng) -> DVec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * rng.uniform();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn interior(rng: &mut Rng, radius: f64) -> DVec3 {
    loop {
        let q = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        if q.length_squared() <= 1.0 {
            return 0.95 * radius * q;
        }
    }
}

fn ray_sets(radius: f64) -> Vec<(&'static str, Vec<Ray>)> {
    let mut rng = Rng::from_keys(1234, &[]);
    let interior_rays = (0..RAYS)
        .map(|_| Ray::new(interior(&mut rng, radius), dir(&mut rng)))
        .collect();
    let camera_rays = (0..RAYS)
        .map(|_| {
            let o = 3.0 * radius * dir(&mut rng);
            let target =
                (DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0) * radius;
            Ray::new(o, (target - o).normalize())
        })
        .collect();
    let segments = (0..RAYS)
        .map(|_| {
            Ray::segment(
                interior(&mut rng, radius),
                dir(&mut rng),
                2.0 * radius * rng.uniform(),
            )
        })
        .collect();
    vec![
        ("interior", interior_rays),
        ("camera", camera_rays),
        ("segments", segments),
    ]
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("tracing");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(RAYS as u64));
    for subdivisions in [6u32, 8] {
        let radius = 1.0;
        let t0 = Instant::now();
        let g = Geometry::build(vec![primitives::icosphere(
            DVec3::ZERO,
            radius,
            subdivisions,
        )]);
        let n = g.triangle_count();
        eprintln!(
            "tracing: icosphere({subdivisions}) = {n} triangles, BVH built in {:.2?}",
            t0.elapsed()
        );
        let sets = ray_sets(radius);
        for (name, rays) in &sets {
            if *name != "segments" {
                group.bench_with_input(
                    BenchmarkId::new(format!("closest/{name}"), format!("tris={n}")),
                    rays,
                    |b, rays| {
                        b.iter(|| {
                            rays.iter()
                                .filter(|r| black_box(g.intersect(r)).is_some())
                                .count()
                        })
                    },
                );
                group.bench_with_input(
                    BenchmarkId::new(format!("closest-object/{name}"), format!("tris={n}")),
                    rays,
                    |b, rays| {
                        b.iter(|| {
                            rays.iter()
                                .filter(|r| black_box(g.intersect_object(0, r)).is_some())
                                .count()
                        })
                    },
                );
            }
            group.bench_with_input(
                BenchmarkId::new(format!("occluded/{name}"), format!("tris={n}")),
                rays,
                |b, rays| b.iter(|| rays.iter().filter(|r| g.occluded(r)).count()),
            );
        }
        let (_, camera) = &sets[1];
        group.bench_with_input(
            BenchmarkId::new("crossings/camera", format!("tris={n}")),
            camera,
            |b, rays| {
                b.iter(|| {
                    let mut k = 0usize;
                    for r in rays {
                        g.for_each_object_hit(0, r, |h| k += black_box(h).prim as usize & 1);
                    }
                    k
                })
            },
        );
        let (_, inner) = &sets[0];
        group.bench_with_input(
            BenchmarkId::new("closest/interior 2 threads", format!("tris={n}")),
            inner,
            |b, rays| {
                b.iter(|| {
                    rays.par_iter()
                        .filter(|r| black_box(g.intersect(r)).is_some())
                        .count()
                })
            },
        );
    }
    group.finish();
}

/// `n` boxes on a square grid filling `[-10, 10]²` (side half the spacing, so about a quarter
/// of the area is covered whatever `n`).
/// Cells per row and cell size of the grid of `n` boxes over [−10, 10]².
fn grid_layout(n: usize) -> (usize, f64) {
    let k = (n as f64).sqrt().ceil() as usize;
    (k, 20.0 / k as f64)
}

/// `n` boxes in a grid over [−10, 10]², each a quarter of its cell, 1 high.
fn box_grid(n: usize) -> Vec<tracer::geometry::TriangleMesh> {
    let (k, spacing) = grid_layout(n);
    (0..n)
        .map(|i| {
            let (x, y) = ((i % k) as f64, (i / k) as f64);
            let lo = DVec3::new(-10.0 + x * spacing, -10.0 + y * spacing, -0.5);
            primitives::cuboid(lo, lo + DVec3::new(0.5 * spacing, 0.5 * spacing, 1.0))
        })
        .collect()
}

/// Many objects: closest-hit and occlusion cost against the number of objects (10 to 3000
/// boxes of a 20 × 20 grid), for two ray sets from above:
/// * `closest`/`occluded`: aimed at random points of the grid. The share of rays that hit
///   something grows with the number of boxes (17 % for 10 boxes, 51 % for 1000, 65 % for
///   3000: oblique rays cross more small boxes), so these compare unequal work.
/// * `closest-on-box`: aimed at random points of a random box's top, so that every ray hits
///   and the work per ray differs only by the tree over objects. This is the set the target
///   "1000 objects cost within 2× of 10" is read on.
///
/// Before the top-level tree, cost grew linearly: 3.17 / 0.93 / 0.16 / 0.06 Mrays/s for
/// 10 / 100 / 1000 / 3000 boxes.
fn many_objects(c: &mut Criterion) {
    let mut group = c.benchmark_group("objects");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(RAYS as u64));
    let mut rng = Rng::from_keys(99, &[]);
    let from_above = |rng: &mut Rng, target: DVec3| {
        let o = DVec3::new(0.0, 0.0, 30.0) + 5.0 * dir(rng);
        Ray::new(o, (target - o).normalize())
    };
    let rays: Vec<Ray> = (0..RAYS)
        .map(|_| {
            let target = DVec3::new(
                20.0 * rng.uniform() - 10.0,
                20.0 * rng.uniform() - 10.0,
                0.0,
            );
            from_above(&mut rng, target)
        })
        .collect();
    for n in [10usize, 100, 1000, 3000] {
        let g = Geometry::build(box_grid(n));
        let (k, spacing) = grid_layout(n);
        let on_box: Vec<Ray> = (0..RAYS)
            .map(|_| {
                let i = ((rng.uniform() * n as f64) as usize).min(n - 1);
                let (x, y) = ((i % k) as f64, (i / k) as f64);
                let target = DVec3::new(
                    -10.0 + (x + 0.5 * rng.uniform()) * spacing,
                    -10.0 + (y + 0.5 * rng.uniform()) * spacing,
                    0.5,
                );
                from_above(&mut rng, target)
            })
            .collect();
        group.bench_with_input(BenchmarkId::new("closest", n), &rays, |b, rays| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| black_box(g.intersect(r)).is_some())
                    .count()
            })
        });
        group.bench_with_input(BenchmarkId::new("occluded", n), &rays, |b, rays| {
            b.iter(|| rays.iter().filter(|r| g.occluded(r)).count())
        });
        group.bench_with_input(BenchmarkId::new("closest-on-box", n), &on_box, |b, rays| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| black_box(g.intersect(r)).is_some())
                    .count()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench, many_objects);
criterion_main!(benches);
