//! `het-bssrdf compare`: error metrics of a test image against a reference (relative L2, RMSE,
//! mean |log10(T/R)|), and a false-colour image of log10(T/R).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use experiments::metrics::{compare_films, log_ratio};
use experiments::plot::{MapPlot, MapScale, map_png};
use tracer::output::read_exr;

/// Arguments of `het-bssrdf compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The image under test (EXR).
    test: PathBuf,
    /// The reference (EXR).
    reference: PathBuf,
    /// Ignore pixels whose centres are closer than R (scene units) to the map centre (beam
    /// maps: r < 1 is dominated by the singular peak). Needs the map extent, read from the
    /// JSON sidecar that `het-bssrdf beam` writes beside the reference.
    #[arg(long = "min-radius", allow_hyphen_values = true)]
    min_radius: Option<f64>,
    /// Print the metrics as JSON.
    #[arg(long)]
    json: bool,
    /// Where to write the difference image (default `<test>-diff.png` beside the test image).
    #[arg(long)]
    diff: Option<PathBuf>,
}

/// The map half-width recorded in a beam map's sidecar.
fn extent_of(exr: &Path) -> anyhow::Result<f64> {
    let json = exr.with_extension("json");
    let text = std::fs::read_to_string(&json).with_context(|| {
        format!(
            "--min-radius needs the map extent from `{}` (written by `het-bssrdf beam`)",
            json.display()
        )
    })?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("`{}` is not valid JSON", json.display()))?;
    v.pointer("/map/extent")
        .and_then(|e| e.as_f64())
        .with_context(|| format!("`{}` has no map.extent field", json.display()))
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let test = read_exr(&args.test).context("the image under test (first argument)")?;
    let reference = read_exr(&args.reference).context("the reference (second argument)")?;
    let exclusion = match args.min_radius {
        None => None,
        Some(r) if r.is_finite() && r >= 0.0 => Some((r, extent_of(&args.reference)?)),
        Some(r) => bail!("--min-radius must be a finite number ≥ 0, got {r}"),
    };
    let m = compare_films(&test, &reference, exclusion).with_context(|| {
        format!(
            "cannot compare `{}` with `{}`",
            args.test.display(),
            args.reference.display()
        )
    })?;
    let diff = args.diff.unwrap_or_else(|| {
        let stem = args
            .test
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        args.test.with_file_name(format!("{stem}-diff.png"))
    });
    let ratio = log_ratio(&test, &reference);
    map_png(
        &diff,
        &MapPlot {
            values: &ratio,
            width: test.width,
            height: test.height,
            extent: [0.0, test.width as f64, test.height as f64, 0.0],
            scale: MapScale::Diverging { limit: 1.0 },
            title: "log10(test / reference)",
            label: "log10 ratio",
        },
    )?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&m)?);
    } else {
        println!("rel_l2 {:.6e}", m.rel_l2);
        println!("rmse {:.6e}", m.rmse);
        println!("mean_abs_log10 {:.6e}", m.mean_abs_log10);
        println!("values {} (log metric over {})", m.values, m.log_values);
    }
    eprintln!("wrote {}", diff.display());
    Ok(())
}
