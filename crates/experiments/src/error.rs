//! Errors of the experiments that write data files and plots.

use tracer::error::OutputError;

/// A data file or a plot could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// A data file (EXR, JSON, CSV, Markdown).
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A plot.
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}
