//! Workspace integration tests: one binary, one module per theme.

mod common;
mod fuzz_regressions;
mod index_matched;
mod image_prefilter;
mod integrators;
mod precision;
mod readme;
mod stability;
mod stiff;
mod tabulated;
mod validation;
