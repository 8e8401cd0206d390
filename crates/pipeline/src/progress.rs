//! Progress bars on stderr (hidden automatically when stderr is not a terminal), and the
//! tracer's render observer drawn as one.

pub use indicatif::ProgressBar;
use indicatif::ProgressStyle;
use tracer::integrator::PrepareObserver;
use tracer::render::RenderObserver;

/// A progress bar over `len` units named `unit`, labelled `prefix`.
pub fn bar(len: u64, prefix: &str, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(len).with_style(counting_style(unit));
    bar.set_prefix(prefix.to_string());
    bar
}

/// The style of [`bar`]: prefix, bar, count of `unit`, elapsed and remaining time.
fn counting_style(unit: &str) -> ProgressStyle {
    ProgressStyle::with_template(&format!(
        "{{prefix:>14}} [{{bar:40}}] {{human_pos}}/{{human_len}} {unit}  {{elapsed}}<{{eta}}"
    ))
    .expect("static template")
    .progress_chars("=> ")
}

/// A render's progress as a bar over every pixel sample of the budget (of the current pass for
/// a time budget), so that a time estimate shows from the first samples; stopped by the
/// tracer's interrupt flag (the default of [`RenderObserver::stop_requested`]).
#[derive(Debug)]
pub struct RenderBar {
    bar: ProgressBar,
    pixels: u64,
    show: bool,
}

impl RenderBar {
    /// A bar labelled `label` for a `width × height` render; hidden when `show` is false.
    pub fn new(label: &str, width: u32, height: u32, show: bool) -> Self {
        // Drawn from the first pass on: not while the render is being prepared, whose own bar
        // ([`PrepareBar`]) shows then.
        let bar = if show {
            let b = ProgressBar::hidden();
            b.set_style(
                ProgressStyle::with_template(
                    "{prefix:>12} [{bar:40}] {percent:>3}%  {elapsed}<{eta}",
                )
                .expect("static template")
                .progress_chars("=> "),
            );
            b.set_prefix(label.to_string());
            b
        } else {
            ProgressBar::hidden()
        };
        Self {
            bar,
            pixels: u64::from(width) * u64::from(height),
            show,
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }

    /// Runs `f` (which prints) with the bar hidden.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
    }
}

impl<C> RenderObserver<C> for RenderBar {
    fn pass_started(&self, first: u32, end: u32, total: Option<u32>) {
        if self.show && first == 0 {
            self.bar
                .set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
        match total {
            Some(n) => {
                if first == 0 {
                    self.bar.set_length(self.pixels * u64::from(n));
                    self.bar.reset();
                }
            }
            None => {
                self.bar.set_length(self.pixels * u64::from(end - first));
                self.bar.reset();
            }
        }
    }
    fn advance(&self, pixel_samples: u64) {
        self.bar.inc(pixel_samples);
    }
}

/// A render's preparation as a bar over each long stage's steps (the shape correction's
/// points); stopped by the tracer's interrupt flag (the default of
/// [`PrepareObserver::stop_requested`]). Hidden until a stage starts, and when `show` is false.
#[derive(Debug)]
pub struct PrepareBar {
    bar: Option<ProgressBar>,
}

impl PrepareBar {
    /// A bar that shows when a stage starts, if `show`.
    pub fn new(show: bool) -> Self {
        Self {
            bar: show.then(|| ProgressBar::hidden().with_style(counting_style("steps"))),
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl PrepareObserver for PrepareBar {
    fn stage(&self, label: &str, units: u64) {
        if let Some(b) = &self.bar {
            b.set_prefix(label.to_string());
            b.set_length(units);
            b.reset();
            b.set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
    }
    fn advance(&self, units: u64) {
        if let Some(b) = &self.bar {
            b.inc(units);
        }
    }
}
