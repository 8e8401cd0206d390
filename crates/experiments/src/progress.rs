//! Progress bars on stderr (hidden automatically when stderr is not a terminal), and the
//! tracer's [`Progress`] callback drawn as one.

pub use indicatif::ProgressBar;
use indicatif::ProgressStyle;
use tracer::render::Progress;

/// A progress bar over `len` units named `unit`, labelled `prefix`.
pub fn bar(len: u64, prefix: &str, unit: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{prefix:>14}} [{{bar:40}}] {{human_pos}}/{{human_len}} {unit}  {{elapsed}}<{{eta}}"
        ))
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_prefix(prefix.to_string());
    bar
}

/// A render's rows as a progress bar; each pass of a time-budget render restarts it.
#[derive(Debug)]
pub struct RowBar(ProgressBar);

impl RowBar {
    /// A bar labelled `label`.
    pub fn new(label: &str) -> Self {
        RowBar(bar(0, label, "rows"))
    }
}

impl Progress for RowBar {
    fn start_pass(&self, rows: u64) {
        self.0.reset();
        self.0.set_length(rows);
    }
    fn row_done(&self) {
        self.0.inc(1);
    }
    fn finish(&self) {
        self.0.finish_and_clear();
    }
}
