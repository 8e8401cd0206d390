//! Time to a given per-pixel error, measured from independent renders (the path tracer's
//! examples `pt_time_to_error` and `pt_marble_time_to_error`).
//!
//! RUNS renders of the same scene with seeds 1..=RUNS give, per pixel and channel, RUNS
//! independent estimates; the standard error of their mean is their spread over √RUNS, and
//! its ratio to the mean is the relative standard error. The median over pixels and channels,
//! e, falls as 1/√(samples), so the time to reach a target error e* is the measured time ×
//! (e / e*)².
//!
//! Each pixel's spread has ν = RUNS − 1 degrees of freedom, so the median over pixels of the
//! estimated standard errors sits below the true one by √(median χ²_ν / ν) (Wilson–Hilferty:
//! median χ²_ν ≈ ν(1 − 2/(9ν))³; 0.978 for 16 runs). [`ErrorSpread::median_relative`] is
//! divided by that factor, which is exact when every pixel has the same relative error and
//! close otherwise.

use bssrdf_core::Rgb;

/// User + system CPU seconds of this process so far (Linux, from `/proc/self/stat`; `None`
/// elsewhere). On a shared machine the wall time includes waiting for the cores; this does not.
pub fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may contain spaces).
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the whole line: 12 and 13 after the name.
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0) // USER_HZ is 100 on Linux
}

/// Error statistics of RUNS independent images of the same scene (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorSpread {
    /// Median over pixels and channels of the relative standard error of the mean of all runs,
    /// corrected for the median's bias ([`chi_median_factor`]).
    pub median_relative: f64,
    /// Median over pixels of the standard error of the mean of R − G, relative to the pixel's
    /// mean grey value (R + G + B)/3: the chroma noise a one-channel-at-a-time estimator shows
    /// as red, green and blue confetti.
    pub chroma_rg: f64,
    /// The same for B − G.
    pub chroma_bg: f64,
    /// Image mean per channel (mean over runs of each run's mean over pixels).
    pub image_mean: Rgb,
    /// Its standard error, from the spread of the runs' image means.
    pub image_mean_se: Rgb,
}

/// √(median χ²_ν / ν) by Wilson–Hilferty: the factor by which the median of estimated
/// standard errors with ν degrees of freedom falls short of the true one.
pub fn chi_median_factor(nu: f64) -> f64 {
    (1.0 - 2.0 / (9.0 * nu)).powi(3).sqrt()
}

/// Median of `v` (sorted in place); 0 for an empty slice.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Mean and standard error of the mean of `v` (at least two values).
fn mean_se(v: impl ExactSizeIterator<Item = f64> + Clone) -> (f64, f64) {
    let k = v.len() as f64;
    let mean = v.clone().sum::<f64>() / k;
    let var = v.map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (mean, (var / k).sqrt())
}

impl ErrorSpread {
    /// The statistics of `images`: RUNS ≥ 2 images of equal size, one per independent seed.
    /// Pixels (and channels) whose mean is not positive are left out of the relative errors.
    pub fn of(images: &[Vec<Rgb>]) -> Self {
        Self::of_pixels(images, |_| true)
    }

    /// [`ErrorSpread::of`] over the pixels `keep` selects (by index); the image mean is still
    /// over all pixels.
    pub fn of_pixels(images: &[Vec<Rgb>], keep: impl Fn(usize) -> bool) -> Self {
        assert!(images.len() >= 2, "at least two runs");
        let n = images[0].len();
        let mut rel = Vec::with_capacity(n * 3);
        let mut rg = Vec::with_capacity(n);
        let mut bg = Vec::with_capacity(n);
        for p in (0..n).filter(|&p| keep(p)) {
            let mut grey = 0.0;
            for c in 0..3 {
                let (mean, se) = mean_se(images.iter().map(|im| im[p][c]));
                grey += mean / 3.0;
                if mean > 0.0 {
                    rel.push(se / mean);
                }
            }
            if grey > 0.0 {
                let diff = |c: usize| mean_se(images.iter().map(move |im| im[p][c] - im[p][1])).1;
                rg.push(diff(0) / grey);
                bg.push(diff(2) / grey);
            }
        }
        let factor = chi_median_factor(images.len() as f64 - 1.0);
        let means: Vec<Rgb> = images
            .iter()
            .map(|im| im.iter().fold(Rgb::ZERO, |a, &x| a + x) * (1.0 / n.max(1) as f64))
            .collect();
        let mut image_mean = Rgb::ZERO;
        let mut image_mean_se = Rgb::ZERO;
        for c in 0..3 {
            (image_mean[c], image_mean_se[c]) = mean_se(means.iter().map(|m| m[c]));
        }
        Self {
            median_relative: median(&mut rel) / factor,
            chroma_rg: median(&mut rg) / factor,
            chroma_bg: median(&mut bg) / factor,
            image_mean,
            image_mean_se,
        }
    }

    /// The factor (e / target)² by which the measured time scales to reach the relative
    /// error `target`.
    pub fn time_factor(&self, target: f64) -> f64 {
        (self.median_relative / target).powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A standard normal variate (Box–Muller).
    fn normal(rng: &mut tracer::rng::Rng) -> f64 {
        let [u, v] = rng.uniform2();
        (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// Images of i.i.d. normal pixels with a known relative error: the median relative
    /// standard error is found within a few per cent, and the chroma spread of channels drawn
    /// independently is √2 times the per-channel error (relative to the grey mean).
    #[test]
    fn spread_of_known_noise_is_recovered() {
        let (runs, pixels, sigma) = (16, 4000, 0.2);
        let mut rng = tracer::rng::Rng::from_keys(5, &[]);
        let images: Vec<Vec<Rgb>> = (0..runs)
            .map(|_| {
                (0..pixels)
                    .map(|_| {
                        Rgb::new(
                            1.0 + sigma * normal(&mut rng),
                            1.0 + sigma * normal(&mut rng),
                            1.0 + sigma * normal(&mut rng),
                        )
                    })
                    .collect()
            })
            .collect();
        let s = ErrorSpread::of(&images);
        let want = sigma / (runs as f64).sqrt();
        assert!((s.median_relative / want - 1.0).abs() < 0.03, "{s:?}");
        for chroma in [s.chroma_rg, s.chroma_bg] {
            assert!((chroma / (want * 2f64.sqrt()) - 1.0).abs() < 0.03, "{s:?}");
        }
        for c in 0..3 {
            assert!(
                (s.image_mean[c] - 1.0).abs() < 4.0 * s.image_mean_se[c],
                "{s:?}"
            );
        }
        // Half the pixels: the same error within the sampling noise of the median.
        let half = ErrorSpread::of_pixels(&images, |p| p % 2 == 0);
        assert!((half.median_relative / want - 1.0).abs() < 0.05, "{half:?}");
        assert_eq!(half.image_mean, s.image_mean);
        // A quarter of the error takes 16 times as long.
        assert!((s.time_factor(s.median_relative / 4.0) - 16.0).abs() < 1e-9);
    }
}
