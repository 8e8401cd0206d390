//! Facade of the het-bssrdf workspace: re-exports the library crates so that examples, tests
//! and benchmarks can use one dependency.
#![deny(missing_docs)]

pub use bssrdf_core;
pub use experiments;

/// The physics the code implements: formulas, sources, units, conventions and the known-answer
/// values the tests use (the repository's `docs/physics.md`, which doc comments across the
/// workspace cite as `docs/physics.md#section`).
#[doc = include_str!("../docs/physics.md")]
pub mod physics {}

/// The diffusion-derived averaging kernel (`--method kernel`): derivation, assumptions, the
/// table and the sampler, and the measurements that chose its variants (the repository's
/// `docs/kernel.md`, cited from the code as `docs/kernel.md#section`).
#[doc = include_str!("../docs/kernel.md")]
pub mod kernel {}

/// Reciprocity: which estimates and BSSRDF values are symmetric in (x_i, x_o) and why, the
/// non-reciprocal point lookups, and the light-traced render that checks it (the repository's
/// `docs/reciprocity.md`).
#[doc = include_str!("../docs/reciprocity.md")]
pub mod reciprocity {}

/// Artist parameters (`subsurface_color`, `subsurface_radius`): the colour-to-albedo inversion
/// per profile, where the estimators invert, the limits and the before/after measurement (the
/// repository's `docs/artist-parameters.md`).
#[doc = include_str!("../docs/artist-parameters.md")]
pub mod artist_parameters {}
pub use het_estimate;
pub use pipeline;
pub use tracer;
