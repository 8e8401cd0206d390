//! `het-bssrdf compare`: error metrics of a test image against a reference (relative L2, RMSE,
//! mean |log10(T/R)|), and a false-colour image of log10(T/R).

use crate::diag::{report, say};
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use experiments::metrics::{Metrics, MetricsError, compare, compare_films, log_ratio};
use experiments::plot::{MapPlot, MapScale, map_png};
use tracer::film::Film;
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
    /// Ignore pixels where the reference (a light-traced beam map) holds fewer than N photons
    /// (value × photons × pixel area, photons and extent from its JSON sidecar), so that the
    /// metrics are not dominated by the reference's own Poisson noise in the far field.
    #[arg(long = "min-counts", allow_hyphen_values = true)]
    min_counts: Option<f64>,
    /// Print the metrics as JSON.
    #[arg(long)]
    json: bool,
    /// Where to write the difference image (default `<test>-diff.png` beside the test image).
    #[arg(long)]
    diff: Option<PathBuf>,
}

/// The map half-width recorded in a beam map's sidecar.
fn extent_of(exr: &Path) -> anyhow::Result<f64> {
    sidecar_number(exr, "/map/extent", "--min-radius")
}

/// The number at `pointer` in the JSON sidecar of the beam map `exr`, for `flag`.
fn sidecar_number(exr: &Path, pointer: &str, flag: &str) -> anyhow::Result<f64> {
    let json = exr.with_extension("json");
    let text = std::fs::read_to_string(&json).with_context(|| {
        format!(
            "{flag} needs `{pointer}` from `{}` (written by `het-bssrdf beam`)",
            json.display()
        )
    })?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("`{}` is not valid JSON", json.display()))?;
    v.pointer(pointer)
        .and_then(|e| e.as_f64())
        .with_context(|| format!("`{}` has no {pointer} field", json.display()))
}

/// Metrics of grey beam maps over the pixels at least `min_radius` from the centre whose
/// reference holds at least `min_counts` photons.
fn compare_counted(
    test: &Film,
    reference: &Film,
    reference_path: &Path,
    min_radius: f64,
    min_counts: f64,
) -> anyhow::Result<Metrics> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(MetricsError::SizeMismatch {
            test: (test.width, test.height),
            reference: (reference.width, reference.height),
        }
        .into());
    }
    let extent = sidecar_number(reference_path, "/map/extent", "--min-counts")?;
    let photons = sidecar_number(reference_path, "/map/samples", "--min-counts")?;
    let (w, h) = (reference.width as usize, reference.height as usize);
    let pixel_area = (2.0 * extent / w as f64) * (2.0 * extent / h as f64);
    let grey = |f: &Film| f.pixels.iter().map(|p| p[0]).collect::<Vec<f64>>();
    let r = grey(reference);
    let keep = |i: usize| {
        let (x, y) = (i % w, i / w);
        let px = -extent + (x as f64 + 0.5) * 2.0 * extent / w as f64;
        let py = extent - (y as f64 + 0.5) * 2.0 * extent / h as f64;
        px.hypot(py) >= min_radius && r[i] * photons * pixel_area >= min_counts
    };
    Ok(compare(&grey(test), &r, 1, keep)?)
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
    let m = match args.min_counts {
        None => compare_films(&test, &reference, exclusion).map_err(anyhow::Error::from),
        Some(n) if n.is_finite() && n >= 0.0 => {
            let r = exclusion.map_or(0.0, |(r, _)| r);
            compare_counted(&test, &reference, &args.reference, r, n)
        }
        Some(n) => bail!("--min-counts must be a finite number ≥ 0, got {n}"),
    }
    .with_context(|| {
        format!(
            "cannot compare `{}` with `{}`",
            args.test.display(),
            args.reference.display()
        )
    })?;
    finish(&args, &test, &reference, m)
}

/// Writes the difference image and prints `m`.
fn finish(args: &Args, test: &Film, reference: &Film, m: Metrics) -> anyhow::Result<()> {
    let diff = args.diff.clone().unwrap_or_else(|| {
        let stem = args
            .test
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        args.test.with_file_name(format!("{stem}-diff.png"))
    });
    let ratio = log_ratio(test, reference);
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
        report(&serde_json::to_string_pretty(&m)?)?;
    } else {
        report(&format!(
            "rel_l2 {:.6e}\nrmse {:.6e}\nmean_abs_log10 {:.6e}\nvalues {} (log metric over {})",
            m.rel_l2, m.rmse, m.mean_abs_log10, m.values, m.log_values
        ))?;
    }
    say!("wrote {}", diff.display());
    Ok(())
}
