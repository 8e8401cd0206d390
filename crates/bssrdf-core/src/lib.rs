#![doc = include_str!("../README.md")]
//! # The layer
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
//! # Models
//! | module | model | source | sampling (`pdf_r`) |
//! |---|---|---|---|
//! | [`dipole`] | classical dipole | JMLH01 | exact, closed-form CDF |
//! | [`better_dipole`] | better dipole | dE12 (via secondary sources, see module) | exact, closed-form CDF |
//! | [`beam_diffusion`] | photon beam diffusion, multiple scattering | HCJ13 / pbrt | closed-form proposal |
//! | [`single_scattering`] | single scattering (any model, via [`Scattering`]) | HCJ13 / pbrt | exponential proposal |
//! | [`directional_dipole`] | directional dipole `S_d(x_i, ω_i, n_i; x_o, n_o)` | FHK14 sample code | — |
//! | [`tabulated`] | the exact half-space profile, single and multiple, by photon simulation | this project (`docs/tabulated-profile.md`) | exact, binned density |
//! | [`slab_profile`] | slab reflection and transmission at a local thickness, multiple scattering, by photon simulation | this project (`docs/tabulated-profile.md`, "The slab table") | — |
//!
//! [`fresnel`] provides the exact Fresnel moments `C₁`, `C₂` (quadrature, valid for η ∈ [1, 3]
//! and beyond) and the optional Egan–Hilgeman fit ([`DiffuseFresnel`]); [`family`] prepares a
//! material once and builds per-pair [`Profile`]s cheaply; [`table`] holds the per-material
//! radius-sampling table. All profile functions return finite, non-negative values for every
//! valid input (σa = 0, σs = 0, vacuum, σt from 1e-6 to 1e6, r = 0 … 1e9, |g| < 1, η ∈ [1, 3]);
//! invalid input is a [`ParamError`].
//!
//! The renderer-side example (the README's, compiled as a doctest) is at the top of this page.
//!
//! The estimators that choose `(σa, σs)` for a heterogeneous object, probe-ray sampling of
//! incident points, and a complete example of both traits a renderer implements are in the
//! `het-estimate` crate's documentation (its README).
//!
//! References are keyed as in `docs/references.md` (JMLH01, HCJ13, dEI11, dE12, FHK14, …).
//! The formulas, units, conventions and known-answer values are collected in the repository's
//! `docs/physics.md` (rendered by `cargo doc` as `het_bssrdf::physics`); doc comments cite its
//! sections as `docs/physics.md#section`.
#![deny(missing_docs)]

pub mod albedo_inversion;
pub mod beam_diffusion;
pub mod better_dipole;
#[cfg(any(test, feature = "tabulate"))]
pub mod chi_square;
mod coefficients;
pub mod dipole;
mod dipole_pair;
pub mod directional_dipole;
pub mod error;
pub mod family;
pub mod fresnel;
pub mod half_space_albedo;
pub mod hg;
pub mod medium;
pub mod model;
pub mod profile;
mod quadrature;
pub mod rgb;
pub mod rgb_profile;
pub mod separable;
pub mod single_scattering;
pub mod slab_profile;
pub mod table;
pub mod tabulated;

pub use albedo_inversion::AlbedoInversion;
pub use coefficients::Coefficients;
pub use error::{ParamError, UnknownName};
pub use error::{SIGMA_EPSILON, SIGMA_MAX};
pub use family::{FamilyOptions, MultipleTerm, Profile, ProfileFamily};
pub use fresnel::{DiffuseFresnel, FresnelMoments};
/// The vector types of the public API (`glam::DVec3`), re-exported so that callers use the
/// same glam version as this crate.
pub use glam;
pub use medium::MediumParams;
pub use model::{ProfileModel, Scattering};
pub use profile::RadialProfile;
pub use rgb::Rgb;
pub use rgb_profile::RgbProfile;
pub use separable::{Crossing, SeparableBssrdf, ShiftSeries};
pub use slab_profile::SlabProfile;
pub use table::{ProfileTable, RadiusSampler};
pub use tabulated::SlabFace;

#[cfg(test)]
mod known_answers;
#[cfg(test)]
mod sampling_tests;
#[cfg(test)]
mod stability_tests;
#[cfg(test)]
mod test_util;
