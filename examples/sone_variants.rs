//! Sone's readings of Eq. (2) that the paper leaves open (the semi-minor axis b = w/2 or w,
//! and ⟨θ²⟩ exact or small-angle), as beam maps of one seed for docs/physics.md#path-width:
//!
//!     cargo run --release --example sone_variants -- <stripe|check> <seed> <out-dir>
//!
//! writes `<out>/<preset>-sone-<variant>.exr` (tabulated profile, 4 × 4 subsamples) for
//! `het-bssrdf compare` against a light-traced reference. The semi-minor axis alone is also
//! a flag of the CLI (`--semi-minor` on `render`, `beam` and `converge`), which is how a
//! scene is rendered with it.

use het_bssrdf::experiments::beam::{Variant, write_variant_maps};
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

fn main() {
    write_variant_maps(
        "sone_variants",
        VARIANTS.into_iter().map(|(name, b, t)| {
            let mut p = SoneParams::paper();
            p.semi_minor = b;
            p.mean_square_angle = t;
            Variant {
                name: format!("sone-{name}"),
                estimator: Estimator::Sone(p),
                sidecar: experiments::serde_json::json!({"variant": name}),
            }
        }),
    );
}
