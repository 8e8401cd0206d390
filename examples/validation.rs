//! Prints the reference path tracer's results next to exact transport results, with standard
//! errors, so that the "Validation" figures of docs/results.md can be re-measured:
//!
//!     cargo run --release --example validation
//!
//! * light tracing into an index-matched, isotropic half-space: total, single- and
//!   multiple-scattering albedo against Chandrasekhar's H-function (computed independently in
//!   `tests/common/chandrasekhar.rs`, shared with the test suite);
//! * the camera path tracer's radiance leaving such a half-space toward the normal, under a
//!   directional light, against Chandrasekhar's diffuse reflection law;
//! * the BSSRDF renderer on the same half-space against its own profile's total (what it must
//!   compute under uniform irradiance), for the dipole and photon beam diffusion.

#[path = "../tests/common/chandrasekhar.rs"]
#[allow(dead_code)]
mod chandrasekhar;
#[path = "../tests/common/half_space.rs"]
mod half_space;

use bssrdf_core::glam::DVec3;
use bssrdf_core::{ProfileFamily, ProfileModel, RadialProfile, Scattering};
use experiments::beam::{BeamSetup, BeamTexture, PhotonBudget, trace_photons};
use het_bssrdf::{bssrdf_core, tracer};
use tracer::integrator::Method;
use tracer::integrator::probe_gathering::PROBE_ENERGY_FRACTION;

fn row(name: &str, got: (f64, f64), want: f64) {
    let z = (got.0 - want) / got.1;
    println!(
        "| {name} | {:.5} ± {:.5} | {want:.5} | {z:+.2} |",
        got.0, got.1
    );
}

fn main() {
    let photons = 1u64 << 21;
    println!("## Light tracing into a half-space ({photons} photons each)\n");
    println!("| quantity | measured ± 1 SE | exact | z |\n|---|---:|---:|---:|");
    for omega in [0.5, 0.9, 0.99] {
        let mut setup = BeamSetup::paper(BeamTexture::Const { value: 1.0 - omega });
        setup.sigma_s = omega;
        setup.resolution = 8;
        setup.scattering = Scattering::All;
        let map = trace_photons(&setup, PhotonBudget::Count(photons), 42, &|_| {}).unwrap();
        let x = map.exits.unwrap();
        let a = chandrasekhar::half_space_albedo(omega);
        let ss = chandrasekhar::single_scattering_albedo(omega);
        row(
            &format!("albedo, ϖ = {omega}"),
            x.reflectance(Scattering::All),
            a,
        );
        row(
            &format!("single scattering, ϖ = {omega}"),
            x.reflectance(Scattering::Single),
            ss,
        );
        row(
            &format!("multiple scattering, ϖ = {omega}"),
            x.reflectance(Scattering::Multiple),
            a - ss,
        );
    }
    println!("\n## Camera path tracer: radiance toward the normal, directional light\n");
    println!("| case | measured ± 1 SE | exact | z |\n|---|---:|---:|---:|");
    for (omega, light) in [(0.9, DVec3::Z), (0.99, DVec3::new(0.6, 0.0, 0.8))] {
        let scene = half_space::half_space_scene(1.0 - omega, omega, light, 1.0);
        let mu0 = light.normalize().z;
        let (all, single) = chandrasekhar::emergent_radiance(omega, 1.0, mu0);
        for (s, want) in [
            (Scattering::All, all),
            (Scattering::Single, single),
            (Scattering::Multiple, all - single),
        ] {
            row(
                &format!("ϖ = {omega}, μ0 = {mu0}, {s}"),
                half_space::mean_and_se(&scene, Method::PathTraced, s, 1024, 16),
                want,
            );
        }
    }
    println!("\n## BSSRDF renderer against its own profile (uniform normal irradiance)\n");
    println!(
        "Expected: ρ_total/π times the fraction of the profile's energy inside the probe sphere \
         ({PROBE_ENERGY_FRACTION}; the truncation is by design, as pbrt's r_max).\n"
    );
    println!("| case | measured ± 1 SE | expected | z |\n|---|---:|---:|---:|");
    let scene = half_space::half_space_scene(0.05, 1.0, DVec3::Z, 1.0);
    for model in [ProfileModel::Dipole, ProfileModel::Pbd] {
        let family = ProfileFamily::new(model, Scattering::Multiple, 0.0, 1.0).unwrap();
        let want = family.profile(0.05, 1.0).unwrap().total() / std::f64::consts::PI
            * PROBE_ENERGY_FRACTION;
        for est in ["jensen-out", "sone"] {
            let method = Method::bssrdf(est.parse().unwrap(), Some(model));
            row(
                &format!("{model}, {est}"),
                half_space::mean_and_se(&scene, method, Scattering::Multiple, 256, 16),
                want,
            );
        }
    }
}
