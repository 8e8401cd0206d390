//! Experiments of het-bssrdf, built on the tracer: the beam exitance maps of the paper's
//! Figure 4, image comparison, error-against-time studies, plots and the `reproduce` report.
#![deny(missing_docs)]

/// The JSON library of the sidecars (`beam::Variant::sidecar` is a `serde_json::Value`),
/// re-exported so that callers build them with the same version.
pub use serde_json;
pub mod beam;
pub mod colour_range;
pub mod commentary;
pub mod converge;
pub mod error;
pub mod ledger;
pub mod metrics;
#[cfg(feature = "plot")]
pub mod plot;
pub mod reproduce;
pub mod scenes;
pub mod study;
pub mod time_to_error;
