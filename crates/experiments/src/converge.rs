//! Error against run time: the convergence study behind `het-bssrdf converge`.
//!
//! Every method is run at doubling budgets (samples per pixel, photons, or points per pixel)
//! and each result is compared with a reference. For each BSSRDF method the summary gives:
//! * its *converged error*: the relative L2 error at its largest budget (BSSRDF methods are
//!   biased, so their error levels off there);
//! * its *time to converge*: the wall time of the first budget whose error is within
//!   [`CONVERGED_TOLERANCE`] of the converged error;
//! * the *path-tracing time to the same error*: interpolated log–log between the two path
//!   tracing runs that bracket it, or, when path tracing never got that low, extrapolated from
//!   its last run along the Monte Carlo rate `error ∝ t^(−1/2)` (flagged as extrapolated);
//! * the *speed-up*: path-tracing time over the method's time — the quantity the paper
//!   reports as "roughly eight times".

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::WriteError;
use crate::metrics::Metrics;
use tracer::error::OutputError;
use tracer::output::{write_atomic, write_json};

/// A run counts as converged once its error is within this factor of the final error.
pub const CONVERGED_TOLERANCE: f64 = 1.1;

/// One run of one method at one budget.
#[derive(Debug, Clone, Serialize)]
pub struct Run {
    /// `pt` or the estimator name (with the profile for beam studies).
    pub method: String,
    /// Samples per pixel, photons, or points per pixel (see `unit`).
    pub budget: u64,
    /// What `budget` counts.
    pub unit: &'static str,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Errors against the reference.
    pub metrics: Metrics,
}

/// The summary of one BSSRDF method against path tracing.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[non_exhaustive]
pub struct MethodSummary {
    /// The method.
    pub method: String,
    /// Relative L2 error at the largest budget.
    #[serde(deserialize_with = "crate::metrics::null_as_nan")]
    pub converged_error: f64,
    /// Mean |log10(T/R)| at the largest budget (less dominated by the brightest pixels).
    #[serde(deserialize_with = "crate::metrics::null_as_nan")]
    pub converged_mean_abs_log10: f64,
    /// Seconds of the first run within `CONVERGED_TOLERANCE` of the converged error.
    #[serde(deserialize_with = "crate::metrics::null_as_nan")]
    pub time_to_converge: f64,
    /// Seconds path tracing needs to reach the same error (None without path-tracing runs).
    pub pt_time_to_same_error: Option<f64>,
    /// True when that time was extrapolated beyond the path-tracing runs.
    pub pt_extrapolated: bool,
    /// `pt_time_to_same_error / time_to_converge`.
    pub speedup: Option<f64>,
}

/// Path-tracing time to reach `error`, from its `(seconds, error)` runs (see the module docs).
/// Returns the time and whether it was extrapolated.
pub fn time_to_error(pt: &[(f64, f64)], error: f64) -> Option<(f64, bool)> {
    let mut pts: Vec<(f64, f64)> = pt
        .iter()
        .copied()
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && e.is_finite())
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (first, last) = (*pts.first()?, *pts.last()?);
    if error.is_nan() || error <= 0.0 {
        return None;
    }
    if first.1 <= error {
        // Already below at the cheapest run: go back along t^(-1/2).
        return Some((first.0 * (first.1 / error).powi(2), true));
    }
    for w in pts.windows(2) {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if e1 <= error && e0 > error {
            let f = (error.ln() - e0.ln()) / (e1.ln() - e0.ln());
            return Some(((t0.ln() + f * (t1.ln() - t0.ln())).exp(), false));
        }
    }
    Some((last.0 * (last.1 / error).powi(2), true))
}

/// Summarises every non-`pt` method of `runs` against the `pt` runs.
pub fn summarize(runs: &[Run]) -> Vec<MethodSummary> {
    let pt: Vec<(f64, f64)> = runs
        .iter()
        .filter(|r| r.method == "pt")
        .map(|r| (r.seconds, r.metrics.rel_l2))
        .collect();
    let mut methods: Vec<&str> = Vec::new();
    for r in runs {
        if r.method != "pt" && !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
    }
    methods
        .into_iter()
        .filter_map(|m| {
            let mut own: Vec<&Run> = runs.iter().filter(|r| r.method == m).collect();
            own.sort_by_key(|r| r.budget);
            let converged = own.last()?.metrics.rel_l2;
            let converged_log = own.last()?.metrics.mean_abs_log10;
            let time = own
                .iter()
                .find(|r| r.metrics.rel_l2 <= CONVERGED_TOLERANCE * converged)
                .map(|r| r.seconds)?;
            let pt_time = time_to_error(&pt, converged);
            Some(MethodSummary {
                method: m.to_string(),
                converged_error: converged,
                converged_mean_abs_log10: converged_log,
                time_to_converge: time,
                pt_time_to_same_error: pt_time.map(|p| p.0),
                pt_extrapolated: pt_time.is_some_and(|p| p.1),
                speedup: pt_time.map(|p| p.0 / time.max(1e-12)),
            })
        })
        .collect()
}

/// The CSV `method,spp,seconds,rel_l2,rmse,mean_abs_log10,unit`.
pub fn csv(runs: &[Run]) -> String {
    let mut s = String::from("method,spp,seconds,rel_l2,rmse,mean_abs_log10,unit\n");
    for r in runs {
        s.push_str(&format!(
            "{},{},{:.6},{:.6e},{:.6e},{:.6e},{}\n",
            r.method,
            r.budget,
            r.seconds,
            r.metrics.rel_l2,
            r.metrics.rmse,
            r.metrics.mean_abs_log10,
            r.unit
        ));
    }
    s
}

/// Writes `convergence.csv`, `convergence.png` (+ `.svg`, feature `plot`) and `summary.json`
/// into `dir`.
pub fn write_outputs(
    dir: &Path,
    title: &str,
    runs: &[Run],
    summary: &[MethodSummary],
    extra: serde_json::Value,
) -> Result<(), WriteError> {
    write_atomic(&dir.join("convergence.csv"), csv(runs).as_bytes())?;
    #[cfg(feature = "plot")]
    {
        use crate::plot::{Series, loglog_png};
        let mut series: Vec<Series> = Vec::new();
        for r in runs {
            match series.iter_mut().find(|s| s.label == r.method) {
                Some(s) => s.points.push((r.seconds, r.metrics.rel_l2)),
                None => series.push(Series {
                    label: r.method.clone(),
                    points: vec![(r.seconds, r.metrics.rel_l2)],
                }),
            }
        }
        loglog_png(
            &dir.join("convergence.png"),
            title,
            "wall-clock seconds",
            "relative L2 error",
            &series,
        )?;
    }
    let mut value = serde_json::json!({ "title": title, "methods": summary });
    if let (Some(obj), serde_json::Value::Object(more)) = (value.as_object_mut(), extra) {
        obj.extend(more);
    }
    write_json(
        &crate::provenance::stamped(value),
        &dir.join("summary.json"),
    )?;
    Ok(())
}

/// Checks that `dir` exists, is a directory and accepts new files (before a long study).
pub fn check_dir(dir: &Path) -> Result<(), OutputError> {
    crate::run::check_dir_accepts_files(dir, &dir.join("convergence.csv"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(method: &str, budget: u64, seconds: f64, rel_l2: f64) -> Run {
        Run {
            method: method.into(),
            budget,
            unit: "spp",
            seconds,
            metrics: Metrics {
                rel_l2,
                rmse: 0.0,
                mean_abs_log10: 0.0,
                values: 1,
                log_values: 1,
            },
        }
    }

    #[test]
    fn pt_time_interpolates_and_extrapolates_along_the_monte_carlo_rate() {
        // error = t^(-1/2): the error 0.25 is reached at t = 16 exactly.
        let pt: Vec<(f64, f64)> = [1.0, 4.0, 64.0]
            .iter()
            .map(|&t: &f64| (t, t.powf(-0.5)))
            .collect();
        let (t, ex) = time_to_error(&pt, 0.25).unwrap();
        assert!((t - 16.0).abs() < 1e-9 && !ex);
        let (t, ex) = time_to_error(&pt, 0.0625).unwrap();
        assert!((t - 256.0).abs() < 1e-9 && ex);
        let (t, ex) = time_to_error(&pt, 2.0).unwrap();
        assert!((t - 0.25).abs() < 1e-9 && ex);
        assert!(time_to_error(&[], 0.1).is_none());
    }

    #[test]
    fn summary_finds_converged_error_time_and_speedup() {
        let runs = vec![
            run("pt", 1, 1.0, 1.0),
            run("pt", 4, 4.0, 0.5),
            run("pt", 16, 16.0, 0.25),
            run("sone", 1, 0.5, 0.5),
            run("sone", 2, 1.0, 0.27),
            run("sone", 4, 2.0, 0.25),
        ];
        let s = summarize(&runs);
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].converged_error, 0.25);
        assert_eq!(s[0].time_to_converge, 1.0); // 0.27 ≤ 1.1 × 0.25
        assert!((s[0].pt_time_to_same_error.unwrap() - 16.0).abs() < 1e-9);
        assert!((s[0].speedup.unwrap() - 16.0).abs() < 1e-9);
        assert!(!s[0].pt_extrapolated);
        let text = csv(&runs);
        assert!(text.starts_with("method,spp,seconds,rel_l2,rmse,mean_abs_log10,unit\npt,1,"));
        assert_eq!(text.lines().count(), 7);
    }
}
