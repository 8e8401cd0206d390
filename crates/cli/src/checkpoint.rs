//! `render --checkpoint SECONDS`: the render's observer that shows the progress bar and, after
//! a completed pass at least `SECONDS` after the last checkpoint, writes the image so far (the
//! EXR, PNG and JSON set; the sidecar says `"checkpoint": true` and the samples taken).

use crate::diag::say;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use pipeline::progress::RenderBar;
use tracer::integrator::PathCounters;
use tracer::render::{Partial, RenderObserver};

/// Writes one checkpoint from the completed passes.
pub type WriteCheckpoint<'a> = dyn Fn(&Partial<'_, PathCounters>) -> anyhow::Result<()> + Sync + 'a;

/// The progress bar plus periodic checkpoints.
pub struct Checkpoints<'a> {
    progress: RenderBar,
    every: Option<Duration>,
    last: Mutex<Instant>,
    write: &'a WriteCheckpoint<'a>,
}

impl<'a> Checkpoints<'a> {
    /// Checkpoints every `every` (none when `None`) written by `write`.
    pub fn new(
        progress: RenderBar,
        every: Option<Duration>,
        write: &'a WriteCheckpoint<'a>,
    ) -> Self {
        Self {
            progress,
            every,
            last: Mutex::new(Instant::now()),
            write,
        }
    }

    /// Removes the progress bar.
    pub fn finish(&self) {
        self.progress.finish();
    }
}

impl RenderObserver<PathCounters> for Checkpoints<'_> {
    fn pass_started(&self, first: u32, end: u32, total: Option<u32>) {
        RenderObserver::<PathCounters>::pass_started(&self.progress, first, end, total);
    }
    fn advance(&self, pixel_samples: u64) {
        RenderObserver::<PathCounters>::advance(&self.progress, pixel_samples);
    }
    fn pass_finished(&self, partial: &Partial<'_, PathCounters>) {
        let Some(every) = self.every else { return };
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() < every {
            return;
        }
        if let Err(e) = (self.write)(partial) {
            self.progress
                .suspend(|| say!("warning: checkpoint not written: {e:#}"));
        }
        *last = Instant::now();
    }
}
