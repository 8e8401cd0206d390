//! Facade of the het-bssrdf workspace: re-exports the library crates so that examples, tests
//! and benchmarks can use one dependency.
#![deny(missing_docs)]

pub use bssrdf_core;
pub use experiments;
pub use het_estimate;
pub use tracer;
