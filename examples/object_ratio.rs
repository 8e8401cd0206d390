//! The ratio of two renders' means over the pixels one object covers: how a BSSRDF render of
//! an object compares with the path tracer's, without the background.
//!
//!     cargo run --release --example object_ratio -- SCENE TEST.exr REFERENCE.exr OBJECT [--faces]
//!
//! A pixel counts when the camera rays through four points of it (the centres of its
//! quarters) all hit `OBJECT` first. The ratio is Σ test / Σ reference over those pixels,
//! summed over the three channels; its standard error is the spread of the same ratio over
//! eight interleaved pixel groups (pixel (x, y) in group (x + y) mod 8), divided by √8. The
//! same ratio per channel follows (a hue shift shows as channels that disagree).
//!
//! With `--faces` the same ratio is also printed per facing (the axis nearest the shading
//! normal at the pixel's centre: +x, −x, …) and, for a translucent object whose σa varies,
//! per half of its σa range at the surface point (`low σa` below the midpoint of the field's
//! bounds, summed over channels; `high σa` above): where on the object a render departs from
//! the reference.

use het_bssrdf::tracer::output::read_exr;
use het_bssrdf::tracer::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (faces, args): (Vec<&String>, Vec<&String>) =
        args.iter().partition(|a| a.as_str() == "--faces");
    let [scene, test, reference, object] = args.as_slice() else {
        return Err("usage: object_ratio SCENE TEST.exr REFERENCE.exr OBJECT [--faces]".into());
    };
    let faces = !faces.is_empty();
    let scene = Scene::load(scene)?;
    let test = read_exr(std::path::Path::new(test))?;
    let reference = read_exr(std::path::Path::new(reference))?;
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err("the two images differ in size".into());
    }
    let id = scene
        .objects()
        .iter()
        .position(|o| &o.name == *object)
        .ok_or_else(|| format!("no object named `{object}` in the scene"))? as u32;
    let camera = scene.camera().with_resolution(test.width, test.height)?;
    let mut groups = [(0.0f64, 0.0f64); 8];
    // Per channel, per group: (test, reference).
    let mut channel_groups = [[(0.0f64, 0.0f64); 8]; 3];
    let mut pixels = 0usize;
    let medium = scene.objects()[id as usize]
        .material
        .translucent()
        .map(|t| &t.medium);
    // σa's midpoint (summed over channels), when it varies.
    let sigma_a_mid = medium.and_then(|m| {
        let b = m.field_bounds();
        let (lo, hi) = (
            b.min.sigma_a.0.iter().sum::<f64>(),
            b.max.sigma_a.0.iter().sum::<f64>(),
        );
        (hi > lo).then_some(0.5 * (lo + hi))
    });
    // (test, reference, pixels) per facing and σa half.
    let mut by_face = [[(0.0f64, 0.0f64, 0usize); 2]; 6];
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
            let (tv, rv) = (
                (0..3).map(|c| test.pixels[i][c]).sum::<f64>(),
                (0..3).map(|c| reference.pixels[i][c]).sum::<f64>(),
            );
            let g = &mut groups[((x + y) % 8) as usize];
            g.0 += tv;
            g.1 += rv;
            for (c, cg) in channel_groups.iter_mut().enumerate() {
                let g = &mut cg[((x + y) % 8) as usize];
                g.0 += test.pixels[i][c];
                g.1 += reference.pixels[i][c];
            }
            pixels += 1;
            if faces {
                let ray = camera.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
                if let Some(hit) = scene.geometry().intersect(&ray) {
                    let n = hit.ns.to_array();
                    let axis = (0..3)
                        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
                        .unwrap_or(2);
                    let face = 2 * axis + usize::from(n[axis] < 0.0);
                    let half = match (sigma_a_mid, medium) {
                        (Some(mid), Some(m)) => {
                            let sa = m.at_surface(hit.p, hit.uv).sigma_a.0.iter().sum::<f64>();
                            usize::from(sa > mid)
                        }
                        _ => 0,
                    };
                    let b = &mut by_face[face][half];
                    b.0 += tv;
                    b.1 += rv;
                    b.2 += 1;
                }
            }
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
    let per_channel: Vec<String> = channel_groups
        .iter()
        .zip(["R", "G", "B"])
        .map(|(cg, name)| {
            let (t, r) = cg.iter().fold((0.0, 0.0), |(t, r), g| (t + g.0, r + g.1));
            let ratios = cg.map(|(t, r)| t / r);
            let m = ratios.iter().sum::<f64>() / 8.0;
            let sd = (ratios.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / 7.0).sqrt();
            format!("{name} {:.4} ± {:.4}", t / r, sd / 8f64.sqrt())
        })
        .collect();
    println!("  per channel: {}", per_channel.join(", "));
    if faces {
        let names = ["+x", "-x", "+y", "-y", "+z", "-z"];
        for (name, halves) in names.iter().zip(&by_face) {
            for (h, &(t, r, n)) in halves.iter().enumerate() {
                if n == 0 {
                    continue;
                }
                let part = match (sigma_a_mid, h) {
                    (None, _) => "",
                    (Some(_), 0) => ", low σa",
                    (Some(_), _) => ", high σa",
                };
                println!(
                    "  facing {name}{part}: {n} pixels, test / reference = {:.3}",
                    t / r
                );
            }
        }
    }
    Ok(())
}
