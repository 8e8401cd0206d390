#![doc = include_str!("../README.md")]
//! # The estimators
//! Estimate the homogeneous BSSRDF parameters that stand in for a heterogeneous medium
//! between an incident point `x_i` and an exitant point `x_o` (Sone, Hachisuka & Koike,
//! "Parameter Estimation of BSSRDF for Heterogeneous Materials"; key `Sone` in
//! `docs/references.md`). Formulas and known answers: `docs/physics.md` (rendered by
//! `cargo doc` as `het_bssrdf::physics`), cited as `docs/physics.md#section`.
//!
//! # Design
//! * **Two traits, implemented by the renderer.** The crate knows nothing about meshes, BVHs
//!   or images (it sits between `bssrdf-core` and the tracer, like pbrt's BSSRDF layer).
//!   [`SurfaceQuery`] projects a point of the averaging plane onto the object being shaded by
//!   two rays along ± the plane normal (the paper's Figure 3); [`CoefficientField`] looks up
//!   σa, σs per colour channel at a surface point and may report bounds (so constant fields
//!   cost nothing) or an exact/prefiltered ellipse average (so closed forms, summed-area
//!   tables or EWA can replace sampling; [`prefilter`] has the closed forms for stripes and
//!   checks, and the fallback criterion on curved surfaces; a field read through texture
//!   coordinates averages through the region's [`UvChart`], which the surface provides). Geometry and texturing are separate because they vary separately
//!   (one mesh, many textures; one procedural field, many shapes), and because tests and
//!   benchmarks substitute analytic versions of each (module [`analytic`]: the plane z = 0 and
//!   closed-form fields over it, also what the Python bindings estimate over). The point type is the
//!   renderer's (`SurfaceQuery::Point`), so a lookup can use triangle ids and UVs.
//! * **A closed set, resolved once.** [`Estimator`] is an enum (names `jensen-in`,
//!   `jensen-out`, `endpoints`, `segment`, `sone`, `kernel`); [`Estimator::prepare`] validates it
//!   and computes the per-material constants (the exact ⟨θ²⟩ is a ~1 µs quadrature; the
//!   kernel's table) into a
//!   [`PreparedEstimator`], whose [`PreparedEstimator::estimate`] dispatches once per pair to
//!   a generic loop over the samples (no allocation, no dynamic dispatch inside).
//! * **Caller-provided randomness** ([`UniformSource`]) keeps renders deterministic per seed.
//!   Region estimators use randomly shifted low-discrepancy points ([`sampling`]).
//! * **Always a usable answer.** Coefficients lie in `[0, 1e12]` (`bssrdf_core::SIGMA_MAX`, the
//!   range the profiles accept: larger values are clamped to it); invalid field values are a
//!   caller bug (debug assertion) and are sanitised in release builds; misses, degenerate
//!   chords and degenerate widths have explicit, documented limits; [`Diagnostics`] reports
//!   what happened (samples, projections, misses, short-circuits, fallbacks, the width).
//!
//! # Conventions
//! Lengths in scene units, coefficients in 1/length, f64 throughout. Normals point out of the
//! medium. Colour is linear RGB ([`Rgb`]), each channel estimated separately (sharing samples).
//! The averaging estimators' estimates are symmetric in x_i ↔ x_o, bit for bit with the same
//! random numbers, on curved surfaces too (canonical chord orientation and an averaging plane
//! from n_i + n_o; docs/reciprocity.md); the point lookups `jensen-in`/`jensen-out` are not.
#![deny(missing_docs)]

#[macro_use]
pub mod names;

pub mod analytic;
pub mod azimuth;
pub mod budget;
mod chord;
pub mod ellipse;
pub mod estimator;
pub mod estimator_output;
pub mod field;
pub mod frame;
pub mod green;
pub mod kernel;
pub mod kernel_table;
mod known;
pub mod local_surface;
pub mod path_integral;
pub mod pattern;
mod point_lookup;
pub mod prefilter;
pub mod probe;
pub mod random;
mod region_average;
pub mod sampling;
pub mod segment;
pub mod sone;
pub mod surface;
pub mod uv_chart;

/// The profile crate this one estimates parameters for, re-exported so that one dependency
/// (`het-estimate`) is enough and both agree on its version.
pub use bssrdf_core;
pub use bssrdf_core::Rgb;
pub use budget::{MissPolicy, SampleBudget};
pub use ellipse::PlanarEllipse;
pub use estimator::{Estimator, EstimatorOptions, PreparedEstimator};
pub use estimator_output::{Diagnostics, Estimate, Region};
pub use field::{CoefficientField, Coefficients, FieldBounds, FieldCapabilities};
/// The vector types of the public traits (`glam::DVec3`), re-exported so that implementors
/// use the same glam version as this crate.
pub use glam;
pub use kernel::KernelParams;
pub use local_surface::Curvature;
pub use names::Named;
pub use path_integral::{MeanSquareAngle, SemiMinorAxis};
pub use prefilter::{Averaging, Flatness};
pub use random::{SplitMix64, UniformSource};
pub use region_average::CHUNK;
pub use segment::SegmentParams;
pub use sone::{SoneParams, WidthScattering};
pub use surface::{Projected, SurfacePoint, SurfaceQuery};
pub use uv_chart::UvChart;
