//! Image error metrics used by `compare` and `converge`: relative L2 error, RMSE and mean
//! absolute log10 ratio. RGB images count each channel of each pixel as one value.

use serde::{Deserialize, Serialize};

/// Reads a number that may have been NaN or infinite when written: JSON has no such numbers,
/// so serde_json writes them as `null`, which reads back as NaN.
pub(crate) fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Option::<f64>::deserialize(d).map(|v| v.unwrap_or(f64::NAN))
}

/// Errors of a test image against a reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Metrics {
    /// ‖T − R‖₂ / ‖R‖₂ over the compared values (infinite if the reference is all zero and
    /// the test is not).
    #[serde(deserialize_with = "null_as_nan")]
    pub rel_l2: f64,
    /// √(mean (T − R)²) over the compared values.
    #[serde(deserialize_with = "null_as_nan")]
    pub rmse: f64,
    /// mean |log10(T / R)| over the compared values where both are positive (NaN if none).
    #[serde(deserialize_with = "null_as_nan")]
    pub mean_abs_log10: f64,
    /// Values compared (pixels × channels).
    pub values: usize,
    /// Values entering the log metric.
    pub log_values: usize,
}

/// Why two images cannot be compared.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum MetricsError {
    /// Different sizes.
    #[error("image sizes differ: {test:?} against reference {reference:?}")]
    SizeMismatch {
        /// Test image (width, height).
        test: (u32, u32),
        /// Reference (width, height).
        reference: (u32, u32),
    },
    /// Nothing left to compare after masking.
    #[error("no pixels to compare (every pixel was masked out)")]
    Empty,
}

/// Compares `test` with `reference` (same length, `channels` values per pixel), counting only
/// pixels for which `keep(pixel_index)` is true.
pub fn compare(
    test: &[f64],
    reference: &[f64],
    channels: usize,
    keep: impl Fn(usize) -> bool,
) -> Result<Metrics, MetricsError> {
    assert_eq!(test.len(), reference.len(), "callers check sizes");
    let (mut d2, mut r2, mut n, mut log_sum, mut n_log) = (0.0, 0.0, 0usize, 0.0, 0usize);
    for (i, (t, r)) in test.iter().zip(reference).enumerate() {
        if !keep(i / channels) {
            continue;
        }
        d2 += (t - r) * (t - r);
        r2 += r * r;
        n += 1;
        if *t > 0.0 && *r > 0.0 {
            log_sum += (t / r).log10().abs();
            n_log += 1;
        }
    }
    if n == 0 {
        return Err(MetricsError::Empty);
    }
    let rel_l2 = if r2 > 0.0 {
        (d2 / r2).sqrt()
    } else if d2 == 0.0 {
        0.0
    } else {
        f64::INFINITY
    };
    Ok(Metrics {
        rel_l2,
        rmse: (d2 / n as f64).sqrt(),
        mean_abs_log10: if n_log > 0 {
            log_sum / n_log as f64
        } else {
            f64::NAN
        },
        values: n,
        log_values: n_log,
    })
}

/// Compares two images given as films, optionally ignoring pixels whose centres lie closer
/// than `min_radius` (scene units) to the centre of a square map of half-width `extent`.
/// Grey images (equal channels in both) are compared on one channel.
pub fn compare_films(
    test: &tracer::film::Film,
    reference: &tracer::film::Film,
    exclusion: Option<(f64, f64)>,
) -> Result<Metrics, MetricsError> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(MetricsError::SizeMismatch {
            test: (test.width, test.height),
            reference: (reference.width, reference.height),
        });
    }
    let grey = |f: &tracer::film::Film| f.pixels.iter().all(|p| p[0] == p[1] && p[1] == p[2]);
    let channels = if grey(test) && grey(reference) { 1 } else { 3 };
    let flat = |f: &tracer::film::Film| -> Vec<f64> {
        f.pixels
            .iter()
            .flat_map(|p| p.0[..channels].to_vec())
            .collect()
    };
    let (w, h) = (test.width as usize, test.height as usize);
    let keep = |i: usize| match exclusion {
        None => true,
        Some((min_radius, extent)) => {
            let (x, y) = (i % w, i / w);
            let px = -extent + (x as f64 + 0.5) * 2.0 * extent / w as f64;
            let py = extent - (y as f64 + 0.5) * 2.0 * extent / h as f64;
            px.hypot(py) >= min_radius
        }
    };
    compare(&flat(test), &flat(reference), channels, keep)
}

/// Per-pixel log10(T/R) of the luminances (NaN where either is not positive), for the
/// difference image.
pub fn log_ratio(test: &tracer::film::Film, reference: &tracer::film::Film) -> Vec<f64> {
    test.pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(t, r)| {
            let (t, r) = (t.luminance(), r.luminance());
            if t > 0.0 && r > 0.0 {
                (t / r).log10()
            } else {
                f64::NAN
            }
        })
        .collect()
}

/// One row of an error table.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ErrorRow {
    /// Experiment (`beam stripe`, `checker slab`).
    pub experiment: String,
    /// Method (and profile).
    pub method: String,
    /// Wall seconds.
    pub seconds: f64,
    /// Errors against the reference.
    pub metrics: Metrics,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_known_images() {
        let r = [1.0, 2.0, 0.0, 4.0];
        let t = [2.0, 2.0, 1.0, 0.4];
        let m = compare(&t, &r, 1, |_| true).unwrap();
        // ‖T−R‖² = 1 + 0 + 1 + 12.96 = 14.96, ‖R‖² = 21.
        assert!((m.rel_l2 - (14.96f64 / 21.0).sqrt()).abs() < 1e-15);
        assert!((m.rmse - (14.96f64 / 4.0).sqrt()).abs() < 1e-15);
        // log terms: |log 2| + 0 + |log 0.1| over 3.
        assert!((m.mean_abs_log10 - (2f64.log10() + 1.0) / 3.0).abs() < 1e-15);
        assert_eq!((m.values, m.log_values), (4, 3));
        let masked = compare(&t, &r, 1, |i| i == 1).unwrap();
        assert_eq!(masked.rel_l2, 0.0);
        assert_eq!(compare(&t, &r, 1, |_| false), Err(MetricsError::Empty));
        let two_channels = compare(&t, &r, 2, |p| p == 0).unwrap();
        assert_eq!(two_channels.values, 2);
    }
}
