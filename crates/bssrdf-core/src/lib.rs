//! Homogeneous BSSRDF profile models in `f64`.
//!
//! This crate is the bottom layer of het-bssrdf (like pbrt's `util/` directory): pure
//! numerics, no scene types, no I/O. It knows how light leaves a *homogeneous*
//! half-space; the `het-estimate` crate decides which homogeneous parameters stand in
//! for a heterogeneous medium, and the tracer evaluates these profiles with them.
//!
//! # Conventions
//! * Lengths are in scene units; coefficients (`sigma_a`, `sigma_s`) in 1/length.
//! * A radial profile `R(r)` is the **diffuse radiant exitance per unit area at distance
//!   `r` from the point of incidence, per unit incident power** (units 1/length²). Its
//!   total `∫₀^∞ 2πr R(r) dr` is the total diffuse reflectance (dimensionless).
//! * `eta = n_medium / n_outside ≥ 1`; `eta = 1` is an index-matched boundary.
//! * Directions in the phase-function API are *propagation* directions: `cos θ = ω_in·ω_out`
//!   with both pointing the way light travels, so forward scattering (`g > 0`) favours
//!   `cos θ > 0`.
//!
//! References are keyed as in `docs/references.md` (JMLH01, HCJ13, dEI11, dE12, FHK14, …).
#![deny(missing_docs)]

pub mod error;
pub mod fresnel;
pub mod hg;
pub mod medium;
pub mod rgb;

pub use error::ParamError;
pub use medium::MediumParams;
pub use rgb::Rgb;
pub mod directional_dipole;
pub mod model;

pub use model::{ProfileModel, Scattering, UnknownName};
