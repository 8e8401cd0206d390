//! f32 geometry meets f64 physics (issue 7).
