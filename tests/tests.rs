//! Workspace integration tests: one binary, one module per theme.

mod artist;
mod common;
mod environment_map;
mod fuzz_regressions;
mod image_prefilter;
mod index_matched;
mod integrators;
mod oblique;
mod precision;
mod readme;
mod reciprocity;
mod rough_surfaces;
mod scene_format;
mod separable;
mod shapes;
mod slab_table;
mod spectral;
mod stability;
mod stiff;
mod tabulated;
mod validation;
