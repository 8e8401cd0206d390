//! Independent reference computations for the workspace tests (never the code under test).

pub mod chandrasekhar;
pub mod half_space;
