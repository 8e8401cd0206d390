//! Shapes the half-space profile cannot see (issue 18): for homogeneous media (σt = 1, g = 0,
//! multiple scattering, uniform environment light, orthographic view), the BSSRDF/PT ratio of
//! the light through the medium on slabs, spheres, a box corner and the bunny, each divided by
//! the same ratio on a half-space, with standard errors over seeds; and the fraction of BSSRDF
//! shading points whose probes found nothing.
//!
//!     cargo run --release --example shapes [-- --quick] [-- --g 0.8] [-- --oblique] [-- --half-space] [-- --scattering all]
//!
//! `--scattering all` counts every scattering order in both renderers (the default is
//! multiple scattering, two or more events). `--only NONE` (a label no shape has) keeps the
//! half-space alone.
//! `--spheres 1.5,3,10` replaces the shapes by spheres of these radii (in mfp): the size
//! sweep behind `--method auto`'s threshold (docs/curved-objects.md).
//! `--oblique` replaces the shapes by the half-space seen at μ = 0.58 and 0.3 from its normal.
//! `--half-space` turns the materials' `thickness_aware` off: the tabulated profile is the
//! half-space one everywhere, as before the slab profile (docs/shapes.md).
//!
//! The set-up is in `tests/common/shapes.rs` (shared with the `shapes` tests). The bunny is
//! read from `../shared/assets/bunny.obj` relative to the repository's root and skipped when
//! absent.

#[path = "../tests/common/shapes.rs"]
#[allow(dead_code)]
mod shapes;

use std::path::PathBuf;

use bssrdf_core::{ProfileModel, Scattering};
use het_bssrdf::{bssrdf_core, tracer};
use shapes::{
    Medium, Shape, bssrdf, mean_se, measure_orders, outside_light, ratio, shape_scene_with,
};
use tracer::integrator::Method;

/// Samples per pixel and seeds: per shape (pixel counts differ) and per method.
fn budget(shape: Shape, quick: bool) -> (u32, u32, u64) {
    let (pt, bs) = match shape.pixels() {
        4 => (4096, 1024),
        _ => (256, 64),
    };
    let seeds = if quick { 4 } else { 8 };
    if quick {
        (pt / 4, bs / 4, seeds)
    } else {
        (pt, bs, seeds)
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let thickness_aware = !args.iter().any(|a| a == "--half-space");
    let corrected = args.iter().any(|a| a == "--corrected");
    let only: Option<String> = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .cloned();
    let g = args
        .iter()
        .position(|a| a == "--g")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.parse::<f64>().expect("--g takes a number"))
        .unwrap_or(0.0);
    let scattering: Scattering = args
        .iter()
        .position(|a| a == "--scattering")
        .and_then(|i| args.get(i + 1))
        .map(|s| {
            s.parse()
                .expect("--scattering takes multiple, single or all")
        })
        .unwrap_or(Scattering::Multiple);
    let bunny = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/bunny.obj");
    let columns: Vec<Medium> = Medium::COLUMNS.iter().map(|m| Medium { g, ..*m }).collect();
    let models: Vec<ProfileModel> = if args.iter().any(|a| a == "--tabulated-only") {
        vec![ProfileModel::Tabulated]
    } else {
        vec![ProfileModel::Tabulated, ProfileModel::Dipole]
    };
    let mut shapes_list = vec![Shape::HalfSpace];
    let spheres: Option<Vec<f64>> = args
        .iter()
        .position(|a| a == "--spheres")
        .and_then(|i| args.get(i + 1))
        .map(|s| {
            s.split(',')
                .map(|r| r.parse().expect("--spheres takes radii, comma-separated"))
                .collect()
        });
    if let Some(radii) = spheres {
        // A size sweep: how the half-space assumption's error grows as a body shrinks
        // (the calibration of `--method auto`'s threshold, docs/curved-objects.md).
        shapes_list.extend(radii.into_iter().map(Shape::Sphere));
    } else if args.iter().any(|a| a == "--oblique") {
        // The half-space seen obliquely: the part of the error due to the exit direction.
        shapes_list.extend([Shape::Oblique(0.58), Shape::Oblique(0.3)]);
    } else {
        shapes_list.extend(
            Shape::TABLE
                .into_iter()
                .filter(|s| *s != Shape::Bunny || bunny.exists())
                .filter(|s| only.as_ref().is_none_or(|o| s.label().contains(o.as_str()))),
        );
    }
    // results[shape][column] = (PT, per-model BSSRDF, per-model miss fraction)
    let mut through = Vec::new();
    let mut misses = Vec::new();
    for &shape in &shapes_list {
        let (spp_pt, spp_b, seeds) = budget(shape, quick);
        let mut row = Vec::new();
        let mut miss_row = Vec::new();
        for (ci, &m) in columns.iter().enumerate() {
            let scene = shape_scene_with(shape, m, &bunny, thickness_aware, corrected);
            let outside = outside_light(&scene, m.eta, 32);
            let t0 = std::time::Instant::now();
            let seed0 = 1000 * ci as u64;
            let pt = measure_orders(
                &scene,
                Method::PathTraced,
                scattering,
                outside,
                spp_pt,
                seed0..seed0 + seeds,
            );
            let pt = mean_se(pt.iter().map(|s| s.through));
            let mut per_model = Vec::new();
            let mut miss = Vec::new();
            for &model in &models {
                let b = measure_orders(
                    &scene,
                    bssrdf(model),
                    scattering,
                    outside,
                    spp_b,
                    seed0..seed0 + seeds,
                );
                per_model.push(mean_se(b.iter().map(|s| s.through)));
                miss.push(mean_se(b.iter().map(|s| s.miss_fraction)));
            }
            eprintln!(
                "{} {}: PT {:.5} ± {:.5}, outside {outside:.5}, {:.1} s",
                shape.label(),
                m.label(),
                pt.0,
                pt.1,
                t0.elapsed().as_secs_f64()
            );
            row.push((pt, per_model));
            miss_row.push(miss);
        }
        through.push(row);
        misses.push(miss_row);
    }
    let header = |what: &str| {
        print!("| {what} |");
        for m in &columns {
            print!(" {} |", m.label());
        }
        println!();
        print!("|---|");
        for _ in &columns {
            print!("---:|");
        }
        println!();
    };
    println!(
        "\n## (BSSRDF/PT on the shape) / (BSSRDF/PT on the half-space) ± 1 SE, {:?}\n",
        models
    );
    header("shape");
    let hs = &through[0];
    for (si, &shape) in shapes_list.iter().enumerate().skip(1) {
        print!("| {} |", shape.label());
        for ci in 0..columns.len() {
            let (pt, ref b) = through[si][ci];
            let (pt_hs, ref b_hs) = hs[ci];
            let cells: Vec<String> = (0..models.len())
                .map(|k| {
                    let (q, se) = ratio(ratio(b[k], pt), ratio(b_hs[k], pt_hs));
                    format!("{q:.3} ± {se:.3}")
                })
                .collect();
            print!(" {} |", cells.join(" / "));
        }
        println!();
    }
    println!(
        "\n## BSSRDF/PT on the half-space (the profile's own error), {:?}\n",
        models
    );
    header("shape");
    print!("| half-space |");
    for (pt, b) in hs {
        let cells: Vec<String> = b
            .iter()
            .map(|&bk| {
                let (q, se) = ratio(bk, *pt);
                format!("{q:.3} ± {se:.3}")
            })
            .collect();
        print!(" {} |", cells.join(" / "));
    }
    println!();
    println!(
        "\n## Probe-miss fraction (shading points whose three probes found nothing), {:?}\n",
        models
    );
    header("shape");
    for (si, &shape) in shapes_list.iter().enumerate() {
        print!("| {} |", shape.label());
        for miss in &misses[si] {
            let cells: Vec<String> = miss
                .iter()
                .map(|(m, _)| format!("{:.1} %", 100.0 * m))
                .collect();
            print!(" {} |", cells.join(" / "));
        }
        println!();
    }
}
