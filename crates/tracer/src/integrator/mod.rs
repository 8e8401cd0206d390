//! Integrators. The reference volumetric path tracer and the BSSRDF renderer are one camera
//! path loop ([`path`]) that differs only at translucent surfaces; the random walk inside a
//! medium ([`walk`]) also serves the light tracer of the beam experiment. [`light_trace`] is
//! the BSSRDF renderer's adjoint (light paths splatted to the camera), for reciprocity checks.

pub(crate) mod bssrdf;
pub mod counters;
pub mod light_trace;
pub mod lighting;
mod method;
pub mod path;
pub mod plan;
pub mod preparation;
pub mod probe_gathering;
pub mod profile_eval;
pub mod walk;
pub mod warnings;

pub use counters::PathCounters;
pub use light_trace::{LightTraceError, LightTraceOptions, LightTraced, LightTracer, Roles};
pub use path::{Correction, Coverage, LightStrategy, Method, PathIntegrator, PathOptions, Policy};
pub use preparation::PrepareObserver;

/// Why a render could not start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The scene cannot be rendered with this method (open mesh, surface-only field, …).
    #[error(transparent)]
    Scene(#[from] crate::error::SceneError),
    /// A material's parameters are invalid for the chosen profile or estimator.
    #[error("object `{object}`: invalid {what}")]
    Param {
        /// The object.
        object: String,
        /// What was being prepared ("profile", "estimator").
        what: &'static str,
        /// The parameter error.
        source: bssrdf_core::ParamError,
    },
    /// Preparation was stopped ([`PrepareObserver::stop_requested`], an interrupt) while the
    /// object's shape correction was being measured; nothing was rendered.
    #[error("object `{object}`: stopped while its shape correction was being measured")]
    Interrupted {
        /// The object.
        object: String,
    },
}

impl RenderError {
    pub(crate) fn param(object: &str, what: &'static str, source: bssrdf_core::ParamError) -> Self {
        RenderError::Param {
            object: object.to_string(),
            what,
            source,
        }
    }
}
