//! Sone's readings of Eq. (2) that the paper leaves open (the semi-minor axis b = w/2 or w,
//! and ⟨θ²⟩ exact or small-angle), measured on a scene's image mean and on the beam maps:
//!
//!     cargo run --release --example sone_variants -- scene <scene.toml> <spp> <seeds>
//!     cargo run --release --example sone_variants -- beam <stripe|check> <seed> <out-dir>
//!
//! `scene` prints the image mean of each variant (tabulated profile) for seeds 1..=<seeds>;
//! `beam` writes `<out>/<preset>-sone-<variant>.exr` beam maps (tabulated profile, 4 × 4
//! subsamples) for `het-bssrdf compare` against a light-traced reference.

use het_bssrdf::bssrdf_core::ProfileModel;
use het_bssrdf::experiments::beam::{BeamSetup, BeamTexture, bssrdf_map, write_beam_map};
use het_bssrdf::experiments::run::{RenderJob, render_scene};
use het_bssrdf::het_estimate::path_integral::{MeanSquareAngle, SemiMinorAxis};
use het_bssrdf::het_estimate::{Estimator, SoneParams};
use het_bssrdf::tracer::integrator::Method;
use het_bssrdf::tracer::render::Budget;
use het_bssrdf::tracer::scene::Scene;

/// The variants: (name, semi-minor axis, ⟨θ²⟩).
const VARIANTS: [(&str, SemiMinorAxis, MeanSquareAngle); 3] = [
    (
        "half-width",
        SemiMinorAxis::HalfWidth,
        MeanSquareAngle::Exact,
    ),
    ("width", SemiMinorAxis::Width, MeanSquareAngle::Exact),
    (
        "half-width-small-angle",
        SemiMinorAxis::HalfWidth,
        MeanSquareAngle::SmallAngle,
    ),
];

fn params(b: SemiMinorAxis, t: MeanSquareAngle) -> SoneParams {
    let mut p = SoneParams::paper();
    p.semi_minor = b;
    p.mean_square_angle = t;
    p
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        ["scene", path, spp, seeds] => {
            let scene = Scene::load(path).expect("scene");
            let spp: u32 = spp.parse().expect("spp: an integer");
            let seeds: u64 = seeds.parse().expect("seeds: an integer");
            for (name, b, t) in VARIANTS {
                let means: Vec<String> = (1..=seeds)
                    .map(|seed| {
                        let method = Method::Bssrdf {
                            estimator: Estimator::Sone(params(b, t)),
                            profile: Some(ProfileModel::Tabulated),
                        };
                        let mut job = RenderJob::from_scene(&scene, method);
                        job.seed = seed;
                        job.budget = Budget::Samples(spp);
                        let out = render_scene(&scene, &job).expect("render");
                        format!("{:.6}", out.film.mean()[0])
                    })
                    .collect();
                println!("{name}: image means (seeds 1–{seeds}) {}", means.join(" "));
            }
        }
        ["beam", preset, seed, out] => {
            let texture = BeamTexture::preset(preset).expect("preset: stripe or check");
            let seed: u64 = seed.parse().expect("seed: an integer");
            let setup = BeamSetup::paper(texture);
            std::fs::create_dir_all(out).expect("output directory");
            for (name, b, t) in VARIANTS {
                let map = bssrdf_map(
                    &setup,
                    Estimator::Sone(params(b, t)),
                    ProfileModel::Tabulated,
                    4,
                    seed,
                    &|_| {},
                )
                .expect("beam map");
                let path = std::path::Path::new(out).join(format!("{preset}-sone-{name}.exr"));
                write_beam_map(&map, &setup, &path, serde_json::json!({"variant": name}))
                    .expect("write");
                println!("{} ({:.1} s)", path.display(), map.seconds);
            }
        }
        _ => {
            eprintln!(
                "usage: sone_variants scene <scene.toml> <spp> <seeds> | beam <stripe|check> <seed> <out-dir>"
            );
            std::process::exit(2);
        }
    }
}
