//! The Rust side of `examples/pair.c`: the same material, surface, texture and pair through
//! the Rust crates directly (not through the C ABI), printing S and its bits. `.ci/run`
//! compiles and runs the C program and checks that its bits equal these.
//!
//! Run: `cargo run -p het-bssrdf-capi --example pair`

use het_estimate::analytic::{Plane, PlanePoint};
use het_estimate::bssrdf_core::glam::DVec3;
use het_estimate::bssrdf_core::{
    Coefficients, Crossing, ProfileModel, Rgb, Scattering, SeparableBssrdf,
};
use het_estimate::{CoefficientField, Estimator, SplitMix64};

/// The checkerboard's cell size.
const CELL: f64 = 0.5;

/// The checkerboard of `pair.c` (lookups only, as the C callback offers).
struct Checker([Coefficients; 2]);

impl CoefficientField<PlanePoint> for Checker {
    fn coefficients(&self, p: &PlanePoint) -> Coefficients {
        let cells = (p.x / CELL).floor() as i64 + (p.y / CELL).floor() as i64;
        self.0[(cells & 1) as usize]
    }
}

fn main() -> Result<(), het_estimate::bssrdf_core::ParamError> {
    let field = Checker([
        Coefficients::new(Rgb::new(0.02, 0.05, 0.1), Rgb::splat(1.0)),
        Coefficients::new(Rgb::new(0.3, 0.4, 0.6), Rgb::splat(2.0)),
    ]);
    let (g, eta) = (0.0, 1.3);
    let bssrdf = SeparableBssrdf::new(ProfileModel::Tabulated, Scattering::All, g, eta)?;
    let estimator = "sone".parse::<Estimator>()?.prepare(g, eta)?;
    let (x_i, x_o) = (PlanePoint::new(0.1, 0.2), PlanePoint::new(0.7, -0.3));
    let c = estimator
        .estimate(&Plane, &field, &x_i, &x_o, &mut SplitMix64::new(7))
        .coefficients;
    let incident = Crossing::new(
        DVec3::new(0.1, 0.2, 0.0),
        DVec3::Z,
        DVec3::new(0.6, 0.0, 0.8),
    );
    let exitant = Crossing::new(
        DVec3::new(0.7, -0.3, 0.0),
        DVec3::Z,
        DVec3::new(0.0, 0.28, 0.96),
    );
    let s = bssrdf.eval(&c, &incident, &exitant)?;
    println!("sigma_a = {:?}, sigma_s = {:?}", c.sigma_a.0, c.sigma_s.0);
    println!("S = {:e} {:e} {:e} (1/(length^2 sr))", s[0], s[1], s[2]);
    println!(
        "bits {:016x} {:016x} {:016x}",
        s[0].to_bits(),
        s[1].to_bits(),
        s[2].to_bits()
    );
    Ok(())
}
