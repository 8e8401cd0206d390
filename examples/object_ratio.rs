//! The ratio of two renders' means over the pixels one object covers: how a BSSRDF render of
//! an object compares with the path tracer's, without the background.
//!
//!     cargo run --release --example object_ratio -- SCENE TEST.exr REFERENCE.exr OBJECT
//!
//! A pixel counts when the camera rays through four points of it (the centres of its
//! quarters) all hit `OBJECT` first. The ratio is Σ test / Σ reference over those pixels,
//! summed over the three channels; its standard error is the spread of the same ratio over
//! eight interleaved pixel groups (pixel (x, y) in group (x + y) mod 8), divided by √8.

use het_bssrdf::tracer::output::read_exr;
use het_bssrdf::tracer::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, test, reference, object] = args.as_slice() else {
        return Err("usage: object_ratio SCENE TEST.exr REFERENCE.exr OBJECT".into());
    };
    let scene = Scene::load(scene)?;
    let test = read_exr(std::path::Path::new(test))?;
    let reference = read_exr(std::path::Path::new(reference))?;
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err("the two images differ in size".into());
    }
    let id = scene
        .objects()
        .iter()
        .position(|o| &o.name == object)
        .ok_or_else(|| format!("no object named `{object}` in the scene"))? as u32;
    let camera = scene.camera().with_resolution(test.width, test.height)?;
    let mut groups = [(0.0f64, 0.0f64); 8];
    let mut pixels = 0usize;
    for y in 0..test.height {
        for x in 0..test.width {
            let covered = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
                .iter()
                .all(|&(dx, dy)| {
                    let ray = camera.ray(f64::from(x) + dx, f64::from(y) + dy);
                    scene.geometry().intersect(&ray).map(|h| h.object) == Some(id)
                });
            if !covered {
                continue;
            }
            let i = (y * test.width + x) as usize;
            let g = &mut groups[((x + y) % 8) as usize];
            g.0 += (0..3).map(|c| test.pixels[i][c]).sum::<f64>();
            g.1 += (0..3).map(|c| reference.pixels[i][c]).sum::<f64>();
            pixels += 1;
        }
    }
    let (t, r) = groups
        .iter()
        .fold((0.0, 0.0), |(t, r), g| (t + g.0, r + g.1));
    let ratios = groups.map(|(t, r)| t / r);
    let m = ratios.iter().sum::<f64>() / 8.0;
    let sd = (ratios.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / 7.0).sqrt();
    println!(
        "{object}: {pixels} pixels, test / reference = {:.4} ± {:.4}",
        t / r,
        sd / 8f64.sqrt()
    );
    Ok(())
}
