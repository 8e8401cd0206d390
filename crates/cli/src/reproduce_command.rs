//! `het-bssrdf reproduce`: the paper's experiments end to end, summarised in `report.md`.

use crate::diag::say;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use experiments::reproduce::{Scale, reproduce};

/// How much work to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ScaleArg {
    /// A few seconds (used by the tests).
    Tiny,
    /// About 3 minutes on 2 cores.
    Quick,
    /// The full run (about 15 minutes on 2 cores).
    Full,
}

/// Arguments of `het-bssrdf reproduce`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Shorthand for `--scale quick`.
    #[arg(long, conflicts_with = "scale")]
    quick: bool,
    /// How much work to do (default full).
    #[arg(long, value_enum)]
    scale: Option<ScaleArg>,
    /// Output directory (created if missing).
    #[arg(short, long, default_value = "reproduce-out")]
    out: PathBuf,
    /// Seed of the runs (references use a different one).
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    seed: u64,
    /// Skip the steps that an earlier run into the same --out (same scale and seed) finished,
    /// reusing their files and numbers (kept in `reproduce-state.json`); the report is the same
    /// as an uninterrupted run's.
    #[arg(long)]
    resume: bool,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let scale = match (args.quick, args.scale) {
        (true, _) | (false, Some(ScaleArg::Quick)) => Scale::QUICK,
        (false, Some(ScaleArg::Tiny)) => Scale::TINY,
        (false, Some(ScaleArg::Full)) | (false, None) => Scale::FULL,
    };
    // Fail now, not after the first experiments, if the output directory is unusable.
    std::fs::create_dir_all(&args.out).with_context(|| {
        format!(
            "invalid --out: cannot create the output directory `{}`",
            args.out.display()
        )
    })?;
    pipeline::files::check_dir_accepts_files(&args.out, &args.out.join("report.md"))
        .context("invalid --out")?;
    say!(
        "reproduce ({} scale): expected time {}; writing into {}",
        scale.name,
        scale.expected,
        args.out.display()
    );
    let bar = pipeline::progress::ProgressBar::new_spinner();
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let start = Instant::now();
    let mut step = |msg: &str| {
        bar.set_message(format!("[{:>5.0} s] {msg}", start.elapsed().as_secs_f64()));
        if !bar.is_hidden() {
            return;
        }
        say!("[{:>5.0} s] {msg}", start.elapsed().as_secs_f64());
    };
    let report = reproduce(&args.out, &scale, args.seed, args.resume, &mut step)
        .with_context(|| format!("reproduce into `{}` failed", args.out.display()))?;
    bar.finish_and_clear();
    say!(
        "done in {:.0} s; report: {}",
        start.elapsed().as_secs_f64(),
        report.display()
    );
    Ok(())
}
