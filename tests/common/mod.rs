//! Independent reference computations for the workspace tests (never the code under test),
//! and a small harness of shared render calls (`harness`).

pub mod chandrasekhar;
pub mod half_space;
pub mod harness;
pub mod radial;
pub mod shapes;
