//! Built-in scenes, embedded so that `reproduce` runs from any directory. Each is identical to
//! its file in `examples/scenes/` (a test checks it).

/// `examples/scenes/checker-slab.toml`: the paper's Figure 5 situation (see the file).
pub const CHECKER_SLAB: &str = include_str!("checker-slab.toml");
