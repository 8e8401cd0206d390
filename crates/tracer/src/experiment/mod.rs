//! Experiments: the beam exitance maps of the paper's Figure 4, image comparison and
//! error-against-time studies.

pub mod beam;
pub mod converge;
pub mod metrics;
pub mod reproduce;
pub mod run;
pub mod scenes;
pub mod study;
