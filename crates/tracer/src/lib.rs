//! The het-bssrdf CPU tracer: one BVH-backed tracer through which both the reference
//! volumetric path tracer and the BSSRDF renderer run, so that every reported error compares
//! like with like (same geometry, textures, camera, lights and film). The transport it
//! computes (MIS, scattering orders, known answers) is described in `docs/physics.md`
//! (rendered by `cargo doc` as `het_bssrdf::physics`).
#![deny(missing_docs)]

/// The thread pool renders run on (`rayon`), re-exported so that a caller sizing it
/// (`rayon::ThreadPoolBuilder`) uses the same version.
pub use rayon;
pub mod bsdf;
pub mod camera;
mod correction;
pub mod distribution;
pub mod error;
pub mod field;
pub mod film;
pub mod geometry;
pub mod integrator;
pub mod interrupt;
pub mod light;
pub mod memory;
pub mod optical_size;
pub mod output;
pub mod render;
pub mod rng;
pub mod scene;
pub mod spectral;
#[cfg(test)]
mod sphere_bins;
pub mod volume;
