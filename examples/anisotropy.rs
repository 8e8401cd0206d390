//! Anisotropic scattering (g ≠ 0), measured against the beam light tracer, for
//! `docs/tabulated-profile.md#anisotropic-scattering` and `docs/physics.md#path-width`:
//!
//!     cargo run --release --example anisotropy [-- PHOTONS]
//!
//! 1. **Similarity.** The tabulated profile is isotropic; for g ≠ 0 it is evaluated at the
//!    reduced coefficients σs' = (1 − g)σs. On a homogeneous half-space (σa = 0.01, σs = 1,
//!    η = 1, all scattering orders) the map of the tabulated profile is compared with the
//!    light-traced one at g = 0, 0.5 and 0.9: the ratio of the totals over the mapped square
//!    and the errors over the pixels with r ≥ 1.
//! 2. **Eq. (2) for g ≠ 0.** On both beam presets at g = 0.8 (multiple scattering, tabulated
//!    profile) the Sone estimator with each reading of Eq. (2)'s σs ([`WidthScattering`])
//!    against the light tracer.
//!
//! Light tracing uses PHOTONS photons per map (default 2²³, seed 1000); BSSRDF maps 4 × 4
//! subsamples (seed 1). Relative L2 and mean |log10| are over the pixels with r ≥ 1 where the
//! reference holds at least 100 photons.

use bssrdf_core::{ProfileModel, Scattering};
use experiments::beam::{BeamMap, BeamSetup, BeamTexture, PhotonBudget, bssrdf_map, trace_photons};
use experiments::metrics::{Metrics, compare};
use het_bssrdf::{bssrdf_core, het_estimate};
use het_estimate::{Estimator, Named, SoneParams, WidthScattering};

fn kept(setup: &BeamSetup, reference: &BeamMap, photons: u64) -> impl Fn(usize) -> bool {
    let n = setup.resolution as usize;
    let e = setup.extent;
    let area = setup.pixel_size() * setup.pixel_size();
    let values = reference.values.clone();
    move |i: usize| {
        let (x, y) = (i % n, i / n);
        let px = -e + (x as f64 + 0.5) * 2.0 * e / n as f64;
        let py = e - (y as f64 + 0.5) * 2.0 * e / n as f64;
        px.hypot(py) >= 1.0 && values[i] * area * photons as f64 >= 100.0
    }
}

fn metrics(setup: &BeamSetup, test: &BeamMap, reference: &BeamMap, photons: u64) -> Metrics {
    compare(
        &test.values,
        &reference.values,
        1,
        kept(setup, reference, photons),
    )
    .expect("same-size maps")
}

fn main() {
    let photons: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("PHOTONS must be a positive integer"))
        .unwrap_or(1 << 23);
    let quiet = |_: u64| {};

    println!("## Similarity: tabulated profile at (1 − g)σs against light tracing\n");
    println!("| g | total, tabulated / light traced | rel. L2 | mean abs log10 |");
    println!("|---:|---:|---:|---:|");
    for g in [0.0, 0.5, 0.9] {
        let mut setup = BeamSetup::paper(BeamTexture::Const { value: 0.01 });
        setup.g = g;
        setup.resolution = 64;
        setup.scattering = Scattering::All;
        let pt =
            trace_photons(&setup, PhotonBudget::Count(photons), 1000, &quiet).expect("beam scene");
        let tab = bssrdf_map(
            &setup,
            Estimator::JensenOut,
            ProfileModel::Tabulated,
            4,
            1,
            &quiet,
        )
        .expect("beam scene");
        let ratio = tab.values.iter().sum::<f64>() / pt.values.iter().sum::<f64>();
        let m = metrics(&setup, &tab, &pt, photons);
        println!(
            "| {g} | {ratio:.4} | {:.4} | {:.4} |",
            m.rel_l2, m.mean_abs_log10
        );
    }

    println!("\n## Eq. (2) at g = 0.8: Sone with each reading of σs (tabulated profile)\n");
    println!("| preset | reading | rel. L2 | mean abs log10 |");
    println!("|---|---|---:|---:|");
    for preset in ["stripe", "check"] {
        let mut setup = BeamSetup::paper(BeamTexture::preset(preset).expect("built-in preset"));
        setup.g = 0.8;
        let pt =
            trace_photons(&setup, PhotonBudget::Count(photons), 1000, &quiet).expect("beam scene");
        for reading in WidthScattering::ALL {
            let mut p = SoneParams::paper();
            p.width_scattering = *reading;
            let map = bssrdf_map(
                &setup,
                Estimator::Sone(p),
                ProfileModel::Tabulated,
                4,
                1,
                &quiet,
            )
            .expect("beam scene");
            let m = metrics(&setup, &map, &pt, photons);
            println!(
                "| {preset} | {} | {:.4} | {:.4} |",
                reading.name(),
                m.rel_l2,
                m.mean_abs_log10
            );
        }
    }
}
