//! Estimate the homogeneous BSSRDF parameters that stand in for a heterogeneous medium
//! between an incident point `x_i` and an exitant point `x_o` (Sone, Hachisuka & Koike,
//! "Parameter Estimation of BSSRDF for Heterogeneous Materials").
//!
//! The crate knows nothing about meshes, BVHs or images. A renderer implements two traits:
//! * [`SurfaceQuery`]: project a point of the averaging plane onto the object being shaded by
//!   tracing two rays along ± the plane normal (the paper's Figure 3);
//! * [`CoefficientField`]: look up σa and σs (per colour channel) at a surface point, and say
//!   cheaply whether the field is constant or bounded.
#![deny(missing_docs)]

pub mod field;
pub mod pattern;
pub mod sampler;
pub mod surface;

pub use bssrdf_core::Rgb;
pub use field::{CoefficientField, Coefficients, FieldBounds};
pub use sampler::UniformSource;
pub use surface::{SurfacePoint, SurfaceQuery};
