//! An exact homogeneous half-space profile, tabulated by Monte Carlo simulation of the
//! radiative transfer it stands for (this project's own photon tracer, [`simulate`]).
//!
//! For a half-space with isotropic scattering the exitance depends only on the albedo α, on the
//! radius in mean free paths and on η: `R(r; σt, α, η) = σt² · R̂(σt r; α, η)`. The table holds
//! R̂ for single and multiple scattering separately ([`grid`] lists the η planes, albedo rows
//! and radial bins), with the photon counts and standard errors it was made with ([`mod@file`]).
//! The slab table ([`slab`], [`slab_file`]) holds the same for slabs of finite thickness:
//! reflection and transmission.
pub mod angular;
pub mod angular_file;
pub mod file;
pub mod grid;
pub mod profile;
pub mod simulate;
pub mod slab;
pub mod slab_file;

pub use angular::AngularCoupling;
pub use profile::TabulatedTerm;
pub use slab::{SlabFace, SlabTerm};
