//! Beam maps of the `kernel` estimator's variants (iterations, points, power-mean exponent), for the measurements
//! in docs/kernel.md. Writes `<out>/<preset>-<variant>.exr` (with the JSON sidecar that
//! `het-bssrdf compare` reads) for the tabulated profile, 4 × 4 subsamples per pixel:
//!
//!     cargo run --release --example kernel_variants -- <stripe|check> <seed> <out-dir>
//!
//! then compare each map with a light-traced reference of the same preset, e.g.
//! `het-bssrdf compare <out>/stripe-it2-n64-p0.875.exr stripe-pt.exr --min-radius 1 --min-counts 100`.

use het_bssrdf::experiments::beam::{Variant, write_variant_maps};
use het_bssrdf::het_estimate::{Estimator, KernelParams, SampleBudget};

fn main() {
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
    write_variant_maps(
        "kernel_variants",
        variants
            .into_iter()
            .map(|(iterations, samples, exponent)| Variant {
                name: format!("it{iterations}-n{samples}-p{exponent}"),
                estimator: Estimator::Kernel(
                    KernelParams::new()
                        .with_iterations(iterations)
                        .with_samples(SampleBudget::fixed(samples))
                        .with_exponent(exponent),
                ),
                sidecar: experiments::serde_json::json!({
                    "iterations": iterations,
                    "samples": samples,
                    "exponent": exponent,
                }),
            }),
    );
}
