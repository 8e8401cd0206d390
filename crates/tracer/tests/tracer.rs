//! Integration tests of the tracer's infrastructure (one test binary, one module per theme).
// Channel loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

#[path = "tracer/artist.rs"]
mod artist;
#[path = "tracer/common.rs"]
mod common;
#[path = "tracer/direct_lighting.rs"]
mod direct_lighting;
#[path = "tracer/geometry.rs"]
mod geometry;
#[cfg(feature = "gltf")]
#[path = "tracer/gltf_materials.rs"]
mod gltf_materials;
#[path = "tracer/lights.rs"]
mod lights;
#[path = "tracer/meshes.rs"]
mod meshes;
#[path = "tracer/offset.rs"]
mod offset;
#[path = "tracer/output.rs"]
mod output;
#[path = "tracer/ply.rs"]
mod ply;
#[path = "tracer/scene.rs"]
mod scene;
#[path = "tracer/surfaces.rs"]
mod surfaces;
#[path = "tracer/textures.rs"]
mod textures;
#[path = "tracer/uv_interior.rs"]
mod uv_interior;
