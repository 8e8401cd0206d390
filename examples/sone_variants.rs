//! Sone's readings of Eq. (2) that the paper leaves open (the semi-minor axis b = w/2 or w,
//! and ⟨θ²⟩ exact or small-angle), as beam maps of one seed for docs/physics.md#path-width:
//!
//!     cargo run --release --example sone_variants -- <stripe|check> <seed> <out-dir>
//!
//! writes `<out>/<preset>-sone-<variant>.exr` (tabulated profile, 4 × 4 subsamples) for
//! `het-bssrdf compare` against a light-traced reference. The semi-minor axis alone is also
//! a flag of the CLI (`--semi-minor` on `render`, `beam` and `converge`), which is how a
//! scene is rendered with it.

use het_bssrdf::bssrdf_core::ProfileModel;
use het_bssrdf::experiments::beam::{BeamSetup, BeamTexture, bssrdf_map, write_beam_map};
use het_bssrdf::het_estimate::path_integral::{MeanSquareAngle, SemiMinorAxis};
use het_bssrdf::het_estimate::{Estimator, SoneParams};

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
    let [preset, seed, out] = &args[..] else {
        eprintln!("usage: sone_variants <stripe|check> <seed> <out-dir>");
        std::process::exit(2);
    };
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
        write_beam_map(&map, &setup, &path, serde_json::json!({"variant": name})).expect("write");
        println!("{} ({:.1} s)", path.display(), map.seconds);
    }
}
