//! The per-pixel noise of a render, object by object: two renders of one scene that differ only
//! in their seed, compared over the pixels each object covers.
//!
//!     cargo run --release --example object_noise -- SCENE A.exr B.exr
//!
//! A pixel belongs to an object when the camera rays through five points of it (its centre and
//! four points near its corners) all hit that object first; the rest (silhouettes, and the
//! background) form one more group. For each group it prints the relative noise of one image,
//! `√(Σ (a − b)²/2 / Σ ((a + b)/2)²)` over the group's pixels and channels (the expected
//! relative L2 distance of one render from the noise-free image, when the two are independent),
//! and the group's share of the whole image's squared noise. Variance falls as 1/spp, so at
//! equal run time the method with the smaller `noise² × seconds` is the faster one.

use het_bssrdf::tracer::output::read_exr;
use het_bssrdf::tracer::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, a, b] = args.as_slice() else {
        return Err("usage: object_noise SCENE A.exr B.exr".into());
    };
    let scene = Scene::load(scene)?;
    let a = read_exr(std::path::Path::new(a))?;
    let b = read_exr(std::path::Path::new(b))?;
    if (a.width, a.height) != (b.width, b.height) {
        return Err("the two images differ in size".into());
    }
    let camera = scene.camera().with_resolution(a.width, a.height)?;
    let rest = scene.objects().len();
    // Per group: squared differences / 2, squared means, pixels.
    let mut groups = vec![(0.0f64, 0.0f64, 0usize); rest + 1];
    for y in 0..a.height {
        for x in 0..a.width {
            let first = |dx: f64, dy: f64| {
                let ray = camera.ray(f64::from(x) + dx, f64::from(y) + dy);
                scene.geometry().intersect(&ray).map(|h| h.object as usize)
            };
            let centre = first(0.5, 0.5);
            let inside = [(0.1, 0.1), (0.9, 0.1), (0.1, 0.9), (0.9, 0.9)]
                .iter()
                .all(|&(dx, dy)| first(dx, dy) == centre);
            let g = match centre {
                Some(o) if inside => o,
                _ => rest,
            };
            let i = (y * a.width + x) as usize;
            let group = &mut groups[g];
            for c in 0..3 {
                let (p, q) = (a.pixels[i][c], b.pixels[i][c]);
                group.0 += 0.5 * (p - q) * (p - q);
                group.1 += (0.5 * (p + q)).powi(2);
            }
            group.2 += 1;
        }
    }
    let (noise, signal) = groups
        .iter()
        .fold((0.0, 0.0), |(n, s), g| (n + g.0, s + g.1));
    for (g, &(n, s, pixels)) in groups.iter().enumerate() {
        if pixels == 0 {
            continue;
        }
        let name = match scene.objects().get(g) {
            Some(o) => o.name.as_str(),
            None => "(silhouettes and background)",
        };
        println!(
            "{name}: {pixels} pixels, relative noise {:.4}, share of the image's squared noise {:.3}",
            (n / s.max(f64::MIN_POSITIVE)).sqrt(),
            n / noise.max(f64::MIN_POSITIVE)
        );
    }
    println!(
        "whole image: relative noise {:.4}",
        (noise / signal.max(f64::MIN_POSITIVE)).sqrt()
    );
    Ok(())
}
