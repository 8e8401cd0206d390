//! Validation of the reference path tracer against exact transport results (issue 7): the
//! light tracer of the beam experiment on a homogeneous, isotropic, index-matched half-space
//! against Chandrasekhar's exact albedo and the exact single-scattering albedo.

use bssrdf_core::Scattering;
use tracer::experiment::beam::{BeamSetup, BeamTexture, PhotonBudget, trace_photons};

use crate::common::chandrasekhar::{half_space_albedo, single_scattering_albedo};

/// 4 standard errors: with fixed seeds a correct tracer fails with probability ~6e-5 per check.
const Z: f64 = 4.0;

fn homogeneous(omega: f64) -> BeamSetup {
    let mut s = BeamSetup::paper(BeamTexture::Const { value: 1.0 - omega });
    s.sigma_s = omega;
    s.scattering = Scattering::All;
    s.resolution = 8;
    s
}

#[test]
fn half_space_albedo_matches_chandrasekhar_and_orders_split_exactly() {
    for (k, omega) in [0.5, 0.9, 0.99].into_iter().enumerate() {
        let setup = homogeneous(omega);
        let map = trace_photons(
            &setup,
            PhotonBudget::Count(1 << 17),
            100 + k as u64,
            &|_| {},
        )
        .expect("beam scene");
        let exits = map.exits.expect("light tracing counts exits");
        let want = half_space_albedo(omega);
        let (a, se) = exits.reflectance(Scattering::All);
        assert!(
            (a - want).abs() < Z * se,
            "ϖ={omega}: albedo {a} ± {se}, exact {want}"
        );
        let want_ss = single_scattering_albedo(omega);
        let (ss, se_ss) = exits.reflectance(Scattering::Single);
        assert!(
            (ss - want_ss).abs() < Z * se_ss,
            "ϖ={omega}: single {ss} ± {se_ss}, exact {want_ss}"
        );
        let (ms, se_ms) = exits.reflectance(Scattering::Multiple);
        let want_ms = want - want_ss;
        assert!(
            (ms - want_ms).abs() < Z * se_ms,
            "ϖ={omega}: multiple {ms} ± {se_ms}, exact {want_ms}"
        );
        // The orders partition the exits: nothing leaves unscattered at normal incidence.
        assert_eq!(exits.unscattered, 0);
        assert_eq!(
            map.counters.capped + map.counters.leaks,
            0,
            "{:?}",
            map.counters
        );
    }
}
