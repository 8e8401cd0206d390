//! Workspace integration tests: one binary, one module per theme.

mod artist;
mod common;
mod fuzz_regressions;
mod image_prefilter;
mod index_matched;
mod integrators;
mod oblique;
mod precision;
mod readme;
mod reciprocity;
mod separable;
mod shapes;
mod slab_table;
mod spectral;
mod stability;
mod stiff;
mod tabulated;
mod validation;
