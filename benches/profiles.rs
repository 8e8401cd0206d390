//! Criterion benchmarks of the homogeneous profile models (bssrdf-core): per-evaluation cost of
//! each model, per-pair construction, table build and table sampling, and the tabulated
//! profile's angular coupling per pair with and without its oblique shape.
//!
//! Run: `cargo bench --bench profiles` (add `-- --quick` for a fast pass).
use bssrdf_core::{ProfileFamily, ProfileModel, ProfileTable, RadialProfile, Rgb, Scattering};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use std::hint::black_box;

fn eval(c: &mut Criterion) {
    let mut g = c.benchmark_group("eval");
    for (model, sc) in [
        (ProfileModel::Dipole, Scattering::Multiple),
        (ProfileModel::BetterDipole, Scattering::Multiple),
        (ProfileModel::Pbd, Scattering::Multiple),
        (ProfileModel::Pbd, Scattering::Single),
    ] {
        let p = ProfileFamily::new(model, sc, 0.0, 1.33)
            .unwrap()
            .profile(0.01, 1.0)
            .unwrap();
        for r in [0.01, 1.0] {
            g.bench_function(format!("{model} {sc} r={r}"), |b| {
                b.iter(|| black_box(&p).eval(black_box(r)))
            });
        }
    }
    let fam = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.33).unwrap();
    let fhk = fam.directional_dipole(0.01, 1.0).unwrap();
    let n = DVec3::Z;
    let w = DVec3::new(0.3, 0.0, 0.95).normalize();
    g.bench_function("directional-dipole S_d r=1", |b| {
        b.iter(|| black_box(&fhk).s_d(DVec3::ZERO, w, n, black_box(DVec3::new(1.0, 0.2, 0.0)), n))
    });
    for model in [ProfileModel::Dipole, ProfileModel::Pbd] {
        let fam = ProfileFamily::new(model, Scattering::Multiple, 0.0, 1.33).unwrap();
        let (sa, ss) = (Rgb::new(0.01, 0.02, 0.05), Rgb::new(1.0, 1.1, 1.2));
        g.bench_function(format!("profile_rgb+eval_rgb {model} r=1"), |b| {
            b.iter(|| {
                fam.profile_rgb(black_box(sa), black_box(ss))
                    .unwrap()
                    .eval_rgb(black_box(1.0))
            })
        });
    }
    g.finish();
}

/// Per-material calls: numerical totals and energy radii of models without closed forms.
fn per_material(c: &mut Criterion) {
    let mut g = c.benchmark_group("per-material");
    g.sample_size(10);
    for model in [ProfileModel::Dipole, ProfileModel::Pbd] {
        let p = ProfileFamily::new(model, Scattering::All, 0.0, 1.33)
            .unwrap()
            .profile(0.01, 1.0)
            .unwrap();
        g.bench_function(format!("total {model} all"), |b| {
            b.iter(|| black_box(&p).total())
        });
        g.bench_function(format!("radius_for_fraction 0.999 {model} all"), |b| {
            b.iter(|| black_box(&p).radius_for_fraction(black_box(0.999)))
        });
    }
    g.finish();
}

fn construction(c: &mut Criterion) {
    let mut g = c.benchmark_group("construction");
    g.bench_function("ProfileFamily::new pbd eta=1.33", |b| {
        b.iter(|| {
            ProfileFamily::new(
                ProfileModel::Pbd,
                Scattering::Multiple,
                0.0,
                black_box(1.33),
            )
            .unwrap()
        })
    });
    for model in [ProfileModel::Dipole, ProfileModel::Pbd] {
        let fam = ProfileFamily::new(model, Scattering::All, 0.0, 1.33).unwrap();
        g.bench_function(format!("family.profile {model} all"), |b| {
            b.iter(|| fam.profile(black_box(0.01), black_box(1.0)).unwrap())
        });
    }
    g.sample_size(10);
    for model in [ProfileModel::Dipole, ProfileModel::Pbd] {
        let fam = ProfileFamily::new(model, Scattering::Multiple, 0.0, 1.33).unwrap();
        g.bench_function(format!("ProfileTable::new {model}"), |b| {
            b.iter(|| ProfileTable::new(black_box(fam)))
        });
    }
    g.finish();
}

fn sampling(c: &mut Criterion) {
    let mut g = c.benchmark_group("sampling");
    let fam = ProfileFamily::new(ProfileModel::Pbd, Scattering::Multiple, 0.0, 1.33).unwrap();
    let table = ProfileTable::new(fam);
    let mut u = 0.1234_f64;
    g.bench_function("table sampler+sample_r+pdf_r pbd", |b| {
        b.iter(|| {
            u = (u + 0.618_033_988_749_895) % 1.0;
            let s = table.sampler(black_box(0.013), black_box(1.0)).unwrap();
            let r = s.sample_r(u).unwrap();
            s.pdf_r(r)
        })
    });
    g.bench_function("table radius_for_fraction 0.999", |b| {
        b.iter(|| {
            table
                .sampler(black_box(0.013), black_box(1.0))
                .unwrap()
                .radius_for_fraction(0.999)
        })
    });
    let p = ProfileFamily::new(ProfileModel::Dipole, Scattering::Multiple, 0.0, 1.33)
        .unwrap()
        .profile(0.01, 1.0)
        .unwrap();
    g.bench_function("dipole exact sample_r (closed-form CDF, Newton)", |b| {
        b.iter(|| {
            u = (u + 0.618_033_988_749_895) % 1.0;
            p.sample_r(black_box(u))
        })
    });
    g.finish();
}

/// The angular coupling of the tabulated profile per pair (`SeparableBssrdf::coupling_between`),
/// without and with the oblique shape (docs/oblique-incidence.md), on 64 pairs of a flat
/// surface lit from 30° with grey and coloured coefficients (one channel's table lookups, or
/// three).
fn coupling(c: &mut Criterion) {
    use bssrdf_core::{Coefficients, Crossing, SeparableBssrdf};
    let mut g = c.benchmark_group("coupling");
    let light = DVec3::new(0.5, 0.0, 0.866).normalize();
    let pairs: Vec<(Crossing, Crossing)> = (0..64)
        .map(|k| {
            let (phi, r) = (k as f64 * 2.399_963, 0.05 + 0.07 * k as f64);
            let view = DVec3::new((0.1 * k as f64).sin() * 0.6, 0.2, 1.0).normalize();
            (
                Crossing::new(DVec3::ZERO, DVec3::Z, light),
                Crossing::new(
                    DVec3::new(r * phi.cos(), r * phi.sin(), 0.0),
                    DVec3::Z,
                    view,
                ),
            )
        })
        .collect();
    for (name, sigma_a, sigma_s) in [
        ("grey", Rgb::splat(0.02), Rgb::splat(1.0)),
        ("rgb", Rgb::new(0.01, 0.03, 0.08), Rgb::new(1.0, 1.1, 1.2)),
    ] {
        let coeffs = Coefficients { sigma_a, sigma_s };
        for oblique in [false, true] {
            let b = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::Multiple, 0.0, 1.0)
                .unwrap()
                .with_oblique_shape(oblique);
            let id = format!("{name} oblique={oblique} (64 pairs)");
            g.bench_function(id, |bn| {
                bn.iter(|| {
                    pairs
                        .iter()
                        .map(|(i, o)| b.coupling_between(black_box(&coeffs), i, o).0[1])
                        .sum::<f64>()
                })
            });
        }
    }
    g.finish();
}

criterion_group!(
    benches,
    eval,
    per_material,
    construction,
    sampling,
    coupling
);
criterion_main!(benches);
