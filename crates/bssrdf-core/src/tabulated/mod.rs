//! An exact homogeneous half-space profile, tabulated by Monte Carlo simulation of the
//! radiative transfer it stands for (this project's own photon tracer, [`simulate`]).
//!
//! For a half-space with isotropic scattering the exitance depends only on the albedo α, on the
//! radius in mean free paths and on η: `R(r; σt, α, η) = σt² · R̂(σt r; α, η)`. The table holds
//! R̂ for single and multiple scattering separately ([`grid`] lists the η planes, albedo rows
//! and radial bins), with the photon counts and standard errors it was made with ([`mod@file`]).
//! The slab table ([`slab`], [`slab_file`]) holds the same for slabs of finite thickness:
//! reflection and transmission.
//!
//! The photon simulation and the functions that write new tables (`simulate`,
//! `file::tabulate`, `slab_file::tabulate_slab`, `angular_file::tabulate_angular`) are data
//! tooling, public only with the `tabulate` feature (the `het-bssrdf tabulate` command uses
//! them); a renderer reads the built-in tables and needs none of it.
pub mod angular;
// Without `tabulate` the simulation's writers are compiled out, and parts of what they share
// with the readers are unused.
#[cfg_attr(not(feature = "tabulate"), allow(dead_code, unused_imports))]
pub mod angular_file;
#[cfg_attr(not(feature = "tabulate"), allow(dead_code, unused_imports))]
pub mod file;
pub mod grid;
pub mod half_space;
#[cfg(feature = "tabulate")]
pub mod simulate;
#[cfg(not(feature = "tabulate"))]
#[allow(dead_code)]
pub(crate) mod simulate;
pub mod slab;
#[cfg_attr(not(feature = "tabulate"), allow(dead_code, unused_imports))]
pub mod slab_file;

pub use angular::AngularCoupling;
pub use half_space::TabulatedTerm;
pub use slab::{SlabFace, SlabTerm};
