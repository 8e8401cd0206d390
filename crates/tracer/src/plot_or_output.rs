//! The error of writers that produce both data files and plots.

/// A data file or a plot could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// A data file (EXR, JSON, CSV, Markdown).
    #[error(transparent)]
    Output(#[from] crate::error::OutputError),
    /// A plot.
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}
