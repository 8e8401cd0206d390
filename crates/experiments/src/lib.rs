//! Experiments of het-bssrdf, built on the tracer: the beam exitance maps of the paper's
//! Figure 4, image comparison, error-against-time studies, plots and the `reproduce` report.
#![deny(missing_docs)]

pub mod beam;
pub mod commentary;
pub mod converge;
pub mod error;
pub mod ledger;
pub mod metrics;
#[cfg(feature = "plot")]
pub mod plot;
pub mod progress;
pub mod provenance;
pub mod reproduce;
pub mod run;
pub mod scenes;
pub mod shard;
pub mod study;
pub mod time_to_error;
