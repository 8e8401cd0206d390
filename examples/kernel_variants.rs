//! Beam maps of the `kernel` estimator's variants (iterations, points, power-mean exponent), for the measurements
//! in docs/kernel.md. Writes `<out>/<preset>-<variant>.exr` (with the JSON sidecar that
//! `het-bssrdf compare` reads) for the tabulated profile, 4 × 4 subsamples per pixel:
//!
//!     cargo run --release --example kernel_variants -- <stripe|check> <seed> <out-dir>
//!
//! then compare each map with a light-traced reference of the same preset, e.g.
//! `het-bssrdf compare <out>/stripe-it2-n32.exr stripe-pt.exr --min-radius 1 --min-counts 100`.

use bssrdf_core::ProfileModel;
use experiments::beam::{BeamSetup, BeamTexture, bssrdf_map, write_beam_map};
use het_bssrdf::het_estimate::{Estimator, KernelParams, SampleBudget};
use het_bssrdf::{bssrdf_core, experiments};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [preset, seed, out] = &args[..] else {
        eprintln!("usage: kernel_variants <stripe|check> <seed> <out-dir>");
        std::process::exit(2);
    };
    let texture = BeamTexture::preset(preset).expect("preset: stripe or check");
    let seed: u64 = seed.parse().expect("seed: an integer");
    let setup = BeamSetup::paper(texture);
    std::fs::create_dir_all(out).expect("output directory");
    // (iterations, points, power-mean exponent p)
    let variants = [
        (1, 32, 1.0),
        (2, 32, 1.0),
        (3, 32, 1.0),
        (2, 16, 1.0),
        (2, 64, 1.0),
        (2, 32, 0.5),
        (1, 32, 0.75),
        (2, 32, 0.75),
        (3, 32, 0.75),
        (2, 16, 0.75),
        (2, 64, 0.75),
        (2, 256, 0.75),
        (2, 1024, 0.75),
        (2, 1024, 1.0),
        (2, 64, 0.875),
        (2, 128, 0.875),
        (2, 256, 0.875),
        (2, 1024, 0.875),
        (2, 64, 0.9),
        (2, 128, 0.9),
    ];
    for (iterations, samples, exponent) in variants {
        let params = KernelParams::new()
            .with_iterations(iterations)
            .with_samples(SampleBudget::fixed(samples))
            .with_exponent(exponent);
        let map = bssrdf_map(
            &setup,
            Estimator::Kernel(params),
            ProfileModel::Tabulated,
            4,
            seed,
            &|_| {},
        )
        .expect("beam map");
        let path = std::path::Path::new(out).join(format!(
            "{preset}-it{iterations}-n{samples}-p{exponent}.exr"
        ));
        write_beam_map(
            &map,
            &setup,
            &path,
            serde_json::json!({"iterations": iterations, "samples": samples, "exponent": exponent}),
        )
        .expect("write");
        println!("{} ({:.1} s)", path.display(), map.seconds);
    }
}
